"""Test-bench runs (spindle.bench): the format's rules, its errors, and the model inputs."""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from spindle.bench import BenchRun, BenchWarning, check_against_spec, read_bench
from spindle.bench_inputs import bench_grid, inputs
from spindle.drive import drive_for
from spindle.errors import InputError
from spindle.power import bearing_friction, power_balance
from spindle.spec_reader import load_spec

HEADER = "time_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_C,T2_C,T_stator_C,P1_um"


@pytest.fixture(scope="module")
def spec():
    return load_spec("spl2782")


def row(t: float, speed: str = "", power: str = "1.2", env: str = "20.0", cool: str = "20.0",
        t1: str = "22.0", t2: str = "21.5", ts: str = "30.0", p1: str = "1.0") -> str:
    return f"{t:g},{speed},{power},{env},{cool},{t1},{t2},{ts},{p1}"


def good_rows(n: int = 61, dt: float = 60.0) -> list[str]:
    """n rows every dt s (61 x 60 s = one hour): speed 4300 rpm logged once at the start."""
    return [row(i * dt, speed="4300" if i == 0 else "") for i in range(n)]


def write(tmp_path: Path, lines: list[str], name: str = "run.csv", header: str = HEADER,
          comments: tuple[str, ...] = ()) -> Path:
    path = tmp_path / name
    path.write_text("\n".join([*comments, header, *lines]) + "\n", encoding="utf-8")
    return path


def problem(path: Path) -> tuple[str, str, str]:
    """(field, message, fix) of the InputError that reading ``path`` raises."""
    with pytest.raises(InputError) as info:
        read_bench(path)
    p = info.value.problem
    assert p.file == str(path) and p.fix  # every error names the file and gives a fix
    assert str(info.value).startswith(f"{path}: ") and "; fix: " in str(info.value)
    return p.field, p.message, p.fix


# =============================================================================== reading


def test_metadata_comments_column_order_and_unknown_columns(tmp_path):
    header = "P1_um,humidity_pct,T2_C,operator,T_coolant_C,time_s,T_env_C,power_kW,speed_rpm,T1_C"
    lines = [f"{2.0 + i},45,21.5,anna,19.0,{60.0 * i:g},20.5,1.5,{'4300' if i == 0 else ''},"
             f"{22 + 0.1 * i:.1f}" for i in range(61)]
    path = write(tmp_path, lines, header=header, comments=(
        "# spindle: spl2782", "# bench: SPL test stand 2", "# started: 2026-03-02T07:10:00",
        "# exported by the stand software", "# two words: not metadata", "#"))
    run = read_bench(path)
    assert run.metadata == {"spindle": "spl2782", "bench": "SPL test stand 2",
                            "started": "2026-03-02T07:10:00"}
    assert run.channels == ["T1", "T2", "P1"]  # the model's order, not the file's
    assert run.unknown_columns == ["humidity_pct", "operator"]
    np.testing.assert_array_equal(run.extra["humidity_pct"], np.full(61, 45.0))
    assert run.extra["operator"] == ["anna"] * 61  # text kept as text
    assert run.columns["T_coolant_C"][0] == 19.0 and run.columns["T1_C"][10] == pytest.approx(23.0)
    assert run.lines[0] == 8  # file lines, comments and header counted
    assert not run.load_torque_measured
    np.testing.assert_array_equal(run.columns["load_torque_Nm"], np.zeros(61))  # no-load run
    s = run.summary()
    assert s["unknown_columns"] == ["humidity_pct", "operator"]
    assert s["metadata"]["bench"] == "SPL test stand 2"
    assert s["channels"] == {"T1": 61, "T2": 61, "P1": 61}
    assert run.duration_s == 3600.0 and s["rows"] == 61


def test_fast_and_general_parsers_agree(tmp_path):
    """Unquoted files go through numpy's parser (text-valued unknown columns split off by
    hand), quoted ones through the csv module; all give the same numbers."""
    lines = good_rows()
    lines[5] = row(300, speed="", t1="")
    a = read_bench(write(tmp_path, lines, "a.csv"))
    b = read_bench(write(tmp_path, [ln + ',"x"' for ln in lines], "b.csv", header=HEADER + ",note_txt"))
    for col, v in a.columns.items():
        np.testing.assert_array_equal(v, b.columns[col])
    assert b.extra["note_txt"] == ["x"] * 61
    c = read_bench(write(tmp_path, [ln + ",anna" for ln in lines], "c.csv", header=HEADER + ",operator"))
    for col, v in a.columns.items():
        np.testing.assert_array_equal(v, c.columns[col])
    assert c.extra["operator"] == ["anna"] * 61
    assert np.isnan(a.columns["T1_C"][5]) and a.summary()["channels"]["T1"] == 60


def test_bom_crlf_blank_lines_and_comments_between_rows(tmp_path):
    lines = good_rows()
    text = ("\ufeff# spindle: spl2782\r\n" + HEADER + "\r\n" + "\r\n".join(lines[:10])
            + "\r\n\r\n# pause\r\n" + "\r\n".join(lines[10:]) + "\r\n")
    path = tmp_path / "crlf.csv"
    path.write_bytes(text.encode("utf-8"))
    run = read_bench(path)
    assert run.metadata == {"spindle": "spl2782"}
    assert len(run.time_s) == 61
    assert run.lines[9] == 12 and run.lines[10] == 15  # the blank and the comment line counted


def test_trailing_separators_make_no_column(tmp_path):
    run = read_bench(write(tmp_path, [ln + "," for ln in good_rows()], header=HEADER + ","))
    assert run.unknown_columns == [] and run.channels == ["T1", "T2", "T_stator", "P1"]
    filled = [ln + ",7" for ln in good_rows()]
    unnamed = read_bench(write(tmp_path, filled, "b.csv", header=HEADER + ","))
    assert unnamed.unknown_columns == ["(column 10)"]


def test_irregular_sampling_and_gaps_in_summary(tmp_path):
    times = [0, 1, 3, 4, 5, 6, 8, 9, 10] + [10 + 2 * k for k in range(1, 50)] + [2000, 2001, 2003]
    run = read_bench(write(tmp_path, [row(t, speed="1000" if t == 0 else "") for t in times]))
    s = run.summary()
    assert s["rows"] == len(times)
    assert s["median_dt_s"] == pytest.approx(2.0)
    assert s["max_gap_s"] == pytest.approx(2000 - 108)
    assert s["gaps"] == 1 and s["gap_threshold_s"] == pytest.approx(20.0)


def test_p1_is_zeroed_at_its_first_valid_sample_and_channels_are_si(tmp_path):
    lines = good_rows()
    lines[0] = row(0, speed="4300", p1="", t1="21.0")
    lines[1] = row(60, p1="12.5")
    lines[2] = row(120, p1="14.0")
    run = read_bench(write(tmp_path, lines))
    assert run.P1_reference_um == 12.5
    assert np.isnan(run.columns["P1_um"][0]) and run.columns["P1_um"][1] == 0.0
    assert run.columns["P1_um"][2] == pytest.approx(1.5)
    t, y = run.channel("P1")
    assert t[0] == 60.0 and len(t) == 60  # valid samples only
    assert y[1] == pytest.approx(1.5e-6)  # metres
    t, y = run.channel("T1_C")
    assert y[0] == pytest.approx(21.0 + 273.15)  # kelvin
    with pytest.raises(KeyError):
        read_bench(write(tmp_path, good_rows(), "b.csv", header=HEADER.replace("T2_C", "T9_C"))).channel("T2")


