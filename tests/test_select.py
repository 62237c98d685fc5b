"""The selection (compare.fit.select) and its competitor (compare.fit.competitor): which route
a candidate's criteria give, when a signature contradicts a fit, and, on data from the grey
box itself, that a library effect is named, that clean data name nothing, and that a heat in
a window no library effect makes is "unexplained" and located."""

from __future__ import annotations

import numpy as np
import pytest

from compare.fit.calibrate import Calibrator, Measured
from compare.fit.competitor import WindowHeat
from compare.fit.criteria import Criteria
from compare.fit.effects import Effect, candidates, hypothesis
from compare.fit.greybox import GreyBox
from compare.fit.params import Param
from compare.fit.select import Judgement, select, signature_outcome
from compare.fit.signatures import EventTest
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES
from spindle.spec_reader import load_spec
from tests.cycle_inputs import inputs_from_cycle

CHANNELS = ["T1", "T2", "T_stator", "P1"]
ALL_PASS = {"significant": True, "material": True, "signature": None,
            "predicts": True, "beats_something_else": True,
            "distinct": True, "changes_prediction": True, "restores_plausible_base": None,
            "null_at_optimum": None, "final_model_adequate": None}


@pytest.mark.parametrize("changes, route", [
    ({}, "open loop"),
    ({"signature": True, "predicts": None, "beats_something_else": False}, "signature"),
    ({"signature": False}, None),  # a contradicting signature vetoes both routes
    # a signature without a significant gain in likelihood: the fit does not want it
    ({"significant": False, "signature": True}, None),
    ({"material": False}, None),
    ({"predicts": False}, None),
    ({"beats_something_else": False}, None),
    ({"distinct": False}, None),
    ({"changes_prediction": False}, None),  # the base re-adjusts around it
    ({"changes_prediction": False, "signature": True}, "signature"),  # its own evidence
    ({"changes_prediction": None}, "open loop"),  # switched off
    # the prediction does not move, but the base is implausible without it and not with it
    ({"changes_prediction": False, "restores_plausible_base": True}, "open loop"),
    ({"changes_prediction": False, "restores_plausible_base": False}, None),
    ({"restores_plausible_base": True, "predicts": False}, None),
    # its gain was the null's shortfall: the model without it gains as much from its refit
    ({"null_at_optimum": False}, None),
    ({"null_at_optimum": False, "signature": True}, None),
    ({"null_at_optimum": True}, "open loop"),
])
def test_a_candidates_route_follows_its_named_criteria(changes, route):
    j = Judgement("x", 1, None, 10.0, 20.0, 1e-5, 2.0, {**ALL_PASS, **changes})
    assert j.route == route and j.qualifies is (route is not None)


def test_a_candidate_its_signature_found_joins_before_a_larger_open_loop_gain():
    """In one round a centrifugal shortening qualifies by its signature (gain 18) and a lag
    of P1 by the open loop alone (gain 45), as on a held-out run with a shortening and no
    lag: the shortening joins, and the lag is judged again against the model that holds it.
    Between two of one route the larger gain joins."""
    from compare.fit.select import joins_first

    signature = Judgement("centrifugal_shortening", 1, None, 18.0, 36.0, 1e-9, 3.0,
                          {**ALL_PASS, "signature": True})
    open_loop = Judgement("sensor_lag(P1)", 1, None, 45.0, 90.0, 1e-20, 2.0, dict(ALL_PASS))
    assert joins_first([open_loop, signature]) is signature
    larger = Judgement("fixture_expansion", 1, None, 60.0, 120.0, 1e-26, 2.0, dict(ALL_PASS))
    assert joins_first([open_loop, larger]) is larger


def _test(z: float, value: float, ci: tuple[float, float]) -> EventTest:
    from scipy.stats import norm

    return EventTest("e", "P1", value, 1.0, z, float(norm.sf(z)), 5, "u", "m",
                     parameter={"name": "k", "value": value, "ci95": list(ci)})


@pytest.mark.parametrize("test, outcome", [
    (None, None),                            # no test: the open loop may judge
    (_test(4.0, 2.0, (1.0, 3.0)), True),     # it found the effect (significant at 1 %)
    (_test(1.0, 0.5, (-0.5, 1.5)), False),   # it applies and did not find it
])
def test_a_signature_that_applies_must_agree(test, outcome):
    """An applicable test that is not significant vetoes the effect, whatever the fitted
    size (its own test looked for it and did not find it)."""
    assert signature_outcome(test, 0.01) is outcome


@pytest.fixture(scope="module")
def setup():
    spec = load_spec("spl2782")
    cycle = load_cycle("spl-16h")
    grid = np.arange(0.0, cycle.duration_s + 1.0, 120.0)
    return spec, inputs_from_cycle(cycle, grid)


def _noisy(out: dict, n: int, seed: int) -> dict:
    # white noise of a resolution-limited bench: 0.05 K, 0.1 µm
    rng = np.random.default_rng(seed)
    return {c: out[c] + rng.normal(0, 0.1e-6 if c == "P1" else 0.05, n) for c in CHANNELS}


def _select(spec, inp, vals, names=None):
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    base = cal.fit()
    return select(cal, base, candidates(CHANNELS, names), Criteria())


def test_selection_names_a_known_effect_and_recovers_it(setup):
    """Grey-box data with fixture_expansion (k = 1.5 µm/K) and noise: the selection names it
    alone among the whole library and recovers k within 0.1 µm/K (seeds 3 and 4 gave 1.449
    +- 0.031 and 1.479 +- 0.030 with the old selection) with a 95 % interval narrower than
    0.25 µm/K; the run is not unexplained."""
    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp, effects=("fixture_expansion",))
    vals = _noisy(truth.simulate({"k_fix_um_K": 1.5, "f0": 0.4}), len(inp.grid_s), 3)
    sel = _select(spec, inp, vals)
    assert [s.label for s in sel.steps] == ["fixture_expansion"]
    assert abs(sel.final.theta["k_fix_um_K"] - 1.5) < 0.1
    lo, hi = sel.final.ci95["k_fix_um_K"]
    assert hi - lo < 0.25
    assert not sel.verdict.unexplained
    every = {j.label for j in sel.judged if j.round == 1}
    assert every == set(candidates(CHANNELS))  # each candidate judged, criteria recorded
    assert all(set(j.criteria) == set(ALL_PASS) for j in sel.judged)


