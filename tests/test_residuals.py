"""Residual diagnostics (compare/residuals.py): whiteness tests on series whose answer is known
(white noise, AR(1), a sinusoid in noise), Ljung-Box against a hand computation (and statsmodels
when it is installed), the sign of the cross-correlation lag, NaN handling, the per-channel
diagnosis and its JSON export, and the plot helpers."""

import json
import math
from fractions import Fraction

import numpy as np
import pytest
from scipy import signal, stats

from compare.residuals import (
    Diagnostics,
    acf,
    acf_band,
    cp_exit_frequency,
    cp_test,
    cross_correlation,
    cumulated_periodogram,
    diagnose,
    effective_samples,
    ks_constant,
    ljung_box,
    peak_lag,
    plot_acf,
    plot_cumulated_periodogram,
    summary_stats,
    whiteness,
)

N = 2000
SEEDS = range(20)


def ar1(phi: float, n: int, seed: int) -> np.ndarray:
    e = np.random.default_rng(seed).standard_normal(n + 200)
    x = np.zeros_like(e)
    for t in range(1, e.size):
        x[t] = phi * x[t - 1] + e[t]
    return x[200:]  # burn-in: start from the stationary distribution


def max_false_alarms(rate: float, trials: int, risk: float = 1e-3) -> int:
    """Smallest m with P(X > m) < risk for X ~ Binomial(trials, rate): the number of rejections
    of a true null (per-trial false-alarm probability ``rate``) this suite tolerates; it fails
    on correct code with probability below ``risk`` over a random choice of seeds."""
    return next(m for m in range(trials + 1) if stats.binom.sf(m, trials, rate) < risk)


# ---------------------------------------------------------------------------------- summary
def test_summary_stats_by_hand_and_ignoring_nan():
    s = summary_stats([1.0, -3.0, np.nan, 2.0])
    assert s["n"] == 3 and s["max"] == 3.0 and s["i_max"] == 1
    assert s["bias"] == pytest.approx(0.0, abs=1e-15)
    assert s["rmse"] == pytest.approx(math.sqrt(14 / 3), rel=1e-15)
    with pytest.raises(ValueError, match="no valid"):
        summary_stats([np.nan, np.nan])


# ------------------------------------------------------------------------------ ACF, Ljung-Box
X6 = [1.0, -1.0, 2.0, 0.0, 3.0, -2.0]


def test_acf_and_ljung_box_by_hand():
    # mean 1/2, centred (1, -3, 3, -1, 5, -5)/2: c0 = 35/2, c1 = -45/4, c2 = 13/2
    rho1, rho2 = Fraction(-9, 14), Fraction(13, 35)
    rho = acf(X6, 2)
    assert rho[0] == 1.0  # lag 0 is exactly one
    assert rho[1:] == pytest.approx([float(rho1), float(rho2)], rel=1e-14)  # FFT round-off
    # Q(h) = n (n+2) sum rho_k^2 / (n-k), n = 6
    q1 = 6 * 8 * rho1**2 / 5
    q2 = q1 + 6 * 8 * rho2**2 / 4
    assert (q1, q2) == (Fraction(972, 245), Fraction(6888, 1225))
    (h1, Q1, p1), (h2, Q2, p2) = ljung_box(X6, (1, 2))
    assert (h1, h2) == (1, 2)
    assert Q1 == pytest.approx(float(q1), rel=1e-13) and Q2 == pytest.approx(float(q2), rel=1e-13)
    # chi2 with 2 degrees of freedom: sf(Q) = exp(-Q/2); with 1: erfc(sqrt(Q/2))
    assert p2 == pytest.approx(math.exp(-float(q2) / 2), rel=1e-12)
    assert p1 == pytest.approx(math.erfc(math.sqrt(float(q1) / 2)), rel=1e-12)
    # model_df removes degrees of freedom: chi2(2 - 1)
    assert ljung_box(X6, 2, model_df=1)[0][2] == pytest.approx(stats.chi2.sf(float(q2), 1), rel=1e-12)


def test_acf_lag_zero_is_one_and_band():
    x = ar1(0.5, 500, 3)
    rho = acf(x - x.mean(), 30)
    assert rho.shape == (31,) and rho[0] == 1.0 and np.all(np.abs(rho) <= 1.0)
    assert rho[1] == pytest.approx(0.5, abs=4 / math.sqrt(500))  # AR(1): rho_1 = phi (4 sigma)
    assert acf_band(400) == pytest.approx(1.959963984540054 / 20, rel=1e-12)  # 1.96 / sqrt(n)
    with pytest.raises(ValueError, match="constant"):
        acf(np.full(10, 2.5), 3)