def test_big_file_parses(tmp_path):
    """16 h at 1 s (57,600 rows), as a bench exports it; the parse time is in docs/bench.md."""
    n = 57_600
    t = np.arange(n, dtype=float)
    speed = np.where(t < 40_000, 4300.0, 0.0)
    lines = [f"{t[i]:g},{'' if i and speed[i] == speed[i - 1] else f'{speed[i]:g}'},1.2,20.0,20.0,"
             f"{22 + i * 1e-4:.4f},21.5,30.0,{'' if i % 7 == 3 else f'{i * 2e-4:.4f}'}" for i in range(n)]
    run = read_bench(write(tmp_path, lines, comments=("# spindle: spl2782",)))
    assert len(run.time_s) == n and run.duration_s == n - 1
    assert run.columns["T1_C"][-1] == pytest.approx(22 + (n - 1) * 1e-4)
    assert np.count_nonzero(~np.isnan(run.columns["speed_rpm"])) == 2
    assert run.summary()["channels"]["P1"] == n - len(range(3, n, 7))


# ================================================================================ errors

ERRORS = [
    # (name, header, change(lines) -> lines, field contains, message contains)
    ("missing required", HEADER.replace("power_kW", "power_W"), None,
     "power_kW", "required column is missing from the header (line 1) (the header has 'power_W'"),
    ("no channel", "time_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_K",
     lambda ls: [ln.rsplit(",", 3)[0] for ln in ls], "header (line 1)", "no measured channel"),
    ("time empty", HEADER, lambda ls: ls[:5] + [",," + ls[5].split(",", 2)[2]] + ls[6:],
     "time_s (line 7)", "is empty"),
    ("time text", HEADER, lambda ls: ls[:5] + ["5 min" + ls[5][3:]] + ls[6:],
     "time_s (line 7)", "'5 min' is not a number"),
    ("time empty before text", HEADER,
     lambda ls: ls[:5] + [",," + ls[5].split(",", 2)[2]] + ls[6:9] + ["x" + ls[9]] + ls[10:],
     "time_s (line 7)", "is empty"),
    ("time back", HEADER, lambda ls: ls[:10] + [row(500)] + ls[11:], "time_s (line 12)",
     "500 s is not after 540 s on line 11"),
    ("time repeated", HEADER, lambda ls: ls[:10] + [row(540)] + ls[11:], "time_s (line 12)",
     "is not after"),
    ("time negative", HEADER, lambda ls: [row(-1, speed="4300")] + ls[1:], "time_s (line 2)",
     "is negative"),
    ("cell text", HEADER, lambda ls: ls[:20] + [row(1200, t2="n/a")] + ls[21:], "T2_C (line 22)",
     "'n/a' is not a number"),
    ("cell decimal comma", HEADER, lambda ls: ls[:20] + ['1200,,"1,2",20,20,22,21,30,1'] + ls[21:],
     "power_kW (line 22)", "'1,2' is not a number"),
    ("cell inf", HEADER, lambda ls: ls[:3] + [row(180, power="inf")] + ls[4:], "power_kW (line 5)",
     "is not finite"),
    ("required column empty", HEADER, lambda ls: [row(i * 60.0, speed="4300", env="")
                                                  for i in range(61)], "T_env_C",
     "empty in every row"),
    ("every channel empty", HEADER, lambda ls: [row(i * 60.0, speed="4300", t1="", t2="", ts="",
                                                    p1="") for i in range(61)],
     "T1_C, T2_C, T_stator_C, P1_um", "every sensor column is empty in every row"),
    ("kelvin median", HEADER, lambda ls: [ln.replace(",22.0,", ",295.15,") for ln in ls],
     "T1_C (line 2)", "looks like kelvin"),
    ("kelvin one", HEADER, lambda ls: ls[:30] + [row(1800, ts="300")] + ls[31:], "T_stator_C (line 32)",
     "300 (median 30) looks like kelvin"),
    # 5000 K is no bench temperature either: a broken reading, not a unit
    # two rows in a row: no single sample between readings (drop_impossible_samples)
    ("spike", HEADER, lambda ls: ls[:30] + [row(1800, t1="5000"), row(1860, t1="5000")]
     + ls[32:], "T1_C (line 32)",
     "5000 °C is above 250 °C while the column's median is 22 °C: a broken reading"),
    ("too cold", HEADER, lambda ls: ls[:7] + [row(420, cool="-80"), row(480, cool="-80")]
     + ls[9:], "T_coolant_C (line 9)", "-80 °C is below -60 °C"),
    ("speed high", HEADER, lambda ls: ls[:7] + [row(420, speed="258000")] + ls[8:], "speed_rpm (line 9)",
     "above 100000 rpm"),
    ("speed negative and high", HEADER, lambda ls: ls[:7] + [row(420, speed="-258000")] + ls[8:],
     "speed_rpm (line 9)", "above 100000 rpm"),
    ("power in W", HEADER, lambda ls: ls[:7] + [row(420, power="1200")] + ls[8:], "power_kW (line 9)",
     "outside ±1000 kW"),
    ("power very negative", HEADER, lambda ls: ls[:7] + [row(420, power="-1500")] + ls[8:],
     "power_kW (line 9)", "outside ±1000 kW"),
    # Python's float reads 1_0 as 10 (found by fuzzing: it passed as a number)
    ("cell underscore", HEADER, lambda ls: ls[:20] + [row(1200, t1="2_2")] + ls[21:], "T1_C (line 22)",
     "'2_2' is not a number"),
    # a growth of 6500 um is no spindle's: nm exported as um (found by fuzzing: 1e12 passed)
    ("P1 in nm", HEADER, lambda ls: ls[:7] + [row(420, p1="6500"), row(480, p1="6600")] + ls[9:],
     "P1_um (line 9)",
     "beyond ±5000 um"),
    ("too few rows", HEADER, lambda ls: [row(i * 60.0, speed="1") for i in range(40)], "rows",
     "40 rows with a measured channel"),
    ("too short", HEADER, lambda ls: [row(i * 10.0, speed="1") for i in range(100)], "rows",
     "spanning 16.5 min"),
    ("duplicate column", HEADER + ",T1_C", lambda ls: [ln + ",1" for ln in ls], "T1_C (line 1)",
     "column name appears twice (columns 6 and 10)"),
    ("cells missing", HEADER, lambda ls: ls[:12] + [ls[12].rsplit(",", 1)[0]] + ls[13:], "line 14",
     "has 8 cells, the header (line 1) has 9"),
    ("cells extra", HEADER, lambda ls: ls[:12] + [ls[12] + ",7"] + ls[13:], "line 14", "has 10 cells"),
    ("semicolons", HEADER.replace(",", ";"), lambda ls: [ln.replace(",", ";") for ln in ls],
     "header (line 1)", "separated by ';'"),
    ("no header", "0,4300,1.2,20,20,22,21,30,1", None, "header (line 1)", "holds numbers"),
    ("no rows", HEADER, lambda ls: [], "rows", "no data rows"),
]


@pytest.mark.parametrize(("header", "change", "fld", "msg"), [e[1:] for e in ERRORS],
                         ids=[e[0] for e in ERRORS])
def test_errors_name_line_or_column_and_give_a_fix(tmp_path, header, change, fld, msg):
    lines = good_rows()
    if change is not None:
        lines = change(lines)
    got_field, got_msg, _ = problem(write(tmp_path, lines, header=header))
    assert fld in got_field
    assert msg in got_msg


def test_kelvin_fix_says_export_celsius(tmp_path):
    lines = [ln.replace(",20.0,20.0,", ",293.15,20.0,") for ln in good_rows()]
    fld, msg, fix = problem(write(tmp_path, lines))
    assert fld == "T_env_C (line 2)" and "looks like kelvin" in msg and fix.startswith("export °C")


def test_file_level_errors(tmp_path):
    empty = tmp_path / "empty.csv"
    empty.write_text("\n  \n", encoding="utf-8")
    assert problem(empty)[:2] == ("file", "is empty")
    comments = tmp_path / "comments.csv"
    comments.write_text("# spindle: spl2782\n# bench: 2\n", encoding="utf-8")
    assert "no header row" in problem(comments)[1]
    assert "cannot be read" in problem(tmp_path / "missing.csv")[1]
    assert "cannot be read" in problem(tmp_path)[1]  # a folder
    latin = tmp_path / "latin1.csv"
    latin.write_bytes(("# unit: °C\n" + HEADER + "\n" + "\n".join(good_rows())).encode("latin-1"))
    fld, msg, fix = problem(latin)
    assert fld == "line 1" and "not UTF-8" in msg and "0xb0" in msg and "UTF-8" in fix


