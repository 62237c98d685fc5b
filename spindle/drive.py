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
    sources = {k: TimeSeries(starts, tuple(h[k] for h in heats), "previous") for k in heats[0]}
    return cycle.to_load_case(spec, sources, others="zero")


def check_drive_feeds(spec: Spec, drive: Drive) -> list[str]:
    """InputError where the drive's power balance feeds a heat source the spec does not have
    (a source renamed or left out: its watts would heat nothing); returns the spec's heat
    sources the drive does not feed, which get 0 W (a source of the spec's own)."""
    fed = list(drive.heat_W(0.0, 0.0, None))
    names = [h.name for h in spec.heat_sources]
    missing = [k for k in fed if k not in names]
    if missing:
        raise InputError(spec.path, "heat_sources", f"the power balance of the drive "
                         f"'{drive.name}' feeds sources {missing} that the spec does not have",
                         f"name the spec's heat sources {', '.join(fed)}, as the drive's "
                         "motor and bearing sets are named")
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
    """The LoadCase of any cycle a user can name: a shipped cycle name, a cycle TOML, a
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
    return cycle_load_case(spec, load_cycle(name_or_path), where=str(name_or_path))