def test_ljung_box_equals_statsmodels():
    sm = pytest.importorskip("statsmodels.stats.diagnostic")
    x = ar1(0.3, 500, 1) + 2.0
    ref = sm.acorr_ljungbox(x, lags=[5, 10, 20])
    mine = ljung_box(x, (5, 10, 20))
    np.testing.assert_allclose([q for _, q, _ in mine], ref["lb_stat"].to_numpy(), rtol=0, atol=1e-10)
    np.testing.assert_allclose([p for _, _, p in mine], ref["lb_pvalue"].to_numpy(), rtol=0, atol=1e-10)


# ------------------------------------------------------------------ white noise and AR(1)
def test_white_noise_is_accepted_up_to_the_binomial_false_alarm_count():
    """On white noise every test rejects with probability alpha (the tests are asymptotic; at
    n = 2000 their size is close to nominal, the KS one slightly below). Over 20 seeds the number
    of rejections is Binomial(20, rate); we allow the count exceeded with probability < 1e-3:
    3 for Ljung-Box at 1 % and for the CP test at 1 %, 4 for ``white`` (three tests at 1 %,
    rate <= 3 % by Bonferroni), 5 for the CP test at 5 %."""
    lb_rej = cp1_rej = cp5_rej = not_white = 0
    for seed in SEEDS:
        e = np.random.default_rng(seed).standard_normal(N)
        lb_rej += ljung_box(e, 20)[0][2] < 0.01
        cp1_rej += not cp_test(e, 0.01)[2]
        cp5_rej += not cp_test(e)[2]
        not_white += not whiteness(e, alpha=0.01, lags=(10, 20)).white
    assert max_false_alarms(0.01, 20) == 3 and max_false_alarms(0.03, 20) == 4
    assert lb_rej <= max_false_alarms(0.01, 20)
    assert cp1_rej <= max_false_alarms(0.01, 20)
    assert cp5_rej <= max_false_alarms(0.05, 20)
    assert not_white <= max_false_alarms(0.03, 20)
    w = whiteness(np.random.default_rng(0).standard_normal(N))
    assert w.white and w.describe().startswith("residual is white at the 1 % level")


def test_ar1_is_rejected():
    x = ar1(0.8, N, 7)
    for _, _, p in ljung_box(x, (10, 20)):
        assert p < 1e-6
    d, p, passes = cp_test(x, 0.01)
    assert not passes and p < 1e-6
    w = whiteness(x, alpha=0.01, dt_s=10.0)
    assert not w.white
    text = w.describe()
    assert text.startswith("residual is structured: Ljung-Box p")
    assert "cumulated periodogram leaves the 1 % band at" in text and "Hz" in text
    # an AR(1) with phi > 0 piles its power at low frequency: it leaves the band early and above
    freqs, c, band = cumulated_periodogram(x, 10.0, 0.01)
    assert w.cp_exit_hz is not None and w.cp_exit_hz < 0.1 * freqs[-1]
    i = np.searchsorted(freqs, w.cp_exit_hz)
    assert c[i] > band[1, i]


def test_cumulated_periodogram_jumps_at_a_sinusoid():
    dt_s, f0 = 2.0, 0.025  # f0 N dt_s = 100: exactly on the 100th Fourier frequency
    t = np.arange(N) * dt_s
    x = 0.5 * np.sin(2 * np.pi * f0 * t) + np.random.default_rng(11).standard_normal(N)
    freqs, c, band = cumulated_periodogram(x, dt_s, 0.01)
    q = (N - 1) // 2
    assert freqs.shape == c.shape == (q,) and band.shape == (2, q) and c[-1] == 1.0
    assert freqs[0] == pytest.approx(1 / (N * dt_s)) and np.all(np.diff(c) >= 0)
    jumps = np.diff(c, prepend=0.0)
    k = int(np.argmax(jumps))
    assert freqs[k] == pytest.approx(f0, rel=1e-12)
    # expected jump: sinusoid ordinate N A^2 / 4 = 125 over a total of ~125 + q sigma^2 = 1124
    assert jumps[k] == pytest.approx(125 / 1124, rel=0.3)  # 30 %: the noise ordinates are chi2(2)/2
    assert jumps[k] > 50 * np.median(jumps)
    assert not cp_test(x, 0.01)[2]
    assert cp_exit_frequency(x, dt_s, 0.01) == pytest.approx(f0, rel=1e-12)


def test_ks_band_constants():
    # Box & Jenkins / Madsen tabulate K = 1.36 (5 %) and 1.63 (1 %), rounded to 2 decimals
    assert ks_constant(0.05) == pytest.approx(1.36, abs=0.005)
    assert ks_constant(0.01) == pytest.approx(1.63, abs=0.005)
    x = np.random.default_rng(2).standard_normal(501)  # odd N: q = (N-1)/2 = 250
    freqs, _, band = cumulated_periodogram(x)
    assert freqs.size == 250
    np.testing.assert_allclose(band[1] - band[0], 2 * ks_constant(0.05) / math.sqrt(250), rtol=1e-14)
    d, p, passes = cp_test(x)
    assert passes == (p >= 0.05)  # the band and the p-value agree


