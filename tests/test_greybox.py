"""The grey-box model and the fit loop (compare/fit/greybox.py, compare/fit/calibrate.py, compare/fit/run.py,
compare/synth/bench.py): nesting of every effect, agreement with the lumped model, calibration
intervals, and forward selection on data with a known truth."""

import json
from pathlib import Path

import numpy as np
import pytest

from compare.cli import main
from compare.fit.calibrate import Calibrator, Measured
from compare.fit.criteria import Criteria
from compare.fit.effects import LIBRARY, label
from compare.fit.greybox import GreyBox
from lumped import build
from spindle.bench import read_bench
from spindle.bench_inputs import resample
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES, cycle_load_case
from spindle.spec_reader import load_spec
from tests.cycle_inputs import inputs_from_cycle

CHANNELS = ["T1", "T2", "T_stator", "P1"]


@pytest.fixture(scope="module")
def setup():
    spec = load_spec("spl2782")
    cycle = load_cycle("spl-16h")
    grid = np.arange(0.0, cycle.duration_s + 1.0, 120.0)
    return spec, cycle, inputs_from_cycle(cycle, grid)


def test_greybox_is_the_lumped_model(setup):
    from spindle.loads import time_grid

    spec, cycle, _ = setup
    case = cycle_load_case(spec, cycle, DRIVES["spl2782"])
    grid = time_grid(case, 120.0)  # the lumped transient's own grid (steps on the corners)
    inp = inputs_from_cycle(cycle, grid)
    out = GreyBox(spec, DRIVES["spl2782"], inp).simulate({})
    tr = build(spec, 11).transient(case, 120.0, T0=float(case.T_ambient_K(0)))
    np.testing.assert_array_equal(tr.times_s, grid)
    # the same network, inputs held at the same mid-step values, exact ZOH in both (expm in
    # one, eigenvectors in the other): round-off
    for c in ("T1", "T2", "T_stator"):
        np.testing.assert_allclose(out[c], tr.sensor(c), atol=1e-8)
    np.testing.assert_allclose(out["P1"], tr.growth_m["P1"] - tr.growth_m["P1"][0], atol=1e-14)


@pytest.mark.parametrize("lab", [None, "bearing_preload", "coolant_dynamics", "windage_loss",
                                 "mount_conduction", "sensor_lag(T1)"])
def test_a_simulation_does_not_depend_on_the_parameter_sets_simulated_before(setup, lab):
    """A calibration asks for thousands of parameter sets, and the grey box keeps what they
    share: each speed-dependent conductance read once per speed (shared by every set's
    system), the systems and their modes, the sources, the effects' flows configured in
    place. The channels of one set must then be the same, bit for bit, from a fresh grey box
    as from one that simulated other films, contacts, friction, lengths and effect values
    first; only then is a fit's result independent of the path its optimizer took. (That the
    shared readings are the right ones is test_greybox_is_the_lumped_model's: at the spec's
    values every speed-dependent film goes through them.) The base, and the effects that
    enter the network's flows, conductances or the sensors' dynamics."""
    spec, _, inp = setup
    extra = ("G_seat_W_K", "axial_scale", "friction_exponent")
    effects = () if lab is None else (lab,)

    def grey_box() -> GreyBox:
        return GreyBox(spec, DRIVES["spl2782"], inp, base_extra=extra).variant(effects)

    params = grey_box().parameters()
    own = [k for k in params if k not in GreyBox(spec, DRIVES["spl2782"], inp,
                                                  base_extra=extra).parameters()]

    def at(share: float) -> dict[str, float]:  # the effect's parameters across their range
        return {k: params[k].lo + share * (params[k].hi - params[k].lo) for k in own}

    theta = {"h_coolant": 0.8, "h_air": 1.3, "h_rotating": 1.7, "contact": 0.6,
             "stator_contact": 1.4, "f0": 1.1, "axial_scale": 1.05, "G_seat_W_K": 2.0,
             "friction_exponent": 0.1, **at(0.3)}
    fresh = grey_box().simulate(theta)
    warm = grey_box()
    # a neighbour within 1e-12 of each value that has a cache key of its own: once the keys
    # were rounded to 12 decimals, so the set after it got the neighbour's sources and
    # matrices (and a Jacobian column in a forked child, whose cache saw other sets, differed
    # from the same column in one process: docs/fit-history.md "(12)")
    near = {k: v + 2e-13 for k, v in theta.items()}
    nearby = warm.simulate(near)
    assert not np.array_equal(nearby["T1"], fresh["T1"])  # the last bits show the neighbour
    for other in ({}, {"h_rotating": 0.5, "axial_scale": 0.9, **at(0.7)},
                  {**theta, "h_rotating": 1.2, **at(0.1)}, {**theta, "f0": 0.9, "contact": 1.6}):
        moved = warm.simulate(other)
        assert np.max(np.abs(moved["T1"] - fresh["T1"])) > 0.01  # they are other sets
    again = warm.simulate(theta)
    for c in CHANNELS:
        np.testing.assert_array_equal(again[c], fresh[c])


@pytest.mark.parametrize("bin_rel", [0.0, 0.05])
def test_a_feedback_simulation_is_the_recursion_step_by_step(setup, bin_rel):
    """With a bearing preload the bearings' heat enters the matrices, so the grey box steps
    through the run with an exact zero-order-hold step per interval. It makes one step per
    distinct binned heat of a segment and bins the run's heat once (binning and keying each
    interval took half of a preload run's fit). The states must be, bit for bit, those of
    the recursion x+ = Phi(q_i) x + Gamma(q_i) u_i with each interval's own step: the same
    steps and the same products in the same order. The states are read through unit
    read-out rows, which copy them exactly."""
    from dataclasses import replace

    spec, _, inp = setup
    # a logged speed that wanders within 3 % of its level, as a bench's does: the conductances
    # see one binned speed (one segment), the bearings' heat the exact one, so the heat, and
    # with it the step, changes from interval to interval inside a segment
    wobble = 1.0 + 0.03 * np.sin(np.arange(len(inp.speed_rpm)) * 0.7)
    inp = replace(inp, speed_rpm=np.asarray(inp.speed_rpm, dtype=float) * wobble)
    gb = GreyBox(spec, DRIVES["spl2782"], inp, speed_bin_rel=bin_rel).variant(
        ("bearing_preload",))
    theta = {"k_preload_1_K": 0.02, "k_preload_rear_1_K": 0.01, "f0": 1.2}
    th = gb.full_theta(theta)
    system = gb._model(th).system
    assert system.temperature_dependent
    n = system.n_states
    rows = {f"x{k}": np.eye(n)[k] for k in range(n)}
    out = gb.simulate(theta, extra_rows=rows)
    X = np.column_stack([out[f"x{k}"] for k in range(n)])
    U = gb._input_matrix(th, system)
    m = len(system.source_names)
    speeds, dts = gb.conductance_speeds(), np.diff(inp.grid_s)
    x = X[0]
    steps = []
    for i in range(len(dts)):
        Phi, Gam = system.discretize(float(dts[i]), float(speeds[i]), gb._binned(U[i, :m]))
        x = Phi @ x + Gam @ U[i]
        steps.append(x)
    np.testing.assert_array_equal(X[1:], np.array(steps))
    if bin_rel:  # segments of many intervals, whose heats differ
        assert len(np.unique(speeds)) < len(speeds) / 4
        assert len(np.unique(gb._binned(U[:, :m]), axis=0)) > 2 * len(np.unique(speeds))
    assert np.ptp(X[:, 0]) > 1.0  # the run heats the spindle


