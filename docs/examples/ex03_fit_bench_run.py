"""Fit a test-bench run: calibrate the grey box, judge the base model, name missing effects.

    python docs/examples/ex03_fit_bench_run.py [OUT_DIR [RUN.csv]]

Without a run, makes one first: ``synth`` solves the FEM reference (level 0) over the
paper's 16 h cycle with an ambient-driven sensor fixture (``fixture_expansion``, its
parameters drawn from the seed) and samples it like a bench (irregular times, noise, a gap).
``run_fit`` then reads it as a bench export, anchors the 11-node grey box to the FEM solved on
the run's inputs, calibrates the base parameters on the first 60 % of the run, gives the
base-adequacy verdict, tests the candidate effects and reports the error on the last 40 %;
``save_report`` writes report.json and report.html. The same as
``spindle-verify fit RUN.csv --spec spl2782 --out OUT_DIR``. Under a minute on 2 cores with the
whole effect library; ``candidates`` narrows it (``--candidates`` on the command line).
"""

from __future__ import annotations

import json
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

import spindle_verify


def main(out: Path, run: Path | None = None, candidates: Sequence[str] | None = None) -> dict:
    """Fit ``run`` (synthesised into ``out/run.csv`` if None) and write the report to ``out``;
    returns report.json's content. ``candidates``: the effects to try (None: all)."""
    out.mkdir(parents=True, exist_ok=True)
    if run is None:
        run = out / "run.csv"
        # writes run.csv and run.truth.json (what was injected; fit never reads it)
        spindle_verify.synth("spl2782", "spl-16h", "fixture_expansion", seed=2, out_csv=run,
                             level=0)
    report = spindle_verify.fit(run, spec="spl2782",
                                candidates=list(candidates) if candidates else None)
    doc = report.to_dict()

    print(doc["verdict"]["summary"])  # the verdict first, as `spindle-verify fit` prints it
    print(f"The base model {doc['base_adequacy']['statement']}.")
    for e in doc["effects"]:
        print(f"  {e['name']}: " + ", ".join(f"{k} = {v:.3g}" for k, v in e["parameters"].items()))
    truth = run.with_suffix(".truth.json")
    if truth.exists():  # a synthetic run: what was injected, to compare with the line above
        injected = json.loads(truth.read_text())
        print(f"  injected {injected['effect']}: " + ", ".join(
            f"{k} = {v:.3g}" for k, v in injected["parameters"].items()))
    for channel, e in doc["error_after"]["validation"].items():
        print(f"  {channel}: open-loop RMS {e['rmse']:.3f} {e['unit']} on the validation window")
    files = report.save(out, pictures=False)  # pictures=True adds the PNGs
    print(f"wrote {', '.join(f.name for f in files)} to {out}")
    return doc


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()),
         Path(sys.argv[2]) if len(sys.argv) > 2 else None)
