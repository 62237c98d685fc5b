"""Load cycles (spindle/cycles.py): shipped cycles, step series, the ambient and coolant
generators, the TOML and CSV readers, bad input and the LoadCase they give."""

from __future__ import annotations

import math
import textwrap
from types import SimpleNamespace

import numpy as np
import pytest

from spindle.cycle_files import load_cycle, read_cycle_steps_csv, read_cycle_toml, shipped_cycles
from spindle.cycles import Cycle, Step, chiller_cycling, drifting_ambient
from spindle.errors import InputError
from spindle.loads import LoadCase, TimeSeries

K0 = 273.15
H = 3600.0

# the documented spl-16h table (docs/cycles.md): speed [rpm], duration [h]
SPL_16H = [(1000, 1.5), (2000, 2.0), (3000, 2.0), (4300, 3.0), (3000, 1.5), (4300, 2.0),
           (2000, 1.0), (1000, 1.0), (0, 2.0)]


def write(tmp_path, name: str, text: str):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text), encoding="utf-8")
    return p


# --------------------------------------------------------------------------- shipped cycles


def test_shipped_cycles_are_listed_and_load_by_name_or_path():
    shipped = shipped_cycles()
    assert {"spl-16h", "nominal"} <= set(shipped)
    for name, path in shipped.items():
        assert load_cycle(name) == load_cycle(path) == load_cycle(str(path))


def test_spl_16h_steps_duration_and_speeds():
    c = load_cycle("spl-16h")
    assert c.name == "spl-16h" and not c.steady
    assert [(s.speed_rpm, s.duration_s / H) for s in c.steps] == SPL_16H
    assert c.duration_s == pytest.approx(16 * H, abs=1e-9)
    assert sum(s.duration_s for s in c.steps) == 16 * H
    assert c.max_speed_rpm == 4300.0  # up to the rated speed, not beyond
    assert 4300.0 in [s.speed_rpm for s in c.steps]  # the rated speed is a plateau
    assert all(s.load_torque_Nm == 0.0 and s.power_kW is None for s in c.steps)  # no load
    assert c.power_kW is None
    assert c.steps[-1] == Step(0.0, 2 * H)  # final standstill cool-down
    assert all(1 * H <= s.duration_s <= 3 * H for s in c.steps)
    # ambient drifts 19.5 -> 22.5 (at 9 h) -> 21.0 degC; coolant 20 +- 0.5 degC
    amb = np.asarray(c.T_ambient_K.values) - K0
    assert amb[0] == pytest.approx(19.5) and amb.max() == pytest.approx(22.5)
    assert c.T_ambient_K(9 * H) - K0 == pytest.approx(22.5)
    assert c.T_ambient_K(16 * H) - K0 == pytest.approx(21.0)
    cool = np.asarray(c.T_coolant_K.values) - K0
    assert cool.min() == pytest.approx(19.5) and cool.max() == pytest.approx(20.5)
    assert c.T_ambient_K.time_s[-1] == c.T_coolant_K.time_s[-1] == 16 * H


def test_nominal_is_a_steady_38kW_point():
    c = load_cycle("nominal")
    assert c.steady and len(c.steps) == 1
    (s,) = c.steps
    assert (s.speed_rpm, s.power_kW, s.duration_s) == (4300.0, 38.0, 12 * H)
    # torque documented as (38 kW - 5146 W of losses) / omega
    assert s.load_torque_Nm == pytest.approx((38e3 - 5146.0) / (4300 * 2 * math.pi / 60), abs=0.01)
    assert c.T_ambient_K == c.T_coolant_K == TimeSeries.constant(20.0 + K0)
    assert c.speed_rpm.is_constant and c.power_kW(5 * H) == 38.0


# --------------------------------------------------------------------------- step series


