"""Residual diagnostics for grey-box model identification: is the residual of a fitted model
white (the model explains the data) or structured (an effect is missing)?

The residual of a channel is r_k = measured - model on a common regular time grid of step
``dt_s`` [s] (after resampling); temperatures are in K, the axial growth P1 in m, and every
statistic below is in the unit of its channel unless it is dimensionless. The tests follow
grey-box practice (Bacher & Madsen, Energy and Buildings 43 (2011) 1511; Madsen, *Time Series
Analysis*, Chapman & Hall 2008, ch. 6; Box & Jenkins, *Time Series Analysis*, 1976, §8.2):

- sample autocorrelation (biased estimator, lag 0 = 1) with the white-noise band
  ±z_(1-alpha/2)/sqrt(n) (±1.96/sqrt(n) at 5 %, Bartlett; pointwise, not simultaneous);
- Ljung-Box portmanteau Q(h) = n (n+2) Σ_(k=1..h) ρ_k² / (n-k), p from chi2(h - model_df)
  (Ljung & Box, Biometrika 65 (1978) 297);
- normalised cumulated periodogram C(ν_j) = Σ_(i<=j) I(ν_i) / Σ_(i<=q) I(ν_i) over the q
  Fourier frequencies ν_i = i / (N dt_s), i = 1..q, q = (N-1)//2 (Nyquist and zero frequency
  left out: q = (N-2)/2 for N even, (N-1)/2 for N odd as in Madsen 2008), with the
  Kolmogorov-Smirnov band j/q ± K_alpha/sqrt(q), K_alpha = kstwobign.isf(alpha) (1.36 at 5 %,
  1.63 at 1 %). The test passes iff the curve stays inside the band, p = kstwobign.sf(sqrt(q) D)
  (asymptotic KS distribution, as the band);
- cross-correlation of the residual with an input or a candidate effect's signature.

Conventions
-----------
NaN handling (every function the same way): a NaN marks a missing sample. Means, variances and
``n`` use the valid samples only; the time grid is kept (the series is never compressed, which
would shift lags), the centred series is set to zero at the missing samples and sums over
lagged products therefore run over the pairs where both samples are valid, with the biased
divisor n = number of valid samples (lag 0 is exactly 1; the same as statsmodels'
``acf(missing="conservative")``). The cumulated periodogram drops leading and trailing NaNs and
zero-fills inner ones; zero-filling a centred white series keeps it uncorrelated, but with many
gaps the periodogram ordinates are no longer independent and the KS test is approximate.
A series with too few valid samples or with zero variance raises ValueError (its correlation is
undefined).

Cross-correlation sign: ccf(k) = Σ_t r_c[t+k] x_c[t] / sqrt(Σ r_c² Σ x_c²), for
k = -max_lag..max_lag samples. A peak at k > 0 means the residual *follows* x by k samples
(r[t] ≈ a x[t-k], x leads); k < 0 means the residual leads x. Both series are centred (or
linearly detrended) over the samples where both are valid. The band ±z_(1-alpha/2)/sqrt(n) is the
pointwise band of zero cross-correlation; it holds when at least one of the two series is white
(Bartlett), i.e. it is meaningful for the residual of a good model; two autocorrelated series
give wider spurious peaks (prewhitening, Box & Jenkins §11.2, is not done here), and the largest
of 2 max_lag + 1 values exceeds a pointwise band more often than alpha.

Computing and drawing are apart: the ``plot_*`` helpers only draw what the functions above
compute (matplotlib on the Agg backend through :func:`spindle.plots.pyplot`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy import signal, stats

from spindle.outputs import jsonable

#: default Ljung-Box lags [samples]
DEFAULT_LAGS: tuple[int, ...] = (10, 20)


# ---------------------------------------------------------------------------------- helpers
def _as_series(r: Any) -> np.ndarray:
    a = np.asarray(r, dtype=float)
    if a.ndim != 1:
        raise ValueError(f"a residual is a 1-D series, got shape {a.shape}")
    return a


def _centred(r: Any, mask: np.ndarray | None = None, detrend: str = "constant") -> tuple[np.ndarray, int]:
    """(series with the mean -- or linear trend -- of its valid samples removed and zeros at the
    missing ones, number of valid samples). ``mask``: the valid samples (default: not NaN)."""
    a = _as_series(r)
    valid = np.isfinite(a) if mask is None else mask
    n = int(valid.sum())
    if n == 0:
        raise ValueError("the series has no valid (non-NaN) sample")
    out = np.zeros_like(a)
    if detrend == "constant":
        out[valid] = a[valid] - a[valid].mean()
    elif detrend == "linear":
        if n < 3:
            raise ValueError("a linear detrend needs at least 3 valid samples")
        t = np.flatnonzero(valid).astype(float)
        design = np.column_stack([np.ones_like(t), t - t.mean()])
        coef, *_ = np.linalg.lstsq(design, a[valid], rcond=None)
        out[valid] = a[valid] - design @ coef
    else:
        raise ValueError(f"detrend must be 'constant' or 'linear', got {detrend!r}")
    return out, n


def _lag_products(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lags, Σ_t a[t+k] b[t]) for every lag k = -(len-1)..len-1 (FFT or direct, whichever
    scipy finds faster)."""
    c = signal.correlate(a, b, mode="full")
    return signal.correlation_lags(len(a), len(b), mode="full"), c


