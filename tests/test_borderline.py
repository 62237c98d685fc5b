"""Verdicts with their uncertainty (issue 34): a model whose margin to a tolerance is within
the reference's own uncertainty is "borderline" in every table, not a bare PASS or FAIL."""

from __future__ import annotations

import pytest

from compare.report import verdict_cell
from compare.verify.accuracy import AccuracyResult, Entry
from spindle.spec_reader import load_spec

SPEC = load_spec("spl2782")
NAMES = [s.name for s in SPEC.temperature_sensors()]


def _accuracy(errors_K: dict[str, float], uncertainty: dict | None) -> AccuracyResult:
    """Models off the reference by a uniform error [K] at every sensor and 0.1 um on P1."""
    ref = Entry("reference", "reference", 0, 0.0, dict.fromkeys(NAMES, 300.0), {"P1": 5e-6})
    entries = [Entry(name, "lumped", 10, 0.0, {n: 300.0 + e for n in NAMES}, {"P1": 5.1e-6})
               for name, e in errors_K.items()]
    return AccuracyResult(SPEC, "nominal", False, ref, "a reference", entries,
                          uncertainty=uncertainty)


@pytest.mark.parametrize(("error_K", "word"), [
    (0.90, "PASS"),         # 0.10 K to spare, more than the 0.04 K uncertainty
    (0.97, "borderline"),   # passes by 0.03 K: within it
    (1.03, "borderline"),   # fails by 0.03 K: within it
    (1.10, "FAIL"),         # fails by 0.10 K
])
def test_a_margin_within_the_uncertainty_is_borderline(error_K, word):
    acc = _accuracy({"m": error_K}, {"K": 0.04, "um": 0.01})
    row = acc.errors(acc.entries[0])
    assert acc.verdict_word(row) == word
    t = acc.table()
    assert t["borderline"][0] is (word == "borderline")
    assert t["meets_tolerances"][0] is (error_K <= 1.0)
    md = acc.markdown()
    assert (word in md) and ("borderline" in acc.verdict(row)) is (word == "borderline")


def test_without_an_uncertainty_the_verdict_is_plain():
    acc = _accuracy({"m": 0.999}, None)
    assert acc.verdict_word(acc.errors(acc.entries[0])) == "PASS"


def test_the_html_cell_says_borderline_and_its_side():
    assert "borderline (passes)" in verdict_cell(True, borderline=True)
    assert "borderline (fails)" in verdict_cell(False, borderline=True)
    assert 'class="pass">PASS' in verdict_cell(True)
