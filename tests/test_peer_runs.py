"""``fit`` on a peer's nine development runs (../shared/bench-runs/: an independent simulator
of an SPL2782-family spindle that is not the shipped spec), against its truth.json: the one
undeclared effect per run named alone, nothing named on the two control runs (issue 13).

Slow: one fit of 10-25 s per run on 2 cores, with the tool's defaults (the blocked
cross-validation guard included) (benchmarks/bench_devruns.py prints the same
table). The fast path (events, selection, report) is covered in the default run by
tests/test_events.py (the event tests on these runs' raw samples) and
tests/test_greybox.py::test_synth_then_fit_end_to_end.

The runs the tool still gets wrong are marked xfail(strict) (docs/fit.md, "Runs from a
spindle the spec only approximates"), and so are the named runs whose validation error stays
above a tolerance. Strict, so that a fix shows up as a failure to update here.
"""

from __future__ import annotations

import functools
import json
from pathlib import Path

import pytest

PEER_RUNS = Path(__file__).resolve().parents[2] / "shared" / "bench-runs"
#: the runs named wrongly at the last measurement, with what fit names (docs/fit.md)
KNOWN_WRONG: dict[str, str] = {}
#: runs whose validation open-loop RMS after the fit exceeds a tolerance although the effect
#: is named, with the channel (docs/fit.md: the base model's misfit, not the effect's)
KNOWN_OVER_TOLERANCE: dict[str, str] = {}
TOLERANCE = {"T1": 1.0, "T2": 1.0, "T_stator": 1.0, "P1": 1.5}  # the paper's: K, K, K, µm


@functools.cache
def _fit(label: str) -> dict:
    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec

    return run_fit(PEER_RUNS / f"{label}.csv", load_spec("spl2782")).to_dict()


def _runs() -> list:
    if not (PEER_RUNS / "truth.json").exists():
        return []
    truth = json.loads((PEER_RUNS / "truth.json").read_text(encoding="utf-8"))
    return [pytest.param(label, t["truth"], id=label, marks=[pytest.mark.xfail(
        strict=True, reason=KNOWN_WRONG[label])] if label in KNOWN_WRONG else [])
        for label, t in sorted(truth.items())]


@pytest.mark.slow
@pytest.mark.skipif(not (PEER_RUNS / "truth.json").exists(),
                    reason="the peer's bench runs are beside the project")
@pytest.mark.parametrize(("label", "truth"), _runs())
def test_fit_names_the_peer_runs_effect(label, truth):
    doc = _fit(label)
    named = [e["name"] for e in doc["effects"]]
    assert named == ([truth] if truth else []), named
    for e in doc["effects"]:  # each named effect carries its evidence
        assert e["p_value"] < doc["alpha"] and e["needed_by"]


def _named_runs() -> list:
    if not (PEER_RUNS / "truth.json").exists():
        return []
    truth = json.loads((PEER_RUNS / "truth.json").read_text(encoding="utf-8"))
    return [pytest.param(label, id=label, marks=[pytest.mark.xfail(
        strict=True, reason=KNOWN_OVER_TOLERANCE[label])] if label in KNOWN_OVER_TOLERANCE
        else []) for label, t in sorted(truth.items())
        if t["truth"] and label not in KNOWN_WRONG]


@pytest.mark.slow
@pytest.mark.skipif(not (PEER_RUNS / "truth.json").exists(),
                    reason="the peer's bench runs are beside the project")
@pytest.mark.parametrize("label", _named_runs())
def test_validation_error_after_is_within_the_tolerances(label):
    """Issue 13 §6: where the effect is named, the validation open-loop RMS after the fit is
    within 1 K and 1.5 µm on every channel."""
    val = _fit(label)["error_after"]["validation"]
    over = {c: e["rmse"] for c, e in val.items() if e["rmse"] > TOLERANCE[c]}
    assert not over, over


#: (run, seed of the spec's perturbation): a mount (the verdict the guards balance most
#: finely), a preload named by its power drift, a control and the loaded control (where,
#: with the friction exponent in the base, the loop named a rear-set-only preload until
#: compare.fit.calibrate.front_set_carries), fitted with a spec whose
#: geometry, films and
#: contacts are further off (compare.fit.mismatch.perturbed_spec; seed 2 stretches the axis by
#: 12 % and moves the air film x 1.6, the contacts x 1.9); benchmarks/bench_devruns.py
#: --spec-mismatch 1/2/3 measured 9 of 9 on each seed (docs/fit.md)
PERTURBED = [("dev-07", 2), ("dev-02", 2), ("dev-06", 2), ("dev-09", 2)]


@pytest.mark.slow
@pytest.mark.skipif(not (PEER_RUNS / "truth.json").exists(),
                    reason="the peer's bench runs are beside the project")
@pytest.mark.parametrize(("label", "seed"), PERTURBED, ids=[f"{a}-spec{b}" for a, b in PERTURBED])
def test_verdict_holds_when_the_spec_is_further_off(label, seed):
    from compare.fit.mismatch import perturbed_spec
    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec

    truth = json.loads((PEER_RUNS / "truth.json").read_text(encoding="utf-8"))[label]["truth"]
    doc = run_fit(PEER_RUNS / f"{label}.csv",
                  perturbed_spec(load_spec("spl2782"), seed)).to_dict()
    assert [e["name"] for e in doc["effects"]] == ([truth] if truth else [])
    for e in doc["effects"]:  # each named effect carries its evidence
        assert e["p_value"] < doc["alpha"] and e["needed_by"]
    # issue 13 §6: within the tolerances where an effect is named (measured: worst 0.80 K)
    if truth:
        val = doc["error_after"]["validation"]
        assert all(e["rmse"] <= TOLERANCE[c] for c, e in val.items()), val
