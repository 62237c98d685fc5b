"""The command line: outputs, messages and exit status 2 for bad input."""

import argparse
import json
import subprocess
import sys
from pathlib import Path

import pytest

from compare.cli import main


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "compare", *args], capture_output=True,
                          text=True, timeout=300)


def test_help():
    r = run("--help")
    assert r.returncode == 0 and "solve" in r.stdout and "mesh" in r.stdout


def test_version_is_the_installed_distributions():
    """--version prints the version pyproject.toml gives the installed package (issue 34)."""
    import tomllib
    from pathlib import Path

    meta = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())
    r = run("--version")
    assert r.returncode == 0 and r.stdout.strip() == f"spindle-verify {meta['project']['version']}"


def test_specs_lists_shipped(capsys):
    assert main(["specs"]) == 0
    out = capsys.readouterr().out
    assert "spl2782" in out and "fin-shaft" in out


def test_mesh_command(tmp_path, capsys):
    assert main(["mesh", "fin-shaft", "--level", "1", "--out", str(tmp_path / "m")]) == 0
    info = json.loads((tmp_path / "m" / "mesh.json").read_text())
    assert [row["level"] for row in info["levels"]] == [0, 1]
    assert (tmp_path / "m" / "mesh_level1.png").exists()
    assert (tmp_path / "m" / "mesh_level1.vtu").exists()


