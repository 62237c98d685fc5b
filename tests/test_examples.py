"""The examples in docs/examples/ run, and say what the docs say they say (scikit-fem's habit:
examples that double as tests)."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "docs" / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_example_is_tested():
    tested = {"ex01_solve_spec", "ex02_lumped_vs_reference", "ex03_fit_bench_run",
              "ex04_my_pytest_suite"}
    assert {p.stem for p in EXAMPLES.glob("*.py")} == tested


def test_ex01_solve_spec(tmp_path):
    """The nominal point on level 1: the energy balance closes to round-off (the reference's
    own check, 1e-12 in docs/verification.md) and the outputs are written. T1 and P1 lie within
    a few per cent of level 2's 27 K rise and 11.3 µm (README), the grid error of level 1."""
    out = _load("ex01_solve_spec").main(tmp_path)
    assert out["relative_imbalance"] < 1e-10
    assert 40.0 < out["T1_C"] < 54.0 and 10.5 < out["P1_um"] < 12.0
    assert (tmp_path / "summary.json").exists() and (tmp_path / "sensors.csv").exists()


def test_ex02_lumped_vs_reference():
    """The README's finding, reproduced: the 11-node model misses the 1 K tolerance at the
    nominal point by several kelvin (4.8 K against the extrapolated reference; level 1 is
    within 0.1 K of it) and P1 by about 2.6 µm."""
    out = _load("ex02_lumped_vs_reference").main()
    assert 4.0 < out["worst_K"] < 5.5 and 2.0 < out["P1_um"] < 3.2


@pytest.mark.slow
def test_ex03_fit_bench_run(tmp_path):
    """A synthetic fixture_expansion run is fitted: the effect is named, the validation error
    is within the tolerances, and the report carries the base-adequacy verdict (slow: 45 s on
    2 cores, the full candidate library; tests/test_greybox.py::test_synth_then_fit_end_to_end
    covers the same path, synth then fit then the report, in the default run)."""
    doc = _load("ex03_fit_bench_run").main(None, tmp_path)
    assert [e["name"] for e in doc["effects"]] == ["fixture_expansion"]
    for c, e in doc["error_after"]["validation"].items():
        assert e["rmse"] <= (1.5 if c == "P1" else 1.0), c
    assert doc["base_adequacy"]["verdict"].startswith("The calibrated base model")
    assert (tmp_path / "report.json").exists() and (tmp_path / "report.html").exists()


def test_ex04_my_pytest_suite():
    """The plugin example is a pytest file of its own: both its tests pass when pytest runs it."""
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                        str(EXAMPLES / "ex04_my_pytest_suite.py")],
                       capture_output=True, text=True, cwd=EXAMPLES)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "2 passed" in r.stdout


@pytest.mark.parametrize("name", ["ex01_solve_spec", "ex02_lumped_vs_reference"])
def test_examples_run_as_scripts(name, tmp_path):
    """As a user runs them: ``python docs/examples/NAME.py``."""
    r = subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py"), str(tmp_path)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert "µm" in r.stdout
