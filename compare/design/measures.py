"""Design measures of the thermal stiffness strategy (paper section 4, eq. 22-32): predicted
by the simplified formulas, verified by the FEM reference solved on the modified spec.

A **measure** changes the spec's heat dissipation (docs/measures.md):

- ``added_surface``: an added heat-dissipating surface A_M [m2] with coefficient alpha_M
  [W/m2/K] (fins). The model is axisymmetric, so the fins are an added film conductance
  alpha_M A_M spread uniformly over the named host surfaces (fin efficiency 1):
  h_eff = h + alpha_M A_M / sum(A_host), towards the host's own T_ref.
- ``improved_coefficient``: the coefficient of the k named surfaces becomes alpha_M2 (at
  every speed).
- ``both``: the named surfaces get alpha_M2 *and* the added surface, h_eff = alpha_M2 +
  alpha_M A_M / sum(A_host).

**The simplified formulas** (one body at one temperature, one environment, no internal
resistance) make the heat stiffness K_alpha = 1 / sum(alpha_i A_i), so the heat stiffness
ratio of eq. 22 is lambda_tr = K_alpha1 / K_alpha2 = sum_after / sum_before:

- eq. 25 (as it must read; the paper prints it upside down, which gives lambda < 1 against
  its own eq. 26 and text): lambda_I = (sum(alpha_i A_i) + alpha_M1 A_M1) / sum(alpha_i A_i);
- eq. 26: lambda_I = 1 + A_M1 / sum(A_i) (all coefficients equal);
- eq. 27 / 28: lambda_II = 1 + sum_j (alpha_M2 - alpha_j) A_j / sum(alpha_i A_i);
- eq. 29 / 30: lambda_III = lambda_I + lambda_II - 1;
- eq. 24: Delta T = T1 (lambda - 1) / lambda;  eq. 32: xi = (lambda - 1) / lambda 100 %;
- eq. 31: lambda = K_Q2 / K_Q1 for the growth; for the uniform body the growth is
  proportional to its rise (eq. 20), so the formulas predict the same lambda.

Here sum(alpha_i A_i) runs over **every surface of the spec with a film coefficient**, at
the case's speed, coolant jacket included (:func:`compare.design.stiffness.surface_films`).

**The reference** solves the modified spec (same mesh: only film coefficients change, so the
assembled operator is reused with the new coefficients, which is exact because K is affine
in them) and reads K_alpha from the volume-mean and the maximum rise
(:mod:`compare.design.stiffness`); lambda_ref = K_alpha1 / K_alpha2 at the same losses.

**Inverse problem** (:func:`solve_inverse`): the smallest size of a measure (A_M, or
alpha_M2) that reaches a target xi (or a target growth), by Brent's method on the FEM solve,
with the formula's prediction of the same size.

``spindle-verify measures SPEC --measures FILE`` runs it all (:func:`run_measures`) and writes
tables, JSON and the Fig. 15 / Fig. 16 pictures (:mod:`compare.design.plots`).
"""

from __future__ import annotations

import math
import time
import tomllib
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from compare.design.stiffness import (
    Indicators,
    indicators,
    paper_consistency,
    sum_alpha_A_W_K,
    surface_films,
)
from spindle.errors import Problem, SpindleVerifyError
from spindle.faces import exposed_faces, surface_faces
from spindle.loads import LoadCase, SpeedTable, TimeSeries
from spindle.spec import Spec

KINDS = ("added_surface", "improved_coefficient", "both")
SWEEPS = ("area", "length", "film", "heat")
#: the size an inverse problem varies, by kind (and what "both" may vary instead)
SIZE_FIELDS = {"added_surface": ("A_M_m2",), "improved_coefficient": ("alpha_M2_W_m2K",),
               "both": ("A_M_m2", "alpha_M2_W_m2K")}
#: the paper's recommended range of the heat stiffness ratio (section 4): 1.1 < lambda <= 5..6
PAPER_LAMBDA_RANGE = (1.1, 6.0)


# ============================================================================ formulas


def lambda_added(sum_alpha_A_W_K: float, alpha_M_W_m2K: float, A_M_m2: float) -> float:
    """Eq. 25 in its consistent form: (sum(alpha_i A_i) + alpha_M A_M) / sum(alpha_i A_i)."""
    return (sum_alpha_A_W_K + alpha_M_W_m2K * A_M_m2) / sum_alpha_A_W_K


def lambda_added_as_printed(sum_alpha_A_W_K: float, alpha_M_W_m2K: float, A_M_m2: float
                            ) -> float:
    """Eq. 25 exactly as the paper prints it (the reciprocal of :func:`lambda_added`, < 1 for
    any added surface); kept only to document the misprint."""
    return sum_alpha_A_W_K / (sum_alpha_A_W_K + alpha_M_W_m2K * A_M_m2)


def lambda_added_equal_alpha(A_M_m2: float, sum_A_m2: float) -> float:
    """Eq. 26: 1 + A_M / sum(A_i), every coefficient equal."""
    return 1.0 + A_M_m2 / sum_A_m2


