"""Calibration of the grey box against a measured bench run.

- **Data.** The measured channels (T1, T2, T_stator in K, P1 in m) are resampled onto the
  model grid (the value at each grid point, linear between valid samples; a point inside a
  logging gap, Criteria.gap_min_steps, is left out). The run is split in time: the first part
  (default 60 %) is the fit window, the rest the validation window.
- **Weighted least squares** (scipy.optimize.least_squares): residuals are divided by the
  channel's tolerance (1 K, 1.5 µm, paper section 3), so the channels weigh alike at their
  tolerance. Parameters are fitted on a log scale (factors) or scaled to their bounds.
- **Confidence intervals** from the Jacobian: cov = s^2 (J^T J)^-1 with s^2 the residual
  variance, inflated by n / n_eff for the residual's autocorrelation (n_eff = n / tau_int with
  tau_int the integrated autocorrelation time: compare.residuals.effective_samples), 95 %
  intervals; correlations; a parameter is reported not identifiable when its interval spans
  more than its bounds' range (a direction the information matrix does not determine counts
  with an eigenvalue of 1e-12 of the largest: it takes the parameters that share it out of
  their bounds, and leaves the others alone).
- **Priors** (when :meth:`Calibrator.set_prior` is called, as ``fit`` does): each base
  parameter is Gaussian around the spec's value on its fitted scale, with the width
  ``Param.prior_sd``; the data term is weighted by n_eff / n against them.
- **Likelihood** (unknown variance per channel, Gaussian): l = -1/2 sum_c n_c ln(RSS_c / n_c).
  A richer model is tested against the nested one by LR = 2 [(l1 - l0) n_eff / n -
  (penalty1 - penalty0)] ~ chi2(k) (k its added parameters; the autocorrelation correction
  keeps serially correlated residuals from passing as independent evidence). The selection
  of effects (compare.fit.select) computes it on the linearized model (compare.fit.linear),
  as it does the blocked cross-validation.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from compare.fit.effects import LIBRARY, effect_of
from compare.fit.greybox import GreyBox
from compare.fit.params import BASE_PARAMS, EXTRA_BASE_PARAMS, PREHISTORY, PREHISTORY_HEAT, Param
from compare.forked import ForkedColumns
from compare.residuals import effective_samples
from spindle.tolerances import channel_tolerance, edge_scale, edge_unit

#: the paper's tolerance per bench channel [K; m for P1] (spindle.tolerances)
TOLERANCE = {c: channel_tolerance(c) for c in ("T1", "T2", "T_stator", "P1")}


def block_index(edges: np.ndarray, t_s: np.ndarray) -> np.ndarray:
    """Index of the block [edges[i], edges[i + 1]) each time [s] lies in, the last block
    closed at its end and times outside taken into the nearest block."""
    return np.clip(np.searchsorted(edges, t_s, side="right") - 1, 0, len(edges) - 2)


@dataclass
class Measured:
    """Measured channels on the model grid (NaN where not measured), and the windows.

    ``blocks`` = 1: the fit window is the first ``fit_fraction`` of the run, the rest
    validates. ``blocks`` > 1: the run is cut into that many equal blocks and about
    ``1 - fit_fraction`` of them, spread over the run, validate (issue 13 §4: a cycle that
    ramps up would otherwise be validated only on speeds the fit never saw). ``held_out``:
    one block validates and every other fits (a fold of blocked cross-validation)."""

    grid_s: np.ndarray
    values: dict[str, np.ndarray]
    fit_fraction: float = 0.6
    blocks: int = 1
    held_out: int | None = None
    _fit_points: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        g = np.asarray(self.grid_s, dtype=float)
        if self.blocks <= 1:
            self._fit_points = g <= self.split_s
            return
        block = block_index(np.linspace(g[0], g[-1], self.blocks + 1), g)
        self._fit_points = ~np.isin(block, self.validation_blocks())

    @property
    def split_s(self) -> float:
        """End of the fit window of a one-split scheme [s]."""
        return float(self.grid_s[0] + self.fit_fraction * (self.grid_s[-1] - self.grid_s[0]))

    def validation_blocks(self) -> list[int]:
        """The validating blocks: ``held_out``, or round(blocks (1 - fit_fraction)) of them
        at even spacing (5 blocks at 0.6: the 2nd and the 4th)."""
        if self.held_out is not None:
            return [self.held_out]
        n_val = int(round(self.blocks * (1.0 - self.fit_fraction)))
        return sorted({int((i + 0.5) * self.blocks / n_val) for i in range(n_val)})

    def fit_points(self) -> np.ndarray:
        """True at the grid points of the fit window."""
        return self._fit_points

    def spans(self) -> list[tuple[float, float, str]]:
        """The windows as contiguous (start [s], end [s], "fit" | "validation") spans."""
        g, f = np.asarray(self.grid_s, dtype=float), self._fit_points
        cut = np.flatnonzero(f[1:] != f[:-1]) + 1
        starts, ends = np.r_[0, cut], np.r_[cut, len(g)]
        return [(float(g[a] if a == 0 else g[a - 1]), float(g[b - 1]),
                 "fit" if f[a] else "validation") for a, b in zip(starts, ends, strict=True)]

    def mask(self, channel: str, window: str) -> np.ndarray:
        ok = ~np.isnan(self.values[channel])
        if window == "fit":
            return ok & self._fit_points
        if window == "validation":
            return ok & ~self._fit_points
        return ok


# ---------------------------------------------------------------------- scaling of parameters
def _to_z(p: Param, v: float) -> float:
    return math.log(v) if p.log else (v - p.lo) / (p.hi - p.lo)


def _from_z(p: Param, z: float) -> float:
    return math.exp(z) if p.log else p.lo + z * (p.hi - p.lo)


def z_bounds(params: Sequence[Param]) -> tuple[np.ndarray, np.ndarray]:
    """(lower, upper) bounds of ``params`` on their fitted scale."""
    b = np.array([(_to_z(p, p.lo), _to_z(p, p.hi)) for p in params], dtype=float).reshape(-1, 2)
    return b[:, 0], b[:, 1]


def concentrated_loglik(residuals: Iterable[np.ndarray]) -> float:
    """-1/2 sum_c n_c ln(RSS_c / n_c) over the channels' residuals (an unknown variance per
    channel, Gaussian: module docstring)."""
    return sum(-0.5 * len(r) * math.log(max(float(np.mean(r * r)), 1e-300))
               for r in residuals if len(r))


@dataclass
class Fit:
    """One calibration: parameters, their intervals and correlations, errors, likelihood."""

    effects: tuple[str, ...]  # labels (compare.fit.effects.label)
    theta: dict[str, float]
    free: list[str]
    ci95: dict[str, tuple[float, float]]
    correlation: np.ndarray
    identifiable: dict[str, bool]
    loglik: float
    n: int
    n_eff: float
    model: dict[str, np.ndarray]
    errors: dict[str, dict[str, dict[str, float]]]  # window -> channel -> error_row and rmse_w [tolerances]
    nfev: int = 0
    penalty: float = 0.0  # 1/2 sum ((z - z_ref) / sd)^2 over the free parameters with a prior
    #: for a parameter the run does not determine alone, the one it is determined with:
    #: (name, correlation), where fixing that one would make it identifiable (_intervals)
    partners: dict[str, tuple[str, float]] = field(default_factory=dict)

    @property
    def sample_share(self) -> float:
        """n_eff / n: the share of the residual's samples the likelihood counts as independent
        (every log-likelihood gain of the selection is weighed by it)."""
        return self.n_eff / max(self.n, 1)

    def log_posterior(self, share: float) -> float:
        """The log-posterior with the data counted at ``share`` (n_eff / n) of its samples, as
        the selection counts every gain: loglik x share less the prior penalty."""
        return self.loglik * share - self.penalty

    def validation_score(self) -> float:
        """Weighted RMS over the validation window (tolerance units)."""
        vals = [e["rmse_w"] for e in self.errors["validation"].values() if e["n"] > 0]
        return float(np.sqrt(np.mean(np.square(vals)))) if vals else math.nan


@dataclass
class Calibrator:
    """Fits a :class:`GreyBox` to :class:`Measured` data."""

    gb: GreyBox
    measured: Measured
    channels: Sequence[str]
    max_nfev: int = 60
    #: least_squares' ftol and xtol (compare.fit.criteria.Criteria.optimizer_tol)
    tol: float = 1e-6
    #: prior centres (the spec's values, compare.fit.discrepancy); the widths are Param.prior_sd
    prior: dict[str, float] | None = None
    #: sqrt(s^2 n / n_eff) of the data term, so that data and prior weigh as a posterior
    prior_scale: float = 1.0
    #: per channel, the validation RMS [tolerance units] no effect can remove: the sensor
    #: noise (set_floor); None counts the whole validation error
    floor: dict[str, float] | None = None
    #: what the selection computes once per calibrator (compare.fit.competitor's columns)
    memo: dict = field(default_factory=dict, repr=False)
    #: processes that evaluate a Jacobian's columns (compare.forked; 1: this one alone)
    workers: int = 1

    def set_floor(self, fit: Fit) -> None:
        """The floor from the noise of ``fit``'s residual, estimated from its second differences
        (var(d2 r) = 6 sigma^2 for white noise; the smooth model-form part hardly enters them)."""
        self.floor = {c: float(np.sqrt(np.var(np.diff(r, 2)) / 6.0)) if len(r) > 3 else 0.0
                      for c, r in self.residuals(fit.model, "all").items()}

    def fit_with_prior(self, centre: dict[str, float], start: dict[str, float] | None = None
                       ) -> tuple[Fit, Fit]:
        """(fit without priors, fit with priors around ``centre``): the first sets the data's
        weight against the priors and the noise floor (set_prior, set_floor), the second
        starts where it ended."""
        free_fit = self.fit(start=start)
        self.set_prior(centre, free_fit)
        self.set_floor(free_fit)
        return free_fit, self.fit(start=free_fit.theta)

    def prior_z(self, fit: Fit) -> dict[str, float]:
        """Each base parameter's distance from its prior centre in prior standard deviations
        (empty without priors)."""
        if not self.prior:
            return {}
        params = self.gb.variant(fit.effects).parameters()
        return {k: (_to_z(params[k], fit.theta[k]) - _to_z(params[k], self.prior[k]))
                / params[k].prior_sd for k in fit.free
                if params[k].prior_sd and k in self.prior}

    def set_prior(self, centre: dict[str, float], fit: Fit) -> None:
        """Priors around ``centre``, weighed against the data by ``fit``'s residual variance
        and effective sample size (held fixed from then on, so likelihoods stay comparable)."""
        r = np.concatenate(list(self.residuals(fit.model, "fit").values()))
        self.prior = dict(centre)
        self.prior_scale = float(np.sqrt(np.mean(r * r) * fit.n / fit.n_eff))

    def _prior_terms(self, params: dict[str, Param], free: Sequence[str],
                     z: np.ndarray) -> np.ndarray:
        return np.asarray([(v - _to_z(params[k], self.prior[k])) / params[k].prior_sd
                           for k, v in zip(free, z, strict=True)
                           if self.prior and params[k].prior_sd and k in self.prior])

    def residuals(self, out: dict[str, np.ndarray], window: str) -> dict[str, np.ndarray]:
        """Measured minus ``out`` per channel on ``window``'s samples [tolerances]."""
        masks = {c: self.measured.mask(c, window) for c in self.channels}
        return {c: (self.measured.values[c][m] - out[c][m]) / TOLERANCE[c]
                for c, m in masks.items()}

    def errors(self, out: dict[str, np.ndarray]) -> dict[str, dict[str, dict[str, float]]]:
        errs: dict[str, dict[str, dict[str, float]]] = {"fit": {}, "validation": {}}
        for window, rows in errs.items():
            for c in self.channels:
                m = self.measured.mask(c, window)
                d = self.measured.values[c][m] - out[c][m]
                rows[c] = {"n": 0} if len(d) == 0 else {
                    **error_row(c, d), "rmse_w": float(np.sqrt(np.mean(d * d)) / TOLERANCE[c])}
        return errs

    def fit(self, effects: tuple[str, ...] = (), free: Sequence[str] | None = None,
            start: dict[str, float] | None = None, max_nfev: int | None = None) -> Fit:
        """Weighted least squares over ``free`` (default: every parameter of the model with
        the effects ``effects``, labels)."""
        from scipy.optimize import least_squares

        gb = self.gb.variant(effects)
        params = gb.parameters()
        free = list(free) if free is not None else list(params)
        theta = {k: p.default for k, p in params.items()}
        theta.update({k: v for k, v in (start or {}).items() if k in params})
        for k in free:  # keep the start strictly inside the bounds
            p = params[k]
            theta[k] = min(max(theta[k], p.lo + 1e-9 * (p.hi - p.lo)), p.hi)
        lo, hi = z_bounds([params[k] for k in free])
        z0 = np.clip(np.array([_to_z(params[k], theta[k]) for k in free]), lo, hi)
        nfev = 0

        def vec(z: np.ndarray) -> np.ndarray:
            nonlocal nfev
            nfev += 1
            th = dict(theta)
            th.update({k: _from_z(params[k], float(v)) for k, v in zip(free, z, strict=True)})
            out = gb.simulate(th)
            return np.concatenate([*self.residuals(out, "fit").values(),
                                   self.prior_scale * self._prior_terms(params, free, z)])

        costly = set(gb.matrix_params())
        with ForkedColumns(vec, [k in costly for k in free], self.workers) as columns:
            sol = least_squares(vec, z0, bounds=(lo, hi), diff_step=1e-4, x_scale="jac",
                                max_nfev=max_nfev or self.max_nfev, ftol=self.tol,
                                xtol=self.tol, workers=columns)
        nfev += columns.child_evaluations
        theta.update({k: _from_z(params[k], float(v)) for k, v in zip(free, sol.x, strict=True)})
        out = gb.simulate(theta)
        res = self.residuals(out, "fit")
        r_all = np.concatenate(list(res.values()))
        n = len(r_all)
        n_eff = max(effective_samples(res), len(free) + 2.0)
        J = sol.jac[:n]  # the data rows: the intervals say what this run alone determines
        penalty = 0.5 * float(np.sum(self._prior_terms(params, free, sol.x) ** 2))
        ci, corr, ident, partners = _intervals(J, r_all, n, n_eff, free, params, sol.x)
        return Fit(tuple(effects), theta, free, ci, corr, ident,
                   concentrated_loglik(res.values()), n, n_eff, out, self.errors(out),
                   nfev, penalty, partners)


