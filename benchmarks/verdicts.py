"""What the verdict benchmarks share (bench_devruns, bench_families, bench_peerinject,
bench_input_contract): run cases through :func:`compare.executor.run_cases`, print a row per
case, count the right verdicts (in all and per group), write the rows as JSON.

A benchmark gives ``one(case) -> dict`` (a row with a boolean ``"right"``), a header and
``line(row) -> str``; :func:`run_verdicts` does the rest. Imported by the scripts beside it
(``python benchmarks/bench_x.py`` puts this folder on the path).
"""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import figures  # noqa: F401  (it checks that the checkout's code is the code measured)

#: the channels of a fit's validation RMS, in the order the tables print them
CHANNELS = ("T1", "T2", "T_stator", "P1")
RMS_HEADER = "validation RMS after (T1 T2 Tst K, P1 µm)"


def rms_cells(rmse: dict[str, float], width: int = 5) -> str:
    """The RMS per channel [K; µm for P1] as fixed-width cells (nan where a run lacks one)."""
    return " ".join(f"{rmse.get(c, float('nan')):{width}.2f}" for c in CHANNELS)


def fit_outcome(doc: dict) -> dict:
    """What every verdict table reads from a fit's report.json: the named effects (plain
    names and labels), the verdict's kind, whether it says unexplained, and the validation
    RMS after per channel."""
    return {"named_plain": [e["name"] for e in doc["effects"]],
            "named": [e["label"] for e in doc["effects"]],
            "verdict": doc["verdict"]["kind"],
            "unexplained": bool(doc["verdict"]["unexplained"]),
            "validation_rmse": {c: v["rmse"] for c, v in doc["error_after"]["validation"]
                                .items()}}


def located(doc: dict, truth_doc: dict) -> bool | None:
    """Whether the window of an "unexplained" verdict's event (report.json's something_else
    hypothesis, where the competitor's test made the run unexplained) meets the span [s] over
    which a cause outside the library in the run's truth acts (compare.synth.outside's
    ``acts_s``); None where the verdict located no event or no such cause has a span (an
    electronics drift acts over the whole run)."""
    from compare.synth.outside import OUTSIDE

    se = doc.get("something_else") or {}
    h = se.get("hypothesis")
    if se.get("basis") != "something else" or not h:
        return None
    effects = truth_doc.get("effect")
    params = truth_doc.get("parameters") or {}
    if isinstance(effects, str):
        effects, params = [effects], {effects: params}
    spans = [OUTSIDE[e].acts_s(params[e]) for e in effects or [] if e in OUTSIDE]
    spans = [s for s in spans if s is not None]
    if not spans:
        return None
    return any(h["t0_s"] < b and h["t1_s"] > a for a, b in spans)


def within_tolerances(rmse: dict[str, float]) -> bool:
    """Whether every channel's RMS [K; µm for P1] is within its tolerance."""
    from spindle.tolerances import channel_tolerance, edge_scale

    return all(v <= channel_tolerance(c) * edge_scale(c) for c, v in rmse.items())


def judge_verdict(truth, named: list[str], unexplained: bool) -> dict:
    """How a fit's verdict compares with a run's truth: ``truth`` is None or "none" (a
    control), "unexplained" or the name of a cause outside the library, an effect's name, or
    a list of effects (several in one run); ``named`` the plain names the fit named, in order.

    - ``right``: the verdict as a whole: a control names nothing; a run outside the library
      names nothing and says unexplained; an effect's run names it alone; a run of several
      names them all and nothing else;
    - ``first``: the first name is a true effect (runs with an effect only);
    - ``false_second``: a second name that is not a true effect after a right first one;
    - ``wrong``: some name is not a true effect (on any run);
    - ``kind``: "control", "outside", "effect", "effects" or "effect+outside" (a list with
      a cause outside the library beside the library's effects: right where it names those
      and says something else remains).
    """
    from compare.fit.effects import LIBRARY

    if truth in (None, "none", "clean"):
        kind, true = "control", []
    elif isinstance(truth, list | tuple):
        true = [t for t in truth if t in LIBRARY]
        kind = ("effects" if len(true) == len(truth) else "effect+outside" if true
                else "outside")
    elif truth in LIBRARY:
        kind, true = "effect", [truth]
    else:
        kind, true = "outside", []
    wrong = any(n not in true for n in named)
    if kind in ("control", "outside"):
        right = not named and (unexplained or kind == "control")
        first = None
    else:
        right = (set(named) == set(true) and len(named) == len(true)
                 and (unexplained or kind != "effect+outside"))
        first = bool(named) and named[0] in true
    second = (bool(first) and len(named) > 1 and named[1] not in true) if first else False
    return {"kind": kind, "right": right, "first": first, "false_second": second,
            "wrong": wrong}