def test_look_alike_unknown_column_is_kept_with_a_warning(tmp_path):
    lines = [ln + ",295.0" for ln in good_rows()]
    with pytest.warns(BenchWarning, match=r"T2_K: kept as an unknown column .*'T2_C'"):
        run = read_bench(write(tmp_path, lines, header=HEADER + ",T2_K"))
    assert run.unknown_columns == ["T2_K"] and "T2" in run.channels


# ================================================================================ spec


def test_channels_map_to_the_shipped_spec(tmp_path, spec):
    run = read_bench(write(tmp_path, good_rows()))
    assert check_against_spec(run, spec) == ["T1", "T2", "T_stator", "P1"]


def test_channel_without_sensor_is_skipped_and_reported(tmp_path, spec):
    run = read_bench(write(tmp_path, good_rows()))
    no_p1 = dataclasses.replace(spec, sensors=tuple(s for s in spec.sensors if s.name != "P1"))
    with pytest.warns(BenchWarning, match=r"P1_um: the spec 'spl2782' has no sensor 'P1'.*fix: add"):
        assert check_against_spec(run, no_p1) == ["T1", "T2", "T_stator"]
    wrong_kind = dataclasses.replace(spec, sensors=tuple(
        dataclasses.replace(s, kind="temperature") if s.name == "P1" else s for s in spec.sensors))
    with pytest.warns(BenchWarning, match="of kind 'temperature', not 'axial_displacement'"):
        assert "P1" not in check_against_spec(run, wrong_kind)


def test_no_channel_maps_is_an_error(tmp_path, spec):
    run = read_bench(write(tmp_path, good_rows()))
    bare = dataclasses.replace(spec, sensors=())
    with pytest.warns(BenchWarning), pytest.raises(InputError) as info:
        check_against_spec(run, bare)
    p = info.value.problem
    assert p.field == "T1_C, T2_C, T_stator_C, P1_um" and "no measured channel" in p.message
    assert "[[sensors]]" in p.fix


# ========================================================================= model inputs


def test_grid_every_60_s_plus_the_runs_start_and_end(tmp_path):
    lines = [row(5 + i * 60.0, speed="4300" if i == 0 else "") for i in range(60)] + [row(3570), row(3630)]
    run = read_bench(write(tmp_path, lines))
    grid = bench_grid(run)
    assert grid[:3].tolist() == [0.0, 5.0, 60.0] and grid[-2:].tolist() == [3600.0, 3630.0]
    assert (np.diff(grid) > 0).all() and len(grid) == 63
    assert bench_grid(run, 600.0).tolist() == [0.0, 5.0, 600.0, 1200.0, 1800.0, 2400.0, 3000.0,
                                               3600.0, 3630.0]
    with pytest.raises(InputError, match="grid_s"):
        bench_grid(run, 0.0)
    # 1e-4 s over the hour is 3.6e7 points (spindle.units.MAX_SERIES_POINTS): it ran for
    # minutes in the API (found by fuzzing); the command line's --dt had the check
    with pytest.raises(InputError, match="grid_s: 0.0001 s over the run's 1.007 h is more than"):
        bench_grid(run, 1e-4)


