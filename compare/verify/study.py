"""The verification study of a spec: how far can its models be trusted?

1. Grid convergence of the FEM reference on nested levels (compare.verify.convergence): observed
   order, Richardson extrapolation, GCI; the ground-truth level.
2. Steady accuracy (the nominal point, or the spec's own load case): eq. 14, the lumped models
   for every N and the FEM levels against the Richardson-extrapolated reference.
3. Transient accuracy (spl-16h, or an 8 h warm-up for a spec without a power balance): the
   lumped models and the coarser FEM levels against the FEM ground-truth level.
4. A self-contained HTML report with the tables, the plots and the revolved 3-D field.

The independent runs of steps 2 and 3 (every lumped model, steady and transient, and the FEM
transients) go through :func:`compare.executor.run_cases`: serially in this process by
default (``workers=1``), in a process pool (``workers`` > 1) or on a Dask cluster
(``scheduler``). A run that fails is listed in :attr:`StudyResult.failures` (label and
message) and left out of its table; the study goes on. The steady FEM levels of step 1 run
here, one after the other: their results hold the sparse LU factorisation (which does not
pickle) and the reference level's result draws the 3-D picture.
"""

from __future__ import annotations

import gc
import html
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import partial
from pathlib import Path

import numpy as np

from compare.report import html_figure, html_page, markdown_to_html_table, verdict_cell
from compare.verify.accuracy import (
    NODES,
    TOL_GROWTH_UM,
    TOL_TEMP_K,
    AccuracyResult,
    Entry,
    eq14_entry,
    fem_entry,
    lumped_entries,
    worst_temperature_K,
)
from compare.verify.convergence import ConvergenceResult, convergence_study
from spindle.errors import InputError
from spindle.loads import LoadCase, check_time_step
from spindle.plots import levels_text
from spindle.spec import Spec

WARMUP_S = 8 * 3600.0


