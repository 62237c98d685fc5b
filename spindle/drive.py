"""From a load cycle to heat sources: the power balance (spindle.power) applied per step.

A :class:`Drive` bundles the motor and bearing parameter sets of one spindle; a spec names
its drive in ``[power_balance] preset``. Each step of a cycle gives, through eq. 15-19 and
Palmgren's friction, the heat of the stator, the rotor and each bearing pair, held over the
step (the sources are the spec's heat sources of the same names).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

from spindle.cycles import Cycle, load_cycle
from spindle.errors import InputError
from spindle.loads import LoadCase, TimeSeries, read_cycle_csv
from spindle.power import (
    SPL2782_BEARINGS,
    SPL2782_MOTOR,
    SPL2782_NOMINAL_T_WINDING_K,
    BearingParams,
    MotorParams,
    power_balance,
)
from spindle.spec import Spec


@dataclass(frozen=True)
class Drive:
    """Motor and bearings of a spindle. ``T_winding_K`` [K] is the winding temperature used
    for the copper resistance R(T) (eq. 17); ``bearings`` maps heat-source names to sets."""

    name: str
    motor: MotorParams
    bearings: dict[str, BearingParams] = field(default_factory=dict)
    T_winding_K: float = SPL2782_NOMINAL_T_WINDING_K

    def heat_W(self, speed_rpm: float, load_torque_Nm: float = 0.0,
               power_kW: float | None = None) -> dict[str, float]:
        """Heat per source [W] at one operating point."""
        pb = power_balance(self.motor, self.bearings, speed_rpm, load_torque_Nm,
                           self.T_winding_K,
                           P_el_W=None if power_kW is None else power_kW * 1e3)
        return pb.heat_sources_W()

    def with_f0(self, f0: float) -> Drive:
        """The same drive with bearing friction factor f0 on every pair."""
        return replace(self, bearings={k: replace(b, f0=f0) for k, b in self.bearings.items()})

    def with_rotor_share(self, share: float) -> Drive:
        return replace(self, motor=replace(self.motor, rotor_loss_share=share))


DRIVES: dict[str, Drive] = {
    "spl2782": Drive("spl2782", SPL2782_MOTOR, dict(SPL2782_BEARINGS)),
}


def drive_for(spec: Spec) -> Drive | None:
    """The drive named by the spec's ``[power_balance] preset``, or None."""
    if spec.power_preset is None:
        return None
    if spec.power_preset not in DRIVES:
        raise InputError(spec.path, "power_balance.preset", f"unknown preset "
                         f"'{spec.power_preset}'", f"use one of: {', '.join(sorted(DRIVES))}")
    return DRIVES[spec.power_preset]


def cycle_load_case(spec: Spec, cycle: Cycle, drive: Drive | None = None) -> LoadCase:
    """The LoadCase of ``cycle`` on ``spec``: speeds, ambient and coolant from the cycle;
    heat sources from the drive's power balance per step (or, without a drive, the spec's
    own constant sources)."""
    drive = drive if drive is not None else drive_for(spec)
    if drive is None:
        return cycle.to_load_case(spec)
    starts = tuple(float(t) for t in cycle.boundaries_s[:-1])
    heats = [drive.heat_W(s.speed_rpm, s.load_torque_Nm, s.power_kW) for s in cycle.steps]
    names = {h.name for h in spec.heat_sources}
    missing = set(heats[0]) - names
    if missing:
        raise InputError(spec.path, "heat_sources", f"the power balance feeds sources "
                         f"{sorted(missing)} that the spec does not have",
                         "name the spec's heat sources stator, rotor, front_bearing, rear_bearing")
    sources = {k: TimeSeries(starts, tuple(h[k] for h in heats), "previous") for k in heats[0]}
    return cycle.to_load_case(spec, sources, others="zero")


def load_case(spec: Spec, name_or_path: str | Path, base: LoadCase | None = None) -> LoadCase:
    """The LoadCase of any cycle a user can name: a shipped cycle name, a cycle TOML, a
    step-table CSV (``speed_rpm, duration_s, ...``: heat from the power balance) or a
    time-series CSV (``time_s, speed_rpm, T_env_C, T_coolant_C, <source>_W``: heat as given,
    what the file leaves out taken from ``base``, by default the spec's own load case)."""
    path = Path(name_or_path)
    if path.suffix.lower() == ".csv" and path.is_file():
        header = next((ln for ln in path.read_text(encoding="utf-8", errors="replace").splitlines()
                       if ln.strip() and not ln.lstrip().startswith("#")), "")
        if "time_s" in [h.strip() for h in header.split(",")]:
            return read_cycle_csv(path, [h.name for h in spec.heat_sources],
                                  base if base is not None else spec.default_load_case())
    return cycle_load_case(spec, load_cycle(name_or_path))