def test_a_run_whose_clock_starts_late_gets_the_grid_of_the_shifted_run(tmp_path):
    """A bench that logs the time of day (the run starts at 25,200 s, 7 am, a multiple of the
    grid) gets the grid and the inputs of the same run logged from 0, shifted: the grid
    started at 0 before, so the fit window (the grid's first 60 %) held no sample and fit
    refused every channel (found by shifting a peer's run by 1e6 s)."""
    lines = good_rows()
    shift = 25_200.0
    late = [",".join([str(float(x.split(",")[0]) + shift), *x.split(",")[1:]]) for x in lines]
    early_run = read_bench(write(tmp_path, lines, "early.csv"))
    late_run = read_bench(write(tmp_path, late, "late.csv"))
    np.testing.assert_allclose(bench_grid(late_run), bench_grid(early_run) + shift, rtol=0,
                               atol=1e-9)
    from spindle.bench_inputs import interval_inputs

    a, b = interval_inputs(early_run), interval_inputs(late_run)
    for name in ("speed_rpm", "power_kW", "load_torque_Nm", "T_env_K", "T_coolant_K"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_a_run_whose_clock_starts_late_lasts_as_long_and_loads_alike(tmp_path, spec):
    """The same time-of-day run: its duration is the last time less the first (it was the
    last time, so fit's summary said "7.xx h" for a run of one hour), and the load case it
    gives is the run logged from 0, on the same relative times."""
    lines = good_rows()
    shift = 25_200.0
    late = [",".join([str(float(x.split(",")[0]) + shift), *x.split(",")[1:]]) for x in lines]
    early_run = read_bench(write(tmp_path, lines, "early.csv"))
    late_run = read_bench(write(tmp_path, late, "late.csv"))
    assert late_run.duration_s == early_run.duration_s == early_run.time_s[-1]
    (a, grid_a), (b, grid_b) = inputs(early_run, spec), inputs(late_run, spec)
    np.testing.assert_allclose(grid_b, grid_a + shift, rtol=0, atol=1e-9)
    assert b.duration_s == a.duration_s
    for t in grid_a:
        assert b.speed_rpm(t) == a.speed_rpm(t) and b.T_ambient_K(t) == a.T_ambient_K(t)
        assert all(b.sources[k](t) == a.sources[k](t) for k in a.sources)


def test_speed_is_held_and_leading_gaps_take_the_first_value(tmp_path, spec):
    lines = good_rows()
    lines[0] = row(0, speed="")
    lines[1] = row(60, speed="")
    lines[2] = row(90 + 30, speed="2000")  # at 120 s
    lines[10] = row(600, speed="4300")
    lines[40] = row(2400, speed="0")
    # a measured power moves with the speed (check_power_moves): it stands from 2400 s
    lines[41:] = [row(60.0 * i, power="0.01") for i in range(41, len(lines))]
    run = read_bench(write(tmp_path, lines))
    case, grid = inputs(run, spec)
    speed = np.array([case.speed_rpm(t) for t in grid])
    assert case.speed_rpm.interpolation == "previous"
    np.testing.assert_array_equal(speed[:10], 2000.0)  # before 120 s: the first logged value
    np.testing.assert_array_equal(speed[10:40], 4300.0)
    np.testing.assert_array_equal(speed[40:], 0.0)
    assert case.speed_rpm(659.0) == 4300.0


def test_interval_averages_by_hand(tmp_path, spec):
    # samples at 0, 60, 75, 100, then every 60 s from 180 s (no sample in [120, 180))
    times = [0.0, 60.0, 75.0, 100.0] + [180.0 + 60.0 * k for k in range(58)]
    power = {0.0: "1.0", 60.0: "1.0", 75.0: "2.0", 100.0: "4.5", 180.0: "3.0"}
    env = {60.0: "20.0", 75.0: "21.0", 100.0: "23.0", 180.0: "26.0"}
    lines = [row(t, speed="4300" if t == 0 else "", power=power.get(t, "3.0"), env=env.get(t, "26.0"))
             for t in times]
    lines[3] = row(100.0, power="4.5", env="23.0", t1="")  # a row without T1 is still used
    lines += [row(3600.0 + k, power="") for k in range(1, 3)]  # power not measured at the end
    run = read_bench(write(tmp_path, lines, header=HEADER))
    drive = drive_for(spec)
    case, grid = inputs(run, spec)
    assert grid[:4].tolist() == [0.0, 60.0, 120.0, 180.0]
    # power: the time mean of the logged signal, each sample held until the next (for two
    # grid steps, 120 s, at most). Over [60, 120): 1.0 for 15 s, 2.0 for 25 s, 4.5 for 20 s;
    # over [120, 180): no row from 100 s to 180 s, a silence longer than a grid step (not a
    # gap), so the 180 s value began in it, at its middle, 140 s (input_samples): 4.5 for
    # 20 s, then 3.0 for 40 s
    p_60, p_120 = (15 * 1.0 + 25 * 2.0 + 20 * 4.5) / 60, (20 * 4.5 + 40 * 3.0) / 60
    for t0, p in ((60.0, p_60), (120.0, p_120)):
        expect = drive.heat_W(4300.0, 0.0, p)
        for name, w in expect.items():
            assert case.sources[name](t0 + 1.0) == pytest.approx(w, rel=1e-12)
    # ambient at the grid point 60 s: time mean over the cell [30, 90): the 0 s sample's 26
    # holds to 60 s, then 20 for 15 s and 21 for 15 s; in K
    T_60 = (30 * 26.0 + 15 * 20.0 + 15 * 21.0) / 60
    assert case.T_ambient_K(60.0) == pytest.approx(T_60 + 273.15)
    # at 120 s: cell [90, 150): 21 to 100 s, then the 100 s sample's 23, and from 140 s
    # the 180 s sample's 26 (begun mid-silence, as the power's)
    T_120 = (10 * 21.0 + 40 * 23.0 + 10 * 26.0) / 60
    assert case.T_ambient_K(120.0) == pytest.approx(T_120 + 273.15)
    assert case.T_ambient_K(90.0) == pytest.approx(0.5 * (T_60 + T_120) + 273.15)  # linear
    assert case.T_ambient_K.interpolation == "linear" and case.T_coolant_K(0.0) == pytest.approx(293.15)
    assert case.name == "run" and case.duration_s == 3602.0 and grid[-1] == 3602.0


def test_no_load_heat_is_the_power_balance_at_each_interval(tmp_path, spec):
    lines = [row(i * 60.0, speed="3000" if i == 0 else ("6000" if i == 30 else ""),
                 power=f"{0.9 + 0.01 * (i % 5):.2f}") for i in range(61)]
    power = [float(f"{0.9 + 0.01 * (i % 5):.2f}") for i in range(61)]
    run = read_bench(write(tmp_path, lines))
    case, grid = inputs(run, spec)
    drive = drive_for(spec)
    assert set(case.sources) == {h.name for h in spec.heat_sources}
    for i in (0, 7, 29, 30, 59):
        # each interval's power is its sample's, held over the interval (the one at its end
        # starts no time of its own)
        n, p = 3000.0 if i < 30 else 6000.0, power[i]
        expect = drive.heat_W(n, 0.0, p)
        got = {k: case.sources[k](grid[i]) for k in expect}
        assert got == pytest.approx(expect, rel=1e-12)
        assert case.sources["stator"].interpolation == "previous"


def test_load_torque_is_averaged_into_the_power_balance(tmp_path, spec):
    lines = [f"{row(i * 60.0, speed='4300' if i == 0 else '', power='40')},{80.0 + (i % 2) * 4:g}"
             for i in range(61)]
    run = read_bench(write(tmp_path, lines, header=HEADER + ",load_torque_Nm"))
    assert run.load_torque_measured
    case, grid = inputs(run, spec, grid_s=120.0)
    expect = drive_for(spec).heat_W(4300.0, 82.0, 40.0)  # mean of 80 and 84 N m in each 120 s
    assert {k: case.sources[k](grid[3]) for k in expect} == pytest.approx(expect, rel=1e-12)


def test_standstill_and_noisy_power_do_not_crash(tmp_path, spec):
    """Standstill: no losses, even with a slightly negative power; a running interval whose
    power is below the friction power: motor losses 0, bearings keep their friction heat.
    (Five such intervals of thirty, none beside another: in most, a spindle draws at least
    its bearings' friction, or the run is refused,
    test_a_no_load_power_in_megawatts_or_zero_is_refused; three in a row are refused too,
    test_three_running_intervals_below_the_friction_floor_are_refused.)"""
    lines = [row(i * 60.0, speed="0" if i == 0 else ("12000" if i == 30 else ""),
                 power="-0.02" if i < 30 else ("0.1" if i in (30, 32, 34, 36, 38) else "3.0"))
             for i in range(61)]
    run = read_bench(write(tmp_path, lines))
    with pytest.warns(BenchWarning, match=r"power_kW: in 5 of 60 intervals \(first at t = 1800 s\)"):
        case, grid = inputs(run, spec)
    assert all(case.sources[k](600.0) == 0.0 for k in case.sources)
    drive = drive_for(spec)
    pb = power_balance(drive.motor, drive.bearings, 12000.0, 0.0, drive.T_winding_K)
    assert case.sources["stator"](1830.0) == pytest.approx(0.0, abs=1e-6)
    assert case.sources["front_bearing"](1830.0) == pytest.approx(pb.bearings["front_bearing"].heat_W)


def test_spec_without_drive_is_an_error(tmp_path, spec):
    run = read_bench(write(tmp_path, good_rows()))
    with pytest.raises(InputError) as info:
        inputs(run, dataclasses.replace(spec, power_preset=None))
    assert info.value.problem.field == "power_balance.preset"
    assert "[power_balance] preset" in info.value.problem.fix


def test_benchrun_is_a_plain_record(tmp_path):
    run = read_bench(write(tmp_path, good_rows()))
    assert isinstance(run, BenchRun) and run.path == tmp_path / "run.csv" and run.name == "run"
    assert run.time_s.dtype == float and np.isnan(run.columns["speed_rpm"][1])


def test_settled_speed_merges_drive_scatter_and_keeps_real_steps():
    """A drive's +-5 rpm scatter around 1500 and 6000 rpm collapses to one level per step
    (the median of the step's samples); a real step, however small beyond the band (1 % or
    20 rpm), is kept; a standstill stays 0."""
    from spindle.bench_inputs import settled_speed

    rng = np.random.default_rng(0)
    set_speed = np.repeat([0.0, 1500.0, 1530.0, 6000.0, 0.0], 50)
    logged = set_speed + np.where(set_speed > 0, rng.integers(-5, 6, set_speed.size), 0)
    out = settled_speed(logged)
    for level in (1500.0, 1530.0, 6000.0):
        step = out[set_speed == level]
        assert np.unique(step).size == 1 and abs(step[0] - level) <= 5
    assert np.all(out[set_speed == 0.0] == 0.0)
    assert np.unique(out).size == 4  # 0, 1500, 1530, 6000: five steps, two at standstill


@pytest.mark.parametrize("column, cell", [("P1_um", "p1"), ("T2_C", "t2")])
def test_a_sensor_column_empty_in_every_row_was_not_measured(tmp_path, column, cell):
    """An empty cell means "not measured at this instant" (the format), and users should not
    have to edit their exports: a sensor column empty in every row is read as absent, with a
    warning naming it (it was an error asking to drop the column; found by fuzzing)."""
    path = write(tmp_path, [row(i * 60.0, speed="4300", **{cell: ""}) for i in range(61)])
    with pytest.warns(BenchWarning, match=f"{column}: empty in every row, read as not measured"):
        run = read_bench(path)
    assert column not in run.columns and column.rsplit("_", 1)[0] not in run.channels
    assert len(run.channels) == 3


def test_a_torque_column_empty_in_every_row_is_a_no_load_run_said_so(tmp_path):
    """As a file without the column (the format: absent means a no-load run), with a warning
    that says what that assumes."""
    lines = [row(i * 60.0, speed="4300") + "," for i in range(61)]
    with pytest.warns(BenchWarning, match="load_torque_Nm: empty in every row.*no-load run"):
        run = read_bench(write(tmp_path, lines, header=HEADER + ",load_torque_Nm"))
    assert not run.load_torque_measured and not run.columns["load_torque_Nm"].any()


PEER_RUNS = Path(__file__).resolve().parent / "data" / "peer-runs"


def _without_torque(src: Path, dst: Path) -> Path:
    """The peer's run ``src`` with its load_torque_Nm column dropped, as a bench without a
    torque sensor would export it."""
    out, at = [], None
    for line in src.read_text(encoding="utf-8").splitlines():
        if line.startswith("#"):
            out.append(line)
            continue
        cells = line.split(",")
        at = cells.index("load_torque_Nm") if at is None else at
        out.append(",".join(cells[:at] + cells[at + 1:]))
    dst.write_text("\n".join(out) + "\n", encoding="utf-8")
    return dst


def test_a_loaded_run_without_its_torque_is_refused_where_its_power_cannot_be_losses(
        tmp_path, spec):
    """A run without load_torque_Nm is a no-load run whose power is all heat (the format).
    The peer's dev2-10 (48 N m, up to 33.7 kW) exported without its torque had gone into the
    fit as 33 kW of heat, which ended "unexplained" (and report.html in an internal error).
    Its power exceeds what the drive loses even at its rated torque, which no spindle
    without a load can draw: refused by name, with the fix (exit 2 at the command line)."""
    run = read_bench(_without_torque(PEER_RUNS / "bench-runs-2" / "dev2-10.csv",
                                     tmp_path / "dev2-10.csv"))
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == "load_torque_Nm" and p.file == str(run.path)
    assert "no-load run" in p.message and "rated torque" in p.message
    assert "add the load_torque_Nm column" in p.fix


def test_the_no_load_bound_is_the_drives_losses_at_its_rated_torque(tmp_path, spec):
    """At 4300 rpm, a no-load run may draw up to the losses of the spec's drive at the rated
    torque (the nominal point's P_mech / omega), its bearings' friction taken three times
    (Palmgren's spread), computed here from spindle.power's balance directly: 1 % below
    passes, 1 % above is refused."""
    drive = drive_for(spec)
    omega = drive.nominal.speed_rpm * 2.0 * np.pi / 60.0
    rated = drive.nominal.P_mech_W / omega
    heat = power_balance(drive.motor, drive.bearings, 4300.0, rated,
                         drive.T_winding_K).heat_sources_W()
    limit_kW = sum(q * (3.0 if k in drive.bearings else 1.0) for k, q in heat.items()) / 1e3

    def no_load_W(n: float) -> float:
        return power_balance(drive.motor, drive.bearings, n, 0.0, drive.T_winding_K).total_heat_W

    # the figures docs/bench.md and the docstring quote, to their rounding: 84 N m, five
    # times the no-load losses at 4300 rpm, thirty at 1000 rpm
    assert round(rated) == 84
    assert 4.5 <= 1e3 * limit_kW / no_load_W(4300.0) < 5.5
    low = power_balance(drive.motor, drive.bearings, 1000.0, rated, drive.T_winding_K)
    assert 25.0 <= low.total_heat_W / no_load_W(1000.0) < 35.0
    # and 2.4 at 8000 rpm, where the margin is thinner (2.6 with the bearings' friction
    # three times); a threefold friction factor moves the bound by less than 8 %
    # (docs/bench.md)
    high = power_balance(drive.motor, drive.bearings, 8000.0, rated, drive.T_winding_K)
    assert 2.35 <= high.total_heat_W / no_load_W(8000.0) < 2.45
    rough = {k: dataclasses.replace(b, f0=3.0 * b.f0) for k, b in drive.bearings.items()}
    for n in (1000.0, 4300.0, 8000.0):
        base = power_balance(drive.motor, drive.bearings, n, rated, drive.T_winding_K)
        more = power_balance(drive.motor, rough, n, rated, drive.T_winding_K)
        assert more.total_heat_W < 1.08 * base.total_heat_W
    # an hour at 4300 rpm whose no-load power is the spec's, but for ten minutes at the
    # bound: the median rule (3 times the no-load losses) lets a few intervals through,
    # the loss bound judges each one
    usual_kW = no_load_W(4300.0) / 1e3
    _hour_at_4300(tmp_path, spec, lambda f, i: f * limit_kW if 20 <= i < 30 else usual_kW,
                  ((0.99, False), (1.01, True)), "load_torque_Nm")


def _hour_at_4300(tmp_path, spec, power_kW, cases, field: str) -> None:
    """For each (factor, refused) of ``cases``, an hour at 4300 rpm without a load whose
    interval i draws ``power_kW(factor, i)`` [kW]: refused naming ``field``, or read."""
    for factor, refused in cases:
        lines = [row(i * 60.0, speed="4300", power=f"{power_kW(factor, i):.6f}")
                 for i in range(61)]
        run = read_bench(write(tmp_path, lines, name=f"run-{factor}.csv"))
        if refused:
            with pytest.raises(InputError, match=field):
                inputs(run, spec)
        else:  # read; intervals below the friction are said (motor losses 0 there)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", BenchWarning)
                inputs(run, spec)


def test_the_no_load_median_bound_is_three_times_the_drives_no_load_losses(tmp_path, spec):
    """An hour at 4300 rpm without a load at 2.9 times the drive's no-load losses (from
    spindle.power's balance directly) passes; at 3.1 times it is refused, naming the speed
    (Palmgren's spread, spindle.bench_inputs.PALMGREN_SPREAD)."""
    drive = drive_for(spec)
    no_load_kW = power_balance(drive.motor, drive.bearings, 4300.0, 0.0,
                               drive.T_winding_K).total_heat_W / 1e3
    _hour_at_4300(tmp_path, spec, lambda f, i: f * no_load_kW, ((2.9, False), (3.1, True)),
                  "speed_rpm")


def test_every_peer_run_keeps_the_power_balance():
    """The bounds refuse none of the peer's 23 runs (the figures of docs/bench.md, whose
    table is the benchmark's; these are recomputed): the 17 without a torque column draw at
    most 0.07-0.14 of the no-load bound and at least 6 times their bearings' friction at a
    third of its factor; the 6 loaded ones lose 0.29-0.34 of theirs, their
    load takes a median 0.93-0.94 of the power, and read as if without a load they draw
    4.4-5.2 times the bound. Without a load, 21 of them draw a median 0.24-0.42 times the
    drive's no-load losses (bound 3), at standstill none draws a watt, and none has more
    than one running interval in a row below the friction floor (bound 3)."""
    import spindle.bench_inputs as bi

    spec = load_spec("spl2782")
    drive = drive_for(spec)
    runs = sorted(PEER_RUNS.glob("bench-runs*/*.csv"))
    figures: dict[str, list[float]] = {"no_torque": [], "loaded": [], "without": [], "eta": [],
                                       "friction": [], "no_load": [], "standstill": [],
                                       "stretch": []}
    for path in runs:
        run = read_bench(path)
        raw = bi.interval_inputs(run)
        n, P, M = raw.speed_rpm, raw.power_kW, raw.load_torque_Nm
        bi.check_power_balance(run, drive, raw.grid_s, n, P, M)
        share = bi.no_load_share(drive, n, P, M)[0]
        if np.isfinite(share):
            figures["no_load"].append(share)
        figures["standstill"].append(abs(bi.standstill_power(n, P)[0]))
        figures["stretch"].append(bi.below_friction_stretch(drive, n, P, M)[1])
        ratio = bi.loss_excess(drive, n, P, M).ratio
        if not run.load_torque_measured:
            figures["no_torque"].append(ratio)
            figures["friction"].append(bi.friction_share(drive, n, P))
            continue
        figures["loaded"].append(ratio)
        figures["without"].append(bi.loss_excess(drive, n, P, 0.0 * M).ratio)
        figures["eta"].append(bi.load_efficiency(n, P, M)[0])
    assert len(figures["no_torque"]) == 17 and len(figures["loaded"]) == 6
    for key, lo, hi in (("no_torque", 0.065, 0.145), ("loaded", 0.285, 0.345),
                        ("without", 4.3, 5.25), ("eta", 0.925, 0.945),
                        ("friction", 6.0, 10.5), ("no_load", 0.235, 0.425),
                        ("standstill", 0.0, 0.001), ("stretch", 0, 1)):
        assert lo <= min(figures[key]) and max(figures[key]) <= hi, (key, figures[key])


def _cells_edited(src: Path, dst: Path, column: str, edit, until_s: float = float("inf")
                  ) -> Path:
    """The peer's run ``src``, its rows up to ``until_s`` [s], with each cell of ``column``
    replaced by ``edit(time_s, cell)`` (strings as in the file)."""
    lines = src.read_text(encoding="utf-8").splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("time_s"))
    k = lines[head].split(",").index(column)
    out = lines[:head + 1]
    for ln in lines[head + 1:]:
        cells = ln.split(",")
        if float(cells[0]) > until_s:
            break
        cells[k] = edit(float(cells[0]), cells[k])
        out.append(",".join(cells))
    dst.write_text("\n".join(out) + "\n", encoding="utf-8")
    return dst