@dataclass
class StudyResult:
    spec: Spec
    convergence: ConvergenceResult
    steady: AccuracyResult
    transient: AccuracyResult | None
    ground_truth_level: int | None
    reference_level: int
    runtime_s: float
    steady_case: LoadCase
    reference_result: object  # the FEM steady result on the reference level (3-D picture)
    #: runs that failed: {"label", "error", "type"} each; their models are missing from the
    #: tables (a failed FEM transient on the reference level leaves ``transient`` None)
    failures: list[dict[str, str]] = field(default_factory=list)
    #: how the reference transient was integrated in time (_exact_reference); None
    #: without a transient
    time_integration: dict | None = None

    def summary(self) -> dict:
        return {"spec": self.spec.name, "runtime_s": self.runtime_s,
                "ground_truth_level": self.ground_truth_level,
                "reference_level": self.reference_level,
                "convergence": self.convergence.summary(),
                "time_integration": self.time_integration,
                "steady": self.steady.summary(),
                "transient": self.transient.summary() if self.transient else None,
                "failures": self.failures}

    def verdicts(self) -> list[dict]:
        """One row per case and model (the paper's models, the lumped presets and eq. 14,
        and every other lumped model or ROM that passes or is borderline): ``case``,
        ``model``, ``passes`` (both tolerances met), ``borderline`` (the margin within the
        reference's uncertainty: the verdict is not decided),
        ``temperature_error_K`` (the worst), ``temperature_margin_K`` (tolerance minus error:
        negative when it fails), ``P1_error_um``, ``P1_margin_um`` (nan without P1), and
        the sentence ``verdict``."""
        out = []
        for acc in (self.steady, self.transient):
            if acc is None:
                continue
            t = acc.table()
            for i, name in enumerate(t["model"]):
                paper = bool(t["preset"][i]) or t["kind"][i] == "eq14"
                other = (t["kind"][i] in ("lumped", "rom")
                         and (t["meets_tolerances"][i] or t["borderline"][i]))
                if not (paper or other):
                    continue
                worst = worst_temperature_K({k: t[k][i] for k in t if k.endswith("_max_K")})
                p1 = t.get("P1_max_um", [math.nan] * len(t["model"]))[i]
                out.append({"case": acc.case_name,
                            "model": name + (f" ({t['preset'][i]})" if t["preset"][i] else ""),
                            "passes": bool(t["meets_tolerances"][i]),
                            "borderline": bool(t["borderline"][i]), "paper": paper,
                            "temperature_error_K": worst,
                            "temperature_margin_K": acc.tol_temp_K - worst,
                            "P1_error_um": p1, "P1_margin_um": acc.tol_growth_um - p1,
                            "verdict": t["verdict"][i]})
        return out

    def headline(self) -> str:
        """One paragraph: which models meet the paper's tolerances on which case, and the
        ground truth they are measured against."""
        conv = self.convergence
        gt = self.ground_truth_level
        worst = conv.summary()["worst_GCI_pct_per_level"].get(str(self.reference_level))
        truth = (f"the FEM reference at level {gt} (worst grid convergence index "
                 f"{worst:.2g} % over every sensor and growth reading)" if gt is not None and
                 worst is not None else f"the FEM reference at its finest level "
                 f"{self.reference_level}, whose GCI stays above {100 * conv.threshold:g} %")
        sentences = []
        verdicts = self.verdicts()
        for acc in (self.steady, self.transient):
            if acc is None:
                continue
            rows = [v for v in verdicts if v["case"] == acc.case_name]
            paper = [v for v in rows if v["paper"]]
            good = [v["model"] for v in paper if v["passes"] and not v["borderline"]]
            bad = [v["model"] for v in paper if not v["passes"] and not v["borderline"]]
            edge = [v["model"] for v in rows if v["borderline"]]
            kind = "transient" if acc.transient else "steady"
            others = [v["model"] for v in rows if not v["paper"] and v["passes"]
                      and not v["borderline"]]
            sentences.append(
                f"On the {kind} case {acc.case_name}, "
                + (f"{', '.join(good)} meet{'s' if len(good) == 1 else ''} both tolerances"
                   if good else "none of the paper's models meets both tolerances")
                + (f"; {', '.join(bad)} fail{'s' if len(bad) == 1 else ''}" if bad and good
                   else f" ({', '.join(bad)} fail)" if bad else "")
                + (f"; of the other models, {', '.join(others)} "
                   f"meet{'s' if len(others) == 1 else ''} both" if others else "")
                + (f"; {', '.join(edge)} {'is' if len(edge) == 1 else 'are'} borderline "
                   "(within the reference's uncertainty of a tolerance)" if edge else "")
                + ".")
        return (f"Checked against {truth}, with the paper's tolerances {TOL_TEMP_K:g} K and "
                f"±{TOL_GROWTH_UM:g} µm. " + " ".join(sentences))

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        from spindle.outputs import write_json

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        files = self.convergence.save(out, pictures)
        files += self.steady.save(out, "accuracy_steady", pictures)
        if self.transient is not None:
            files += self.transient.save(out, "accuracy_transient", pictures)
        if pictures:
            from reference import plots

            res = self.reference_result
            title = (f"{self.spec.name}: {self.steady_case.name}, FEM level "
                     f"{self.reference_level}")
            plots.revolved_png(res.model, res.T, out / "reference_3d.png", title)
            plots.section_png(res.model, res.T, out / "reference_section.png", title)
            files += [out / "reference_3d.png", out / "reference_section.png"]
        write_json(out / "study.json", self.summary())
        files.append(out / "study.json")
        (out / "report.html").write_text(self._html(out, pictures), encoding="utf-8")
        files.append(out / "report.html")
        return files

    # ------------------------------------------------------------------ report
    def cases_text(self) -> str:
        """The load cases in words: the steady one's speed and heat per source, the
        transient one's name (spindle.drive.rated_cycles)."""
        c = self.steady_case
        heat = {k: float(q(0.0)) for k, q in c.sources.items()}
        text = (f"steady case '{c.name}' at {c.speed_rpm(0.0):g} rpm, {sum(heat.values()):.0f} W "
                "of heat (" + ", ".join(f"{k} {q:.0f} W" for k, q in heat.items()) + ")")
        if self.transient is not None:
            text += f"; transient case '{self.transient.case_name}'"
        return text

    def _html(self, out: Path, pictures: bool) -> str:
        def img(name: str, alt: str) -> str:
            # without pictures, a PNG left in ``out`` by an earlier run must not be shown
            return html_figure(out / name, alt) if pictures else ""

        conv = self.convergence
        gt = self.ground_truth_level
        gt_text = (f"level {gt} (the coarsest with GCI ≤ {100 * conv.threshold:g} % for every "
                   "sensor and growth reading)" if gt is not None else
                   f"none of levels {levels_text(conv.analysed_levels)} has GCI ≤ {100 * conv.threshold:g} % "
                   f"for every quantity; the finest, level {self.reference_level}, is used")
        flagged = conv.summary()["flagged"]
        parts = [
            f"<h1>Verification study: {html.escape(self.spec.name)}</h1>",
            f"<p>{html.escape(self.spec.description)}<br>Source: {html.escape(self.spec.source)}"
            f"<br>Run time {self.runtime_s:.1f} s. Tolerances (paper): {TOL_TEMP_K:g} K, "
            f"±{TOL_GROWTH_UM:g} µm.<br>Load cases: {html.escape(self.cases_text())}.</p>",
            f'<p class="summary">{html.escape(self.headline())}</p>',
            "<h2>Verdicts</h2>" + self._verdict_table(),
            self._failures_html(),
            "<h2>1. Grid convergence of the FEM reference</h2>",
            f"<p>Case: {html.escape(conv.case_name)}; levels {levels_text(conv.levels)} "
            f"({', '.join(f'{d} DOFs' for d in conv.dofs)}). Ground truth: "
            f"{html.escape(gt_text)}. Temperatures as rises above ambient [K], growth in µm. "
            + (f"Flagged: {html.escape(', '.join(f'{q} ({f})' for q, f in flagged.items()))}."
               if flagged else "No quantity is flagged "
               "oscillatory or divergent on the finest triplet.") + "</p>",
            markdown_to_html_table(conv.markdown()), img("convergence.png", "grid convergence"),
            img("reference_3d.png", "reference temperature field, revolved"),
            img("reference_section.png", "reference temperature on the half-section"),
            f"<h2>2. Steady accuracy ({html.escape(self.steady.case_name)})</h2>",
            f"<p>Reference: {html.escape(self.steady.reference_label)}.</p>",
            markdown_to_html_table(self.steady.markdown()),
            img("accuracy_steady_error.png", "error against unknowns"),
            img("accuracy_steady_runtime.png", "error against runtime"),
            img("accuracy_steady_shaft_profile.png", "shaft sensors per model (paper Fig. 4)"),
        ]
        if self.transient is not None:
            parts += [
                f"<h2>3. Transient accuracy ({html.escape(self.transient.case_name)})</h2>",
                f"<p>Reference: {html.escape(self.transient.reference_label)}. Errors are "
                "over the sensors and over time.</p>",
                self._time_html(),
                markdown_to_html_table(self.transient.markdown()),
                img("accuracy_transient_error.png", "error against unknowns"),
                img("accuracy_transient_runtime.png", "error against runtime"),
                img("accuracy_transient_shaft_profile.png", "shaft sensors at the peak"),
            ]
        return html_page(f"spindle-verify study: {self.spec.name}", parts)

    def _verdict_table(self) -> str:
        """PASS / FAIL in words and colour, each error with its margin to the tolerance."""
        def num(v: float, unit: str) -> str:
            return "n/a" if math.isnan(v) else f"{v:.2f} {unit}"

        def margin(v: float, unit: str) -> str:
            if math.isnan(v):
                return "n/a"
            return (f"{v:.2f} {unit} to spare" if v >= 0 else f"over by {-v:.2f} {unit}")

        head = ["case", "model", "verdict", "worst temperature error", "margin to 1 K",
                "P1 error", "margin to ±1.5 µm"]
        rows = "".join(
            "<tr>" + f"<td>{html.escape(v['case'])}</td><td>{html.escape(v['model'])}</td>"
            + verdict_cell(v["passes"], v["borderline"])
            + "".join(f"<td>{html.escape(x)}</td>" for x in (
                num(v["temperature_error_K"], "K"), margin(v["temperature_margin_K"], "K"),
                num(v["P1_error_um"], "µm"), margin(v["P1_margin_um"], "µm"))) + "</tr>"
            for v in self.verdicts())
        th = "".join(f"<th>{html.escape(h)}</th>" for h in head)
        return f"<table><thead><tr>{th}</tr></thead><tbody>{rows}</tbody></table>"

    def _time_html(self) -> str:
        ti = self.time_integration
        if not ti:
            return ""
        limit = f"the {100 * ti['limit']:g} % limit"
        verdict = (f"below {limit}" if ti["converged"] else f"ABOVE {limit}: the transient "
                   "verdicts carry that much time error")
        return (f"<p><b>Time.</b> The reference is {html.escape(ti['method'])}. Read every "
                f"{ti['dt_s']:g} s and 1, 2, 4 ... 64 s after each step of speed or heat. "
                f"Its temporal error: {ti['time_error_K']:.2g} K and "
                f"{ti['time_error_um']:.2g} µm, {100 * ti['share']:.2g} % of "
                f"{html.escape(ti['against'])}: {verdict}. The lumped models integrate exactly "
                "for inputs held over each step and are read at the same instants.</p>")

    def _failures_html(self) -> str:
        if not self.failures:
            return ""
        rows = "".join(f"<li>{html.escape(f['label'])}: {html.escape(f['error'])}</li>"
                       for f in self.failures)
        return (f"<h2>Failed runs ({len(self.failures)})</h2><p>These runs raised an error; "
                f"their models are missing from the tables below.</p><ul>{rows}</ul>")


