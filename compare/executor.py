"""Run many independent cases (sweep points, measures, inverse problems) in parallel.

:func:`run_cases` calls ``fn(case)`` for every case and returns one :class:`CaseOutcome`
per case, in the order of ``cases``. A case that raises does not stop the others: its
outcome carries the exception's message (never a traceback) and the run goes on.

Where the cases run:

- ``workers == 1``: in this process, one after the other (easiest to debug);
- default: a :class:`concurrent.futures.ProcessPoolExecutor` with ``workers`` processes
  (default ``min(2, os.cpu_count())``); ``fn`` and the cases must be picklable (module-level
  functions, dataclasses);
- ``scheduler`` given: a Dask distributed cluster at that address (``tcp://host:8786``), or
  ``"local"`` for a local cluster of ``workers`` processes. Dask is an optional extra,
  imported only here: ``pip install "spindle-verify[dask]"``.

``progress`` (e.g. :func:`stderr_progress`) gets one line per finished case:
``[3/12] A_M=0.02 m2 done 1.4 s`` or ``[4/12] ... FAILED: message``. A function that takes
a ``progress`` keyword (``progress(k, n)``: k of its n steps done) reports from inside a
case too, in this process or from a pool's worker (through a queue; not on Dask), as
``[3.4/12] FEM level 1 transient: 4 of 9``: the cases done so far, counting the running
ones' fractions, so that a long case moves the count (compare.progress reads it).
"""

from __future__ import annotations

import functools
import inspect
import os
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any

from spindle.errors import InputError

#: what to install when a Dask scheduler is asked for and dask is missing
DASK_FIX = 'pip install "spindle-verify[dask]"'


@dataclass
class CaseOutcome:
    """The result of one case: ``value`` when it ran, else ``error`` (the message)."""

    index: int
    label: str
    value: Any = None
    error: str | None = None
    error_type: str | None = None
    runtime_s: float = 0.0

    @property
    def ok(self) -> bool:
        return self.error is None


def default_workers() -> int:
    """min(2, number of CPUs): the harness's default pool size."""
    return max(1, min(2, os.cpu_count() or 1))


def case_label(case: Any) -> str:
    """A case's ``label`` attribute if it has one, else ``str(case)`` (shortened)."""
    label = getattr(case, "label", None)
    text = str(label if label is not None else case)
    return text if len(text) <= 80 else text[:77] + "..."


