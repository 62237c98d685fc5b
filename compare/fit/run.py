"""``spindle-verify fit RUN.csv --spec SPEC --out DIR``: confront the model with a bench run.

1. Ingest the run (spindle.bench), map its channels to the spec's sensors, build the inputs
   through the power balance on a 60 s grid.
2. Solve the FEM reference on the run's inputs and anchor the grey box to it
   (compare.fit.discrepancy); calibrate the declared parameters, with priors around the spec's
   values, on the fit window (default the first 60 %), validate on the rest (compare.fit.calibrate).
   With ``model="fem"`` the base parameters are calibrated on the FEM reference itself
   (compare.fit.femgrey), and the lumped grey box is anchored to the FEM at the calibrated point
   for the selection of effects.
3. Diagnose the residual (compare.fit.residuals), select effects forward (likelihood-ratio test at
   ``alpha``, and needed by the validation error or by plausibility), and say ``unexplained``
   when the final residual is still structured and material in a channel and no candidate
   explains it.
4. Write ``report.json`` (the stable contract of issue 6) and ``report.html``.
"""

from __future__ import annotations

import html
import math
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from compare.fit.adequacy import base_adequacy, extrapolation_warnings, verdict_text
from compare.fit.calibrate import (
    TOLERANCE,
    Calibrator,
    Fit,
    Measured,
    Selection,
    at_bound,
    cross_validate,
    forward_selection,
    parameters_table,
    resample,
)
from compare.fit.events import event_tests
from compare.fit.greybox import (
    BASE_PARAMS,
    DEFAULT_BASE_EXTRA,
    EFFECTS,
    EXTRA_BASE_PARAMS,
    GreyBox,
    Inputs,
    base_params,
    default_theta,
)
from compare.report import html_figure, html_page, html_table
from spindle.bench import BenchRun, check_against_spec, read_bench
from spindle.bench_inputs import bench_grid, cell_means, held, settled_speed
from spindle.drive import drive_for
from spindle.errors import InputError, SolverError
from spindle.outputs import jsonable
from spindle.results import check_plausible
from spindle.spec import Spec
from spindle.tolerances import edge_absolute, edge_scale, edge_unit
from spindle.units import ZERO_C_K

REPORT_FORMAT = "spindle-verify-fit/1"


#: validation RMS [tolerance units] above which a structured residual is reported unexplained
MATERIAL_RMS = 0.25


def _valid_samples(run: BenchRun, col: str) -> tuple[np.ndarray, np.ndarray]:
    """(times [s], values) of column ``col``'s non-empty cells."""
    y = run.columns[col]
    ok = ~np.isnan(y)
    return run.time_s[ok], y[ok]


def greybox_inputs(run: BenchRun, grid_s: float = 60.0) -> Inputs:
    """Per-interval inputs of the grey box: the speed logged at the interval's middle (a step
    inside an interval is at most half an interval off), power, torque, ambient and coolant
    averaged over the interval (spindle.bench's helpers)."""
    grid = bench_grid(run, grid_s)
    mids = 0.5 * (grid[:-1] + grid[1:])
    speed = settled_speed(held(*_valid_samples(run, "speed_rpm"), mids))
    power = cell_means(*_valid_samples(run, "power_kW"), grid, mids)
    torque = (cell_means(*_valid_samples(run, "load_torque_Nm"), grid, mids)
              if run.load_torque_measured else np.zeros(len(mids)))
    t_env, y_env = _valid_samples(run, "T_env_C")
    T_env = cell_means(t_env, y_env, grid, mids) + ZERO_C_K
    T_cool = cell_means(*_valid_samples(run, "T_coolant_C"), grid, mids) + ZERO_C_K
    return Inputs(grid, speed, power, torque, T_env, T_cool, float(y_env[0]) + ZERO_C_K)


@dataclass
class FitReport:
    run: BenchRun
    spec: Spec
    channels: list[str]
    measured: Measured
    inputs: Inputs
    selection: Selection
    diagnostics_before: object
    diagnostics_after: object
    unexplained: bool
    unexplained_text: str
    signatures: dict[str, dict[str, np.ndarray]]
    runtime_s: float
    alpha: float
    anchor: object = None  # compare.fit.discrepancy.Discrepancy; None: lumped alone, no priors
    floor: dict | None = None  # per channel [tolerance units]
    prior_z: dict | None = None  # final base parameters, prior sds from the spec's values
    calibration_model: str = "lumped"  # "fem": base parameters calibrated on the FEM itself
    fem_calibration: dict | None = None  # with "fem": FEM runs, seconds, evaluations
    #: compare.fit.adequacy.base_adequacy of the calibrated base model
    base_adequacy: dict | None = None
    #: operating points of the validation window the fit window never saw
    warnings: list[str] = field(default_factory=list)
    #: compare.fit.events tests of the raw samples, by candidate label
    events: dict[str, dict] = field(default_factory=dict)
    #: compare.fit.calibrate.cross_validate of the base and the final model ("base",
    #: "final"); empty when switched off
    cross_validation: dict = field(default_factory=dict)
    #: compare.fit.gaps.GapSwitch per logging gap with an operating change inside
    gap_switches: list = field(default_factory=list)

    def to_dict(self) -> dict:
        sel = self.selection
        final = sel.final
        effects = []
        for st in sel.steps:
            e = EFFECTS[st.effect]
            # the final model's values (it holds every accepted effect), as in the parameter
            # table; the step's own fit is the one its test was made on
            params = {p.name: final.theta[p.name] for p in e.params}
            if st.effect == "sensor_lag":
                params["channel"] = final.lag_channel
            effects.append({"name": st.effect, "parameters": params,
                            "confidence_intervals": {p.name: list(final.ci95[p.name])
                                                     for p in e.params},
                            "p_value": st.p_value, "delta_bic": st.delta_bic,
                            "explanation": e.explanation,
                            "validation_error_before": st.validation_before,
                            "validation_error_after": st.validation_after,
                            "needed_by": st.needed_by,
                            # on its range's bound: a limit of the effect, not an estimate
                            "at_bound": at_bound(final, st.effect)})
        return jsonable({
            "format": REPORT_FORMAT, "run": str(self.run.path), "spec": self.spec.name,
            "channels": self.channels, "run_summary": self.run.summary(),
            "windows": {"blocks": self.measured.blocks,
                        "fit": [[a, b] for a, b, w in self.measured.spans() if w == "fit"],
                        "validation": [[a, b] for a, b, w in self.measured.spans()
                                       if w == "validation"]},
            "cross_validation": self.cross_validation,
            "tolerances": {"temperature_K": 1.0, "growth_um": 1.5},
            "alpha": self.alpha,
            "calibration_model": self.calibration_model,
            "fem_calibration": self.fem_calibration,
            "base_adequacy": self.base_adequacy,
            "warnings": self.warnings,
            # where the speed changed inside a logging gap, as placed (s, rpm)
            "gap_switches": [asdict(g) for g in self.gap_switches],
            "events": self.events,
            "effects": effects,
            "unexplained": {"unexplained": self.unexplained, "description": self.unexplained_text},
            "error_before": _errors(sel.base), "error_after": _errors(final),
            "parameters": parameters_table(final),
            "parameters_before": parameters_table(sel.base),
            "parameters_prior_z": self.prior_z,
            "correlation": {"names": final.free, "matrix": final.correlation.tolist()},
            "not_identifiable": [k for k, ok in final.identifiable.items() if not ok],
            "candidates_tried": sel.tried,
            "fem_anchor": None if self.anchor is None else {
                "fem_level": self.anchor.fem_level,
                "prior_centre": default_theta(base_params(drive_for(self.spec))),
                # where FEM = anchored lumped: the spec's values, or with --model fem the
                # FEM-calibrated base parameters
                "anchored_at": self.anchor.theta_ref,
                "prior_sd": {k: p.prior_sd for k, p in BASE_PARAMS.items()},
                "fem_minus_lumped_rms": self.anchor.rms,
                "validation_floor": self.floor},
            "diagnostics_before": self.diagnostics_before.to_dict(),
            "diagnostics_after": self.diagnostics_after.to_dict(),
            "runtime_s": self.runtime_s})


