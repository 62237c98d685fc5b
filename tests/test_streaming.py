"""The streaming kernel both real-time predictors share (spindle/streaming.py), on a system
whose exact answer is known in closed form: two decoupled first-order masses,
x_i' = -lam_i x_i + u_i, held inputs over a sample of dt, so x_k = a x_(k-1) + (1 - a) / lam u_k
with a = exp(-lam dt), and a second speed with other rates."""

from __future__ import annotations

import numpy as np
import pytest

from spindle.streaming import FusedStepper, lfilter_recursion, modal_recursion

DT = 1.0
RATES = {0.0: np.array([1e-3, 2e-2]), 1000.0: np.array([5e-3, 0.5])}  # 1/s per speed


def _discrete(speed: float) -> tuple[np.ndarray, np.ndarray]:
    lam = RATES[speed]
    a = np.exp(-lam * DT)
    return np.diag(a), np.diag((1 - a) / lam)


def _modal(speed: float) -> tuple[np.ndarray, ...]:
    lam = RATES[speed]
    a = np.exp(-lam * DT)
    return a, np.diag((1 - a) / lam), np.eye(2), np.eye(2)


def _closed_form(U: np.ndarray, speeds: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """The exact states, one sample after another (the reference the kernel must match)."""
    x, out = x0.astype(float).copy(), []
    for u, n in zip(U, speeds, strict=True):
        lam = RATES[float(n)]
        a = np.exp(-lam * DT)
        x = a * x + (1 - a) / lam * u
        out.append(x.copy())
    return np.array(out)


@pytest.fixture
def record():
    rng = np.random.default_rng(3)
    n = 5000
    speeds = np.where(np.arange(n) < 2000, 0.0, 1000.0)
    speeds[3500:] = 0.0
    return rng.uniform(0, 10, (n, 2)), speeds


def _stepper(recursion=None) -> FusedStepper:
    readout = np.array([[1.0, 0.0], [0.0, 1.0], [0.5, 0.5]])  # two "sensors", one "reading"
    offset = np.array([0.0, 0.0, -1.0])
    return FusedStepper(_discrete, _modal, readout, offset, np.array([2.0, 3.0]), 2,
                        n_first=2, picked=2, speeds=[0.0], recursion=recursion)


@pytest.mark.parametrize("recursion", [modal_recursion, lfilter_recursion])
def test_replay_and_streaming_equal_the_closed_form(record, recursion):
    U, speeds = record
    X = _closed_form(U, speeds, np.array([2.0, 3.0]))
    expected = np.column_stack([X, 0.5 * X.sum(axis=1) - 1.0])
    replay = _stepper(recursion)
    Y = replay.run(U, speeds)
    # 1e-9 of values of order 1-1000: the blocked sums lose at most 4 of 16 digits
    np.testing.assert_allclose(Y, expected, rtol=1e-9, atol=1e-9)
    stream = _stepper(recursion)
    for k in range(len(U)):
        first, picked = stream.step(U[k], speeds[k])
        np.testing.assert_allclose(first, expected[k, :2], rtol=1e-12)
        assert picked == pytest.approx(expected[k, 2], rel=1e-12)
    np.testing.assert_allclose(stream.state, replay.state, rtol=1e-9)
    np.testing.assert_allclose(stream.outputs_now(), Y[-1], rtol=1e-9)


def test_speeds_are_cached_to_their_resolution():
    s = _stepper()
    assert s.key(0.4) == 0.0 and s.fused(0.4) is s.fused(0.0)
    assert s.modes(1000.2) is s.modes(1000.0)


def test_no_picked_output_reads_nan():
    s = FusedStepper(_discrete, _modal, np.eye(2), np.zeros(2), np.zeros(2), 2, n_first=2,
                     picked=None)
    assert np.isnan(s.step(np.ones(2), 0.0)[1])


def test_a_mode_that_decays_within_one_step_takes_single_sample_blocks():
    """A mode with a = exp(-lam dt) below 1e-4 makes the blocks one sample long (as in a fit
    on a 60 s grid, whose bearing rings settle in seconds): the recursion is then the plain
    one, and equals the closed form to round-off; no samples return the entering state."""
    lam = np.array([12.0, 2e-3])  # a = 6e-6 and 0.998
    a = np.exp(-lam * DT)
    rng = np.random.default_rng(5)
    U = rng.uniform(0, 10, (300, 2))
    x, want = np.array([1.0, 2.0]), []
    for u in U:
        x = a * x + (1 - a) / lam * u
        want.append(x.copy())
    Y, last = modal_recursion(a, np.diag((1 - a) / lam), U, np.array([1.0, 2.0]), np.eye(2))
    np.testing.assert_allclose(Y, np.array(want), rtol=1e-13)
    np.testing.assert_array_equal(last, Y[-1])
    Y0, last0 = modal_recursion(a, np.diag((1 - a) / lam), U[:0], np.array([1.0, 2.0]),
                                np.eye(2))
    assert Y0.shape == (0, 2) and list(last0) == [1.0, 2.0]
