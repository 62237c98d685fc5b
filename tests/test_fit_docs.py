"""docs/fit.md cannot go stale: its library table is the registry's, its criteria rows are
``Criteria().table()``'s, and its generalisation figures are the file the benchmark wrote
(docs/figures/fit-families.txt, from ``python benchmarks/bench_families.py``)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC = (ROOT / "docs" / "fit.md").read_text(encoding="utf-8")


def _block(name: str) -> str:
    m = re.search(rf"<!-- {name}:begin -->\n(.*?)<!-- {name}:end -->", DOC, re.S)
    assert m, f"docs/fit.md has no {name} block"
    return m.group(1)


def _rows(block: str) -> list[list[str]]:
    rows = [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in block.splitlines() if line.startswith("|")]
    return rows[2:]  # header and rule


def test_the_library_table_is_the_registry():
    from compare.fit.effects import LIBRARY
    from compare.fit.effects.base import Effect

    rows = {re.match(r"`(\w+)`", r[0]).group(1): r for r in _rows(_block("library"))}
    assert set(rows) == set(LIBRARY)
    for name, effect in LIBRARY.items():
        documented = re.findall(r"`(\w+)`", rows[name][1])
        assert documented == [p.name for p in effect.params], name
        has_test = type(effect).signature is not Effect.signature
        assert (not rows[name][2].startswith("none")) == has_test, name
        assert ("per channel" in rows[name][0]) == effect.per_channel, name


def test_the_criteria_rows_are_the_table_the_fit_runs_with():
    from compare.fit.criteria import Criteria

    table = {r["name"]: r for r in Criteria().table()}
    rows = _rows(_block("criteria"))
    assert rows
    for name, value, unit in rows:
        name = name.strip("`")
        assert name in table, name
        assert value == str(table[name]["value"]), (name, value, table[name]["value"])
        assert unit == table[name]["unit"], name


@pytest.mark.parametrize("block, name", [("families", "fit-families.txt"),
                                         ("held-out", "fit-families-held-out.txt"),
                                         ("perturb", "perturb-peers.txt"),
                                         ("start", "fit-start.txt"),
                                         ("start-elsewhere", "fit-start-elsewhere.txt"),
                                         ("mixed", "fit-families-mixed.txt"),
                                         ("losslaw", "fit-families-losslaw.txt"),
                                         ("trade-law-rivals", "fit-trade-law-rivals.txt")])
def test_the_generalisation_figures_are_the_benchmarks_file(block, name):
    generated = (ROOT / "docs" / "figures" / name).read_text(encoding="utf-8")
    block = _block(block).strip()
    assert block.startswith("```") and block.endswith("```"), "a fenced copy of the file"
    assert block.strip("`").strip() == generated.strip()


def trade_table(doc: dict) -> str:
    """A rule's trade as docs/fit.md shows it, from the figures file that
    benchmarks/compare_reports.py wrote: per family, the counts before -> after, then the
    runs whose verdict changed."""
    def cell(row: dict, key: str, fmt: str = "{}") -> str:
        b, a = row["before"][key], row["after"][key]
        return "—" if b is None or a is None else f"{fmt.format(b)} → {fmt.format(a)}"

    lines = ["| family | runs | right verdict | true effect first | a wrong name | "
             "unexplained | base RMS [tol] |", "|---|---:|---|---|---|---|---|"]
    for fam, row in doc["families"].items():
        lines.append(f"| {fam} | {row['runs']} | {cell(row, 'right')} | {cell(row, 'first')} | "
                     f"{cell(row, 'wrong')} | {cell(row, 'unexplained')} | "
                     f"{cell(row, 'base_rms_tol_median', '{:.3f}')} |")
    lines.append("")
    if not doc["changed"]:
        lines.append("No verdict changed.")
    for c in doc["changed"]:
        def text(v) -> str:
            return ", ".join(v) if isinstance(v, list) else v
        lines.append(f"- {c['run']}: {text(c['before'])} → {text(c['after'])} "
                     f"({'right' if c['right'][0] else 'not right'} → "
                     f"{'right' if c['right'][1] else 'not right'})")
    return "\n".join(lines)


#: the trades of docs/fit.md measured with benchmarks/compare_reports.py, by block
TRADES = {"trade-time-mean": "fit-trade-time-mean.json",
          "trade-null-step": "fit-trade-null-step.json",
          "trade-signature-lr": "fit-trade-signature-lr.json",
          "trade-gap": "fit-trade-gap.json",
          "trade-reanchor": "fit-trade-reanchor.json",
          "trade-estimate": "fit-trade-estimate.json",
          "trade-material-change": "fit-trade-material-change.json",
          "trade-scan-null": "fit-trade-scan-null.json",
          "trade-misfit-named": "fit-trade-misfit-named.json",
          "trade-misfit-named-held-out": "fit-trade-misfit-named-held-out.json",
          "trade-scan-tail": "fit-trade-scan-tail.json",
          "trade-plausible-base": "fit-trade-plausible-base.json",
          "trade-plausible-base-held-out": "fit-trade-plausible-base-held-out.json",
          "trade-gap-load": "fit-trade-gap-load.json",
          "trade-gap-load-held-out": "fit-trade-gap-load-held-out.json",
          "trade-joint-verdict": "fit-trade-joint-verdict.json",
          "trade-joint-verdict-held-out": "fit-trade-joint-verdict-held-out.json",
          "trade-every-gap": "fit-trade-every-gap.json",
          "trade-every-gap-held-out": "fit-trade-every-gap-held-out.json",
          "trade-every-gap-fresh": "fit-trade-every-gap-fresh.json",
          "trade-withdraw": "fit-trade-withdraw.json",
          "trade-withdraw-held-out": "fit-trade-withdraw-held-out.json",
          "trade-withdraw-resume": "fit-trade-withdraw-resume.json",
          "trade-withdraw-resume-held-out": "fit-trade-withdraw-resume-held-out.json",
          "trade-complements": "fit-trade-complements.json",
          "trade-complements-held-out": "fit-trade-complements-held-out.json",
          "trade-complements-fresh": "fit-trade-complements-fresh.json",
          "trade-optimizer-tol": "fit-trade-optimizer-tol.json",
          "trade-optimizer-tol-held-out": "fit-trade-optimizer-tol-held-out.json",
          "trade-exact-keys": "fit-trade-exact-keys.json",
          "trade-refit-exact-steps": "fit-trade-refit-exact-steps.json",
          "trade-null-at-optimum": "fit-trade-null-at-optimum.json",
          "trade-friction-speed": "fit-trade-friction-speed.json",
          # round-off: a new machine, and the ambient read 1e-5 K higher
          "new-machine": "fit-new-machine.json",
          "roundoff-ambient": "fit-roundoff-ambient-peers.json",
          "roundoff-ambient-drawn": "fit-roundoff-ambient-drawn.json",
          "trade-prior-penalty-peers": "fit-trade-prior-penalty-peers.json",
          "roundoff-ambient-penalty": "fit-roundoff-ambient-peers-penalty.json",
          "trade-prior-penalty-drawn": "fit-trade-prior-penalty-drawn.json",
          # one objective for the calibration and the selection (2026-12-01)
          "trade-one-objective": "fit-trade-one-objective-all.json",
          "trade-pooled-variance-peers": "fit-trade-pooled-variance-peers.json",
          "roundoff-ambient-one-objective": "fit-roundoff-ambient-peers-one-objective.json"}


@pytest.mark.parametrize("block", sorted(TRADES))
def test_each_trade_is_its_figures_file(block):
    import json

    from tests.docs_blocks import assert_block

    doc = json.loads((ROOT / "docs" / "figures" / TRADES[block]).read_text(encoding="utf-8"))
    assert_block("docs/fit.md", block, trade_table(doc))


def optimizer_tol_text() -> str:
    """docs/fit.md's figures of the optimizer's tolerance, from the files compare_reports.py
    wrote from rows (validation RMS moves and fit times)."""
    import json
    import textwrap

    def doc(name: str) -> dict:
        return json.loads((ROOT / "docs" / "figures" / name).read_text(encoding="utf-8"))

    def moved(d: dict) -> str:
        m = d["rms_moved"]
        return (f"{m['over_0.001']} of {m['runs']} runs, by more than 0.01 on {m['over_0.01']}, "
                f"at most {m['largest']}")

    main, held = doc("fit-trade-optimizer-tol.json"), doc("fit-trade-optimizer-tol-held-out.json")
    r6, r8 = doc("fit-roundoff-1e-6.json"), doc("fit-roundoff-1e-8.json")
    t = main["fit_s"]
    return textwrap.fill(
        f"At 1e-8 the validation RMS moved by more than 0.001 (K or µm) on {moved(main)}; held "
        f"out on {moved(held)}. The fits took {t['after']['total']} s in all against "
        f"{t['before']['total']} s: median {t['before']['median']} → {t['after']['median']} s, "
        f"maximum {t['before']['max']} → {t['after']['max']} s. The round-off change moved the "
        f"validation RMS by more than 0.001 on {moved(r6)} at 1e-6, and on {moved(r8)} at "
        "1e-8 (docs/figures/fit-roundoff-1e-6.json and -1e-8.json: the rows before the "
        "stamps, at 1e-6 and with 1e-8 written into that tree, against those after).",
        width=92)


def exact_keys_text(name: str = "fit-trade-exact-keys.json") -> str:
    """docs/fit.md's figures of a sample fitted again (the exact cache keys; the exact steps),
    from the file compare_reports.py wrote from rows (validation RMS moves and fit times)."""
    import json
    import textwrap

    d = json.loads((ROOT / "docs" / "figures" / name).read_text(encoding="utf-8"))
    m, t = d["rms_moved"], d["fit_s"]
    return textwrap.fill(
        f"The validation RMS after moved by more than 0.001 (K or µm) on {m['over_0.001']} of "
        f"{m['runs']} runs, by more than 0.01 on {m['over_0.01']}, at most {m['largest']}, "
        f"in either direction. The fits took {t['after']['total']} s in all against "
        f"{t['before']['total']} s (median {t['before']['median']} → {t['after']['median']} s "
        "a run, one process a fit, two at a time).", width=92)


def test_the_exact_keys_figures_are_their_file():
    from tests.docs_blocks import assert_block

    assert_block("docs/fit.md", "exact-keys-figures", exact_keys_text())
    assert_block("docs/fit.md", "refit-exact-steps-figures",
                 exact_keys_text("fit-trade-refit-exact-steps.json"))
    assert_block("docs/fit.md", "one-objective-figures",
                 exact_keys_text("fit-trade-one-objective-all.json"))


def test_the_optimizer_tolerance_figures_are_their_files():
    from tests.docs_blocks import assert_block

    assert_block("docs/fit.md", "optimizer-tol-figures", optimizer_tol_text())


#: issue 32's targets: the summary's line, the bound and its direction
TARGETS = (("true effect named first (runs with an effect)", 95.0, ">="),
           ("unexplained, nothing named (runs outside the library)", 90.0, ">="),
           ("nothing named on clean runs", 95.0, ">="),
           ("a false second effect (after a right first)", 5.0, "<="),
           ("a wrong effect named (any run)", 2.0, "<="),
           ("validation RMS within the tolerances (named or adequate)", 100.0, ">="))


def _rate(summary: str, label: str) -> tuple[str, str, str, str, str]:
    """The summary line ``label``'s count, runs, rate [%] and 95 % interval, as printed."""
    m = re.search(rf"^  {re.escape(label)}\s+(\d+) of\s+(\d+)\s+([\d.]+) %\s+"
                  r"\[\s*([\d.]+),\s*([\d.]+)\]", summary, re.M)
    assert m, f"the summary has no line '{label}'"
    return m.groups()


