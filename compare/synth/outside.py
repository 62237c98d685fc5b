"""Causes outside the library, for synthetic runs only: what ``fit`` should call
``unexplained`` and name nothing for. They use the hooks of an effect
(compare.fit.effects.base.Effect) but are not registered in the library, so the fit never
tries them. Each is a kind of thing that goes wrong on a bench, unlike the library's effects,
which are laws of the inputs:

- ``electronics_drift``: the P1 electronics drift slowly (a sinusoid of hours);
- ``sensor_drift``: a temperature sensor's reading drifts linearly from some time on (an
  ageing connection);
- ``coolant_sensor_offset``: the coolant temperature the bench logs is off from some time on
  (its sensor moved to the chiller's return), so the model is driven with a wrong input;
- ``bearing_run_in``: fresh grease: the bearings' friction starts high and decays over hours
  (the motor supplies it, so the logged power carries it);
- ``enclosure_draft``: the air around the spindle is warmer or colder for a few hours (an
  enclosure door open, a neighbour's exhaust) while the room sensor, elsewhere, reads on;
- ``coolant_flow_drop``: the coolant flow falls for a few hours (a filter clogging, then
  cleaned): the water warms along the jacket as ``coolant_dynamics`` has it, but only then,
  so no law of the inputs holds for the whole run.

Each says where in the run it acts (``acts_s``), which benchmarks/verdicts.py ``located``
compares with the window an "unexplained" verdict gives.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from compare.fit.effects.base import Effect, Feedback
from spindle.loads import TimeSeries

#: the ramp [s] at either end of a window of hours: a door opened, a filter clogging
RAMP_S = 600.0


def _window(t_s, start_h: float, duration_h: float) -> np.ndarray:
    """0 before ``start_h``, 1 for ``duration_h`` after it, 0 again, with linear ramps of
    :data:`RAMP_S` [s] in between."""
    t = np.asarray(t_s, dtype=float)
    a, b = start_h * 3600.0, (start_h + duration_h) * 3600.0
    return np.clip((t - a) / RAMP_S, 0.0, 1.0) * np.clip((b + RAMP_S - t) / RAMP_S, 0.0, 1.0)


def _draw_window(rng) -> dict:
    return {"start_h": float(rng.uniform(3.0, 10.0)), "duration_h": float(rng.uniform(1.5, 4.0))}


class _Windowed(Effect):
    """A cause that acts during a window of hours (:func:`_draw_window`)."""

    def acts_s(self, truth) -> tuple[float, float] | None:
        """Where in the run it acts [s]: its window, the closing ramp included."""
        a = truth["start_h"] * 3600.0
        return a, a + truth["duration_h"] * 3600.0 + RAMP_S


class _FromStart(Effect):
    """A cause that acts from a drawn start (``start_h``) to the run's end."""

    def acts_s(self, truth) -> tuple[float, float] | None:
        """Where in the run it acts [s]: from its start on."""
        return truth["start_h"] * 3600.0, math.inf


