"""Pictures of FEM results (computing stays in reference.thermal; this module only draws)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from meshes.io import quiet_vtk
from reference.fields import field_grid, revolved
from spindle.outputs import atomic_write
from spindle.plots import pyplot


def _pyplot():
    return pyplot()


def plot_section(model, T: np.ndarray, ax=None, title: str = "", sensors: bool = True):
    """Temperature [degC] on the half-section, with the sensor points; returns the axes."""
    import matplotlib.tri as mtri

    plt = _pyplot()
    if ax is None:
        _, ax = plt.subplots(figsize=(12, 4.2), layout="constrained")
    grid = field_grid(model, T)
    tri = grid.cells.reshape(-1, 4)[:, 1:]
    pts = grid.points
    tc = ax.tripcolor(mtri.Triangulation(pts[:, 0] * 1e3, pts[:, 1] * 1e3, tri),
                      grid.point_data["T_C"], shading="gouraud", cmap="inferno")
    ax.figure.colorbar(tc, ax=ax, label="temperature [°C]", shrink=0.9)
    if sensors:
        for s in model.spec.temperature_sensors():
            marker = "." if s.array else "o"
            ax.plot(s.z * 1e3, s.r * 1e3, marker, color="cyan", ms=4 if s.array else 6,
                    mec="black", mew=0.5)
            if not s.array:
                ax.annotate(s.name, (s.z * 1e3, s.r * 1e3), xytext=(3, 3),
                            textcoords="offset points", fontsize=7, color="cyan")
    ax.set_aspect("equal")
    ax.set_xlabel("z [mm] (rear → tool)")
    ax.set_ylabel("r [mm]")
    ax.set_title(title)
    return ax


def section_png(model, T: np.ndarray, path: Path, title: str = "") -> None:
    plt = _pyplot()
    ax = plot_section(model, T, title=title)
    atomic_write(Path(path), lambda tmp: ax.figure.savefig(tmp, dpi=130))
    plt.close(ax.figure)


def revolved_png(model, T: np.ndarray, path: Path, title: str = "",
                 window: tuple[int, int] = (1400, 800)) -> None:
    """The field revolved to 3-D as a 270 degree cut-away (off-screen pyvista)."""
    pl = revolved_plotter(model, T, title, window)
    atomic_write(Path(path), lambda tmp: pl.screenshot(str(tmp)))
    pl.close()


def revolved_plotter(model, T: np.ndarray, title: str = "",
                     window: tuple[int, int] = (1400, 800)):
    """The off-screen pyvista plotter of :func:`revolved_png`, camera set, not yet drawn."""
    import pyvista as pv

    quiet_vtk()
    solid = revolved(field_grid(model, T))
    pl = pv.Plotter(off_screen=True, window_size=list(window))
    pl.set_background("white")
    pl.add_mesh(solid, scalars="T_C", cmap="inferno", smooth_shading=False,
                scalar_bar_args={"title": "T [°C]", "color": "black", "vertical": True,
                                 "fmt": "%.0f"})  # whole degrees, not VTK's "122."
    pl.add_text(title, font_size=10, color="black")
    b = solid.bounds
    focal = (0.5 * (b[0] + b[1]), 0.0, 0.0)
    size = b[1] - b[0]
    pl.camera_position = [(focal[0] - 0.35 * size, 0.9 * size, 0.7 * size), focal, (0, 0, 1)]
    pl.reset_camera()
    pl.camera.zoom(1.4)
    return pl


def deformed_png(grid, path: Path, title: str = "", growth_m: dict | None = None) -> None:
    """Half-section deformed by the displacement, exaggerated so that the largest
    displacement shows as 3 % of the spindle length; colour: axial displacement [µm].
    ``grid`` is a field grid with displacement (reference.fields.add_displacement)."""
    plt = _pyplot()
    fig = deformed_figure(grid, title, growth_m)
    atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=130))
    plt.close(fig)


def deformed_figure(grid, title: str = "", growth_m: dict | None = None):
    """The matplotlib figure of :func:`deformed_png`."""
    import matplotlib.tri as mtri

    plt = _pyplot()
    tri = grid.cells.reshape(-1, 4)[:, 1:]
    pts, d = grid.points[:, :2], grid.point_data["displacement"][:, :2]
    length = np.ptp(pts[:, 0])
    scale = 0.03 * length / max(np.abs(d).max(), 1e-30)
    fig, ax = plt.subplots(figsize=(12, 4.2), layout="constrained")
    ax.triplot(mtri.Triangulation(pts[:, 0] * 1e3, pts[:, 1] * 1e3, tri), color="0.85", lw=0.2)
    moved = pts + scale * d
    from matplotlib.colors import Normalize

    uz = np.asarray(grid.point_data["u_z_um"])
    # a diverging map centred on zero, one scale both ways (a micrometre is the same colour
    # step forwards and backwards): white is "does not move", red and blue the two ways
    span = max(float(np.abs(uz).max()), 1e-12)
    norm = Normalize(vmin=-span, vmax=span)
    tc = ax.tripcolor(mtri.Triangulation(moved[:, 0] * 1e3, moved[:, 1] * 1e3, tri),
                      uz, shading="gouraud", cmap="coolwarm", norm=norm)
    fig.colorbar(tc, ax=ax, label="axial displacement u_z [µm]", shrink=0.9)
    text = ", ".join(f"{k} = {v * 1e6:.2f} µm" for k, v in (growth_m or {}).items())
    ax.set_title(f"{title}\ndeformed x{scale:.0f} (grey: undeformed); {text}", fontsize=10)
    ax.set_aspect("equal")
    ax.set_xlabel("z [mm]")
    ax.set_ylabel("r [mm]")
    return fig