def test_solve_steady_writes_everything(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["solve", "spl2782", "--level", "0", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "T1" in text and "relative imbalance" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["energy"]["relative_imbalance"] < 1e-10
    assert summary["relative_residual"] <= 1e-8
    assert "P1_um" in text and "TCP_um" in text
    assert summary["growth_um"]["P1"] > 0
    for f in ("sensors.csv", "temperature.vtu", "temperature_section.png",
              "temperature_3d.png", "sensor_profile.png", "deformation_section.png"):
        assert (out / f).stat().st_size > 0
    assert not list(tmp_path.glob(".*tmp*"))


def test_solve_cycle(tmp_path, capsys):
    cycle = tmp_path / "c.csv"
    cycle.write_text("# warm-up and stop\ntime_s,speed_rpm,T_env_C,stator_W\n"
                     "0,4300,20,2000\n3600,0,21,0\n7200,0,21,0\n")
    out = tmp_path / "t"
    assert main(["solve", "spl2782", "--level", "0", "--cycle", str(cycle), "--dt", "600",
                 "--out", str(out), "--quiet"]) == 0
    assert (out / "temperature.pvd").exists()
    rows = (out / "sensors_timeseries.csv").read_text().splitlines()
    assert rows[0].startswith("time_s,T1_C") and rows[0].endswith("P1_um,TCP_um")
    assert len(rows) == 1 + 13
    assert (out / "T1_P1_tolerance.png").exists()
    assert "peak_C" in capsys.readouterr().out


@pytest.mark.parametrize("content, words", [
    ("# a comment\ntime_s,speed_rpm\n0,100\n0,200\n", "time_s (line 4): time does not increase"),
    ("time_s,speed_rpm\n0,abc\n10,1\n", "speed_rpm (line 2): 'abc' is not a number"),
    ("speed_rpm\n0\n", "duration_s: required column is missing"),  # read as a step table
    ("time_s,torque_Nm\n0,1\n10,1\n", "torque_Nm: is not a cycle column"),
    ("time_s,T_env_C\n0,293\n10,293\n", "outside -60..200 degC"),
    # a negative loss ended the stator at -83 degC with exit 0; 1e300 W overflowed
    ("time_s,Q1_rear_bearing_A_W\n0,-5000\n10,0\n", "-5000 W is outside 0..1e+06 W"),
    ("time_s,Q1_rear_bearing_A_W\n0,1e300\n10,0\n", "1e+300 W is outside 0..1e+06 W"),
])
def test_bad_cycle_exits_2(tmp_path, capsys, content, words):
    # in-process (compare.cli.main, as the command runs it): a Python process a case cost
    # 2 s each; the command's own process is the other tests' run()
    cycle = tmp_path / "bad.csv"
    cycle.write_text(content)
    assert main(["solve", "fin-shaft", "--level", "0", "--cycle", str(cycle), "--out",
                 str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert words in err and "Traceback" not in err
    assert "bad.csv" in err and "fix:" in err
    assert not (tmp_path / "o").exists()


def test_bad_spec_exits_2_without_output(tmp_path):
    spec = tmp_path / "broken.toml"
    spec.write_text('[spindle]\nname = "x"\n[operating]\nT_ambient_K = 293.15\n'
                    '[[parts]]\nname = "s"\nrole = "shaft"\nmaterial = "steel_42CrMo4"\n'
                    'sections = [{ z_start = 0.0, z_end = 0.1, r_inner = 0.05, r_outer = 0.04 }]\n')
    r = run("solve", str(spec), "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    assert "broken.toml: parts[0].sections[0].r_inner" in r.stderr
    assert "Traceback" not in r.stderr
    assert not (tmp_path / "o").exists()


def test_bad_option_exits_2(tmp_path):
    r = run("solve", "fin-shaft", "--level", "9", "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "--level" in r.stderr


@pytest.mark.parametrize("extra, words", [
    (["none", "G_seat_W_K"], "none with other parameters"),
    (["seat"], "invalid choice"),
])
def test_fit_bad_base_extra_exits_2(tmp_path, capsys, extra, words):
    assert main(["fit", str(tmp_path / "run.csv"), "--base-extra", *extra, "--out",
                 str(tmp_path / "o")]) == 2  # in-process, as test_bad_cycle_exits_2
    err = capsys.readouterr().err
    assert "--base-extra" in err and words in err
    assert "Traceback" not in err and not (tmp_path / "o").exists()


def test_fit_refuses_a_loaded_run_without_its_torque_before_any_fitting(tmp_path):
    """The peer's dev2-10 exported without load_torque_Nm: one message naming the column and
    the fix, exit 2, nothing written (it had fitted 33 kW of heat and ended in an internal
    error while writing report.html)."""
    from tests.test_bench import PEER_RUNS, _without_torque

    csv = _without_torque(PEER_RUNS / "bench-runs-2" / "dev2-10.csv", tmp_path / "dev2-10.csv")
    r = run("fit", str(csv), "--spec", "spl2782", "--out", str(tmp_path / "o"))
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert f"{csv}: load_torque_Nm: the run has no load torque" in r.stderr
    assert "fix: add the load_torque_Nm column" in r.stderr
    assert not (tmp_path / "o").exists()


def test_output_never_overwrites_input(tmp_path):
    spec = tmp_path / "sensors.csv"  # an input named like an output
    from spindle.spec_reader import load_spec

    spec.write_text(open(load_spec("fin-shaft").path).read())
    before = spec.read_text()
    # a .csv spec is still TOML; the output folder is the spec's own folder
    r = run("solve", str(spec), "--level", "0", "--out", str(tmp_path), "--no-pictures")
    assert r.returncode == 2 and "overwrite" in r.stderr
    assert spec.read_text() == before


def test_solve_nominal_case_uses_the_power_balance(tmp_path, capsys):
    out = tmp_path / "n"
    assert main(["solve", "spl2782", "--case", "nominal", "--level", "0", "--out", str(out),
                 "--no-pictures"]) == 0
    summary = json.loads((out / "summary.json").read_text())
    # the nominal cycle gives 38 kW electrical at 4300 rpm: losses P_el - P_shaft = 5146 W
    assert summary["energy"]["heat_in_W"] == pytest.approx(5146.0, rel=1e-3)
    assert summary["speed_rpm"] == 4300.0


def test_solve_shipped_cycle_and_step_csv(tmp_path, capsys):
    out = tmp_path / "c"
    assert main(["solve", "spl2782", "--cycle", "spl-16h", "--level", "0", "--dt", "1800",
                 "--out", str(out), "--quiet", "--no-pictures"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["duration_s"] == 16 * 3600 and s["peak_growth_um"]["P1"] > 0
    steps = tmp_path / "steps.csv"
    steps.write_text("speed_rpm,duration_s\n4300,3600\n0,3600\n")
    assert main(["solve", "spl2782", "--cycle", str(steps), "--level", "0", "--dt", "900",
                 "--out", str(tmp_path / "s"), "--quiet", "--no-pictures"]) == 0
    s2 = json.loads((tmp_path / "s" / "summary.json").read_text())
    assert s2["duration_s"] == 7200 and s2["peak_C"]["T1"] > 20.0


def test_solve_lumped_steady_and_cycle(tmp_path, capsys):
    out = tmp_path / "l"
    assert main(["solve", "spl2782", "--model", "lumped", "--nodes", "paper11", "--case",
                 "nominal", "--out", str(out), "--no-pictures"]) == 0
    text = capsys.readouterr().out
    assert "lumped function-block model, 11 nodes" in text and "P1_um" in text
    summary = json.loads((out / "summary.json").read_text())
    assert summary["model"] == {"kind": "lumped", "nodes": 11, "masses": 48}
    assert abs(summary["energy"]["relative_imbalance"]) < 1e-12
    assert (out / "masses.csv").exists()
    out2 = tmp_path / "c"
    assert main(["solve", "spl2782", "--model", "lumped", "--nodes", "5", "--cycle", "spl-16h",
                 "--dt", "300", "--quiet", "--out", str(out2)]) == 0
    assert "exact zero-order hold" in capsys.readouterr().out
    assert (out2 / "T1_P1_tolerance.png").exists()
    assert "P1_um" in (out2 / "sensors_timeseries.csv").read_text().splitlines()[0]


@pytest.mark.parametrize("nodes", ["1", "paper7"])
def test_bad_node_count_exits_2(tmp_path, capsys, nodes):
    assert main(["solve", "fin-shaft", "--model", "lumped", "--nodes", nodes, "--out",
                 str(tmp_path / "x")]) == 2  # in-process, as test_bad_cycle_exits_2
    err = capsys.readouterr().err
    assert "--nodes" in err and "fix:" in err
    assert "Traceback" not in err and not (tmp_path / "x").exists()


def test_crosscheck_is_a_command():
    r = run("crosscheck", "--help")
    assert r.returncode == 0 and "CalculiX" in r.stdout and "--keep-deck" in r.stdout


def test_sensors_command(tmp_path, capsys):
    out = tmp_path / "s"
    assert main(["sensors", "fin-shaft", "--nodes", "3", "11", "--level", "1", "--tol-temp",
                 "30", "--quiet", "--no-pictures", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "Recommended: N = 3, the smallest node count" in text  # 22.6 K on the warm-up < 30 K
    assert (out / "nodes.csv").exists()


def test_an_internal_error_is_one_line_with_the_traceback_in_a_file(tmp_path, monkeypatch, capsys):
    """A bug (an exception that is not a SpindleVerifyError) ends in one line on stderr that
    says it is not the user's input and where its traceback was written, exit status 1 (2 is
    bad input), and no output folder."""
    import compare.fit.run

    def broken(*args, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(compare.fit.run, "run_fit", broken)
    monkeypatch.setattr("tempfile.tempdir", str(tmp_path))
    run_csv = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs" / "dev-01.csv"
    out = tmp_path / "o"
    assert main(["fit", str(run_csv), "--out", str(out), "--quiet"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "internal error: RuntimeError: boom" in err and "not your input" in err
    crash = next(tmp_path.glob("spindle-verify-crash-*.txt"))
    assert crash.name in err and "RuntimeError: boom" in crash.read_text(encoding="utf-8")
    assert not out.exists()


def test_running_out_of_memory_is_the_problems_size_not_a_bug(tmp_path, monkeypatch, capsys):
    """A mesh level the machine cannot hold ran into MemoryError, reported as an internal
    error (fuzzing round 6: level 3 of a spec with h0_m = 0.6 mm under a 2.5 GB limit). It
    is the size asked for: one line naming what to make smaller, exit 2, no output."""
    import compare.fit.run

    def too_big(*args, **kwargs):
        raise MemoryError

    monkeypatch.setattr(compare.fit.run, "run_fit", too_big)
    run_csv = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs" / "dev-01.csv"
    out = tmp_path / "o"
    assert main(["fit", str(run_csv), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ran out of memory" in err and "fix: a coarser --level" in err
    assert "internal error" not in err and not out.exists()


def test_synth_on_a_spec_without_a_drive_or_p1_names_what_it_needs(tmp_path):
    """synth writes a bench run: its power column needs the spec's drive (fin-shaft has none);
    it was an internal error (a KeyError or an AttributeError) before."""
    r = run("synth", "--spec", "fin-shaft", "--level", "0", "--cycle", "nominal", "--out",
            str(tmp_path / "run.csv"))
    assert r.returncode == 2 and "power_balance.preset" in r.stderr and "fix:" in r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "run.csv").exists()


def test_an_output_path_the_system_refuses_is_named_exit_2(tmp_path):
    """A folder name longer than the file system allows (255 bytes) is the user's path, not a
    bug: one line naming it, exit 2."""
    out = tmp_path / ("y" * 300)
    r = run("solve", "fin-shaft", "--model", "lumped", "--no-pictures", "--out", str(out))
    assert r.returncode == 2 and "File name too long" in r.stderr and "fix:" in r.stderr
    assert r.stderr.count("\n") == 1 and "Traceback" not in r.stderr


def test_a_result_above_the_melting_point_of_iron_is_refused(tmp_path):
    """The fin-shaft with its radius in a thousandth of its millimetres (1e-6 m): its 60 W
    have nowhere to go, and the lumped model ends above 1e6 K. Such a result is a slip in the
    spec, not a temperature: refused by name, exit 2, nothing written (it was written with
    exit 0 before)."""
    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "fin-shaft.toml").read_text(encoding="utf-8")
    assert "r_outer = 0.025" in text
    spec = tmp_path / "thin.toml"
    spec.write_text(text.replace("r_outer = 0.025", "r_outer = 1e-6"), encoding="utf-8")
    out = tmp_path / "o"
    r = run("solve", str(spec), "--model", "lumped", "--no-pictures", "--out", str(out))
    assert r.returncode == 2 and "melting point of iron" in r.stderr and "fix:" in r.stderr
    assert not out.exists()


def test_a_node_count_beyond_the_bound_is_refused_before_any_work(tmp_path):
    """--nodes 100000 (a typo) ran for hours; the bound is lumped.build.MAX_NODES, which the
    parser's NODE_COUNT repeats (it does not import numpy)."""
    from compare.cli.common import NODE_COUNT
    from lumped.build import MAX_NODES

    assert NODE_COUNT(str(MAX_NODES)) == MAX_NODES
    with pytest.raises(argparse.ArgumentTypeError):
        NODE_COUNT(str(MAX_NODES + 1))
    r = run("solve", "fin-shaft", "--model", "lumped", "--nodes", "100000", "--out",
            str(tmp_path / "o"))
    assert r.returncode == 2 and "--nodes" in r.stderr and "2..1000" in r.stderr


def test_rom_on_a_spec_without_growth_readings_and_a_steady_training_case(tmp_path):
    """fin-shaft has no P1: its ROM has temperatures only (the held-out rows stacked an empty
    growth array and raised); a steady case cannot train a ROM (no snapshots in time): named,
    exit 2 (it was an IndexError)."""
    out = tmp_path / "rom"
    r = run("rom", "fin-shaft", "--level", "0", "--no-pictures", "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert json.loads((out / "rom.json").read_text(encoding="utf-8"))
    r = run("rom", "fin-shaft", "--level", "0", "--cycle", "nominal", "--no-pictures", "--out",
            str(tmp_path / "steady"))
    assert r.returncode == 2 and "--cycle" in r.stderr and "steady case" in r.stderr
    assert not (tmp_path / "steady").exists()


def test_the_lumped_model_refuses_a_surface_that_selects_nothing_as_the_fem_does(tmp_path):
    """fin-shaft's rear face asked on the bore side of a solid shaft: no face. The FEM's mesh
    refused it; the lumped model dropped the 15 W source on it unseen (heat in 45 W, not 60)."""
    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "fin-shaft.toml").read_text(encoding="utf-8")
    assert 'side = "rear"' in text
    spec = tmp_path / "s.toml"
    spec.write_text(text.replace('side = "rear"', 'side = "inner"', 1), encoding="utf-8")
    for model in (["--model", "lumped"], ["--level", "0"]):
        r = run("solve", str(spec), *model, "--no-pictures", "--out", str(tmp_path / "o"))
        assert r.returncode == 2 and "surfaces.end_A: selects no exposed boundary" in r.stderr
        assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("option", ["--out", "--cycle", "--case"])
def test_an_empty_option_is_refused_not_taken_for_its_default(tmp_path, capsys, option):
    """`--out "$DIR"` with DIR unset wrote into the default folder; an empty --cycle or --case
    was ignored: each is named, exit 2 (in-process, as test_bad_cycle_exits_2)."""
    assert main(["solve", "fin-shaft", "--model", "lumped", option, ""]) == 2
    err = capsys.readouterr().err
    assert f"{option}: is empty" in err and "fix:" in err


@pytest.mark.parametrize("spec, option, value", [("fin-shaft", "--cycle", "spl-16h"),
                                                 ("spl2782", "--case", "nominal")])
def test_a_speed_beside_a_cycle_is_refused_not_ignored(tmp_path, capsys, spec, option, value):
    """`solve --cycle C --speed N` ran the cycle at its own speeds and said nothing of N;
    `solve spl2782 --case nominal --speed 1000` solved at 1000 rpm with the 5146 W of the
    nominal 4300 rpm (found by fuzzing). In-process, as test_bad_cycle_exits_2."""
    assert main(["solve", spec, "--model", "lumped", option, value, "--speed", "1000",
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "--speed:" in err and "drop --speed" in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("argv, words", [
    (["solve", "fin-shaft", "--level", "9"], "spindle-verify solve: --level: 9 is too large"),
    (["solv"], "spindle-verify: COMMAND: invalid choice: 'solv'"),
    (["fit"], "spindle-verify fit: the following arguments are required: RUN.csv"),
])
def test_an_option_the_parser_refuses_is_one_line(argv, words):
    """argparse printed its usage block (up to 8 lines) before the message; the message is
    now the only line, and it says where the options are listed."""
    r = run(*argv)
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.count("\n") == 1 and r.stderr.startswith(words), r.stderr
    assert f"'{words.split(':')[0]} --help' lists the options" in r.stderr


@pytest.mark.parametrize("extra, clashes", [
    # the housing's outer film again, on a piece of it: the boundary would lose heat twice
    ('[[surfaces]]\nname = "draft"\nparts = ["housing"]\nside = "outer"\nz_min = 0.2\n'
     'z_max = 0.3\nh_W_m2K = 20.0\nT_ref = "ambient"\n', True),
    # a source-only surface (no film) on the same boundary is legal
    ('[[surfaces]]\nname = "pad"\nparts = ["housing"]\nside = "outer"\nz_min = 0.2\n'
     'z_max = 0.3\n', False),
])
def test_the_lumped_model_refuses_two_films_on_one_boundary_as_the_fem_does(tmp_path, extra,
                                                                              clashes):
    """The FEM's mesh refused a second film on a boundary; the lumped model added both."""
    from lumped import build
    from meshes import build_mesh
    from spindle.errors import SpecError
    from spindle.spec_reader import load_spec, shipped_specs

    text = shipped_specs()["spl2782"].read_text(encoding="utf-8")
    path = tmp_path / "s.toml"
    path.write_text(text + "\n" + extra, encoding="utf-8")
    spec = load_spec(path)
    for make in (lambda: build(spec, 11), lambda: build_mesh(spec, 0)):
        if not clashes:
            make()
            continue
        with pytest.raises(SpecError) as exc:
            make()
        (p,) = exc.value.problems
        assert p.field == "surfaces.draft" and "same boundary as 'housing_outer'" in p.message


def test_a_warning_about_the_input_is_one_line_naming_the_input(tmp_path):
    """A bench column in another unit is kept aside with a warning; it was printed in
    Python's form, with the path and line of the tool's source that raised it."""
    bench = tmp_path / "run.csv"
    bench.write_text("time_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_K,T2_C,T_stator_C,P1_um\n"
                     "0,0,0,20,20,293.15,20,20,0\n60,0,0,20,20,293.15,20,20,0\n")  # too short
    r = run("fit", str(bench), "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    line = next(x for x in r.stderr.splitlines() if "T1_K" in x)
    assert line.startswith("spindle-verify: warning: ") and str(bench) in line, r.stderr
    assert ".py:" not in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("command", [["solve", "--model", "lumped"], ["study", "--steady-only"],
                                     ["sensors"], ["rom"], ["crosscheck"]])
def test_a_spec_without_temperature_sensors_is_refused_where_models_are_compared(tmp_path,
                                                                                command):
    """These commands compare models at the spec's temperature sensors; a spec without any
    stopped them with an internal error (found by fuzzing). measures and the library still
    take such a spec (tests/data/uniform_body.toml, the analytic cases)."""
    from compare.cli import main

    spec = str(Path(__file__).parent / "data" / "uniform_body.toml")
    out = tmp_path / "o"
    assert main([command[0], spec, *command[1:], "--out", str(out), "--quiet"]) == 2
    assert not out.exists()


def test_a_time_step_too_fine_for_the_study_is_refused_before_any_work(tmp_path, capsys):
    """study --dt 1e-3 ran the steady work, failed the transients one by one and wrote its
    outputs with exit 1 (found by fuzzing); it is the command line's error, exit 2."""
    from compare.cli import main

    out = tmp_path / "o"
    assert main(["study", "fin-shaft", "--nodes", "3", "--dt", "1e-3", "--out", str(out),
                 "--quiet"]) == 2
    assert "--dt" in capsys.readouterr().err and not out.exists()


def _thin_fin_shaft(tmp_path) -> Path:
    """The fin-shaft with its radius in a thousandth of its millimetres: its 60 W have
    nowhere to go, and every model ends far above iron's melting point."""
    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "fin-shaft.toml").read_text(encoding="utf-8")
    assert "r_outer = 0.025" in text
    spec = tmp_path / "thin.toml"
    spec.write_text(text.replace("r_outer = 0.025", "r_outer = 1e-6"), encoding="utf-8")
    return spec


@pytest.mark.parametrize("command", [
    ("study", "--levels", "0", "1", "2", "--nodes", "3", "--steady-only", "--no-pictures"),
    pytest.param(("crosscheck", "--level", "0"), marks=pytest.mark.skipif(
        __import__("shutil").which("ccx") is None, reason="CalculiX (ccx) is not installed")),
])
def test_every_command_that_solves_refuses_a_result_no_solid_can_have(tmp_path, capsys, command):
    """solve refused such a result; study wrote errors of 1e305 K with exit 1 and crosscheck
    wrote T1 = 174 050 °C with exit 0 (found by fuzzing). Both now check the reference's
    result as solve does (spindle.results.check_plausible): exit 2, nothing written."""
    out = tmp_path / "o"
    assert main([command[0], str(_thin_fin_shaft(tmp_path)), *command[1:], "--out", str(out),
                 "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "not physical" in err and "fix:" in err and not out.exists()


def test_measures_refuse_a_baseline_no_solid_can_have(tmp_path, capsys):
    """measures wrote indicators of a 45.8 MW overload case with exit 0 (found by fuzzing):
    the uniform body's 0.785 W/K to the room with 1e5 W in it rises by 1.3e5 K."""
    data = Path(__file__).parent / "data"
    spec = tmp_path / "hot.toml"
    text = (data / "uniform_body.toml").read_text(encoding="utf-8")
    assert "power_W = 100.0" in text
    spec.write_text(text.replace("power_W = 100.0", "power_W = 1e5"), encoding="utf-8")
    out = tmp_path / "o"
    assert main(["measures", str(spec), "--measures", str(data / "uniform_body_measures.toml"),
                 "--level", "0", "--no-sweeps", "--no-pictures", "--quiet", "--out",
                 str(out)]) == 2
    err = capsys.readouterr().err
    assert "melting point of iron" in err and str(spec) in err and not out.exists()


@pytest.mark.skipif(__import__("shutil").which("ccx") is None,
                    reason="CalculiX (ccx) is not installed")
def test_crosscheck_takes_a_spec_whose_name_is_no_file_name(tmp_path, capsys):
    """A spec's name is any text; crosscheck named its decks after it and a 5000-character
    name stopped it with "File name too long" (found by fuzzing); solve took the name."""
    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "fin-shaft.toml").read_text(encoding="utf-8")
    assert 'name = "fin-shaft"' in text
    spec = tmp_path / "long.toml"
    spec.write_text(text.replace('name = "fin-shaft"', f'name = "{"x" * 5000}"', 1),
                    encoding="utf-8")
    assert main(["crosscheck", str(spec), "--level", "0", "--quiet", "--out",
                 str(tmp_path / "o")]) == 0
    assert (tmp_path / "o" / "crosscheck.json").is_file()


@pytest.mark.parametrize("model", [("--level", "0"), ("--model", "lumped")])
def test_a_spindle_without_heat_sits_at_its_reference_temperature(tmp_path, capsys, model):
    """The fin-shaft with both sources at 0 W: every temperature is the room's. solve refused
    it as "ill-conditioned" (its round-off flows were judged against themselves, an
    imbalance of 100 %; found by fuzzing); the balance is now judged against at least
    spindle.results.FLOW_FLOOR_W."""
    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "fin-shaft.toml").read_text(encoding="utf-8")
    assert text.count("power_W = 15.0") == 1 and text.count("power_W = 45.0") == 1
    spec = tmp_path / "cold.toml"
    spec.write_text(text.replace("power_W = 15.0", "power_W = 0.0")
                    .replace("power_W = 45.0", "power_W = 0.0"), encoding="utf-8")
    out = tmp_path / "o"
    assert main(["solve", str(spec), *model, "--no-pictures", "--quiet", "--out", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    # the room is 20 °C; 1e-9 K is round-off on 293 K
    assert all(abs(v - 20.0) < 1e-9 for v in summary["sensors_C"].values())


@pytest.mark.parametrize("effects, words", [(["sensor_lag", "sensor_lag"], "given twice"),
                                            (["clean", "fixture_expansion"], "'clean'")])
def test_synth_refuses_an_effect_twice_or_clean_with_effects(tmp_path, capsys, effects, words):
    """`synth --effect sensor_lag sensor_lag` applied the lag twice and wrote one parameter
    set to the truth (5.60 K for the effect, 8.28 K in the run; found by fuzzing)."""
    out = tmp_path / "run.csv"
    assert main(["synth", "--level", "0", "--effect", *effects, "--out", str(out),
                 "--quiet"]) == 2
    assert words in capsys.readouterr().err and not out.exists()
    from compare.synth.bench import synth
    from spindle.errors import InputError
    from spindle.spec_reader import load_spec

    with pytest.raises(InputError, match=words):  # the library refuses it too, before work
        synth(load_spec("spl2782"), "spl-16h", effects, 0, out)
    assert not out.exists()


def test_a_mesh_level_beyond_the_machine_is_refused_before_it_is_made(tmp_path, capsys):
    """A spec with a fine h0_m passes the level-0 check, and `mesh --level 6` then built 90
    million elements until it was killed (found by fuzzing). meshes.build.MAX_ELEMENTS is
    checked from level 0's count before the refinement."""
    text = (Path(__file__).resolve().parents[1] / "spindle" / "data" / "specs"
            / "fin-shaft.toml").read_text(encoding="utf-8")
    spec = tmp_path / "fine.toml"
    spec.write_text(text.replace("h0_m = 0.025", "h0_m = 0.002"), encoding="utf-8")
    out = tmp_path / "m"
    assert main(["mesh", str(spec), "--level", "6", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "level: level 6 of this spec would have" in err and "fix: give a level of at most" \
        in err and not out.exists()


@pytest.mark.parametrize("argv, words", [
    (["fit", ""], "the path of the bench run is empty"),
    (["fit", "RUN", "--criteria", "missing.toml"], "--criteria: cannot be read (No such file"),
])
def test_an_empty_run_path_or_a_missing_criteria_file_says_so(tmp_path, capsys, argv, words):
    """Fuzzing round 6: an empty run path was reported as the folder '.', and a missing
    criteria file as a file that 'cannot be read as TOML', with the fix to write TOML."""
    run_csv = Path(__file__).resolve().parent / "data" / "peer-runs" / "bench-runs" / "dev-01.csv"
    argv = [str(run_csv) if a == "RUN" else str(tmp_path / a) if a.endswith(".toml") else a
            for a in argv]
    out = tmp_path / "o"
    assert main([*argv, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1 and not out.exists()


def test_fit_refuses_more_nodes_than_the_grey_box_takes(tmp_path, capsys):
    """fit's --nodes stops at compare.fit.greybox.MAX_NODES (161: 4.5 GB and 4 min on a 16 h
    run; 500 would need tens of GB): the command line refuses 162 before any work, and the
    Python API (spindle_verify.fit) refuses it as an InputError, not a MemoryError."""
    import spindle_verify
    from compare.cli.fit import FIT_NODES_MAX
    from compare.fit.greybox import MAX_NODES
    from spindle.errors import InputError

    assert FIT_NODES_MAX == MAX_NODES
    run = str(Path(__file__).parent / "data" / "peer-runs" / "bench-runs" / "dev-01.csv")
    out = tmp_path / "x"
    assert main(["fit", run, "--nodes", str(MAX_NODES + 1), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--nodes" in err and "Traceback" not in err and not out.exists()
    with pytest.raises(InputError, match="--nodes"):
        spindle_verify.fit(run, nodes=MAX_NODES + 1)
