"""Signature tests on a bench run's raw samples (compare.fit.signatures and each effect's own
test in compare.fit.effects), on analytic signals and on a peer's bench runs
(tests/data/peer-runs/bench-runs, data this project did not make):

- the event signatures around the speed steps: P1's centrifugal jump
  (effects.centrifugal.jump_test) and a sensor's lagging onset (effects.lag.lag_test);
- the power signatures at constant speed and no load: a preload's drifting power
  (effects.preload.drift_test) and windage's n^3 term (effects.windage.cube_test), and the
  grey box's heat bookkeeping of both effects when the power is measured;
- the load signature of coolant warming (effects.coolant.load_response_test): the bearing
  rings' response to the motor's loss at constant speed, separated from the rotor's path. A
  constructed case checks the regression and its jackknife against responses whose
  coefficients the test sets itself; the peer's two loaded runs (one with coolant warming,
  its control without) check it on a spindle the spec only approximates, through the
  calibrated base model as ``fit`` uses it.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from compare.fit.criteria import Criteria
from compare.fit.effects import LIBRARY, preload
from compare.fit.effects.centrifugal import jump_test
from compare.fit.effects.coolant import load_plateaus, load_response_test
from compare.fit.effects.lag import lag_test
from compare.fit.effects.preload import drift_test, model_drift_of
from compare.fit.effects.windage import cube_test
from compare.fit.signatures import Context, onset_ratio, segments, speed_steps
from lumped.elastic import first_order_lag
from spindle.cycles import ramped_steps, random_cycle

PEER_RUNS = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs"
CRITERIA = Criteria()
SHORT = CRITERIA.onset_scales[0]  # the onset scale of the minutes: 2 min over the next 4


def _steps(t: np.ndarray, n: np.ndarray, scale=SHORT):
    """The clean speed steps at ``scale`` with the criteria's step size."""
    return speed_steps(t, n, CRITERIA, scale.quiet_s)


# =================================================================== events at the speed steps
STEPS_RPM = [(0.0, 0.0), (3600.0, 2000.0), (9000.0, 6000.0), (16000.0, 1000.0),
             (22000.0, 4500.0), (29000.0, 0.0)]  # (start [s], speed [rpm]), non-monotonic
T_EV = np.arange(0.0, 36000.0, 1.0)  # 1 Hz, 10 h


def _step_speed(t: np.ndarray) -> np.ndarray:
    starts = np.array([s for s, _ in STEPS_RPM])
    return np.array([n for _, n in STEPS_RPM])[np.searchsorted(starts, t, side="right") - 1]


def _thermal(t: np.ndarray, tau_s: float, gain: float) -> np.ndarray:
    """A first-order thermal response to heat ~ speed: the exact solution of
    tau dy/dt + y = gain n(t), continuous at the steps."""
    y = np.zeros_like(t)
    level, y0, t0 = 0.0, 0.0, 0.0
    for k, (start, n) in enumerate(STEPS_RPM):
        end = STEPS_RPM[k + 1][0] if k + 1 < len(STEPS_RPM) else np.inf
        if k:
            y0 = level + (y0 - level) * math.exp(-(start - t0) / tau_s)
        level, t0 = gain * n, start
        m = (t >= start) & (t < end)
        y[m] = level + (y0 - level) * np.exp(-(t[m] - start) / tau_s)
    return y


def test_speed_steps_finds_the_steps_and_groups_a_ramp():
    n = _step_speed(T_EV).astype(float)
    ramp = (T_EV >= 9000.0) & (T_EV < 9004.0)
    n[ramp] = np.linspace(2000.0, 6000.0, ramp.sum() + 2)[1:-1]  # a drive ramping over 4 s
    steps = _steps(T_EV, n)
    assert [round(s.t_s, -2) for s in steps] == [3600.0, 9000.0, 16000.0, 22000.0, 29000.0]
    assert steps[1].n_before_rpm == 2000.0 and steps[1].n_after_rpm == 6000.0


@pytest.mark.parametrize("c_true", [0.02, 0.06])
def test_centrifugal_jump_is_recovered(c_true):
    """P1 = a fast thermal response (tau 300 s, so the short windows carry curvature) minus
    c n^2 and noise of 0.1 µm quantised to 0.1 µm, as a bench logs it. The estimate is within
    3 standard errors of the truth or 20 % (the curvature's bias, which the docstring says
    works against a shortening), and significant."""
    rng = np.random.default_rng(1)
    n = _step_speed(T_EV)
    p1_um = _thermal(T_EV, 300.0, 1e-3) - c_true * (n / 1000.0) ** 2
    p1_um = np.round(p1_um + rng.normal(0.0, 0.1, len(T_EV)), 1)
    test = jump_test(T_EV, p1_um * 1e-6, _steps(T_EV, n), CRITERIA)
    assert test.n_steps == 5
    assert abs(test.estimate - c_true) < max(3 * test.se, 0.2 * c_true)
    assert test.significant(0.01)


