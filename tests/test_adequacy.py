"""The base-adequacy verdict and the extrapolation warnings of ``fit`` (compare.fit.adequacy)."""

from pathlib import Path

import numpy as np
import pytest

from compare.fit.adequacy import WHERE_IN_SPEC, base_adequacy, extrapolation_warnings
from compare.fit.criteria import Criteria

IMPLAUSIBLE_Z = Criteria().implausible_z()  # the plausible range at the default alpha


def _errors(rmse_w: dict[str, tuple[float, float]]) -> dict:
    return {w: {c: {"n": 100, "rmse_w": v[i]} for c, v in rmse_w.items()}
            for i, w in enumerate(("fit", "validation"))}


SPEC = {"h_coolant": 1.0, "f0": 0.3}


def test_adequate_when_within_tolerance_and_in_range():
    ad = base_adequacy(_errors({"T1": (0.2, 0.3), "P1": (0.1, 0.4)}), {"h_coolant": 1.3, "f0": 0.31},
                       SPEC, {"h_coolant": 1.0, "f0": 0.1})
    assert ad["adequate"] and ad["inadequate_channels"] == [] and ad["implausible"] == []
    assert ad["channels"]["T1"] == {"fit": 0.2, "validation": 0.3}


def test_inadequate_names_the_channel_the_factor_and_where_to_look():
    """A channel past its tolerance on either window and a parameter beyond the two-sided 1 %
    prior range make the base inadequate; the statement names both, with the spec's place."""
    z = IMPLAUSIBLE_Z + 0.5
    ad = base_adequacy(_errors({"T1": (0.4, 2.5), "T_stator": (1.5, 0.9)}),
                       {"h_coolant": 6.0, "f0": 0.3}, SPEC, {"h_coolant": z, "f0": 0.0})
    assert not ad["adequate"]
    assert ad["inadequate_channels"] == ["T1", "T_stator"]
    assert ad["implausible"] == ["h_coolant"]
    assert "T1 by 2.5 times its tolerance" in ad["statement"]
    assert "T_stator by 1.5 times" in ad["statement"] and "coolant-jacket films" in ad["statement"]
    assert {m["name"]: m["calibrated"] for m in ad["moved"]} == {"h_coolant": 6.0, "f0": 0.3}


@pytest.mark.parametrize("G, named", [(0.3, False), (15.0, True)])
def test_a_path_the_spec_lacks_is_named_when_the_run_needs_it(G, named):
    """G_seat_W_K (spec 0, no prior) above Criteria.missing_path_W_K is said in the statement with
    where to look, and does not by itself make the calibrated base inadequate."""
    ad = base_adequacy(_errors({"T1": (0.2, 0.3)}), {"h_coolant": 1.1, "f0": 0.3,
                                                     "G_seat_W_K": G},
                       {**SPEC, "G_seat_W_K": 0.0}, {"h_coolant": 0.4, "f0": 0.0})
    assert ad["adequate"]
    assert (ad["missing_paths"] == ["G_seat_W_K"]) is named
    assert ("bearing seats" in ad["statement"]) is named


def test_a_parameter_on_its_bound_is_said_not_judged():
    """axial_scale's range (0.8-1.25, +-1.5 prior sd) lies inside the prior's 1 % tails, so on
    its bound it is not implausible; the statement still says it ran there and where to look,
    and the verdict stays adequate. A parameter inside its range is not listed; one both
    implausible and on its bound is said once, as implausible."""
    spec = {**SPEC, "axial_scale": 1.0}
    bounds = {"h_coolant": (0.2, 5.0), "f0": (0.05, 3.0), "axial_scale": (0.8, 1.25)}
    ad = base_adequacy(_errors({"T1": (0.2, 0.3)}), {"h_coolant": 0.2, "f0": 0.3,
                                                     "axial_scale": 0.8},
                       spec, {"h_coolant": -6.4, "f0": 0.0, "axial_scale": -1.5}, bounds)
    assert ad["at_bound"] == ["axial_scale"] and ad["implausible"] == ["h_coolant"]
    assert "axial_scale ran to the bound of its range (0.8" in ad["statement"]
    assert "axial dimensions" in ad["statement"] and ad["statement"].count("h_coolant") == 1
    inside = base_adequacy(_errors({"T1": (0.2, 0.3)}), {"h_coolant": 1.0, "f0": 0.3,
                                                         "axial_scale": 1.1},
                           spec, {"h_coolant": 0.0, "f0": 0.0, "axial_scale": 0.6}, bounds)
    assert inside["at_bound"] == [] and inside["adequate"]


