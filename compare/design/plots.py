"""Pictures of the thermal stiffness strategy (paper section 4); computing stays in
:mod:`compare.design.report`.

- :func:`fig15_png`: the paper's Fig. 15, the temperature drop Delta T = T1 (lambda - 1) /
  lambda (eq. 24) against the heat stiffness ratio lambda_tr, with each measure's lambda
  from the formulas and from the reference on it (T1: the reference's mean excess
  temperature before the measures).
- :func:`fig16_png`: Fig. 16-style sensitivities, heat stiffness K_alpha against added area,
  length, film coefficient and heat flow: reference (mean and maximum) and the simplified
  formula 1 / sum(alpha_i A_i).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from compare.design.cases import SWEEP_UNITS
from compare.design.formulas import PAPER_LAMBDA_RANGE, temperature_drop_K
from compare.design.report import MeasuresReport
from spindle.outputs import atomic_write
from spindle.plots import pyplot

_SWEEP_TITLES = {"area": "added surface A_M", "length": "length L,",
                 "film": "film coefficient alpha", "heat": "heat flow Q"}


def _points(rep: MeasuresReport):
    out = []
    for m in rep.measures:
        row = m.to_row()
        if not math.isnan(row["lambda_ref_mean"]):
            out.append((m.measure.name, row["lambda_formula"], row["lambda_ref_mean"]))
    return out


def _draw_fig15(ax, T1: float, lam_max: float, pts, zoom: bool) -> None:
    lam = np.linspace(1.0, lam_max, 400)
    ax.plot(lam, temperature_drop_K(T1, lam), color="k", lw=1.5,
            label=f"eq. 24: T1 (lambda - 1) / lambda, T1 = {T1:.1f} K")
    if not zoom:
        ax.axvspan(*PAPER_LAMBDA_RANGE, color="tab:green", alpha=0.08,
                   label="paper's recommended 1.1 < lambda <= 5..6")
    colors = iter(("tab:blue", "tab:orange", "tab:red", "tab:purple", "tab:brown", "tab:pink",
                   "tab:olive", "tab:cyan", "tab:gray"))
    for name, lf, lr in pts:
        c = next(colors, "tab:gray")
        ax.plot([lf], [temperature_drop_K(T1, lf)], "o", mfc="none", mec=c, ms=8)
        ax.plot([lr], [temperature_drop_K(T1, lr)], "s", color=c, ms=6, label=name)
        ax.annotate("", xy=(lr, temperature_drop_K(T1, lr)),
                    xytext=(lf, temperature_drop_K(T1, lf)),
                    arrowprops={"arrowstyle": "->", "color": c, "lw": 0.8})
    ax.set_xlabel("heat stiffness ratio lambda_tr = K_alpha1 / K_alpha2")
    ax.set_ylabel("drop of the mean excess temperature Delta T [K]")
    ax.grid(alpha=0.3)
    ax.set_xlim(1.0, lam_max)
    ax.set_ylim(bottom=0.0)


def fig15_png(rep: MeasuresReport, path: Path) -> None:
    """Fig. 15 with the measures: open circle = formula's lambda, filled square = the
    reference's; the right panel zooms on the measures' range."""
    plt = pyplot()
    T1 = rep.baseline.mean_rise_K
    pts = _points(rep)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.8), layout="constrained")
    _draw_fig15(a1, T1, 6.0, pts, zoom=False)
    a1.set_title("paper Fig. 15: Delta T against lambda_tr (eq. 24)", fontsize=10)
    a1.legend(fontsize=7, loc="lower right")
    top = max([1.0] + [max(lf, lr) for _, lf, lr in pts])
    _draw_fig15(a2, T1, 1.0 + 1.15 * (top - 1.0) if top > 1.0 else 1.1, pts, zoom=True)
    a2.set_title("zoom on the measures: o formulas (eq. 25-30), ■ FEM reference", fontsize=10)
    fig.suptitle(f"{rep.spec_name}, {rep.case_name}: heat stiffness ratio of the measures",
                 fontsize=11)
    atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=130))
    plt.close(fig)


def fig16_png(rep: MeasuresReport, path: Path) -> None:
    """Heat stiffness against each swept parameter, one panel per sweep."""
    plt = pyplot()
    kinds = [k for k in ("area", "length", "film", "heat") if any(p.sweep == k
                                                                   for p in rep.sweeps)]
    n = max(1, len(kinds))
    cols = 2 if n > 1 else 1
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(6 * cols, 4 * rows), layout="constrained",
                             squeeze=False)
    for ax, kind in zip(axes.flat, kinds, strict=False):
        pts = sorted((p for p in rep.sweeps if p.sweep == kind), key=lambda p: p.x)
        x = np.array([p.x for p in pts])
        ax.plot(x, [p.K_alpha_mean_K_W * 1e3 for p in pts], "o-", color="tab:blue",
                label="FEM, mean rise / Q")
        ax.plot(x, [p.K_alpha_max_K_W * 1e3 for p in pts], "s--", color="tab:red", ms=4,
                label="FEM, max rise / Q")
        ax.plot(x, [p.K_alpha_formula_K_W * 1e3 for p in pts], "-", color="k", lw=1.2,
                label="formula 1 / sum(alpha A)")
        ax.set_xlabel(f"{_SWEEP_TITLES[kind]} {pts[0].where} [{SWEEP_UNITS[kind]}]")
        ax.set_ylabel("heat stiffness K_alpha [mK/W]")
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    for ax in list(axes.flat)[len(kinds):]:
        ax.set_visible(False)
    fig.suptitle(f"{rep.spec_name}, {rep.case_name}: heat stiffness sensitivities "
                 "(paper Fig. 16 style)", fontsize=11)
    atomic_write(Path(path), lambda tmp: fig.savefig(tmp, dpi=130))
    plt.close(fig)
