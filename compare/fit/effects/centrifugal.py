"""``centrifugal_shortening``: P1 drops with the square of the speed, at once.

At speed the rotating shaft is stretched radially by the centrifugal load and, by Poisson's
ratio, shortens axially. The shortening follows n^2 with no thermal lag, so P1 jumps at every
speed step. Signature: P1's jump at the speed steps against -(n_after^2 - n_before^2)
(:func:`jump_test`); no thermal response can jump.
"""

from __future__ import annotations

import math

import numpy as np

from compare.fit.effects.base import Effect
from compare.fit.params import Param
from compare.fit.signatures import EventTest, line_fit, through_origin


class CentrifugalShortening(Effect):
    name = "centrifugal_shortening"
    explanation = ("At speed the rotating shaft is stretched radially by the centrifugal load "
                   "and, by Poisson's ratio, shortens axially; the shortening follows n^2 at "
                   "once, with no thermal lag, so P1 drops at every speed-up and recovers at "
                   "every slow-down.")
    params = (Param("c_cf_um_krpm2", "um/krpm^2", 0.0, 0.0, 1.0,
                    "axial shortening at P1 per (1000 rpm)^2", log=False,
                    source="the FEM's own centrifugal load of spl2782 gives 0.014 um/krpm^2; "
                    "a more compliant rotor up to tens of times that"),)
    channels = ("P1",)
    measurement_only = True
    hint = ("the rotor's centrifugal shortening: compensate P1 by -c n^2 at once, beside the "
            "thermal model")

    def p1(self, p1_m, theta, inputs):
        n_end = np.concatenate([[inputs.speed_rpm[0]], inputs.speed_rpm])  # over the step
        return p1_m - theta["c_cf_um_krpm2"] * 1e-6 * (n_end / 1000.0) ** 2

    def signature(self, ctx) -> dict:
        if "P1" not in ctx.channels:
            return {}
        return {self.name: jump_test(*ctx.run.channel("P1"), ctx.steps(), ctx.criteria)}

    def draw(self, rng):
        return {"scale": float(rng.uniform(8.0, 15.0))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        # the FEM's centrifugal part, scaled, follows the speed at once: it is evaluated at
        # the bench's own sample times, not interpolated from the model grid, where it would
        # ramp over a whole time step after every speed step
        scale = truth["scale"]
        return {"P1": lambda ts: scale * reference.centrifugal_m(case, ts, "P1")}

    def measure(self, t_s, columns, truth, channel):
        n = np.nan_to_num(columns["speed_rpm"])
        return {**columns, "P1": columns["P1"] - truth["c_cf_um_krpm2"] * 1e-6 * (n / 1000.0) ** 2}


def jump_test(t_s: np.ndarray, p1_m: np.ndarray, steps, criteria) -> EventTest:
    """P1's jumps at the speed steps against -(n_after^2 - n_before^2): the shortening c
    [µm/krpm^2], z = c / se, one-sided p (c > 0 is a shortening). The jump is the offset at
    the step instant between a line fitted just before it and one just after it (a thermal
    response is continuous; its curvature biases the offset against a shortening, so the
    test is conservative)."""
    from scipy.stats import norm

    J, X, S, rows = [], [], [], []
    sparse = 0  # steps large enough whose windows hold too few of P1's samples
    for s in steps:
        if abs(s.dn2_krpm2) < criteria.jump_min_dn2_krpm2:
            continue
        before = line_fit(t_s, p1_m, criteria.jump_before_s, s.t_s, criteria)
        after = line_fit(t_s, p1_m, criteria.jump_after_s, s.t_s, criteria)
        if before is None or after is None:
            sparse += 1
            continue
        jump_um = (after[0] - before[0]) * 1e6
        se_um = math.hypot(after[2], before[2]) * 1e6
        J.append(jump_um)
        X.append(-s.dn2_krpm2)
        S.append(max(se_um, criteria.jump_se_floor_um))
        rows.append({"t_s": s.t_s, "n_before_rpm": s.n_before_rpm, "n_after_rpm": s.n_after_rpm,
                     "jump_um": jump_um, "se_um": se_um})
    if len(J) < 2:
        why = "too few clean speed steps to read P1's jumps"
        if sparse:
            a, b = criteria.jump_after_s
            why += (f": {sparse} step(s) have fewer than {criteria.line_min_samples} of P1's "
                    f"samples within {a:g}-{b:g} s after them or in the minutes before (P1 "
                    "logged too sparsely to see a jump)")
        return EventTest("centrifugal_shortening", "P1", math.nan, math.nan, math.nan, math.nan,
                         len(J), "um/krpm^2", why)
    c, se = through_origin(np.array(J), np.array(X), np.array(S))
    z = c / se
    return EventTest("centrifugal_shortening", "P1", c, se, z, float(norm.sf(z)), len(J),
                     "um/krpm^2", "P1's jump at the speed steps per (1000 rpm)^2 of the step "
                     "(positive: shortening as the speed rises)", per_step=rows,
                     parameter={"name": "c_cf_um_krpm2", "value": c,
                                "ci95": [c - 1.96 * se, c + 1.96 * se]})