def test_speed_series_holds_steps_and_lands_on_boundaries():
    c = load_cycle("spl-16h")
    sp = c.speed_rpm
    assert sp.interpolation == "previous"
    starts = np.concatenate([[0.0], np.cumsum([d for _, d in SPL_16H])[:-1]]) * H
    np.testing.assert_array_equal(sp.breakpoints(), starts)
    np.testing.assert_array_equal(c.boundaries_s[:-1], starts)
    for (speed, dur), t0 in zip(SPL_16H, starts, strict=True):
        assert sp(t0) == speed  # a boundary starts the new step
        assert sp(t0 + 0.5 * dur * H) == speed  # held, not interpolated
        assert sp(t0 + dur * H - 1e-6) == speed
        assert c.steps[c.step_index(t0 + 1.0)].speed_rpm == speed
    assert sp(5.5 * H - 1.0) == 3000.0 and sp(5.5 * H) == 4300.0
    assert sp(20 * H) == 0.0  # after the end: the last step
    np.testing.assert_array_equal(sp(np.array([0.5, 1.5, 8.0, 9.0, 11.0]) * H),
                                  [1000.0, 2000.0, 4300.0, 3000.0, 4300.0])
    assert c.load_torque_Nm(5 * H) == 0.0


# --------------------------------------------------------------------------- generators


def test_drifting_ambient_extremes_and_shape():
    D = 16 * H
    ts = drifting_ambient(D, T_start_C=19.5, T_peak_C=22.5, t_peak_h=9.0, T_end_C=21.0,
                          sample_s=900.0)
    t, T = np.asarray(ts.time_s), np.asarray(ts.values) - K0
    assert ts.interpolation == "linear"
    np.testing.assert_allclose(np.diff(t), 900.0)  # 9 h and 16 h are on the 15 min grid
    assert (t[0], t[-1], len(t)) == (0.0, D, 65)
    assert T[0] == pytest.approx(19.5) and T.max() == pytest.approx(22.5)
    assert t[np.argmax(T)] == 9 * H and T[-1] == pytest.approx(21.0)
    assert np.all(np.diff(T[t <= 9 * H]) > 0) and np.all(np.diff(T[t >= 9 * H]) < 0)
    # half-cosine legs, computed by hand: 1/3 of the rise leg -> (1 - cos 60 deg) / 2 = 1/4
    assert ts(3 * H) - K0 == pytest.approx(19.5 + 3.0 * 0.25, abs=1e-9)
    assert ts(4.5 * H) - K0 == pytest.approx(21.0, abs=1e-9)  # half way: the mean
    assert ts(12.5 * H) - K0 == pytest.approx(22.5 - 1.5 * 0.5, abs=1e-9)
    # smooth: zero slope at the start and the peak (first differences small there)
    assert T[1] - T[0] < 0.01 and abs(T[36] - T[35]) < 0.01
    # without T_end the room stays at the peak; a peak after the end only rises
    assert drifting_ambient(D, t_peak_h=9.0)(16 * H) - K0 == pytest.approx(22.5)
    r = drifting_ambient(4 * H, T_start_C=18.0, T_peak_C=24.0, t_peak_h=8.0)
    assert r(4 * H) - K0 == pytest.approx(21.0)


def test_chiller_cycling_extremes_period_and_mean():
    P, D = 1200.0, 16 * H
    ts = chiller_cycling(D, setpoint_C=20.0, band_K=0.5, period_s=P)
    t, T = np.asarray(ts.time_s), np.asarray(ts.values) - K0
    assert T.min() == pytest.approx(19.5) and T.max() == pytest.approx(20.5)
    assert ts(0.0) - K0 == pytest.approx(20.0)  # starts at the set point, warming
    tmax, tmin = t[np.isclose(T, 20.5)], t[np.isclose(T, 19.5)]
    np.testing.assert_allclose(np.diff(tmax), P)
    np.testing.assert_allclose(np.diff(tmin), P)
    assert tmax[0] == 300.0 and tmin[0] == 900.0 and len(tmax) == D / P
    # triangle: 1 K in 600 s each way
    for tq, exp in ((150.0, 20.25), (600.0, 20.0), (1200.0, 20.0), (1350.0, 20.25), (5 * H + 60, 20.1)):
        assert ts(tq) - K0 == pytest.approx(exp, abs=1e-9)
    fine = np.linspace(0.0, 10 * P, 20001)
    Tf = ts(fine) - K0
    mean = float(np.sum(0.5 * (Tf[1:] + Tf[:-1]) * np.diff(fine))) / (10 * P)  # trapezoid rule
    assert mean == pytest.approx(20.0, abs=1e-9)
    assert ts(D) - K0 == pytest.approx(20.0)  # 48 whole periods


