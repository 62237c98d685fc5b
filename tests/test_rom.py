"""The reduced-order model (reference/rom/, issue 17) against the full FEM computed independently:
ReferenceModel.transient / .steady (the reference's own solvers) and
ThermalModel.exact_readouts (modal, exact in time), on small meshes."""

from __future__ import annotations

import shutil
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from compare.verify.romstudy import named_case
from reference import ReferenceModel
from reference.rom import build_rom
from reference.rom.model import fem_transient, full_system
from reference.rom.realtime import ROMPredictor

#: the issue's targets: every sensor within 0.05 K, P1 within 0.1 µm of the ground truth
TOL_K, TOL_UM = 0.05, 0.1
DT = 300.0  # a coarse grid keeps the FEM runs of the test short; the ROM is built on it


@pytest.fixture(scope="module")
def spl0():
    ref = ReferenceModel("spl2782", level=0)
    train = named_case(ref.spec, "random-loaded", seed=0)
    rom, report = build_rom(ref, train, DT, TOL_K, TOL_UM, level=0)
    return ref, rom, report


def test_size_choice_meets_the_training_tolerances(spl0):
    _, rom, report = spl0
    assert report.chosen == rom.n_states <= 100
    err = report.errors[-1]
    assert err["temperature_max_K"] <= TOL_K / report.safety
    assert err["P1_max_um"] <= TOL_UM / report.safety
    # a smaller size tried before failed (else the choice is not the smallest)
    if len(report.errors) > 1:
        prev = report.errors[-2]
        assert prev["temperature_max_K"] > TOL_K / report.safety or \
            max(v for k, v in prev.items() if k.endswith("_um")) > TOL_UM / report.safety


def test_fem_training_run_is_the_reference_scheme(spl0):
    """The size choice's FEM run is ReferenceModel.transient's backward Euler (to round-off)."""
    ref, _, _ = spl0
    case = replace(named_case(ref.spec, "spl-16h"), duration_s=4 * 3600.0)
    res = ref.transient(case, DT)
    t, Y = fem_transient(full_system(ref), case, DT)
    np.testing.assert_allclose(t, res.times_s)
    ns = len(res.names)
    assert np.abs(Y[:, :ns] - res.sensor_K).max() < 1e-9
    assert np.abs(Y[:, ns] - res.growth_m["P1"]).max() < 1e-15  # m


@pytest.mark.parametrize("cycle, seed", [("spl-16h", 0), ("random", 2)])
def test_rom_held_out_cycles_against_the_fem(spl0, cycle, seed):
    """Cycles the ROM was not built from, against ReferenceModel.transient on the same grid."""
    ref, rom, _ = spl0
    case = named_case(ref.spec, cycle, seed)
    fem = ref.transient(case, DT)
    res = rom.transient(case, DT)
    assert np.abs(res.sensor_K - fem.sensor_K).max() <= TOL_K
    assert np.abs(res.growth_m["P1"] - fem.growth_m["P1"]).max() * 1e6 <= TOL_UM
    assert set(res.to_pandas().columns) >= {"time_s", "T1_C", "P1_um"}


def test_rom_steady_against_the_fem(spl0):
    ref, rom, _ = spl0
    case = named_case(ref.spec, "nominal")
    fem, red = ref.steady(case), rom.steady(case)
    for k, v in fem.sensors.items():
        assert abs(red.sensors[k] - v) <= TOL_K
    assert abs(red.growth_m["P1"] - fem.growth_m["P1"]) * 1e6 <= TOL_UM
    # the result interface of the other models
    assert list(red.to_pandas()["sensor"]) == list(fem.sensors)
    assert red.summary()["model"]["kind"] == "rom"
    assert red.plot() is not None


def test_rom_exact_time_integration_against_modal_fem():
    """fin-shaft (405 unknowns): the ROM's exact integrator against the FEM's modal one."""
    from compare.verify.study import study_cases

    ref = ReferenceModel("fin-shaft", level=1, elastic=False)
    case = study_cases(ref.spec)[1]
    rom, report = build_rom(ref, case, 600.0, TOL_K, TOL_UM)
    assert report.chosen is not None
    t, names, S, _, _ = ref.thermal.exact_readouts(case, 600.0, method="modal")
    res = rom.transient(case, 600.0, method="exact")
    np.testing.assert_allclose(res.times_s, t)
    assert np.abs(res.sensor_K - S).max() <= TOL_K


