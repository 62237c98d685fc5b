"""Where each switchable rule of the selection decided something, read off kept reports.

    python benchmarks/rule_census.py DIR [DIR ...]

DIR holds report.json files named by run (``bench_families.py --reports DIR``). A rule
*decided* on a run where the verdict would read otherwise without it, as far as the report's
named criteria tell (compare.fit.select: the criteria of every judged candidate, the
verdict's basis):

- ``plausible_base_route``: an open-loop candidate qualified only because its base went from
  implausible to plausible (its prediction did not change materially);
- ``open_loop_material_change``: a candidate that passed every other criterion of the open
  loop was stopped because its prediction did not change materially;
- ``null_from_candidate``: a joining candidate's refit found the model without it better
  (``null_at_optimum`` false), and the round was judged again;
- ``open_loop_adequate_model``: an open-loop name withdrawn after the selection;
- ``law_rivals``: a candidate that passed every other criterion did not beat something else,
  and a law of the speed was the likeliest rival (a report names that law since 2026-12-02;
  on reports written before, this rule's decisions are not seen);
- ``held_out_misfit_unexplained``: the run is "unexplained" by its held-out misfit alone;
- ``signature veto``: a candidate that passed every other criterion of the open loop was
  stopped because its signature applies and is not significant.

A rule that decides on no run of many drawn families could go without changing a verdict; one
that decides on some is a trade to measure (``bench_families.py --criterion NAME=false``).
Prints, per rule, the runs it decided on.
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Iterable
from pathlib import Path

from compare.fit.select import OPEN_LOOP


def decisions(report: dict) -> set[str]:
    """The rules that decided something on one run's report (module docstring)."""
    out: set[str] = set()
    for j in report.get("candidates", []):
        c = j["criteria"]
        passed = bool(c["significant"] and c["material"])
        # a signature that applies decides alone (named by it, or vetoed): the open loop's
        # rules and the laws decide only where none applies (compare.fit.select.Judgement.route)
        open_loop = passed and c["signature"] is None and all(c.get(k) for k in OPEN_LOOP)
        if open_loop and c.get("changes_prediction") is False:
            out.add("plausible_base_route" if c.get("restores_plausible_base")
                    else "open_loop_material_change")
        if c.get("null_at_optimum") is False:
            out.add("null_from_candidate")
        if c.get("final_model_adequate") is False:
            out.add("open_loop_adequate_model")
        others = (passed and c["signature"] is None and c.get("predicts")
                  and c.get("distinct"))
        if others and not c["beats_something_else"] and j.get("law"):
            out.add("law_rivals")
        if (passed and c["signature"] is False and all(c.get(k) for k in OPEN_LOOP)
                and c.get("changes_prediction") is not False):
            out.add("signature veto")
    if report.get("something_else", {}).get("basis") == "held-out misfit":
        out.add("held_out_misfit_unexplained")
    return out


def census(folders: Iterable[Path]) -> tuple[int, dict[str, list[str]]]:
    """(reports read, the runs each rule decided on)."""
    runs: dict[str, list[str]] = {}
    n = 0
    for folder in folders:
        for path in sorted(Path(folder).glob("*.json")):
            n += 1
            for rule in decisions(json.loads(path.read_text(encoding="utf-8"))):
                runs.setdefault(rule, []).append(path.stem)
    return n, runs


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path, help="folders of report.json files")
    args = ap.parse_args(argv)
    n, runs = census(args.folders)
    print(f"{n} reports")
    for rule, names in sorted(runs.items(), key=lambda kv: -len(kv[1])):
        print(f"  {rule:30} decided on {len(names):3d} runs: {', '.join(names)}")


if __name__ == "__main__":
    main()