def _errors(fit: Fit) -> dict:
    out = {}
    for window, chans in fit.errors.items():
        out[window] = {}
        for c, e in chans.items():
            if not e.get("n"):
                continue
            unit = "um" if c == "P1" else "K"
            out[window][c] = {"rmse": e[f"rmse_{unit}"], "max": e[f"max_{unit}"],
                              "bias": e[f"bias_{unit}"], "unit": unit,
                              "within_tolerance": e["within_tolerance"], "n": e["n"]}
    return out




def _residuals(measured: Measured, model: dict[str, np.ndarray], channels) -> dict:
    return {c: (measured.values[c] - model[c]) / TOLERANCE[c] for c in channels}


def _check_base_extra(base_extra: tuple[str, ...], model: str) -> None:
    unknown = [k for k in base_extra if k not in EXTRA_BASE_PARAMS]
    if unknown:
        raise InputError("command line", "--base-extra", f"unknown parameter {unknown[0]}",
                         f"use {' or '.join(EXTRA_BASE_PARAMS)}")
    if base_extra and model == "fem":
        raise InputError("command line", "--base-extra", "the FEM calibration swaps films, "
                         "contacts and sources only", "drop --base-extra or --model fem")


@dataclass
class BaseCalibration:
    """Where the effect loop starts: the bench run, its channels, the grey box's inputs, the
    measured data with its windows, the calibrator, the calibrated base fit, the spec's own
    parameter values, and the FEM anchor and FEM calibration details (None where unused)."""

    run: BenchRun
    channels: list[str]
    inputs: Inputs
    measured: Measured
    cal: Calibrator
    base: Fit
    spec_values: dict[str, float]
    anchor: object | None = None
    fem_calibration: dict | None = None
    #: compare.fit.gaps.GapSwitch per logging gap with an operating change inside
    gap_switches: list = field(default_factory=list)
    #: which model placed them: the calibrated, anchored one (the lumped path) or the spec's
    #: (the FEM calibration and the unanchored path place them once, before calibrating)
    switches_placed_by: str = "the spec's model"