def test_the_heat_of_each_interval_is_its_operating_points(setup):
    """The power balances are made once per distinct operating point of the run (speed,
    torque, power) and spread over the intervals; each interval's heat must be the drive's
    heat at its own operating point, exactly."""
    spec, _, inp = setup
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    points, which = gb._operating_points()
    assert len(points) < len(which) / 5  # a cycle repeats its operating points
    heat = gb.sources(1.3, 0.4, 0.2)
    drive = DRIVES["spl2782"].with_f0(1.3).with_rotor_share(0.4).with_friction_exponent(0.2)
    for i in range(0, len(which), 7):
        ref = drive.heat_W(round(float(inp.speed_rpm[i]), 3),
                           round(float(inp.load_torque_Nm[i]), 2), None)
        for src, value in ref.items():
            assert heat[src][i] == pytest.approx(value, rel=1e-12, abs=1e-12), (i, src)


def test_grey_boxes_on_other_inputs_may_share_a_cache_without_its_input_keys(setup):
    """The gap placement (compare.fit.run._place_gap_switches) tries a speed switch at each
    grid edge inside a logging gap, each a grey box on other inputs sharing one cache (the
    network does not depend on the inputs), and drops the keys ("src", ...) between them.
    Everything input-dependent must sit under those keys: a grey box on the trial inputs
    must then give, bit for bit, what a fresh one does. (The run's operating points, tried
    under another key, kept the first trial's speeds for every later trial:
    docs/fit-history.md.)"""
    from dataclasses import replace

    spec, _, inp = setup
    shared: dict = {}
    GreyBox(spec, DRIVES["spl2782"], inp, _cache=shared).simulate({})
    speed = np.asarray(inp.speed_rpm, dtype=float).copy()
    speed[100:140] = np.where(speed[100:140] > 0, 0.5 * speed[100:140] + 700.0, 2000.0)
    trial = replace(inp, speed_rpm=speed)
    for k in [k for k in shared if isinstance(k, tuple) and k[:1] == ("src",)]:
        del shared[k]
    reused = GreyBox(spec, DRIVES["spl2782"], trial, _cache=shared).simulate({})
    fresh = GreyBox(spec, DRIVES["spl2782"], trial).simulate({})
    assert np.max(np.abs(fresh["T_stator"] - GreyBox(spec, DRIVES["spl2782"], inp)
                         .simulate({})["T_stator"])) > 0.5  # the trial's speeds matter
    for c in CHANNELS:
        np.testing.assert_array_equal(reused[c], fresh[c])


#: one candidate label per library effect (a per-channel effect on P1)
LABELS = [label(n, "P1" if e.per_channel else None) for n, e in sorted(LIBRARY.items())]


@pytest.mark.parametrize("lab", LABELS)
def test_every_effect_is_nested_and_acts(setup, lab):
    spec, _, inp = setup
    base = GreyBox(spec, DRIVES["spl2782"], inp).simulate({})
    gb = GreyBox(spec, DRIVES["spl2782"], inp, effects=(lab,))
    neutral = gb.simulate({})  # every effect parameter at its neutral default
    # exact nesting, except coolant_dynamics, whose R = 0 limit is an advection conductance
    # of 1e9 W/K (kW over 1e9 W/K: ~1e-6 K)
    tol = 1e-5 if lab == "coolant_dynamics" else 1e-12
    for c in CHANNELS:
        np.testing.assert_allclose(neutral[c], base[c], atol=tol * (1e-6 if c == "P1" else 1))
    effect = LIBRARY[lab.split("(")[0]]
    on = gb.simulate({p.name: p.lo + 0.75 * (p.hi - p.lo) for p in effect.params})
    moved = [c for c in CHANNELS if np.max(np.abs(on[c] - base[c])) > (1e-8 if c == "P1"
                                                                      else 1e-3)]
    assert moved, f"{lab} changes nothing"
    if effect.channels == ("P1",) or effect.per_channel:
        assert moved == ["P1"]  # output effects touch their channel only


def test_seat_conductance_is_nested_and_cools_the_rings(setup):
    """The default base extra G_seat_W_K: at 0 W/K the model is the spec's (a zero
    conductance), and a seat conductance pulls both bearing rings toward the coolant, T1 and
    T2 most, the stator least (it is cooled by the sleeve already)."""
    spec, _, inp = setup
    plain = GreyBox(spec, DRIVES["spl2782"], inp).simulate({})
    gb = GreyBox(spec, DRIVES["spl2782"], inp, base_extra=("G_seat_W_K",))
    model = gb._structure()[0]
    seats = [(i, j, name) for i, j, _, name in model.system.edges if name.startswith("seat:")]
    assert sorted(s[2] for s in seats) == ["seat:front_bearing", "seat:rear_bearing"]
    labels = [lab[0] for lab in model.system.labels]
    assert {labels[i] for i, _, _ in seats} == {"front_bearing.outer", "rear_bearing.outer"}
    assert {labels[j] for _, j, _ in seats} == {"coolant"}
    zero = gb.simulate({"G_seat_W_K": 0.0})
    for c in CHANNELS:  # the same network but for two zero conductances: round-off
        np.testing.assert_allclose(zero[c], plain[c], atol=1e-9 * (1e-6 if c == "P1" else 1))
    on = gb.simulate({"G_seat_W_K": 20.0})
    T_cool = np.concatenate([[inp.T_coolant_K[0]], inp.T_coolant_K])
    rise = {c: np.max(plain[c] - T_cool) for c in ("T1", "T2", "T_stator")}
    cooled = {c: np.max(on[c] - T_cool) for c in rise}
    assert cooled["T1"] < 0.7 * rise["T1"] and cooled["T2"] < 0.7 * rise["T2"], (rise, cooled)
    assert (rise["T_stator"] - cooled["T_stator"]) < (rise["T1"] - cooled["T1"])


