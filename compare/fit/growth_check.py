"""P1 against the spec's own prediction, before any calibration: a sign or a unit slip.

The growth chain of the spec's model (eq. 12-13, 20) predicts P1 from the run's power and speed
to within the calibration's freedom (a factor of about two: alpha_eff's prior). A P1 column
whose gain on that prediction is negative, or a thousand times off, is a column the fit
cannot represent: a sign flipped in the export, or a growth in nm or mm. :func:`check_growth`
regresses P1 on the prediction (with an offset: P1 is zeroed at the run's start, the model
at its own; and beside the library's instantaneous P1 terms, the speed squared and the
room's temperature, so that a strong centrifugal shortening is not read as a sign), weighs
the gain's standard error by the residual's autocorrelation
(compare.residuals.effective_samples) and refuses a gain whose interval at the fit's alpha
lies below zero, or beyond Criteria.growth_unit_gain either way.
"""

from __future__ import annotations

import math

import numpy as np

from compare.residuals import effective_samples
from spindle.errors import InputError
from spindle.tolerances import channel_tolerance


def library_terms(inputs) -> list[np.ndarray]:
    """The library's instantaneous P1 terms at the grid points of ``inputs``
    (spindle.bench_inputs.Inputs): the speed squared [rpm^2] (a centrifugal shortening) and
    the room's temperature [K] (a fixture's expansion), each the value of the interval that
    ends at the point."""
    k = np.maximum(np.arange(len(inputs.grid_s)) - 1, 0)
    return [np.asarray(inputs.speed_rpm, dtype=float)[k] ** 2,
            np.asarray(inputs.T_env_K, dtype=float)[k]]


def growth_gain(measured_m: np.ndarray, predicted_m: np.ndarray,
                terms: list[np.ndarray] = ()) -> tuple[float, float] | None:
    """(gain, standard error) of P1 [m] on the model's P1 [m] over the grid points where both
    are finite, fitted with an offset and the further ``terms`` (:func:`library_terms`: a
    centrifugal shortening or a fixture's growth takes its own share, not the growth's), the
    error inflated by n / n_eff for the residual's autocorrelation. None where the prediction
    moves by less than P1's tolerance (the spec predicts too little growth to tell a unit) or
    fewer than ten points are measured."""
    y, m = np.asarray(measured_m, dtype=float), np.asarray(predicted_m, dtype=float)
    extra = [np.asarray(t, dtype=float) for t in terms]
    ok = np.logical_and.reduce([np.isfinite(a) for a in (y, m, *extra)])
    y, m = y[ok], m[ok]
    if len(y) < 10 or np.ptp(m) < channel_tolerance("P1"):
        return None
    cols = [m] + [t[ok] for t in extra if np.ptp(t[ok]) > 0]
    X = np.column_stack([np.ones(len(y))] + [(c - c.mean()) / np.ptp(c) for c in cols])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    e = y - X @ coef
    n, p = X.shape
    n_eff = max(effective_samples({"P1": e}), p + 1.0)
    s2 = float(e @ e) / max(n - p, 1) * (n / n_eff)
    cov = s2 * np.linalg.pinv(X.T @ X)
    scale = np.ptp(m)  # the gain's column was divided by it
    return float(coef[1]) / scale, math.sqrt(max(float(cov[1, 1]), 0.0)) / scale


def check_growth(path: str, measured_m: np.ndarray, predicted_m: np.ndarray, criteria,
                 terms: list[np.ndarray] = ()) -> None:
    """Refuse (InputError on ``path``'s P1_um) a P1 [m] whose gain on the spec's predicted
    P1 [m] (beside ``terms``: :func:`growth_gain`) is negative, or beyond
    ``criteria.growth_unit_gain`` either way, by more than its interval at ``criteria.alpha``
    (module docstring)."""
    from scipy.stats import norm

    found = growth_gain(measured_m, predicted_m, terms)
    if found is None:
        return
    gain, se = found
    z = float(norm.isf(criteria.alpha / 2))
    lo, hi = gain - z * se, gain + z * se
    band = criteria.growth_unit_gain
    said = (f"P1 moves {gain:.3g} times the growth the spec's model predicts from the run's "
            f"power and speed ({100 * (1 - criteria.alpha):g} % interval {lo:.3g} to {hi:.3g})")
    if hi < 0:
        raise InputError(
            path, "P1_um", f"{said}: it shrinks where the spindle grows",
            "export P1_um positive where the shaft grows out toward the tool (docs/bench.md); "
            "if the sign is right, the spec's growth chain (the locating bearing, the "
            "materials' alpha_1_K) is not this spindle's")
    if lo > band:
        raise InputError(
            path, "P1_um", f"{said}: more than {band:g} times, nearer a growth in nm than "
            "one in µm", "export the axial growth in µm (a value in nm is 1000 times too large)")
    if 0 <= hi < 1 / band:
        raise InputError(
            path, "P1_um", f"{said}: less than 1/{band:g} of it, nearer a growth in mm than "
            "one in µm, or a sensor that does not follow the shaft",
            "export the axial growth in µm (a value in mm is 1000 times too small), and check "
            "that the P1 sensor faces the shaft's front end")