def test_a_jump_test_on_p1_logged_every_30_s_says_the_logging_is_too_sparse():
    """The shortening of the test above, P1 logged every 30 s: the 10-80 s after a step hold
    two or three samples, fewer than a line's four, so the jumps cannot be read. The test is
    not applicable and says why (the logging, not the cycle's steps)."""
    n = _step_speed(T_EV)
    p1_um = _thermal(T_EV, 300.0, 1e-3) - 0.06 * (n / 1000.0) ** 2
    every_30 = slice(None, None, 30)
    test = jump_test(T_EV[every_30], p1_um[every_30] * 1e-6, _steps(T_EV, n), CRITERIA)
    assert math.isnan(test.p_value) and test.n_steps == 0
    assert "5 step(s) have fewer than 4 of P1's samples within 10-80 s" in test.meaning


def test_the_step_and_line_criteria_are_the_ones_the_rules_read():
    """The entries of Criteria that steps, lines and jumps read change what they find: a step made
    in two, 5 s apart, is one step, and none where changes 2 s apart are not grouped (its
    halves are too near each other to be clean); a line that asks more samples than the 70 of a
    1 Hz log in the 10-80 s after a step, or a span longer than its window, reads no jump; no
    step of the cycle enters a jump regression that asks n^2 to change by 100 krpm^2 (10,000
    rpm from standstill); and no step enters an onset ratio that asks an impossible z of the
    late slope change."""
    n = _step_speed(T_EV).astype(float)
    n[(T_EV >= 9000.0) & (T_EV < 9005.0)] = 4000.0  # 2000 -> 4000, 5 s later -> 6000 rpm
    assert 9000.0 in [round(s.t_s, -2) for s in _steps(T_EV, n)]
    ungrouped = speed_steps(T_EV, n, replace(CRITERIA, step_ramp_s=2.0), SHORT.quiet_s)
    assert [round(s.t_s, -2) for s in ungrouped] == [3600.0, 16000.0, 22000.0, 29000.0]
    p1 = (_thermal(T_EV, 300.0, 1e-3) - 0.06 * (_step_speed(T_EV) / 1000.0) ** 2) * 1e-6
    assert jump_test(T_EV, p1, _steps(T_EV, n), CRITERIA).n_steps == 5
    for strict in (replace(CRITERIA, line_min_samples=100), replace(CRITERIA, line_min_span=1.1),
                   replace(CRITERIA, jump_min_dn2_krpm2=100.0)):
        assert jump_test(T_EV, p1, _steps(T_EV, n), strict).n_steps == 0
    y = _thermal(T_EV, 900.0, 1e-3)
    assert math.isfinite(onset_ratio(T_EV, y, _steps(T_EV, n), SHORT, CRITERIA)[0])
    assert math.isnan(onset_ratio(T_EV, y, _steps(T_EV, n), SHORT,
                                  replace(CRITERIA, onset_min_late_z=1e9))[0])


def test_no_jump_is_not_called_a_jump():
    """The same fast thermal response without the shortening: no significant shortening (at
    the fit's 1 % level), over 20 noise draws."""
    n = _step_speed(T_EV)
    for seed in range(20):
        rng = np.random.default_rng(seed)
        p1_um = np.round(_thermal(T_EV, 300.0, 1e-3) + rng.normal(0.0, 0.1, len(T_EV)), 1)
        assert not jump_test(T_EV, p1_um * 1e-6, _steps(T_EV, n), CRITERIA).significant(0.01)


def test_onset_ratio_tells_a_lagging_sensor():
    """A first-order response (time constant 900 s) has a concave onset: slope changes
    fastest right after the step, so the ratio of the early (10-120 s) to the late
    (120-360 s) slope change is above 1; analytically, for tau = 900 s, the mean slopes are
    e^-(t/tau) averaged over the windows, (e^(-10/900) - e^(-120/900)) / 110 over
    (e^(-120/900) - e^(-360/900)) / 240 = 1.17. The same signal through a 300 s lag has an
    S-shaped onset: below 1."""
    n = _step_speed(T_EV)
    y = _thermal(T_EV, 900.0, 1e-3)
    steps = _steps(T_EV, n)
    ratio, se, _ = onset_ratio(T_EV, y, steps, SHORT, CRITERIA)
    expected = ((math.exp(-10 / 900) - math.exp(-120 / 900)) / 110) / (
        (math.exp(-120 / 900) - math.exp(-360 / 900)) / 240)
    # tolerance: the straight-line fits over each window approximate the mean slope; 3 %
    assert ratio == pytest.approx(expected, rel=0.03)
    lagged, se_l, _ = onset_ratio(T_EV, first_order_lag(T_EV, y, 300.0), steps, SHORT,
                           CRITERIA)
    assert lagged < 1.0 - 3 * max(se_l, 1e-3)


