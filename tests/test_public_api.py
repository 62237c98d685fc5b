"""The public API under one name, spindle_verify (issue 34): each function on the shipped
specs, names accepted where objects are, and assert_within as a plain function."""

from __future__ import annotations

import subprocess
import sys

import pytest

import spindle_verify as sv
from spindle.errors import InputError


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


def _constant_case(**change):
    from spindle.loads import LoadCase, TimeSeries

    values = {"speed_rpm": 4300.0, "T_ambient_K": 293.15, "T_coolant_K": 293.15, **change}
    sources = values.pop("sources", {})
    return LoadCase("c", *(TimeSeries.constant(values[k]) for k in
                           ("speed_rpm", "T_ambient_K", "T_coolant_K")),
                    {k: TimeSeries.constant(v) for k, v in sources.items()})


# Each was found by fuzzing the API:
# a NaN ran to NaN results or empty CSV cells, an impossible value solved, a wrong type failed
# deep in pathlib, numpy or scikit-fem without naming the argument.
BAD_CALLS = [
    (lambda: sv.reference_model("fin-shaft", level="1"), TypeError, "level must be a whole"),
    (lambda: sv.reference_model("fin-shaft", level=1.5), TypeError, "level must be a whole"),
    (lambda: sv.reference_model("fin-shaft", level=0, order="2"), TypeError, "order"),
    (lambda: sv.lumped_model("spl2782", nodes=None), Exception, "None is not an integer"),
    (lambda: sv.solve("spl2782", model=5), TypeError, "model must be"),
    (lambda: sv.solve("spl2782", model="fem:x"), ValueError, "L is a mesh level"),
    (lambda: sv.solve("spl2782", 42, model="lumped:5"), TypeError, "a case is a LoadCase"),
    (lambda: sv.solve("spl2782", "spl-16h", dt_s="60", model="lumped:5"), TypeError, "dt_s"),
    (lambda: sv.lumped_model("spl2782", 5).transient("spl-16h", 600.0, T0=float("nan")),
     ValueError, "T0 must be finite"),
    (lambda: sv.lumped_model("spl2782", 5).transient("spl-16h", 600.0, T0=-5.0), ValueError,
     "above 0 K"),
    (lambda: _constant_case(speed_rpm=float("nan")), ValueError, "must be finite"),
    (lambda: sv.solve("spl2782", _constant_case(T_ambient_K=20.0), model="lumped:5"),
     InputError, "T_ambient_K: reaches 20 K"),
    (lambda: sv.solve("spl2782", _constant_case(speed_rpm=-4300.0), model="lumped:5"),
     InputError, "speed_rpm: reaches -4300 rpm"),
    (lambda: sv.solve("spl2782", _constant_case(sources={"front_bearing": -500.0}),
                      model="lumped:5"), InputError, "reaches -500 W"),
    (lambda: sv.solve("spl2782", _constant_case(sources={"no_such": 10.0}), model="lumped:5"),
     InputError, "not heat sources of spec"),
    (lambda: __import__("spindle.loads", fromlist=["LoadCase"]).LoadCase(
        "x", 4300.0, 293.15, 293.15), TypeError, "speed_rpm must be a TimeSeries"),
    (lambda: sv.assert_within("fin-shaft", "lumped:5", tol_temp_K="5", reference_level=0),
     TypeError, "tol_temp_K must be a number"),
    (lambda: sv.synth("spl2782", "spl-16h", "clean", -1, "x.csv"), ValueError, "seed is -1"),
    (lambda: sv.fit("no-such.csv", alpha="0.01"), Exception, "alpha: is '0.01', not a float"),
    (lambda: sv.fit(123), TypeError, "path of its CSV file"),
    (lambda: sv.fit("no-such.csv", workers=0), ValueError, "workers is 0, outside 1.."),
    (lambda: __import__("spindle.spec_reader", fromlist=["load_spec"]).load_spec(123),
     TypeError, "a spec is a shipped name or a path"),
    # a result's save and read-outs: pictures='no' drew them; sensor(5) said "5 is not in list"
    (lambda: sv.solve("fin-shaft", model="lumped:5").save("x", pictures="no"), TypeError,
     "pictures must be True or False"),
    (lambda: sv.solve("fin-shaft", model="lumped:5").save(123), TypeError,
     "out must be a folder's path"),
    (lambda: sv.solve("spl2782", "spl-16h", dt_s=3600.0, model="lumped:5").sensor(5),
     KeyError, "no sensor named 5; the sensors are"),
]


@pytest.mark.parametrize("call, kind, words", BAD_CALLS,
                         ids=[f"bad{i}" for i in range(len(BAD_CALLS))])
def test_a_bad_argument_is_named_where_it_is_given(call, kind, words):
    with pytest.raises(kind, match=words):
        call()


def test_a_result_is_not_saved_over_a_file(tmp_path):
    """save(out) onto an existing file failed in pathlib's mkdir with "File exists"."""
    f = tmp_path / "afile.txt"
    f.write_text("mine", encoding="utf-8")
    with pytest.raises(NotADirectoryError, match="is a file, not a folder"):
        sv.solve("fin-shaft", model="lumped:5").save(f)
    assert f.read_text(encoding="utf-8") == "mine"
