"""The no-load bound (spindle.bench_inputs.no_load_excess) on runs this project did not make
and on the drawn families: each run's largest ratio of an interval's power to the drive's
losses at its speed and rated torque, for runs without a torque column (no-load runs, which
must stay below 1) and for loaded runs read as if they had none (which the bound must catch).

    python benchmarks/bench_no_load_bound.py [--families benchmarks/.families-cache]
        [--out docs/figures/no-load-bound.json]

The peer's runs are tests/data/peer-runs/ (23 runs); the families are the synthesised runs
of benchmarks/bench_families.py's cache, where it exists (its on-change copies are the same
runs logged otherwise, and are counted as runs of their own). Prints a table; writes the
figures to ``--out``, from which docs/bench.md's block is checked (tests/test_docs_figures.py).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import warnings
from pathlib import Path

from figures import ROOT, write_figures


def ratios(paths: list[Path]) -> dict[str, list[float]]:
    """{"no_torque": [...], "loaded": [...]}: each run's largest ratio, by whether it logs a
    load torque."""
    from spindle import load_spec
    from spindle.bench import read_bench
    from spindle.bench_inputs import interval_inputs, no_load_excess
    from spindle.drive import drive_for

    drive = drive_for(load_spec("spl2782"))
    out: dict[str, list[float]] = {"no_torque": [], "loaded": []}
    for i, path in enumerate(paths, 1):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run = read_bench(path)
            raw = interval_inputs(run)
        ex = no_load_excess(drive, raw.speed_rpm, raw.power_kW)
        if ex is not None:
            out["loaded" if run.load_torque_measured else "no_torque"].append(ex.ratio)
        print(f"\r{i}/{len(paths)} runs read", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return out


def summary(values: list[float]) -> dict:
    return {"runs": len(values), "min": min(values), "median": statistics.median(values),
            "max": max(values)} if values else {"runs": 0}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--families", type=Path, default=ROOT / "benchmarks" / ".families-cache",
                    help="folder of the drawn families' runs (default: %(default)s)")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "no-load-bound.json")
    args = ap.parse_args(argv)
    peers = sorted((ROOT / "tests" / "data" / "peer-runs").glob("bench-runs*/*.csv"))
    drawn = sorted(args.families.glob("*.csv")) if args.families.is_dir() else []
    groups = {"peers": ratios(peers), "families": ratios(drawn)}
    doc = {g: {k: summary(v) for k, v in r.items()} for g, r in groups.items()}
    print(f"{'runs':10s} {'torque column':14s} {'n':>4s} {'min':>6s} {'median':>7s} {'max':>6s}")
    for g, r in doc.items():
        for k, s in r.items():
            if s["runs"]:
                print(f"{g:10s} {'no' if k == 'no_torque' else 'yes':14s} {s['runs']:4d} "
                      f"{s['min']:6.2f} {s['median']:7.2f} {s['max']:6.2f}")
    write_figures(args.out, "python benchmarks/bench_no_load_bound.py", doc)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
