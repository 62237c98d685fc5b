"""The benchmarks measure the checkout's code (benchmarks/figures.py): run as
``python benchmarks/x.py``, a script imports the installed package, not the folder beside it,
so a non-editable install of an older tree would be measured under the checkout's commit."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _figures(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import figures

    return figures


def test_this_environment_imports_the_checkout(monkeypatch):
    """Editable or not, the code the tests run is the checkout's (CI installs it with pip)."""
    assert _figures(monkeypatch).checkout_difference() is None


def test_a_tree_that_differs_from_the_imported_code_is_named(monkeypatch, tmp_path):
    """A copy of the checkout with one file changed: the file is named, as the imported copy
    no longer matches it."""
    figures = _figures(monkeypatch)
    for name in figures.PACKAGES:
        shutil.copytree(ROOT / name, tmp_path / name,
                        ignore=shutil.ignore_patterns("__pycache__"))
    changed = tmp_path / "compare" / "fit" / "linear.py"
    changed.write_text(changed.read_text(encoding="utf-8") + "\n# changed\n", encoding="utf-8")
    monkeypatch.setattr(figures, "ROOT", tmp_path)
    diff = figures.checkout_difference()
    assert diff is not None and diff.startswith("compare/fit/linear.py differs"), diff


def test_a_benchmark_refuses_other_code_with_status_2(monkeypatch, tmp_path):
    """The same from the command line: one message naming the file and the fix, status 2, no
    traceback (a copy of benchmarks/ beside a changed tree)."""
    shutil.copytree(ROOT / "benchmarks", tmp_path / "benchmarks",
                    ignore=shutil.ignore_patterns("__pycache__", ".families-cache"))
    for name in _figures(monkeypatch).PACKAGES:
        shutil.copytree(ROOT / name, tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    changed = tmp_path / "spindle" / "outputs.py"
    changed.write_text(changed.read_text(encoding="utf-8") + "\n# changed\n", encoding="utf-8")
    r = subprocess.run([sys.executable, str(tmp_path / "benchmarks" / "compare_reports.py"),
                        "a", "b"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "spindle/outputs.py differs" in r.stderr and "pip install -e" in r.stderr
    assert "Traceback" not in r.stderr


def _row(run: str, named: list, right: bool, rms_T1: float, fit_s: float) -> dict:
    return {"family": run.split("-")[0], "run": run, "named": named,
            "verdict": "named" if named else "base adequate", "unexplained": False,
            "right": right, "first": right, "wrong": False,
            "validation_rmse": {"T1": rms_T1, "P1": 0.2}, "fit_s": fit_s}


def test_compare_reports_compares_two_files_of_rows(monkeypatch, tmp_path):
    """Rows of bench_families --json, before and after: the counts per family, the run whose
    verdict changed, the runs whose validation RMS moved (by 0.005 and by 0.3 on T1: one above
    0.01) and the fit times; a folder against a file is refused with status 2."""
    import json

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import compare_reports

    before = [_row("two-1", ["windage_loss", "mount_conduction"], True, 0.1, 10.0),
              _row("two-2", ["fixture_expansion"], True, 0.2, 20.0),
              _row("clean-1", [], True, 0.1, 6.0)]
    after = [_row("two-1", ["windage_loss"], False, 0.4, 12.0),
             _row("two-2", ["fixture_expansion"], True, 0.205, 22.0),
             _row("clean-1", [], True, 0.1, 6.0)]
    paths = []
    for name, rows in (("before.json", before), ("after.json", after)):
        paths.append(tmp_path / name)
        paths[-1].write_text(json.dumps(rows), encoding="utf-8")
    out = tmp_path / "trade.json"
    compare_reports.main([str(paths[0]), str(paths[1]), "--json", str(out)])
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert doc["families"]["two"]["before"]["right"] == 2
    assert doc["families"]["two"]["after"]["right"] == 1
    assert doc["changed"] == [{"run": "two-1", "before": ["windage_loss", "mount_conduction"],
                               "after": ["windage_loss"], "right": [True, False]}]
    assert doc["rms_moved"] == {"runs": 3, "over_0.001": 2, "over_0.01": 1, "largest": 0.3,
                                "unit": "K; um for P1"}
    assert doc["fit_s"]["after"]["max"] == 22.0 and doc["fit_s"]["before"]["total"] == 36
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "compare_reports.py"),
                        str(tmp_path), str(paths[1])], capture_output=True, text=True)
    assert r.returncode == 2 and "compare two of a kind" in r.stderr, r.stderr