def targets_table(summary: str, held_out: str) -> str:
    """docs/fit.md's table of issue 32's targets from the benchmark's summary files (the
    main set and the held-out one): each rate with its 95 % interval, and whether the rate
    itself meets the target."""
    lines = ["| target | issue 32 | measured (95 % interval) | met | held out (95 % interval) "
             "| met |", "|---|---|---|---|---|---|"]
    for label, bound, op in TARGETS:
        cells = []
        for text in (summary, held_out):
            k, n, p, lo, hi = _rate(text, label)
            met = float(p) >= bound if op == ">=" else float(p) <= bound
            cells.append(f"{k} of {n}, {p} % [{lo}, {hi}] | {'yes' if met else 'no'}")
        lines.append(f"| {label} | {'≥' if op == '>=' else '≤'} {bound:g} % | "
                     + " | ".join(cells) + " |")
    return "\n".join(lines)


def test_the_targets_table_is_the_benchmarks_files():
    from tests.docs_blocks import assert_block

    figures = ROOT / "docs" / "figures"
    assert_block("docs/fit.md", "targets", targets_table(
        (figures / "fit-families.txt").read_text(encoding="utf-8"),
        (figures / "fit-families-held-out.txt").read_text(encoding="utf-8")))


def readme_fit_rates(summary: str) -> str:
    """The README's sentence on fit's measured rates, from docs/figures/fit-families.txt."""
    runs = re.search(r"^runs: (.*)$", summary, re.M).group(1)
    total = sum(int(x) for x in re.findall(r"\w+ (\d+)", runs))
    wk, wn, wp, _, _ = _rate(summary, "a wrong effect named (any run)")
    tk, tn, tp, _, _ = _rate(summary, "true effect named first (runs with an effect)")
    ck, cn, _, _, _ = _rate(summary, "nothing named on clean runs")
    ok, on, op, _, _ = _rate(summary, "unexplained, nothing named (runs outside the library)")
    lk, ln, _, _, _ = _rate(summary, "'unexplained' where the cause acts (its event's window "
                            "meets the cause's)")
    assert int(wn) == total
    return (f"On {total} runs drawn from families and the peer's, it named a wrong cause on "
            f"{wk} ({wp} %), the true effect first on {tk} of {tn} ({tp} %), nothing on "
            f"{ck} of {cn} clean runs, and \"unexplained\" on {ok} of {on} runs outside its "
            f"library ({op} %). Where it located the cause as an event, the window it gave met "
            f"the span the cause acts over on {lk} of {ln}.")


