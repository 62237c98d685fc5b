"""Grey-box inputs of a shipped cycle, for the tests that drive the grey box without a bench
run (a bench run's inputs come from spindle.bench_inputs.interval_inputs)."""

from __future__ import annotations

import numpy as np

from spindle.bench_inputs import Inputs


def inputs_from_cycle(cycle, grid_s: np.ndarray) -> Inputs:
    """Inputs of a shipped or user cycle (spindle.cycles.Cycle) on ``grid_s``: each
    interval takes the step, ambient and coolant at its middle; power unknown (nan)."""
    mid = 0.5 * (grid_s[1:] + grid_s[:-1])
    idx = np.clip(np.searchsorted(np.asarray(cycle.boundaries_s), mid, side="right") - 1, 0,
                  len(cycle.steps) - 1)
    steps = [cycle.steps[i] for i in idx]
    power = np.array([np.nan if s.power_kW is None else s.power_kW for s in steps])
    return Inputs(grid_s, np.array([s.speed_rpm for s in steps]), power,
                  np.array([s.load_torque_Nm for s in steps]),
                  np.asarray(cycle.T_ambient_K(mid), dtype=float),
                  np.asarray(cycle.T_coolant_K(mid), dtype=float),
                  float(cycle.T_ambient_K(grid_s[0])))