def test_predictor_step_run_and_steady(spl0):
    """Streaming steps and the batch replay agree to round-off; held long at constant
    inputs the predictor reaches the ROM's steady state (a linear solve, not an exponential)."""
    ref, rom, _ = spl0
    case = named_case(ref.spec, "nominal")
    u = rom.inputs(case, 0.0)[0]
    n = float(case.speed_rpm(0.0))
    a, b = ROMPredictor(rom, 60.0), ROMPredictor(rom, 60.0)
    steps = 3000  # 50 h: many times the slowest time constant
    Ys = np.array([(a.step(u, n), a.outputs_now())[1] for _ in range(steps)])
    Yr = b.run(np.tile(u, (steps, 1)), np.full(steps, n))
    assert np.abs(Ys - Yr).max() < 1e-9
    st = rom.steady(case)
    assert np.abs(Ys[-1, :len(rom.sensor_names)] - st.sensor_values).max() < 1e-6


@pytest.mark.skipif(shutil.which("gcc") is None, reason="no C compiler")
def test_c_export_matches_the_predictor(spl0, tmp_path):
    """The generated C builds with -std=c99 -Wall -Wextra -pedantic -Werror; at the table's
    speeds it is the Python predictor to round-off; between them it interpolates within the
    error it states; outside the table it says so in its status; its losses are the power
    balance's within the error it states, and rom_step_cnc is rom_losses then rom_step."""
    import ctypes
    import json

    from reference.rom.export import STATUS, export
    from spindle.drive import drive_for

    ref, rom, _ = spl0
    case = named_case(ref.spec, "spl-16h")
    dt = 60.0
    t = np.arange(0.0, case.duration_s, dt) + 0.5 * dt
    U = rom.inputs(case, t)
    speeds = np.asarray(case.speed_rpm(t), dtype=float)
    pred = ROMPredictor(rom, dt)
    drive = drive_for(ref.spec)
    table = np.arange(0.0, 4500.0, 500.0)  # every 500 rpm: the cycle's 1000..4300 included
    files = export(pred, np.r_[table, np.unique(speeds)], tmp_path, drive=drive)
    lib = tmp_path / "librom.so"
    subprocess.run(["gcc", "-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror", "-O2",
                    "-shared", "-fPIC", "-o", str(lib), str(tmp_path / "spindle_rom.c"), "-lm"],
                   check=True)
    doc = json.loads((tmp_path / "spindle_rom.json").read_text())
    c = ctypes.CDLL(str(lib))
    dbl = ctypes.POINTER(ctypes.c_double)
    p = len(rom.sensor_names) + len(rom.readings)

    def c_run(inputs: np.ndarray, speed: np.ndarray) -> tuple[np.ndarray, list[int]]:
        state, y, out, status = np.zeros(rom.n_states), np.zeros(p), [], []
        c.rom_initial_state(state.ctypes.data_as(dbl))
        for u, n in zip(inputs, speed, strict=True):
            inp = np.ascontiguousarray(np.r_[u, n])
            status.append(c.rom_step(state.ctypes.data_as(dbl), inp.ctypes.data_as(dbl),
                                     y.ctypes.data_as(dbl)))
            out.append(y.copy())
        return np.array(out), status

    # at the tabulated speeds: the predictor to round-off
    state0 = np.zeros(rom.n_states)
    c.rom_initial_state(state0.ctypes.data_as(dbl))
    np.testing.assert_allclose(state0, pred.state, rtol=0, atol=1e-12)
    Y, status = c_run(U, speeds)
    Yp = np.array([(pred.step(u, n), pred.outputs_now())[1] for u, n in zip(U, speeds,
                                                                              strict=True)])
    assert np.abs(Y - Yp).max() < 1e-9 and not any(status)
    # between table speeds (250 rpm off every entry): within the stated error, measured on a
    # staircase through the midpoints (another cycle; its ambient and coolant drift besides,
    # which the factor 2 leaves room for)
    off = np.clip(speeds + 250.0, 0.0, 4250.0)
    Y, status = c_run(U, off)
    exact = ROMPredictor(rom, dt)
    Ye = np.array([(exact.step(u, n), exact.outputs_now())[1] for u, n in zip(U, off,
                                                                               strict=True)])
    ns = len(rom.sensor_names)
    stated = doc["interpolation"]
    assert 0 < np.abs(Y - Ye)[:, :ns].max() <= 2 * stated["speed_staircase_K"]
    assert np.abs(Y - Ye)[:, ns:].max() <= 2 * stated["speed_staircase_m"]
    assert not any(status)
    # outside the table: the status says so; the value is held at the table's end
    _, status = c_run(U[:2], np.array([5000.0, -10.0]))
    assert status == [STATUS["SPEED_ABOVE"], STATUS["SPEED_BELOW"]]
    # the losses a CNC's speed and torque give, against the Python power balance
    heat = np.zeros(len(rom.source_names))
    c.rom_losses.argtypes = [ctypes.c_double, ctypes.c_double, dbl]
    worst = 0.0
    for n, M in [(1000.0, 0.0), (2750.0, 30.0), (4300.0, 84.0), (1234.0, 55.5)]:
        assert c.rom_losses(n, M, heat.ctypes.data_as(dbl)) == 0
        want = drive.heat_W(n, M)
        got = dict(zip(rom.source_names, heat, strict=True))
        worst = max(worst, max(abs(got[k] - v) for k, v in want.items()))
    assert worst <= stated["losses_W"] + 1e-9
    assert c.rom_losses(1000.0, 1e4, heat.ctypes.data_as(dbl)) == STATUS["TORQUE_OUTSIDE"]
    # the CNC step: the losses, then the step with the ambient and coolant given
    c.rom_step_cnc.argtypes = [dbl, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                               ctypes.c_double, dbl]
    s1, s2, y1, y2 = (np.zeros(rom.n_states), np.zeros(rom.n_states), np.zeros(p), np.zeros(p))
    c.rom_initial_state(s1.ctypes.data_as(dbl))
    c.rom_initial_state(s2.ctypes.data_as(dbl))
    for _ in range(5):
        assert c.rom_step_cnc(s1.ctypes.data_as(dbl), 2750.0, 30.0, 294.0, 293.0,
                              y1.ctypes.data_as(dbl)) == 0
        c.rom_losses(2750.0, 30.0, heat.ctypes.data_as(dbl))
        inp = np.ascontiguousarray(np.r_[heat, 294.0, 293.0, 2750.0])
        c.rom_step(s2.ctypes.data_as(dbl), inp.ctypes.data_as(dbl), y2.ctypes.data_as(dbl))
    np.testing.assert_array_equal(y1, y2)
    assert {f.suffix for f in files} == {".npz", ".json", ".h", ".c"}


