"""Signature tests on a bench run's raw samples: the machinery the effects' own tests share.

On a spindle its spec describes only approximately, the calibrated base model misses the
bench by tenths of a kelvin to kelvins over hours. An effect whose open-loop signature is
slow hides in that misfit or is imitated by it. Some effects also leave a mark that no
thermal mass, film or contact can make, and that can be read from the raw samples without
the open-loop fit: what a channel does within minutes of a speed step, or what the drive's
power does at constant speed. This module holds what those tests share:

- :class:`EventTest`, one test's estimate, standard error, z and one-sided p;
- the speed steps of a run (:func:`speed_steps`), straight lines before and after a step
  (:func:`line_fit`), weighted regressions through the origin (:func:`through_origin`);
- the onset ratio of a channel after the steps (:func:`onset_ratio`) and the base model's own
  onsets (:func:`model_onsets`);
- the constant-speed segments of the power (:func:`segments`);
- :class:`Context`: the run, the calibrated base model and the criteria, with the shared
  pieces computed once; each effect's :meth:`~compare.fit.effects.base.Effect.signature`
  reads it.

Units: times in s, speeds in rpm, P1 in m internally (µm in fields named ``_um``),
temperatures in K, power in W.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from lumped.elastic import first_order_lag


@dataclass(frozen=True)
class OnsetScale:
    """Windows around a step [s] for an onset ratio: the slope before, early and late after."""

    name: str
    before_s: tuple[float, float]
    early_s: tuple[float, float]
    late_s: tuple[float, float]

    @property
    def quiet_s(self) -> tuple[float, float]:
        """The window around a step that must hold no other step."""
        return self.before_s[0], self.late_s[1]


@dataclass(frozen=True)
class Step:
    """A speed step at ``t_s`` [s] from ``n_before`` to ``n_after`` [rpm]."""

    t_s: float
    n_before_rpm: float
    n_after_rpm: float

    @property
    def dn2_krpm2(self) -> float:
        return (self.n_after_rpm ** 2 - self.n_before_rpm ** 2) / 1e6


@dataclass
class EventTest:
    """One signature test: estimate, standard error, z, one-sided p, and its per-step data."""

    effect: str
    channel: str
    estimate: float
    se: float
    z: float
    p_value: float
    n_steps: int
    unit: str
    meaning: str
    reference: float | None = None  # the model's onset ratio (lag tests)
    per_step: list[dict] = field(default_factory=list)
    #: the effect's parameter as the test reads it: name, value, 95 % interval (own units)
    parameter: dict | None = None
    #: lag tests: the onset scale reported, and the test at every scale
    scale: str | None = None
    scales: list[dict] = field(default_factory=list)
    #: the run holds the test's conditions, but its log is too sparse to read them (a power
    #: logged every 5 min has no level 2-6 min after a speed step): unlike a test that does
    #: not apply, it cannot tell the effect from the base's misfit (select.signature_outcome)
    unreadable: bool = False

    @property
    def applies(self) -> bool:
        """Whether the run allowed the test (enough steps, segments, plateaus)."""
        return bool(np.isfinite(self.p_value))

    def significant(self, alpha: float) -> bool:
        return bool(self.applies and self.p_value < alpha)

    def to_dict(self) -> dict:
        return {"effect": self.effect, "channel": self.channel, "estimate": self.estimate,
                "se": self.se, "z": self.z, "p_value": self.p_value, "n_steps": self.n_steps,
                "unit": self.unit, "meaning": self.meaning, "model_reference": self.reference,
                "parameter": self.parameter, "scale": self.scale, "scales": self.scales,
                "unreadable": self.unreadable}


def speed_steps(t_s: np.ndarray, speed_rpm: np.ndarray, criteria,
                quiet_s: tuple[float, float]) -> list[Step]:
    """Speed steps (beyond ``criteria.step_rpm``) of a logged run with no other step in the
    ``quiet_s`` window around them (NaN speeds are skipped; the step instant is midway
    between the two samples; changes within ``criteria.step_ramp_s`` are one step)."""
    ok = np.isfinite(speed_rpm)
    t, n = np.asarray(t_s, float)[ok], np.asarray(speed_rpm, float)[ok]
    idx = np.where(np.abs(np.diff(n)) > criteria.step_rpm)[0]
    groups: list[list[int]] = []
    for i in idx:
        if groups and t[i] - t[groups[-1][-1] + 1] <= criteria.step_ramp_s:
            groups[-1].append(i)
        else:
            groups.append([i])
    steps = [Step(float(0.5 * (t[g[0]] + t[g[-1] + 1])), float(n[g[0]]), float(n[g[-1] + 1]))
             for g in groups]
    times = np.array([s.t_s for s in steps])
    return [s for s in steps if not np.any((times != s.t_s) & (times > s.t_s + quiet_s[0])
                                           & (times < s.t_s + quiet_s[1]))]


def line_fit(t: np.ndarray, y: np.ndarray, window: tuple[float, float], t0: float, criteria
             ) -> tuple[float, float, float, float] | None:
    """(value at t0, slope, se of value, se of slope) of a straight line through the samples
    in ``t0 + window``; None with too few samples or too short a span (``criteria``)."""
    m = (t >= t0 + window[0]) & (t <= t0 + window[1]) & np.isfinite(y)
    if (m.sum() < criteria.line_min_samples
            or np.ptp(t[m]) < criteria.line_min_span * (window[1] - window[0])):
        return None
    x = t[m] - t0
    A = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(A, y[m], rcond=None)
    r = y[m] - A @ coef
    s2 = float(r @ r) / max(len(x) - 2, 1)
    cov = s2 * np.linalg.inv(A.T @ A)
    return float(coef[0]), float(coef[1]), math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])


def through_origin(y: np.ndarray, x: np.ndarray, se: np.ndarray) -> tuple[float, float]:
    """Weighted least squares of y = b x: (b, se of b), inflated by the reduced chi-square
    when the points scatter more than their own errors say."""
    w = 1.0 / np.maximum(se, 1e-300) ** 2
    sxx = float(np.sum(w * x * x))
    if sxx <= 0:
        return math.nan, math.nan
    b = float(np.sum(w * x * y)) / sxx
    dof = len(x) - 1
    chi2 = float(np.sum(w * (y - b * x) ** 2)) / dof if dof > 0 else 1.0
    return b, math.sqrt(max(chi2, 1.0) / sxx)


def onset_ratio(t_s: np.ndarray, y: np.ndarray, steps: list[Step], scale: OnsetScale,
                criteria) -> tuple[float, float, list[dict]]:
    """(ratio, se, per step) of the change of slope early after the steps to that late after
    them (``scale``'s windows), regressed over the steps (units of y cancel)."""
    early, late, se_e, rows = [], [], [], []
    for s in steps:
        b, e, la = (line_fit(t_s, y, w, s.t_s, criteria)
                    for w in (scale.before_s, scale.early_s, scale.late_s))
        if b is None or e is None or la is None:
            continue
        early.append(e[1] - b[1])
        late.append(la[1] - b[1])
        se_e.append(math.hypot(e[3], b[3]))
        rows.append({"t_s": s.t_s, "early_slope_change": e[1] - b[1],
                     "late_slope_change": la[1] - b[1]})
    if len(early) < 2:
        return math.nan, math.nan, rows
    x, yv, se = np.array(late), np.array(early), np.array(se_e)
    keep = np.abs(x) > criteria.onset_min_late_z * se
    if keep.sum() < 2:
        return math.nan, math.nan, rows
    ratio, err = through_origin(yv[keep], x[keep], np.maximum(se[keep], 1e-12))
    return ratio, err, rows


def fine_inputs(inputs, sub: int = 6):
    """``inputs`` (compare.fit.greybox.Inputs) with every interval cut into ``sub`` equal
    ones holding the same values: the model's response between its grid points."""
    g = inputs.grid_s
    pieces = [np.linspace(a, b, sub + 1)[:-1] for a, b in zip(g[:-1], g[1:], strict=True)]
    fine = np.concatenate([*pieces, g[-1:]])

    def rep(v: np.ndarray) -> np.ndarray:
        return np.repeat(np.asarray(v), sub)

    return replace(inputs, grid_s=fine, speed_rpm=rep(inputs.speed_rpm),
                   power_kW=rep(inputs.power_kW), load_torque_Nm=rep(inputs.load_torque_Nm),
                   T_env_K=rep(inputs.T_env_K), T_coolant_K=rep(inputs.T_coolant_K))


@dataclass
class ModelOnsets:
    """The base model's response on a fine grid at its own speed steps: ``ratios`` per channel
    and scale name, and what :meth:`lag_for_ratio` needs."""

    t_s: np.ndarray
    outputs: dict[str, np.ndarray]
    steps: dict[str, list[Step]]
    ratios: dict[str, dict[str, float]]
    criteria: object  # compare.fit.criteria.Criteria
    #: the ratios' standard errors (their scatter over the model's steps)
    ratio_se: dict[str, dict[str, float]] = field(default_factory=dict)

    def lag_for_ratio(self, channel: str, ratio: float, scale: OnsetScale) -> float:
        """The first-order lag time constant [s] that brings the model's onset ratio of
        ``channel`` at ``scale`` down to ``ratio`` (0 when it is already at or below; the
        grid's longest lag when even that does not)."""
        grid = self.criteria.lag_grid_s
        ratios = [self.ratios[channel][scale.name]]
        for tau in grid[1:]:
            y = first_order_lag(self.t_s, self.outputs[channel], tau)
            ratios.append(onset_ratio(self.t_s, y, self.steps[scale.name], scale, self.criteria)[0])
        r = np.array(ratios)
        if not np.isfinite(ratio) or ratio >= r[0]:
            return 0.0
        below = np.where(np.isfinite(r) & (r <= ratio))[0]
        if len(below) == 0:
            return float(grid[-1])
        k = int(below[0])
        # log-linear between the grid's neighbours
        t0, t1 = max(grid[k - 1], 1.0), grid[k]
        f = (r[k - 1] - ratio) / (r[k - 1] - r[k]) if r[k - 1] != r[k] else 1.0
        return float(math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))))


