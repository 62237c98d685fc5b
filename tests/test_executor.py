"""The case executor (compare/executor.py): order, per-case failures, progress, back-ends."""

from __future__ import annotations

import socket
import sys
import time
import types
from concurrent.futures import Future

import pytest

from compare.executor import CONNECT_TIMEOUT_S, DASK_FIX, case_label, run_cases
from spindle.errors import InputError


def square_or_fail(x: int) -> int:
    """Module level, so the process pool can pickle it."""
    if x == 3:
        raise ValueError("three is not allowed\nsecond line of detail")
    return x * x


class Labelled:
    def __init__(self, x: int):
        self.x = x
        self.label = f"x={x} m2"


def labelled_square(c: Labelled) -> int:
    return c.x * c.x


@pytest.mark.parametrize("workers", [1, 2])
def test_results_in_order_and_failures_captured(workers):
    lines: list[str] = []
    out = run_cases(square_or_fail, [1, 2, 3, 4], workers=workers, progress=lines.append)
    assert [o.index for o in out] == [0, 1, 2, 3]
    assert [o.value for o in out] == [1, 4, None, 16]
    assert [o.ok for o in out] == [True, True, False, True]
    bad = out[2]
    assert bad.error == "three is not allowed"  # the message's first line, no traceback
    assert bad.error_type == "ValueError"
    assert "Traceback" not in " ".join(lines)
    # one progress line per finished case, numbered 1..n in finishing order
    assert sorted(int(ln[1:ln.index("/")]) for ln in lines) == [1, 2, 3, 4]
    assert all(ln.split("]")[0].endswith("/4") for ln in lines)
    assert sum("FAILED: three is not allowed" in ln for ln in lines) == 1
    assert sum(" done " in ln and ln.endswith(" s") for ln in lines) == 3


def test_progress_line_uses_the_case_label():
    lines: list[str] = []
    out = run_cases(labelled_square, [Labelled(2)], workers=1, progress=lines.append)
    assert out[0].value == 4 and out[0].label == "x=2 m2"
    assert lines[0].startswith("[1/1] x=2 m2 done ") and lines[0].endswith(" s")


def test_unpicklable_function_fails_per_case_in_the_pool():
    out = run_cases(lambda x: x, [1, 2], workers=2)  # a lambda cannot be pickled
    assert [o.ok for o in out] == [False, False]
    assert all(o.error for o in out)


def test_empty_and_bad_worker_count():
    assert run_cases(square_or_fail, [], workers=2) == []
    with pytest.raises(InputError, match="--workers"):
        run_cases(square_or_fail, [1], workers=0)


def test_long_labels_are_shortened():
    assert len(case_label("x" * 200)) == 80
    assert case_label(5) == "5"


def test_missing_dask_names_the_fix(monkeypatch):
    monkeypatch.setitem(sys.modules, "dask", None)  # import dask -> ImportError
    with pytest.raises(InputError) as exc:
        run_cases(square_or_fail, [1], scheduler="tcp://127.0.0.1:8786")
    assert DASK_FIX in str(exc.value) and "--scheduler" in str(exc.value)


class _FakeClient:
    """The part of dask.distributed.Client the executor uses, run in this process."""

    addresses: list[str] = []
    closed = 0

    def __init__(self, address):
        if address == "tcp://nowhere:1":
            raise OSError("Timed out trying to connect")
        _FakeClient.addresses.append(address)

    def submit(self, fn, *args, pure=True):
        assert pure is False  # every case must run, even with equal arguments
        f: Future = Future()
        f.set_result(fn(*args))
        return f

    def close(self):
        _FakeClient.closed += 1


def _fake_dask(monkeypatch):
    dist = types.ModuleType("dask.distributed")
    dist.Client = _FakeClient
    dist.as_completed = lambda futures: iter(list(futures)[::-1])  # any completion order
    dask = types.ModuleType("dask")
    dask.distributed = dist
    monkeypatch.setitem(sys.modules, "dask", dask)
    monkeypatch.setitem(sys.modules, "dask.distributed", dist)
    real = socket.create_connection

    def connect(address, timeout=None):  # the fake hosts accept; the machine's own are real
        if address[0] == "h":
            return types.SimpleNamespace(close=lambda: None)
        if address[0] == "nowhere":
            raise OSError("Name or service not known")
        return real(address, timeout=timeout)

    monkeypatch.setattr(socket, "create_connection", connect)