def _air_cooled(tmp_path):
    """spl2782 with its jacket's films towards the room: a spindle without a coolant."""
    text = Path(load_spec("spl2782").path).read_text(encoding="utf-8")
    assert text.count('T_ref = "coolant"') >= 1  # the jacket's films
    path = tmp_path / "air.toml"
    path.write_text(text.replace('T_ref = "coolant"', 'T_ref = "ambient"'), encoding="utf-8")
    return load_spec(path)


def test_an_air_cooled_spindle_has_no_coolant_parameters(setup, tmp_path):
    """On a spec without a coolant film, h_coolant scales no edge and the bearing seats have
    no coolant to be linked to: neither is a parameter (the default extras had ended ``fit``
    with an internal error, and h_coolant was reported not identifiable), and the model
    with G_seat_W_K asked for is the model without it."""
    from compare.fit.params import DEFAULT_BASE_EXTRA

    _, _, inp = setup
    air = _air_cooled(tmp_path)
    gb = GreyBox(air, DRIVES["spl2782"], inp, base_extra=DEFAULT_BASE_EXTRA)
    assert gb.inert_params() == {"h_coolant", "G_seat_W_K"}
    params = gb.parameters()
    assert "h_coolant" not in params and "G_seat_W_K" not in params
    assert {"h_air", "h_rotating", "contact", "stator_contact", "axial_scale"} <= set(params)
    without = GreyBox(air, DRIVES["spl2782"], inp, base_extra=("axial_scale",
                                                                "friction_exponent"))
    a, b = gb.simulate({}), without.simulate({})
    for c in CHANNELS:
        np.testing.assert_array_equal(a[c], b[c])
    # the shipped, water-cooled spec: every parameter acts
    assert GreyBox(setup[0], DRIVES["spl2782"], inp).inert_params() == set()


def test_asking_for_seats_on_an_air_cooled_spindle_is_refused(tmp_path, capsys):
    """``--base-extra G_seat_W_K`` on a spec without a coolant: exit 2, naming the option and
    the fix, nothing written."""
    _air_cooled(tmp_path)
    run = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs" / "dev-06.csv"
    out = tmp_path / "fit"
    assert main(["fit", str(run), "--spec", str(tmp_path / "air.toml"), "--out", str(out),
                 "--quiet", "--base-extra", "G_seat_W_K"]) == 2
    err = capsys.readouterr().err
    assert "--base-extra" in err and "G_seat_W_K acts on nothing" in err
    assert "leave G_seat_W_K out" in err and not out.exists()


def test_effects_through_the_coolant_are_not_tried_on_an_air_cooled_spindle(tmp_path, capsys):
    """coolant_dynamics (and the outside causes that act through the coolant) need a coolant
    film: on a spec without one synth had ended with an internal error (a matmul of no
    film rows); now synth refuses them and fit neither tries nor lets one be asked for,
    each with exit 2 before any work and nothing written."""
    from compare.synth.outside import OUTSIDE

    air = _air_cooled(tmp_path)
    spec = tmp_path / "air.toml"
    lacking = {n for n, e in {**LIBRARY, **OUTSIDE}.items() if e.missing_in(air)}
    assert lacking == {"coolant_dynamics", "coolant_flow_drop", "coolant_sensor_offset"}
    assert not any(e.missing_in(load_spec("spl2782")) for e in {**LIBRARY, **OUTSIDE}.values())
    run = tmp_path / "run.csv"
    for effect in ("coolant_dynamics", "coolant_flow_drop"):
        assert main(["synth", "--spec", str(spec), "--effect", effect, "--out", str(run)]) == 2
        err = capsys.readouterr().err
        assert f"{effect} needs a coolant film" in err and "choose another effect" in err
        assert not run.exists()
    peer = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs" / "dev-06.csv"
    assert main(["fit", str(peer), "--spec", str(spec), "--out", str(tmp_path / "fit"),
                 "--quiet", "--candidates", "coolant_dynamics"]) == 2
    assert "leave coolant_dynamics out" in capsys.readouterr().err


def test_heat_moved_into_a_rotor_needs_a_rotor_source(tmp_path, capsys):
    """windage_loss and rotor_loss_rise put their synthetic heat on the source of the part
    whose role is rotor (and the loss law takes it from the stator's): on a spec whose rotor
    loss sits on the shaft synth had ended with an internal error (an empty list indexed, a
    StopIteration); now it refuses them with exit 2 before any work, nothing written. The fit
    still tries windage there (it heats the rotor part's masses, which the spec has)."""
    from compare.synth.losslaw import LOSS_LAWS

    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "spl2782.toml").read_text("utf-8")
    moved = text.replace('name = "rotor"\npart = "rotor"', 'name = "rotor"\npart = "shaft"')
    assert moved != text
    spec_file = tmp_path / "rotor-on-shaft.toml"
    spec_file.write_text(moved, encoding="utf-8")
    spec = load_spec(spec_file)
    assert not LIBRARY["windage_loss"].missing_in(spec)  # the fit's candidate stays
    run = tmp_path / "run.csv"
    for effect in ("windage_loss", *LOSS_LAWS):
        assert LIBRARY.get(effect, LOSS_LAWS.get(effect)).missing_in(spec, synth=True)
        assert main(["synth", "--spec", str(spec_file), "--effect", effect, "--out",
                     str(run)]) == 2
        err = capsys.readouterr().err
        assert f'{effect} needs a heat source on a part with role = "rotor"' in err
        assert "choose another effect" in err and not run.exists()
    assert not any(e.missing_in(load_spec("spl2782"), synth=True)
                   for e in {**LIBRARY, **LOSS_LAWS}.values())


