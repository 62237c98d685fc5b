"""Projection-based reduced-order model (ROM) of the FEM thermal reference, with its
thermoelastic read-out (issue 17).

The reference is, at speed n, ``M dT/dt + K(n) T = B(n) u(t)`` with the affine forms of
:class:`reference.thermal.Operator`::

    K(n) = K_solid + sum_c h_c C_c + sum_l g_l(n) K_l + sum_s h_s(n) R_s
    B(n) u = sum_j P_j f_j + sum_s h_s(n) T_ref,s b_s

u = (source powers [W], ambient [K], coolant [K]) and the outputs y = O T + o: the sensors
(probe rows) and the growth readings P1, TCP (``g . (T - T_ref)``, reference.elastic).

One basis V (N x r), orthonormal in the capacity inner product (V^T M V = I), serves every
speed: the one-sided Galerkin projection keeps every affine term (V^T K_j V, V^T b_s,
V^T f_j, O V), so K_r(n) is symmetric positive definite at every speed (stable) and the
speed dependence is exact in the reduced model, not interpolated. V holds

1. the uniform field (so the initial state and the all-equal steady state are exact);
2. rational Krylov vectors (K(n_i) + s_k M)^-1 [B(n_i), O^T] at a few speeds n_i over the
   speed range and shifts s_k from 0 (steady states) to 0.1 1/s (input and output
   directions; K and M are symmetric, so the output directions double the moments matched);
3. compressed by POD of the candidate ROM's trajectory on a training cycle plus its steady
   responses, so that the first r directions are the ones that matter; r is chosen as the
   smallest that meets the tolerances against the FEM on the training cycle (rom.build).

Time integration: ``method="be"`` is the reference's backward Euler on its own grid (the
difference from :meth:`ReferenceModel.transient` is then the projection error alone);
``method="exact"`` integrates the reduced system exactly for inputs linear between grid
points, speed held at its mid-step value (as :meth:`ThermalModel.exact_readouts`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from spindle.errors import SolverError
from spindle.loads import LoadCase, start_temperature_K, time_grid
from spindle.spec import BearingLink

TWO_PI = 2.0 * math.pi
#: Krylov shifts [1/s]: 0 (steady state) to 0.1 1/s (10 s), covering the thermal time
#: constants of a spindle (minutes to hours) and the 1 s sample time of a controller
DEFAULT_SHIFTS = (0.0, 3e-5, 3e-4, 3e-3, 3e-2, 0.3)
#: speeds of the Krylov vectors, as fractions of the top speed (4 points over 0..top)
SPEED_FRACTIONS = (0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0)


# ============================================================================ full model
@dataclass
class FullSystem:
    """The reference's affine pieces as plain arrays, with the read-out rows.

    ``terms``: (coefficient function of speed, sparse matrix) per affine term of K(n);
    the films' load vectors share their coefficient with their K term (``film_terms``).
    """

    M: object
    terms: list[tuple[Callable[[float], float], object]]
    film_rows: list[tuple[int, np.ndarray, str]]  # (index in terms, b_s, "ambient"/"coolant")
    F_src: np.ndarray  # (N, n_sources)
    source_names: list[str]
    source_defaults: list[object]  # the spec's heat sources (their power series)
    O: np.ndarray  # noqa: E741 (n_out, N) dense: sensors then growth readings
    offset: np.ndarray  # (n_out,) constant part of the outputs
    sensor_names: list[str]
    readings: list[str]
    T_initial_K: float

    @property
    def n(self) -> int:
        return self.M.shape[0]

    def theta(self, speed_rpm: float) -> np.ndarray:
        return np.array([f(speed_rpm) for f, _ in self.terms])

    def K(self, speed_rpm: float):
        th = self.theta(speed_rpm)
        K = self.terms[0][1] * th[0]
        for c, (_, A) in zip(th[1:], self.terms[1:], strict=True):
            K = K + c * A
        return K.tocsr()

    def B(self, speed_rpm: float) -> np.ndarray:
        """Input matrix (N, n_sources + 2) at a speed: sources, ambient, coolant."""
        th = self.theta(speed_rpm)
        B = np.zeros((self.n, self.F_src.shape[1] + 2))
        B[:, :self.F_src.shape[1]] = self.F_src
        for j, b, ref in self.film_rows:
            B[:, -2 if ref == "ambient" else -1] += th[j] * b
        return B

    def inputs(self, case: LoadCase, t: np.ndarray) -> np.ndarray:
        """u at times t (n_t, n_sources + 2): source powers [W], ambient, coolant [K]."""
        return case_inputs(case, t, self.source_names, self.source_defaults)


def step_end_inputs(inputs: Callable, case: LoadCase, grid: np.ndarray) -> np.ndarray:
    """u at the end of each step of ``grid`` read from the left (n_steps, n_u): a held input
    switching at a step's end acts from there on, not over the step (as
    :meth:`reference.thermal.ThermalModel.solve_transient` reads it); ``inputs(case, t)``."""
    grid = np.asarray(grid, dtype=float)
    return inputs(case, grid[1:] - 1e-9 * np.diff(grid))


def case_inputs(case: LoadCase, t, source_names: Sequence[str], source_defaults: Sequence
                ) -> np.ndarray:
    """u at times t [s] (n_t, n_sources + 2): each source's power [W] (the case's, else the
    spec's default), then ambient and coolant [K]; the full and the reduced model share it."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    cols = [np.broadcast_to(np.asarray(case.sources.get(n, d.power_W)(t), dtype=float), t.shape)
            for n, d in zip(source_names, source_defaults, strict=True)]
    cols.append(np.broadcast_to(np.asarray(case.T_ambient_K(t), dtype=float), t.shape))
    cols.append(np.broadcast_to(np.asarray(case.T_coolant_K(t), dtype=float), t.shape))
    return np.stack(cols, axis=-1)


