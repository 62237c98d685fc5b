"""The reference's P2 mesh in CalculiX numbering, node for node and element for element.

ccx's axisymmetric elements live in the x-y plane with x = radius and y = axial coordinate, so
our (z, r) become (r, z); its 6-node triangle lists the corners counterclockwise, then the
mid-side nodes of edges 1-2, 2-3, 3-1, and face k of a triangle is its edge k (corner k to
corner k+1). docs/crosscheck.md has the details."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from reference.simulation import ReferenceModel
from spindle.errors import InputError, SolverError


@dataclass
class CcxMesh:
    """The reference's P2 mesh in ccx numbering: node id = scikit-fem DOF index + 1."""

    rz: np.ndarray  # (N, 2) node coordinates r, z [m]
    conn: np.ndarray  # (ne, 6) ccx connectivity, 1-based, counterclockwise in (r, z)
    face_of: dict[int, tuple[int, int]]  # boundary facet -> (element id, ccx face 1..3)
    facet_nodes: np.ndarray  # (3, nfacets) 0-based DOFs of each facet: ends and middle


def ccx_mesh(model: ReferenceModel) -> CcxMesh:
    """The P2 mesh of ``model`` renumbered for ccx (raises InputError for P1)."""
    th = model.thermal
    if th.order != 2:
        raise InputError("crosscheck", "order", f"the CalculiX deck needs P2 elements, not "
                         f"P{th.order}", "build the ReferenceModel with order=2")
    mesh, basis = th.smesh.mesh, th.basis
    dofs = basis.element_dofs  # (6, ne): vertices t0, t1, t2, then edges (t0t1, t1t2, t0t2)
    loc = basis.doflocs
    for k, (a, b) in enumerate(((0, 1), (1, 2), (0, 2))):
        mid = 0.5 * (loc[:, dofs[a]] + loc[:, dofs[b]])
        if np.max(np.abs(loc[:, dofs[3 + k]] - mid)) > 1e-12:
            raise SolverError("unexpected scikit-fem P2 DOF layout (edge midpoints)")
    xy = loc[::-1]  # ccx's (x, y) = our (r, z): swapping the axes flips the orientation
    a = xy[:, dofs[1]] - xy[:, dofs[0]]
    b = xy[:, dofs[2]] - xy[:, dofs[0]]
    ccw = a[0] * b[1] - a[1] * b[0] > 0
    # ccx order: corners counterclockwise, then mid-sides of 1-2, 2-3, 3-1
    conn = np.where(ccw, dofs[[0, 1, 2, 3, 4, 5]], dofs[[0, 2, 1, 5, 4, 3]]).T + 1
    # ccx face k joins corner k and corner k+1 (1-based, cyclic)
    face_of: dict[int, tuple[int, int]] = {}
    nv = mesh.nvertices
    facet_nodes = np.vstack([mesh.facets, nv + np.arange(mesh.nfacets)])
    bf = mesh.boundary_facets()
    elem = mesh.f2t[0, bf]
    for f, e in zip(bf.tolist(), elem.tolist(), strict=True):
        ends = {int(mesh.facets[0, f]) + 1, int(mesh.facets[1, f]) + 1}
        c = conn[e]
        for k in range(3):
            if {int(c[k]), int(c[(k + 1) % 3])} == ends:
                face_of[f] = (e + 1, k + 1)
                break
        else:  # pragma: no cover - a facet always belongs to its element
            raise SolverError(f"boundary facet {f} is not an edge of element {e}")
    return CcxMesh(xy.T.copy(), conn, face_of, facet_nodes)