# --------------------------------------------------------------------------- cross-correlation
def test_cross_correlation_lag_sign():
    rng = np.random.default_rng(5)
    x = rng.standard_normal(N)
    r = np.r_[np.zeros(5), x[:-5]] + 0.3 * rng.standard_normal(N)  # r[t] = x[t-5]: x leads
    lags, cc, band = cross_correlation(r, x, 50)
    assert lags[0] == -50 and lags[-1] == 50 and cc.shape == lags.shape
    lag, val = peak_lag(lags, cc)
    assert lag == 5 and val > 0.9  # 1 / sqrt(1 + 0.3^2) = 0.958 less the 5 leading zeros
    assert band == pytest.approx(1.959963984540054 / math.sqrt(N))
    assert np.all(np.abs(cc) <= 1.0 + 1e-12)
    # the residual leading x: negative lag; a negative correlation is found by |ccf|
    r2 = -np.r_[x[5:], np.zeros(5)] + 0.3 * rng.standard_normal(N)  # r2[t] = -x[t+5]
    lag2, val2 = peak_lag(*cross_correlation(r2, x, 50)[:2])
    assert lag2 == -5 and val2 < -0.9
    # a linear trend in both does not hide the lag with detrend="linear"
    ramp = np.linspace(0, 50, N)
    lag3, _ = peak_lag(*cross_correlation(r + ramp, x + ramp, 50, detrend="linear")[:2])
    assert lag3 == 5
    with pytest.raises(ValueError, match="length"):
        cross_correlation(r, x[:-1], 5)


# --------------------------------------------------------------------------------- NaN handling
def test_nan_samples_are_left_out_on_the_kept_grid():
    x = ar1(0.5, 300, 9)
    x[[0, 17, 18, 150, 299]] = np.nan
    valid = np.isfinite(x)
    xc = np.where(valid, x - x[valid].mean(), 0.0)
    # hand: sums over the pairs where both samples are valid, divided by n_valid (cancels)
    hand = [float(np.sum(xc[: x.size - k] * xc[k:]) / np.sum(xc**2)) for k in range(6)]
    np.testing.assert_allclose(acf(x, 5), hand, rtol=0, atol=1e-14)
    n = int(valid.sum())
    q_hand = n * (n + 2) * sum(hand[k] ** 2 / (n - k) for k in range(1, 6))
    assert ljung_box(x, 5)[0][1] == pytest.approx(q_hand, rel=1e-12)
    # the same convention as statsmodels' acf(missing="conservative"), when installed
    try:
        from statsmodels.tsa.stattools import acf as sm_acf
    except ImportError:
        pass
    else:
        np.testing.assert_allclose(acf(x, 5), sm_acf(x, nlags=5, missing="conservative"), atol=1e-12)
    # white noise with 5 % missing samples is still white (gaps zero-filled after centring)
    e = np.random.default_rng(4).standard_normal(N)
    e[np.random.default_rng(40).random(N) < 0.05] = np.nan
    w = whiteness(e)
    assert w.white and w.n == int(np.isfinite(e).sum())
    # leading and trailing NaNs do not change the cumulated periodogram
    f, c, _ = cumulated_periodogram(e[np.isfinite(e).argmax():])
    f2, c2, _ = cumulated_periodogram(np.r_[np.nan, np.nan, e[np.isfinite(e).argmax():], np.nan])
    np.testing.assert_array_equal(f, f2)
    np.testing.assert_allclose(c, c2, atol=1e-14)
    with pytest.raises(ValueError, match="no valid"):
        acf(np.full(5, np.nan), 1)


# ------------------------------------------------------------------------------------ diagnose
def json_types_only(v) -> bool:
    if isinstance(v, dict):
        return all(isinstance(k, str) and json_types_only(x) for k, x in v.items())
    if isinstance(v, list):
        return all(json_types_only(x) for x in v)
    return v is None or type(v) in (str, int, float, bool)


