"""From a load cycle to heat sources: the power balance (spindle.power) applied per step.

A :class:`~spindle.drive_file.Drive` bundles the motor and bearing parameter sets of one
spindle; it is read from a drive file (spindle/data/drives/*.toml for the shipped ones,
format in docs/power.md). A spec names its drive in ``[power_balance] preset``: a shipped
drive's name, or the path of the spindle's own drive file, relative to the spec's folder.
Each step of a cycle gives, through eq. 15-19 and Palmgren's friction, the heat of the
stator, the rotor and each bearing pair, held over the step (the sources are the spec's heat
sources of the same names).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spindle.checks import omega_rad_s
from spindle.cycle_files import load_cycle
from spindle.cycles import Cycle
from spindle.drive_file import Drive, read_drive_toml
from spindle.errors import InputError
from spindle.loads import LoadCase, TimeSeries, read_cycle_csv
from spindle.spec import Spec
from spindle.spec_reader import drive_file_path, shipped_drives

#: The shipped drives by name, read once at import.
DRIVES: dict[str, Drive] = {name: read_drive_toml(path) for name, path in shipped_drives().items()}


def drive_for(spec: Spec) -> Drive | None:
    """The drive named by the spec's ``[power_balance] preset``, or None without one.

    The preset is a shipped drive's name (:data:`DRIVES`) or else the path of a drive TOML,
    relative to the folder of the spec file. InputError if it is neither; SpecError, listing
    every problem, if the drive file is wrong.
    """
    preset = spec.power_preset
    if preset is None:
        return None
    if preset in DRIVES:
        return DRIVES[preset]
    path = drive_file_path(spec.path, preset)  # checked when the spec was read; gone since?
    if path is not None:
        return read_drive_toml(path)
    raise InputError(spec.path, "power_balance.preset",
                     f"'{preset}' is neither a shipped drive nor a drive file (no file "
                     f"{Path(spec.path).parent / preset})",
                     f"use one of: {', '.join(sorted(DRIVES))}, or the path of a drive TOML "
                     "relative to the spec's folder (format: docs/power.md)")


def rated_torque_Nm(drive: Drive) -> float | None:
    """The drive's rated torque [N m]: its nominal point's P_mech / omega (None without one)."""
    if drive.nominal is None:
        return None
    return drive.nominal.P_mech_W / omega_rad_s(drive.nominal.speed_rpm)


#: the shipped cycles' rated point (the SPL2782.1's, paper section 3): ``nominal`` holds it
#: and ``spl-16h`` climbs to its speed
PAPER_RATED = (4300.0, 38000.0)  # rpm, W of mechanical output


def rated_cycles(spec: Spec, drive: Drive) -> tuple[Cycle, Cycle]:
    """(steady, transient) cycles at the spindle's own rated point: the shipped ``nominal``
    and ``spl-16h`` where the drive's nominal point is the paper's (the SPL2782.1's);
    otherwise the drive's nominal point held (its ``[nominal]`` speed against the torque
    P_mech / omega, the losses from the drive's own models) and ``spl-16h`` with every
    speed scaled by the rated speed / 4300 rpm (the same plateaus at the same shares of the
    rated speed, the same room and chiller). A drive without ``[nominal]`` is rated at the
    spec's ``[operating] speed_rpm``, without load."""
    from dataclasses import replace

    from spindle.cycles import Step

    nominal, cycle = load_cycle("nominal"), load_cycle("spl-16h")
    point = drive.nominal
    speed, p_mech = ((point.speed_rpm, point.P_mech_W) if point is not None
                     else (spec.speed_rpm, 0.0))
    if (speed, p_mech) == PAPER_RATED:
        return nominal, cycle
    torque = rated_torque_Nm(drive) or 0.0
    what = (f"the drive's nominal point, {speed:g} rpm and {p_mech / 1e3:g} kW" if point
            else f"the spec's operating speed, {speed:g} rpm without load")
    steady = replace(nominal, name="rated", description=f"{what}, held to a steady state",
                     source=f"the drive file of {spec.name}",
                     steps=(Step(speed, nominal.steps[0].duration_s, torque),))
    scale = speed / PAPER_RATED[0]
    transient = replace(cycle, name=f"spl-16h at {speed:g} rpm",
                        description=f"{cycle.description}, its speeds x {scale:.4g} ({what})",
                        steps=tuple(replace(s, speed_rpm=s.speed_rpm * scale)
                                    for s in cycle.steps))
    return steady, transient


#: cycles named for a spindle's own rating (:func:`rated_cycles`): its rated point held, and
#: the paper's 16 h cycle at its rated speed
RATED_CYCLES = ("rated", "rated-16h")


def rated_scale(spec: Spec, drive: Drive) -> tuple[float, float | None]:
    """(speed factor, torque factor) from the paper's rated point (:data:`PAPER_RATED`) to
    the spindle's (the drive's ``[nominal]``): (1, 1) for the SPL2782.1. The torque factor
    is None where the drive has no nominal point (its rated torque is not known)."""
    point = drive.nominal
    if point is None:
        return spec.speed_rpm / PAPER_RATED[0], None
    if (point.speed_rpm, point.P_mech_W) == PAPER_RATED:
        return 1.0, 1.0
    paper_Nm = PAPER_RATED[1] / omega_rad_s(PAPER_RATED[0])
    return point.speed_rpm / PAPER_RATED[0], rated_torque_Nm(drive) / paper_Nm


def spindle_cycle(spec: Spec, name: str, seed: int = 0) -> Cycle:
    """The cycle ``name`` for this spindle: ``rated`` and ``rated-16h`` at its own rated
    point (:func:`rated_cycles`; a spec without a drive, whose sources are constant, takes the
    shipped ``nominal`` and ``spl-16h`` as they are); ``random``, ``random-loaded``, ``random-ramped-load``
    drawn from ``seed`` (spindle.cycles.drawn_cycle, drawn for the SPL2782.1) with speeds
    and torques scaled to its rated point (:func:`rated_scale`); else the shipped cycle or
    cycle file as it is."""
    from dataclasses import replace

    from spindle.cycles import RANDOM_CYCLES, drawn_cycle

    drive = drive_for(spec)
    if name in RATED_CYCLES:  # without a drive: the paper's, with the spec's own sources
        cycles = (rated_cycles(spec, drive) if drive is not None
                  else (load_cycle("nominal"), load_cycle("spl-16h")))
        return cycles[RATED_CYCLES.index(name)]
    if name not in RANDOM_CYCLES:
        return load_cycle(name)
    cycle = drawn_cycle(name, seed)
    speed, torque = rated_scale(spec, drive) if drive is not None else (1.0, 1.0)
    if (speed, torque) == (1.0, 1.0):
        return cycle
    loaded = any(s.load_torque_Nm > 0 for s in cycle.steps)
    if torque is None and loaded:
        raise InputError(spec.path, "power_balance.preset", f"'{name}' draws process loads "
                         "relative to the drive's rated torque, and the drive file has no "
                         "[nominal] point", "add [nominal] speed_rpm and P_mech_W to the drive "
                         "file (docs/power.md), or use 'random'")
    return replace(cycle, description=f"{cycle.description}; speeds x {speed:.4g}, torques x "
                   f"{torque or 0:.4g} (the spindle's rated point)",
                   steps=tuple(replace(s, speed_rpm=s.speed_rpm * speed,
                                       load_torque_Nm=s.load_torque_Nm * (torque or 0.0))
                               for s in cycle.steps))


def cycle_load_case(spec: Spec, cycle: Cycle, drive: Drive | None = None,
                    where: str | None = None) -> LoadCase:
    """The LoadCase of ``cycle`` on ``spec``: speeds, ambient and coolant from the cycle;
    heat sources from the drive's power balance per step (or, without a drive, the spec's
    own constant sources). ``where``: the cycle's file or name, for messages."""
    drive = drive if drive is not None else drive_for(spec)
    if drive is None:
        return cycle.to_load_case(spec)
    starts = tuple(float(t) for t in cycle.boundaries_s[:-1])
    heats = []
    for i, s in enumerate(cycle.steps):
        try:
            heats.append(drive.heat_W(s.speed_rpm, s.load_torque_Nm, s.power_kW))
        except ValueError as exc:  # a step the power balance cannot close (P_el < M omega)
            raise InputError(where or f"cycle {cycle.name}", f"steps[{i}]", str(exc),
                             "give the step a power_kW above its mechanical power M omega, or "
                             "leave power_kW out (the motor model then gives the losses)") from None
    check_drive_feeds(spec, drive)
    _warn_overload(cycle, drive, where)
    sources = {k: TimeSeries(starts, tuple(h[k] for h in heats), "previous") for k in heats[0]}
    return cycle.to_load_case(spec, sources, others="zero")


#: a step's process torque beyond this many times the drive's rated torque is warned of: a
#: spindle motor's short-time ratings (S6, S2) are 1.3-1.6 times its S1 torque
OVERLOAD = 2.0


def _warn_overload(cycle: Cycle, drive: Drive, where: str | None) -> None:
    """A CycleWarning where a step of ``cycle`` asks more than :data:`OVERLOAD` times the
    drive's rated torque (P_mech / omega at its ``[nominal]`` point; none without one)."""
    import warnings

    from spindle.errors import CycleWarning

    rated = rated_torque_Nm(drive)
    if rated is None:
        return
    point = drive.nominal
    worst = max(range(len(cycle.steps)), key=lambda i: cycle.steps[i].load_torque_Nm)
    torque = cycle.steps[worst].load_torque_Nm
    if torque > OVERLOAD * rated:
        warnings.warn(CycleWarning(
            f"{where or 'cycle ' + cycle.name}: steps[{worst}]: a process torque of {torque:g} "
            f"N m is {torque / rated:.1f} times the drive's rated {rated:.3g} N m "
            f"({point.P_mech_W / 1e3:g} kW at {point.speed_rpm:g} rpm): its heat is computed, "
            "but no spindle motor holds it (fix: check the cycle's torques and units)"),
            stacklevel=3)


def check_drive_feeds(spec: Spec, drive: Drive) -> list[str]:
    """InputError where the drive's power balance feeds a heat source the spec does not have
    (a source renamed or left out: its watts would heat nothing); returns the spec's heat
    sources the drive does not feed, which get 0 W (a source of the spec's own)."""
    fed = list(drive.heat_W(0.0, 0.0, None))
    names = [h.name for h in spec.heat_sources]
    missing = [k for k in fed if k not in names]
    if missing:
        unfed = [k for k in names if k not in fed]
        raise InputError(spec.path, "heat_sources", f"the power balance of the drive "
                         f"'{drive.name}' feeds sources {missing} that the spec does not have"
                         + (f" (the spec's {unfed} get nothing)" if unfed else ""),
                         f"name the drive file's sets ([bearings.NAME]) as the spec's heat "
                         f"sources, or the spec's heat sources {', '.join(fed)}, as the "
                         "drive's motor and bearing sets are named")
    return [k for k in names if k not in fed]


def as_load_case(spec: Spec, case: LoadCase | str | Path | None) -> LoadCase:
    """``case`` as the LoadCase a solver takes: a LoadCase as it is, None as the spec's own
    case, a cycle's name or file as :func:`load_case` reads it (so that
    ``model.transient("spl-16h", dt_s=60)`` works as the CLI's ``--cycle spl-16h`` does)."""
    if case is None:
        return spec.default_load_case()
    if isinstance(case, str | Path):
        return load_case(spec, case)
    if not isinstance(case, LoadCase):
        raise TypeError(f"a case is a LoadCase, a cycle's name or file, or None, not "
                        f"{type(case).__name__}")
    check_load_case(spec, case)
    return case


def check_load_case(spec: Spec, case: LoadCase) -> None:
    """InputError (the case named as its file) where a LoadCase built in Python asks what no
    input file may: a source the spec does not have (it was ignored: the spec's own power
    stood), a speed outside 0..SPEED_MAX_RPM, a temperature outside the bench's -60..250 °C
    (the most a file may give), a heat outside 0..POWER_MAX_KW. Found by fuzzing the API:
    each of these solved."""
    from spindle.bench import T_KELVIN_MAX_C, T_MIN_C
    from spindle.units import POWER_MAX_KW, SPEED_MAX_RPM, ZERO_C_K

    where = f"load case '{case.name}'"
    names = [h.name for h in spec.heat_sources]
    unknown = [k for k in case.sources if k not in names]
    if unknown:
        raise InputError(where, "sources", f"{unknown} are not heat sources of spec "
                         f"'{spec.name}'", f"name sources of the spec: {names}")
    limits = [("speed_rpm", case.speed_rpm, 0.0, SPEED_MAX_RPM, "rpm"),
              ("T_ambient_K", case.T_ambient_K, T_MIN_C + ZERO_C_K, T_KELVIN_MAX_C + ZERO_C_K,
               "K"),
              ("T_coolant_K", case.T_coolant_K, T_MIN_C + ZERO_C_K, T_KELVIN_MAX_C + ZERO_C_K,
               "K"),
              *((f"sources['{k}']", v, 0.0, POWER_MAX_KW * 1e3, "W")
                for k, v in case.sources.items())]
    for what, series, lo, hi, unit in limits:
        v = np.asarray(series.values, dtype=float)
        if v.min() < lo or v.max() > hi:
            bad = v.min() if v.min() < lo else v.max()
            raise InputError(where, what, f"reaches {bad:g} {unit}, outside {lo:g}..{hi:g} "
                             f"{unit}", "give temperatures in K" if unit == "K" else
                             f"give values in {lo:g}..{hi:g} {unit}")


def load_case(spec: Spec, name_or_path: str | Path, base: LoadCase | None = None) -> LoadCase:
    """The LoadCase of any cycle a user can name: a shipped cycle name, ``rated`` or
    ``rated-16h`` (the spindle's own rating, :func:`rated_cycles`), a cycle TOML, a
    step-table CSV (``speed_rpm, duration_s, ...``: heat from the power balance) or a
    time-series CSV (``time_s, speed_rpm, T_env_C, T_coolant_C, <source>_W``: heat as given,
    what the file leaves out taken from ``base``, by default the spec's own load case)."""
    path = Path(name_or_path)
    if path.suffix.lower() == ".csv" and path.is_file():
        header = next((ln for ln in path.read_text(encoding="utf-8-sig", errors="replace").splitlines()
                       if ln.strip() and not ln.lstrip().startswith("#")), "")
        if "time_s" in [h.strip() for h in header.split(",")]:
            return read_cycle_csv(path, [h.name for h in spec.heat_sources],
                                  base if base is not None else spec.default_load_case())
    if str(name_or_path) in RATED_CYCLES:
        return cycle_load_case(spec, spindle_cycle(spec, str(name_or_path)))
    return cycle_load_case(spec, load_cycle(name_or_path), where=str(name_or_path))
