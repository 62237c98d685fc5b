"""What each criterion of the open loop decides, on fit reports (``bench_families.py
--reports``): among the candidates of a round of the selection that pass every *other*
criterion, how many true effects and how many false candidates it passes, and its figure
for each (so that a threshold is seen against the spread it cuts).

    python benchmarks/criteria_margins.py REPORTS_DIR [REPORTS_DIR ...] [--rounds 1 2]
                                          [--json OUT.json]

A candidate is true where its effect is one of the run's (the truths as compare_reports.py
reads them). Every candidate counted is significant and material (the cross-validation is
asked only of those) and is judged by the open loop (the signature route's candidates are not
asked the open loop's criteria); the signature's veto is counted as a criterion. The figures
(compare.fit.select.judge):

- ``predicts``: the share of the cross-validated excess error it removes, against cv_gain;
- ``beats_something_else``: its penalised gain less the competitor's, against 0;
- ``distinct``: its penalised gain less the best rival's and the margin, against 0;
- ``changes_prediction``: the fitted model's net change on its channels [tolerances],
  against material_peak (it passes, too, where ``restores_plausible_base`` does:
  compare.fit.select.model_changes).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable
from pathlib import Path

from compare_reports import peer_truths, require_reports, truth_of

from compare.fit.select import CRITERIA_ORDER, OPEN_LOOP, model_changes

#: asked of every candidate counted (they gate the cross-validation)
PREREQUISITES = ("significant", "material")
#: the criteria counted: the rest, restores_plausible_base within changes_prediction
#: (null_at_optimum and final_model_adequate are asked of the joining candidate only)
CRITERIA = tuple(c for c in CRITERIA_ORDER
                 if c not in (*PREREQUISITES, "restores_plausible_base", "null_at_optimum",
                              "final_model_adequate"))


def passes(crit: dict, name: str) -> bool:
    """Whether a candidate's named criteria ``crit`` pass criterion ``name`` (None, not
    asked, passes; changes_prediction as compare.fit.select.model_changes)."""
    return model_changes(crit) if name == "changes_prediction" else crit.get(name) is not False


def figure(c: dict, name: str, criteria: dict) -> float | None:
    """The candidate's figure for criterion ``name`` (module docstring), None where the report
    has none; ``criteria``: the report's criteria table by name."""
    from scipy.stats import chi2

    if name == "predicts":
        b, a = c.get("cv_before"), c.get("cv_after")
        return None if b is None or a is None or b <= 0 else 1.0 - a / b
    if name == "beats_something_else":
        comp = c.get("competitor_penalised_gain")
        return c["penalised_gain"] - (comp if comp is not None else -math.inf)
    if name == "distinct":
        rival = c.get("rival_penalised_gain")
        margin = 0.5 * float(chi2.isf(criteria["alpha"], 1))
        return c["penalised_gain"] - margin - (rival if rival is not None else -math.inf)
    if name == "changes_prediction":
        return c.get("net_change_peak")
    return None


def margins(folders: list[Path], truth: Callable[[str], object], rnd: int = 1) -> dict:
    """Per criterion: the true and false open-loop candidates of round ``rnd`` that pass every
    other criterion, how many of each it passes, and their figures (``truth``: a run's truth
    by its name, as compare_reports.truth_of)."""
    from compare.fit.effects import parse_label

    out = {k: {"true": [], "false": []} for k in CRITERIA}
    for folder in folders:
        for p in sorted(folder.glob("*.json")):
            doc = json.loads(p.read_text(encoding="utf-8"))
            t = truth(p.stem)
            true = set(t) if isinstance(t, list | tuple) else {t}
            table = {row["name"]: row["value"] for row in doc["criteria"]}
            for c in doc["candidates"]:
                crit = c["criteria"]
                if (c["round"] != rnd or crit.get("signature") is True
                        or not all(crit.get(k) for k in PREREQUISITES)):
                    continue
                side = "true" if parse_label(c["candidate"])[0] in true else "false"
                for k in CRITERIA:
                    # open loop: every other criterion passed or not asked (None), and the
                    # open-loop ones asked
                    if not all(passes(crit, o) for o in CRITERIA if o != k) or any(
                            crit.get(o) is None for o in OPEN_LOOP if o != k):
                        continue
                    out[k][side].append({"run": p.stem, "candidate": c["candidate"],
                                         "passes": passes(crit, k),
                                         "figure": figure(c, k, table)})
    return out


def table(result: dict) -> list[dict]:
    """Per criterion: counts of true and false candidates and their passes, the true ones'
    least and median figure, the false ones' median and largest, and which runs they are."""
    rows = []
    for k, sides in result.items():
        t, f = sides["true"], sides["false"]
        tf = sorted(x["figure"] for x in t if x["figure"] is not None)
        ff = sorted(x["figure"] for x in f if x["figure"] is not None)

        def q(v: list[float], at: float) -> float | None:
            return v[min(int(at * len(v)), len(v) - 1)] if v else None

        rows.append({"criterion": k, "true": len(t), "true_pass": sum(x["passes"] for x in t),
                     "false": len(f), "false_pass": sum(x["passes"] for x in f),
                     "true_min": q(tf, 0.0), "true_median": q(tf, 0.5),
                     "false_median": q(ff, 0.5), "false_max": q(ff, 1.0),
                     "true_failing": [f"{x['run']}:{x['candidate']}" for x in t
                                      if not x["passes"]],
                     "false_passing": [f"{x['run']}:{x['candidate']}" for x in f
                                       if x["passes"]]})
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("reports", type=Path, nargs="+")
    ap.add_argument("--rounds", type=int, nargs="+", default=[1, 2],
                    help="the selection's rounds (default 1 2: against the base, and against "
                    "the model that holds the first effect)")
    ap.add_argument("--json", type=Path, help="write the tables as a figures file")
    args = ap.parse_args(argv)
    require_reports(args.reports)
    peers = peer_truths()
    tables = {}
    for rnd in args.rounds:
        rows = tables[str(rnd)] = table(margins(args.reports, lambda r: truth_of(r, peers), rnd))
        print(f"round {rnd}:")
        print(f"  {'criterion':22} {'true: pass / all':>17} {'false: pass / all':>18}   "
              "true figure min / median   false figure median / max")

        def num(v: float | None) -> str:
            return "-" if v is None else f"{v:.2f}"

        for row in rows:
            print(f"  {row['criterion']:22} {row['true_pass']:8d} / {row['true']:<6d} "
                  f"{row['false_pass']:9d} / {row['false']:<6d}   {num(row['true_min']):>10} / "
                  f"{num(row['true_median']):<10}   {num(row['false_median']):>10} / "
                  f"{num(row['false_max'])}")
    if args.json:
        from figures import write_figures

        write_figures(args.json, "python benchmarks/criteria_margins.py "
                      + " ".join(argv or sys.argv[1:]), {"rounds": tables})


if __name__ == "__main__":
    main()