def test_a_base_short_of_its_optimum_is_refitted_from_the_joining_candidates_fit(setup):
    """The base calibration stopped after 3 evaluations from f0 = 1.2 (the truth is 0.4), as a
    calibration stopped in a poorer basin does: the fixture expansion in the data qualifies in
    round 1, and the model without it, refitted from where its refit ended, gains more than
    Criteria.distinct_margin over that base. The candidate does not join on that gain
    (null_at_optimum False); the round is judged again from the better base, where it joins
    (True) and is recovered as in the test above. Before the rule the base stayed as given. The
    signature tests are read at the base given and again at the better one."""
    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp, effects=("fixture_expansion",))
    vals = _noisy(truth.simulate({"k_fix_um_K": 1.5, "f0": 0.4}), len(inp.grid_s), 3)
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    short = cal.fit(start={"f0": 1.2, "h_air": 3.0}, max_nfev=3)
    read_at = []  # the base values each reading of the signatures was given
    sel = select(cal, short, candidates(CHANNELS), Criteria(),
                 signatures=lambda fit: read_at.append(fit.theta) or {})
    asked = [(j.label, j.round, j.criteria["null_at_optimum"]) for j in sel.judged
             if j.criteria["null_at_optimum"] is not None]
    assert asked == [("fixture_expansion", 1, False), ("fixture_expansion", 2, True)]
    margin = Criteria().distinct_margin()
    first = next(j for j in sel.judged if j.criteria["null_at_optimum"] is False)
    assert first.figures["null_shortfall"] > margin
    assert sel.base.loglik > short.loglik and abs(sel.base.theta["f0"] - 0.4) < 0.1
    # a signature may read the base's values, so they are read again at the better base
    assert read_at == [short.theta, sel.base.theta]
    assert [s.label for s in sel.steps] == ["fixture_expansion"]
    assert abs(sel.final.theta["k_fix_um_K"] - 1.5) < 0.1


def test_clean_data_name_nothing_and_are_explained(setup):
    spec, inp = setup
    vals = _noisy(GreyBox(spec, DRIVES["spl2782"], inp).simulate({"f0": 0.4}),
                  len(inp.grid_s), 5)
    sel = _select(spec, inp, vals)
    assert sel.steps == [] and not sel.verdict.unexplained


def test_a_heat_no_effect_makes_is_unexplained_and_located(setup):
    """150 W into the housing from 6 h to 9 h (no library effect makes a heat that starts and
    stops with no change of the inputs): nothing named; the competitor says unexplained, with
    a heat into the housing whose window overlaps 6-9 h."""
    spec, inp = setup
    g = inp.grid_s
    mid = 0.5 * (g[1:] + g[:-1])
    extra = WindowHeat("housing", 6 * 3600.0, 9 * 3600.0)
    extra.name = "test window heat"
    lab = hypothesis(extra)
    out = GreyBox(spec, DRIVES["spl2782"], inp, effects=(lab,)).simulate(
        {"f0": 0.4, "q_else_W": 150.0})
    assert np.any((mid > 6 * 3600) & (mid < 9 * 3600))
    sel = _select(spec, inp, _noisy(out, len(g), 7))
    assert sel.steps == []
    v = sel.verdict
    assert v.unexplained and v.lr > v.threshold
    h = v.hypothesis
    # located to the scan's 30 min blocks (Criteria.competitor_step_s): 6.0-9.0 h exactly
    # on seeds 7 and 8; its amplitude is what the calibrated base leaves (about 40 W: the
    # base parameters take up the rest), so it is not asserted
    assert (h.kind, h.where, h.t0_s, h.t1_s) == ("heat", "housing", 6 * 3600.0, 9 * 3600.0), h


@pytest.mark.parametrize("law, named", [
    # a heat into the rotor rising as n^3, taken from the motor: windage's own law
    ("windage", ["windage_loss"]),
    # the same size at the top speed rising as n^4 (a loss split that moves with speed): a law
    # of the speed no effect of the library makes, which something else explains
    ("n^4", []),
])
def test_a_law_of_the_speed_no_effect_makes_is_something_else(setup, law, named):
    """compare.fit.competitor.SpeedHeat counts as something else (Criteria.law_rivals):
    grey-box data with a heat into the rotor of 200 W at the paper's cycle's top speed,
    4300 rpm (no signature read, so the open loop judges). As windage's n^3 it is named windage_loss, which
    explains it with one parameter where the law needs two; rising as n^4 nothing is named,
    where without the laws windage_loss is named for it."""
    from compare.fit.competitor import LAWS

    spec, inp = setup
    if law == "windage":
        gb = GreyBox(spec, DRIVES["spl2782"], inp, effects=("windage_loss",))
        out = gb.simulate({"f0": 0.4, "c_w_W_krpm3": 200.0 / 4.3 ** 3})
    else:
        gb = GreyBox(spec, DRIVES["spl2782"], inp, effects=(LAWS["rotor"],))
        out = gb.simulate({"f0": 0.4, "q_law_W": 200.0 / (4300.0 / 3000.0) ** 4, "k_law": 4.0})
    vals = _noisy(out, len(inp.grid_s), 11)
    sel = _select(spec, inp, vals)
    assert [s.label for s in sel.steps] == named
    if not named:
        cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals),
                         CHANNELS)
        off = select(cal, cal.fit(), candidates(CHANNELS),
                     Criteria().with_options(law_rivals=False))
        assert [s.label for s in off.steps] == ["windage_loss"]


def test_a_law_of_the_speed_is_a_drag_the_drive_supplies():
    """SpeedHeat's heat q (n / 3000 rpm)^k [W] goes into its own source; where the power is
    measured it is taken from the motor's sources (the total stays the logged one), where it
    is not it comes on top; at q = 0 the sources are as they were."""
    from types import SimpleNamespace

    from compare.fit.competitor import SpeedHeat

    law = SpeedHeat("rotor")
    n = np.array([0.0, 3000.0, 6000.0])
    src = {"stator": np.array([0.0, 500.0, 1500.0]), "rotor": np.array([0.0, 30.0, 100.0]),
           "front_bearing": np.array([0.0, 30.0, 90.0])}
    measured = SimpleNamespace(speed_rpm=n, power_kW=np.array([0.0, 0.6, 1.7]))
    unknown = SimpleNamespace(speed_rpm=n, power_kW=np.full(3, np.nan))
    out = law.heat(src, {"q_law_W": 50.0, "k_law": 2.0}, measured)
    np.testing.assert_allclose(out["law:rotor"], [0.0, 50.0, 200.0])
    np.testing.assert_allclose(sum(out.values()), sum(src.values()))
    on_top = law.heat(src, {"q_law_W": 50.0, "k_law": 2.0}, unknown)
    np.testing.assert_allclose(sum(on_top.values()), sum(src.values()) + [0.0, 50.0, 200.0])
    none = law.heat(src, {"q_law_W": 0.0, "k_law": 2.0}, measured)
    assert all(np.array_equal(none[k], src[k]) for k in src)


