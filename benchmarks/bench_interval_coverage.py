"""How often a named effect's 95 % interval holds the value that was injected: the reports of
drawn runs (``bench_families.py --reports DIR``), against their truth sidecars.

    python benchmarks/bench_families.py --families effect --reports DIR
    python benchmarks/bench_interval_coverage.py DIR [--cache benchmarks/.families-cache]
                                                     [--json OUT.json]

Prints the share of intervals that hold the injected value (95 % Wilson interval), per effect,
and every interval that misses it (estimate, interval, truth). Only parameters the truth names
as the effect's own are counted: centrifugal_shortening's truth is a factor on the FEM's
centrifugal load, not the fit's c_cf, and is left out. An interval that holds its truth on
95 % of runs is what a reader of "95 %" expects; the fit's is the noise's alone
(compare.fit.calibrate._intervals), and a spindle unlike its spec biases the estimate.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from bench_families import ROOT, wilson

CACHE = ROOT / "benchmarks" / ".families-cache"


def interval_rows(reports: Path, cache: Path) -> list[dict]:
    """One row per parameter of a named effect that is the run's injected effect."""
    rows = []
    for path in sorted(reports.glob("*.json")):
        truth_file = cache / f"{path.stem}.truth.json"
        if not truth_file.exists():
            continue
        truth = json.loads(truth_file.read_text(encoding="utf-8"))
        if not isinstance(truth["effect"], str):
            continue  # several effects: their parameters are by effect
        doc = json.loads(path.read_text(encoding="utf-8"))
        for e in doc["effects"]:
            if e["name"] != truth["effect"]:
                continue
            for name, value in e["parameters"].items():
                if name not in truth["parameters"] or not isinstance(value, int | float):
                    continue
                lo, hi = e["confidence_intervals"][name]
                t = float(truth["parameters"][name])
                rows.append({"run": path.stem, "effect": e["name"], "parameter": name,
                             "truth": t, "estimate": value, "ci95": [lo, hi],
                             "holds": bool(lo <= t <= hi)})
    return rows


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("reports", type=Path, help="a folder of report.json files named by run")
    ap.add_argument("--cache", type=Path, default=CACHE,
                    help="the drawn runs' truth sidecars (default benchmarks/.families-cache)")
    ap.add_argument("--json", type=Path, help="also write the rows and the rate here")
    args = ap.parse_args(argv)
    if not args.reports.is_dir():
        print(f"bench_interval_coverage: {args.reports}: not a folder of reports",
              file=sys.stderr)
        return 2
    rows = interval_rows(args.reports, args.cache)
    k, n = sum(r["holds"] for r in rows), len(rows)
    p, lo, hi = wilson(k, n)
    print(f"95 % intervals that hold the injected value: {k} of {n}, {100 * p:.1f} % "
          f"[{100 * lo:.1f}, {100 * hi:.1f}]")
    for effect in sorted({r["effect"] for r in rows}):
        mine = [r for r in rows if r["effect"] == effect]
        print(f"  {effect:<24} {sum(r['holds'] for r in mine):3d} of {len(mine):3d}")
    for r in rows:
        if not r["holds"]:
            print(f"  misses: {r['run']} {r['parameter']}: truth {r['truth']:.4g}, estimate "
                  f"{r['estimate']:.4g} (95 %: {r['ci95'][0]:.4g} to {r['ci95'][1]:.4g})")
    if args.json:
        args.json.write_text(json.dumps({"holds": k, "intervals": n, "rows": rows}, indent=1),
                             encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
