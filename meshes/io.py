"""Mesh output: VTU for ParaView and pyvista, PNG pictures of the half-section.

Pictures are rendered off-screen (no display needed). The half-section is drawn with z
(axial, m) to the right and r (radius, m) upwards.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshes.build import SpindleMesh
from spindle.outputs import atomic_write


def quiet_vtk() -> None:
    """Silence VTK's console warnings (e.g. 'bad X server connection' when off-screen)."""
    try:
        from vtkmodules.vtkCommonCore import vtkLogger, vtkObject
    except ImportError:  # pragma: no cover - pyvista always brings vtk
        return
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    vtkObject.GlobalWarningDisplayOff()


def to_pyvista(sm: SpindleMesh, points: np.ndarray | None = None,
               triangles: np.ndarray | None = None):
    """An UnstructuredGrid of the half-section (x = z, y = r, in m) with part ids per cell.

    ``points``/``triangles`` replace the mesh's own (used for P2 fields split into four
    linear triangles per element; ``triangles`` then has 4 cells per element in order).
    """
    import pyvista as pv

    p = sm.mesh.p if points is None else points
    t = sm.mesh.t if triangles is None else triangles
    per_el = t.shape[1] // sm.mesh.nelements
    cells = np.hstack([np.full((t.shape[1], 1), 3), t.T]).ravel()
    pts = np.column_stack([p[0], p[1], np.zeros(p.shape[1])])
    grid = pv.UnstructuredGrid(cells, np.full(t.shape[1], pv.CellType.TRIANGLE), pts)
    grid.cell_data["part_id"] = np.repeat(sm.element_part, per_el)
    grid.cell_data["region_id"] = np.repeat(sm.element_region, per_el)
    grid.field_data["part_names"] = np.array(sm.part_names)
    return grid


def save_mesh_vtu(sm: SpindleMesh, path: Path) -> None:
    atomic_write(Path(path), lambda tmp: to_pyvista(sm).save(str(tmp)))


def fit_xy(pl, bounds, window: tuple[int, int], margin: float = 1.08) -> None:
    """Parallel projection looking at the (z, r) plane, zoomed to fill the window."""
    zc, rc = 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3])
    pl.view_xy()
    pl.enable_parallel_projection()
    pl.camera.focal_point = (zc, rc, 0.0)
    pl.camera.position = (zc, rc, 1.0)
    aspect = window[0] / window[1]
    pl.camera.parallel_scale = 0.5 * margin * max(bounds[3] - bounds[2],
                                                 (bounds[1] - bounds[0]) / aspect)


def mesh_png(sm: SpindleMesh, path: Path, window: tuple[int, int] = (1800, 520)) -> None:
    """Off-screen picture of the meshed half-section, coloured by part, with a legend."""
    import pyvista as pv

    quiet_vtk()
    grid = to_pyvista(sm)
    from matplotlib import colormaps

    colors = [colormaps["tab10"](i)[:3] for i in range(10)]
    pl = pv.Plotter(off_screen=True, window_size=list(window))
    pl.set_background("white")
    legend = []
    for i, name in enumerate(sm.part_names):
        sub = grid.extract_cells(np.nonzero(grid.cell_data["part_id"] == i)[0])
        color = colors[i % len(colors)]
        pl.add_mesh(sub, color=color, show_edges=sm.mesh.nelements < 30000, edge_color="black",
                    line_width=0.4)
        legend.append((name, color))
    pl.add_legend(legend, bcolor="white", face="rectangle", size=(0.18, 0.32), loc="upper right")
    c = sm.counts(2)
    pl.add_text(f"{sm.spec.name}  level {sm.level}: {c['elements']} elements, "
                f"{c['nodes']} nodes  (z to the right, r up)", font_size=10, color="black",
                position="lower_left")
    fit_xy(pl, grid.bounds, window)
    atomic_write(Path(path), lambda tmp: pl.screenshot(str(tmp)))
    pl.close()
