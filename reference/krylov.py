"""The reference transient by rational Krylov projection, one speed segment at a time.

Over a segment at one speed the FEM heat equation is linear and time-invariant::

    M x' = -K x + F(t),   F(t) = a_k + b_k (t - t_k) on step k,

with M and K symmetric positive definite. Its loads span a space of low rank (about three on
spl2782: the heat sources, the ambient and the coolant), so the exact solution lies,
to any accuracy, in a small rational Krylov space (Ruhe 1984; for the matrix exponential
Moret and Novati 2004, van den Eshof and Hochbruck 2006, whose shift-invert spaces converge
independently of the mesh for such operators)::

    V = span{ x_s, K^-1 Q, (M + s_j K)^-1 M ... } ,

Q a basis of the loads, x_s the state at the segment's start, the shifts s_j [s] spread
over the time scales read (the 1 s steps after a jump up to hours). V is M-orthonormal;
the Galerkin system z' = -V^T K V z + V^T F(t) is integrated exactly in time by its modes,
as :meth:`ThermalModel._modal_readouts` integrates a small mesh, so the only error is the
projection's.

The space grows by blocks until the read-outs of the last two spaces agree to ``tol``
[K, or m for the growth read-outs]; their largest difference over the segment is the
stated estimate of the error (the projection error falls geometrically with the blocks, so
the difference of two successive spaces bounds the error of the larger in practice; it is
an estimate, checked against the exact CRAM-16 integration in
tests/test_time_convergence.py). Per segment this costs one LU of K and one per shift, and a
few dozen solves, instead of CRAM's eight complex solves per step (reference.exact).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
import scipy.sparse as sp

#: shifts [s] of the rational Krylov space: the time scales read, from the ladder's 1 s
#: after a jump to the hours of the housing's warm-up, a decade apart or so
SHIFTS_S = (1.0, 30.0, 1000.0)
#: the most blocks of a segment's space (each block has the loads' rank + 1 columns)
MAX_BLOCKS = 40
#: blocks added between two checks of the estimate
CHECK_EVERY = 2


def _m_orthonormalise(W: np.ndarray, V: np.ndarray | None, M: sp.spmatrix,
                      drop: float = 1e-10) -> np.ndarray:
    """Columns of W made M-orthonormal to V and to each other (twice, classical
    Gram-Schmidt; a column that is numerically in the span already is dropped)."""
    new: list[np.ndarray] = []
    for w in W.T:
        w = w.copy()
        n0 = float(np.sqrt(max(w @ (M @ w), 0.0)))
        if n0 == 0.0:
            continue
        for _ in range(2):
            # against V, then the columns kept so far (not stacked onto V: V is large)
            for B in (V, np.array(new).T if new else None):
                if B is not None and B.shape[1]:
                    w -= B @ (B.T @ (M @ w))
        n1 = float(np.sqrt(max(w @ (M @ w), 0.0)))
        if n1 > drop * n0:
            new.append(w / n1)
    return np.array(new).T if new else np.zeros((W.shape[0], 0))


def _load_basis(loads: Sequence[tuple[np.ndarray, np.ndarray]], rel: float = 1e-12
                ) -> np.ndarray:
    """An orthonormal basis (Euclidean) of the span of every a_k and b_k."""
    scale = max(max(float(np.linalg.norm(a)), float(np.linalg.norm(b))) for a, b in loads)
    Q = np.zeros((len(loads[0][0]), 0))
    for a, b in loads:
        for v in (a, b):
            r = v - Q @ (Q.T @ v)
            r -= Q @ (Q.T @ r)
            n = float(np.linalg.norm(r))
            if n > rel * max(scale, 1e-300):
                Q = np.column_stack([Q, r / n])
    return Q


def modal_step(z: np.ndarray, lam: np.ndarray, dt: float, a: np.ndarray, b: np.ndarray
               ) -> np.ndarray:
    """Modal amplitudes after an exact step of ``dt`` [s] of z' = -lam z + a + b t (rates
    lam [1/s], modal loads a + b t over the step); series where lam dt is small."""
    e = np.exp(-lam * dt)
    g1 = np.where(lam * dt > 1e-8, -np.expm1(-lam * dt) / np.maximum(lam, 1e-300), dt)
    g2 = np.where(lam * dt > 1e-4, (dt - g1) / np.maximum(lam, 1e-300),
                  dt * dt / 2 - lam * dt ** 3 / 6)
    return e * z + g1 * a + g2 * b


def _galerkin_readouts(V: np.ndarray, KV: np.ndarray, M: sp.spmatrix, x0: np.ndarray,
                       loads_r: list[tuple[np.ndarray, np.ndarray]], h: np.ndarray,
                       readout_r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Read-outs after each step of the Galerkin system on V (M-orthonormal), exact in
    time for the linear loads; and the final reduced state."""
    from scipy.linalg import eigh

    Kr = V.T @ KV
    lam, W = eigh(0.5 * (Kr + Kr.T))
    lam = np.maximum(lam, 0.0)
    z = W.T @ (V.T @ (M @ x0))
    OW = readout_r @ W
    Y = np.empty((len(h), readout_r.shape[0]))
    for k, dt in enumerate(h):
        z = modal_step(z, lam, dt, W.T @ loads_r[k][0], W.T @ loads_r[k][1])
        Y[k] = OW @ z
    return Y, V @ (W @ z)


