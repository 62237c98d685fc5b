"""The spindle description (spec): a TOML file of CAD dimensions, materials, links, boundary
conditions, heat sources and sensors, in SI units. See docs/spec.md for every field.

:func:`load_spec` reads and validates a file; every problem found is reported at once, each
naming the file, the field and the fix (:class:`~spindle.errors.SpecError`).
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from spindle.errors import Problem, SpecError
from spindle.geometry import TOL_M, Trapezoid, contact_length, overlap
from spindle.loads import LoadCase, SpeedTable, TimeSeries

ROLES = ("shaft", "tool", "rotor", "stator", "housing", "cooling_sleeve",
         "front_bearing", "rear_bearing")
BEARING_ROLES = ("front_bearing", "rear_bearing")
SIDES = ("outer", "inner", "front", "rear", "any")
T_REFS = ("ambient", "coolant")
LINK_TYPES = ("bearing", "air_gap", "contact")
#: A rotor-stator gap wider than this is not an air gap of a built-in motor [m].
MAX_AIR_GAP_M = 5e-3
#: the fields every table of a spec may hold (docs/spec.md); ``description``, ``source`` and
#: ``note`` document an entry anywhere
_DOC = ("description", "source", "note")
KNOWN_FIELDS: dict[str, tuple[str, ...]] = {
    "": ("spindle", "operating", "power_balance", "mesh", "materials", "parts", "links",
         "surfaces", "heat_sources", "sensors", "sensor_arrays"),
    "spindle": ("name", *_DOC),
    "operating": ("speed_rpm", "T_ambient_K", "T_coolant_K", "T_initial_K", *_DOC),
    "power_balance": ("preset", *_DOC),
    "mesh": ("h0_m", *_DOC),
    "materials": ("k_W_mK", "k_r_W_mK", "k_z_W_mK", "rho_kg_m3", "c_J_kgK", "E_Pa", "nu",
                  "alpha_1_K", *_DOC),
    "parts": ("name", "role", "material", "sections", *_DOC),
    "sections": ("z_start", "z_end", "r_inner", "r_outer", "material", "name", *_DOC),
    "links.bearing": ("type", "part", "section", "G_W_K", *_DOC),
    "links.air_gap": ("type", "inner", "outer", "h_W_m2K", *_DOC),
    "links.contact": ("type", "parts", "h_W_m2K", *_DOC),
    "surfaces": ("name", "parts", "part", "side", "z_min", "z_max", "h_W_m2K", "T_ref", *_DOC),
    "heat_sources": ("name", "power_W", "part", "section", "surface", *_DOC),
    "sensors": ("name", "kind", "z", "r", "z_ref", "r_ref", *_DOC),
    "sensor_arrays": ("name", "part", "count", "radius", *_DOC),
}
#: the largest dimension [m] of a motor spindle (the SPL2782 is 0.6 m long); beyond this a
#: spec is taken to be in millimetres
MAX_SIZE_M = 5.0
#: the most elements a spec's level-0 mesh may have (spl2782: 1379); every level adds 4x
MAX_LEVEL0_ELEMENTS = 200_000


@dataclass(frozen=True)
class Material:
    """Thermal and elastic properties, SI. ``k_r``/``k_z``: radial/axial conductivity [W/m/K]."""

    name: str
    k_r_W_mK: float
    k_z_W_mK: float
    rho_kg_m3: float
    c_J_kgK: float
    E_Pa: float
    nu: float
    alpha_1_K: float
    source: str = ""

    @property
    def isotropic(self) -> bool:
        return self.k_r_W_mK == self.k_z_W_mK


@dataclass(frozen=True)
class Section(Trapezoid):
    """One axisymmetric section of a part: geometry [m], its material and optional name."""

    material: str = ""
    name: str = ""


@dataclass(frozen=True)
class Part:
    name: str
    role: str
    sections: tuple[Section, ...]


@dataclass(frozen=True)
class BearingLink:
    """Rolling-contact conductance between the raceways [W/K]; its ``section`` of the bearing
    ``part`` is meshed with the conductivity that gives this conductance radially."""

    part: str
    section: str
    G_W_K: SpeedTable


@dataclass(frozen=True)
class AirGapLink:
    """Effective rotor-stator air-gap coefficient [W/m2/K] on the rotor surface; the gap
    between ``inner`` and ``outer`` is meshed as a layer with the matching conductivity."""

    inner: str
    outer: str
    h_W_m2K: SpeedTable


@dataclass(frozen=True)
class ContactLink:
    """Fitted-joint contact conductance [W/m2/K] on the interface of two touching parts."""

    parts: tuple[str, str]
    h_W_m2K: float


Link = BearingLink | AirGapLink | ContactLink


@dataclass(frozen=True)
class Surface:
    """Named exposed surface: the boundary of ``parts`` facing ``side``, within z limits [m].

    With ``h_W_m2K`` it is a convective boundary towards ``T_ref`` (ambient or coolant);
    without, it only names the place for a surface heat source.
    """

    name: str
    parts: tuple[str, ...]
    side: str
    z_min: float
    z_max: float
    h_W_m2K: SpeedTable | None
    T_ref: str | None


@dataclass(frozen=True)
class HeatSource:
    """Heat [W] into a part (or one named section of it) by volume, or into a surface."""

    name: str
    power_W: TimeSeries
    part: str | None = None
    section: str | None = None
    surface: str | None = None


@dataclass(frozen=True)
class Sensor:
    """A virtual sensor at (z, r) [m]. ``axial_displacement`` sensors also have a reference
    point (z_ref, r_ref) and read the axial displacement of (z, r) relative to it."""

    name: str
    kind: str
    z: float
    r: float
    z_ref: float | None = None
    r_ref: float | None = None
    array: str | None = None


@dataclass(frozen=True)
class SensorArray:
    """``count`` temperature sensors spaced evenly over the axial length of ``part``."""

    name: str
    part: str
    count: int
    radius: str | float


@dataclass(frozen=True)
class Spec:
    """A validated spindle description (SI units)."""

    name: str
    path: str
    description: str
    source: str
    speed_rpm: float
    T_ambient_K: float
    T_coolant_K: float
    T_initial_K: float
    h0_m: float
    materials: dict[str, Material]
    parts: tuple[Part, ...]
    links: tuple[Link, ...]
    surfaces: tuple[Surface, ...]
    heat_sources: tuple[HeatSource, ...]
    sensors: tuple[Sensor, ...]
    sensor_arrays: tuple[SensorArray, ...] = field(default_factory=tuple)
    power_preset: str | None = None  # [power_balance] preset: motor and bearing parameters

    def part(self, name: str) -> Part:
        return next(p for p in self.parts if p.name == name)

    def sections(self) -> Iterator[tuple[Part, Section]]:
        for p in self.parts:
            for s in p.sections:
                yield p, s

    def parts_with_role(self, role: str) -> list[Part]:
        return [p for p in self.parts if p.role == role]

    def mass_kg(self, part: str, section: str | None = None) -> float:
        return float(sum(self.materials[s.material].rho_kg_m3 * s.volume_m3
                         for s in self.part(part).sections
                         if section is None or s.name == section))

    def temperature_sensors(self) -> list[Sensor]:
        return [s for s in self.sensors if s.kind == "temperature"]

    def growth_points(self) -> dict[str, tuple[float, float, float, float]]:
        """Axial-growth readings (z, r, z_ref, r_ref) [m]: every displacement sensor and, when a
        tool is clamped, ``TCP`` (tool tip on the axis, or on its bore) against the first
        sensor's reference point (paper sec. 2.1: the TCP is at the tool tip)."""
        pts = {s.name: (s.z, s.r, s.z_ref, s.r_ref) for s in self.sensors
               if s.kind == "axial_displacement"}
        tools = self.parts_with_role("tool")
        if tools and pts:
            ref = next(iter(pts.values()))
            tip = max(tools[0].sections, key=lambda s: s.z_end)
            pts["TCP"] = (tip.z_end, 0.0 if tip.r_inner[1] == 0 else tip.r_inner[1],
                          ref[2], ref[3])
        return pts

    def default_load_case(self) -> LoadCase:
        """Constant inputs from the spec's [operating] table and heat sources."""
        return LoadCase(
            name="steady",
            speed_rpm=TimeSeries.constant(self.speed_rpm),
            T_ambient_K=TimeSeries.constant(self.T_ambient_K),
            T_coolant_K=TimeSeries.constant(self.T_coolant_K),
            sources={h.name: h.power_W for h in self.heat_sources},
        )


