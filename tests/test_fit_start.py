"""Where a bench run starts (compare.fit.start): the grey box and the FEM start from the
first operating point held for a prehistory where the first samples contradict a uniform
start at the room's temperature. And what the run's header says of the spindle."""

from dataclasses import replace

import numpy as np
import pytest

from compare.fit.criteria import Criteria
from compare.fit.greybox import GreyBox
from compare.fit.params import default_theta
from compare.fit.start import first_samples, run_start
from spindle.bench import read_bench
from spindle.bench_inputs import Inputs, interval_inputs
from spindle.drive import drive_for
from spindle.spec_reader import load_spec
from tests.test_bench import PEER_RUNS

SPEC = load_spec("spl2782")


def _inputs(n: int = 120, speed_rpm: float = 4000.0, T_cool_K: float = 291.15) -> Inputs:
    """Two hours at ``speed_rpm`` in a 20 °C room, the coolant at ``T_cool_K``."""
    grid = np.arange(0.0, 60.0 * n + 1.0, 60.0)
    return Inputs(grid, np.full(n, speed_rpm), np.full(n, 2.0), np.zeros(n),
                  np.full(n, 293.15), np.full(n, T_cool_K))


@pytest.mark.parametrize("speed_rpm", [0.0, 4000.0])
def test_the_prehistory_is_the_first_interval_held_that_long(speed_rpm):
    """The grey box on inputs with a prehistory of 3 h reads what the same model reads on
    a run that begins with the first interval held for 3 h, from that run's 3 h on: the
    ordinary step recursion, an independent path to the exact modal step of
    GreyBox._start. Exact to rounding (1e-9 K, 1e-12 m)."""
    tau = 3 * 3600.0
    inputs = _inputs(speed_rpm=speed_rpm)
    n = len(inputs.grid_s) - 1

    def first(x: np.ndarray) -> np.ndarray:
        return np.r_[x[0], x]

    longer = Inputs(np.r_[-tau, inputs.grid_s], *(first(getattr(inputs, k)) for k in (
        "speed_rpm", "power_kW", "load_torque_Nm", "T_env_K", "T_coolant_K")))
    drive = drive_for(SPEC)
    held = GreyBox(SPEC, drive, replace(inputs, prehistory_s=tau)).simulate({})
    ref = GreyBox(SPEC, drive, longer).simulate({})
    for c in ("T1", "T2", "T_stator"):
        np.testing.assert_allclose(held[c], ref[c][1:], rtol=0, atol=1e-9)
        assert abs(held[c][0] - 293.15) > 0.5  # it did move the start
    np.testing.assert_allclose(held["P1"], ref["P1"][1:] - ref["P1"][1], rtol=0, atol=1e-12)
    assert len(held["T1"]) == n + 1


def test_no_prehistory_is_the_uniform_start():
    """prehistory_s = 0 starts every mass at the room's first temperature."""
    gb = GreyBox(SPEC, drive_for(SPEC), _inputs())
    y = gb.simulate({})
    assert all(y[c][0] == 293.15 for c in ("T1", "T2", "T_stator"))


def _start(path):
    run = read_bench(path)
    inputs = interval_inputs(run, 60.0)
    gb = GreyBox(SPEC, drive_for(SPEC), inputs)
    return run_start(gb, default_theta(gb.parameters()),
                     first_samples(run, run.channels, inputs.grid_s), Criteria())


def test_a_run_soaked_by_its_coolant_starts_from_the_soak():
    """The peer's dev2-06 starts with every sensor 1.7-2.0 K below the room, at the
    coolant's temperature (chilled overnight): beyond the tolerance of 1 K
    (Criteria.start_within_tolerances) from a uniform start. The start read from its first
    samples leaves each channel within 0.5 K: the spec's model at rest with that coolant,
    half a tolerance being the material_peak of the criteria table."""
    start = _start(PEER_RUNS / "bench-runs-2" / "dev2-06.csv")
    assert min(start.uniform_misfit.values()) < -1.0
    assert start.prehistory_s > 3600.0
    assert max(abs(v) for v in start.misfit.values()) < 0.5
    assert "does not start at the room's temperature" in start.text()


def test_a_run_whose_first_samples_agree_keeps_the_uniform_start():
    """dev-03's coolant starts 2.9 K below the room but its sensors within 0.6 K of it (the
    coolant not yet flowing): the uniform start agrees with the samples within the
    tolerance, and is kept (the soak would miss them by 2.3 K)."""
    start = _start(PEER_RUNS / "bench-runs" / "dev-03.csv")
    assert start.prehistory_s == 0.0 and start.text() == ""
    assert max(abs(v) for v in start.uniform_misfit.values()) <= 1.0