def missed_by(doc: dict, truth) -> list[str] | None:
    """Why a run's true effect was not named first, read off its report.json (``doc``): the
    named criteria (compare.fit.select) that the true effect's first-round judgement failed,
    ``signature`` where its own test vetoed it; ``qualified, another joined first`` where it
    qualified and a candidate with more likelihood joined instead; ``not a candidate`` where
    the fit did not try it. Of a per-channel effect (a lag) the judgement with the largest
    gain counts. None where the run carries no library effect or named a true one first."""
    from compare.fit.effects import parse_label
    from compare.fit.select import model_changes

    verdict = judge_verdict(truth, [e["name"] for e in doc["effects"]],
                            bool(doc["verdict"]["unexplained"]))
    if verdict["kind"] not in ("effect", "effects", "effect+outside") or verdict["first"]:
        return None
    true = set(truth) if isinstance(truth, list | tuple) else {truth}
    mine = [c for c in doc.get("candidates", [])
            if c["round"] == 1 and parse_label(c["candidate"])[0] in true]
    if not mine:
        return ["not a candidate"]
    best = max(mine, key=lambda c: c["gain"])
    if best["qualifies"]:
        return ["qualified, another joined first"]
    crit = best["criteria"]
    # the open loop's last criterion is one of two (compare.fit.select.model_changes): the
    # prediction's change, failed only where the plausible base does not stand in for it
    failed = {k for k, v in crit.items() if v is False} - {"restores_plausible_base"}
    if model_changes(crit):
        failed.discard("changes_prediction")
    return sorted(failed)


def named_text(named: Sequence[str], unexplained: bool) -> str:
    """The named effects as the tables print them, or 'unexplained' / 'nothing'."""
    return ", ".join(named) or ("unexplained" if unexplained else "nothing")


def require_files(paths, what: str) -> None:
    """End the script with one message and exit status 2, not a traceback, where one of
    ``paths`` is not a file (``what`` says which argument gave it)."""
    missing = [str(p) for p in paths if not Path(p).is_file()]
    if missing:
        print(f"error: {', '.join(missing)}: not found; {what} must name existing bench "
              "exports (CSV, docs/bench.md)", file=sys.stderr)
        sys.exit(2)


def read_truth(folder: Path) -> dict:
    """The runs' truth.json of a folder; a missing or broken one ends the script with one
    message and exit status 2, not a traceback."""
    path = Path(folder) / "truth.json"
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        problem = "not found; --runs must name a folder with the runs and their truth.json"
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        problem = f"cannot be read ({exc}); give a folder with a valid truth.json"
    print(f"error: {path}: {problem}", file=sys.stderr)
    sys.exit(2)


def run_verdicts(one: Callable[[object], dict], cases: Sequence, *, workers: int,
                 header: str, line: Callable[[dict], str],
                 group: Callable[[dict], str] | None = None,
                 json_path: Path | None = None) -> list[dict]:
    """Run ``one`` on every case (a process pool of ``workers``, progress on stderr), print
    ``header`` and a ``line`` per row (an empty line is not printed; a case that failed says
    so), the right verdicts per ``group`` and in all, and write the rows to ``json_path``.
    Returns the rows."""
    from compare.executor import run_cases, stderr_progress
    from spindle.outputs import write_json

    t = time.perf_counter()
    outcomes = run_cases(one, list(cases), workers=workers, progress=stderr_progress())
    rows = []
    print(header)
    for o in outcomes:
        if o.error:
            print(f"{o.label} failed: {o.error}")
            continue
        rows.append(o.value)
        text = line(o.value)
        if text:
            print(text)
    if group is not None:
        print("right, per group:")
        for g in dict.fromkeys(group(r) for r in rows):
            mine = [r for r in rows if group(r) == g]
            print(f"  {g:24} {sum(r['right'] for r in mine)} of {len(mine)}")
    print(f"right verdicts: {sum(r['right'] for r in rows)} of {len(cases)}; wall time "
          f"{time.perf_counter() - t:.0f} s on {workers} workers")
    if json_path is not None:
        write_json(Path(json_path), rows)  # a list, as before: write_json takes any JSON
    return rows
