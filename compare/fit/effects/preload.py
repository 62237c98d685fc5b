"""``bearing_preload``: the inner ring runs warmer than the outer ring; the difference expands
the inner ring more and raises the preload of the angular-contact pairs, so the friction heat
rises with the ring difference, Q (1 + k (T_inner - T_outer)): a thermal feedback.

Signature (runs with a measured power): at constant speed and no load the drive draws the
bearing friction, so the power *drifts* as the ring difference builds up after a speed-up and
decays after a slow-down; a spindle without the feedback draws a power that settles within
the drive's own response. The drifts of the no-load segments, regressed on the drift the
calibrated base model's q_b (T_inner - T_outer) makes over the same windows, give k
(:func:`drift_test`). The extra friction is a torque the motor supplies, so the logged power
already holds it: the model takes it out of the motor sources (:func:`_drag_flows`).
"""

from __future__ import annotations

import math

import numpy as np

from compare.fit.effects.base import Effect, Feedback
from compare.fit.params import Param
from compare.fit.signatures import EventTest, through_origin
from lumped.blocks import PrescribedHeatFlow
from spindle.drive_file import MOTOR_SOURCES
from spindle.loads import TimeSeries

FRONT, REAR = "k_preload_1_K", "k_preload_rear_1_K"


class BearingPreload(Effect):
    name = "bearing_preload"
    explanation = ("The inner ring runs warmer than the outer ring; the difference expands the "
                   "inner ring more and raises the preload of the angular-contact pairs, so the "
                   "friction heat rises with the shaft-housing temperature difference (a "
                   "thermal feedback).")
    params = (Param(FRONT, "1/K", 0.0, 0.0, 1.0,
                    "relative rise of the front bearing's friction per K of its inner-outer "
                    "ring difference", log=False,
                    source="Harris: rigidly preloaded pairs gain 5-20 % friction per K of "
                    "ring difference"),
              Param(REAR, "1/K", 0.0, 0.0, 1.0,
                    "the same for the rear bearing (often spring-preloaded and floating, where "
                    "it stays near 0)", log=False, source="as the front set's"))
    # the feedback's flows enter the matrices (share x k x the bearing's heat), and so does
    # the motor's share of the drag flows: the rotor's share of the motor loss
    in_conductance = (FRONT, REAR, "rotor_share")
    hint = ("the bearings' preload (rigid front set: its preload rises as the inner ring "
            "warms; a spring preload or more radial play holds it)")

    def network_options(self):
        return {"bearing_tc_1_K": 1.0}  # set per parameter set

    def extend_network(self, net, spec, power_measured):
        feedback = [(b, param_of(spec, b.source)) for b in net.network.blocks
                    if isinstance(b, PrescribedHeatFlow) and b.across is not None]
        return feedback, (_drag_flows(net) if power_measured else [])

    def configure(self, handle, theta):
        feedback, drag = handle
        for f, name in feedback:
            f.tc_1_K = theta.get(name, 0.0)
        rs = theta["rotor_share"]
        for neg, pos, motor_source, share, k_name in drag:
            w = share * (rs if motor_source == "rotor" else 1.0 - rs)
            neg.share, pos.share = -w, w
            neg.tc_1_K = theta.get(k_name, 0.0)

    def signature(self, ctx) -> dict:
        if ctx.segments() is None:
            return {}
        test = drift_test(ctx.segments(), ctx.criteria,
                          model_drift_of(ctx.gb, ctx.theta, ctx.criteria))
        if test.applies:  # the front set's coefficient, significant or not (its interval
            # says what size of preload the drifts exclude)
            test.parameter = front_parameter(test, ctx.gb, ctx.theta, ctx.criteria)
        return {self.name: test}

    def draw(self, rng):
        k = float(rng.uniform(0.10, 0.20))  # both bearing sets alike
        return {FRONT: k, REAR: k}

    def feedback(self, thermal, spec, truth):
        rings = [(p.name, sec) for p in spec.parts if p.role in ("front_bearing", "rear_bearing")
                 for sec in p.sections if sec.name in ("inner_ring", "outer_ring")]
        pts = []
        for _, sec in rings:  # each ring's mid-point
            z = 0.5 * (sec.z_start + sec.z_end)
            pts.append((z, 0.5 * float(sec.r_in(z) + sec.r_out(z))))
        P = thermal.probe_matrix(np.array(pts).T).toarray()
        functionals = {f"{p}.{sec.name}": row for (p, sec), row in zip(rings, P, strict=True)}
        bearings = spec.sources_with_role("front_bearing", "rear_bearing")
        # a truth written before the rear coefficient existed holds one for both
        ks = [truth.get(param_of(spec, h.name), truth[FRONT]) for h in bearings]

        def differences(readings, case, t):
            return np.concatenate([readings[f"{h.part}.inner_ring"]
                                   - readings[f"{h.part}.outer_ring"] for h in bearings])

        def apply(case, x, t):
            return case.with_sources({
                h.name: TimeSeries(tuple(t), tuple(np.asarray(case.sources[h.name](t))
                                                   * (1 + k * dT)))
                for h, k, dT in zip(bearings, ks, np.split(x, len(bearings)), strict=True)})

        def drag(ts, case, t, x):
            extra = sum(np.asarray(case.sources[h.name](t)) * k * dT
                        for h, k, dT in zip(bearings, ks, np.split(x, len(bearings)),
                                            strict=True))
            return np.interp(ts, t, extra)

        return Feedback(functionals, apply, differences, differences, {"power_W": drag})