def _edited(src: Path, dst: Path, column: str, factor: float = 1.0, swap: str | None = None,
            copy_of: str | None = None, plus: float = 0.0) -> Path:
    """The peer's run ``src`` with ``column`` times ``factor``, or swapped with ``swap`` (its
    header names exchanged), or replaced by the column ``copy_of`` plus ``plus``: an export
    with a unit slip, a mislabelled column or one channel mapped twice."""
    lines = src.read_text(encoding="utf-8").splitlines()
    out, head = [], None
    for line in lines:
        if line.startswith("#"):
            out.append(line)
            continue
        cells = line.split(",")
        if head is None:
            head = cells
            if swap:
                a, b = head.index(column), head.index(swap)
                cells[a], cells[b] = cells[b], cells[a]
            out.append(",".join(cells))
            continue
        k = head.index(column)
        if copy_of:
            v = cells[head.index(copy_of)]
            cells[k] = f"{float(v) + plus:.6g}" if v else ""
        elif cells[k] and factor != 1.0:
            cells[k] = f"{float(cells[k]) * factor:.6g}"
        out.append(",".join(cells))
    dst.write_text("\n".join(out) + "\n", encoding="utf-8")
    return dst


@pytest.mark.parametrize("column, factor, swap, field, words", [
    # a torque in N cm: the load takes 94 times the power drawn (fuzzing: "unexplained")
    ("load_torque_Nm", 100.0, None, "load_torque_Nm", "the load takes more power than the drive"),
    # a power in MW
    ("power_kW", 1e-3, None, "load_torque_Nm", "median of M omega / P_el"),
    # power and torque swapped: 21 kW of losses on a 31 kW run ("a heat of -4684 W")
    ("power_kW", 1.0, "load_torque_Nm", "power_kW", "swapped columns"),
    # a torque of the wrong sign: the load drives the spindle
    ("load_torque_Nm", -1.0, None, "power_kW", "exceed in"),
    # a speed in rad/s
    ("speed_rpm", 2.0 * np.pi / 60.0, None, "power_kW", "a speed in rad/s"),
])
def test_a_loaded_run_whose_power_torque_and_speed_cannot_belong_together_is_refused(
        tmp_path, spec, column, factor, swap, field, words):
    """The peer's loaded dev2-07 with a unit slip or swapped columns: each had been fitted
    to a confident "unexplained" with kilowatts of "something else" (fuzzing round 4); by
    energy conservation it is refused, naming the column and the fix."""
    run = read_bench(_edited(PEER_RUNS / "bench-runs-2" / "dev2-07.csv", tmp_path / "run.csv",
                             column, factor, swap))
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == field and words in p.message + " " + p.fix, str(info.value)