def test_the_long_onset_scale_reads_a_slow_lag_on_a_noisy_channel():
    """A P1-like channel (noise 0.05 µm, 0.1 µm steps, as a bench logs P1) through a 900 s
    lag: over two and four minutes the slope change is lost in the quantisation, over 6.5 and
    13 minutes it is not; the test reports the long scale, Bonferroni over the two, and finds
    nothing on the same channel without the lag (20 noise seeds, none below p = 0.01, which
    expects 0.2 false alarms)."""
    scales = CRITERIA.onset_scales
    n = _step_speed(T_EV)
    y = _thermal(T_EV, 1800.0, 3e-4) + _thermal(T_EV, 300.0, 1e-4)  # µm, concave, two masses
    steps = {sc.name: _steps(T_EV, n, sc) for sc in scales}
    model = {sc.name: onset_ratio(T_EV, y, steps[sc.name], sc, CRITERIA)[0] for sc in scales}

    def bench(signal: np.ndarray, seed: int) -> np.ndarray:
        rng = np.random.default_rng(seed)
        return np.round((signal + rng.normal(0.0, 0.05, len(T_EV))) / 0.1) * 0.1

    lagged = lag_test("P1", T_EV, bench(first_order_lag(T_EV, y, 900.0), 2), steps, model,
                      CRITERIA)
    assert lagged.p_value < 0.01 and lagged.scale == scales[1].name
    assert [s["applicable"] for s in lagged.scales] == [True, True]
    assert lagged.scales[0]["z"] < 2.58  # the short scale alone: not significant at 1 %
    assert all(not lag_test("P1", T_EV, bench(y, s), steps, model, CRITERIA).significant(0.01)
               for s in range(20))


def test_the_onset_test_applies_only_where_the_model_is_concave_beyond_its_own_scatter():
    """The lag test reads a channel's onset against the model's: it applies where the model's
    onset ratio clears concave_ratio by z_(1-alpha) of the ratio's own standard error over the
    model's steps. The lagged channel of the test above, against a model ratio 1.9 with se 0.5
    (a scatter such as a peer run's T_stator shows: 0.85 +- 1.91): at alpha 0.01 the lower
    bound 1.9 - 2.33 * 0.5 = 0.74 is below 1.15, so nothing is read (without the se the lag is
    found); at alpha 0.1, 1.9 - 1.28 * 0.5 = 1.26 clears it and the lag is found: --alpha
    reaches the gate. The model's own se (the concave two-mass signal, noiseless) is small and
    leaves the test as it was."""
    from dataclasses import replace

    scales = CRITERIA.onset_scales
    n = _step_speed(T_EV)
    y = _thermal(T_EV, 1800.0, 3e-4) + _thermal(T_EV, 300.0, 1e-4)
    steps = {sc.name: _steps(T_EV, n, sc) for sc in scales}
    own = {sc.name: onset_ratio(T_EV, y, steps[sc.name], sc, CRITERIA)[:2] for sc in scales}
    rng = np.random.default_rng(2)
    bench = np.round((first_order_lag(T_EV, y, 900.0) + rng.normal(0.0, 0.05, len(T_EV)))
                     / 0.1) * 0.1
    with_own_se = lag_test("P1", T_EV, bench, steps, {k: v[0] for k, v in own.items()},
                           CRITERIA, {k: v[1] for k, v in own.items()})
    assert [s["applicable"] for s in with_own_se.scales] == [True, True]
    assert with_own_se.p_value < 0.01

    ambiguous = {sc.name: 1.9 for sc in scales}
    scatter = {sc.name: 0.5 for sc in scales}
    assert lag_test("P1", T_EV, bench, steps, ambiguous, CRITERIA).p_value < 0.01
    vetoed = lag_test("P1", T_EV, bench, steps, ambiguous, CRITERIA, scatter)
    assert not any(s["applicable"] for s in vetoed.scales) and math.isnan(vetoed.p_value)
    assert all(s["model_ratio_se"] == 0.5 for s in vetoed.scales)
    lenient = lag_test("P1", T_EV, bench, steps, ambiguous, replace(CRITERIA, alpha=0.1),
                       scatter)
    assert all(s["applicable"] for s in lenient.scales) and lenient.p_value < 0.1


def test_event_signatures_on_the_peer_runs():
    """On a peer's nine runs (an independent simulator): P1 jumps significantly with n^2 only
    on the centrifugal-shortening run, and T1's onset is S-shaped (ratio below 1 by more than
    3 se) only on the sensor-lag run; on every other run T1's onset ratio is above 1. Model-
    free: the raw samples only."""
    from spindle.bench import read_bench

    truth = json.loads((PEER_RUNS / "truth.json").read_text(encoding="utf-8"))
    for label, t in sorted(truth.items()):
        run = read_bench(PEER_RUNS / f"{label}.csv")
        steps = _steps(run.time_s, run.columns["speed_rpm"])
        cf = jump_test(*run.channel("P1"), steps, CRITERIA)
        assert cf.significant(0.01) == (t["truth"] == "centrifugal_shortening"), label
        ratio, se, _ = onset_ratio(*run.channel("T1"), steps, SHORT, CRITERIA)
        lag = ratio < 1.0 - 3 * se
        assert lag == (t["truth"] == "sensor_lag"), (label, ratio, se)
        if not lag:
            assert ratio > 1.0, label


# =================================================================== the power at constant speed
#: a non-monotonic no-load cycle: (start [s], speed [rpm]); each level held an hour or more
LEVELS = [(0.0, 0.0), (900.0, 1500.0), (4500.0, 3000.0), (9900.0, 6000.0), (17100.0, 2000.0),
          (20700.0, 4500.0), (27900.0, 1000.0), (31500.0, 5000.0), (38700.0, 3000.0),
          (44100.0, 0.0)]
T_PW = np.arange(0.0, 46000.0, 1.0)