def test_the_verdict_says_which_law_stopped_which_effects():
    """report.verdict_lines: candidates that fitted (significant, material) and failed
    beats_something_else against a law of the speed get one sentence naming the law's fit
    and them; a candidate that was not significant, or that beat it, is not listed, nor one
    its signature decided (named by it or vetoed: the law stops the open loop only) or one
    the run names after all (the peer's dev2-14 read "so none is named for it:
    bearing_preload" beside "Named: bearing_preload ... its signature")."""
    from compare.fit.competitor import LAWS
    from compare.fit.report import verdict_lines

    law = {"label": LAWS["rotor"], "values": {"q_law_W": 52.4, "k_law": 3.62}}

    def cand(name, beats=False, significant=True, signature=None):
        return {"candidate": name, "round": 1, "law": law,
                "criteria": {**ALL_PASS, "beats_something_else": beats,
                             "significant": significant, "signature": signature}}

    def said(candidates, effects=()):
        doc = {"verdict": {"kind": "unexplained", "unexplained": True, "where": "somewhere"},
               "effects": [{"label": e} for e in effects], "error_before": {"validation": {}},
               "error_after": {"validation": {}}, "candidates": candidates}
        return [x for x in verdict_lines(doc) if x.startswith("A law the library lacks")]

    assert said([cand("windage_loss"), cand("bearing_preload"),
                 cand("mount_conduction", significant=False),
                 cand("fixture_expansion", beats=True), cand("windage_loss"),
                 cand("centrifugal_shortening", signature=False),
                 cand("sensor_lag(T1)", signature=True)]) == [
        "A law the library lacks, a heat into the rotor of 52 W (n / 3000 rpm)^3.6, explains "
        "the run better than these 2 effects of the library, by more than one degree of "
        "freedom's margin, so none is named: windage_loss, bearing_preload."]
    one = said([cand("windage_loss"), cand("bearing_preload")], effects=["bearing_preload"])
    assert one == ["A law the library lacks, a heat into the rotor of 52 W (n / 3000 rpm)^3.6, "
                   "explains the run better than this effect of the library, by more than one "
                   "degree of freedom's margin, so it is not named: windage_loss."]
    assert said([cand("bearing_preload")], effects=["bearing_preload"]) == []


def test_a_held_out_misfit_with_nothing_named_is_unexplained_and_says_where():
    """Criteria.held_out_misfit_unexplained: nothing named and a channel beyond one tolerance
    on the validation window makes the verdict 'unexplained' (basis "held-out misfit"),
    naming the channel and its RMS; within the tolerance it does not; the competitor's
    significant event keeps its own basis."""
    from compare.fit.competitor import Hypothesis
    from compare.fit.select import Verdict, held_out_misses

    errors = {"fit": {"T1": {"n": 10, "rmse_w": 3.0}},
              "validation": {"T1": {"n": 10, "rmse_w": 1.3}, "T2": {"n": 10, "rmse_w": 0.4},
                             "P1": {"n": 0, "rmse_w": 9.0}}}
    assert held_out_misses(errors) == {"T1": 1.3}  # not the fit window, not an empty channel
    assert held_out_misses({"validation": {"T1": {"n": 5, "rmse_w": 1.0}}}) == {}
    h = Hypothesis("heat", "stator", 3600.0, 7200.0, 12.0, 0.8, 40.0, 528)
    v = Verdict(h, 3.0, 20.0, True, held_out_misses(errors))
    assert v.basis == "held-out misfit"
    assert v.where().startswith("T1 misses its tolerance on the held-out window (1.3 times)")
    assert "not significant alone: a heat of +12 W into the stator, 1.0-2.0 h" in v.where()
    assert v.to_dict()["basis"] == "held-out misfit"
    assert Verdict(h, 30.0, 20.0, True).basis == "something else"
    assert Verdict(h, 3.0, 20.0, False).basis == ""


def test_an_unexplained_verdict_says_which_channel_and_which_input():
    """Issue 32 §3: "unexplained" says where the residual lives: the channel with the largest
    RMS in the competitor's window and the input its residual follows (the residual
    diagnostics' largest cross-correlation, with its lag). Here T2's residual is the speed's
    step delayed by 10 min, two tolerances high; T1 is noise."""
    from types import SimpleNamespace

    from compare.fit.calibrate import TOLERANCE
    from compare.fit.report import place_text, residual_place
    from compare.residuals import diagnose

    g = np.arange(0.0, 4 * 3600.0 + 1.0, 60.0)
    speed = np.where((g >= 3000.0) & (g < 6600.0), 4000.0, 0.0)
    rng = np.random.default_rng(0)
    residual = {"T1": 0.05 * rng.standard_normal(len(g)),
                "T2": np.where((g >= 3600.0) & (g < 7200.0), 2.0, 0.0)
                + 0.05 * rng.standard_normal(len(g))}
    measured = SimpleNamespace(grid_s=g, values={c: r * TOLERANCE[c] for c, r in residual.items()},
                               mask=lambda c, w: g >= 0.6 * g[-1])
    rep = SimpleNamespace(
        measured=measured, channels=["T1", "T2"],
        selection=SimpleNamespace(final=SimpleNamespace(model={c: np.zeros(len(g))
                                                               for c in residual})),
        diagnostics_after=diagnose(residual, 60.0, {"speed": speed}, alpha=0.01))
    place = residual_place(rep, 3600.0, 7200.0)
    assert place["channel"] == "T2" and abs(place["rms_tolerances"] - 2.0) < 0.05
    assert place["input"] == "speed" and place["lag_s"] == 600.0 and place["ccf"] > 0.9
    assert place_text(place).startswith("the residual is largest in T2 (2.0 tolerances RMS "
                                        "there) and follows the speed most closely (10 min "
                                        "after it")
    # on the validation window (the last 40 %) both channels are noise of 0.05 tolerances
    assert residual_place(rep)["rms_tolerances"] < 0.1


def test_a_residual_that_leads_an_input_is_not_said_to_follow_it():
    """The input named in "unexplained, where" is the largest cross-correlation at lags >= 0
    (compare.residuals.CrossPeak.ccf_after): a residual that leads an input is no response to
    it. The verdict had said "follows the speed most closely (127 min before it)" on a
    coolant-flow drop (outside-2). Here T2's residual is the speed's step two hours early: the
    diagnostics' peak over both signs stays at -120 min for the residual table, and the
    verdict's sentence names no input at a negative lag. Nor one whose correlation peaks at
    the largest lag tried ("240 min after it" on outside-2 then): no lag was found there."""
    from types import SimpleNamespace

    from compare.fit.calibrate import TOLERANCE
    from compare.fit.report import place_text, residual_place
    from compare.residuals import diagnose

    g = np.arange(0.0, 8 * 3600.0 + 1.0, 60.0)
    speed = np.where((g >= 4 * 3600.0) & (g < 5 * 3600.0), 4000.0, 0.0)
    rng = np.random.default_rng(1)
    residual = {"T2": np.where((g >= 2 * 3600.0) & (g < 3 * 3600.0), 2.0, 0.0)
                + 0.05 * rng.standard_normal(len(g))}
    diag = diagnose(residual, 60.0, {"speed": speed}, alpha=0.01)
    peak = diag.channels["T2"].best("input")
    assert peak.lag_s == -7200.0 and peak.ccf > 0.9  # both signs: the residual leads
    assert peak.lag_after_s >= 0.0 and abs(peak.ccf_after) < 0.5 * peak.ccf
    measured = SimpleNamespace(grid_s=g, values={"T2": residual["T2"] * TOLERANCE["T2"]},
                               mask=lambda c, w: g >= 0.0)
    rep = SimpleNamespace(measured=measured, channels=["T2"], diagnostics_after=diag,
                          selection=SimpleNamespace(final=SimpleNamespace(
                              model={"T2": np.zeros(len(g))})))
    place = residual_place(rep, 2 * 3600.0, 3 * 3600.0)
    assert place["lag_s"] is None or place["lag_s"] >= 0.0
    assert "before it" not in place_text(place)
    # a step of the residual 3.5 h after the room's: its correlation grows up to the largest
    # lag tried (a quarter of the 8 h, 2 h), where no peak was found, so the room is not named
    room = np.where(g >= 3600.0, 1.0, 0.0)
    late = {"T2": np.where(g >= 4.5 * 3600.0, 1.0, 0.0) + 0.01 * rng.standard_normal(len(g))}
    rep.diagnostics_after = diagnose(late, 60.0, {"T_env": room}, alpha=0.01)
    peak = rep.diagnostics_after.channels["T2"].cross[0]
    assert peak.after_at_edge and peak.lag_after_s == 7200.0 and peak.ccf_after > peak.band
    assert residual_place(rep, 2 * 3600.0, 3 * 3600.0)["input"] is None