def _z(alpha: float) -> float:
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha}")
    return float(stats.norm.isf(alpha / 2.0))


def _pct(alpha: float) -> str:
    return f"{alpha * 100:g} %"




# ----------------------------------------------------------------------- 1. summary statistics
def summary_stats(r: Any) -> dict[str, float | int]:
    """RMSE, max |r| and bias (mean) of a residual, in its unit (K, m), over its valid samples.

    Returns ``{"rmse", "max", "bias", "n", "i_max"}``: ``max`` is the largest |r|, ``i_max`` its
    sample index on the given grid, ``n`` the number of valid (non-NaN) samples.
    """
    a = _as_series(r)
    valid = np.isfinite(a)
    if not valid.any():
        raise ValueError("the residual has no valid (non-NaN) sample")
    v = a[valid]
    i_max = int(np.flatnonzero(valid)[np.argmax(np.abs(v))])
    return {"rmse": float(np.sqrt(np.mean(v**2))), "max": float(np.abs(v).max()),
            "bias": float(v.mean()), "n": int(v.size), "i_max": i_max}


# ------------------------------------------------------------------- 2. ACF and Ljung-Box
def acf(r: Any, nlags: int) -> np.ndarray:
    """Sample autocorrelation ρ_k, k = 0..nlags [samples], biased estimator
    ρ_k = Σ_t r_c[t] r_c[t+k] / Σ_t r_c[t]² (r_c centred; NaNs as in the module docstring);
    ρ_0 = 1. Dimensionless, length nlags + 1."""
    rc, n = _centred(r)
    if nlags < 0 or nlags >= len(rc):
        raise ValueError(f"nlags must be in 0..{len(rc) - 1}, got {nlags}")
    c0 = float(rc @ rc)
    if c0 == 0.0:
        raise ValueError("the residual is constant: its autocorrelation is undefined")
    lags, c = _lag_products(rc, rc)
    rho = c[(lags >= 0) & (lags <= nlags)] / c0
    rho[0] = 1.0  # exact, whatever the FFT round-off
    return rho


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


def acf_band(n: int, alpha: float = 0.05) -> float:
    """Half-width of the pointwise white-noise band of the ACF (and CCF), z_(1-alpha/2)/sqrt(n):
    1.96/sqrt(n) at alpha = 5 %. ``n``: number of valid samples. Dimensionless."""
    if n < 1:
        raise ValueError("n must be positive")
    return _z(alpha) / math.sqrt(n)