# --------------------------------------------------------------------------- reading


def _finite(v: Any) -> float | None:
    """``v`` as a finite float, or None (not a number, a bool, NaN, inf, or an integer too
    large for a float)."""
    if isinstance(v, bool) or not isinstance(v, int | float):
        return None
    try:
        f = float(v)
    except OverflowError:
        return None
    return f if math.isfinite(f) else None


def _show(v: Any) -> str:
    """A short text for a bad value in a message (no 400-digit integers)."""
    text = repr(v)
    return text if len(text) <= 40 else text[:37] + "..."


#: plausibility limits of a motor spindle's description, with the reason (docs/spec.md)
MAX_POWER_W = 1e6
#: film coefficients: forced water convection reaches 1e4-1e5 W/m2/K; 1e6 is boiling
MAX_FILM_W_M2K = 1e6
PLAUSIBLE_FILM = "air films are 5-500 W/m2/K, water jackets up to 1e5"
#: bearing conductances: a pair conducts 5-50 W/K (docs/spec.md)
MAX_G_W_K = 1e5
PLAUSIBLE_POWER = "a motor spindle's losses are watts to kilowatts (SPL2782: 5.1 kW in all)"


class _Reader:
    """Collects problems while reading nested TOML tables; never stops at the first."""

    def __init__(self, file: str):
        self.file = file
        self.problems: list[Problem] = []
        #: fields whose problems follow from one already reported (a misspelt or missing
        #: table): not reported again
        self.quiet: set[str] = set()
        #: names of parts, surfaces and materials that are defined but could not be read:
        #: a reference to one is not a second problem
        self.broken: dict[str, set[str]] = {"part": set(), "surface": set(), "material": set()}

    def add(self, fld: str, message: str, fix: str) -> None:
        if any(fld == q or fld.startswith(q + ".") or fld.startswith(q + "[")
               for q in self.quiet):
            return
        self.problems.append(Problem(self.file, fld, message, fix))

    def unknown(self, kind: str, name: str, fld: str, fix: str) -> None:
        """An unknown ``kind`` (part, surface, material) named ``name`` at ``fld``; nothing
        when that name is defined but broken (its own problem is the root cause)."""
        if name not in self.broken[kind]:
            self.add(fld, f"unknown {kind} '{name}'", fix)

    def keys(self, data: dict, known: tuple[str, ...], path: str) -> None:
        """Every key of ``data`` must be one of ``known``: an unknown one (a misspelling) is a
        problem with the nearest known name; the field it was meant for is then not reported
        missing as well."""
        import difflib

        for k in data:
            if k in known:
                continue
            near = difflib.get_close_matches(str(k), known, n=1, cutoff=0.6)
            where = f"{path}.{k}" if path else str(k)
            what = "table" if not path and isinstance(data[k], dict | list) else "field"
            if near:
                self.add(where, f"unknown {what} '{k}'", f"did you mean '{near[0]}'?")
                self.quiet.add(f"{path}.{near[0]}" if path else near[0])
            else:
                self.add(where, f"unknown {what} '{k}'",
                         f"use one of: {', '.join(known)} (docs/spec.md)")

    def table(self, data: dict, key: str, path: str, required: bool = True) -> dict | None:
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}{key}", "required table is missing", f"add a [{path}{key}] table")
                self.quiet.add(f"{path}{key}")  # its fields are not missing a second time
            return None
        if not isinstance(v, dict):
            self.add(f"{path}{key}", "must be a table", f"write it as [{path}{key}]")
            self.quiet.add(f"{path}{key}")
            return None
        return v

    def array(self, data: dict, key: str, path: str, required: bool = True) -> list[dict]:
        v = data.get(key)
        if v is None:
            if required:
                self.add(key, "required list is missing", f"add at least one [[{key}]] entry")
            return []
        if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
            self.add(f"{path}{key}", "must be a list of tables", f"write entries as [[{key}]]")
            return []
        return v

    def string(self, data: dict, key: str, path: str, required: bool = True,
               choices: tuple[str, ...] | None = None, default: str | None = None) -> str | None:
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}.{key}", "required field is missing", f"add {key} = \"...\"")
            return default
        if not isinstance(v, str) or not v:
            self.add(f"{path}.{key}", f"must be a text, not {v!r}", f"write {key} = \"...\"")
            return default
        if choices is not None and v not in choices:
            self.add(f"{path}.{key}", f"'{v}' is not one of {', '.join(choices)}",
                     f"use one of {', '.join(choices)}")
            return default
        return v

    def number(self, data: dict, key: str, path: str, unit: str, required: bool = True,
               default: float | None = None, lo: float | None = None, lo_open: bool = False,
               hi: float | None = None) -> float | None:
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}.{key}", "required field is missing",
                         f"add {key} = <number in {unit}>")
            return default
        v = _finite(v)
        if v is None:
            self.add(f"{path}.{key}", f"must be a finite number in {unit}, not "
                     f"{_show(data.get(key))}", f"write {key} = <number in {unit}>")
            return default
        if lo is not None and (v <= lo if lo_open else v < lo):
            rel = ">" if lo_open else ">="
            self.add(f"{path}.{key}", f"{v:g} {unit} is not physical (must be {rel} {lo:g})",
                     f"give {key} {rel} {lo:g} {unit}")
            return default
        if hi is not None and v > hi:
            self.add(f"{path}.{key}", f"{v:g} {unit} is out of range (must be <= {hi:g})",
                     f"give {key} <= {hi:g} {unit}")
            return default
        return v

    def radius(self, data: dict, key: str, path: str) -> tuple[float, float] | None:
        v = data.get(key)
        ends = [_finite(x) for x in v] if isinstance(v, list) and len(v) == 2 else [_finite(v)] * 2
        if None not in ends:
            pair = (ends[0], ends[1])
        elif v is None:
            self.add(f"{path}.{key}", "required field is missing",
                     f"add {key} = <radius in m> (or [start, end] for a cone)")
            return None
        else:
            self.add(f"{path}.{key}", f"must be a finite radius in m or [start, end], not "
                     f"{_show(v)}", f"write {key} = 0.04 or {key} = [0.04, 0.05]")
            return None
        if min(pair) < 0:
            self.add(f"{path}.{key}", "a radius cannot be negative", "give radii >= 0 m")
            return None
        return pair

    def speed_table(self, data: dict, key: str, path: str, unit: str,
                    required: bool = True) -> SpeedTable | None:
        """A constant, or {speed_rpm = [...], value = [...]} interpolated in speed."""
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}.{key}", "required field is missing",
                         f"add {key} = <number in {unit}>")
            return None
        if isinstance(v, dict) and "correlation" in v:
            return self.correlation(v, f"{path}.{key}")
        if isinstance(v, dict):
            n, vals = v.get("speed_rpm"), v.get("value")
            ok = (isinstance(n, list) and isinstance(vals, list) and len(n) == len(vals) >= 1
                  and all(_finite(x) is not None for x in [*n, *vals]))
            if not ok:
                self.add(f"{path}.{key}", "a speed table needs lists speed_rpm and value of "
                         "equal length", f"write {key} = {{speed_rpm = [0, 4300], value = [10, 60]}}")
                return None
            if any(b <= a for a, b in zip(n, n[1:], strict=False)):
                self.add(f"{path}.{key}.speed_rpm", "must increase", "sort the table by speed")
                return None
            if min(vals) < 0:
                self.add(f"{path}.{key}.value", f"negative {unit} is not physical",
                         "give values >= 0")
                return None
            return SpeedTable(tuple(float(x) for x in n), tuple(float(x) for x in vals))
        num = self.number(data, key, path, unit, lo=0.0)
        return None if num is None else SpeedTable.constant(num)

    def correlation(self, d: dict, path: str) -> SpeedTable | None:
        """A film coefficient from a cited correlation of spindle.power, tabulated in speed:
        ``rotating_shaft`` (d_m), ``air_gap`` (r_rotor_m, gap_m) or ``coolant_channel``
        (flow_l_min, width_m, height_m); ``factor`` (default 1) scales the result, e.g. for
        the wetted fraction of a channel modelled as an annulus."""
        from spindle import power

        name = d.get("correlation")
        needs = {"rotating_shaft": ("d_m",), "air_gap": ("r_rotor_m", "gap_m"),
                 "coolant_channel": ("flow_l_min", "width_m", "height_m")}
        if name not in needs:
            self.add(f"{path}.correlation", f"unknown correlation {name!r}",
                     f"use one of: {', '.join(needs)}")
            return None
        extra = set(d) - {"correlation", "factor", *needs[name]}
        if extra:
            self.add(f"{path}.{sorted(extra)[0]}", f"is not a parameter of '{name}'",
                     f"give only {', '.join(needs[name])} (and factor)")
            return None
        n0 = len(self.problems)
        args = [self.number(d, k, path, "SI", lo=0.0, lo_open=True) for k in needs[name]]
        factor = self.number(d, "factor", path, "-", required=False, default=1.0, lo=0.0,
                             lo_open=True)
        if len(self.problems) > n0:
            return None
        try:
            if name == "rotating_shaft":
                table = power.shaft_film_table(*args)
            elif name == "air_gap":
                table = power.air_gap_film_table(*args)
            else:
                table = SpeedTable.constant(power.h_coolant_channel_W_m2K(*args))
        except ValueError as exc:
            self.add(path, f"the correlation cannot be evaluated ({exc})",
                     "check the parameters against the correlation's range in docs/power.md")
            return None
        return SpeedTable(table.speed_rpm, tuple(factor * h for h in table.values))

    def power(self, data: dict, path: str) -> TimeSeries | None:
        """A constant power [W] or {time_s = [...], value = [...]} (linear in time)."""
        v = data.get("power_W")
        if isinstance(v, dict):
            t, vals = v.get("time_s"), v.get("value")
            ok = (isinstance(t, list) and isinstance(vals, list) and len(t) == len(vals) >= 1
                  and all(_finite(x) is not None for x in [*t, *vals]))
            if not ok or any(b <= a for a, b in zip(t or [], (t or [])[1:], strict=False)):
                self.add(f"{path}.power_W", "a power series needs increasing time_s and value "
                         "lists of equal length",
                         "write power_W = {time_s = [0, 3600], value = [40, 60]}")
                return None
            if min(vals) < 0 or max(vals) > MAX_POWER_W:
                self.add(f"{path}.power_W.value", f"values from {min(vals):g} to {max(vals):g} W "
                         f"are not plausible: {PLAUSIBLE_POWER}", "give values from 0 to "
                         f"{MAX_POWER_W:g} W")
                return None
            return TimeSeries(tuple(map(float, t)), tuple(map(float, vals)))
        num = self.number(data, "power_W", path, "W", lo=0.0, hi=MAX_POWER_W)
        return None if num is None else TimeSeries.constant(num)


