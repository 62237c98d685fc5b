"""The quadrature twin: the reference's discrete problem assembled with ccx's quadrature
(scikit-fem), so that reference - twin is the quadrature difference and twin - ccx the print
precision of ccx's result file (docs/crosscheck.md)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from skfem import Basis, ElementTriP0, ElementTriP2, ElementVector, FacetBasis, asm

from compare.crosscheck.ccx_mesh import CcxMesh
from compare.crosscheck.elastic_data import elastic_materials, reduction, vector_dofs
from compare.crosscheck.thermal_data import ThermalData, load_vector
from reference.elastic import FLOATING_SHEAR
from reference.forms import conduction, elasticity, film, thermal_coupling
from reference.simulation import ReferenceModel
from reference.thermal import factorize
from spindle.errors import SolverError

#: Quadrature of ccx's DCAX6/CAX6 (found by reproducing single-element ccx results with
#: scikit-fem): the 3-point rule of degree 2 over the triangle ...
CCX_VOLUME_INTORDER = 2
#: ... and 2-point Gauss (degree 3) on a face
CCX_FACE_INTORDER = 3
#: ccx's face-to-face gap conductance integrates the matching interface exactly (as the
#: reference does)
CCX_CONTACT_INTORDER = 5


def _pair_matrix(cm: CcxMesh, fa: np.ndarray, fb: np.ndarray, n: int) -> sp.csr_matrix:
    """Jump operator (D U)_i = U_i - U_twin(i) of an interface's side-A nodes."""
    na = np.unique(cm.facet_nodes[:, fa])
    nb = np.unique(cm.facet_nodes[:, fb])
    d, j = cKDTree(cm.rz[nb]).query(cm.rz[na])
    if np.max(d, initial=0.0) > 1e-9:
        raise SolverError("contact interface nodes do not match pairwise (mesh bug)")
    return sp.csr_matrix((np.r_[np.ones(len(na)), -np.ones(len(na))],
                          (np.r_[na, na], np.r_[na, nb[j]])), shape=(n, n))


def twin_thermal(model: ReferenceModel, cm: CcxMesh, data: ThermalData) -> np.ndarray:
    """Nodal temperatures [K] of the reference's discrete problem assembled with ccx's
    quadrature (see :data:`CCX_VOLUME_INTORDER`)."""
    mesh, n = model.thermal.smesh.mesh, len(cm.rz)
    b = Basis(mesh, ElementTriP2(), intorder=CCX_VOLUME_INTORDER)
    p0 = b.with_element(ElementTriP0())
    K = asm(conduction, b, kr=p0.interpolate(data.k_r), kz=p0.interpolate(data.k_z))
    by_h: dict[float, list[int]] = {}
    for f, h, _, _ in data.films:
        by_h.setdefault(h, []).append(f)
    for h, facets in by_h.items():
        fb = FacetBasis(mesh, ElementTriP2(), facets=np.array(facets), intorder=CCX_FACE_INTORDER)
        K = K + asm(film, fb, h=h)
    for lk, fa, fb_ in data.contacts:
        Ma = asm(film, FacetBasis(mesh, ElementTriP2(), facets=fa, intorder=CCX_CONTACT_INTORDER),
                 h=lk.h_W_m2K)
        D = _pair_matrix(cm, fa, fb_, n)
        K = K + D.T @ Ma @ D
    F = load_vector(model, data, CCX_VOLUME_INTORDER, CCX_FACE_INTORDER, data.T_ambient_K)
    return data.T_ambient_K + factorize(K.tocsr()).solve(F)


def reading_rows(model: ReferenceModel) -> dict[str, np.ndarray]:
    """Per growth reading, the dense row p with reading = p . u_z(nodes) [-]."""
    th = model.thermal
    out = {}
    for k, (z, r, zr, rr) in model.spec.growth_points().items():
        row = th.probe_matrix(np.array([[z, zr], [r, rr]]))
        out[k] = np.asarray((row[0] - row[1]).todense()).ravel()
    return out


def twin_gains(model: ReferenceModel, cm: CcxMesh, con: dict) -> dict[str, np.ndarray]:
    """Per reading, g with reading = g . (T - T_initial) [m/K]: the reference's elastic
    problem with ccx's quadrature and the deck's own constraints (adjoint solve)."""
    rows = reading_rows(model)
    if not rows:
        return {}
    mesh = model.thermal.smesh.mesh
    b = Basis(mesh, ElementVector(ElementTriP2()), intorder=CCX_VOLUME_INTORDER)
    mat = np.array(elastic_materials(model), dtype=float)
    E, nu, alpha, floating = mat.T
    mu = E / (2 * (1 + nu))
    p0 = b.with_element(ElementTriP0())
    f = {"lam": p0.interpolate(E * nu / ((1 + nu) * (1 - 2 * nu))), "mu": p0.interpolate(mu),
         "mu_s": p0.interpolate(mu * np.where(floating > 0, FLOATING_SHEAR, 1.0)),
         "alpha": p0.interpolate(alpha)}
    K = asm(elasticity, b, lam=f["lam"], mu=f["mu"], mu_s=f["mu_s"])
    tb = Basis(mesh, ElementTriP2(), quadrature=b.quadrature)
    B = asm(thermal_coupling, tb, b, lam=f["lam"], mu=f["mu"], alpha=f["alpha"])
    dz, dr = vector_dofs(b)
    P = reduction(con, dz, dr, b.N)
    lu = factorize((P.T @ K @ P).tocsr())
    gains = {}
    for k, row in rows.items():
        w = np.zeros(b.N)
        w[dz] = row
        gains[k] = B.T @ (P @ lu.solve(P.T @ w))
    return gains