def calibrate_base(path: str | Path, spec: Spec, fit_fraction: float = 0.6, nodes: int = 11,
                   grid_s: float = 60.0, progress: Callable[[str], None] | None = None,
                   fem_level: int | None = 0, model: str = "lumped",
                   base_extra: tuple[str, ...] | None = None, blocks: int = 1
                   ) -> BaseCalibration:
    """The first half of :func:`run_fit`: read the run, check it against the spec, anchor the
    grey box to the FEM reference and calibrate the base parameters (arguments as there)."""
    from compare.fit.discrepancy import fem_discrepancy

    say = progress or (lambda _m: None)
    if model not in ("lumped", "fem"):
        raise InputError("command line", "--model", f"unknown model '{model}'",
                         "use lumped or fem")
    if model == "fem" and fem_level is None:
        raise InputError("command line", "--model", "--model fem calibrates on the FEM "
                         "reference, --lumped-only switches the FEM off",
                         "drop one of the two options")
    if base_extra is None:  # the default extras, with the lumped calibration only
        base_extra = DEFAULT_BASE_EXTRA if model == "lumped" else ()
    base_extra = tuple(base_extra)
    _check_base_extra(base_extra, model)
    if not 0.2 <= fit_fraction <= 0.9:
        raise InputError("command line", "--fit-fraction", f"{fit_fraction} is outside 0.2..0.9",
                         "fit on 20 % to 90 % of the run, e.g. 0.6")
    say(f"reading {path}")
    run = read_bench(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        channels = check_against_spec(run, spec)
    drive = drive_for(spec)
    if drive is None:
        raise InputError(spec.path, "power_balance.preset", "the spec names no drive",
                         "add [power_balance] preset to the spec")
    held = greybox_inputs(run, grid_s)
    measured = _measured(run, channels, held.grid_s, fit_fraction, blocks)
    inputs, switches = _place_gap_switches(run, spec, drive, held, measured, channels, nodes,
                                           tuple(base_extra), say)

    def calibrator(on: Inputs) -> Calibrator:
        return Calibrator(GreyBox(spec, drive, on, nodes, base_extra=tuple(base_extra)),
                          measured, channels, progress=say)

    cal = calibrator(inputs)
    spec_values = default_theta(cal.gb.parameters(), [*BASE_PARAMS, *base_extra])

    def anchored(cal: Calibrator, start: dict[str, float]) -> tuple[object, Fit]:
        """The FEM anchor on ``cal``'s inputs, set on its grey box, and the base calibrated
        with the priors from ``start``."""
        say(f"solving the FEM reference (level {fem_level}) on this run's inputs")
        anchor = fem_discrepancy(cal.gb, channels, fem_level)
        cal.gb.discrepancy = anchor.offsets
        say("calibrating the base model")
        return anchor, cal.fit_with_prior({**spec_values, **anchor.theta_ref}, start=start)[1]

    anchor = None
    fem_cal_info = None
    placed_by = "the spec's model"
    # an extra whose spec value is its range's bound (a conductance the spec lacks) starts
    # inside its range: a start on the bound can stall there
    params = cal.gb.parameters()
    start = {k: params[k].lo + 0.05 * (params[k].hi - params[k].lo) for k in base_extra
             if params[k].default <= params[k].lo}
    if fem_level is None:  # the lumped model alone, factors of 1, no priors (older behaviour)
        say("calibrating the base model")
        base = cal.fit(start=start)
    elif model == "fem":
        base, anchor, fem_cal_info = _calibrate_on_fem(cal, fem_level, say)
    else:
        anchor, base = anchored(cal, start)
        if switches:
            # placed by the spec's model, whose level on a spindle the spec only approximates
            # can be kelvins off after the gap and pull the switch to the gap's edge; placed
            # again by the calibrated model, and the base recalibrated on those inputs
            # (docs/fit.md, *Input timing*)
            again, moved = _place_gap_switches(run, spec, drive, held, measured, channels,
                                               nodes, tuple(base_extra), say, base.theta,
                                               cal.gb.discrepancy)
            placed_by = "the calibrated model"
            if [m.switch_s for m in moved] != [w.switch_s for w in switches]:
                inputs, switches = again, moved
                cal = calibrator(inputs)
                anchor, base = anchored(cal, base.theta)
    return BaseCalibration(run, channels, inputs, measured, cal, base, spec_values, anchor,
                           fem_cal_info, switches, placed_by)


def _place_gap_switches(run: BenchRun, spec: Spec, drive, inputs: Inputs, measured: Measured,
                        channels: list[str], nodes: int, base_extra: tuple[str, ...],
                        say: Callable[[str], None], theta: dict[str, float] | None = None,
                        discrepancy: dict[str, np.ndarray] | None = None
                        ) -> tuple[Inputs, list]:
    """compare.fit.gaps.place_switches with the model's misfit over the hour after each gap:
    the lumped grey box at ``theta`` (default: the spec's values, no anchor, before the FEM
    runs) with the FEM anchor's ``discrepancy`` if given."""
    from compare.fit.gaps import JUDGE_S, gaps_with_change, place_switches

    t_n, n = _valid_samples(run, "speed_rpm")
    if not gaps_with_change(run.time_s, t_n, n, inputs.grid_s):
        return inputs, []
    say("placing the operating change inside a logging gap")
    cache: dict = {}

    def misfit(trial: Inputs, end_s: float) -> float:
        for k in [k for k in cache if isinstance(k, tuple) and k[:1] == ("src",)]:
            del cache[k]  # the heat sources depend on the inputs, the network does not
        gb = GreyBox(spec, drive, trial, nodes, base_extra=base_extra, _cache=cache,
                     discrepancy=discrepancy)
        y = gb.simulate(default_theta(gb.parameters()) if theta is None else theta)
        window = (trial.grid_s >= end_s) & (trial.grid_s <= end_s + JUDGE_S)
        total = 0.0
        for c in channels:
            r = (measured.values[c][window] - y[c][window]) / TOLERANCE[c]
            total += float(np.nansum(r * r))
        return total

    return place_switches(inputs, run.time_s, t_n, n, *_valid_samples(run, "power_kW"),
                          misfit)


def run_fit(path: str | Path, spec: Spec, fit_fraction: float = 0.6, alpha: float = 0.01,
            nodes: int = 11, grid_s: float = 60.0, candidates: list[str] | None = None,
            min_gain: float = 0.25, progress: Callable[[str], None] | None = None,
            fem_level: int | None = 0, model: str = "lumped",
            base_extra: tuple[str, ...] | None = None, blocks: int = 1,
            cv_blocks: int = 5) -> FitReport:
    """The whole loop (module docstring). ``model``: "lumped" calibrates the base parameters
    on the lumped grey box anchored to the FEM at the spec's values; "fem" calibrates them on
    the FEM reference itself (level ``fem_level``), then anchors the lumped grey box there
    and selects effects on it. ``base_extra``: names of EXTRA_BASE_PARAMS calibrated with
    the base (lumped calibration only). ``blocks``: the run is cut into that many blocks, of
    which about 1 - ``fit_fraction`` validate, spread over the run (1: the fit window is the
    first ``fit_fraction``). ``cv_blocks``: blocked cross-validation of the base and the
    final model over that many blocks, each left out in turn (compare.fit.calibrate.
    cross_validate; 0: none)."""
    from compare.fit.residuals import diagnose

    t0 = time.perf_counter()
    say = progress or (lambda _m: None)
    prep = calibrate_base(path, spec, fit_fraction, nodes, grid_s, progress, fem_level, model,
                          base_extra, blocks)
    run, channels, inputs, measured = prep.run, prep.channels, prep.inputs, prep.measured
    cal, base, spec_values, anchor = prep.cal, prep.base, prep.spec_values, prep.anchor
    fem_cal_info = prep.fem_calibration
    say("reading the events (speed steps) of the raw samples")
    events = event_tests(run, cal.gb, base.theta, channels, alpha)
    sel = forward_selection(cal, candidates, alpha, base=base, min_gain=min_gain, events=events)
    final = sel.final
    for fit in (sel.base, final):  # nothing impossible is written (issue 14)
        check_plausible(np.concatenate([fit.model[c] for c in channels if c != "P1"] or
                                       [np.ones(1)]), 0.0, str(path))
        if "P1" in channels and not np.all(np.isfinite(fit.model["P1"])):
            raise SolverError(f"{path}: P1: the calibrated model's growth is not finite; fix: "
                              "check the run's inputs (speed, power, torque) for values far "
                              "outside the spec's operating range")
    ins = {"speed": np.concatenate([[inputs.speed_rpm[0]], inputs.speed_rpm]),
           "power": np.concatenate([[inputs.power_kW[0]], inputs.power_kW]),
           "T_env": np.concatenate([[inputs.T_env_K[0]], inputs.T_env_K])}
    # each candidate's signature: what it would add to the final model (a third of its range)
    signatures: dict[str, dict[str, np.ndarray]] = {}
    gb_final = cal.gb.variant(final.effects, final.lag_channel)
    for name, e in EFFECTS.items():
        if name in final.effects or name == "sensor_lag":
            continue
        g = cal.gb.variant(final.effects + (name,), final.lag_channel)
        th = dict(final.theta)
        th.update({p.name: p.lo + (p.hi - p.lo) / 3 if p.lo >= 0 else p.hi / 3 for p in e.params})
        with_e, without = g.simulate(th), gb_final.simulate(final.theta)
        signatures[name] = {c: with_e[c] - without[c] for c in channels}
    res_b = _residuals(measured, sel.base.model, channels)
    res_a = _residuals(measured, final.model, channels)
    sig_flat = {f"{n}:{c}": s[c] for n, s in signatures.items() for c in channels
                if np.nanstd(s[c]) > 1e-12 * max(np.nanmax(np.abs(s[c])), 1e-300)
                and np.nanmax(np.abs(s[c])) > 0}
    dt = float(np.median(np.diff(inputs.grid_s)))
    diag_b = diagnose(res_b, dt, ins, sig_flat, alpha=alpha)
    diag_a = diagnose(res_a, dt, ins, sig_flat, alpha=alpha)
    # unexplained: in some channel the final residual is structured AND material: its
    # validation RMS above a quarter of the tolerance (clean FEM-anchored runs leave at most
    # about a tenth), or more than 5 % of the validation samples outside the tolerance
    errs = final.errors["validation"]
    structured = [c for c in channels if not diag_a.channels[c].whiteness.white]
    material = [c for c in structured if errs[c].get("n") and (
        errs[c]["rmse_w"] > MATERIAL_RMS or errs[c]["within_tolerance"] < 0.95)]
    unexplained = bool(material)
    text = ""
    if unexplained:
        worst = ", ".join(f"{c} (RMS {errs[c]['rmse_w']:.2f} of its tolerance, "
                          f"{100 * (1 - errs[c]['within_tolerance']):.0f} % of the validation "
                          "samples outside it)" for c in material)
        text = (f"no candidate effect explains the remaining residual in {worst}: "
                + diag_a.unexplained_description(among=material))
    elif structured:
        text = ("the residual is still serially correlated in " + ", ".join(structured)
                + " but within the tolerances on the validation window (model-form error "
                "below the tolerances: the lumped model's sensitivities and the FEM level); no "
                "effect is named for it")
    ranges = {k: (p.lo, p.hi) for k, p in cal.gb.parameters().items()}
    adequacy = base_adequacy(sel.base.errors, sel.base.theta, spec_values,
                             cal.prior_z(sel.base), ranges)
    adequacy_final = base_adequacy(final.errors, final.theta, spec_values, cal.prior_z(final),
                                   ranges)
    adequacy["with_effects"] = adequacy_final
    adequacy["verdict"] = verdict_text(adequacy, adequacy_final, list(final.effects))
    warns = extrapolation_warnings(inputs.grid_s, inputs.speed_rpm, inputs.load_torque_Nm,
                                   measured.fit_points())
    warns += [f"the speed changed from {g.speed_before_rpm:.0f} to {g.speed_after_rpm:.0f} rpm "
              f"inside a logging gap ({g.start_s / 3600:.2f}-{g.end_s / 3600:.2f} h); the change "
              f"is placed at {g.switch_s / 3600:.2f} h, where {prep.switches_placed_by} fits "
              "the hour after the gap best (compare.fit.gaps)" for g in prep.gap_switches]
    cv = {}
    if cv_blocks:
        say(f"cross-validating over {cv_blocks} blocks")
        cv = {"base": cross_validate(cal, sel.base, cv_blocks),
              "final": cross_validate(cal, final, cv_blocks)}
    return FitReport(run, spec, channels, measured, inputs, sel, diag_b, diag_a, unexplained,
                     text, signatures, time.perf_counter() - t0, alpha, anchor, cal.floor,
                     cal.prior_z(final) or None, model, fem_cal_info, adequacy, warns,
                     {k: t.to_dict() for k, t in events.items()}, cv, prep.gap_switches)


#: least_squares function evaluations of the FEM fit with priors (each iteration adds a
#: Jacobian of six FEM runs, ~3.5 s each for 16 h on the 60 s grid at level 0; alpha_eff
#: costs none). On the 16 h mount_conduction synthetic run it stops at this limit, with the
#: data cost flat to 0.1 % for the last five iterations and the parameters within 3e-4 of a
#: fit started elsewhere (from the anchored lumped fit with priors)
FEM_MAX_NFEV = 12
#: ... and of the FEM fit without priors, which only sets the data's weight against the priors
#: and the noise floor: after 5 evaluations (36 FEM runs) both are those of 12 (71 runs) to
#: 0.02 % on that run; the remaining iterations creep along a flat valley
FEM_FREE_NFEV = 5


def _calibrate_on_fem(cal: Calibrator, fem_level: int, say: Callable[[str], None]):
    """The base parameters calibrated on the FEM reference (compare.fit.femgrey) with the same
    priors, windows and floor as the lumped path; then ``cal``'s grey box anchored to the FEM
    at the calibrated point, and ``cal`` given the FEM calibrator's priors and floor.

    Returns (the FEM base fit, the anchor at the calibrated point, a summary for the report).
    """
    from compare.fit.discrepancy import Discrepancy
    from compare.fit.femgrey import FemGreyBox

    t0 = time.perf_counter()
    gb = cal.gb
    channels = list(cal.channels)
    theta_spec = default_theta(base_params(gb.drive))
    plain = gb.plain()
    say(f"building the FEM reference (level {fem_level}) for the calibration")
    fem = FemGreyBox(gb.spec, gb.drive, gb.inputs, gb.nodes, fem_level,
                     progress=lambda m: say("  " + m))
    # a warm start: the free fit of the lumped grey box anchored at the spec's values, as the
    # lumped path calibrates it (seconds)
    fem_spec = fem.simulate(theta_spec)
    lumped_spec = plain.simulate(theta_spec)
    gb.discrepancy = {c: fem_spec[c] - lumped_spec[c] for c in channels}
    say("warm start: calibrating the anchored lumped model")
    start = cal.fit()
    fcal = Calibrator(fem, cal.measured, channels, max_nfev=FEM_MAX_NFEV, progress=say)
    say("calibrating the base parameters on the FEM reference, without priors")
    # as in the lumped path: the fit without priors sets the data's weight against them
    free_fit, base = fcal.fit_with_prior(theta_spec, start=start.theta,
                                         free_nfev=FEM_FREE_NFEV, say=say)
    theta_cal = {k: base.theta.get(k, p.default) for k, p in BASE_PARAMS.items()}
    # re-anchor: the lumped model plus [FEM - lumped] at the calibrated point is the FEM
    # there; the selection of effects runs on it, from the calibrated point
    fem_cal = fem.simulate(theta_cal)
    lumped_cal = plain.simulate(theta_cal)
    offsets = {c: fem_cal[c] - lumped_cal[c] for c in channels}
    gb.discrepancy = offsets
    cal.prior, cal.prior_scale, cal.floor = dict(fcal.prior), fcal.prior_scale, fcal.floor
    seconds = time.perf_counter() - t0
    anchor = Discrepancy(theta_cal, offsets,
                         {c: float(np.sqrt(np.mean(offsets[c] ** 2))) for c in channels},
                         fem_level, seconds)
    info = {"fem_level": fem_level, "fem_runs": fem.fem_runs,
            "fem_seconds": fem.fem_seconds, "seconds": seconds,
            "evaluations": {"free": free_fit.nfev, "with_priors": base.nfev},
            "max_nfev": {"free": FEM_FREE_NFEV, "with_priors": FEM_MAX_NFEV},
            "warm_start": {k: start.theta[k] for k in BASE_PARAMS}}
    say(f"FEM calibration: {fem.fem_runs} FEM runs, {seconds:.0f} s")
    return base, anchor, info


# ---------------------------------------------------------------------- report files
def save_report(rep: FitReport, out: Path, pictures: bool = True) -> list[Path]:
    from spindle.outputs import atomic_write, write_json

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    doc = rep.to_dict()
    write_json(out / "report.json", doc)
    files = [out / "report.json"]
    pngs: list[tuple[str, str]] = []
    if pictures:
        pngs = _pictures(rep, out)
        files += [out / name for name, _ in pngs]
    atomic_write(out / "report.html", lambda tmp: tmp.write_text(_html(rep, doc, out, pngs),
                                                                   "utf-8"))
    files.append(out / "report.html")
    return files


def _measured(run: BenchRun, channels: list[str], grid_s: np.ndarray, fit_fraction: float,
              blocks: int) -> Measured:
    """The measured channels on the model grid, with the windows; refuses a channel with too
    few samples in either window."""
    if not 1 <= blocks <= 20:
        raise InputError("command line", "--blocks", f"{blocks} is outside 1..20",
                         "cut the run into 1 (one split) to 20 blocks, e.g. 5")
    values = {}
    for c in channels:
        t, y = run.channel(c)
        values[c] = resample(t, y, grid_s)
    measured = Measured(grid_s, values, fit_fraction, blocks)
    for c in channels:
        if measured.mask(c, "fit").sum() < 10 or measured.mask(c, "validation").sum() < 5:
            raise InputError(str(run.path), c, "has too few samples in the fit or validation "
                             "window", "export a run that measures this channel throughout, "
                             "or drop it")
    return measured


def _spans_text(measured: Measured) -> str:
    return ", ".join(f"{a / 3600:.2f}-{b / 3600:.2f} h" for a, b, w in measured.spans()
                     if w == "validation")


def _cv_html(doc: dict) -> str:
    cv = doc.get("cross_validation") or {}
    if not cv:
        return ""
    rows = []
    for key, label in (("base", "base model"), ("final", "final model")):
        for c, e in cv[key]["pooled"].items():
            rows.append([label, c, e["rmse"], e["max"], e["unit"], 100 * e["within_tolerance"]])
    return (f"<h2>Blocked cross-validation ({cv['final']['blocks']} blocks, each held out "
            "once)</h2><p>Each block refitted without it and simulated open loop: the error "
            "where the model was not calibrated, over the run's whole operating range.</p>"
            + html_table(["model", "channel", "rms", "max", "unit", "% within tolerance"], rows,
                         ["s", "s", ".3f", ".3f", "s", ".0f"]))


def _pictures(rep: FitReport, out: Path) -> list[tuple[str, str]]:
    from compare.fit.residuals import plot_acf, plot_cumulated_periodogram
    from spindle.outputs import atomic_write
    from spindle.plots import pyplot

    plt = pyplot()
    g = rep.measured.grid_s / 3600
    sel = rep.selection
    made = []
    n = len(rep.channels)
    fig, axes = plt.subplots(n, 2, figsize=(13, 2.8 * n), layout="constrained", squeeze=False)
    for i, c in enumerate(rep.channels):
        scale, off, unit = edge_absolute(c)
        tol = TOLERANCE[c] * scale
        meas = rep.measured.values[c] * scale - off
        for j, (fit, label) in enumerate(((sel.base, "before"), (sel.final, "after"))):
            ax = axes[i, j]
            model = fit.model[c] * scale - off
            ax.fill_between(g, model - tol, model + tol, color="tab:blue", alpha=0.15,
                            label=f"model ±{tol:g} {unit}")
            ax.plot(g, model, color="tab:blue", ls="--", lw=1, label="model")
            ax.plot(g, meas, color="black", lw=0.8, label="measured")
            for a, b, w in rep.measured.spans():
                if w == "validation":
                    ax.axvspan(a / 3600, b / 3600, color="tab:orange", alpha=0.08, lw=0)
            ax.set_ylabel(f"{c} [{unit}]")
            ax.set_title(f"{c} {label}" + (f" (+ {', '.join(fit.effects)})" if fit.effects
                                            else " (base model)"), fontsize=9)
            ax.grid(alpha=0.3)
            if i == 0:
                ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("time [h] (shaded: validation window)")
    atomic_write(out / "fit_channels.png", lambda tmp: fig.savefig(tmp, dpi=110))
    plt.close(fig)
    made.append(("fit_channels.png", "measured against the model, before and after, with the "
                 "tolerance bands (paper Fig. 13)"))
    fig, axes = plt.subplots(n, 3, figsize=(14, 2.6 * n), layout="constrained", squeeze=False)
    dt = float(np.median(np.diff(rep.measured.grid_s)))
    for i, c in enumerate(rep.channels):
        rb = (rep.measured.values[c] - sel.base.model[c]) / TOLERANCE[c]
        ra = (rep.measured.values[c] - sel.final.model[c]) / TOLERANCE[c]
        ax = axes[i, 0]
        ax.plot(g, rb, lw=0.8, color="C0", label="before")
        ax.plot(g, ra, lw=0.8, color="C1", label="after")
        ax.axhspan(-1, 1, color="0.9")
        ax.set_ylabel(f"{c} residual / tol")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
        first = True
        for r, colour, label in ((rb, "C0", "before"), (ra, "C1", "after")):
            if (~np.isnan(r)).sum() > 20:
                plot_acf(axes[i, 1], r, 40, 0.01, dt, color=colour, label=label, band=first)
                plot_cumulated_periodogram(axes[i, 2], r, 0.01, dt, color=colour, label=label,
                                           band=first)
                first = False
        axes[i, 1].legend(fontsize=7, loc="upper right")
        axes[i, 2].legend(fontsize=7, loc="lower right")
        axes[i, 1].set_title(f"{c}: ACF (before, after)", fontsize=9)
        axes[i, 2].set_title(f"{c}: cumulated periodogram (before, after)", fontsize=9)
    atomic_write(out / "fit_residuals.png", lambda tmp: fig.savefig(tmp, dpi=110))
    plt.close(fig)
    made.append(("fit_residuals.png", "residuals before and after (in tolerance units), their "
                 "autocorrelation and cumulated periodograms"))
    if sel.steps:
        st = sel.steps[0]
        fig, axes = plt.subplots(1, n, figsize=(4.5 * n, 3.2), layout="constrained",
                                 squeeze=False)
        before_it = sel.base
        with_it = st.fit
        for i, c in enumerate(rep.channels):
            ax = axes[0, i]
            scale = edge_scale(c)
            ax.plot(g, (rep.measured.values[c] - before_it.model[c]) * scale, lw=0.8,
                    label="residual of the base model")
            ax.plot(g, (with_it.model[c] - before_it.model[c]) * scale, lw=1.2,
                    label=f"{st.effect} signature")
            ax.set_title(c, fontsize=9)
            ax.grid(alpha=0.3)
        axes[0, 0].legend(fontsize=7)
        atomic_write(out / "fit_signature.png", lambda tmp: fig.savefig(tmp, dpi=110))
        plt.close(fig)
        made.append(("fit_signature.png", f"the base model's residual against the accepted "
                     f"effect's signature ({st.effect})"))
    return made


def _html(rep: FitReport, doc: dict, out: Path, pngs: list[tuple[str, str]]) -> str:
    def err_table(block: dict) -> str:
        rows = [[window, c, e["rmse"], e["max"], e["bias"], e["unit"],
                 100 * e["within_tolerance"]]
                for window in ("fit", "validation") for c, e in block.get(window, {}).items()]
        return html_table(["window", "channel", "RMSE", "max", "bias", "unit",
                           "within tolerance [%]"], rows,
                          ["s", "s", ".3f", ".3f", "+.3f", "s", ".1f"])

    eff = _effects_html(doc)
    anchor = doc.get("fem_anchor")
    if anchor and rep.calibration_model == "fem":
        z = {k: v for k, v in (doc["parameters_prior_z"] or {}).items()}
        fc = doc["fem_calibration"] or {}
        anchor_html = (
            f"<p>Calibration model: <b>fem</b>. The base parameters were calibrated on the FEM "
            f"reference itself (level {anchor['fem_level']}; {fc.get('fem_runs', 0)} FEM runs, "
            f"{fc.get('seconds', 0.0):.0f} s); the effects were selected on the lumped model "
            "anchored to the FEM at the calibrated values. FEM minus lumped there, RMS: "
            + ", ".join(f"{c} {v * edge_scale(c):.3g} {edge_unit(c)}"
                        for c, v in anchor["fem_minus_lumped_rms"].items())
            + ". Base parameters in prior standard deviations from the spec's values "
            "(|z| > 2.58 is implausible): " + ", ".join(f"{k} {v:+.2f}" for k, v in z.items())
            + ".</p>")
    elif anchor:
        z = {k: v for k, v in (doc["parameters_prior_z"] or {}).items()}
        anchor_html = (
            "<p>Calibration model: lumped. "
            f"Model: the lumped model anchored to the FEM reference (level "
            f"{anchor['fem_level']}) on this run's inputs; FEM minus lumped at the spec's values, "
            "RMS: " + ", ".join(f"{c} {v * edge_scale(c):.3g} {edge_unit(c)}"
                                for c, v in anchor["fem_minus_lumped_rms"].items())
            + ". Base parameters in prior standard deviations from the spec's values "
            "(|z| > 2.58 is implausible): " + ", ".join(f"{k} {v:+.2f}" for k, v in z.items())
            + ".</p>")
    else:
        anchor_html = ("<p>Calibration model: lumped. Model: the lumped model alone, no "
                       "priors (--lumped-only).</p>")
    params = html_table(
        ["name", "value", "95 %", "unit", "identifiable", "meaning"],
        [[p["name"], p["value"], f"{p['ci95'][0]:.4g} .. {p['ci95'][1]:.4g}", p["unit"],
          "yes" if p["identifiable"] else "NO", p["meaning"]] for p in doc["parameters"]],
        ["s", ".4g", "s", "s", "s", "s"])
    unexpl = doc["unexplained"]
    return html_page("spindle-verify fit", [
        f"<h1>Fit of {html.escape(str(rep.run.path))} to {html.escape(rep.spec.name)}</h1>",
        f"<p>Channels {', '.join(rep.channels)}; validation window "
        f"{_spans_text(rep.measured)}, the "
        f"rest fits; likelihood-ratio level {rep.alpha:g}; {rep.runtime_s:.1f} s.</p>",
        _cv_html(doc),
        anchor_html,
        _adequacy_html(doc),
        "<h2>Effects accepted (in order)</h2>" + eff,
        _events_html(doc),
        f"<p><b>Unexplained:</b> {'yes' if unexpl['unexplained'] else 'no'}. "
        f"{html.escape(unexpl['description'])}</p>",
        "<h2>Error before</h2>" + err_table(doc["error_before"]),
        "<h2>Error after</h2>" + err_table(doc["error_after"])
        + "".join(f"<p>{html.escape(n)}</p>" for n in error_notes(doc)),
        "<h2>Calibrated parameters (95 % intervals)</h2>" + params,
        *[html_figure(out / n, c) for n, c in pngs]])


def error_notes(doc: dict) -> list[str]:
    """Plain remarks where the validation error after the fit does not read one way: the RMS
    fell but the largest error rose (or the other way round)."""
    notes = []
    before = doc["error_before"].get("validation", {})
    for c, a in doc["error_after"].get("validation", {}).items():
        b = before.get(c)
        if not b or "rmse" not in a or "rmse" not in b:
            continue
        unit = a["unit"]
        if a["rmse"] < b["rmse"] and a["max"] > b["max"]:
            notes.append(f"{c}: the validation RMS fell ({b['rmse']:.3f} → {a['rmse']:.3f} "
                         f"{unit}) but the largest error rose ({b['max']:.3f} → {a['max']:.3f} "
                         f"{unit}): the final model follows the window better overall and "
                         "misses more at its worst instant; the channel plot shows where.")
        elif a["rmse"] > b["rmse"] and a["max"] < b["max"]:
            notes.append(f"{c}: the largest validation error fell ({b['max']:.3f} → "
                         f"{a['max']:.3f} {unit}) but the RMS rose ({b['rmse']:.3f} → "
                         f"{a['rmse']:.3f} {unit}).")
    return notes


def p_text(p: float | None) -> str:
    """A p-value as people read it (one below double precision's range is not 0)."""
    if p is None or not math.isfinite(p):
        return "n/a"
    return "< 1e-300" if p < 1e-300 else f"{p:.2g}"


def _effects_html(doc: dict) -> str:
    """The accepted effects: each parameter with its value, 95 % interval and unit, the
    evidence (the event test's statistic, or the likelihood-ratio test) and what needed it."""
    if not doc["effects"]:
        return "<p>None accepted.</p>"
    units = {p.name: p.unit for e in EFFECTS.values() for p in e.params}
    rows, notes = [], []
    for e in doc["effects"]:
        test = next((t for t in (doc.get("events") or {}).values()
                     if e["needed_by"] == "event" and t["effect"] == e["name"]
                     and (e["name"] != "sensor_lag"
                          or t["channel"] == e["parameters"].get("channel"))), None)
        evidence = (f"event test on {test['channel']}: z = {test['z'] or math.nan:.1f}, "
                    f"p = {p_text(test['p_value'])}" if test else
                    f"likelihood ratio: p = {p_text(e['p_value'])}, ΔBIC = {e['delta_bic']:.1f}")
        for k, v in e["parameters"].items():
            if not isinstance(v, int | float):
                continue
            lo, hi = e["confidence_intervals"].get(k, (math.nan, math.nan))
            rows.append([e["name"], k, f"{v:.4g}", f"{lo:.4g} .. {hi:.4g}", units.get(k, ""),
                         evidence, e["needed_by"]])
        notes.append(f"<li><b>{html.escape(e['name'])}</b>: {html.escape(e['explanation'])}"
                     "</li>")
    return (html_table(["effect", "parameter", "value", "95 %", "unit", "evidence",
                        "needed by"], rows, ["s"] * 7) + "<ul>" + "".join(notes) + "</ul>")


def _events_html(doc: dict) -> str:
    """Every event test of the raw samples: what it reads, its estimate and statistic, and
    whether it applied to this run."""
    events = doc.get("events") or {}
    if not events:
        return ""
    rows = []
    for label, t in events.items():
        applies = t["p_value"] is not None and math.isfinite(t["p_value"])
        meaning = t["meaning"]
        if t.get("material") is False and t.get("peak_effect"):
            ch, v = max(t["peak_effect"].items(), key=lambda kv: kv[1] / TOLERANCE[kv[0]])
            size = f"{v * edge_scale(ch):.2f} {edge_unit(ch)}"
            meaning += (f"; at its estimate it moves {ch} by at most {size}, less than the "
                        "tolerance: not material, not named")
        rows.append([label, t["channel"],
                     f"{t['estimate']:.4g} ± {t['se']:.2g}" if applies else "",
                     t["unit"], f"{t['z']:.1f}" if applies else "", p_text(t["p_value"]),
                     meaning])
    return ("<h2>Event tests (raw samples)</h2><p>Effects with a signature the thermal "
            "model's slow misfit cannot produce are judged on these alone where they apply "
            "(docs/fit.md).</p>"
            + html_table(["test", "channel", "estimate ± se", "unit", "z", "p", "what it reads"],
                         rows, ["s"] * 7))


def _adequacy_html(doc: dict) -> str:
    """The base-adequacy verdict and the extrapolation warnings, first thing in the report."""
    ad = doc.get("base_adequacy")
    if not ad:
        return ""
    verdict = "adequate" if ad["adequate"] else "inadequate"
    rows = "".join(f"<tr><td>{html.escape(c)}</td>" + "".join(
        f"<td>{w.get(k, float('nan')):.2f}</td>" for k in ("fit", "validation")) + "</tr>"
                   for c, w in ad["channels"].items())
    warns = "".join(f"<li>{html.escape(w)}</li>" for w in doc.get("warnings") or [])
    return (f"<h2>Base model: {verdict}</h2><p>{html.escape(ad['verdict'])}</p>"
            "<table><tr><th>channel</th><th>fit RMS / tolerance</th>"
            f"<th>validation RMS / tolerance</th></tr>{rows}</table>"
            + (f"<p><b>Warnings</b></p><ul>{warns}</ul>" if warns else ""))


def report_summary_text(rep: FitReport) -> str:
    doc = rep.to_dict()
    lines = [f"{rep.run.path}: {len(rep.run.time_s)} rows, {rep.run.duration_s / 3600:.2f} h, "
             f"channels {', '.join(rep.channels)}; {rep.runtime_s:.1f} s"]
    if rep.calibration_model == "fem":
        fc = doc["fem_calibration"] or {}
        lines.append(f"  calibration model: fem (base parameters calibrated on the FEM level "
                     f"{fc.get('fem_level')}: {fc.get('fem_runs')} FEM runs, "
                     f"{fc.get('seconds', 0.0):.0f} s; effects selected on the lumped model "
                     "anchored there)")
    else:
        lines.append("  calibration model: lumped")
    ad = doc.get("base_adequacy")
    if ad:
        lines.append(f"  base model {'adequate' if ad['adequate'] else 'INADEQUATE'}: "
                     f"{ad['verdict']}")
    for w in doc.get("warnings") or []:
        lines.append(f"  warning: {w}")
    for e in doc["effects"]:
        pars = ", ".join(f"{k} = {v:.4g}" if isinstance(v, int | float) else f"{k} = {v}"
                         for k, v in e["parameters"].items())
        lines.append(f"  effect {e['name']}: {pars} (p = {p_text(e['p_value'])}, "
                     f"delta BIC {e['delta_bic']:.1f}, needed by {e['needed_by']})"
                     + (f"; {', '.join(e['at_bound'])} on its range's bound: the effect is "
                        "at least this large in magnitude" if e.get("at_bound") else ""))
    if not doc["effects"]:
        lines.append("  no effect accepted")
    lines.append(f"  unexplained: {doc['unexplained']['unexplained']}"
                 + (f" - {doc['unexplained']['description']}"
                    if doc["unexplained"]["description"] else ""))
    for key, label in (("error_before", "before"), ("error_after", "after")):
        v = doc[key].get("validation", {})
        lines.append(f"  validation error {label}: " + ", ".join(
            f"{c} {e['rmse']:.3f} {e['unit']} rms / {e['max']:.3f} max" for c, e in v.items()))
    lines += [f"  note: {n}" for n in error_notes(doc)]
    for key, label in (("base", "before"), ("final", "after")):
        pooled = (doc.get("cross_validation") or {}).get(key, {}).get("pooled")
        if pooled:
            lines.append(f"  cross-validated error {label} ({doc['cross_validation'][key]['blocks']}"
                         " blocks, each held out): " + ", ".join(
                             f"{c} {e['rmse']:.3f} {e['unit']} rms" for c, e in pooled.items()))
    odd = {k: v for k, v in (doc.get("parameters_prior_z") or {}).items() if abs(v) > 2.576}
    if odd:
        lines.append("  base parameters still implausible (prior sds from the spec's values): "
                     + ", ".join(f"{k} {v:+.1f}" for k, v in odd.items()))
    bad = doc["not_identifiable"]
    if bad:
        lines.append(f"  not identifiable from this run: {', '.join(bad)}")
    return "\n".join(lines)


def named_effects(doc: dict) -> list[str]:
    """The effects a report's ``to_dict()`` names, a lag with its channel (``sensor_lag(T1)``)."""
    return [e["name"] + (f"({e['parameters']['channel']})" if e["name"] == "sensor_lag"
                         and e["parameters"].get("channel") else "") for e in doc["effects"]]


def selection_trace(doc: dict, event_fields: Sequence[str] = ("estimate", "se", "z",
                                                              "p_value", "material")) -> dict:
    """What a benchmark keeps of a report's ``to_dict()`` to see why an effect was named or
    not: the event tests (``event_fields`` of each), the refitted candidates of the loop
    (gains, validation and cross-validated excess before/after, need, verdict) and the
    calibrated parameters."""
    keys = ("effect", "channel", "round", "gain", "excess_before", "excess_after",
            "cv_before", "cv_after", "peak_effect", "judged_on", "needed_by", "qualifies",
            "accepted")
    return {"events": {k: {f: v.get(f) for f in event_fields}
                       for k, v in doc.get("events", {}).items()},
            "tried": [{k: c.get(k) for k in keys}
                      for c in doc["candidates_tried"] if "qualifies" in c],
            "parameters": {p["name"]: p["value"] for p in doc.get("parameters", [])}}
