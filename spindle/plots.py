"""Pictures both models draw the same way: sensor profiles along z, sensor histories, and
T1/P1 over a cycle with the paper's tolerance band (computing stays elsewhere)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from spindle.outputs import atomic_write
from spindle.tolerances import GROWTH_TOLERANCE_M


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend (runs headless)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def wrapped(text: str, width_in: float, fontsize: float) -> str:
    """``text`` broken into lines that fit ``width_in`` inches at ``fontsize`` points (an
    average glyph is about 0.55 of the font size wide), so that a title is never cut off by
    its canvas."""
    import textwrap

    chars = max(int(width_in * 72 / (0.55 * fontsize)), 20)
    return "\n".join(textwrap.fill(line, chars) for line in text.split("\n"))


def levels_text(levels) -> str:
    """FEM levels as words, not a Python list: "1, 2 and 3" ("1 and 2", "2")."""
    items = [str(v) for v in levels]
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def sensor_profile_png(table, path: Path, title: str = "") -> None:
    """Array sensors (shaft, housing) along z, from a sensor DataFrame-like table."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4), layout="constrained")
    for arr in sorted({a for a in table["array"] if a}):
        rows = [i for i, a in enumerate(table["array"]) if a == arr]
        ax.plot([table["z_m"][i] * 1e3 for i in rows], [table["T_C"][i] for i in rows],
                "o-", label=f"{arr} sensors")
    ax.set_xlabel("z [mm]")
    ax.set_ylabel("temperature [°C]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend()
    atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=130))
    plt.close(fig)


def timeseries_png(times_s: np.ndarray, names: list[str], values_C: np.ndarray, path: Path,
                   title: str = "", arrays: dict[str, str] | None = None) -> None:
    """Sensors over time [h]: point sensors bold, each array as a shaded family of lines
    (``arrays`` maps sensor name to its array name)."""
    from matplotlib import colormaps

    plt = pyplot()
    arrays = arrays or {}
    fig, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
    families: dict[str, list[int]] = {}
    for j, n in enumerate(names):
        if n in arrays:
            families.setdefault(arrays[n], []).append(j)
        else:
            ax.plot(times_s / 3600, values_C[:, j], lw=1.8, label=n)
    for (fam, cols), cmap in zip(families.items(), ("Greys", "Blues", "Greens", "Oranges"),
                                 strict=False):
        shades = colormaps[cmap](np.linspace(0.35, 0.9, len(cols)))
        for k, (j, color) in enumerate(zip(cols, shades, strict=True)):
            ax.plot(times_s / 3600, values_C[:, j], color=color, lw=0.8,
                    label=f"{fam} sensors ({names[cols[0]]} light .. {names[cols[-1]]} dark)"
                    if k == len(cols) - 1 else None)
    ax.set_xlabel("time [h]")
    ax.set_ylabel("temperature [°C]")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=130))
    plt.close(fig)


def growth_band_png(times_s: np.ndarray, T1_C: np.ndarray, P1_um: np.ndarray, path: Path,
                    title: str = "", band_um: float = GROWTH_TOLERANCE_M * 1e6,
                    measured: tuple[np.ndarray, np.ndarray] | None = None) -> None:
    """T1 and P1 over the cycle, P1 with the paper's ±1.5 µm tolerance band around the
    prediction (paper Fig. 11-13); ``measured`` = (times_s, P1_um) adds a test run."""
    plt = pyplot()
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(9, 6), sharex=True, layout="constrained")
    h = times_s / 3600
    a1.plot(h, T1_C, color="tab:red", label="T1 prediction (front bearing outer ring)")
    a1.set_ylabel("T1 [°C]")
    a1.grid(alpha=0.3)
    a1.legend(fontsize=8)
    a1.set_title(title)
    a2.fill_between(h, P1_um - band_um, P1_um + band_um, color="tab:blue", alpha=0.2,
                    label=f"±{band_um:g} µm tolerance")
    a2.plot(h, P1_um, color="tab:blue", ls="--", label="P1 prediction")
    if measured is not None:
        a2.plot(measured[0] / 3600, measured[1], color="black", lw=1, label="P1 test")
    a2.set_xlabel("time [h]")
    a2.set_ylabel("P1 axial growth [µm]")
    a2.grid(alpha=0.3)
    a2.legend(fontsize=8)
    atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=130))
    plt.close(fig)
