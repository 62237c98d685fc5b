"""The power balance's bounds (spindle.bench_inputs.check_power_balance) on runs this project
did not make and on the drawn families: per run, the largest ratio of an interval's losses
(power less the load's M omega) to the drive's losses at its speed and torque (at least the
rated one), which must stay below 1; the same for loaded runs read as if they had no torque
column (which the bound must catch); and the median share of the power the load takes,
M omega / P_el, which must stay below 1; without a load, the median power against the
bearings' friction at a third of their friction factor, which must stay above 1.

    python benchmarks/bench_power_balance.py [--families benchmarks/.families-cache]
        [--out docs/figures/power-balance.json]

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

import numpy as np
from figures import ROOT, write_figures


def growth_gain(run, raw, spec, drive) -> float | None:
    """P1's gain on the growth the spec's own model predicts, beside the library's
    instantaneous terms (compare.fit.growth_check), on the fit's grid and inputs before gap
    switches are placed."""
    from compare.fit.criteria import Criteria
    from compare.fit.greybox import GreyBox
    from compare.fit.growth_check import growth_gain as gain_of
    from compare.fit.growth_check import library_terms
    from compare.fit.params import BASE_PARAMS, DEFAULT_BASE_EXTRA, default_theta
    from spindle.bench_inputs import logging_step_s, resample

    if "P1" not in run.channels:
        return None
    t, y = run.channel("P1")
    measured = resample(t, y, raw.grid_s, Criteria().gap_min_steps, logging_step_s(run.time_s))
    gb = GreyBox(spec, drive, raw, 11, base_extra=tuple(DEFAULT_BASE_EXTRA))
    theta = default_theta(gb.parameters(), [*BASE_PARAMS, *DEFAULT_BASE_EXTRA])
    found = gain_of(measured, gb.simulate(theta)["P1"], library_terms(raw))
    return None if found is None else found[0]


def measure(paths: list[Path]) -> dict[str, list[float]]:
    """Per run: "no_torque" (loss ratio of runs without a torque column), "friction_share"
    (their median power against the bearings' friction at f0 / 3), "loaded" (loss
    ratio of runs with one), "loaded_without_torque" (the same runs' ratio with the torque
    taken as 0) and "efficiency" (their median M omega / P_el); of every run,
    "no_load_share" (the median power without a load against the drive's no-load losses),
    "standstill_kW" (the median power at standstill), "growth_gain" (P1 on the spec's
    predicted growth) and "below_friction_run" (the most running intervals in a row below
    the friction floor)."""
    from spindle import load_spec
    from spindle.bench import read_bench
    from spindle.bench_inputs import (
        below_friction_stretch,
        friction_share,
        interval_inputs,
        load_efficiency,
        loss_excess,
        no_load_share,
        standstill_power,
    )
    from spindle.drive import drive_for

    spec = load_spec("spl2782")
    drive = drive_for(spec)
    out: dict[str, list[float]] = {"no_torque": [], "friction_share": [], "loaded": [],
                                   "loaded_without_torque": [], "efficiency": [],
                                   "no_load_share": [], "standstill_kW": [], "growth_gain": [],
                                   "below_friction_run": []}
    for i, path in enumerate(paths, 1):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            run = read_bench(path)
            raw = interval_inputs(run)
        share = no_load_share(drive, raw.speed_rpm, raw.power_kW, raw.load_torque_Nm)[0]
        still = standstill_power(raw.speed_rpm, raw.power_kW)[0]
        gain = growth_gain(run, raw, spec, drive)
        stretch = below_friction_stretch(drive, raw.speed_rpm, raw.power_kW,
                                         raw.load_torque_Nm)[1]
        for key, v in (("no_load_share", share), ("standstill_kW", still), ("growth_gain", gain),
                       ("below_friction_run", stretch)):
            if v is not None and np.isfinite(v):
                out[key].append(v)
        ex = loss_excess(drive, raw.speed_rpm, raw.power_kW, raw.load_torque_Nm)
        if ex is None:
            continue
        if not run.load_torque_measured:
            out["no_torque"].append(ex.ratio)
            out["friction_share"].append(friction_share(drive, raw.speed_rpm, raw.power_kW))
        else:
            out["loaded"].append(ex.ratio)
            zero = np.zeros_like(raw.load_torque_Nm)
            out["loaded_without_torque"].append(
                loss_excess(drive, raw.speed_rpm, raw.power_kW, zero).ratio)
            out["efficiency"].append(
                load_efficiency(raw.speed_rpm, raw.power_kW, raw.load_torque_Nm)[0])
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
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "power-balance.json")
    args = ap.parse_args(argv)
    peers = sorted((ROOT / "tests" / "data" / "peer-runs").glob("bench-runs*/*.csv"))
    drawn = sorted(args.families.glob("*.csv")) if args.families.is_dir() else []
    groups = {"peers": measure(peers), "families": measure(drawn)}
    doc = {g: {k: summary(v) for k, v in r.items()} for g, r in groups.items()}
    print(f"{'runs':10s} {'figure':24s} {'n':>4s} {'min':>6s} {'median':>7s} {'max':>6s}")
    for g, r in doc.items():
        for k, s in r.items():
            if s["runs"]:
                print(f"{g:10s} {k:24s} {s['runs']:4d} {s['min']:6.2f} {s['median']:7.2f} "
                      f"{s['max']:6.2f}")
    write_figures(args.out, "python benchmarks/bench_power_balance.py", doc)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