OWN_SPECS = Path(__file__).resolve().parent / "data" / "own-specs"


def _nudged_bs25(folder: Path) -> Path:
    """bs25 with its rotor starting 9 nm before the shaft's slice edge at 0.2 m: a face
    offset just inside the geometry's tolerance (spindle.geometry.TOL_M, 10 nm), which
    stretched by 1.2 is just outside it, so the stretched network has a link more."""
    text = (OWN_SPECS / "bs25.toml").read_text()
    rotor = "z_start = 0.200, z_end = 0.540, r_inner = 0.065"
    nudged = text.replace(rotor, rotor.replace("0.200", "0.199999991"))
    nudged = nudged.replace('"drives/bs25.toml"', f'"{(OWN_SPECS / "drives" / "bs25.toml").as_posix()}"')
    assert nudged.count("0.199999991") == 1 and "own-specs/drives" in nudged
    out = folder / "bs25-nudged.toml"
    out.write_text(nudged)
    return out


def test_axial_scale_on_a_spindle_whose_layout_changes_when_stretched(capsys, tmp_path):
    """A spec whose lumped network changes its layout when stretched cannot calibrate
    axial_scale: asked for, it is refused as an option (exit 2 before any work); by default it
    is left out with a warning (compare.fit.run.calibrate_base; the fit runs)."""
    from compare.fit.greybox import stretch_exponents
    from spindle.errors import InputError

    nudged = _nudged_bs25(tmp_path)
    with pytest.raises(InputError, match="axial_scale cannot be calibrated on the spec bs25"):
        stretch_exponents(load_spec(nudged), 11)
    peer = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs" / "dev-06.csv"
    assert main(["fit", str(peer), "--spec", str(nudged), "--out", "unused",
                 "--quiet", "--base-extra", "axial_scale"]) == 2
    err = capsys.readouterr().err
    assert "--base-extra" in err and "leave axial_scale out of --base-extra" in err


@pytest.mark.parametrize("spec_path", ["spl2782", *sorted(OWN_SPECS.glob("*.toml"))],
                         ids=lambda p: Path(str(p)).stem)
@pytest.mark.parametrize("nodes", [5, 11, 21])
def test_a_stretched_network_has_the_same_links(spec_path, nodes):
    """Stretching a spindle along its axis scales every slice, so its lumped network keeps
    its masses and links: bs25's did not, since its rotor starts where a shaft slice ends
    and the two z, each in its own floating point, left a sliver of 1e-17 m between them
    once stretched by 1.2, a link of shaft[2] and rotor[0] that do not touch
    (lumped.build._Builder.cuts drops pieces shorter than the geometry's tolerance). Every
    spec we ship or draw from is asked, at the probe stretch and its inverse."""
    from compare.fit.greybox import STRETCH_PROBE
    from lumped.build import build_network
    from lumped.simulation import LumpedModel
    from spindle.stretch import stretch_axially

    spec = load_spec(spec_path)

    def links(sp):
        return [e[3] for e in LumpedModel(sp, network=build_network(sp, nodes)).system.edges]

    plain = links(spec)
    for factor in (STRETCH_PROBE, 1.0 / STRETCH_PROBE):
        assert links(stretch_axially(spec, factor)) == plain


@pytest.mark.parametrize("scale", [0.88, 1.1])
def test_axial_scale_is_the_stretched_spindle(setup, scale):
    """The default base extra axial_scale reproduces the network built anew from the spec
    stretched along its axis (spindle.stretch.stretch_axially: another code path, the network
    builder on other lengths), on both sides of 1 and away from the probe stretch (1.2) its
    exponents are read at. The per-edge power laws are exact for an edge whose conductance
    is its length or area times a constant; films and contacts that cover part of a mass
    deviate: measured 0.001 K and 0.001 um at x1.145. Tolerance 0.02 K, a fifth of the
    stator's sensor noise (0.1 K), and 0.02 um (the noise of P1 is 0.05 um). At 1 the model
    is the spec's to round-off, and the stretch itself moves each channel by far more than
    the tolerance (measured 1.1-1.9 K at x1.145), so the test can fail."""
    from spindle.stretch import stretch_axially

    spec, _, inp = setup
    extra = ("G_seat_W_K", "axial_scale")
    plain = GreyBox(spec, DRIVES["spl2782"], inp).simulate({})
    gb = GreyBox(spec, DRIVES["spl2782"], inp, base_extra=extra)
    neutral = gb.simulate({})
    stretched = GreyBox(stretch_axially(spec, scale), DRIVES["spl2782"], inp,
                        base_extra=extra).simulate({})
    scaled = gb.simulate({"axial_scale": scale})
    for c in CHANNELS:
        k = 1e6 if c == "P1" else 1.0
        np.testing.assert_allclose(neutral[c] * k, plain[c] * k, atol=1e-9)
        np.testing.assert_allclose(scaled[c] * k, stretched[c] * k, atol=0.02)
    assert all(np.max(np.abs(stretched[c] - plain[c])) > 0.2 for c in ("T1", "T2", "T_stator"))


def test_seats_see_the_warmed_coolant(setup):
    """With coolant_dynamics the bearing seats' conductance ends at the coolant's mean
    temperature (behind the advection conductance), as the sleeve's films do, not at the
    supply: the water that warms along the jacket is the water at the seats. So the same
    coolant warming raises T1 and T2 more with the seats than without."""
    spec, _, inp = setup
    gb = GreyBox(spec, DRIVES["spl2782"], inp, effects=("coolant_dynamics",),
                 base_extra=("G_seat_W_K",))
    edges = gb._structure()[0].system.edges
    mean = next(i for i, _, _, name in edges if name == "coolant_advection")
    assert {j for _, j, _, name in edges if name.startswith("seat:")} == {mean}

    def warming(G: float) -> dict[str, float]:
        off = gb.simulate({"G_seat_W_K": G, "R_adv_K_W": 0.0})
        on = gb.simulate({"G_seat_W_K": G, "R_adv_K_W": 0.004})
        return {c: float(np.max(on[c] - off[c])) for c in ("T1", "T2")}

    # measured: T1 2.93 K without seats, 3.88 K with 20 W/K; T2 3.64 / 4.09 K
    without, with_seats = warming(0.0), warming(20.0)
    assert all(with_seats[c] > without[c] + 0.2 for c in without), (without, with_seats)


