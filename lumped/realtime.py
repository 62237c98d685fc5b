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
speeds are cached to ``speed_resolution_rpm``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lumped.simulation import LumpedModel


class RealTimePredictor:
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
        self.resolution = float(speed_resolution_rpm)
        n = model.n_states
        self.n, self.m = n, model.system.n_inputs
        w = model.chain.rows.get(reading)
        x_start = model._initial(x0)
        # outputs: the sensors, then the growth reading w . (x - x_start): zeroed at the start,
        # as a bench zeroes P1 (and as LumpedModel.transient reads it)
        self.O = np.vstack([model.S, (w if w is not None else np.zeros(n))[None, :]])
        self._offset = np.zeros(len(self.O))
        self._offset[-1] = -(w @ x_start) if w is not None else 0.0
        self._steps: dict[float, np.ndarray] = {}
        self._modal: dict[float, tuple] = {}
        for s in speeds_rpm:
            self._fused(s)
        self._speed, self._Z = None, None
        self.xu = np.empty(n + self.m + 1)  # [x, u, 1]: the 1 carries the growth offset
        self.xu[:n] = x_start
        self.xu[-1] = 1.0
        self._buf = np.empty(n + len(self.O))

    def _key(self, speed_rpm: float) -> float:
        return round(float(speed_rpm) / self.resolution) * self.resolution

    def _fused(self, speed_rpm: float) -> np.ndarray:
        """[[Phi, Gamma, 0], [O Phi, O Gamma, offset]] acting on [x, u, 1]."""
        key = self._key(speed_rpm)
        Z = self._steps.get(key)
        if Z is None:
            Phi, Gam = self.model.system.discretize(self.dt_s, key)
            top = np.hstack([Phi, Gam, np.zeros((self.n, 1))])
            bottom = np.hstack([self.O @ Phi, self.O @ Gam, self._offset[:, None]])
            Z = np.ascontiguousarray(np.vstack([top, bottom]))
            self._steps[key] = Z
        return Z

    @property
    def state(self) -> np.ndarray:
        """Mass temperatures [K] now."""
        return self.xu[:self.n].copy()

    def step(self, u: np.ndarray, speed_rpm: float) -> tuple[np.ndarray, float]:
        """Advance one sample with inputs u held over it; returns (sensor temperatures [K] at
        the end of the sample (a fresh array), the growth reading [m])."""
        if speed_rpm != self._speed:
            self._Z = self._fused(speed_rpm)
            self._speed = speed_rpm
        xu, buf, n = self.xu, self._buf, self.n
        xu[n:-1] = u
        np.dot(self._Z, xu, out=buf)
        xu[:n] = buf[:n]
        return buf[n:-1].copy(), buf[-1]

    # ------------------------------------------------------------------ batch replay
    def _modes(self, speed_rpm: float) -> tuple:
        """(a, Bm, to_modal, from_modal, read-out in modal form) at a speed (cached)."""
        key = self._key(speed_rpm)
        if key not in self._modal:
            modal = self.model.system.modes(self.dt_s, key)
            self._modal[key] = (*modal, self.O @ modal[3])
        return self._modal[key]

    def run(self, U: np.ndarray, speeds_rpm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Replay samples: U (n_samples x n_inputs) held over each sample, speeds per sample.
        Returns (sensor temperatures [K], growth reading [m]) at the end of every sample, and
        leaves the predictor at the final state."""
        U = np.asarray(U, dtype=float)
        speeds = np.asarray(speeds_rpm, dtype=float)
        keys = np.round(speeds / self.resolution) * self.resolution
        cuts = np.concatenate([[0], np.flatnonzero(np.diff(keys)) + 1, [len(keys)]])
        Y = np.empty((len(U), len(self.O)))
        x = self.xu[:self.n].copy()
        for a0, b0 in zip(cuts[:-1], cuts[1:], strict=True):
            a, Bm, to_modal, from_modal, out = self._modes(keys[a0])
            z = to_modal @ x
            for c0 in range(a0, b0, _CHUNK):  # chunks stay in cache
                c1 = min(c0 + _CHUNK, b0)
                Y[c0:c1], z = modal_recursion(a, Bm, U[c0:c1], z, out)
            x = from_modal @ z
        self.xu[:self.n] = x
        Y += self._offset
        return Y[:, :-1], Y[:, -1]


_CHUNK = 16384


def modal_recursion(a: np.ndarray, Bm: np.ndarray, U: np.ndarray, z0: np.ndarray,
                     out: np.ndarray) -> np.ndarray:
    """Outputs out @ z_k (samples x outputs) of z_k = a z_(k-1) + Bm u_k for every mode.

    Samples are taken in blocks of L: inside a block z_j = a^j (cumsum_i(a^-i d_i) + a s),
    with s the state entering the block; the block states follow from a short loop over
    blocks, vectorised over modes. L keeps a^-L below 1e4, so the cumulative sums lose at
    most 4 of 16 digits. Arrays are laid out (position in block, block, mode) so that every
    pass runs over contiguous rows; the running sum is a loop of L row additions (numpy's
    cumsum along a middle axis is ten times slower). Returns (outputs, last modal state).
    """
    n, modes = len(U), len(a)
    a_min = float(a.min())
    L = int(np.clip(np.floor(np.log(1e4) / -np.log(a_min)) if a_min > 0 else 1, 1, 512))
    nb = -(-n // L)
    Up = np.zeros((nb * L, U.shape[1]))
    Up[:n] = U
    Uj = np.ascontiguousarray(Up.reshape(nb, L, -1).transpose(1, 0, 2))  # (L, nb, inputs)
    W = (Uj.reshape(L * nb, -1) @ Bm.T).reshape(L, nb, modes)  # 2-D BLAS
    j = np.arange(L)[:, None]
    with np.errstate(over="ignore", under="ignore"):
        inv = (a[None, :] ** -j)[:, None, :]  # a^-j, bounded by 1e4 through L
        pw = (a[None, :] ** j)[:, None, :]
    W *= inv
    for k in range(1, L):
        np.add(W[k], W[k - 1], out=W[k])
    ends = W[-1] * pw[-1]  # local block responses at their last sample (nb, modes)
    aL = a**L
    entering = np.empty((nb, modes))
    s = z0
    for b in range(nb):  # n / L steps, each vectorised over the modes
        entering[b] = s
        s = aL * s + ends[b]
    W += (a * entering)[None, :, :]
    W *= pw
    Y = (W.reshape(L * nb, modes) @ out.T).reshape(L, nb, -1).transpose(1, 0, 2)
    Y = Y.reshape(nb * L, -1)[:n]
    last = W[(n - 1) % L, (n - 1) // L].copy()
    return Y, last