def _read_material(r: _Reader, name: str, d: dict, path: str) -> Material | None:
    # upper limits: beyond every engineering solid (diamond conducts 2200 W/m/K, osmium is
    # 22600 kg/m3, E of diamond 1.2e12 Pa, thermal expansion of polymers 2e-4 1/K); k up to
    # 1e6 W/m/K for the near-ideal conductors of verification cases
    n0 = len(r.problems)
    r.keys(d, KNOWN_FIELDS["materials"], path)
    if "k_W_mK" in d and ("k_r_W_mK" in d or "k_z_W_mK" in d):
        r.add(f"{path}.k_W_mK", "is given together with k_r_W_mK / k_z_W_mK",
              "give either k_W_mK (isotropic) or both k_r_W_mK and k_z_W_mK")
        kr = kz = None
    elif "k_W_mK" in d:
        kr = kz = r.number(d, "k_W_mK", path, "W/m/K", lo=0.0, lo_open=True, hi=1e6)
    else:
        kr = r.number(d, "k_r_W_mK", path, "W/m/K", lo=0.0, lo_open=True, hi=1e6)
        kz = r.number(d, "k_z_W_mK", path, "W/m/K", lo=0.0, lo_open=True, hi=1e6)
    rho = r.number(d, "rho_kg_m3", path, "kg/m3", lo=0.0, lo_open=True, hi=30000.0)
    c = r.number(d, "c_J_kgK", path, "J/kg/K", lo=0.0, lo_open=True, hi=20000.0)
    E = r.number(d, "E_Pa", path, "Pa", lo=0.0, lo_open=True, hi=2e12)
    nu = r.number(d, "nu", path, "-", lo=-1.0, lo_open=True, hi=0.4999)
    alpha = r.number(d, "alpha_1_K", path, "1/K", lo=0.0, hi=1e-3)
    if len(r.problems) > n0:
        return None
    return Material(name, kr, kz, rho, c, E, nu, alpha, str(d.get("source", "")))


