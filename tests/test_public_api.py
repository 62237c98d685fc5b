"""The public API under one name, spindle_verify (issue 34): each function on the shipped
specs, names accepted where objects are, and assert_within as a plain function."""

from __future__ import annotations

import subprocess
import sys

import pytest

import spindle_verify as sv


def test_import_is_quick_and_lazy():
    """``import spindle_verify`` loads none of the models (they load when first used)."""
    code = "import sys, spindle_verify; print('reference.simulation' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "False"


def test_solve_takes_names_and_returns_results_in_si():
    steady = sv.solve("spl2782", "nominal", model="lumped:5")
    assert steady.speed_rpm == 4300.0 and steady.summary()["growth_um"]["P1"] > 0
    run = sv.solve("spl2782", "spl-16h", dt_s=600.0, model="lumped:paper5")
    assert run.times_s[-1] == 16 * 3600 and set(run.growth_m) >= {"P1"}
    fem = sv.solve("fin-shaft", model="fem:0")
    assert type(fem).__name__ == "SteadyResult" and fem.T.min() > 273.15
    with pytest.raises(ValueError, match="fem:L"):
        sv.solve("spl2782", model="rom:3")


def test_models_and_types_are_reachable():
    assert isinstance(sv.lumped_model("spl2782", nodes=7), sv.LumpedModel)
    assert isinstance(sv.reference_model("fin-shaft", level=0), sv.ReferenceModel)
    assert sv.__version__
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        sv.nothing  # noqa: B018


def test_assert_within_is_a_plain_function():
    """Within: the errors come back; beyond: AssertionError naming the worst sensor (the
    lumped 11-node model of spl2782 misses 1 K at the nominal point by kelvins: docs/lumped.md),
    outside pytest too."""
    v = sv.assert_within("fin-shaft", "lumped:paper11", tol_temp_K=1.0, reference_level=1)
    assert 0.1 < v.worst_temp_K <= 1.0
    with pytest.raises(AssertionError, match=r"temperature error \d+\.\d+ K > 1 K \(worst: "):
        sv.assert_within("spl2782", "lumped:11", case="nominal", reference_level=1)
    assert sv.model_error("spl2782", "lumped:11", "nominal", 1).worst_temp_K > 1.0


def test_the_examples_use_only_the_public_name():
    """docs/examples/ import the tool as spindle_verify alone (issue 34: the README and the
    examples use only it), so a user copying them needs no internal module."""
    import ast
    from pathlib import Path

    internal = {"compare", "spindle", "reference", "lumped", "meshes"}
    for path in sorted((Path(__file__).resolve().parents[1] / "docs" / "examples").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module or ""] if isinstance(node, ast.ImportFrom) else [])
            assert not {n.split(".")[0] for n in names} & internal, (path.name, names)
