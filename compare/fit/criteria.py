"""Every threshold, window and level the fit's rules use, in one table: :class:`Criteria`.

Each entry has its value, its unit and its reason: a statistical argument, a physical bound,
a sensor's resolution or a computing budget. ``fit``'s options (``--alpha``, ``--min-gain``,
``--cv-blocks``) set the entries of the same names, and every rule that reads them reads them
here; the report lists the table it ran with (:meth:`Criteria.table`) and, for each
candidate, which named criteria it passed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

from compare.fit.signatures import OnsetScale
from spindle.bench_inputs import SPEED_BAND_REL, SPEED_BAND_RPM


def _c(value, unit: str, reason: str):
    return field(default=value, metadata={"unit": unit, "reason": reason})


@dataclass(frozen=True)
class Criteria:
    """The criteria of one fit (module docstring). Frozen: derive another with
    :meth:`with_options`."""

    # ---------------------------------------------------------------- statistics
    alpha: float = _c(
        0.01, "-", "the level of every test: an effect's likelihood-ratio test, each "
        "signature test, the competitor's scan (against its Monte Carlo critical value: "
        "scan_null_tail) and the plausible range of a base parameter (two-sided). At 1 % per "
        "test, the about ten candidates of a run give a false one in under 10 % of clean runs "
        "before the other criteria")
    material_peak: float = _c(
        0.5, "tolerances", "an effect (or the competitor) is named only if at its estimate it "
        "moves one of its channels by half a tolerance at its peak: a smaller term cannot take "
        "a compensation that meets the tolerances out of them, so naming it helps no user")
    open_loop_material_change: bool = _c(
        True, "-", "an effect named by the open loop must also change the fitted model's "
        "prediction (the effect and the base's re-adjustment together) by material_peak on "
        "one of its channels: the open loop's only evidence is that prediction, and an effect "
        "the base re-adjusts around to within half a tolerance changes no compensation built "
        "on the model. The signature route keeps its own evidence")
    plausible_base_route: bool = _c(
        True, "-", "an open-loop effect that does not change the prediction by material_peak "
        "still changes the model where, without it, the calibrated base needs an implausible "
        "value (some |prior z| above implausible_z) and, with it, none: the priors say the "
        "spindle is like its spec within the declared widths, so a base that can imitate the "
        "effect only outside them does not (the adequacy verdict would otherwise blame the spec "
        "for it: 'needs implausible values to fit the run')")
    cv_blocks: int = _c(
        5, "blocks", "blocked cross-validation: each fifth of the run held out in turn; five "
        "blocks of a 16 h run are about 3 h, longer than the slowest time constant (the "
        "housing's, 1-2 h), so a held-out block is not predicted from its neighbours' state")
    cv_gain: float = _c(
        0.25, "-", "an effect judged by the open-loop fit (no signature test applies) must "
        "remove this share of the blocked cross-validated error above the noise floor on its "
        "channels: a law of the inputs predicts the blocks it was not fitted on. A quarter is "
        "five times the scatter of the folds' own refits (a few % on a run with nothing to "
        "find)")
    held_out_misfit_unexplained: bool = _c(
        True, "-", "where the final model misses a channel's tolerance on the held-out "
        "validation window (open-loop RMS above one tolerance), the run is 'unexplained' (with "
        "nothing named) or says 'something else remains' (beside what was named) even if no "
        "localized form of the competitor is significant: with sensor noise a tenth of the "
        "tolerance, an RMS of one tolerance on held-out data is not noise (the test's "
        "false-alarm rate is nil under a correct model), whatever the library took up. 'Base "
        "inadequate' said the same and pointed at the spec alone; the report still gives the "
        "adequacy verdict on the spec. False: such runs end 'nothing named, base inadequate' "
        "or name their effects alone")
    distinct_among_alternatives: bool = _c(
        True, "-", "the distinct criterion weighs a candidate against the other candidates "
        "on its channels that are alternatives to it, not against complements: two candidates "
        "each of which, as the amplitude of its fitted shift, adds a significant gain (at "
        "alpha, one degree of freedom) to the other's (jointly with the base's step) explain "
        "different parts of the run, so naming the larger is no guess between them; forward "
        "selection then judges the other against the model that holds it. False: every other "
        "candidate on a shared channel is a rival")
    open_loop_adequate_model: bool = _c(
        True, "-", "an effect named by the open loop is withdrawn where the final model, with "
        "it, still misses the tolerance of one of the effect's own channels on the held-out "
        "validation window (as for held_out_misfit_unexplained): the open loop's evidence is "
        "the model's likelihood, and the likelihood-ratio test holds only under a model that "
        "explains the data; where it does not, any candidate that moves the channel gains "
        "from what is missing, so the cause is a guess. A misfit on a channel the effect does "
        "not act on leaves its test as it was. A step judged on a model holding a withdrawn "
        "one goes with it; a signature's evidence is the raw samples' and stays")
    competitor_step_s: float = _c(
        1800.0, "s", "the time grid of the competitor's windows: half an hour resolves an "
        "event of a few hours, and a 16 h run gives 32 blocks, 528 windows")
    scan_null_tail: int = _c(
        10, "draws", "the verdict's scan is significant above the critical value of the same "
        "scan on white noise (a Monte Carlo test of its largest statistic, which, unlike a "
        "Bonferroni bound over its thousands of overlapping windows, knows they are nearly "
        "the same test): the 10th largest maximum of 10 / alpha - 1 draws (999 at 1 %), so "
        "the test's level is alpha exactly (its Monte Carlo scatter over seeds and its value "
        "against the Bonferroni bound: docs/figures/scan-null.json)")
    competitor_masses: tuple[str, ...] = _c(
        ("stator", "rotor", "front_bearing", "rear_bearing", "housing", "cooling_sleeve"),
        "part roles", "where the competitor may put an unexplained heat: one mass of each "
        "role a motor spindle's heat passes through (the first of the role found)")

    speed_bin_rel: float = _c(
        0.05, "-", "the grey box evaluates its speed-dependent conductances (films, bearings) "
        "at the interval's speed rounded to a geometric grid of 5 % steps: the films follow "
        "n^0.5-0.8, so they move by at most 4 %, a tenth of their prior sd; a ramp logged on "
        "change then needs a few dozen sets of modes, not one per interval. The heat sources "
        "take the exact speed; a feedback whose heat enters the matrices (a preload's) takes "
        "its heat on the same grid, which moves its term by at most 2.5 %")

    # ---------------------------------------------------------------- base model
    at_bound_rel: float = _c(
        1e-3, "of the range", "a calibrated value within this share of its range from a "
        "bound is reported as on the bound")
    missing_path_W_K: float = _c(
        1.0, "W/K", "a conductance the spec lacks (G_seat_W_K) is reported as needed above "
        "1 W/K: that moves a bearing ring carrying 30-60 W of friction by several kelvin, far "
        "above the sensors' resolution")
    optimizer_tol: float = _c(
        1e-6, "-", "least_squares' ftol and xtol (the relative change of the cost and of the "
        "scaled parameters at which a calibration stops): a computing budget. 1e-8 was "
        "measured on the main and held-out sets: 9 % more time, no verdict better, and the "
        "validation RMS as sensitive to round-off as at 1e-6, since it moves along directions "
        "the run does not determine (docs/fit-history.md, 2026-11-28)")
    refit_nfev: int = _c(
        20, "evaluations", "computing budget of the refit of the candidate that joins the "
        "model, which starts from its Gauss-Newton fit and converges in a few iterations")

    # ---------------------------------------------------------------- input timing
    gap_min_steps: float = _c(
        2.0, "grid steps", "a stretch without any logged row longer than two grid steps is a "
        "logging gap (a bench logging on change writes at least a heartbeat per step)")
    gap_judge_s: float = _c(
        3600.0, "s", "an operating change inside a logging gap is placed where the model fits "
        "the hour after the gap best: long against the rings' settling, short against the run. "
        "Until that hour is over the inputs are not known (what ran inside the gap is a "
        "guess), so something else is not looked for in the gap nor in that hour. That holds "
        "for every gap, not only one with an operating change: the room's and the coolant's "
        "temperatures inside it are interpolated, and a chiller's on-off cycle (tenths of a "
        "kelvin to a kelvin, in minutes to tens of minutes) is shorter than a gap")
    gap_level_s: float = _c(
        300.0, "s", "the speed, power and load levels either side of a gap are read over five "
        "minutes of samples")

    # ---------------------------------------------------------------- signatures: steps
    step_rpm: float = _c(
        200.0, "rpm", "a speed change between two samples larger than this is a step: ten "
        "times a drive's speed scatter (20 rpm) and a tenth of the smallest step of a test "
        "cycle")
    moving_rpm: float = _c(
        300.0, "rpm", "below this a spindle stands: its bearing and motor heat is nil")
    no_load_Nm: float = _c(
        0.5, "N m", "a segment turns without load up to this process torque (a load cell's "
        "zero drift); two load levels either side of a logging gap that differ by more are an "
        "operating change inside it (compare.fit.gaps), as a speed change beyond the drive's "
        "scatter is")
    speed_band_rpm: float = _c(
        SPEED_BAND_RPM, "rpm", "a logged speed within max(20 rpm, 1 %) of the current step "
        "belongs to it: a drive's scatter around its set speed (spindle.bench_inputs)")
    speed_band_rel: float = _c(SPEED_BAND_REL, "-", "as speed_band_rpm")
    step_ramp_s: float = _c(
        30.0, "s", "speed changes beyond step_rpm less than 30 s apart are one step: a "
        "drive's ramp (about 10 s) logged over several samples, with room for an on-change "
        "log's spacing; short against the onset windows (2 min and longer)")
    line_min_samples: int = _c(
        4, "samples", "a straight line before or after a step is read from at least four "
        "samples: two for the line, two degrees of freedom for its standard errors")
    line_min_span: float = _c(
        0.5, "of the window", "and its samples must span half its window: a line through a "
        "burst of samples at one end of the window is extrapolated over the rest")
    onset_min_late_z: float = _c(
        2.0, "se", "a step enters the onset ratio only where its late slope change is two "
        "standard errors from nothing: the ratio is regressed on it, and a regressor with a "
        "relative error above one half biases the slope towards zero and gives it heavy tails "
        "(errors in variables)")
    jump_min_dn2_krpm2: float = _c(
        1.0, "krpm^2", "a step enters P1's jump regression where n^2 changes by 1 krpm^2 "
        "(1000 rpm from standstill, 100 rpm at 5000): a smaller step's jump is under P1's "
        "0.1 um resolution for any shortening below 0.1 um/krpm^2, seven times the FEM's own "
        "for spl2782, so it adds nothing but a thermal transient to the regression")
    jump_before_s: tuple[float, float] = _c(
        (-180.0, -10.0), "s from a step", "the line before a speed step for P1's jump: three "
        "minutes, short against the thermal response, the ramp's last 10 s left out")
    jump_after_s: tuple[float, float] = _c(
        (10.0, 80.0), "s from a step", "the line after it: the drive's ramp (10 s) left out, "
        "70 s before the heat arrives at the nose")
    jump_se_floor_um: float = _c(
        0.02, "um", "the least standard error of a jump: a line through quantised samples "
        "can fit them exactly, and a fifth of P1's 0.1 um resolution is what it resolves")
    onset_scales: tuple[OnsetScale, ...] = _c(
        (OnsetScale("2 min / 4 min", (-300.0, -10.0), (10.0, 120.0), (120.0, 360.0)),
         OnsetScale("6.5 min / 13 min", (-600.0, -10.0), (10.0, 400.0), (400.0, 1200.0))),
        "s from a step", "the onset is read at two time scales: minutes (a lag of a few "
        "minutes; the temperatures' noise is small) and a quarter of an hour (a lag of ten to "
        "twenty minutes, and a channel as coarsely logged as P1)")
    concave_ratio: float = _c(
        1.15, "-", "the model's onset ratio above which a channel is expected to respond at "
        "once (a concave onset): the ratio of a first-order response's slope change over "
        "the two windows is 1.3 and falls to 1 for a ramp; 1.15 is half-way. The model's "
        "ratio must clear it by its own one-sided interval at alpha")
    lag_grid_s: tuple[float, ...] = _c(
        (0.0, 15.0, 30.0, 60.0, 120.0, 240.0, 480.0, 960.0, 1800.0, 3600.0), "s",
        "the lag time constants the onset ratio is mapped over, doubling up to the library's "
        "bound")

    # ---------------------------------------------------------------- signatures: power
    drift_min_segment_s: float = _c(
        1800.0, "s", "a no-load segment is read for a drift when it lasts half an hour: the "
        "ring difference settles in 10-20 min")
    drift_min_segments: int = _c(
        3, "segments", "the preload coefficient is regressed through the origin on the "
        "segments' drifts: three give its standard error two degrees of freedom")
    drift_early_s: tuple[float, float] = _c(
        (120.0, 360.0), "s from the start", "the early power of a segment: after the drive's "
        "ramp and its first averaging, before the rings have warmed")
    drift_late_s: float = _c(
        900.0, "s", "the late power: the segment's last quarter of an hour")
    window_min_samples: int = _c(
        3, "samples", "a window's mean (of the power, of a block of residual) carries the "
        "standard error of its own samples' scatter: three samples give it two degrees of "
        "freedom (an on-change log holds a few samples in minutes)")
    power_resolution_W: float = _c(
        0.05, "W", "the least standard error of a mean power: a drive's power reading resolves "
        "about 0.1 W")
    level_min_s: float = _c(
        600.0, "s", "a no-load segment gives a power level when it lasts ten minutes (its "
        "second half settled)")
    level_rpm: float = _c(50.0, "rpm", "no-load segments within 50 rpm are one speed level")
    min_levels: int = _c(
        5, "levels", "the n^3 term is read from at least five speed levels: four terms are "
        "fitted (n, n^(5/3), n^2, n^3), so one degree of freedom is left for the scatter")
    min_speed_span: float = _c(
        3.0, "-", "the levels must span a factor 3 in speed, or n^2 and n^3 cannot be told "
        "apart")

    # ---------------------------------------------------------------- signatures: load
    load_plateau_min_s: float = _c(
        1800.0, "s", "a loaded constant-speed plateau is read when it lasts half an hour")
    load_settle_s: float = _c(
        900.0, "s", "after a speed change the rings settle to the new bearing heat for a "
        "quarter of an hour (their time constant, 5-10 min, three times over)")
    load_block_s: float = _c(
        300.0, "s", "the residual is averaged over five-minute blocks: short against the "
        "motor's thermal response, long against the logging")
    load_span_Nm: float = _c(
        5.0, "N m", "the process torque must vary by 5 N m within a plateau: 100-500 W of "
        "motor loss, a response of tenths of a kelvin at the rings")
    load_min_plateaus: int = _c(
        4, "plateaus", "the jackknife over the plateaus needs four for its standard error")
    load_probe_R_K_W: float = _c(
        0.002, "K/W", "the probe coolant resistance of the sensitivity (the model is linear in "
        "it to first order; a tenth of the library range's upper end)")
    max_path_correlation: float = _c(
        0.8, "-", "the coolant's and the rotor's paths to the rings are told apart only where "
        "their regressors correlate at most 0.8: a variance inflation 1 / (1 - r^2) of 2.8, "
        "beyond which the two estimates trade")

    # ---------------------------------------------------------------- derived
    def implausible_z(self) -> float:
        """The prior |z| beyond which a base parameter is implausible: two-sided at alpha."""
        from scipy.stats import norm

        return float(norm.isf(self.alpha / 2))

    def distinct_margin(self) -> float:
        """The log-likelihood margin of ``distinct`` and of :func:`compare.fit.select.complements`:
        half the chi-square quantile of one degree of freedom at alpha (3.3 at 1 %)."""
        return 0.5 * chi2_threshold(self.alpha, 1)

    def with_options(self, **values) -> Criteria:
        """These criteria with some entries set (None leaves an entry as it is)."""
        return replace(self, **{k: v for k, v in values.items() if v is not None})

    def table(self) -> list[dict]:
        """Every entry: name, value, unit, reason (the report's criteria table)."""
        out = []
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, tuple) and v and isinstance(v[0], OnsetScale):
                v = [s.name for s in v]
            out.append({"name": f.name, "value": v, "unit": f.metadata["unit"],
                        "reason": f.metadata["reason"]})
        out.append({"name": "implausible_z", "value": round(self.implausible_z(), 3),
                    "unit": "prior sd", "reason": "derived: two-sided normal quantile at "
                    "alpha, so the verdict's plausible range and the selection agree"})
        return out


def chi2_threshold(alpha: float, df: int, tests: int = 1) -> float:
    """The chi-square quantile at level ``alpha`` / ``tests`` (Bonferroni) with ``df``
    degrees of freedom."""
    from scipy.stats import chi2

    return float(chi2.isf(alpha / max(tests, 1), df)) if alpha > 0 else math.inf