def ljung_box(r: Any, lags: int | Iterable[int] = DEFAULT_LAGS,
              model_df: int = 0) -> list[tuple[int, float, float]]:
    """Ljung-Box portmanteau test of no autocorrelation up to each lag h [samples]:
    Q(h) = n (n+2) Σ_(k=1..h) ρ_k² / (n-k), p = chi2.sf(Q, h - model_df), n = valid samples.

    ``model_df``: parameters of a fitted ARMA noise model (0 for the residual of a deterministic
    model). Returns ``[(h, Q, p_value), ...]`` in the order given. Same numbers as
    ``statsmodels.stats.diagnostic.acorr_ljungbox`` (not required).
    """
    hs = [int(lags)] if isinstance(lags, int | np.integer) else [int(h) for h in lags]
    if not hs:
        raise ValueError("no Ljung-Box lag given")
    n = int(np.isfinite(_as_series(r)).sum())
    for h in hs:
        if not model_df < h < n:
            raise ValueError(f"Ljung-Box lag {h} must be in {model_df + 1}..{n - 1} (n = {n} valid)")
    rho = acf(r, max(hs))
    k = np.arange(1, max(hs) + 1)
    terms = np.cumsum(rho[1:] ** 2 / (n - k))
    out = []
    for h in hs:
        q = float(n * (n + 2) * terms[h - 1])
        out.append((h, q, float(stats.chi2.sf(q, h - model_df))))
    return out


# ------------------------------------------------------------ 3. cumulated periodogram
def _cp(r: Any) -> tuple[np.ndarray, int, int]:
    """(normalised cumulated periodogram C_1..C_q, q, N) of a residual trimmed of leading and
    trailing NaNs."""
    a = _as_series(r)
    idx = np.flatnonzero(np.isfinite(a))
    if idx.size == 0:
        raise ValueError("the residual has no valid (non-NaN) sample")
    rc, _ = _centred(a[idx[0]:idx[-1] + 1])
    big_n = len(rc)
    q = (big_n - 1) // 2
    if q < 2:
        raise ValueError(f"the cumulated periodogram needs at least 5 samples, got {big_n}")
    power = np.abs(np.fft.rfft(rc)[1:q + 1]) ** 2 / big_n
    total = float(power.sum())
    if total == 0.0:
        raise ValueError("the residual is constant: its periodogram is zero")
    c = np.cumsum(power) / total
    c[-1] = 1.0
    return c, q, big_n


def ks_constant(alpha: float = 0.05) -> float:
    """K_alpha of the Kolmogorov-Smirnov band, kstwobign.isf(alpha): 1.358 at 5 %, 1.628 at 1 %
    (Box & Jenkins' table: 1.36, 1.63). Dimensionless."""
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must be in (0, 1), got {alpha}")
    return float(stats.kstwobign.isf(alpha))


