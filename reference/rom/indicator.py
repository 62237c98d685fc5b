"""A-posteriori error indicator of a ROM run: the residual of the full model at the lifted
reduced state.

For a backward-Euler run (the reference's scheme) the lifted state T_k = V z_k leaves the
residual ``res_k = M (T_k - T_(k-1)) / dt + K(n) T_k - B(n) u_k`` in the full equations. The
error e_k = T_fem,k - T_k then obeys (M + dt K) e_k = M e_(k-1) - dt res_k, and since
(M + dt K)^-1 M contracts the capacity norm ||x||_M = sqrt(x^T M x) by 1 / (1 + dt lam_min)::

    ||e_k||_M <= (||e_(k-1)||_M + dt ||res_k||_(M^-1)) / (1 + dt lam_min)

(lam_min: the smallest rate of K(n) v = lam M v; the ROM's own smallest rate is used, an upper
estimate as the slow modes are in the basis, so the recursion is an estimate, not a strict
bound). Divided by sqrt(1^T M 1) it is the capacity-weighted RMS temperature error [K]
(``bound_rms_K``). A point sensor is not bounded by an energy norm, so the sensors' error is
estimated as ``calibration * bound_rms_K`` with the ratio of the true worst sensor error to
the bound on the training cycle (``estimated_max_K``).

||res_k||_(M^-1) costs no full-size work per step: res_k is linear in
w_k = (dz/dt, theta_j(n) z for every affine term, source powers, theta_s(n) T_ref,s per
film), so ||res_k||^2 = w_k^T G w_k with the Gram matrix G = R^T M^-1 R of the pieces
R = [M V, K_j V, f_j, b_s] computed once (M^-1 M V = V needs no solve).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.rom.model import step_end_inputs
from spindle.loads import LoadCase


@dataclass
class ResidualIndicator:
    G: np.ndarray
    capacity_J_K: float  # 1^T M 1 (per radian, as M)
    calibration_K: float = float("nan")  # true worst sensor error / bound_rms_K (training)

    def _w(self, rom, case: LoadCase, grid: np.ndarray, Z: np.ndarray) -> np.ndarray:
        sysr = rom.system
        mid = 0.5 * (grid[1:] + grid[:-1])
        speeds = np.asarray(case.speed_rpm(mid), dtype=float)
        U = step_end_inputs(rom.inputs, case, grid)  # as the scheme reads them
        th = np.array([sysr.theta(float(n)) for n in speeds])  # (steps, terms)
        dz = (Z[1:] - Z[:-1]) / np.diff(grid)[:, None]
        ms = sysr.F_src.shape[1]
        films = np.array([th[:, j] * U[:, -2 if ref == "ambient" else -1]
                          for j, ref in sysr.film_rows]).T if sysr.film_rows else \
            np.zeros((len(speeds), 0))
        Kz = (th[:, :, None] * Z[1:, None, :]).reshape(len(speeds), -1)
        # the load enters the residual with a minus sign
        return np.hstack([dz, Kz, -U[:, :ms], -films]), speeds

    def residual_norms(self, rom, case: LoadCase, grid: np.ndarray, Z: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
        """||res_k||_(M^-1) per step, and the speed of each step."""
        W, speeds = self._w(rom, case, grid, Z)
        q = np.einsum("ij,jk,ik->i", W, self.G, W)
        return np.sqrt(np.maximum(q, 0.0)), speeds

    def bound(self, rom, case: LoadCase, grid: np.ndarray, Z: np.ndarray) -> np.ndarray:
        """The recursion of the module docstring as an RMS temperature [K] per grid time."""
        eta, speeds = self.residual_norms(rom, case, grid, Z)
        dt = np.diff(grid)
        lam = {n: float(rom.system.modes(n)[0][0]) for n in np.unique(speeds)}
        E = np.zeros(len(grid))
        for k in range(len(dt)):
            E[k + 1] = (E[k] + dt[k] * eta[k]) / (1.0 + dt[k] * lam[speeds[k]])
        return E / np.sqrt(self.capacity_J_K)

    def estimate(self, rom, case: LoadCase, grid: np.ndarray, Z: np.ndarray) -> dict:
        E = self.bound(rom, case, grid, Z)
        return {"bound_rms_K": float(E.max()),
                "estimated_max_K": float(self.calibration_K * E.max()),
                "calibration": self.calibration_K}


def residual_indicator(full, V: np.ndarray) -> ResidualIndicator:
    """The Gram matrix of the residual's pieces for basis V (one sparse LU of M)."""
    from reference.thermal import factorize

    M = full.M
    MV = M @ V
    pieces = [MV] + [A @ V for _, A in full.terms] + [full.F_src] + \
        [b[:, None] for _, b, _ in full.film_rows]
    R = np.hstack(pieces)
    lu = factorize(M)
    MinvR = np.hstack([V, lu.solve(np.hstack(pieces[1:]))])
    G = R.T @ MinvR
    return ResidualIndicator(0.5 * (G + G.T), float(M.sum()))