def lambda_improved(sum_alpha_A_W_K: float, alpha_M2_W_m2K: float,
                    alphas_W_m2K: list[float], areas_m2: list[float]) -> float:
    """Eq. 27: 1 + sum_j (alpha_M2 - alpha_j) A_j / sum(alpha_i A_i) over the k improved
    surfaces j (coefficients alpha_j, areas A_j)."""
    gain = sum((alpha_M2_W_m2K - a) * A for a, A in zip(alphas_W_m2K, areas_m2, strict=True))
    return 1.0 + gain / sum_alpha_A_W_K


def lambda_improved_equal_alpha(alpha_M2_W_m2K: float, alpha_W_m2K: float, sum_A_k_m2: float,
                                sum_A_m2: float) -> float:
    """Eq. 28: 1 + (alpha_M2 / alpha - 1) sum(A_k) / sum(A_i), every other coefficient alpha."""
    return 1.0 + (alpha_M2_W_m2K / alpha_W_m2K - 1.0) * sum_A_k_m2 / sum_A_m2


def lambda_both(sum_alpha_A_W_K: float, alpha_M_W_m2K: float, A_M_m2: float,
                alpha_M2_W_m2K: float, alphas_W_m2K: list[float], areas_m2: list[float]) -> float:
    """Eq. 29: lambda_I + lambda_II - 1."""
    return (lambda_added(sum_alpha_A_W_K, alpha_M_W_m2K, A_M_m2)
            + lambda_improved(sum_alpha_A_W_K, alpha_M2_W_m2K, alphas_W_m2K, areas_m2) - 1.0)


def lambda_both_equal_alpha(A_M_m2: float, alpha_M2_W_m2K: float, alpha_W_m2K: float,
                            sum_A_k_m2: float, sum_A_m2: float) -> float:
    """Eq. 30: 1 + A_M / sum(A_i) + (alpha_M2 / alpha - 1) sum(A_k) / sum(A_i)."""
    return 1.0 + A_M_m2 / sum_A_m2 + (alpha_M2_W_m2K / alpha_W_m2K - 1.0) * sum_A_k_m2 / sum_A_m2


def xi_pct(lam: float) -> float:
    """Eq. 32: reduction of the excess temperature [%], (lambda - 1) / lambda 100."""
    return (lam - 1.0) / lam * 100.0


def lambda_from_xi(xi: float) -> float:
    """Eq. 32 inverted: lambda = 1 / (1 - xi / 100)."""
    return 1.0 / (1.0 - xi / 100.0)


def temperature_drop_K(T1_rise_K: float, lam: float) -> float:
    """Eq. 24: Delta T = T1 (lambda - 1) / lambda [K] (T1: the excess temperature before)."""
    return T1_rise_K * (lam - 1.0) / lam


# ============================================================================ measures


@dataclass(frozen=True)
class Measure:
    """A change to the spec's heat dissipation (module doc). Sizes SI: A_M_m2 [m2],
    coefficients [W/m2/K]; fields a kind does not use are None."""

    name: str
    kind: str
    surfaces: tuple[str, ...]
    A_M_m2: float | None = None
    alpha_M_W_m2K: float | None = None
    alpha_M2_W_m2K: float | None = None
    description: str = ""

    def with_size(self, field_name: str, value: float) -> Measure:
        """The same measure with ``A_M_m2`` or ``alpha_M2_W_m2K`` set to ``value``."""
        return replace(self, **{field_name: float(value)})

    @property
    def size_text(self) -> str:
        parts = []
        if self.A_M_m2 is not None:
            parts.append(f"A_M={self.A_M_m2:.4g} m2 at {self.alpha_M_W_m2K:.4g} W/m2K")
        if self.alpha_M2_W_m2K is not None:
            parts.append(f"alpha_M2={self.alpha_M2_W_m2K:.4g} W/m2K")
        return ", ".join(parts)


def _host_area_m2(spec: Spec, names: tuple[str, ...]) -> float:
    faces = exposed_faces(spec)
    return float(sum(f.area_m2 for s in spec.surfaces if s.name in names
                     for f in surface_faces(s, faces)))


def apply_measure(spec: Spec, measure: Measure | None) -> Spec:
    """The spec with the measure's film coefficients (module doc); ``None``: unchanged.

    Speed tables keep their speeds: an added surface adds alpha_M A_M / sum(A_host) to every
    value; an improved coefficient replaces the table by the constant alpha_M2.
    """
    if measure is None:
        return spec
    names = set(measure.surfaces)
    add = 0.0
    if measure.kind in ("added_surface", "both"):
        add = float(measure.alpha_M_W_m2K) * float(measure.A_M_m2) / _host_area_m2(
            spec, measure.surfaces)
    new = []
    for s in spec.surfaces:
        if s.name in names:
            if measure.kind in ("improved_coefficient", "both"):
                h = SpeedTable.constant(float(measure.alpha_M2_W_m2K) + add)
            else:
                h = SpeedTable(s.h_W_m2K.speed_rpm, tuple(v + add for v in s.h_W_m2K.values))
            s = replace(s, h_W_m2K=h)
        new.append(s)
    return replace(spec, surfaces=tuple(new))