def cumulated_periodogram(r: Any, dt_s: float = 1.0,
                          alpha: float = 0.05) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Normalised cumulated periodogram of a residual and its KS band for white noise.

    Returns ``(freqs, C, band)``: ``freqs`` [Hz] the q Fourier frequencies i / (N dt_s),
    i = 1..q, q = (N-1)//2; ``C`` (dimensionless, rising to 1 at the last frequency);
    ``band`` shape (2, q), the lower and upper lines j/q ∓ K_alpha/sqrt(q) around the diagonal
    of white noise (K = 1.36 at alpha = 5 %). ``dt_s``: sample step [s].
    """
    c, q, big_n = _cp(r)
    j = np.arange(1, q + 1)
    half = ks_constant(alpha) / math.sqrt(q)
    diag = j / q
    return j / (big_n * dt_s), c, np.vstack([diag - half, diag + half])


def cp_test(r: Any, alpha: float = 0.05) -> tuple[float, float, bool]:
    """KS test of the cumulated periodogram against white noise.

    Returns ``(D, p_value, passes)``: D = max_j |C_j - j/q| (dimensionless), p = kstwobign.sf(
    sqrt(q) D) (asymptotic Kolmogorov distribution), ``passes`` iff the curve stays inside the
    band of :func:`cumulated_periodogram` at ``alpha`` (equivalently p >= alpha).
    """
    c, q, _ = _cp(r)
    d = float(np.abs(c - np.arange(1, q + 1) / q).max())
    return d, float(stats.kstwobign.sf(math.sqrt(q) * d)), d <= ks_constant(alpha) / math.sqrt(q)


def cp_exit_frequency(r: Any, dt_s: float = 1.0, alpha: float = 0.05) -> float | None:
    """First frequency [Hz] at which the cumulated periodogram leaves its KS band, None if it
    stays inside."""
    freqs, c, band = cumulated_periodogram(r, dt_s, alpha)
    out = np.flatnonzero((c < band[0]) | (c > band[1]))
    return float(freqs[out[0]]) if out.size else None


# ------------------------------------------------------------- 4. cross-correlation
def cross_correlation(r: Any, x: Any, max_lag: int, alpha: float = 0.05,
                      detrend: str = "constant") -> tuple[np.ndarray, np.ndarray, float]:
    """Normalised cross-correlation of a residual with an input or a signature on the same grid.

    ccf(k) = Σ_t r_c[t+k] x_c[t] / sqrt(Σ r_c² Σ x_c²) for k = -max_lag..max_lag [samples];
    k > 0: the residual follows x by k samples. Both series are centred (``detrend="constant"``)
    or linearly detrended (``"linear"``) over the samples where both are valid; the others are
    left out. Returns ``(lags, ccf, band)``, ``band`` = z_(1-alpha/2)/sqrt(n) the pointwise
    half-width of zero correlation (valid when one of the two series is white), n = samples
    valid in both. Dimensionless.
    """
    a, b = _as_series(r), _as_series(x)
    if a.shape != b.shape:
        raise ValueError(f"residual and signal differ in length: {a.size} vs {b.size}")
    both = np.isfinite(a) & np.isfinite(b)
    rc, n = _centred(a, both, detrend)
    xc, _ = _centred(b, both, detrend)
    denom = math.sqrt(float(rc @ rc) * float(xc @ xc))
    if denom == 0.0:
        raise ValueError("residual or signal is constant over the common valid samples")
    max_lag = int(min(max_lag, a.size - 1))
    if max_lag < 0:
        raise ValueError("max_lag must be >= 0")
    lags, c = _lag_products(rc, xc)
    keep = np.abs(lags) <= max_lag
    return lags[keep], c[keep] / denom, acf_band(n, alpha)


def _constant_where_both(r: Any, x: Any) -> bool:
    """Whether the signal ``x`` is constant over the samples where it and ``r`` are valid (its
    cross-correlation with ``r`` is then undefined)."""
    a, b = _as_series(r), _as_series(x)
    v = b[np.isfinite(a) & np.isfinite(b)] if a.shape == b.shape else b[np.isfinite(b)]
    return bool(v.size and np.ptp(v) == 0.0)


def peak_lag(lags: np.ndarray, ccf: np.ndarray) -> tuple[int, float]:
    """(lag [samples], ccf value) of the largest |ccf| (the first one on a tie)."""
    i = int(np.argmax(np.abs(ccf)))
    return int(lags[i]), float(ccf[i])


# ------------------------------------------------------------------------- 5. whiteness
@dataclass(frozen=True)
class Whiteness:
    """Whiteness of one residual at level ``alpha``: Ljung-Box at each lag and the KS test of the
    cumulated periodogram. ``white`` iff every one of them passes at ``alpha`` (so the
    false-alarm rate on white noise is at most (number of lags + 1) alpha)."""

    alpha: float
    n: int  # valid samples
    dt_s: float  # sample step [s]
    ljung_box: list[tuple[int, float, float]]  # (lag [samples], Q, p)
    cp_statistic: float  # max |C_j - j/q|
    cp_p_value: float
    cp_passes: bool
    cp_exit_hz: float | None  # first frequency outside the band [Hz], None: inside

    @property
    def ljung_box_passes(self) -> bool:
        return all(p >= self.alpha for _, _, p in self.ljung_box)

    @property
    def white(self) -> bool:
        return self.ljung_box_passes and self.cp_passes

    def describe(self) -> str:
        """One plain sentence, e.g. ``residual is structured: Ljung-Box p = 1e-40 at lag 20;
        cumulated periodogram leaves the 1 % band at 0.004 Hz``."""
        lag, _, p = min(self.ljung_box, key=lambda t: t[2])
        pp = "p < 1e-300" if p == 0.0 else f"p = {p:.2g}"
        lb = (f"Ljung-Box {pp} at lag {lag} ({lag * self.dt_s:g} s)" if not self.ljung_box_passes
              else f"Ljung-Box passes (smallest {pp}, at lag {lag})")
        cp = (f"cumulated periodogram stays within the {_pct(self.alpha)} band" if self.cp_passes
              else f"cumulated periodogram leaves the {_pct(self.alpha)} band at {self.cp_exit_hz:.3g} Hz")
        head = (f"residual is white at the {_pct(self.alpha)} level" if self.white
                else "residual is structured")
        return f"{head}: {lb}; {cp}"

    def to_dict(self) -> dict[str, Any]:
        return jsonable({"alpha": self.alpha, "n": self.n, "white": self.white,
                       "ljung_box": [{"lag": h, "lag_s": h * self.dt_s, "Q": q, "p": p}
                                     for h, q, p in self.ljung_box],
                       "cp_statistic": self.cp_statistic, "cp_p_value": self.cp_p_value,
                       "cp_passes": self.cp_passes, "cp_exit_hz": self.cp_exit_hz})


def whiteness(r: Any, alpha: float = 0.01, lags: Sequence[int] = DEFAULT_LAGS,
              dt_s: float = 1.0) -> Whiteness:
    """Ljung-Box at ``lags`` [samples] (those below n) and the cumulated-periodogram KS test, at
    level ``alpha``; ``dt_s`` [s] only converts lags and frequencies for the report."""
    n = int(np.isfinite(_as_series(r)).sum())
    usable = [h for h in lags if 0 < h < n]
    if not usable:
        raise ValueError(f"no Ljung-Box lag below the {n} valid samples")
    d, p, passes = cp_test(r, alpha)
    return Whiteness(alpha=alpha, n=n, dt_s=dt_s, ljung_box=ljung_box(r, usable), cp_statistic=d,
                     cp_p_value=p, cp_passes=passes,
                     cp_exit_hz=None if passes else cp_exit_frequency(r, dt_s, alpha))


# ------------------------------------------------------------------ 6. per-channel diagnosis
@dataclass(frozen=True)
class CrossPeak:
    """Largest |ccf| of a residual with one input or signature."""

    name: str
    kind: str  # "input" or "signature"
    lag: int  # [samples]; > 0: the residual follows the signal
    lag_s: float  # [s]
    ccf: float  # dimensionless, signed
    band: float  # pointwise half-width at the diagnosis' alpha
    #: the largest |ccf| at lags >= 0 alone (the residual at or after the signal, as a
    #: response to it can be): its lag [s] and value, and whether that lag is the largest
    #: tried (then the peak lies beyond the range, not at a lag it found)
    lag_after_s: float = 0.0
    ccf_after: float = 0.0
    after_at_edge: bool = False

    @property
    def beyond_band(self) -> bool:
        return abs(self.ccf) > self.band

    def to_dict(self) -> dict[str, Any]:
        return jsonable({"name": self.name, "kind": self.kind, "lag": self.lag, "lag_s": self.lag_s,
                       "ccf": self.ccf, "band": self.band, "beyond_band": self.beyond_band,
                       "lag_after_s": self.lag_after_s, "ccf_after": self.ccf_after,
                       "after_at_edge": self.after_at_edge})


@dataclass(frozen=True)
class ChannelDiagnostics:
    """Everything about one channel's residual, in the channel's unit (K, m)."""

    name: str
    n: int  # valid samples
    rmse: float
    max_abs: float
    bias: float
    t_max_s: float  # time of the largest |r| [s]
    whiteness: Whiteness
    cross: list[CrossPeak] = field(default_factory=list)

    def best(self, kind: str, after: bool = False) -> CrossPeak | None:
        """The input (``kind="input"``) or signature with the largest |ccf| (``after``: at
        lags >= 0 alone, short of the largest lag tried), None if none."""
        peaks = [c for c in self.cross if c.kind == kind and not (after and c.after_at_edge)]
        return max(peaks, key=lambda c: abs(c.ccf_after if after else c.ccf)) if peaks else None

    def to_dict(self) -> dict[str, Any]:
        return jsonable({"name": self.name, "n": self.n, "rmse": self.rmse, "max_abs": self.max_abs,
                       "bias": self.bias, "t_max_s": self.t_max_s,
                       "whiteness": self.whiteness.to_dict(),
                       "cross": [c.to_dict() for c in self.cross]})


def _lag_phrase(p: CrossPeak) -> str:
    if p.lag == 0:
        return "at lag 0 s"
    how = "following" if p.lag > 0 else "leading"
    return f"at lag {p.lag_s:+.4g} s, the residual {how} it"


@dataclass(frozen=True)
class Diagnostics:
    """Diagnostics of every channel; ``scales`` [channel unit] rank channels of different units
    (e.g. tolerances 1 K and 1.5e-6 m)."""

    dt_s: float
    alpha: float
    channels: dict[str, ChannelDiagnostics]
    scales: dict[str, float] = field(default_factory=dict)

    def scaled_max(self, name: str) -> float:
        """max |r| of a channel divided by its scale (1 when none given)."""
        return self.channels[name].max_abs / self.scales.get(name, 1.0)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready (python types only, non-finite numbers as None)."""
        return jsonable({"dt_s": self.dt_s, "alpha": self.alpha, "scales": self.scales,
                       "channels": {k: c.to_dict() for k, c in self.channels.items()},
                       "unexplained": self.unexplained_description()})

    def unexplained_description(self, among: Sequence[str] | None = None) -> str:
        """One sentence: the channel where the residual is largest (max |r| over its scale),
        among ``among`` (default all channels), and when, and the input (and signature) its
        residual correlates with most, at what lag."""
        pool = [c for c in (among or self.channels) if c in self.channels] or list(self.channels)
        name = max(pool, key=self.scaled_max)
        c = self.channels[name]
        scale = (f", {self.scaled_max(name):.3g} times its scale {self.scales[name]:g}"
                 if name in self.scales else "")
        out = (f"The residual is largest in {name} (max |r| = {c.max_abs:.3g}{scale}, at "
               f"t = {c.t_max_s:.6g} s; RMSE {c.rmse:.3g}, bias {c.bias:.3g}; "
               f"{'white' if c.whiteness.white else 'structured'} at the {_pct(self.alpha)} level)")
        parts = []
        for kind in ("input", "signature"):
            p = c.best(kind)
            if p is not None:
                note = "" if p.beyond_band else f", within the ±{p.band:.2g} band of no correlation"
                lead = "of the signatures, with" if parts else f"it correlates most with {kind}"
                parts.append(f"{lead} {p.name} (ccf = {p.ccf:+.2f} {_lag_phrase(p)}{note})")
        return out + ("; " + ", and ".join(parts) if parts else "") + "."


