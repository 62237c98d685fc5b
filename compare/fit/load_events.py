"""Load signature: how the bearing rings follow the motor's loss at constant speed.

At a constant speed the bearings' friction heat is constant. When the process torque then
varies (a loaded bench run ramps its load within each speed plateau), only the motor's
losses change, and the bearing outer rings (T1, T2) follow them along two paths:

- through the **rotor**: its share of the loss heats the shaft, and the inner rings pass it
  on. The share is uncertain under load (an induction motor's rotor copper loss grows with
  the torque), so it is a nuisance here, estimated alongside;
- through the **water**: with ``coolant_dynamics`` the coolant warms by the heat it carries,
  Q / (2 m_dot c_p), and every wetted surface sees it at once, the bearing seats too.

Neither path moves the rings when the torque is constant, so within a plateau the calibrated
base model's residual at T1 and T2, regressed on the two paths' sensitivities (the base model
with a probe coolant resistance, and with its rotor share raised by 10 %), separates them.
Both sides of the regression are taken relative to their plateau's mean, so a plateau's
offset (the base model's misfit at that speed, what the speed step left settling) does not
enter, and the first ``SETTLE_S`` after a speed change are left out.

The two paths must be told apart: where the water reaches the rings only through the
housing (no cooled seats), its response looks like the rotor's, and the test does not apply
(``MAX_PATH_CORRELATION``); the loop judges the effect then.

The coolant resistance R [K/W] is the estimate; its standard error comes from a jackknife
over the plateaus (the samples within a plateau are correlated; the plateaus are the
independent pieces), and the one-sided p from Student's t with plateaus - 1 degrees of
freedom. The test applies to runs with at least ``MIN_PLATEAUS`` such plateaus; a no-load run
has none and its coolant warming is judged in the open-loop loop as before.

The regression compares the base model's load response with the rings', so an error in that
response (the base structure's, not an effect) reads as a small R of either sign. The effect
is therefore named only when it is also **material**: at its estimate it moves a measured
channel by at least that channel's tolerance (1 K) somewhere in the run.

On a peer's two loaded runs of one SPL2782-family spindle (../shared/bench-runs, docs/fit.md),
with the seats' conductance in the base model (G_seat_W_K, which connects the rings to the
warmed coolant), the coolant run gives R = 0.0018 K/W, t = 9.6, a warming of 2.5-3.1 K at
T1, T2 and T_stator; its control gives R = 0.0003 K/W, t = 3.3 (significant at 1 %), a
warming of 0.52-0.58 K: the base structure's bias, below the tolerance. Units: s, N m, K, W.
"""

from __future__ import annotations

import math

import numpy as np

from compare.fit.calibrate import TOLERANCE
from compare.fit.events import STEP_RPM, EventTest

#: a constant-speed plateau is read when it lasts at least this long [s]
PLATEAU_MIN_S = 1800.0
#: after a speed change the rings settle to the new bearing heat; left out [s]
SETTLE_S = 900.0
#: the residual is averaged over blocks of this length [s] (the sensors' noise; 5 min is
#: short against the motor's thermal response, long against the bench's logging)
BLOCK_S = 300.0
#: the process torque must span at least this much within a plateau [N m]
MIN_TORQUE_SPAN_NM = 5.0
#: plateaus needed for the jackknife
MIN_PLATEAUS = 4
#: speed below which a plateau is standstill [rpm]
MOVING_RPM = 300.0
#: the probe coolant resistance for the sensitivity [K/W] (the model is linear in it to first
#: order; a tenth of the library range's upper end)
R_PROBE_K_W = 0.002
#: the channels read: the bearing outer rings (the stator follows its own loss directly and
#: carries the base model's largest misfit)
RING_CHANNELS = ("T1", "T2")
#: the nuisance paths estimated alongside (module doc)
NUISANCE = ("rotor_share",)
#: the test applies only where the coolant's and the rotor's regressors correlate at most
#: this much (variance inflation 1 / (1 - r^2) <= 2.8). Measured: r = 0.67-0.69 on the peer's
#: loaded pair, whose rings the calibrated seats tie to the water; 0.89-0.98 on this project's
#: mismatched ramped-load runs, whose FEM has no cooled seats, where the test named coolant
#: warming on clean runs (docs/fit.md)
MAX_PATH_CORRELATION = 0.8

MEANING = ("coolant warming: the bearing rings' response to the motor's loss at constant "
           "speed beyond the rotor's path, as a coolant resistance 1 / (2 m_dot c_p) [K/W]")


def load_plateaus(run) -> list[tuple[float, float]]:
    """(start, end) [s] of the constant-speed plateaus of a bench run (spindle.bench.BenchRun)
    that turn, last ``PLATEAU_MIN_S`` and whose process torque spans ``MIN_TORQUE_SPAN_NM``
    after ``SETTLE_S``; none without a load column."""
    if "load_torque_Nm" not in run.columns:
        return []
    t = np.asarray(run.time_s, dtype=float)
    n = np.asarray(run.columns["speed_rpm"], dtype=float)
    M = np.asarray(run.columns["load_torque_Nm"], dtype=float)
    ok = np.isfinite(n)
    cuts = t[ok][1:][np.abs(np.diff(n[ok])) > STEP_RPM]
    edges = np.concatenate([[t[0]], cuts, [t[-1] + 1e-9]])
    out = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if b - a < PLATEAU_MIN_S:
            continue
        inside = (t >= a) & (t < b)
        late = inside & (t >= a + SETTLE_S) & np.isfinite(M)
        if np.nanmedian(n[inside]) < MOVING_RPM or late.sum() < 10:
            continue
        if float(np.ptp(M[late])) >= MIN_TORQUE_SPAN_NM:
            out.append((float(a), float(b)))
    return out


