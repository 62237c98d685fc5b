"""The calibrated model linearized at a fit: what the selection asks of a fit many times (a
candidate's screen, the competitor's joint fit, blocked cross-validation, the refit to the
whole run) answered by one Gauss-Newton step on the Jacobian instead of a nonlinear refit.

At a fit the residual (measured minus model, in tolerances) over every valid sample of the run
is r(z) ~ r0 + J (z - z0), z the free parameters on their fitted scale (compare.fit.calibrate).
A step minimises the sum of squares over chosen rows plus the priors' terms, within the
parameters' bounds (scipy.optimize.lsq_linear), exactly as the nonlinear fit would to first
order; extra columns (an effect's parameters at their neutral value, a window's heat) join the
same step. One Jacobian costs one simulation per free parameter.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from compare.fit.calibrate import (
    TOLERANCE,
    Calibrator,
    Fit,
    _from_z,
    _to_z,
    block_index,
    concentrated_loglik,
    error_row,
    z_bounds,
)
from compare.fit.effects import effect_of

#: the step of the finite differences on the fitted scale (as the nonlinear fit's)
STEP = 1e-4


@dataclass
class Local:
    """The model of ``fit`` linearized (module docstring): the residual rows of every
    channel's valid samples over the whole run, their channel and grid index, which lie in the
    fit window, the Jacobian of the free parameters, and what the priors add."""

    cal: Calibrator
    fit: Fit
    channel: np.ndarray  # per row: index into cal.channels
    point: np.ndarray  # per row: index into the grid
    in_fit: np.ndarray  # per row: in the fit window
    r0: np.ndarray
    J: np.ndarray  # (rows, free)
    z0: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    prior_rows: np.ndarray  # (free,) prior_scale / sd, 0 where no prior
    prior_z: np.ndarray  # (free,) prior centre on the fitted scale (z0 where none)

    def step(self, rows: np.ndarray, extra: np.ndarray | None = None,
             extra_bounds: Sequence[tuple[float, float]] = ()) -> np.ndarray:
        """The step over ``rows`` (boolean mask) with ``extra`` columns (rows, m) bounded by
        ``extra_bounds``: the change of the free parameters' z, then the extra amplitudes."""
        from scipy.optimize import lsq_linear

        A = self.J[rows] if extra is None else np.hstack([self.J[rows], extra[rows]])
        keep = self.prior_rows > 0
        # the priors' rows act on the base parameters alone, not on the extra columns
        P = np.pad(np.diag(self.prior_rows)[keep], ((0, 0), (0, A.shape[1] - len(keep))))
        bp = -self.prior_rows * (self.z0 - self.prior_z)
        lo = np.concatenate([self.lo - self.z0, [a for a, _ in extra_bounds]])
        hi = np.concatenate([self.hi - self.z0, [c for _, c in extra_bounds]])
        # a parameter sitting on a bound can only move inside
        lo, hi = np.minimum(lo, 0.0), np.maximum(hi, 0.0)
        if A.shape[1] == 0:
            return np.zeros(0)
        return lsq_linear(np.vstack([A, P]), np.concatenate([-self.r0[rows], bp[keep]]),
                          bounds=(lo, hi), method="bvls" if A.shape[1] < 30 else "trf",
                          lsmr_tol="auto").x

    def residual(self, delta: np.ndarray, extra: np.ndarray | None = None) -> np.ndarray:
        """The residual of every row after ``delta`` (free parameters, then extras)."""
        kb = self.J.shape[1]
        r = self.r0 + self.J @ delta[:kb]
        if extra is not None and len(delta) > kb:
            r = r + extra @ delta[kb:]
        return r

    def _prior_terms(self, delta: np.ndarray) -> np.ndarray:
        """The priors' residuals after the step ``delta`` (prior_scale / sd times the distance
        from the prior centre on the fitted scale; 0 where no prior)."""
        return self.prior_rows * (self.z0 + delta[:len(self.z0)] - self.prior_z)

    def theta_after(self, delta: np.ndarray) -> dict[str, float]:
        """The parameter values of the fit with its free parameters moved by the step
        ``delta`` on the fitted scale (extra amplitudes beyond them are not parameters)."""
        params = self.cal.gb.variant(self.fit.effects).parameters()
        free = self.fit.free
        return {**self.fit.theta, **{k: _from_z(params[k], float(z + d)) for k, z, d
                                     in zip(free, self.z0, delta[:len(free)], strict=True)}}

    def prior_sds(self, delta: np.ndarray) -> np.ndarray:
        """Each base parameter's distance from its prior centre after the step ``delta``, in
        prior standard deviations (0 where it has no prior)."""
        return self._prior_terms(delta) / self.cal.prior_scale

    def penalty(self, delta: np.ndarray) -> float:
        t = self._prior_terms(delta)
        return 0.5 * float(t @ t)

    def loglik(self, r: np.ndarray, rows: np.ndarray) -> float:
        """The concentrated log-likelihood of residual ``r`` over ``rows``
        (compare.fit.calibrate.concentrated_loglik)."""
        return concentrated_loglik(r[rows & (self.channel == c)]
                                   for c in range(len(self.cal.channels)))

    def gain_of(self, r1: np.ndarray, delta: np.ndarray) -> float:
        """The log-posterior gain over the fit window of the residual ``r1`` after the step
        ``delta`` against this model's own, counted in the fit's effective samples (the
        likelihood of compare.fit.calibrate)."""
        rows = self.in_fit
        return ((self.loglik(r1, rows) - self.loglik(self.r0, rows)) * self.fit.sample_share
                - (self.penalty(delta) - self.penalty(np.zeros_like(delta))))

    def gain(self, extra: np.ndarray | None = None,
             extra_bounds: Sequence[tuple[float, float]] = ()) -> tuple[float, np.ndarray]:
        """(log-posterior gain over the fit window of the step with ``extra`` (:meth:`gain_of`);
        the step)."""
        delta = self.step(self.in_fit, extra, extra_bounds)
        return self.gain_of(self.residual(delta, extra), delta), delta

    def held_out(self, blocks: int, extra: np.ndarray | None = None,
                 extra_bounds: Sequence[tuple[float, float]] = ()) -> np.ndarray:
        """Blocked cross-validation, one step per fold: each of ``blocks`` equal blocks of the run
        held out, the step (with the ``extra`` columns, as :meth:`step`) fitted on the rest (every
        window); the residual of every row where its block was held out [tolerances]."""
        meas = self.cal.measured
        edges = np.linspace(meas.grid_s[0], meas.grid_s[-1], blocks + 1)
        block = block_index(edges, meas.grid_s[self.point])
        held = np.empty_like(self.r0)
        for b in range(blocks):
            out = block == b
            delta = self.step(~out, extra, extra_bounds)
            held[out] = self.residual(delta, extra)[out]
        return held

    def rms_by_channel(self, held: np.ndarray) -> dict[str, float]:
        """Per channel, the RMS of a residual over every row [tolerances]."""
        return {c: float(np.sqrt(np.mean(held[self.channel == j] ** 2)))
                for j, c in enumerate(self.cal.channels) if (self.channel == j).any()}

    def cross_validation_report(self, blocks: int) -> dict:
        """:meth:`held_out` pooled per channel as the report shows it: RMS, max, bias (the
        channel's unit at the edges), the share within the tolerance."""
        held = self.held_out(blocks)
        pooled = {c: error_row(c, held[self.channel == j] * TOLERANCE[c])
                  for j, c in enumerate(self.cal.channels) if (self.channel == j).any()}
        return {"blocks": blocks, "method": "one Gauss-Newton step per fold", "pooled": pooled}


