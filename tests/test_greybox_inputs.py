"""The grey box's per-interval inputs from a bench run (spindle.bench_inputs.interval_inputs): the
losses an interval takes from the power balance are the mean over its samples of
P_el - M omega, also where the speed ramps inside the interval (issue 32)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from spindle.bench import BenchRun
from spindle.bench_inputs import interval_inputs


def _ramp_run(losses_W: float = 900.0, torque_Nm: float = 42.0) -> BenchRun:
    """10 min at 1 Hz: 5000 rpm, a ramp to 1000 rpm from 125 s to 135 s (inside the cell
    120-180 s, before its middle), then 1000 rpm; a constant process torque and constant losses, so the logged
    electrical power is the losses plus M omega at every sample."""
    t = np.arange(0.0, 601.0, 1.0)
    n = np.interp(t, [0.0, 125.0, 135.0, 600.0], [5000.0, 5000.0, 1000.0, 1000.0])
    M = np.full_like(t, torque_Nm)
    P_kW = (losses_W + M * 2.0 * math.pi * n / 60.0) / 1e3
    cols = {"speed_rpm": n, "power_kW": P_kW, "load_torque_Nm": M,
            "T_env_C": np.full_like(t, 20.0), "T_coolant_C": np.full_like(t, 20.0),
            "T1_C": np.full_like(t, 20.0)}
    return BenchRun(Path("ramp.csv"), {}, t, cols, {}, [], ["T1"], float(t[-1]),
                    load_torque_measured=True)


def test_losses_are_the_samples_mean_through_a_ramp_inside_a_cell():
    inp = interval_inputs(_ramp_run(), 60.0)
    omega = 2.0 * math.pi * inp.speed_rpm / 60.0  # rad/s of each interval's held speed
    losses = inp.power_kW * 1e3 - inp.load_torque_Nm * omega
    # every interval, the ramp's included, gives the samples' 900 W to round-off
    np.testing.assert_allclose(losses, 900.0, atol=1e-6)
    # also where the ramp's cell takes the speed of its mean friction (the torque is the one
    # that does the mean mechanical work at that speed)
    with_friction = interval_inputs(_ramp_run(), 60.0, friction_W=lambda n: n * n)
    w = 2.0 * math.pi * with_friction.speed_rpm / 60.0
    assert not np.allclose(w, omega)
    np.testing.assert_allclose(with_friction.power_kW * 1e3 - with_friction.load_torque_Nm * w,
                               900.0, atol=1e-6)
    # not vacuous: the mean power less the torque at the middle's speed (the old inputs) is
    # M (mean omega - omega_mid) = 42 N m x 70 rad/s, about 2.9 kW, off in the ramp's cell
    k = int(np.flatnonzero((inp.grid_s[:-1] <= 150.0) & (inp.grid_s[1:] > 150.0))[0])
    old = inp.power_kW[k] * 1e3 - 42.0 * omega[k]
    assert abs(old - 900.0) > 1000.0, old


def test_a_run_without_torque_has_none():
    from dataclasses import replace

    run = _ramp_run()
    run = replace(run, columns={**run.columns, "load_torque_Nm": np.zeros_like(run.time_s)},
                  load_torque_measured=False)
    assert np.all(interval_inputs(run, 60.0).load_torque_Nm == 0.0)


def test_an_on_change_log_averages_over_time_not_over_samples():
    """A bench that logs on change writes samples where the signal moves: a drive at 1 kW for
    50 s that steps to 5 kW and reports every second after the step (its scatter crossing the
    dead band) has a time mean of (50 x 1 + 10 x 5) / 60 kW over the minute, while the mean of
    its 11 samples is 4.6 kW (spindle.bench_inputs.cell_means with a hold). A sample holds for
    the hold at most: a cell the log never reaches gets the interpolation, not a stale
    value. With regular samples the two means agree (to the cell's edge sample)."""
    from spindle.bench_inputs import cell_means

    t = np.array([0.0, *np.arange(50.0, 60.0, 1.0)])
    y = np.array([1.0, *np.full(10, 5.0)])
    edges, centres = np.array([0.0, 60.0]), np.array([30.0])
    assert cell_means(t, y, edges, centres)[0] == pytest.approx(4.636, abs=1e-3)
    assert cell_means(t, y, edges, centres, hold_s=120.0)[0] == pytest.approx(100.0 / 60.0)
    # a 5 min silence after the last sample: the second cell is held only for the hold's
    # 120 s (its first 60 s), the third not at all (it interpolates, here the last value)
    edges = np.array([0.0, 60.0, 120.0, 180.0, 240.0])
    out = cell_means(np.array([0.0, 59.0]), np.array([1.0, 3.0]), edges,
                     0.5 * (edges[1:] + edges[:-1]), hold_s=120.0)
    assert out[0] == pytest.approx((59 * 1 + 1 * 3) / 60) and out[1] == pytest.approx(3.0)
    tr = np.arange(0.0, 60.0, 1.0)
    yr = np.where(tr < 50, 1.0, 5.0)
    assert cell_means(tr, yr, edges[:2], centres, hold_s=120.0)[0] == pytest.approx(
        cell_means(tr, yr, edges[:2], centres)[0])


def _logged_every(step_s: float, switch_s: float = 3 * 3600.0 + 0.5 * 600.0,
                  temperatures_s: float | None = None) -> BenchRun:
    """6 h of a no-load run logged every ``step_s`` (the temperatures every
    ``temperatures_s`` where given, their cells empty between): 2000 rpm, stepping to 6000
    rpm at ``switch_s``, between two of a 10 min logger's rows; T1 a smooth warming."""
    t = np.arange(0.0, 6 * 3600.0 + 1.0, step_s)
    n = np.where(t < switch_s, 2000.0, 6000.0)
    T1 = 20.0 + 5.0 * (1.0 - np.exp(-t / 7200.0))
    if temperatures_s:
        T1 = np.where(np.isclose(np.mod(t, temperatures_s), 0.0), T1, np.nan)
    cols = {"speed_rpm": n, "power_kW": np.where(n > 3000.0, 1.5, 0.3),
            "T_env_C": np.full_like(t, 20.0), "T_coolant_C": np.full_like(t, 20.0),
            "T1_C": T1}
    return BenchRun(Path("sparse.csv"), {}, t, cols, {}, [], ["T1"], float(t[-1]))


@pytest.mark.parametrize("step_s, temperatures_s", [(600.0, None), (130.0, None),
                                                    (10.0, 600.0)])
def test_a_sparse_logger_has_no_gaps_between_its_rows(step_s, temperatures_s):
    """A bench that writes a row every 10 min (or its temperatures every 10 min beside a
    drive every 10 s) logs throughout: no logging gap, and the channel is known at every
    grid point between its samples. A stretch without a row was a gap when longer than two
    60 s grid steps, so fit refused such runs ("too few samples") or, logged every 2 min
    with jitter, cut them into hundreds of gaps (fuzzing round 4)."""
    from compare.fit.gaps import logging_gaps
    from spindle.bench_inputs import bench_grid, logging_step_s, resample

    run = _logged_every(step_s, temperatures_s=temperatures_s)
    grid = bench_grid(run, 60.0)
    assert logging_gaps(run.time_s, grid) == []
    t, y = run.channel("T1")
    values = resample(t, y, grid, 2.0, logging_step_s(run.time_s))
    assert np.all(np.isfinite(values[grid <= t[~np.isnan(y)][-1]]))
    # a real gap is still one: two hours without a row in a run logged every 10 min
    cut = (run.time_s < 2 * 3600.0) | (run.time_s > 4 * 3600.0)
    kept = run.time_s[cut]
    assert logging_gaps(kept, grid) == [(float(kept[kept < 7200.0][-1]),
                                         float(kept[kept > 14400.0][0]))]


def test_a_step_between_a_sparse_loggers_rows_is_placed_at_the_silences_middle():
    """A 10 min logger sees a speed step up to 10 min late. Held from the row that logs it,
    the step came 5 min late on average, which fit read as a sensor lag of 1020 s on a clean
    control (fuzzing round 4). It now begins halfway between that row and the one before,
    the unbiased estimate; a run logged every second keeps the logged time (the shift would
    be below the grid's resolution)."""
    expect_s = 3 * 3600.0 + 300.0  # the true switch, midway between two 10 min rows
    for step_s in (600.0, 1.0):
        run = _logged_every(step_s)
        inp = interval_inputs(run, 60.0)
        first = float(inp.grid_s[np.flatnonzero(inp.speed_rpm > 3000.0)[0]])
        # the interval whose middle lies past the step's estimate is the first at 6000 rpm
        assert expect_s - 60.0 <= first <= expect_s, (step_s, first)


def _step_run(at_s: float = 168.0) -> BenchRun:
    """5 min at 1 Hz: 10 000 rpm, a step to 30 000 rpm at ``at_s`` (in the cell 120-180 s,
    after its middle), no load, a power of a kilowatt."""
    t = np.arange(0.0, 301.0, 1.0)
    n = np.where(t < at_s, 10000.0, 30000.0)
    cols = {"speed_rpm": n, "power_kW": np.full_like(t, 1.0),
            "T_env_C": np.full_like(t, 20.0), "T_coolant_C": np.full_like(t, 20.0),
            "T1_C": np.full_like(t, 20.0)}
    return BenchRun(Path("step.csv"), {}, t, cols, {}, [], ["T1"], float(t[-1]))


def test_a_speed_step_inside_a_cell_takes_the_speed_of_its_mean_friction():
    """With a friction law f = n^2 [W] the step's cell (48 s at 10 000 rpm, 12 s at 30 000)
    has a mean friction of 0.8 x 1e8 + 0.2 x 9e8 = 2.6e8 W, so its speed is sqrt(2.6e8) =
    16 125 rpm (the table's interpolation reads it to 0.1 %); every other cell keeps its
    logged speed. Without the law the cell keeps the speed of its middle, 10 000 rpm, whose
    friction is 2.6 times too small: the bearings' part of the power balance."""
    run = _step_run()
    plain = interval_inputs(run, 60.0)
    inp = interval_inputs(run, 60.0, friction_W=lambda n: n * n)
    k = int(np.flatnonzero(inp.grid_s[:-1] == 120.0)[0])
    assert plain.speed_rpm[k] == 10000.0
    assert inp.speed_rpm[k] == pytest.approx(math.sqrt(2.6e8), rel=1e-3)
    others = np.arange(len(inp.speed_rpm)) != k
    np.testing.assert_array_equal(inp.speed_rpm[others], plain.speed_rpm[others])
    # the mechanical power is kept: no load here, so the torque stays zero
    assert np.all(inp.load_torque_Nm == 0.0)
