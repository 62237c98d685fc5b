"""The drive of a spindle: its motor and bearing parameter set, and the TOML file it lives in.

A parameter set is data, not code (as PyBaMM keeps parameter sets apart from its models): a
:class:`Drive` is read from a drive file (format: docs/power.md, "Drive files"; shipped
ones in spindle/data/drives/) by :func:`read_drive_toml`, which checks every field and
raises :class:`~spindle.errors.SpecError` with one problem per wrong field, each naming the
file, the field and the fix. The loss models that use the set are in spindle.power.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from spindle.checks import omega_rad_s
from spindle.errors import Problem, SpecError
from spindle.power import BearingParams, MotorParams, PowerBalance, bearing_friction, power_balance
from spindle.spec_reader import read_toml
from spindle.units import SPEED_MAX_RPM


@dataclass(frozen=True)
class NominalPoint:
    """The rated point a parameter set is tuned to: ``speed_rpm`` [rpm], mechanical output
    ``P_mech_W`` [W] and, for reference, the published total loss ``losses_W`` [W]."""

    speed_rpm: float
    P_mech_W: float
    losses_W: float | None = None


#: speed at which a drive's friction_exponent leaves the friction factors unchanged [rpm]
FRICTION_REF_RPM = 3000.0


@dataclass(frozen=True)
class Drive:
    """Motor and bearings of a spindle. ``T_winding_K`` [K] is the winding temperature used
    for the copper resistance R(T) (eq. 17); ``bearings`` maps heat-source names to sets."""

    name: str
    motor: MotorParams
    bearings: dict[str, BearingParams]
    T_winding_K: float
    nominal: NominalPoint | None = None
    description: str = ""
    #: the bearings' friction factors times (n / FRICTION_REF_RPM)^e: a speed dependence of
    #: the friction beyond Palmgren's (nu n)^(2/3) (0: Palmgren's law as it stands)
    friction_exponent: float = 0.0
    #: bearings_at's sets by speed (a fit asks for the same speed levels at hundreds of
    #: operating points); not a field of the parameter set: replace() starts it empty
    _bearings_by_speed: dict = field(default_factory=dict, init=False, repr=False,
                                     compare=False)

    def bearings_at(self, speed_rpm: float) -> dict[str, BearingParams]:
        """The bearing sets at ``speed_rpm`` [rpm], with the friction exponent applied."""
        if self.friction_exponent == 0.0:
            return self.bearings
        n = float(speed_rpm)
        out = self._bearings_by_speed.get(n)
        if out is None:
            scale = (max(n, 1.0) / FRICTION_REF_RPM) ** self.friction_exponent
            out = {k: replace(b, f0=b.f0 * scale) for k, b in self.bearings.items()}
            self._bearings_by_speed[n] = out
        return out

    def heat_W(self, speed_rpm: float, load_torque_Nm: float = 0.0,
               power_kW: float | None = None) -> dict[str, float]:
        """Heat per source [W] at one operating point."""
        pb = power_balance(self.motor, self.bearings_at(speed_rpm), speed_rpm, load_torque_Nm,
                           self.T_winding_K,
                           P_el_W=None if power_kW is None else power_kW * 1e3)
        return pb.heat_sources_W()

    def with_friction_exponent(self, exponent: float) -> Drive:
        """The same drive with friction factors times (n / FRICTION_REF_RPM)^``exponent``."""
        return replace(self, friction_exponent=float(exponent))

    def with_f0(self, f0: float) -> Drive:
        """The same drive with bearing friction factor f0 on every pair."""
        return replace(self, bearings={k: replace(b, f0=f0) for k, b in self.bearings.items()})

    def with_rotor_share(self, share: float) -> Drive:
        """The same drive with the rotor's fraction ``share`` [-] of the motor loss."""
        return replace(self, motor=replace(self.motor, rotor_loss_share=share))

    def nominal_point(self, T_winding_K: float | None = None) -> PowerBalance:
        """The power balance at the nominal point: the motor delivers ``nominal.P_mech_W`` at
        ``nominal.speed_rpm``; the process torque is what remains after the bearing friction
        torque. ``T_winding_K`` [K] defaults to the drive's. ValueError without a nominal point.
        """
        if self.nominal is None:
            raise ValueError(f"drive '{self.name}' has no nominal point; add a [nominal] table")
        n = self.nominal.speed_rpm
        w = omega_rad_s(n)
        friction = sum(bearing_friction(p, n).torque_Nm for p in self.bearings.values())
        return power_balance(self.motor, self.bearings, n, self.nominal.P_mech_W / w - friction,
                             self.T_winding_K if T_winding_K is None else T_winding_K)


# ------------------------------------------------------------------------------ file format


@dataclass(frozen=True)
class Field:
    """One number of a drive file: its key (with the unit in it), unit text for messages, and
    the range it must lie in; ``whole`` for counts. A field without ``required`` takes the
    parameter class's default."""

    key: str
    unit: str
    lo: float | None = None
    lo_open: bool = False
    hi: float | None = None
    whole: bool = False
    required: bool = True