@pytest.mark.parametrize("factor", [1e-3, 0.0])
def test_a_no_load_power_in_megawatts_or_zero_is_refused(tmp_path, spec, factor):
    """dev-06 with its power in MW, or a column of zeros: it turns, so it draws at least
    its bearings' friction; both had been clipped without a word to a confident
    "unexplained" (fuzzing round 4)."""
    run = read_bench(_edited(PEER_RUNS / "bench-runs" / "dev-06.csv", tmp_path / "run.csv",
                             "power_kW", factor))
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == "power_kW" and "less than its bearings' friction" in p.message
    assert "MW" in p.fix


def test_a_no_load_power_in_watts_is_named_as_watts(tmp_path, spec):
    """A no-load run's power in W exceeds the no-load bound as a missing torque would; where
    it also exceeds what the drive draws at its nominal point, the message names the unit
    (it had said "add the load_torque_Nm column")."""
    run = read_bench(_edited(PEER_RUNS / "bench-runs" / "dev-06.csv", tmp_path / "run.csv",
                             "power_kW", 1e3))
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == "power_kW" and "looks like watts" in p.message and "W / 1000" in p.fix


def test_the_load_cells_zero_drift_is_the_fits():
    """The power balance's loaded intervals and the fit's no_load_Nm criterion are one
    figure (spindle cannot read compare's table, so the value stands in both places)."""
    from compare.fit.criteria import Criteria
    from spindle.bench_inputs import LOAD_CELL_ZERO_NM

    assert Criteria().no_load_Nm == LOAD_CELL_ZERO_NM


@pytest.mark.parametrize("change, words, fix", [
    # the time starts again at line 42: two runs in one file (fuzzing: "export the rows in
    # time order without duplicate rows")
    (lambda ls: ls[:40] + [row(i * 60.0) for i in range(21)], "the time starts again",
     "export one run a file (the second starts at line 42)"),
    # a clock set back by 9 min in the middle of a run
    (lambda ls: ls[:40] + [row(1800.0 + i * 60.0) for i in range(21)],
     "the time goes back by 540 s",
     "if the bench's clock was set back"),
    (lambda ls: ls[:10] + [row(540)] + ls[11:], "is not after", "without duplicate rows"),
])
def test_time_that_goes_back_says_how(tmp_path, change, words, fix):
    """A time that is not increasing names what it looks like: a duplicate row, a second
    run appended (the time back near the first row's), or a clock set back."""
    fld, msg, got_fix = problem(write(tmp_path, change(good_rows())))
    assert fld.startswith("time_s (line ") and words in msg and fix in got_fix, (msg, got_fix)


def test_a_run_of_many_rows_in_minutes_asks_for_seconds(tmp_path):
    """16 h logged every 10 s with time_s in minutes spans 16 min: "too little data", and the
    fix now says that 5760 rows in that span is a row every 0.17 s (fuzzing round 4)."""
    lines = [row(i * 10.0 / 60.0, speed="4300" if i == 0 else "") for i in range(5760)]
    fld, msg, fix = problem(write(tmp_path, lines))
    assert fld == "rows" and "spanning 16.0 min" in msg
    assert "a row every 0.167 s: if time_s is in minutes or hours, export seconds" in fix


def test_a_sensor_that_reads_one_value_throughout_is_left_out_with_a_warning(tmp_path):
    """T1 at 20.00 in every row had been fitted as a model that "misses T1 by 2 tolerances"
    (fuzzing round 4). A sensor on a spindle shows at least its noise, so fit leaves such a
    channel out with a BenchWarning naming it; with every channel stuck, nothing is left to
    fit: InputError."""
    from spindle.bench import stuck_channels
    from spindle.bench_clean import without_stuck

    lines = [row(i * 60.0, speed="4300" if i == 0 else "", t2=f"{21.5 + 0.01 * i:.2f}",
                 ts=f"{30 + 0.02 * i:.2f}", p1=f"{1.0 + 0.015 * i:.2f}") for i in range(61)]
    run = read_bench(write(tmp_path, lines))
    assert stuck_channels(run, run.channels) == ["T1"]
    with pytest.warns(BenchWarning, match="T1_C: reads 22 in each of its 61 samples.*left out"):
        assert without_stuck(run, run.channels)[0] == ["T2", "T_stator", "P1"]
    flat = read_bench(write(tmp_path, good_rows(), name="flat.csv"))
    with pytest.raises(InputError, match="every measured channel reads one value"):
        with pytest.warns(BenchWarning):
            without_stuck(flat, flat.channels)