def test_a_warming_coolant_is_not_a_weaker_jacket_film(setup):
    """The coolant's warming (R) lifts the housing's wetted bore with the stator's heat, which
    no jacket-film factor does, so the two are told apart by the bearing temperatures: the
    best factor alone leaves a good part of the warming at T2 (measured here on spl-16h: 0.81
    of 1.98 K RMS, factor 0.33; docs/fit-history.md, *Coolant warming is not a film factor*: 1.0 of
    2.3 K on a random cycle, the FEM 0.8 K). Bar: a third of the effect's RMS at T2, and
    0.3 K, ten times the bench's T sensor noise (0.03 K)."""
    from scipy.optimize import minimize_scalar

    spec, _, inp = setup
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    cool = gb.variant(("coolant_dynamics",)).simulate({"R_adv_K_W": 0.0035})
    plain = gb.simulate({})

    def film(log_f: float) -> dict[str, np.ndarray]:
        return gb.simulate({"h_coolant": float(np.exp(log_f))})

    def cost(log_f: float) -> float:
        y = film(log_f)
        return sum(float(np.mean((y[c] - cool[c]) ** 2)) for c in ("T1", "T2", "T_stator"))

    best = minimize_scalar(cost, bounds=(np.log(0.05), 0.0), method="bounded").x
    rms = {c: float(np.sqrt(np.mean((film(best)[c] - cool[c]) ** 2))) for c in ("T1", "T2")}
    effect = float(np.sqrt(np.mean((cool["T2"] - plain["T2"]) ** 2)))
    assert rms["T2"] > max(0.3, effect / 3.0), (rms, effect, float(np.exp(best)))


def test_resample_leaves_gaps_empty():
    t = np.concatenate([np.arange(0, 600, 1.0), np.arange(1800, 2400, 1.0)])
    y = t * 0.01
    g = np.arange(0, 2401, 60.0)
    r = resample(t, y, g, Criteria().gap_min_steps)
    assert np.isnan(r[(g > 660) & (g < 1740)]).all()  # inside the 20 min gap
    np.testing.assert_allclose(r[g <= 540], g[g <= 540] * 0.01)


# slow: about 21 s. The default run keeps the same synthetic run (fixture_expansion, seed 2)
# fitted with the same two candidates by tests/test_examples.py::
# test_ex03_fit_bench_run_two_candidates, and the command line's fit by
# tests/test_adequacy.py; this one adds the command line's synth, the hidden truth and the
# report's windows
@pytest.mark.slow
def test_synth_then_fit_end_to_end(tmp_path, capsys):
    """A FEM (level 0) run with fixture_expansion, in the bench format, fitted by the command
    line: the report names the effect; the truth sidecar is never read by fit."""
    run = tmp_path / "run.csv"
    assert main(["synth", "--effect", "fixture_expansion", "--seed", "2", "--level", "0",
                 "--out", str(run)]) == 0
    truth = json.loads(run.with_suffix(".truth.json").read_text())
    run.with_suffix(".truth.json").rename(tmp_path / "elsewhere.json")  # fit cannot see it
    out = tmp_path / "fit"
    capsys.readouterr()
    assert main(["fit", str(run), "--out", str(out), "--quiet",
                 "--candidates", "fixture_expansion", "centrifugal_shortening"]) == 0
    # synth logs a column the format does not know, as a bench may: kept and said, never used
    assert "unknown columns kept, not used: vibration_mm_s;" in capsys.readouterr().out
    rep = json.loads((out / "report.json").read_text())
    assert [e["name"] for e in rep["effects"]] == ["fixture_expansion"]
    k = rep["effects"][0]["parameters"]["k_fix_um_K"]
    assert abs(k - truth["parameters"]["k_fix_um_K"]) < 0.3  # µm/K; lumped vs FEM model form
    for c, e in rep["error_after"]["validation"].items():  # RMS within the tolerances
        assert e["rmse"] <= (1.5 if c == "P1" else 1.0), (c, e)
    assert set(rep) >= {"effects", "unexplained", "error_before", "error_after", "parameters",
                        "base_adequacy", "warnings"}
    assert isinstance(rep["warnings"], list)
    # synth's 20 min logging gap, nothing changed across it: something else is not looked
    # for from its start to Criteria.gap_judge_s after its end (the inputs are interpolated)
    t = read_bench(run).time_s
    i = int(np.argmax(np.diff(t)))
    assert rep["windows"]["inputs_unknown"] == [[t[i], t[i + 1] + Criteria().gap_judge_s]]
    ad = rep["base_adequacy"]
    assert isinstance(ad["adequate"], bool) and set(ad["channels"]) == set(rep["channels"])
    # the spec's own spindle has no cooled bearing seats: the default extra stays near 0
    # (0.016 W/K measured on a clean run) and no missing path is said; 1 W/K is the
    # adequacy's own threshold (compare.fit.adequacy.MISSING_PATH_W_K)
    seat = {p["name"]: p["value"] for p in rep["parameters"]}["G_seat_W_K"]
    assert seat < 1.0 and ad["missing_paths"] == [], seat
    assert "The base model" in (out / "report.html").read_text()
    assert (out / "report.html").exists() and (out / "fit_channels.png").exists()


