"""Fit a test-bench run: calibrate the grey box, judge the base model, name missing effects.

    python docs/examples/ex03_fit_bench_run.py [RUN.csv] [OUT_DIR]

Without a run, makes one first: ``synth`` solves the FEM reference (level 0) over the
paper's 16 h cycle with an ambient-driven sensor fixture (``fixture_expansion``) and samples
it like a bench (irregular times, noise, a gap). ``run_fit`` then reads it as a bench export,
calibrates the base parameters, gives the base-adequacy verdict, tests the candidate effects
and reports the open-loop error before and after; ``save_report`` writes report.json and
report.html. The same as ``spindle-verify fit RUN.csv --spec spl2782 --out OUT_DIR``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from compare.fit.run import run_fit, save_report
from compare.fit.synth import synth
from spindle.spec import load_spec


def main(run: Path | None, out: Path) -> dict:
    spec = load_spec("spl2782")
    if run is None:
        run = out / "run.csv"
        out.mkdir(parents=True, exist_ok=True)
        synth(spec, "spl-16h", "fixture_expansion", seed=2, out_csv=run, level=0)
    report = run_fit(run, spec)
    doc = report.to_dict()
    print(doc["base_adequacy"]["verdict"])
    print("effects named:", [e["name"] for e in doc["effects"]] or "none")
    for c, e in doc["error_after"]["validation"].items():
        print(f"  {c}: validation RMS {e['rmse']:.3f} {e['unit']} after the fit")
    save_report(report, out, pictures=False)
    return doc


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 and sys.argv[1] else None,
         Path(sys.argv[2]) if len(sys.argv) > 2 else Path(tempfile.mkdtemp()))
