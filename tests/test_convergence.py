"""Grid convergence analysis (compare/verify/convergence.py): the GCI arithmetic on series with a
known exact value and order, the flags, and a study of the FEM reference."""

import math

import pytest

from compare.verify.convergence import GCI, ConvergenceResult, convergence_study
from spindle.spec_reader import load_spec


def series(exact: float, C: float, p: float, levels=(0, 1, 2, 3)):
    """f(h) = exact + C h^p on h = 2^-level (an error that is exactly asymptotic)."""
    return [exact + C * 2.0 ** (-p * lv) for lv in levels]


def test_gci_recovers_order_and_limit_of_an_exact_power_law():
    f3, f2, f1 = series(50.0, 2.0, 1.7, (0, 1, 2))
    g = GCI(f1, f2, f3)
    assert g.flag == ""
    assert g.p == pytest.approx(1.7, rel=1e-12)
    assert g.extrapolated == pytest.approx(50.0, rel=1e-12)
    # Roache: Fs |(f1 - f2)/f1| / (r^p - 1); here f1 - f2 = 2 (4^-1.7 - 2^-1.7)
    hand = 1.25 * abs(2.0 * (4**-1.7 - 2**-1.7) / f1) / (2**1.7 - 1)
    assert g.gci_fine == pytest.approx(hand, rel=1e-12)
    # the true relative error of f1 is below the GCI (the safety factor 1.25)
    assert abs(f1 - 50.0) / f1 < g.gci_fine


def test_flags():
    assert GCI(1.0, 1.1, 0.9).flag == "oscillatory"
    assert GCI(1.0, 1.2, 1.3).flag == "divergent"  # differences grow towards the fine grid
    assert GCI(5.0, 5.0, 5.0).flag == "converged" and GCI(5.0, 5.0, 5.0).gci_fine == 0.0
    tiny = GCI(5.0, 5.0 + 1e-9, 5.1)  # fine-grid change at solver round-off
    assert tiny.flag == "converged" and tiny.gci_fine == pytest.approx(1.25 * 1e-9 / 5.0)
    slow = GCI(10.0, 10.01, 10.0201)  # differences 0.01 and 0.0101: p = 0.014
    assert slow.flag == "slow" and math.isnan(slow.extrapolated)
    assert slow.gci_fine == pytest.approx(1.25 * 0.01 / 10.0 / (2**0.5 - 1))
    # oscillatory: Fs times half the range of the three values
    assert GCI(1.0, 1.1, 0.9).gci_fine == pytest.approx(1.25 * 0.5 * 0.2 / 1.0)
    assert math.isnan(GCI(1.0, 1.2, 1.3).gci_fine)


def fake_result(values, threshold=0.01):
    spec = load_spec("fin-shaft")
    n = len(next(iter(values.values())))
    return ConvergenceResult(spec, "test", list(range(n)), [1] * n, [1] * n, [0.0] * n, values,
                             dict.fromkeys(values, "K"), threshold)


def test_ground_truth_level_and_asymptotic_ratio():
    a, b = series(10.0, 1.0, 2.0), series(20.0, -5.0, 2.0)
    res = fake_result({"a": a, "b": b})
    t = res.table()
    # an exact power law is in the asymptotic range: the ratio is f(level 3) / f(level 2),
    # the relative-error normalisation of the two GCIs, i.e. 1 up to that
    assert t["asymptotic_ratio"] == pytest.approx([a[3] / a[2], b[3] / b[2]], rel=1e-9)
    assert t["p"] == pytest.approx([2.0, 2.0]) and t["p_previous"] == pytest.approx([2.0, 2.0])
    # level-2 GCI of 'a': 1.25 |f(1/4) - f(1/2)| / f(1/4) / 3 = 1.25 * 0.1875 / 10.0625 / 3
    assert res.gci("a", 2).gci_fine == pytest.approx(1.25 * 0.1875 / 10.0625 / 3)
    # 'a' has 0.78 % at level 2, 'b' 1.98 % (1.25 * 0.9375 / 19.6875 / 3): level 3 it is
    assert res.gci("b", 2).gci_fine == pytest.approx(1.25 * 0.9375 / 19.6875 / 3)
    assert res.ground_truth_level() == 3
    loose = fake_result({"a": series(10.0, 1.0, 2.0)}, threshold=0.01)
    assert loose.gci("a", 2).gci_fine < 0.01 and loose.ground_truth_level() == 2
    osc = fake_result({"a": [1.0, 1.2, 1.1, 1.15]})  # 5 % half-range: no level qualifies
    assert osc.ground_truth_level() is None
    assert osc.table()["flag"] == ["oscillatory"]
    div = fake_result({"a": [1.0, 1.01, 1.03, 1.07]})
    assert div.table()["flag"] == ["divergent"] and div.ground_truth_level() is None


def test_reference_study_on_fin_shaft(tmp_path):
    res = convergence_study(load_spec("fin-shaft"), levels=(0, 1, 2))
    t = res.table()
    assert len(t["quantity"]) == 11  # the 11 virtual sensors
    # a smooth solution: the P2 sensors change by < 3e-4 K from level 1 to 2 (some oscillate
    # at 1e-7 of the value and are flagged), far below 1 %
    assert res.ground_truth_level() == 2
    assert all(g < 1.0 for g in t["GCI_fine_pct"])
    assert "oscillatory" in t["flag"]  # flagged, not hidden
    files = res.save(tmp_path)
    assert {f.name for f in files} == {"convergence.csv", "convergence.json", "convergence.md",
                                       "convergence.png"}
