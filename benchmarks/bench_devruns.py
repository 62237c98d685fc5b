"""Bench-data loop on runs we did not make: ``fit`` on every run of a folder with a truth.json
(default tests/data/peer-runs/bench-runs/, a peer's simulator of an SPL2782-family spindle that is not
the shipped spec), against the truth.

    python benchmarks/bench_devruns.py [--runs DIR] [--spec spl2782] [--only dev-01 dev-06]
                                       [--workers 2] [--json OUT.json] [--fit-fraction 0.6]
                                       [--base-extra none | G_seat_W_K heat_capacity ...]

Prints, per run: the true effect, what ``fit`` named (and how), whether the verdict is right
(the true effect named alone; no effect named on a control run), the validation open-loop RMS
after the fit per channel against the tolerances (1 K, 1.5 µm), the base parameters beyond
their prior range, and the wall time; then the totals. Runs go through
:func:`compare.executor.run_cases` (a process pool), one ``fit`` per run.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass
from pathlib import Path

from verdicts import (
    RMS_HEADER,
    fit_outcome,
    judge_verdict,
    named_text,
    read_truth,
    rms_cells,
    run_verdicts,
)

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_RUNS = ROOT / "tests" / "data" / "peer-runs" / "bench-runs"


@dataclass(frozen=True)
class DevRun:
    path: Path
    spec: str
    truth: str | list | None
    base_extra: tuple[str, ...] | None = None
    blocks: int = 1
    cv_blocks: int = 5
    fit_fraction: float = 0.6
    #: fit with the spec's geometry, films and contacts perturbed as this seed's mismatch
    #: (compare.synth.mismatch.draw_mismatch): the runs as if from yet another variant
    spec_seed: int | None = None

    @property
    def label(self) -> str:
        return self.path.stem


def fit_one(case: DevRun) -> dict:
    """``fit`` on one run; the figures the table prints."""
    from compare.fit.criteria import Criteria
    from compare.fit.report import selection_trace
    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec
    from spindle.tolerances import channel_tolerance, edge_scale

    t = time.perf_counter()
    spec = load_spec(case.spec)
    if case.spec_seed is not None:
        from compare.synth.mismatch import perturbed_spec

        spec = perturbed_spec(spec, case.spec_seed)
    rep = run_fit(case.path, spec, base_extra=case.base_extra,
                  blocks=case.blocks, cv_blocks=case.cv_blocks, fit_fraction=case.fit_fraction)
    doc = rep.to_dict()
    out = fit_outcome(doc)
    return {"run": case.label, "truth": case.truth, "named": out["named"],
            "verdict": out["verdict"], "unexplained": out["unexplained"],
            **judge_verdict(case.truth, out["named_plain"], out["unexplained"]),
            "validation_rmse": out["validation_rmse"],
            "cross_validated_rmse": {c: v["rmse"] for c, v in (
                doc["cross_validation"].get("final", {}).get("pooled", {}).items())},
            "within_tolerance": {c: v <= channel_tolerance(c) * edge_scale(c)
                                 for c, v in out["validation_rmse"].items()},
            "implausible": {k: round(v, 2) for k, v in (doc.get("parameters_prior_z") or {})
                            .items() if abs(v) > Criteria(alpha=doc["alpha"]).implausible_z()},
            **selection_trace(doc),
            "seconds": time.perf_counter() - t}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=DEFAULT_RUNS,
                    help="folder with RUN.csv files and truth.json (default: %(default)s)")
    ap.add_argument("--spec", default="spl2782", help="spec the runs are fitted with")
    ap.add_argument("--only", nargs="*", help="run labels to fit (default: all in truth.json)")
    ap.add_argument("--workers", type=int, default=2, help="parallel fits (default 2)")
    ap.add_argument("--base-extra", nargs="+", default=None, metavar="PARAM",
                    help="as fit --base-extra (G_seat_W_K, heat_capacity, friction_exponent, "
                    "none; default: fit's default)")
    ap.add_argument("--blocks", type=int, default=1, help="as fit --blocks (default 1)")
    ap.add_argument("--cv-blocks", type=int, default=5, help="as fit --cv-blocks (default 5)")
    ap.add_argument("--fit-fraction", type=float, default=0.6,
                    help="as fit --fit-fraction (default 0.6): how stable the verdicts are when "
                    "the split moves")
    ap.add_argument("--spec-mismatch", type=int, default=None, metavar="SEED",
                    help="fit with the spec's geometry (axis stretched or shrunk by 10-15 %%), film groups "
                    "and contacts (x 0.5-2) perturbed as synth's mismatch of this seed: how the "
                    "verdicts hold when the spec is further off (default: the spec as is)")
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    if args.spec_mismatch is not None and args.spec_mismatch < 0:
        ap.error("--spec-mismatch: a seed >= 0")

    truth = read_truth(args.runs)
    labels = args.only or sorted(truth)
    extra = (None if args.base_extra is None
             else tuple(n for n in args.base_extra if n != "none"))
    cases = [DevRun(args.runs / f"{k}.csv", args.spec, truth[k]["truth"], extra,
                    args.blocks, args.cv_blocks, args.fit_fraction, args.spec_mismatch)
             for k in labels]

    def line(r: dict) -> str:
        return (f"{r['run']:8} {str(r['truth'])[:24]:24} "
                f"{named_text(r['named'], r['unexplained']):30} {'yes' if r['right'] else 'NO ':3} "
                f"{rms_cells(r['validation_rmse'])} {r['seconds']:5.0f}  "
                f"{rms_cells(r['cross_validated_rmse'])}"
                + (f"  implausible {r['implausible']}" if r["implausible"] else ""))

    run_verdicts(fit_one, cases, workers=args.workers, line=line, json_path=args.json,
                 header=f"{'run':8} {'truth':24} {'named':30} ok  {RMS_HEADER}   s  "
                        "cross-validated RMS after")

if __name__ == "__main__":
    main()
