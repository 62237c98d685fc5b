"""The FEM thermal reference: assembly from a meshed spec, steady and transient solves.

The conductance matrix at speed n is an affine combination of matrices assembled once::

    K(n) = K_solid + sum_links g_l(n) K_l + sum_surfaces h_s(n) R_s + sum_contacts h_c C_c

and the load is ``F(t) = sum_s h_s T_ref,s(t) b_s + sum_j P_j(t) f_j``. A change of speed
or of time therefore never reassembles, and one sparse LU is reused for every time step
of the same length at the same speed.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu
from scipy.spatial import cKDTree
from skfem import Basis, ElementTriP1, ElementTriP2, FacetBasis, asm

from meshes import SpindleMesh
from reference.assembly import assemble, light_basis, return_free_memory
from reference.forms import capacity, conduction, film, surface_flux, volume_source
from reference.probes import probe_matrix
from spindle.errors import SolverError
from spindle.loads import (
    LoadCase,
    check_start_temperature,
    start_temperature_K,
    time_grid,
    time_step_s,
)
from spindle.spec import BearingLink, ContactLink
from spindle.units import ZERO_C_K

TWO_PI = 2.0 * math.pi


#: the largest mesh [unknowns] that ThermalModel.exact_readouts integrates by dense modes
#: (method "modal", the check of the CRAM path: eigh of a 2500 x 2500 pencil takes about
#: 4 s per speed; spl2782 level 0, 3200, 34 s for 5)
EXACT_MAX_DOFS = 2500
#: the projection error asked of the Krylov integration (ThermalModel.exact_readouts):
#: 1e-5 K and 1e-10 m, under 1 % of the spatial uncertainty of a converged level (spl2782's
#: worst GCI, 0.12 %, is about 0.04 K and 0.016 um: docs/verification.md)
KRYLOV_TOL = (1e-5, 1e-10)


def factorize(A: sp.spmatrix):
    """Sparse LU of a symmetric positive definite matrix (conductance, or M/dt + theta K).

    SuperLU in symmetric mode: minimum-degree ordering on A^T + A and no pivoting (SPD
    matrices need none), which halves the fill of the default COLAMD ordering here. A CSR
    matrix is factorised as its transpose, the CSC matrix on the same arrays: equal to A for a
    symmetric A, and no copy of A (95 MB for the elastic operator of spl2782 level 3) sits
    beside the factorisation while it is made.

    A panel of 2 columns (SuperLU's default is 10) is 10-20 % faster on the reference's
    matrices and takes the peak of the level-3 elastic factorisation of spl2782 from 0.60 to
    0.51 GB above the matrix (benchmarks/bench_solvers.py measures the project's setting).
    """
    At = A.T if A.format == "csr" else A.tocsc()
    return splu(At, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, panel_size=2,
                options={"SymmetricMode": True})
ELEMENTS = {1: ElementTriP1, 2: ElementTriP2}


def layer_conductivity_factor(region_shape, kind: str) -> float:
    """Conductivity [W/m/K] of a link layer per unit link value (W/K or W/m2/K).

    Bearing: a radial annulus of length L between r_i and r_o has the conductance
    G = 2 pi k L / ln(r_o / r_i), so k = G ln(r_o / r_i) / (2 pi L).
    Air gap: the film coefficient h acts on the rotor surface 2 pi r_i L, so
    k = h r_i ln(r_o / r_i). Radii are the section's means (exact for cylinders).
    """
    ri = 0.5 * (region_shape.r_inner[0] + region_shape.r_inner[1])
    ro = 0.5 * (region_shape.r_outer[0] + region_shape.r_outer[1])
    if kind == "bearing":
        return math.log(ro / ri) / (TWO_PI * region_shape.length)
    return ri * math.log(ro / ri)


@dataclass
class Operator:
    """The matrices of one mesh and element order, and how to combine them."""

    K_solid: sp.csr_matrix
    M: sp.csr_matrix
    links: list[tuple[object, sp.csr_matrix]]  # (link, unit matrix)
    films: list[tuple[object, sp.csr_matrix, np.ndarray]]  # (surface, R_s, b_s)
    contacts: list[tuple[object, sp.csr_matrix]]  # (link, C_c at h = 1)
    sources: list[tuple[object, np.ndarray]]  # (heat source, load per W)

    def K(self, speed_rpm: float) -> sp.csr_matrix:
        K = self.K_solid.copy()
        for lk, A in self.links:
            value = lk.G_W_K(speed_rpm) if isinstance(lk, BearingLink) else lk.h_W_m2K(speed_rpm)
            K = K + value * A
        for s, R, _ in self.films:
            K = K + s.h_W_m2K(speed_rpm) * R
        for lk, C in self.contacts:
            K = K + lk.h_W_m2K * C
        return K.tocsr()

    def F(self, case: LoadCase, t: float, speed_rpm: float) -> np.ndarray:
        F = np.zeros(self.M.shape[0])
        T_ref = {"ambient": float(case.T_ambient_K(t)), "coolant": float(case.T_coolant_K(t))}
        for s, _, b in self.films:
            F += s.h_W_m2K(speed_rpm) * T_ref[s.T_ref] * b
        for src, f in self.sources:
            F += float(case.sources.get(src.name, src.power_W)(t)) * f
        return F

    def heat_in_W(self, case: LoadCase, t: float) -> float:
        return float(sum(case.sources.get(src.name, src.power_W)(t) for src, _ in self.sources))

    def heat_out_W(self, T: np.ndarray, case: LoadCase, t: float, speed_rpm: float
                   ) -> dict[str, float]:
        """Heat leaving through each convective surface [W]."""
        T_ref = {"ambient": float(case.T_ambient_K(t)), "coolant": float(case.T_coolant_K(t))}
        # 1^T R_s T = int_s T r ds and 1^T b_s = int_s r ds (partition of unity)
        return {s.name: TWO_PI * s.h_W_m2K(speed_rpm) * (float(b @ T) - T_ref[s.T_ref] * b.sum())
                for s, _, b in self.films}

    def inputs_used(self, case: LoadCase, t: float, speed_rpm: float) -> dict:
        """What the solve used at time ``t`` [s] and ``speed_rpm``, for an independent check
        (issue 15): each heat source [W], each film's coefficient [W/m2/K], area [m2] and
        reference temperature [degC], each link's conductance (bearing G [W/K], air-gap and
        contact coefficients [W/m2/K])."""
        T_ref = {"ambient": float(case.T_ambient_K(t)), "coolant": float(case.T_coolant_K(t))}
        links = {}
        for lk, _ in self.links:
            if isinstance(lk, BearingLink):
                links[f"bearing:{lk.part}"] = {"G_W_K": float(lk.G_W_K(speed_rpm))}
            else:
                links[f"air_gap:{lk.inner}-{lk.outer}"] = {"h_W_m2K": float(lk.h_W_m2K(speed_rpm))}
        for lk, _ in self.contacts:
            links[f"contact:{'-'.join(lk.parts)}"] = {"h_W_m2K": float(lk.h_W_m2K)}
        return {
            # "steady": the spec's [operating] point and [[heat_sources]]; otherwise the cycle
            # or case whose power balance gave the sources
            "load_case": case.name,
            "heat_sources_W": {src.name: float(case.sources.get(src.name, src.power_W)(t))
                               for src, _ in self.sources},
            "films": {s.name: {"h_W_m2K": float(s.h_W_m2K(speed_rpm)),
                               "area_m2": TWO_PI * float(b.sum()), "T_ref": s.T_ref,
                               "T_ref_C": T_ref[s.T_ref] - ZERO_C_K}
                      for s, _, b in self.films},
            "links": links}

    def stored_J(self, T: np.ndarray, T0: np.ndarray) -> float:
        """Heat stored since T0 [J]: 2 pi 1^T M (T - T0)."""
        return TWO_PI * float(np.asarray(self.M.sum(axis=0)).ravel() @ (T - T0))



def _regular_steps(h: np.ndarray, speeds: np.ndarray, more_than: int = 4) -> frozenset[float]:
    """The step lengths [s] that occur more than ``more_than`` times before the speed first
    changes (``h`` and ``speeds`` from the current step on): they get their own LUs."""
    end = int(np.argmax(speeds != speeds[0])) if np.any(speeds != speeds[0]) else len(h)
    lengths, counts = np.unique(np.round(h[:end], 9), return_counts=True)
    return frozenset(lengths[counts > more_than].tolist())


class ThermalModel:
    """FEM heat conduction on a :class:`~meshes.SpindleMesh` with P1 or P2 elements."""

    def __init__(self, smesh: SpindleMesh, order: int = 2):
        if order not in ELEMENTS:
            raise ValueError(f"order must be 1 or 2, not {order!r}")
        self.smesh, self.order, self.spec = smesh, order, smesh.spec
        mesh = smesh.mesh
        self.intorder = 2 * order + 1
        self.basis = light_basis(mesh, ELEMENTS[order]())  # DOFs and probes (assembly.py)
        self.op = self._assemble()
        return_free_memory()  # the assembly's temporaries
        self._lu: dict[tuple, object] = {}

    # ------------------------------------------------------------------ assembly
    def element_fields(self):
        regions, er = self.smesh.regions, self.smesh.element_region
        kr = np.array([r.material.k_r_W_mK if r.kind == "solid" else 0.0 for r in regions])[er]
        kz = np.array([r.material.k_z_W_mK if r.kind == "solid" else 0.0 for r in regions])[er]
        rhoc = np.array([r.material.rho_kg_m3 * r.material.c_J_kgK for r in regions])[er]
        return kr, kz, rhoc

    def quadrature_basis(self, elements: np.ndarray | None = None) -> Basis:
        """A basis with this model's element and quadrature (order 2p + 1) on ``elements``
        (default: all), for forms, projections and norms of your own. Built on each call and
        not kept (``basis`` has no quadrature points: reference/assembly.py)."""
        return Basis(self.smesh.mesh, self.basis.elem, elements=elements,
                     intorder=self.intorder)

    def assemble(self, form, cells: dict[str, np.ndarray] | None = None,
                 elements: np.ndarray | None = None):
        """``form`` on this model's element and quadrature (``cells``: per-element constants
        by name), in chunks of elements (:func:`reference.assembly.assemble`)."""
        return assemble(form, self.smesh.mesh, self.basis.elem, self.intorder, cells, elements)

    def _assemble(self) -> Operator:
        sm, spec, basis = self.smesh, self.spec, self.basis
        kr, kz, rhoc = self.element_fields()
        K_solid = self.assemble(conduction, {"kr": kr, "kz": kz})
        M = self.assemble(capacity, {"rhoc": rhoc})
        links = []
        for li, lk in enumerate(spec.links):
            if isinstance(lk, ContactLink):
                continue
            factor = np.zeros(len(sm.regions))
            for ri, reg in enumerate(sm.regions):
                if reg.link == li:
                    factor[ri] = layer_conductivity_factor(reg.shape, reg.kind)
            g = factor[sm.element_region]
            els = np.nonzero(g > 0)[0]
            links.append((lk, self.assemble(conduction, {"kr": g, "kz": g}, els)))
        films = []
        for s in spec.surfaces:
            if s.h_W_m2K is None:
                continue
            fb = FacetBasis(sm.mesh, basis.elem, facets=sm.surfaces[s.name],
                            intorder=self.intorder)
            films.append((s, asm(film, fb, h=1.0).tocsr(), asm(surface_flux, fb, qs=1.0)))
        contacts = [(spec.links[li], self._contact_matrix(fa, fb))
                    for li, fa, fb in sm.contacts if len(fa)]
        sources = []
        for src in spec.heat_sources:
            if src.surface is not None:
                fb = FacetBasis(sm.mesh, basis.elem, facets=sm.surfaces[src.surface],
                                intorder=self.intorder)
                area = TWO_PI * asm(surface_flux, fb, qs=1.0).sum()
                sources.append((src, asm(surface_flux, fb, qs=1.0 / area)))
            else:
                w = self._volume_weights(src.part, src.section)
                sources.append((src, w / (TWO_PI * w.sum())))  # 2 pi w.sum() is the volume
        return Operator(K_solid, M, links, films, contacts, sources)

    def _contact_matrix(self, fa: np.ndarray, fb: np.ndarray) -> sp.csr_matrix:
        """Interface term of int h_c [T][v] r ds at h_c = 1 as D^T M_a D.

        M_a is the facet mass on side A; D maps a vector to its jump across the interface,
        (D U)_i = U_i - U_phi(i), phi pairing each A-side DOF with the B-side DOF at the
        same place (the two sides' Lagrange traces coincide, so this is exact).
        """
        basis, n = self.basis, self.basis.N
        fbasis = FacetBasis(self.smesh.mesh, basis.elem, facets=fa, intorder=self.intorder)
        Ma = asm(film, fbasis, h=1.0).tocsr()
        da = np.unique(basis.get_dofs(facets=fa).flatten())
        db = np.unique(basis.get_dofs(facets=fb).flatten())
        dist, j = cKDTree(basis.doflocs[:, db].T).query(basis.doflocs[:, da].T)
        if np.max(dist, initial=0.0) > 1e-9:
            raise SolverError("contact interface DOFs do not match pairwise (mesh bug)")
        D = sp.csr_matrix((np.r_[np.ones(len(da)), -np.ones(len(da))],
                           (np.r_[da, da], np.r_[da, db[j]])), shape=(n, n))
        return (D.T @ Ma @ D).tocsr()

    # ------------------------------------------------------------------ sensors
    def _volume_weights(self, part: str, section: str | None = None) -> np.ndarray:
        """int phi_i r dA over the part (or one section): sums to its volume / 2 pi [m3]."""
        return self.assemble(volume_source, {"q": np.ones(self.smesh.mesh.nelements)},
                             self.smesh.elements_of(part, section))

    def mean_functional(self, part: str) -> np.ndarray:
        """Vector w with w . T = volume-mean temperature of ``part`` [K]."""
        w = self._volume_weights(part)
        return w / w.sum()

    def probe_matrix(self, points: np.ndarray) -> sp.csr_matrix:
        """Interpolation (not nearest node) of the field at points (2 x n, z and r in m);
        boundary points as :func:`reference.probes.probe_matrix` treats them."""
        return probe_matrix(self.basis, points)

    def sensor_points(self) -> tuple[list[str], np.ndarray]:
        sensors = self.spec.temperature_sensors()
        return [s.name for s in sensors], np.array([[s.z for s in sensors],
                                                    [s.r for s in sensors]])

    # ------------------------------------------------------------------ solves
    def _factor(self, build: Callable[[], sp.spmatrix], key: tuple):
        """LU of ``build()``, cached by ``key`` so equal steps reuse one factorisation."""
        if key not in self._lu:
            if len(self._lu) > 16:
                self._lu.clear()
            try:
                self._lu[key] = factorize(build())
            except RuntimeError as exc:
                raise SolverError(f"{self.spec.path}: the thermal problem is singular ({exc}); "
                                  "fix: give every part a heat path to a fixed temperature "
                                  "([[surfaces]] with h_W_m2K > 0)") from None
        return self._lu[key]

    def release(self) -> None:
        """Drop the cached factorisations (memory; they are made again when next needed)."""
        self._lu.clear()
        return_free_memory()

    def set_coefficients(self, films: list | None = None, contacts: list | None = None,
                         links: list | None = None) -> None:
        """Replace the operator's film, contact or link terms (each a list as
        :class:`Operator` holds it: the same surfaces and links, with other coefficients,
        since the conductance is affine in them) and drop every factorisation made with the
        old ones. A list not given is kept."""
        op = self.op
        op.films = list(op.films if films is None else films)
        op.contacts = list(op.contacts if contacts is None else contacts)
        op.links = list(op.links if links is None else links)
        self._lu.clear()

    def solve_steady(self, case: LoadCase | None = None, t: float = 0.0):
        """Steady state for the inputs of ``case`` at time ``t`` [s]."""
        from reference.results import SteadyResult

        case = case or self.spec.default_load_case()
        n = float(case.speed_rpm(t))
        K, F = self.op.K(n), self.op.F(case, t, n)
        T = self._factor(lambda: K, ("steady", n)).solve(F)
        if not np.all(np.isfinite(T)):
            raise SolverError(f"{self.spec.path}: the steady solution is not finite; "
                              "fix: check film coefficients and conductances for zeros")
        residual = float(np.linalg.norm(K @ T - F) / max(np.linalg.norm(F), 1e-300))
        q_in = self.op.heat_in_W(case, t)
        q_out = self.op.heat_out_W(T, case, t, n)
        return SteadyResult(self, case, t, n, T, q_in, q_out, residual)

    def exact_readouts(self, case: LoadCase, dt_s: float, T0: float | None = None,
                       functionals: dict[str, np.ndarray] | None = None,
                       method: str = "krylov", tol: tuple[float, float] = KRYLOV_TOL,
                       progress: Callable[[int, int], None] | None = None
                       ) -> tuple[np.ndarray, list[str], np.ndarray, dict[str, np.ndarray],
                                  dict[str, float]]:
        """Sensor temperatures [K] and functionals g . T on time_grid(case, dt_s), integrated
        exactly in time for inputs linear between grid points (issue 15 §1): speed held at
        its mid-step value (as solve_transient), sources, ambient and coolant linear from
        just after one grid point to just before the next, so steps land exactly.

        ``method`` "krylov" (the default, any mesh): per speed segment, the Galerkin system
        on a rational Krylov space integrated exactly by its modes, the space grown until
        the estimate of the projection error is below ``tol`` ([K] for the sensors, [m] for
        the functionals; reference.krylov); "cram" (any mesh, the test oracle): each step's
        exponential by CRAM-16 on sparse LUs (reference.exact), about 20 times slower;
        "modal" (at most EXACT_MAX_DOFS unknowns, an independent check): per speed, the
        dense generalised eigenproblem K v = lambda M v gives the modes and each step is
        the exponential of the modal rates.
        Returns (times [s], sensor names, sensors [n_t, n_sensors], functional series, and
        per read-out its error: the projection error's estimate for "krylov", CRAM's bound
        for "cram", 0 for "modal"; rounding aside). ``progress(k, n)`` is called after each
        of the n speed segments ("krylov")."""
        if method not in ("krylov", "cram", "modal"):
            raise ValueError(f"method must be 'krylov', 'cram' or 'modal', not {method!r}")
        grid = time_grid(case, dt_s)
        names, pts = self.sensor_points()
        fnames = list(functionals or {})
        readout = np.vstack([self.probe_matrix(pts).toarray()]
                            + ([np.array([functionals[k] for k in fnames])] if fnames else []))
        x0 = np.full(self.op.M.shape[0], start_temperature_K(case, T0))
        if method == "modal":
            Y, bound = self._modal_readouts(case, grid, readout, x0), np.zeros(len(readout))
        elif method == "krylov":
            tols = np.array([tol[0]] * len(names) + [tol[1]] * len(fnames))
            Y, bound = self._krylov_readouts(case, grid, readout, x0, tols, progress)
            # the estimate holds for a kind of read-out as a whole, not for each one (one
            # sensor's difference of two spaces can be smaller than its error while the
            # largest over the sensors is not: tests/test_time_convergence.py)
            for part in (slice(0, len(names)), slice(len(names), None)):
                if bound[part].size:
                    bound[part] = bound[part].max()
        else:
            Y, bound = self._cram_readouts(case, grid, readout, x0)
        n_s = len(names)
        return (grid, names, Y[:, :n_s], {k: Y[:, n_s + j] for j, k in enumerate(fnames)},
                dict(zip(names + fnames, bound.tolist(), strict=True)))

    def _linear_load(self, case: LoadCase, t0: float, t1: float, n: float
                     ) -> tuple[np.ndarray, np.ndarray]:
        """(a, b): the load a + b (t - t0) over the step, from just after t0 to just before
        t1 (a jump on a grid point belongs to the next step)."""
        eps = 1e-9 * (t1 - t0)
        a = self.op.F(case, t0 + eps, n)
        return a, (self.op.F(case, t1 - eps, n) - a) / (t1 - t0)

    def _krylov_readouts(self, case: LoadCase, grid: np.ndarray, readout: np.ndarray,
                         x: np.ndarray, tol: np.ndarray,
                         progress: Callable[[int, int], None] | None = None
                         ) -> tuple[np.ndarray, np.ndarray]:
        """Read-outs on ``grid`` by rational Krylov projection per speed segment
        (reference.krylov), and each read-out's largest error estimate."""
        from reference.krylov import segment_readouts

        op = self.op
        Y = np.empty((len(grid), readout.shape[0]))
        Y[0] = readout @ x
        h = np.diff(grid)
        speeds = np.asarray(case.speed_rpm(0.5 * (grid[1:] + grid[:-1])), dtype=float)
        starts = [*np.flatnonzero(np.r_[True, speeds[1:] != speeds[:-1]]), len(speeds)]
        estimate = np.zeros(readout.shape[0])
        for i, (s0, s1) in enumerate(zip(starts[:-1], starts[1:], strict=True), start=1):
            n = float(speeds[s0])
            loads = [self._linear_load(case, grid[k], grid[k + 1], n) for k in range(s0, s1)]
            Ys, est, x, _ = segment_readouts(op.K(n), op.M, x, loads, h[s0:s1], readout,
                                             factorize, tol)
            Y[s0 + 1:s1 + 1] = Ys
            # the segments' errors add up at worst (the heat equation forgets, never grows
            # an error: an upper estimate)
            estimate += est
            if progress is not None:
                progress(i, len(starts) - 1)
        return Y, estimate

    def _cram_readouts(self, case: LoadCase, grid: np.ndarray, readout: np.ndarray,
                       x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Read-outs on ``grid`` by exact sparse steps (reference.exact.ExactStepper), one
        speed's LUs at a time, and each read-out's bound on CRAM's error."""
        from reference.exact import ExactStepper, readout_norms

        op = self.op
        Y = np.empty((len(grid), readout.shape[0]))
        Y[0] = readout @ x
        h = np.diff(grid)
        speeds = np.asarray(case.speed_rpm(0.5 * (grid[1:] + grid[:-1])), dtype=float)
        stepper, total = None, 0.0
        for k in range(1, len(grid)):
            n = float(speeds[k - 1])
            if stepper is None or n != speeds[k - 2]:  # a new speed: drop the last LUs
                total += stepper.bound if stepper else 0.0
                stepper = None
                K = op.K(n)
                stepper = ExactStepper(K, op.M, factorize(K),
                                       regular=_regular_steps(h[k - 1:], speeds[k - 1:]))
            a, b = self._linear_load(case, grid[k - 1], grid[k], n)
            x = stepper.step(x, a, b, h[k - 1])
            Y[k] = readout @ x
        total += stepper.bound if stepper else 0.0
        return Y, total * readout_norms(op.M, readout, factorize)

    def _modal_readouts(self, case: LoadCase, grid: np.ndarray, readout: np.ndarray,
                        x: np.ndarray) -> np.ndarray:
        """Read-outs on ``grid`` by dense modes (small meshes only)."""
        from scipy.linalg import eigh

        from reference.krylov import modal_step

        op, N = self.op, self.op.M.shape[0]
        if N > EXACT_MAX_DOFS:
            raise SolverError(f"modal time integration is for meshes of at most "
                              f"{EXACT_MAX_DOFS} unknowns, not {N}")
        M = op.M.toarray()
        Y = np.empty((len(grid), readout.shape[0]))
        Y[0] = readout @ x
        modes: dict[float, tuple] = {}
        current, z = None, None
        for k in range(1, len(grid)):
            t0, t1 = grid[k - 1], grid[k]
            dt = t1 - t0
            n = float(case.speed_rpm(t0 + 0.5 * dt))
            if n not in modes:
                lam, V = eigh(op.K(n).toarray(), M)
                modes[n] = (np.maximum(lam, 0.0), V, readout @ V, V.T @ M)
            lam, V, OV, VtM = modes[n]
            if n != current:  # into this speed's modes
                z = VtM @ (x if current is None else modes[current][1] @ z)
                current = n
            a, b = (V.T @ f for f in self._linear_load(case, t0, t1, n))
            z = modal_step(z, lam, dt, a, b)
            Y[k] = OV @ z
        return Y

    def solve_transient(self, case: LoadCase, dt_s: float, theta: float = 1.0,
                        T0: np.ndarray | float | None = None, save_every: int = 0,
                        progress: Callable[[float], None] | None = None,
                        functionals: dict[str, np.ndarray] | None = None):
        """Theta-method time integration over ``case.duration_s`` [s].

        theta = 1 is backward Euler (first order), theta = 0.5 Crank-Nicolson (second order).
        Steps of ``dt_s`` land on every sample time of the inputs. ``T0`` is the initial
        field (K), a uniform temperature, or None for the case's ambient at t = 0.
        Fields are kept every ``save_every`` steps (0: first and last only).
        ``functionals`` maps names to vectors g whose values g . T are recorded every step
        (the thermoelastic sensors are such functionals).
        """
        from reference.results import TransientResult

        if not 0.0 <= theta <= 1.0:
            raise ValueError("theta must be within [0, 1]")
        if time_step_s(dt_s) <= 0 or case.duration_s <= 0:
            raise SolverError("a transient run needs dt_s > 0 and a duration > 0")
        grid = time_grid(case, dt_s)
        op = self.op
        N = op.M.shape[0]
        if T0 is None or np.isscalar(T0):
            T = np.full(N, start_temperature_K(case, T0))
        else:
            check_start_temperature(T0)
            T = np.asarray(T0, dtype=float).copy()
        T_start = T.copy()
        names, pts = self.sensor_points()
        P = self.probe_matrix(pts)
        sensors = np.empty((len(grid), len(names)))
        sensors[0] = P @ T
        functionals = functionals or {}
        G = np.array(list(functionals.values())) if functionals else np.zeros((0, N))
        fvals = np.empty((len(grid), len(functionals)))
        fvals[0] = G @ T
        fields_t, fields = [0.0], [T.copy()]
        n0 = float(case.speed_rpm(0.0))
        K0, F0 = op.K(n0), op.F(case, 0.0, n0)
        q_in0 = op.heat_in_W(case, 0.0)
        q_out0 = sum(op.heat_out_W(T, case, 0.0, n0).values())
        E_in = E_out = 0.0
        heat_in, heat_out = np.empty(len(grid)), np.empty(len(grid))
        heat_in[0], heat_out[0] = q_in0, q_out0
        K_cache: dict[float, sp.csr_matrix] = {n0: K0}
        for k in range(1, len(grid)):
            t0, t1 = grid[k - 1], grid[k]
            dt = t1 - t0
            # speed is held over a step at its value at the step's start (zero-order hold)
            n1 = float(case.speed_rpm(t0 + 0.5 * dt))
            if n1 not in K_cache:
                K_cache[n1] = op.K(n1)
            K1 = K_cache[n1]
            # the inputs held over the step (a 'previous' series, a bench's interval means)
            # are read as the step's own values: at t1 from the left, at t0 from the right.
            # Read at t1 itself, a held input switching there would already act over this
            # step, a lead of one step (60 s on a bench grid: 4 K at the stator at a speed
            # step, docs/fit-history.md); a continuous input is the same either way
            t1_in, t0_in = t1 - 1e-9 * dt, t0 + 1e-9 * dt
            F1 = op.F(case, t1_in, n1)
            if theta < 1.0:
                F0, q_in0 = op.F(case, t0_in, n0), op.heat_in_W(case, t0_in)
            lu = self._factor(lambda dt=dt, K1=K1: op.M / dt + theta * K1,
                              ("step", round(dt, 9), n1, theta))
            rhs = op.M @ T / dt + theta * F1 + (1 - theta) * (F0 - K0 @ T)
            T_new = lu.solve(rhs)
            q_in1 = op.heat_in_W(case, t1_in)
            q_out1 = sum(op.heat_out_W(T_new, case, t1_in, n1).values())
            # heat flows of the same theta-weighting as the scheme: the balance is exact
            E_in += dt * (theta * q_in1 + (1 - theta) * q_in0)
            # the explicit part acts with the previous step's operator, hence q_out0
            E_out += dt * (theta * q_out1 + (1 - theta) * q_out0)
            # F0 and q_in0 of the next step are read at its start when theta < 1
            T, K0, q_in0, q_out0, n0 = T_new, K1, q_in1, q_out1, n1
            sensors[k] = P @ T
            fvals[k] = G @ T
            heat_in[k], heat_out[k] = q_in1, q_out1
            if (save_every and k % save_every == 0) or k == len(grid) - 1:
                fields_t.append(float(t1))
                fields.append(T.copy())
            if progress is not None:
                progress(t1 / case.duration_s)
        E_stored = op.stored_J(T, T_start)
        return TransientResult(self, case, theta, grid, names, sensors, np.array(fields_t),
                               np.array(fields), heat_in, heat_out, E_in, E_out, E_stored,
                               {k: fvals[:, j] for j, k in enumerate(functionals)})
