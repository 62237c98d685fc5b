"""Calibration and forward selection of effects against a measured bench run.

- **Data.** The measured channels (T1, T2, T_stator in K, P1 in m) are resampled onto the
  model grid (the value at each grid point, linear between valid samples; a point inside a
  gap of more than two grid steps is left out). The run is split in time: the first part
  (default 60 %) is the fit window, the rest the validation window.
- **Weighted least squares** (scipy.optimize.least_squares): residuals are divided by the
  channel's tolerance (1 K, 1.5 µm, paper section 3), so the channels weigh alike at their
  tolerance. Parameters are fitted on a log scale (factors) or scaled to their bounds.
- **Confidence intervals** from the Jacobian: cov = s^2 (J^T J)^-1 with s^2 the residual
  variance, inflated by n / n_eff for the residual's autocorrelation (n_eff = n / tau_int with
  tau_int the integrated autocorrelation time, see :func:`effective_samples`), 95 % intervals;
  correlations; a parameter is
  reported not identifiable when its interval spans more than its bounds' range or the
  information matrix is numerically singular.
- **Priors** (when :meth:`Calibrator.set_prior` is called, as ``fit`` does): each base
  parameter is Gaussian around the spec's value on its fitted scale, with the width
  ``Param.prior_sd``; the data term is weighted by n_eff / n against them.
- **Likelihood** (unknown variance per channel, Gaussian): l = -1/2 sum_c n_c ln(RSS_c / n_c).
  An effect qualifies by a likelihood-ratio test against the model without it:
  LR = 2 [(l1 - l0) n_eff / n - (penalty1 - penalty0)] ~ chi2(k) (k its parameters; the
  autocorrelation correction keeps serially correlated residuals from passing as independent
  evidence), at level ``alpha`` (default 1 %), and only if it is needed: it removes at least
  ``min_gain`` (default 25 %) of the validation error above the noise floor, or without it a
  base parameter lies beyond the (1 - alpha) prior range and with it all lie within the
  central 95 %. Of the qualifying candidates the best likelihood is accepted (Bacher and
  Madsen 2011, forward selection, with these two guards; docs/fit.md says why).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple, TypeVar

import numpy as np

from compare.fit.events import EventTest
from compare.fit.greybox import BASE_PARAMS, EFFECTS, EXTRA_BASE_PARAMS, GreyBox, Param
from spindle.tolerances import channel_tolerance, edge_scale, edge_unit

#: |z| of every base parameter after an effect that is needed for plausibility (95 % central)
RESTORED_Z = 1.96
#: the least an effect named by the open-loop loop must move one of its channels, at its
#: peak over the run, in tolerances (1 K, 1.5 um): less cannot change what a compensation
#: within those tolerances does. Measured (docs/fit.md, *Materiality*): with the base model
#: fitting a mismatched spindle to the noise, a fixture term of 0.26-0.65 um at its peak
#: passed the relative gains on excesses near zero; the true ones of the matrix and the
#: injected cases peak at 1.6-6 um
MATERIAL_PEAK = 0.5
#: the paper's tolerance per bench channel [K; m for P1] (spindle.tolerances)
TOLERANCE = {c: channel_tolerance(c) for c in ("T1", "T2", "T_stator", "P1")}


def implausible_z(alpha: float) -> float:
    """The prior |z| beyond which a base parameter is implausible: two-sided at ``alpha``."""
    from scipy.stats import norm

    return float(norm.isf(alpha / 2))


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
        block = self.block_of(g)
        self._fit_points = ~np.isin(block, self.validation_blocks())

    @property
    def split_s(self) -> float:
        """End of the fit window of a one-split scheme [s]."""
        return float(self.grid_s[0] + self.fit_fraction * (self.grid_s[-1] - self.grid_s[0]))

    def block_edges(self) -> np.ndarray:
        """The blocks' bounds [s]: ``blocks`` equal parts of the grid's span."""
        return np.linspace(self.grid_s[0], self.grid_s[-1], self.blocks + 1)

    def block_of(self, t_s: np.ndarray) -> np.ndarray:
        """Index of the block each time [s] lies in."""
        return np.clip(np.searchsorted(self.block_edges(), t_s, side="right") - 1, 0,
                       self.blocks - 1)

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


def resample(t_s: np.ndarray, y: np.ndarray, grid_s: np.ndarray) -> np.ndarray:
    """Values at the grid points: linear between valid samples; NaN outside the samples and
    inside gaps longer than two grid steps."""
    ok = ~np.isnan(y)
    t, v = t_s[ok], y[ok]
    out = np.full(len(grid_s), np.nan)
    if len(t) < 2:
        return out
    inside = (grid_s >= t[0]) & (grid_s <= t[-1])
    out[inside] = np.interp(grid_s[inside], t, v)
    step = np.median(np.diff(grid_s))
    k = np.clip(np.searchsorted(t, grid_s), 1, len(t) - 1)
    gap = (t[k] - t[k - 1]) > 2 * step
    out[gap & inside] = np.nan
    return out


# ---------------------------------------------------------------------- scaling of parameters
def _to_z(p: Param, v: float) -> float:
    if p.log:
        return math.log(v)
    return (v - p.lo) / (p.hi - p.lo)


def _from_z(p: Param, z: float) -> float:
    if p.log:
        return math.exp(z)
    return p.lo + z * (p.hi - p.lo)


def _bounds_z(p: Param) -> tuple[float, float]:
    return (_to_z(p, p.lo), _to_z(p, p.hi))


@dataclass
class Fit:
    """One calibration: parameters, their intervals and correlations, errors, likelihood."""

    effects: tuple[str, ...]
    lag_channel: str | None
    theta: dict[str, float]
    free: list[str]
    ci95: dict[str, tuple[float, float]]
    correlation: np.ndarray
    identifiable: dict[str, bool]
    loglik: float
    n: int
    n_eff: float
    model: dict[str, np.ndarray]
    errors: dict[str, dict[str, dict[str, float]]]  # window -> channel -> rmse, max, within
    runtime_s: float = 0.0
    nfev: int = 0
    penalty: float = 0.0  # 1/2 sum ((z - z_ref) / sd)^2 over the free parameters with a prior

    @property
    def k(self) -> int:
        return len(self.free)

    def bic(self) -> float:
        return -2 * self.loglik + self.k * math.log(max(self.n_eff, 2.0))

    def validation_score(self) -> float:
        """Weighted RMS over the validation window (tolerance units)."""
        v = self.errors["validation"]
        vals = [v[c]["rmse_w"] for c in v if v[c]["n"] > 0]
        return float(np.sqrt(np.mean(np.square(vals)))) if vals else math.nan


@dataclass
class Calibrator:
    """Fits a :class:`GreyBox` to :class:`Measured` data."""

    gb: GreyBox
    measured: Measured
    channels: Sequence[str]
    max_nfev: int = 60
    progress: Callable[[str], None] | None = None
    evaluations: int = field(default=0)
    #: prior centres (the spec's values, compare.fit.discrepancy); the widths are Param.prior_sd
    prior: dict[str, float] | None = None
    #: sqrt(s^2 n / n_eff) of the data term, so that data and prior weigh as a posterior
    prior_scale: float = 1.0
    #: per channel, the validation RMS [tolerance units] no effect can remove: the sensor
    #: noise (set_floor); None counts the whole validation error
    floor: dict[str, float] | None = None
    #: priors on effect parameters read from the run's events (compare.fit.events): name ->
    #: (centre in the parameter's units, sd on its fitted scale)
    event_prior: dict[str, tuple[float, float]] = field(default_factory=dict)

    def set_floor(self, fit: Fit) -> None:
        """The floor from the noise of ``fit``'s residual, estimated from its second
        differences (var(d2 r) = 6 sigma^2 for white noise; the smooth model-form part hardly
        enters them)."""
        floor = {}
        for c in self.channels:
            m = self.measured.mask(c, "all")
            r = (self.measured.values[c][m] - fit.model[c][m]) / TOLERANCE[c]
            floor[c] = float(np.sqrt(np.var(np.diff(r, 2)) / 6.0)) if len(r) > 3 else 0.0
        self.floor = floor

    def fit_with_prior(self, centre: dict[str, float], start: dict[str, float] | None = None,
                       free_nfev: int | None = None,
                       say: Callable[[str], None] | None = None) -> tuple[Fit, Fit]:
        """(fit without priors, fit with priors around ``centre``): the first sets the data's
        weight against the priors and the noise floor (set_prior, set_floor), the second
        starts where it ended."""
        free_fit = self.fit(start=start, max_nfev=free_nfev)
        self.set_prior(centre, free_fit)
        self.set_floor(free_fit)
        if say is not None:
            say("calibrating with priors")
        return free_fit, self.fit(start=free_fit.theta)

    def prior_z(self, fit: Fit) -> dict[str, float]:
        """Each base parameter's distance from its prior centre in prior standard deviations
        (empty without priors)."""
        if not self.prior:
            return {}
        params = self.gb.variant(fit.effects, fit.lag_channel).parameters()
        return {k: (_to_z(params[k], fit.theta[k]) - _to_z(params[k], self.prior[k]))
                / params[k].prior_sd for k in fit.free
                if params[k].prior_sd and k in self.prior}

    def implausible(self, fit: Fit, alpha: float) -> list[str]:
        """The base parameters outside their two-sided (1 - alpha) prior range."""
        z_crit = implausible_z(alpha)
        return [k for k, z in self.prior_z(fit).items() if abs(z) > z_crit]

    def comfortable(self, fit: Fit) -> bool:
        """Every base parameter inside the central 95 % of its prior (|z| <= 1.96): the bar
        an effect must clear to count as restoring plausibility, well inside the 1 % bar
        that called it implausible, so that nudging a parameter just across does not count."""
        return all(abs(z) <= RESTORED_Z for z in self.prior_z(fit).values())

    def effect_peak(self, fit: Fit, name: str, channels: Sequence[str]) -> float:
        """The largest change effect ``name`` makes in ``fit``'s model over the run, on
        ``channels``, in tolerances: ``fit`` against the same parameters with the effect's at
        their neutral values (the base model is nested)."""
        neutral = dict(fit.theta)
        neutral.update({p.name: p.default for p in EFFECTS[name].params})
        without = self.gb.variant(fit.effects, fit.lag_channel).simulate(neutral)
        return max((float(np.nanmax(np.abs(fit.model[c] - without[c]))) / TOLERANCE[c]
                    for c in channels if c in fit.model), default=0.0)

    def validation_excess(self, fit: Fit, channels: Sequence[str] | None = None) -> float:
        """Mean square validation error above the floor, summed over ``channels`` (default:
        all) [tolerance units squared]: what an effect could still explain."""
        total = 0.0
        for c, e in fit.errors["validation"].items():
            if e.get("n") and (channels is None or c in channels):
                f = (self.floor or {}).get(c, 0.0)
                total += max(e["rmse_w"] ** 2 - f * f, 0.0)
        return total

    def set_prior(self, centre: dict[str, float], fit: Fit) -> None:
        """Priors around ``centre``, weighed against the data by ``fit``'s residual variance
        and effective sample size (held fixed from then on, so likelihoods stay comparable)."""
        r = np.concatenate(list(self.residuals(fit.model, "fit").values()))
        self.prior = dict(centre)
        self.prior_scale = float(np.sqrt(np.mean(r * r) * fit.n / fit.n_eff))

    def _prior_terms(self, params: dict[str, Param], free: Sequence[str],
                     z: np.ndarray) -> np.ndarray:
        out = []
        for k, v in zip(free, z, strict=True):
            p = params[k]
            if self.prior and p.prior_sd and k in self.prior:
                out.append((v - _to_z(p, self.prior[k])) / p.prior_sd)
            elif k in self.event_prior:
                centre, sd = self.event_prior[k]
                out.append((v - _to_z(p, centre)) / sd)
        return np.asarray(out)

    def set_event_prior(self, name: str, value: float, ci95: Sequence[float]) -> float:
        """A prior on effect parameter ``name`` from an event test: centred on ``value``
        (clipped into the bounds), with the sd of its 95 % interval ``ci95`` on the fitted
        scale. Returns the centre (a start for the fit)."""
        p = next(q for e in EFFECTS.values() for q in e.params if q.name == name)
        floor = 1e-12 if p.log else -math.inf  # the log scale needs v > 0
        lo, hi, centre = (min(max(v, p.lo, floor), p.hi) for v in (*ci95, value))
        self.event_prior[name] = (centre, max((_to_z(p, hi) - _to_z(p, lo)) / 3.92, 1e-3))
        return centre

    def residuals(self, out: dict[str, np.ndarray], window: str) -> dict[str, np.ndarray]:
        res = {}
        for c in self.channels:
            m = self.measured.mask(c, window)
            res[c] = (self.measured.values[c][m] - out[c][m]) / TOLERANCE[c]
        return res

    def loglik(self, res: dict[str, np.ndarray]) -> float:
        total = 0.0
        for r in res.values():
            if len(r):
                total += -0.5 * len(r) * math.log(max(float(np.mean(r * r)), 1e-300))
        return total

    def errors(self, out: dict[str, np.ndarray]) -> dict[str, dict[str, dict[str, float]]]:
        errs: dict[str, dict[str, dict[str, float]]] = {}
        for window in ("fit", "validation"):
            errs[window] = {}
            for c in self.channels:
                m = self.measured.mask(c, window)
                d = self.measured.values[c][m] - out[c][m]
                if len(d) == 0:
                    errs[window][c] = {"n": 0}
                    continue
                row = _error_row(c, d)
                unit = row["unit"]
                errs[window][c] = {
                    "n": row["n"], f"rmse_{unit}": row["rmse"], f"max_{unit}": row["max"],
                    f"bias_{unit}": row["bias"], "within_tolerance": row["within_tolerance"],
                    "rmse_w": float(np.sqrt(np.mean(d * d)) / TOLERANCE[c])}
        return errs

    def fit(self, effects: tuple[str, ...] = (), free: Sequence[str] | None = None,
            start: dict[str, float] | None = None, lag_channel: str | None = None,
            max_nfev: int | None = None) -> Fit:
        """Weighted least squares over ``free`` (default: every parameter of the model)."""
        from scipy.optimize import least_squares

        t0 = time.perf_counter()
        gb = self.gb.variant(effects, lag_channel)
        params = gb.parameters()
        free = list(free) if free is not None else list(params)
        theta = {k: p.default for k, p in params.items()}
        theta.update({k: v for k, v in (start or {}).items() if k in params})
        for k in free:  # keep the start strictly inside the bounds
            p = params[k]
            theta[k] = min(max(theta[k], p.lo + 1e-9 * (p.hi - p.lo)), p.hi)
        z0 = np.array([_to_z(params[k], theta[k]) for k in free])
        lo = np.array([_bounds_z(params[k])[0] for k in free])
        hi = np.array([_bounds_z(params[k])[1] for k in free])
        z0 = np.clip(z0, lo, hi)
        nfev = 0

        def vec(z: np.ndarray) -> np.ndarray:
            nonlocal nfev
            nfev += 1
            th = dict(theta)
            th.update({k: _from_z(params[k], float(v)) for k, v in zip(free, z, strict=True)})
            out = gb.simulate(th)
            return np.concatenate([*self.residuals(out, "fit").values(),
                                   self.prior_scale * self._prior_terms(params, free, z)])

        sol = least_squares(vec, z0, bounds=(lo, hi), diff_step=1e-4, x_scale="jac",
                            max_nfev=max_nfev or self.max_nfev, ftol=1e-6, xtol=1e-6)
        theta.update({k: _from_z(params[k], float(v)) for k, v in zip(free, sol.x, strict=True)})
        out = gb.simulate(theta)
        res = self.residuals(out, "fit")
        r_all = np.concatenate(list(res.values()))
        n = len(r_all)
        n_eff = max(effective_samples(res), len(free) + 2.0)
        J = sol.jac[:n]  # the data rows: the intervals say what this run alone determines
        penalty = 0.5 * float(np.sum(self._prior_terms(params, free, sol.x) ** 2))
        ci, corr, ident = _intervals(J, r_all, n, n_eff, free, params, sol.x)
        self.evaluations += nfev
        return Fit(effects, lag_channel, theta, free, ci, corr, ident, self.loglik(res), n, n_eff,
                   out, self.errors(out), time.perf_counter() - t0, nfev, penalty)


def effective_samples(res: dict[str, np.ndarray]) -> float:
    """Sum over channels of n / tau_int, tau_int = 1 + 2 sum_k rho_k the integrated
    autocorrelation time of the residual (Sokal's self-consistent window M >= 5 tau), so that
    serially correlated residuals count as the independent samples they are worth."""
    total = 0.0
    for r in res.values():
        n = len(r)
        if n < 4:
            total += n
            continue
        rc = r - r.mean()
        f = np.fft.rfft(rc, 2 * n)
        ac = np.fft.irfft(f * np.conj(f))[:n]
        rho = ac / ac[0] if ac[0] > 0 else np.zeros(n)
        tau = 1.0
        for m in range(1, n // 2):
            tau += 2 * rho[m]
            if m >= 5 * tau:
                break
        total += n / max(tau, 1.0)
    return total


def _intervals(J: np.ndarray, r: np.ndarray, n: int, n_eff: float, free: list[str],
               params: dict[str, Param], z: np.ndarray):
    """95 % intervals in the parameters' own units, correlations, identifiability."""
    p = len(free)
    s2 = float(np.dot(r, r)) / max(n - p, 1) * (n / n_eff)
    JtJ = J.T @ J
    ci: dict[str, tuple[float, float]] = {}
    ident: dict[str, bool] = {}
    try:
        cond = np.linalg.cond(JtJ)
        cov = np.linalg.pinv(JtJ) * s2
    except np.linalg.LinAlgError:
        cond, cov = math.inf, np.full((p, p), np.nan)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    for i, k in enumerate(free):
        pr = params[k]
        lo_z, hi_z = z[i] - 1.96 * sd[i], z[i] + 1.96 * sd[i]
        b_lo, b_hi = _bounds_z(pr)
        ci[k] = (_from_z(pr, max(lo_z, b_lo)), _from_z(pr, min(hi_z, b_hi)))
        ident[k] = bool(np.isfinite(sd[i]) and cond < 1e12 and 3.92 * sd[i] < (b_hi - b_lo))
    return ci, corr, ident


# ---------------------------------------------------------------------- forward selection
@dataclass
class Step:
    """One accepted effect: its fit, the test against the model before it."""

    effect: str
    fit: Fit
    lr: float
    p_value: float
    delta_bic: float
    validation_before: float
    validation_after: float
    needed_by: str = "validation"  # or "plausibility", "event" (forward_selection)


@dataclass
class Selection:
    base: Fit
    steps: list[Step]
    tried: list[dict]  # every candidate of every round: name, p, validation, accepted

    @property
    def final(self) -> Fit:
        return self.steps[-1].fit if self.steps else self.base


def log_posterior_gain(before: Fit, after: Fit) -> float:
    """Log-likelihood gain of ``after`` over ``before``, counted in effective samples
    (n_eff / n), minus the rise of the prior penalty."""
    return ((after.loglik - before.loglik) * after.n_eff / after.n
            - (after.penalty - before.penalty))


def lr_test(before: Fit, after: Fit) -> tuple[float, float]:
    """(LR statistic corrected for autocorrelation, p-value) of ``after`` against the nested
    ``before``."""
    from scipy.stats import chi2

    k = max(after.k - before.k, 1)
    lr = max(2.0 * log_posterior_gain(before, after), 0.0)
    return lr, float(chi2.sf(lr, k))


#: effects with an instantaneous signature, judged on the run's events where a test applies
#: (compare.fit.events) rather than on the open-loop fit, whose slow misfit they cannot mimic
EVENT_EFFECTS = ("centrifugal_shortening", "sensor_lag", "bearing_preload", "windage_loss",
                 "coolant_dynamics")


def event_supported(events: Mapping[str, EventTest], alpha: float
                    ) -> list[tuple[str, str | None, EventTest]]:
    """The event-signature effects the run's events support at level ``alpha``: the
    centrifugal jump test, and the most significant lag test of the channels where one
    applies, at alpha over their number (Bonferroni: one lag is looked for in several
    channels). (effect, lag channel, test) in that order."""
    out: list[tuple[str, str | None, EventTest]] = []
    for name in EVENT_EFFECTS:
        if name == "sensor_lag":  # one test per channel, below
            continue
        c = events.get(name)
        if c is not None and c.significant(alpha):
            out.append((name, None, c))
    lags = [t for k, t in events.items() if k.startswith("sensor_lag(")
            and math.isfinite(t.p_value)]
    if lags:
        best = max(lags, key=lambda t: t.z)
        if best.significant(alpha / len(lags)):
            out.append(("sensor_lag", best.channel, best))
    return out


#: the event signatures read from P1's shape at the speed steps (forward_selection)
P1_STEP_RIVALS = ("centrifugal_shortening", "sensor_lag(P1)")


def _accept_events(cal: Calibrator, current: Fit, events: Mapping[str, EventTest],
                   alpha: float, steps: list[Step], tried: list[dict],
                   say: Callable[[str], None]) -> Fit:
    """Adds the event-supported effects (:func:`event_supported`) to ``current``, each with
    a prior on its parameter from its event test, and returns the extended fit."""
    for name, channel, test in event_supported(events, alpha):
        say(f"adding {name}" + (f" ({channel})" if channel else "") + " from its events")
        par = test.parameter or {}
        start = dict(current.theta)
        if par:
            start[par["name"]] = cal.set_event_prior(par["name"], par["value"], par["ci95"])
        else:  # no estimate from the event: start inside the range (not on the neutral bound)
            for p in EFFECTS[name].params:
                start[p.name] = p.lo + 0.1 * (p.hi - p.lo) if p.lo >= 0 else 0.1 * p.hi
        v0 = current.validation_score()
        full = cal.fit(current.effects + (name,), start=start,
                       lag_channel=channel or current.lag_channel)
        steps.append(Step(name, full, test.z ** 2, test.p_value, full.bic() - current.bic(),
                          v0, full.validation_score(), "event"))
        tried.append({"effect": name, "channel": channel, "round": 0,
                      "p_value": test.p_value, "event_test": test.to_dict(),
                      "validation_before": v0, "validation_after": full.validation_score(),
                      "needed_by": "event", "qualifies": True, "accepted": True})
        current = full
    return current


def at_bound(fit: Fit, effect: str, rel: float = 1e-3) -> list[str]:
    """The parameters of ``effect`` whose calibrated value lies on the bound of its range away
    from the neutral value (within ``rel`` of the range)."""
    out = []
    for p in EFFECTS[effect].params:
        v, tol = fit.theta[p.name], rel * (p.hi - p.lo)
        if (p.hi != p.default and v >= p.hi - tol) or (p.lo != p.default and v <= p.lo + tol):
            out.append(p.name)
    return out


def front_set_carries(fit: Fit, effect: str) -> bool:
    """False for a ``bearing_preload`` whose front set's coefficient is not resolved from 0
    (its 95 % interval reaches 0); True otherwise and for every other effect.

    The thermal rise of a preload is the rigidly preloaded front set's; the rear set of a
    motor spindle floats on springs that hold its preload. A feedback on the rear set alone
    is a temperature dependence of the friction that the base lacks, not this effect: on the
    peer's loaded control (dev-09) fitted with a spec further off (seed 2 of
    ``--spec-mismatch``) the loop found front 0.0, rear 0.042 /K, and named it. Every true
    preload so far had the front set's the larger (the peer's 0.96 against 0.35; the
    synthetic ones, equal in truth, 0.21-0.47 against 0.13-0.28)."""
    if effect != "bearing_preload":
        return True
    p = next(q for q in EFFECTS[effect].params if q.name == "k_preload_1_K")
    lower = fit.ci95.get(p.name, (math.nan, math.nan))[0]
    return bool(lower > p.lo + 1e-6 * (p.hi - p.lo))


R = TypeVar("R", bound=tuple)


class Refit(NamedTuple):
    """One candidate refitted jointly in a round of :func:`forward_selection`, with its
    tests (the first two items are what :func:`choose_refit` reads)."""

    qualifies: bool
    gain: float  # log-posterior gain over the current model
    name: str
    fit: Fit
    lag_channel: str | None
    lr: float
    p_value: float
    excess_before: float
    excess_after: float
    needed_by: str | None
    at_bound: list[str]
    cv: tuple[float, float] | None
    peak: float | None = None  # the effect's largest change of its channels [tolerances]


class _Judge:
    """Whether a refitted candidate qualifies in the open-loop loop of
    :func:`forward_selection`: (ok, validation excess before, after, needed by, parameters
    on a bound, (cross-validated score before, after) or None, the effect's peak in
    tolerances or None where the tests before it failed)."""

    def __init__(self, cal: Calibrator, current: Fit, alpha: float, min_gain: float,
                 cv_blocks: int, cv_gain: float):
        self.cal, self.current, self.alpha = cal, current, alpha
        self.min_gain, self.cv_blocks, self.cv_gain = min_gain, cv_blocks, cv_gain
        self.x0, self.v0 = cal.validation_excess(current), current.validation_score()
        self.odd0 = cal.implausible(current, alpha)
        self.z0 = cal.prior_z(current)
        self._cv_now: dict | None = None

    def __call__(self, name: str, full: Fit, pv: float, lag_channel: str | None = None
                 ) -> tuple:
        cal = self.cal
        own = own_channels(name, lag_channel)
        # needed: it predicts the validation window better (over the whole misfit: an
        # effect that explains a small part of it is not worth naming), or without it the
        # base parameters sit outside their prior range and with it they do not. A lag,
        # though, is a defect of one sensor: it cannot explain another channel's misfit,
        # which would hide it (a lag of 1200 s injected on T_stator of the peer's control
        # dev-06: 0.97 of that channel's excess explained), so it is judged on its channel
        if name == "sensor_lag":
            x0, x1 = cal.validation_excess(self.current, own), cal.validation_excess(full, own)
        else:
            x0, x1 = self.x0, cal.validation_excess(full)
        why = ("validation" if x1 < (1.0 - self.min_gain) * x0 else
               "plausibility" if self.odd0 and cal.comfortable(full) else None)
        # an estimate on its range's bound is reported (at_bound) but no longer refuses the
        # effect: with the bearing seats' conductance in the base, the sink it guarded
        # against (a mount at its bound on a preload run) is gone, and it refused the
        # peer's true mount, whose conductance saturates (the housing face at room
        # temperature); the validation and cross-validation gains judge it (docs/fit.md)
        bound = at_bound(full, name)
        ok = pv < self.alpha and why is not None and front_set_carries(full, name)
        # material: the gains above are relative, and with the base fitting to the noise a
        # term of a few tenths of a tolerance can remove most of an excess near zero
        peak = cal.effect_peak(full, name, own) if ok else None
        ok = ok and peak >= MATERIAL_PEAK
        cv = None
        if ok and self.cv_blocks:
            # the split's validation window is one stretch of the run; over blocks of the
            # whole run a sink for the base model's misfit predicts little better. Judged on
            # the channels the effect acts on: each fold refits the base parameters, which
            # moves the other channels' errors by the refit's own scatter, and pooled with
            # them a P1 term's gain drowns (a fixture term of -0.5 um/K injected into the
            # peer's control dev-09: 21 % pooled, docs/fit.md)
            if cal.progress:
                cal.progress(f"cross-validating {name} over {self.cv_blocks} blocks")
            if self._cv_now is None:
                self._cv_now = cross_validate(cal, self.current, self.cv_blocks)
            cv = (cv_score(self._cv_now, cal.floor, own),
                  cv_score(cross_validate(cal, full, self.cv_blocks), cal.floor, own))
            asked = cv_gain_asked(self.cv_gain, self.z0, cal.prior_z(full),
                                  implausible_z(self.alpha))
            ok = cv[1] <= (1.0 - asked) * cv[0]
        return ok, x0, x1, why, bound, cv, peak


def cv_gain_asked(cv_gain: float, z_before: Mapping[str, float],
                  z_after: Mapping[str, float], z_crit: float) -> float:
    """The blocked cross-validated gain a candidate must show: ``cv_gain``, or half of it
    when the candidate also restores plausibility. ``z_before``, ``z_after``: the base
    parameters' prior z without and with it; ``z_crit``: the z beyond which a parameter is
    implausible (two-sided, at the selection's alpha). Restoring: some parameter beyond
    ``z_crit`` comes back within 1.96 (:data:`RESTORED_Z`, the bar of
    :meth:`Calibrator.comfortable`, so that nudging one just across does not count) and none
    that was inside goes beyond ``z_crit``. That is a second line of evidence the
    cross-validation cannot see: each fold refits the base parameters, so a base that
    imitates the effect with implausible values predicts the held-out block nearly as well
    (a synthetic mount of 3.5 W/K on a mismatched spindle: the base took it as the housing's
    air film x 4.3, +4.2 sd; with the mount the film went back to x 1.1, +0.3 sd, and the
    cross-validated gain was 15 %, docs/fit.md). Half, not none: the fold refits scatter by
    a few %, and a gain within that scatter is no evidence."""
    out_before = {k for k, z in z_before.items() if abs(z) > z_crit}
    out_after = {k for k, z in z_after.items() if abs(z) > z_crit}
    restored = {k for k in out_before if abs(z_after.get(k, math.inf)) <= RESTORED_Z}
    return 0.5 * cv_gain if restored and out_after <= out_before else cv_gain


def own_channels(name: str, lag_channel: str | None = None) -> tuple[str, ...]:
    """The channels effect ``name`` acts on (a lag: its one channel)."""
    if name == "sensor_lag" and lag_channel:
        return (lag_channel,)
    return EFFECTS[name].channels


def choose_refit(refits: Sequence[R], channels: Callable[[R], set[str]] | None = None
                 ) -> R | None:
    """The refit a forward-selection round accepts, or None to stop. ``refits`` are tuples
    whose first two items are (qualifies, log-posterior gain); ``channels`` gives the
    channels a refit's effect acts on (default: all, the same for every refit). Bacher and
    Madsen (2011) extend the model by the candidate that raises the likelihood most and stop
    when that one fails its tests; falling back to the next-best qualifying candidate instead
    lets a candidate that only soaks up base misfit (a mount sink on a fixture-expansion run,
    issue 13) be named when the effect that fits best narrowly misses a threshold. A better
    refit blocks only a candidate that acts on a channel it acts on too: a P1 term that fails
    its tests says nothing against a lag on the stator's sensor (the peer's control dev-06
    with a lag injected on T_stator, docs/fit.md)."""
    blocked: set[str] = set()
    for r in sorted(refits, key=lambda r: -r[1]):
        own = channels(r) if channels else {"*"}
        if r[0] and not (own & blocked):
            return r
        blocked |= own
    return None


def _event_judged(events: Mapping[str, EventTest], candidates: Sequence[str], alpha: float
                  ) -> tuple[set[str], dict[str, EventTest]]:
    """The candidates the event tests judge (left out of the open-loop loop), and their
    tests."""
    # a lag whose onset was measured but is not testable (the model itself expects no
    # concave onset there) is not left to the loop either: its own signature, the onset,
    # is what could support it, and it showed nothing beyond the model's
    judged = {k for k, t in events.items() if k.split("(")[0] in candidates
              and (math.isfinite(t.p_value) or (
                  k.startswith("sensor_lag(") and t.estimate is not None
                  and math.isfinite(t.estimate) and t.reference is not None))}
    cands = {k: t for k, t in events.items() if k in judged}
    # a centrifugal jump and a lag on P1 are both read from P1's shape at the speed steps,
    # and a lagged P1 bends the jump test (a lag of 900 s injected into the peer's control
    # dev-06 gave a jump at z 2.5 beside the lag at z 4.7): when both are significant the
    # weaker goes to the loop, judged against the stronger
    rivals = [f"{n}({c})" if c else n for n, c, _t in event_supported(cands, alpha)]
    rivals = [k for k in rivals if k in P1_STEP_RIVALS]
    if len(rivals) == 2:
        weaker = min(rivals, key=lambda k: cands[k].z)
        cands.pop(weaker)
        judged.discard(weaker)
    return judged, cands


def forward_selection(cal: Calibrator, candidates: Sequence[str] | None = None,
                      alpha: float = 0.01, base: Fit | None = None,
                      min_gain: float = 0.25, refit_top: int = 3,
                      screen_nfev: int = 12,
                      events: Mapping[str, EventTest] | None = None,
                      cv_blocks: int = 5, cv_gain: float = 0.25) -> Selection:
    """Bacher-Madsen forward selection over the candidate effects. A candidate of the
    open-loop loop that passes the likelihood-ratio test, is needed and lies inside its range
    must also lower the blocked cross-validated error above the noise floor (``cv_blocks``
    blocks; 0: not asked) by ``cv_gain``, the same 25 % the split asks of the validation
    window (``min_gain``), or by half that when it also restores plausibility
    (:func:`cv_gain_asked`). With ``events`` (the
    run's event tests, compare.fit.events.event_tests) the event-signature effects are
    judged on them where a test applies: added first when it is significant, never
    otherwise."""
    say = cal.progress or (lambda _m: None)
    candidates = list(candidates or EFFECTS)
    if base is None:
        say("calibrating the base model")
        base = cal.fit()
    current = base
    steps: list[Step] = []
    tried: list[dict] = []
    judged: set[str] = set()
    if events:
        judged, cands = _event_judged(events, candidates, alpha)
        current = _accept_events(cal, current, cands, alpha, steps, tried, say)
    while True:
        screens = []
        for name in candidates:
            if name in current.effects:
                continue
            variants = [c for c in cal.channels] if name == "sensor_lag" else [None]
            for lag_ch in variants:
                label = name + (f"({lag_ch})" if lag_ch else "")
                if label in judged:
                    continue
                say(f"round {len(steps) + 1}: trying {label}")
                effects = current.effects + (name,)
                # screen: a short joint fit (the base parameters may already have absorbed
                # part of the effect, so holding them would hide it), started inside the
                # candidate's range (a start on the neutral bound can stall there)
                start = dict(current.theta)
                for p in EFFECTS[name].params:
                    start[p.name] = p.lo + 0.1 * (p.hi - p.lo) if p.lo >= 0 else 0.1 * p.hi
                screen = cal.fit(effects, start=start,
                                 lag_channel=lag_ch or current.lag_channel, max_nfev=screen_nfev)
                lr, pv = lr_test(current, screen)
                tried.append({"effect": name, "channel": lag_ch, "round": len(steps) + 1,
                              "p_value_screen": pv, "loglik": screen.loglik,
                              "validation": screen.validation_score(),
                              "validation_excess": cal.validation_excess(screen)})
                screens.append((name, screen, lag_ch))
        if not screens:
            break
        # the screen is short: refit the best few jointly; an effect qualifies when its
        # likelihood-ratio test is significant and it is needed (below); the refit with the
        # best likelihood must itself qualify (choose_refit)
        def gain(f: Fit, cur: Fit = current) -> float:
            return log_posterior_gain(cur, f)

        judge = _Judge(cal, current, alpha, min_gain, cv_blocks, cv_gain)
        v0, odd0 = judge.v0, judge.odd0
        refits = []
        for name, screen, lag_ch in sorted(screens, key=lambda s: -gain(s[1]))[:refit_top]:
            say(f"round {len(steps) + 1}: refitting with {name}" + (f" ({lag_ch})" if lag_ch else ""))
            full = cal.fit(current.effects + (name,), start=screen.theta,
                           lag_channel=lag_ch or current.lag_channel)
            if gain(full) < gain(screen):  # the joint fit may stop early; keep the better
                full = screen
            lr, pv = lr_test(current, full)
            ok, x0, x1, why, bound, cv, peak = judge(name, full, pv, lag_ch)
            refits.append(Refit(ok, gain(full), name, full, lag_ch, lr, pv, x0, x1, why, bound,
                                cv, peak))
        chosen = choose_refit(refits, lambda r: set(own_channels(r.name, r.lag_channel)))
        for ok, _g, name, full, lag_ch, _lr, pv, x0, x1, why, bound, cv, peak in refits:
            tried.append({"effect": name, "channel": lag_ch, "round": len(steps) + 1,
                          "p_value": pv, "validation_before": v0,
                          "validation_after": full.validation_score(), "excess_before": x0,
                          "excess_after": x1, "implausible_before": odd0,
                          "implausible_after": cal.implausible(full, alpha),
                          "prior_z_before": cal.prior_z(current),
                          "prior_z_after": cal.prior_z(full),
                          "judged_on": list(own_channels(name, lag_ch)),
                          "needed_by": why, "at_bound": bound, "gain": _g,
                          "cv_before": None if cv is None else cv[0],
                          "cv_after": None if cv is None else cv[1], "peak_effect": peak,
                          "qualifies": ok,
                          "accepted": chosen is not None and full is chosen.fit})
        if chosen is None:
            break
        full = chosen.fit
        steps.append(Step(chosen.name, full, chosen.lr, chosen.p_value,
                          full.bic() - current.bic(), v0, full.validation_score(),
                          chosen.needed_by))
        current = full
    return Selection(base, steps, tried)


def parameters_table(fit: Fit) -> list[dict]:
    params = {**BASE_PARAMS, **EXTRA_BASE_PARAMS,
              **{p.name: p for e in EFFECTS.values() for p in e.params}}
    rows = []
    for k in fit.free:
        p = params[k]
        rows.append({"name": k, "unit": p.unit, "value": fit.theta[k],
                     "ci95": list(fit.ci95[k]), "identifiable": fit.identifiable[k],
                     "meaning": p.doc})
    return rows


def cross_validate(cal: Calibrator, fit: Fit, blocks: int = 5, max_nfev: int = 20) -> dict:
    """Blocked cross-validation of ``fit``'s model (issue 13 §4): for each of ``blocks``
    equal blocks of the run, refit the same free parameters on every
    other block, starting from ``fit``'s values with the same priors, and simulate the held-out
    block open loop. Returns per fold the block [s] and each channel's held-out error, and
    per channel the error pooled over the folds (``rmse``, ``max``, ``within_tolerance``;
    ``unit`` K or um): what the model predicts where it was not calibrated, the run's whole
    operating range included."""
    from dataclasses import replace

    meas = cal.measured
    blocks = max(int(blocks), 2)
    folds, pooled = [], {c: [] for c in cal.channels}
    for i in range(blocks):
        held = replace(meas, blocks=blocks, held_out=i)
        edges = held.block_edges()
        fold_cal = replace(cal, measured=held, progress=None, evaluations=0)
        refit = fold_cal.fit(fit.effects, free=fit.free, start=fit.theta,
                             lag_channel=fit.lag_channel, max_nfev=max_nfev)
        cal.evaluations += fold_cal.evaluations
        errs = {}
        for c in cal.channels:
            m = held.mask(c, "validation")
            d = meas.values[c][m] - refit.model[c][m]
            pooled[c].append(d)
            if len(d):
                errs[c] = _error_row(c, d)
        folds.append({"block_s": [float(edges[i]), float(edges[i + 1])], "validation": errs})
    total = {c: _error_row(c, np.concatenate(d)) for c, d in pooled.items()
             if sum(len(x) for x in d)}
    return {"blocks": blocks, "folds": folds, "pooled": total}


def cv_score(cv: dict, floor: Mapping[str, float] | None = None,
             channels: Sequence[str] | None = None) -> float:
    """The pooled cross-validated open-loop error of :func:`cross_validate` above the noise
    ``floor`` (per channel, tolerance units): sum over ``channels`` (default: all) of
    RMS² − floor² [tolerance units squared], as :meth:`Calibrator.validation_excess` does
    for the split."""
    total = 0.0
    for c, r in cv["pooled"].items():  # rmse in K, or in µm for P1
        if channels is not None and c not in channels:
            continue
        w = r["rmse"] / (TOLERANCE[c] * edge_scale(c))
        f = (floor or {}).get(c, 0.0)
        total += max(w * w - f * f, 0.0)
    return total


def _error_row(channel: str, d: np.ndarray) -> dict:
    """rmse, max, bias (channel unit at the edges: K or um) and within_tolerance of
    differences ``d`` [SI]; the errors of Calibrator.errors and of cross_validate."""
    scale, unit = edge_scale(channel), edge_unit(channel, ascii=True)
    return {"rmse": float(np.sqrt(np.mean(d * d)) * scale),
            "max": float(np.max(np.abs(d)) * scale), "bias": float(np.mean(d) * scale),
            "unit": unit,
            "within_tolerance": float(np.mean(np.abs(d) <= TOLERANCE[channel])), "n": int(len(d))}