def test_error_indicator_tracks_the_true_error(spl0):
    """The residual bound of a run falls with the size as the true error does, and on a
    held-out cycle its calibrated estimate is within a factor 10 of the true worst sensor
    error (the calibration is a ratio from another cycle: an order of magnitude is what a
    user needs to decide whether to trust a run)."""
    ref, rom, _ = spl0
    case = named_case(ref.spec, "spl-16h")
    fem = ref.transient(case, DT)
    res = rom.transient(case, DT)
    true = np.abs(res.sensor_K - fem.sensor_K).max()
    est = res.error_estimate["estimated_max_K"]
    assert true / 10 <= est <= true * 10
    # a much smaller ROM: the bound and the true error both grow
    small, _ = build_rom(ref, named_case(ref.spec, "random-loaded", 0), DT, 5.0, 5.0,
                         sizes=(4,), level=0)
    res_s = small.transient(case, DT)
    true_s = np.abs(res_s.sensor_K - fem.sensor_K).max()
    assert true_s > true
    assert res_s.error_estimate["bound_rms_K"] > res.error_estimate["bound_rms_K"]


def test_study_rom_row():
    """The ROM as a row of the study's tables (fin-shaft, whose reference is exact in time):
    its error against the reference is the projection error, below the ROM's tolerance,
    while the steady reference is the Richardson extrapolation of the levels (the ROM of the
    finest level inherits that level's discretisation error, below 1e-3 K on fin-shaft,
    tests/test_study.py)."""
    from compare.verify.study import run_study
    from spindle.spec_reader import load_spec

    study = run_study(load_spec("fin-shaft"), levels=(0, 1, 2), nodes=(3,), dt_s=600.0, rom=True)
    for acc in (study.steady, study.transient):
        t = acc.table()
        i = [k for k, kind in enumerate(t["kind"]) if kind == "rom"]
        assert len(i) == 1
        worst = max(v[i[0]] for k, v in t.items() if k.endswith("_max_K"))
        assert worst <= TOL_K + 1e-3
        assert t["unknowns"][i[0]] <= 100
    fig = study.transient.plot().figure
    labels = [text.get_text() for text in fig.axes[0].get_legend().get_texts()]
    assert any("ROM" in lab for lab in labels)