def test_chiller_sawtooth_rise_fraction():
    # warms 1 K in 0.25 * 1200 = 300 s, cools 1 K in 900 s; max at 150 s, min at 1050 s
    ts = chiller_cycling(3600.0, setpoint_C=15.0, band_K=0.5, period_s=1200.0, rise_fraction=0.25)
    assert ts(150.0) - K0 == pytest.approx(15.5) and ts(1050.0) - K0 == pytest.approx(14.5)
    assert ts(600.0) - K0 == pytest.approx(15.5 - 450.0 / 900.0)
    assert ts(1200.0) - K0 == pytest.approx(15.0)
    assert ts(1100.0) - K0 == pytest.approx(14.5 + 50.0 / 300.0)
    assert max(ts.values) - K0 == pytest.approx(15.5) and min(ts.values) - K0 == pytest.approx(14.5)


@pytest.mark.parametrize("kwargs, param", [
    ({"band_K": -0.1}, "band_K"), ({"period_s": 0.0}, "period_s"),
    ({"rise_fraction": 1.0}, "rise_fraction"), ({"setpoint_C": 250.0}, "setpoint_C"),
])
def test_chiller_bad_parameters(kwargs, param):
    with pytest.raises(ValueError, match=param):
        chiller_cycling(3600.0, **kwargs)


# --------------------------------------------------------------------------- readers

TOML_STEPS = """\
[cycle]
name = "same"
description = "three steps"
source = "test"
steps = [
  { speed_rpm = 0, duration_s = 600 },
  { speed_rpm = 1500.5, duration_h = 0.5, load_torque_Nm = 12.5, power_kW = 3.25 },
  { speed_rpm = 4300, duration_s = 7200, load_torque_Nm = 0 },
]

[ambient]
T_C = 21.0

[coolant]
T_C = 18.5
"""

CSV_STEPS = """\
# name: same
# description: three steps
# source: test
# T_ambient_C: 21.0
# T_coolant_C: 18.5
# a comment: with a colon is ignored
speed_rpm,duration_s,load_torque_Nm,power_kW
0,600,,
1500.5,1800,12.5,3.25

4300,7200,0,
"""


def test_toml_and_csv_give_the_same_cycle(tmp_path):
    a = read_cycle_toml(write(tmp_path, "a.toml", TOML_STEPS))
    b = read_cycle_steps_csv(write(tmp_path, "b.csv", CSV_STEPS))
    assert a == b
    assert a.steps == (Step(0.0, 600.0), Step(1500.5, 1800.0, 12.5, 3.25), Step(4300.0, 7200.0))
    assert a.duration_s == 9600.0 and a.T_coolant_K(1e4) == pytest.approx(18.5 + K0)
    assert load_cycle(tmp_path / "a.toml") == load_cycle(str(tmp_path / "b.csv"))
    # keyword temperatures override the file's metadata
    c = read_cycle_steps_csv(tmp_path / "b.csv", T_ambient_C=25.0)
    assert c.T_ambient_K(0.0) == pytest.approx(25.0 + K0) and c.T_coolant_K(0.0) == pytest.approx(18.5 + K0)


def test_csv_defaults(tmp_path):
    c = read_cycle_steps_csv(write(tmp_path, "plain.csv", "duration_s,speed_rpm\n60,100\n"))
    assert c.name == "plain" and not c.steady and c.steps == (Step(100.0, 60.0),)
    assert c.T_ambient_K == c.T_coolant_K == TimeSeries.constant(20.0 + K0)


