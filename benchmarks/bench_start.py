"""Runs that do not start at the room's temperature: ``fit`` with its start read from the
first samples (compare.fit.start) against the uniform start, on drawn runs.

    python benchmarks/bench_start.py [--runs 40] [--workers 2] [--json OUT.json]
                                     [--summary FILE] [--rows ROWS.json [--before OLD.json]]

Each run is a family run of bench_families.py (one its cache holds as a regular log, with
its truth) with its first hours cut off: a logger started on a spindle that was already
running, as a bench that is not the lab's often is. The cut is drawn from 1 to 4 h, the
family (effect, clean, outside, two, in turn), the run and the cut from a stream of their
own. Every cut run is fitted twice: with the table's ``start_within_tolerances`` (the start
read from the first samples where the uniform start misses them) and with it at 100 (always
the uniform start, the code before). Prints, per
arm, the issue's rates with 95 % Wilson intervals, and the runs whose verdict changed.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

from bench_families import FAMILIES, rate_line
from verdicts import fit_outcome, judge_verdict, run_verdicts, within_tolerances

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)

ROOT = Path(__file__).resolve().parents[1]
CACHE = ROOT / "benchmarks" / ".families-cache"
#: the drawn cut [h]: from an hour (the bearings warm) to four (the housing too)
CUT_H = (1.0, 4.0)
ARMS = {"read": (), "uniform": (("start_within_tolerances", 100.0),)}


def cut_run(src: Path, dst: Path, cut_s: float) -> None:
    """``src`` without its rows before ``cut_s`` [s], its clock restarted at the first row
    kept (the format zeroes P1 there itself)."""
    lines = src.read_text(encoding="utf-8").splitlines()
    head = [ln for ln in lines if ln.startswith("#") and not ln.startswith("# rows:")]
    rows = [ln for ln in lines if not ln.startswith("#")]
    header, data = rows[0], rows[1:]
    rows = [(float(t), rest) for t, rest in (ln.split(",", 1) for ln in data)]
    kept = [(t, rest) for t, rest in rows if t >= cut_s]
    out = [f"{t - kept[0][0]:.2f},{rest}" for t, rest in kept]
    dst.write_text("\n".join([*head, header, *out]) + "\n", encoding="utf-8")


@dataclass(frozen=True)
class Job:
    family: str
    seed: int  # one of the 50 the family benchmark draws
    cut_s: float
    arm: str = "read"

    @property
    def label(self) -> str:
        return f"{self.family}-{self.seed} cut {self.cut_s / 3600:.2f} h, {self.arm}"


def cases(n: int) -> list[Job]:
    """The drawn cut runs: the family in turn, a run of it the cache holds (a regular log
    with its truth; main and held-out seeds alike) and the cut, from a stream of their own."""
    import numpy as np

    rng = np.random.default_rng([2026, 11, 29])
    held = {f: sorted(int(p.stem.rsplit("-", 1)[1]) for p in CACHE.glob(f"{f}-*.csv")
                      if p.stem.rsplit("-", 1)[1].isdigit()
                      and p.with_suffix(".truth.json").exists()) for f in FAMILIES}
    families = [f for f in FAMILIES if held[f]]
    return [Job(f, int(rng.choice(held[f])), float(rng.uniform(*CUT_H) * 3600))
            for i in range(n) for f in [families[i % len(families)]]]


def cut_path(job: Job) -> Path:
    return CACHE / "cut" / f"{job.family}-{job.seed}-cut{job.cut_s / 3600:.2f}h.csv"


def one(job: Job) -> dict:
    from compare.fit.criteria import Criteria
    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec

    case = asdict(job)
    src = CACHE / f"{job.family}-{job.seed}.csv"
    truth_doc = json.loads(src.with_suffix(".truth.json").read_text(encoding="utf-8"))
    dst = cut_path(job)
    truth = truth_doc["effect"]
    truth = ("unexplained" if job.family == "outside" else
             None if truth == "clean" else truth)
    rep = run_fit(dst, load_spec("spl2782"),
                  criteria=Criteria().with_options(**dict(ARMS[job.arm])))
    doc = rep.to_dict()
    out = fit_outcome(doc)
    return {**case, "run": dst.stem, "truth": truth, "named": out["named"],
            "verdict": out["verdict"],
            **judge_verdict(truth, out["named_plain"], out["unexplained"]),
            "rms_within_tolerance": within_tolerances(out["validation_rmse"]),
            "validation_rmse": out["validation_rmse"],
            "prehistory_s": (doc.get("start") or {}).get("prehistory_s"), "fit_s": rep.runtime_s}


def rates(rows: list[dict]) -> list[str]:
    def line(label: str, hit, of) -> str:
        return rate_line(label, rows, hit, of)

    effect = lambda r: r["kind"] in ("effect", "effects")  # noqa: E731
    return [line("true effect named first", lambda r: r["first"], effect),
            line("clean: nothing named", lambda r: r["right"], lambda r: r["kind"] == "control"),
            line("outside: unexplained, nothing named", lambda r: r["right"],
                 lambda r: r["kind"] == "outside"),
            line("wrong effect named (any run)", lambda r: r["wrong"], lambda r: True),
            line("right verdict as a whole", lambda r: r["right"], lambda r: True),
            line("validation RMS within tolerances (named or adequate)",
                 lambda r: r["rms_within_tolerance"],
                 lambda r: r["verdict"] in ("named", "base adequate"))]


def _said(row: dict) -> str:
    """A fit's verdict and names, and whether it was right."""
    return (f"{row['verdict']} {','.join(row['named'])}".strip()
            + (" (right)" if row["right"] else ""))