def shipped_materials() -> dict[str, Material]:
    """The shipped material table (spindle/data/materials.toml), each with its source."""
    text = resources.files("spindle").joinpath("data/materials.toml").read_text("utf-8")
    r = _Reader("spindle/data/materials.toml")
    out = {}
    for name, d in tomllib.loads(text).items():
        m = _read_material(r, name, d, f"{name}")
        if m is not None:
            out[name] = m
    if r.problems:  # a broken shipped table is a bug, but say where
        raise SpecError(r.problems)
    return out


def shipped_specs() -> dict[str, Path]:
    """Shipped specs by name (``spindle-verify specs`` lists them)."""
    root = resources.files("spindle").joinpath("data/specs")
    return {Path(str(p)).stem: Path(str(p)) for p in root.iterdir() if str(p).endswith(".toml")}


def shipped_drives() -> dict[str, Path]:
    """Shipped drive files (spindle/data/drives/*.toml) by name (the file stem)."""
    root = resources.files("spindle").joinpath("data/drives")
    return {Path(str(p)).stem: Path(str(p)) for p in sorted(root.iterdir(), key=str)
            if str(p).endswith(".toml")}


def drive_file_path(spec_file: str | Path, preset: str) -> Path | None:
    """The drive file a ``[power_balance] preset`` names: a shipped drive's, else a path
    relative to the spec's folder (an absolute one as it is); None if there is no such
    file."""
    shipped = shipped_drives()
    if preset in shipped:
        return shipped[preset]
    path = Path(spec_file).parent / Path(preset).expanduser()
    return path if path.is_file() else None


def resolve_spec_path(name_or_path: str | Path) -> Path:
    """A path to a TOML file, or the name of a shipped spec."""
    p = Path(name_or_path)
    if p.is_file():
        return p
    shipped = shipped_specs()
    if str(name_or_path) in shipped:
        return shipped[str(name_or_path)]
    raise SpecError([Problem(str(name_or_path), "file", "is neither a file nor a shipped spec",
                             f"give a path to a .toml spec or one of: {', '.join(sorted(shipped))}")])