def _level_speed(t: np.ndarray) -> np.ndarray:
    starts = np.array([s for s, _ in LEVELS])
    return np.array([n for _, n in LEVELS], dtype=float)[
        np.searchsorted(starts, t, side="right") - 1]


def _losses_W(n_rpm: np.ndarray, c_windage: float = 0.0) -> np.ndarray:
    """No-load losses [W] of a made-up spindle: hysteresis, viscous friction, eddy currents
    (coefficients of the size of the SPL2782 family's), plus windage c (n / 1000)^3."""
    k = n_rpm / 1000.0
    return 12.0 * k + 9.0 * k ** (5.0 / 3.0) + 1.5 * k ** 2 + c_windage * k ** 3


def _power_run(power_W: np.ndarray, torque_Nm: float | None = None, seed: int = 0):
    """A bench run as the power tests read it, with 4 W of noise on the power (as logged)."""
    rng = np.random.default_rng(seed)
    cols = {"speed_rpm": _level_speed(T_PW),
            "power_kW": (power_W + rng.normal(0, 4.0, len(T_PW))) / 1e3}
    if torque_Nm is not None:
        cols["load_torque_Nm"] = np.full(len(T_PW), torque_Nm)
    return SimpleNamespace(time_s=T_PW, columns=cols)


def _with_drift(base_W: np.ndarray, k_per_kW: float, tau_s: float = 900.0) -> np.ndarray:
    """A preload-like power: at each level the extra friction relaxes with tau towards
    k P (P - 0) (the ring difference follows the bearing heat), continuous across steps."""
    out = base_W.copy()
    extra, t0, target = 0.0, 0.0, 0.0
    starts = [s for s, _ in LEVELS] + [T_PW[-1] + 1]
    for i, (start, _n) in enumerate(LEVELS):
        m = (T_PW >= start) & (T_PW < starts[i + 1])
        if i:
            extra = target + (extra - target) * math.exp(-(start - t0) / tau_s)
        level = float(np.mean(base_W[m]))
        target, t0 = k_per_kW * level * level / 1e3, start
        out[m] += target + (extra - target) * np.exp(-(T_PW[m] - start) / tau_s)
    return out


def _drag_box(monkeypatch, t_s: np.ndarray, base_W: np.ndarray):
    """A stand-in for the calibrated base grey box whose q_b (T_inner - T_outer) [W] is the
    analytic preload's extra power at k = 1 (``_with_drift``'s, sampled at ``t_s``), one
    front bearing set: preload.model_drift_of reads it over a segment's windows as it reads
    the grey box's (preload.ring_drag_W)."""
    unit = _with_drift(base_W, 1.0) - base_W
    monkeypatch.setattr(preload, "ring_drag_W",
                        lambda gb, theta: {"front": np.interp(t_s, T_PW, unit)})
    spec = SimpleNamespace(heat_sources=[SimpleNamespace(name="front", part="front_bearing")],
                           part=lambda name: SimpleNamespace(role="front_bearing"))
    return SimpleNamespace(inputs=SimpleNamespace(grid_s=t_s), spec=spec)


def _power_tests(run, gb, theta: dict[str, float] | None = None) -> dict:
    """Both power tests of ``run`` as ``fit`` reads them: each effect's signature on one
    compare.fit.signatures.Context of the grey box ``gb`` at ``theta``, in the library's
    order (the windage test reads the preload's)."""
    ctx = Context(run, gb, theta or {}, [], CRITERIA)
    for name in ("bearing_preload", "windage_loss"):
        ctx.tests.update(LIBRARY[name].signature(ctx))
    return ctx.tests


def test_settled_power_has_no_drift_and_no_windage(monkeypatch):
    base = _losses_W(_level_speed(T_PW))
    tests = _power_tests(_power_run(base), _drag_box(monkeypatch, T_PW, base))
    assert not tests["bearing_preload"].significant(0.01)
    assert np.isfinite(tests["windage_loss"].p_value)  # applicable: 7 levels, factor 6
    assert not tests["windage_loss"].significant(0.01)


@pytest.mark.parametrize("c_true", [0.3, 0.9])
def test_windage_term_is_recovered(c_true, monkeypatch):
    """c within its 95 % interval (the power is exactly of the regression's form, so only the
    noise limits it)."""
    base = _losses_W(_level_speed(T_PW))
    test = _power_tests(_power_run(_losses_W(_level_speed(T_PW), c_true)),
                        _drag_box(monkeypatch, T_PW, base))["windage_loss"]
    assert test.significant(0.01)
    lo, hi = test.parameter["ci95"]
    assert lo <= c_true <= hi


def test_a_drifting_power_is_a_preload_and_not_windage(monkeypatch):
    """A friction that rises as the bearing warms: the drift test fires and the windage test,
    whose levels would read steeper, is not applied. The model's drift here is the analytic
    preload's own at k = 1, so the front set's coefficient comes back within its 95 %
    interval (preload.front_parameter; only the 4 W noise limits it)."""
    base = _losses_W(_level_speed(T_PW))
    tests = _power_tests(_power_run(_with_drift(base, k_per_kW=0.15)),
                         _drag_box(monkeypatch, T_PW, base))
    assert tests["bearing_preload"].significant(0.01) and tests["bearing_preload"].estimate > 0
    assert math.isnan(tests["windage_loss"].p_value)
    lo, hi = tests["bearing_preload"].parameter["ci95"]
    assert lo <= 0.15 <= hi