def segment_readouts(K: sp.spmatrix, M: sp.spmatrix, x0: np.ndarray,
                     loads: Sequence[tuple[np.ndarray, np.ndarray]], h: np.ndarray,
                     readout: np.ndarray, factor: Callable, tol: float,
                     shifts: Sequence[float] = SHIFTS_S) -> tuple[np.ndarray, np.ndarray,
                                                                  np.ndarray, int]:
    """One speed segment (module docstring): read-outs after each of its steps (``h`` [s],
    loads a_k + b_k (t - t_k)), the estimate of each read-out's largest error over the
    segment, the state at its end, and the dimension of the space used.

    ``readout``: rows c, read as c . x. ``tol``: the estimate asked, per read-out (a
    scalar or one per row). ``factor`` makes a sparse LU (``.solve``)."""
    tol = np.broadcast_to(np.asarray(tol, dtype=float), (readout.shape[0],))
    Q = _load_basis(loads)
    lu_K = factor(K)
    # the loads' static responses and the start state: the space at time scales >> the
    # shifts; then shift-invert blocks for the faster ones
    V = _m_orthonormalise(np.column_stack([x0, lu_K.solve(Q)]), None, M)
    del lu_K
    lus = [factor((M + s * K).tocsc()) for s in shifts]
    coeffs = [(Q.T @ a, Q.T @ b) for a, b in loads]

    def galerkin() -> tuple[np.ndarray, np.ndarray]:
        VQ = V.T @ Q
        return _galerkin_readouts(V, K @ V, M, x0, [(VQ @ a, VQ @ b) for a, b in coeffs], h,
                                  readout @ V)

    block = V
    previous, est, checked = None, np.full(readout.shape[0], np.inf), 0
    for j in range(MAX_BLOCKS):
        block = _m_orthonormalise(lus[j % len(lus)].solve(M @ block), V, M)
        if block.shape[1] == 0:  # the space is invariant: the projection is exact
            break
        V = np.column_stack([V, block])
        if (j + 1) % CHECK_EVERY:
            continue
        Y, x_end = galerkin()
        checked = V.shape[1]
        if previous is not None:
            est = np.max(np.abs(Y - previous), axis=0)
            if np.all(est <= tol):
                return Y, est, x_end, checked
        previous = Y
    if checked != V.shape[1]:  # the space grew since the last check
        Y, x_end = galerkin()
        if previous is not None:
            est = np.max(np.abs(Y - previous), axis=0)
    return Y, est, x_end, V.shape[1]
