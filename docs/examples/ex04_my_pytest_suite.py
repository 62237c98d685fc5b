"""Guard a thermal model in your own pytest suite.

    python -m pytest docs/examples/ex04_my_pytest_suite.py
    python docs/examples/ex04_my_pytest_suite.py [OUT_DIR]   # the same, with a JUnit XML

The ``spindle_verify`` fixture comes with the package (a pytest plugin, registered when
spindle-verify is installed). ``assert_within`` solves the model and the FEM reference (level 2
by default) on the case and fails with the worst sensor and the error sizes when the model
leaves the tolerance; ``error`` returns the errors without asserting. Specs: a shipped name or
the path of your TOML. Models: ``"lumped:N"``, ``"lumped:paper11"`` or ``"fem:L"``; cases: a
shipped cycle name (``nominal`` is steady, ``spl-16h`` a transient) or None for the spec's own
load case. Copy the tests below into your suite and put your spec and tolerances in.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import pytest


def test_fine_fem_level_matches_the_reference(spindle_verify):
    # level 1 against the reference level 2 on the fin benchmark: a mesh-convergence guard
    spindle_verify.assert_within("fin-shaft", "fem:1", tol_temp_K=0.05, tol_growth_um=0.05)


def test_the_paper_5_node_model_misses_the_fin_by_kelvins(spindle_verify):
    # eq. 14's benchmark: 5 masses are kelvins off, 11 are closer (docs/lumped.md: 4.35 K and
    # 0.73 K against eq. 14; against the FEM reference about 4.4 K and 0.8 K)
    five = spindle_verify.error("fin-shaft", "lumped:paper5")
    eleven = spindle_verify.error("fin-shaft", "lumped:paper11")
    assert eleven.worst_temp_K < five.worst_temp_K


def test_the_11_node_model_keeps_its_known_error(spindle_verify):
    # a regression guard for a model that misses the paper's 1 K (README: 4.8 K and 2.7 µm at
    # the nominal point): hold it to what it reaches today, so that any change that makes it
    # worse fails
    spindle_verify.assert_within("spl2782", "lumped:paper11", case="nominal",
                                 tol_temp_K=5.0, tol_growth_um=3.0)


def test_what_a_failure_says(spindle_verify):
    # a model beyond its tolerance fails the test with the worst sensor and the error sizes;
    # here the paper's 5-node model on the fin at 1 K, caught to show the message
    with pytest.raises(pytest.fail.Exception, match=r"temperature error .* K > 1 K \(worst: "):
        spindle_verify.assert_within("fin-shaft", "lumped:paper5", tol_temp_K=1.0)


def main(out: Path) -> int:
    """Run this file's tests with pytest, writing a JUnit XML report to ``out``; returns
    pytest's exit code (0: every test passed)."""
    out.mkdir(parents=True, exist_ok=True)
    code = pytest.main(["-q", "-p", "no:cacheprovider", f"--junitxml={out / 'junit.xml'}",
                        __file__])
    print(f"pytest exit code {int(code)}; wrote {out / 'junit.xml'}")
    return int(code)


if __name__ == "__main__":
    sys.exit(main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp())))