def diagnose(residuals: Mapping[str, Any], dt_s: float,
             inputs: Mapping[str, Any] | None = None,
             signatures: Mapping[str, Any] | None = None, alpha: float = 0.01,
             lags: Sequence[int] = DEFAULT_LAGS, max_lag_s: float | None = None,
             t0_s: float = 0.0, scales: Mapping[str, float] | None = None,
             detrend: str = "constant") -> Diagnostics:
    """Run every diagnostic on each channel's residual (measured - model, channel unit).

    All series share one regular grid of step ``dt_s`` [s] starting at ``t0_s`` [s].
    ``inputs`` (e.g. speed, power) and ``signatures`` (a candidate effect's response) are
    cross-correlated with every residual for lags up to ``max_lag_s`` [s] (default a quarter of
    the record); ``alpha`` is the level of the whiteness tests and of the ccf band; ``lags``
    the Ljung-Box lags [samples]; ``scales`` [channel unit] rank channels for
    :meth:`Diagnostics.unexplained_description`.
    """
    if dt_s <= 0:
        raise ValueError("dt_s must be positive")
    if not residuals:
        raise ValueError("no residual given")
    signals = [(k, "input", v) for k, v in (inputs or {}).items()]
    signals += [(k, "signature", v) for k, v in (signatures or {}).items()]
    channels = {}
    for name, r in residuals.items():
        a = _as_series(r)
        try:
            s = summary_stats(a)
            w = whiteness(a, alpha, lags, dt_s)
            max_lag = a.size // 4 if max_lag_s is None else int(round(max_lag_s / dt_s))
            cross = []
            for sname, kind, x in signals:
                if _constant_where_both(a, x):
                    continue  # a constant input (a run at standstill) follows no residual
                ls, cc, band = cross_correlation(a, x, max_lag, alpha, detrend)
                lag, val = peak_lag(ls, cc)
                pos = ls >= 0
                lag_after, val_after = peak_lag(ls[pos], cc[pos])
                cross.append(CrossPeak(sname, kind, lag, lag * dt_s, val, band,
                                       lag_after * dt_s, val_after, lag_after == ls.max()))
        except ValueError as e:
            raise ValueError(f"channel {name}: {e}") from e
        channels[name] = ChannelDiagnostics(name, int(s["n"]), float(s["rmse"]), float(s["max"]),
                                            float(s["bias"]), t0_s + s["i_max"] * dt_s, w, cross)
    return Diagnostics(dt_s=dt_s, alpha=alpha, channels=channels, scales=dict(scales or {}))


