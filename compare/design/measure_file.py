"""The measures file (TOML, docs/measures.md): measures, inverse targets and sensitivity sweeps
for one spec, read with one message per problem naming the file, the field and the fix."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from compare.design.measure import KINDS, SIZE_FIELDS, SWEEPS, Measure, axial_length_m
from compare.design.stiffness import surface_films
from spindle.errors import Problem, SpindleVerifyError
from spindle.spec import Spec
from spindle.spec_fields import MAX_POWER_W


class MeasureFileError(SpindleVerifyError):
    """Problems in a measures file; each names the file, the field and the fix."""

    def __init__(self, problems: list[Problem]):
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


@dataclass(frozen=True)
class InverseTarget:
    """Find the smallest ``vary`` (A_M_m2 or alpha_M2_W_m2K) of measure ``measure`` that
    reaches ``xi_pct`` (reduction of the mean excess temperature, eq. 32) or ``growth_um``
    (the axial growth, TCP or P1, at most this) on the reference; search up to ``size_max``."""

    name: str
    measure: str
    vary: str
    xi_pct: float | None = None
    growth_um: float | None = None
    size_max: float | None = None


@dataclass(frozen=True)
class SweepSpec:
    """One Fig. 16-style sensitivity: heat stiffness against ``kind`` at ``values``.

    area: added area A_M [m2] with ``alpha_M_W_m2K`` on ``surfaces``; film: coefficient
    alpha [W/m2/K] of ``surfaces``; heat: power [W] of heat source ``source`` (the others
    as in the case); length: axial length [m] of the whole spindle (stretched along z).
    """

    kind: str
    values: tuple[float, ...]
    surfaces: tuple[str, ...] = ()
    alpha_M_W_m2K: float | None = None
    source: str | None = None


@dataclass(frozen=True)
class MeasureFile:
    path: str
    measures: tuple[Measure, ...]
    inverse: tuple[InverseTarget, ...] = ()
    sweeps: tuple[SweepSpec, ...] | None = None  # None: derive defaults from the spec


#: the largest added surface [m2] and film coefficient [W/(m2 K)] a measure or a sweep may
#: name: a spindle's housing has about 1 m2; forced water convection reaches 1e4-1e5 W/(m2 K)
MAX_AREA_M2 = 100.0
MAX_FILM_W_M2K = 1e5
#: the range of a length sweep's factors: a design study of the spindle's length within an
#: order of magnitude either way (a factor of 10 already makes the SPL2782 a 5 m shaft; the
#: mesh grows with the factor)
LENGTH_FACTORS = (0.1, 10.0)

_MEASURE_KEYS = ("name", "kind", "description", "surfaces", "A_M_m2", "alpha_M_W_m2K",
                 "alpha_M2_W_m2K")


_INVERSE_KEYS = ("name", "measure", "vary", "xi_pct", "growth_um", "size_max")


_TOP_KEYS = ("spec", "description", "measure", "inverse", "sweeps")


_SWEEP_KEYS = {"area": ("surfaces", "alpha_M_W_m2K", "min_m2", "max_m2"),
               "film": ("surfaces", "min_W_m2K", "max_W_m2K"),
               "heat": ("source", "min_W", "max_W"),
               "length": ("min_factor", "max_factor")}


def shipped_measures(spec_name: str) -> Path | None:
    """The shipped measures file of a spec (spindle/data/measures/<name>.toml), if any."""
    p = resources.files("spindle").joinpath(f"data/measures/{spec_name}.toml")
    return Path(str(p)) if p.is_file() else None


class _Reader:
    def __init__(self, file: str):
        self.file, self.problems = file, []

    def add(self, fld: str, message: str, fix: str) -> None:
        self.problems.append(Problem(self.file, fld, message, fix))

    def unknown(self, d: dict, allowed, where: str) -> None:
        for k in d:
            if k not in allowed:
                self.add(f"{where}.{k}" if where else k, "is not a field here",
                         f"remove it or use one of {list(allowed)}")

    def number(self, d: dict, key: str, where: str, unit: str, required: bool = False,
               positive: bool = True, lo: float | None = None, hi: float | None = None
               ) -> float | None:
        fld = f"{where}.{key}"
        if key not in d:
            if required:
                self.add(fld, "required field is missing", f"add {key} = <number> [{unit}]")
            return None
        v = d[key]
        if not isinstance(v, int | float) or isinstance(v, bool) or not math.isfinite(v):
            self.add(fld, f"{v!r} is not a number", f"write {key} = <number> [{unit}]")
            return None
        v = float(v)
        if positive and v <= 0:
            self.add(fld, f"{v:g} is not > 0", f"give {key} > 0 {unit}")
            return None
        if lo is not None and v < lo or hi is not None and v > hi:
            span = (f"within {lo:g}..{hi:g}" if lo is not None and hi is not None
                    else f"at most {hi:g}" if hi is not None else f"at least {lo:g}")
            self.add(fld, f"{v:g} is not {span}", f"give {key} {span} {unit}")
            return None
        return v

    def name(self, d: dict, where: str, seen: set[str]) -> str | None:
        v = d.get("name")
        if not isinstance(v, str) or not v.strip():
            self.add(f"{where}.name", "required text field is missing", 'add name = "..."')
            return None
        if v in seen:
            self.add(f"{where}.name", f"'{v}' is used twice", "give each entry its own name")
            return None
        seen.add(v)
        return v

    def surfaces(self, d: dict, where: str, convective: list[str]) -> tuple[str, ...] | None:
        v = d.get("surfaces")
        if not (isinstance(v, list) and v and all(isinstance(x, str) for x in v)):
            self.add(f"{where}.surfaces", "must list one or more surface names",
                     f"write surfaces = [\"{convective[0] if convective else 'name'}\"]")
            return None
        bad = [x for x in v if x not in convective]
        if bad:
            self.add(f"{where}.surfaces", f"'{bad[0]}' is not a surface of the spec with a film "
                     "coefficient", f"use one of {convective} (spec [[surfaces]] with h_W_m2K)")
            return None
        if len(set(v)) != len(v):
            self.add(f"{where}.surfaces", "names a surface twice", "list each surface once")
            return None
        return tuple(v)


def read_measures(path: str | Path, spec: Spec, points: int | None = None) -> MeasureFile:
    """Read and check a measures file (TOML, docs/measures.md) against ``spec``; every
    problem is reported at once (:class:`MeasureFileError`). ``points`` overrides the
    number of points per sweep."""
    path = Path(path)
    r = _Reader(str(path))
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except FileNotFoundError:
        raise MeasureFileError([Problem(str(path), "file", "does not exist",
                                        "give the path of a measures TOML file")]) from None
    except tomllib.TOMLDecodeError as exc:
        raise MeasureFileError([Problem(str(path), "syntax", str(exc),
                                        "fix the TOML syntax at that line")]) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise MeasureFileError([Problem(str(path), "file", f"cannot be read ({exc})",
                                        "check the path and that the file is UTF-8 text")]) \
            from None
    r.unknown(data, _TOP_KEYS, "")
    if "spec" in data and data["spec"] != spec.name:
        r.add("spec", f"the file is written for spec '{data['spec']}', not '{spec.name}'",
              f"give the measures file of '{spec.name}' (its surface names differ)")
    convective = [s.name for s in spec.surfaces if s.h_W_m2K is not None]
    measures = _read_measure_list(r, data, convective)
    inverse = _read_inverse(r, data, {m.name: m for m in measures}, bool(spec.growth_points()))
    sweeps = None
    if "sweeps" in data:
        sweeps = _read_sweeps(r, data["sweeps"], spec, convective, points)
    if r.problems:
        raise MeasureFileError(r.problems)
    return MeasureFile(str(path), tuple(measures), tuple(inverse), sweeps)


def _read_measure_list(r: _Reader, data: dict, convective: list[str]) -> list[Measure]:
    items = data.get("measure")
    if not (isinstance(items, list) and items and all(isinstance(x, dict) for x in items)):
        r.add("measure", "needs at least one [[measure]] table",
              'add [[measure]] with name, kind, surfaces and its sizes')
        return []
    out, seen = [], set()
    for i, d in enumerate(items):
        where = f"measure[{i}]"
        r.unknown(d, _MEASURE_KEYS, where)
        name = r.name(d, where, seen)
        kind = d.get("kind")
        if kind not in KINDS:
            r.add(f"{where}.kind", f"{kind!r} is not a kind of measure",
                  f"use one of {list(KINDS)}")
            continue
        surfaces = r.surfaces(d, where, convective)
        uses_A = kind in ("added_surface", "both")
        uses_a2 = kind in ("improved_coefficient", "both")
        # bounds far beyond any measure, so that a unit slip or an exponent is named: a
        # hundred times a motor spindle's whole surface (about 1 m2), and a boiling film
        A_M = r.number(d, "A_M_m2", where, "m2", required=uses_A, lo=0.0, hi=MAX_AREA_M2)
        a_M = r.number(d, "alpha_M_W_m2K", where, "W/m2/K", required=uses_A, lo=0.0,
                       hi=MAX_FILM_W_M2K)
        a_M2 = r.number(d, "alpha_M2_W_m2K", where, "W/m2/K", required=uses_a2, lo=0.0,
                        hi=MAX_FILM_W_M2K)
        for key, used in (("A_M_m2", uses_A), ("alpha_M_W_m2K", uses_A),
                          ("alpha_M2_W_m2K", uses_a2)):
            if key in d and not used:
                r.add(f"{where}.{key}", f"is not used by kind '{kind}'",
                      "remove it, or use kind = \"both\" for an added surface with improved "
                      "coefficients")
        desc = d.get("description", "")
        if name is None or surfaces is None or (uses_A and None in (A_M, a_M)) or \
                (uses_a2 and a_M2 is None):
            continue
        out.append(Measure(name, kind, surfaces, A_M if uses_A else None,
                           a_M if uses_A else None, a_M2 if uses_a2 else None, str(desc)))
    return out


def _read_inverse(r: _Reader, data: dict, measures: dict[str, Measure],
                  growth_readings: bool) -> list[InverseTarget]:
    items = data.get("inverse", [])
    if not (isinstance(items, list) and all(isinstance(x, dict) for x in items)):
        r.add("inverse", "must be a list of tables", "write each target as [[inverse]]")
        return []
    listed = data.get("measure")
    written = {x.get("name") for x in listed if isinstance(x, dict)} if isinstance(
        listed, list) else set()
    out, seen = [], set()
    for i, d in enumerate(items):
        where = f"inverse[{i}]"
        r.unknown(d, _INVERSE_KEYS, where)
        name = r.name(d, where, seen)
        mname = d.get("measure")
        m = measures.get(mname) if isinstance(mname, str) else None
        if m is None:
            if not (isinstance(mname, str) and mname in written):  # else its own problems
                # (a measure of this file that could not be read) are said already
                r.add(f"{where}.measure", f"{mname!r} is not a measure of this file",
                      f"name one of {sorted(measures)}")
            continue
        vary = d.get("vary", SIZE_FIELDS[m.kind][0])
        if vary not in SIZE_FIELDS[m.kind]:
            r.add(f"{where}.vary", f"{vary!r} cannot be varied for kind '{m.kind}'",
                  f"use one of {list(SIZE_FIELDS[m.kind])}")
            continue
        xi = r.number(d, "xi_pct", where, "%", lo=0.0, hi=99.9)
        g = r.number(d, "growth_um", where, "um")
        if ("xi_pct" in d) == ("growth_um" in d):
            r.add(where, "needs exactly one target", "give xi_pct = <percent> (temperature, "
                  "eq. 32) or growth_um = <um> (axial growth), not both")
            continue
        if "growth_um" in d and not growth_readings:
            r.add(f"{where}.growth_um", "the spec has no growth reading (no axial_displacement "
                  "sensor)", "give xi_pct instead, or add a P1 sensor to the spec")
            continue
        smax = r.number(d, "size_max", where, "m2 or W/m2/K")
        if name is not None and (xi is not None or g is not None):
            out.append(InverseTarget(name, m.name, vary, xi, g, smax))
    return out


def _read_sweeps(r: _Reader, d: Any, spec: Spec, convective: list[str],
                 points: int | None) -> tuple[SweepSpec, ...]:
    if not isinstance(d, dict):
        r.add("sweeps", "must be a table", "write it as [sweeps]")
        return ()
    r.unknown(d, ("points", *SWEEPS), "sweeps")
    n = d.get("points", 7)
    if not isinstance(n, int) or isinstance(n, bool) or not 2 <= n <= 100:
        r.add("sweeps.points", f"{n!r} is not an integer within 2..100", "write points = 7")
        n = 7
    n = points or n
    out: list[SweepSpec] = []
    for kind in SWEEPS:
        t = d.get(kind)
        if t is None:
            continue
        where = f"sweeps.{kind}"
        n_out, n_problems = len(out), len(r.problems)
        if not isinstance(t, dict):
            r.add(where, "must be a table", f"write {kind} = {{ ... }}")
            continue
        r.unknown(t, _SWEEP_KEYS[kind], where)
        if kind == "area":
            s = r.surfaces(t, where, convective)
            a = r.number(t, "alpha_M_W_m2K", where, "W/m2/K", required=True,
                         hi=MAX_FILM_W_M2K)
            lo = r.number(t, "min_m2", where, "m2", positive=False, lo=0.0,
                          hi=MAX_AREA_M2) or 0.0
            hi = r.number(t, "max_m2", where, "m2", required=True, hi=MAX_AREA_M2)
            if s and a and hi and hi > lo:
                out.append(SweepSpec(kind, tuple(np.linspace(lo, hi, n)), s, a))
        elif kind == "film":
            s = r.surfaces(t, where, convective)
            lo = r.number(t, "min_W_m2K", where, "W/m2/K", positive=False, lo=0.0,
                          hi=MAX_FILM_W_M2K) or 0.0
            hi = r.number(t, "max_W_m2K", where, "W/m2/K", required=True, hi=MAX_FILM_W_M2K)
            if s and hi and hi > lo:
                out.append(SweepSpec(kind, tuple(np.linspace(lo, hi, n)), s))
        elif kind == "heat":
            src = t.get("source")
            names = [h.name for h in spec.heat_sources]
            if src not in names:
                r.add(f"{where}.source", f"{src!r} is not a heat source of the spec",
                      f"use one of {names}")
                continue
            lo = r.number(t, "min_W", where, "W", positive=False, lo=0.0,
                          hi=MAX_POWER_W) or 0.0
            hi = r.number(t, "max_W", where, "W", required=True, hi=MAX_POWER_W)
            if hi and hi > lo:
                out.append(SweepSpec(kind, tuple(np.linspace(lo, hi, n)), source=src))
        else:
            lo = r.number(t, "min_factor", where, "-", required=True, lo=LENGTH_FACTORS[0],
                          hi=LENGTH_FACTORS[1])
            hi = r.number(t, "max_factor", where, "-", required=True, lo=LENGTH_FACTORS[0],
                          hi=LENGTH_FACTORS[1])
            if lo and hi and hi > lo:
                L0 = axial_length_m(spec)
                out.append(SweepSpec(kind, tuple(L0 * np.linspace(lo, hi, n))))
        if len(out) == n_out and len(r.problems) == n_problems:
            r.add(where, "the range is empty", "give a maximum above the minimum")
    return tuple(out)


def default_sweeps(spec: Spec, speed_rpm: float, points: int = 7) -> tuple[SweepSpec, ...]:
    """Sweeps for a spec without a [sweeps] table: area and film on its largest convective
    surface (area up to twice that surface, at its own coefficient; film 0 .. max(60, 3 h)
    W/m2/K, the paper's Fig. 16 range at least), the first heat source from 0 to twice its
    power in the spec, and the length from 0.5 to 1.5 times the spindle's."""
    films = sorted(surface_films(spec, speed_rpm), key=lambda f: f.A_m2)
    out = []
    if films:
        f = films[-1]
        out.append(SweepSpec("area", tuple(np.linspace(0.0, 2.0 * f.A_m2, points)), (f.name,),
                             f.h_W_m2K))
        out.append(SweepSpec("film", tuple(np.linspace(0.0, max(60.0, 3.0 * f.h_W_m2K), points)),
                             (f.name,)))
    if spec.heat_sources:
        h = spec.heat_sources[0]
        p = max(float(np.max(h.power_W.values)), 1.0)
        out.append(SweepSpec("heat", tuple(np.linspace(0.0, 2.0 * p, points)), source=h.name))
    out.append(SweepSpec("length", tuple(axial_length_m(spec) * np.linspace(0.5, 1.5, points))))
    return tuple(out)