def model_onsets(gb, theta: dict[str, float], channels, criteria, sub: int = 6) -> ModelOnsets:
    """The onset ratio each channel of the grey box ``gb`` (base model, parameters ``theta``)
    shows at its own speed steps, simulated on a grid ``sub`` times finer than the fit's."""
    model = gb.on_inputs(fine_inputs(gb.inputs, sub))
    out = model.simulate(theta)
    t = model.inputs.grid_s
    n_end = np.concatenate([[model.inputs.speed_rpm[0]], model.inputs.speed_rpm])
    steps = {sc.name: speed_steps(t, n_end, criteria, sc.quiet_s) for sc in criteria.onset_scales}
    fits = {c: {sc.name: onset_ratio(t, out[c], steps[sc.name], sc, criteria)[:2]
                for sc in criteria.onset_scales} for c in channels if c in out}
    ratios = {c: {k: v[0] for k, v in f.items()} for c, f in fits.items()}
    ratio_se = {c: {k: v[1] for k, v in f.items()} for c, f in fits.items()}
    return ModelOnsets(t, {c: out[c] for c in ratios}, steps, ratios, criteria, ratio_se)


@dataclass(frozen=True)
class Segment:
    """A constant-speed stretch of a run: start and end [s], speed [rpm], mean process torque
    [N m], its power samples (times from the segment's start [s], power [W]), and whether it
    turns without load."""

    t0_s: float
    t1_s: float
    speed_rpm: float
    torque_Nm: float
    t_s: np.ndarray
    power_W: np.ndarray
    no_load: bool
    min_samples: int  # a window's mean needs this many (Criteria.window_min_samples)

    @property
    def duration_s(self) -> float:
        return self.t1_s - self.t0_s

    def mean_W(self, lo_s: float, hi_s: float) -> tuple[float, float, int]:
        """(mean, its standard error, samples) of the power over [lo, hi) from the start."""
        m = (self.t_s >= lo_s) & (self.t_s < hi_s)
        p = self.power_W[m]
        if len(p) < self.min_samples:
            return math.nan, math.nan, len(p)
        return float(p.mean()), float(p.std(ddof=1) / math.sqrt(len(p))), len(p)

    def settled_W(self) -> tuple[float, float]:
        """(mean, standard error) of the power over the segment's second half."""
        return self.mean_W(0.5 * self.duration_s, self.duration_s + 1.0)[:2]