def test_a_stuck_channel_is_named_in_the_fits_report(tmp_path):
    """The warning reaches report.json and report.html, not only stderr: the peer's dev-06,
    its first 2 h, with T1 at 20.00 in every row."""
    from compare.fit.run import run_fit

    path = _cells_edited(PEER_RUNS / "bench-runs" / "dev-06.csv",
                         tmp_path / "dev-06-T1-stuck.csv", "T1_C", lambda t, v: "20.00", 7200.0)
    with pytest.warns(BenchWarning, match="T1_C: reads 20"):
        rep = run_fit(path, load_spec("spl2782"))
    doc = rep.to_dict()
    assert "T1" not in doc["channels"]
    assert any(w.startswith("T1_C reads one value in every row") for w in doc["warnings"])


@pytest.mark.parametrize("factor, unit", [(2.0 * np.pi / 60.0, "rad/s"), (1.0 / 60.0, "Hz")])
def test_a_no_load_speed_in_rad_s_or_hz_is_refused(tmp_path, spec, factor, unit):
    """dev-06 with its speed in rad/s or Hz: without a load all its power is loss, and it
    draws 5 or 37 times the drive's no-load losses at the speeds it logs, where a spindle
    within Palmgren's spread of its spec draws at most 3 times (the peer's no-load runs 0.24-
    0.42: test_every_peer_run_keeps_the_power_balance). Fuzzing round 4 had it fitted to a
    confident "unexplained"."""
    run = read_bench(_edited(PEER_RUNS / "bench-runs" / "dev-06.csv", tmp_path / "run.csv",
                             "speed_rpm", factor))
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == "speed_rpm" and "too low for the power" in p.message, str(info.value)
    assert unit in p.fix


def test_a_loaded_run_whose_speed_reads_zero_is_refused(tmp_path, spec):
    """dev2-07 with a speed column of zeros: at standstill it would draw a median 9 kW, more
    than the drive loses holding its rated torque (4.03 kW), so it turned."""
    run = read_bench(_edited(PEER_RUNS / "bench-runs-2" / "dev2-07.csv", tmp_path / "run.csv",
                             "speed_rpm", 0.0))
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == "speed_rpm" and "standstill" in p.message, str(info.value)


def test_the_standstill_median_skips_the_intervals_next_to_a_start_or_a_stop():
    """An interval at standstill beside a running one may hold a ramp's power: only those
    whose neighbours stand too count (here the 9 kW beside the start is left out)."""
    from spindle.bench_inputs import standstill_power

    speed = np.array([0.0, 0.0, 0.0, 0.0, 3000.0, 3000.0])
    power = np.array([0.0, 0.0, 0.0, 9.0, 2.0, 2.0])
    assert standstill_power(speed, power) == (0.0, 2)


def test_a_column_copied_into_another_is_refused(tmp_path):
    """dev-06 with P1 pasted into T_stator (plus 20, so that it looks like a temperature):
    two sensors never differ by one constant, so read_bench refuses it naming both columns
    (fuzzing round 4 had fitted it as "base adequate")."""
    csv = _edited(PEER_RUNS / "bench-runs" / "dev-06.csv", tmp_path / "run.csv", "T_stator_C",
                  copy_of="P1_um", plus=20.0)
    with pytest.raises(InputError) as info:
        read_bench(csv)
    p = info.value.problem
    assert "copy of the other" in p.message and "T_stator_C" in p.message
    assert "P1_um" in p.message and "channel mapping" in p.fix


def test_the_room_and_the_coolant_may_be_one_sensor(tmp_path):
    """An air-cooled spindle's coolant is the room's air: a bench may export one sensor as
    both T_env_C and T_coolant_C, and the copy check leaves that pair alone."""
    lines = [row(i * 60.0, speed="4300", env=f"{20 + 0.01 * i:.2f}",
                 cool=f"{20 + 0.01 * i:.2f}", t2=f"{21.5 + 0.013 * i:.3f}",
                 ts=f"{30 + 0.02 * i:.2f}", p1=f"{1.0 + 0.015 * i:.3f}") for i in range(61)]
    run = read_bench(write(tmp_path, lines))
    assert np.array_equal(run.columns["T_env_C"], run.columns["T_coolant_C"])


def test_three_running_intervals_below_the_friction_floor_are_refused(tmp_path, spec):
    """An hour at 4300 rpm whose power drops to half the bearings' friction at a third of
    their factor (spindle.power directly) for two intervals is read (a speed step inside an
    interval and its neighbour); for three, the spindle stood while the log held its speed
    (fuzzing round 5: a speed column empty for the last 3 h was fitted as "unexplained")."""
    drive = drive_for(spec)
    low = {k: dataclasses.replace(b, f0=b.f0 / 3.0) for k, b in drive.bearings.items()}
    floor_kW = sum(bearing_friction(b, 4300.0).heat_W for b in low.values()) / 1e3
    usual_kW = power_balance(drive.motor, drive.bearings, 4300.0, 0.0,
                             drive.T_winding_K).total_heat_W / 1e3
    _hour_at_4300(tmp_path, spec,
                  lambda k, i: 0.5 * floor_kW if 20 <= i < 20 + k else usual_kW,
                  ((2, False), (3, True)), "speed_rpm")


PEER_LOADED = PEER_RUNS / "bench-runs" / "dev-08.csv"


def _reversed_copy(src: Path, dst: Path, torque_too: bool) -> int:
    """``src`` with its speed negated from the middle row on (a drive that logs M04 as
    negative), its load torque too where ``torque_too`` (a torque flange whose sign follows
    the direction); returns the number of negative speed samples written."""
    lines = src.read_text().splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.startswith("time_s"))
    cols = lines[head].split(",")
    js, jm = cols.index("speed_rpm"), cols.index("load_torque_Nm")
    body = lines[head + 1:]
    out, turned = [], 0
    for k, ln in enumerate(body):
        cells = ln.split(",")
        if k >= len(body) // 2:
            for j in (js, jm) if torque_too else (js,):
                if cells[j] and float(cells[j]) != 0.0:
                    turned += j == js
                    cells[j] = repr(-float(cells[j]))
        out.append(",".join(cells))
    dst.write_text("\n".join(lines[:head + 1] + out) + "\n")
    return turned


def test_a_spindle_turning_in_reverse_is_read_as_its_speed_magnitude(tmp_path, spec):
    """A drive logs M04 as a negative speed: the format asks for the drive's speed, and a user
    should not have to edit the export. The losses follow |n| and the process's power M n is
    the same in either sign convention, so a run reversed half-way (speed and load torque
    negated, as a torque flange reads) gives the original run's inputs exactly, with a
    warning that counts the samples."""
    back = tmp_path / "reversed.csv"
    turned = _reversed_copy(PEER_LOADED, back, torque_too=True)
    assert turned > 100
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run = read_bench(back)
    said = [str(w.message) for w in caught if issubclass(w.category, BenchWarning)]
    assert any(f"negative in {turned} of" in m and "reverse" in m and "torque" in m
               for m in said), said
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ref = read_bench(PEER_LOADED)
    for col in ("speed_rpm", "load_torque_Nm"):
        np.testing.assert_array_equal(run.columns[col], ref.columns[col])
    case, grid = inputs(run, spec)
    case_ref, grid_ref = inputs(ref, spec)
    np.testing.assert_array_equal(grid, grid_ref)
    for k in case_ref.sources:
        np.testing.assert_array_equal(case.sources[k].values, case_ref.sources[k].values)


