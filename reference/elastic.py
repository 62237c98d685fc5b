"""The FEM thermoelastic reference: axial growth at the tool centre point (the paper's P1).

Quasi-static linear thermoelasticity on the thermal model's mesh (vector P1/P2 of the same
order), each part with its own E, nu, alpha and the stress-free temperature ``T_initial_K``.

How the bodies hang together (see docs/reference.md):

- Fitted joints (contact links) are bonded mechanically: the split interface DOFs are tied.
- Bearings: the front pair's rolling layer is a solid of the rolling-layer material, so it
  locates the shaft axially (fixed bearing). The rear pair's rolling layer keeps its normal
  stiffness but has a vanishing shear modulus (1e-6 of its own), so the shaft slides axially
  through it (floating bearing).
- The rotor-stator air gap has no stiffness: its elements add nothing to the stiffness, and
  the DOFs only they hold are removed, so it carries no load.
- Supports: u_r = 0 on the axis; the housing is held axially at one point, the reference
  point of the first axial-displacement sensor (P1: the housing fixation below the front
  bearing), or, without one, the lowest-z point on the axis.

Because the elastic operator does not change, one factorisation serves every solve, and each
displacement sensor is a linear functional of the temperature rise: P1 = g . (T - T_ref) +
omega^2 c (g from one adjoint solve), so a whole transient costs one dot product per step.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from skfem import ElementVector

from reference.assembly import assemble, light_basis, return_free_memory
from reference.forms import centrifugal, elasticity, thermal_coupling
from reference.probes import probe_matrix
from reference.thermal import ELEMENTS, ThermalModel, factorize
from spindle.spec import ContactLink
from spindle.units import RPM_TO_RAD_S

#: shear modulus of a floating bearing's rolling layer, relative to its own
FLOATING_SHEAR = 1e-6
ROTATING_ROLES = ("shaft", "tool", "rotor")


class ThermoelasticModel:
    """Displacements [m] from a temperature field of a :class:`ThermalModel`."""

    def __init__(self, thermal: ThermalModel, fixed_axial: list[str] | None = None):
        self.thermal, self.smesh, self.spec = thermal, thermal.smesh, thermal.spec
        sm, order = self.smesh, thermal.order
        elem = ElementVector(ELEMENTS[order]())
        self.basis = light_basis(sm.mesh, elem)  # DOFs and probes (reference/assembly.py)
        self.T_ref = self.spec.T_initial_K
        self.iz, self.ir = self.basis.split_indices()
        lam, mu, mu_s, alpha, rho_rot = self.element_fields()
        io = thermal.intorder
        K = assemble(elasticity, sm.mesh, elem, io, dict(lam=lam, mu=mu, mu_s=mu_s))
        self._coupling = dict(lam=lam, mu=mu, alpha=alpha)
        self._B = None  # the thermal load operator, assembled when first needed
        self.f_cf = assemble(centrifugal, sm.mesh, elem, io, dict(rho_rot=rho_rot))
        self.P = self._reduction(fixed_axial)
        self.K_red = (self.P.T @ K @ self.P).tocsr()
        del K
        return_free_memory()  # the assembly's temporaries, before a factorisation needs room
        self._lu_cache = None  # the factorisation of K_red, made when first needed
        self._gains: dict[str, tuple[np.ndarray, float]] = {}

    @property
    def _lu(self):
        if self._lu_cache is None:
            self._lu_cache = factorize(self.K_red)
        return self._lu_cache

    @property
    def B(self) -> sp.csr_matrix:
        """The thermal load per kelvin of rise [N/K per DOF pair] (n_u x n_T), assembled when
        first needed and kept until :meth:`release`."""
        if self._B is None:
            self._B = assemble(thermal_coupling, self.smesh.mesh, self.thermal.basis.elem,
                               self.thermal.intorder, self._coupling, test_elem=self.basis.elem)
        return self._B

    def release(self) -> None:
        """Drop the factorisation and the load operator B (memory: 0.5 and 0.05 GB on spl2782
        level 3; they are made again when next needed)."""
        self._lu_cache = self._B = None
        return_free_memory()

    # ------------------------------------------------------------------ setup
    def element_fields(self):
        sm, spec = self.smesh, self.spec
        floating = {(lk.part, lk.section) for lk in spec.links
                    if getattr(lk, "section", None) and spec.part(lk.part).role == "rear_bearing"}
        rows = []
        for reg in sm.regions:
            m = reg.material
            lam = m.E_Pa * m.nu / ((1 + m.nu) * (1 - 2 * m.nu))
            mu = m.E_Pa / (2 * (1 + m.nu))
            float_ = reg.kind == "bearing" and (reg.part, reg.section) in floating
            role = spec.part(reg.part).role if reg.kind != "air_gap" else "air"
            inner_ring = role in ("front_bearing", "rear_bearing") and reg.section == "inner_ring"
            rotating = role in ROTATING_ROLES or inner_ring
            if reg.kind == "air_gap":  # a gap carries no load: no stiffness (its own DOFs
                lam = mu = 0.0          # are removed in _reduction)
            rows.append((lam, mu, mu * (FLOATING_SHEAR if float_ else 1.0), m.alpha_1_K,
                         m.rho_kg_m3 if rotating else 0.0))
        arr = np.array(rows)[sm.element_region]
        return tuple(arr[:, k] for k in range(5))

    def _reduction(self, fixed_axial: list[str] | None):
        """Map from free reduced DOFs to all DOFs: ties across contact joints, u_r = 0 on the
        axis, and the axial support."""
        b, sm, n = self.basis, self.smesh, self.basis.N
        pairs = []
        for li, fa, fb in sm.contacts:
            if not isinstance(self.spec.links[li], ContactLink) or not len(fa):
                continue
            da = np.unique(b.get_dofs(facets=fa).flatten())
            db = np.unique(b.get_dofs(facets=fb).flatten())
            for comp in (self.iz, self.ir):
                a, bb = np.intersect1d(da, comp), np.intersect1d(db, comp)
                d, j = cKDTree(b.doflocs[:, a].T).query(b.doflocs[:, bb].T)
                assert d.max(initial=0.0) < 1e-9
                pairs.append(np.vstack([a[j], bb]))
        # every group of DOFs tied together (a chain of joints too) shares one representative,
        # its lowest DOF: connected components of the tie graph
        from scipy.sparse.csgraph import connected_components

        ties = np.hstack(pairs) if pairs else np.zeros((2, 0), dtype=np.int64)
        graph = sp.csr_matrix((np.ones(ties.shape[1]), (ties[0], ties[1])), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        first = np.full(label.max() + 1, n)
        np.minimum.at(first, label, np.arange(n))
        rep = first[label]
        fixed = np.zeros(n, dtype=bool)
        fixed[self.ir[np.abs(b.doflocs[1, self.ir]) < 1e-12]] = True
        fixed[self._air_only_dofs()] = True  # inside an air gap: no stiffness, no meaning
        if fixed_axial:
            for name in fixed_axial:
                fixed[np.intersect1d(b.get_dofs(facets=sm.surfaces[name]).flatten(), self.iz)] = True
        else:
            fixed[rep[self._axial_support_dof()]] = True
        keep = np.unique(rep[~fixed[rep]])
        col = -np.ones(n, dtype=np.int64)
        col[keep] = np.arange(len(keep))
        rows = np.nonzero(col[rep] >= 0)[0]
        return sp.csr_matrix((np.ones(len(rows)), (rows, col[rep[rows]])), shape=(n, len(keep)))

    def _air_only_dofs(self) -> np.ndarray:
        """DOFs that only air-gap elements hold (the layer's interior and mid-edge nodes)."""
        sm, b = self.smesh, self.basis
        air = np.array([reg.kind == "air_gap" for reg in sm.regions])[sm.element_region]
        if not air.any():
            return np.zeros(0, dtype=np.int64)
        in_air = np.unique(b.element_dofs[:, air])
        return np.setdiff1d(in_air, np.unique(b.element_dofs[:, ~air]))

    def _axial_support_dof(self) -> int:
        b = self.basis
        disp = [s for s in self.spec.sensors if s.kind == "axial_displacement"]
        if disp:
            target = np.array([disp[0].z_ref, disp[0].r_ref])
            housing = self.smesh.elements_of(next((p.name for p in self.spec.parts
                                                   if p.role == "housing"),
                                                  self.spec.parts[0].name))
            cand = np.intersect1d(np.unique(b.element_dofs[:, housing]), self.iz)
        else:
            target = np.array([b.doflocs[0, self.iz].min(), 0.0])
            cand = self.iz
        return int(cand[np.argmin(np.linalg.norm(b.doflocs[:, cand].T - target, axis=1))])

    # ------------------------------------------------------------------ solves
    def load(self, T: np.ndarray, speed_rpm: float = 0.0, centrifugal: bool = False) -> np.ndarray:
        f = self.B @ (np.asarray(T) - self.T_ref)
        if centrifugal and speed_rpm:
            f = f + (speed_rpm * RPM_TO_RAD_S) ** 2 * self.f_cf
        return f

    def displacement(self, T: np.ndarray, speed_rpm: float = 0.0,
                     centrifugal: bool = False) -> np.ndarray:
        """Nodal displacements [m] (all DOFs) for the nodal temperatures T [K]."""
        return self.solve(self.load(T, speed_rpm, centrifugal))

    def solve(self, f: np.ndarray) -> np.ndarray:
        """Nodal displacements [m] (all DOFs) under the nodal loads f [N] (all DOFs)."""
        return self.P @ self._lu.solve(self.P.T @ f)

    def axial_probe(self, z: float, r: float) -> sp.csr_matrix:
        """Row that reads u_z [m] at (z, r) from the displacement vector."""
        return probe_matrix(self.basis, np.array([[z], [r]]))[0]

    def growth_points(self) -> dict[str, tuple[float, float, float, float]]:
        """Axial-displacement readings (see :meth:`spindle.spec.Spec.growth_points`)."""
        return self.spec.growth_points()

    def growth(self, U: np.ndarray) -> dict[str, float]:
        """Every reading of :meth:`growth_points` [m] from a displacement vector U."""
        return {k: float(((self.axial_probe(z, r) - self.axial_probe(zr, rr)) @ U)[0])
                for k, (z, r, zr, rr) in self.growth_points().items()}

    def gain(self, sensor: str) -> tuple[np.ndarray, float]:
        """(g, c): the axial-displacement reading ``sensor`` (see :meth:`growth_points`) is
        g . (T - T_ref) + omega^2 c [m]; g comes from one adjoint solve."""
        if sensor not in self._gains:
            z, r, z_ref, r_ref = self.growth_points()[sensor]
            p = self.axial_probe(z, r) - self.axial_probe(z_ref, r_ref)
            w = self.P @ self._lu.solve(self.P.T @ np.asarray(p.todense()).ravel())  # adjoint
            self._gains[sensor] = (self.B.T @ w, float(w @ self.f_cf))
        return self._gains[sensor]

    def read(self, sensor: str, T: np.ndarray, speed_rpm: float = 0.0,
             centrifugal: bool = False) -> np.ndarray:
        """Axial displacement [m] of a sensor for one field T or a stack of fields (rows)."""
        g, c = self.gain(sensor)
        out = (np.asarray(T) - self.T_ref) @ g
        if centrifugal:
            out = out + (np.asarray(speed_rpm) * RPM_TO_RAD_S) ** 2 * c
        return out
