"""Does a verdict survive what a bench's logging does to a run? Each of the peer's runs is
fitted as exported and again after a change of its logging that leaves the spindle's
physics alone; the share of verdicts that stay the same, and of right verdicts, with 95 %
Wilson intervals.

    python benchmarks/bench_perturb.py [--runs FOLDER ...] [--perturbations clock ...]
                                       [--workers 2] [--json OUT.json] [--summary FILE]
    python benchmarks/bench_perturb.py --rows OUT.json --summary FILE

Perturbations (each from the run as exported):

- ``clock``: the bench logs the time of day: every ``time_s`` plus an offset drawn per run
  from 0-24 h (to 0.1 s). The model's grid holds the multiples of 60 s of the run's own
  clock (spindle.bench_inputs.bench_grid), so it falls on other samples;
- ``decimate``: a slower logger: a row at the first sample at or after every 30 s, each
  cell the channel's last logged value there (a log by exception leaves cells empty);
- ``sparse``: a logger that reports each measured channel (T1, T2, T_stator, P1) half as
  often: every second value of each left out (its cell empty);
- ``reorder``: the columns in reverse order, an unknown column, CRLF line ends and one more
  comment line: the same data, so the verdict must be the same to the last digit (a
  control of the benchmark itself).

A verdict "stays" when the named effects (in order) and the unexplained flag are those of
the run as exported. The peer's truth.json says which verdict is right
(benchmarks/verdicts.judge_verdict). About 20 min on 2 cores for the 23 runs and four
perturbations.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import sys
import tempfile
import zlib
from dataclasses import dataclass
from pathlib import Path

from bench_families import PEER_RUNS, rate_line
from verdicts import fit_outcome, judge_verdict, named_text, read_truth, run_verdicts

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)

PERTURBATIONS = ("clock", "decimate", "sparse", "reorder")
MEASURED = ("T1_C", "T2_C", "T_stator_C", "P1_um")
#: the slower logger's period [s]
DECIMATE_S = 30.0


@dataclass(frozen=True)
class Case:
    run: str  # the exported CSV
    truth: object
    perturbation: str  # "none" or one of PERTURBATIONS
    seed: int = 0

    @property
    def label(self) -> str:
        return f"{Path(self.run).stem}/{self.perturbation}"


def perturbed_text(text: str, perturbation: str, seed: int) -> str:
    """The CSV ``text`` of a bench export as the logging ``perturbation`` (module docstring)
    would have written it; ``seed`` draws the clock's offset."""
    import numpy as np

    lines = text.splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    rows = list(csv.reader(ln for ln in lines if not ln.startswith("#")))
    header, body = rows[0], [r for r in rows[1:] if r]
    it = header.index("time_s")
    newline = "\n"
    if perturbation == "clock":
        offset = round(float(np.random.default_rng([seed, 17]).uniform(0.0, 86400.0)), 1)
        body = [[f"{float(v) + offset:.3f}" if i == it else v for i, v in enumerate(r)]
                for r in body]
    elif perturbation == "decimate":
        kept, last, next_t = [], [""] * len(header), -float("inf")
        for r in body:
            # each channel's last logged value (a log by exception leaves cells empty)
            last = [v if v != "" else h for v, h in zip(r, last, strict=True)]
            if float(r[it]) >= next_t:
                kept.append(list(last))
                next_t = float(r[it]) + DECIMATE_S
        body = kept
    elif perturbation == "sparse":
        count = dict.fromkeys((i for i, h in enumerate(header) if h in MEASURED), 0)
        for r in body:
            for i in count:
                if r[i] != "":
                    count[i] += 1
                    if count[i] % 2 == 0:
                        r[i] = ""
    elif perturbation == "reorder":
        order = list(reversed(range(len(header))))
        header = [header[i] for i in order] + ["humidity_pct"]
        body = [[r[i] for i in order] + ["45"] for r in body]
        comments = [*comments, "# exported: with a spare column"]
        newline = "\r\n"
    elif perturbation != "none":
        raise ValueError(f"unknown perturbation {perturbation!r}")
    out = io.StringIO()
    writer = csv.writer(out, lineterminator=newline)
    writer.writerow(header)
    writer.writerows(body)
    return "".join(c + newline for c in comments) + out.getvalue()