def formula_lambda(spec: Spec, measure: Measure, speed_rpm: float) -> tuple[float, float, float]:
    """(lambda_tr, sum(alpha_i A_i) [W/K], added conductance [W/K]) of the simplified
    formulas (eq. 25 consistent form, 27, 29) for ``measure`` on ``spec`` at ``speed_rpm``."""
    films = {f.name: f for f in surface_films(spec, speed_rpm)}
    G0 = sum(f.G_W_K for f in films.values())
    lam = 1.0
    if measure.kind == "added_surface":
        lam = lambda_added(G0, measure.alpha_M_W_m2K, measure.A_M_m2)
    else:
        j = [films[n] for n in measure.surfaces]
        alphas, areas = [f.h_W_m2K for f in j], [f.A_m2 for f in j]
        if measure.kind == "improved_coefficient":
            lam = lambda_improved(G0, measure.alpha_M2_W_m2K, alphas, areas)
        else:
            lam = lambda_both(G0, measure.alpha_M_W_m2K, measure.A_M_m2,
                              measure.alpha_M2_W_m2K, alphas, areas)
    return lam, G0, (lam - 1.0) * G0


def scale_axially(spec: Spec, factor: float) -> Spec:
    """The spec stretched along the axis by ``factor`` (every z: sections, surface limits,
    sensors); radii, materials, links, powers and the mesh size h0 stay. For the length
    sensitivity of Fig. 16."""
    def z(v: float) -> float:
        return v * factor if math.isfinite(v) else v

    parts = tuple(replace(p, sections=tuple(replace(s, z_start=z(s.z_start), z_end=z(s.z_end))
                                            for s in p.sections)) for p in spec.parts)
    surfaces = tuple(replace(s, z_min=z(s.z_min), z_max=z(s.z_max)) for s in spec.surfaces)
    sensors = tuple(replace(s, z=z(s.z), z_ref=None if s.z_ref is None else z(s.z_ref))
                    for s in spec.sensors)
    return replace(spec, parts=parts, surfaces=surfaces, sensors=sensors)


def axial_length_m(spec: Spec) -> float:
    """Axial extent of the spindle (all parts) [m]."""
    zs = [v for _, s in spec.sections() for v in (s.z_start, s.z_end)]
    return max(zs) - min(zs)


# ============================================================================ the file


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
            self.add(fld, f"{v:g} is outside {lo:g}..{hi:g}", f"give {key} within {lo:g}..{hi:g}"
                     f" {unit}")
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
        data = tomllib.loads(path.read_text(encoding="utf-8"))
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
        A_M = r.number(d, "A_M_m2", where, "m2", required=uses_A)
        a_M = r.number(d, "alpha_M_W_m2K", where, "W/m2/K", required=uses_A)
        a_M2 = r.number(d, "alpha_M2_W_m2K", where, "W/m2/K", required=uses_a2)
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
    out, seen = [], set()
    for i, d in enumerate(items):
        where = f"inverse[{i}]"
        r.unknown(d, _INVERSE_KEYS, where)
        name = r.name(d, where, seen)
        mname = d.get("measure")
        m = measures.get(mname) if isinstance(mname, str) else None
        if m is None:
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
            a = r.number(t, "alpha_M_W_m2K", where, "W/m2/K", required=True)
            lo = r.number(t, "min_m2", where, "m2", positive=False, lo=0.0, hi=1e3) or 0.0
            hi = r.number(t, "max_m2", where, "m2", required=True)
            if s and a and hi and hi > lo:
                out.append(SweepSpec(kind, tuple(np.linspace(lo, hi, n)), s, a))
        elif kind == "film":
            s = r.surfaces(t, where, convective)
            lo = r.number(t, "min_W_m2K", where, "W/m2/K", positive=False, lo=0.0, hi=1e6) or 0.0
            hi = r.number(t, "max_W_m2K", where, "W/m2/K", required=True)
            if s and hi and hi > lo:
                out.append(SweepSpec(kind, tuple(np.linspace(lo, hi, n)), s))
        elif kind == "heat":
            src = t.get("source")
            names = [h.name for h in spec.heat_sources]
            if src not in names:
                r.add(f"{where}.source", f"{src!r} is not a heat source of the spec",
                      f"use one of {names}")
                continue
            lo = r.number(t, "min_W", where, "W", positive=False, lo=0.0, hi=1e7) or 0.0
            hi = r.number(t, "max_W", where, "W", required=True)
            if hi and hi > lo:
                out.append(SweepSpec(kind, tuple(np.linspace(lo, hi, n)), source=src))
        else:
            lo = r.number(t, "min_factor", where, "-", required=True)
            hi = r.number(t, "max_factor", where, "-", required=True)
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


# ============================================================================ reference


_MODELS: dict[tuple, tuple[Any, list]] = {}
_MAX_MODELS = 4


def _model_key(spec: Spec, level: int, elastic: bool) -> tuple | None:
    """Everything an assembled FEM operator depends on except the film coefficients."""
    key = (spec.path, spec.name, level, elastic, spec.h0_m, spec.T_initial_K, spec.parts,
           spec.links, tuple(sorted(spec.materials.items())),
           tuple((s.name, s.parts, s.side, s.z_min, s.z_max, s.T_ref, s.h_W_m2K is None)
                 for s in spec.surfaces), spec.heat_sources, spec.sensors)
    try:
        hash(key)
    except TypeError:
        return None
    return key


