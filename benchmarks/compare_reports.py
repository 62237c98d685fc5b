"""A rule's trade, measured: two folders of fit reports (``bench_families.py --reports``) of
the same runs, before and after a change, compared run by run; or two files of rows
(``bench_families.py --json``).

    python benchmarks/compare_reports.py BEFORE AFTER [--json OUT.json]
                                         [--label "what changed"]

Prints, per family and in all, the runs with the right verdict, the true effect named first,
a wrong name and 'unexplained', before and after; every run whose verdict changed; and the
median validation RMS of the calibrated base model [tolerances] (the base's misfit, before any
effect is named; rows do not hold it). From rows, it also counts the runs whose validation RMS
after moved and gives the fit times. ``--json`` writes the same as a figures file (benchmarks/figures.py) that
docs/fit.md quotes. The truths are read where bench_families keeps them: the synthetic runs'
sidecars in benchmarks/.families-cache, the peer's truth.json in tests/data/peer-runs.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from bench_families import FAMILIES, PEER_RUNS, ROOT
from verdicts import fit_outcome, judge_verdict, read_truth

CACHE = ROOT / "benchmarks" / ".families-cache"
COUNTS = ("right", "first", "wrong", "unexplained")


def truth_of(run: str, peers: dict) -> object:
    """A run's truth as bench_families judges it."""
    if run in peers:
        return peers[run]
    doc = json.loads((CACHE / f"{run}.truth.json").read_text(encoding="utf-8"))
    if run.startswith("outside"):
        return "unexplained"
    return None if doc["effect"] == "clean" else doc["effect"]


def require_reports(paths) -> None:
    """End the script with one message and exit status 2 where a path is neither a folder of
    reports nor a file of rows, or where one is a folder and the other a file."""
    for d in paths:
        if not (d.is_file() or (d.is_dir() and any(d.glob("*.json")))):
            print(f"error: {d}: no report.json files; give folders written by "
                  "bench_families.py --reports or files written by its --json",
                  file=sys.stderr)
            raise SystemExit(2)
    if len({d.is_file() for d in paths}) > 1:
        print(f"error: {paths[0]}, {paths[1]}: one is a folder of reports and the other a file "
              "of rows; compare two of a kind", file=sys.stderr)
        raise SystemExit(2)


def peer_truths() -> dict:
    """The peer's runs' truths by run name (tests/data/peer-runs)."""
    peers = {}
    for folder in (PEER_RUNS / "bench-runs", PEER_RUNS / "bench-runs-2"):
        peers.update({k: v.get("truth") for k, v in read_truth(folder).items()})
    return peers


def family_of(run: str) -> str:
    head = run.split("-")[0]
    return head if head in FAMILIES else "peers"


def row_outcomes(path: Path) -> dict[str, dict]:
    """:func:`outcomes` from the rows of ``bench_families.py --json`` (judged when they were
    written), with the validation RMS after [K; µm for P1] and the fit time [s]; the base's
    RMS is not in them."""
    try:
        rows = json.loads(path.read_text(encoding="utf-8"))
        return {r["run"]: {"family": r["family"], "named": r["named"], "verdict": r["verdict"],
                           "unexplained": r["unexplained"], "right": r["right"],
                           "first": bool(r["first"]), "wrong": r["wrong"], "base_rms_tol": None,
                           "rms_after": r["validation_rmse"], "fit_s": r["fit_s"]}
                for r in rows}
    except (ValueError, TypeError, KeyError) as e:
        print(f"error: {path}: not the rows of bench_families.py --json ({e!r})", file=sys.stderr)
        raise SystemExit(2) from None


def outcomes(path: Path, peers: dict) -> dict[str, dict]:
    """Per run: the family, the verdict judged against the truth, the named effects and the
    base's median validation RMS over its channels [tolerances]; from a folder of reports, or
    from a file of rows (:func:`row_outcomes`)."""
    import numpy as np

    if path.is_file():
        return row_outcomes(path)
    out = {}
    for p in sorted(path.glob("*.json")):
        doc = json.loads(p.read_text(encoding="utf-8"))
        o = fit_outcome(doc)
        v = judge_verdict(truth_of(p.stem, peers), o["named_plain"], o["unexplained"])
        base = [e["rmse_tolerances"] for e in doc["error_before"]["validation"].values()]
        out[p.stem] = {"family": family_of(p.stem), "named": o["named"],
                       "verdict": o["verdict"], "unexplained": o["unexplained"],
                       "right": v["right"], "first": bool(v["first"]), "wrong": v["wrong"],
                       "base_rms_tol": float(np.median(base)) if base else None}
    return out