def test_a_time_series_given_for_a_step_cycle_is_named_as_one(tmp_path):
    """synth takes a cycle of steps; given a time series (which solve --cycle runs) it asked
    for a duration_s column."""
    p = write(tmp_path, "ts.csv", "time_s,speed_rpm,T_env_C\n0,4300,20\n60,4300,20\n")
    with pytest.raises(InputError) as err:
        load_cycle(p)
    assert err.value.problem.field.startswith("time_s") and "time series" in str(err.value)
    assert "solve --cycle" in err.value.problem.fix


def test_toml_table_and_generator_temperatures(tmp_path):
    p = write(tmp_path, "t.toml", """\
        [cycle]
        steady = true
        steps = [{ speed_rpm = 2000, duration_h = 2 }]
        [ambient]
        time_h = [0, 1, 2]
        T_C = [20, 22, 21]
        [coolant]
        model = "chiller"
        setpoint_C = 18.0
        band_K = 1.0
        period_s = 600
        """)
    c = read_cycle_toml(p)
    assert c.name == "t" and c.steady
    assert c.T_ambient_K(1.5 * H) == pytest.approx(21.5 + K0)
    assert c.T_coolant_K == chiller_cycling(2 * H, setpoint_C=18.0, band_K=1.0, period_s=600)
    q = write(tmp_path, "d.toml", """\
        [cycle]
        steps = [{ speed_rpm = 2000, duration_h = 16 }]
        [ambient]
        model = "drift"
        T_start_C = 19.5
        T_peak_C = 22.5
        t_peak_h = 9
        T_end_C = 21
        """)
    d = read_cycle_toml(q)
    assert d.T_ambient_K == drifting_ambient(16 * H, T_start_C=19.5, T_peak_C=22.5, t_peak_h=9.0,
                                             T_end_C=21.0)
    assert d.T_coolant_K == d.T_ambient_K  # coolant defaults to the ambient


# --------------------------------------------------------------------------- bad input

BAD_CSV = [
    ("speed_rpm,load_torque_Nm\n1000,0\n", "duration_s", "required column is missing"),
    ("speed_rpm,duration_s\n1000,-60\n", "duration_s (line 2)", "negative"),
    ("speed_rpm,duration_s\n1000,0\n", "duration_s (line 2)", "zero"),
    ("# cycle\nspeed_rpm,duration_s\n1000,60\n-5,60\n", "speed_rpm (line 4)", "negative"),
    ("speed_rpm,duration_s\nfast,60\n", "speed_rpm (line 2)", "not a number"),
    ("speed_rpm,duration_s\n1000,nan\n", "duration_s (line 2)", "not finite"),
    ("speed_rpm,duration_s\n1000,\n", "duration_s (line 2)", "is empty"),
    ("speed_rpm,duration_s\n", "steps", "step table is empty"),
    ("# only a comment\n", "header", "no header"),
    ("speed_rpm,duration_s,torque\n1,1,1\n", "torque (line 1)", "not a step column"),
    ("speed_rpm,duration_s\n1000,60,5\n", "line 2", "has 3 cells"),
    ("# T_ambient_C: 250\nspeed_rpm,duration_s\n1000,60\n", "T_ambient_C (line 1)", "outside -60..200"),
    ("# T_coolant_C: cold\nspeed_rpm,duration_s\n1000,60\n", "T_coolant_C (line 1)", "not a number"),
    ("# steady: maybe\nspeed_rpm,duration_s\n1000,60\n", "steady (line 1)", "not true or false"),
]


@pytest.mark.parametrize("content, field, words", BAD_CSV)
def test_bad_csv_names_file_and_field(tmp_path, content, field, words):
    p = write(tmp_path, "bad.csv", content)
    with pytest.raises(InputError) as exc:
        read_cycle_steps_csv(p)
    prob = exc.value.problem
    assert prob.file == str(p) and prob.field == field and words in prob.message and prob.fix
    assert str(p) in str(exc.value) and field in str(exc.value)