def test_something_else_is_not_looked_for_where_the_inputs_are_not_known():
    """A logging gap with an operating change inside: what ran in the gap is a guess until the
    response to it has settled, so the rows from the gap's start to an hour after its end
    are left out of the competitor's scan (compare.fit.select.known_inputs); the rest stay."""
    from types import SimpleNamespace

    from compare.fit.select import known_inputs

    grid = np.arange(0.0, 10 * 3600.0 + 1.0, 60.0)
    point = np.concatenate([np.arange(len(grid)), np.arange(len(grid))])  # two channels
    loc = SimpleNamespace(cal=SimpleNamespace(measured=SimpleNamespace(grid_s=grid)),
                          point=point)
    gap = (3.0 * 3600.0, 3.5 * 3600.0 + 3600.0)
    rows = known_inputs(loc, [gap])
    t = grid[point]
    assert not rows[(t >= 3.0 * 3600.0) & (t < 4.5 * 3600.0)].any()
    assert rows[(t < 3.0 * 3600.0) | (t >= 4.5 * 3600.0)].all()
    assert known_inputs(loc, []).all()


def test_a_chiller_cycle_hidden_in_a_gap_is_found_by_the_scan_unless_the_gap_is_left_out(
        setup):
    """Why every logging gap leaves its inputs unknown (compare.fit.gaps.unknown_input_spans),
    not only one with an operating change: the grey box's own clean run, the coolant cycling
    as an on/off chiller does (spindle.cycles.chiller_cycling's defaults: +-0.5 K every
    20 min), logged every 10 s but for a 20 min gap across which the fit's coolant is
    interpolated, as a bench export gives it. Nothing happened, yet the competitor's scan
    finds a significant "something else" at the gap (its Monte Carlo critical value at
    alpha: compare.fit.competitor); with the gap and the hour after it left out, it finds
    nothing significant."""
    from dataclasses import replace

    from compare.fit.competitor import regressors
    from compare.fit.gaps import unknown_input_spans
    from compare.fit.linear import local
    from compare.fit.select import verdict_on
    from spindle.cycles import chiller_cycling

    spec, inp = setup
    grid = inp.grid_s
    mids = 0.5 * (grid[:-1] + grid[1:])
    truth = replace(inp, T_coolant_K=np.asarray(chiller_cycling(grid[-1])(mids)))
    vals = _noisy(GreyBox(spec, DRIVES["spl2782"], truth).simulate({}), len(grid), 3)
    gap = (6.0 * 3600.0, 6.0 * 3600.0 + 1200.0)
    logged = np.concatenate([np.arange(0.0, gap[0] + 1.0, 10.0),
                             np.arange(gap[1], grid[-1] + 1.0, 10.0)])
    hole = (grid > gap[0]) & (grid < gap[1])
    vals = {c: np.where(hole, np.nan, v) for c, v in vals.items()}
    inside = (mids > gap[0]) & (mids < gap[1])
    cool = truth.T_coolant_K.copy()
    cool[inside] = np.interp(mids[inside], gap, np.interp(gap, mids, cool))
    seen = replace(truth, T_coolant_K=cool)
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], seen), Measured(grid, vals), CHANNELS)
    base = cal.fit()
    crit = Criteria()
    loc, reg = local(cal, base), regressors(cal, base, crit)
    found = verdict_on(loc, reg, crit)
    h = found.hypothesis
    assert found.lr > found.threshold and h.t0_s < gap[1] and h.t1_s > gap[0], found
    left_out = verdict_on(loc, reg, crit, unknown_inputs=unknown_input_spans(logged, grid))
    assert left_out.lr < left_out.threshold, left_out


def test_a_fitted_effect_is_reported_where_its_gain_was_measured(setup):
    """fit_effect's estimate is where its last Gauss-Newton step lands, the point whose gain
    it reports, and its shift is the effect simulated there: with a mount of 3 W/K in the
    data, fitted from 20 W/K (a tenth into its range), the step from 0 W/K used to be
    reported as 0 W/K with no shift beside the gain of its landing point. Checked
    independently of the fit: the shift is the grey box's own difference at the reported
    value, to round-off (1e-9 tolerances)."""
    from compare.fit.linear import fit_effect, local, residual_rows

    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp, effects=("mount_conduction",))
    vals = _noisy(truth.simulate({"G_mount_W_K": 3.0, "f0": 0.4}), len(inp.grid_s), 7)
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    base = cal.fit()
    ef = fit_effect(local(cal, base), "mount_conduction")
    g = ef.values["G_mount_W_K"]
    assert g > 0.5, ef.values  # the truth is 3 W/K; the bound of no effect is 0
    gb = cal.gb.variant(base.effects + ("mount_conduction",))
    at = {v: residual_rows(cal, gb.simulate({**base.theta, "G_mount_W_K": v}))[0]
          for v in (0.0, g)}
    np.testing.assert_allclose(ef.shift, at[g] - at[0.0], atol=1e-9)
    assert np.max(np.abs(ef.shift)) > 0.0


def _smooth_block_regressors(rng, rows: int, blocks: int, channels: int):
    """A competitor's table as the scan meets it: per part, each block's heat answered by a
    first-order lag over the following blocks (so neighbouring windows are nearly the same
    test), and per channel, the block indicators."""
    from compare.fit.competitor import Regressors

    t = np.linspace(0.0, blocks, rows)
    channel = rng.integers(0, channels, rows)
    heat = {}
    for part, tau in (("a", 1.5), ("b", 4.0)):
        X = np.zeros((rows, blocks))
        for b in range(blocks):
            # a unit heat during [b, b + 1): the lag's rise, then its decay
            rise = 1.0 - np.exp(-np.clip(t - b, 0.0, 1.0) / tau)
            X[:, b] = np.where(t > b, rise * np.exp(-np.clip(t - b - 1.0, 0.0, None) / tau), 0.0)
        heat[part] = X
    block = np.minimum(t.astype(int), blocks - 1)
    offset = {}
    for c in range(channels):
        X = np.zeros((rows, blocks))
        m = channel == c
        X[np.flatnonzero(m), block[m]] = -1.0
        offset[c] = X
    return Regressors(np.arange(blocks + 1, dtype=float), heat, offset), channel