#: (effect, seed) of the matrix below that the loop misses, each with the reason: strict, so
#: that a fix shows up
MATRIX_MISSED = {
    ("mount_conduction", 11): "G 2.39 W/K on the spec's own no-load cycle, missed since the "
    "axial scale joined the base (2026-11-26; found only then: this matrix had not been run "
    "with it): the mount's refit gains 26 in log-posterior but brings h_air only from +3.7 to "
    "+2.3 prior sd (1.96 asked for plausibility) and 16-18 % of the validation excess (25 % "
    "asked); the same with and without the friction exponent (docs/fit-history.md)",
    # measured 2026-11-28 (python -m pytest -m slow tests/test_greybox.py -k injected): the
    # slow set had not been run whole since 2026-11-26, and on seed 12 the base now takes up
    # three effects within the tolerances, as on the outside family's misses (fit-families.txt)
    **{(e, 12): f"{e} not named: nothing named, base adequate (the calibrated base explains "
       f"the run within the tolerances, validation RMS {rms}); named when the matrix was "
       "last run whole (2026-11-26) (docs/fit-history.md, 2026-11-28 (3))"
       for e, rms in (("coolant_dynamics", "0.07-0.13 K, P1 0.07 µm"),
                      ("mount_conduction", "0.05-0.10 K, P1 0.05 µm, h_air outside its prior"),
                      ("windage_loss", "0.11-0.20 K, P1 0.12 µm"))},
    # the slow set run whole on 2026-12-01: passes at d5dcfec^, fails from d5dcfec (a cell's
    # speed that of its mean bearing friction; docs/fit-history.md, 2026-12-01 (23))
    ("windage_loss", 11): "windage_loss not named since the speed of a cell's mean friction "
    "(d5dcfec; docs/fit-history.md, 2026-12-01 (23))",
    **{("electronics_drift", s): "outside the library, but not unexplained: nothing named, "
       f"base adequate (validation RMS P1 {p1} µm of 1.5); measured 2026-11-28 "
       "(docs/fit-history.md, 2026-11-28 (3))" for s, p1 in ((11, "0.94"), (12, "1.01"))},
}


def _matrix_cases() -> list:
    return [pytest.param(e, s, marks=[pytest.mark.xfail(strict=True, reason=MATRIX_MISSED[e, s])]
                         if (e, s) in MATRIX_MISSED else [], id=f"{e}-{s}")
            for s in (11, 12) for e in [*sorted(LIBRARY), "clean", "electronics_drift"]]


@pytest.mark.slow
@pytest.mark.parametrize(("effect", "seed"), _matrix_cases())
def test_fit_names_the_injected_effect(tmp_path, effect, seed):
    """Issue 6 §5, the full matrix (slow: about 1 min per case; test_synth_then_fit_end_to_end
    covers the same code path in the default run). Every library effect is named, alone, with
    the validation error within the tolerances; clean data get nothing; an effect outside the
    library is reported unexplained and nothing is named for it."""
    run = tmp_path / "run.csv"
    assert main(["synth", "--effect", effect, "--seed", str(seed), "--out", str(run)]) == 0
    run.with_suffix(".truth.json").unlink()
    out = tmp_path / "fit"
    assert main(["fit", str(run), "--out", str(out), "--quiet", "--no-pictures"]) == 0
    rep = json.loads((out / "report.json").read_text())
    named = [e["name"] for e in rep["effects"]]
    if effect == "clean":
        assert named == []
    elif effect == "electronics_drift":
        assert named == [] and rep["unexplained"]["unexplained"]
    else:
        assert named == [effect]
        # RMS within the tolerances (the max is not asserted: with centrifugal_shortening P1
        # jumps by ~3 µm at a speed step, and the 60 s model grid against the bench's
        # irregular samples leaves a spike of up to ~2 µm there, docs/fit-history.md)
        for c, e in rep["error_after"]["validation"].items():
            assert e["rmse"] <= (1.5 if c == "P1" else 1.0), (c, e)


# ---------------------------------------------------------------------- FEM anchor and priors
def test_fem_on_greybox_inputs_is_the_fem_on_the_cycle(setup):
    """compare.fit.discrepancy drives the FEM with the grey box's per-interval inputs; on a cycle
    whose steps fall on the grid, with the ambient and coolant held per interval as the grey
    box holds them, this is spindle.drive's load case, so the two FEM runs agree to round-off
    (same mesh, same steps, same inputs; only the path that builds them differs)."""
    from compare.fit.discrepancy import reference_channels
    from reference import ReferenceModel
    from spindle.loads import TimeSeries

    spec, cycle, _ = setup
    grid = np.arange(0.0, 4 * 3600.0 + 1.0, 600.0)  # the first 4 h, steps on the grid
    inp = inputs_from_cycle(cycle, grid)
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    ours = reference_channels(gb, CHANNELS, level=0)
    case = cycle_load_case(spec, cycle, DRIVES["spl2782"])
    starts = tuple(grid[:-1])
    case = type(case)(case.name, case.speed_rpm,
                      TimeSeries(starts, tuple(inp.T_env_K), "previous"),
                      TimeSeries(starts, tuple(inp.T_coolant_K), "previous"),
                      case.sources, grid[-1])
    res = ReferenceModel(spec, 0).transient(case, 600.0, T0=float(cycle.T_ambient_K(0.0)))
    for c in ("T1", "T2", "T_stator"):
        np.testing.assert_allclose(ours[c], np.interp(grid, res.times_s, res.sensor(c)),
                                   atol=1e-9)
    p1 = res.growth_m["P1"] - res.growth_m["P1"][0]
    np.testing.assert_allclose(ours["P1"], np.interp(grid, res.times_s, p1), atol=1e-15)


def test_anchored_greybox_is_the_fem_at_the_spec_values(setup):
    """With the discrepancy added, the grey box at the spec's values returns the FEM
    readings; a parameter change moves it by what it moves the lumped model alone."""
    from compare.fit.discrepancy import fem_discrepancy

    spec, cycle, _ = setup
    grid = np.arange(0.0, 4 * 3600.0 + 1.0, 600.0)
    inp = inputs_from_cycle(cycle, grid)
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    d = fem_discrepancy(gb, CHANNELS, level=0)
    plain = {"spec": gb.simulate({}), "h_air": gb.simulate({"h_air": 2.0})}
    gb.discrepancy = d.offsets
    anchored = {"spec": gb.simulate({}), "h_air": gb.simulate({"h_air": 2.0})}
    from compare.fit.discrepancy import reference_channels

    fem = reference_channels(gb, CHANNELS, level=0)
    for c in CHANNELS:
        scale = 1e-6 if c == "P1" else 1.0
        np.testing.assert_allclose(anchored["spec"][c], fem[c], atol=1e-9 * scale)
        np.testing.assert_allclose(anchored["h_air"][c] - anchored["spec"][c],
                                   plain["h_air"][c] - plain["spec"][c], atol=1e-9 * scale)
    # the lumped model is not the FEM: the offsets are real (T_stator: tenths of a kelvin)
    assert d.rms["T_stator"] > 0.01