def test_the_fem_starts_from_the_same_prehistory():
    """compare.fit.discrepancy.fem_readings with a prehistory of 2 h reads what the FEM
    reads on the run that begins with the first interval held for 2 h, from 2 h on: the
    same backward Euler steps of 60 s either way (below discrepancy.PREHISTORY_STEPS), so
    equal to the factorisation's rounding (1e-8 K)."""
    from compare.fit.discrepancy import fem_readings
    from reference import ReferenceModel

    tau = 7200.0
    inputs = _inputs(n=20, speed_rpm=4000.0)
    gb = GreyBox(SPEC, drive_for(SPEC), inputs)
    src = gb.sources(1.0, 0.5)

    def first(x: np.ndarray) -> np.ndarray:
        return np.r_[np.full(120, x[0]), x]

    longer = Inputs(np.r_[np.arange(-tau, 0.0, 60.0), inputs.grid_s],
                    *(first(getattr(inputs, k)) for k in ("speed_rpm", "power_kW",
                                                          "load_torque_Nm", "T_env_K",
                                                          "T_coolant_K")))
    ref = ReferenceModel(SPEC, 0)
    held = fem_readings(ref, SPEC, replace(inputs, prehistory_s=tau),
                        {k: v for k, v in src.items()}, ["T1", "T_stator"])
    whole = fem_readings(ref, SPEC, longer, {k: first(v) for k, v in src.items()},
                         ["T1", "T_stator"])
    for c in ("T1", "T_stator"):
        np.testing.assert_allclose(held[c], whole[c][120:], rtol=0, atol=1e-8)
        assert held[c][0] - 293.15 > 0.5


def test_a_start_no_prehistory_reaches_is_said():
    """A log begun at rest on a spindle 5 K above a room the coolant matches (stopped after
    a run: cooling), and at rest throughout: the first operating point holds every mass at
    the room and the run makes no heat, so no prehistory of its heat reaches the samples;
    the start stays uniform and the warning says the first hours' misfit is partly the
    start's."""
    inputs = _inputs(speed_rpm=0.0, T_cool_K=293.15)
    gb = GreyBox(SPEC, drive_for(SPEC), replace(inputs, power_kW=np.zeros(120)))
    start = run_start(gb, default_theta(gb.parameters()),
                      {"T1": 298.15, "T2": 298.15, "T_stator": 298.15}, Criteria())
    assert not start.reached and start.prehistory_s == 0.0 and start.heat_W is None
    assert "no prehistory of the run's heat reaches" in start.text()


def _ran_elsewhere(tau_s: float, n_hot: int = 10) -> tuple[Inputs, Inputs]:
    """A log begun at 6000 rpm under 2 N m on a spindle that ran at 6000 rpm under 30 N m
    for ``tau_s`` before it; the log reaches that point later, for ``n_hot`` intervals. The
    log's inputs, and the same with that point held for ``tau_s`` in front (60 s steps).
    (One speed: the prehistory's films are the first interval's, compare.fit.start.)"""
    n = 120
    speed, torque = np.full(n, 6000.0), np.full(n, 2.0)
    torque[60:60 + n_hot] = 30.0
    power = (torque * speed * np.pi / 30.0 + 900.0 + 2.0 * torque ** 2) / 1e3
    log = Inputs(np.arange(0.0, 60.0 * n + 1.0, 60.0), speed, power, torque,
                 np.full(n, 293.15), np.full(n, 291.15))
    k = int(tau_s / 60.0)

    def before(x: np.ndarray) -> np.ndarray:
        return np.r_[np.full(k, x[60]), x]

    longer = Inputs(np.r_[np.arange(-tau_s, 0.0, 60.0), log.grid_s],
                    *(before(getattr(log, f)) for f in ("speed_rpm", "power_kW",
                                                        "load_torque_Nm", "T_env_K",
                                                        "T_coolant_K")))
    return log, longer


