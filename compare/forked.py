"""Columns of a finite-difference Jacobian shared with forked copies of this process.

``scipy.optimize.least_squares(..., workers=m)`` evaluates a Jacobian's columns as
``m(fun, points)``. :class:`ForkedColumns` is such an ``m``: the columns it is told are costly
go to child processes forked from this one, the rest stay here, and both run at once. The
children inherit the model, its caches included, so only the points and the residual vectors
cross between processes. Each column is the same computation as in one process, so the
Jacobian, and the fit, are the same to the last bit (tests/test_forked.py).

Forking needs a platform whose processes fork (Linux) and a process that may have children
(not a daemonic pool worker); elsewhere, and with ``workers`` = 1, the columns are evaluated
here one after another.
"""

from __future__ import annotations

import multiprocessing
import signal
import sys
from collections.abc import Callable, Iterable, Sequence

import numpy as np

#: the signals a forked child leaves to its parent
_SIGNALS = {signal.SIGINT, signal.SIGTERM}
#: the function a forked child evaluates (set just before the fork, so the child inherits it)
_CHILD_FUN: Callable[[np.ndarray], np.ndarray] | None = None


def _in_child(x: np.ndarray) -> tuple[bool, np.ndarray | None]:
    try:
        return True, np.atleast_1d(_CHILD_FUN(x))
    except Exception:  # noqa: BLE001 (evaluated again in the parent, which raises as in serial)
        return False, None


def _leave_signals_to_the_parent() -> None:
    """A child's start: out of the terminal's process group, so that a Ctrl-C or
    ``timeout``'s signal to the group reaches the parent alone, which ends its children
    (:meth:`ForkedColumns.__exit__`); SIGINT ignored and SIGTERM the default, not the
    parent's handler (compare.cli), which would print a traceback from the child and could
    leave the pool hung on a child that died mid-task."""
    import os

    os.setpgrp()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _SIGNALS)  # blocked by the parent's fork


def can_fork() -> bool:
    """Whether children can be forked copies of this process (Linux, not a daemonic
    process: a multiprocessing pool's workers may not have children)."""
    return (sys.platform.startswith("linux")
            and "fork" in multiprocessing.get_all_start_methods()
            and not multiprocessing.current_process().daemon)


class ForkedColumns:
    """A map-like callable for ``least_squares(workers=...)``, and a context manager whose
    exit ends the children.

    ``fun``: the residual function the children evaluate, the one given to
    ``least_squares`` (whose wrappers only make its result an array of at least one
    dimension). ``costly[i]``: whether column i costs much wherever it is evaluated (a
    parameter that enters the network's matrices needs new modes at every speed level, in
    any process). The children take costly columns up to their share of the estimated cost;
    this process takes the rest, whose cheap columns reuse what it computed at the
    Jacobian's centre. ``workers``: processes in all, this one included."""

    #: a costly column's cost in cheap columns: new modes at some 10-50 speed levels against
    #: one recursion over the run (20-30 ms against 6-10 ms on the bench runs of
    #: ../shared/bench-runs-2, benchmarks/bench_fit.py)
    COSTLY = 3.0

    def __init__(self, fun: Callable[[np.ndarray], np.ndarray], costly: Sequence[bool],
                 workers: int = 2) -> None:
        self.fun = fun
        self.costly = list(costly)
        self.workers = max(1, int(workers)) if can_fork() else 1
        self.pool = None
        #: evaluations made by the children (the caller's own count misses them)
        self.child_evaluations = 0

    def __enter__(self) -> ForkedColumns:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.pool is not None:
            self.pool.terminate()
            self.pool.join()
            self.pool = None

    def split(self, n: int) -> list[int]:
        """The columns (of ``n``) for the children: costly ones, first to last, while they
        hold no more than their share of the estimated cost (by half a column)."""
        if self.workers == 1 or n != len(self.costly):
            return []
        cost = [self.COSTLY if c else 1.0 for c in self.costly]
        share = sum(cost) * (self.workers - 1) / self.workers
        away: list[int] = []
        held = 0.0
        for i, c in enumerate(cost):
            if self.costly[i] and held + c / 2 <= share:
                away.append(i)
                held += c
        return away

    def _start(self) -> bool:
        global _CHILD_FUN
        _CHILD_FUN = self.fun  # forked now, so the children also hold today's caches
        # the signals wait until a child has its own handlers (they stay blocked in the
        # pool's threads, as Python handles them in the main thread)
        held = signal.pthread_sigmask(signal.SIG_BLOCK, _SIGNALS)
        try:
            self.pool = multiprocessing.get_context("fork").Pool(
                self.workers - 1, initializer=_leave_signals_to_the_parent)
        except (OSError, AssertionError, ValueError):  # no children to be had: serial
            self.workers = 1
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
        return self.pool is not None

    def __call__(self, fun: Callable, points: Iterable[np.ndarray]) -> list[np.ndarray]:
        xs = list(points)
        away = self.split(len(xs))
        if not away or (self.pool is None and not self._start()):
            return [fun(x) for x in xs]
        pending = self.pool.map_async(_in_child, [xs[i] for i in away], chunksize=1)
        out: list = [None] * len(xs)
        for i in range(len(xs)):
            if i not in away:
                out[i] = fun(xs[i])
        for i, (ok, f) in zip(away, pending.get(), strict=True):
            if ok:
                self.child_evaluations += 1
            out[i] = f if ok else fun(xs[i])  # a failure raises here, as in one process
        return out
