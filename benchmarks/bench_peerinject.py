"""Effects injected into a peer's control runs (compare/synth/inject.py): held-out-like cases
whose base misfit is a real one this project did not make, with magnitudes and channels other
than the peer's own effect runs.

    python benchmarks/bench_peerinject.py [--runs DIR] [--controls dev-06 dev-09]
                                          [--only sensor_lag] [--workers 2] [--json OUT.json]

Each case: one control run (truth ``none`` in truth.json) with one measurement-side effect
injected (centrifugal shortening, fixture expansion, a sensor lag on one channel), then
``fit --spec spl2782``. Right: that effect (and for a lag, that channel) named alone. Prints
the table and the share right; the controls themselves are fitted as they are (right: nothing
named).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from verdicts import RMS_HEADER, fit_outcome, named_text, read_truth, rms_cells, run_verdicts

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_RUNS = ROOT / "tests" / "data" / "peer-runs" / "bench-runs"

#: (effect, parameters, lag channel): magnitudes around and away from the peer's own effect
#: runs (dev-01 c 0.055 um/krpm^2, dev-04 k -0.72 um/K, dev-03 lag on T1, 400 s fitted)
INJECTIONS = (
    ("none", {}, None),
    ("centrifugal_shortening", {"c_cf_um_krpm2": 0.03}, None),
    ("centrifugal_shortening", {"c_cf_um_krpm2": 0.1}, None),
    ("fixture_expansion", {"k_fix_um_K": -0.5}, None),
    ("fixture_expansion", {"k_fix_um_K": 1.5}, None),
    ("sensor_lag", {"tau_s": 600.0}, "T1"),
    ("sensor_lag", {"tau_s": 600.0}, "T2"),
    ("sensor_lag", {"tau_s": 900.0}, "P1"),
    ("sensor_lag", {"tau_s": 1200.0}, "T_stator"),
)


@dataclass(frozen=True)
class Injected:
    control: Path
    effect: str
    params: dict = field(hash=False)
    channel: str | None
    spec: str = "spl2782"
    spec_seed: int | None = None  # as bench_devruns --spec-mismatch

    @property
    def label(self) -> str:
        what = "+".join(f"{v:g}" for v in self.params.values())
        return f"{self.control.stem}:{self.effect}" + (f"({self.channel})" if self.channel
                                                      else "") + (f"={what}" if what else "")


def fit_one(case: Injected) -> dict:
    """Inject, then ``fit``; the figures the table prints."""
    from compare.fit.report import named_effects, selection_trace
    from compare.fit.run import run_fit
    from compare.synth.inject import inject
    from spindle.spec_reader import load_spec

    t = time.perf_counter()
    text = case.control.read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / f"{case.control.stem}.csv"
        if case.effect != "none":
            text = inject(text, case.effect, case.params, case.channel)
        run.write_text(text, encoding="utf-8")
        spec = load_spec(case.spec)
        if case.spec_seed is not None:
            from compare.synth.mismatch import perturbed_spec

            spec = perturbed_spec(spec, case.spec_seed)
        doc = run_fit(run, spec).to_dict()
    named = named_effects(doc)
    want = [] if case.effect == "none" else [case.effect + (f"({case.channel})"
                                                           if case.channel else "")]
    out = fit_outcome(doc)
    estimate = {k: v for e in doc["effects"] for k, v in e["parameters"].items()
                if k != "channel"}
    return {"case": case.label, "truth": want, "named": named, "right": named == want,
            "unexplained": out["unexplained"], "injected": case.params,
            "estimate": estimate, "validation_rmse": out["validation_rmse"],
            **selection_trace(doc),
            "seconds": time.perf_counter() - t}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=Path, default=DEFAULT_RUNS,
                    help="folder with RUN.csv files and truth.json (default: %(default)s)")
    ap.add_argument("--controls", nargs="*",
                    help="control runs to inject into (default: every run whose truth is none)")
    ap.add_argument("--only", nargs="*", help="effects to inject (default: all; 'none' fits "
                    "the controls as they are)")
    ap.add_argument("--spec", default="spl2782")
    ap.add_argument("--spec-mismatch", type=int, default=None, metavar="SEED",
                    help="fit with the spec perturbed as synth's mismatch of this seed "
                    "(compare.synth.mismatch.perturbed_spec; as bench_devruns.py)")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    args = ap.parse_args(argv)
    if args.spec_mismatch is not None and args.spec_mismatch < 0:
        ap.error("--spec-mismatch: a seed >= 0")

    truth = read_truth(args.runs)
    controls = args.controls or sorted(k for k, v in truth.items()
                                       if v.get("truth") in (None, "none"))
    cases = [Injected(args.runs / f"{c}.csv", e, p, ch, args.spec, args.spec_mismatch)
             for c in controls
             for e, p, ch in INJECTIONS if not args.only or e in args.only]

    def line(r: dict) -> str:
        est = " ".join(f"{x:.3g}" for x in r["estimate"].values())
        return (f"{r['case']:46} {named_text(r['named'], r['unexplained']):26} "
                f"{'yes' if r['right'] else 'NO ':3} {est:13} {rms_cells(r['validation_rmse'])}")

    run_verdicts(fit_one, cases, workers=args.workers, line=line, json_path=args.json,
                 header=f"{'case':46} {'named':26} ok  estimate      {RMS_HEADER}")

if __name__ == "__main__":
    main()
