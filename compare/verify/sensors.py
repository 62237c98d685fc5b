"""Sensors (issue 5, section 3): how many lumped nodes a spec needs, and which measured points
best reconstruct the shaft temperature and the axial growth P1.

1. :func:`choose_nodes` runs the lumped model for every node count N on every load case and
   compares it with the FEM reference exactly as the accuracy table does
   (:meth:`compare.verify.accuracy.AccuracyResult.errors`): the worst temperature error is the
   largest ``*_max_K`` entry (shaft and housing arrays, T1, T2; over the sensors, and over
   time for a transient), the growth error is ``P1_max_um``. The chosen N is the smallest
   whose worst temperature error is <= ``tol_temp_K`` AND whose P1 error is <=
   ``tol_growth_um`` on every case; None when no N does. The reference is the FEM P2
   solution on one level (default 2), not the Richardson extrapolation of ``study``.
2. :func:`rank_sensors` orders candidate measuring points by how well their temperatures
   reconstruct the targets over a FEM transient (snapshots every ``dt_s``): an affine
   least-squares map (intercept + one gain per selected sensor) is fitted on the first 60 %
   of the time samples and evaluated on the remaining 40 % (the validation window, which for
   spl-16h holds the step down, the second rated hold, the run-out and the cool-down: an
   extrapolation in time). ``greedy`` adds, one at a time, the candidate that most reduces
   the training residual sum_g (RMS_g / tol_g)^2 over the target groups (temperatures
   weighted by the 1 K tolerance, growth readings by 1.5 µm); ``qr`` takes the first k
   pivots of a column-pivoted QR of the centred candidate snapshot matrix (training window),
   which ignores the targets.
3. :func:`register` adds the ``spindle-verify sensors`` command.

SI inside (K, m, s); µm and °C appear only in output column names.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from compare.verify.accuracy import (
    NODES,
    TOL_GROWTH_UM,
    TOL_TEMP_K,
    AccuracyResult,
    fem_entry,
    lumped_entries,
)
from spindle.errors import InputError
from spindle.loads import LoadCase
from spindle.spec import Spec

#: share of the time samples (the first ones) the reconstruction is fitted on
TRAIN_FRACTION = 0.6
#: points along a part for a ``part:<name>`` target (finer than the 11-sensor arrays)
FINE_POINTS = 41
METHODS = ("greedy", "qr")
MAX_LEVEL = 6


# ============================================================================ load cases
def default_cases(spec: Spec) -> list[LoadCase]:
    """The two cases of :func:`compare.verify.study.study_cases`: the steady one (its duration set
    to 0 s, so it runs as a steady state) and the transient one (spl-16h, or the 8 h warm-up
    of a spec without a power balance)."""
    from compare.verify.study import study_cases

    steady, transient = study_cases(spec)
    return [replace(steady, duration_s=0.0), transient]


def load_cases(spec: Spec, names: Sequence[str], steady_cycles: bool = True) -> list[LoadCase]:
    """Load cases from shipped cycle names (or cycle files), through the spec's power balance
    (:func:`spindle.drive.cycle_load_case`). A cycle marked ``steady`` (``nominal``) becomes a
    steady case (duration 0 s) when ``steady_cycles``; every other cycle is a transient."""
    from spindle.cycles import load_cycle
    from spindle.drive import cycle_load_case

    out = []
    for name in names:
        cycle = load_cycle(name)
        case = cycle_load_case(spec, cycle)
        if cycle.steady and steady_cycles:
            case = replace(case, duration_s=0.0)
        out.append(case)
    return out


def _transient_default(spec: Spec) -> LoadCase:
    from compare.verify.study import study_cases

    return study_cases(spec)[1]


# ============================================================================ node count
@dataclass
class CaseCurve:
    """Errors of the lumped model against the FEM reference on one case, per node count."""

    name: str
    transient: bool
    reference_label: str
    nodes: list[int]
    masses: list[int]  # lumped states (masses) per N
    worst_temp_K: list[float]  # largest *_max_K of the accuracy row [K]
    p1_um: list[float]  # P1_max_um of the accuracy row [µm] (nan: the spec has no P1)
    rows: list[dict[str, float]]  # the full accuracy rows (AccuracyResult.errors)
    reference_runtime_s: float = 0.0

    @property
    def kind(self) -> str:
        return "transient" if self.transient else "steady"


def _meets(worst_K: float, p1_um: float, tol_temp_K: float, tol_growth_um: float) -> bool:
    return (not math.isnan(worst_K) and worst_K <= tol_temp_K
            and (math.isnan(p1_um) or p1_um <= tol_growth_um))


@dataclass
class NodeChoice:
    """The lumped node count a spec needs: error curves per case and the chosen N."""

    spec_name: str
    nodes: list[int]
    curves: list[CaseCurve]
    tol_temp_K: float
    tol_growth_um: float
    chosen: int | None
    reference_level: int
    dt_s: float
    runtime_s: float = 0.0

    def meets(self, n: int, tol_temp_K: float | None = None,
              tol_growth_um: float | None = None) -> bool:
        """Whether N = ``n`` meets both tolerances on every case."""
        tT = self.tol_temp_K if tol_temp_K is None else tol_temp_K
        tP = self.tol_growth_um if tol_growth_um is None else tol_growth_um
        i = self.nodes.index(n)
        return all(_meets(c.worst_temp_K[i], c.p1_um[i], tT, tP) for c in self.curves)

    def choose(self, tol_temp_K: float | None = None,
               tol_growth_um: float | None = None) -> int | None:
        """The smallest N meeting the tolerances [K, µm] on every case (default: this
        result's own); None if none does. Recomputes nothing."""
        return next((n for n in self.nodes if self.meets(n, tol_temp_K, tol_growth_um)), None)

    def worst(self, n: int) -> tuple[float, float]:
        """(worst temperature error [K], worst P1 error [µm]) of N = ``n`` over the cases
        (the P1 error is nan when the spec has no P1)."""
        i = self.nodes.index(n)
        temps = [c.worst_temp_K[i] for c in self.curves]
        p1 = [c.p1_um[i] for c in self.curves if not math.isnan(c.p1_um[i])]
        return max(temps), (max(p1) if p1 else math.nan)

    def best(self) -> int:
        """The N with the smallest error relative to the tolerances: the minimum over N of
        max(worst temperature error / tol_temp_K, P1 error / tol_growth_um) over the cases."""
        def score(n: int) -> float:
            t, p = self.worst(n)
            return max(t / self.tol_temp_K, 0.0 if math.isnan(p) else p / self.tol_growth_um)

        return min(self.nodes, key=score)

    def message(self) -> str:
        """One sentence: the chosen N, or why there is none and the best available."""
        def errs(n: int) -> str:
            t, p = self.worst(n)
            return f"{t:.3g} K" + ("" if math.isnan(p) else f" / {p:.3g} µm")

        has_p1 = any(not math.isnan(v) for c in self.curves for v in c.p1_um)
        tol = (f"{self.tol_temp_K:g} K and {self.tol_growth_um:g} µm" if has_p1
               else f"{self.tol_temp_K:g} K (the spec has no P1)")
        cases = ", ".join(c.name for c in self.curves)
        if self.chosen is not None:
            return (f"N = {self.chosen} is the smallest node count in {self.nodes} that meets "
                    f"{tol} on every case ({cases}); its worst errors: {errs(self.chosen)}")
        b = self.best()
        return (f"no N in {self.nodes} meets {'both tolerances' if has_p1 else 'the tolerance'} "
                f"({tol}) on every case ({cases}); "
                f"the best is N={b} with {errs(b)}")

    def table(self) -> dict[str, list]:
        """Long table: one row per case and N, with the whole accuracy row."""
        rows = []
        for c in self.curves:
            for i, n in enumerate(c.nodes):
                rows.append({"case": c.name, "kind": c.kind, "nodes": n, "masses": c.masses[i],
                             "worst_err_K": c.worst_temp_K[i], "err_P1_um": c.p1_um[i],
                             "meets_tolerances": _meets(c.worst_temp_K[i], c.p1_um[i],
                                                        self.tol_temp_K, self.tol_growth_um),
                             **c.rows[i]})
        keys = list(dict.fromkeys(k for r in rows for k in r))
        return {k: [r.get(k, math.nan) for r in rows] for k in keys}

    def to_pandas(self):
        """:meth:`table` as a DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.table())

    def text(self) -> str:
        """The error curves as a fixed-width table: N, masses, per case the worst temperature
        error [K] and the P1 error [µm], and whether N meets both tolerances everywhere."""
        labels = [f"{c.name} ({c.kind})" for c in self.curves]
        w = [max(len(lb), 23) - 10 for lb in labels]
        head = f"  {'N':>3} {'masses':>6}" + "".join(
            f" | {lb:<{wi + 10}}" for lb, wi in zip(labels, w, strict=True)) + " |"
        lines = [head, f"  {'':>3} {'':>6}" + "".join(
            f" | {'worst T err K':>{wi}} {'P1 err um':>9}" for wi in w) + " | meets"]
        for i, n in enumerate(self.nodes):
            row = f"  {n:3d} {self.curves[0].masses[i]:6d}"
            for c, wi in zip(self.curves, w, strict=True):
                p1 = "—" if math.isnan(c.p1_um[i]) else f"{c.p1_um[i]:.3f}"
                row += f" | {c.worst_temp_K[i]:{wi}.3f} {p1:>9}"
            mark = "yes" if self.meets(n) else "--"
            lines.append(row + f" | {mark}" + ("  <- chosen" if n == self.chosen else ""))
        return "\n".join(lines)

    def summary(self) -> dict:
        def clean(v):
            return None if isinstance(v, float) and math.isnan(v) else v

        b = self.best()
        bt, bp = self.worst(b)
        return {"spec": self.spec_name, "reference_level": self.reference_level,
                "dt_s": self.dt_s, "nodes": self.nodes,
                "tolerances": {"temperature_K": self.tol_temp_K,
                               "growth_um": self.tol_growth_um},
                "chosen_nodes": self.chosen,
                "best": {"nodes": b, "worst_err_K": bt, "err_P1_um": clean(bp)},
                "message": self.message(), "runtime_s": self.runtime_s,
                "cases": [{"case": c.name, "kind": c.kind, "reference": c.reference_label,
                           "reference_runtime_s": c.reference_runtime_s,
                           "worst_err_K": c.worst_temp_K,
                           "err_P1_um": [clean(v) for v in c.p1_um]} for c in self.curves]}

    def plot(self):
        """Error against N per case, log-log: worst temperature error [K] and, when the spec
        has P1, the P1 error [µm]; tolerance lines dashed, the chosen N marked. Returns the
        figure."""
        from matplotlib.ticker import NullLocator

        from spindle.plots import pyplot

        plt = pyplot()
        has_p1 = any(not math.isnan(v) for c in self.curves for v in c.p1_um)
        fig, axes = plt.subplots(1, 2 if has_p1 else 1, figsize=(11 if has_p1 else 6.5, 4.5),
                                 layout="constrained", squeeze=False)
        panels = [(axes[0, 0], "worst_temp_K", self.tol_temp_K, "worst temperature error [K]",
                   "K")]
        if has_p1:
            panels.append((axes[0, 1], "p1_um", self.tol_growth_um, "P1 error [µm]", "µm"))
        for ax, attr, tol, ylabel, unit in panels:
            for c, marker in zip(self.curves, "osD^v<>", strict=False):
                y = np.asarray(getattr(c, attr), dtype=float)
                ok = np.isfinite(y) & (y > 0)
                ax.loglog(np.asarray(c.nodes)[ok], y[ok], marker + "-",
                          label=f"{c.name} ({c.kind})")
            ax.axhline(tol, color="tab:red", ls="--", lw=1, label=f"tolerance {tol:g} {unit}")
            if self.chosen is not None:
                ax.axvline(self.chosen, color="tab:green", ls=":", lw=1.5,
                           label=f"chosen N = {self.chosen}")
            ax.set_xticks(self.nodes, [str(n) for n in self.nodes])
            ax.xaxis.set_minor_locator(NullLocator())
            ax.set_xlabel("lumped nodes N along shaft and housing")
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=8)
        verdict = (f"chosen N = {self.chosen}" if self.chosen is not None
                   else f"no N meets {self.tol_temp_K:g} K / {self.tol_growth_um:g} µm "
                        f"(best N = {self.best()})")
        fig.suptitle(f"{self.spec_name}: lumped model against FEM level {self.reference_level}; "
                     f"{verdict}", fontsize=10)
        return fig

    def save(self, out: Path, pictures: bool = True, stem: str = "nodes") -> list[Path]:
        """``<stem>.csv`` (the long table), ``<stem>.json`` (summary), ``<stem>.png``; each
        written atomically."""
        return _save_result(self, Path(out), stem, pictures)


def _save_result(result, out: Path, stem: str, pictures: bool) -> list[Path]:
    """``<stem>.csv`` (``result.table()``), ``<stem>.json`` (``result.summary()``) and
    ``<stem>.png`` (``result.plot()``), each written atomically."""
    from spindle.outputs import atomic_write, write_csv, write_json
    from spindle.plots import pyplot

    out.mkdir(parents=True, exist_ok=True)
    t = result.table()
    write_csv(out / f"{stem}.csv", list(t), zip(*t.values(), strict=True))
    write_json(out / f"{stem}.json", result.summary())
    files = [out / f"{stem}.csv", out / f"{stem}.json"]
    if pictures:
        fig = result.plot()
        atomic_write(out / f"{stem}.png", lambda tmp: fig.savefig(tmp, dpi=130))
        pyplot().close(fig)
        files.append(out / f"{stem}.png")
    return files


def _check_level(level: int, option: str) -> None:
    if not 0 <= int(level) <= MAX_LEVEL:
        raise InputError("command line", option, f"{level} is out of range",
                         f"give a level between 0 and {MAX_LEVEL}")


def _check_positive(value: float, option: str, unit: str) -> None:
    if not (math.isfinite(value) and value > 0):
        raise InputError("command line", option, f"{value:g} {unit} must be > 0",
                         f"give a positive value in {unit}")


def choose_nodes(spec: Spec, cases: Sequence[LoadCase] | None = None,
                 tol_temp_K: float = TOL_TEMP_K, tol_growth_um: float = TOL_GROWTH_UM,
                 nodes: Sequence[int] = NODES, reference_level: int | None = None,
                 dt_s: float = 60.0, progress: Callable[[str], None] | None = None
                 ) -> NodeChoice:
    """The smallest lumped node count N that meets both tolerances on every case.

    ``cases``: load cases; one with ``duration_s > 0`` runs as a transient (backward Euler
    FEM and exact zero-order-hold lumped runs on the same grid, step ``dt_s`` [s], from the
    ambient temperature at t = 0), otherwise as a steady state. Default: the steady and the
    transient case of :func:`compare.verify.study.study_cases`. ``tol_temp_K`` [K] bounds the worst
    sensor temperature error, ``tol_growth_um`` [µm] the P1 error (ignored for a spec
    without P1). ``reference_level``: the FEM P2 mesh level of the reference (default 2).
    ``progress`` receives one message per model run.
    """
    from spindle.loads import time_grid

    level = 2 if reference_level is None else int(reference_level)
    _check_level(level, "--level")
    _check_positive(tol_temp_K, "--tol-temp", "K")
    _check_positive(tol_growth_um, "--tol-growth", "µm")
    _check_positive(dt_s, "--dt", "s")
    nodes = sorted({int(n) for n in nodes})
    if not nodes or nodes[0] < 2:
        raise InputError("command line", "--nodes", f"{nodes} is empty or has a value < 2",
                         "give node counts >= 2, e.g. --nodes 2 3 5 7 11")
    cases = default_cases(spec) if cases is None else list(cases)
    if not cases:
        raise InputError("command line", "--cases", "no load case given",
                         "give at least one cycle name, e.g. --cases nominal spl-16h")
    t0 = time.perf_counter()
    curves = []
    for case in cases:
        transient = case.duration_s > 0
        dt = dt_s if transient else None
        T0 = float(case.T_ambient_K(0.0)) if transient else None
        if progress:
            progress(f"FEM level {level} {'transient' if transient else 'steady'} "
                     f"({case.name}{f', dt {dt_s:g} s' if transient else ''})")
        ref = fem_entry(spec, level, case, dt, T0)
        label = f"FEM P2 level {level}" + (f", backward Euler dt {dt_s:g} s" if transient else "")
        entries = lumped_entries(spec, case, nodes, dt, T0, progress)
        acc = AccuracyResult(spec, case.name, transient, ref, label, entries,
                             times_s=time_grid(case, dt_s) if transient else None,
                             tol_temp_K=tol_temp_K, tol_growth_um=tol_growth_um)
        rows = [acc.errors(e) for e in entries]
        worst = []
        for row in rows:
            temps = [v for k, v in row.items() if k.endswith("_max_K") and not math.isnan(v)]
            worst.append(max(temps) if temps else math.nan)
        curves.append(CaseCurve(case.name, transient, label, nodes, [e.size for e in entries],
                                worst, [row.get("P1_max_um", math.nan) for row in rows], rows,
                                ref.runtime_s))
    result = NodeChoice(spec.name, nodes, curves, tol_temp_K, tol_growth_um, None, level, dt_s,
                        time.perf_counter() - t0)
    result.chosen = result.choose()
    return result


# ============================================================================ sensor ranking
@dataclass
class Target:
    """A group of reconstructed quantities: temperatures at points (K) or a growth reading
    (m); ``scale`` is its tolerance in the same unit (the greedy weight)."""

    label: str
    kind: str  # "temperature" | "growth"
    names: list[str]
    points: dict[str, tuple[float, float]] = field(default_factory=dict)
    scale: float = 1.0

    @property
    def unit(self) -> str:
        return "K" if self.kind == "temperature" else "um"

    @property
    def factor(self) -> float:
        """SI value -> output unit (K stays K, m -> µm)."""
        return 1.0 if self.kind == "temperature" else 1e6


def _inside(spec: Spec, z: float, r: float) -> bool:
    return any(sec.contains(z, r) for _, sec in spec.sections())


def _fine_points(spec: Spec, part: str, count: int = FINE_POINTS) -> dict[str, tuple[float, float]]:
    """``count`` points evenly along ``part`` at the mid radius of its sections [m]."""
    from spindle.spec import SensorArray, array_sensors

    sensors = array_sensors(SensorArray(f"{part}_fine", part, count, "mid"), spec.part(part))
    return {s.name: (s.z, s.r) for s in sensors}


def _candidate_points(spec: Spec, candidates: Sequence[str] | Mapping[str, tuple[float, float]]
                      | None) -> dict[str, tuple[float, float]]:
    """Name -> (z, r) [m] of every candidate; names of temperature sensors or of sensor arrays
    (all their sensors), or a mapping to points of your own."""
    temps = {s.name: s for s in spec.temperature_sensors()}
    if candidates is None:
        return {n: (s.z, s.r) for n, s in temps.items()}
    if isinstance(candidates, Mapping):
        out = {}
        for n, (z, r) in candidates.items():
            if not _inside(spec, float(z), float(r)):
                raise InputError(spec.path, f"candidates.{n}", f"point (z = {z:g} m, r = {r:g} m)"
                                 " is outside every part", "give a point inside a section")
            out[str(n)] = (float(z), float(r))
        return out
    arrays = {a.name for a in spec.sensor_arrays}
    out = {}
    for n in candidates:
        if n in arrays:
            out.update({s.name: (s.z, s.r) for s in temps.values() if s.array == n})
        elif n in temps:
            out[n] = (temps[n].z, temps[n].r)
        else:
            raise InputError(spec.path, "--candidates", f"'{n}' is neither a temperature sensor "
                             "nor a sensor array of the spec",
                             f"use sensor or array names: {sorted(arrays) + sorted(temps)}")
    return out


def _resolve_targets(spec: Spec, targets: Sequence[str] | None, tol_temp_K: float,
                     tol_growth_um: float) -> list[Target]:
    """Target strings -> groups. A sensor array name (its sensors), a temperature sensor, a
    growth reading (P1, TCP), or ``part:<name>`` (FINE_POINTS points along the part at mid
    radius). ``None``: ("shaft", "P1"), those of them the spec has (the shaft array, or else
    fine points along the shaft-role part)."""
    temps = {s.name: s for s in spec.temperature_sensors()}
    arrays = {a.name for a in spec.sensor_arrays}
    growth = spec.growth_points()
    strict = targets is not None
    out: list[Target] = []
    for t in (targets if strict else ("shaft", "P1")):
        if t in arrays:
            sel = [s for s in temps.values() if s.array == t]
            out.append(Target(t, "temperature", [s.name for s in sel],
                              {s.name: (s.z, s.r) for s in sel}, tol_temp_K))
        elif t in temps:
            out.append(Target(t, "temperature", [t], {t: (temps[t].z, temps[t].r)},
                              tol_temp_K))
        elif t in growth:
            out.append(Target(t, "growth", [t], {}, tol_growth_um * 1e-6))
        elif t.startswith("part:") and t[5:] in {p.name for p in spec.parts}:
            pts = _fine_points(spec, t[5:])
            out.append(Target(f"{t[5:]}_fine", "temperature", list(pts), pts, tol_temp_K))
        elif not strict and t == "shaft" and spec.parts_with_role("shaft"):
            part = spec.parts_with_role("shaft")[0].name
            pts = _fine_points(spec, part)
            out.append(Target(f"{part}_fine", "temperature", list(pts), pts, tol_temp_K))
        elif strict:
            raise InputError(spec.path, "targets", f"'{t}' is not a sensor array, a temperature "
                             "sensor, a growth reading or part:<name> of the spec",
                             f"use one of {sorted(arrays) + sorted(temps) + sorted(growth)}")
    if not out:
        raise InputError(spec.path, "targets", "the spec has neither a shaft nor P1",
                         "name the targets explicitly")
    return out


@dataclass
class Snapshots:
    """Histories of a FEM transient: candidate temperatures X [K] (n_times x n_candidates)
    and target values Y (n_times x n_targets; K for temperatures, m for growth)."""

    times_s: np.ndarray
    candidates: list[str]
    points: dict[str, tuple[float, float]]
    X: np.ndarray
    targets: list[Target]
    Y: np.ndarray
    runtime_s: float = 0.0
    case_name: str = ""
    reference_level: int | None = None  # FEM level of the run (None: not from the FEM)
    dt_s: float = math.nan  # its time step [s]

    def columns(self) -> dict[str, list[int]]:
        """Target label -> its columns of Y."""
        out, k = {}, 0
        for t in self.targets:
            out[t.label] = list(range(k, k + len(t.names)))
            k += len(t.names)
        return out


def snapshots(spec: Spec, case: LoadCase, candidates: dict[str, tuple[float, float]],
              targets: list[Target], level: int = 1, dt_s: float = 300.0) -> Snapshots:
    """One FEM P2 backward-Euler transient of ``case`` from the ambient temperature, recording
    only the point values (rows of the probe matrix as functionals) and the growth readings
    (their adjoint gains, as :class:`reference.ReferenceModel` does): no fields are kept."""
    from reference import ReferenceModel

    t0 = time.perf_counter()
    growth = [t.names[0] for t in targets if t.kind == "growth"]
    model = ReferenceModel(spec, level, 2, elastic=bool(growth))
    th = model.thermal
    names, pts = th.sensor_points()
    own = dict(zip(names, zip(pts[0], pts[1], strict=True), strict=True))
    wanted = dict(candidates)
    for t in targets:
        for n, p in t.points.items():
            if n in wanted and not np.allclose(wanted[n], p, rtol=0, atol=1e-12):
                raise InputError(spec.path, f"candidates.{n}", "the name is used for two "
                                 "different points", "give each point its own name")
            wanted[n] = p
    extra = {n: p for n, p in wanted.items() if n not in own or
             not np.allclose(own[n], p, rtol=0, atol=1e-12)}
    functionals: dict[str, np.ndarray] = {}
    if extra:
        P = th.probe_matrix(np.array(list(extra.values())).T)
        for j, n in enumerate(extra):
            functionals[f"point:{n}"] = np.asarray(P[j].todense()).ravel()
    gains = {g: model.elastic.gain(g)[0] for g in growth}
    functionals.update({f"growth:{g}": v for g, v in gains.items()})
    res = th.solve_transient(case, dt_s, 1.0, float(case.T_ambient_K(0.0)),
                             functionals=functionals)

    def point(n: str) -> np.ndarray:
        if n in extra:
            return res.functionals[f"point:{n}"]
        return res.sensor_K[:, res.names.index(n)]

    X = np.column_stack([point(n) for n in candidates])
    cols = []
    for t in targets:
        if t.kind == "growth":  # as ReferenceModel.transient, without the centrifugal term
            g = gains[t.names[0]]
            cols.append(res.functionals[f"growth:{t.names[0]}"] - model.elastic.T_ref * g.sum())
        else:
            cols.extend(point(n) for n in t.names)
    return Snapshots(res.times_s, list(candidates), dict(candidates), X, targets,
                     np.column_stack(cols), time.perf_counter() - t0, case.name, level, dt_s)


def _fit(X: np.ndarray, Y: np.ndarray, cols: Sequence[int], n_train: int
         ) -> tuple[np.ndarray, np.ndarray]:
    """Affine least squares from X[:, cols] to Y on the first n_train rows; residuals on the
    training rows and on the rest."""
    mx, my = X[:n_train].mean(axis=0), Y[:n_train].mean(axis=0)
    A = np.column_stack([np.ones(len(X)), X[:, list(cols)] - mx[list(cols)]])
    coef, *_ = np.linalg.lstsq(A[:n_train], Y[:n_train] - my, rcond=None)
    R = A @ coef + my - Y
    return R[:n_train], R[n_train:]


def _score(R: np.ndarray, groups: Sequence[tuple[list[int], float]]) -> float:
    return float(sum(np.mean(R[:, c] ** 2) / s**2 for c, s in groups))


def select(X: np.ndarray, Y: np.ndarray, k_max: int, method: str, n_train: int,
           groups: Sequence[tuple[list[int], float]]) -> list[int]:
    """Indices of the first ``k_max`` candidates (columns of X) in the order chosen.

    ``greedy``: forward selection on the training rows minimising sum over the target groups
    (columns of Y, scale) of mean(residual^2) / scale^2. ``qr``: the first pivots of
    ``scipy.linalg.qr(pivoting=True)`` of X's training rows, centred per column (all
    candidates are temperatures in K, so no per-column scaling: standardising would promote
    nearly constant points).
    """
    if method == "qr":
        from scipy.linalg import qr

        Xc = X[:n_train] - X[:n_train].mean(axis=0)
        _, piv = qr(Xc, mode="r", pivoting=True)
        return [int(j) for j in piv[:k_max]]
    if method != "greedy":
        raise InputError("command line", "--method", f"'{method}' is unknown",
                         f"use one of {', '.join(METHODS)}")
    chosen: list[int] = []
    for _ in range(k_max):
        best, best_j = math.inf, -1
        for j in range(X.shape[1]):
            if j in chosen:
                continue
            s = _score(_fit(X, Y, [*chosen, j], n_train)[0], groups)
            if s < best:
                best, best_j = s, j
        chosen.append(best_j)
    return chosen


@dataclass
class SensorRanking:
    """Candidate points in the order a method picks them, and how the reconstruction error
    of each target group falls with the number k of points used (k = 1 .. len(selected)).

    Curves are in SI per group (K for temperatures, m for growth): RMS and max over the
    group's quantities and the training (first 60 %) or validation (last 40 %) samples.
    """

    spec_name: str
    case_name: str
    method: str
    reference_level: int
    dt_s: float
    candidates: list[str]
    points: dict[str, tuple[float, float]]  # candidate -> (z, r) [m]
    targets: list[Target]
    selected: list[str]
    train_rms: dict[str, np.ndarray]
    train_max: dict[str, np.ndarray]
    valid_rms: dict[str, np.ndarray]
    valid_max: dict[str, np.ndarray]
    n_train: int
    n_valid: int
    split_time_s: float  # first validation sample [s]
    tol_temp_K: float = TOL_TEMP_K
    tol_growth_um: float = TOL_GROWTH_UM
    runtime_s: float = 0.0
    snap: Snapshots | None = field(default=None, repr=False)  # reuse: rank_sensors(snap=...)

    @property
    def k(self) -> list[int]:
        return list(range(1, len(self.selected) + 1))

    def table(self) -> dict[str, list]:
        """One row per k: the k-th sensor and its (z, r) [m], then per target group the
        validation RMS and max errors (``err_<group>_rms_K`` / ``_um``) and the same on the
        training window (``train_err_...``)."""
        t: dict[str, list] = {"k": self.k, "sensor": list(self.selected),
                              "z_m": [self.points[s][0] for s in self.selected],
                              "r_m": [self.points[s][1] for s in self.selected]}
        for g in self.targets:
            for pre, rms, mx in (("err", self.valid_rms, self.valid_max),
                                 ("train_err", self.train_rms, self.train_max)):
                t[f"{pre}_{g.label}_rms_{g.unit}"] = [float(v) * g.factor for v in rms[g.label]]
                t[f"{pre}_{g.label}_max_{g.unit}"] = [float(v) * g.factor for v in mx[g.label]]
        return t

    def to_pandas(self):
        """:meth:`table` as a DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.table())

    def text(self, ks: Sequence[int] | None = None) -> str:
        """Fixed-width table of :meth:`table` (validation errors), rows ``ks`` (default all)."""
        t = self.table()
        cols = [c for c in t if c.startswith("err_")]
        lines = [f"  {'k':>2} {'sensor':<16} {'z_mm':>7} {'r_mm':>6} "
                 + " ".join(f"{c[4:]:>16}" for c in cols)]
        for i, k in enumerate(self.k):
            if ks is not None and k not in ks:
                continue
            lines.append(f"  {k:2d} {t['sensor'][i]:<16} {t['z_m'][i] * 1e3:7.1f} "
                         f"{t['r_m'][i] * 1e3:6.2f} "
                         + " ".join(f"{t[c][i]:16.4g}" for c in cols))
        return "\n".join(lines)

    def summary(self) -> dict:
        return {"spec": self.spec_name, "case": self.case_name, "method": self.method,
                "reference": f"FEM P2 level {self.reference_level}, backward Euler dt "
                             f"{self.dt_s:g} s",
                "fit": f"affine least squares on the first {self.n_train} samples "
                       f"({100 * TRAIN_FRACTION:g} %); errors on the last {self.n_valid} "
                       f"(from t = {self.split_time_s / 3600:.2f} h)",
                "candidates": {n: {"z_m": p[0], "r_m": p[1]} for n, p in self.points.items()},
                "targets": {g.label: {"unit": g.unit, "quantities": g.names}
                            for g in self.targets},
                "runtime_s": self.runtime_s, "table": self.table()}

    def plot(self):
        """Validation (solid) and training (dashed) RMS error against k, one panel per unit
        (temperature targets [K], growth readings [µm]), tolerances dashed red. Returns the
        figure."""
        from spindle.plots import pyplot

        plt = pyplot()
        units = list(dict.fromkeys(g.unit for g in self.targets))
        fig, axes = plt.subplots(1, len(units), figsize=(5.5 * len(units) + 1, 4.5),
                                 layout="constrained", squeeze=False)
        k = np.array(self.k)
        for ax, unit in zip(axes[0], units, strict=True):
            tol = self.tol_temp_K if unit == "K" else self.tol_growth_um
            floor = 1e-4 * tol
            for g in (g for g in self.targets if g.unit == unit):
                for curve, style, what in ((self.valid_rms, "o-", "validation RMS"),
                                           (self.valid_max, "^:", "validation max"),
                                           (self.train_rms, "s--", "training RMS")):
                    y = np.maximum(np.asarray(curve[g.label]) * g.factor, floor)
                    ax.semilogy(k, y, style, ms=4, label=f"{g.label}: {what}")
            ax.axhline(tol, color="tab:red", ls="--", lw=1,
                       label=f"tolerance {tol:g} {'µm' if unit == 'um' else unit}")
            ax.set_xticks(k)
            ax.set_xticklabels([f"{i}\n{s}" for i, s in zip(k, self.selected, strict=True)],
                               fontsize=6, rotation=90)
            ax.set_xlabel("k: sensors used (the k-th added)")
            ax.set_ylabel(f"reconstruction error [{'µm' if unit == 'um' else unit}]"
                          f" (floored at {floor:g})")
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=7)
        fig.suptitle(f"{self.spec_name}, {self.case_name}: {self.method} sensor ranking; fit on "
                     f"the first {100 * TRAIN_FRACTION:g} % of the samples, validated on the rest "
                     f"(from {self.split_time_s / 3600:.1f} h)", fontsize=9)
        return fig

    def save(self, out: Path, pictures: bool = True, stem: str | None = None) -> list[Path]:
        """``ranking_<method>.csv``, ``.json`` and ``.png`` (atomic writes)."""
        return _save_result(self, Path(out), stem or f"ranking_{self.method}", pictures)