def test_sensors_considers_the_rom():
    """`sensors` with the ROM on spl2782 (level 0, to be fast): the lumped 11-node model
    fails the paper's 1 K / 1.5 µm (the harness's headline) while the ROM sized for them
    meets them on both cases, against the same FEM reference."""
    from compare.verify.nodecount import choose_nodes
    from spindle.spec_reader import load_spec

    choice = choose_nodes(load_spec("spl2782"), None, 1.0, 1.5, (11,), 0, 600.0, rom=True)
    assert choice.chosen is None
    assert choice.rom["meets"] and choice.rom["states"] <= 100
    assert len(choice.rom["cases"]) == 2
    assert all(c["worst_err_K"] <= 1.0 and c["err_P1_um"] <= 1.5 for c in choice.rom["cases"])
    assert "reduced-order model" in choice.message() and choice.summary()["rom"] is choice.rom


def test_rom_command_writes_its_outputs(tmp_path, capsys):
    import json

    from compare.cli import main

    out = tmp_path / "rom"
    assert main(["rom", "spl2782", "--level", "0", "--dt", "600", "--held-out", "spl-16h",
                 "nominal", "--quiet", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "held-out cycles: PASS" in text
    summary = json.loads((out / "rom.json").read_text())
    assert summary["states"] <= 100 and summary["meets_tolerances_on_held_out"]
    assert [h["case"] for h in summary["held_out"]] == ["spl-16h", "nominal"]
    for name in ("rom_errors.csv", "rom.npz", "rom_size.png", "controller/spindle_rom.c",
                 "controller/spindle_rom.h", "controller/spindle_rom.json"):
        assert (out / name).exists(), name


@pytest.mark.parametrize("args, words", [
    (["--held-out", "no-such-cycle"], "neither a shipped cycle"),
    (["--cycle", "random:x"], "is not a whole number"),
    (["--tol-temp", "0"], "rom: --tol-temp:"),
])
def test_rom_command_bad_options_exit_2(tmp_path, capsys, args, words):
    from compare.cli import main

    assert main(["rom", "fin-shaft", *args, "--out", str(tmp_path / "x")]) == 2
    assert words in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_rom_at_the_ground_truth_level():
    """spl2782 level 2 (45 881 DOFs), the issue's figures: <= 0.05 K at every sensor and
    <= 0.1 µm on P1 at r <= 100 on spl-16h and two cycles not used to build it, against
    ReferenceModel.transient at dt 60 s (about 4 minutes on 2 cores; the fast tests above
    cover the same code on level 0)."""
    ref = ReferenceModel("spl2782", level=2)
    rom, _ = build_rom(ref, named_case(ref.spec, "random-loaded", 0), 60.0, TOL_K, TOL_UM,
                       level=2, indicator=False)
    assert rom.n_states <= 100
    for cycle, seed in (("spl-16h", 0), ("random-loaded", 1), ("random", 2)):
        case = named_case(ref.spec, cycle, seed)
        fem = ref.transient(case, 60.0)
        res = rom.transient(case, 60.0)
        assert np.abs(res.sensor_K - fem.sensor_K).max() <= TOL_K, cycle
        assert np.abs(res.growth_m["P1"] - fem.growth_m["P1"]).max() * 1e6 <= TOL_UM, cycle


def test_rom_transient_result_saves(spl0, tmp_path):
    import json

    ref, rom, _ = spl0
    res = rom.transient(named_case(ref.spec, "spl-16h"), DT)
    files = res.save(tmp_path)
    assert {f.name for f in files} == {"summary.json", "sensors_timeseries.csv",
                                        "sensors_timeseries.png"}
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["model"]["states"] == rom.n_states
    assert summary["error_estimate"]["estimated_max_K"] > 0
