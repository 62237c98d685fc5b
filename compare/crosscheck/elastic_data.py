"""What the thermoelastic deck holds besides the mesh: elastic constants per element and the
constraints (bonded joints, axis, axial support), rebuilt from the mesh and the spec and
checked against the reference's own elastic problem."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from compare.crosscheck.ccx_mesh import CcxMesh
from reference.elastic import FLOATING_SHEAR
from reference.simulation import ReferenceModel
from spindle.errors import SolverError
from spindle.spec import BearingLink, ContactLink


def _union(pairs: list[tuple[int, int]], n: int) -> np.ndarray:
    """Representative (smallest member) of each node's group under the tie ``pairs``."""
    parent = np.arange(n)

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in pairs:
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    return np.array([find(i) for i in range(n)])


def elastic_constraints(model: ReferenceModel, cm: CcxMesh) -> dict:
    """Ties, axis and axial support of the reference, rebuilt from the mesh and the spec.

    Contact joints are bonded: every node of a side-B facet is tied to the side-A node at the
    same place (both displacement components). u_r = 0 on the axis; u_z = 0 at the housing
    node nearest the reference point of the first axial-displacement sensor (or, without
    one, at the lowest-z node on the axis). Returns 0-based node indices: ``rep`` (each
    node's tie group representative), boolean masks ``fixed_r`` and ``fixed_z``, the
    ``support`` node and the number of ``ties``.
    """
    sm, spec = model.thermal.smesh, model.spec
    n = len(cm.rz)
    pairs: list[tuple[int, int]] = []
    for li, fa, fb in sm.contacts:
        if not isinstance(spec.links[li], ContactLink) or not len(fa):
            continue
        na = np.unique(cm.facet_nodes[:, fa])
        nb = np.unique(cm.facet_nodes[:, fb])
        d, j = cKDTree(cm.rz[na]).query(cm.rz[nb])
        if np.max(d, initial=0.0) > 1e-9:
            raise SolverError("contact interface nodes do not match pairwise (mesh bug)")
        pairs.extend(zip(na[j].tolist(), nb.tolist(), strict=True))
    rep = _union(pairs, n)
    axis = np.nonzero(np.abs(cm.rz[:, 0]) < 1e-12)[0]
    disp = [s for s in spec.sensors if s.kind == "axial_displacement"]
    if disp:
        target = np.array([disp[0].r_ref, disp[0].z_ref])
        housing = next((p.name for p in spec.parts if p.role == "housing"), spec.parts[0].name)
        cand = np.unique(cm.conn[sm.elements_of(housing)] - 1)
    else:
        cand = np.arange(n)
        target = np.array([0.0, cm.rz[:, 1].min()])
    support = int(cand[np.argmin(np.linalg.norm(cm.rz[cand] - target, axis=1))])
    fixed_r = np.isin(rep, rep[axis])  # a group with a node on the axis
    fixed_z = rep == rep[support]
    air = np.array([r.kind == "air_gap" for r in sm.regions])[sm.element_region]
    if air.any():  # nodes only the air gap holds carry nothing: fixed, as in the reference
        only_air = np.setdiff1d(np.unique(cm.conn[air] - 1), np.unique(cm.conn[~air] - 1))
        fixed_r[only_air] = fixed_z[only_air] = True
    return {"rep": rep, "fixed_r": fixed_r, "fixed_z": fixed_z, "support": support,
            "ties": int(np.sum(rep != np.arange(n)))}


#: the modulus [Pa] ccx gets for the air gap, a stand-in for the reference's zero (1e-14 of
#: steel; its nodes that no solid holds are fixed)
AIR_GAP_E_PA = 1e-3