def _reference_entry(conv: ConvergenceResult, case: LoadCase) -> tuple[Entry, str]:
    """The Richardson-extrapolated values where the finest triplet allows, else the finest
    level's value."""
    fine = conv.levels[-1]
    T_amb = float(case.T_ambient_K(0.0))
    sensors, growth, fallback = {}, {}, []
    for q, vals in conv.values.items():
        g = conv.gci(q, fine)
        v = g.extrapolated
        if math.isnan(v):
            v = vals[-1]
            fallback.append(q)
        if conv.units[q] == "um":
            growth[q] = v * 1e-6
        else:
            sensors[q] = T_amb + v
    label = f"Richardson extrapolation of FEM levels {levels_text(conv.levels[-3:])}"
    if fallback:
        label += f" (finest level for {len(fallback)} flagged quantities)"
    return Entry(label, "reference", 0, 0.0, sensors, growth), label


def study_cases(spec: Spec) -> tuple[LoadCase, LoadCase]:
    """(steady case, transient case) through the power balance for a spec with one: the
    spindle's rated point held and the paper's 16 h cycle at its rated speed
    (spindle.drive.rated_cycles: for the SPL2782.1 the shipped ``nominal`` and ``spl-16h``);
    otherwise its own load case, and an 8 h warm-up from ambient."""
    from spindle.drive import cycle_load_case, drive_for, rated_cycles

    drive = drive_for(spec)
    if drive is not None:
        steady, transient = rated_cycles(spec, drive)
        return (cycle_load_case(spec, steady, drive), cycle_load_case(spec, transient, drive))
    base = spec.default_load_case()
    return base, replace(base, name="warm-up 8 h", duration_s=WARMUP_S)