def _coefficient(obj, kind: str) -> Callable[[float], float]:
    if kind == "link":
        if isinstance(obj, BearingLink):
            return lambda n: float(obj.G_W_K(n))
        return lambda n: float(obj.h_W_m2K(n))
    if kind == "film":
        return lambda n: float(obj.h_W_m2K(n))
    return lambda n: 1.0


def full_system(reference) -> FullSystem:
    """The affine pieces and read-outs of a :class:`reference.ReferenceModel`."""
    th = reference.thermal
    op = th.op
    K0 = op.K_solid.copy()
    for lk, C in op.contacts:  # contacts do not depend on speed
        K0 = K0 + lk.h_W_m2K * C
    terms = [(_coefficient(None, "one"), K0.tocsr())]
    terms += [(_coefficient(lk, "link"), A) for lk, A in op.links]
    film_rows = []
    for s, R, b in op.films:
        film_rows.append((len(terms), np.asarray(b, dtype=float), s.T_ref))
        terms.append((_coefficient(s, "film"), R))
    names, pts = th.sensor_points()
    rows = [th.probe_matrix(pts).toarray()]
    gains = reference.growth_gains()
    readings = list(gains)
    offset = np.zeros(len(names) + len(readings))
    if readings:
        rows.append(np.array([g for g, _ in gains.values()]))
        offset[len(names):] = [-reference.elastic.T_ref * g.sum() for g, _ in gains.values()]
    F_src = np.column_stack([f for _, f in op.sources]) if op.sources else np.zeros((op.M.shape[0], 0))
    return FullSystem(op.M, terms, film_rows, F_src, [s.name for s, _ in op.sources],
                      [s for s, _ in op.sources], np.vstack(rows), offset, names, readings,
                      float(reference.spec.T_initial_K))