def elastic_materials(model: ReferenceModel) -> list[tuple]:
    """(E [Pa], nu, alpha [1/K], floating) per element, as the reference's regions. The air
    gap carries no load in the reference (zero stiffness); ccx needs a modulus, so it gets
    AIR_GAP_E_PA, which moves P1 by ~1e-20 m."""
    sm, spec = model.thermal.smesh, model.spec
    floating = {(lk.part, lk.section) for lk in spec.links
                if isinstance(lk, BearingLink) and spec.part(lk.part).role == "rear_bearing"}
    rows = [(AIR_GAP_E_PA, 0.0, 0.0, False) if r.kind == "air_gap" else
            (r.material.E_Pa, r.material.nu, r.material.alpha_1_K,
             r.kind == "bearing" and (r.part, r.section) in floating) for r in sm.regions]
    return [rows[k] for k in sm.element_region.tolist()]


def vector_dofs(basis) -> tuple[np.ndarray, np.ndarray]:
    """(u_z, u_r) DOF of every P2 node in a scikit-fem ElementVector(P2) basis."""
    return (np.r_[basis.nodal_dofs[0], basis.facet_dofs[0]],
            np.r_[basis.nodal_dofs[1], basis.facet_dofs[1]])


def reduction(con: dict, dz: np.ndarray, dr: np.ndarray, n_dofs: int) -> sp.csr_matrix:
    """Map from the free DOFs to all DOFs of the constraints ``con`` (ties, axis, support)."""
    rows, cols = [], []
    ncol = 0
    for dofs, fixed in ((dz, con["fixed_z"]), (dr, con["fixed_r"])):
        free = np.nonzero(~fixed)[0]
        groups, col = np.unique(con["rep"][free], return_inverse=True)
        rows.append(dofs[free])
        cols.append(ncol + col)
        ncol += len(groups)
    return sp.csr_matrix((np.ones(sum(len(r) for r in rows)), (np.concatenate(rows),
                                                               np.concatenate(cols))),
                         shape=(n_dofs, ncol))


def elastic_checks(model: ReferenceModel, con: dict) -> dict:
    """Do the deck's elastic constants and constraints equal the reference's? (relative
    difference of the constants, and whether the constraints fix and tie the same DOFs)"""
    el = model.elastic
    if el is None:
        return {}
    lam, mu, mu_s, alpha, _ = el.element_fields()
    mat = np.array(elastic_materials(model), dtype=float)
    E, nu, a, fl = mat.T
    mine = np.vstack([E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu)),
                      E / (2 * (1 + nu)) * np.where(fl > 0, FLOATING_SHEAR, 1.0), a])
    ref = np.vstack([lam, mu, mu_s, alpha])
    # the air gap is 0 in the reference and AIR_GAP_E_PA in the deck: reported as its ratio to
    # the largest modulus, the other elements' constants relative to themselves
    sm = model.thermal.smesh
    solid = ~np.array([r.kind == "air_gap" for r in sm.regions])[sm.element_region]
    rel = float(np.max(np.abs(mine - ref)[:, solid]
                       / np.maximum(np.abs(ref[:, solid]), 1e-300)))
    air_ratio = 0.0 if solid.all() else float(AIR_GAP_E_PA / np.max(E))
    dz, dr = vector_dofs(el.basis)
    P_mine = reduction(con, dz, dr, el.basis.N)
    same = _same_partition(el.P, P_mine)
    return {"elastic_constants_rel_diff": rel, "constraints_as_reference": same,
            "air_gap_modulus_ratio": air_ratio}


def _same_partition(A: sp.spmatrix, B: sp.spmatrix) -> bool:
    """Do two 0/1 reduction matrices fix the same DOFs and tie the same groups?"""
    def cols(M):
        M = sp.csr_matrix(M)
        c = -np.ones(M.shape[0], dtype=np.int64)
        nz = np.diff(M.indptr) > 0
        c[nz] = M.indices[M.indptr[:-1][nz]]
        return c

    a, b = cols(A), cols(B)
    if not np.array_equal(a < 0, b < 0):
        return False
    pairs = np.unique(np.vstack([a[a >= 0], b[b >= 0]]), axis=1)
    return len(np.unique(pairs[0])) == len(np.unique(pairs[1])) == pairs.shape[1]