def test_loaded_segments_are_not_read(monkeypatch):
    """Under load the copper loss drifts with the winding temperature: no test applies."""
    base = _losses_W(_level_speed(T_PW))
    tests = _power_tests(_power_run(_with_drift(base, 0.15), torque_Nm=30.0),
                         _drag_box(monkeypatch, T_PW, base))
    assert math.isnan(tests["bearing_preload"].p_value)
    assert math.isnan(tests["windage_loss"].p_value)


def test_segments_cut_at_the_speed_steps(monkeypatch):
    base = _losses_W(_level_speed(T_PW))
    segs = segments(_power_run(base), CRITERIA)
    assert [round(s.speed_rpm) for s in segs] == [n for _, n in LEVELS]
    assert segs[3].duration_s == pytest.approx(7200.0, abs=2.0)
    drift = model_drift_of(_drag_box(monkeypatch, T_PW, base), {}, CRITERIA)
    assert drift_test(segs[:2], CRITERIA, drift).n_steps < 3 and math.isnan(
        cube_test(segs[:3], CRITERIA).p_value)  # too little to read: not applicable


def test_a_small_speed_step_cuts_a_segment_and_is_no_drift(monkeypatch):
    """5800 then 6000 rpm, an hour each (a random cycle's neighbours): two segments, and the
    power's step between them is no preload's drift. One segment of both read as a 100 W
    drift at z 2.3 on three synthetic runs without a preload (docs/fit-history.md). The drive's own
    scatter (a few rpm) cuts nothing: the band is max(20 rpm, 1 %)."""
    t = np.arange(0.0, 4 * 3600.0, 1.0)
    n = np.select([t < 900.0, t < 900.0 + 3600.0, t < 900.0 + 7200.0], [0.0, 5800.0, 6000.0],
                  1000.0)
    rng = np.random.default_rng(3)
    n_logged = np.where(n > 0, n + rng.integers(-3, 4, len(t)), 0.0)
    run = SimpleNamespace(time_s=t, columns={
        "speed_rpm": n_logged, "power_kW": (_losses_W(n) + rng.normal(0, 4.0, len(t))) / 1e3})
    segs = segments(run, CRITERIA)
    assert [round(s.speed_rpm, -2) for s in segs] == [0.0, 5800.0, 6000.0, 1000.0]
    # the model's drift: the analytic preload's on the long cycle, any finite predictor will
    # do (the assertion is on the measured drifts)
    base = _losses_W(_level_speed(T_PW))
    drift = model_drift_of(_drag_box(monkeypatch, t, base), {}, CRITERIA)
    rows = drift_test(segs, CRITERIA, drift).per_step
    drifts = [r["drift_W"] for r in rows]
    assert len(drifts) == 3  # the three moving segments, each longer than half an hour
    assert all(abs(d) < 5.0 for d in drifts), drifts  # 4 W noise over 240-900 s windows


def test_power_signatures_on_the_peer_runs():
    """On the peer's nine runs: the drift only on the preload run, the n^3 term only on the
    windage run (both far beyond 1 %), neither test applicable on the loaded runs. The drift
    is regressed on the spec's own grey box at its spec values on each run's inputs (not
    calibrated: a second each)."""
    from compare.fit.greybox import GreyBox
    from compare.fit.params import DEFAULT_BASE_EXTRA, default_theta
    from spindle.bench import read_bench
    from spindle.bench_inputs import interval_inputs
    from spindle.drive import drive_for
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    drive = drive_for(spec)

    def tests_of(label: str) -> dict:
        run = read_bench(PEER_RUNS / f"{label}.csv")
        gb = GreyBox(spec, drive, interval_inputs(run), base_extra=DEFAULT_BASE_EXTRA)
        return _power_tests(run, gb, default_theta(gb.parameters()))

    truth = json.loads((PEER_RUNS / "truth.json").read_text(encoding="utf-8"))
    w = None
    for label, t in sorted(truth.items()):
        tests = tests_of(label)
        fired = sorted(k for k, v in tests.items() if v.significant(0.01))
        expected = [t["truth"]] if t["truth"] in ("bearing_preload", "windage_loss") else []
        assert fired == expected, (label, {k: v.z for k, v in tests.items()})
        if label in ("dev-08", "dev-09"):  # loaded at every step
            assert all(math.isnan(v.p_value) for v in tests.values())
        if label == "dev-05":
            w = tests["windage_loss"]
    # the peer's windage: 190 W more than the control run at 6000 rpm, 0.88 W/krpm^3 (their
    # difference); part of it goes to the n^2 column of the regression
    assert 0.6 < w.parameter["value"] < 1.0


# ------------------------------------------------------------- heat bookkeeping in the grey box
@pytest.fixture(scope="module")
def box():
    from spindle.bench_inputs import Inputs
    from spindle.drive import DRIVES
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    grid = np.arange(0.0, 4 * 3600.0 + 1.0, 60.0)
    m = len(grid) - 1
    n = np.where(grid[:-1] < 7200.0, 6000.0, 2000.0)
    inp = Inputs(grid, n, np.where(n > 3000, 0.40, 0.10), np.zeros(m), np.full(m, 293.15),
                 np.full(m, 293.15), 293.15)
    return spec, DRIVES["spl2782"], inp


