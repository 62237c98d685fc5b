"""Power signatures: what the drive's electrical power does at constant speed and no load.

A bench logs the electrical power the motor draws. At no load it is the motor's own losses
plus every drag torque the motor supplies: bearing friction, windage, and a bearing preload's
extra friction. Two library effects leave a mark there that no film, contact or mass of the
thermal model can produce or hide, because the thermal model does not predict the power at
all (the power is an input of the fit):

- ``bearing_preload``: the friction rises with the inner-outer ring temperature difference,
  which builds up over minutes after a speed-up and decays after a slow-down. At constant
  speed the power therefore *drifts*: up after a speed-up, down after a slow-down. A spindle
  without it draws a power that settles within the drive's own response. Per no-load segment
  of at least ``MIN_SEGMENT_S``, the drift is the mean power over the segment's last
  ``LATE_S`` minus that over ``EARLY_S`` after its start; the preload predicts it in
  proportion to q_b(n) (q_b(n) - q_b(n_before)) (the extra friction is k q_b dT, and the
  ring difference dT follows the bearing heat q_b), read with the settled power level P
  standing for q_b. The regression of the drifts on P (P - P_before) [kW W] through the
  origin gives b [1/kW] and z = b / se (one-sided: a preload raises the friction).
- ``windage_loss``: air friction adds a drag power c (n / 1000)^3. The no-load losses of a
  motor spindle are sums of terms in n (hysteresis, a constant friction torque), n^(5/3)
  (Palmgren's viscous friction, (nu n)^(2/3) n), and n^2 (eddy currents); a term in n^3 is
  windage. The settled power levels of the no-load segments (the mean over their second
  half) are regressed on n, n^(5/3), n^2 and n^3 (ordinary least squares); c is the n^3
  coefficient [W/krpm^3], t = c / se with the residual scatter between levels, one-sided p
  from Student's t with levels - 4 degrees of freedom. It needs ``MIN_LEVELS`` speed levels
  spanning a factor ``MIN_SPAN`` in speed, and power levels that are settled: when the
  preload drift is significant the test does not apply (the drift would read as a steeper
  curve).

Both return :class:`compare.fit.events.EventTest`; ``compare.fit.calibrate.forward_selection``
judges an effect with an applicable test on it alone (docs/fit.md). Loaded segments (the
process torque above ``NO_LOAD_NM``) are left out: the copper loss there drifts with the
winding temperature. Units: s, rpm, W (kW in the drift regressor, as named).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from compare.fit.events import EventTest, _through_origin
from spindle.bench_inputs import SPEED_BAND_REL, SPEED_BAND_RPM

#: no-load segments shorter than this [s] are not read for a drift
MIN_SEGMENT_S = 1800.0
#: window after a segment's start [s] for the early power (the drive's ramp and the first
#: samples' averaging left out)
EARLY_S = (120.0, 360.0)
#: the late power: the segment's last this many seconds
LATE_S = 900.0
#: process torque [N m] up to which a segment counts as no-load
NO_LOAD_NM = 0.5
#: speed [rpm] below which a segment is standstill
MOVING_RPM = 300.0
#: the windage test needs this many no-load speed levels spanning this factor in speed
MIN_LEVELS = 5
MIN_SPAN = 3.0
#: speeds within this many rpm are one level
LEVEL_RPM = 50.0


@dataclass(frozen=True)
class Segment:
    """A constant-speed stretch of a run: start and end [s], speed [rpm], mean process torque
    [N m], and its power samples (times from the segment's start [s], power [W])."""

    t0_s: float
    t1_s: float
    speed_rpm: float
    torque_Nm: float
    t_s: np.ndarray
    power_W: np.ndarray

    @property
    def duration_s(self) -> float:
        return self.t1_s - self.t0_s

    @property
    def no_load(self) -> bool:
        return self.speed_rpm >= MOVING_RPM and abs(self.torque_Nm) <= NO_LOAD_NM

    def mean_W(self, lo_s: float, hi_s: float) -> tuple[float, float, int]:
        """(mean, its standard error, samples) of the power over [lo, hi) from the start."""
        m = (self.t_s >= lo_s) & (self.t_s < hi_s)
        p = self.power_W[m]
        if len(p) < 10:
            return math.nan, math.nan, len(p)
        return float(p.mean()), float(p.std(ddof=1) / math.sqrt(len(p))), len(p)

    def settled_W(self) -> tuple[float, float]:
        """(mean, standard error) of the power over the segment's second half."""
        mean, se, _ = self.mean_W(0.5 * self.duration_s, self.duration_s + 1.0)
        return mean, se


def segments(run) -> list[Segment]:
    """Constant-speed segments of a bench run (spindle.bench.BenchRun): cut where the logged
    speed changes beyond the drive's scatter band between samples (max(20 rpm, 1 %), the band
    of spindle.bench_inputs.settled_speed). Cut only at steps of 200 rpm (the jump tests' STEP_RPM),
    a 5800 -> 6000 rpm step stayed inside one segment, and its 100 W more power read as a
    preload's drift at z 2.3 on three synthetic runs without one (docs/fit.md)."""
    t = np.asarray(run.time_s, dtype=float)
    n = np.asarray(run.columns["speed_rpm"], dtype=float)
    P = np.asarray(run.columns["power_kW"], dtype=float) * 1e3
    M = (np.asarray(run.columns["load_torque_Nm"], dtype=float)
         if "load_torque_Nm" in run.columns else np.zeros_like(t))
    ok = np.isfinite(n)
    tn, nn = t[ok], n[ok]
    band = np.maximum(SPEED_BAND_RPM,
                      SPEED_BAND_REL * np.maximum(np.abs(nn[1:]), np.abs(nn[:-1])))
    cuts = tn[1:][np.abs(np.diff(nn)) > band]
    edges = np.concatenate([[t[0]], cuts, [t[-1] + 1e-9]])
    out = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        m = (t >= a) & (t < b)
        if m.sum() < 10:
            continue
        pm = m & np.isfinite(P)
        mm = m & np.isfinite(M)
        out.append(Segment(float(a), float(b), float(np.nanmedian(n[m])),
                           float(M[mm].mean()) if mm.any() else 0.0,
                           t[pm] - a, P[pm]))
    return out


def preload_drift_test(segs: list[Segment], model_drift=None) -> EventTest:
    """The power's drift at constant speed against the preload's prediction (module doc).

    ``model_drift(t0, t1)``: the drift [W] a preload of k = 1/K makes over the same windows
    of a segment [t0, t1] in the calibrated base model (:func:`model_drift_of`). With it the
    drifts are regressed on the model's, and the estimate is k [1/K]: the model knows how the
    ring difference moves after each step (it can rise and then fall back as the housing
    warms), which P (P - P_before) does not. Without it, the model-free predictor."""
    from scipy.stats import norm

    D, X, S, rows = [], [], [], []
    for prev, s in zip(segs[:-1], segs[1:], strict=True):
        if not (s.no_load and s.duration_s >= MIN_SEGMENT_S):
            continue
        before = prev.settled_W()[0] if prev.speed_rpm >= MOVING_RPM else 0.0
        early, se_e, _ = s.mean_W(*EARLY_S)
        late, se_l, _ = s.mean_W(s.duration_s - LATE_S, s.duration_s + 1.0)
        level = s.settled_W()[0]
        if not all(np.isfinite([before, early, late, level])) or (
                abs(prev.torque_Nm) > NO_LOAD_NM):
            continue
        x = (level * (level - before) / 1e3 if model_drift is None
             else model_drift(s.t0_s, s.t1_s))
        if not np.isfinite(x):
            continue
        D.append(late - early)
        X.append(x)
        S.append(max(math.hypot(se_e, se_l), 0.05))
        rows.append({"t_s": s.t0_s, "t_end_s": s.t1_s, "speed_rpm": s.speed_rpm,
                     "drift_W": late - early,
                     "se_W": math.hypot(se_e, se_l), "predictor_kW_W": x})
    if model_drift is None:
        unit, least = "1/kW", 1.0
        meaning = ("drift of the no-load power at constant speed per P (P - P_before) [1/kW] "
                   "(positive: the friction rises as the bearing warms, a preload)")
    else:
        unit, least = "1/K", 1e-3
        meaning = ("drift of the no-load power at constant speed against the base model's "
                   "drift of q_b (T_inner - T_outer): the preload coefficient k [1/K] "
                   "(positive: the friction rises with the ring difference, a preload)")
    if len(D) < 3 or max((abs(x) for x in X), default=0.0) < least:
        return EventTest("bearing_preload", "power", math.nan, math.nan, math.nan, math.nan,
                         len(D), unit, meaning + " (too few long no-load segments after a "
                         "speed change: no drift can be read)", per_step=rows)
    b, se = _through_origin(np.array(D), np.array(X), np.array(S))
    z = b / se
    return EventTest("bearing_preload", "power", b, se, z, float(norm.sf(z)), len(D), unit,
                     meaning, per_step=rows)


def model_drift_of(gb, theta: dict[str, float], front_only: bool = False):
    """``(t0, t1) -> drift [W]`` of q_b (T_inner - T_outer) summed over the bearings (or the
    front set's alone) of the grey box ``gb`` at ``theta``, over a segment's windows: the
    extra power of a preload of k = 1/K (:meth:`GreyBox.ring_drag_W`)."""
    from compare.fit.greybox import _preload_param

    drag = gb.ring_drag_W(theta)
    parts = [v for k, v in drag.items()
             if not front_only or _preload_param(gb.spec, k) == "k_preload_1_K"]
    t = gb.inputs.grid_s
    if not parts:
        return lambda t0, t1: math.nan
    e = np.sum(parts, axis=0)

    def drift(t0: float, t1: float) -> float:
        early = e[(t >= t0 + EARLY_S[0]) & (t <= t0 + EARLY_S[1])]
        late = e[(t >= t1 - LATE_S) & (t <= t1)]
        if len(early) == 0 or len(late) == 0:
            return math.nan
        return float(late.mean() - early.mean())

    return drift


def preload_parameter(test: EventTest, gb, theta: dict[str, float]) -> dict | None:
    """The front bearing set's preload coefficient k [1/K] the measured drifts call for: the
    grey box ``gb`` at ``theta`` (the calibrated base) gives, per segment of ``test``, the drift
    of q_front (T_inner - T_outer) over the same windows; the measured drifts regressed on it
    through the origin give k with its 95 % interval (``{"name", "value", "ci95"}``; None when
    the model's drifts are nil). The front set: a motor spindle's rigidly preloaded set, whose
    preload rises as the inner ring warms (the rear set floats on springs); the thermal fit
    then decides both coefficients."""
    if not test.per_step:
        return None
    drift = model_drift_of(gb, theta, front_only=True)
    D, X, S = [], [], []
    for row in test.per_step:
        x = drift(row["t_s"], row["t_end_s"])
        if np.isfinite(x):
            D.append(row["drift_W"])
            X.append(x)
            S.append(max(row["se_W"], 0.05))
    if len(D) < 2 or max(abs(x) for x in X) <= 0.0:
        return None
    k, se = _through_origin(np.array(D), np.array(X), np.array(S))
    if not np.isfinite(k):
        return None
    return {"name": "k_preload_1_K", "value": max(k, 0.0),
            "ci95": [max(k - 1.96 * se, 0.0), k + 1.96 * se]}


def windage_test(segs: list[Segment], drifting: bool = False) -> EventTest:
    """The n^3 term of the settled no-load power levels (module doc); not applicable when
    ``drifting`` (the preload drift test is significant)."""
    from scipy.stats import t as student

    levels: list[list[tuple[float, float]]] = []
    speeds: list[float] = []
    for s in segs:
        if not s.no_load or s.duration_s < 600.0:
            continue
        P, _ = s.settled_W()
        if not np.isfinite(P):
            continue
        for k, n in enumerate(speeds):
            if abs(n - s.speed_rpm) <= LEVEL_RPM:
                levels[k].append((s.speed_rpm, P))
                break
        else:
            speeds.append(s.speed_rpm)
            levels.append([(s.speed_rpm, P)])
    n = np.array([np.mean([v[0] for v in lv]) for lv in levels]) / 1e3
    P = np.array([np.mean([v[1] for v in lv]) for lv in levels])
    rows = [{"speed_rpm": float(a * 1e3), "power_W": float(b)} for a, b in zip(n, P, strict=True)]
    meaning = "windage: the n^3 term of the settled no-load power [W/krpm^3]"
    span = float(n.max() / n.min()) if len(n) else 0.0
    if drifting or len(n) < MIN_LEVELS or span < MIN_SPAN:
        why = ("the power drifts at constant speed (a preload), so its levels are not settled"
               if drifting else f"fewer than {MIN_LEVELS} no-load speed levels spanning a "
               f"factor {MIN_SPAN:g}")
        return EventTest("windage_loss", "power", math.nan, math.nan, math.nan, math.nan,
                         len(n), "W/krpm^3", f"{meaning} ({why}: not applicable)",
                         per_step=rows)
    A = np.column_stack([n, n ** (5.0 / 3.0), n ** 2, n ** 3])
    coef, *_ = np.linalg.lstsq(A, P, rcond=None)
    r = P - A @ coef
    dof = len(P) - A.shape[1]
    s2 = max(float(r @ r) / dof, 1e-12)
    cov = s2 * np.linalg.inv(A.T @ A)
    c, se = float(coef[3]), math.sqrt(float(cov[3, 3]))
    tval = c / se
    test = EventTest("windage_loss", "power", c, se, tval, float(student.sf(tval, dof)), len(n),
                     "W/krpm^3", meaning, per_step=rows)
    q = float(student.ppf(0.975, dof))
    test.parameter = {"name": "c_w_W_krpm3", "value": max(c, 0.0),
                      "ci95": [max(c - q * se, 0.0), c + q * se]}
    return test


def power_tests(run, alpha: float, gb=None, theta: dict[str, float] | None = None
                ) -> dict[str, EventTest]:
    """Both power tests of a bench run, keyed by effect name (no keys without a power
    column). With the grey box ``gb`` and its base parameters ``theta``, a significant drift
    carries the preload coefficient it calls for (:func:`preload_parameter`)."""
    if "power_kW" not in run.columns:
        return {}
    segs = segments(run)
    model = gb is not None and theta is not None
    drift = preload_drift_test(segs, model_drift_of(gb, theta) if model else None)
    if model and drift.significant(alpha):
        drift.parameter = preload_parameter(drift, gb, theta)
    return {"bearing_preload": drift,
            "windage_loss": windage_test(segs, drifting=drift.significant(alpha))}