def over_tolerance(window_errors: Mapping[str, Mapping[str, float]]) -> dict[str, float]:
    """The channels of one window of :meth:`Calibrator.errors` whose RMS exceeds one
    tolerance, with that RMS in tolerances (channels without samples are left out). The one
    test of 'misses its tolerance' that the adequacy verdict, the held-out rules of the
    selection and the report's verdict read."""
    return {c: float(e["rmse_w"]) for c, e in window_errors.items()
            if e.get("n") and e["rmse_w"] > 1.0}


def _intervals(J: np.ndarray, r: np.ndarray, n: int, n_eff: float, free: list[str],
               params: dict[str, Param], z: np.ndarray):
    """95 % intervals in the parameters' own units, correlations, identifiability, and for
    each parameter that is not identifiable the one it is determined with: the parameter of
    largest |correlation| r, where with that one fixed its interval (sd sqrt(1 - r^2)) would
    fit its range. Where none would, the run leaves it free with several others."""
    p = len(free)
    s2 = float(np.dot(r, r)) / max(n - p, 1) * (n / n_eff)
    ci: dict[str, tuple[float, float]] = {}
    ident: dict[str, bool] = {}
    try:
        # the inverse by eigenvalues, each at least 1e-12 of the largest (double precision's
        # digits): a direction the run does not determine (a parameter at a value where it
        # does nothing, a column of zeros) gets an interval wider than any bounds, and only
        # the parameters that share it lose theirs. A pseudo-inverse would give it none.
        w, V = np.linalg.eigh(J.T @ J)
        w = np.maximum(w, 1e-12 * max(float(w.max()), np.finfo(float).tiny))
        cov = (V / w) @ V.T * s2
    except np.linalg.LinAlgError:
        cov = np.full((p, p), np.nan)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    partners: dict[str, tuple[str, float]] = {}
    for i, k in enumerate(free):
        pr = params[k]
        lo_z, hi_z = z[i] - 1.96 * sd[i], z[i] + 1.96 * sd[i]
        b_lo, b_hi = _to_z(pr, pr.lo), _to_z(pr, pr.hi)
        ci[k] = (_from_z(pr, max(lo_z, b_lo)), _from_z(pr, min(hi_z, b_hi)))
        ident[k] = bool(np.isfinite(sd[i]) and 3.92 * sd[i] < (b_hi - b_lo))
        if ident[k] or p < 2 or not np.isfinite(sd[i]):
            continue
        rho = np.nan_to_num(corr[i])  # a copy
        rho[i] = 0.0
        j = int(np.argmax(np.abs(rho)))
        if 3.92 * sd[i] * np.sqrt(max(1.0 - rho[j] ** 2, 0.0)) < (b_hi - b_lo):
            partners[k] = (free[j], float(rho[j]))
    return ci, corr, ident, partners


