"""The verdict's scan against its null: the Monte Carlo critical value of the competitor's
largest statistic (compare.fit.competitor.scan_threshold) over seeds, against the Bonferroni
bound it replaced, with the hypotheses the scan tries and the time one critical value takes.

    python benchmarks/scan_null_figures.py [--run CSV] [--seeds 8] [--json docs/figures/scan-null.json]

It fits the run (default: the peer's clean control dev-06, which a clone holds), keeps the
scan's table as the verdict met it, and computes the critical value again with other seeds.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import figures  # noqa: F401  (checks that the checkout's code is what runs)
from figures import ROOT, write_figures
from verdicts import require_files

DEFAULT_RUN = ROOT / "tests" / "data" / "peer-runs" / "bench-runs" / "dev-06.csv"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--run", type=Path, default=DEFAULT_RUN, help="a bench export (CSV)")
    ap.add_argument("--spec", default="spl2782")
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--json", type=Path, help="write the figures file here")
    args = ap.parse_args(argv)
    require_files([args.run], "--run")

    import numpy as np

    import compare.fit.select as select
    from compare.fit.competitor import scan, scan_null_draws, scan_threshold
    from compare.fit.criteria import Criteria, chi2_threshold
    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec

    met = {}

    def keep(reg, channel, rows, alpha, tail, seed=0):
        met.update(reg=reg, channel=channel, rows=rows)
        return scan_threshold(reg, channel, rows, alpha, tail, seed)

    select.scan_threshold = keep  # the verdict's own call, recorded
    run_fit(args.run, load_spec(args.spec))
    if not met:
        raise SystemExit(f"error: {args.run}: the fit scanned nothing (no residual rows)")
    criteria = Criteria()
    reg, channel, rows = met["reg"], met["channel"], met["rows"]
    values, seconds = [], []
    for seed in range(args.seeds):
        t0 = time.perf_counter()
        values.append(scan_threshold(reg, channel, rows, criteria.alpha,
                                     criteria.scan_null_tail, seed))
        seconds.append(time.perf_counter() - t0)
    noise = np.random.default_rng(0).standard_normal(len(channel))
    _, tried = scan(reg, noise, channel, rows, 1.0, top=1)
    run = args.run.resolve()
    fields = {"run": str(run.relative_to(ROOT)) if run.is_relative_to(ROOT) else str(run),
              "alpha": criteria.alpha,
              "draws": scan_null_draws(criteria.alpha, criteria.scan_null_tail),
              "hypotheses": tried, "critical_value_seed_0": values[0],
              "critical_value_min": min(values), "critical_value_max": max(values),
              "critical_value_sd_rel": float(np.std(values) / np.mean(values)),
              "bonferroni": chi2_threshold(criteria.alpha, 1, tried),
              "seconds_median": float(np.median(seconds)), "seeds": args.seeds}
    for k, v in fields.items():
        print(f"{k:24} {v:.4g}" if isinstance(v, float) else f"{k:24} {v}")
    if args.json:
        given = sys.argv[1:] if argv is None else argv
        write_figures(args.json, " ".join(["python benchmarks/scan_null_figures.py", *given]),
                      fields)


if __name__ == "__main__":
    main()