def test_diagnose_two_channels_with_an_input():
    n, dt_s, t0 = 3000, 10.0, 3600.0
    rng = np.random.default_rng(21)
    speed = np.repeat(rng.choice([0.0, 0.5, 1.0], n // 150), 150)  # speed steps every 1500 s
    lagged = np.r_[np.full(30, speed[0]), speed[:-30]]  # 30 samples = 300 s later
    residuals = {
        "T1": 0.05 * rng.standard_normal(n),  # K, white: the model explains T1
        "P1": 2e-6 * (lagged - lagged.mean()) + 2e-7 * rng.standard_normal(n),  # m, missing effect
    }
    residuals["T1"][1234] = 0.4  # the largest T1 residual, at t0 + 12340 s
    d = diagnose(residuals, dt_s, inputs={"speed": speed}, signatures={"lagged": lagged},
                 alpha=0.01, max_lag_s=1000.0, t0_s=t0, scales={"T1": 1.0, "P1": 1.5e-6})
    assert isinstance(d, Diagnostics) and list(d.channels) == ["T1", "P1"]
    t1, p1 = d.channels["T1"], d.channels["P1"]
    assert t1.t_max_s == t0 + 1234 * dt_s and t1.max_abs == 0.4 and t1.n == n
    assert t1.whiteness.white and not p1.whiteness.white
    best = p1.best("input")
    assert (best.name, best.lag, best.lag_s) == ("speed", 30, 300.0) and best.ccf > 0.9
    assert best.beyond_band
    assert p1.best("signature").lag == 0
    # T1 is independent of the speed: its largest |ccf| over 201 lags stays near 3 / sqrt(n) = 0.055
    assert abs(t1.best("input").ccf) < 0.1
    text = d.unexplained_description()
    assert text.startswith("The residual is largest in P1")  # 2e-6 / 1.5e-6 > 0.4 / 1
    assert "input speed" in text and "+300 s, the residual following it" in text
    # asked about T1 only (the channel outside its tolerance), it describes T1's largest value
    assert d.unexplained_description(among=["T1"]).startswith(
        "The residual is largest in T1 (max |r| = 0.4")
    out = d.to_dict()
    assert json_types_only(out)
    back = json.loads(json.dumps(out, allow_nan=False))
    assert back["channels"]["P1"]["cross"][0]["lag_s"] == 300.0
    assert back["channels"]["T1"]["whiteness"]["white"] is True
    with pytest.raises(ValueError, match="channel T2"):
        diagnose({"T2": np.zeros(100)}, dt_s)  # a constant residual has no autocorrelation


def test_a_constant_input_is_left_out_of_the_cross_correlations():
    """A run at standstill throughout logs a constant speed: its cross-correlation with a
    residual is 0 / 0, so diagnose leaves that input out (it follows no residual) and still
    reads the others; it raised before (found by feeding ``fit`` a run with its speed zeroed)."""
    n = 600
    rng = np.random.default_rng(3)
    power = np.repeat(rng.uniform(0.0, 5.0, n // 60), 60)
    r = {"T1": 0.1 * (power - power.mean()) + 0.01 * rng.standard_normal(n)}
    d = diagnose(r, 60.0, inputs={"speed": np.zeros(n), "power": power}, alpha=0.01)
    assert [c.name for c in d.channels["T1"].cross] == ["power"]
    assert d.channels["T1"].best("input").ccf > 0.9
    # constant only where the residual is valid: still constant for the correlation
    gappy = np.where(np.arange(n) < n // 2, 1500.0, np.nan)
    r_half = {"T1": np.where(np.arange(n) < n // 2, r["T1"], np.nan)}
    d = diagnose(r_half, 60.0, inputs={"speed": gappy, "power": power}, alpha=0.01)
    assert [c.name for c in d.channels["T1"].cross] == ["power"]


# ---------------------------------------------------------------------------------------- plots
def test_plot_helpers_draw_and_return_the_axes():
    from spindle.plots import pyplot

    plt = pyplot()
    x = ar1(0.5, 400, 2)
    fig, axes = plt.subplots(1, 2)
    assert plot_acf(axes[0], x, 20, dt_s=10.0) is axes[0]
    assert plot_cumulated_periodogram(axes[1], x, 0.01, dt_s=10.0) is axes[1]
    assert all(len(ax.lines) >= 3 for ax in axes)
    assert axes[1].get_xlabel() == "frequency [Hz]"
    plt.close(fig)


@pytest.mark.parametrize("phi", [0.0, 0.5, 0.9])
def test_effective_samples_of_ar1_is_n_over_its_integrated_time(phi):
    """An AR(1) series x_t = phi x_(t-1) + e_t has rho_k = phi^k, so tau_int = 1 + 2 sum_k
    phi^k = (1 + phi) / (1 - phi) (Sokal's definition; Madsen 2008 ch. 5): n_eff = n / tau.
    The tolerance is the estimator's scatter at n = 200,000: the sd of tau's estimate is about
    tau sqrt(2 (2M + 1) / n) with the window M ~ 5 tau (Sokal), 4 % at phi = 0.9; 4 sd."""
    rng = np.random.default_rng(7)
    n = 200_000
    x = signal.lfilter([1.0], [1.0, -phi], rng.standard_normal(n))
    tau = (1 + phi) / (1 - phi)
    sd_rel = math.sqrt(2 * (2 * 5 * tau + 1) / n)
    got = effective_samples({"a": x, "b": x[: n // 2]})  # channels add
    assert got == pytest.approx(1.5 * n / tau, rel=4 * sd_rel)