def _block_rows(t: np.ndarray, e: np.ndarray, X: np.ndarray, a: float
                ) -> tuple[np.ndarray, np.ndarray]:
    """Block means of the residual ``e`` and the regressors ``X`` over a plateau starting at
    ``a``, relative to the plateau's mean."""
    blk = ((t - a) // BLOCK_S).astype(int)
    keys = [k for k in np.unique(blk) if np.sum(blk == k) >= 3]
    if len(keys) < 2:
        return np.empty(0), np.empty((0, X.shape[1]))
    eb = np.array([e[blk == k].mean() for k in keys])
    Xb = np.array([X[blk == k].mean(axis=0) for k in keys])
    return eb - eb.mean(), Xb - Xb.mean(axis=0)


def _not_applicable(plateaus: int, why: str) -> EventTest:
    return EventTest("coolant_dynamics", "T1, T2", math.nan, math.nan, math.nan, math.nan,
                     plateaus, "K/W", f"{MEANING} ({why}: not applicable)")


def coolant_load_test(run, gb, theta: dict[str, float]) -> EventTest:
    """The coolant resistance the rings' load response calls for (module doc), from the bench
    run ``run`` and the calibrated base grey box ``gb`` at ``theta``."""
    from scipy.stats import t as student

    name = "coolant_dynamics"
    plats = load_plateaus(run)
    channels = [c for c in RING_CHANNELS if c in run.channels]
    if not channels:
        return _not_applicable(0, "neither T1 nor T2 is measured")
    if len(plats) < MIN_PLATEAUS:
        return _not_applicable(len(plats), f"fewer than {MIN_PLATEAUS} constant-speed plateaus "
                               "with a varying load")
    grid = gb.inputs.grid_s
    base = gb.simulate(theta)
    probe = gb.variant(tuple(dict.fromkeys((*gb.effects, name))), gb.lag_channel)
    with_r = probe.simulate({**theta, "R_adv_K_W": R_PROBE_K_W})
    cols = [(with_r, R_PROBE_K_W)]
    for k in NUISANCE:
        cols.append((gb.simulate({**theta, k: theta[k] * 1.1}), 0.1))
    sens = {c: np.column_stack([(w[c] - base[c]) / d for w, d in cols]) for c in channels}
    E, X, P = [], [], []
    for a, b in plats:
        for c in channels:
            tc, yc = run.channel(c)
            m = (tc >= a + SETTLE_S) & (tc < b) & np.isfinite(yc)
            e = yc[m] - np.interp(tc[m], grid, base[c])
            Xc = np.column_stack([np.interp(tc[m], grid, s) for s in sens[c].T])
            eb, Xb = _block_rows(tc[m], e, Xc, a)
            E.append(eb)
            X.append(Xb)
            P.append(np.full(len(eb), a))
    E, X, P = np.concatenate(E), np.vstack(X), np.concatenate(P)
    keys = np.unique(P)
    if len(keys) < MIN_PLATEAUS:  # plateaus lost in the logging gaps
        return _not_applicable(len(keys), "too few logged blocks in the load plateaus")
    # the paths must be separable: where the coolant's route to the rings is the rotor's
    # route (no cooled seats), a misfit of one reads as the other
    r_paths = float(np.corrcoef(X[:, 0], X[:, 1])[0, 1]) if X.shape[1] > 1 else 0.0
    if not abs(r_paths) <= MAX_PATH_CORRELATION:
        return _not_applicable(len(keys), "the coolant's and the rotor's paths to the rings "
                               f"are not separable on this run (r = {r_paths:.2f})")
    coef = np.linalg.lstsq(X, E, rcond=None)[0]
    # jackknife over the plateaus: the blocks within one are correlated
    loo = np.array([np.linalg.lstsq(X[P != k], E[P != k], rcond=None)[0] for k in keys])
    m = len(keys)
    se = np.sqrt((m - 1) / m * np.sum((loo - loo.mean(axis=0)) ** 2, axis=0))
    R, se_R = float(coef[0]), float(se[0])
    if not (np.isfinite(se_R) and se_R > 0):
        return _not_applicable(m, "the plateaus do not determine it")
    z = R / se_R
    rows = [{"t_s": a, "t_end_s": b} for a, b in plats]
    test = EventTest(name, ", ".join(channels), R, se_R, z, float(student.sf(z, m - 1)), m,
                     "K/W", MEANING, per_step=rows)
    q = float(student.ppf(0.975, m - 1))
    test.parameter = {"name": "R_adv_K_W", "value": max(R, 0.0),
                      "ci95": [max(R - q * se_R, 0.0), R + q * se_R]}
    # materiality: the plateaus compare the base model's load response with the rings', so
    # an error in that response (the base structure's, not an effect) reads as a small R;
    # the peer's loaded control run gives R = 0.0003 K/W at t = 3.3, a warming of 0.5 K at
    # the rings. The effect is named only when its warming reaches a channel's tolerance.
    with_est = probe.simulate({**theta, "R_adv_K_W": max(R, 0.0)})
    peak = {c: float(np.max(np.abs(with_est[c] - base[c]))) for c in run.channels
            if c in base and c in TOLERANCE}
    test.peak_effect = peak
    test.material = any(v >= TOLERANCE[c] for c, v in peak.items())
    return test