def compare(before: dict, after: dict) -> dict:
    """The counts per family (and ``all``) over the runs both folders hold, the runs whose
    verdict changed, and the median base validation RMS per family."""
    import numpy as np

    runs = sorted(set(before) & set(after))
    fams = [f for f in (*FAMILIES, "peers") if any(before[r]["family"] == f for r in runs)]
    table = {}
    for f in [*fams, "all"]:
        mine = [r for r in runs if f == "all" or before[r]["family"] == f]
        row = {"runs": len(mine)}
        for tag, x in (("before", before), ("after", after)):
            row[tag] = {k: int(sum(bool(x[r][k]) for r in mine)) for k in COUNTS}
            base = [x[r]["base_rms_tol"] for r in mine if x[r]["base_rms_tol"] is not None]
            row[tag]["base_rms_tol_median"] = round(float(np.median(base)), 4) if base else None
        table[f] = row
    changed = [{"run": r, "before": before[r]["named"] or before[r]["verdict"],
                "after": after[r]["named"] or after[r]["verdict"],
                "right": [before[r]["right"], after[r]["right"]]}
               for r in runs if (before[r]["named"], before[r]["verdict"])
               != (after[r]["named"], after[r]["verdict"])]
    result = {"families": table, "changed": changed}
    if all("rms_after" in x[r] for x in (before, after) for r in runs):
        result.update(rms_moves(before, after, runs))
    return result


def rms_moves(before: dict, after: dict, runs: list[str]) -> dict:
    """Over the runs with a validation RMS in both: how many moved by more than 0.001 and 0.01
    (K; µm for P1) on some channel, and the largest move; the fit times' median and maximum."""
    import numpy as np

    moves = []
    for r in runs:
        b, a = before[r]["rms_after"], after[r]["rms_after"]
        if b and a:
            moves.append(max((abs(a[c] - b[c]) for c in b if c in a), default=0.0))
    moves = np.asarray(moves)
    return {"rms_moved": {"runs": len(moves), "over_0.001": int((moves > 1e-3).sum()),
                          "over_0.01": int((moves > 1e-2).sum()),
                          "largest": round(float(moves.max()), 3) if len(moves) else None,
                          "unit": "K; um for P1"},
            "fit_s": {tag: {"median": round(float(np.median([x[r]["fit_s"] for r in runs])), 1),
                            "max": round(float(max(x[r]["fit_s"] for r in runs)), 1),
                            "total": round(float(sum(x[r]["fit_s"] for r in runs)))}
                      for tag, x in (("before", before), ("after", after))}}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("before", type=Path)
    ap.add_argument("after", type=Path)
    ap.add_argument("--json", type=Path, help="write the comparison as a figures file")
    ap.add_argument("--label", default="", help="what changed between the two folders")
    args = ap.parse_args(argv)
    require_reports((args.before, args.after))
    peers = peer_truths()
    result = compare(outcomes(args.before, peers), outcomes(args.after, peers))
    for f, row in result["families"].items():
        b, a = row["before"], row["after"]
        print(f"{f:8} {row['runs']:4d} runs  " + "  ".join(
            f"{k} {b[k]} -> {a[k]}" for k in COUNTS)
            + f"  base RMS {b['base_rms_tol_median']} -> {a['base_rms_tol_median']} tol")
    for c in result["changed"]:
        print(f"  {c['run']:14} {c['before']} -> {c['after']}  right {c['right'][0]} -> "
              f"{c['right'][1]}")
    if "rms_moved" in result:
        m, t = result["rms_moved"], result["fit_s"]
        print(f"validation RMS after moved on {m['over_0.001']} of {m['runs']} runs by more "
              f"than 0.001 ({m['over_0.01']} by more than 0.01), at most {m['largest']} "
              f"({m['unit']})")
        print("fit time: " + ", ".join(f"{k} median {v['median']} s, max {v['max']} s, total "
                                       f"{v['total']} s" for k, v in t.items()))
    if args.json:
        from figures import write_figures

        write_figures(args.json, "python benchmarks/compare_reports.py "
                      + " ".join(argv or sys.argv[1:]), {"label": args.label, **result})


if __name__ == "__main__":
    main()
