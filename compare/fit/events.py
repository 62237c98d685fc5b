"""Event signatures: what a measured channel does within minutes of a speed step, where the
base model's slow misfit cannot reach.

On a spindle its spec describes only approximately, the calibrated base model misses the
bench by tenths of a kelvin to kelvins over hours (films, contacts, masses, loss models). An
effect whose open-loop signature is slow hides in that misfit or is imitated by it. Two
library effects also have a *fast* signature that no thermal mass can produce, and that can
be read from the raw samples around each speed step without any model:

- ``centrifugal_shortening``: P1 jumps at the step by -c (n_after^2 - n_before^2), at once
  (the centrifugal load acts at the speed of rotation, the heat takes minutes to arrive).
  A thermal response is continuous, so a straight line fitted just before the step and one
  fitted just after it meet at the step instant; a centrifugal jump is their offset there.
  The thermal curvature left in the short windows biases the offset *against* shortening (a
  speed-up heats and raises P1), so the test is conservative.
- ``sensor_lag``: a sensor that reads through a first-order lag turns a heat step's sudden
  change of slope into a gradual one. Per step, the change of slope in the first two minutes
  over the change of slope in the following four (the *onset ratio*) is above 1 for a
  channel that responds at once (its response is concave: fastest right after the step) and
  below 1 for a lagging one (S-shaped). The same ratio over 6.5 and 13 minutes reads lags of
  ten to twenty minutes, and a channel as coarsely logged as P1 (``ONSET_SCALES``). The base
  model's own ratio on the same steps is the reference: a channel the model expects to
  respond at once at a scale (ratio >= ``CONCAVE``) but that measures an S-shaped onset
  there lags. The comparison is with 1, not with the model's ratio: on a spindle the spec
  only approximates, the model's onset ratios are off by up to a factor of three (a peer's
  runs, docs/fit.md), while "S-shaped or not" is robust.

Both estimates are weighted regressions over the run's steps (through the origin), with
standard errors inflated by the scatter between steps (reduced chi-square, at least 1); each
gives a z statistic and a one-sided p-value. ``compare.fit.calibrate.forward_selection`` names
these two effects only on their event signatures (docs/fit.md, issue 13).

Units: times in s, speeds in rpm, P1 in m internally (µm in the fields named ``_um``),
temperatures in K.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: a speed change [rpm] between consecutive samples that counts as a step
STEP_RPM = 200.0
#: windows around a step [s] for P1's jump: just before, just after. The first 10 s after a
#: step are skipped: the drive ramps.
JUMP_BEFORE_S = (-180.0, -10.0)
JUMP_AFTER_S = (10.0, 80.0)


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


#: the onset is read at two time scales: minutes (a lag of a few minutes; the temperatures'
#: noise is small) and a quarter of an hour (a lag of ten to twenty minutes, and a noisier
#: channel such as P1, whose 0.1 µm steps hide a slope change over two minutes)
ONSET_SCALES = (OnsetScale("2 min / 4 min", (-300.0, -10.0), (10.0, 120.0), (120.0, 360.0)),
                OnsetScale("6.5 min / 13 min", (-600.0, -10.0), (10.0, 400.0), (400.0, 1200.0)))
SHORT = ONSET_SCALES[0]
#: model onset ratio above which a channel is expected to respond at once (concave onset)
CONCAVE = 1.15
#: a lag is read when the measured onset ratio is below 1 (an S-shaped onset) by z_alpha
LAG_RATIO = 1.0


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
    """One event test: estimate, standard error, z, one-sided p, and its per-step data."""

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
    #: the effect's parameter as the events read it: name, value, 95 % interval (own units)
    parameter: dict | None = None
    #: lag tests: the onset scale reported, and the test at every scale
    scale: str | None = None
    scales: list[dict] = field(default_factory=list)
    #: tests with a materiality floor: the effect at its estimate moves a measured channel by
    #: at least that channel's tolerance (None where the test has no such floor)
    material: bool | None = None
    #: the largest change the effect at its estimate makes per channel (K, m)
    peak_effect: dict | None = None

    def significant(self, alpha: float) -> bool:
        return bool(np.isfinite(self.p_value) and self.p_value < alpha
                    and self.material is not False)

    def to_dict(self) -> dict:
        return {"effect": self.effect, "channel": self.channel, "estimate": self.estimate,
                "se": self.se, "z": self.z, "p_value": self.p_value, "n_steps": self.n_steps,
                "unit": self.unit, "meaning": self.meaning, "model_reference": self.reference,
                "parameter": self.parameter, "scale": self.scale, "scales": self.scales,
                "material": self.material, "peak_effect": self.peak_effect}


def speed_steps(t_s: np.ndarray, speed_rpm: np.ndarray, min_step_rpm: float = STEP_RPM,
                quiet_s: tuple[float, float] = SHORT.quiet_s) -> list[Step]:
    """Speed steps of a logged run with no other step in the ``quiet_s`` window around them
    (NaN speeds are skipped; the step instant is midway between the two samples)."""
    ok = np.isfinite(speed_rpm)
    t, n = np.asarray(t_s, float)[ok], np.asarray(speed_rpm, float)[ok]
    idx = np.where(np.abs(np.diff(n)) > min_step_rpm)[0]
    # a ramp logged over several samples is one step: group consecutive changes
    groups: list[list[int]] = []
    for i in idx:
        if groups and t[i] - t[groups[-1][-1] + 1] <= 30.0:
            groups[-1].append(i)
        else:
            groups.append([i])
    steps = []
    for g in groups:
        t0 = 0.5 * (t[g[0]] + t[g[-1] + 1])
        steps.append(Step(float(t0), float(n[g[0]]), float(n[g[-1] + 1])))
    times = np.array([s.t_s for s in steps])
    keep = []
    for s in steps:
        others = times[(times != s.t_s)]
        if not np.any((others > s.t_s + quiet_s[0]) & (others < s.t_s + quiet_s[1])):
            keep.append(s)
    return keep


def _line(t: np.ndarray, y: np.ndarray, window: tuple[float, float], t0: float
          ) -> tuple[float, float, float, float] | None:
    """(value at t0, slope, se of value, se of slope) of a straight line through the samples
    in ``t0 + window``; None with fewer than 4 samples or too short a span."""
    m = (t >= t0 + window[0]) & (t <= t0 + window[1]) & np.isfinite(y)
    if m.sum() < 4 or np.ptp(t[m]) < 0.5 * (window[1] - window[0]):
        return None
    x = t[m] - t0
    A = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(A, y[m], rcond=None)
    r = y[m] - A @ coef
    s2 = float(r @ r) / max(len(x) - 2, 1)
    cov = s2 * np.linalg.inv(A.T @ A)
    return float(coef[0]), float(coef[1]), math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1])


def _through_origin(y: np.ndarray, x: np.ndarray, se: np.ndarray) -> tuple[float, float]:
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


def centrifugal_test(t_s: np.ndarray, p1_m: np.ndarray, steps: list[Step]) -> EventTest:
    """P1's jumps at the speed steps against -(n_after^2 - n_before^2): the shortening c
    [µm/krpm^2], z = c / se, one-sided p (c > 0 is a shortening)."""
    from scipy.stats import norm

    J, X, S, rows = [], [], [], []
    for s in steps:
        before = _line(t_s, p1_m, JUMP_BEFORE_S, s.t_s)
        after = _line(t_s, p1_m, JUMP_AFTER_S, s.t_s)
        if before is None or after is None or abs(s.dn2_krpm2) < 1.0:
            continue
        jump_um = (after[0] - before[0]) * 1e6
        se_um = math.hypot(after[2], before[2]) * 1e6
        J.append(jump_um)
        X.append(-s.dn2_krpm2)
        S.append(max(se_um, 0.02))  # a floor: quantised channels can fit a line exactly
        rows.append({"t_s": s.t_s, "n_before_rpm": s.n_before_rpm, "n_after_rpm": s.n_after_rpm,
                     "jump_um": jump_um, "se_um": se_um})
    if len(J) < 2:
        return EventTest("centrifugal_shortening", "P1", math.nan, math.nan, math.nan, math.nan,
                         len(J), "um/krpm^2", "too few clean speed steps to read P1's jumps")
    c, se = _through_origin(np.array(J), np.array(X), np.array(S))
    z = c / se
    return EventTest("centrifugal_shortening", "P1", c, se, z, float(norm.sf(z)), len(J),
                     "um/krpm^2", "P1's jump at the speed steps per (1000 rpm)^2 of the step "
                     "(positive: shortening as the speed rises)", per_step=rows,
                     parameter={"name": "c_cf_um_krpm2", "value": c,
                                "ci95": [c - 1.96 * se, c + 1.96 * se]})


def onset_ratio(t_s: np.ndarray, y: np.ndarray, steps: list[Step],
                scale: OnsetScale = SHORT) -> tuple[float, float, list[dict]]:
    """(ratio, se, per step) of the change of slope early after the steps to that late after
    them (``scale``'s windows; by default the first two minutes and the following four),
    regressed over the steps (units of y cancel)."""
    early, late, se_e, rows = [], [], [], []
    for s in steps:
        b = _line(t_s, y, scale.before_s, s.t_s)
        e = _line(t_s, y, scale.early_s, s.t_s)
        la = _line(t_s, y, scale.late_s, s.t_s)
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
    # steps whose late response is lost in the noise say nothing about the onset's shape
    keep = np.abs(x) > 2.0 * se
    if keep.sum() < 2:
        return math.nan, math.nan, rows
    ratio, err = _through_origin(yv[keep], x[keep], np.maximum(se[keep], 1e-12))
    return ratio, err, rows


def lag_test(channel: str, t_s: np.ndarray, y: np.ndarray,
             steps: dict[str, list[Step]], model_ratios: dict[str, float]) -> EventTest:
    """The onset test of one channel at every scale of ``ONSET_SCALES`` (``steps`` and
    ``model_ratios`` by scale name): z = (1 - ratio) / se at the scales where the model expects
    the channel to respond at once (its ratio >= ``CONCAVE``); the test reports the scale with
    the largest z, its one-sided p multiplied by the number of such scales (Bonferroni). Not
    applicable (p = nan) at no such scale."""
    from scipy.stats import norm

    meaning = ("change of slope early after the speed steps over that later (above 1: responds "
               "at once; below 1: reads through a lag)")
    scales, best = [], None
    for sc in ONSET_SCALES:
        ratio, se, rows = onset_ratio(t_s, y, steps[sc.name], sc)
        ref = model_ratios.get(sc.name, math.nan)
        ok = bool(np.isfinite(ratio) and np.isfinite(ref) and ref >= CONCAVE)
        z = (LAG_RATIO - ratio) / se if ok else math.nan
        scales.append({"scale": sc.name, "ratio": ratio, "se": se, "model_ratio": ref,
                       "applicable": ok, "z": z, "n_steps": len(rows)})
        if ok and (best is None or z > best[3]):
            best = (sc, ratio, se, z, ref, rows)
    if best is None:
        sc = ONSET_SCALES[0]
        first = scales[0]
        return EventTest("sensor_lag", channel, first["ratio"], first["se"], math.nan, math.nan,
                         first["n_steps"], "-", meaning + " (the model's own onset is not "
                         "concave here, or too few steps: no lag can be read)",
                         first["model_ratio"], scale=sc.name, scales=scales)
    sc, ratio, se, z, ref, rows = best
    n_ok = sum(x["applicable"] for x in scales)
    p = min(1.0, n_ok * float(norm.sf(z)))
    return EventTest("sensor_lag", channel, ratio, se, z, p, len(rows), "-",
                     f"{meaning}, at the scale {sc.name}", ref, rows, scale=sc.name,
                     scales=scales)


def fine_inputs(inputs, sub: int = 6):
    """``inputs`` (compare.fit.greybox.Inputs) with every interval cut into ``sub`` equal
    ones holding the same values: the model's response between its grid points."""
    from dataclasses import replace

    g = inputs.grid_s
    fine = np.concatenate([np.linspace(a, b, sub + 1)[:-1] for a, b in zip(g[:-1], g[1:],
                                                                            strict=True)]
                          + [g[-1:]])

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

    def lag_for_ratio(self, channel: str, ratio: float, scale: OnsetScale = SHORT) -> float:
        """The first-order lag time constant [s] that brings the model's onset ratio of
        ``channel`` at ``scale`` down to ``ratio`` (0 when it is already at or below;
        LAG_GRID_S[-1] when even the longest lag on the grid does not)."""
        from lumped.elastic import first_order_lag

        ratios = [self.ratios[channel][scale.name]]
        for tau in LAG_GRID_S[1:]:
            y = first_order_lag(self.t_s, self.outputs[channel], tau)
            ratios.append(onset_ratio(self.t_s, y, self.steps[scale.name], scale)[0])
        r = np.array(ratios)
        if not np.isfinite(ratio) or ratio >= r[0]:
            return 0.0
        below = np.where(np.isfinite(r) & (r <= ratio))[0]
        if len(below) == 0:
            return float(LAG_GRID_S[-1])
        k = int(below[0])
        # log-linear between the grid's neighbours
        t0, t1 = max(LAG_GRID_S[k - 1], 1.0), LAG_GRID_S[k]
        f = (r[k - 1] - ratio) / (r[k - 1] - r[k]) if r[k - 1] != r[k] else 1.0
        return float(math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0))))


