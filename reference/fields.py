"""FEM fields as pyvista grids: the half-section and its revolution to 3-D.

A P2 field is written on four linear triangles per element (vertices and edge midpoints
carry the exact nodal values), so VTU files stay plain linear cells for any reader.
"""

from __future__ import annotations

import numpy as np

from meshes.io import to_pyvista
from spindle.units import ZERO_C_K

# local P2 DOFs: 0-2 vertices, 3 = edge (0,1), 4 = edge (1,2), 5 = edge (0,2)
_P2_SPLIT = np.array([[0, 3, 5], [1, 4, 3], [2, 5, 4], [3, 4, 5]])


def field_grid(model, T: np.ndarray, name: str = "T_C", offset: float = -ZERO_C_K):
    """The half-section (x = z, y = r [m]) with point data ``name`` = T + offset."""
    basis, sm = model.basis, model.smesh
    if model.order == 1:
        grid = to_pyvista(sm)
        grid.point_data[name] = T[: sm.mesh.nvertices] + offset
        return grid
    ed = basis.element_dofs
    tris = np.vstack([ed[_P2_SPLIT[k]] for k in range(4)])  # 12 x nel
    tris = tris.reshape(4, 3, -1).transpose(1, 2, 0).reshape(3, -1)  # 4 children per element
    grid = to_pyvista(sm, points=basis.doflocs, triangles=tris)
    grid.point_data[name] = T + offset
    return grid


def add_displacement(grid, elastic, U: np.ndarray) -> None:
    """Add point data u_z_um, u_r_um and the 3-D vector 'displacement' [m] to a field grid
    made by :func:`field_grid` (the vector DOFs sit at the same places as the scalar ones)."""
    uz, ur = U[elastic.iz], U[elastic.ir]
    if elastic.thermal.order == 1:
        n = elastic.smesh.mesh.nvertices
        uz, ur = uz[:n], ur[:n]
    grid.point_data["u_z_um"] = uz * 1e6
    grid.point_data["u_r_um"] = ur * 1e6
    grid.point_data["displacement"] = np.column_stack([uz, ur, np.zeros_like(uz)])


def revolved(grid, angle_deg: float = -270.0, resolution: int = 90):
    """Sweep the half-section about the z axis: a cut-away solid showing the section.

    The default sweep leaves out the quarter between +y and +z, where the camera looks in.
    """
    import pyvista as pv

    # the section's boundary swept, and the section itself at both ends: what VTK's capped
    # sweep of the whole section draws, without the copy of every interior point at every
    # angle that it makes (4.2 million points, 0.45 GB to render, for spl2782 level 2)
    surf = grid.extract_surface(algorithm="dataset_surface")
    rim = surf.extract_feature_edges(boundary_edges=True, feature_edges=False,
                                     non_manifold_edges=False, manifold_edges=False)
    sweep = rim.extrude_rotate(resolution=resolution, angle=angle_deg, capping=False,
                               rotation_axis=(1.0, 0.0, 0.0))
    end = surf.rotate_x(angle_deg, point=(0.0, 0.0, 0.0), inplace=False)
    return pv.merge([sweep, surf, end], merge_points=False)