# Upper (and some lower) bounds are not plausibility: they are a hundred to a thousand times
# beyond any motor spindle's value (the shipped spl2782's in brackets), so that a unit slip
# or a stray exponent is refused by name instead of overflowing the power balance.
DRIVE_FIELDS = (Field("T_winding_K", "K", lo=200.0, hi=700.0),)
NOMINAL_FIELDS = (Field("speed_rpm", "rpm", lo=0.0, lo_open=True, hi=SPEED_MAX_RPM),
                  Field("P_mech_W", "W", lo=0.0, hi=1e7),  # 10 MW (38 kW)
                  Field("losses_W", "W", lo=0.0, hi=1e7, required=False))
MOTOR_FIELDS = (Field("R20_ohm", "ohm", lo=0.0, lo_open=True, hi=100.0),  # (0.195)
                Field("kT_Nm_A", "N m/A", lo=0.01, hi=100.0),  # (1.2)
                Field("pole_pairs", "-", lo=1.0, hi=64.0, whole=True),  # (4)
                Field("k_h_W_HzT2", "W/(Hz T2)", lo=0.0, hi=1e3),  # (0.6)
                Field("k_e_W_Hz2T2", "W/(Hz2 T2)", lo=0.0, hi=10.0),  # (0.003)
                Field("B_T", "T", lo=0.0, hi=5.0),  # electrical steel saturates near 2 T (1.5)
                Field("phases", "-", lo=1.0, hi=12.0, whole=True, required=False),
                Field("rotor_loss_share", "-", lo=0.0, hi=1.0, required=False),
                Field("alpha_cu_1_K", "1/K", lo=0.0, hi=0.1, required=False))  # (0.00393)
BEARING_FIELDS = (Field("f0", "-", lo=0.0, lo_open=True, hi=100.0),  # Palmgren's 1-10 (0.26)
                  # 2 m catches a pitch diameter given in mm
                  Field("dm_m", "m", lo=0.0, lo_open=True, hi=2.0),
                  # 0.1 mm2/s is a tenth of water's: it catches a viscosity given in m2/s
                  Field("nu_mm2_s", "mm2/s", lo=0.1, hi=1e5),  # (12)
                  Field("preload_N", "N", lo=0.0, hi=1e6),  # (300-400)
                  # 100 N catches a rating given in kN (40-52 kN)
                  Field("C0_N", "N", lo=100.0, hi=1e8),
                  Field("count", "-", lo=1.0, hi=64.0, whole=True, required=False),
                  Field("inner_ring_share", "-", lo=0.0, hi=1.0, required=False))
TEXT_KEYS = ("name", "source")
DRIVE_KEYS = ("name", "description", "T_winding_K")
TABLES = ("drive", "nominal", "motor", "bearings")
#: A unit slip that a range check most likely caught, named in the fix.
UNIT_SLIPS = {"T_winding_K": " (in K: 120 degC is 393.15 K)", "dm_m": " (in m: 115 mm is 0.115 m)",
              "C0_N": " (in N: 40 kN is 40000 N)",
              "nu_mm2_s": " (in mm2/s: 1.5e-5 m2/s is 15 mm2/s)"}
#: Heat-source names the motor feeds; a bearing set cannot take them.
MOTOR_SOURCES = ("stator", "rotor")