def segments(run, criteria) -> list[Segment]:
    """Constant-speed segments of a bench run: cut where the logged speed changes beyond the
    drive's scatter band between samples (``criteria.speed_band_rpm`` or
    ``criteria.speed_band_rel`` of the speed, the larger)."""
    t = np.asarray(run.time_s, dtype=float)
    n = np.asarray(run.columns["speed_rpm"], dtype=float)
    P = np.asarray(run.columns["power_kW"], dtype=float) * 1e3
    M = (np.asarray(run.columns["load_torque_Nm"], dtype=float)
         if "load_torque_Nm" in run.columns else np.zeros_like(t))
    ok = np.isfinite(n)
    tn, nn = t[ok], n[ok]
    band = np.maximum(criteria.speed_band_rpm,
                      criteria.speed_band_rel * np.maximum(np.abs(nn[1:]), np.abs(nn[:-1])))
    cuts = tn[1:][np.abs(np.diff(nn)) > band]
    edges = np.concatenate([[t[0]], cuts, [t[-1] + 1e-9]])
    out = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        m = (t >= a) & (t < b)
        if m.sum() < criteria.window_min_samples:
            continue
        pm = m & np.isfinite(P)
        mm = m & np.isfinite(M)
        speed = float(np.nanmedian(n[m]))
        torque = float(M[mm].mean()) if mm.any() else 0.0
        out.append(Segment(float(a), float(b), speed, torque, t[pm] - a, P[pm],
                           speed >= criteria.moving_rpm and abs(torque) <= criteria.no_load_Nm,
                           criteria.window_min_samples))
    return out