def test_windage_is_taken_from_the_motor_when_the_power_is_measured(box):
    from compare.fit.effects.windage import from_motor
    from compare.fit.greybox import GreyBox

    spec, drive, inp = box
    src = GreyBox(spec, drive, inp).sources(0.3, 0.06)
    out = from_motor(src, 0.5, inp.speed_rpm, inp.power_kW)
    total = sum(src.values())
    np.testing.assert_allclose(sum(out.values()), total, rtol=1e-12)  # the measured heat
    np.testing.assert_allclose(out["windage"], 0.5 * (inp.speed_rpm / 1e3) ** 3)
    unknown = from_motor(src, 0.5, inp.speed_rpm, np.full_like(inp.power_kW, np.nan))
    np.testing.assert_allclose(sum(unknown.values()), total + unknown["windage"], rtol=1e-12)


def test_preload_heat_is_taken_from_the_motor_when_the_power_is_measured(box):
    """With a measured power the preload moves heat from the motor to the bearings: the heat
    into the network at any temperature field equals the power balance's, whatever k and the
    ring differences; without the drag flows it would rise by sum k q_b dT_b."""
    from compare.fit.greybox import GreyBox
    from compare.fit.params import default_theta

    spec, drive, inp = box
    gb = GreyBox(spec, drive, inp, effects=("bearing_preload",))
    theta = default_theta(gb.parameters())
    theta.update(k_preload_1_K=0.3, k_preload_rear_1_K=0.1)
    sysm = gb._model(theta).system
    src = gb.sources(theta["f0"], theta["rotor_share"])
    q = np.array([src[s][0] if s in src else 0.0 for s in sysm.source_names])
    rng = np.random.default_rng(1)
    T_all = 293.15 + rng.uniform(0.0, 10.0, len(sysm.capacity))  # every node
    assert sysm.heat_in(T_all, q) == pytest.approx(float(q.sum()), rel=1e-12)
    _feedback, drag = gb._structure()[-1]["bearing_preload"]
    assert len(drag) > 0  # the drag flows exist


def test_spec_values_of_the_drive_parameters_come_from_the_drive(box):
    """The prior centres of f0 and the rotor share are the drive file's own values (a
    recalibrated drive, or a user's, moves them), not numbers written into the fit."""
    from dataclasses import replace

    from compare.fit.greybox import GreyBox

    spec, drive, inp = box
    params = GreyBox(spec, drive, inp).parameters()
    assert params["f0"].default == next(iter(drive.bearings.values())).f0
    assert params["rotor_share"].default == drive.motor.rotor_loss_share
    other = drive.with_f0(1.1).with_rotor_share(0.2)
    params = GreyBox(spec, other, inp).parameters()
    assert params["f0"].default == 1.1 and params["rotor_share"].default == 0.2
    mixed = replace(drive, bearings={k: replace(b, f0=0.2 + 0.1 * i)
                                     for i, (k, b) in enumerate(drive.bearings.items())})
    assert GreyBox(spec, mixed, inp).parameters()["f0"].default == 0.30  # no common value


# =================================================================== the rings' load response
#: a loaded cycle: (start [s], speed [rpm]); the torque ramps 20 -> 40 -> 20 N m in each
LOADED = [(0.0, 0.0), (900.0, 1500.0), (4500.0, 3000.0), (8100.0, 6000.0), (11700.0, 2000.0),
          (15300.0, 4500.0), (18900.0, 1000.0), (22500.0, 5000.0), (26100.0, 0.0)]
T_LD = np.arange(0.0, 28000.0, 10.0)
GRID = np.arange(0.0, 28000.0 + 60.0, 60.0)


def _loaded_level(t: np.ndarray) -> np.ndarray:
    starts = np.array([s for s, _ in LOADED])
    return np.searchsorted(starts, t, side="right") - 1


def _loaded_speed(t: np.ndarray) -> np.ndarray:
    return np.array([n for _, n in LOADED], dtype=float)[_loaded_level(t)]


def _torque(t: np.ndarray) -> np.ndarray:
    starts = np.array([s for s, _ in LOADED] + [1e9])
    k = _loaded_level(t)
    x = (t - starts[k]) / (starts[k + 1] - starts[k])
    return np.where(_loaded_speed(t) > 0, 20.0 + 20.0 * (1.0 - np.abs(2.0 * x - 1.0)), 0.0)


def _lagged(u: np.ndarray, t: np.ndarray, tau_s: float) -> np.ndarray:
    out = np.empty_like(u)
    out[0] = u[0]
    for i in range(1, len(u)):
        a = math.exp(-(t[i] - t[i - 1]) / tau_s)
        out[i] = a * out[i - 1] + (1 - a) * u[i]
    return out


