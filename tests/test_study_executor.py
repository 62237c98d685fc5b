"""The study's independent runs go through the executor (compare/verify/study.py, compare/executor.py):
the same figures serially and in a process pool, and a failed run is reported, not raised."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

import compare.verify.study
from compare.cli import main
from compare.verify.study import StudyRun, run_study
from spindle.errors import InputError
from spindle.spec_reader import load_spec

# small and fast: three levels (the fewest a GCI allows), two node counts, 48 steps of 600 s
SMALL = {"levels": (0, 1, 2), "nodes": (3, 11), "dt_s": 600.0}


def _figures(study) -> dict[str, np.ndarray]:
    """Every sensor and growth reading of every entry (and reference), by name."""
    out = {}
    for acc in (study.steady, study.transient):
        tag = "transient" if acc.transient else "steady"
        for e in [acc.reference, *acc.entries]:
            for kind, values in (("sensor", e.sensors), ("growth", e.growth)):
                for k, v in values.items():
                    out[f"{tag}/{e.name}/{kind}/{k}"] = np.asarray(v, dtype=float)
    return out


def test_serial_and_pool_give_the_same_figures():
    spec = load_spec("fin-shaft")
    lines: list[str] = []
    serial = run_study(spec, **SMALL, workers=1)
    pool = run_study(spec, **SMALL, workers=2, progress=lines.append)
    assert serial.failures == [] and pool.failures == []
    for s in (serial, pool):
        assert [e.name for e in s.steady.entries] == ["eq. 14", "lumped 3", "lumped 11",
                                                      "FEM level 0", "FEM level 1",
                                                      "FEM level 2"]
        assert [e.name for e in s.transient.entries] == ["lumped 3", "lumped 11",
                                                         "FEM level 0", "FEM level 1"]
    a, b = _figures(serial), _figures(pool)
    assert a.keys() == b.keys() and len(a) > 100
    # The same code on the same inputs (the spec and the load case cross to the workers by
    # pickle, which round-trips floats exactly): bit-identical in practice. 1e-12 relative
    # leaves room only for a different reduction order of threaded BLAS in another process
    # (a few thousand ulp), far below any figure the study reports (3 significant digits).
    for k in a:
        np.testing.assert_allclose(b[k], a[k], rtol=1e-12, atol=0.0, err_msg=k)
    # progress: one line per pooled run, "[i/n] label done x s", and a FEM transient's speed
    # segments from inside its worker, "[x.y/n] label: k of m" (issue 33); the reference
    # transient runs first, on its own, reports each speed segment "[k/n] reference
    # transient: ..." and states its temporal error (issue 15 §1)
    runs = [ln for ln in lines if ln.startswith("[") and "reference transient" not in ln]
    finished = [ln for ln in runs if " done " in ln]
    assert len(finished) == 6
    assert all(re.match(r"\[\d+\.\d/6\] FEM level \d transient .*: \d+ of \d+$", ln)
               for ln in runs if ln not in finished)
    segments = [ln for ln in lines if ln.startswith("[") and "reference transient" in ln]
    assert segments and segments[-1].startswith(f"[{len(segments)}/{len(segments)}]")
    assert any(ln.startswith("reference transient on level") for ln in lines)
    assert any(ln.startswith("temporal error ") for ln in lines)


def _fail_for_5_nodes_steady(monkeypatch):
    real = compare.verify.study.lumped_entries

    def flaky(spec, case, nodes, dt_s, T0, progress=None):
        if tuple(nodes) == (5,) and dt_s is None:
            raise FloatingPointError("injected failure\nsecond line")
        return real(spec, case, nodes, dt_s, T0, progress)

    monkeypatch.setattr(compare.verify.study, "lumped_entries", flaky)


def test_a_failed_run_is_listed_and_the_others_are_present(monkeypatch):
    _fail_for_5_nodes_steady(monkeypatch)
    lines: list[str] = []
    study = run_study(load_spec("fin-shaft"), **{**SMALL, "nodes": (3, 5, 11)}, workers=1,
                      progress=lines.append)
    assert study.failures == [{"label": "lumped 5 nodes steady (steady)",
                               "error": "injected failure", "type": "FloatingPointError"}]
    assert any(ln.endswith("lumped 5 nodes steady (steady) FAILED: injected failure")
               for ln in lines)
    steady = [e.name for e in study.steady.entries]
    assert "lumped 5" not in steady and {"lumped 3", "lumped 11", "FEM level 2"} <= set(steady)
    # the transient 5-node run did not fail
    assert "lumped 5" in [e.name for e in study.transient.entries]
    assert study.summary()["failures"] == study.failures


def test_a_failed_reference_transient_leaves_no_transient_table(monkeypatch):
    real = compare.verify.study.fem_entry

    def broken(spec, level, case, dt_s, T0, order=2):
        if dt_s is not None and level == 2:
            raise RuntimeError("out of memory")
        return real(spec, level, case, dt_s, T0, order)

    monkeypatch.setattr(compare.verify.study, "fem_entry", broken)
    study = run_study(load_spec("fin-shaft"), **SMALL, workers=1)
    assert study.transient is None
    assert [f["label"] for f in study.failures] == ["FEM level 2 transient (warm-up 8 h)"]
    assert study.steady.entries  # the steady comparison is complete


def test_study_command_reports_failures_and_exits_1(monkeypatch, tmp_path, capsys):
    _fail_for_5_nodes_steady(monkeypatch)
    out = tmp_path / "study"
    code = main(["study", "fin-shaft", "--levels", "0", "1", "2", "--nodes", "3", "5",
                 "--steady-only", "--no-pictures", "--out", str(out)])
    assert code == 1
    cap = capsys.readouterr()
    assert "FAILED lumped 5 nodes steady (steady): injected failure" in cap.out
    assert "FAILED: injected failure" in cap.err and "Traceback" not in cap.err
    summary = json.loads((out / "study.json").read_text())  # outputs written all the same
    assert summary["failures"][0]["label"] == "lumped 5 nodes steady (steady)"
    html = (out / "report.html").read_text()
    assert "Failed runs (1)" in html and "injected failure" in html


def test_workers_option():
    assert main(["study", "fin-shaft", "--workers", "0"]) == 2
    spec = load_spec("fin-shaft")
    run = StudyRun(spec, spec.default_load_case(), "fem", 1, 60.0, 300.0)
    assert run.label == "FEM level 1 transient (steady)"  # the spec's own case is "steady"
    with pytest.raises(InputError, match="--workers"):  # before the grid convergence runs
        run_study(spec, **SMALL, workers=0)
