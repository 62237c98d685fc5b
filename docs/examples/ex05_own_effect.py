"""Add an effect of your own to the library, make a run that carries it, and let ``fit`` find it.

    python docs/examples/ex05_own_effect.py [OUT_DIR]

The effect: a contact seal at the rear of the shaft (a rotary union, say) rubs with a
friction torque that barely depends on speed, so it heats the rear bearing's seat by
c * n / 1000 rpm watts. The spindle's spec knows no such seal. The effect is a subclass of
:class:`compare.fit.effects.Effect` that declares its one parameter (unit, neutral value,
bounds, source), its heat in the grey box (the ``heat`` hook), its heat in a synthetic FEM
run (``synth_case``) and a size to draw (``draw``). :func:`spindle_verify.register_effect`
adds it to the library. From then on ``synth`` can inject it, and ``fit`` tries it beside
the library's own effects and judges it by the same criteria (compare.fit.criteria). It has
no signature test, so it is named only by the open loop: it must predict held-out blocks,
beat "something else" and every other effect.

Under a minute on 2 cores (a level-0 FEM run and one fit).
"""

from __future__ import annotations

import json
import sys
import tempfile
from pathlib import Path

import numpy as np

import spindle_verify
from spindle_verify import Effect, Param, TimeSeries


class RearSealFriction(Effect):
    name = "rear_seal_friction"
    explanation = ("A contact seal at the rear of the shaft rubs with a nearly constant "
                   "torque: heat into the rear bearing's seat rising linearly with speed.")
    params = (Param("c_seal_W_krpm", "W/krpm", 0.0, 0.0, 40.0,
                    "seal heat per 1000 rpm into the rear bearing", log=False,
                    source="a lip seal of 60 mm at 0.1-0.5 N m: 6-50 W/krpm"),)
    channels = ("T1", "T2", "T_stator", "P1")
    hint = "a rubbing seal or rotary union at the rear of the shaft"

    def heat(self, sources_W, theta, inputs):
        q = theta["c_seal_W_krpm"] * np.asarray(inputs.speed_rpm) / 1000.0
        out = dict(sources_W)
        out["rear_bearing"] = sources_W["rear_bearing"] + q
        # the motor supplies the seal's drag: where the bench logs the electrical power, the
        # power balance booked it as motor loss, so it moves from the stator to the seal
        measured = ~np.isnan(np.asarray(inputs.power_kW, dtype=float))
        out["stator"] = np.where(measured, np.maximum(sources_W["stator"] - q, 0.0),
                                 sources_W["stator"])
        return out

    def draw(self, rng):
        return {"c_seal_W_krpm": float(rng.uniform(8.0, 15.0))}

    def synth_case(self, case, spec, truth):
        src = case.sources["rear_bearing"]
        t = np.asarray(src.time_s)
        c = truth["c_seal_W_krpm"]
        extra = c * np.asarray(case.speed_rpm(t + 1e-6)) / 1000.0
        case = case.with_sources({"rear_bearing": TimeSeries(
            tuple(t), tuple(np.asarray(src.values) + extra), src.interpolation)})
        # the bench's electrical power carries the drag the motor supplies
        return case, {"power_W": lambda ts: c * np.asarray(case.speed_rpm(ts), float) / 1000.0}


def main(out: Path, seed: int = 4) -> dict:
    """Register the seal, synthesise a level-0 FEM run of the paper's 16 h cycle with it
    into ``out/run.csv``, fit it, write the report to ``out``; returns report.json's content
    with the truth beside it (``doc["truth"]``). The effect leaves the library afterwards."""
    out.mkdir(parents=True, exist_ok=True)
    spindle_verify.register_effect(RearSealFriction())
    try:
        truth = spindle_verify.synth("spl2782", "spl-16h", "rear_seal_friction", seed=seed,
                                     out_csv=out / "run.csv", level=0)
        report = spindle_verify.fit(out / "run.csv", spec="spl2782")
        report.save(out, pictures=False)
        doc = report.to_dict()
    finally:
        spindle_verify.unregister_effect("rear_seal_friction")
    doc["truth"] = truth
    return doc


if __name__ == "__main__":
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())
    doc = main(folder)
    print(doc["verdict"]["summary"])
    print(f"injected: {json.dumps(doc['truth']['parameters'])}; report in {folder}")
