"""Grid convergence of the FEM reference: observed order, Richardson extrapolation and Roache's
grid convergence index (GCI) for every sensor and growth reading.

For three solutions f1 (fine), f2, f3 (coarse) on nested meshes with refinement ratio r
(Roache 1998; Celik et al., J. Fluids Eng. 130 (2008) 078001)::

    e21 = f2 - f1, e32 = f3 - f2,  p = ln|e32 / e21| / ln r
    f_ext = f1 + (f1 - f2) / (r^p - 1)
    GCI21 = Fs |(f1 - f2) / f1| / (r^p - 1),   Fs = 1.25 with three or more grids

Asymptotic range: GCI_coarse ~ r^p GCI_fine. Computed from one triplet with its own observed
p that ratio is f1/f2 by construction, so the check uses four levels: the fine-grid GCI of the
triplet one level coarser against r^p times that of the finest triplet (and p of both
triplets are reported); with three levels it is not available.

Temperatures are taken as rises above ambient [K] (a relative error of an absolute
temperature near 300 K would make every GCI look small), growth readings in µm.
Series whose differences change sign are flagged ``oscillatory`` and get, instead of a GCI,
Fs times half the range of the three values (the oscillatory uncertainty of Stern et al.,
J. Fluids Eng. 123 (2001) 793); those whose differences grow (p < 0) are flagged
``divergent`` and get no bound, which blocks the choice of a ground-truth level; a fine-grid
change below 1e-8 of the value is ``converged`` (bound Fs |e21 / f1|); an observed order
below 0.5 is ``slow`` (no extrapolation; GCI with p = 0.5). Flags are reported, never hidden.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from compare.report import markdown_table
from spindle.loads import LoadCase
from spindle.spec import Spec

SAFETY_FACTOR = 1.25
#: observed orders below this are flagged ``slow`` (e.g. a logarithmic corner singularity):
#: no extrapolation, and the GCI is computed with this floor order instead
P_SLOW = 0.5
#: a fine-grid change below this fraction of the value is converged (solver round-off of the
#: sparse direct solve is ~1e-12; 1e-8 is far below any engineering tolerance)
ROUNDOFF = 1e-8


@dataclass(frozen=True)
class GCI:
    """Richardson analysis of one quantity on three nested grids (fine first)."""

    f1: float
    f2: float
    f3: float
    r: float = 2.0
    Fs: float = SAFETY_FACTOR

    @property
    def e21(self) -> float:
        return self.f2 - self.f1

    @property
    def e32(self) -> float:
        return self.f3 - self.f2

    @property
    def flag(self) -> str:
        """'' (monotone, converging), 'converged', 'oscillatory' or 'divergent'."""
        scale = max(abs(self.f1), 1e-300)
        if abs(self.e21) <= ROUNDOFF * scale:
            return "converged"
        if self.e21 == 0.0 or self.e32 * self.e21 < 0:
            return "oscillatory"
        if abs(self.e21) >= abs(self.e32):
            return "divergent"
        if math.log(abs(self.e32 / self.e21)) / math.log(self.r) < P_SLOW:
            return "slow"
        return ""

    @property
    def p(self) -> float:
        """Observed order (nan when flagged, except ``slow``)."""
        if self.flag not in ("", "slow"):
            return math.nan
        return math.log(abs(self.e32 / self.e21)) / math.log(self.r)

    @property
    def extrapolated(self) -> float:
        if self.flag == "converged":
            return self.f1
        if self.flag:
            return math.nan
        return self.f1 + (self.f1 - self.f2) / (self.r**self.p - 1)

    @property
    def gci_fine(self) -> float:
        """GCI of the fine solution, relative (0.01 = 1 %). A converged quantity (no order to
        observe) gets the first-order bound Fs |e21 / f1|."""
        if self.flag == "converged":
            return self.Fs * abs(self.e21 / self.f1) if self.f1 else 0.0
        if self.flag == "oscillatory":  # half the range of the three values (Stern et al. 2001)
            spread = max(self.f1, self.f2, self.f3) - min(self.f1, self.f2, self.f3)
            return self.Fs * 0.5 * spread / abs(self.f1) if self.f1 else math.nan
        if self.flag == "slow":  # bound with the floor order, never extrapolated
            return self.Fs * abs(self.e21 / self.f1) / (self.r**P_SLOW - 1)
        if self.flag:
            return math.nan
        return self.Fs * abs(self.e21 / self.f1) / (self.r**self.p - 1)


@dataclass
class ConvergenceResult:
    """Values per level of every quantity, and the GCI analysis of every level that has two
    coarser ones."""

    spec: Spec
    case_name: str
    levels: list[int]
    elements: list[int]
    dofs: list[int]
    runtime_s: list[float]
    values: dict[str, list[float]]  # quantity -> value per level (K rise, or µm)
    units: dict[str, str]
    threshold: float = 0.01
    results: list = field(default_factory=list, repr=False)  # the steady results per level

    def gci(self, quantity: str, level: int) -> GCI:
        """The analysis with ``level`` as the fine grid."""
        k = self.levels.index(level)
        if k < 2:
            raise ValueError(f"level {level} needs two coarser levels for a GCI")
        v = self.values[quantity]
        return GCI(v[k], v[k - 1], v[k - 2])

    @property
    def analysed_levels(self) -> list[int]:
        return self.levels[2:]

    def ground_truth_level(self) -> int | None:
        """The coarsest level whose GCI is <= threshold for every quantity (None if none)."""
        for level in self.analysed_levels:
            ok = True
            for q in self.values:
                g = self.gci(q, level)
                if not (g.gci_fine <= self.threshold):  # nan (flagged) fails too
                    ok = False
                    break
            if ok:
                return level
        return None

    def table(self) -> dict[str, list]:
        """One row per quantity: values per level, and the analysis on the finest level."""
        fine = self.levels[-1]
        rows: dict[str, list] = {"quantity": [], "unit": []}
        for lv in self.levels:
            rows[f"level_{lv}"] = []
        for key in ("p", "p_previous", "extrapolated", "GCI_fine_pct", "GCI_previous_pct",
                    "asymptotic_ratio", "flag"):
            rows[key] = []
        for q, vals in self.values.items():
            g = self.gci(q, fine)
            prev = self.gci(q, self.levels[-2]) if len(self.levels) >= 4 else None
            rows["quantity"].append(q)
            rows["unit"].append(self.units[q])
            for lv, v in zip(self.levels, vals, strict=True):
                rows[f"level_{lv}"].append(v)
            rows["p"].append(g.p)
            rows["p_previous"].append(prev.p if prev else math.nan)
            rows["extrapolated"].append(g.extrapolated)
            rows["GCI_fine_pct"].append(100 * g.gci_fine)
            rows["GCI_previous_pct"].append(100 * prev.gci_fine if prev else math.nan)
            ratio = math.nan
            if prev and not g.flag and not prev.flag and g.gci_fine > 0:
                ratio = prev.gci_fine / (g.r**g.p * g.gci_fine)
            rows["asymptotic_ratio"].append(ratio)
            rows["flag"].append(g.flag)
        return rows

    def to_pandas(self):
        import pandas as pd

        return pd.DataFrame(self.table())

    def summary(self) -> dict:
        gt = self.ground_truth_level()
        worst = {}
        for lv in self.analysed_levels:
            g = [self.gci(q, lv).gci_fine for q in self.values]
            worst[str(lv)] = float(np.nanmax(g)) * 100 if not all(map(math.isnan, g)) else None
        flags = {q: self.gci(q, self.levels[-1]).flag for q in self.values}
        flagged = {q: f for q, f in flags.items() if f not in ("", "converged")}
        return {"spec": self.spec.name, "case": self.case_name, "levels": self.levels,
                "elements": self.elements, "dofs": self.dofs, "runtime_s": self.runtime_s,
                "threshold_pct": 100 * self.threshold, "ground_truth_level": gt,
                "worst_GCI_pct_per_level": worst, "flagged": flagged}

    def markdown(self) -> str:
        """The table as Markdown: values per level, and the finest level's analysis."""
        t = self.table()
        lv = [f"level_{x}" for x in self.levels]
        head = ["quantity", "unit", *lv, "p", "p_previous", "extrapolated", "GCI_fine_pct",
                "asymptotic_ratio", "flag"]
        fmts = ["s", "s", *[".5g"] * len(lv), ".3f", ".3f", ".5g", ".3g", ".3f", "s"]
        rows = zip(*(t[c] for c in head), strict=True)
        return markdown_table(head, list(rows), fmts)

    #: the named sensors drawn in colour and labelled; the rest of a group in grey
    NAMED = ("T1", "T2", "T_stator", "T_front_bearing", "T_rear_bearing", "P1", "TCP")

    def plot(self, ax=None):
        """Difference to the Richardson extrapolation against element size, log-log, every
        level drawn: one panel per unit (temperatures in K, growths in µm), the named sensors
        labelled in colour with their observed order, the other sensors of the group in grey,
        and a guide of the elements' theoretical order, named. ``ax``: one axes for
        everything, or as many as there are units (None: a new figure)."""
        from spindle.plots import pyplot, wrapped

        plt = pyplot()
        units = sorted({self.units[q] for q in self.values}, key=lambda u: u != "K")
        if ax is None:
            _, axes = plt.subplots(1, len(units), figsize=(6.2 * len(units), 4.8),
                                   layout="constrained", squeeze=False)
            axes = list(axes[0])
        else:
            axes = list(ax) if isinstance(ax, list | tuple | np.ndarray) else [ax] * len(units)
        h = np.array([2.0 ** -lv for lv in self.levels])
        colours = plt.get_cmap("tab10")
        errors = {q: self._errors(q) for q in self.values}
        for a, unit in zip(axes, units, strict=True):
            named = [q for q in self.values if self.units[q] == unit and q in self.NAMED
                     and errors[q] is not None]
            others = [q for q in self.values if self.units[q] == unit
                      and q not in self.NAMED and errors[q] is not None]
            for q in others:
                a.loglog(h, errors[q], "-", color="0.7", lw=0.7, zorder=1)
            if others:
                a.plot([], [], "-", color="0.7", lw=0.7,
                       label=f"other sensors ({len(others)})")
            for k, q in enumerate(named):
                g = self.gci(q, self.levels[-1])
                a.loglog(h, errors[q], "o-", color=colours(k % 10), lw=1.4, ms=4, zorder=3,
                         label=f"{q} (observed order {g.p:.2f})")
            drawn = [errors[q] for q in (*named, *others)]
            if drawn:
                top = float(np.nanmax([e[0] for e in drawn]))
                a.loglog(h, top * (h / h[0]) ** 3, "k--", lw=1, zorder=2,
                         label="h³: P2's order on smooth fields\n(the parts' corners and "
                               "contact interfaces lower it)")
            a.set_xlabel("relative element size h / h0 (level 0 at 1)")
            a.set_ylabel(f"|value − Richardson extrapolation| [{'µm' if unit == 'um' else unit}]")
            a.set_title(f"{'temperatures' if unit == 'K' else 'axial growth'}")
            a.grid(alpha=0.3, which="both")
            a.invert_xaxis()
            a.legend(fontsize=8, loc="lower left")
        fig = axes[0].figure
        fig.suptitle(wrapped(f"{self.spec.name}: grid convergence ({self.case_name}); the "
                             "finest level's error is its distance to the extrapolated value",
                             fig.get_size_inches()[0], 12))
        return axes if len(axes) > 1 else axes[0]

    def _errors(self, q: str) -> np.ndarray | None:
        """|value − extrapolated| per level, or None where the finest analysis is flagged
        (nothing to extrapolate to) or a value equals it."""
        g = self.gci(q, self.levels[-1])
        if g.flag:
            return None
        err = np.abs(np.array(self.values[q]) - g.extrapolated)
        return err if np.all(err > 0) else None

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        from spindle.outputs import atomic_write, write_csv, write_json

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        t = self.table()
        write_csv(out / "convergence.csv", list(t), zip(*t.values(), strict=True))
        write_json(out / "convergence.json", {**self.summary(), "table": t})
        atomic_write(out / "convergence.md", lambda tmp: tmp.write_text(self.markdown() + "\n",
                                                                           "utf-8"))
        files = ["convergence.csv", "convergence.json", "convergence.md"]
        if pictures:
            from spindle.plots import pyplot

            ax = self.plot()
            fig = (ax[0] if isinstance(ax, list) else ax).figure
            atomic_write(out / "convergence.png", lambda tmp: fig.savefig(tmp, dpi=130))
            pyplot().close(fig)
            files.append("convergence.png")
        return [out / f for f in files]