# ---------------------------------------------------------------------- tests

def at_bound(fit: Fit, effect_label: str, rel: float) -> list[str]:
    """The parameters of the effect ``effect_label`` whose calibrated value lies on the bound
    of its range away from the neutral value (within ``rel`` of the range)."""
    return [p.name for p in effect_of(effect_label).params
            if (p.hi != p.default and fit.theta[p.name] >= p.hi - rel * (p.hi - p.lo))
            or (p.lo != p.default and fit.theta[p.name] <= p.lo + rel * (p.hi - p.lo))]


def parameters_table(fit: Fit) -> list[dict]:
    params = {**BASE_PARAMS, **EXTRA_BASE_PARAMS, PREHISTORY.name: PREHISTORY,
              **{p.name: p for p in PREHISTORY_HEAT.values()},
              **{p.name: p for e in LIBRARY.values() for p in e.params}}
    return [{"name": k, "unit": params[k].unit, "value": fit.theta[k], "ci95": list(fit.ci95[k]),
             "identifiable": fit.identifiable[k], "meaning": params[k].doc,
             "source": params[k].source} for k in fit.free]


def error_row(channel: str, d: np.ndarray) -> dict:
    """rmse, max, bias (channel unit at the edges: K or um) and within_tolerance of
    differences ``d`` [SI]; the errors of Calibrator.errors and Local.cross_validation_report."""
    scale, unit = edge_scale(channel), edge_unit(channel, ascii=True)
    return {"rmse": float(np.sqrt(np.mean(d * d)) * scale),
            "max": float(np.max(np.abs(d)) * scale), "bias": float(np.mean(d) * scale),
            "unit": unit,
            "within_tolerance": float(np.mean(np.abs(d) <= TOLERANCE[channel])), "n": int(len(d))}