def test_a_spindle_that_ran_elsewhere_starts_from_a_prehistory_of_its_heat():
    """A log begun lightly loaded on a spindle that ran at its hottest point for 6 h before:
    no time at the light load reaches the first samples (the stator far warmer), so the
    start reads the prehistory's heat too, as a fraction of the run's largest in the
    motor and in the bearings. The first samples are the grey box's own readings after that
    point held for 6 h, by the ordinary step recursion (an independent path to the modal
    step the start reads them with): the start meets them within 0.05 tolerances (the
    least-squares fit's, far below the 1 tolerance of Criteria.start_within_tolerances) and
    the prehistory's heat is the hot point's to 2 % (an exactly determined inversion of three
    readings for three unknowns)."""
    from spindle.drive_file import MOTOR_SOURCES

    tau = 6 * 3600.0
    log, longer = _ran_elsewhere(tau)
    drive = drive_for(SPEC)
    k = int(tau / 60.0)
    whole = GreyBox(SPEC, drive, longer).simulate({})
    first = {c: float(whole[c][k]) for c in ("T1", "T2", "T_stator")}
    gb = GreyBox(SPEC, drive, log)
    theta = default_theta(gb.parameters())
    readings = gb.start_readings(theta)
    for held in np.geomspace(60.0, Criteria().prehistory_max_s, 30):  # the light load held: short
        assert max(abs(v - readings(held)[c]) for c, v in first.items()) > 1.5
    start = run_start(gb, theta, first, Criteria())
    assert start.reached and start.heat_W is not None
    assert max(abs(v) for v in start.misfit.values()) < 0.05
    hot = gb.sources(theta["f0"], theta["rotor_share"])
    for motor in (True, False):
        want = sum(float(v[60]) for n, v in hot.items() if (n in MOTOR_SOURCES) == motor)
        assert start.group_W("motor" if motor else "bearings") == pytest.approx(want, rel=0.02)
    assert "prehistory that ran elsewhere" in start.text()


def test_the_prehistory_heat_starts_grey_box_and_fem_alike():
    """A prehistory of another heat (Inputs.prehistory_heat_W) starts the grey box and the
    FEM as the run that begins with that heat held for the prehistory does, each by its own
    steps: the grey box's modal step against its step recursion (1e-9 K), the FEM's against
    the same backward Euler steps in front (1e-8 K, its factorisation's rounding)."""
    from compare.fit.discrepancy import fem_readings
    from reference import ReferenceModel

    tau = 2 * 3600.0
    log, longer = _ran_elsewhere(tau)
    drive = drive_for(SPEC)
    k = int(tau / 60.0)
    gb = GreyBox(SPEC, drive, log)
    theta = default_theta(gb.parameters())
    hot = gb.sources(theta["f0"], theta["rotor_share"], theta.get("friction_exponent", 0.0))
    heat_W = {n: float(v[60]) for n, v in hot.items()}
    moved = replace(log, prehistory_s=tau, prehistory_heat_W=heat_W)
    held = GreyBox(SPEC, drive, moved).simulate({})
    whole = GreyBox(SPEC, drive, longer).simulate({})
    for c in ("T1", "T2", "T_stator"):
        np.testing.assert_allclose(held[c], whole[c][k:], rtol=0, atol=1e-9)
    ref = ReferenceModel(SPEC, 0)
    short = replace(moved, grid_s=moved.grid_s[:21], **{
        f: getattr(moved, f)[:20] for f in ("speed_rpm", "power_kW", "load_torque_Nm",
                                            "T_env_K", "T_coolant_K")})
    front = replace(longer, grid_s=longer.grid_s[:k + 21], **{
        f: getattr(longer, f)[:k + 20] for f in ("speed_rpm", "power_kW", "load_torque_Nm",
                                                 "T_env_K", "T_coolant_K")})
    fem = fem_readings(ref, SPEC, short, {n: v[:20] for n, v in hot.items()}, ["T1", "T_stator"])
    fem_whole = fem_readings(ref, SPEC, front, {n: np.r_[np.full(k, v[60]), v[:20]]
                                                for n, v in hot.items()}, ["T1", "T_stator"])
    for c in ("T1", "T_stator"):
        np.testing.assert_allclose(fem[c], fem_whole[c][k:], rtol=0, atol=1e-8)
        assert fem[c][0] - 293.15 > 2.0


def test_a_run_of_another_spindle_is_warned_of():
    """A run whose ``# spindle:`` line names another spindle than the spec it is fitted with
    gets a warning (fuzzing round 5 found none); one naming the spec, or a peer's "SPL2782-
    family spindle (not identical to the shipped spl2782 spec)", gets none."""
    from compare.fit.run import _other_spindle

    def run(named):
        return replace(read_bench(PEER_RUNS / "bench-runs-2" / "dev2-06.csv"),
                       metadata={"spindle": named} if named else {})

    from spindle.bench import BenchWarning

    # in the report and on stderr at once (a user's run had it on stdout after the verdict)
    with pytest.warns(BenchWarning, match="names the spindle 'spl9999'"):
        assert "names the spindle 'spl9999'" in _other_spindle(run("spl9999"), SPEC)
    assert _other_spindle(run("SPL2782"), SPEC) == ""
    assert _other_spindle(run("SPL2782-family spindle (not identical to the shipped spl2782 "
                              "spec)"), SPEC) == ""
    assert _other_spindle(run(None), SPEC) == ""


