"""The speed of an interval whose logged speed changes inside it, as the bearings see it:
the one of the interval's mean friction (spindle.bench_inputs.interval_inputs)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from spindle.bench_inputs import _per_rpm, cell_means, held, speed_changed
from spindle.drive import Drive
from spindle.power import bearing_friction


def bearing_friction_W(drive: Drive) -> Callable[[float], float]:
    """The bearings' friction [W] at a speed [rpm], as the drive's power balance takes it."""
    return _per_rpm(lambda n: sum(bearing_friction(b, n).heat_W
                                  for b in drive.bearings_at(n).values()))


def friction_speed(t_n: np.ndarray, n: np.ndarray, grid: np.ndarray, hold_s: float,
                   speed: np.ndarray, friction_W: Callable[[float], float]) -> np.ndarray:
    """``speed`` [rpm], one per interval of ``grid`` [s], where the logged speed (samples
    ``n`` [rpm] at ``t_n`` [s], each held for ``hold_s`` at most) changes inside the interval
    beyond the drive's scatter band, replaced by the speed at which ``friction_W`` (the
    bearings' friction [W] at a speed, increasing) equals its time mean over the interval.
    The power balance then gives the bearings the heat the samples give them. At the speed of
    the interval's middle it gave them the friction of one side of the step for the whole
    interval and the motor the rest: a step from 10 600 to 33 500 rpm late in an interval put
    the bearings 5 K low at its end, a step down late in one 14 K high (a 24 000 rpm grinder)."""
    n = np.asarray(n, dtype=float)
    # the friction is smooth and increasing: a table of 2001 speeds reads it to a few watts
    table_n = np.linspace(0.0, max(float(np.max(n)), 1.0), 2001)
    table_f = np.array([friction_W(float(x)) for x in table_n])
    mean_f = cell_means(t_n, np.interp(n, table_n, table_f), grid,
                        0.5 * (grid[:-1] + grid[1:]), hold_s)
    # the levels an interval holds: the one at its start and every sample inside it
    cells = len(grid) - 1
    lo = held(t_n, n, grid[:-1])
    hi = lo.copy()
    k = np.searchsorted(grid, t_n, side="right") - 1
    inside = (k >= 0) & (k < cells)
    np.minimum.at(lo, k[inside], n[inside])
    np.maximum.at(hi, k[inside], n[inside])
    return np.where(speed_changed(lo, hi), np.interp(mean_f, table_f, table_n), speed)