@dataclass(frozen=True)
class StudyRun:
    """One independent run of the study: a lumped model (``size`` = node count) or the FEM
    (``size`` = mesh level), steady (``dt_s`` None) or transient from ``T0``. Picklable (the
    spec and the load case are dataclasses), so the executor can ship it to a worker."""

    spec: Spec
    case: LoadCase
    model: str  # "lumped" or "fem"
    size: int
    dt_s: float | None = None
    T0: float | None = None

    @property
    def label(self) -> str:
        what = f"lumped {self.size} nodes" if self.model == "lumped" else f"FEM level {self.size}"
        return f"{what} {'steady' if self.dt_s is None else 'transient'} ({self.case.name})"


def run_study_case(run: StudyRun, progress: Callable[[int, int], None] | None = None) -> Entry:
    """The executor's function: one run, as an :class:`~compare.verify.accuracy.Entry` (module level,
    so it pickles). ``progress(k, n)``: the FEM transient's speed segments done."""
    if run.model == "lumped":
        return lumped_entries(run.spec, run.case, (run.size,), run.dt_s, run.T0)[0]
    return fem_entry(run.spec, run.size, run.case, run.dt_s, run.T0, progress=progress)


def run_study(spec: Spec, levels: Sequence[int] = (0, 1, 2, 3), nodes: Sequence[int] = NODES,
              steady_case: LoadCase | None = None, transient_case: LoadCase | None = None,
              transient: bool = True, dt_s: float = 60.0, threshold: float = 0.01,
              progress: Callable[[str], None] | None = None, workers: int = 1,
              scheduler: str | None = None, rom: bool = False) -> StudyResult:
    """Run the whole study (see the module docstring).

    The steady FEM levels (grid convergence) run first, here. Then every independent run (the
    lumped models for each node count, steady and transient; the FEM transients on the
    reference level and the coarser ones) goes through :func:`compare.executor.run_cases`
    with ``workers`` and ``scheduler``. ``workers=1`` (the default) runs them one after the
    other in this process: the runtimes in the tables (the cost side of accuracy against
    cost) are then measured without other runs competing for the cores. ``workers=2`` runs
    them in a process pool (shorter wall time, same figures, runtimes taken under load);
    ``scheduler`` sends them to a Dask cluster (``"local"`` or ``tcp://host:port``).

    A run that fails does not stop the study: it is reported through ``progress`` and
    listed in :attr:`StudyResult.failures`, and its model is missing from the tables.

    ``rom``: also a reduced-order model of the reference level (rom.build_rom, trained on
    the random-loaded:0 cycle, 0.05 K / 0.1 µm) as a row of both tables, integrated in time
    as the reference was. Off by default: on spl2782 it adds 40-100 s (the build and the
    training cycle's FEM run) and the build's candidate vectors (about 0.6 GB at level 2;
    docs/rom.md gives the measured cost).
    """
    from compare.executor import check_scheduler, run_cases

    if workers < 1:
        raise InputError("command line", "--workers", f"{workers} is below 1",
                         "give --workers 1 (serial) or more")
    check_scheduler(scheduler)  # a missing extra or no scheduler there: now, not after the
    # grid convergence
    t0 = time.perf_counter()
    s_case, t_case = study_cases(spec)
    s_case = steady_case or s_case
    t_case = transient_case or t_case
    if transient:  # a step too fine is the caller's error, before the steady work
        check_time_step(t_case, dt_s)
    conv = convergence_study(spec, s_case, levels, threshold=threshold, progress=progress,
                             keep_results=True)
    gt = conv.ground_truth_level()
    ref_level = gt if gt is not None else conv.levels[-1]
    ref_entry, label = _reference_entry(conv, s_case)
    fem = []
    for lv, res, rt, n in zip(conv.levels, conv.results, conv.runtime_s, conv.dofs, strict=True):
        fem.append(Entry(f"FEM level {lv}", "fem", n, rt, res.sensors, res.growth_m, level=lv))
    # only the reference level's fields are drawn: the other levels' models (matrices, bases;
    # about 0.4 GB at level 3 of spl2782) go before the transient reference's factorisations
    keep = conv.levels.index(ref_level)
    conv.results = [r if i == keep else None for i, r in enumerate(conv.results)]
    del res
    gc.collect()

    T0 = float(t_case.T_ambient_K(0.0))
    failures: list[dict[str, str]] = []
    reference, time_integration = None, None
    if transient:  # the reference exact in time (issue 15 §1), on the reference level
        # every model is read 1, 2, 4 ... 64 s after every step too, whatever dt: the peak
        # errors are there
        t_case = t_case.with_jump_ladder()
        reference, time_integration, failed = _exact_reference(
            spec, t_case, ref_level, dt_s, T0, spatial_uncertainty(conv, ref_level), threshold,
            progress)
        failures += failed
    # the independent runs, longest first (the FEM transients) so that a pool stays busy
    coarse_levels = [lv for lv in conv.levels if lv < ref_level]
    groups: dict[str, list[StudyRun]] = {"steady": [StudyRun(spec, s_case, "lumped", n)
                                                    for n in nodes]}
    if reference is not None:
        groups = {"coarse": [StudyRun(spec, t_case, "fem", lv, dt_s, T0)
                             for lv in reversed(coarse_levels)],
                  "lumped": [StudyRun(spec, t_case, "lumped", n, dt_s, T0) for n in nodes],
                  **groups}
    runs = [r for g in groups.values() for r in g]
    if progress:
        where = (f"Dask scheduler {scheduler}" if scheduler else
                 "in this process" if workers == 1 else f"{workers} processes")
        progress(f"{len(runs)} independent runs ({where})")
    outcomes = iter(run_cases(run_study_case, runs, scheduler=scheduler, workers=workers,
                              progress=progress))
    got: dict[str, list[Entry]] = {}
    for name, group in groups.items():  # outcomes come in the order of ``runs``
        got[name] = []
        for _ in group:
            o = next(outcomes)
            if o.ok:
                got[name].append(o.value)
            else:
                failures.append(_failure(o))

    if rom:
        ref_res = conv.results[conv.levels.index(ref_level)]
        rom_rows = _rom_rows(ref_res, ref_level, s_case, t_case if reference is not None else None,
                             dt_s, T0, progress)
        got["steady"].append(rom_rows[0])
        if reference is not None:
            got["lumped"].append(rom_rows[1])
    eq14 = eq14_entry(spec, s_case)
    # the reference's own uncertainty, below which a margin to a tolerance decides nothing:
    # the extrapolated steady reference is within the finest level's GCI; the transient
    # reference within its level's (at the nominal point, the hottest) plus its time error
    steady = AccuracyResult(spec, s_case.name, False, ref_entry, label,
                            ([eq14] if eq14 else []) + got["steady"] + fem,
                            uncertainty=spatial_uncertainty(conv, conv.levels[-1]))
    trans = None
    if reference is not None:
        from spindle.loads import time_grid

        coarse = sorted(got["coarse"], key=lambda e: e.level)  # the table goes coarse first
        ti = time_integration
        how = (f"exact in time (Krylov; temporal error {ti['time_error_K']:.2g} K, "
               f"{ti['time_error_um']:.2g} µm)")
        trans = AccuracyResult(spec, t_case.name, True, reference,
                               f"FEM level {ref_level}, {how}; read every {dt_s:g} s"
                               + (" and 1, 2, 4 ... 64 s after each step"
                                  if t_case.extra_times_s else ""),
                               got["lumped"] + coarse, times_s=time_grid(t_case, dt_s),
                               uncertainty=_transient_uncertainty(conv, ref_level, ti))
    ref_res = conv.results[conv.levels.index(ref_level)]
    return StudyResult(spec, conv, steady, trans, gt, ref_level, time.perf_counter() - t0,
                       s_case, ref_res, failures, time_integration)