def fem_transient(full: FullSystem, case: LoadCase, dt_s: float, T0: float | None = None,
                  progress: Callable[[float], None] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Backward Euler of the full model on time_grid(case, dt_s), exactly the scheme of
    :meth:`reference.thermal.ThermalModel.solve_transient` (theta = 1, speed at mid-step,
    load at the step's end read from the left: :func:`step_end_inputs`), keeping only the
    outputs. Returns (times [s], Y (n_t, n_out))."""
    from reference.thermal import factorize

    grid = time_grid(case, dt_s)
    T = np.full(full.n, start_temperature_K(case, T0))
    Y = np.empty((len(grid), len(full.offset)))
    Y[0] = full.O @ T
    lus: dict[tuple, object] = {}
    Bs: dict[float, np.ndarray] = {}
    U = step_end_inputs(full.inputs, case, grid)
    mid = 0.5 * (grid[1:] + grid[:-1])
    speeds = np.asarray(case.speed_rpm(mid), dtype=float)
    for k in range(1, len(grid)):
        dt, n = grid[k] - grid[k - 1], float(speeds[k - 1])
        key = (round(dt, 9), n)
        if key not in lus:
            lus.clear()  # one LU at a time: at level 2 each holds about 100 MB
            lus[key] = factorize(full.M / dt + full.K(n))
        if n not in Bs:
            Bs[n] = full.B(n)
        T = lus[key].solve(full.M @ T / dt + Bs[n] @ U[k - 1])
        Y[k] = full.O @ T
        if progress is not None:
            progress(grid[k] / case.duration_s)
    return grid, zeroed_readings(Y + full.offset, len(full.sensor_names))


def zeroed_readings(Y: np.ndarray, n_sensors: int) -> np.ndarray:
    """Outputs (n_t, sensors then growth readings) with each growth reading [m] relative to
    its value at the start, as reference.simulation.zeroed_at_start (temperatures as they
    are)."""
    Y = np.array(Y, dtype=float)
    Y[:, n_sensors:] -= Y[0, n_sensors:]
    return Y


def fem_steady(full: FullSystem, case: LoadCase, t: float = 0.0) -> np.ndarray:
    from reference.thermal import factorize

    n = float(case.speed_rpm(t))
    T = factorize(full.K(n)).solve(full.B(n) @ full.inputs(case, t)[0])
    return full.O @ T + full.offset


# ============================================================================ basis
def _gram(W: np.ndarray, M, chunk: int = 64) -> np.ndarray:
    """W^T M W, M W formed a block of columns at a time (memory: one block, not W again)."""
    G = np.empty((W.shape[1], W.shape[1]))
    for a in range(0, W.shape[1], chunk):
        G[:, a:a + chunk] = W.T @ (M @ W[:, a:a + chunk])
    return 0.5 * (G + G.T)


def m_orthonormalize(W: np.ndarray, M, rtol: float = 1e-11) -> np.ndarray:
    """Columns spanning W's range (directions above rtol of the largest dropped), orthonormal
    in the M inner product; two passes of the Gram-matrix method (the second restores
    orthonormality to round-off). W is overwritten."""
    norms = np.sqrt(np.diag(_gram(W, M)))
    W = W[:, norms > 0]  # an input the spec lacks is zero
    W /= norms[norms > 0][None, :]
    for _ in range(2):
        lam, U = np.linalg.eigh(_gram(W, M))
        keep = lam > rtol * lam.max()
        W = W @ (U[:, keep] / np.sqrt(lam[keep])[None, :])
    return W


def krylov_candidates(full: FullSystem, speeds_rpm: Sequence[float],
                      shifts: Sequence[float] = DEFAULT_SHIFTS,
                      progress: Callable[[str], None] | None = None) -> np.ndarray:
    """The uniform field and (K(n) + s M)^-1 [B(n), O^T] for every speed n and shift s,
    orthonormal in M."""
    from reference.thermal import factorize

    Ot = full.O.T
    m = full.F_src.shape[1] + 2 + Ot.shape[1]
    W = np.empty((full.n, 1 + len(speeds_rpm) * len(shifts) * m))
    W[:, 0] = 1.0
    j = 1
    for n in speeds_rpm:
        K, B = full.K(float(n)), full.B(float(n))
        rhs = np.hstack([B, Ot])
        for s in shifts:
            if progress:
                progress(f"Krylov vectors at {n:g} rpm, shift {s:g} 1/s")
            W[:, j:j + m] = factorize(K + s * full.M if s else K).solve(rhs)
            j += m
    return m_orthonormalize(W, full.M)


# ============================================================================ reduced model
@dataclass
class ReducedSystem:
    """The projected affine system (V^T M V = I): K_r(n) = sum_j theta_j(n) K_j,
    B_r(n) u = F_src u_src + sum_films theta_j(n) T_ref b_j, y = O z + offset."""

    Kj: np.ndarray  # (n_terms, r, r)
    bj: np.ndarray  # (n_films, r)
    film_rows: list[tuple[int, str]]
    F_src: np.ndarray  # (r, n_sources)
    O: np.ndarray  # noqa: E741 (n_out, r) read-out
    offset: np.ndarray
    coefficients: list[Callable[[float], float]]
    z_one: np.ndarray  # V^T M 1: the uniform unit field in reduced coordinates
    _cache: dict = field(default_factory=dict, repr=False)

    @property
    def r(self) -> int:
        return self.Kj.shape[1]

    def theta(self, speed_rpm: float) -> np.ndarray:
        return np.array([f(speed_rpm) for f in self.coefficients])

    def K(self, speed_rpm: float) -> np.ndarray:
        return np.tensordot(self.theta(speed_rpm), self.Kj, axes=1)

    def B(self, speed_rpm: float) -> np.ndarray:
        th = self.theta(speed_rpm)
        B = np.zeros((self.r, self.F_src.shape[1] + 2))
        B[:, :self.F_src.shape[1]] = self.F_src
        for (j, ref), b in zip(self.film_rows, self.bj, strict=True):
            B[:, -2 if ref == "ambient" else -1] += th[j] * b
        return B

    def truncated(self, Phi: np.ndarray) -> ReducedSystem:
        """The system projected further on the orthonormal columns Phi."""
        return ReducedSystem(np.einsum("ia,jab,bk->jik", Phi.T, self.Kj, Phi), self.bj @ Phi,
                             self.film_rows, Phi.T @ self.F_src, self.O @ Phi, self.offset,
                             self.coefficients, Phi.T @ self.z_one)

    def modes(self, speed_rpm: float) -> tuple[np.ndarray, np.ndarray]:
        """(rates, orthonormal modes) of K_r(n) (symmetric: M_r = I), cached."""
        key = ("modes", float(speed_rpm))
        if key not in self._cache:
            lam, Q = np.linalg.eigh(self.K(speed_rpm))
            self._cache[key] = (np.maximum(lam, 0.0), Q)
        return self._cache[key]

    def steady(self, u: np.ndarray, speed_rpm: float) -> np.ndarray:
        return np.linalg.solve(self.K(speed_rpm), self.B(speed_rpm) @ u)

    def simulate(self, full_inputs: Callable, case: LoadCase, dt_s: float, z0: np.ndarray,
                 method: str = "be") -> tuple[np.ndarray, np.ndarray]:
        """Reduced states (n_t, r) on time_grid(case, dt_s); see the module docstring."""
        grid = time_grid(case, dt_s)
        mid = 0.5 * (grid[1:] + grid[:-1])
        speeds = np.asarray(case.speed_rpm(mid), dtype=float)
        Z = np.empty((len(grid), self.r))
        Z[0] = z0
        if method == "be":
            U = step_end_inputs(full_inputs, case, grid)
            for k in range(1, len(grid)):
                dt, n = grid[k] - grid[k - 1], float(speeds[k - 1])
                key = ("be", round(dt, 9), n)
                if key not in self._cache:
                    A = np.eye(self.r) / dt + self.K(n)
                    self._cache[key] = (sla.cho_factor(A), self.B(n))
                cf, B = self._cache[key]
                Z[k] = sla.cho_solve(cf, Z[k - 1] / dt + B @ U[k - 1])
            return grid, Z
        if method != "exact":
            raise ValueError(f"method must be 'be' or 'exact', not {method!r}")
        eps = 1e-9
        for k in range(1, len(grid)):
            t0, t1 = grid[k - 1], grid[k]
            dt, n = t1 - t0, float(speeds[k - 1])
            lam, Q = self.modes(n)
            B = self._cache.setdefault(("B", n), self.B(n))
            ua = full_inputs(case, np.array([t0 + eps * dt, t1 - eps * dt]))
            a = Q.T @ (B @ ua[0])
            b = (Q.T @ (B @ ua[1]) - a) / dt
            g1, g2, e = phi_integrals(lam, dt)
            Z[k] = Q @ (e * (Q.T @ Z[k - 1]) + g1 * a + g2 * b)
        return grid, Z


def phi_integrals(lam: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact integrals of exp(-lam (dt - s)) and s exp(-lam (dt - s)) over [0, dt]."""
    e = np.exp(-lam * dt)
    g1 = np.where(lam * dt > 1e-8, -np.expm1(-lam * dt) / np.maximum(lam, 1e-300), dt)
    g2 = np.where(lam * dt > 1e-4, (dt - g1) / np.maximum(lam, 1e-300),
                  dt * dt / 2 - lam * dt ** 3 / 6)
    return g1, g2, e


def project(full: FullSystem, V: np.ndarray) -> ReducedSystem:
    """Galerkin projection of the affine pieces on V (M-orthonormal columns)."""
    Kj = np.array([V.T @ (A @ V) for _, A in full.terms])
    Kj = 0.5 * (Kj + Kj.transpose(0, 2, 1))
    bj = np.array([V.T @ b for _, b, _ in full.film_rows]) if full.film_rows else \
        np.zeros((0, V.shape[1]))
    return ReducedSystem(Kj, bj, [(j, ref) for j, _, ref in full.film_rows], V.T @ full.F_src,
                         full.O @ V, full.offset.copy(), [f for f, _ in full.terms],
                         V.T @ (full.M @ np.ones(full.n)))


def pod_directions(red: ReducedSystem, Z: np.ndarray, steady_cols: np.ndarray) -> np.ndarray:
    """Orthonormal directions of the candidate space ordered by importance: the uniform field
    first, then the POD modes of the snapshots (trajectory and steady responses) with the
    uniform part removed."""
    one = red.z_one / np.linalg.norm(red.z_one)
    S = np.hstack([Z.T, steady_cols])
    S = S - np.outer(one, one @ S)
    U, sv, _ = np.linalg.svd(S, full_matrices=False)
    keep = sv > 1e-12 * sv[0]
    return np.column_stack([one, U[:, keep]]), sv[keep]


# ============================================================================ the ROM
@dataclass
class ReducedModel:
    """A reduced model of the FEM reference of ``spec`` at mesh ``level`` (see the module
    docstring): ``steady``, ``transient`` and the streaming predictor (rom.realtime) with
    the result interface of the other models."""

    spec: object
    level: int
    order: int
    n_full: int
    system: ReducedSystem
    source_names: list[str]
    source_defaults: list[object]
    sensor_names: list[str]
    readings: list[str]
    V: np.ndarray | None = None  # (N, r) the basis (fields, error indicator); may be dropped
    info: dict = field(default_factory=dict)
    indicator: object | None = None  # rom.indicator.ResidualIndicator, when built

    @property
    def n_states(self) -> int:
        return self.system.r

    @property
    def input_names(self) -> list[str]:
        return [*self.source_names, "T_ambient_K", "T_coolant_K"]

    def inputs(self, case: LoadCase, t) -> np.ndarray:
        return case_inputs(case, t, self.source_names, self.source_defaults)

    def initial(self, T0: float | None = None) -> np.ndarray:
        """The reduced state of the uniform field T0 [K] (None: the spec's T_initial_K)."""
        return self.system.z_one * (self.spec.T_initial_K if T0 is None else float(T0))

    def outputs(self, Z: np.ndarray) -> np.ndarray:
        return Z @ self.system.O.T + self.system.offset

    def steady(self, case: LoadCase | None = None, t: float = 0.0):
        from reference.rom.results import ROMSteadyResult

        case = case or self.spec.default_load_case()
        n = float(case.speed_rpm(t))
        u = self.inputs(case, t)[0]
        z = self.system.steady(u, n)
        y = self.outputs(z[None, :])[0]
        ns = len(self.sensor_names)
        return ROMSteadyResult(self, case, t, n, z, y[:ns],
                               {k: float(y[ns + j]) for j, k in enumerate(self.readings)})

    def transient(self, case: LoadCase, dt_s: float, T0: float | None = None,
                  method: str = "be"):
        """Transient on time_grid(case, dt_s) from the uniform T0 [K] (None: the case's ambient
        at t = 0), growth readings zeroed at the start: ``method`` "be" (the reference's
        backward Euler) or "exact" (exact for inputs linear between grid points)."""
        from reference.rom.results import ROMTransientResult

        if dt_s <= 0 or case.duration_s <= 0:
            raise SolverError("a transient run needs dt_s > 0 and a duration > 0")
        t0 = time.perf_counter()
        z0 = self.initial(start_temperature_K(case, T0))
        grid, Z = self.system.simulate(self.inputs, case, dt_s, z0, method)
        Y = zeroed_readings(self.outputs(Z), len(self.sensor_names))
        ns = len(self.sensor_names)
        res = ROMTransientResult(self, case, grid, list(self.sensor_names), Y[:, :ns],
                                 {k: Y[:, ns + j] for j, k in enumerate(self.readings)}, Z,
                                 method, time.perf_counter() - t0)
        if self.indicator is not None and method == "be":
            res.error_estimate = self.indicator.estimate(self, case, grid, Z)
        return res


def reduced_model(reference, system: ReducedSystem, V: np.ndarray | None, full: FullSystem,
                  info: dict) -> ReducedModel:
    return ReducedModel(reference.spec, info.get("level", -1), reference.thermal.order,
                        full.n, system, list(full.source_names), list(full.source_defaults),
                        list(full.sensor_names), list(full.readings), V, info)