def test_a_moved_start_is_calibrated_from_its_estimate():
    """A moved start's prehistory is a parameter of the grey box (compare.fit.params.PREHISTORY,
    in hours, without a prior), calibrated with the base from the first samples' estimate:
    its default is that estimate, and a value set in theta is the prehistory simulated. A
    uniform start has no such parameter."""
    from compare.fit.params import PREHISTORY

    inputs = _inputs()
    drive = drive_for(SPEC)
    assert PREHISTORY.name not in GreyBox(SPEC, drive, inputs).parameters()
    moved = GreyBox(SPEC, drive, replace(inputs, prehistory_s=7200.0))
    p = moved.parameters()[PREHISTORY.name]
    assert p.default == 2.0 and p.prior_sd is None and p.unit == "h"
    three = GreyBox(SPEC, drive, replace(inputs, prehistory_s=3 * 3600.0)).simulate({})
    np.testing.assert_array_equal(moved.simulate({PREHISTORY.name: 3.0})["T1"], three["T1"])


def test_a_moved_start_is_said_to_be_one():
    """Start.moved: a first sample beyond Criteria.start_within_tolerances of the uniform
    start, and only then a warning."""
    from compare.fit.start import Start

    assert Start({}, {"T1": -1.2}, {"T1": 0.1}, 3600.0).moved
    quiet = Start({}, {"T1": 0.9, "T2": -0.5}, {"T1": 0.9, "T2": -0.5}, 0.0)
    assert not quiet.moved and quiet.text() == ""


@pytest.mark.slow  # about 15 s; the tests above cover the start's pieces
def test_a_control_logged_on_a_running_spindle_fits_as_its_unedited_run(tmp_path):
    """The peer's clean control dev-06 without its first 2 h (fuzzing round 5's c36: the
    bearings 1.9 K warm at 3000 rpm) was "unexplained" with the uniform start; with the start
    read it is "base adequate", as the unedited run (measured 2026-11-29: P1's validation
    RMS 0.47 um)."""
    import sys

    from compare.fit.run import run_fit

    sys.path.insert(0, str(PEER_RUNS.parents[2] / "benchmarks"))
    from bench_start import cut_run

    cut = tmp_path / "dev-06-cut.csv"
    cut_run(PEER_RUNS / "bench-runs" / "dev-06.csv", cut, 7200.0)
    doc = run_fit(cut, SPEC).to_dict()
    assert doc["start"]["prehistory_s"] > 0
    assert doc["verdict"]["kind"] == "base adequate", doc["verdict"]


def test_a_prehistory_elsewhere_has_its_heat_calibrated_up_to_the_runs_largest():
    """A prehistory that ran elsewhere (Inputs.prehistory_heat_W) gives the grey box two
    parameters, its heat in the motor and in the bearings as multiples of the read heat
    (compare.fit.params.PREHISTORY_HEAT, calibrated with the base as prehistory_h is): a
    multiple set in theta is that heat simulated, and each is bounded by the run's largest
    heat in its group over the read one. A group read at no heat has no parameter."""
    from compare.fit.params import PREHISTORY_HEAT
    from spindle.drive_file import MOTOR_SOURCES

    log, _ = _ran_elsewhere(3 * 3600.0)
    drive = drive_for(SPEC)
    gb = GreyBox(SPEC, drive, log)
    theta = default_theta(gb.parameters())
    src = gb.sources(theta["f0"], theta["rotor_share"], theta.get("friction_exponent", 0.0))
    read = {n: 0.5 * float(v[60]) for n, v in src.items()}  # half the hot point's
    moved = GreyBox(SPEC, drive, replace(log, prehistory_s=3 * 3600.0, prehistory_heat_W=read))
    params = moved.parameters()
    motor, bearings = (PREHISTORY_HEAT[g].name for g in ("motor", "bearings"))
    for name, group in ((motor, True), (bearings, False)):
        peak = max(sum(float(v[i]) for n, v in src.items() if (n in MOTOR_SOURCES) == group)
                   for i in range(len(log.grid_s) - 1))
        want = peak / sum(v for n, v in read.items() if (n in MOTOR_SOURCES) == group)
        assert params[name].hi == pytest.approx(want, rel=1e-12) and params[name].default == 1.0
    doubled = {n: (2.0 if n in MOTOR_SOURCES else 1.0) * v for n, v in read.items()}
    same = GreyBox(SPEC, drive, replace(log, prehistory_s=3 * 3600.0, prehistory_heat_W=doubled))
    np.testing.assert_array_equal(moved.simulate({motor: 2.0})["T_stator"],
                                  same.simulate({})["T_stator"])
    no_motor = {n: (0.0 if n in MOTOR_SOURCES else v) for n, v in read.items()}
    cold = GreyBox(SPEC, drive, replace(log, prehistory_s=3600.0, prehistory_heat_W=no_motor))
    assert motor not in cold.parameters() and bearings in cold.parameters()
