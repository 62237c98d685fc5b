"""Fit benchmark: a 16 h bench run at about 1 Hz from ingest to report.

    python benchmarks/bench_fit.py [--effect fixture_expansion] [--seed 1] [--keep DIR]
    python benchmarks/bench_fit.py --run tests/data/peer-runs/bench-runs/dev-06.csv

Makes a synthetic run with ``spindle-verify synth`` (FEM level 1, not timed), or takes
``--run``, a bench export such as a peer's development run; then times reading it, one
grey-box simulation, and the whole ``fit`` (calibration, forward selection over the library,
cross-validation, diagnostics, report.json and report.html). Target (issues 6, 13): <= 60 s
on 2 cores for a 16 h run.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from verdicts import require_files

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--effect", default="fixture_expansion")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--keep", help="keep the run and the report in this folder")
    ap.add_argument("--run", type=Path, help="time this bench export instead of a synthetic run")
    args = ap.parse_args(argv)
    if args.run is not None:
        require_files([args.run], "--run")

    from compare.fit.greybox import GreyBox
    from compare.fit.report import save_report
    from compare.fit.run import greybox_inputs, run_fit
    from compare.synth.bench import synth
    from spindle.bench import read_bench
    from spindle.drive import drive_for
    from spindle.spec_reader import load_spec

    folder = Path(args.keep) if args.keep else Path(tempfile.mkdtemp())
    spec = load_spec("spl2782")
    run = args.run or folder / "run.csv"
    t = time.perf_counter()
    if args.run is None:
        synth(spec, "spl-16h", args.effect, args.seed, run)
    t_synth = time.perf_counter() - t
    t = time.perf_counter()
    bench = read_bench(run)
    t_read = time.perf_counter() - t
    gb = GreyBox(spec, drive_for(spec), greybox_inputs(bench))
    gb.simulate({})
    t = time.perf_counter()
    for _ in range(10):
        gb.simulate({"h_air": 1.01})
    t_sim = (time.perf_counter() - t) / 10
    t = time.perf_counter()
    rep = run_fit(run, spec)
    save_report(rep, folder / "fit")
    t_fit = time.perf_counter() - t
    named = [s.label for s in rep.selection.steps]
    print(f"{run}: rows {len(bench.time_s)}, {bench.duration_s / 3600:.1f} h"
          + ("" if args.run else f"; synth (FEM, untimed) {t_synth:.1f} s"))
    print(f"read {t_read:.2f} s; one 16 h simulation {t_sim * 1e3:.1f} ms; fit to report "
          f"{t_fit:.1f} s (target 60 s: {'met' if t_fit <= 60 else 'MISSED'}); "
          f"{len(rep.selection.judged)} candidate fits; named "
          f"{named or 'nothing'}" + ("" if args.run else f" (injected {args.effect})"))


if __name__ == "__main__":
    main()