def readme_mixed_rates(summary: str) -> str:
    """The README's sentence on runs with a library effect and a cause outside it, from
    docs/figures/fit-families-mixed.txt."""
    wk, wn, _, _, _ = _rate(summary, "a wrong effect named (any run)")
    fk, fn, _, _, _ = _rate(summary, "the library's effect named first, beside a cause outside it")
    uk, un, _, _, _ = _rate(summary, "something else said to remain, beside a cause outside the "
                                     "library")
    assert wn == fn == un
    return (f"On {fn} runs that hold a library effect and a cause outside it together, it named "
            f"a wrong cause on {wk}, the library's effect first on {fk}, and said that something "
            f"else remains on {uk}")


def readme_losslaw_rates(summary: str) -> str:
    """The README's sentence on runs with a loss law the spec lacks, from
    docs/figures/fit-families-losslaw.txt and the same runs' rows fitted without the laws
    (fit-families-losslaw-without-laws.json)."""
    import json

    wk, wn, _, _, _ = _rate(summary, "a wrong effect named (any run)")
    before = json.loads((ROOT / "docs" / "figures" / "fit-families-losslaw-without-laws.json")
                        .read_text(encoding="utf-8"))
    assert len(before) == int(wn)
    return (f"On {wn} runs from spindles whose motor's loss split moves with speed, a law no "
            f"spec states, it named a wrong cause on {wk} (on {sum(r['wrong'] for r in before)}"
            " before it weighed such laws as something else;")


@pytest.mark.parametrize("name, sentence", [("fit-families.txt", readme_fit_rates),
                                            ("fit-families-losslaw.txt", readme_losslaw_rates),
                                            ("fit-families-mixed.txt", readme_mixed_rates)])
def test_the_readme_quotes_the_measured_rates(name, sentence):
    summary = (ROOT / "docs" / "figures" / name).read_text(encoding="utf-8")
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert sentence(summary) in readme, sentence(summary)


