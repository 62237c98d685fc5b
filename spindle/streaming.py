"""The streaming kernel both real-time predictors share (lumped.realtime for the lumped model,
reference.rom.realtime for the reduced model of the FEM): numerics only, no spindle knowledge.

A linear system x_k = Ad(n) x_(k-1) + Bd(n) u_k, read out as y_k = O x_k + offset, is held
per speed n (rounded to ``speed_resolution``) as one fused matrix acting on [x, u, 1]::

    [[Ad, Bd, 0], [O Ad, O Bd, offset]]

so a streaming step is one small matrix-vector product. :meth:`FusedStepper.run` replays a
whole record mode by mode instead: per constant-speed segment the step is diagonal in the
speed's modes (x = from_modal z, z_k = a z_(k-1) + Bm u_k), and each mode is a first-order
recursion evaluated without a Python loop over samples (:func:`modal_recursion`, or
:func:`lfilter_recursion` where the modes are fast). The model supplies the discrete step
and the modes of a speed (``discrete(n)``, ``modal(n)``); both are computed once per speed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

#: samples per block of the batch replay (blocks stay in cache)
CHUNK = 16384

#: (outputs, last modal state) of z_k = a z_(k-1) + Bm u_k read through ``out``
Recursion = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray],
                     tuple[np.ndarray, np.ndarray]]


class FusedStepper:
    """Streaming and replay of a per-speed linear discrete system (module docstring).

    ``discrete(n) -> (Ad, Bd)`` and ``modal(n) -> (a, Bm, to_modal, from_modal)`` give the
    step of speed n; ``readout`` (n_out x n) and ``offset`` (n_out) the outputs; ``x0`` the
    initial state; ``speeds`` are prepared at once. ``recursion`` runs the modes of a replay.
    :meth:`step` returns the first ``n_first`` outputs (the temperatures) and the one at
    ``picked`` (a growth reading; None: NaN).
    """

    def __init__(self, discrete: Callable[[float], tuple[np.ndarray, np.ndarray]],
                 modal: Callable[[float], tuple[np.ndarray, ...]], readout: np.ndarray,
                 offset: np.ndarray, x0: np.ndarray, n_inputs: int, n_first: int,
                 picked: int | None, speeds: Sequence[float] = (),
                 speed_resolution: float = 1.0, recursion: Recursion | None = None):
        self._discrete, self._modal = discrete, modal
        self.O = np.asarray(readout, dtype=float)  # noqa: E741
        self.offset = np.asarray(offset, dtype=float)
        self.n, self.m = self.O.shape[1], int(n_inputs)
        self.n_first = int(n_first)
        # the picked output's place in the step's buffer [x_end, outputs]
        self._picked = None if picked is None else self.n + int(picked)
        self.resolution = float(speed_resolution)
        self.recursion = recursion or modal_recursion
        self._steps: dict[float, np.ndarray] = {}
        self._modes: dict[float, tuple] = {}
        self.xu = np.empty(self.n + self.m + 1)  # [x, u, 1]: the 1 carries the offsets
        self.xu[:self.n] = x0
        self.xu[-1] = 1.0
        self._buf = np.empty(self.n + len(self.O))
        self._speed, self._Z = None, None
        for s in speeds:
            self.fused(s)

    def key(self, speed: float) -> float:
        """The speed as the cache holds it (rounded to the resolution)."""
        return round(float(speed) / self.resolution) * self.resolution

    def fused(self, speed: float) -> np.ndarray:
        """[[Ad, Bd, 0], [O Ad, O Bd, offset]] of a speed, acting on [x, u, 1] (cached)."""
        key = self.key(speed)
        Z = self._steps.get(key)
        if Z is None:
            Ad, Bd = self._discrete(key)
            top = np.hstack([Ad, Bd, np.zeros((self.n, 1))])
            bottom = np.hstack([self.O @ Ad, self.O @ Bd, self.offset[:, None]])
            Z = np.ascontiguousarray(np.vstack([top, bottom]))
            self._steps[key] = Z
        return Z

    def modes(self, speed: float) -> tuple:
        """(a, Bm, to_modal, from_modal, read-out in modal form) of a speed (cached)."""
        key = self.key(speed)
        if key not in self._modes:
            modal = self._modal(key)
            self._modes[key] = (*modal, self.O @ modal[3])
        return self._modes[key]

    @property
    def state(self) -> np.ndarray:
        """The state now (a copy)."""
        return self.xu[:self.n].copy()

    @state.setter
    def state(self, x: np.ndarray) -> None:
        self.xu[:self.n] = x

    def step(self, u: np.ndarray, speed: float) -> tuple[np.ndarray, float]:
        """Advance one sample with inputs u held over it; returns (the first ``n_first``
        outputs at its end (a fresh array), the picked output). The hot path of a CNC's
        compensation: one matrix-vector product."""
        if speed != self._speed:
            self._Z = self.fused(speed)
            self._speed = speed
        xu, buf, n = self.xu, self._buf, self.n
        xu[n:-1] = u
        np.dot(self._Z, xu, out=buf)
        xu[:n] = buf[:n]
        return buf[n:n + self.n_first].copy(), \
            (float(buf[self._picked]) if self._picked is not None else float("nan"))

    def outputs_now(self) -> np.ndarray:
        """Every output after the last step (a copy)."""
        return self._buf[self.n:].copy()

    def run(self, U: np.ndarray, speeds: np.ndarray) -> np.ndarray:
        """Replay samples (U: n_samples x n_inputs, held over each; a speed per sample).
        Returns every output (n_samples x n_out) at the end of each sample and leaves the
        stepper at the final state."""
        U = np.asarray(U, dtype=float)
        keys = np.round(np.asarray(speeds, dtype=float) / self.resolution) * self.resolution
        cuts = np.concatenate([[0], np.flatnonzero(np.diff(keys)) + 1, [len(keys)]])
        Y = np.empty((len(U), len(self.O)))
        x = self.xu[:self.n].copy()
        for a0, b0 in zip(cuts[:-1], cuts[1:], strict=True):
            a, Bm, to_modal, from_modal, out = self.modes(keys[a0])
            z = to_modal @ x
            for c0 in range(a0, b0, CHUNK):
                c1 = min(c0 + CHUNK, b0)
                Y[c0:c1], z = self.recursion(a, Bm, U[c0:c1], z, out)
            x = from_modal @ z
        self.xu[:self.n] = x
        return Y + self.offset


def modal_recursion(a: np.ndarray, Bm: np.ndarray, U: np.ndarray, z0: np.ndarray,
                    out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Outputs out @ z_k (samples x outputs) of z_k = a z_(k-1) + Bm u_k for every mode.

    Samples are taken in blocks of L: inside a block z_j = a^j (cumsum_i(a^-i d_i) + a s),
    with s the state entering the block; the block states follow from a short loop over
    blocks, vectorised over modes. L keeps a^-L below 1e4, so the cumulative sums lose at
    most 4 of 16 digits. Arrays are laid out (position in block, block, mode) so that every
    pass runs over contiguous rows; the running sum is a loop of L row additions (numpy's
    cumsum along a middle axis is ten times slower). Returns (outputs, last modal state).
    Fast modes make L small: :func:`lfilter_recursion` suits them better.
    """
    n, modes = len(U), len(a)
    a_min = float(a.min())
    L = int(np.clip(np.floor(np.log(1e4) / -np.log(a_min)) if a_min > 0 else 1, 1, 512))
    if L == 1:  # single-sample blocks: the same sums without the blocks' bookkeeping
        D = U @ Bm.T
        Z = np.empty((n, modes))
        s = z0
        for k in range(n):
            s = a * s + D[k]
            Z[k] = s
        return Z @ out.T, (Z[-1].copy() if n else np.array(z0, dtype=float))
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


def lfilter_recursion(a: np.ndarray, Bm: np.ndarray, U: np.ndarray, w0: np.ndarray,
                      out: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """As :func:`modal_recursion`, one ``scipy.signal.lfilter`` per mode: the better choice
    where modes of a few seconds would cut the blocked sums into tiny blocks."""
    from scipy.signal import lfilter

    D = U @ Bm.T  # (samples, modes)
    W = np.empty_like(D)
    for j in range(len(a)):
        W[:, j] = lfilter([1.0], [1.0, -a[j]], D[:, j], zi=[a[j] * w0[j]])[0]
    return W @ out.T, W[-1].copy()
