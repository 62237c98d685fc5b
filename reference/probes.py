"""Reading a field at points of the mesh: interpolation by the element's basis (not the
nearest node), for sensors and growth readings."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: the first step by which a point just outside the mesh is moved into it [m]: 1 nm, the
#: rounding of the mesh's axial cuts (meshes.build rounds them to 9 decimals)
PROBE_NUDGE_M = 1e-9
#: the farthest such a point is moved [m]: 1 um, a thousandth of an element and below any
#: sensor's placement accuracy; a point farther out is an error
PROBE_NUDGE_MAX_M = 1e-6


def probe_matrix(basis, points: np.ndarray) -> sp.csr_matrix:
    """Rows that interpolate a field of ``basis`` at ``points`` (2 x n, z and r in m). A point
    on the boundary that rounding puts a little outside the mesh (a sensor on an end face of a
    stretched spec, a tool tip whose z has more digits than the mesh's cuts) is moved inside
    first, by at most PROBE_NUDGE_MAX_M; a point farther out raises scikit-fem's
    ValueError."""
    pts = np.asarray(points, dtype=float)
    try:
        return basis.probes(pts).tocsr()
    except ValueError:
        return basis.probes(_nudged_inside(basis.mesh, pts)).tocsr()


def _nudged_inside(mesh, pts: np.ndarray) -> np.ndarray:
    """Points outside the mesh moved towards the centroid of the nearest element, by
    PROBE_NUDGE_M and then four times farther each try up to PROBE_NUDGE_MAX_M, until inside
    (the move's component normal to the boundary is what counts, and the direction to a
    centroid can be nearly along the boundary); the others, and those still outside,
    unchanged."""
    finder = mesh.element_finder()
    centroids = mesh.p[:, mesh.t].mean(axis=1)

    def inside(p: np.ndarray) -> bool:
        try:
            finder(p[0:1], p[1:2])
        except ValueError:
            return False
        return True

    out = pts.copy()
    for k in range(pts.shape[1]):
        p = pts[:, k]
        if inside(p):
            continue
        d = centroids - p[:, None]
        j = int(np.argmin((d * d).sum(axis=0)))
        unit = d[:, j] / np.linalg.norm(d[:, j])
        step = PROBE_NUDGE_M
        while step <= PROBE_NUDGE_MAX_M:
            if inside(p + unit * step):
                out[:, k] = p + unit * step
                break
            step *= 4.0
    return out