def rank_snapshots(snap: Snapshots, k_max: int = 11, method: str = "greedy",
                   train_fraction: float = TRAIN_FRACTION) -> tuple[list[int], dict]:
    """Order of the candidates (column indices of ``snap.X``) and the error curves per target
    group (SI) for k = 1 .. k_max: the selection and the fits of :func:`select` and
    :func:`_fit`, on the first ``train_fraction`` of the samples."""
    n = len(snap.times_s)
    n_train = int(math.floor(train_fraction * n))
    k_max = min(int(k_max), snap.X.shape[1])
    if n_train < k_max + 2 or n - n_train < 1:
        raise InputError("command line", "--rank", f"{n} time samples are too few to fit "
                         f"{k_max} sensors on {100 * train_fraction:g} % of them",
                         "use a smaller time step or fewer sensors")
    cols = snap.columns()
    groups = [(cols[g.label], g.scale) for g in snap.targets]
    order = select(snap.X, snap.Y, k_max, method, n_train, groups)
    curves: dict[str, dict[str, list[float]]] = {
        key: {g.label: [] for g in snap.targets}
        for key in ("train_rms", "train_max", "valid_rms", "valid_max")}
    for k in range(1, k_max + 1):
        r_tr, r_va = _fit(snap.X, snap.Y, order[:k], n_train)
        for g in snap.targets:
            c = cols[g.label]
            curves["train_rms"][g.label].append(float(np.sqrt(np.mean(r_tr[:, c] ** 2))))
            curves["train_max"][g.label].append(float(np.max(np.abs(r_tr[:, c]))))
            curves["valid_rms"][g.label].append(float(np.sqrt(np.mean(r_va[:, c] ** 2))))
            curves["valid_max"][g.label].append(float(np.max(np.abs(r_va[:, c]))))
    out = {key: {g: np.array(v) for g, v in d.items()} for key, d in curves.items()}
    out["n_train"], out["n_valid"] = n_train, n - n_train
    out["split_time_s"] = float(snap.times_s[n_train])
    return order, out


