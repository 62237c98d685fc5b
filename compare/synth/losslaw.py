"""Loss laws the spec does not have, for synthetic runs only: a spindle whose losses go where
the spec's motor model does not put them, with nothing wrong on the bench. ``fit`` should
name nothing on such a run (the base is off, no effect of the library is present); they are
drawn as a family of their own (benchmarks/bench_families.py ``losslaw``), not as causes
outside the library, so that the families drawn before are drawn as they were.

- ``rotor_loss_rise``: the rotor's share of the motor's frequency-dependent losses rises with
  speed. In a permanent-magnet spindle motor the eddy currents that the slot and converter
  harmonics drive in the magnets and their sleeve grow with the electrical frequency squared
  (Zhu, Ng, Schofield and Howe, IEE Proc. Electr. Power Appl. 151(6), 2004: rotor
  eddy-current loss of PM machines), and rotor losses of a tenth to a third of the motor's at
  high speed are reported for such motors; the stator's copper loss, which a load adds, stays
  in the winding. The spec's split is one share at every operating point (``[motor]
  rotor_loss_share``, the base's ``rotor_share``). The motor's total loss, and so the logged
  power, is unchanged: only where it is dissipated moves.
"""

from __future__ import annotations

import numpy as np

from compare.fit.effects.base import Effect
from spindle.cycles import RANDOM_MAX_SPEED_RPM
from spindle.loads import TimeSeries

#: the speed [rpm] at which the drawn rise of the rotor's share is reached: the drawn cycles'
#: top speed
RISE_AT_RPM = RANDOM_MAX_SPEED_RPM


class RotorLossRise(Effect):
    name = "rotor_loss_rise"
    synth_sources = ("rotor", "stator")  # it moves loss from the one to the other

    def draw(self, rng):
        """The share of the motor's no-load loss that moves to the rotor at
        :data:`RISE_AT_RPM` [-]: a tenth to three tenths."""
        return {"share_rise": float(rng.uniform(0.10, 0.30))}

    def synth_case(self, case, spec, truth):
        """``share_rise`` (n / RISE_AT_RPM)^2 of the motor's no-load loss at speed n (the
        spec's drive, stator and rotor together: the frequency-dependent part) moved from the
        stator to the rotor, at most what the stator holds; the two sources' sum, and so the
        power the bench logs, is unchanged."""
        from spindle.drive import drive_for

        drive = drive_for(spec)
        rotor, stator = (spec.sources_with_role(r)[0].name for r in ("rotor", "stator"))
        src_r, src_s = case.sources[rotor], case.sources[stator]
        t = np.unique(np.concatenate([np.asarray(src_r.time_s, dtype=float),
                                      np.asarray(src_s.time_s, dtype=float),
                                      np.asarray(case.speed_rpm.time_s, dtype=float),
                                      np.arange(0.0, case.duration_s + 1.0, 600.0)]))
        q_r, q_s = np.asarray(src_r(t), dtype=float), np.asarray(src_s(t), dtype=float)
        # the speed just after each time: a step at t holds from t on, as the sources do
        n = np.asarray(case.speed_rpm(t + 1e-6), dtype=float)
        no_load = {}
        for v in np.unique(n):
            heat = drive.heat_W(float(v), 0.0, None)
            no_load[v] = heat.get(rotor, 0.0) + heat.get(stator, 0.0)
        q_nl = np.array([no_load[v] for v in n])
        move = np.clip(truth["share_rise"] * (n / RISE_AT_RPM) ** 2 * q_nl, 0.0, q_s)
        how = src_r.interpolation  # a ramp's losses stay ramps, a step's steps
        out = {rotor: TimeSeries(tuple(t), tuple(q_r + move), how),
               stator: TimeSeries(tuple(t), tuple(q_s - move), how)}
        return case.with_sources(out), {}


LOSS_LAWS: dict[str, Effect] = {e.name: e for e in (RotorLossRise(),)}