# ------------------------------------------------------------------------------- 7. plots
def plot_acf(ax: Any, r: Any, nlags: int, alpha: float = 0.05, dt_s: float | None = None,
             color: str = "C0", label: str | None = None, band: bool = True) -> Any:
    """Draw the ACF (stems, in ``color``, labelled ``label``) and, with ``band``, its
    ±z/sqrt(n) white-noise band on ``ax``; lags in samples, or in s with ``dt_s``. Draw a
    second residual on the same axes with another colour and ``band=False``. Returns ``ax``."""
    rho = acf(r, nlags)
    half = acf_band(int(np.isfinite(_as_series(r)).sum()), alpha)
    k = np.arange(nlags + 1) * (dt_s or 1)
    ax.vlines(k, 0.0, rho, color=color, lw=1.2, alpha=0.8)
    ax.plot(k, rho, "o", color=color, ms=3, label=label)
    if band:
        ax.axhline(0.0, color="k", lw=0.6)
        for s in (-1, 1):
            ax.axhline(s * half, color="C3", ls="--", lw=0.9,
                       label=f"{_pct(alpha)} white-noise band" if s > 0 else None)
    ax.set_xlabel("lag [s]" if dt_s else "lag [samples]")
    ax.set_ylabel("autocorrelation [-]")
    ax.legend(loc="upper right")
    return ax


def plot_cumulated_periodogram(ax: Any, r: Any, alpha: float = 0.05, dt_s: float = 1.0,
                               color: str = "C0", label: str = "cumulated periodogram",
                               band: bool = True) -> Any:
    """Draw the cumulated periodogram (in ``color``) and, with ``band``, the white-noise
    diagonal and its KS band on ``ax`` (frequency in Hz). Returns ``ax``."""
    freqs, c, ks = cumulated_periodogram(r, dt_s, alpha)
    diag = np.arange(1, c.size + 1) / c.size
    ax.step(freqs, c, where="post", color=color, lw=1.2, label=label)
    if band:
        ax.plot(freqs, diag, color="k", lw=0.7, label="white noise")
        ax.plot(freqs, ks[0], color="C3", ls="--", lw=0.9, label=f"{_pct(alpha)} KS band")
        ax.plot(freqs, ks[1], color="C3", ls="--", lw=0.9)
    ax.set_xlim(0.0, freqs[-1])
    ax.set_ylim(0.0, 1.0)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("cumulated periodogram [-]")
    ax.legend(loc="lower right")
    return ax
