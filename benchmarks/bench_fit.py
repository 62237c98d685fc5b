"""Fit benchmark: a 16 h bench run at about 1 Hz from ingest to report.

    python benchmarks/bench_fit.py [--effect fixture_expansion] [--seed 1] [--keep DIR]
    python benchmarks/bench_fit.py --run tests/data/peer-runs/bench-runs/dev-06.csv
    python benchmarks/bench_fit.py --run ../shared/bench-runs-2/dev2-01.csv --workers 2 --serial-too

Makes a synthetic run with ``spindle-verify synth`` (FEM level 1, not timed), or takes
``--run``, a bench export such as a peer's development run; then times reading it, one
grey-box simulation, and the whole ``fit`` (calibration, forward selection over the library,
cross-validation, diagnostics, report.json and report.html), with ``--workers`` processes as
``spindle-verify fit`` runs (default min(2, CPUs), as fit's); with ``--serial-too`` it times
the fit again with one process, prints the ratio and says whether the two reports agree
(they must, to the last bit: docs/fit.md "Options"). Target
(issues 6, 13, 32): <= 60 s on 2 cores for a 16 h run.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from verdicts import require_files

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)
from compare.executor import default_workers


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--effect", default="fixture_expansion")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--keep", help="keep the run and the report in this folder")
    ap.add_argument("--run", type=Path, help="time this bench export instead of a synthetic run")
    ap.add_argument("--workers", type=int, default=default_workers(),
                    help=f"processes per fit (default {default_workers()} here, as "
                    "spindle-verify fit)")
    ap.add_argument("--serial-too", action="store_true",
                    help="time the fit with one process too and print the ratio")
    args = ap.parse_args(argv)
    if args.run is not None:
        require_files([args.run], "--run")

    from compare.fit.greybox import GreyBox
    from compare.fit.report import save_report
    from compare.fit.run import run_fit
    from compare.synth.bench import synth
    from spindle.bench import read_bench
    from spindle.bench_inputs import interval_inputs
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
    gb = GreyBox(spec, drive_for(spec), interval_inputs(bench))
    gb.simulate({})
    t = time.perf_counter()
    for _ in range(10):
        gb.simulate({"h_air": 1.01})
    t_sim = (time.perf_counter() - t) / 10
    workers = args.workers
    t = time.perf_counter()
    rep = run_fit(run, spec, workers=workers)
    save_report(rep, folder / "fit")
    t_fit = time.perf_counter() - t
    serial = ""
    if args.serial_too and workers > 1:
        t = time.perf_counter()
        rep1 = run_fit(run, spec, workers=1)
        save_report(rep1, folder / "fit-serial")
        t_one = time.perf_counter() - t
        same = _same_report(folder / "fit" / "report.json", folder / "fit-serial" / "report.json")
        serial = (f"; one process {t_one:.1f} s, {t_one / t_fit:.2f}x the time with {workers} "
                  f"(run second, on this process's warm caches: a lower bound; reports "
                  f"{'the same' if same else 'DIFFER'})")
    named = [s.label for s in rep.selection.steps]
    print(f"{run}: rows {len(bench.time_s)}, {bench.duration_s / 3600:.1f} h"
          + ("" if args.run else f"; synth (FEM, untimed) {t_synth:.1f} s"))
    print(f"read {t_read:.2f} s; one 16 h simulation {t_sim * 1e3:.1f} ms; fit to report "
          f"{t_fit:.1f} s with {workers} process(es) (target 60 s: "
          f"{'met' if t_fit <= 60 else 'MISSED'}){serial}; "
          f"{len(rep.selection.judged)} candidate fits; named "
          f"{named or 'nothing'}" + ("" if args.run else f" (injected {args.effect})"))


def _same_report(a: Path, b: Path) -> bool:
    """Whether two report.json files agree but for their runtimes."""
    import json

    def strip(x):
        if isinstance(x, dict):
            return {k: strip(v) for k, v in x.items() if "runtime" not in k and k != "fit_s"}
        return [strip(v) for v in x] if isinstance(x, list) else x

    return strip(json.loads(a.read_text())) == strip(json.loads(b.read_text()))


if __name__ == "__main__":
    main()