def residual_rows(cal: Calibrator, model: dict[str, np.ndarray]
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(residual [tolerances], channel index, grid index, in the fit window) of every valid
    sample of the run, channel after channel."""
    meas = cal.measured
    idx = [np.flatnonzero(meas.mask(c, "all")) for c in cal.channels]
    r = np.concatenate([(meas.values[c][i] - model[c][i]) / TOLERANCE[c]
                        for c, i in zip(cal.channels, idx, strict=True)])
    ch = np.concatenate([np.full(len(i), j) for j, i in enumerate(idx)])
    pt = np.concatenate(idx)
    return r, ch, pt, meas.fit_points()[pt]


def local(cal: Calibrator, fit: Fit) -> Local:
    """The model of ``fit`` linearized at its parameters (one simulation per free parameter)."""
    gb = cal.gb.variant(fit.effects)
    params = gb.parameters()
    free = list(fit.free)
    r0, ch, pt, in_fit = residual_rows(cal, fit.model)
    z0 = np.array([_to_z(params[k], fit.theta[k]) for k in free])
    lo, hi = z_bounds([params[k] for k in free])
    J = np.empty((len(r0), len(free)))
    prior_rows = np.zeros(len(free))
    prior_z = z0.copy()
    for i, k in enumerate(free):
        p = params[k]
        # step inside the bounds (a parameter on its upper bound steps down)
        h = STEP if z0[i] + STEP <= hi[i] else -STEP
        r1 = residual_rows(cal, gb.simulate({**fit.theta, k: _from_z(p, z0[i] + h)}))[0]
        J[:, i] = (r1 - r0) / h
        if cal.prior and p.prior_sd and k in cal.prior:
            prior_rows[i] = cal.prior_scale / p.prior_sd
            prior_z[i] = _to_z(p, cal.prior[k])
    return Local(cal, fit, ch, pt, in_fit, r0, J, z0, lo, hi, prior_rows, prior_z)


@dataclass
class EffectFit:
    """An effect fitted to the linearized model: its parameters on the fitted scale ``z``
    (and in their units, ``values``), the base parameters' step, the residual of every row
    (linearized) and the log-posterior gain over the fit window (counted in the current
    fit's effective samples), all at the estimate ``z``; the effect's own columns where its
    last step was taken from."""

    label: str
    z: np.ndarray
    values: dict[str, float]
    delta: np.ndarray
    residual: np.ndarray
    columns: np.ndarray
    gain: float
    shift: np.ndarray  # what the effect alone moves every row by [tolerances]


def _columns(at: Callable[[np.ndarray], np.ndarray], z: np.ndarray, r_z: np.ndarray,
             hi: np.ndarray) -> np.ndarray:
    """The residual's forward differences in each of the effect's parameters at ``z``
    (``r_z`` the residual there), stepping back from an upper bound."""
    cols = np.empty((len(r_z), len(z)))
    for i in range(len(z)):
        h = STEP if z[i] + STEP <= hi[i] else -STEP
        zz = z.copy()
        zz[i] += h
        cols[:, i] = (at(zz) - r_z) / h
    return cols


def fit_effect(loc: Local, label: str, start: dict[str, float] | None = None,
               iterations: int = 6) -> EffectFit | None:
    """The effect ``label`` fitted jointly with the base parameters on the linearized model
    ``loc``: the base parameters enter through the Jacobian, the effect's own parameters
    exactly (the model is simulated at their value, and their columns taken there), by a
    few Gauss-Newton iterations within their bounds. ``start``: the effect's parameters to
    start from (default: a tenth into their range). Costs one simulation per iteration and
    parameter, and one more per iteration. None where the model runs away (becomes
    non-finite) wherever the effect was tried: a feedback beyond its stability."""
    cal, fit = loc.cal, loc.fit
    gb = cal.gb.variant(fit.effects + (label,))
    params = effect_of(label).params
    lo, hi = z_bounds(params)
    z_n = np.array([_to_z(p, p.default) for p in params])
    z = np.clip([_to_z(p, (start or {}).get(p.name, p.lo + 0.1 * (p.hi - p.lo)
                                            if p.lo >= 0 else 0.1 * p.hi))
                 for p in params], lo, hi)
    kb = loc.J.shape[1]

    def at(zv: np.ndarray) -> np.ndarray:
        own = {p.name: _from_z(p, float(v)) for p, v in zip(params, zv, strict=True)}
        return residual_rows(cal, gb.simulate({**fit.theta, **own}))[0]

    simulated: dict[bytes, np.ndarray] = {}

    def at_once(zv: np.ndarray) -> np.ndarray:
        key = zv.tobytes()
        if key not in simulated:
            simulated[key] = at(zv)
        return simulated[key]

    def finite(zv: np.ndarray) -> bool:
        # a residual whose sum of squares overflows has no likelihood either
        r = at_once(zv)
        with np.errstate(over="ignore", invalid="ignore"):
            return bool(np.isfinite(np.dot(r, r)))

    r_neutral = at_once(z_n)
    # a feedback beyond its stability (a preload near 1/K) runs away, which no spindle on a
    # bench does: a start or a step that lands there is halved towards where the model is
    for _ in range(30):
        if finite(z):
            break
        z = z_n + 0.5 * (z - z_n)
    best = None
    for _ in range(iterations if finite(z) else 0):
        r_z = at_once(z)
        cols = _columns(at, z, r_z, hi)
        if not np.all(np.isfinite(cols)):  # at the edge of a runaway: stop where it is
            break
        # the base parameters' step from the current model and the effect's from z
        shifted = replace(loc, r0=r_z)
        step = shifted.step(loc.in_fit, cols, list(zip(lo - z, hi - z, strict=True)))
        for _ in range(30):
            z_new = np.clip(z + step[kb:], lo, hi)
            if finite(z_new):
                break
            step = 0.5 * step
        else:
            break
        r1 = shifted.residual(step, cols)
        gain = loc.gain_of(r1, step)
        if not np.isfinite(gain):  # finite but overflowing in the step: a runaway as well
            break
        # the gain is that of the stepped parameters, so the estimate is where the step lands
        # (not where it was taken from: a mount fitted from 0 W/K to 3 W/K has the gain of
        # 3 W/K, and its shift at 0 W/K is nothing)
        if best is None or gain > best[0]:
            best = (gain, z_new.copy(), step[:kb].copy(), r1, cols)
        if np.max(np.abs(z_new - z)) < 1e-4 * np.max(hi - lo):
            break
        z = z_new
    if best is None:  # the model runs away wherever the effect was tried: no estimate
        return None
    gain, z, delta, r1, cols = best
    values = {p.name: _from_z(p, float(v)) for p, v in zip(params, z, strict=True)}
    return EffectFit(label, z, values, delta, r1, cols, float(gain), at_once(z) - r_neutral)


def effect_held_out(loc: Local, ef: EffectFit, blocks: int) -> dict[str, float]:
    """Blocked cross-validation of the model with the effect fitted as ``ef``, one
    Gauss-Newton step per fold on the base parameters and the effect's (its columns at its
    estimate): per channel, the RMS of the held-out residual [tolerances]."""
    around = replace(loc, r0=ef.residual, z0=loc.z0 + ef.delta)
    lo, hi = z_bounds(effect_of(ef.label).params)
    held = around.held_out(blocks, ef.columns, list(zip(lo - ef.z, hi - ef.z, strict=True)))
    return around.rms_by_channel(held)