def _rom_rows(ref_res, level: int, s_case: LoadCase, t_case: LoadCase | None, dt_s: float,
              T0: float, progress: Callable[[str], None] | None
              ) -> list[Entry]:
    """The ROM of FEM ``level`` (built on the operators of its steady result ``ref_res``):
    its steady row, and its transient row if ``t_case``."""
    from compare.verify.accuracy import rom_entry
    from compare.verify.romstudy import named_case
    from reference import ReferenceModel
    from reference.rom import build_rom

    if progress:
        progress(f"ROM of FEM level {level} (trained on random-loaded:0)")
    ref = ReferenceModel.from_parts(ref_res.model, ref_res.elastic)
    spec = ref.spec
    train = named_case(spec, "random-loaded", 0)
    if t_case is not None and t_case.extra_times_s:  # read 1 ... 64 s after the steps too:
        train = train.with_jump_ladder()  # then the ROM is chosen on those times as well
    model, _ = build_rom(ref, train, 60.0, level=level, keep_basis=False, indicator=False)
    ref.release()
    rows = [rom_entry(model, s_case, None, None)]
    if t_case is not None:
        rows.append(rom_entry(model, t_case, dt_s, T0))
    return rows


def _failure(outcome) -> dict[str, str]:
    """The failures entry of a run that failed (compare.executor's outcome)."""
    return {"label": outcome.label, "error": outcome.error or "",
            "type": outcome.error_type or ""}


