"""The accuracy harness and the verification study (compare/verify/accuracy.py, compare/verify/study.py,
spindle-verify study) on fin-shaft, where eq. 14 is exact up to its Biot number."""

import json
import math

import numpy as np
import pytest

from compare.cli import main
from compare.verify.accuracy import AccuracyResult, Entry
from compare.verify.study import run_study
from spindle.spec_reader import load_spec


@pytest.fixture(scope="module")
def study():
    return run_study(load_spec("fin-shaft"), levels=(0, 1, 2), nodes=(3, 5, 11, 21),
                     dt_s=600.0)


def test_steady_errors_fall_with_nodes_and_eq14_is_close(study):
    t = study.steady.table()
    worst = dict(zip(t["model"], t["shaft_max_K"], strict=True))
    # lumped fin: second order in the node spacing (tests/test_lumped_fin.py), so the error
    # against the FEM falls until it meets the lumped model's own floor
    assert worst["lumped 3"] > worst["lumped 5"] > worst["lumped 11"] > worst["lumped 21"]
    # eq. 14 assumes an isothermal cross-section: within 1 % of the rise (Bi = 5.9e-3,
    # tests/test_verification_fin.py), i.e. below 1.4 K on a 137 K rise
    assert worst["eq. 14"] < 1.4
    # FEM levels against the Richardson extrapolation of themselves: far below 1 K
    assert worst["FEM level 2"] < 1e-3
    assert study.ground_truth_level == 2
    assert set(study.steady.slopes()) == {"lumped", "fem"}
    assert study.steady.slopes()["lumped"] < -1.5  # order 2 in N


def test_transient_against_the_ground_truth_level(study):
    acc = study.transient
    assert acc.transient and acc.case_name == "warm-up 8 h"
    t = acc.table()
    assert "shaft_rms_K" in t and all(not math.isnan(v) for v in t["shaft_rms_K"])
    rows = dict(zip(t["model"], t["shaft_max_K"], strict=True))
    assert rows["lumped 21"] < rows["lumped 3"]


def test_errors_and_verdicts_by_hand():
    spec = load_spec("fin-shaft")
    names = [s.name for s in spec.temperature_sensors()]
    ref = Entry("ref", "fem", 1, 0.0, dict.fromkeys(names, 300.0))
    off = Entry("off", "lumped", 2, 0.0, {n: 300.0 + (0.5 if i == 3 else 0.0)
                                          for i, n in enumerate(names)})
    acc = AccuracyResult(spec, "c", False, ref, "ref", [off])
    row = acc.errors(off)
    assert row["shaft_max_K"] == pytest.approx(0.5)
    assert row["shaft_rms_K"] == pytest.approx(0.5 / np.sqrt(11))
    assert acc.table()["meets_tolerances"] == [True]  # 0.5 K <= 1 K
    off.sensors[names[0]] = 301.5
    assert acc.table()["meets_tolerances"] == [False]
    assert "fails 1 K (1.50 K)" in acc.table()["verdict"][0]


def test_study_command_writes_the_report(tmp_path, capsys):
    out = tmp_path / "study"
    assert main(["study", "fin-shaft", "--levels", "0", "1", "2", "--nodes", "3", "11",
                 "--steady-only", "--quiet", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "ground truth = level 2" in text and "lumped 11 (paper11)" in text
    html = (out / "report.html").read_text()
    assert "data:image/png;base64," in html and "Grid convergence" in html
    summary = json.loads((out / "study.json").read_text())
    assert summary["ground_truth_level"] == 2 and summary["transient"] is None
    for name in ("convergence.csv", "accuracy_steady.md", "accuracy_steady_error.png",
                 "accuracy_steady_shaft_profile.png", "reference_3d.png"):
        assert (out / name).exists(), name


@pytest.mark.parametrize("args, words", [
    (["--levels", "0", "1"], "fewer than 3 levels"),
    (["--nodes", "1", "5"], "study: --nodes: 1 is too small"),  # the parser's message
    (["--levels", "0", "1", "9"], "study: --levels: 9 is too large"),
])
def test_study_bad_options_exit_2(tmp_path, capsys, args, words):
    assert main(["study", "fin-shaft", *args, "--out", str(tmp_path / "x")]) == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