class _RunsAway(Effect):
    """An effect for the test below: T1 rises by k times 5 K over the run, and beyond
    ``k_max`` the model becomes non-finite, as a feedback beyond its stability does (a
    preload near 1/K on a spindle whose base calibrated a high friction: found on a peer run
    exported with T1 alone, where fit used to stop with a LinAlgError)."""

    name = "test_runs_away"
    params = (Param("k_runs_away", "-", 0.0, 0.0, 1.0, "the rise's share", log=False),)
    channels = ("T1",)

    def __init__(self, k_max: float, huge: float | None = None):
        self.k_max, self.huge = k_max, huge

    def as_measured(self, out, theta, inputs, channel):
        k = theta["k_runs_away"]
        g = np.asarray(inputs.grid_s, dtype=float)
        ramp = (g - g[0]) / (g[-1] - g[0])
        if k > self.k_max:
            if self.huge:  # finite, but its squares overflow: a dev2-10 exported without its
                # load torque ran a preload to 1e268 K, whose gain came out NaN
                return {**out, "T1": out["T1"] + self.huge * k * ramp}
            return {c: v * np.nan for c, v in out.items()}
        return {**out, "T1": out["T1"] + k * 5.0 * ramp}


@pytest.mark.parametrize("k_true, k_max, huge, start, expect", [
    (0.3, 0.6, None, 0.95, "near truth"),  # a start where the model runs away is halved to 0.475
    (0.9, 0.6, None, None, "at the edge"),  # every step towards the truth lands beyond the edge
    (0.3, 0.0, None, None, "none"),  # the model runs away wherever the effect is
    (0.3, 0.0, 1e200, None, "none"),  # finite, but beyond what a gain can be computed on
])
def test_a_candidate_that_makes_the_model_run_away_is_fitted_where_it_does_not(
        setup, k_true, k_max, huge, start, expect):
    """compare.fit.linear.fit_effect halves a start or a Gauss-Newton step that lands where
    the model is not finite, back towards where it is; where it is nowhere but at the neutral
    value, there is no estimate (None), and the selection goes on without the candidate
    instead of failing. A model finite but so large that the step's gain is not (1e200 K)
    has run away as well: its NaN gain had reached report.html, which failed on it."""
    from compare.fit.effects import register, unregister
    from compare.fit.linear import fit_effect, local

    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp).simulate({"f0": 0.4})
    g = inp.grid_s
    truth["T1"] = truth["T1"] + k_true * 5.0 * (g - g[0]) / (g[-1] - g[0])
    vals = _noisy(truth, len(g), 11)
    effect = register(_RunsAway(k_max, huge))
    try:
        cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(g, vals), CHANNELS)
        base = cal.fit()
        ef = fit_effect(local(cal, base), effect.name,
                        None if start is None else {"k_runs_away": start})
        if expect == "none":
            assert ef is None
            sel = select(cal, base, [effect.name], Criteria())
            assert sel.steps == [] and sel.judged == [], sel.judged
            return
        k = ef.values["k_runs_away"]
        assert np.all(np.isfinite(ef.shift)) and np.isfinite(ef.gain) and k <= k_max
        if expect == "near truth":  # the linear rise is found exactly but for the noise
            assert k == pytest.approx(k_true, abs=0.02), k
        else:  # halved towards the edge: within the last halving of it
            assert k >= 0.5 * k_max, k
    finally:
        unregister(effect.name)


def test_the_verdicts_scan_has_its_stated_level_on_noise_and_is_sharper_than_bonferroni():
    """compare.fit.competitor.scan_threshold: the scan's largest statistic on white noise
    it has not drawn exceeds the critical value at about the rate alpha (Monte Carlo test,
    exact in level), and the critical value lies below the Bonferroni bound over the
    hypotheses tried, since overlapping windows are nearly the same test."""
    from compare.fit.competitor import scan, scan_threshold
    from compare.fit.criteria import chi2_threshold

    rng = np.random.default_rng(7)
    reg, channel = _smooth_block_regressors(rng, 1200, 16, 3)
    rows = rng.random(len(channel)) < 0.9
    alpha = 0.05
    crit = scan_threshold(reg, channel, rows, alpha, tail=10)
    draws, above, tried = 400, 0, 0
    for _ in range(draws):
        found, tried = scan(reg, rng.standard_normal(len(channel)), channel, rows, 1.0, top=1)
        above += 2.0 * found[0].gain > crit
    # 20 expected of 400 (sd 4.4); 3.5 sd either side: a correct test fails this 1 in 2000
    assert 5 <= above <= 35, above
    assert crit < chi2_threshold(alpha, 1, tried)
    assert scan_threshold(reg, channel, rows, alpha, tail=10) == crit  # seeded: reproducible


def test_a_hypothesis_column_is_the_window_the_scan_fitted():
    """compare.fit.competitor.Regressors.column, which the competitor's joint fits read: the
    column of a scanned hypothesis is its table's blocks from t0 to t1 summed, so that
    refitting it by least squares gives the scan's amplitude. (It started a block late:
    a window [t0, t1) lost its first block, and a one-block window was empty.)"""
    from compare.fit.competitor import scan

    rng = np.random.default_rng(11)
    reg, channel = _smooth_block_regressors(rng, 900, 12, 2)
    r = 2.0 * reg.heat["a"][:, 4:7].sum(axis=1) + rng.standard_normal(900) * 0.3
    rows = np.ones(900, dtype=bool)
    found, _ = scan(reg, r, channel, rows, 1.0, top=10 ** 6)
    for h in found:
        a, b = int(h.t0_s), int(h.t1_s)  # the blocks are one unit long from 0
        table = reg.heat[h.where] if h.kind == "heat" else reg.offset[h.where]
        np.testing.assert_array_equal(reg.column(h), table[:, a:b].sum(axis=1))
    one = next(h for h in found if h.t1_s - h.t0_s == 1.0 and h.t0_s > 0)
    assert np.any(reg.column(one) != 0.0)