@pytest.mark.parametrize("name, edit", [
    # classic Mac "CSV (Macintosh)": lines end in a carriage return alone
    ("CR line ends", lambda text: text.replace("\n", "\r")),
    # an export with its byte-order mark, appended to comment lines written before it
    ("mark after comments", lambda text: "# bench: 2\n\ufeff" + text),
    # the separator hint a spreadsheet writes as the first line
    ("sep= line", lambda text: "sep=,\n" + text),
])
def test_spreadsheet_dialects_read_as_the_plain_file(tmp_path, name, edit):
    """Three ways spreadsheets write a CSV that the format's reader had refused with a
    misleading message ("no header row", "time_s is missing"; fuzzing round 6): each reads
    as the plain file."""
    plain = write(tmp_path, good_rows(), name="plain.csv")
    other = tmp_path / "other.csv"
    other.write_bytes(edit(plain.read_text(encoding="utf-8")).encode("utf-8"))
    a, b = read_bench(plain), read_bench(other)
    np.testing.assert_array_equal(a.time_s, b.time_s)
    assert a.columns.keys() == b.columns.keys()
    for k in a.columns:
        np.testing.assert_array_equal(a.columns[k], b.columns[k])


def test_an_unknown_column_twice_is_kept_twice(tmp_path):
    """The format: unknown columns are kept and reported, never an error; a name twice is
    kept as both, the second named by its column. A known column twice stays an error (which
    one holds the measurement is not known)."""
    lines = [f"{ln},{i},{2 * i}" for i, ln in enumerate(good_rows())]
    run = read_bench(write(tmp_path, lines, header=HEADER + ",aux_V,aux_V"))
    assert run.unknown_columns == ["aux_V", "aux_V (column 11)"]
    assert run.extra["aux_V (column 11)"][3] == 6.0
    lines = [f"{ln},1.0" for ln in good_rows()]
    fld, message, _ = problem(write(tmp_path, lines, name="t1.csv", header=HEADER + ",T1_C"))
    assert fld == "T1_C (line 1)" and "appears twice" in message


def test_a_power_that_reads_one_value_while_the_speed_changes_is_refused(tmp_path, spec):
    """The peer's dev-06 with its power column a constant 0.15 kW (fuzzing round 6: a
    control then ended "unexplained"). Friction and motor losses follow the speed, so a
    measured power moves with it; one value throughout is no measurement."""
    src = PEER_RUNS / "bench-runs" / "dev-06.csv"
    run = read_bench(_edited(src, tmp_path / "run.csv", "power_kW", 0.0))
    run.columns["power_kW"][:] = 0.15
    with pytest.raises(InputError) as info:
        inputs(run, spec)
    p = info.value.problem
    assert p.field == "power_kW" and "reads 0.15 kW in every row" in p.message
    assert "measured electrical power" in p.fix


def test_a_file_with_nul_bytes_names_the_line_without_echoing_them(tmp_path):
    """A logger that lost power pads its file with zero bytes; the message had echoed a
    cell of 200 of them to the terminal (fuzzing round 6)."""
    path = write(tmp_path, good_rows())
    lines = path.read_bytes().split(b"\n")
    path.write_bytes(b"\n".join(lines[:10] + [b"\x00" * 200] + lines[10:]))
    fld, message, fix = problem(path)
    assert fld == "line 11" and "NUL bytes" in message and "\x00" not in message + fix


def test_a_coolant_that_reads_the_room_on_a_water_cooled_spec_is_said(tmp_path, spec):
    """Fuzzing round 6: the peer's dev-01 with its coolant column the room's named a lag at
    its bound without a word. A chiller's supply is regulated apart from the room, and two
    sensors carry their own noise, so the same value in every row is the room's column
    twice; on a spec without coolant films (fin-shaft) the room's air is the coolant."""
    from spindle.bench_clean import coolant_as_room

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        run = read_bench(PEER_RUNS / "bench-runs" / "dev-01.csv")
    assert coolant_as_room(run, spec) is None
    run.columns["T_coolant_C"] = run.columns["T_env_C"].copy()
    said = coolant_as_room(run, spec)
    assert said and "looks like the room's" in said and "fix:" in said
    assert coolant_as_room(run, load_spec("fin-shaft")) is None


@pytest.mark.parametrize("column, cell", [("T1_C", "850"), ("T2_C", "-999"),
                                          ("P1_um", "9999"), ("T_env_C", "-999")])
def test_a_single_sample_no_sensor_reads_is_read_as_not_measured(tmp_path, column, cell):
    """A logger's no-data code or an open PT100 between two readings (fuzzing round 6: one
    such cell in 5531 rows refused the whole run, and the user had to edit the export): read
    as not measured, with a warning naming the column, the value and the line. Two such
    samples in a row stay refused (the ERRORS above), and so does a single value that is a
    plausible temperature in kelvin ("kelvin one")."""
    j = HEADER.split(",").index(column)
    lines = good_rows()
    cells = lines[20].split(",")
    cells[j] = cell
    lines[20] = ",".join(cells)
    with pytest.warns(BenchWarning, match=rf"{column}: 1 single sample.* \({cell} on line 22\)"):
        run = read_bench(write(tmp_path, lines))
    y = run.columns[column]
    assert np.isnan(y[20]) and np.count_nonzero(np.isnan(y)) == 1


OWN_SPECS = Path(__file__).resolve().parent / "data" / "own-specs"


def test_a_high_speed_spindle_at_its_losses_passes_the_power_balance(tmp_path):
    """gs24 (a user's 15 kW / 24 000 rpm grinder) with a load cell at 0.4 N m, within its
    zero, and losses three times the drive's friction: drawn runs like it had been refused
    twice, once as losses beyond the rated torque's (friction dominates there; the bound now
    takes the bearings' friction three times, Palmgren's spread) and once as speeds too low
    for the power (0.4 N m at 24 000 rpm is 1 kW of the power; the no-load median now takes
    the logged M omega out). Energy is still checked: a run drawing 4 times the losses
    without a torque column is refused."""
    spec = load_spec(OWN_SPECS / "gs24.toml")
    drive = drive_for(spec)
    n, torque = 24000.0, 0.4
    omega = n * 2.0 * np.pi / 60.0
    heat = drive.heat_W(n, torque, None)
    losses = sum(q * (3.0 if k in drive.bearings else 1.0) for k, q in heat.items())
    header = HEADER + ",load_torque_Nm"

    def hour(power_kW: float, name: str, with_torque: bool = True) -> Path:
        lines = [row(i * 60.0, speed=f"{n:g}", power=f"{power_kW:.6f}")
                 + (f",{torque:g}" if with_torque else "") for i in range(61)]
        return write(tmp_path, lines, name=name, header=header if with_torque else HEADER)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BenchWarning)
        inputs(read_bench(hour(0.99 * (losses + torque * omega) / 1e3, "ok.csv")), spec)
    with pytest.raises(InputError):
        inputs(read_bench(hour(4.0 * losses / 1e3, "four.csv", with_torque=False)), spec)


def test_an_interval_at_a_logging_gap_is_not_judged_by_the_loss_bound(tmp_path):
    """A speed change inside a logging gap leaves the interval at the gap's end with the old
    speed and the new power (a drawn ms12 run, 7800 -> 16 500 rpm in a 20 min gap, was
    refused as 1.1 times the losses any spindle makes). Such intervals are left to the fit,
    which places the change (compare.fit.gaps); the loss bound judges every other one, so
    a unit slip is still refused (the tests above)."""
    from spindle.bench_inputs import gap_intervals

    spec = load_spec("spl2782")
    drive = drive_for(spec)
    header = HEADER + ",load_torque_Nm"
    omega = 6000.0 * 2.0 * np.pi / 60.0
    high_kW = (sum(drive.heat_W(6000.0, 60.0, None).values()) + 60.0 * omega) / 1e3
    low_kW = sum(drive.heat_W(1500.0, 0.0, None).values()) / 1e3
    lines = [row(i * 10.0, speed="1500", power=f"{low_kW:.4f}") + ",0" for i in range(90)]
    lines += [row(1800.0 + i * 10.0, speed="6000", power=f"{high_kW:.4f}") + ",60"
              for i in range(180)]  # silent from 890 s to 1800 s: the change inside
    run = read_bench(write(tmp_path, lines, header=header))
    grid = bench_grid(run, 60.0)
    at_gap = gap_intervals(run.time_s, grid)
    assert at_gap.any() and not at_gap[:14].any() and not at_gap[32:].any()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", BenchWarning)
        inputs(run, spec)