def test_dask_backend_keeps_order_and_captures_failures(monkeypatch):
    _fake_dask(monkeypatch)
    _FakeClient.addresses, _FakeClient.closed = [], 0
    lines: list[str] = []
    out = run_cases(square_or_fail, [1, 2, 3, 4], scheduler="tcp://h:8786",
                    progress=lines.append)
    assert [o.value for o in out] == [1, 4, None, 16]
    assert out[2].error == "three is not allowed"
    assert _FakeClient.addresses == ["tcp://h:8786"] and _FakeClient.closed == 1
    assert len(lines) == 4


def test_unreachable_scheduler_is_one_clear_error(monkeypatch):
    _fake_dask(monkeypatch)
    with pytest.raises(InputError) as exc:
        run_cases(square_or_fail, [1], scheduler="tcp://nowhere:1")
    assert "cannot connect to 'tcp://nowhere:1'" in str(exc.value)
    assert "fix:" in str(exc.value)


@pytest.mark.slow
def test_real_local_dask_cluster():
    pytest.importorskip("dask.distributed")
    out = run_cases(square_or_fail, [1, 2, 3], scheduler="local", workers=2)
    assert [o.value for o in out] == [1, 4, None]
    assert out[2].error == "three is not allowed"


def square_in_steps(x: int, progress=None) -> int:
    """A case that reports its own progress (k of 4 steps), as run_study_case does; module
    level so the pool can pickle it."""
    import time

    for k in range(1, 5):
        if progress is not None:
            progress(k, 4)
            time.sleep(0.05)  # a step takes time, so a worker's report is read before the end
    return x * x


@pytest.mark.parametrize("workers", [1, 2])
def test_a_case_reports_its_own_steps_in_the_process_and_from_a_worker(workers):
    """A long case moves the count while it runs: [done + its fraction / n], also from a
    pool's worker (through the queue), and the finished lines are as before."""
    lines: list[str] = []
    out = run_cases(square_in_steps, [1, 2, 3], workers=workers, progress=lines.append)
    assert [o.value for o in out] == [1, 4, 9]
    steps = [ln for ln in lines if " of 4" in ln]
    if workers == 1:  # every step, in order: the first case's second is half a case of three
        assert len(steps) == 12 and steps[1] == "[0.5/3] 1: 2 of 4"
    else:  # a worker's step read after its case finished is not shown (the case is done)
        for x in (1, 2, 3):
            assert any(f"] {x}: 1 of 4" in ln for ln in steps), steps
    assert sum(1 for ln in lines if " done " in ln) == 3


def test_a_bound_progress_is_not_replaced():
    """A function whose progress is already bound (functools.partial) keeps its own."""
    from functools import partial

    mine: list[tuple[int, int]] = []
    lines: list[str] = []
    run_cases(partial(square_in_steps, progress=lambda k, n: mine.append((k, n))), [5],
              workers=1, progress=lines.append)
    assert mine == [(1, 4), (2, 4), (3, 4), (4, 4)]
    assert not any(" of 4" in ln for ln in lines)


def test_a_scheduler_address_where_nothing_listens_is_named_at_once(monkeypatch):
    """Dask retried a refused connection for its 30 s timeout before the message came (found
    by fuzzing); the address is tried once, with compare.executor.CONNECT_TIMEOUT_S."""
    _fake_dask(monkeypatch)
    _FakeClient.addresses = []
    with socket.socket() as s:  # a port of this machine that nothing listens on
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    t = time.perf_counter()
    with pytest.raises(InputError) as exc:
        run_cases(square_or_fail, [1], scheduler=f"tcp://127.0.0.1:{port}")
    # a refused connection is refused at once; the bound is the check's own timeout
    assert time.perf_counter() - t < CONNECT_TIMEOUT_S
    assert f"cannot connect to 'tcp://127.0.0.1:{port}'" in str(exc.value)
    assert _FakeClient.addresses == []  # Dask was never asked
    with pytest.raises(InputError, match="is not an address"):
        run_cases(square_or_fail, [1], scheduler="tcp://127.0.0.1:port")