def param_of(spec, source: str) -> str:
    """The preload parameter of a bearing heat source: the front set's or the rear's."""
    src = next(h for h in spec.heat_sources if h.name == source)
    return REAR if spec.part(src.part).role == "rear_bearing" else FRONT


def _drag_flows(net) -> list[tuple]:
    """Heat flows that take a bearing preload's extra friction out of the motor sources.

    On a bench the motor supplies the extra friction torque, so the measured electrical power
    already holds the extra heat, which the power balance (knowing no preload) booked as motor
    loss. For each bearing with rings and each motor-source flow (share s of its source): a flow
    -s w q_b (1 + k (T_in - T_out)) and a flow +s w q_b, which together take s w q_b k (T_in -
    T_out) from that motor mass (w the source's fraction of the motor loss, set per parameter
    set; k set with the preload's own flows). Returns (negative flow, constant flow, motor
    source, s, the bearing's preload parameter) per pair."""
    masses = {m.name: m for pm in net.parts.values() for m in pm.masses}
    motor = [b for b in net.network.blocks
             if isinstance(b, PrescribedHeatFlow) and b.source in MOTOR_SOURCES]
    rings = [(src.name, net.parts[src.part].masses) for src in net.spec.heat_sources
             if src.part is not None and net.parts[src.part].ring]
    out = []
    for bearing, (inner, outer) in rings:
        for f in motor:
            mass = masses[f.name.split(":", 2)[2]]
            neg = net.network.add(PrescribedHeatFlow(
                f"preload_drag:{bearing}:{mass.name}", source=bearing, share=0.0, tc_1_K=0.0,
                across=(inner.block.port, outer.block.port)))
            pos = net.network.add(PrescribedHeatFlow(
                f"preload_drag_base:{bearing}:{mass.name}", source=bearing, share=0.0))
            net.network.connect(mass.block.port, neg.port)
            net.network.connect(mass.block.port, pos.port)
            out.append((neg, pos, f.source, f.share, param_of(net.spec, bearing)))
    return out


def ring_drag_W(gb, theta: dict[str, float]) -> dict[str, np.ndarray]:
    """Per bearing heat source with rings: q_b (T_inner - T_outer) [W] at the grid points
    (the interval's heat held), the extra friction a preload of 1/K would add."""
    model = gb.structure_model()
    net = model.net
    th = gb.full_theta(theta)
    heat = gb.sources(th["f0"], th["rotor_share"], th.get("friction_exponent", 0.0))
    rows, names = {}, []
    for src in gb.spec.heat_sources:
        # a source the drive does not feed has no heat, so no drag (spindle.drive)
        if src.part is not None and net.parts[src.part].ring and src.name in heat:
            inner, outer = net.parts[src.part].masses
            r = np.zeros(model.system.n_states)
            r[inner.index], r[outer.index] = 1.0, -1.0
            rows[f"ring:{src.name}"] = r
            names.append(src.name)
    out = gb.simulate(theta, extra_rows=rows)
    # at a grid point, the heat of the interval ending there
    return {n: np.concatenate([heat[n][:1], heat[n]]) * out[f"ring:{n}"] for n in names}


def model_drift_of(gb, theta: dict[str, float], criteria, front_only: bool = False):
    """``(t0, t1) -> drift [W]`` of q_b (T_inner - T_outer) summed over the bearings (or the
    front set's alone) of the grey box ``gb`` at ``theta``, over a segment's windows: the
    extra power of a preload of k = 1/K (:func:`ring_drag_W`)."""
    drag = ring_drag_W(gb, theta)
    parts = [v for k, v in drag.items() if not front_only or param_of(gb.spec, k) == FRONT]
    t = gb.inputs.grid_s
    if not parts:
        return lambda t0, t1: math.nan
    e = np.sum(parts, axis=0)
    early_s, late_s = criteria.drift_early_s, criteria.drift_late_s

    def drift(t0: float, t1: float) -> float:
        early = e[(t >= t0 + early_s[0]) & (t <= t0 + early_s[1])]
        late = e[(t >= t1 - late_s) & (t <= t1)]
        if len(early) == 0 or len(late) == 0:
            return math.nan
        return float(late.mean() - early.mean())

    return drift