def test_no_priors_judges_the_channels_only():
    ad = base_adequacy(_errors({"T1": (0.3, 0.2)}), {"h_coolant": 50.0}, SPEC, None)
    assert ad["adequate"] and ad["moved"][0]["z"] is None


def test_extrapolation_warnings():
    """A cycle that ramps up warns when the validation window is its end (one split); one
    that visits the same levels before and after does not; the blocked windows of a ramp
    (compare.fit.calibrate.Measured, blocks=5) hold no speed beyond the fit window's."""
    from compare.fit.calibrate import Measured

    grid = np.arange(0.0, 10 * 3600.0 + 1.0, 60.0)
    t = grid[:-1]
    after_6h = grid <= 6 * 3600.0
    ramp = np.floor(t / 3600.0) * 600.0  # 0, 600, ..., 5400 rpm; 3600 starts at the split
    w = extrapolation_warnings(grid, ramp, np.zeros_like(t), after_6h)
    assert any("speed 5400 rpm, above the fit window's 3600" in m for m in w)
    assert any("never occur in the fit window" in m for m in w)
    back_and_forth = np.where((t // 3600.0) % 2 == 0, 1500.0, 4500.0)
    assert extrapolation_warnings(grid, back_and_forth, np.zeros_like(t), after_6h) == []
    torque = np.where(t > 6 * 3600.0, 40.0, 10.0)
    assert any("load torque 40" in m for m in extrapolation_warnings(
        grid, back_and_forth, torque, after_6h))
    blocked = Measured(grid, {"T1": np.zeros_like(grid)}, 0.6, blocks=5).fit_points()
    w = extrapolation_warnings(grid, ramp, np.zeros_like(t), blocked)
    assert not any("above the fit window" in m for m in w)


PEER_RUNS = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs"
PEER_RUNS_2 = PEER_RUNS.parent / "bench-runs-2"


@pytest.mark.slow
def test_base_inadequacy_on_a_peer_run_with_a_cause_outside_the_library():
    """On the peer's dev2-03 (another SPL2782-family spindle) T2's sensor offset jumps by
    1.6 K at 9 h (truth.json: a re-seated connector; 1.6 K on T2 alone, none on the other
    channels). No parameter of the base moves one sensor's offset, so the calibrated base must
    miss T2 by more than its 1 K tolerance and no other channel: the verdict says so, in a
    sentence that states the channel and the factor (slow: one fit, about 20 s;
    test_synth_then_fit_end_to_end covers the path). Until 2026-11-28 this test asked the same
    of the loaded control dev-09, whose base has fitted within the tolerances since the
    friction exponent and the axial scale joined it (docs/fit-history.md, 2026-11-28 (3))."""
    import json

    from compare.fit.run import run_fit
    from spindle.spec_reader import load_spec

    truth = json.loads((PEER_RUNS_2 / "truth.json").read_text(encoding="utf-8"))["dev2-03"]
    assert truth["effect_size_by_channel"] == {"T1": 0.0, "T2": 1.6, "Tst": 0.0, "P1": 0.0}
    ad = run_fit(PEER_RUNS_2 / "dev2-03.csv", load_spec("spl2782")).base_adequacy
    assert not ad["adequate"]
    assert ad["inadequate_channels"] == ["T2"], ad["inadequate_channels"]
    assert ad["statement"].startswith("misses T2 by ") and "times its tolerance" in ad["statement"]


def test_the_plausible_range_follows_alpha():
    """The verdict's implausible range is the selection's (two-sided at the fit's alpha, issue
    32: with --alpha 0.05 they disagreed): z = 2.2 is implausible at 5 % (1.96), not at 1 %
    (2.58)."""
    args = (_errors({"T1": (0.2, 0.3)}), {"h_coolant": 1.9, "f0": 0.3}, SPEC,
            {"h_coolant": 2.2, "f0": 0.0})
    assert base_adequacy(*args)["implausible"] == []
    assert base_adequacy(*args, criteria=Criteria(alpha=0.05))["implausible"] == ["h_coolant"]


def test_no_bound_advice_where_the_bound_is_the_specs_value():
    """A conductance the spec lacks (G_seat_W_K, spec 0 = its lower bound) calibrated to 0
    says "not needed": no advice to look at it (issue 32)."""
    ad = base_adequacy(_errors({"T1": (0.2, 0.3)}), {"h_coolant": 1.0, "f0": 0.3,
                                                     "G_seat_W_K": 0.0},
                       {**SPEC, "G_seat_W_K": 0.0}, {"h_coolant": 0.0, "f0": 0.0},
                       {"G_seat_W_K": (0.0, 200.0)})
    assert ad["at_bound"] == [] and "bearing seats" not in ad["statement"]


def test_a_run_at_standstill_throughout_is_fitted_not_a_traceback(tmp_path):
    """A peer's run with its speed column zeroed (every input but the speed as logged): the
    constant speed has no cross-correlation with the residuals, and fit still ends with a
    verdict and its report (exit 0), where it raised a ValueError before. The drive's power
    then heats a spindle that does not turn, which the model cannot explain: the verdict is
    not 'base adequate'."""
    import json

    from compare.cli import main

    lines = (PEER_RUNS / "dev-01.csv").read_text(encoding="utf-8").splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    k = lines[head].split(",").index("speed_rpm")
    rows = [line.split(",") for line in lines[head + 1:]]
    for r in rows:
        r[k] = "0"
    run = tmp_path / "standstill.csv"
    run.write_text("\n".join(lines[:head + 1] + [",".join(r) for r in rows]) + "\n",
                   encoding="utf-8")
    out = tmp_path / "fit"
    assert main(["fit", str(run), "--out", str(out), "--quiet", "--no-pictures"]) == 0
    verdict = json.loads((out / "report.json").read_text(encoding="utf-8"))["verdict"]
    assert verdict["kind"] != "base adequate"


def test_advice_on_a_parameter_the_run_determines_only_in_a_pair_names_the_pair():
    """alpha_eff and axial_scale both scale P1: a run determines their product, not each. An
    implausible alpha_eff whose partner is axial_scale (Fit.partners) is said with both
    places to look; without partners the advice is the parameter's own."""
    spec = {**SPEC, "alpha_eff": 1.0, "axial_scale": 1.0}
    theta = {"h_coolant": 1.0, "f0": 0.3, "alpha_eff": 0.7, "axial_scale": 0.8}
    args = (_errors({"P1": (0.1, 0.2)}), theta, spec,
            {"h_coolant": 0.0, "f0": 0.0, "alpha_eff": -(IMPLAUSIBLE_Z + 1.0),
             "axial_scale": -1.5})
    alone = base_adequacy(*args)
    paired = base_adequacy(*args, partners={"alpha_eff": ("axial_scale", -0.97)})
    assert alone["implausible"] == paired["implausible"] == ["alpha_eff"]
    assert "together with" not in alone["statement"]
    assert ("this run does not determine alpha_eff alone but together with axial_scale "
            "(correlation -0.97): look at the axial dimensions") in paired["statement"]
    # axial_scale on its bound has its own advice: the pair is named, its place said once
    on_bound = base_adequacy(*args, bounds={"axial_scale": (0.8, 1.25)},
                             partners={"alpha_eff": ("axial_scale", -0.97)})
    assert on_bound["at_bound"] == ["axial_scale"]
    assert ("together with axial_scale (correlation -0.97); axial_scale ran to the bound"
            in on_bound["statement"])
    assert on_bound["statement"].count("the axial dimensions") == 1


def test_the_partner_of_a_parameter_is_the_one_it_is_determined_with():
    """_intervals on a Jacobian whose first two columns nearly coincide (the data determine a
    + b, hardly a - b) and a third of its own, on three log-scaled parameters (h_coolant's
    prior and range): a and b are not identifiable, each the other's partner (correlation
    near -1, and fixing one determines the other); c is identifiable and has none. A column
    of zeros (d) is free alone and with any partner, so it has none either."""
    from compare.fit.calibrate import _intervals
    from compare.fit.params import BASE_PARAMS

    rng = np.random.default_rng(1)
    x = rng.normal(size=(400, 2))
    J = np.column_stack([x[:, 0], x[:, 0] + 1e-3 * x[:, 1], rng.normal(size=400),
                         np.zeros(400)])
    r = 0.05 * rng.normal(size=400)
    names = ["a", "b", "c", "d"]
    params = dict.fromkeys(names, BASE_PARAMS["h_coolant"])
    _, corr, ident, partners = _intervals(J, r, 400, 400.0, names, params, np.zeros(4))
    assert ident == {"a": False, "b": False, "c": True, "d": False}
    assert set(partners) == {"a", "b"}
    assert partners["a"][0] == "b" and partners["b"][0] == "a"
    assert partners["a"][1] < -0.99


def _depth(text: str) -> int:
    """The deepest nesting of parentheses in ``text``."""
    depth = deepest = 0
    for ch in text:
        depth += (ch == "(") - (ch == ")")
        deepest = max(deepest, depth)
    assert depth == 0, text
    return deepest


@pytest.mark.parametrize("name", sorted(WHERE_IN_SPEC))
def test_the_advice_for_an_implausible_parameter_reads_without_nested_parentheses(name):
    """Each parameter's place in the spec carries its own parentheses (the drive file's
    [motor] rotor_loss_share, ...): the statement around it must not wrap it in another pair,
    as "h_rotating 3.43 (the spec's 1, +3.1 prior sd; look at ... (shaft and tool surfaces,
    correlation d_m))" did (issue 32: each sentence reads as a sentence)."""
    theta = {**SPEC, name: 2.0}
    out = base_adequacy(_errors({"T1": (0.1, 0.2)}), theta, {**SPEC, name: 1.0},
                        {name: IMPLAUSIBLE_Z + 1.0})
    assert out["implausible"] == [name]
    assert f"{name} 2, +{IMPLAUSIBLE_Z + 1.0:.1f} prior sd from the spec's 1: look at" \
        in out["statement"]
    assert _depth(out["statement"]) <= 1, out["statement"]


def test_a_base_that_misses_and_needs_implausible_values_says_both_in_one_sentence():
    """"The base model misses T2 by 1.7 times its tolerance (...); needs implausible values"
    lost its subject after the semicolon (dev2-03's report): the second clause says "it"."""
    out = base_adequacy(_errors({"T2": (0.5, 1.7)}), {**SPEC, "f0": 0.9}, SPEC,
                        {"f0": IMPLAUSIBLE_Z + 1.0, "h_coolant": 0.0})
    assert out["inadequate_channels"] == ["T2"] and out["implausible"] == ["f0"]
    assert out["statement"].startswith("misses T2 by 1.7 times its tolerance")
    assert "validation window); it needs implausible values to fit the run: f0 0.9" \
        in out["statement"]
    alone = base_adequacy(_errors({"T2": (0.1, 0.2)}), {**SPEC, "f0": 0.9}, SPEC,
                          {"f0": IMPLAUSIBLE_Z + 1.0, "h_coolant": 0.0})
    assert alone["statement"].startswith("needs implausible values to fit the run: f0 0.9")
