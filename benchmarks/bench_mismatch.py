"""The mismatch matrix (issue 13 §2, §6): every library effect, clean data and an effect
outside the library, synthesised on a spindle that differs from the spec (``synth
--mismatch``: films, contacts, axial length, friction, loss split, FEM level, drawn from the
seed) over a cycle that is not the spec's own, then fitted with the spec.

    python benchmarks/bench_mismatch.py [--seeds 1 2 3] [--cycle random] [--workers 2]
                                        [--only windage_loss clean] [--json OUT.json]
                                        [--keep RUNS_DIR]

Prints, per case: the truth, what ``fit`` named (and how), whether the verdict is right (the
effect named alone; nothing on clean data; ``unexplained`` with nothing named for the
effect outside the library), the validation RMS after the fit, and the wall time; then the
share right per effect. Cases run through :func:`compare.executor.run_cases`.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from verdicts import RMS_HEADER, fit_outcome, named_text, rms_cells, run_verdicts

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)


@dataclass(frozen=True)
class Case:
    effect: str
    seed: int
    cycle: str
    spec: str
    keep: str | None = None

    @property
    def label(self) -> str:
        return f"{self.effect}-{self.seed}"


def run_one(case: Case) -> dict:
    """``synth --mismatch`` then ``fit`` on one case; the figures the table prints."""
    from compare.fit.run import run_fit, selection_trace
    from compare.fit.synth import synth
    from spindle.spec_reader import load_spec

    t = time.perf_counter()
    spec = load_spec(case.spec)
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(case.keep or tmp) / f"{case.cycle}-{case.label}.csv"
        if case.keep and run.exists() and run.with_suffix(".truth.json").exists():
            # a kept run is fitted again as it is (to compare fit changes on the same data)
            truth = json.loads(run.with_suffix(".truth.json").read_text(encoding="utf-8"))
        else:
            truth = synth(spec, case.cycle, case.effect, case.seed, run, mismatch=True)
        t_synth = time.perf_counter() - t
        doc = run_fit(run, spec).to_dict()
    out = fit_outcome(doc)
    named, unexplained = out["named_plain"], out["unexplained"]
    if case.effect == "clean":
        right = named == []
    elif case.effect == "electronics_drift":
        right = named == [] and unexplained
    else:
        right = named == [case.effect]
    return {"case": case.label, "effect": case.effect, "seed": case.seed, "named": named,
            "how": [e.get("needed_by") for e in doc["effects"]], "unexplained": unexplained,
            "right": right, "validation_rmse": out["validation_rmse"],
            "truth": truth, "synth_s": t_synth,
            **selection_trace(doc),
            "seconds": time.perf_counter() - t}


def main(argv: list[str] | None = None) -> None:
    from compare.fit.greybox import EFFECTS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    ap.add_argument("--cycle", default="random",
                    help="random, random-loaded, random-ramped-load, or a cycle name (default random)")
    ap.add_argument("--spec", default="spl2782")
    ap.add_argument("--only", nargs="*", help="effects to run (default: all, clean, "
                    "electronics_drift)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    ap.add_argument("--keep", type=Path, help="keep the synthetic runs in this folder; runs "
                    "already there are fitted again without synthesising them anew")
    args = ap.parse_args(argv)
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)

    effects = args.only or [*sorted(EFFECTS), "clean", "electronics_drift"]
    cases = [Case(e, s, args.cycle, args.spec, str(args.keep) if args.keep else None)
             for e in effects for s in args.seeds]

    def line(r: dict) -> str:
        named = named_text([f"{n} ({h})" for n, h in zip(r["named"], r["how"], strict=True)],
                           r["unexplained"])
        return (f"{r['case']:26} {named:34} {'yes' if r['right'] else 'NO ':3} "
                f"{rms_cells(r['validation_rmse'])} {r['seconds']:5.0f}")

    run_verdicts(run_one, cases, workers=args.workers, line=line, json_path=args.json,
                 group=lambda r: r["effect"],
                 header=f"{'case':26} {'named':34} ok  {RMS_HEADER}    s")

if __name__ == "__main__":
    main()