def reference_model(spec: Spec, level: int = 1, elastic: bool = True):
    """A :class:`reference.ReferenceModel` of ``spec``, cached per process: specs that differ
    only in film coefficients share one mesh and assembly, with the coefficients swapped
    in (exact: the conductance matrix is affine in them). The model is shared: the next call
    re-points it at the next spec, so solve before asking for another."""
    from reference import ReferenceModel

    key = _model_key(spec, level, elastic)
    if key is None or key not in _MODELS:
        model = ReferenceModel(spec, level, elastic=elastic)
        if key is not None:
            while len(_MODELS) >= _MAX_MODELS:
                _MODELS.pop(next(iter(_MODELS)))
            _MODELS[key] = (model, list(model.thermal.op.films))
        return model
    model, base = _MODELS[key]
    by_name = {s.name: s for s in spec.surfaces}
    model.thermal.op.films = [(by_name[s.name], R, b) for s, R, b in base]
    model.thermal._lu.clear()
    model.spec = model.thermal.spec = spec
    return model


def _speed(case: LoadCase) -> float:
    return float(case.speed_rpm(0.0))


def _nodes_arg(nodes: str | int) -> str | int:
    return int(nodes) if isinstance(nodes, str) and nodes.isdigit() else nodes


@dataclass(frozen=True)
class MeasureCase:
    """Indicators of the spec with ``measure`` (None: as it is) from the FEM at ``level``
    and from each lumped model in ``nodes``. A picklable unit of work for the executor."""

    spec: Spec
    case: LoadCase
    measure: Measure | None
    level: int = 1
    nodes: tuple[str | int, ...] = ()

    @property
    def label(self) -> str:
        return "baseline" if self.measure is None else f"measure {self.measure.name}"

    def run(self) -> dict[str, Any]:
        spec = apply_measure(self.spec, self.measure)
        fem = indicators(reference_model(spec, self.level), self.case,
                         f"FEM level {self.level}")
        lumped = {}
        if self.nodes:
            from lumped import LumpedModel

            for n in self.nodes:
                lumped[str(n)] = indicators(LumpedModel(spec, _nodes_arg(n)), self.case,
                                            f"lumped {n}")
        return {"fem": fem, "lumped": lumped}


@dataclass(frozen=True)
class MeasureResult:
    """One measure: the formulas' prediction against the reference (and lumped models)."""

    measure: Measure
    lambda_formula: float
    sum_alpha_A_W_K: float
    added_G_W_K: float
    before: Indicators
    after: Indicators | None
    lumped_before: dict[str, Indicators] = field(default_factory=dict)
    lumped_after: dict[str, Indicators] = field(default_factory=dict)
    error: str | None = None

    @property
    def xi_formula_pct(self) -> float:
        return xi_pct(self.lambda_formula)

    def _ratio(self, attr: str, a: Indicators | None = None, b: Indicators | None = None
               ) -> float:
        a, b = a or self.before, b or self.after
        if b is None:
            return math.nan
        return getattr(a, attr) / getattr(b, attr)

    @property
    def lambda_ref_mean(self) -> float:
        """K_alpha1 / K_alpha2 from the reference's mean rise (eq. 22)."""
        return self._ratio("K_alpha_mean_K_W")

    @property
    def lambda_ref_max(self) -> float:
        return self._ratio("K_alpha_max_K_W")

    @property
    def lambda_growth_ref(self) -> float:
        """K_Q2 / K_Q1 from the reference's growth (eq. 31)."""
        return 1.0 / self._ratio("K_Q_W_um") if self.after is not None else math.nan

    @property
    def effect_ratio(self) -> float:
        """(lambda_ref - 1) / (lambda_formula - 1): the share of the predicted effect the
        reference confirms (1: the formulas are exact)."""
        d = self.lambda_formula - 1.0
        return (self.lambda_ref_mean - 1.0) / d if d else math.nan

    def lambda_lumped(self, nodes: str) -> float:
        if nodes not in self.lumped_after:
            return math.nan
        return self._ratio("K_alpha_mean_K_W", self.lumped_before[nodes], self.lumped_after[nodes])

    def to_row(self) -> dict[str, Any]:
        m, b, a = self.measure, self.before, self.after
        nan = math.nan
        lam_r, lam_g = self.lambda_ref_mean, self.lambda_growth_ref
        row = {
            "measure": m.name, "kind": m.kind, "surfaces": " ".join(m.surfaces),
            "A_M_m2": m.A_M_m2, "alpha_M_W_m2K": m.alpha_M_W_m2K,
            "alpha_M2_W_m2K": m.alpha_M2_W_m2K,
            "sum_alpha_A_W_K": self.sum_alpha_A_W_K, "added_G_W_K": self.added_G_W_K,
            "lambda_formula": self.lambda_formula, "xi_formula_pct": self.xi_formula_pct,
            "lambda_ref_mean": lam_r, "xi_ref_mean_pct": xi_pct(lam_r),
            "lambda_ref_max": self.lambda_ref_max, "xi_ref_max_pct": xi_pct(self.lambda_ref_max),
            "gap_lambda": lam_r - self.lambda_formula,
            "gap_xi_pct_points": xi_pct(lam_r) - self.xi_formula_pct,
            "effect_ratio": self.effect_ratio,
            "dT_formula_K": temperature_drop_K(b.mean_rise_K, self.lambda_formula),
            "dT_ref_K": b.mean_rise_K - a.mean_rise_K if a else nan,
            "mean_rise_before_K": b.mean_rise_K, "mean_rise_after_K": a.mean_rise_K if a else nan,
            "max_rise_before_K": b.max_rise_K, "max_rise_after_K": a.max_rise_K if a else nan,
            "growth_before_um": b.growth_um, "growth_after_um": a.growth_um if a else nan,
            "lambda_growth_formula": self.lambda_formula, "lambda_growth_ref": lam_g,
            "xi_growth_ref_pct": xi_pct(lam_g),
            "gap_growth_lambda": lam_g - self.lambda_formula,
        }
        for n in self.lumped_before:
            row[f"lambda_lumped_{n}"] = self.lambda_lumped(n)
        row["error"] = self.error or ""
        return row