def test_a_named_effect_that_leaves_a_held_out_misfit_says_something_else_remains(setup):
    """Criteria.held_out_misfit_unexplained holds beside a named effect too: fixture_expansion
    data (as above) whose T1 reads 2 K high on the validation window only (a sensor re-seated
    after the fit window). The fixture is named, and T1 misses its tolerance on held-out
    data, so the verdict says something else remains, and where. The competitor is blinded
    (every input declared unknown, so the scan has no rows) to test this rule alone: it
    would otherwise find the offset itself."""
    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp, effects=("fixture_expansion",))
    vals = _noisy(truth.simulate({"k_fix_um_K": 1.5, "f0": 0.4}), len(inp.grid_s), 3)
    measured = Measured(inp.grid_s, vals)
    late = inp.grid_s >= measured.split_s
    vals["T1"] = np.where(late, vals["T1"] + 2.0, vals["T1"])  # 2 tolerances: 1 K each
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    sel = select(cal, cal.fit(), candidates(CHANNELS), Criteria(),
                 unknown_inputs=[(float(inp.grid_s[0]), float(inp.grid_s[-1]) + 1.0)])
    assert [s.label for s in sel.steps] == ["fixture_expansion"]
    v = sel.verdict
    assert v.unexplained and v.basis == "held-out misfit", v.to_dict()
    assert set(v.misses) == {"T1"} and v.misses["T1"] > 1.0
    # the rule switched off, the same final model names its effect alone
    from compare.fit.competitor import regressors
    from compare.fit.linear import local
    from compare.fit.select import verdict_on

    off = Criteria(held_out_misfit_unexplained=False)
    quiet = verdict_on(local(cal, sel.final), regressors(cal, sel.base, off), off,
                       unknown_inputs=[(float(inp.grid_s[0]), float(inp.grid_s[-1]) + 1.0)])
    assert not quiet.unexplained and quiet.misses == {}


def test_an_open_loop_name_whose_model_misses_its_own_channel_held_out_is_withdrawn(setup):
    """Criteria.open_loop_adequate_model: the fixture_expansion data above, but the held-out
    misfit is on P1, the fixture's own channel (the probe reads 3 um, two tolerances, high on
    the validation window only). The fixture is fitted and qualifies by the open loop, but the
    model with it misses P1 on held-out data, so its likelihood ratio does not tell the
    cause: it is withdrawn, nothing is named and the run is unexplained. With the rule off the
    same selection names it. (On T1, which the fixture does not move, it stays: above.)"""
    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp, effects=("fixture_expansion",))
    vals = _noisy(truth.simulate({"k_fix_um_K": 1.5, "f0": 0.4}), len(inp.grid_s), 3)
    late = inp.grid_s >= Measured(inp.grid_s, vals).split_s
    vals["P1"] = np.where(late, vals["P1"] + 3e-6, vals["P1"])  # [m]: 2 x 1.5 um
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    base = cal.fit()
    blind = [(float(inp.grid_s[0]), float(inp.grid_s[-1]) + 1.0)]  # the competitor alone off
    off = select(cal, base, ["fixture_expansion"], Criteria(open_loop_adequate_model=False),
                 unknown_inputs=blind)
    assert [(s.label, s.judgement.route) for s in off.steps] == [("fixture_expansion",
                                                                  "open loop")]
    sel = select(cal, base, ["fixture_expansion"], Criteria(), unknown_inputs=blind)
    assert sel.steps == [] and sel.final is base
    j = next(j for j in sel.judged if j.label == "fixture_expansion")
    assert j.criteria["final_model_adequate"] is False and j.route is None
    assert sel.verdict.unexplained and "P1" in sel.verdict.misses, sel.verdict


def test_after_a_withdrawal_the_others_judged_with_it_are_judged_again_without_it(setup):
    """A withdrawn effect's failure says nothing of the candidates judged beside it. Grey-box
    data with a T1 sensor lag (25 min) and a fixture (2 µm/K), and T1 read 1.5 K high on the
    validation window only (one and a half tolerances, as in the test above). In round 1 both
    qualify by the open loop; the lag has the larger gain and joins, then the fixture. The
    final model misses T1 held out, so the lag is withdrawn, and the fixture with it, since it
    joined after it. The selection then goes on from the base without the lag: the fixture
    qualifies again and is named, and the T1 misfit leaves the run unexplained. Before this
    rule the selection ended there and named nothing (held-out two-1001, docs/fit.md step 4)."""
    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp, effects=("sensor_lag(T1)", "fixture_expansion"))
    vals = _noisy(truth.simulate({"tau_s": 1500.0, "k_fix_um_K": 2.0}), len(inp.grid_s), 3)
    late = inp.grid_s >= Measured(inp.grid_s, vals).split_s
    vals["T1"] = np.where(late, vals["T1"] + 1.5, vals["T1"])
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    blind = [(float(inp.grid_s[0]), float(inp.grid_s[-1]) + 1.0)]  # the competitor alone off
    sel = select(cal, cal.fit(), ["sensor_lag(T1)", "fixture_expansion"], Criteria(),
                 unknown_inputs=blind)
    lag = next(j for j in sel.judged if j.label == "sensor_lag(T1)")
    assert lag.round == 1 and lag.criteria["final_model_adequate"] is False
    first = next(j for j in sel.judged if j.label == "fixture_expansion")
    assert first.round == 1 and first.route == "open loop"  # qualified, the lag joined first
    assert [s.label for s in sel.steps] == ["fixture_expansion"]
    assert sel.steps[0].judgement.round > 2  # judged again after the withdrawal
    assert "sensor_lag(T1)" not in sel.final.effects
    assert sel.verdict.unexplained and "T1" in sel.verdict.misses, sel.verdict


def test_the_linearized_models_prior_distances_are_the_calibrators(setup):
    """Local.prior_sds (the base parameters' |prior z| that restores_plausible_base reads)
    agrees with Calibrator.prior_z, which computes it from the parameter values instead of the
    fitted scale: at the fit (no step) and after a step of the base (to round-off)."""
    from types import SimpleNamespace

    from compare.fit.linear import local
    from compare.fit.params import default_theta

    spec, inp = setup
    truth = GreyBox(spec, DRIVES["spl2782"], inp)
    vals = _noisy(truth.simulate({"f0": 0.4, "h_air": 2.0}), len(inp.grid_s), 11)
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    centre = default_theta(cal.gb.parameters())
    _, fit = cal.fit_with_prior(centre)
    loc = local(cal, fit)
    rng = np.random.default_rng(0)
    for delta in (np.zeros(len(fit.free)), rng.normal(scale=0.3, size=len(fit.free))):
        want = cal.prior_z(SimpleNamespace(effects=fit.effects, free=fit.free,
                                           theta=loc.theta_after(delta)))
        got = dict(zip(fit.free, loc.prior_sds(delta), strict=True))
        assert want and all(got[k] == pytest.approx(v, abs=1e-9) for k, v in want.items())


def test_the_verdict_says_when_an_effect_was_named_for_the_base_it_spares():
    """report.verdict_lines on hand-written report documents: an open-loop effect named by
    the plausible-base route (its prediction's change failed, restores_plausible_base
    passed) says that without it the base needs a value outside its prior's range; one that
    moved the prediction does not."""
    from compare.fit.report import verdict_lines

    def doc(criteria):
        effect = {"label": "mount_conduction", "parameters": {"G_mount_W_K": 4.0},
                  "units": {"G_mount_W_K": "W/K"},
                  "confidence_intervals": {"G_mount_W_K": [3.0, 5.0]}, "evidence": None,
                  "route": "open loop", "p_value": 1e-6, "criteria": criteria}
        return {"verdict": {"kind": "named", "unexplained": False}, "effects": [effect],
                "error_before": {"validation": {}}, "error_after": {"validation": {}}}

    spared = verdict_lines(doc({**ALL_PASS, "changes_prediction": False,
                                "restores_plausible_base": True}))[0]
    assert "without it the calibrated base needs a value outside its prior's range" in spared
    moved = verdict_lines(doc(ALL_PASS))[0]
    assert "prior's range" not in moved and moved.startswith("Named: mount_conduction")