def summary(rows: list[dict], before: list[dict] | None = None) -> list[str]:
    """The rates per arm and the verdicts the start changed (uniform -> read); with
    ``before`` (rows of an earlier commit), the 'read' arm of each and the verdicts the
    commit changed (before -> now), on the cut runs both hold."""
    if before is not None:
        now = {r["run"]: r for r in rows if r["arm"] == "read"}
        then = {r["run"]: r for r in before if r["arm"] == "read" and r["run"] in now}
        arms = {"before": list(then.values()), "now": [now[k] for k in then]}
        frm, to = "before", "now"
    else:
        arms = {arm: [r for r in rows if r["arm"] == arm] for arm in ARMS}
        frm, to = "uniform", "read"
    out = [f"runs: {len({r['run'] for r in rows if before is None or r['run'] in then})} cut "
           "runs, " + ("each fitted with the start read, before and now" if before is not None
                       else "each fitted with both starts")]
    for arm, sub in arms.items():
        moved = sum((r["prehistory_s"] or 0) > 0 for r in sub)
        out += [f"start {arm!r}" + (f" (moved on {moved} runs):" if arm != "uniform" else ":"),
                *rates(sub)]
    by = {r["run"]: r for r in arms[frm]}
    changed = [(r["run"], by[r["run"]], r) for r in arms[to]
               if r["run"] in by and _said(by[r["run"]]) != _said(r)]
    out.append(f"verdicts changed ({len(changed)}): run, truth: {frm} -> {to}")
    out += [f"  {run}, {r['truth']}: {_said(u)} -> {_said(r)}" for run, u, r in changed]
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, help="write the rows to this JSON file")
    ap.add_argument("--rows", type=Path, help="summarise these rows (no fitting)")
    ap.add_argument("--before", type=Path,
                    help="with --rows: rows of an earlier commit, whose 'read' arm the summary "
                    "sets against the rows' (the rates of each, the verdicts changed)")
    ap.add_argument("--summary", type=Path, help="also write the summary to this file")
    ap.add_argument("--arms", nargs="+", choices=list(ARMS), default=list(ARMS),
                    help="fit these starts only (default: both)")
    args = ap.parse_args(argv)
    if args.rows:
        rows = json.loads(args.rows.read_text(encoding="utf-8"))
    else:
        if not cases(args.runs):
            sys.exit(f"bench_start: no family runs in {CACHE}; run "
                     "python benchmarks/bench_families.py --synth-only first")
        from dataclasses import replace

        for c in cases(args.runs):  # made here once, read by both arms' workers
            if not cut_path(c).exists():
                cut_path(c).parent.mkdir(exist_ok=True)
                cut_run(CACHE / f"{c.family}-{c.seed}.csv", cut_path(c), c.cut_s)
        jobs = [replace(c, arm=arm) for c in cases(args.runs) for arm in args.arms]
        rows = run_verdicts(
            one, jobs, workers=args.workers, header="cut run, start: truth -> verdict",
            line=lambda r: f"  {r['run']}, {r['arm']}: {r['truth']} -> {r['verdict']} "
                           f"{','.join(r['named'])}", group=lambda r: r["arm"],
            json_path=args.json)
    if args.before and not args.rows:
        ap.error("--before needs --rows")
    before = json.loads(args.before.read_text(encoding="utf-8")) if args.before else None
    text = "\n".join(summary(rows, before))
    print(text)
    if args.summary:
        from spindle.outputs import atomic_write

        atomic_write(args.summary, lambda tmp: tmp.write_text(text + "\n", encoding="utf-8"))


if __name__ == "__main__":
    main()