def test_the_logging_perturbations_leave_the_data_as_they_say(monkeypatch, tmp_path):
    """benchmarks/bench_perturb.py measures whether a verdict survives a change of logging,
    so each perturbation must change the logging alone, read back through the bench reader:
    ``reorder`` the same columns to the bit, ``clock`` every time shifted by one offset that
    is not a multiple of the 60 s grid, ``decimate`` rows at least 30 s apart holding each
    channel's last logged value, ``sparse`` half of each measured channel's values (a peer's
    run logged by exception)."""
    from spindle.bench import read_bench

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_perturb

    src = ROOT / "tests" / "data" / "peer-runs" / "bench-runs-2" / "dev2-04.csv"
    text = src.read_text(encoding="utf-8")
    runs = {}
    for p in ("none", *bench_perturb.PERTURBATIONS):
        path = tmp_path / f"{p}.csv"
        path.write_text(bench_perturb.perturbed_text(text, p, 7), encoding="utf-8", newline="")
        runs[p] = read_bench(path)
    base, cols = runs["none"], ("speed_rpm", "power_kW", "T1_C", "P1_um")
    for c in cols:
        np.testing.assert_array_equal(runs["reorder"].columns[c], base.columns[c])
    shift = runs["clock"].time_s - base.time_s
    np.testing.assert_allclose(shift, shift[0], rtol=0, atol=1e-3)  # written to 1 ms
    assert shift[0] > 0 and abs(shift[0] / 60.0 - round(shift[0] / 60.0)) > 1e-3
    dec = runs["decimate"]
    assert np.all(np.diff(dec.time_s) >= bench_perturb.DECIMATE_S - 1e-9)  # to round-off
    for c in cols:  # each kept row holds the channel's last value logged at or before it
        logged = np.isfinite(base.columns[c])
        t, y = base.time_s[logged], base.columns[c][logged]
        i = np.searchsorted(t, dec.time_s, side="right") - 1
        np.testing.assert_array_equal(dec.columns[c][i >= 0], y[i[i >= 0]])
    for c in ("T1_C", "P1_um"):
        n0 = np.isfinite(base.columns[c]).sum()
        assert np.isfinite(runs["sparse"].columns[c]).sum() == n0 - n0 // 2


def test_interval_coverage_counts_the_intervals_that_hold_the_truth(monkeypatch, tmp_path):
    """benchmarks/bench_interval_coverage.py on two made-up reports: an interval that holds
    the injected value, one that misses it, and a named effect that is not the injected one
    (not counted)."""
    import json

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_interval_coverage as cov

    reports, cache = tmp_path / "reports", tmp_path / "cache"
    reports.mkdir()
    cache.mkdir()
    for run, (lo, hi) in {"effect-1": (0.1, 0.2), "effect-2": (0.05, 0.09)}.items():
        (cache / f"{run}.truth.json").write_text(json.dumps(
            {"effect": "bearing_preload", "parameters": {"k_preload_1_K": 0.15}}))
        (reports / f"{run}.json").write_text(json.dumps({"effects": [
            {"name": "bearing_preload", "parameters": {"k_preload_1_K": 0.5 * (lo + hi)},
             "confidence_intervals": {"k_preload_1_K": [lo, hi]}},
            {"name": "mount_conduction", "parameters": {"G_mount_W_K": 3.0},
             "confidence_intervals": {"G_mount_W_K": [2.0, 4.0]}}]}))
    rows = cov.interval_rows(reports, cache)
    assert [(r["run"], r["holds"]) for r in rows] == [("effect-1", True), ("effect-2", False)]


def test_the_ambient_shifted_copy_moves_the_ambient_alone(monkeypatch, tmp_path):
    """bench_families --ambient-shift-K: of the peer's on-change file (comment lines, empty
    cells), the copy read back has T_env_C higher by the shift wherever it was logged, and every
    other column and every empty cell as read from the original, to the bit; the original is
    not touched."""
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_families

    from spindle.bench import read_bench

    run = ROOT / "tests" / "data" / "peer-runs" / "bench-runs-2" / "dev2-14.csv"
    before = run.read_bytes()
    copy = bench_families.shifted_ambient(run, 1e-5, tmp_path / "shifted")
    assert run.read_bytes() == before and copy.parent == tmp_path / "shifted"
    a, b = read_bench(run), read_bench(copy)
    np.testing.assert_array_equal(a.time_s, b.time_s)
    assert set(a.columns) == set(b.columns) and "T_env_C" in a.columns
    for name, col in a.columns.items():
        logged = ~np.isnan(col)
        np.testing.assert_array_equal(logged, ~np.isnan(b.columns[name]))
        want = col + 1e-5 if name == "T_env_C" else col
        np.testing.assert_allclose(b.columns[name][logged], want[logged], rtol=0, atol=1e-12)


