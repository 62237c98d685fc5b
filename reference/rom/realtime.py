"""Streaming prediction with the reduced model, for CNC compensation.

:class:`ROMPredictor` is :class:`lumped.realtime.RealTimePredictor` for a
:class:`rom.model.ReducedModel`: the exact zero-order-hold step of the reduced system at a
fixed sample time (M_r = I and K_r(n) symmetric, so exp(-K_r dt) comes from one small
eigendecomposition per speed, cached to ``speed_resolution_rpm``), fused with the read-out
into one matrix acting on [z, u, 1]: ``step(u, speed) -> (sensor temperatures [K], P1 [m])``.
:meth:`ROMPredictor.run` replays a whole record mode by mode: each mode is a first-order
recursion, run by scipy.signal.lfilter (no Python loop over samples; the lumped predictor's
blocked cumulative sums would take tiny blocks here, as the ROM keeps modes of a few seconds).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from reference.rom.model import ReducedModel, _phi

_CHUNK = 16384  # samples per block of the batch replay (as lumped.realtime: stays in cache)


class ROMPredictor:
    """Streaming predictor at sample time ``dt_s`` [s]; inputs u follow
    ``model.input_names`` (source powers [W], ambient and coolant [K]), held over a sample.
    The growth readings are zeroed at the start field, uniform ``T0`` [K] (None: the spec's
    T_initial_K)."""

    def __init__(self, model: ReducedModel, dt_s: float, T0: float | None = None,
                 speeds_rpm: Sequence[float] = (), reading: str = "P1",
                 speed_resolution_rpm: float = 1.0):
        self.model, self.dt_s, self.reading = model, float(dt_s), reading
        self.resolution = float(speed_resolution_rpm)
        sysr = model.system
        self.n, self.m = sysr.r, len(model.input_names)
        self.n_sensors = len(model.sensor_names)
        z0 = model.initial(T0)
        # growth readings zeroed at the start, as ReducedModel.transient reads them
        self.O, self.offset = sysr.O, sysr.offset.copy()
        self.offset[self.n_sensors:] = -(sysr.O[self.n_sensors:] @ z0)
        self._reading = self.n_sensors + model.readings.index(reading) if reading in \
            model.readings else None
        self._steps: dict[float, np.ndarray] = {}
        self._modal: dict[float, tuple] = {}
        for s in speeds_rpm:
            self.fused(s)
        self._speed, self._Z = None, None
        self.xu = np.empty(self.n + self.m + 1)  # [z, u, 1]: the 1 carries the offsets
        self.xu[:self.n] = z0
        self.xu[-1] = 1.0
        self._buf = np.empty(self.n + len(self.O))

    def key(self, speed_rpm: float) -> float:
        return round(float(speed_rpm) / self.resolution) * self.resolution

    def discrete(self, speed_rpm: float) -> tuple[np.ndarray, np.ndarray]:
        """(Ad, Bd): z_k = Ad z_(k-1) + Bd u_k, exact for u held over the sample."""
        lam, Q = self.model.system.modes(self.key(speed_rpm))
        g1, _, e = _phi(lam, self.dt_s)
        B = self.model.system.B(self.key(speed_rpm))
        return (Q * e[None, :]) @ Q.T, (Q * g1[None, :]) @ (Q.T @ B)

    def fused(self, speed_rpm: float) -> np.ndarray:
        """[[Ad, Bd, 0], [O Ad, O Bd, offset]] acting on [z, u, 1]."""
        key = self.key(speed_rpm)
        Z = self._steps.get(key)
        if Z is None:
            Ad, Bd = self.discrete(key)
            top = np.hstack([Ad, Bd, np.zeros((self.n, 1))])
            bottom = np.hstack([self.O @ Ad, self.O @ Bd, self.offset[:, None]])
            Z = np.ascontiguousarray(np.vstack([top, bottom]))
            self._steps[key] = Z
        return Z

    @property
    def state(self) -> np.ndarray:
        return self.xu[:self.n].copy()

    def step(self, u: np.ndarray, speed_rpm: float) -> tuple[np.ndarray, float]:
        """Advance one sample; returns (sensor temperatures [K] at its end, the reading [m])."""
        if speed_rpm != self._speed:
            self._Z = self.fused(speed_rpm)
            self._speed = speed_rpm
        xu, buf, n = self.xu, self._buf, self.n
        xu[n:-1] = u
        np.dot(self._Z, xu, out=buf)
        xu[:n] = buf[:n]
        return buf[n:n + self.n_sensors].copy(), \
            (float(buf[n + self._reading]) if self._reading is not None else float("nan"))

    def outputs_now(self) -> np.ndarray:
        """Every output (sensors, then every growth reading) after the last step."""
        return self._buf[self.n:].copy()

    def run(self, U: np.ndarray, speeds_rpm: np.ndarray) -> np.ndarray:
        """Replay samples (U: n_samples x n_inputs, held over each; a speed per sample).
        Returns every output (n_samples x (sensors + readings)) at the end of each sample
        and leaves the predictor at the final state."""
        U = np.asarray(U, dtype=float)
        keys = np.round(np.asarray(speeds_rpm, dtype=float) / self.resolution) * self.resolution
        cuts = np.concatenate([[0], np.flatnonzero(np.diff(keys)) + 1, [len(keys)]])
        Y = np.empty((len(U), len(self.O)))
        z = self.xu[:self.n].copy()
        for a0, b0 in zip(cuts[:-1], cuts[1:], strict=True):
            key = float(keys[a0])
            if key not in self._modal:
                lam, Q = self.model.system.modes(key)
                g1, _, e = _phi(lam, self.dt_s)
                Bm = g1[:, None] * (Q.T @ self.model.system.B(key))
                self._modal[key] = (e, Bm, Q, self.O @ Q)
            e, Bm, Q, out = self._modal[key]
            w = Q.T @ z
            for c0 in range(a0, b0, _CHUNK):
                c1 = min(c0 + _CHUNK, b0)
                Y[c0:c1], w = _first_order(e, Bm, U[c0:c1], w, out)
            z = Q @ w
        self.xu[:self.n] = z
        return Y + self.offset


def _first_order(a: np.ndarray, Bm: np.ndarray, U: np.ndarray, w0: np.ndarray,
                 out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outputs out @ w_k (samples x outputs) of w_k = a w_(k-1) + Bm u_k per mode, and the
    last modal state."""
    from scipy.signal import lfilter

    D = U @ Bm.T  # (samples, modes)
    W = np.empty_like(D)
    for j in range(len(a)):
        W[:, j] = lfilter([1.0], [1.0, -a[j]], D[:, j], zi=[a[j] * w0[j]])[0]
    return W @ out.T, W[-1].copy()