def measure_result(spec: Spec, case: LoadCase, measure: Measure, base: dict, after: dict | None,
                   error: str | None = None) -> MeasureResult:
    """Combine the formula with the before/after indicators of :class:`MeasureCase`."""
    lam, G0, dG = formula_lambda(spec, measure, _speed(case))
    return MeasureResult(measure, lam, G0, dG, base["fem"], after["fem"] if after else None,
                         base["lumped"], after["lumped"] if after else {}, error)


# ============================================================================ inverse


@dataclass(frozen=True)
class InverseResult:
    """The smallest size reaching the target on the reference, and the formula's size."""

    target: InverseTarget
    kind: str
    reached: bool
    size_ref: float  # nan when not reached
    size_formula: float
    size_start: float  # where the search started (no measure, or alpha_M2 at today's mean)
    value_at_size: float  # xi [%] or growth [µm] of the reference at size_ref
    best_value: float  # the best value the reference reached within size_max
    size_max: float
    solves: int
    note: str = ""

    @property
    def unit(self) -> str:
        return "m2" if self.target.vary == "A_M_m2" else "W/m2K"

    def to_row(self) -> dict[str, Any]:
        t = self.target
        return {"target": t.name, "measure": t.measure, "kind": self.kind, "vary": t.vary,
                "target_xi_pct": t.xi_pct, "target_growth_um": t.growth_um,
                "reached": self.reached, "size_ref": self.size_ref,
                "size_formula": self.size_formula, "unit": self.unit,
                "formula_over_ref": self.size_formula / self.size_ref
                if self.reached and self.size_ref else math.nan,
                "value_at_size": self.value_at_size, "best_value_within_max": self.best_value,
                "size_start": self.size_start, "size_max": self.size_max,
                "fem_solves": self.solves, "note": self.note}


@dataclass(frozen=True)
class InverseCase:
    """The inverse problem of one target (a picklable unit of work for the executor)."""

    spec: Spec
    case: LoadCase
    target: InverseTarget
    template: Measure
    level: int = 1

    @property
    def label(self) -> str:
        t = self.target
        goal = f"xi={t.xi_pct:g} %" if t.xi_pct is not None else f"growth={t.growth_um:g} um"
        return f"inverse {t.name} ({goal})"

    def run(self) -> InverseResult:
        return solve_inverse(self.spec, self.case, self.template, self.target, self.level)


def solve_inverse(spec: Spec, case: LoadCase, template: Measure, target: InverseTarget,
                  level: int = 1) -> InverseResult:
    """Smallest ``target.vary`` of ``template`` whose reference solution reaches the target
    (Brent's method on the FEM solve; xi and the growth are monotone in the size)."""
    from scipy.optimize import brentq

    speed = _speed(case)
    films = {f.name: f for f in surface_films(spec, speed)}
    hosts = [films[n] for n in template.surfaces]
    if target.vary == "A_M_m2":
        start, default_max = 0.0, 1e3 * sum(f.A_m2 for f in films.values())
    else:  # today's area-weighted coefficient of the improved surfaces: no effect predicted
        start = sum(f.G_W_K for f in hosts) / sum(f.A_m2 for f in hosts)
        default_max = 1e6
    size_max = target.size_max or default_max
    base = indicators(reference_model(spec, level), case)
    use_growth = target.growth_um is not None
    if use_growth and not base.growth_reading:
        raise ValueError(f"{spec.path}: the spec has no growth reading (an axial_displacement "
                         "sensor), so a growth target cannot be solved; fix: give xi_pct")
    values: dict[float, float] = {}  # size -> xi [%] or growth [um], one FEM solve each

    def value(size: float) -> float:
        if size not in values:
            ind = indicators(reference_model(apply_measure(
                spec, template.with_size(target.vary, size)), level), case)
            values[size] = ind.growth_um if use_growth else \
                xi_pct(base.mean_rise_K / ind.mean_rise_K)
        return values[size]

    goal = target.growth_um if use_growth else target.xi_pct
    sign = -1.0 if use_growth else 1.0  # f >= 0 once the target is reached

    def f(size: float) -> float:
        return sign * (value(size) - goal)

    # formula: lambda is affine in the size
    lam_t = base.growth_um / goal if use_growth else lambda_from_xi(goal)
    l0 = formula_lambda(spec, template.with_size(target.vary, start), speed)[0]
    l1 = formula_lambda(spec, template.with_size(target.vary, start + 1.0), speed)[0]
    size_formula = start + (lam_t - l0) / (l1 - l0) if l1 != l0 else math.nan

    if size_max <= start:
        return InverseResult(target, template.kind, False, math.nan, size_formula, start,
                             math.nan, value(start), size_max, len(values) + 1,
                             f"not reachable: size_max {size_max:.4g} is not above the start "
                             f"{start:.4g}")
    if f(start) >= 0:
        return InverseResult(target, template.kind, True, start, size_formula, start,
                             value(start), value(start), size_max, len(values) + 1,
                             "reached without the measure")
    # bracket: from the file's size (at least twice the start), growing 4x up to size_max
    lo = start
    hi = min(max(getattr(template, target.vary) or 1.0, 2.0 * start), size_max)
    while f(hi) < 0 and hi < size_max:
        lo, hi = hi, min(4.0 * hi, size_max)
    if f(hi) < 0:
        best = value(hi)
        return InverseResult(target, template.kind, False, math.nan, size_formula, start,
                             math.nan, best, size_max, len(values) + 1,
                             f"not reachable: the reference reaches {best:.4g} "
                             f"{'um' if use_growth else '%'} at {hi:.4g}")
    size = float(brentq(f, lo, hi, xtol=1e-9 * hi, rtol=1e-6))
    v = value(size)
    return InverseResult(target, template.kind, True, size, size_formula, start, v, v,
                         size_max, len(values) + 1)