def _exact_reference(spec: Spec, case: LoadCase, level: int, dt_s: float, T0: float,
                     spatial: dict[str, float] | None, threshold: float,
                     progress: Callable[[str], None] | None
                     ) -> tuple[Entry | None, dict | None, list[dict[str, str]]]:
    """The reference transient on ``level``, exact in time for inputs linear between the
    grid points on a rational Krylov space (ThermalModel.exact_readouts, reference.krylov),
    with its temporal error estimate held against the spatial uncertainty ``spatial``
    (:func:`spatial_uncertainty`), or against ``threshold`` of the peak where the grid
    study gives none. Returns the entry, the ``time_integration`` record for study.json and
    the failures."""
    from compare.executor import run_cases

    if progress:
        progress(f"reference transient on level {level} (Krylov, exact in time), read every "
                 f"{dt_s:g} s")
    def segments(k: int, n: int) -> None:  # compare.progress reads "[k/n]" as a fraction
        if progress:
            progress(f"[{k}/{n}] reference transient: speed segment {k} of {n} done")

    # in this process (workers=1), so that the segments' progress reaches the console
    (o,) = run_cases(partial(run_study_case, progress=segments),
                     [StudyRun(spec, case, "fem", level, dt_s, T0)], workers=1)
    if not o.ok:
        return None, None, [_failure(o)]
    record = _time_error_record(o.value, T0, dt_s, spatial, threshold)
    if progress:
        progress(f"temporal error {record['time_error_K']:.2g} K, {record['time_error_um']:.2g}"
                 f" µm: {100 * record['share']:.2g} % of {record['against']} (limit "
                 f"{100 * record['limit']:g} %)")
    return o.value, record, []