def one(case: Case) -> dict:
    """Fit the run as the case's logging would have written it; its verdict."""
    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec

    text = Path(case.run).read_text(encoding="utf-8")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / Path(case.run).name
        path.write_text(perturbed_text(text, case.perturbation, case.seed), encoding="utf-8",
                        newline="")
        rep = run_fit(path, load_spec("spl2782"))
    out = fit_outcome(rep.to_dict())
    verdict = judge_verdict(case.truth, out["named_plain"], out["unexplained"])
    return {"run": Path(case.run).stem, "perturbation": case.perturbation,
            "truth": case.truth, **out, **verdict, "fit_s": rep.runtime_s}


def summary(rows: list[dict]) -> str:
    """Per perturbation: verdicts that stay, right verdicts, and the runs that changed."""
    base = {r["run"]: r for r in rows if r["perturbation"] == "none"}

    def stays(r: dict) -> bool:
        b = base[r["run"]]
        return (r["named"], r["unexplained"]) == (b["named"], b["unexplained"])

    def right(r: dict) -> bool:
        return r["right"]

    def wrong(r: dict) -> bool:
        return r["wrong"]

    exported = list(base.values())
    lines = [f"runs: {len(base)} as exported; rates with 95 % Wilson intervals",
             rate_line("right verdict, as exported", exported, right),
             rate_line("a wrong effect named, as exported", exported, wrong)]
    for p in dict.fromkeys(r["perturbation"] for r in rows if r["perturbation"] != "none"):
        mine = [r for r in rows if r["perturbation"] == p and r["run"] in base]
        lines += [f"{p}:", rate_line("verdict stays", mine, stays),
                  rate_line("right verdict", mine, right),
                  rate_line("a wrong effect named", mine, wrong)]
        for r in (r for r in mine if not stays(r)):
            b = base[r["run"]]
            lines.append(f"    {r['run']:8} {named_text(b['named'], b['unexplained'])} -> "
                         f"{named_text(r['named'], r['unexplained'])} "
                         f"({'right' if b['right'] else 'not right'} -> "
                         f"{'right' if r['right'] else 'not right'})")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", nargs="+", type=Path,
                    default=[PEER_RUNS / "bench-runs", PEER_RUNS / "bench-runs-2"],
                    help="folders of bench exports with their truth.json")
    ap.add_argument("--perturbations", nargs="+", choices=PERTURBATIONS,
                    default=list(PERTURBATIONS))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    ap.add_argument("--rows", type=Path, help="summarise rows written by --json, fit nothing")
    ap.add_argument("--summary", type=Path, help="also write the summary to this file")
    args = ap.parse_args(argv)
    if args.rows is not None:
        rows = json.loads(args.rows.read_text(encoding="utf-8"))
    else:
        cases = []
        for folder in args.runs:
            for k, v in sorted(read_truth(folder).items()):
                seed = zlib.crc32(k.encode())  # the clock's offset: a run's own
                cases += [Case(str(folder / f"{k}.csv"), v.get("truth"), p, seed)
                          for p in ["none", *args.perturbations]]

        def line(r: dict) -> str:
            return (f"{r['run']:8} {r['perturbation']:9} {str(r['truth'])[:36]:36} "
                    f"{named_text(r['named'], r['unexplained'])[:40]:40} "
                    f"{'yes' if r['right'] else 'NO ':3} {r['fit_s']:5.0f}")

        rows = run_verdicts(one, cases, workers=args.workers, line=line, json_path=args.json,
                            group=lambda r: r["perturbation"],
                            header=f"{'run':8} {'logging':9} {'truth':36} {'named':40} ok  s")
    text = summary(rows)
    print(text)
    if args.summary is not None:
        from spindle.outputs import atomic_write

        command = f"python benchmarks/bench_perturb.py {' '.join(argv or sys.argv[1:])}"
        if args.rows is not None:  # the rows of a fitting call saved with --json
            command = ("python benchmarks/bench_perturb.py --json ROWS; python "
                       f"benchmarks/bench_perturb.py --rows ROWS --summary {args.summary}")
        atomic_write(args.summary, lambda tmp: tmp.write_text(f"{command}\n{text}\n",
                                                              encoding="utf-8"))


if __name__ == "__main__":
    main()
