"""How many lumped nodes a spec needs: :func:`choose_nodes` runs the lumped model for every
node count N on every load case and compares it with the FEM reference exactly as the
accuracy table does (:meth:`compare.verify.accuracy.AccuracyResult.errors`): the worst
temperature error is the largest ``*_max_K`` entry (shaft and housing arrays, T1, T2; over the
sensors, and over time for a transient), the growth error is ``P1_max_um``. The chosen N is
the smallest whose worst temperature error is <= ``tol_temp_K`` AND whose P1 error is <=
``tol_growth_um`` on every case; None when no N does. The reference is the FEM P2 solution on
one level (default 2), not the Richardson extrapolation of ``study``.

SI inside (K, m, s); µm and °C appear only in output column names."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from compare.verify.accuracy import (
    NODES,
    TOL_GROWTH_UM,
    TOL_TEMP_K,
    AccuracyResult,
    fem_entry,
    lumped_entries,
    rom_entry,
)
from compare.verify.cases import check_level, check_positive, default_cases, save_result
from spindle.errors import InputError
from spindle.loads import LoadCase
from spindle.plots import levels_text
from spindle.spec import Spec


# ============================================================================ node count
@dataclass
class CaseCurve:
    """Errors of the lumped model against the FEM reference on one case, per node count."""

    name: str
    transient: bool
    reference_label: str
    nodes: list[int]
    masses: list[int]  # lumped states (masses) per N
    worst_temp_K: list[float]  # largest *_max_K of the accuracy row [K]
    p1_um: list[float]  # P1_max_um of the accuracy row [µm] (nan: the spec has no P1)
    rows: list[dict[str, float]]  # the full accuracy rows (AccuracyResult.errors)
    reference_runtime_s: float = 0.0

    @property
    def kind(self) -> str:
        return "transient" if self.transient else "steady"


def _meets(worst_K: float, p1_um: float, tol_temp_K: float, tol_growth_um: float) -> bool:
    return (not math.isnan(worst_K) and worst_K <= tol_temp_K
            and (math.isnan(p1_um) or p1_um <= tol_growth_um))


@dataclass
class NodeChoice:
    """The lumped node count a spec needs: error curves per case and the chosen N."""

    spec_name: str
    nodes: list[int]
    curves: list[CaseCurve]
    tol_temp_K: float
    tol_growth_um: float
    chosen: int | None
    reference_level: int
    dt_s: float
    runtime_s: float = 0.0
    #: the reduced-order model of the reference considered too (choose_nodes(rom=True)):
    #: its states, per case its worst temperature and P1 errors, and whether it meets both
    rom: dict | None = None

    def meets(self, n: int, tol_temp_K: float | None = None,
              tol_growth_um: float | None = None) -> bool:
        """Whether N = ``n`` meets both tolerances on every case."""
        tT = self.tol_temp_K if tol_temp_K is None else tol_temp_K
        tP = self.tol_growth_um if tol_growth_um is None else tol_growth_um
        i = self.nodes.index(n)
        return all(_meets(c.worst_temp_K[i], c.p1_um[i], tT, tP) for c in self.curves)

    def choose(self, tol_temp_K: float | None = None,
               tol_growth_um: float | None = None) -> int | None:
        """The smallest N meeting the tolerances [K, µm] on every case (default: this
        result's own); None if none does. Recomputes nothing."""
        return next((n for n in self.nodes if self.meets(n, tol_temp_K, tol_growth_um)), None)

    def worst(self, n: int) -> tuple[float, float]:
        """(worst temperature error [K], worst P1 error [µm]) of N = ``n`` over the cases
        (the P1 error is nan when the spec has no P1)."""
        i = self.nodes.index(n)
        temps = [c.worst_temp_K[i] for c in self.curves]
        p1 = [c.p1_um[i] for c in self.curves if not math.isnan(c.p1_um[i])]
        return max(temps), (max(p1) if p1 else math.nan)

    def best(self) -> int:
        """The N with the smallest error relative to the tolerances: the minimum over N of
        max(worst temperature error / tol_temp_K, P1 error / tol_growth_um) over the cases."""
        def score(n: int) -> float:
            t, p = self.worst(n)
            return max(t / self.tol_temp_K, 0.0 if math.isnan(p) else p / self.tol_growth_um)

        return min(self.nodes, key=score)

    def message(self) -> str:
        """One sentence: the chosen N, or why there is none and the best available."""
        def errs(n: int) -> str:
            t, p = self.worst(n)
            return f"{t:.3g} K" + ("" if math.isnan(p) else f" / {p:.3g} µm")

        has_p1 = any(not math.isnan(v) for c in self.curves for v in c.p1_um)
        tol = (f"{self.tol_temp_K:g} K and {self.tol_growth_um:g} µm" if has_p1
               else f"{self.tol_temp_K:g} K (the spec has no P1)")
        cases = ", ".join(c.name for c in self.curves)
        tried = levels_text(self.nodes).replace(" and ", " or ")
        if self.chosen is not None:
            return (f"Recommended: N = {self.chosen}, the smallest node count of {tried} that "
                    f"meets {tol} on every case ({cases}); its worst errors: "
                    f"{errs(self.chosen)}" + self._rom_message())
        b = self.best()
        per_case = []
        for c in self.curves:
            ok = [n for i, n in enumerate(self.nodes)
                  if _meets(c.worst_temp_K[i], c.p1_um[i], self.tol_temp_K, self.tol_growth_um)]
            per_case.append(f"on {c.name} alone N = {ok[0]} does" if ok
                            else f"on {c.name} none does")
        return (f"No N of {tried} meets {'both tolerances' if has_p1 else 'the tolerance'} "
                f"({tol}) on every case ({cases}): {'; '.join(per_case)}. Recommended if a "
                f"lumped model must serve: N = {b}, the smallest worst error relative to the "
                f"tolerances ({errs(b)}), knowing it misses them" + self._rom_message())

    def _rom_message(self) -> str:
        if not self.rom:
            return ""
        r = self.rom
        t = max(c["worst_err_K"] for c in r["cases"])
        p = [c["err_P1_um"] for c in r["cases"] if not math.isnan(c["err_P1_um"])]
        errs = f"{t:.3g} K" + (f" / {max(p):.3g} µm" if p else "")
        return (f". The reduced-order model of FEM level {r['level']} with {r['states']} states "
                f"{'meets' if r['meets'] else 'does NOT meet'} them on every case ({errs})")

    def table(self) -> dict[str, list]:
        """Long table: one row per case and N, with the whole accuracy row."""
        rows = []
        for c in self.curves:
            for i, n in enumerate(c.nodes):
                rows.append({"case": c.name, "kind": c.kind, "nodes": n, "masses": c.masses[i],
                             "worst_err_K": c.worst_temp_K[i], "err_P1_um": c.p1_um[i],
                             "meets_tolerances": _meets(c.worst_temp_K[i], c.p1_um[i],
                                                        self.tol_temp_K, self.tol_growth_um),
                             **c.rows[i]})
        keys = list(dict.fromkeys(k for r in rows for k in r))
        return {k: [r.get(k, math.nan) for r in rows] for k in keys}

    def to_pandas(self):
        """:meth:`table` as a DataFrame (needs pandas)."""
        import pandas as pd

        return pd.DataFrame(self.table())

    def text(self) -> str:
        """The error curves as a fixed-width table: N, masses, per case the worst temperature
        error [K] and the P1 error [µm], and whether N meets both tolerances everywhere."""
        labels = [f"{c.name} ({c.kind})" for c in self.curves]
        w = [max(len(lb), 23) - 10 for lb in labels]
        head = f"  {'N':>3} {'masses':>6}" + "".join(
            f" | {lb:<{wi + 10}}" for lb, wi in zip(labels, w, strict=True)) + " |"
        lines = [head, f"  {'':>3} {'':>6}" + "".join(
            f" | {'worst T err K':>{wi}} {'P1 err um':>9}" for wi in w) + " | verdict"]
        for i, n in enumerate(self.nodes):
            row = f"  {n:3d} {self.curves[0].masses[i]:6d}"
            for c, wi in zip(self.curves, w, strict=True):
                p1 = "—" if math.isnan(c.p1_um[i]) else f"{c.p1_um[i]:.3f}"
                row += f" | {c.worst_temp_K[i]:{wi}.3f} {p1:>9}"
            mark = "PASS" if self.meets(n) else "FAIL"
            lines.append(row + f" | {mark}" + ("  <- chosen" if n == self.chosen else ""))
        return "\n".join(lines)

    def summary(self) -> dict:
        def clean(v):
            return None if isinstance(v, float) and math.isnan(v) else v

        b = self.best()
        bt, bp = self.worst(b)
        return {"spec": self.spec_name, "reference_level": self.reference_level,
                "dt_s": self.dt_s, "nodes": self.nodes,
                "tolerances": {"temperature_K": self.tol_temp_K,
                               "growth_um": self.tol_growth_um},
                "chosen_nodes": self.chosen,
                "best": {"nodes": b, "worst_err_K": bt, "err_P1_um": clean(bp)},
                "message": self.message(), "runtime_s": self.runtime_s, "rom": self.rom,
                "cases": [{"case": c.name, "kind": c.kind, "reference": c.reference_label,
                           "reference_runtime_s": c.reference_runtime_s,
                           "worst_err_K": c.worst_temp_K,
                           "err_P1_um": [clean(v) for v in c.p1_um]} for c in self.curves]}

    def plot(self):
        """Error against N per case, log-log: worst temperature error [K] and, when the spec
        has P1, the P1 error [µm]; tolerance lines dashed, the chosen N marked. Returns the
        figure."""
        from matplotlib.ticker import NullLocator

        from spindle.plots import pyplot

        plt = pyplot()
        has_p1 = any(not math.isnan(v) for c in self.curves for v in c.p1_um)
        fig, axes = plt.subplots(1, 2 if has_p1 else 1, figsize=(11 if has_p1 else 6.5, 4.5),
                                 layout="constrained", squeeze=False)
        panels = [(axes[0, 0], "worst_temp_K", self.tol_temp_K, "worst temperature error [K]",
                   "K")]
        if has_p1:
            panels.append((axes[0, 1], "p1_um", self.tol_growth_um, "P1 error [µm]", "µm"))
        for ax, attr, tol, ylabel, unit in panels:
            for c, marker in zip(self.curves, "osD^v<>", strict=False):
                y = np.asarray(getattr(c, attr), dtype=float)
                ok = np.isfinite(y) & (y > 0)
                ax.loglog(np.asarray(c.nodes)[ok], y[ok], marker + "-",
                          label=f"{c.name} ({c.kind})")
            ax.axhline(tol, color="tab:red", ls="--", lw=1, label=f"tolerance {tol:g} {unit}")
            if self.chosen is not None:
                ax.axvline(self.chosen, color="tab:green", ls=":", lw=1.5,
                           label=f"chosen N = {self.chosen}")
            ax.set_xticks(self.nodes, [str(n) for n in self.nodes])
            ax.xaxis.set_minor_locator(NullLocator())
            ax.set_xlabel("lumped nodes N along shaft and housing")
            ax.set_ylabel(ylabel)
            ax.grid(alpha=0.3, which="both")
            ax.legend(fontsize=8)
        verdict = (f"chosen N = {self.chosen}" if self.chosen is not None
                   else f"no N meets {self.tol_temp_K:g} K / {self.tol_growth_um:g} µm on "
                        f"every case (best N = {self.best()})")
        fig.suptitle(f"{self.spec_name}: lumped model against FEM level {self.reference_level}; "
                     f"{verdict}", fontsize=10)
        return fig

    def save(self, out: Path, pictures: bool = True, stem: str = "nodes") -> list[Path]:
        """``<stem>.csv`` (the long table), ``<stem>.json`` (summary), ``<stem>.png``; each
        written atomically."""
        return save_result(self, Path(out), stem, pictures)


def choose_nodes(spec: Spec, cases: Sequence[LoadCase] | None = None,
                 tol_temp_K: float = TOL_TEMP_K, tol_growth_um: float = TOL_GROWTH_UM,
                 nodes: Sequence[int] = NODES, reference_level: int | None = None,
                 dt_s: float = 60.0, progress: Callable[[str], None] | None = None,
                 rom: bool = False) -> NodeChoice:
    """The smallest lumped node count N that meets both tolerances on every case.

    ``cases``: load cases; one with ``duration_s > 0`` runs as a transient (backward Euler
    FEM and exact zero-order-hold lumped runs on the same grid, step ``dt_s`` [s], from the
    ambient temperature at t = 0), otherwise as a steady state. Default: the steady and the
    transient case of :func:`compare.verify.study.study_cases`. ``tol_temp_K`` [K] bounds the worst
    sensor temperature error, ``tol_growth_um`` [µm] the P1 error (ignored for a spec
    without P1). ``reference_level``: the FEM P2 mesh level of the reference (default 2).
    ``progress`` receives one message per model run. ``rom``: also build the reduced-order
    model of the reference level that meets the tolerances (rom.build_rom, trained on
    random-loaded:0) and check it on every case against the same reference (NodeChoice.rom).
    """
    from spindle.loads import time_grid

    level = 2 if reference_level is None else int(reference_level)
    check_level(level, "--level")
    check_positive(tol_temp_K, "--tol-temp", "K")
    check_positive(tol_growth_um, "--tol-growth", "µm")
    check_positive(dt_s, "--dt", "s")
    nodes = sorted({int(n) for n in nodes})
    if not nodes or nodes[0] < 2:
        raise InputError("command line", "--nodes", f"{nodes} is empty or has a value < 2",
                         "give node counts >= 2, e.g. --nodes 2 3 5 7 11")
    cases = default_cases(spec) if cases is None else list(cases)
    if not cases:
        raise InputError("command line", "--cases", "no load case given",
                         "give at least one cycle name, e.g. --cases nominal spl-16h")
    t0 = time.perf_counter()
    curves = []
    rom_model = _rom_for(spec, level, tol_temp_K, tol_growth_um, progress) if rom else None
    rom_cases = []
    for case in cases:
        transient = case.duration_s > 0
        dt = dt_s if transient else None
        T0 = float(case.T_ambient_K(0.0)) if transient else None
        if progress:
            progress(f"FEM level {level} {'transient' if transient else 'steady'} "
                     f"({case.name}{f', dt {dt_s:g} s' if transient else ''})")
        ref = fem_entry(spec, level, case, dt, T0)
        label = f"FEM P2 level {level}" + (f", backward Euler dt {dt_s:g} s" if transient else "")
        entries = lumped_entries(spec, case, nodes, dt, T0, progress)
        acc = AccuracyResult(spec, case.name, transient, ref, label, entries,
                             times_s=time_grid(case, dt_s) if transient else None,
                             tol_temp_K=tol_temp_K, tol_growth_um=tol_growth_um)
        rows = [acc.errors(e) for e in entries]
        worst = []
        for row in rows:
            temps = [v for k, v in row.items() if k.endswith("_max_K") and not math.isnan(v)]
            worst.append(max(temps) if temps else math.nan)
        if rom_model is not None:
            row = acc.errors(rom_entry(rom_model, case, dt, T0))
            rom_cases.append({"case": case.name, "worst_err_K": max(
                v for k, v in row.items() if k.endswith("_max_K") and not math.isnan(v)),
                "err_P1_um": row.get("P1_max_um", math.nan)})
        curves.append(CaseCurve(case.name, transient, label, nodes, [e.size for e in entries],
                                worst, [row.get("P1_max_um", math.nan) for row in rows], rows,
                                ref.runtime_s))
    result = NodeChoice(spec.name, nodes, curves, tol_temp_K, tol_growth_um, None, level, dt_s,
                        time.perf_counter() - t0)
    result.chosen = result.choose()
    if rom_model is not None:
        result.rom = {"states": rom_model.n_states, "level": level, "cases": rom_cases,
                      "meets": all(_meets(c["worst_err_K"], c["err_P1_um"], tol_temp_K,
                                          tol_growth_um) for c in rom_cases)}
    return result


def _rom_for(spec: Spec, level: int, tol_temp_K: float, tol_growth_um: float,
             progress: Callable[[str], None] | None):
    """The ROM of FEM ``level`` sized for the tolerances (rom.build_rom)."""
    from compare.verify.romstudy import named_case
    from reference import ReferenceModel
    from reference.rom import build_rom

    if progress:
        progress(f"reduced-order model of FEM level {level} for {tol_temp_K:g} K / "
                 f"{tol_growth_um:g} µm (trained on random-loaded:0)")
    ref = ReferenceModel(spec, level)
    model, _ = build_rom(ref, named_case(spec, "random-loaded", 0), 60.0, tol_temp_K,
                         tol_growth_um, level=level, keep_basis=False, indicator=False)
    ref.release()
    return model
