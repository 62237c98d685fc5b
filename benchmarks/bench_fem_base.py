"""Would a base model with the reference's physics lower the base misfit? (issue 32 item 4)

    python benchmarks/bench_fem_base.py [RUN.csv ...] [--workers 1] [--json OUT.json]

For each bench run, the base model is calibrated twice, as ``fit`` does before it selects
any effect:

- ``lumped``: the 11-node grey box anchored to the FEM at the spec's values, with its
  default extra parameters (the default of ``spindle-verify fit``);
- ``fem``: the base parameters calibrated on the FEM reference itself (level 0), the grey
  box then anchored there, so that at the calibrated point the base *is* the FEM
  (``fit --model fem``).

A reduced FEM that is parametric in the calibrated parameters approximates the second; its
misfit cannot be lower than the FEM's own (up to the reduction error). So if ``fem`` does
not fit the runs better than ``lumped``, a parametric reduced FEM is not worth building.

Prints per run and channel the base model's RMS over the validation window (K, um) and the
time each calibration took, then the median ratio fem / lumped per channel. Default runs:
the peer's clean controls (a clean run's misfit is the base model's own) and the synthetic
clean runs 1-4 of ``bench_families.py`` (made if missing).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from verdicts import require_files

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT / "tests" / "data" / "peer-runs"
PEER_CONTROLS = (SHARED / "bench-runs" / "dev-06.csv", SHARED / "bench-runs" / "dev-09.csv",
                 SHARED / "bench-runs-2" / "dev2-02.csv", SHARED / "bench-runs-2" / "dev2-07.csv")
CACHE = ROOT / "benchmarks" / ".families-cache"


def synthetic_clean(seed: int) -> Path:
    """bench_families.py's clean run ``seed`` (same draw), made if it is not in the cache."""
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from bench_families import draw

    from compare.synth.bench import synth
    from spindle.spec_reader import load_spec

    path = CACHE / f"clean-{seed}.csv"
    if not (path.exists() and path.with_suffix(".truth.json").exists()):
        _, cycle = draw("clean", seed)
        CACHE.mkdir(parents=True, exist_ok=True)
        synth(load_spec("spl2782"), cycle, "clean", seed, path, mismatch=True)
    return path


def one(path: str) -> dict:
    """Both base calibrations of one run: validation RMS per channel and seconds."""
    from compare.fit.run import calibrate_base
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    row: dict = {"run": Path(path).stem}
    for model in ("lumped", "fem"):
        t0 = time.perf_counter()
        prep = calibrate_base(path, spec, model=model)
        val = prep.base.errors["validation"]
        row[model] = {c: next(v for k, v in e.items() if k.startswith("rmse_") and k != "rmse_w")
                      for c, e in val.items() if e.get("n", 0) > 0}
        row[f"{model}_s"] = time.perf_counter() - t0
    return row


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="*", type=Path)
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    require_files(args.runs, "the runs")
    runs = args.runs or [p for p in PEER_CONTROLS if p.exists()]
    if not args.runs:
        runs += [synthetic_clean(s) for s in range(1, 5)]
    rows = []
    with ProcessPoolExecutor(args.workers) as pool:
        for row in pool.map(one, [str(p) for p in runs]):
            rows.append(row)
            cells = "  ".join(f"{c} {row['lumped'][c]:.3f} -> {row['fem'].get(c, np.nan):.3f}"
                              for c in row["lumped"])
            print(f"{row['run']:>10}  {cells}   ({row['lumped_s']:.0f} s, {row['fem_s']:.0f} s)",
                  flush=True)
    channels = sorted({c for r in rows for c in r["lumped"]})
    print("median fem / lumped validation RMS per channel (below 1: the FEM base fits better):")
    for c in channels:
        ratios = [r["fem"][c] / r["lumped"][c] for r in rows if c in r["fem"] and c in r["lumped"]]
        print(f"  {c:>9}  {np.median(ratios):.2f}  (range {min(ratios):.2f}-{max(ratios):.2f},"
              f" {len(ratios)} runs)")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1), encoding="utf-8")


if __name__ == "__main__":
    main()