def test_the_copy_sampled_every_minute_is_the_first_row_of_each_minute(monkeypatch, tmp_path):
    """bench_families --every-s 60: of the peer's 10 s file (which has gaps), the copy read
    back holds, for each minute, the original's first row at or after it (one row only where a
    gap spans minutes), every column as read from the original to the bit; the original is not
    touched."""
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_families

    from spindle.bench import read_bench

    run = ROOT / "tests" / "data" / "peer-runs" / "bench-runs" / "dev-01.csv"
    before = run.read_bytes()
    copy = bench_families.sampled_every(run, 60.0, tmp_path / "every")
    assert run.read_bytes() == before and copy.parent == tmp_path / "every"
    a, b = read_bench(run), read_bench(copy)
    minutes = np.arange(0.0, a.time_s[-1] + 1.0, 60.0)
    keep = np.unique(np.searchsorted(a.time_s, minutes, side="left"))
    keep = keep[keep < len(a.time_s)]
    assert len(keep) < len(a.time_s) / 5  # a sixth of a 10 s log, fewer over its gaps
    np.testing.assert_array_equal(b.time_s, a.time_s[keep])
    assert set(a.columns) == set(b.columns)
    for name, col in a.columns.items():
        np.testing.assert_array_equal(b.columns[name], col[keep])


def test_the_mixed_family_is_judged_by_its_library_effect_and_what_remains(monkeypatch):
    """bench_families' ``mixed`` runs carry one library effect and one cause outside the
    library (compare.synth.outside): right is that effect named alone *and* something else
    said to remain; a name that is not the library's effect is wrong; appending the family
    left the other families' draws as the committed rows (docs/figures/fit-families.json,
    written before it existed) record them."""
    import json

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_families
    from verdicts import judge_verdict

    from compare.fit.effects import LIBRARY
    from compare.synth.outside import OUTSIDE

    truth = ["fixture_expansion", "electronics_drift"]
    assert judge_verdict(truth, ["fixture_expansion"], True) == {
        "kind": "effect+outside", "right": True, "first": True, "false_second": False,
        "wrong": False}
    assert not judge_verdict(truth, ["fixture_expansion"], False)["right"]
    assert judge_verdict(truth, ["mount_conduction"], True)["wrong"]
    assert not judge_verdict(truth, [], True)["right"]
    # causes outside the library alone, however many: an outside run
    assert judge_verdict(["sensor_drift", "electronics_drift"], [], True)["kind"] == "outside"
    for seed in range(1, 51):
        (effect, cause), _ = bench_families.draw("mixed", seed)
        assert effect in LIBRARY and cause in OUTSIDE
    rows = json.loads((ROOT / "docs" / "figures" / "fit-families.json").read_text("utf-8"))
    drawn = [r for r in rows if r["family"] in ("effect", "two")]
    assert drawn
    for r in drawn:
        effects, _ = bench_families.draw(r["family"], int(r["run"].rsplit("-", 1)[1]))
        assert (effects if r["family"] == "two" else effects[0]) == r["truth"], r["run"]


def test_the_losslaw_family_is_a_control_drawn_beside_the_others(monkeypatch):
    """bench_families' ``losslaw`` runs carry no effect but a loss law the spec lacks
    (compare.synth.losslaw): judged as controls (right is nothing named, whatever the verdict
    says of the base), and appending the family left the mixed family's draws as its
    committed rows (docs/figures/fit-families-mixed.json, written before it) record them."""
    import json

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_families
    from verdicts import judge_verdict

    from compare.synth.losslaw import LOSS_LAWS

    for seed in range(1, 51):
        (law,), _ = bench_families.draw("losslaw", seed)
        assert law in LOSS_LAWS
    assert judge_verdict(None, [], True)["right"] and judge_verdict(None, [], False)["right"]
    assert judge_verdict(None, ["windage_loss"], False)["wrong"]
    rows = json.loads((ROOT / "docs" / "figures" / "fit-families-mixed.json")
                      .read_text("utf-8"))
    assert rows
    for r in rows:
        effects, _ = bench_families.draw("mixed", int(r["run"].rsplit("-", 1)[1]))
        assert effects == r["truth"], r["run"]