def test_an_open_loop_name_with_a_look_alike_says_what_it_is_not_told_apart_from():
    """report.verdict_lines: windage_loss named by the open loop (its signature, the n^3 term
    of the no-load power, not applying) is followed by a sentence naming its look-alike
    outside the library and why the signature did not apply; named by its signature, or an
    effect without a look-alike, it is not."""
    from compare.fit.effects import LIBRARY
    from compare.fit.report import verdict_lines

    def doc(label, route):
        effect = {"label": label, "parameters": {}, "units": {}, "confidence_intervals": {},
                  "evidence": {"z": 5.0, "p_value": 1e-7}, "route": route, "p_value": 1e-9,
                  "criteria": dict(ALL_PASS)}
        return {"verdict": {"kind": "named", "unexplained": False}, "effects": [effect],
                "signatures": {label: {"meaning": "the n^3 term (not applicable)"}},
                "error_before": {"validation": {}}, "error_after": {"validation": {}}}

    lines = verdict_lines(doc("windage_loss", "open loop"))
    assert lines[1] == ("Not told apart: windage_loss and "
                        f"{LIBRARY['windage_loss'].look_alike} leave the same mark in the "
                        "channels; its signature tells them apart and does not apply to this "
                        "run: the n^3 term (not applicable).")
    for label, route in (("windage_loss", "signature"), ("mount_conduction", "open loop")):
        assert not any(x.startswith("Not told apart") for x in verdict_lines(doc(label, route)))


@pytest.mark.parametrize("unit, shown", [("um/krpm^2", "µm/krpm²"), ("W/krpm^3", "W/krpm³"),
                                         ("um/K", "µm/K"), ("K/W", "K/W"), ("s", "s"),
                                         ("kg/m^3", "kg/m³"), ("drum/s", "drum/s")])
def test_a_named_effect_states_its_unit_as_the_other_lines_do(unit, shown):
    """The verdict's error line says µm; the named effect's value said "0.0519 um/krpm^2"
    (dev-01), the code's ASCII spelling. It says µm/krpm² now; report.json keeps the code's."""
    from compare.fit.report import verdict_lines

    effect = {"label": "centrifugal_shortening", "parameters": {"c": 0.0519},
              "units": {"c": unit}, "confidence_intervals": {"c": [0.04, 0.064]},
              "evidence": {"z": 25.3, "p_value": 1e-10}, "route": "signature", "criteria": {}}
    doc = {"verdict": {"kind": "named", "unexplained": False}, "effects": [effect],
           "error_before": {"validation": {}}, "error_after": {"validation": {}}}
    assert verdict_lines(doc)[0].startswith(
        f"Named: centrifugal_shortening, c = 0.0519 {shown} (95 %: 0.04 to 0.064).")


def test_an_adequate_base_with_implausible_values_says_so_in_the_verdict():
    """report.verdict_lines: "nothing named, base adequate" (the tolerances are met) points to
    the base parameters outside their prior range where the adequacy lists some, so that the
    verdict and the adequacy's "needs implausible values" below it do not read as a
    contradiction; a plausible base's verdict stays as it was."""
    from compare.fit.report import verdict_lines

    def doc(implausible):
        return {"verdict": {"kind": "base adequate", "unexplained": False}, "effects": [],
                "base_adequacy": {"implausible": implausible},
                "error_before": {"validation": {}}, "error_after": {"validation": {}}}

    assert verdict_lines(doc(["stator_contact"]))[0] == (
        "Nothing named, base adequate: the calibrated base model explains the run within the "
        "tolerances, with stator_contact outside its prior range (the base's adequacy, below).")
    assert verdict_lines(doc([]))[0] == ("Nothing named, base adequate: the calibrated base "
                                         "model explains the run within the tolerances.")


def test_an_adequate_base_says_how_near_the_verdicts_test_came():
    """report.verdict_lines: where nothing is named, the line after the verdict gives the
    scan's likeliest event with its likelihood ratio against the critical value (an offset
    at 16.8 against 20.7 reads as a near miss, not as nothing); one above the critical value
    that the verdict set aside is said to be too small to matter, with its peak; without a
    hypothesis, or with the test off (no finite critical value), nothing is said."""
    from compare.fit.report import verdict_lines

    def doc(hypothesis, lr=16.8, threshold=20.7):
        return {"verdict": {"kind": "base adequate", "unexplained": False}, "effects": [],
                "alpha": 0.01, "base_adequacy": {"implausible": []},
                "something_else": {"unexplained": False, "lr": lr, "threshold": threshold,
                                   "where": "P1 off by -1.03 tolerances, 12.0-13.5 h",
                                   "hypothesis": hypothesis},
                "error_before": {"validation": {}}, "error_after": {"validation": {}}}

    offset = {"kind": "offset", "peak_tolerances": 0.08}
    assert verdict_lines(doc(offset))[1] == (
        "Not significant: the likeliest event the library lacks, P1 off by -1.03 tolerances, "
        "12.0-13.5 h (likelihood ratio 16.8, critical value 20.7 at alpha 0.01).")
    assert verdict_lines(doc(offset, lr=38.2))[1] == (
        "Too small to matter: the likeliest event the library lacks, P1 off by -1.03 "
        "tolerances, 12.0-13.5 h, is significant (likelihood ratio 38.2, critical value 20.7 "
        "at alpha 0.01) but moves no channel by more than 0.08 tolerances.")
    assert verdict_lines(doc(None))[1].startswith("Validation error")
    assert verdict_lines(doc(offset, threshold=None))[1].startswith("Validation error")


def test_the_verdict_says_which_fitted_effect_was_withdrawn_and_why():
    """report.verdict_lines on a hand-written report document: a candidate withdrawn after
    the selection (final_model_adequate False) is named as fitted and withdrawn, with the
    reason, after the verdict; a run without one says nothing of it, nor does one whose
    withdrawn candidate was named again once the selection went on."""
    from compare.fit.report import verdict_lines

    def doc(adequate):
        cand = {"candidate": "bearing_preload",
                "criteria": {**ALL_PASS, "final_model_adequate": adequate}}
        return {"verdict": {"kind": "unexplained", "unexplained": True, "basis":
                            "held-out misfit", "where": "T2 misses its tolerance"},
                "effects": [], "candidates": [cand],
                "error_before": {"validation": {}}, "error_after": {"validation": {}}}

    lines = verdict_lines(doc(False))
    assert lines[0].startswith("Unexplained:")
    assert lines[1].startswith("Fitted and withdrawn: bearing_preload. The model with it "
                               "still misses the tolerances on held-out data")
    assert not any("withdrawn" in line for line in verdict_lines(doc(None)))
    # one withdrawn only because it joined after the cause, then named again, is not listed
    named = {"label": "bearing_preload", "parameters": {"k_preload_1_K": 0.1},
             "units": {"k_preload_1_K": "1/K"},
             "confidence_intervals": {"k_preload_1_K": [0.08, 0.12]}, "evidence": None,
             "route": "open loop", "p_value": 1e-6, "criteria": dict(ALL_PASS)}
    again = {**doc(False), "effects": [named],
             "verdict": {"kind": "named", "unexplained": False}}
    lines = verdict_lines(again)
    assert lines[0].startswith("Named: bearing_preload")
    assert not any("withdrawn" in line for line in lines)