class Context:
    """What the signature tests of one run read: the bench run, the calibrated base grey box
    ``gb`` at ``theta``, the measured ``channels`` and the ``criteria``; the speed steps, the
    power's segments and the model's onsets are computed once, when first asked for."""

    def __init__(self, run, gb, theta: dict[str, float], channels, criteria):
        self.run, self.gb, self.theta = run, gb, dict(theta)
        self.channels, self.criteria = list(channels), criteria
        self.tests: dict[str, EventTest] = {}  # the tests so far (a later test may read one)
        self._memo: dict[str, object] = {}

    def _once(self, key: str, make):
        if key not in self._memo:
            self._memo[key] = make()
        return self._memo[key]

    def steps_by_scale(self) -> dict[str, list[Step]]:
        """The run's clean speed steps per onset scale (no other step within its windows)."""
        t, n = self.run.time_s, self.run.columns["speed_rpm"]
        return self._once("steps", lambda: {
            sc.name: speed_steps(t, n, self.criteria, sc.quiet_s)
            for sc in self.criteria.onset_scales})

    def steps(self) -> list[Step]:
        """The clean speed steps at the shortest onset scale."""
        return self.steps_by_scale()[self.criteria.onset_scales[0].name]

    def model_onsets(self) -> ModelOnsets:
        return self._once("onsets", lambda: model_onsets(self.gb, self.theta, self.channels,
                                                         self.criteria))

    def segments(self) -> list[Segment] | None:
        """The power's constant-speed segments; None without a power column."""
        if "power_kW" not in self.run.columns:
            return None
        return self._once("segments", lambda: segments(self.run, self.criteria))
