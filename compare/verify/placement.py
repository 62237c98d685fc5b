"""Which measured points best reconstruct the shaft temperature and the axial growth P1:
:func:`rank_sensors` orders candidate measuring points by how well their temperatures
reconstruct the targets over a FEM transient (snapshots every ``dt_s``): an affine
least-squares map (intercept + one gain per selected sensor) is fitted on the first 60 % of
the time samples and evaluated on the remaining 40 % (the validation window, which for
spl-16h holds the step down, the second rated hold, the run-out and the cool-down: an
extrapolation in time). ``greedy`` adds, one at a time, the candidate that most reduces the
training residual sum_g (RMS_g / tol_g)^2 over the target groups (temperatures weighted by the
1 K tolerance, growth readings by 1.5 µm); ``qr`` takes the first k pivots of a
column-pivoted QR of the centred candidate snapshot matrix (training window), which ignores
the targets.

SI inside (K, m, s); µm and °C appear only in output column names."""

from __future__ import annotations

import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from compare.verify.accuracy import (
    TOL_GROWTH_UM,
    TOL_TEMP_K,
)
from compare.verify.cases import check_level, check_positive, save_result, transient_default
from spindle.errors import InputError
from spindle.loads import LoadCase
from spindle.spec import Spec

#: share of the time samples (the first ones) the reconstruction is fitted on
TRAIN_FRACTION = 0.6


#: points along a part for a ``part:<name>`` target (finer than the 11-sensor arrays)
FINE_POINTS = 41


METHODS = ("greedy", "qr")


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
    from spindle.spec import SensorArray
    from spindle.spec_reader import array_sensors

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
        if t.kind == "growth":  # as ReferenceModel.transient (zeroed at the start), without
            f = res.functionals[f"growth:{t.names[0]}"]  # the centrifugal term
            cols.append(f - f[0])
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
        return save_result(self, Path(out), stem or f"ranking_{self.method}", pictures)


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
        check_level(reference_level, "--rank-level")
        check_positive(dt_s, "--rank-dt", "s")
        case = case if case is not None else transient_default(spec)
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