class _Problems:
    """Collects the problems of one drive file; never stops at the first."""

    def __init__(self, file: str):
        self.file = file
        self.problems: list[Problem] = []

    def add(self, fld: str, message: str, fix: str) -> None:
        self.problems.append(Problem(self.file, fld, message, fix))

    def table(self, data: dict[str, Any], key: str, *, missing_fix: str | None) -> dict | None:
        """The table ``key`` of ``data``; None if absent (a problem if ``missing_fix``)."""
        v = data.get(key)
        if v is None:
            if missing_fix is not None:
                self.add(key, "required table is missing", missing_fix)
            return None
        if not isinstance(v, dict):
            self.add(key, "must be a table", f"write it as [{key}]")
            return None
        return v

    def unknown_keys(self, d: dict[str, Any], allowed: tuple[str, ...], where: str) -> None:
        what = "field" if where else "table"
        for k in d:
            if k not in allowed:
                self.add(f"{where}.{k}" if where else k, f"is not a {what} here (a typo?)",
                         f"use one of {', '.join(allowed)}")

    def number(self, d: dict[str, Any], f: Field, where: str) -> float | int | None:
        """The value of ``f`` in table ``d`` (None if missing or wrong; problems recorded)."""
        fld = f"{where}.{f.key}"
        unit = "" if f.unit == "-" else f" {f.unit}"
        in_unit = "" if f.unit == "-" else f" in {f.unit}"
        if f.key not in d:
            if f.required:
                self.add(fld, "required field is missing", f"add {f.key} = <number{unit}>")
            return None
        v = d[f.key]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            self.add(fld, f"must be a finite number{in_unit}, not {v!r}",
                     f"write {f.key} = <number{unit}>")
            return None
        if f.whole and v != int(v):
            self.add(fld, f"{v:g} is not a whole number", f"give {f.key} as a whole number")
            return None
        low = f.lo is not None and (v <= f.lo if f.lo_open else v < f.lo)
        if low or (f.hi is not None and v > f.hi):
            rng = f"> {f.lo:g}" if f.lo_open else f">= {f.lo:g}"
            if f.hi is not None:
                rng = f"{rng} and <= {f.hi:g}" if f.lo_open else f"in {f.lo:g}..{f.hi:g}"
            self.add(fld, f"{v:g}{unit} is out of range (must be {rng})",
                     f"give {f.key} {rng}{unit}{UNIT_SLIPS.get(f.key, '')}")
            return None
        return int(v) if f.whole else float(v)

    def numbers(self, d: dict[str, Any], spec: tuple[Field, ...], where: str) -> dict | None:
        """The fields ``spec`` of table ``d`` by key; None if any is missing or wrong."""
        n0 = len(self.problems)
        out = {f.key: self.number(d, f, where) for f in spec}
        if len(self.problems) > n0:
            return None
        return {k: v for k, v in out.items() if v is not None}

    def text(self, d: dict[str, Any], key: str, where: str, default: str) -> str:
        v = d.get(key, default)
        if not isinstance(v, str):
            self.add(f"{where}.{key}", f"must be a text, not {v!r}", f'write {key} = "..."')
            return default
        return v


def _keys(spec: tuple[Field, ...]) -> tuple[str, ...]:
    return (*TEXT_KEYS, *(f.key for f in spec))


def _read(file: str, data: dict[str, Any], stem: str) -> Drive:
    p = _Problems(file)
    p.unknown_keys(data, TABLES, "")

    head = p.table(data, "drive", missing_fix="add a [drive] table with T_winding_K = <K>")
    name, description, winding = stem, "", None
    if head is not None:
        p.unknown_keys(head, DRIVE_KEYS, "drive")
        name = p.text(head, "name", "drive", stem)
        description = p.text(head, "description", "drive", "")
        winding = p.numbers(head, DRIVE_FIELDS, "drive")

    nom = p.table(data, "nominal", missing_fix=None)
    nominal = None
    if nom is not None:
        p.unknown_keys(nom, tuple(f.key for f in NOMINAL_FIELDS), "nominal")
        nv = p.numbers(nom, NOMINAL_FIELDS, "nominal")
        nominal = None if nv is None else NominalPoint(**nv)

    mt = p.table(data, "motor", missing_fix="add a [motor] table (fields: docs/power.md)")
    motor = None
    if mt is not None:
        p.unknown_keys(mt, _keys(MOTOR_FIELDS), "motor")
        mv = p.numbers(mt, MOTOR_FIELDS, "motor")
        texts = {"name": p.text(mt, "name", "motor", f"{name} motor"),
                 "source": p.text(mt, "source", "motor", "")}
        motor = None if mv is None else _build(p, MotorParams, "motor", **texts, **mv)

    bearings: dict[str, BearingParams] = {}
    for key, bd in (p.table(data, "bearings", missing_fix=None) or {}).items():
        where = f"bearings.{key}"
        if key in MOTOR_SOURCES:
            p.add(where, f"'{key}' is the motor's heat source",
                  "name the set after the spec's bearing heat source, e.g. front_bearing")
            continue
        if not isinstance(bd, dict):
            p.add(where, "must be a table", f"write it as [{where}] with f0, dm_m, ...")
            continue
        p.unknown_keys(bd, _keys(BEARING_FIELDS), where)
        bv = p.numbers(bd, BEARING_FIELDS, where)
        texts = {"name": p.text(bd, "name", where, f"{name} {key}"),
                 "source": p.text(bd, "source", where, "")}
        if bv is not None and (b := _build(p, BearingParams, where, **texts, **bv)) is not None:
            bearings[key] = b

    if p.problems or motor is None or winding is None:
        raise SpecError(p.problems)
    return Drive(name, motor, bearings, winding["T_winding_K"], nominal, description)


def _build(p: _Problems, cls: type, where: str, **kw: Any) -> Any:
    """``cls(**kw)``; a ValueError the field checks above did not foresee becomes a problem."""
    try:
        return cls(**kw)
    except ValueError as exc:
        p.add(where, str(exc), "correct that value (ranges: docs/power.md)")
        return None


def read_drive_toml(path: str | Path) -> Drive:
    """Read and check a drive file (format: docs/power.md). Raises SpecError listing every
    problem, each with the file, the field and the fix."""
    path = Path(path)
    return _read(str(path), read_toml(path), path.stem)

