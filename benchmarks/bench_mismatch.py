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
    from spindle.spec import load_spec

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
    named = [e["name"] for e in doc["effects"]]
    unexplained = bool(doc["unexplained"]["unexplained"])
    if case.effect == "clean":
        right = named == []
    elif case.effect == "electronics_drift":
        right = named == [] and unexplained
    else:
        right = named == [case.effect]
    val = doc["error_after"]["validation"]
    return {"case": case.label, "effect": case.effect, "seed": case.seed, "named": named,
            "how": [e.get("needed_by") for e in doc["effects"]], "unexplained": unexplained,
            "right": right, "validation_rmse": {c: v["rmse"] for c, v in val.items()},
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

    from compare.executor import run_cases, stderr_progress

    effects = args.only or [*sorted(EFFECTS), "clean", "electronics_drift"]
    cases = [Case(e, s, args.cycle, args.spec, str(args.keep) if args.keep else None)
             for e in effects for s in args.seeds]
    t = time.perf_counter()
    outcomes = run_cases(run_one, cases, workers=args.workers, progress=stderr_progress())
    rows = []
    print(f"{'case':26} {'named':34} ok  validation RMS after (T1 T2 Tst K, P1 µm)    s")
    for o in outcomes:
        if o.error:
            print(f"{o.label:26} failed: {o.error}")
            continue
        r = o.value
        rows.append(r)
        v = r["validation_rmse"]
        named = ", ".join(f"{n} ({h})" for n, h in zip(r["named"], r["how"], strict=True)) \
            or ("unexplained" if r["unexplained"] else "nothing")
        print(f"{r['case']:26} {named:34} {'yes' if r['right'] else 'NO ':3} "
              + " ".join(f"{v.get(c, float('nan')):5.2f}" for c in ("T1", "T2", "T_stator", "P1"))
              + f" {r['seconds']:5.0f}")
    print("right, per effect:")
    for e in effects:
        mine = [r for r in rows if r["effect"] == e]
        print(f"  {e:24} {sum(r['right'] for r in mine)} of {len(mine)}")
    n_right = sum(r["right"] for r in rows)
    print(f"right verdicts: {n_right} of {len(cases)}; wall time {time.perf_counter() - t:.0f} s "
          f"on {args.workers} workers")
    if args.json:
        args.json.write_text(json.dumps(rows, indent=2, default=str) + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