def drift_test(segs, criteria, model_drift) -> EventTest:
    """The power's drift at constant speed and no load against the base model's drift of
    q_b (T_inner - T_outer) over the same windows (``model_drift(t0, t1)``, a preload of
    k = 1/K): regressed through the origin, the estimate is k [1/K], z = k / se, one-sided p
    (a preload raises the friction)."""
    from scipy.stats import norm

    D, X, S, rows = [], [], [], []
    held = 0  # segments whose conditions hold (long, no load, after no load), read or not
    for prev, s in zip(segs[:-1], segs[1:], strict=True):
        if not (s.no_load and s.duration_s >= criteria.drift_min_segment_s) or (
                abs(prev.torque_Nm) > criteria.no_load_Nm):
            continue
        held += 1
        # after a no-load segment (or standstill) whose level is read, as this one's
        before = prev.settled_W()[0] if prev.speed_rpm >= criteria.moving_rpm else 0.0
        early, se_e, _ = s.mean_W(*criteria.drift_early_s)
        late, se_l, _ = s.mean_W(s.duration_s - criteria.drift_late_s, s.duration_s + 1.0)
        if not all(np.isfinite([before, early, late, s.settled_W()[0]])):
            continue
        x = model_drift(s.t0_s, s.t1_s)
        if not np.isfinite(x):
            continue
        D.append(late - early)
        X.append(x)
        S.append(max(math.hypot(se_e, se_l), criteria.power_resolution_W))
        rows.append({"t_s": s.t0_s, "t_end_s": s.t1_s, "speed_rpm": s.speed_rpm,
                     "drift_W": late - early, "se_W": math.hypot(se_e, se_l),
                     "predictor_W": x})
    meaning = ("drift of the no-load power at constant speed against the base model's drift of "
               "q_b (T_inner - T_outer): the preload coefficient k [1/K] (positive: the "
               "friction rises with the ring difference, a preload)")
    if len(D) < criteria.drift_min_segments <= held:
        # the run has the segments, its log not the power within minutes of their start
        return EventTest("bearing_preload", "power", math.nan, math.nan, math.nan, math.nan,
                         len(D), "1/K", meaning + f" (unreadable: {held} long no-load "
                         f"segments after a speed change, but the power is logged in the "
                         f"window {criteria.drift_early_s[0]:g}-{criteria.drift_early_s[1]:g} s "
                         f"after their start on only {len(D)}; a preload cannot then be told "
                         "from the base's misfit, so the open loop does not name it alone)",
                         per_step=rows, unreadable=True)
    if len(D) < criteria.drift_min_segments or max((abs(x) for x in X), default=0.0) < \
            criteria.power_resolution_W:
        return EventTest("bearing_preload", "power", math.nan, math.nan, math.nan, math.nan,
                         len(D), "1/K", meaning + " (too few long no-load segments after a "
                         "speed change: no drift can be read)", per_step=rows)
    b, se = through_origin(np.array(D), np.array(X), np.array(S))
    z = b / se
    return EventTest("bearing_preload", "power", b, se, z, float(norm.sf(z)), len(D), "1/K",
                     meaning, per_step=rows)


def front_parameter(test: EventTest, gb, theta: dict[str, float], criteria) -> dict | None:
    """The front set's coefficient k [1/K] the measured drifts call for, regressed on the
    front set's own model drift, with its 95 % interval (a start and prior for the fit: the
    thermal fit then decides both coefficients)."""
    if not test.per_step:
        return None
    drift = model_drift_of(gb, theta, criteria, front_only=True)
    D, X, S = [], [], []
    for row in test.per_step:
        x = drift(row["t_s"], row["t_end_s"])
        if np.isfinite(x):
            D.append(row["drift_W"])
            X.append(x)
            S.append(max(row["se_W"], criteria.power_resolution_W))
    if len(D) < 2 or max(abs(x) for x in X) <= 0.0:
        return None
    k, se = through_origin(np.array(D), np.array(X), np.array(S))
    if not np.isfinite(k):
        return None
    return {"name": FRONT, "value": max(k, 0.0), "ci95": [max(k - 1.96 * se, 0.0), k + 1.96 * se]}