def test_prior_penalty_and_plausibility(setup):
    """The prior terms are (z - z_ref) / sd on the fitted scale; a base parameter beyond the
    two-sided 1 % point (2.576 sd) is implausible."""
    spec, _, inp = setup
    out = GreyBox(spec, DRIVES["spl2782"], inp).simulate({})
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, out), CHANNELS)
    free_fit = cal.fit(free=["h_coolant"], start={"h_coolant": 1.0})
    cal.set_prior({"h_coolant": 1.0}, free_fit)
    fit = cal.fit(free=["h_coolant"], start={"h_coolant": 0.5}, max_nfev=1)
    z = np.log(fit.theta["h_coolant"]) / 0.25  # BASE_PARAMS prior_sd of h_coolant
    assert fit.penalty == pytest.approx(0.5 * z * z, rel=1e-12)
    assert cal.prior_z(fit) == {"h_coolant": pytest.approx(z, rel=1e-12)}
    # the plausible range at alpha = 1 % is the normal distribution's two-sided 1 % point
    z_crit = Criteria(alpha=0.01).implausible_z()
    assert z_crit == pytest.approx(2.5758, abs=1e-4)
    fit.theta["h_coolant"] = float(np.exp(-2.6 * 0.25))
    assert abs(cal.prior_z(fit)["h_coolant"]) > z_crit
    fit.theta["h_coolant"] = float(np.exp(-2.5 * 0.25))
    assert abs(cal.prior_z(fit)["h_coolant"]) < z_crit


def test_anderson_solves_a_slow_linear_fixed_point():
    """x = A x + b with contraction 0.95 (plain iteration: ~300 steps to 1e-6): Anderson
    acceleration reaches the exact solution to 1e-8 in a handful of evaluations."""
    from compare.synth.bench import _anderson

    rng = np.random.default_rng(0)
    Q = np.linalg.qr(rng.normal(size=(40, 40)))[0]
    A = Q @ np.diag(np.linspace(0.1, 0.95, 40)) @ Q.T
    b = rng.normal(size=40)
    x, iterations, err = _anderson(lambda x: A @ x + b, np.zeros(40), 1e-8, max_iter=60,
                                   memory=40)
    np.testing.assert_allclose(x, np.linalg.solve(np.eye(40) - A, b), atol=1e-7)
    assert iterations < 45 and err < 1e-8


def test_anderson_takes_a_stalled_iterate_within_what_a_logger_resolves():
    """A fixed point whose evaluations carry an error of their own (here a deterministic
    +-2e-4 K, as a FEM run's round-off) cannot reach a tolerance of 1e-4 K: the best iterate is
    taken where it is within ``accept`` (synth: SOLVED_K, a tenth of the loggers' 0.01 K),
    and refused with the residual named where it is not."""
    from compare.synth.bench import SOLVED_K, _anderson

    calls = []

    def G(x):
        calls.append(1)
        return 0.5 * x + 1.0 + 2e-4 * (-1.0) ** len(calls)

    x, _, err = _anderson(G, np.zeros(3), 1e-4, max_iter=15, accept=SOLVED_K)
    assert 1e-4 <= err < SOLVED_K
    np.testing.assert_allclose(x, 2.0, atol=2 * SOLVED_K)
    with pytest.raises(RuntimeError, match="did not converge: max"):
        _anderson(G, np.zeros(3), 1e-4, max_iter=15)  # accept defaults to the tolerance


def test_synth_coolant_feedback_is_converged(setup):
    """The injected coolant warming satisfies its own equation: the mean coolant
    temperature equals (Ts + R g.T) / (1 + R sum g) from the final FEM run, to 1e-3 K (the
    solver's tolerance is 1e-4 K), with R = 0.008 K/W where a fixed number of plain
    iterations would leave most of the effect out."""
    from compare.synth.bench import _fixed_point
    from reference import ReferenceModel
    from reference.thermal import TWO_PI

    spec, cycle, _ = setup
    case = cycle_load_case(spec, cycle, DRIVES["spl2782"])
    case = type(case)(case.name, case.speed_rpm, case.T_ambient_K, case.T_coolant_K,
                      case.sources, 4 * 3600.0)
    ref = ReferenceModel(spec, 0)
    T0 = float(case.T_ambient_K(0.0))
    R = 0.008
    coolant = LIBRARY["coolant_dynamics"]
    feedback = coolant.feedback(ref.thermal, spec, {"R_adv_K_W": R})
    res, (Tm,), _ = _fixed_point(ref, case, [feedback], 600.0, T0)
    th = ref.thermal
    g = np.sum([TWO_PI * s.h_W_m2K(0.0) * b for s, _, b in th.op.films
                if s.T_ref == "coolant"], axis=0)
    from dataclasses import replace

    from spindle.loads import TimeSeries

    t = res.times_s
    again = th.solve_transient(replace(case, T_coolant_K=TimeSeries(tuple(t), tuple(Tm))),
                               600.0, 1.0, T0, 0, None, {"g": g})
    Ts = np.asarray(case.T_coolant_K(t))
    expected = (Ts + R * again.functionals["g"]) / (1 + R * g.sum())
    np.testing.assert_allclose(Tm, expected, atol=1e-3)
    assert np.max(Tm - Ts) > 0.5  # the coolant does warm (K): the test is not vacuous


def test_blocked_windows_partition_the_run_and_spread_the_validation():
    """5 blocks at fit fraction 0.6: the 2nd and 4th validate, the rest fit, and the two
    windows together are the whole grid; a held-out fold validates on its block only."""
    grid = np.arange(0.0, 10 * 3600.0 + 1.0, 60.0)
    vals = {"T1": np.zeros_like(grid)}
    m = Measured(grid, vals, 0.6, blocks=5)
    assert m.validation_blocks() == [1, 3]
    fit, val = m.mask("T1", "fit"), m.mask("T1", "validation")
    assert not np.any(fit & val) and np.all(fit | val)
    assert [w for _, _, w in m.spans()] == ["fit", "validation", "fit", "validation", "fit"]
    assert abs(val.mean() - 0.4) < 0.01
    held = Measured(grid, vals, 0.6, blocks=5, held_out=4)
    assert np.all(~held.mask("T1", "validation") == (grid < 8 * 3600.0))


