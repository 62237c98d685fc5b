"""``windage_loss``: air friction of the rotor and the shaft, rising with n^3, heats the rotor
beyond what the electrical balance assigns to it.

Signature: the no-load power levels of a motor spindle are sums of terms in n, n^(5/3)
(Palmgren's viscous friction) and n^2 (eddy currents); a term in n^3 is windage
(:func:`cube_test`).
"""

from __future__ import annotations

import math

import numpy as np

from compare.fit.effects.base import Effect, heat_from_motor, spread_heat
from compare.fit.params import Param
from compare.fit.signatures import EventTest
from spindle.loads import TimeSeries


class WindageLoss(Effect):
    name = "windage_loss"
    explanation = ("Air friction of the rotor in the air gap and of the shaft surfaces, "
                   "rising roughly with n^3, heats the rotor beyond what the electrical "
                   "balance assigns to it.")
    params = (Param("c_w_W_krpm3", "W/krpm^3", 0.0, 0.0, 5.0,
                    "windage heat per (1000 rpm)^3 into the rotor", log=False,
                    source="Vrancik's air-gap friction for a 90 mm rotor of 0.3 m: about "
                    "0.5 W/krpm^3; up to a few W with a rough or finned rotor"),)
    hint = ("air friction of the rotor and shaft (the air gap, the rotor's ends, the nose's "
            "labyrinth): a loss the motor model lacks")
    synth_sources = ("rotor",)  # its synthetic heat rides on the rotor's source
    # the motor supplies windage's drag, so the logged power holds it; a loss split that
    # moves heat into the rotor at speed changes where the heat goes, not how much
    look_alike = ("a rotor share of the motor losses that rises with speed (eddy currents in "
                  "the magnets and their sleeve)")

    def extend_network(self, net, spec, power_measured):
        rotor = [p for p in net.parts.values() if p.part.role == "rotor"]
        masses = rotor[0].masses if rotor else net.parts[spec.parts[0].name].masses
        spread_heat(net, masses, "windage", "source:windage")

    def heat(self, sources_W, theta, inputs):
        return from_motor(sources_W, theta["c_w_W_krpm3"], inputs.speed_rpm, inputs.power_kW)

    def signature(self, ctx) -> dict:
        if ctx.segments() is None:
            return {}
        # the levels are not settled where the power drifts at constant speed (the preload's
        # test, run before this one: the library's order)
        drift = ctx.tests.get("bearing_preload")
        drifting = bool(drift is not None and drift.significant(ctx.criteria.alpha))
        return {self.name: cube_test(ctx.segments(), ctx.criteria, drifting)}

    def draw(self, rng):
        return {"c_w_W_krpm3": float(rng.uniform(0.6, 1.5))}

    def synth_case(self, case, spec, truth):
        rotor = [h.name for h in spec.sources_with_role("rotor")]
        src = case.sources[rotor[0]]
        t = np.asarray(src.time_s)
        c = truth["c_w_W_krpm3"]
        extra = c * (np.asarray(case.speed_rpm(t + 1e-6)) / 1000.0) ** 3
        values = tuple(np.asarray(src.values) + extra)
        case = case.with_sources({rotor[0]: TimeSeries(tuple(t), values, src.interpolation)})
        # a drag the motor supplies: the logged electrical power carries it
        return case, {"power_W": lambda ts: c * (np.asarray(case.speed_rpm(ts), dtype=float)
                                                 / 1000.0) ** 3}


def from_motor(sources_W: dict[str, np.ndarray], c_W_krpm3: float, speed_rpm: np.ndarray,
               power_kW: np.ndarray) -> dict[str, np.ndarray]:
    """The heat sources [W] per interval with a windage loss c (n / 1000 rpm)^3 [W] into the
    rotor (source ``windage``), a drag the motor supplies (compare.fit.effects.base.
    heat_from_motor)."""
    w = c_W_krpm3 * (np.asarray(speed_rpm, dtype=float) / 1000.0) ** 3
    return heat_from_motor(sources_W, "windage", w, power_kW)


def cube_test(segs, criteria, drifting: bool = False) -> EventTest:
    """The n^3 term of the settled no-load power levels [W/krpm^3]: levels regressed on n,
    n^(5/3), n^2 and n^3 (ordinary least squares), t = c / se with the scatter between levels,
    one-sided p from Student's t. Not applicable with too few levels or span, or when the
    power drifts at constant speed (``drifting``: its levels are not settled)."""
    from scipy.stats import t as student

    levels: list[list[tuple[float, float]]] = []  # per speed level, its (speed, power) pairs
    for s in segs:
        if not s.no_load or s.duration_s < criteria.level_min_s:
            continue
        P, _ = s.settled_W()
        if not np.isfinite(P):
            continue
        for lv in levels:  # joins the first level within level_rpm of its first speed
            if abs(lv[0][0] - s.speed_rpm) <= criteria.level_rpm:
                lv.append((s.speed_rpm, P))
                break
        else:
            levels.append([(s.speed_rpm, P)])
    n = np.array([np.mean([v[0] for v in lv]) for lv in levels]) / 1e3
    P = np.array([np.mean([v[1] for v in lv]) for lv in levels])
    rows = [{"speed_rpm": float(a * 1e3), "power_W": float(b)} for a, b in zip(n, P, strict=True)]
    meaning = "windage: the n^3 term of the settled no-load power [W/krpm^3]"
    span = float(n.max() / n.min()) if len(n) else 0.0
    if drifting or len(n) < criteria.min_levels or span < criteria.min_speed_span:
        why = ("the power drifts at constant speed (a preload), so its levels are not settled"
               if drifting else f"fewer than {criteria.min_levels} no-load speed levels "
               f"spanning a factor {criteria.min_speed_span:g}")
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
    q = float(student.ppf(0.975, dof))
    return EventTest("windage_loss", "power", c, se, tval, float(student.sf(tval, dof)), len(n),
                     "W/krpm^3", meaning, per_step=rows,
                     parameter={"name": "c_w_W_krpm3", "value": max(c, 0.0),
                                "ci95": [max(c - q * se, 0.0), c + q * se]})
