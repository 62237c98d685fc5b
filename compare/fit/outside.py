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
  (the motor supplies it, so the logged power carries it).
"""

from __future__ import annotations

import numpy as np

from compare.fit.effects.base import Effect
from spindle.loads import TimeSeries


class ElectronicsDrift(Effect):
    name = "electronics_drift"

    def draw(self, rng):
        return {"amplitude_um": float(rng.uniform(1.0, 2.0)),
                "period_h": float(rng.uniform(4.0, 8.0)),
                "phase": float(rng.uniform(0.0, 2 * np.pi))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        phase = truth.get("phase", 0.0)
        wave = np.sin(2 * np.pi * t_s / (truth["period_h"] * 3600.0) + phase) - np.sin(phase)
        channels["P1"] = channels["P1"] + truth["amplitude_um"] * 1e-6 * wave
        return {}


class SensorDrift(Effect):
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


class CoolantSensorOffset(Effect):
    name = "coolant_sensor_offset"

    def draw(self, rng):
        return {"start_h": float(rng.uniform(3.0, 11.0)),
                "offset_K": float(rng.choice([-1, 1]) * rng.uniform(1.0, 2.5))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        t0, d = truth["start_h"] * 3600.0, truth["offset_K"]
        return {"T_coolant": lambda ts: np.where(np.asarray(ts) >= t0, d, 0.0)}


class BearingRunIn(Effect):
    name = "bearing_run_in"

    def draw(self, rng):
        return {"excess": float(rng.uniform(0.5, 1.2)), "tau_h": float(rng.uniform(1.0, 3.0))}

    def synth_case(self, case, spec, truth):
        bearings = [h.name for h in spec.heat_sources
                    if h.part and spec.part(h.part).role in ("front_bearing", "rear_bearing")]
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


OUTSIDE: dict[str, Effect] = {e.name: e for e in (ElectronicsDrift(), SensorDrift(),
                                                 CoolantSensorOffset(), BearingRunIn())}
