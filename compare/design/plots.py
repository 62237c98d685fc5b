"""Pictures of the thermal stiffness strategy (paper section 4); computing stays in
:mod:`compare.design.report`.

- :func:`fig15_png`: the paper's Fig. 15, the temperature drop Delta T = T1 (lambda - 1) /
  lambda (eq. 24) against the heat stiffness ratio lambda_tr (log axes of lambda_tr - 1 and
  Delta T), with each measure's lambda from the formulas and from the reference on it
  (T1: the reference's mean excess temperature before the measures); beside it one row per
  measure with both temperature drops written out.
- :func:`fig16_png`: Fig. 16-style sensitivities, heat stiffness K_alpha against added area,
  length, film coefficient and heat flow: reference (mean and maximum) and the simplified
  formula 1 / sum(alpha_i A_i).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from compare.design.cases import SWEEP_UNITS
from compare.design.formulas import PAPER_LAMBDA_RANGE, temperature_drop_K
from spindle.outputs import atomic_write
from spindle.plots import pyplot

if TYPE_CHECKING:  # the report calls these plots: only its type is needed here
    from compare.design.report import MeasuresReport

_SWEEP_TITLES = {"area": "added surface A_M", "length": "length L,",
                 "film": "film coefficient alpha", "heat": "heat flow Q"}


def _points(rep: MeasuresReport):
    out = []
    for m in rep.measures:
        row = m.to_row()
        if not math.isnan(row["lambda_ref_mean"]):
            out.append((m.measure.name, row["lambda_formula"], row["lambda_ref_mean"]))
    return out


#: the left panel's x axis, lambda_tr - 1, on a log scale: a measure below the lower end
#: (no gain, or a loss: lambda <= 1) is drawn at it and says so in the legend
_LAMBDA_EXCESS_RANGE = (1e-3, 10.0)
_COLORS = ("tab:blue", "tab:orange", "tab:red", "tab:purple", "tab:brown", "tab:pink",
           "tab:olive", "tab:cyan", "tab:gray")


def _excess(lam: float) -> float:
    """lambda_tr - 1 for the log axis, held at the axis's lower end."""
    return max(lam - 1.0, _LAMBDA_EXCESS_RANGE[0])


def _draw_fig15_curve(ax, T1: float, pts) -> None:
    """Eq. 24 against lambda_tr - 1 on a log axis: the measures' lambdas, from 1.002 to 1.7
    on spl2782, spread over three decades instead of crowding at lambda = 1."""
    lo, hi = _LAMBDA_EXCESS_RANGE
    x = np.geomspace(lo, hi, 400)
    ax.plot(x, temperature_drop_K(T1, 1.0 + x), color="k", lw=1.5,
            label=f"eq. 24: T1 (lambda - 1) / lambda, T1 = {T1:.1f} K")
    ax.axvspan(PAPER_LAMBDA_RANGE[0] - 1.0, PAPER_LAMBDA_RANGE[1] - 1.0, color="tab:green",
               alpha=0.08, label="paper's recommended 1.1 < lambda <= 5..6")
    for (name, lf, lr), c in zip(pts, _COLORS * len(pts), strict=False):
        below = " (lambda <= 1 + 1e-3 drawn at the axis)" if min(lf, lr) - 1.0 < lo else ""
        ax.plot([_excess(lf)], [temperature_drop_K(T1, max(lf, 1.0 + lo))], "o", mfc="none",
                mec=c, ms=8)
        ax.plot([_excess(lr)], [temperature_drop_K(T1, max(lr, 1.0 + lo))], "s", color=c,
                ms=6, label=name + below)
        ax.annotate("", xy=(_excess(lr), temperature_drop_K(T1, max(lr, 1.0 + lo))),
                    xytext=(_excess(lf), temperature_drop_K(T1, max(lf, 1.0 + lo))),
                    arrowprops={"arrowstyle": "->", "color": c, "lw": 0.8})
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlim(lo, hi)
    ax.set_ylim(temperature_drop_K(T1, 1.0 + lo) / 1.5, T1 * 1.5)
    ax.set_xlabel("heat stiffness ratio minus one, lambda_tr - 1 = K_alpha1 / K_alpha2 - 1")
    ax.set_ylabel("drop of the mean excess temperature Delta T [K]")
    ax.grid(alpha=0.3)


def _draw_fig15_rows(ax, T1: float, pts) -> None:
    """One row per measure: the temperature drop by the formulas (o) and by the FEM
    reference (■), with both values in the row's label."""
    names = []
    for row, ((name, lf, lr), c) in enumerate(zip(pts, _COLORS * len(pts), strict=False)):
        df, dr = temperature_drop_K(T1, lf), temperature_drop_K(T1, lr)
        ax.plot([df], [row], "o", mfc="none", mec=c, ms=8)
        ax.plot([dr], [row], "s", color=c, ms=6)
        ax.annotate("", xy=(dr, row), xytext=(df, row),
                    arrowprops={"arrowstyle": "->", "color": c, "lw": 0.8})
        names.append(f"{name}\no {df:.2f} K, ■ {dr:.2f} K (lambda {lf:.3f}, {lr:.3f})")
    ax.set_yticks(range(len(names)), names, fontsize=8)
    ax.set_ylim(len(names) - 0.5, -0.5)
    if pts and min(temperature_drop_K(T1, v) for _, lf, lr in pts for v in (lf, lr)) > 0:
        ax.set_xscale("log")
    ax.set_xlabel("drop of the mean excess temperature Delta T [K] (eq. 24)")
    ax.grid(alpha=0.3, axis="x")


def fig15_png(rep: MeasuresReport, path: Path) -> None:
    """Fig. 15 with the measures: open circle = formula's lambda, filled square = the
    reference's. Left: eq. 24 on log axes, so that lambdas a little above 1 stay apart;
    right: one row per measure with its temperature drops written out."""
    plt = pyplot()
    T1 = rep.baseline.mean_rise_K
    pts = _points(rep)
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5.2), layout="constrained",
                                 width_ratios=(1.1, 1.0))
    _draw_fig15_curve(a1, T1, pts)
    a1.set_title("paper Fig. 15: Delta T against lambda_tr (eq. 24), log axes; o formulas, "
                 "■ FEM", fontsize=10)
    a1.legend(fontsize=7, loc="upper left")
    _draw_fig15_rows(a2, T1, pts)
    a2.set_title("each measure: o formulas (eq. 25-30) -> ■ FEM reference", fontsize=10)
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