# ============================================================================ sweeps


@dataclass(frozen=True)
class SweepPoint:
    """Heat stiffness at one point of a sensitivity sweep: reference and formula."""

    sweep: str
    x: float
    losses_W: float
    K_alpha_mean_K_W: float
    K_alpha_max_K_W: float
    K_alpha_formula_K_W: float  # 1 / sum(alpha_i A_i)
    where: str = ""  # what is swept: surfaces, or the heat source

    def to_row(self) -> dict[str, Any]:
        return {**asdict(self), "x_unit": SWEEP_UNITS[self.sweep]}


SWEEP_UNITS = {"area": "m2", "length": "m", "film": "W/m2K", "heat": "W"}
SWEEP_LABELS = {"area": "A_M", "length": "L", "film": "alpha", "heat": "Q"}


@dataclass(frozen=True)
class SweepCase:
    """One point of a sweep (a picklable unit of work for the executor)."""

    spec: Spec
    case: LoadCase
    sweep: SweepSpec
    x: float
    level: int = 1

    @property
    def label(self) -> str:
        return f"sweep {self.sweep.kind} {SWEEP_LABELS[self.sweep.kind]}={self.x:.4g} " \
               f"{SWEEP_UNITS[self.sweep.kind]}"

    def run(self) -> SweepPoint:
        spec, case, sw = self.spec, self.case, self.sweep
        if sw.kind == "area":
            spec = apply_measure(spec, Measure("sweep", "added_surface", sw.surfaces, self.x,
                                               sw.alpha_M_W_m2K))
        elif sw.kind == "film":
            spec = apply_measure(spec, Measure("sweep", "improved_coefficient", sw.surfaces,
                                               alpha_M2_W_m2K=self.x))
        elif sw.kind == "heat":
            case = case.with_sources({sw.source: TimeSeries.constant(self.x)})
        else:
            spec = scale_axially(spec, self.x / axial_length_m(spec))
        ind = indicators(reference_model(spec, self.level, elastic=False), case)
        G = sum_alpha_A_W_K(spec, _speed(case))
        return SweepPoint(sw.kind, self.x, ind.losses_W, ind.K_alpha_mean_K_W,
                          ind.K_alpha_max_K_W, 1.0 / G if G > 0 else math.nan, sweep_where(sw))


def sweep_where(sw: SweepSpec) -> str:
    """What a sweep changes, in words (for tables and axis labels)."""
    if sw.kind == "area":
        return f"on {', '.join(sw.surfaces)} at {sw.alpha_M_W_m2K:.4g} W/m2K"
    if sw.kind == "film":
        return f"of {', '.join(sw.surfaces)}"
    if sw.kind == "heat":
        return f"of {sw.source}"
    return "whole spindle, stretched along z"


def run_case(case: MeasureCase | InverseCase | SweepCase) -> Any:
    """The executor's function: run one unit of work (module level, so it pickles)."""
    return case.run()


# ============================================================================ the run


