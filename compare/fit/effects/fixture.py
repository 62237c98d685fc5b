"""``fixture_expansion``: the P1 sensor's holder moves with the room.

The eddy-current sensor's holder is fixed to the housing's outside and expands with the air
temperature, so P1 carries a term proportional to the ambient's change since the start. No
signature test: the open-loop fit judges it (the ambient is an input, so the term's shape is
known).
"""

from __future__ import annotations

import numpy as np

from compare.fit.effects.base import Effect
from compare.fit.params import Param


class FixtureExpansion(Effect):
    name = "fixture_expansion"
    explanation = ("The eddy-current sensor's holder is fixed to the housing's outside and "
                   "moves with the air temperature, so P1 carries a term proportional to the "
                   "ambient change.")
    params = (Param("k_fix_um_K", "um/K", 0.0, -5.0, 5.0, "P1 change per K of ambient change",
                    log=False, source="a steel holder of 50-200 mm expands 0.6-2.4 um/K; "
                    "either sign, as it is mounted"),)
    channels = ("P1",)
    measurement_only = True
    hint = "the P1 sensor's holder (its length and material, and where it is fixed)"

    def p1(self, p1_m, theta, inputs):
        T_env = np.concatenate([[inputs.T_env_K[0]], inputs.T_env_K])
        return p1_m + theta["k_fix_um_K"] * 1e-6 * (T_env - T_env[0])

    def draw(self, rng):
        return {"k_fix_um_K": float(rng.choice([-1, 1]) * rng.uniform(0.8, 2.0))}

    def synth_measure(self, t_s, channels, case, truth, reference):
        env = np.asarray(case.T_ambient_K(t_s))
        channels["P1"] = channels["P1"] + truth["k_fix_um_K"] * 1e-6 * (env - env[0])
        return {}

    def measure(self, t_s, columns, truth, channel):
        env = columns["T_env_K"]
        env0 = env[np.isfinite(env)][0]
        return {**columns, "P1": columns["P1"] + truth["k_fix_um_K"] * 1e-6 * np.where(
            np.isfinite(env), env - env0, 0.0)}
