"""Reading a field at points of the mesh: interpolation by the element's basis (not the
nearest node), for sensors and growth readings."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: how far a point on the boundary may be moved into the mesh [m] (1 nm: far below any
#: element, far above the rounding of a stretched geometry)
PROBE_NUDGE_M = 1e-9


def probe_matrix(basis, points: np.ndarray) -> sp.csr_matrix:
    """Rows that interpolate a field of ``basis`` at ``points`` (2 x n, z and r in m). A point
    on the boundary that rounding puts a few ulps outside the mesh (a sensor on an end face of
    a stretched spec) is moved inside by at most PROBE_NUDGE_M first; a point farther out
    raises scikit-fem's ValueError."""
    pts = np.asarray(points, dtype=float)
    try:
        return basis.probes(pts).tocsr()
    except ValueError:
        return basis.probes(_nudged_inside(basis.mesh, pts)).tocsr()


def _nudged_inside(mesh, pts: np.ndarray) -> np.ndarray:
    """Points outside the mesh moved towards the centroid of the nearest element by
    PROBE_NUDGE_M; the others unchanged."""
    finder = mesh.element_finder()
    centroids = mesh.p[:, mesh.t].mean(axis=1)
    out = pts.copy()
    for k in range(pts.shape[1]):
        try:
            finder(pts[0:1, k], pts[1:2, k])
            continue
        except ValueError:
            pass
        d = centroids - pts[:, k:k + 1]
        j = int(np.argmin((d * d).sum(axis=0)))
        out[:, k] = pts[:, k] + d[:, j] / np.linalg.norm(d[:, j]) * PROBE_NUDGE_M
    return out