class ElectronicsDrift(Effect):
    name = "electronics_drift"

    def acts_s(self, truth) -> tuple[float, float] | None:
        """Where in the run it acts [s]: over the whole run, no window (None)."""
        return None

    def draw(self, rng):
        return {"amplitude_um": float(rng.uniform(1.0, 2.0)),
                "period_h": float(rng.uniform(4.0, 8.0)),
                "phase": float(rng.uniform(0.0, 2 * np.pi))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        phase = truth.get("phase", 0.0)
        wave = np.sin(2 * np.pi * t_s / (truth["period_h"] * 3600.0) + phase) - np.sin(phase)
        channels["P1"] = channels["P1"] + truth["amplitude_um"] * 1e-6 * wave
        return {}


class SensorDrift(_FromStart):
    name = "sensor_drift"

    def draw(self, rng):
        return {"channel": str(rng.choice(["T1", "T2", "T_stator"])),
                "start_h": float(rng.uniform(2.0, 10.0)),
                "rate_K_h": float(rng.choice([-1, 1]) * rng.uniform(0.3, 0.8))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        c = truth["channel"]
        h = np.maximum(t_s / 3600.0 - truth["start_h"], 0.0)
        channels[c] = channels[c] + truth["rate_K_h"] * h
        return {}


class CoolantSensorOffset(_FromStart):
    name = "coolant_sensor_offset"
    needs_coolant = True  # without a coolant film the logged coolant drives nothing

    def draw(self, rng):
        return {"start_h": float(rng.uniform(3.0, 11.0)),
                "offset_K": float(rng.choice([-1, 1]) * rng.uniform(1.0, 2.5))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        t0, d = truth["start_h"] * 3600.0, truth["offset_K"]
        return {"T_coolant": lambda ts: np.where(np.asarray(ts) >= t0, d, 0.0)}


class BearingRunIn(Effect):
    name = "bearing_run_in"

    def acts_s(self, truth) -> tuple[float, float] | None:
        """Where in the run it acts [s]: from the start to three decay times (the excess is
        then under 5 % of its first value)."""
        return 0.0, 3.0 * truth["tau_h"] * 3600.0

    def draw(self, rng):
        return {"excess": float(rng.uniform(0.5, 1.2)), "tau_h": float(rng.uniform(1.0, 3.0))}

    def synth_case(self, case, spec, truth):
        bearings = [h.name for h in spec.sources_with_role("front_bearing", "rear_bearing")]
        a, tau = truth["excess"], truth["tau_h"] * 3600.0
        out = {}
        extra = []
        for name in bearings:
            src = case.sources[name]
            t = np.unique(np.concatenate([np.asarray(src.time_s, dtype=float),
                                          np.arange(0.0, case.duration_s + 1.0, 600.0)]))
            q = np.asarray(src(t), dtype=float)
            # held over 10 min pieces, the cycle's steps kept
            out[name] = TimeSeries(tuple(t), tuple(q * (1.0 + a * np.exp(-t / tau))),
                                   "previous")
            extra.append((src, t))

        def drag(ts):
            ts = np.asarray(ts, dtype=float)
            return sum(np.asarray(src(ts), dtype=float) * a * np.exp(-ts / tau)
                       for src, _ in extra)

        return case.with_sources(out), {"power_W": drag}


class EnclosureDraft(_Windowed):
    name = "enclosure_draft"

    def draw(self, rng):
        return {**_draw_window(rng), "delta_K": float(rng.choice([-1, 1]) * rng.uniform(4.0, 8.0))}

    def synth_case(self, case, spec, truth):
        t = np.arange(0.0, case.duration_s + 60.0, 60.0)

        def change(ts):
            return truth["delta_K"] * _window(ts, truth["start_h"], truth["duration_h"])

        air = TimeSeries(tuple(t), tuple(np.asarray(case.T_ambient_K(t)) + change(t)))
        # the physics sees it; the bench logs the room from the cycle's own load case
        # (compare.synth.bench.bench_rows), which does not
        return replace(case, T_ambient_K=air), {}


class CoolantFlowDrop(_Windowed):
    name = "coolant_flow_drop"
    needs_coolant = True

    def draw(self, rng):
        return {**_draw_window(rng), "R_K_W": float(rng.uniform(0.003, 0.008))}

    def feedback(self, thermal, spec, truth):
        from reference.thermal import TWO_PI

        rows = [TWO_PI * s.h_W_m2K(0.0) * b for s, _, b in thermal.op.films
                if s.T_ref == "coolant"]
        g = np.sum(rows, axis=0)
        Gs = float(g.sum())

        def apply(case, x, t):
            return replace(case, T_coolant_K=TimeSeries(tuple(t), tuple(x)))

        def update(readings, case, t):
            # as coolant_dynamics, with the resistance of the window: Tm = (Ts + R g.T) /
            # (1 + R sum g)
            R = truth["R_K_W"] * _window(t, truth["start_h"], truth["duration_h"])
            return (np.asarray(case.T_coolant_K(t)) + R * readings["coolant_bT"]) / (1.0 + R * Gs)

        def start(readings, case, t):
            return np.asarray(case.T_coolant_K(t), dtype=float)

        return Feedback({"coolant_bT": g}, apply, update, start)


OUTSIDE: dict[str, Effect] = {e.name: e for e in (ElectronicsDrift(), SensorDrift(),
                                                 CoolantSensorOffset(), BearingRunIn(),
                                                 EnclosureDraft(), CoolantFlowDrop())}
