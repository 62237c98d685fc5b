"""``coolant_dynamics``: the coolant warms along the jacket with the heat it carries, so the
films see the supply temperature plus Q / (2 m_dot c_p), not the supply temperature.

Signature (loaded runs): at a constant speed the bearings' friction heat is constant, and
when the process torque varies only the motor's losses change. The bearing rings follow them
along two paths, through the rotor (its share of the loss, a nuisance estimated alongside)
and through the warmed water, which every wetted surface sees at once. Within each plateau
the base model's residual at T1 and T2, regressed on both paths' sensitivities relative to
the plateau's mean, separates them (:func:`load_response_test`); the resistance's standard
error comes from a jackknife over the plateaus.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from compare.fit.effects.base import Effect, Feedback
from compare.fit.params import Param
from compare.fit.signatures import EventTest
from spindle.loads import TimeSeries

MEANING = ("coolant warming: the bearing rings' response to the motor's loss at constant "
           "speed beyond the rotor's path, as a coolant resistance 1 / (2 m_dot c_p) [K/W]")
#: the channels the load test reads: the bearing outer rings (the stator follows its own loss
#: directly)
RING_CHANNELS = ("T1", "T2")


class CoolantDynamics(Effect):
    name = "coolant_dynamics"
    explanation = ("The coolant warms along the jacket with the heat it carries: the films see "
                   "the supply temperature plus Q / (2 m_dot c_p), not the supply temperature.")
    params = (Param("R_adv_K_W", "K/W", 0.0, 0.0, 0.02, "1 / (2 m_dot c_p) of the coolant flow",
                    log=False, source="water at 1-10 l/min: 1 / (2 m_dot c_p) = 0.0004-0.004 "
                    "K/W; 0.02 is a flow of 0.7 l/min"),)
    in_conductance = ("R_adv_K_W",)
    hint = "the coolant flow (the chiller's flow rate and the jacket's supply temperature)"
    needs_coolant = True

    def network_options(self):
        return {"coolant_advection_W_K": 1.0}  # set per parameter set

    def edge_conductances(self, theta):
        R = theta.get("R_adv_K_W", 0.0)
        return {"coolant_advection": 1.0 / R if R > 0 else 1e9}  # R = 0: the films see the supply

    def signature(self, ctx) -> dict:
        return {self.name: load_response_test(ctx.run, ctx.gb, ctx.theta, ctx.criteria)}

    def draw(self, rng):
        return {"R_adv_K_W": float(rng.uniform(0.002, 0.005))}

    def feedback(self, thermal, spec, truth):
        from reference.thermal import TWO_PI

        # coolant films do not depend on speed (Dittus-Boelter on the flow)
        rows = [TWO_PI * s.h_W_m2K(0.0) * b for s, _, b in thermal.op.films if s.T_ref == "coolant"]
        g = np.sum(rows, axis=0)
        R, Gs = truth["R_adv_K_W"], float(g.sum())

        def apply(case, x, t):
            return replace(case, T_coolant_K=TimeSeries(tuple(t), tuple(x)))

        def update(readings, case, t):
            # the films see the mean coolant temperature Tm, with sum g (T - Tm) = (Tm - Ts) / R
            # (Ts the supply): Tm = (Ts + R g.T) / (1 + R sum g)
            Ts = np.asarray(case.T_coolant_K(t))
            return (Ts + R * readings["coolant_bT"]) / (1.0 + R * Gs)

        def start(readings, case, t):
            return np.asarray(case.T_coolant_K(t), dtype=float)

        return Feedback({"coolant_bT": g}, apply, update, start)


def load_plateaus(run, criteria) -> list[tuple[float, float]]:
    """(start, end) [s] of the constant-speed plateaus of a bench run that turn, last
    ``criteria.load_plateau_min_s`` and whose process torque spans
    ``criteria.load_span_Nm`` after ``criteria.load_settle_s``; none without a load column."""
    if "load_torque_Nm" not in run.columns:
        return []
    t = np.asarray(run.time_s, dtype=float)
    n = np.asarray(run.columns["speed_rpm"], dtype=float)
    M = np.asarray(run.columns["load_torque_Nm"], dtype=float)
    ok = np.isfinite(n)
    cuts = t[ok][1:][np.abs(np.diff(n[ok])) > criteria.step_rpm]
    edges = np.concatenate([[t[0]], cuts, [t[-1] + 1e-9]])
    out = []
    for a, b in zip(edges[:-1], edges[1:], strict=True):
        if b - a < criteria.load_plateau_min_s:
            continue
        inside = (t >= a) & (t < b)
        late = inside & (t >= a + criteria.load_settle_s) & np.isfinite(M)
        if np.nanmedian(n[inside]) < criteria.moving_rpm or late.sum() < criteria.window_min_samples:
            continue
        if float(np.ptp(M[late])) >= criteria.load_span_Nm:
            out.append((float(a), float(b)))
    return out


def _block_rows(t: np.ndarray, e: np.ndarray, X: np.ndarray, a: float, criteria
                ) -> tuple[np.ndarray, np.ndarray]:
    """Block means (``criteria.load_block_s``, each of ``criteria.window_min_samples``
    samples or more) of the residual ``e`` and the regressors ``X`` over a plateau starting
    at ``a``, relative to the plateau's mean."""
    blk = ((t - a) // criteria.load_block_s).astype(int)
    keys = [k for k in np.unique(blk) if np.sum(blk == k) >= criteria.window_min_samples]
    if len(keys) < 2:
        return np.empty(0), np.empty((0, X.shape[1]))
    eb = np.array([e[blk == k].mean() for k in keys])
    Xb = np.array([X[blk == k].mean(axis=0) for k in keys])
    return eb - eb.mean(), Xb - Xb.mean(axis=0)


def _not_applicable(plateaus: int, why: str) -> EventTest:
    return EventTest("coolant_dynamics", "T1, T2", math.nan, math.nan, math.nan, math.nan,
                     plateaus, "K/W", f"{MEANING} ({why}: not applicable)")


def load_response_test(run, gb, theta: dict[str, float], criteria) -> EventTest:
    """The coolant resistance the rings' load response calls for (module doc), from the bench
    run ``run`` and the calibrated base grey box ``gb`` at ``theta``."""
    from scipy.stats import t as student

    name = "coolant_dynamics"
    plats = load_plateaus(run, criteria)
    channels = [c for c in RING_CHANNELS if c in run.channels]
    if not channels:
        return _not_applicable(0, "neither T1 nor T2 is measured")
    if len(plats) < criteria.load_min_plateaus:
        return _not_applicable(len(plats), f"fewer than {criteria.load_min_plateaus} "
                               "constant-speed plateaus with a varying load")
    grid = gb.inputs.grid_s
    base = gb.simulate(theta)
    probe = gb.variant(tuple(dict.fromkeys((*gb.effects, name))))
    r_probe = criteria.load_probe_R_K_W
    cols = [(probe.simulate({**theta, "R_adv_K_W": r_probe}), r_probe),
            # the nuisance path: the rotor's share of the loss, raised by 10 %
            (gb.simulate({**theta, "rotor_share": theta["rotor_share"] * 1.1}), 0.1)]
    sens = {c: np.column_stack([(w[c] - base[c]) / d for w, d in cols]) for c in channels}
    blocks = []  # (residual, regressors, plateau start) of each block
    for a, b in plats:
        for c in channels:
            tc, yc = run.channel(c)
            m = (tc >= a + criteria.load_settle_s) & (tc < b) & np.isfinite(yc)
            e = yc[m] - np.interp(tc[m], grid, base[c])
            Xc = np.column_stack([np.interp(tc[m], grid, s) for s in sens[c].T])
            eb, Xb = _block_rows(tc[m], e, Xc, a, criteria)
            blocks.append((eb, Xb, np.full(len(eb), a)))
    E, X, P = (np.concatenate(parts) for parts in zip(*blocks, strict=True))
    keys = np.unique(P)
    if len(keys) < criteria.load_min_plateaus:  # plateaus lost in the logging gaps
        return _not_applicable(len(keys), "too few logged blocks in the load plateaus")
    # the paths must be separable: where the coolant's route to the rings is the rotor's
    # route (no cooled seats), a misfit of one reads as the other
    with np.errstate(invalid="ignore", divide="ignore"):  # a path without variation: nan
        r_paths = float(np.corrcoef(X[:, 0], X[:, 1])[0, 1])
    if not abs(r_paths) <= criteria.max_path_correlation:
        why = ("one of them does not vary" if np.isnan(r_paths) else f"r = {r_paths:.2f}")
        return _not_applicable(len(keys), "the coolant's and the rotor's paths to the rings "
                               f"are not separable on this run ({why})")
    coef = np.linalg.lstsq(X, E, rcond=None)[0]
    # jackknife over the plateaus: the blocks within one are correlated
    loo = np.array([np.linalg.lstsq(X[P != k], E[P != k], rcond=None)[0] for k in keys])
    m = len(keys)
    se = np.sqrt((m - 1) / m * np.sum((loo - loo.mean(axis=0)) ** 2, axis=0))
    R, se_R = float(coef[0]), float(se[0])
    if not (np.isfinite(se_R) and se_R > 0):
        return _not_applicable(m, "the plateaus do not determine it")
    z = R / se_R
    q = float(student.ppf(0.975, m - 1))
    return EventTest(name, ", ".join(channels), R, se_R, z, float(student.sf(z, m - 1)), m,
                     "K/W", MEANING, per_step=[{"t_s": a, "t_end_s": b} for a, b in plats],
                     parameter={"name": "R_adv_K_W", "value": max(R, 0.0),
                                "ci95": [max(R - q * se_R, 0.0), R + q * se_R]})