def test_two_effects_that_each_add_to_the_other_are_complements_not_rivals(setup):
    """The distinct criterion weighs a candidate against alternatives only
    (Criteria.distinct_among_alternatives). Grey-box data with a mount (3 W/K) and a fixture
    (1.5 µm/K) both present: each, fitted alone on the base, adds a significant gain to the
    other's, so they are complements. Data with the fixture alone: the mount, fitted on the
    same base, adds nothing significant once the fixture is in, so it stays the fixture's
    rival. The margin is the criteria's (Criteria.distinct_margin, alpha 1 %), as in the
    rule."""
    from compare.fit.linear import fit_effect, local
    from compare.fit.select import complements

    spec, inp = setup
    n = len(inp.grid_s)
    both = GreyBox(spec, DRIVES["spl2782"], inp, effects=("mount_conduction", "fixture_expansion"))
    alone = GreyBox(spec, DRIVES["spl2782"], inp, effects=("fixture_expansion",))
    runs = {"both": _noisy(both.simulate({"G_mount_W_K": 3.0, "k_fix_um_K": 1.5, "f0": 0.4}),
                           n, 11),
            "fixture alone": _noisy(alone.simulate({"k_fix_um_K": 1.5, "f0": 0.4}), n, 11)}
    found = {}
    for name, vals in runs.items():
        cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals),
                         CHANNELS)
        loc = local(cal, cal.fit())
        mount, fixture = fit_effect(loc, "mount_conduction"), fit_effect(loc, "fixture_expansion")
        found[name] = complements(loc, mount, fixture, Criteria().distinct_margin())
    assert found == {"both": True, "fixture alone": False}


def test_the_candidates_table_says_which_candidates_were_complements_not_rivals():
    """report.html's candidates table has a column of each candidate's complements (read from
    report.json's candidates), so that a reader sees why `distinct` passed beside a larger
    gain; a hand-written report, one candidate with two complements and one with none."""
    import re

    from compare.fit.report import _criteria_html

    crit = dict(ALL_PASS)
    doc = {"candidates": [
        {"candidate": "windage_loss", "round": 1, "gain": 43.1, "p_value": 1e-6,
         "peak_tolerances": 1.2, "criteria": crit, "route": "open loop",
         "complements": ["sensor_lag(T_stator)", "bearing_preload"]},
        {"candidate": "mount_conduction", "round": 1, "gain": 3.3, "p_value": 0.2,
         "peak_tolerances": 0.1, "criteria": {**crit, "significant": False}, "route": None,
         "complements": []}]}
    html = _criteria_html(doc)
    head = re.findall(r"<th>(.*?)</th>", html)
    at = head.index("complements")
    cells = {r[0]: r for r in (re.findall(r"<td>(.*?)</td>", row)
                               for row in re.findall(r"<tbody>(.*?)</tbody>", html, re.S)[0]
                               .split("</tr>") if "<td>" in row)}
    assert cells["windage_loss"][at] == "sensor_lag(T_stator), bearing_preload"
    assert cells["mount_conduction"][at] == ""


def test_the_refit_of_a_joining_effect_is_no_worse_than_its_nested_start(setup):
    """select's refit of the model with the effect that joins it starts at the linearized
    step and at the current model with only the effect added, and keeps the better. Data:
    the grey box with a bearing preload (0.15 /K, front and rear), the coolant film at 0.7 of
    the spec's and noise of a bench. The step is pushed 2 prior sd (on the fitted scale) past
    its own estimate for every base parameter, as a linearization extrapolated over a large
    change is: refitted from there alone within the selection's budget, the model ends worse
    than from the nested start, and the refit must not."""
    from dataclasses import replace

    from compare.fit.linear import fit_effect, local
    from compare.fit.select import refit

    spec, inp = setup
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    truth = gb.variant(("bearing_preload",))
    out = truth.simulate(truth.full_theta(
        {"k_preload_1_K": 0.15, "k_preload_rear_1_K": 0.15, "h_coolant": 0.7}))
    cal = Calibrator(gb, Measured(inp.grid_s, _noisy(out, len(inp.grid_s), 0)), CHANNELS)
    base = cal.fit()
    loc = local(cal, base)
    ef = fit_effect(loc, "bearing_preload")
    far = replace(ef, delta=ef.delta + 2.0)
    crit = Criteria()

    def posterior(f):  # as refit weighs them: in the current model's effective samples
        return f.loglik * base.n_eff / base.n - f.penalty

    def from_start(start):
        return cal.fit(base.effects + (ef.label,), start=start, max_nfev=crit.refit_nfev)

    nested = posterior(from_start({**base.theta, **ef.values}))
    stepped = {**loc.theta_after(far.delta), **ef.values}
    # the case the second start is for (half a unit of log-posterior: more than round-off)
    assert posterior(from_start(stepped)) < nested - 0.5
    fit, start = refit(cal, loc, far, crit)
    assert posterior(fit) >= nested - 1e-6 and start == "nested"


def test_the_criteria_table_shows_a_figure_report_json_could_not_hold_as_not_available():
    """report.json writes a non-finite figure as None (NaN is not JSON); report.html's table
    of candidates formatted it with ':.1f' and the whole fit ended in an internal error after
    the fitting (a dev2-10 exported without its load torque, whose preload ran away)."""
    from compare.fit.report import _criteria_html

    row = {"candidate": "bearing_preload", "round": 1, "gain": None, "p_value": None,
           "peak_tolerances": None, "criteria": {}, "route": None}
    html = _criteria_html({"candidates": [row]})
    assert html.count("n/a") == 3, html


def test_a_heat_beyond_what_a_part_holds_is_read_as_where():
    """compare.fit.competitor.Hypothesis.text: the scan's amplitudes are not bounded, and a
    coolant-flow drop reads as "a heat of +5398 W into the cooling_sleeve" (outside-2); beyond
    Q_MAX_W (a heat no part holds) the sentence says to read the window as where the misfit
    is, not as a heat. Within it, as before."""
    from compare.fit.competitor import Q_MAX_W, Hypothesis

    big = Hypothesis("heat", "cooling_sleeve", 19800.0, 25200.0, 5398.0, 30.0, 8.8, 100)
    small = Hypothesis("heat", "housing", 0.0, 12600.0, 25.0, 9.0, 0.8, 100)
    assert big.text() == (f"a heat of +5398 W into the cooling_sleeve, 5.5-7.0 h (beyond the "
                          f"{Q_MAX_W:.0f} W a part could take: read it as where, not as a heat)")
    assert small.text() == "a heat of +25 W into the housing, 0.0-3.5 h"
