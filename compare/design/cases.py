"""Running design measures on the FEM reference.

**The reference** solves the modified spec (same mesh: only film coefficients change, so the
assembled operator is reused with the new coefficients, which is exact because K is affine
in them) and reads K_alpha from the volume-mean and the maximum rise
(:mod:`compare.design.stiffness`); lambda_ref = K_alpha1 / K_alpha2 at the same losses.

**Inverse problem** (:func:`solve_inverse`): the smallest size of a measure (A_M, or
alpha_M2) that reaches a target xi (or a target growth), by Brent's method on the FEM solve,
with the formula's prediction of the same size.

Sensitivity sweeps (Fig. 16) vary one size of a measure and solve each point."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from compare.design.formulas import lambda_from_xi, temperature_drop_K, xi_pct
from compare.design.measure import Measure, apply_measure, axial_length_m, formula_lambda, scale_axially
from compare.design.measure_file import InverseTarget, SweepSpec
from compare.design.stiffness import (
    Indicators,
    indicators,
    sum_alpha_A_W_K,
    surface_films,
)
from spindle.loads import LoadCase, TimeSeries
from spindle.spec import Spec

#: assembled reference models by everything but the film coefficients (reference_model),
#: with their original films; at most _MAX_MODELS, oldest dropped first
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
    model.thermal.set_coefficients(films=[(by_name[s.name], R, b) for s, R, b in base])
    model.spec = model.thermal.spec = spec
    return model


def case_speed_rpm(case: LoadCase) -> float:
    """The steady case's speed [rpm] (at t = 0)."""
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
    lam, G0, dG = formula_lambda(spec, measure, case_speed_rpm(case))
    return MeasureResult(measure, lam, G0, dG, base["fem"], after["fem"] if after else None,
                         base["lumped"], after["lumped"] if after else {}, error)


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

    speed = case_speed_rpm(case)
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
                             f"{'um' if use_growth else '%'} at {target.vary} = {hi:.4g}, "
                             "its size_max")
    size = float(brentq(f, lo, hi, xtol=1e-9 * hi, rtol=1e-6))
    v = value(size)
    return InverseResult(target, template.kind, True, size, size_formula, start, v, v,
                         size_max, len(values) + 1)


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
        G = sum_alpha_A_W_K(spec, case_speed_rpm(case))
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