def _message(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _call(fn: Callable[[Any], Any], case: Any, report: Callable[[int, int], None] | None = None
          ) -> tuple[Any, str | None, str | None, float]:
    """Run one case, catching its error: (value, message, type name, runtime [s]).

    Runs in the worker, so a failing case reaches the caller as data, not as a traceback.
    ``report``: handed to ``fn`` as its ``progress`` keyword, if given.
    """
    t0 = time.perf_counter()
    try:
        value = fn(case) if report is None else fn(case, progress=report)
        return value, None, None, time.perf_counter() - t0
    except Exception as exc:  # every case failure is reported, none stops the run
        return None, _message(exc), type(exc).__name__, time.perf_counter() - t0


def _takes_progress(fn: Callable) -> bool:
    """Does ``fn`` take a ``progress`` keyword (and has it not been bound already)?"""
    if isinstance(fn, functools.partial) and "progress" in fn.keywords:
        return False
    try:
        return "progress" in inspect.signature(fn).parameters
    except (TypeError, ValueError):  # a builtin without a signature
        return False


@dataclass(frozen=True)
class _QueueReport:
    """A case's ``progress(k, n)`` in a pool's worker: (case, k, n) onto the parent's queue
    (picklable, unlike a closure)."""

    queue: Any
    index: int

    def __call__(self, k: int, n: int) -> None:
        self.queue.put((self.index, k, n))


def stderr_progress(enabled: bool = True) -> Callable[[str], None]:
    """A progress callable printing each line to stderr (nothing when ``enabled`` is False)."""
    def say(line: str) -> None:
        if enabled:
            print(line, file=sys.stderr, flush=True)

    return say


def run_cases(fn: Callable[[Any], Any], cases: Iterable[Any], scheduler: str | None = None,
              workers: int | None = None, progress: Callable[[str], None] | None = None
              ) -> list[CaseOutcome]:
    """``fn(case)`` for every case, in parallel; outcomes in the order of ``cases``.

    ``workers``: processes (default :func:`default_workers`; 1 runs serially in this
    process). ``scheduler``: a Dask scheduler address or ``"local"``. ``progress``: called
    with one line per finished case.
    """
    cases = list(cases)
    if workers is None:
        workers = default_workers()
    if workers < 1:
        raise InputError("command line", "--workers", f"{workers} is not a number of processes",
                         "give --workers 1 or more")
    labels = [case_label(c) for c in cases]
    outcomes: list[CaseOutcome | None] = [None] * len(cases)
    done = 0
    running: dict[int, float] = {}  # the fraction done of each running case that reports
    lock = threading.Lock()

    def finish(i: int, value: Any, error: str | None, etype: str | None, dt: float) -> None:
        nonlocal done
        with lock:
            done += 1
            running.pop(i, None)
            outcomes[i] = CaseOutcome(i, labels[i], value, error, etype, dt)
            if progress is not None:
                status = f"done {dt:.1f} s" if error is None else f"FAILED: {error}"
                progress(f"[{done}/{len(cases)}] {labels[i]} {status}")

    def step(i: int, k: int, n: int) -> None:
        with lock:
            if outcomes[i] is not None or progress is None:
                return
            running[i] = min(max(k / max(n, 1), 0.0), 1.0)
            count = done + sum(running.values())
            progress(f"[{count:.1f}/{len(cases)}] {labels[i]}: {k} of {n}")

    if not cases:
        return []
    reports = progress is not None and _takes_progress(fn)
    if scheduler:
        _run_dask(fn, cases, scheduler, workers, finish)
    elif workers == 1:
        for i, c in enumerate(cases):
            finish(i, *_call(fn, c, (lambda k, n, i=i: step(i, k, n)) if reports else None))
    else:
        _run_pool(fn, cases, workers, finish, step if reports else None)
    return [o for o in outcomes if o is not None]


def _run_pool(fn, cases: Sequence[Any], workers: int, finish, step=None) -> None:
    manager = queue = drain = None
    if step is not None:  # the workers' progress(k, n) comes back through a queue
        import multiprocessing

        manager = multiprocessing.Manager()
        queue = manager.Queue()

        def pump() -> None:
            while (item := queue.get()) is not None:
                step(*item)

        drain = threading.Thread(target=pump, daemon=True)
        drain.start()
    try:
        with ProcessPoolExecutor(max_workers=min(workers, len(cases))) as pool:
            futures = {}
            for i, c in enumerate(cases):
                t0 = time.perf_counter()
                report = _QueueReport(queue, i) if queue is not None else None
                try:
                    futures[pool.submit(_call, fn, c, report)] = (i, t0)
                except Exception as exc:  # e.g. the pool broke: report, go on
                    finish(i, None, _message(exc), type(exc).__name__, 0.0)
            for fut in as_completed(futures):
                i, t0 = futures[fut]
                try:
                    finish(i, *fut.result())
                except Exception as exc:  # pickling errors, a worker that died
                    finish(i, None, _message(exc), type(exc).__name__,
                           time.perf_counter() - t0)
    finally:
        if manager is not None:
            queue.put(None)
            drain.join(timeout=5)
            manager.shutdown()


def import_dask():
    try:
        from dask import distributed  # optional extra, imported on demand
    except ImportError:
        raise InputError("command line", "--scheduler", "a Dask scheduler needs the optional "
                         "'dask' extra, which is not installed", f"run {DASK_FIX}, or leave "
                         "out --scheduler to use the local process pool") from None
    return distributed


#: how long [s] a scheduler's address may take to accept a connection before it is called
#: unreachable: a scheduler on a network answers in milliseconds, and Dask's own retries
#: took 30 s to say that nothing listens there
CONNECT_TIMEOUT_S = 5.0


def check_scheduler(scheduler: str | None) -> None:
    """InputError at once when ``scheduler`` (``tcp://host:port``) accepts no connection; the
    Dask extra is imported (a missing extra is named). ``None`` and ``"local"`` pass."""
    if not scheduler:
        return
    import_dask()
    if scheduler == "local":
        return
    import socket
    from urllib.parse import urlsplit

    where = urlsplit(scheduler if "://" in scheduler else f"tcp://{scheduler}")
    if where.scheme not in ("tcp", "tls"):
        return  # another of Dask's transports (inproc, ucx): Dask's own connect says
    try:
        host, port = where.hostname, where.port
    except ValueError:  # a port that is no number
        host = port = None
    if not host or port is None:
        raise InputError("command line", "--scheduler", f"'{scheduler}' is not an address "
                         "host:port", "give e.g. tcp://host:8786, or 'local'")
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S).close()
    except OSError as exc:
        raise InputError("command line", "--scheduler", f"cannot connect to '{scheduler}' "
                         f"({exc.strerror or exc})", "give the address of a running Dask "
                         "scheduler, e.g. tcp://host:8786, or 'local'") from None


def _run_dask(fn, cases: Sequence[Any], scheduler: str, workers: int, finish) -> None:
    distributed = import_dask()
    check_scheduler(scheduler)
    cluster = None
    try:
        if scheduler == "local":
            cluster = distributed.LocalCluster(n_workers=workers, threads_per_worker=1,
                                               processes=True, dashboard_address=None)
            client = distributed.Client(cluster)
        else:
            client = distributed.Client(scheduler)
    except Exception as exc:  # cannot reach the scheduler: one clear message
        if cluster is not None:
            cluster.close()
        raise InputError("command line", "--scheduler", f"cannot connect to '{scheduler}' "
                         f"({_message(exc)})", "give the address of a running Dask scheduler, "
                         "e.g. tcp://host:8786, or 'local'") from None
    try:
        futures = {}
        for i, c in enumerate(cases):
            futures[client.submit(_call, fn, c, pure=False)] = (i, time.perf_counter())
        for fut in distributed.as_completed(list(futures)):
            i, t0 = futures[fut]
            try:
                finish(i, *fut.result())
            except Exception as exc:  # a lost worker, a pickling error
                finish(i, None, _message(exc), type(exc).__name__, time.perf_counter() - t0)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
