"""Real-time prediction for CNC compensation: the lumped model discretised once, exactly.

:class:`RealTimePredictor` holds the zero-order-hold step of the model at a fixed sample time
(matrix exponential, :meth:`lumped.network.ThermalSystem.discretize`) and advances it one
sample at a time: ``step(u, speed) -> (sensor temperatures [K], P1 [m])``. The step and the
read-out are fused into one matrix, so a step is one small matrix-vector product.

:meth:`RealTimePredictor.run` replays a whole record at once: per constant-speed segment the
system is diagonalised (C^-1/2 K C^-1/2 is symmetric, so the modes are real and orthogonal)
and each mode is a first-order recursion, evaluated in blocks with cumulative sums (exact up
to rounding; no Python loop over samples).

A new speed costs one matrix exponential (or eigendecomposition) the first time it is seen;
speeds are cached to ``speed_resolution_rpm``. The fused step, the cache and the replay are
the kernel :class:`spindle.streaming.FusedStepper`, shared with the reduced model's
predictor.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lumped.simulation import LumpedModel
from spindle.streaming import FusedStepper


class RealTimePredictor(FusedStepper):
    """Streaming predictor at sample time ``dt_s`` [s] for ``model``.

    Inputs u follow ``model.system.input_names`` (heat-source powers [W], then ambient and
    coolant temperatures [K]); ``reading`` names the growth reading returned (P1), zeroed
    at the start state ``x0`` [K] (per mass, uniform, or None: the spec's T_initial_K).
    """

    def __init__(self, model: LumpedModel, dt_s: float, x0: np.ndarray | float | None = None,
                 speeds_rpm: Sequence[float] = (), reading: str = "P1",
                 speed_resolution_rpm: float = 1.0):
        if model.system.temperature_dependent:
            raise ValueError("temperature-dependent heat flows make the step depend on the "
                             "inputs; the real-time predictor needs a linear time-invariant "
                             "model per speed")
        self.model, self.dt_s, self.reading = model, float(dt_s), reading
        n = model.n_states
        w = model.chain.rows.get(reading)
        x_start = model.initial_state(x0)
        # outputs: the sensors, then the growth reading w . (x - x_start): zeroed at the start,
        # as a bench zeroes P1 (and as LumpedModel.transient reads it)
        readout = np.vstack([model.S, (w if w is not None else np.zeros(n))[None, :]])
        offset = np.zeros(len(readout))
        offset[-1] = -(w @ x_start) if w is not None else 0.0
        system = model.system
        super().__init__(lambda key: system.discretize(self.dt_s, key),
                         lambda key: system.modes(self.dt_s, key), readout, offset, x_start,
                         system.n_inputs, n_first=len(readout) - 1, picked=len(readout) - 1,
                         speeds=speeds_rpm, speed_resolution=speed_resolution_rpm)

    def run(self, U: np.ndarray, speeds_rpm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Replay samples: U (n_samples x n_inputs) held over each sample, speeds per sample.
        Returns (sensor temperatures [K], growth reading [m]) at the end of every sample, and
        leaves the predictor at the final state."""
        Y = super().run(U, speeds_rpm)
        return Y[:, :-1], Y[:, -1]