def read_toml(path: Path) -> dict:
    """A TOML file's tables; a syntax error or an unreadable file raises SpecError naming the
    file and the fix (every TOML input of the project reads through here)."""
    file = str(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a BOM is accepted
    except tomllib.TOMLDecodeError as exc:
        raise SpecError([Problem(file, "syntax", str(exc), "fix the TOML syntax at that line")]) \
            from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError([Problem(file, "file", f"cannot be read ({exc})",
                                 "check the path and that the file is UTF-8 text")]) from None


def load_spec(name_or_path: str | Path) -> Spec:
    """Read and validate a spec (a file path or a shipped name). Raises SpecError."""
    path = resolve_spec_path(name_or_path)
    return _build(_Reader(str(path)), read_toml(path))


def as_spec(spec: Spec | str | Path) -> Spec:
    """``spec`` itself, or the spec a shipped name or a file path names (:func:`load_spec`):
    what every public constructor that takes a spec accepts, as the command line does."""
    if isinstance(spec, Spec):
        return spec
    if isinstance(spec, str | Path):
        return load_spec(spec)
    raise TypeError(f"a spec is a Spec, a shipped name or a path, not {type(spec).__name__}")


def _build(r: _Reader, data: dict[str, Any]) -> Spec:
    """Read the tables one after the other (the problems are listed in that order), then,
    if none was found, check the geometry; raises SpecError with every problem."""
    r.keys(data, KNOWN_FIELDS[""], "")
    for t in ("spindle", "operating", "power_balance", "mesh"):
        if isinstance(data.get(t), dict):
            r.keys(data[t], KNOWN_FIELDS[t], t)
    head = r.table(data, "spindle", "") or {}
    name = r.string(head, "name", "spindle") or "?"
    speed, T_amb, T_cool, T_init = _read_operating(r, data)
    mesh = r.table(data, "mesh", "", required=False) or {}
    h0 = r.number(mesh, "h0_m", "mesh", "m", required=False, default=0.01, lo=0.0, lo_open=True)
    materials = _read_materials(r, data)
    parts = _read_parts(r, data, materials)
    links = _read_links(r, data, parts)
    surfaces = _read_surfaces(r, data, parts)
    sources = _read_heat_sources(r, data, parts, surfaces)
    sensors, arrays = _read_sensors(r, data, parts)
    pb = r.table(data, "power_balance", "", required=False) or {}
    preset = r.string(pb, "preset", "power_balance", required=False)
    if preset is not None and drive_file_path(r.file, preset) is None:
        r.add("power_balance.preset", f"'{preset}' is neither a shipped drive nor a drive "
              f"file (no file {Path(r.file).parent / preset})",
              f"use one of: {', '.join(sorted(shipped_drives()))}, or the path of a drive "
              "TOML relative to the spec's folder (format: docs/power.md)")

    if not r.problems:
        _check_size(r, parts, h0)
    if not r.problems:
        _check_geometry(r, parts, links, surfaces, sensors)
    if r.problems:
        raise SpecError(r.problems)
    return Spec(
        name=name, path=r.file, description=str(head.get("description", "")),
        source=str(head.get("source", "")), speed_rpm=speed, T_ambient_K=T_amb,
        T_coolant_K=T_cool, T_initial_K=T_init, h0_m=h0,
        materials={m: materials[m] for m in {s.material for p in parts for s in p.sections}},
        parts=tuple(parts), links=tuple(links), surfaces=tuple(surfaces),
        heat_sources=tuple(sources), sensors=tuple(sensors), sensor_arrays=tuple(arrays),
        power_preset=preset)


def _read_operating(r: _Reader, data: dict[str, Any]) -> tuple[float, float, float, float]:
    """[operating]: speed [rpm] and the ambient, coolant and initial temperatures [K]
    (coolant and initial default to the ambient)."""
    op = r.table(data, "operating", "") or {}
    speed = r.number(op, "speed_rpm", "operating", "rpm", required=False, default=0.0, lo=0.0, hi=1e5)
    T_amb = r.number(op, "T_ambient_K", "operating", "K", lo=150.0, hi=500.0)
    T_cool = r.number(op, "T_coolant_K", "operating", "K", required=False, default=T_amb, lo=150.0, hi=500.0)
    T_init = r.number(op, "T_initial_K", "operating", "K", required=False, default=T_amb, lo=150.0, hi=500.0)
    return speed, T_amb, T_cool, T_init


def _read_materials(r: _Reader, data: dict[str, Any]) -> dict[str, Material]:
    """The shipped materials, overridden and extended by the spec's [materials] tables."""
    materials = dict(shipped_materials())
    for mname, md in (r.table(data, "materials", "", required=False) or {}).items():
        if not isinstance(md, dict):
            r.add(f"materials.{mname}", "must be a table", f"write it as [materials.{mname}]")
            continue
        m = _read_material(r, mname, md, f"materials.{mname}")
        if m is not None:
            materials[mname] = m
        else:
            r.broken["material"].add(mname)
            materials.pop(mname, None)
    return materials


def _read_parts(r: _Reader, data: dict[str, Any], materials: dict[str, Material]) -> list[Part]:
    """[[parts]] with their sections; a part with a problem is left out."""
    parts: list[Part] = []
    for i, pd in enumerate(r.array(data, "parts", "")):
        path = f"parts[{i}]"
        n0 = len(r.problems)
        r.keys(pd, KNOWN_FIELDS["parts"], path)
        pname = r.string(pd, "name", path)
        role = r.string(pd, "role", path, choices=ROLES)
        pmat = pd.get("material")
        if pname is not None and any(p.name == pname for p in parts):
            r.add(f"{path}.name", f"part '{pname}' is defined twice", "give each part its own name")
        secs = pd.get("sections")
        if not isinstance(secs, list) or not secs or not all(isinstance(s, dict) for s in secs):
            r.add(f"{path}.sections", "required list of sections is missing or empty",
                  "add sections = [{z_start = 0.0, z_end = 0.1, r_inner = 0.0, r_outer = 0.04}]")
            secs = []
        sections = []
        for j, sd in enumerate(secs):
            sec = _read_section(r, sd, f"{path}.sections[{j}]", path, pmat, materials)
            if sec is not None:
                sections.append(sec)
        if len(sections) == len(secs):
            _check_sections_join(r, sections, path)
        ok = pname is not None and role is not None and bool(sections)
        if ok:
            parts.append(Part(pname, role, tuple(sections)))
        if pname is not None and (not ok or len(r.problems) > n0 or len(sections) < len(secs)):
            r.broken["part"].add(pname)
    return parts


def _check_sections_join(r: _Reader, sections: list[Section], path: str) -> None:
    """A part is one body: its sections, in z order, must meet without a gap."""
    order = sorted(range(len(sections)), key=lambda j: sections[j].z_start)
    for a, b in zip(order, order[1:], strict=False):
        gap = sections[b].z_start - sections[a].z_end
        if gap > TOL_M:
            r.add(f"{path}.sections[{b}].z_start",
                  f"a {gap * 1e3:.3g} mm gap after sections[{a}] (z = {sections[a].z_end:g} to "
                  f"{sections[b].z_start:g} m): a part is one body",
                  f"give z_start = {sections[a].z_end:g} (or make the piece beyond the gap a "
                  "part of its own, joined by a link)")


def _read_section(r: _Reader, sd: dict, sp: str, path: str, pmat: Any,
                  materials: dict[str, Material]) -> Section | None:
    """One section ``sp`` of part ``path``; its material defaults to the part's ``pmat``."""
    r.keys(sd, KNOWN_FIELDS["sections"], sp)
    z0 = r.number(sd, "z_start", sp, "m")
    z1 = r.number(sd, "z_end", sp, "m")
    ri = r.radius(sd, "r_inner", sp)
    ro = r.radius(sd, "r_outer", sp)
    mat = sd.get("material", pmat)
    if mat is None:
        r.add(f"{sp}.material", "no material for this section or its part",
              f"add material = \"...\" to {path} (one of: {', '.join(sorted(materials))})")
    elif not isinstance(mat, str):
        r.add(f"{sp}.material" if "material" in sd else f"{path}.material",
              f"must be a material name, not {_show(mat)}", "write material = \"steel\"")
        mat = None
    elif mat not in materials:
        r.unknown("material", mat, f"{sp}.material" if "material" in sd else f"{path}.material",
                  f"use one of: {', '.join(sorted(materials))}, or define [materials.{mat}]")
        mat = None
    if None in (z0, z1, ri, ro, mat):
        return None
    if z1 - z0 <= TOL_M:
        r.add(f"{sp}.z_end", f"z_end = {z1:g} m is not after z_start = {z0:g} m",
              "give z_end > z_start (z grows from the rear towards the tool)")
        return None
    if ri[0] >= ro[0] - TOL_M or ri[1] >= ro[1] - TOL_M:
        r.add(f"{sp}.r_inner", f"r_inner {list(ri)} m is not below r_outer {list(ro)} m",
              "give r_inner < r_outer at both ends (r_inner = 0 for a solid section)")
        return None
    return Section(z0, z1, ri, ro, material=mat, name=str(sd.get("name", "")))


def _read_links(r: _Reader, data: dict[str, Any], parts: list[Part]) -> list[Link]:
    """[[links]]: bearing, air_gap and contact; a link with a problem is left out."""
    readers = {"bearing": _read_bearing_link, "air_gap": _read_air_gap_link,
               "contact": _read_contact_link}
    links: list[Link] = []
    for i, ld in enumerate(r.array(data, "links", "", required=False)):
        path = f"links[{i}]"
        kind = r.string(ld, "type", path, choices=LINK_TYPES)
        if kind is not None:
            r.keys(ld, KNOWN_FIELDS[f"links.{kind}"], path)
        link = readers[kind](r, ld, path, parts) if kind is not None else None
        if link is not None:
            links.append(link)
    return links


def _read_bearing_link(r: _Reader, ld: dict, path: str, parts: list[Part]) -> BearingLink | None:
    part_names = {p.name for p in parts}
    pn = r.string(ld, "part", path)
    sn = r.string(ld, "section", path)
    G = r.speed_table(ld, "G_W_K", path, "W/K")
    if pn is not None and pn not in part_names:
        r.unknown("part", pn, f"{path}.part", f"use one of: {sorted(part_names)}")
    elif G is not None and G.max > MAX_G_W_K:
        r.add(f"{path}.G_W_K", f"{G.max:g} W/K is not a bearing's conductance (typ. 5-50 W/K "
              f"per pair; above {MAX_G_W_K:g} W/K it would weld the rings)",
              f"give G_W_K <= {MAX_G_W_K:g} W/K")
    elif pn is not None and sn is not None and not any(
            s.name == sn for s in next(p for p in parts if p.name == pn).sections):
        r.add(f"{path}.section", f"part '{pn}' has no section named '{sn}'",
              f"add name = \"{sn}\" to the rolling-element section of part '{pn}'")
    elif G is not None and G.min <= 0:
        r.add(f"{path}.G_W_K", "a bearing conductance must be > 0 W/K",
              "give G_W_K > 0 (typ. 5-50 W/K per bearing pair)")
    elif None not in (pn, sn, G):
        return BearingLink(pn, sn, G)
    return None


def _read_air_gap_link(r: _Reader, ld: dict, path: str, parts: list[Part]) -> AirGapLink | None:
    part_names = {p.name for p in parts}
    a = r.string(ld, "inner", path)
    b = r.string(ld, "outer", path)
    h = r.speed_table(ld, "h_W_m2K", path, "W/m2/K")
    for key, v in (("inner", a), ("outer", b)):
        if v is not None and v not in part_names:
            r.unknown("part", v, f"{path}.{key}", f"use one of: {sorted(part_names)}")
    if h is not None and h.min <= 0:
        r.add(f"{path}.h_W_m2K", "an air-gap coefficient must be > 0 W/m2/K",
              "give h_W_m2K > 0")
    elif h is not None and h.max > MAX_FILM_W_M2K:
        r.add(f"{path}.h_W_m2K", f"{h.max:g} W/m2/K is not an air gap's film ({PLAUSIBLE_FILM})",
              f"give h_W_m2K <= {MAX_FILM_W_M2K:g}")
    elif a in part_names and b in part_names and h is not None:
        return AirGapLink(a, b, h)
    return None


def _read_contact_link(r: _Reader, ld: dict, path: str, parts: list[Part]) -> ContactLink | None:
    part_names = {p.name for p in parts}
    pl = ld.get("parts")
    # a contact conducts 1e3-1e5 W/m2/K (pressed steel joints); 1e8 is a perfect bond
    h = r.number(ld, "h_W_m2K", path, "W/m2/K", lo=0.0, lo_open=True, hi=1e8)
    if not (isinstance(pl, list) and len(pl) == 2 and all(isinstance(x, str) for x in pl)):
        r.add(f"{path}.parts", "must name two parts", "write parts = [\"shaft\", \"rotor\"]")
    elif any(x not in part_names for x in pl):
        bad = next(x for x in pl if x not in part_names)
        r.unknown("part", bad, f"{path}.parts", f"use one of: {sorted(part_names)}")
    elif h is not None:
        return ContactLink((pl[0], pl[1]), h)
    return None


def _read_surfaces(r: _Reader, data: dict[str, Any], parts: list[Part]) -> list[Surface]:
    """[[surfaces]]; a surface with a problem is left out."""
    part_names = {p.name for p in parts}
    surfaces: list[Surface] = []
    for i, sd in enumerate(r.array(data, "surfaces", "", required=False)):
        path = f"surfaces[{i}]"
        n0 = len(r.problems)
        r.keys(sd, KNOWN_FIELDS["surfaces"], path)
        sname = r.string(sd, "name", path)
        pl = sd.get("parts", sd.get("part"))
        pl = [pl] if isinstance(pl, str) else pl
        if not (isinstance(pl, list) and pl and all(isinstance(x, str) for x in pl)):
            r.add(f"{path}.parts", "must name one or more parts", "write parts = [\"housing\"]")
            pl = []
        for x in pl:
            if x not in part_names:
                r.unknown("part", x, f"{path}.parts", f"use one of: {sorted(part_names)}")
        side = r.string(sd, "side", path, required=False, choices=SIDES, default="any")
        zmin = r.number(sd, "z_min", path, "m", required=False, default=-np.inf)
        zmax = r.number(sd, "z_max", path, "m", required=False, default=np.inf)
        h = r.speed_table(sd, "h_W_m2K", path, "W/m2/K", required=False)
        if h is not None and h.max > MAX_FILM_W_M2K:
            r.add(f"{path}.h_W_m2K", f"{h.max:g} W/m2/K is not a film coefficient "
                  f"({PLAUSIBLE_FILM})", f"give h_W_m2K <= {MAX_FILM_W_M2K:g}")
        tref = r.string(sd, "T_ref", path, required=h is not None, choices=T_REFS)
        if sname is not None and any(s.name == sname for s in surfaces):
            r.add(f"{path}.name", f"surface '{sname}' is defined twice", "give each its own name")
        elif sname is not None and all(x in part_names for x in pl) and pl \
                and len(r.problems) == n0:
            surfaces.append(Surface(sname, tuple(pl), side, zmin, zmax, h, tref))
        elif sname is not None:
            r.broken["surface"].add(sname)
    return surfaces


def _read_heat_sources(r: _Reader, data: dict[str, Any], parts: list[Part],
                       surfaces: list[Surface]) -> list[HeatSource]:
    """[[heat_sources]]; a source with a problem is left out."""
    sources: list[HeatSource] = []
    for i, hd in enumerate(r.array(data, "heat_sources", "", required=False)):
        src = _read_heat_source(r, hd, f"heat_sources[{i}]", parts, surfaces, sources)
        if src is not None:
            sources.append(src)
    return sources


def _read_heat_source(r: _Reader, hd: dict, path: str, parts: list[Part],
                      surfaces: list[Surface], earlier: list[HeatSource]) -> HeatSource | None:
    part_names = {p.name for p in parts}
    surface_names = {s.name for s in surfaces}
    r.keys(hd, KNOWN_FIELDS["heat_sources"], path)
    hname = r.string(hd, "name", path)
    pw = r.power(hd, path)
    pn, sn, surf = hd.get("part"), hd.get("section"), hd.get("surface")
    if (pn is None) == (surf is None):
        r.add(path, "a heat source goes into either a part or a surface",
              "give exactly one of part = \"...\" or surface = \"...\"")
        return None
    if pn is not None and pn not in part_names:
        r.unknown("part", str(pn), f"{path}.part", f"use one of: {sorted(part_names)}")
        return None
    if sn is not None and not any(s.name == sn for s in
                                  next(p for p in parts if p.name == pn).sections):
        r.add(f"{path}.section", f"part '{pn}' has no section named '{sn}'",
              f"name one of its sections '{sn}' or drop the section field")
        return None
    if surf is not None and surf not in surface_names:
        r.unknown("surface", str(surf), f"{path}.surface",
                  f"define it under [[surfaces]] (known: {sorted(surface_names)})")
        return None
    if hname is not None and any(h.name == hname for h in earlier):
        r.add(f"{path}.name", f"heat source '{hname}' is defined twice",
              "give each its own name")
        return None
    if hname is not None and pw is not None:
        return HeatSource(hname, pw, pn, sn, surf)
    return None


def _read_sensors(r: _Reader, data: dict[str, Any],
                  parts: list[Part]) -> tuple[list[Sensor], list[SensorArray]]:
    """[[sensors]], then [[sensor_arrays]] (whose sensors follow); every name once."""
    sensors: list[Sensor] = []
    for i, sd in enumerate(r.array(data, "sensors", "", required=False)):
        s = _read_sensor(r, sd, f"sensors[{i}]")
        if s is not None:
            sensors.append(s)
    arrays: list[SensorArray] = []
    for i, ad in enumerate(r.array(data, "sensor_arrays", "", required=False)):
        arr = _read_sensor_array(r, ad, f"sensor_arrays[{i}]", parts)
        if arr is not None:
            arrays.append(arr)
            # a part with a problem of its own (a section left out) may not span its length:
            # its sensors wait for that problem's fix, which is reported already
            if arr.part not in r.broken["part"]:
                sensors.extend(array_sensors(arr, next(p for p in parts if p.name == arr.part)))
    seen: set[str] = set()
    for s in sensors:
        if s.name in seen:
            r.add(f"sensors.{s.name}", "sensor name is used twice", "give each sensor its own name")
        seen.add(s.name)
    return sensors, arrays


def _read_sensor(r: _Reader, sd: dict, path: str) -> Sensor | None:
    r.keys(sd, KNOWN_FIELDS["sensors"], path)
    sname = r.string(sd, "name", path)
    kind = r.string(sd, "kind", path, required=False, default="temperature",
                    choices=("temperature", "axial_displacement"))
    z = r.number(sd, "z", path, "m")
    rr = r.number(sd, "r", path, "m", lo=0.0)
    zr = rr_ref = None
    if kind == "axial_displacement":
        zr = r.number(sd, "z_ref", path, "m")
        rr_ref = r.number(sd, "r_ref", path, "m", lo=0.0)
    if None in (sname, z, rr) or (kind == "axial_displacement" and None in (zr, rr_ref)):
        return None
    return Sensor(sname, kind, z, rr, zr, rr_ref)


def _read_sensor_array(r: _Reader, ad: dict, path: str, parts: list[Part]) -> SensorArray | None:
    part_names = {p.name for p in parts}
    r.keys(ad, KNOWN_FIELDS["sensor_arrays"], path)
    aname = r.string(ad, "name", path)
    pn = r.string(ad, "part", path)
    cnt = ad.get("count", 11)
    rad = ad.get("radius", "mid")
    if not isinstance(cnt, int) or isinstance(cnt, bool) or not 2 <= cnt <= 1000:
        r.add(f"{path}.count", f"must be an integer from 2 to 1000, not {_show(cnt)}",
              "write count = 11")
        return None
    if not (rad in ("mid", "inner", "outer") or (isinstance(rad, int | float)
                                                  and not isinstance(rad, bool))):
        r.add(f"{path}.radius", f"{rad!r} is not a radius", "write \"mid\", \"inner\", "
              "\"outer\" or a radius in m")
        return None
    if pn is not None and pn not in part_names:
        r.unknown("part", pn, f"{path}.part", f"use one of: {sorted(part_names)}")
        return None
    if isinstance(rad, int | float) and _finite(rad) is None:
        r.add(f"{path}.radius", f"{_show(rad)} is not a radius", "write a finite radius in m")
        return None
    if aname is not None and pn is not None:
        return SensorArray(aname, pn, cnt, rad)
    return None


def array_sensors(arr: SensorArray, part: Part) -> list[Sensor]:
    z0 = min(s.z_start for s in part.sections)
    z1 = max(s.z_end for s in part.sections)
    out = []
    for i, z in enumerate(np.linspace(z0, z1, arr.count)):
        # a point strictly inside a section takes that section; at a joint or an end, the
        # first section that reaches it
        sec = next((s for s in part.sections if s.z_start < z < s.z_end),
                   next(s for s in part.sections if s.z_start - TOL_M <= z <= s.z_end + TOL_M))
        zc = min(max(z, sec.z_start), sec.z_end)
        ri, ro = float(sec.r_in(zc)), float(sec.r_out(zc))
        rad = {"mid": 0.5 * (ri + ro), "inner": ri, "outer": ro}.get(arr.radius, arr.radius)
        out.append(Sensor(f"{arr.name}_{i:02d}", "temperature", float(z), float(rad),
                          array=arr.name))
    return out


def _check_size(r: _Reader, parts: list[Part], h0_m: float) -> None:
    """A spec in millimetres, and a mesh too fine to build, before any work is done."""
    secs = [s for p in parts for s in p.sections]
    size = max(max(abs(s.z_start), abs(s.z_end), *s.r_outer) for s in secs)
    if size > MAX_SIZE_M:
        unit = "millimetres" if size < MAX_SIZE_M * 1000 else "no plausible unit"
        r.add("parts", f"the geometry reaches {size:g} m from the origin, more than a motor "
              f"spindle's {MAX_SIZE_M:g} m: the dimensions look like {unit}",
              "give every length in metres (z, r and mesh.h0_m: divide millimetres by 1000)")
        return
    if h0_m > size:
        r.add("mesh.h0_m", f"{h0_m:g} m is larger than the whole spindle ({size:g} m)",
              "give an element size of millimetres to centimetres (spl2782 uses 0.01 m)")
        return
    area = sum(0.5 * (s.z_end - s.z_start) * ((s.r_outer[0] - s.r_inner[0])
                                              + (s.r_outer[1] - s.r_inner[1])) for s in secs)
    n0 = (area / h0_m) / h0_m if area > 0 else 0.0  # h0_m >= 1e-300: no overflow to inf
    if n0 > MAX_LEVEL0_ELEMENTS:
        h_min = math.sqrt(area / MAX_LEVEL0_ELEMENTS)
        r.add("mesh.h0_m", f"{h0_m:g} m meshes the {area * 1e4:.3g} cm2 section into about "
              f"{n0:.3g} elements at level 0 (limit {MAX_LEVEL0_ELEMENTS:g}; each level "
              "multiplies by 4)", f"give h0_m >= {h_min:.2g} m (spl2782 uses 0.01 m)")


def _check_geometry(r: _Reader, parts: list[Part], links: list[Link],
                    surfaces: list[Surface], sensors: list[Sensor]) -> None:
    """Overlaps, gaps where a link is required, sensors outside, and heat paths."""
    secs = [(p, j, s) for p in parts for j, s in enumerate(p.sections)]
    touching = _check_overlaps(r, parts, secs)
    if r.problems:
        return
    joined = _check_links(r, parts, links, touching)
    _check_parts_joined(r, parts, links, touching, joined)
    _check_sensors_inside(r, sensors, secs)
    if r.problems:
        return
    _check_heat_paths(r, parts, surfaces, joined)


def _check_overlaps(r: _Reader, parts: list[Part],
                    secs: list[tuple[Part, int, Section]]) -> dict[str, set[str]]:
    """Sections must not overlap; returns the parts each part touches."""
    touching: dict[str, set[str]] = {p.name: set() for p in parts}
    for a in range(len(secs)):
        pa, ja, sa = secs[a]
        for b in range(a + 1, len(secs)):
            pb, jb, sb = secs[b]
            if overlap(sa, sb):
                r.add(f"parts[{parts.index(pb)}].sections[{jb}]",
                      f"part '{pb.name}' overlaps part '{pa.name}' (section {ja}) "
                      f"near z = {max(sa.z_start, sb.z_start):.4g} m",
                      "change the radii or z limits so the sections only touch")
            elif pa.name != pb.name and contact_length(sa, sb) > 0:
                touching[pa.name].add(pb.name)
                touching[pb.name].add(pa.name)
    return touching


def _check_links(r: _Reader, parts: list[Part], links: list[Link],
                 touching: dict[str, set[str]]) -> dict[str, set[str]]:
    """An air gap must be a real, narrow gap; a contact link needs touching parts. Returns
    the parts each part exchanges heat with (touching or across an air gap)."""
    joined = {k: set(v) for k, v in touching.items()}
    for i, link in enumerate(links):
        if isinstance(link, AirGapLink):
            gaps = _air_gap_widths(parts, link)
            if not gaps:
                r.add(f"links[{i}]", f"'{link.inner}' and '{link.outer}' do not face each "
                      "other over any axial length", "make their z ranges overlap")
            elif min(gaps) <= TOL_M or max(gaps) > MAX_AIR_GAP_M:
                r.add(f"links[{i}]", f"the gap between '{link.inner}' and '{link.outer}' is "
                      f"{min(gaps) * 1e3:.3g}..{max(gaps) * 1e3:.3g} mm",
                      f"give the outer part's r_inner above the inner part's r_outer by "
                      f"0 < gap <= {MAX_AIR_GAP_M * 1e3:g} mm")
            else:
                joined[link.inner].add(link.outer)
                joined[link.outer].add(link.inner)
        elif isinstance(link, ContactLink):
            a, b = link.parts
            if b not in touching[a]:
                r.add(f"links[{i}].parts", f"'{a}' and '{b}' do not touch",
                      "a contact link needs parts that share a boundary: fix the radii")
    return joined


def _air_gap_widths(parts: list[Part], link: AirGapLink) -> list[float]:
    """Radial gap [m] at both ends of every z range where the inner and outer part face."""
    return [float(so.r_in(z) - si.r_out(z))
            for si in next(p for p in parts if p.name == link.inner).sections
            for so in next(p for p in parts if p.name == link.outer).sections
            for z in (max(si.z_start, so.z_start), min(si.z_end, so.z_end))
            if min(si.z_end, so.z_end) - max(si.z_start, so.z_start) > TOL_M]


def _check_parts_joined(r: _Reader, parts: list[Part], links: list[Link],
                        touching: dict[str, set[str]], joined: dict[str, set[str]]) -> None:
    """No part stands alone, bearings sit between shaft and housing, and a rotor and a
    stator have an air-gap link."""
    roles = {p.name: p.role for p in parts}
    for p in parts:
        if len(parts) > 1 and not joined[p.name]:
            r.add(f"parts[{parts.index(p)}]", f"part '{p.name}' is separated from every other "
                  "part by a gap", "close the gap in its sections or add a [[links]] entry "
                  "(air_gap) that bridges it")
        if p.role in BEARING_ROLES:
            others = {roles[q] for q in touching[p.name]}
            if not others & {"shaft", "rotor"} or not others & {"housing", "cooling_sleeve"}:
                r.add(f"parts[{parts.index(p)}]", f"bearing '{p.name}' must touch the shaft "
                      "(inner ring) and the housing (outer ring)",
                      "set its r_inner to the shaft seat radius and r_outer to the housing bore")
    has_rotor = [p.name for p in parts if p.role == "rotor"]
    has_stator = [p.name for p in parts if p.role == "stator"]
    if has_rotor and has_stator and not any(isinstance(x, AirGapLink) for x in links):
        r.add("links", f"rotor '{has_rotor[0]}' and stator '{has_stator[0]}' have no air-gap "
              "link", "add [[links]] type = \"air_gap\" with inner/outer and h_W_m2K")


def _check_sensors_inside(r: _Reader, sensors: list[Sensor],
                          secs: list[tuple[Part, int, Section]]) -> None:
    for s in sensors:
        pts = [(s.z, s.r)] + ([(s.z_ref, s.r_ref)] if s.kind == "axial_displacement" else [])
        for z, rr in pts:
            if not any(sec.contains(z, rr) for _, _, sec in secs):
                r.add(f"sensors.{s.name}", f"point (z = {z:g} m, r = {rr:g} m) is outside every "
                      "part", "move it into a part's section (z along the axis, r radius)")


def _check_heat_paths(r: _Reader, parts: list[Part], surfaces: list[Surface],
                      joined: dict[str, set[str]]) -> None:
    """Every group of joined parts needs a path to a fixed temperature."""
    anchored = {x for s in surfaces if s.h_W_m2K is not None and s.h_W_m2K.max > 0
                for x in s.parts}
    seen: set[str] = set()
    for p in parts:
        if p.name in seen:
            continue
        group, stack = set(), [p.name]
        while stack:
            q = stack.pop()
            if q not in group:
                group.add(q)
                stack.extend(joined[q] - group)
        seen |= group
        if not group & anchored:
            r.add("surfaces", f"parts {sorted(group)} have no heat path to a fixed temperature "
                  "(the problem would be singular)", "add a [[surfaces]] entry with h_W_m2K > 0 "
                  "and T_ref = \"ambient\" or \"coolant\" on one of them")


def stretch_axially(spec: Spec, factor: float) -> Spec:
    """The spec stretched along the axis by ``factor`` (every z: sections, surface limits,
    sensors); radii, materials, links, powers and the mesh size h0 stay."""
    def z(v: float) -> float:
        return v * factor if math.isfinite(v) else v

    parts = tuple(replace(p, sections=tuple(replace(s, z_start=z(s.z_start), z_end=z(s.z_end))
                                            for s in p.sections)) for p in spec.parts)
    surfaces = tuple(replace(s, z_min=z(s.z_min), z_max=z(s.z_max)) for s in spec.surfaces)
    sensors = tuple(replace(s, z=z(s.z), z_ref=None if s.z_ref is None else z(s.z_ref))
                    for s in spec.sensors)
    return replace(spec, parts=parts, surfaces=surfaces, sensors=sensors)