def rank_sensors(spec: Spec, case: LoadCase | None = None, k_max: int = 11,
                 candidates: Sequence[str] | Mapping[str, tuple[float, float]] | None = None,
                 targets: Sequence[str] | None = None, method: str = "greedy",
                 reference_level: int = 1, dt_s: float = 300.0,
                 tol_temp_K: float = TOL_TEMP_K, tol_growth_um: float = TOL_GROWTH_UM,
                 snap: Snapshots | None = None) -> SensorRanking:
    """Rank measuring points by how well they reconstruct the targets over a FEM transient.

    ``case``: a transient load case (default: the transient of
    :func:`compare.verify.study.study_cases`, spl-16h or the 8 h warm-up). ``candidates``: sensor
    or array names of the spec, or a mapping name -> (z, r) [m]; default every temperature
    sensor of the spec. ``targets``: sensor arrays, temperature sensors, growth readings or
    ``part:<name>``; default ("shaft", "P1"), those the spec has. ``method``: "greedy" or
    "qr". FEM P2 on ``reference_level``, backward Euler with step ``dt_s`` [s]. The
    tolerances [K, µm] weight the target groups in the greedy criterion and are drawn in the
    plot. ``snap``: the snapshots of an earlier ranking (``ranking.snap``), to rank the same
    data with the other method without a new FEM run (case, candidates, targets, level and
    dt_s are then those of the snapshots).
    """
    if method not in METHODS:
        raise InputError("command line", "--method", f"'{method}' is unknown",
                         f"use one of {', '.join(METHODS)}")
    if int(k_max) < 1:
        raise InputError("command line", "--rank", f"{k_max} sensors", "give --rank K >= 1")
    t0 = time.perf_counter()
    reused = snap is not None
    if snap is None:
        _check_level(reference_level, "--rank-level")
        _check_positive(dt_s, "--rank-dt", "s")
        case = case if case is not None else _transient_default(spec)
        if case.duration_s <= 0:
            raise InputError("command line", "--rank-case", f"'{case.name}' has no duration",
                             "rank on a transient case (a cycle with a duration)")
        cand = _candidate_points(spec, candidates)
        tgts = _resolve_targets(spec, targets, tol_temp_K, tol_growth_um)
        snap = snapshots(spec, case, cand, tgts, reference_level, dt_s)
    order, c = rank_snapshots(snap, k_max, method)
    level = reference_level if snap.reference_level is None else snap.reference_level
    dt = dt_s if math.isnan(snap.dt_s) else snap.dt_s
    return SensorRanking(spec.name, snap.case_name or "given snapshots", method, level, dt,
                         list(snap.candidates), dict(snap.points), list(snap.targets),
                         [snap.candidates[j] for j in order], c["train_rms"], c["train_max"],
                         c["valid_rms"], c["valid_max"], c["n_train"], c["n_valid"],
                         c["split_time_s"], tol_temp_K, tol_growth_um,
                         time.perf_counter() - t0 + (snap.runtime_s if reused else 0.0), snap)


