"""The paper's figures (compare/design/paper.py, docs/paper.md).

The spl-16h peaks T1 = 32.4 degC and P1 = 6.5 µm and the nominal losses 5146 W are
CALIBRATION TARGETS, not predictions: the shipped bearing friction factor f0 and the film
factor of the rotating surfaces were fitted to the two peaks (docs/paper.md), and the motor
parameters to the losses. The test asserts them within the issue's 5 % on FEM level 1, the
level the fit ran on (docs/paper.md's table gives both levels, from docs/figures/paper.json).
The nominal shaft, housing and growth figures are not met by any plausible parameter set
(docs/paper.md); the other tests check that the harness reads the figures as documented and
that each factor acts on the figure it should.
"""

import pytest

from compare.design.paper import TARGETS, PaperStudy


def test_calibration_targets_within_five_percent():
    f = PaperStudy(level=1).figures()
    dev = f.deviations()
    for key in ("losses_W", "T1_peak_C", "P1_peak_um"):  # calibration targets (module doc)
        assert abs(dev[key]) <= 0.05, (key, getattr(f, key), TARGETS[key])


@pytest.fixture(scope="module")
def study():
    return PaperStudy(level=0, dt_s=1800.0)


def test_figures_are_read_as_documented(study):
    f = study.figures()
    assert f.losses_W == pytest.approx(TARGETS["losses_W"], rel=1e-3)  # the power balance
    assert f.K_T_K_um == pytest.approx(f.shaft_rise_K / f.TCP_um)
    assert f.K_Q_W_um == pytest.approx(f.losses_W / f.TCP_um)
    assert f.TCP_um > f.P1_nominal_um > 0  # the tool adds its own growth
    assert set(f.deviations()) == set(TARGETS)


def test_factors_act_where_they_should(study):
    base = study.figures()
    weak_coolant = study.figures({"coolant": 0.2})
    assert weak_coolant.housing_rise_K > base.housing_rise_K + 5.0
    cool_tool = study.figures({"rotating": 3.0})
    assert cool_tool.TCP_um < base.TCP_um
    more_friction = study.figures({"f0": 1.0})
    # nominal: P_el is given, so more bearing friction only moves loss from the motor to the
    # bearings (total unchanged); the no-load cycle has no P_el, so T1 rises
    assert more_friction.losses_W == pytest.approx(base.losses_W, rel=1e-9)
    assert more_friction.T1_peak_C > base.T1_peak_C + 1.0
    study.apply({})  # leave the shared operator as shipped