class _Box:
    """A stand-in for the grey box with responses the test sets: the rings follow the motor's
    loss change through the water (fast, equal at T1 and T2) and through the rotor (slower,
    stronger at T1); the base model misses every plateau by an offset of its own."""

    def __init__(self) -> None:
        q = 0.5 * _torque(GRID) ** 2  # copper loss [W] at the grid: 200-800 W
        self.water = {"T1": 0.8 * _lagged(q, GRID, 600.0), "T2": 0.8 * _lagged(q, GRID, 600.0)}
        self.rotor = {"T1": 0.004 * _lagged(q, GRID, 2400.0),
                      "T2": 0.002 * _lagged(q, GRID, 2400.0)}
        self.inputs = SimpleNamespace(grid_s=GRID)
        self.effects: tuple[str, ...] = ()

    def variant(self, effects):
        box = _Box.__new__(_Box)
        box.__dict__.update(self.__dict__)
        box.effects = tuple(effects)
        return box

    def simulate(self, theta: dict[str, float]) -> dict[str, np.ndarray]:
        R = theta.get("R_adv_K_W", 0.0) if "coolant_dynamics" in self.effects else 0.0
        return {c: 300.0 + R * self.water[c] + math.log(theta["rotor_share"] / 0.06)
                * self.rotor[c] for c in ("T1", "T2")}


def _loaded_run(box: _Box, R_true: float, share_true: float, seed: int = 0):
    """Bench samples: the box's response at the true values, and what the base model misses
    and the regression does not know: an offset per level and channel (its misfit at that
    speed) and a settling after each speed step (its masses' time constants, 25 min, 0.3 K
    at the step), plus 0.03 K of sensor noise."""
    rng = np.random.default_rng(seed)
    truth = box.variant(("coolant_dynamics",)).simulate(
        {"R_adv_K_W": R_true, "rotor_share": share_true})
    offsets = rng.normal(0.0, 0.5, (len(LOADED), 2))
    settle = rng.normal(0.0, 0.3, (len(LOADED), 2))
    since = T_LD - np.array([s for s, _ in LOADED])[_loaded_level(T_LD)]
    cols = {"speed_rpm": _loaded_speed(T_LD), "load_torque_Nm": _torque(T_LD)}
    channels = {}
    for j, c in enumerate(("T1", "T2")):
        y = (np.interp(T_LD, GRID, truth[c]) + offsets[_loaded_level(T_LD), j]
             + settle[_loaded_level(T_LD), j] * np.exp(-since / 1500.0)
             + rng.normal(0, 0.03, len(T_LD)))
        channels[c] = (T_LD, y)
        cols[f"{c}_C"] = y
    return SimpleNamespace(time_s=T_LD, columns=cols, channels=list(channels),
                           channel=lambda c: channels[c])


def test_plateaus_need_a_varying_load():
    box = _Box()
    run = _loaded_run(box, 0.0, 0.06)
    plats = load_plateaus(run, CRITERIA)
    assert len(plats) == 7  # every turning level of LOADED, each an hour long
    run.columns["load_torque_Nm"] = np.where(_loaded_speed(T_LD) > 0, 30.0, 0.0)  # constant
    assert load_plateaus(run, CRITERIA) == []
    del run.columns["load_torque_Nm"]  # a no-load run: nothing to read
    test = load_response_test(run, box, {"rotor_share": 0.06}, CRITERIA)
    assert math.isnan(test.p_value) and "not applicable" in test.meaning
    assert not test.applies


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_coolant_resistance_is_recovered_beside_a_wrong_rotor_share(seed):
    """R = 0.002 K/W with the rotor's share 40 % above the base model's: R comes back within
    its own 95 % interval (Student t, plateaus - 1 dof) and significant at 1 %."""
    box = _Box()
    test = load_response_test(_loaded_run(box, 0.002, 0.084, seed), box,
                              {"rotor_share": 0.06}, CRITERIA)
    lo, hi = test.parameter["ci95"]
    assert lo <= 0.002 <= hi and test.p_value < 0.01, (test.estimate, test.se)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_wrong_rotor_share_alone_is_not_coolant_warming(seed):
    """No coolant warming, but the rotor's share 40 % above the model's: the load response is
    the rotor's, and the test does not fire at 1 %."""
    box = _Box()
    test = load_response_test(_loaded_run(box, 0.0, 0.084, seed), box,
                              {"rotor_share": 0.06}, CRITERIA)
    assert not test.significant(0.01), (test.estimate, test.z)


def test_ramped_cycle_ramps_within_each_speed_step():
    pieces = ramped_steps(3000.0, 3600.0, 10.0, 30.0)
    torques = [p.load_torque_Nm for p in pieces]
    assert {p.speed_rpm for p in pieces} == {3000.0}
    assert sum(p.duration_s for p in pieces) == pytest.approx(3600.0)
    k = int(np.argmax(torques))
    assert np.all(np.diff(torques[:k + 1]) >= 0) and np.all(np.diff(torques[k:]) <= 0)
    assert max(torques) - min(torques) >= CRITERIA.load_span_Nm
    cycle = random_cycle(np.random.default_rng(4), 6000.0, ramped=True)
    assert cycle.duration_s == pytest.approx(16 * 3600.0)
    assert 6000.0 in {s.speed_rpm for s in cycle.steps}
    # the plain random cycle is what it was: one step per speed, the same draws
    plain = random_cycle(np.random.default_rng(4), 6000.0)
    assert len({s.speed_rpm for s in plain.steps}) >= 5
    assert all(s.load_torque_Nm == 0.0 for s in plain.steps)