# ============================================================================ command line
def run(args: argparse.Namespace) -> int:
    """``spindle-verify sensors``: the node count, and with ``--rank K`` the sensor ranking.
    Returns the exit status (0; bad input raises :class:`spindle.errors.InputError`)."""
    from spindle.outputs import output_dir
    from spindle.spec import load_spec

    spec = load_spec(args.spec)
    quiet = args.quiet

    def say(msg: str) -> None:
        if not quiet:
            print(f"  ... {msg}", file=sys.stderr, flush=True)

    cases = load_cases(spec, args.cases) if args.cases else None
    if args.rank is not None and args.rank < 1:
        raise InputError("command line", "--rank", f"{args.rank} sensors", "give --rank K >= 1")
    choice = choose_nodes(spec, cases, args.tol_temp, args.tol_growth, args.nodes, args.level,
                          args.dt, say)
    ranking = None
    if args.rank is not None:
        rank_case = (load_cases(spec, [args.rank_case], steady_cycles=False)[0]
                     if args.rank_case else None)
        say(f"FEM level {args.rank_level} transient for the sensor ranking "
            f"(dt {args.rank_dt:g} s)")
        ranking = rank_sensors(spec, rank_case, args.rank, args.candidates, None, args.method,
                               args.rank_level, args.rank_dt, args.tol_temp, args.tol_growth)
    out = Path(args.out or f"results/{spec.name}/sensors")
    with output_dir(out, inputs=[spec.path]) as tmp:
        files = choice.save(tmp, pictures=not args.no_pictures)
        if ranking is not None:
            files += ranking.save(tmp, pictures=not args.no_pictures)
    print(f"{spec.name}: lumped node count against {choice.curves[0].reference_label.split(',')[0]}"
          f" ({choice.runtime_s:.1f} s)")
    for c in choice.curves:
        print(f"  case {c.name}: {c.kind}, reference {c.reference_label}")
    print(choice.text())
    print(choice.message())
    if ranking is not None:
        print(f"sensor ranking ({ranking.method}, {ranking.case_name}, FEM level "
              f"{ranking.reference_level}, dt {ranking.dt_s:g} s): affine least squares fitted "
              f"on the first {ranking.n_train} samples ({100 * TRAIN_FRACTION:g} %), errors on "
              f"the last {ranking.n_valid} (from t = {ranking.split_time_s / 3600:.2f} h):")
        print(ranking.text())
    print("wrote " + ", ".join(str(out / f.name) for f in files))
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``sensors`` command to ``subparsers`` (from ``add_subparsers``); its
    ``func`` is :func:`run`."""
    p = subparsers.add_parser(
        "sensors", help="the lumped node count that meets the tolerances on every case, and "
                        "a ranking of sensor positions that reconstruct shaft temperature and P1")
    p.add_argument("spec", metavar="SPEC")
    p.add_argument("--tol-temp", type=float, default=TOL_TEMP_K,
                   help=f"tolerance on the worst sensor temperature error [K] (default "
                        f"{TOL_TEMP_K:g})")
    p.add_argument("--tol-growth", type=float, default=TOL_GROWTH_UM,
                   help=f"tolerance on the P1 error [um] (default {TOL_GROWTH_UM:g})")
    p.add_argument("--nodes", type=int, nargs="+", default=list(NODES),
                   help="lumped node counts (default " + " ".join(map(str, NODES)) + ")")
    p.add_argument("--cases", nargs="+", metavar="CYCLE",
                   help="shipped cycle names or cycle files; a steady cycle (nominal) is a "
                        "steady state, the others transients (default: the study's two cases, "
                        "e.g. nominal and spl-16h)")
    p.add_argument("--level", type=int, default=2,
                   help="FEM level of the reference for the node count (default 2)")
    p.add_argument("--dt", type=float, default=60.0,
                   help="time step of the transient cases [s] (default 60)")
    p.add_argument("--rank", type=int, metavar="K",
                   help="also rank the first K sensor positions")
    p.add_argument("--method", choices=METHODS, default="greedy",
                   help="ranking: greedy forward selection (default) or pivoted QR")
    p.add_argument("--candidates", nargs="+", metavar="NAME",
                   help="ranking: candidate sensors or arrays (default: every temperature "
                        "sensor of the spec)")
    p.add_argument("--rank-case", metavar="CYCLE",
                   help="ranking: transient cycle (default: the study's transient case)")
    p.add_argument("--rank-level", type=int, default=1,
                   help="ranking: FEM level (default 1)")
    p.add_argument("--rank-dt", type=float, default=300.0,
                   help="ranking: time step [s] (default 300)")
    p.add_argument("--out", help="output folder (default results/<spec>/sensors)")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNGs")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=run)
    return p
