"""Jacobian columns shared with forked children (compare/forked.py): where each column runs,
that a failure raises as in one process, and that a calibration is the same to the last bit
with one process or two."""

from __future__ import annotations

import os

import numpy as np
import pytest

from compare.forked import ForkedColumns, can_fork

needs_fork = pytest.mark.skipif(not can_fork(), reason="children are forked on Linux only")


def _pid_and_x(x: np.ndarray) -> np.ndarray:
    if x[0] < 0:
        raise ValueError(f"negative first coordinate {x[0]}")
    return np.concatenate([[os.getpid()], x])


def test_the_children_take_costly_columns_up_to_their_share():
    # 3 costly (cost 3 each) and 2 cheap: 11 in all, half is 5.5; the first costly column
    # (3) fits, the second would make 6, which is within half a column (1.5) of 5.5
    cols = ForkedColumns(_pid_and_x, [True, False, True, True, False], workers=2)
    cols.workers = 2  # the split is arithmetic; it holds where children cannot be forked
    assert cols.split(5) == [0, 2]
    cols.workers = 1
    assert cols.split(5) == []
    # not a Jacobian of this size (another caller): nothing leaves this process
    cols.workers = 2
    assert cols.split(4) == []


@needs_fork
def test_costly_columns_run_in_a_child_and_the_others_here():
    xs = [np.array([float(i), 2.0 * i]) for i in range(5)]
    with ForkedColumns(_pid_and_x, [True, False, True, True, False], workers=2) as cols:
        out = cols(_pid_and_x, xs)
        away = cols.split(5)
        assert cols.child_evaluations == len(away) == 2
    for i, (f, x) in enumerate(zip(out, xs, strict=True)):
        np.testing.assert_array_equal(f[1:], x)  # in order
        assert (f[0] != os.getpid()) == (i in away)
    assert cols.pool is None  # the children ended with the block


@needs_fork
def test_a_column_that_fails_in_a_child_raises_here_as_in_one_process():
    xs = [np.array([-1.0, 0.0]), np.array([1.0, 0.0])]
    with ForkedColumns(_pid_and_x, [True, False], workers=2) as cols:
        assert cols.split(2) == [0]
        with pytest.raises(ValueError, match="negative first coordinate -1"):
            cols(_pid_and_x, xs)


@needs_fork
def test_a_calibration_is_the_same_with_one_process_or_two(monkeypatch):
    """The base calibration of a 16 h cycle (six parameters, three of them in the network's
    matrices) with its Jacobian columns shared by two processes gives the parameters, the
    Jacobian-based intervals and the model to the last bit of one process here. (That holds
    on every run only if an evaluation does not depend on what the process evaluated before:
    tests/test_greybox.py test_a_simulation_does_not_depend_on_the_parameter_sets_simulated_before.)"""
    from compare.fit.calibrate import Calibrator, Measured
    from compare.fit.greybox import GreyBox
    from spindle.cycle_files import load_cycle
    from spindle.drive import DRIVES
    from spindle.spec_reader import load_spec
    from tests.cycle_inputs import inputs_from_cycle

    spec = load_spec("spl2782")
    cycle = load_cycle("spl-16h")
    inp = inputs_from_cycle(cycle, np.arange(0.0, cycle.duration_s + 1.0, 240.0))
    truth = {"h_coolant": 1.3, "contact": 0.7, "f0": 1.2, "alpha_eff": 1.1}
    channels = ["T1", "T2", "T_stator", "P1"]
    free = ["h_coolant", "h_air", "contact", "f0", "rotor_share", "alpha_eff"]
    in_children = []
    exit_ = ForkedColumns.__exit__

    def counted(self, *exc):
        in_children.append(self.child_evaluations)
        exit_(self, *exc)

    monkeypatch.setattr(ForkedColumns, "__exit__", counted)
    fits = {}
    for workers in (1, 2):
        gb = GreyBox(spec, DRIVES["spl2782"], inp)
        cal = Calibrator(gb, Measured(inp.grid_s, gb.simulate(truth)), channels,
                         workers=workers)
        fits[workers] = cal.fit(free=free)
    one, two = fits[1], fits[2]
    assert in_children[0] == 0 and in_children[1] > 0  # two processes did share the work
    assert one.theta == two.theta and one.ci95 == two.ci95 and one.nfev == two.nfev
    np.testing.assert_array_equal(one.correlation, two.correlation)
    for c in channels:
        np.testing.assert_array_equal(one.model[c], two.model[c])
    # and it found the truth (noise-free data; 1e-3: the optimizer's tolerance 1e-6 on a
    # problem whose films and contacts are strongly correlated)
    for k, v in truth.items():
        assert one.theta[k] == pytest.approx(v, rel=1e-3)


_INTERRUPTED = """
import faulthandler, os, signal, sys, time
faulthandler.register(signal.SIGUSR1, all_threads=True)  # the test's dump of a hang
import numpy as np
from compare.cli import _terminate
from compare.forked import ForkedColumns

signal.signal(signal.SIGTERM, _terminate)  # as the command line has it
# Ctrl-C as a foreground command has it: a test runner started as a background job of a
# shell without job control inherits SIGINT ignored (POSIX), and so would this process
signal.signal(signal.SIGINT, signal.default_int_handler)
pids = sys.argv[1]

def slow(x):
    open(os.path.join(pids, str(os.getpid())), "w").close()
    time.sleep(0.3)
    return x

try:
    with ForkedColumns(slow, [True, True, False, False], workers=2) as cols:
        while True:
            cols(slow, [np.full(1, float(i)) for i in range(4)])
except KeyboardInterrupt:
    print("interrupted", file=sys.stderr)
    sys.exit(130)
"""


@needs_fork
@pytest.mark.parametrize("signum", ["SIGINT", "SIGTERM"])
def test_a_signal_to_the_process_group_ends_the_fit_and_its_children_quietly(tmp_path,
                                                                              signum):
    """Ctrl-C (SIGINT) or ``timeout`` (SIGTERM) signals the whole process group while the
    children evaluate columns. The parent alone handles it and ends its children: no
    traceback from a child (it once raised the parent's KeyboardInterrupt; a pool can hang
    on a child that died mid-task), exit 130, no child left."""
    import signal
    import subprocess
    import sys
    import time

    pids = tmp_path / "pids"
    pids.mkdir()
    proc = subprocess.Popen([sys.executable, "-c", _INTERRUPTED, str(pids)],
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.monotonic() + 30
    while len(list(pids.iterdir())) < 2 and time.monotonic() < deadline:  # a child is busy
        time.sleep(0.05)
    time.sleep(0.15)  # inside a column, on both sides
    os.killpg(proc.pid, getattr(signal, signum))
    try:
        err = proc.communicate(timeout=20)[1]
    except subprocess.TimeoutExpired:
        # where it hangs, for the next reader: every thread's stack
        os.kill(proc.pid, signal.SIGUSR1)
        time.sleep(1.0)
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("the interrupted process hung; its threads:\n" + proc.communicate()[1])
    assert proc.returncode == 130 and "Traceback" not in err and "interrupted" in err, err
    children = {int(p.name) for p in pids.iterdir()} - {proc.pid}
    assert children
    time.sleep(0.5)
    for pid in children:
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)