@dataclass
class MeasuresReport:
    """Everything ``spindle-verify measures`` computes (SI; µm and % only in names)."""

    spec_name: str
    case_name: str
    level: int
    measures_file: str
    speed_rpm: float
    films: list
    baseline: Indicators
    lumped: dict[str, Indicators]
    measures: list[MeasureResult]
    inverse: list[InverseResult]
    sweeps: list[SweepPoint]
    failures: list[dict[str, str]]
    runtime_s: float = 0.0

    @property
    def sum_alpha_A_W_K(self) -> float:
        return float(sum(f.G_W_K for f in self.films))

    def indicator_rows(self) -> list[dict[str, Any]]:
        rows = [self.baseline.to_row()] + [v.to_row() for v in self.lumped.values()]
        G = self.sum_alpha_A_W_K
        rows.append({"model": "simplified formulas (1 / sum alpha A)",
                     "losses_W": self.baseline.losses_W,
                     "mean_rise_K": self.baseline.losses_W / G,
                     "K_alpha_mean_K_W": 1.0 / G})
        rows.append({"model": "paper (section 4)", "K_alpha_mean_K_W": 0.00019,
                     "K_T_K_um": 0.52, "K_Q_W_um": 64.53})
        return rows

    def to_rows(self) -> dict[str, list[dict[str, Any]]]:
        """Every table as a list of rows (dicts with units in the keys)."""
        return {"indicators": self.indicator_rows(),
                "surfaces": [{"surface": f.name, "T_ref": f.T_ref, "h_W_m2K": f.h_W_m2K,
                              "A_m2": f.A_m2, "G_W_K": f.G_W_K} for f in self.films],
                "measures": [m.to_row() for m in self.measures],
                "inverse": [i.to_row() for i in self.inverse],
                "sweeps": [p.to_row() for p in self.sweeps]}

    def to_pandas(self) -> dict[str, Any]:
        """The tables as DataFrames (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return {k: pd.DataFrame(v) for k, v in self.to_rows().items()}

    def summary(self) -> dict[str, Any]:
        return {"spec": self.spec_name, "case": self.case_name, "fem_level": self.level,
                "measures_file": self.measures_file, "speed_rpm": self.speed_rpm,
                "sum_alpha_A_W_K": self.sum_alpha_A_W_K,
                "sum_alpha_A_runs_over": "every surface with a film coefficient, coolant "
                                         "jacket included, at the case's speed",
                "paper_consistency": paper_consistency(),
                **self.to_rows(), "failures": self.failures, "runtime_s": self.runtime_s}

    def markdown(self) -> str:
        return _markdown(self)

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """measures.csv, indicators.csv, inverse.csv, sweeps.csv, measures.md, measures.json
        and (``pictures``) the Fig. 15 and Fig. 16 PNGs, each written atomically."""
        from spindle.outputs import atomic_write, write_csv, write_json

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        rows = self.to_rows()
        files = []
        for name in ("indicators", "measures", "inverse", "sweeps"):
            if rows[name]:
                header = list(dict.fromkeys(k for r in rows[name] for k in r))
                write_csv(out / f"{name}.csv", header,
                          ([_csv(r.get(k)) for k in header] for r in rows[name]))
                files.append(f"{name}.csv")
        write_json(out / "measures.json", self.summary())
        text = self.markdown()
        atomic_write(out / "measures.md", lambda tmp: tmp.write_text(text, "utf-8"))
        files += ["measures.json", "measures.md"]
        if pictures:
            from compare.design import plots as measures_plots

            measures_plots.fig15_png(self, out / "fig15_temperature_drop.png")
            files.append("fig15_temperature_drop.png")
            if self.sweeps:
                measures_plots.fig16_png(self, out / "fig16_sensitivity.png")
                files.append("fig16_sensitivity.png")
        return [out / f for f in files]


def _csv(v: Any) -> Any:
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    return v




def _fmt(v: Any, spec: str = ".4g") -> str:
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    if isinstance(v, float):
        return format(v, spec)
    return str(v)


def _table(header: list[str], rows: list[list[Any]], fmts: list[str] | None = None) -> str:
    fmts = fmts or [".4g"] * len(header)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    for r in rows:
        lines.append("| " + " | ".join(_fmt(v, f) for v, f in zip(r, fmts, strict=True)) + " |")
    return "\n".join(lines)


def _markdown(rep: MeasuresReport) -> str:
    pc = paper_consistency()
    out = [f"# Thermal stiffness strategy: {rep.spec_name}, case '{rep.case_name}'", "",
           f"FEM reference P2 level {rep.level}; losses {rep.baseline.losses_W:.1f} W at "
           f"{rep.speed_rpm:g} rpm; sum(alpha_i A_i) = {rep.sum_alpha_A_W_K:.4g} W/K over "
           "every convective surface (coolant jacket included). Measures file: "
           f"`{rep.measures_file}`. Run time {rep.runtime_s:.1f} s.", "",
           "## Indicators (paper section 4)", ""]
    ind = rep.indicator_rows()
    out.append(_table(["model", "Q W", "mean rise K", "max rise K", "K_alpha mean K/W",
                       "K_alpha max K/W", "shaft rise K", "growth um", "K_T K/um", "K_Q W/um"],
                      [[r.get("model"), r.get("losses_W"), r.get("mean_rise_K"),
                        r.get("max_rise_K"), r.get("K_alpha_mean_K_W"), r.get("K_alpha_max_K_W"),
                        r.get("shaft_rise_K"), r.get("growth_um"), r.get("K_T_K_um"),
                        r.get("K_Q_W_um")] for r in ind],
                      ["", ".1f", ".2f", ".2f", ".3g", ".3g", ".2f", ".2f", ".3f", ".2f"]))
    out += ["", f"The paper's K_T = 0.52 and K_Q = 64.53 follow from its own figures "
            f"(41.6 K / 79.7 um = {pc['K_T_K_um']:.3f}; 5146 W / 79.7 um = "
            f"{pc['K_Q_W_um']:.2f}); its K_alpha = 0.00019 K/W does not (41.6 K / 5146 W = "
            f"{pc['K_alpha_shaft_K_W']:.4f}, 46.1 K / 5146 W = {pc['K_alpha_housing_K_W']:.4f}) "
            f"and equals 1 K / 5146 W = {pc['one_kelvin_per_losses_K_W']:.3g} K/W.", "",
            "## Convective surfaces: what sum(alpha_i A_i) runs over", ""]
    out.append(_table(["surface", "T_ref", "alpha W/m2K", "A m2", "alpha A W/K", "share"],
                      [[f.name, f.T_ref, f.h_W_m2K, f.A_m2, f.G_W_K,
                        f"{100 * f.G_W_K / rep.sum_alpha_A_W_K:.2f} %"] for f in rep.films],
                      ["", "", ".4g", ".4g", ".4g", ""]))
    out += ["", "## Measures: formulas (eq. 25-30) against the reference", ""]
    mrows = [m.to_row() for m in rep.measures]
    lumped = [k for k in (mrows[0] if mrows else {}) if k.startswith("lambda_lumped_")]
    out.append(_table(
        ["measure", "kind", "size", "lambda formula", "xi formula %", "lambda ref (mean)",
         "xi ref (mean) %", "xi ref (max) %", "gap xi pp", "effect ratio",
         "growth um before/after", "lambda growth ref", "xi growth ref %"]
        + [k.replace("lambda_lumped_", "lambda ") for k in lumped],
        [[r["measure"], r["kind"], m.measure.size_text, r["lambda_formula"], r["xi_formula_pct"],
          r["lambda_ref_mean"], r["xi_ref_mean_pct"], r["xi_ref_max_pct"],
          r["gap_xi_pct_points"], r["effect_ratio"],
          f"{_fmt(r['growth_before_um'], '.2f')} / {_fmt(r['growth_after_um'], '.2f')}",
          r["lambda_growth_ref"], r["xi_growth_ref_pct"]] + [r[k] for k in lumped]
         for r, m in zip(mrows, rep.measures, strict=True)],
        ["", "", "", ".5g", ".3g", ".5g", ".3g", ".3g", "+.3g", ".3g", "", ".5g", ".3g"]
        + [".5g"] * len(lumped)))
    out += ["", "effect ratio = (lambda_ref - 1) / (lambda_formula - 1): the share of the "
            "predicted effect the reference confirms. lambda growth = K_Q2 / K_Q1 (eq. 31); the "
            "formulas predict the same lambda for the growth as for the temperature.", ""]
    if rep.inverse:
        out += ["## Inverse problem (smallest measure reaching a target, on the reference)", ""]
        out.append(_table(["target", "measure", "vary", "goal", "reached", "size (reference)",
                           "size (formula)", "formula / reference", "FEM solves", "note"],
                          [[i.target.name, i.target.measure, i.target.vary,
                            f"xi {i.target.xi_pct:g} %" if i.target.xi_pct is not None
                            else f"growth {i.target.growth_um:g} um", str(i.reached),
                            f"{_fmt(i.size_ref)} {i.unit}", f"{_fmt(i.size_formula)} {i.unit}",
                            i.to_row()["formula_over_ref"], i.solves, i.note]
                           for i in rep.inverse],
                          ["", "", "", "", "", "", "", ".3g", "d", ""]))
        out.append("")
    if rep.failures:
        out += ["## Failed cases", ""] + [f"- {f['label']}: {f['error']}" for f in rep.failures]
        out.append("")
    return "\n".join(out) + "\n"


def run_measures(spec: Spec, mfile: MeasureFile, case: LoadCase, level: int = 1,
                 nodes: tuple[str | int, ...] = ("paper5", "paper11"), sweeps: bool = True,
                 points: int = 7, scheduler: str | None = None, workers: int | None = None,
                 progress: Callable[[str], None] | None = None) -> MeasuresReport:
    """Indicators, every measure of ``mfile`` (formula and reference), its inverse problems
    and sensitivity sweeps; the cases run through :func:`compare.executor.run_cases`."""
    from compare.executor import run_cases

    t0 = time.perf_counter()
    speed = _speed(case)
    # the baseline runs here first: it fails loudly on a bad spec, and the pool's forked
    # workers inherit its assembled model
    base = MeasureCase(spec, case, None, level, tuple(nodes)).run()
    sweep_specs = (mfile.sweeps if mfile.sweeps is not None
                   else default_sweeps(spec, speed, points)) if sweeps else ()
    by_name = {m.name: m for m in mfile.measures}
    cases: list[Any] = [MeasureCase(spec, case, m, level, tuple(nodes)) for m in mfile.measures]
    cases += [InverseCase(spec, case, t, by_name[t.measure], level) for t in mfile.inverse]
    cases += [SweepCase(spec, case, sw, float(x), level) for sw in sweep_specs for x in sw.values]
    if sweep_specs:  # the sweeps' thermal-only model, also inherited by the workers
        reference_model(spec, level, elastic=False)
    outcomes = run_cases(run_case, cases, scheduler=scheduler, workers=workers,
                         progress=progress)
    measures, inverse, points, failures = [], [], [], []
    for c, o in zip(cases, outcomes, strict=True):
        if not o.ok:
            failures.append({"label": o.label, "error": o.error or "", "type": o.error_type or ""})
        if isinstance(c, MeasureCase):
            measures.append(measure_result(spec, case, c.measure, base, o.value if o.ok else None,
                                           None if o.ok else o.error))
        elif o.ok and isinstance(c, InverseCase):
            inverse.append(o.value)
        elif o.ok:
            points.append(o.value)
    return MeasuresReport(spec.name, case.name, level, mfile.path, speed,
                          surface_films(spec, speed), base["fem"], base["lumped"], measures,
                          inverse, points, failures, time.perf_counter() - t0)