# slow: about 14 s, two base calibrations. The default run keeps the same test on synthetic
# loaded runs (the tests above and below); tests/test_peer_runs.py fits these two runs whole
@pytest.mark.slow
def test_coolant_signature_on_the_peer_loaded_runs():
    """The peer's loaded pair: the coolant run's rings follow the motor's loss beyond the
    rotor's path (significant at 1 %), the control's do not (its base-structure bias, R
    0.0003 K/W, is not significant at 1 %); the test applies to both (the calibrated seats
    make the paths separable); the no-load runs have no load plateaus. About 25 s on free
    CPUs: two base calibrations."""
    from compare.fit.run import calibrate_base
    from spindle.bench import read_bench
    from spindle.spec_reader import load_spec

    truth = json.loads((PEER_RUNS / "truth.json").read_text(encoding="utf-8"))
    assert truth["dev-08"]["truth"] == "coolant_dynamics" and truth["dev-09"]["truth"] is None
    spec = load_spec("spl2782")
    fired = {}
    for label in ("dev-08", "dev-09"):
        prep = calibrate_base(PEER_RUNS / f"{label}.csv", spec)
        test = load_response_test(prep.run, prep.cal.gb, prep.base.theta, CRITERIA)
        assert test.n_steps >= 8  # nine speed plateaus with a ramped load
        assert math.isfinite(test.p_value), test.meaning  # applies: judged on it, not the loop
        fired[label] = test.significant(0.01)
    assert fired == {"dev-08": True, "dev-09": False}
    assert load_plateaus(read_bench(PEER_RUNS / "dev-06.csv"), CRITERIA) == []


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_warming_below_the_tolerance_is_seen_by_the_test(seed):
    """R = 0.0004 K/W warms the box's rings by at most 0.26 K (R x 0.8 x 800 W, less with the
    water's lag), a quarter of the 1 K tolerance: the regression still sees it (t 6-12 here; t
    3.3 on the peer's loaded control, docs/fit-history.md). Whether it is named is the selection's
    materiality criterion (compare.fit.select, Criteria.material_peak), not the test's: the
    test is significant, and the warming at its estimate is below half a tolerance."""
    from spindle.tolerances import TEMPERATURE_TOLERANCE_K

    box = _Box()
    test = load_response_test(_loaded_run(box, 0.0004, 0.06, seed), box,
                              {"rotor_share": 0.06}, CRITERIA)
    assert test.p_value < 0.01 and test.significant(0.01), (test.estimate, test.z)
    theta = {"rotor_share": 0.06}
    base = box.simulate(theta)
    warm = box.variant(("coolant_dynamics",)).simulate({**theta, "R_adv_K_W": test.estimate})
    peak = max(float(np.max(np.abs(warm[c] - base[c]))) for c in base)
    assert peak / TEMPERATURE_TOLERANCE_K < CRITERIA.material_peak


def test_paths_that_cannot_be_told_apart_leave_the_test_out():
    """The rotor's path with the water's own shape and lag (as when the water reaches the rings
    only through the housing, like the shaft's heat): the regressors correlate at r = 1, above
    Criteria.max_path_correlation, so the test does not apply, whatever the data; the loop
    judges."""
    box = _Box()
    box.rotor = {c: 0.005 * box.water[c] for c in ("T1", "T2")}
    test = load_response_test(_loaded_run(box, 0.002, 0.084, 0), box, {"rotor_share": 0.06},
                              CRITERIA)
    assert math.isnan(test.p_value) and "not separable" in test.meaning
    assert not test.significant(0.01)


def test_a_drift_test_the_log_cannot_read_is_unreadable_and_vetoes(tmp_path):
    """dev-06 (no load, long segments after its speed steps) logged every 5 min: the
    conditions of the preload's drift test hold, but the power 2-6 min after each step is
    not in the log. The test is then unreadable, not "not applicable", and its outcome
    vetoes the open loop (a preload had been named on this control at p = 7e-30 by the open
    loop alone, fuzzing round 4). Logged every 10 s, the test reads and applies."""
    from compare.fit.criteria import Criteria
    from compare.fit.effects.preload import drift_test
    from compare.fit.select import signature_outcome
    from compare.fit.signatures import segments
    from spindle.bench import read_bench

    src = PEER_RUNS / "dev-06.csv"
    lines = src.read_text(encoding="utf-8").splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("time_s"))
    sparse, last = lines[:head + 1], -1
    for ln in lines[head + 1:]:
        k = int(float(ln.split(",")[0]) // 300.0)
        if k != last:
            sparse.append(ln)
            last = k
    cr = Criteria()
    dense = drift_test(segments(read_bench(src), cr), cr, lambda a, b: 1.0)
    assert dense.applies and not dense.unreadable
    path = tmp_path / "dev-06-5min.csv"
    path.write_text("\n".join(sparse) + "\n", encoding="utf-8")
    test = drift_test(segments(read_bench(path), cr), cr, lambda a, b: 1.0)
    assert test.unreadable and not test.applies and "unreadable" in test.meaning
    assert signature_outcome(test, cr.alpha) is False
    assert signature_outcome(dense, cr.alpha) is not None