#: lag time constants [s] the onset ratio is mapped over
LAG_GRID_S = (0.0, 15.0, 30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1800.0, 3600.0)


def model_onsets(gb, theta: dict[str, float], channels, sub: int = 6) -> ModelOnsets:
    """The onset ratio each channel of the grey box ``gb`` (base model, parameters ``theta``)
    shows at its own speed steps, simulated on a grid ``sub`` times finer than the fit's."""
    from compare.fit.greybox import GreyBox

    fine = fine_inputs(gb.inputs, sub)
    model = GreyBox(gb.spec, gb.drive, fine, gb.nodes, base_extra=gb.base_extra)
    out = model.simulate(theta)
    t = fine.grid_s
    n_end = np.concatenate([[fine.speed_rpm[0]], fine.speed_rpm])
    steps = {sc.name: speed_steps(t, n_end, quiet_s=sc.quiet_s) for sc in ONSET_SCALES}
    ratios = {c: {sc.name: onset_ratio(t, out[c], steps[sc.name], sc)[0] for sc in ONSET_SCALES}
              for c in channels if c in out}
    return ModelOnsets(t, {c: out[c] for c in ratios}, steps, ratios)


def event_tests(run, gb, theta: dict[str, float], channels, alpha: float = 0.01
                ) -> dict[str, EventTest]:
    """The centrifugal test on P1, the lag test of every measured channel, and the power
    tests (compare.fit.power_events; ``alpha`` decides whether the power drifts), on the raw
    samples of the bench run ``run`` (spindle.bench.BenchRun); keys ``centrifugal_shortening``,
    ``sensor_lag(<channel>)``, ``bearing_preload`` and ``windage_loss``."""
    from compare.fit.power_events import power_tests

    t, n = run.time_s, run.columns["speed_rpm"]
    steps = {sc.name: speed_steps(t, n, quiet_s=sc.quiet_s) for sc in ONSET_SCALES}
    out: dict[str, EventTest] = {}
    if "P1" in channels:
        out["centrifugal_shortening"] = centrifugal_test(*run.channel("P1"), steps[SHORT.name])
    onsets = model_onsets(gb, theta, channels)
    by_name = {sc.name: sc for sc in ONSET_SCALES}
    for c in channels:
        test = lag_test(c, *run.channel(c), steps, onsets.ratios.get(c, {}))
        if np.isfinite(test.z):
            sc = by_name[test.scale]
            lo, hi = test.estimate - 1.96 * test.se, test.estimate + 1.96 * test.se
            tau = onsets.lag_for_ratio(c, test.estimate, sc)
            # below the lagged model's floor (a long lag turns the onset into a ramp whose
            # ratio stops falling) the ratio says "lagged" but not by how much: no prior on
            # tau then, the fit over the whole run estimates it
            if tau < LAG_GRID_S[-1]:
                test.parameter = {"name": "tau_s", "value": tau,
                                  "ci95": [onsets.lag_for_ratio(c, hi, sc),
                                           onsets.lag_for_ratio(c, lo, sc)]}
        out[f"sensor_lag({c})"] = test
    out.update(power_tests(run, alpha, gb, theta))
    from compare.fit.load_events import coolant_load_test
    out["coolant_dynamics"] = coolant_load_test(run, gb, theta)
    return out