def test_a_summary_of_saved_rows_names_the_call_that_made_them(tmp_path):
    """``bench_families.py --rows`` heads its summary with the fitting call the rows came
    from: a held-out set (other seeds, some families) must say so, or its rates read as the
    main set's."""
    import json
    import subprocess
    import sys

    rows = json.loads((ROOT / "docs" / "figures" / "fit-families.json").read_text("utf-8"))
    effect = [r for r in rows if r["family"] == "effect"][:2]
    for seed, r in zip((1001, 1002), effect, strict=True):
        r["run"] = f"effect-{seed}"
    saved, summary = tmp_path / "rows.json", tmp_path / "held-out.txt"
    saved.write_text(json.dumps(effect), encoding="utf-8")
    done = subprocess.run([sys.executable, "benchmarks/bench_families.py", "--rows", str(saved),
                           "--summary", str(summary)], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr
    head = summary.read_text(encoding="utf-8").splitlines()[0]
    assert "--runs-per-family 2 --first-seed 1001 --families effect --json ROWS" in head, head
    for r in effect:  # rows of another spindle, fitted with its own spec
        r.update(geometry=[0.75, 1.25], fit_own_spec=True)
    saved.write_text(json.dumps(effect), encoding="utf-8")
    done = subprocess.run([sys.executable, "benchmarks/bench_families.py", "--rows", str(saved),
                           "--summary", str(summary)], cwd=ROOT, capture_output=True, text=True)
    head = summary.read_text(encoding="utf-8").splitlines()[0]
    assert "--families effect --geometry 0.75 1.25 --fit-own-spec --json ROWS" in head, head


def scan_null_table(doc: dict) -> str:
    """docs/fit.md's table of the verdict's scan against its null, from
    docs/figures/scan-null.json (benchmarks/scan_null_figures.py)."""
    return "\n".join([
        "| | value |", "|---|---|",
        f"| hypotheses the scan tries | {doc['hypotheses']:,} |",
        f"| Bonferroni bound at alpha = {doc['alpha']:g} | {doc['bonferroni']:.1f} |",
        f"| Monte Carlo critical value, seed 0 ({doc['draws']} draws) | "
        f"{doc['critical_value_seed_0']:.1f} |",
        f"| ... over {doc['seeds']} seeds | {doc['critical_value_min']:.1f} to "
        f"{doc['critical_value_max']:.1f} (sd {100 * doc['critical_value_sd_rel']:.1f} %) |",
        f"| time of one critical value | {doc['seconds_median']:.1f} s |"])


def test_the_scan_null_table_is_its_figures_file():
    import json

    from tests.docs_blocks import assert_block

    doc = json.loads((ROOT / "docs" / "figures" / "scan-null.json").read_text("utf-8"))
    assert doc["critical_value_max"] < doc["bonferroni"]  # the reason it replaced Bonferroni
    assert_block("docs/fit.md", "scan-null", scan_null_table(doc))


def test_why_a_true_effect_was_missed_is_read_off_its_first_round_criteria():
    """benchmarks/verdicts.missed_by on hand-written reports: the criteria the true effect
    failed in round 1 (a lag: its best channel), "qualified, another joined first" where it
    qualified, None where it was named first or the run has no library effect."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        from verdicts import missed_by
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))

    def judged(label, rnd, gain, qualifies=False, **failed):
        crit = {"significant": True, "material": True, "signature": None, "predicts": True,
                "beats_something_else": True, "distinct": True, "changes_prediction": True}
        crit.update({k: False for k in failed})
        return {"candidate": label, "round": rnd, "gain": gain, "criteria": crit,
                "qualifies": qualifies}

    def report(named, candidates, unexplained=False):
        return {"effects": [{"name": n} for n in named], "candidates": candidates,
                "verdict": {"unexplained": unexplained}}

    lag = [judged("sensor_lag(T1)", 1, 2.0, significant=False, material=False),
           judged("sensor_lag(P1)", 1, 9.0, signature=True),
           judged("sensor_lag(P1)", 2, 30.0, distinct=False)]
    assert missed_by(report([], lag), "sensor_lag") == ["signature"]
    # the plausible base stands in for the prediction's change (select.model_changes)
    rescued = [judged("coolant_dynamics", 1, 30.0, predicts=False, changes_prediction=False)]
    rescued[0]["criteria"]["restores_plausible_base"] = True
    assert missed_by(report([], rescued), "coolant_dynamics") == ["predicts"]
    rescued[0]["criteria"]["restores_plausible_base"] = False
    assert missed_by(report([], rescued), "coolant_dynamics") == ["changes_prediction",
                                                                  "predicts"]
    mount = [judged("mount_conduction", 1, 30.0, changes_prediction=False),
             judged("bearing_preload", 1, 40.0, True)]
    assert missed_by(report([], mount), "mount_conduction") == ["changes_prediction"]
    assert missed_by(report(["bearing_preload"], mount), ["mount_conduction", "windage_loss"]) \
        == ["changes_prediction"]
    preload_second = [judged("bearing_preload", 1, 40.0, True)]
    assert missed_by(report(["windage_loss"], preload_second), "bearing_preload") == [
        "qualified, another joined first"]
    assert missed_by(report([], []), "windage_loss") == ["not a candidate"]
    assert missed_by(report(["mount_conduction"], mount), "mount_conduction") is None
    assert missed_by(report([], mount, unexplained=True), "unexplained") is None
    assert missed_by(report([], mount), None) is None


def test_each_criterions_margin_counts_the_candidates_only_it_decides(tmp_path):
    """benchmarks/criteria_margins.margins on hand-written reports: a criterion counts the
    candidates of its round that pass every other criterion (significant and material
    first), true or false by the run's truth, with its figure; a candidate failing two
    criteria counts for neither, and a signature-route candidate for none."""
    import json
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        from criteria_margins import margins, table
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))

    def judged(label, rnd=1, signature=None, **failed):
        crit = {"significant": True, "material": True, "signature": signature,
                "predicts": True, "beats_something_else": True, "distinct": True,
                "changes_prediction": True}
        crit.update({k: False for k in failed})
        return {"candidate": label, "round": rnd, "gain": 10.0, "p_value": 1e-4,
                "peak_tolerances": 2.0, "criteria": crit, "penalised_gain": 8.0,
                "competitor_penalised_gain": 2.0, "rival_penalised_gain": 1.0,
                "net_change_peak": 0.3, "cv_before": 1.0, "cv_after": 0.4}

    crit = [{"name": "alpha", "value": 0.01}]
    reports = {"a": [judged("mount_conduction", changes_prediction=True),  # only it fails
                     judged("bearing_preload", changes_prediction=True, distinct=True),
                     judged("windage_loss", signature=True)],
               "b": [judged("bearing_preload", changes_prediction=True),
                     judged("mount_conduction", rnd=2, changes_prediction=True)]}
    for run, cands in reports.items():
        (tmp_path / f"{run}.json").write_text(json.dumps({"candidates": cands,
                                                          "criteria": crit}), "utf-8")
    truth = {"a": "mount_conduction", "b": "windage_loss"}.get
    rows = {r["criterion"]: r for r in table(margins([tmp_path], truth, 1))}
    cp = rows["changes_prediction"]
    assert (cp["true"], cp["true_pass"], cp["false"], cp["false_pass"]) == (1, 0, 1, 0)
    assert cp["true_failing"] == ["a:mount_conduction"]
    assert cp["true_min"] == pytest.approx(0.3)
    assert rows["predicts"]["true"] == 0 and rows["distinct"]["false"] == 0
    # the share of the cross-validated excess removed: 1 - 0.4 / 1.0
    (tmp_path / "a.json").write_text(json.dumps({"candidates": [judged("mount_conduction")],
                                                 "criteria": crit}), "utf-8")
    rows = {r["criterion"]: r for r in table(margins([tmp_path], truth, 1))}
    assert rows["predicts"]["true_min"] == pytest.approx(0.6)
    assert table(margins([tmp_path], truth, 2))[-1]["false"] == 1
    # a candidate whose prediction does not move but whose base it spares passes the open
    # loop's last criterion (select.model_changes), so it counts for the others
    spared = judged("mount_conduction", changes_prediction=True, predicts=True)
    spared["criteria"]["restores_plausible_base"] = True
    (tmp_path / "a.json").write_text(json.dumps({"candidates": [spared], "criteria": crit}),
                                     "utf-8")
    rows = {r["criterion"]: r for r in table(margins([tmp_path], truth, 1))}
    assert rows["predicts"]["true_failing"] == ["a:mount_conduction"]
    assert (rows["changes_prediction"]["true"], rows["changes_prediction"]["true_pass"]) == (0, 0)


def margins_table(doc: dict) -> str:
    """docs/fit.md's table of what each open-loop criterion decides, from
    docs/figures/criteria-margins.json (benchmarks/criteria_margins.py)."""
    def num(v) -> str:
        return "—" if v is None else f"{v:.2f}"

    lines = ["| round | criterion | true effects it passes | false candidates it passes | "
             "true: least, median figure | false: median, largest figure |",
             "|---|---|---|---|---|---|"]
    for rnd, rows in doc["rounds"].items():
        for r in rows:
            lines.append(f"| {rnd} | `{r['criterion']}` | {r['true_pass']} of {r['true']} | "
                         f"{r['false_pass']} of {r['false']} | {num(r['true_min'])}, "
                         f"{num(r['true_median'])} | {num(r['false_median'])}, "
                         f"{num(r['false_max'])} |")
    return "\n".join(lines)


def test_the_criteria_margins_table_is_its_figures_file():
    import json

    from tests.docs_blocks import assert_block

    doc = json.loads((ROOT / "docs" / "figures" / "criteria-margins.json").read_text("utf-8"))
    assert_block("docs/fit.md", "criteria-margins", margins_table(doc))


def _sub_rate(summary: str, label: str, family: str) -> tuple[int, int]:
    """The count and runs of ``family``'s line under the summary line ``label``."""
    block = summary[summary.index(f"  {label}"):]
    m = re.search(rf"^    \.\.\. {family}\s+(\d+) of\s+(\d+)", block, re.M)
    assert m, f"no line '... {family}' under '{label}'"
    return int(m.group(1)), int(m.group(2))


def test_the_joint_verdicts_false_alarms_in_prose_are_its_summaries():
    """docs/fit.md's paragraph on the joint verdict (measured, not adopted) quotes the false
    alarms of its summaries against the verdict adopted then (the summaries before every gap's
    inputs were unknown), main set and held out."""
    fig = ROOT / "docs" / "figures"
    before, after = ((fig / f).read_text(encoding="utf-8") for f in
                     ("fit-families-before-every-gap.txt", "fit-families-joint-verdict.txt"))
    held_before, held_after = ((fig / f).read_text(encoding="utf-8") for f in
                               ("fit-families-held-out-before-every-gap.txt",
                                "fit-families-joint-verdict-held-out.txt"))
    text = " ".join((ROOT / "docs" / "fit.md").read_text(encoding="utf-8").split())
    alarm = "'unexplained' on clean runs (a false alarm)"
    beside = "'something else remains' beside a right verdict (a false alarm)"
    c0, c1 = _sub_rate(before, alarm, "clean"), _sub_rate(after, alarm, "clean")
    h0, h1 = _sub_rate(held_before, alarm, "clean"), _sub_rate(held_after, alarm, "clean")
    p0, p1 = _sub_rate(before, alarm, "peers"), _sub_rate(after, alarm, "peers")
    b0, b1 = _rate(before, beside)[:2], _rate(after, beside)[:2]
    q0, q1 = _sub_rate(before, beside, "peers"), _sub_rate(after, beside, "peers")
    expected = (f"\"unexplained\" on clean runs went from {c0[0]} to {c1[0]} of {c1[1]}, from "
                f"{h0[0]} to {h1[0]} of {h1[1]} held out and from {p0[0]} to {p1[0]} of the "
                f"peer's {p1[1]} controls, and \"something else remains\" beside a right name "
                f"from {b0[0]} to {b1[0]} of {b1[1]} (the peer's runs: {q0[0]} to {q1[0]} of "
                f"{q1[1]};")
    assert expected in text, expected


#: docs/fit.md's runs from another spindle: (file stem, the spindle, the spec fitted with)
GEOMETRY_SETS = (
    ("fit-geometry-0.9-0.85-shipped-spec", "radii × 0.9, lengths × 0.85", "spl2782's"),
    ("fit-geometry-0.75-1.25-shipped-spec", "radii × 0.75, lengths × 1.25", "spl2782's"),
    ("fit-geometry-0.75-1.25-own-spec", "radii × 0.75, lengths × 1.25", "its own"),
)
GEOMETRY_RATES = ("true effect named first (runs with an effect)",
                  "nothing named on clean runs", "'unexplained' on clean runs (a false alarm)",
                  "unexplained, nothing named (runs outside the library)",
                  "a wrong effect named (any run)")


def geometry_table() -> str:
    """docs/fit.md's table of the runs drawn from another spindle
    (bench_families --geometry), from their summary files."""
    lines = ["| spindle | spec | " + " | ".join(GEOMETRY_RATES) + " |",
             "|---|---|" + "---|" * len(GEOMETRY_RATES)]
    for stem, spindle, spec in GEOMETRY_SETS:
        text = (ROOT / "docs" / "figures" / f"{stem}.txt").read_text(encoding="utf-8")
        cells = [f"{k} of {n}" for k, n, *_ in (_rate(text, label) for label in GEOMETRY_RATES)]
        lines.append(f"| {spindle} | {spec} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def test_the_other_spindles_table_is_its_files():
    from tests.docs_blocks import assert_block

    assert_block("docs/fit.md", "geometry", geometry_table())


#: docs/fit.md's spindles of other designs, drawn and fitted with their own specs
#: (bench_families --spec tests/data/own-specs/NAME.toml): (file stem, the spindle)
DESIGN_SETS = (
    ("fit-spec-gs24", "gs24, 15 kW / 24 000 rpm grinder"),
    ("fit-spec-bs25", "bs25, 60 kW / 2500 rpm boring spindle"),
    ("fit-spec-ms12", "ms12, 11 kW / 12 000 rpm, air-cooled"),
)


def designs_table() -> str:
    """docs/fit.md's table of the runs drawn from spindles of other designs, from their
    summary files: the runs fitted per family and the rates of GEOMETRY_RATES ("-" where a
    summary has no such runs)."""
    lines = ["| spindle | runs fitted | " + " | ".join(GEOMETRY_RATES) + " |",
             "|---|---|" + "---|" * len(GEOMETRY_RATES)]
    for stem, spindle in DESIGN_SETS:
        text = (ROOT / "docs" / "figures" / f"{stem}.txt").read_text(encoding="utf-8")
        runs = re.search(r"^runs: (.*)$", text, re.M).group(1)
        cells = []
        for label in GEOMETRY_RATES:
            has = re.search(rf"^  {re.escape(label)}\s+\d+ of", text, re.M)
            cells.append("{} of {}".format(*_rate(text, label)[:2]) if has else "-")
        lines.append(f"| {spindle} | {runs} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def readme_designs_rates() -> str:
    """The README's sentence on runs from spindles of other designs, from their summaries
    (DESIGN_SETS)."""
    rates = [_rate((ROOT / "docs" / "figures" / f"{stem}.txt").read_text(encoding="utf-8"),
                   "a wrong effect named (any run)") for stem, _ in DESIGN_SETS]
    runs, wrong = sum(int(r[1]) for r in rates), sum(int(r[0]) for r in rates)
    return (f"On {runs} runs drawn from {len(rates)} spindles of other designs, each fitted "
            f"with its own spec, it named a wrong cause on {wrong}:")


def test_the_readme_quotes_the_other_designs_rates():
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert readme_designs_rates() in readme, readme_designs_rates()


def test_the_other_designs_table_is_its_files():
    from tests.docs_blocks import assert_block

    assert_block("docs/fit.md", "designs", designs_table())


def test_the_event_probes_prose_is_its_figures_file():
    """docs/fit.md's sentence on the probe of judging the library beside the competitor's
    event (docs/fit-history.md "2026-12-02 (25)") from its figures file."""
    import json

    doc = json.loads((ROOT / "docs" / "figures" / "fit-probe-condition-on-event.json")
                     .read_text(encoding="utf-8"))
    probed = [r for r in doc["runs"] if r["probed"]]
    gained = [r for r in probed if r["right_name_gained"]]
    words = {1: "one", 2: "two", 3: "three", 4: "four", 5: "five"}
    assert {r["family"] for r in gained} == {"mixed"}
    assert not any(r["wrong_name_beside"] for r in probed)
    assert not any(r["named_beside_event"] for r in probed if r["family"] != "mixed")
    text = " ".join(DOC.split())
    assert (f"It named the right effect on {words[len(gained)]} of the mixed runs it could act "
            "on and nothing elsewhere") in text


def test_the_readmes_clause_on_mixed_runs_holds():
    """The README says that beside an event the fit 'more often names nothing than the
    effect': true of the mixed family's rows (docs/figures/fit-families-mixed.json)."""
    import json

    rows = json.loads((ROOT / "docs" / "figures" / "fit-families-mixed.json")
                      .read_text(encoding="utf-8"))
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert "it more often names nothing than the effect" in readme
    assert sum(not r["named"] for r in rows) > sum(bool(r["first"]) for r in rows)


def test_the_law_rivals_trade_reads_as_measured():
    """docs/fit.md "A motor whose loss split moves with speed": its prose on the trade, against
    docs/figures/fit-trade-law-rivals.txt (per family: the runs fitted without and with the
    laws, and every run whose verdict moved)."""
    text = (ROOT / "docs" / "figures" / "fit-trade-law-rivals.txt").read_text("utf-8")
    moved = re.findall(r"^  (\S+) .* right (True|False) -> (True|False)$", text, re.M)
    elsewhere = [run for run, _, _ in moved if not run.startswith("losslaw-")]
    assert elsewhere == ["two-6"]
    wrong = re.search(r"^losslaw +(\d+) runs .* wrong (\d+) -> (\d+) ", text, re.M).groups()
    runs = {f: int(n) for f, n in re.findall(r"^(\w+) +(\d+) runs", text, re.M) if f != "all"}
    prose = " ".join((ROOT / "docs" / "fit.md").read_text(encoding="utf-8").split())
    assert (f"the wrong names fall from {wrong[1]} to {wrong[2]} of {wrong[0]}") in prose
    held = (ROOT / "docs" / "figures" / "fit-trade-law-rivals-held-out.txt").read_text("utf-8")
    h = re.search(r"^losslaw +(\d+) runs .* wrong (\d+) -> (\d+) ", held, re.M).groups()
    assert f"the wrong names fall from {h[1]} to {h[2]} of {h[0]}." in prose
    others = runs["effect"] + runs["clean"] + runs["outside"] + runs["peers"]
    assert (f"No verdict moved on the main set's {others} other runs, the peer's "
            f"{runs['peers']} among them, nor on the {runs['mixed']} mixed runs.") in prose


def test_the_probes_beside_the_law_rivals_read_as_measured():
    """docs/fit.md's two mends not adopted, against their figures files: windage only on its
    signature (wrong names on the runs that hold a windage loss) and a rotor share that moves
    with speed in the base (verdicts moved, of the runs fitted)."""
    import json

    figures = ROOT / "docs" / "figures"
    told = json.loads((figures / "fit-probe-told-apart.json").read_text("utf-8"))["rows"]
    share = json.loads((figures / "fit-probe-rotor-share-exponent.json").read_text("utf-8"))
    moved = [r for r in share["rows"] if (r["named_before"], r["verdict_before"])
             != (r["named_after"], r["verdict_after"])]
    prose = " ".join((ROOT / "docs" / "fit.md").read_text(encoding="utf-8").split())
    assert (f"on {len(told)} runs that hold a windage loss, a preload or a lag of P1 took up "
            f"its heat on {sum(r['wrong_after'] for r in told)}") in prose
    assert f"on {len(moved)} of {len(share['rows'])} runs" in prose
    assert all(r["truth"] in ("windage_loss", "coolant_dynamics") for r in moved)


def test_where_an_unexplained_verdict_is_located_reads_as_measured():
    """docs/fit.md "Against the issue's figures": the share of outside runs whose located
    event meets the cause's span is the summary's line (benchmarks/verdicts.py ``located``)."""
    summary = (ROOT / "docs" / "figures" / "fit-families.txt").read_text("utf-8")
    k, n, *_ = _rate(summary, "'unexplained' where the cause acts (its event's window meets "
                     "the cause's)")
    prose = " ".join((ROOT / "docs" / "fit.md").read_text(encoding="utf-8").split())
    assert f"over which the cause acts (compare.synth.outside's `acts_s`) on {k} of {n};" in prose
    import json

    rows = json.loads((ROOT / "docs" / "figures" / "fit-families.json").read_text("utf-8"))
    missed = [r["run"] for r in rows if r.get("located") is False]
    assert missed == ["outside-19", "outside-49"]
    assert "the two it misses are outside-19," in prose and "and outside-49," in prose
    mixed = (ROOT / "docs" / "figures" / "fit-families-mixed.txt").read_text("utf-8")
    k, n, *_ = _rate(mixed, "'unexplained' where the cause acts (its event's window meets "
                     "the cause's)")
    assert f"the window meets the cause's span on {k} of {n}." in prose


def test_the_held_out_refit_reads_as_measured():
    """docs/fit.md "On held-out runs": the verdict that moved, the validation RMS and the
    located events, against docs/figures/fit-held-out-refit.txt and the held-out summary (the
    causes of the runs that end "base adequate" are read where the synthetic runs are cached,
    benchmarks/.families-cache, which a fresh checkout lacks)."""
    import json

    refit = (ROOT / "docs" / "figures" / "fit-held-out-refit.txt").read_text("utf-8")
    moved = re.findall(r"^  (\S+) +\[.*\] -> \[.*\]  right", refit, re.M)
    rms = re.search(r"moved on (\d+) of 100 runs by more than 0.001 .* at most ([\d.]+) ",
                    refit).groups()
    summary = (ROOT / "docs" / "figures" / "fit-families-held-out.txt").read_text("utf-8")
    k, n, *_ = _rate(summary, "'unexplained' where the cause acts (its event's window meets "
                     "the cause's)")
    prose = " ".join((ROOT / "docs" / "fit.md").read_text(encoding="utf-8").split())
    assert moved == ["two-1023"] and "one verdict moved" in prose and "two-1023, a windage" in prose
    assert f"moved on {rms[0]} runs, by at most {float(rms[1]):.2f}" in prose
    assert f"made \"unexplained\", the event's window meets the span its cause acts over on {k};" \
        in prose and f"Of the {n} outside runs" in prose
    rows = json.loads((ROOT / "docs" / "figures" / "fit-families-held-out.json").read_text())
    adequate = [r for r in rows if r["family"] == "outside" and r["verdict"] == "base adequate"]
    drifts = {json.loads((ROOT / "benchmarks" / ".families-cache" / f"{r['run']}.truth.json")
                         .read_text())["effect"] for r in adequate
              if (ROOT / "benchmarks" / ".families-cache" / f"{r['run']}.truth.json").exists()}
    assert len(adequate) == 3 and drifts <= {"electronics_drift"}


#: the rates docs/fit.md's table of the once-a-minute logger compares
CADENCE_RATES = ("true effect named first (runs with an effect)",
                 "'unexplained' on clean runs (a false alarm)",
                 "unexplained, nothing named (runs outside the library)",
                 "a wrong effect named (any run)",
                 "validation RMS within the tolerances (named or adequate)",
                 "the verdict right as a whole")


def _cadence_rows(minute_file: str, logged_file: str) -> tuple[list[dict], list[dict]]:
    """The once-a-minute rows of docs/figures/``minute_file`` and the committed rows of the
    same runs as logged (``logged_file``; a run logged on change is labelled ``-onchange``)."""
    import json

    fig = ROOT / "docs" / "figures"
    minute = json.loads((fig / minute_file).read_text(encoding="utf-8"))
    logged = {r["run"].removesuffix("-onchange"): r
              for r in json.loads((fig / logged_file).read_text(encoding="utf-8"))}
    return minute, [logged[r["run"]] for r in minute]


def cadence_held_out_text() -> str:
    """docs/fit.md's sentence on the held-out runs fitted once a minute
    (fit-families-every-60s-held-out.json) against their committed rows
    (fit-families-held-out.json)."""
    minute, same = _cadence_rows("fit-families-every-60s-held-out.json",
                                 "fit-families-held-out.json")

    def count(rows, hit, of=lambda r: True):
        pool = [r for r in rows if of(r)]
        return f"{sum(bool(hit(r)) for r in pool)} of {len(pool)}"

    clean = lambda r: r["family"] == "clean"  # noqa: E731
    effect = lambda r: r["family"] == "effect"  # noqa: E731
    return (f"On {len(minute)} held-out runs (clean and effect, seeds 1001-1025) once a minute: "
            f"\"unexplained\" on {count(minute, lambda r: r['unexplained'], clean)} clean runs "
            f"(as logged {count(same, lambda r: r['unexplained'], clean)}), the true effect first "
            f"on {count(minute, lambda r: r['first'], effect)} (as logged "
            f"{count(same, lambda r: r['first'], effect)}), a wrong name on "
            f"{count(minute, lambda r: r['wrong'])} (as logged {count(same, lambda r: r['wrong'])}).")


def cadence_table() -> str:
    """docs/fit.md's table of the drawn runs fitted as logged and as a logger scanning once a
    minute records them (bench_families --every-s 60): the rates of CADENCE_RATES of the
    committed main rows of the same runs (docs/figures/fit-families.json) and of the
    once-a-minute rows (fit-families-every-60s.json), each by bench_families' own summary."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        from bench_families import summary
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    minute, same = _cadence_rows("fit-families-every-60s.json", "fit-families.json")
    texts = ["\n".join(summary(same)), "\n".join(summary(minute))]
    lines = ["| rate (the same 100 drawn runs) | as logged | once a minute |", "|---|---|---|"]
    for label in CADENCE_RATES:
        cells = ["{} of {}, {} % [{}, {}]".format(*_rate(t, label)) for t in texts]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def test_the_once_a_minute_table_is_its_files():
    from tests.docs_blocks import assert_block

    assert_block("docs/fit.md", "every-60s", cadence_table())
    assert_block("docs/fit.md", "every-60s-held-out", cadence_held_out_text())


def readme_cadence_rates() -> str:
    """The README's sentence on a bench logging once a minute, from cadence_table's files."""
    minute, same = _cadence_rows("fit-families-every-60s.json", "fit-families.json")
    clean = [r for r in minute if r["family"] == "clean"]
    return (f"Fitted as a bench logging once a minute records them, {len(minute)} of these "
            f"runs got {sum(r['right'] for r in minute)} right verdicts (as logged, "
            f"{sum(r['right'] for r in same)}), a wrong cause on "
            f"{sum(r['wrong'] for r in minute)} and \"unexplained\" on "
            f"{sum(r['unexplained'] for r in clean)} of {len(clean)} clean runs: on a loaded "
            "run the drive's losses change faster than such a log resolves")


def test_the_readme_quotes_the_once_a_minute_rates():
    readme = " ".join((ROOT / "README.md").read_text(encoding="utf-8").split())
    assert readme_cadence_rates() in readme, readme_cadence_rates()


def start_elsewhere_text() -> str:
    """docs/fit.md's sentence on the prehistory that ran elsewhere, per family, from its two
    row files (fit-start-elsewhere-before.json at the commit before, fit-start-elsewhere.json):
    right verdicts per family before -> now, and the wrong names now by effect."""
    import json
    from collections import Counter

    def load(name: str) -> dict:
        rows = json.loads((ROOT / "docs" / "figures" / name).read_text(encoding="utf-8"))
        return {r["run"]: r for r in rows if r["arm"] == "read"}

    now, then = load("fit-start-elsewhere.json"), load("fit-start-elsewhere-before.json")
    runs = [k for k in now if k in then]
    fams = list(dict.fromkeys(now[k]["family"] for k in runs))
    per = ", ".join(f"{f} {sum(then[k]['right'] for k in runs if then[k]['family'] == f)} -> "
                    f"{sum(now[k]['right'] for k in runs if now[k]['family'] == f)} of "
                    f"{sum(now[k]['family'] == f for k in runs)}" for f in fams)

    def wrong(rows: dict) -> str:
        count = Counter()
        for k in runs:
            truth = rows[k]["truth"] if isinstance(rows[k]["truth"], list) else [rows[k]["truth"]]
            count.update(n.split("(")[0] for n in rows[k]["named"] if n.split("(")[0] not in truth)
        return ", ".join(f"{n} {c}" for n, c in count.most_common())

    from scipy.stats import binomtest

    lost = sum(bool(then[k]["wrong"]) and not now[k]["wrong"] for k in runs)
    gained = sum(bool(now[k]["wrong"]) and not then[k]["wrong"] for k in runs)
    p = binomtest(min(lost, gained), lost + gained).pvalue
    return (f"Right verdicts per family, before -> now: {per}. The wrong names before: "
            f"{wrong(then)}; now: {wrong(now)}. A wrong name gone on {lost} runs, new on "
            f"{gained} (McNemar's exact test, p = {p:.2f}).")


def test_the_start_elsewhere_sentence_is_its_files():
    from tests.docs_blocks import assert_block

    assert_block("docs/fit.md", "start-elsewhere-trade", start_elsewhere_text())