def test_an_unexplained_verdict_is_located_where_its_cause_acts(monkeypatch):
    """benchmarks/verdicts.py ``located``: the window of the event that made a run
    "unexplained" meets the span over which the truth's cause outside the library acts
    (compare.synth.outside's ``acts_s``); None where nothing was located (a verdict on the
    held-out misfit alone) or the cause acts over the whole run. A window cause's span is
    where its injection is not zero."""
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    from verdicts import located

    from compare.synth.outside import OUTSIDE, _window

    draft = {"start_h": 5.0, "duration_h": 2.0, "delta_K": 6.0}
    a, b = OUTSIDE["enclosure_draft"].acts_s(draft)
    t = np.arange(0.0, 16 * 3600.0, 60.0)
    on = _window(t, 5.0, 2.0) > 0
    assert a <= t[on][0] and t[on][-1] <= b and not on[(t < a) | (t > b)].any()

    def doc(t0_h, t1_h, basis="something else"):
        return {"something_else": {"basis": basis, "hypothesis": {
            "t0_s": t0_h * 3600.0, "t1_s": t1_h * 3600.0}}}

    truth = {"effect": "enclosure_draft", "parameters": draft}
    assert located(doc(5.5, 7.0), truth) is True
    assert located(doc(10.0, 12.0), truth) is False
    assert located(doc(5.5, 7.0, "held-out misfit"), truth) is None
    drift = {"effect": "electronics_drift", "parameters": {"amplitude_um": 1.0,
                                                            "period_h": 5.0, "phase": 0.0}}
    assert located(doc(5.5, 7.0), drift) is None
    # beside a library effect (the mixed family: parameters by effect); from its start on
    mixed = {"effect": ["fixture_expansion", "sensor_drift"],
             "parameters": {"fixture_expansion": {}, "sensor_drift": {
                 "channel": "T1", "start_h": 9.0, "rate_K_h": 0.5}}}
    assert located(doc(12.0, 16.0), mixed) is True
    assert located(doc(2.0, 8.5), mixed) is False


def test_the_rule_census_reads_which_rule_decided(monkeypatch, tmp_path):
    """benchmarks/rule_census.py on hand-made reports: a candidate stopped only by its material
    change, one qualified only by the plausible base, one a law of the speed stopped, and a run
    unexplained by its held-out misfit; a candidate that failed significance is no rule's, nor
    one its signature decided (vetoed, or named by it): switching an open-loop rule or the laws
    off would not change its verdict."""
    import json

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import rule_census

    base = {"significant": True, "material": True, "signature": None, "predicts": True,
            "beats_something_else": True, "distinct": True, "changes_prediction": True,
            "restores_plausible_base": False, "null_at_optimum": None,
            "final_model_adequate": None}

    def cand(**over):
        return {"candidate": "x", "criteria": {**base, **over}}

    reports = {
        "a": {"candidates": [cand(changes_prediction=False)]},
        "b": {"candidates": [cand(changes_prediction=False, restores_plausible_base=True)]},
        "c": {"candidates": [{**cand(beats_something_else=False), "law": {"label": "L"}}]},
        "d": {"candidates": [cand(significant=False, changes_prediction=False)],
              "something_else": {"basis": "held-out misfit"}},
        "e": {"candidates": [cand(signature=False, changes_prediction=False),
                             {**cand(signature=True, beats_something_else=False),
                              "law": {"label": "L"}}]},
    }
    for name, doc in reports.items():
        (tmp_path / f"{name}.json").write_text(json.dumps(doc), encoding="utf-8")
    n, runs = rule_census.census([tmp_path])
    assert n == 5
    assert runs == {"open_loop_material_change": ["a"], "plausible_base_route": ["b"],
                    "law_rivals": ["c"], "held_out_misfit_unexplained": ["d"]}


def test_bench_start_sets_its_rows_against_an_earlier_commits(monkeypatch, tmp_path):
    """bench_start --rows NOW --before THEN: the 'read' arm of each (the uniform arm and runs
    only one file holds left out), their rates, and the runs whose verdict changed."""
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import bench_start

    def row(run, named, right, arm="read", verdict="named"):
        return {"run": run, "arm": arm, "truth": None, "named": named, "verdict": verdict,
                "kind": "control", "right": right, "first": None, "wrong": bool(named),
                "rms_within_tolerance": True, "prehistory_s": 3600.0}

    then = [row("clean-1-cut2.00h", ["fixture_expansion"], False),
            row("clean-2-cut3.00h", [], True, verdict="base adequate"),
            row("clean-2-cut3.00h", ["fixture_expansion"], False, arm="uniform"),
            row("clean-9-cut1.00h", [], True, verdict="base adequate")]
    now = [row("clean-1-cut2.00h", [], True, verdict="base adequate"),
           row("clean-2-cut3.00h", [], True, verdict="base adequate")]
    text = "\n".join(bench_start.summary(now, then))
    assert text.startswith("runs: 2 cut runs")
    assert "wrong effect named (any run)                                 1 of   2" in text
    assert "wrong effect named (any run)                                 0 of   2" in text
    assert text.endswith("verdicts changed (1): run, truth: before -> now\n"
                         "  clean-1-cut2.00h, None: named fixture_expansion -> base adequate "
                         "(right)")
