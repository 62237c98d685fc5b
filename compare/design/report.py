"""The measures run and its report: :func:`run_measures` runs every case of a measures file
(on :func:`compare.executor.run_cases`) and :class:`MeasuresReport` writes the tables, JSON and
the Fig. 15 / Fig. 16 pictures (:mod:`compare.design.plots`)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from compare.design.cases import (
    InverseCase,
    InverseResult,
    MeasureCase,
    MeasureResult,
    SweepCase,
    SweepPoint,
    case_speed_rpm,
    measure_result,
    reference_model,
    run_case,
)
from compare.design.measure_file import MeasureFile, default_sweeps
from compare.design.stiffness import (
    Indicators,
    paper_consistency,
    surface_films,
)
from compare.report import fmt, markdown_table
from spindle.loads import LoadCase
from spindle.spec import Spec


@dataclass
class MeasuresReport:
    """Everything ``spindle-verify measures`` computes (SI; µm and % only in names)."""

    spec_name: str
    case_name: str
    level: int
    measures_file: str
    speed_rpm: float
    films: list
    baseline: Indicators
    lumped: dict[str, Indicators]
    measures: list[MeasureResult]
    inverse: list[InverseResult]
    sweeps: list[SweepPoint]
    failures: list[dict[str, str]]
    runtime_s: float = 0.0

    @property
    def sum_alpha_A_W_K(self) -> float:
        return float(sum(f.G_W_K for f in self.films))

    def indicator_rows(self) -> list[dict[str, Any]]:
        rows = [self.baseline.to_row()] + [v.to_row() for v in self.lumped.values()]
        G = self.sum_alpha_A_W_K
        rows.append({"model": "simplified formulas (1 / sum alpha A)",
                     "losses_W": self.baseline.losses_W,
                     "mean_rise_K": self.baseline.losses_W / G,
                     "K_alpha_mean_K_W": 1.0 / G})
        rows.append({"model": "paper (section 4)", "K_alpha_mean_K_W": 0.00019,
                     "K_T_K_um": 0.52, "K_Q_W_um": 64.53})
        return rows

    def to_rows(self) -> dict[str, list[dict[str, Any]]]:
        """Every table as a list of rows (dicts with units in the keys)."""
        return {"indicators": self.indicator_rows(),
                "surfaces": [{"surface": f.name, "T_ref": f.T_ref, "h_W_m2K": f.h_W_m2K,
                              "A_m2": f.A_m2, "G_W_K": f.G_W_K} for f in self.films],
                "measures": [m.to_row() for m in self.measures],
                "inverse": [i.to_row() for i in self.inverse],
                "sweeps": [p.to_row() for p in self.sweeps]}

    def to_pandas(self) -> dict[str, Any]:
        """The tables as DataFrames (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return {k: pd.DataFrame(v) for k, v in self.to_rows().items()}

    def summary(self) -> dict[str, Any]:
        return {"spec": self.spec_name, "case": self.case_name, "fem_level": self.level,
                "measures_file": self.measures_file, "speed_rpm": self.speed_rpm,
                "sum_alpha_A_W_K": self.sum_alpha_A_W_K,
                "sum_alpha_A_runs_over": "every surface with a film coefficient, coolant "
                                         "jacket included, at the case's speed",
                "paper_consistency": paper_consistency(),
                **self.to_rows(), "failures": self.failures, "runtime_s": self.runtime_s}

    def markdown(self) -> str:
        return _markdown(self)

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """measures.csv, indicators.csv, inverse.csv, sweeps.csv, measures.md, measures.json
        and (``pictures``) the Fig. 15 and Fig. 16 PNGs, each written atomically."""
        from spindle.outputs import atomic_write, expect_pictures, write_csv, write_json

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        rows = self.to_rows()
        files = []
        for name in ("indicators", "measures", "inverse", "sweeps"):
            if rows[name]:
                header = list(dict.fromkeys(k for r in rows[name] for k in r))
                write_csv(out / f"{name}.csv", header,
                          ([_csv(r.get(k)) for k in header] for r in rows[name]))
                files.append(f"{name}.csv")
        write_json(out / "measures.json", self.summary())
        text = self.markdown()
        atomic_write(out / "measures.md", lambda tmp: tmp.write_text(text, "utf-8"))
        files += ["measures.json", "measures.md"]
        if pictures:
            from compare.design import plots

            expect_pictures(1 + bool(self.sweeps))
            plots.fig15_png(self, out / "fig15_temperature_drop.png")
            files.append("fig15_temperature_drop.png")
            if self.sweeps:
                plots.fig16_png(self, out / "fig16_sensitivity.png")
                files.append("fig16_sensitivity.png")
        return [out / f for f in files]


def _csv(v: Any) -> Any:
    """One CSV cell: None and NaN empty, floats with 6 significant digits."""
    if v is None:
        return ""
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    return v


def _markdown(rep: MeasuresReport) -> str:
    pc = paper_consistency()
    out = [f"# Thermal stiffness strategy: {rep.spec_name}, case '{rep.case_name}'", "",
           f"FEM reference P2 level {rep.level}; losses {rep.baseline.losses_W:.1f} W at "
           f"{rep.speed_rpm:g} rpm; sum(alpha_i A_i) = {rep.sum_alpha_A_W_K:.4g} W/K over "
           "every convective surface (coolant jacket included). Measures file: "
           f"`{rep.measures_file}`. Run time {rep.runtime_s:.1f} s.", "",
           "## Indicators (paper section 4)", ""]
    ind = rep.indicator_rows()
    out.append(markdown_table(
        ["model", "Q W", "mean rise K", "max rise K", "K_alpha mean K/W", "K_alpha max K/W",
         "shaft rise K", "growth um", "K_T K/um", "K_Q W/um"],
        [[r.get("model"), r.get("losses_W"), r.get("mean_rise_K"), r.get("max_rise_K"),
          r.get("K_alpha_mean_K_W"), r.get("K_alpha_max_K_W"), r.get("shaft_rise_K"),
          r.get("growth_um"), r.get("K_T_K_um"), r.get("K_Q_W_um")] for r in ind],
        ["", ".1f", ".2f", ".2f", ".3g", ".3g", ".2f", ".2f", ".3f", ".2f"]))
    out += ["", f"The paper's K_T = 0.52 and K_Q = 64.53 follow from its own figures "
            f"(41.6 K / 79.7 um = {pc['K_T_K_um']:.3f}; 5146 W / 79.7 um = "
            f"{pc['K_Q_W_um']:.2f}); its K_alpha = 0.00019 K/W does not (41.6 K / 5146 W = "
            f"{pc['K_alpha_shaft_K_W']:.4f}, 46.1 K / 5146 W = {pc['K_alpha_housing_K_W']:.4f}) "
            f"and equals 1 K / 5146 W = {pc['one_kelvin_per_losses_K_W']:.3g} K/W.", "",
            "## Convective surfaces: what sum(alpha_i A_i) runs over", ""]
    out.append(markdown_table(
        ["surface", "T_ref", "alpha W/m2K", "A m2", "alpha A W/K", "share"],
        [[f.name, f.T_ref, f.h_W_m2K, f.A_m2, f.G_W_K,
          f"{100 * f.G_W_K / rep.sum_alpha_A_W_K:.2f} %"] for f in rep.films],
        ["", "", ".4g", ".4g", ".4g", ""]))
    out += ["", "## Measures: formulas (eq. 25-30) against the reference", ""]
    mrows = [m.to_row() for m in rep.measures]
    lumped = [k for k in (mrows[0] if mrows else {}) if k.startswith("lambda_lumped_")]
    out.append(markdown_table(
        ["measure", "kind", "size", "lambda formula", "xi formula %", "lambda ref (mean)",
         "xi ref (mean) %", "xi ref (max) %", "gap xi pp", "effect ratio",
         "growth um before/after", "lambda growth ref", "xi growth ref %"]
        + [k.replace("lambda_lumped_", "lambda ") for k in lumped],
        [[r["measure"], r["kind"], m.measure.size_text, r["lambda_formula"], r["xi_formula_pct"],
          r["lambda_ref_mean"], r["xi_ref_mean_pct"], r["xi_ref_max_pct"],
          r["gap_xi_pct_points"], r["effect_ratio"],
          f"{fmt(r['growth_before_um'], '.2f')} / {fmt(r['growth_after_um'], '.2f')}",
          r["lambda_growth_ref"], r["xi_growth_ref_pct"]] + [r[k] for k in lumped]
         for r, m in zip(mrows, rep.measures, strict=True)],
        ["", "", "", ".5g", ".3g", ".5g", ".3g", ".3g", "+.3g", ".3g", "", ".5g", ".3g"]
        + [".5g"] * len(lumped)))
    out += ["", "effect ratio = (lambda_ref - 1) / (lambda_formula - 1): the share of the "
            "predicted effect the reference confirms. lambda growth = K_Q2 / K_Q1 (eq. 31); the "
            "formulas predict the same lambda for the growth as for the temperature.", ""]
    if rep.inverse:
        out += ["## Inverse problem (smallest measure reaching a target, on the reference)", ""]
        out.append(markdown_table(
            ["target", "measure", "vary", "goal", "reached", "size (reference)",
             "size (formula)", "formula / reference", "FEM solves", "note"],
            [[i.target.name, i.target.measure, i.target.vary,
              f"xi {i.target.xi_pct:g} %" if i.target.xi_pct is not None
              else f"growth {i.target.growth_um:g} um", str(i.reached),
              f"{fmt(i.size_ref)} {i.unit}", f"{fmt(i.size_formula)} {i.unit}",
              i.to_row()["formula_over_ref"], i.solves, i.note]
             for i in rep.inverse],
            ["", "", "", "", "", "", "", ".3g", "d", ""]))
        out.append("")
    if rep.failures:
        out += ["## Failed cases", ""] + [f"- {f['label']}: {f['error']}" for f in rep.failures]
        out.append("")
    return "\n".join(out) + "\n"


def run_measures(spec: Spec, mfile: MeasureFile, case: LoadCase, level: int = 1,
                 nodes: tuple[str | int, ...] = ("paper5", "paper11"), sweeps: bool = True,
                 points: int = 7, scheduler: str | None = None, workers: int | None = None,
                 progress: Callable[[str], None] | None = None) -> MeasuresReport:
    """Indicators, every measure of ``mfile`` (formula and reference), its inverse problems
    and sensitivity sweeps; the cases run through :func:`compare.executor.run_cases`."""
    from compare.executor import run_cases

    t0 = time.perf_counter()
    say = progress or (lambda _m: None)
    speed = case_speed_rpm(case)
    say(f"baseline: FEM level {level} and the lumped models {', '.join(map(str, nodes))}")
    # the baseline runs here first: it fails loudly on a bad spec, and the pool's forked
    # workers inherit its assembled model
    base = MeasureCase(spec, case, None, level, tuple(nodes)).run()
    sweep_specs = (mfile.sweeps if mfile.sweeps is not None
                   else default_sweeps(spec, speed, points)) if sweeps else ()
    by_name = {m.name: m for m in mfile.measures}
    cases: list[Any] = [MeasureCase(spec, case, m, level, tuple(nodes)) for m in mfile.measures]
    cases += [InverseCase(spec, case, t, by_name[t.measure], level) for t in mfile.inverse]
    cases += [SweepCase(spec, case, sw, float(x), level) for sw in sweep_specs for x in sw.values]
    if sweep_specs:  # the sweeps' thermal-only model, also inherited by the workers
        say(f"assembling the sweeps' thermal-only FEM model (level {level})")
        reference_model(spec, level, elastic=False)
    say(f"{len(cases)} cases: {len(mfile.measures)} measures, {len(mfile.inverse)} inverse "
        f"problems, {len(cases) - len(mfile.measures) - len(mfile.inverse)} sweep points")
    outcomes = run_cases(run_case, cases, scheduler=scheduler, workers=workers,
                         progress=progress)
    measures, inverse, points, failures = [], [], [], []
    for c, o in zip(cases, outcomes, strict=True):
        if not o.ok:
            failures.append({"label": o.label, "error": o.error or "", "type": o.error_type or ""})
        if isinstance(c, MeasureCase):
            measures.append(measure_result(spec, case, c.measure, base, o.value if o.ok else None,
                                           None if o.ok else o.error))
        elif o.ok and isinstance(c, InverseCase):
            inverse.append(o.value)
        elif o.ok:
            points.append(o.value)
    return MeasuresReport(spec.name, case.name, level, mfile.path, speed,
                          surface_films(spec, speed), base["fem"], base["lumped"], measures,
                          inverse, points, failures, time.perf_counter() - t0)
