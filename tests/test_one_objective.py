"""The calibration maximises the figure the selection judges a model by (compare.fit.calibrate,
"Weighted least squares"): share x the concentrated log-likelihood (a variance per channel)
less the prior penalty. Checked by an independent route: a general-purpose minimiser
(scipy.optimize.minimize, L-BFGS-B) started at the calibration's answer and run on that figure
itself must find nothing worth having. The channels carry noise 30 times apart (0.6 K on T1,
0.02 K on T2), where a least squares with one common weight lands elsewhere: it left 20.8
log-likelihood units for the minimiser to find without priors, 15.1 with them (measured at
ac78811, before the reweighting, 2026-12-01).

Not yet so: the calibration weighs every channel alike and the priors by one scale, and its
reweighted mend (benchmarks/patches/one-objective.patch, `git apply`) is a trade measured and
not adopted (docs/fit.md, "One objective"); both tests are strict xfails until it is.

Tolerance: 0.05 log-likelihood units, a sixtieth of the smallest gain a selection rule acts on
(chi2(1) at the 1 % level, 6.63 / 2 = 3.3) and far above the reweighting's own slack (its 1 %
tolerance on the weights moved the gain by 3e-9 here)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import minimize

from compare.fit.calibrate import (
    Calibrator,
    Measured,
    _from_z,
    _to_z,
    concentrated_loglik,
    z_bounds,
)
from compare.fit.greybox import GreyBox
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES
from spindle.spec_reader import load_spec
from tests.cycle_inputs import inputs_from_cycle

CHANNELS = ["T1", "T2", "T_stator", "P1"]
#: the channels' noise [K; m for P1]: 30 times apart in tolerances
NOISE = {"T1": 0.6, "T2": 0.02, "T_stator": 0.05, "P1": 0.03e-6}
SLACK = 0.05
#: the mend is measured, not adopted (module docstring)
NOT_ADOPTED = pytest.mark.xfail(strict=True, reason="the calibration's least squares weigh the "
                                "channels alike, the selection by a variance per channel "
                                "(docs/fit.md, 'One objective': a trade, not adopted)")


@pytest.fixture(scope="module")
def calibrator() -> Calibrator:
    """Grey-box data of a spindle off its spec (f0 0.4, films x 1.6) with the noise NOISE."""
    spec = load_spec("spl2782")
    cycle = load_cycle("spl-16h")
    grid = np.arange(0.0, cycle.duration_s + 1.0, 120.0)
    gb = GreyBox(spec, DRIVES["spl2782"], inputs_from_cycle(cycle, grid))
    out = gb.simulate({"f0": 0.4, "h_air": 1.6})
    rng = np.random.default_rng(11)
    vals = {c: out[c] + rng.normal(0.0, NOISE[c], len(grid)) for c in CHANNELS}
    return Calibrator(gb, Measured(grid, vals), CHANNELS)


def _best_nearby(cal: Calibrator, fit, share: float) -> float:
    """The judged figure (share x concentrated log-likelihood less the penalty) that L-BFGS-B
    reaches from ``fit``, less the fit's own."""
    params = cal.gb.variant(fit.effects).parameters()
    free = list(fit.free)
    lo, hi = z_bounds([params[k] for k in free])

    def minus_judged(z: np.ndarray) -> float:
        theta = {**fit.theta, **{k: _from_z(params[k], float(v))
                                 for k, v in zip(free, z, strict=True)}}
        ll = concentrated_loglik(cal.residuals(cal.gb.simulate(theta), "fit").values())
        penalty = 0.5 * float(np.sum(cal._prior_terms(params, free, z) ** 2))
        return -(ll * share - penalty)

    z0 = np.array([_to_z(params[k], fit.theta[k]) for k in free])
    start = minus_judged(z0)
    assert start == pytest.approx(-fit.log_posterior(share), rel=1e-12)
    sol = minimize(minus_judged, z0, method="L-BFGS-B", bounds=list(zip(lo, hi, strict=True)),
                   options={"maxiter": 300})
    return start - float(sol.fun)


@NOT_ADOPTED
def test_the_free_fit_maximises_the_concentrated_likelihood(calibrator):
    fit = calibrator.fit()
    assert _best_nearby(calibrator, fit, 1.0) < SLACK


@NOT_ADOPTED
def test_the_fit_with_priors_maximises_the_log_posterior(calibrator):
    """Priors around the spec's values (f0 1, films 1: the data lie off them), the data
    counted at the fit's sample share, as the selection counts every gain."""
    cal = Calibrator(calibrator.gb, calibrator.measured, CHANNELS)
    centre = {k: p.default for k, p in cal.gb.parameters().items()}
    _, fit = cal.fit_with_prior(centre)
    assert fit.penalty > 0.1  # the priors pull
    assert _best_nearby(cal, fit, fit.sample_share) < SLACK

