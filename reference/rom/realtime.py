"""Streaming prediction with the reduced model, for CNC compensation.

:class:`ROMPredictor` is the streaming kernel :class:`spindle.streaming.FusedStepper` (shared
with :class:`lumped.realtime.RealTimePredictor`) on a :class:`rom.model.ReducedModel`: the
exact zero-order-hold step of the reduced system at a fixed sample time (M_r = I and K_r(n)
symmetric, so exp(-K_r dt) comes from one small eigendecomposition per speed, cached to
``speed_resolution_rpm``), fused with the read-out into one matrix acting on [z, u, 1]:
``step(u, speed) -> (sensor temperatures [K], P1 [m])``. :meth:`ROMPredictor.run` replays a
whole record mode by mode with scipy.signal.lfilter (the blocked cumulative sums of the
lumped predictor would take tiny blocks here, as the ROM keeps modes of a few seconds).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from reference.rom.model import ReducedModel, phi_integrals
from spindle.streaming import FusedStepper, lfilter_recursion


class ROMPredictor(FusedStepper):
    """Streaming predictor at sample time ``dt_s`` [s]; inputs u follow
    ``model.input_names`` (source powers [W], ambient and coolant [K]), held over a sample.
    The growth readings are zeroed at the start field, uniform ``T0`` [K] (None: the spec's
    T_initial_K)."""

    def __init__(self, model: ReducedModel, dt_s: float, T0: float | None = None,
                 speeds_rpm: Sequence[float] = (), reading: str = "P1",
                 speed_resolution_rpm: float = 1.0):
        self.model, self.dt_s, self.reading = model, float(dt_s), reading
        sysr = model.system
        self.n_sensors = len(model.sensor_names)
        z0 = model.initial(T0)
        # growth readings zeroed at the start, as ReducedModel.transient reads them
        offset = sysr.offset.copy()
        offset[self.n_sensors:] = -(sysr.O[self.n_sensors:] @ z0)
        picked = self.n_sensors + model.readings.index(reading) if reading in \
            model.readings else None
        super().__init__(self.discrete, self._modal, sysr.O, offset, z0,
                         len(model.input_names), self.n_sensors, picked, speeds_rpm,
                         speed_resolution_rpm, lfilter_recursion)

    def discrete(self, speed_rpm: float) -> tuple[np.ndarray, np.ndarray]:
        """(Ad, Bd): z_k = Ad z_(k-1) + Bd u_k, exact for u held over the sample."""
        lam, Q = self.model.system.modes(self.key(speed_rpm))
        g1, _, e = phi_integrals(lam, self.dt_s)
        B = self.model.system.B(self.key(speed_rpm))
        return (Q * e[None, :]) @ Q.T, (Q * g1[None, :]) @ (Q.T @ B)

    def _modal(self, key: float) -> tuple[np.ndarray, ...]:
        lam, Q = self.model.system.modes(key)
        g1, _, e = phi_integrals(lam, self.dt_s)
        return e, g1[:, None] * (Q.T @ self.model.system.B(key)), Q.T, Q