def quantities(spec: Spec, res, case: LoadCase) -> tuple[dict[str, float], dict[str, str]]:
    """Sensor rises above ambient [K] and growth readings [µm] of a steady result."""
    T_amb = float(case.T_ambient_K(res.time_s))
    vals = {k: v - T_amb for k, v in res.sensors.items()}
    units = dict.fromkeys(vals, "K")
    for k, v in res.growth_m.items():
        vals[k] = v * 1e6
        units[k] = "um"
    return vals, units


def convergence_study(spec: Spec, case: LoadCase | None = None, levels: Sequence[int] = (0, 1, 2, 3),
                      order: int = 2, threshold: float = 0.01,
                      progress: Callable[[str], None] | None = None,
                      keep_results: bool = False) -> ConvergenceResult:
    """Solve the FEM reference (steady) on nested ``levels`` (at least 3) and analyse it."""
    from reference import ReferenceModel

    if len(levels) < 3:
        raise ValueError("a GCI needs three or more levels")
    case = case or spec.default_load_case()
    levels = sorted(levels)
    per_level: dict[int, tuple] = {}
    # finest first: its factorisations are the largest (0.65 GB of the 0.95 GB peak on spl2782
    # level 3), made while no coarser level's operators are held beside them
    for lv in reversed(levels):
        if progress:
            progress(f"FEM level {lv}: meshing and assembling")
        t = time.perf_counter()
        model = ReferenceModel(spec, lv, order)
        if progress:  # level 3 of spl2782: 4 s to here, 7 s to solve
            progress(f"FEM level {lv}: solving {model.thermal.basis.N:,} thermal and "
                     f"{model.elastic.K_red.shape[0]:,} elastic unknowns".replace(",", " "))
        res = model.steady(case, keep_factorisations=False)
        res.check_plausible(spec.path)  # a film of 1e-300 wrote errors of 1e305 K
        vals, units = quantities(spec, res, case)
        per_level[lv] = (time.perf_counter() - t, model.thermal.smesh.counts(order)["elements"],
                         int(model.thermal.basis.N), vals, res if keep_results else None)
        del model, res
    runtime, elements, dofs, vals_per_level, results = (list(x) for x in zip(
        *(per_level[lv] for lv in levels), strict=True))
    values = {k: [v[k] for v in vals_per_level] for k in vals_per_level[0]}
    return ConvergenceResult(spec, case.name, levels, elements, dofs, runtime, values, units,
                             threshold, results if keep_results else [])