STEP = "{ speed_rpm = 1000, duration_h = 1 }"
BAD_TOML = [
    ("[cycle]\nsteps = []\n", "cycle.steps", "step table is empty"),
    ("[cycle]\nname = 'x'\n", "cycle.steps", "required field is missing"),
    ("[ambient]\nT_C = 20\n", "cycle", "required table is missing"),
    ("[cycle]\nsteps = [{ duration_s = 60 }]\n", "cycle.steps[0].speed_rpm", "missing"),
    ("[cycle]\nsteps = [{ speed_rpm = 1000 }]\n", "cycle.steps[0].duration_s", "exactly one"),
    (f"[cycle]\nsteps = [{STEP}, {{ speed_rpm = 1, duration_h = -1 }}]\n",
     "cycle.steps[1].duration_h", "negative"),
    ("[cycle]\nsteps = [{ speed_rpm = -1000, duration_s = 60 }]\n", "cycle.steps[0].speed_rpm",
     "negative"),
    ("[cycle]\nsteps = [{ speed_rpm = 'fast', duration_s = 60 }]\n", "cycle.steps[0].speed_rpm",
     "not a number"),
    ("[cycle]\nsteps = [{ speed_rpm = 1, duration_s = 60, torque = 5 }]\n",
     "cycle.steps[0].torque", "not a field"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\nT_C = 250.0\n", "ambient.T_C", "outside -60..200"),
    (f"[cycle]\nsteps = [{STEP}]\n[coolant]\ntime_h = [0, 1]\nT_C = [20, -80]\n",
     "coolant.T_C[1]", "outside -60..200"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\ntime_h = [0, 2, 1]\nT_C = [20, 21, 22]\n",
     "ambient.time_h[2]", "does not increase"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\ntime_h = [0, 2]\nT_C = [20]\n", "ambient.T_C",
     "needs a list of 2"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\nmodel = 'sine'\n", "ambient.model", "unknown model"),
    (f"[cycle]\nsteps = [{STEP}]\n[coolant]\nmodel = 'chiller'\nband_K = -0.5\n", "coolant.band_K",
     "must be >= 0"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\nmodel = 'drift'\nT_peak_C = 'warm'\n",
     "ambient.T_peak_C", "not a number"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\nmodel = 'drift'\nT_peak_C = 300\n",
     "ambient.T_peak_C", "outside -60..200"),
    (f"[cycle]\nsteps = [{STEP}]\n[ambient]\nmodel = 'drift'\nperiod_s = 5\n",
     "ambient.period_s", "not a field"),
    (f"[cycle]\nsteps = [{STEP}]\nsteady = 'yes'\n", "cycle.steady", "not true or false"),
    (f"[cycle]\nsteps = [{STEP}]\n[room]\nT_C = 20\n", "room", "not a field"),
    ("[cycle\nsteps = 1\n", "syntax", ""),
]


@pytest.mark.parametrize("content, field, words", BAD_TOML)
def test_bad_toml_names_file_and_field(tmp_path, content, field, words):
    p = write(tmp_path, "bad.toml", content)
    with pytest.raises(InputError) as exc:
        read_cycle_toml(p)
    prob = exc.value.problem
    assert prob.file == str(p) and prob.field == field and words in prob.message and prob.fix
    assert str(p) in str(exc.value) and field in str(exc.value)


def test_load_cycle_bad_names(tmp_path):
    with pytest.raises(InputError, match="neither a file nor a shipped cycle"):
        load_cycle("no-such-cycle")
    with pytest.raises(InputError, match="unknown cycle file type"):
        load_cycle(write(tmp_path, "c.txt", "speed_rpm,duration_s\n1,1\n"))
    with pytest.raises(InputError, match="cannot be read"):
        read_cycle_toml(tmp_path / "missing.toml")


def test_programmatic_steps_are_checked():
    with pytest.raises(ValueError, match="duration_s"):
        Step(1000.0, 0.0)
    with pytest.raises(ValueError, match="speed_rpm"):
        Step(-1.0, 10.0)
    with pytest.raises(ValueError, match="at least one step"):
        Cycle("x", "", "", (), TimeSeries.constant(293.15), TimeSeries.constant(293.15))


# --------------------------------------------------------------------------- load case

FAKE_SPEC = SimpleNamespace(path="fake.toml", heat_sources=[SimpleNamespace(name="stator"),
                                                            SimpleNamespace(name="front_bearing")])


def test_to_load_case():
    c = load_cycle("spl-16h")
    bearing = TimeSeries((0.0, 8 * H), (10.0, 40.0))
    case = c.to_load_case(sources={"front_bearing": bearing})
    assert isinstance(case, LoadCase)
    assert case.name == "spl-16h" and case.duration_s == 16 * H
    for t_h, speed in ((0.0, 1000), (1.5, 2000), (5.49, 3000), (5.5, 4300), (8.0, 4300), (8.5, 3000),
                       (10.0, 4300), (12.0, 2000), (13.0, 1000), (14.0, 0), (16.0, 0)):
        assert case.speed_rpm(t_h * H) == speed
    assert case.T_ambient_K is c.T_ambient_K and case.T_coolant_K is c.T_coolant_K
    assert dict(case.sources) == {"front_bearing": bearing}
    bp = case.breakpoints()
    assert bp[0] == 0.0 and bp[-1] == 16 * H and set(c.boundaries_s) <= set(bp)
    # with a spec: names are checked; others="zero" silences the spec's own sources
    z = c.to_load_case(FAKE_SPEC, {"front_bearing": bearing}, others="zero")
    assert set(z.sources) == {"stator", "front_bearing"} and z.sources["stator"](1.0) == 0.0
    assert z.sources["front_bearing"] is bearing
    assert set(c.to_load_case(FAKE_SPEC).sources) == set()
    with pytest.raises(InputError) as exc:
        c.to_load_case(FAKE_SPEC, {"spindle_motor": bearing})
    assert "fake.toml" in str(exc.value) and "spindle_motor" in str(exc.value)
    with pytest.raises(TypeError):
        c.to_load_case(sources={"stator": 100.0})
    with pytest.raises(ValueError, match="needs the spec"):
        c.to_load_case(others="zero")


def test_nominal_load_case_is_constant():
    case = load_cycle("nominal").to_load_case()
    assert case.duration_s == 12 * H
    assert case.speed_rpm(0.0) == case.speed_rpm(11 * H) == 4300.0
    np.testing.assert_array_equal(case.breakpoints(), [0.0])


def test_a_step_table_too_long_asks_for_its_own_column(tmp_path):
    """A CSV step table has duration_s only: its fix must not offer duration_h, which the
    table refuses as "not a step column" (fuzzing round 6); a TOML cycle may use either."""
    p = write(tmp_path, "long.csv", "speed_rpm,duration_s\n1000,1e12\n")
    with pytest.raises(InputError) as exc:
        load_cycle(str(p))
    assert "duration_s column" in exc.value.problem.fix and "duration_h" not in str(exc.value)


def test_a_time_series_with_some_source_columns_says_which_keep_the_specs_power(tmp_path):
    """A time series that gives the stator's heat and not the bearings' kept the bearings at
    the spec's constant watts, at standstill too, without a word (a user's T1 stayed 47 K up
    after an hour at 0 rpm); now a warning names the columns left out. A file with every
    source's column, or none (the spec's sources throughout, as asked), warns of nothing."""
    import warnings

    from spindle.errors import CycleWarning
    from spindle.loads import read_cycle_csv
    from spindle.spec_reader import load_spec

    spec = load_spec("fin-shaft")
    names = [h.name for h in spec.heat_sources]
    base = spec.default_load_case()
    p = write(tmp_path, "partial.csv", f"time_s,speed_rpm,{names[0]}_W\n0,0,1\n60,0,0\n")
    with pytest.warns(CycleWarning, match=f"no column {names[1]}_W: that source keeps the "
                      "spec's constant power"):
        case = read_cycle_csv(p, names, base)
    assert case.sources[names[1]](30.0) == base.sources[names[1]](30.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CycleWarning)
        read_cycle_csv(write(tmp_path, "all.csv", "time_s," + ",".join(f"{n}_W" for n in names)
                             + "\n0,1,1\n60,0,0\n"), names, base)
        read_cycle_csv(write(tmp_path, "none.csv", "time_s,speed_rpm\n0,0\n60,0\n"), names, base)
