"""Logging gaps with an operating change inside: when did the spindle switch?

A bench that stops logging for a while (a 20 min gap in ``synth``'s runs, 9 min in a peer's)
may come back at another speed, or at the same speed under another load. The inputs then
say nothing about when it changed, and a zero-order hold of the last speed puts the change at
the gap's end: up to the whole gap late. On a 6000 -> 1600 rpm change in a 20 min gap that
left the stator 10 K, the rings 1.5 K off the data right after the gap and pulled the
calibrated jacket film to its bound (docs/fit-history.md).

The switch time is a nuisance parameter of the inputs, so it is estimated like one: for each
such gap, every grid point inside it is tried as the switch (the old speed, power and load
torque before, the new after), the lumped grey box is simulated at the spec's values, and the
time that fits the measured channels best over the hour after the gap (sum of squares in
tolerance units) is taken. The fast channels (the stator, the rings) pin it to about a grid
step. This runs before the FEM anchor is solved, so the anchor and the fit see the same inputs.
Units: s, rpm, kW.

Every gap, with a change inside or not, leaves its inputs unknown until the response to them
has settled (:func:`unknown_input_spans`): the room and the coolant inside it are
interpolated, and a chiller cycles within a gap's length.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from compare.fit.criteria import Criteria
from spindle.bench_inputs import Inputs, speed_changed
from spindle.bench_inputs import logging_gaps as gaps_of_rows

#: the criteria of the gaps (gap_min_steps, gap_judge_s, gap_level_s) when none are given
_DEFAULT = Criteria()


@dataclass(frozen=True)
class GapSwitch:
    """A gap with an operating change and the switch time chosen inside it [s, rpm]."""

    start_s: float
    end_s: float
    speed_before_rpm: float
    speed_after_rpm: float
    switch_s: float
    #: the load torque's levels either side [N m] (nan where the bench logs none)
    torque_before_Nm: float = float("nan")
    torque_after_Nm: float = float("nan")

    def text(self) -> str:
        """The change in words: the speed's (beyond the drive's scatter band, as
        :func:`gaps_with_change` judges it), or else the load's."""
        if speed_changed(self.speed_before_rpm, self.speed_after_rpm) or not np.isfinite(
                self.torque_before_Nm + self.torque_after_Nm):
            return (f"the speed changed from {self.speed_before_rpm:.0f} to "
                    f"{self.speed_after_rpm:.0f} rpm")
        return (f"the load changed from {self.torque_before_Nm:.1f} to "
                f"{self.torque_after_Nm:.1f} N m at {self.speed_after_rpm:.0f} rpm")


def gaps_with_change(t_rows_s: np.ndarray, t_speed_s: np.ndarray, speed_rpm: np.ndarray,
                     grid_s: np.ndarray, criteria: Criteria = _DEFAULT,
                     torque: tuple[np.ndarray, np.ndarray] | None = None
                     ) -> list[tuple[float, float, float, float]]:
    """(start, end, speed before, speed after) of each logging gap (:func:`logging_gaps` of
    ``t_rows_s``, every row's time) across which the operating point changed: the speed beyond
    the drive's scatter band (spindle.bench_inputs.speed_changed), or the load torque's level
    (``torque``: its valid samples' times [s] and values [N m], where the bench logs it) by more
    than a load cell's zero drift (``criteria.no_load_Nm``). The speed before is the last valid
    sample at or before the gap, after it the first one at or after its end (``t_speed_s``,
    ``speed_rpm``: the valid speed samples); the torque's levels are its means over
    ``criteria.gap_level_s`` either side. A speed logged only on change (empty cells between
    changes, rows going on) has no gap: its change is at the sample that logs it."""
    out = []
    for start, end in logging_gaps(t_rows_s, grid_s, criteria):
        k = int(np.searchsorted(t_speed_s, start, side="right")) - 1
        j = int(np.searchsorted(t_speed_s, end, side="left"))
        if k < 0 or j >= len(t_speed_s):
            continue
        a, b = float(speed_rpm[k]), float(speed_rpm[j])
        moved = bool(speed_changed(a, b))
        if not moved and torque is not None:
            m0, m1 = levels_around(torque, start, end, criteria)
            moved = bool(abs(m1 - m0) > criteria.no_load_Nm)  # False where either is nan
        if moved:
            out.append((start, end, a, b))
    return out