def test_cross_validation_of_the_true_model_is_at_the_noise(setup):
    """Data from the grey box itself with 0.05 K and 0.1 µm of white noise: every held-out
    block of the true model's cross-validation (compare.fit.linear: one Gauss-Newton step per
    fold from the fit) is predicted to within the noise (pooled RMS below 1.3 times its sd:
    5 refits of 8 parameters leave far less than that), and a model with f0 held at half its
    true value is not."""
    from compare.fit.linear import local

    spec, _, inp = setup
    out = GreyBox(spec, DRIVES["spl2782"], inp).simulate({"f0": 0.4})
    rng = np.random.default_rng(7)
    sd = {c: 0.1e-6 if c == "P1" else 0.05 for c in CHANNELS}
    vals = {c: out[c] + rng.normal(0, sd[c], len(inp.grid_s)) for c in CHANNELS}
    cal = Calibrator(GreyBox(spec, DRIVES["spl2782"], inp), Measured(inp.grid_s, vals), CHANNELS)
    fit = cal.fit(start={"f0": 0.4})
    cv = local(cal, fit).cross_validation_report(4)
    assert cv["blocks"] == 4
    for c in CHANNELS:
        scale = 1e6 if c == "P1" else 1.0
        assert cv["pooled"][c]["rmse"] < 1.3 * sd[c] * scale, (c, cv["pooled"][c])
        assert cv["pooled"][c]["n"] == len(inp.grid_s)
    wrong = cal.fit(free=["h_air"], start={"f0": 0.2})
    cv_wrong = local(cal, wrong).cross_validation_report(4)
    assert cv_wrong["pooled"]["T1"]["rmse"] > 3 * sd["T1"]


def test_a_parameter_the_run_does_not_determine_leaves_the_others_identifiable():
    """A Jacobian column of zeros (a conductance at a value where it does nothing, as
    G_seat_W_K near 0 on its log scale) makes that parameter not identifiable, and only it:
    the other parameters' intervals are those of the same least squares without the column,
    computed here independently as s^2 (J^T J)^-1 of the reduced Jacobian (tolerance: float
    round-off of a well-conditioned 2 x 2 inverse)."""
    from compare.fit.calibrate import _intervals
    from compare.fit.params import Param

    rng = np.random.default_rng(3)
    n = 200
    J = np.column_stack([rng.normal(size=n), rng.normal(size=n), np.zeros(n)])
    r = rng.normal(scale=0.1, size=n)
    params = {k: Param(k, "-", 0.5, 0.0, 1.0, k, log=False) for k in ("a", "b", "c")}
    free = ["a", "b", "c"]
    z = np.array([0.5, 0.5, 0.5])  # mid-range: no interval is cut by a bound
    ci, _, ident, partners = _intervals(J, r, n, float(n), free, params, z)
    assert ident == {"a": True, "b": True, "c": False}
    assert partners == {}  # c does nothing, with any other fixed or not
    s2 = float(r @ r) / (n - 3)
    sd = np.sqrt(np.diag(np.linalg.inv(J[:, :2].T @ J[:, :2]) * s2))
    for i, k in enumerate(("a", "b")):
        half = 0.5 * (ci[k][1] - ci[k][0])
        assert half == pytest.approx(1.96 * sd[i] * (params[k].hi - params[k].lo), rel=1e-9)


def test_the_optimizer_tolerance_decides_where_a_calibration_stops(setup):
    """Criteria.optimizer_tol is least_squares' ftol and xtol: on noise-free data from
    h_coolant = 1.3, a tolerance of 1e-10 recovers it to round-off (1e-6 relative: the
    finite-difference Jacobian's step is 1e-4) in more evaluations than a loose 1e-1, which
    stops farther from it."""
    spec, _, inp = setup
    gb = GreyBox(spec, DRIVES["spl2782"], inp)
    data = Measured(inp.grid_s, gb.simulate({"h_coolant": 1.3}))
    fits = {}
    for tol in (1e-1, 1e-10):
        cal = Calibrator(gb, data, CHANNELS, tol=tol)
        fits[tol] = cal.fit(free=["h_coolant"], start={"h_coolant": 0.5})
    assert fits[1e-10].theta["h_coolant"] == pytest.approx(1.3, rel=1e-6)
    assert abs(fits[1e-1].theta["h_coolant"] - 1.3) > abs(fits[1e-10].theta["h_coolant"] - 1.3)
    assert fits[1e-1].nfev < fits[1e-10].nfev


def test_the_criteria_optimizer_tolerance_reaches_the_calibration(monkeypatch):
    """run's calibrator takes Criteria.optimizer_tol (so that ``--criterion`` in the
    benchmark and the report's criteria table are what the optimizer used)."""
    from compare.fit import run as fit_run

    class Reached(Exception):
        pass

    def first_fit(self, *args, **kwargs):
        raise Reached(self.tol)

    monkeypatch.setattr(Calibrator, "fit", first_fit)
    spec = load_spec("spl2782")
    from pathlib import Path

    path = Path(__file__).parent / "data" / "peer-runs" / "bench-runs" / "dev-06.csv"
    with pytest.raises(Reached) as got:
        fit_run.calibrate_base(path, spec, fem_level=None,
                               criteria=Criteria(optimizer_tol=3e-7))
    assert got.value.args == (3e-7,)


def test_every_fitted_parameter_cites_the_source_of_its_range_and_prior():
    """Each parameter a fit can move (the base's, the extras', every library effect's) states
    where its bounds and prior width come from (Param.source), and report.json's parameter
    table carries it: a reader judges a calibrated value against its prior's reason."""
    from compare.fit.calibrate import parameters_table
    from compare.fit.effects import LIBRARY
    from compare.fit.params import BASE_PARAMS, EXTRA_BASE_PARAMS

    params = [*BASE_PARAMS.values(), *EXTRA_BASE_PARAMS.values(),
              *(p for e in LIBRARY.values() for p in e.params)]
    assert [p.name for p in params if len(p.source) < 15] == []

    class _Fit:  # the fields parameters_table reads
        free = ("h_air", "G_mount_W_K")
        theta = {"h_air": 1.2, "G_mount_W_K": 30.0}
        ci95 = {"h_air": (1.0, 1.4), "G_mount_W_K": (10.0, 50.0)}
        identifiable = {"h_air": True, "G_mount_W_K": True}

    rows = {r["name"]: r for r in parameters_table(_Fit())}
    assert rows["h_air"]["source"] == BASE_PARAMS["h_air"].source
    assert rows["G_mount_W_K"]["source"] == LIBRARY["mount_conduction"].params[0].source
