"""The linearized model (compare.fit.linear.Local) scores a step by the log-posterior the
nonlinear calibration reports (compare.fit.calibrate.Fit.log_posterior): share x the
concentrated log-likelihood less the prior penalty, 1/2 sum of the squared prior distances in
prior standard deviations. The penalty is checked against the calibrator's own figures."""

from __future__ import annotations

import numpy as np
import pytest

from compare.fit.calibrate import Calibrator, Measured, _to_z
from compare.fit.greybox import GreyBox
from compare.fit.linear import local
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES
from spindle.spec_reader import load_spec
from tests.cycle_inputs import inputs_from_cycle

CHANNELS = ["T1", "T2", "T_stator", "P1"]


@pytest.fixture(scope="module")
def calibrated():
    """The base calibrated with priors on grey-box data whose spindle is off its spec (f0
    0.4, the spec's 1.0 x the film factors) and noisy (0.05 K, 0.1 um), as `fit` does it:
    a free fit, then priors around the spec's values weighed by its residual."""
    spec = load_spec("spl2782")
    cycle = load_cycle("spl-16h")
    grid = np.arange(0.0, cycle.duration_s + 1.0, 120.0)
    inp = inputs_from_cycle(cycle, grid)
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    out = gb.simulate({"f0": 0.4, "h_air": 1.6})
    rng = np.random.default_rng(11)
    vals = {c: out[c] + rng.normal(0, 0.1e-6 if c == "P1" else 0.05, len(grid))
            for c in CHANNELS}
    cal = Calibrator(gb, Measured(grid, vals), CHANNELS)
    centre = {k: p.default for k, p in gb.parameters().items()}
    _, fit = cal.fit_with_prior(centre)
    return cal, fit


#: the mend (the penalty in prior sds) changes verdicts, so it waits for the main set's
#: measurement: docs/fit.md "The linearized gains' prior penalty"
NOT_ADOPTED = pytest.mark.xfail(strict=True, reason="the linearized gains weigh the priors "
                                "prior_scale^2 times the calibration's log-posterior (known; "
                                "its mend is a trade measured on 59 runs, not yet adopted)")


@NOT_ADOPTED
def test_the_linear_penalty_is_the_calibrations_own(calibrated):
    """At the fitted point the step of nothing carries the prior penalty the calibration
    reports (Fit.penalty, 1/2 sum ((z - z_prior) / sd)^2), to round-off. It is that penalty
    times prior_scale^2, the weight of the priors' rows in the least squares, and prior_scale
    is not 1 here (asserted: else the test could not tell)."""
    cal, fit = calibrated
    loc = local(cal, fit)
    assert abs(cal.prior_scale - 1.0) > 0.1, cal.prior_scale
    assert fit.penalty > 0.0
    assert loc.penalty(np.zeros(loc.J.shape[1])) == pytest.approx(fit.penalty, rel=1e-12)


@NOT_ADOPTED
def test_a_steps_penalty_is_the_calibrators_at_the_point_it_lands(calibrated):
    """A step of a tenth of a prior sd in each parameter (away from the prior centres): the
    penalty Local scores it with is the calibrator's prior terms at the parameters the step
    lands on (Calibrator._prior_terms, from the values in their units), to 1e-9 (the round
    trip through the parameters' scales)."""
    cal, fit = calibrated
    loc = local(cal, fit)
    params = cal.gb.variant(fit.effects).parameters()
    sd = np.array([params[k].prior_sd or 0.0 for k in fit.free])
    delta = 0.1 * sd * np.sign(loc.z0 - loc.prior_z + 1e-12)
    theta = loc.theta_after(delta)
    z = np.array([_to_z(params[k], theta[k]) for k in fit.free])
    expected = 0.5 * float(np.sum(cal._prior_terms(params, fit.free, z) ** 2))
    assert expected > fit.penalty  # the step moved away from the priors
    assert loc.penalty(delta) == pytest.approx(expected, rel=1e-9)
