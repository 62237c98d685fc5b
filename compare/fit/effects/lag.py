"""``sensor_lag``: one sensor reads through a first-order lag (a PT100 in a bore with poor
contact, a filtered displacement channel). Tried on each measured channel.

Signature: a heat step changes a channel's slope at once; read through a lag, the change is
gradual, and the onset after a speed step is S-shaped instead of concave. The onset ratio
(the change of slope early after the steps over that later, :func:`lag_test`) is below 1 for
a lagging channel, where the base model expects the channel to respond at once.
"""

from __future__ import annotations

import math

import numpy as np

from compare.fit.effects.base import Effect
from compare.fit.params import Param
from compare.fit.signatures import EventTest, onset_ratio
from lumped.elastic import first_order_lag


class SensorLag(Effect):
    name = "sensor_lag"
    explanation = ("A sensor reads with a first-order lag: a PT100 in a bore with poor "
                   "contact, or a filtered displacement channel.")
    params = (Param("tau_s", "s", 0.0, 0.0, 3600.0, "time constant of the lag", log=False,
                    source="a PT100 in a bore with a gap reads with minutes; an hour bounds "
                    "what a 16 h run can tell from the thermal response"),)
    per_channel = True
    measurement_only = True
    hint = "the sensor's mounting (contact, bore, filter settings of its channel)"

    def as_measured(self, out, theta, inputs, channel):
        if channel in out and theta["tau_s"] > 0:
            out = {**out, channel: first_order_lag(inputs.grid_s, out[channel], theta["tau_s"])}
        return out

    def signature(self, ctx) -> dict:
        out = {}
        onsets = ctx.model_onsets()
        for c in ctx.channels:
            test = lag_test(c, *ctx.run.channel(c), ctx.steps_by_scale(),
                            onsets.ratios.get(c, {}), ctx.criteria,
                            onsets.ratio_se.get(c, {}))
            if np.isfinite(test.z):
                sc = next(s for s in ctx.criteria.onset_scales if s.name == test.scale)
                lo, hi = test.estimate - 1.96 * test.se, test.estimate + 1.96 * test.se
                tau = onsets.lag_for_ratio(c, test.estimate, sc)
                # beyond the lagged model's floor (a long lag turns the onset into a ramp
                # whose ratio stops falling) the ratio says "lagged" but not by how much: no
                # prior on tau then, the fit over the whole run estimates it
                if tau < ctx.criteria.lag_grid_s[-1]:
                    test.parameter = {"name": "tau_s", "value": tau,
                                      "ci95": [onsets.lag_for_ratio(c, hi, sc),
                                               onsets.lag_for_ratio(c, lo, sc)]}
            out[f"{self.name}({c})"] = test
        return out

    def draw(self, rng):
        return {"channel": str(rng.choice(["T1", "T2", "T_stator", "P1"])),
                "tau_s": float(rng.uniform(400, 900))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        c = truth["channel"]
        channels[c] = first_order_lag(t_s, channels[c], truth["tau_s"])
        return {}

    def measure(self, t_s, columns, truth, channel):
        x = columns[channel]
        ok = np.isfinite(x)
        y = np.full_like(x, np.nan)
        y[ok] = first_order_lag(t_s[ok], x[ok], float(truth["tau_s"]))
        return {**columns, channel: y}


def lag_test(channel: str, t_s: np.ndarray, y: np.ndarray, steps: dict, model_ratios: dict,
             criteria, model_se: dict | None = None) -> EventTest:
    """The onset test of one channel at every onset scale of ``criteria``: z = (1 - ratio) /
    se at the scales where the model expects the channel to respond at once: its ratio
    (``model_ratios``) minus z_(1-alpha) times its standard error (``model_se``, the ratio's
    scatter over the model's own steps; 0 where not given) is at least
    ``criteria.concave_ratio``. The test reports the scale with the largest z, its one-sided
    p multiplied by the number of such scales (Bonferroni). Not applicable (p = nan) at no
    such scale."""
    from scipy.stats import norm

    meaning = ("change of slope early after the speed steps over that later (above 1: responds "
               "at once; below 1: reads through a lag)")
    scales, best = [], None
    for sc in criteria.onset_scales:
        ratio, se, rows = onset_ratio(t_s, y, steps[sc.name], sc, criteria)
        ref = model_ratios.get(sc.name, math.nan)
        ref_se = (model_se or {}).get(sc.name, 0.0)
        # the model's ratio scatters over its own steps: a ratio above concave_ratio by less
        # than its one-sided interval at alpha does not say the channel responds at once
        lower = ref - float(norm.isf(criteria.alpha)) * ref_se
        ok = bool(np.isfinite(ratio) and np.isfinite(lower) and lower >= criteria.concave_ratio)
        z = (1.0 - ratio) / se if ok else math.nan
        scales.append({"scale": sc.name, "ratio": ratio, "se": se, "model_ratio": ref,
                       "model_ratio_se": ref_se, "applicable": ok, "z": z,
                       "n_steps": len(rows)})
        if ok and (best is None or z > best[3]):
            best = (sc, ratio, se, z, ref, rows)
    if best is None:
        first = scales[0]
        return EventTest("sensor_lag", channel, first["ratio"], first["se"], math.nan, math.nan,
                         first["n_steps"], "-", meaning + " (the model's own onset is not "
                         "concave here, or too few steps: no lag can be read)",
                         first["model_ratio"], scale=criteria.onset_scales[0].name,
                         scales=scales)
    sc, ratio, se, z, ref, rows = best
    n_ok = sum(x["applicable"] for x in scales)
    p = min(1.0, n_ok * float(norm.sf(z)))
    return EventTest("sensor_lag", channel, ratio, se, z, p, len(rows), "-",
                     f"{meaning}, at the scale {sc.name}", ref, rows, scale=sc.name,
                     scales=scales)
