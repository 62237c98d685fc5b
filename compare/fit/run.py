"""``spindle-verify fit RUN.csv --spec SPEC --out DIR``: confront the model with a bench run.

1. Ingest the run (spindle.bench), map its channels to the spec's sensors, build the grey
   box's per-interval inputs (spindle.bench_inputs.interval_inputs) and place an operating
   change inside a logging gap (compare.fit.gaps).
2. Anchor the grey box to the FEM reference on the run's inputs (compare.fit.discrepancy) and
   calibrate the base parameters with priors around the spec's values on the fit window
   (compare.fit.calibrate).
3. Read every effect's signature test on the raw samples (compare.fit.signatures, each
   effect's own test), select effects against "something else" by the named criteria
   (compare.fit.select, compare.fit.criteria) and fit "something else" on the final model.
4. Write ``report.json`` and ``report.html`` (compare.fit.report), the verdict first.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from compare.fit.calibrate import TOLERANCE, Calibrator, Fit, Measured
from compare.fit.criteria import Criteria
from compare.fit.effects import LIBRARY
from compare.fit.effects import candidates as candidate_labels
from compare.fit.gaps import unknown_input_spans
from compare.fit.greybox import MAX_NODES, GreyBox, stretch_exponents
from compare.fit.growth_check import check_growth, library_terms
from compare.fit.params import BASE_PARAMS, DEFAULT_BASE_EXTRA, EXTRA_BASE_PARAMS, default_theta
from compare.fit.select import Selection, select
from compare.fit.signatures import Context, EventTest
from compare.fit.start import Start, first_samples, run_start
from spindle.bench import BenchRun, BenchWarning, check_against_spec, read_bench
from spindle.bench_clean import coolant_as_room, without_spikes, without_stuck
from spindle.bench_inputs import (
    Inputs,
    check_power_balance,
    interval_inputs,
    logging_step_s,
    resample,
    valid_samples,
)
from spindle.drive import check_drive_feeds, drive_for
from spindle.errors import InputError, SolverError
from spindle.interval_speed import bearing_friction_W
from spindle.results import check_plausible
from spindle.spec import Spec


def _check_base_extra(base_extra: tuple[str, ...]) -> None:
    unknown = [k for k in base_extra if k not in EXTRA_BASE_PARAMS]
    if unknown:
        raise InputError("command line", "--base-extra", f"unknown parameter {unknown[0]}",
                         f"use {' or '.join(EXTRA_BASE_PARAMS)}")


@dataclass
class BaseCalibration:
    """Where the selection starts: the bench run, its channels, the grey box's inputs, the
    measured data with its windows, the calibrator, the calibrated base fit, the spec's own
    parameter values, and the FEM anchor (None where unused)."""

    run: BenchRun
    channels: list[str]
    inputs: Inputs
    measured: Measured
    cal: Calibrator
    base: Fit
    spec_values: dict[str, float]
    anchor: object | None = None
    #: compare.fit.gaps.GapSwitch per logging gap with an operating change inside
    gap_switches: list = field(default_factory=list)
    #: which model placed them: the calibrated, anchored one (the lumped path) or the spec's
    switches_placed_by: str = "the spec's model"
    #: channels left out before the fit, each with why (a sensor that reads one value)
    left_out: list[str] = field(default_factory=list)
    #: where the run starts (compare.fit.start)
    start: Start | None = None


def calibrate_base(path: str | Path, spec: Spec, fit_fraction: float = 0.6, nodes: int = 11,
                   grid_s: float = 60.0, progress: Callable[[str], None] | None = None,
                   fem_level: int | None = 0, base_extra: tuple[str, ...] | None = None,
                   blocks: int = 1, criteria: Criteria | None = None,
                   workers: int = 1) -> BaseCalibration:
    """Read the run, check it against the spec, anchor the grey box to the FEM reference and
    calibrate the base parameters (arguments as :func:`run_fit`)."""
    from compare.fit.discrepancy import fem_discrepancy

    criteria = criteria or Criteria()
    say = progress or (lambda _m: None)
    asked = base_extra is not None
    base_extra = tuple(DEFAULT_BASE_EXTRA if base_extra is None else base_extra)
    _check_base_extra(base_extra)
    if not 2 <= nodes <= MAX_NODES:
        raise InputError("command line", "--nodes", f"{nodes} is outside 2..{MAX_NODES}",
                         "fit with the 11 nodes of the default, or at most "
                         f"{MAX_NODES} (time and memory grow fast with them)")
    if not 0.2 <= fit_fraction <= 0.9:
        raise InputError("command line", "--fit-fraction", f"{fit_fraction} is outside 0.2..0.9",
                         "fit on 20 % to 90 % of the run, e.g. 0.6")
    say(f"reading {path}")
    run = read_bench(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        channels = check_against_spec(run, spec)
    channels, left_out = without_stuck(run, channels)
    run, spikes = without_spikes(run, channels, criteria.alpha, grid_s)
    left_out += spikes
    left_out += [w for w in [coolant_as_room(run, spec)] if w]
    drive = drive_for(spec)
    if drive is None:
        raise InputError(spec.path, "power_balance.preset", "the spec names no drive",
                         "add [power_balance] preset to the spec")
    unfed = check_drive_feeds(spec, drive)
    if unfed:
        left_out.append(f"the drive '{drive.name}' feeds no heat to the spec's heat source(s) "
                        f"{', '.join(unfed)}: 0 W there (the power balance names its motor "
                        "and bearing sets as the drive file does)")
    raw = interval_inputs(run, grid_s, criteria.gap_min_steps, bearing_friction_W(drive))
    check_power_balance(run, drive, raw.grid_s, raw.speed_rpm, raw.power_kW,
                        raw.load_torque_Nm, criteria.no_load_Nm)
    measured = _measured(run, channels, raw.grid_s, fit_fraction, blocks, criteria)
    plain = GreyBox(spec, drive, raw, nodes, speed_bin_rel=criteria.speed_bin_rel)
    inert = [k for k in base_extra if k in plain.inert_params()]
    if inert and asked:
        raise InputError("command line", "--base-extra", f"{inert[0]} acts on nothing in the "
                         f"spec {spec.name} (it links the bearing seats to the coolant, and "
                         "the spec has no coolant film)", f"leave {inert[0]} out")
    base_extra = tuple(k for k in base_extra if k not in inert)
    if "axial_scale" in base_extra:
        try:  # its lengths must scale as one parameter (compare.fit.greybox)
            stretch_exponents(spec, nodes)
        except InputError:
            if asked:
                raise
            base_extra = tuple(k for k in base_extra if k != "axial_scale")
            left_out.append("axial_scale, a default extra, is not calibrated: the spec's "
                            "lumped network changes its layout when the spindle is stretched "
                            "axially, so its lengths do not scale as one parameter")
    begins = run_start(plain, default_theta(plain.parameters()),
                       first_samples(run, channels, raw.grid_s), criteria)
    raw = replace(raw, prehistory_s=begins.prehistory_s, prehistory_heat_W=begins.heat_W)
    spec_model = GreyBox(spec, drive, raw, nodes, base_extra=base_extra,
                         speed_bin_rel=criteria.speed_bin_rel,
                         p1_reference_s=_late_p1_reference(run, channels, raw.grid_s))
    inputs, switches = _place_gap_switches(run, spec_model, measured, channels, say, criteria)

    def calibrator(on: Inputs) -> Calibrator:
        return Calibrator(replace(spec_model, inputs=on, _cache={}), measured, channels,
                          tol=criteria.optimizer_tol, workers=workers)

    cal = calibrator(inputs)
    spec_values = default_theta(cal.gb.parameters(), [*BASE_PARAMS, *base_extra])
    if "P1" in channels:  # a sign or unit slip the fit could not represent
        check_growth(str(run.path), measured.values["P1"],
                     cal.gb.simulate(spec_values)["P1"], criteria, library_terms(inputs))

    def anchored(cal: Calibrator, start: dict[str, float]) -> tuple[object, Fit]:
        """The FEM anchor on ``cal``'s inputs, set on its grey box, and the base calibrated
        with the priors from ``start``."""
        say(f"solving the FEM reference (level {fem_level}) on this run's inputs")
        anchor = fem_discrepancy(cal.gb, channels, fem_level)
        cal.gb.discrepancy = anchor.offsets
        say("calibrating the base model")
        return anchor, cal.fit_with_prior({**spec_values, **anchor.theta_ref}, start=start)[1]

    anchor = None
    placed_by = "the spec's model"
    # an extra whose spec value is its range's bound (a conductance the spec lacks) starts
    # inside its range: a start on the bound can stall there
    params = cal.gb.parameters()
    start = {k: params[k].lo + 0.05 * (params[k].hi - params[k].lo) for k in base_extra
             if params[k].default <= params[k].lo}
    if fem_level is None:  # the lumped model alone, factors from 1, no priors
        say("calibrating the base model")
        base = cal.fit(start=start)
    else:
        anchor, base = anchored(cal, start)
        if switches:
            # placed by the spec's model, whose level on a spindle the spec only approximates
            # can be kelvins off after the gap and pull the switch to the gap's edge; placed
            # again by the calibrated model, and the base recalibrated on those inputs
            calibrated = replace(cal.gb, inputs=raw, _cache={})
            again, moved = _place_gap_switches(run, calibrated, measured, channels, say,
                                               criteria, base.theta)
            placed_by = "the calibrated model"
            if [m.switch_s for m in moved] != [w.switch_s for w in switches]:
                inputs, switches = again, moved
                cal = calibrator(inputs)
                anchor, base = anchored(cal, base.theta)
    return BaseCalibration(run, channels, inputs, measured, cal, base, spec_values, anchor,
                           switches, placed_by, left_out, begins)


def _late_p1_reference(run: BenchRun, channels: list[str], grid_s: np.ndarray
                       ) -> float | None:
    """The time [s] of P1's first valid sample, where the format zeroes it, if that is after
    the grid's first interval (a sensor connected late: the model's growth must then be
    counted from there too); else None."""
    if "P1" not in channels:
        return None
    t1 = float(run.channel("P1")[0][0])
    return t1 if t1 > float(grid_s[1]) else None


def _place_gap_switches(run: BenchRun, model: GreyBox, measured: Measured,
                        channels: list[str], say: Callable[[str], None], criteria: Criteria,
                        theta: dict[str, float] | None = None) -> tuple[Inputs, list]:
    """compare.fit.gaps.place_switches on ``model``'s inputs with the misfit over the hour
    after each gap of ``model`` (its extras, FEM anchor and P1 reference) at ``theta``
    (default: the spec's values, before the FEM runs)."""
    from compare.fit.gaps import gaps_with_change, place_switches

    t_n, n = valid_samples(run, "speed_rpm")
    torque = valid_samples(run, "load_torque_Nm") if run.load_torque_measured else None
    inputs = model.inputs
    if not gaps_with_change(run.time_s, t_n, n, inputs.grid_s, criteria=criteria,
                            torque=torque):
        return inputs, []
    say("placing the operating change inside a logging gap")
    cache: dict = {}

    def misfit(trial: Inputs, end_s: float) -> float:
        for k in [k for k in cache if isinstance(k, tuple) and k[:1] == ("src",)]:
            del cache[k]  # the heat sources depend on the inputs, the network does not
        gb = replace(model, inputs=trial, _cache=cache)
        y = gb.simulate(default_theta(gb.parameters()) if theta is None else theta)
        window = (trial.grid_s >= end_s) & (trial.grid_s <= end_s + criteria.gap_judge_s)
        total = 0.0
        for c in channels:
            r = (measured.values[c][window] - y[c][window]) / TOLERANCE[c]
            total += float(np.nansum(r * r))
        return total

    return place_switches(inputs, run.time_s, t_n, n, *valid_samples(run, "power_kW"),
                          misfit, criteria, torque)


def signature_tests(run: BenchRun, gb: GreyBox, theta: dict[str, float], channels,
                    criteria: Criteria) -> dict[str, EventTest]:
    """Every effect's signature test on the raw samples, by candidate label, in the library's
    order (a test may read an earlier one: compare.fit.signatures.Context)."""
    ctx = Context(run, gb, theta, channels, criteria)
    for effect in LIBRARY.values():
        if not effect.missing_in(gb.spec):
            ctx.tests.update(effect.signature(ctx))
    return ctx.tests


@dataclass
class FitReport:
    run: BenchRun
    spec: Spec
    channels: list[str]
    measured: Measured
    inputs: Inputs
    selection: Selection
    signatures: dict[str, EventTest]
    diagnostics_before: object
    diagnostics_after: object
    runtime_s: float
    criteria: Criteria
    anchor: object = None  # compare.fit.discrepancy.Discrepancy; None: lumped alone, no priors
    floor: dict | None = None  # per channel [tolerance units]
    prior_z: dict | None = None  # final base parameters, prior sds from the spec's values
    #: compare.fit.adequacy.base_adequacy of the calibrated base model ("with_effects": final)
    base_adequacy: dict | None = None
    #: operating points of the validation window the fit window never saw, gap switches
    warnings: list[str] = field(default_factory=list)
    #: compare.fit.linear.Local.cross_validation_report of the base and the final model
    cross_validation: dict = field(default_factory=dict)
    #: compare.fit.gaps.GapSwitch per logging gap with an operating change inside
    gap_switches: list = field(default_factory=list)
    #: spans (start, end) [s] whose inputs are not known, where something else is not looked
    #: for (compare.fit.gaps.unknown_input_spans)
    unknown_inputs: list = field(default_factory=list)
    #: where the run starts (compare.fit.start)
    start: Start | None = None

    def to_dict(self) -> dict:
        from compare.fit.report import report_dict

        return report_dict(self)

    def save(self, out: str | Path, pictures: bool = True) -> list[Path]:
        """report.json, report.html, the tables and (``pictures``) the PNGs into ``out``
        (what ``spindle-verify fit`` writes); the paths written."""
        from compare.fit.report import save_report

        return save_report(self, Path(out), pictures)


def run_fit(path: str | Path, spec: Spec, fit_fraction: float = 0.6,
            alpha: float | None = None, nodes: int = 11, grid_s: float = 60.0,
            candidates: list[str] | None = None, min_gain: float | None = None,
            progress: Callable[[str], None] | None = None, fem_level: int | None = 0,
            base_extra: tuple[str, ...] | None = None, blocks: int = 1,
            cv_blocks: int | None = None, criteria: Criteria | None = None,
            workers: int = 1) -> FitReport:
    """The whole loop (module docstring): the base parameters are calibrated on the lumped
    grey box anchored to the FEM (level ``fem_level``; None: the lumped model alone, no
    priors) at the spec's values. ``base_extra``: names of EXTRA_BASE_PARAMS calibrated with
    the base. ``blocks``: the run is cut into that many blocks, of which about 1 -
    ``fit_fraction`` validate, spread over the run (1: the fit window is the first
    ``fit_fraction``). ``alpha``, ``min_gain`` (the cross-validated gain asked, a share) and
    ``cv_blocks`` set the criteria of those names over ``criteria`` (default: the table,
    compare.fit.criteria; None leaves an entry as it is there); ``candidates``:
    the effects to try (default: the library). ``workers``: processes that share each
    calibration's Jacobian columns (compare.forked; default 1: on some runs more
    processes move the parameters' late digits, docs/fit.md "Options")."""
    from compare.fit.adequacy import base_adequacy, extrapolation_warnings
    from compare.residuals import diagnose
    from spindle.arguments import whole_number

    t0 = time.perf_counter()
    workers = whole_number(workers, "workers", 1)
    criteria = (criteria or Criteria()).with_options(alpha=alpha, cv_gain=min_gain,
                                                     cv_blocks=cv_blocks)
    unknown = [c for c in (candidates or []) if c not in LIBRARY]
    if unknown:  # before any work
        raise InputError("command line", "--candidates", f"unknown effect {unknown[0]}",
                         f"use some of {', '.join(LIBRARY)}")
    lacks = {c: LIBRARY[c].missing_in(spec) for c in candidates or LIBRARY}
    if candidates and any(lacks.values()):
        c = next(c for c, need in lacks.items() if need)
        raise InputError("command line", "--candidates", f"{c} needs {lacks[c]}, which the "
                         f"spec {spec.name} lacks", f"leave {c} out")
    candidates = [c for c, need in lacks.items() if not need]  # the rest act on nothing
    say = progress or (lambda _m: None)
    prep = calibrate_base(path, spec, fit_fraction, nodes, grid_s, progress, fem_level,
                          base_extra, blocks, criteria, workers)
    run, channels, inputs, measured = prep.run, prep.channels, prep.inputs, prep.measured
    cal, base = prep.cal, prep.base
    say("reading the effects' signatures in the raw samples")
    unknown = unknown_input_spans(run.time_s, inputs.grid_s, criteria)
    sel = select(cal, base, candidate_labels(channels, candidates), criteria,
                 lambda fit: signature_tests(run, cal.gb, fit.theta, channels, criteria), say,
                 unknown_inputs=unknown)
    final = sel.final
    for fit in (sel.base, final):  # nothing impossible is written (issue 14)
        check_plausible(np.concatenate([fit.model[c] for c in channels if c != "P1"] or
                                       [np.ones(1)]), 0.0, str(path))
        if "P1" in channels and not np.all(np.isfinite(fit.model["P1"])):
            raise SolverError(f"{path}: P1: the calibrated model's growth is not finite; fix: "
                              "check the run's inputs (speed, power, torque) for values far "
                              "outside the spec's operating range")
    ins = {k: np.concatenate([[x[0]], x]) for k, x in (
        ("speed", inputs.speed_rpm), ("power", inputs.power_kW), ("T_env", inputs.T_env_K))}
    dt = float(np.median(np.diff(inputs.grid_s)))
    diag_b, diag_a = (diagnose({c: (measured.values[c] - fit.model[c]) / TOLERANCE[c]
                                for c in channels}, dt, ins, alpha=criteria.alpha)
                      for fit in (sel.base, final))
    ranges = {k: (p.lo, p.hi) for k, p in cal.gb.parameters().items()}
    ad_b, ad_a = (base_adequacy(fit.errors, fit.theta, prep.spec_values, cal.prior_z(fit), ranges,
                                criteria, fit.partners) for fit in (sel.base, final))
    adequacy = {**ad_b, "with_effects": ad_a}
    warns = list(prep.left_out) + [t for t in [prep.start.text(), _other_spindle(run, spec)]
                                   if t]
    warns += extrapolation_warnings(inputs.grid_s, inputs.speed_rpm, inputs.load_torque_Nm,
                                    measured.fit_points())
    warns += [f"{g.text()} inside a logging gap ({g.start_s / 3600:.2f}-{g.end_s / 3600:.2f} "
              f"h); the change is placed at {g.switch_s / 3600:.2f} h, where "
              f"{prep.switches_placed_by} fits the hour after the gap best (compare.fit.gaps)"
              for g in prep.gap_switches]
    cv = {}
    if criteria.cv_blocks:
        from compare.fit.linear import local

        say(f"cross-validating over {criteria.cv_blocks} blocks")
        cv = {"base": local(cal, sel.base).cross_validation_report(criteria.cv_blocks),
              "final": local(cal, final).cross_validation_report(criteria.cv_blocks)}
    return FitReport(run, spec, channels, measured, inputs, sel, sel.signatures, diag_b, diag_a,
                     time.perf_counter() - t0, criteria, prep.anchor, cal.floor,
                     cal.prior_z(final) or None, adequacy, warns, cv, prep.gap_switches,
                     unknown, prep.start)


def _other_spindle(run: BenchRun, spec: Spec) -> str:
    """A warning where the run's ``# spindle:`` line does not name the spec it is fitted
    with ("" where it does, or has none)."""
    named = run.metadata.get("spindle", "").strip()
    if not named or spec.name.lower() in named.lower():
        return ""
    text = (f"the run's header names the spindle '{named}' and it is fitted with the spec "
            f"'{spec.name}': check that --spec describes this spindle")
    # on stderr at once too: every figure of the fit rests on the spec
    warnings.warn(BenchWarning(f"{run.path}: {text}"), stacklevel=2)
    return text


def _measured(run: BenchRun, channels: list[str], grid_s: np.ndarray, fit_fraction: float,
              blocks: int, criteria: Criteria) -> Measured:
    """The measured channels on the model grid, with the windows; refuses a channel with too
    few samples in either window."""
    if not 1 <= blocks <= 20:
        raise InputError("command line", "--blocks", f"{blocks} is outside 1..20",
                         "cut the run into 1 (one split) to 20 blocks, e.g. 5")
    step = logging_step_s(run.time_s)
    values = {c: resample(*run.channel(c), grid_s, criteria.gap_min_steps, step) for c in channels}
    measured = Measured(grid_s, values, fit_fraction, blocks)
    for c in channels:
        if measured.mask(c, "fit").sum() < 10 or measured.mask(c, "validation").sum() < 5:
            raise InputError(str(run.path), c, "has too few samples in the fit or validation "
                             "window", "export a run that measures this channel throughout, "
                             "or drop it")
    return measured