#: the largest share of the reference's spatial uncertainty its temporal error may take
#: (issue 33): below it, the time integration adds nothing a verdict could see
TIME_SHARE_OF_SPATIAL = 0.01


def _transient_uncertainty(conv: ConvergenceResult, level: int, time_integration: dict | None
                           ) -> dict[str, float] | None:
    """The transient reference's uncertainty [K, um]: its level's spatial uncertainty plus
    the stated temporal error."""
    spatial = spatial_uncertainty(conv, level)
    if spatial is None:
        return None
    ti = time_integration or {}
    return {"K": spatial["K"] + float(ti.get("time_error_K") or 0.0),
            "um": spatial["um"] + float(ti.get("time_error_um") or 0.0)}


def spatial_uncertainty(conv: ConvergenceResult, level: int) -> dict[str, float] | None:
    """The reference level's worst spatial uncertainty, GCI times value, over the
    temperature rises [K] and over P1 [um] at the steady case (None where ``level`` has no
    two coarser levels to analyse it)."""
    if level not in conv.analysed_levels:
        return None
    out = {"K": 0.0, "um": 0.0}
    for q, vals in conv.values.items():
        unit = "um" if conv.units[q] in ("µm", "um") else "K"
        if unit == "um" and q != "P1":
            continue
        g = conv.gci(q, level)
        v = abs(vals[conv.levels.index(level)])
        if math.isfinite(g.gci_fine):
            out[unit] = max(out[unit], g.gci_fine * v)
    return out


def _time_error_record(ref: Entry, T0: float, dt: float, spatial: dict[str, float] | None,
                       threshold: float) -> dict:
    temps = [k for k in ref.sensors if k in ref.time_error]
    rise = max(float(np.max(np.abs(np.asarray(ref.sensors[k]) - T0))) for k in temps)
    err_K = max(ref.time_error[k] for k in temps)
    p1 = ref.growth.get("P1")
    err_m = ref.time_error.get("P1", 0.0) if p1 is not None else 0.0
    if spatial and spatial["K"] > 0:
        share = max(err_K / spatial["K"],
                    err_m * 1e6 / spatial["um"] if p1 is not None and spatial["um"] > 0 else 0.0)
        against, limit = "the spatial uncertainty (GCI)", TIME_SHARE_OF_SPATIAL
    else:
        share = err_K / max(rise, 1e-12)
        if p1 is not None:
            share = max(share, err_m / max(float(np.max(np.abs(p1))), 1e-12))
        against, limit = "the peak", threshold
    return {"method": "exact in time for inputs linear between the read-out instants, on a "
                      "rational Krylov space per speed segment grown until two successive "
                      "spaces agree to 1e-5 K and 1e-4 µm; the error is that estimate, summed "
                      "over the segments (reference.krylov; checked against the CRAM-16 "
                      "integration in tests/test_time_convergence.py)",
            "dt_s": dt, "time_error_K": err_K, "time_error_um": err_m * 1e6,
            "peak_rise_K": rise,
            "spatial_uncertainty_K": spatial["K"] if spatial else None,
            "spatial_uncertainty_um": spatial["um"] if spatial else None,
            "share": share, "against": against, "limit": limit, "converged": share <= limit}