def logging_gaps(t_rows_s: np.ndarray, grid_s: np.ndarray, criteria: Criteria = _DEFAULT
                 ) -> list[tuple[float, float]]:
    """(start, end) [s] of each stretch without any row (``t_rows_s``, every row's time)
    longer than ``criteria.gap_min_steps`` steps of the grid ``grid_s`` [s] or of the run's
    own logging, whichever is longer (spindle.bench_inputs.logging_gaps)."""
    return gaps_of_rows(t_rows_s, float(np.median(np.diff(grid_s))), criteria.gap_min_steps)


def unknown_input_spans(t_rows_s: np.ndarray, grid_s: np.ndarray,
                        criteria: Criteria = _DEFAULT) -> list[tuple[float, float]]:
    """The spans [start, end) [s] whose inputs are not known: every logging gap
    (:func:`logging_gaps`) and the ``criteria.gap_judge_s`` after it. Inside a gap the drive,
    the room and the coolant are interpolated; the response to what they really did there is
    a guess until it has settled, with an operating change inside or not."""
    return [(a, b + criteria.gap_judge_s) for a, b in logging_gaps(t_rows_s, grid_s, criteria)]


def levels_around(samples: tuple[np.ndarray, np.ndarray], start_s: float, end_s: float,
                  criteria: Criteria = _DEFAULT) -> tuple[float, float]:
    """A logged signal's mean (``samples``: its valid samples' times [s] and values) over
    ``criteria.gap_level_s`` before a gap and after it (nan where no sample lies there)."""
    return (_level(*samples, start_s - criteria.gap_level_s, start_s),
            _level(*samples, end_s, end_s + criteria.gap_level_s))


def _level(t_s: np.ndarray, y: np.ndarray, t0: float, t1: float) -> float:
    m = (t_s >= t0) & (t_s <= t1) & np.isfinite(y)
    return float(np.mean(y[m])) if m.any() else float("nan")


def place_switches(inputs: Inputs, t_rows_s: np.ndarray, t_speed_s: np.ndarray,
                   speed_rpm: np.ndarray, t_power_s: np.ndarray, power_kW: np.ndarray,
                   misfit: Callable[[Inputs, float], float], criteria: Criteria = _DEFAULT,
                   torque: tuple[np.ndarray, np.ndarray] | None = None
                   ) -> tuple[Inputs, list[GapSwitch]]:
    """``inputs`` with the speed, power and load torque (``torque``: its valid samples, where
    the bench logs it) inside each gap with a change set to the old operating point up to the
    best switch time and the new one after it, and the switches. ``misfit(inputs,
    gap_end_s)``: the spec model's misfit to the measured channels over the window after the
    gap for these inputs (compare.fit.run builds it)."""
    grid = inputs.grid_s
    switches = []
    for start, end, before, after in gaps_with_change(t_rows_s, t_speed_s, speed_rpm, grid,
                                                      criteria=criteria, torque=torque):
        # the grid intervals the gap touches; the switch falls on one of their edges
        inside = np.where((grid[1:] > start) & (grid[:-1] < end))[0]
        if len(inside) == 0:
            continue
        p_before, p_after = levels_around((t_power_s, power_kW), start, end, criteria)
        m_before, m_after = (levels_around(torque, start, end, criteria) if torque is not None
                             else (float("nan"), float("nan")))
        best = None
        for s in range(int(inside[0]), int(inside[-1]) + 2):
            speed, power = inputs.speed_rpm.copy(), inputs.power_kW.copy()
            load = inputs.load_torque_Nm.copy()
            old, new = inside[inside < s], inside[inside >= s]
            speed[old], speed[new] = before, after
            if np.isfinite(p_before) and np.isfinite(p_after):
                power[old], power[new] = p_before, p_after
            if np.isfinite(m_before) and np.isfinite(m_after):
                load[old], load[new] = m_before, m_after
            trial = replace(inputs, speed_rpm=speed, power_kW=power, load_torque_Nm=load)
            cost = misfit(trial, end)
            if best is None or cost < best[0]:
                best = (cost, trial, float(grid[s]) if s < len(grid) else float(grid[-1]))
        inputs = best[1]
        switches.append(GapSwitch(start, end, before, after, best[2], m_before, m_after))
    return inputs, switches
