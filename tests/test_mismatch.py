"""Synthetic runs from a spindle the spec describes only approximately (compare.synth.mismatch,
issue 13 §2): the mismatch does what it declares, random cycles are what they claim."""

import json

import numpy as np
import pytest

from compare.fit.greybox import film_groups
from compare.synth.mismatch import Mismatch, draw_mismatch, perturbed_spec
from spindle.cycles import ramped_steps, random_cycle
from spindle.drive import drive_for
from spindle.faces import exposed_faces, surface_faces
from spindle.spec import ContactLink
from spindle.spec_reader import load_spec


@pytest.fixture(scope="module")
def spl():
    spec = load_spec("spl2782")
    return spec, drive_for(spec)


def _film_conductance(spec, group: str, speed_rpm: float = 3000.0) -> float:
    """sum h A [W/K] over the surfaces of one film group, at a speed."""
    faces = exposed_faces(spec)
    groups = film_groups(spec)
    return sum(s.h_W_m2K(speed_rpm) * sum(f.area_m2 for f in surface_faces(s, faces, spec))
               for s in spec.surfaces if s.h_W_m2K is not None and groups[s.name] == group)


def test_draws_stay_in_their_declared_ranges():
    for seed in range(30):
        mm = draw_mismatch(np.random.default_rng(seed))
        assert all(0.5 <= f <= 2.0 for f in mm.films.values()) and 0.5 <= mm.contact <= 2.0
        assert 0.10 <= abs(mm.axial_scale - 1.0) <= 0.15
        assert 0.7 <= mm.f0_factor <= 1.4 and abs(mm.friction_exponent) <= 0.3
        assert 0.03 <= mm.rotor_share <= 0.15 and mm.fem_level in (1, 2)


def test_apply_changes_what_it_declares(spl):
    """Film conductances per group scale by their factor times the axial stretch (lateral
    areas grow with length; end faces do not: bounded), contacts by theirs, the axial extent
    by the stretch; the drive's f0, exponent and loss split are the drawn ones."""
    spec, drive = spl
    mm = Mismatch(films={"h_coolant": 2.0, "h_air": 0.5, "h_rotating": 1.0}, contact=0.5,
                  axial_scale=1.1, f0_factor=1.2, friction_exponent=0.2, rotor_share=0.1,
                  fem_level=1)
    out, d = mm.apply(spec, drive)
    for group, factor in mm.films.items():
        ratio = _film_conductance(out, group) / _film_conductance(spec, group)
        assert factor * (1 - 1e-9) <= ratio <= factor * 1.1 * (1 + 1e-9), (group, ratio)
    before = [lk.h_W_m2K for lk in spec.links if isinstance(lk, ContactLink)]
    after = [lk.h_W_m2K for lk in out.links if isinstance(lk, ContactLink)]
    assert after == pytest.approx([0.5 * h for h in before], rel=1e-12)
    z = [s.z_end for p in out.parts for s in p.sections]
    z0 = [s.z_end for p in spec.parts for s in p.sections]
    assert max(z) == pytest.approx(1.1 * max(z0), rel=1e-12)
    f0 = drive.bearings["front_bearing"].f0
    assert d.bearings["front_bearing"].f0 == pytest.approx(1.2 * f0, rel=1e-12)
    assert d.friction_exponent == 0.2 and d.motor.rotor_loss_share == 0.1


def test_perturbed_spec_is_the_seeds_mismatch_without_the_drive(spl):
    """What fit reads from a perturbed spec: the seed's films, contacts and stretch (seed 2
    stretches the axis, so a film group's conductance grows by its factor times up to the
    stretch, as in test_apply_changes_what_it_declares); the spec passed in is unchanged; a
    spec without a drive (fin-shaft) is perturbed too; a negative seed is refused."""
    spec, _drive = spl
    mm = draw_mismatch(np.random.default_rng([2, 1]))
    assert mm.axial_scale > 1.0
    out = perturbed_spec(spec, 2)
    for group, factor in mm.films.items():
        ratio = _film_conductance(out, group) / _film_conductance(spec, group)
        assert factor * (1 - 1e-9) <= ratio <= factor * mm.axial_scale * (1 + 1e-9)
    before = [lk.h_W_m2K for lk in spec.links if isinstance(lk, ContactLink)]
    after = [lk.h_W_m2K for lk in out.links if isinstance(lk, ContactLink)]
    assert after == pytest.approx([mm.contact * h for h in before], rel=1e-12)
    z = max(s.z_end for p in out.parts for s in p.sections)
    assert z == pytest.approx(mm.axial_scale * max(s.z_end for p in spec.parts
                                                   for s in p.sections), rel=1e-12)
    assert spec == load_spec("spl2782")
    fin = load_spec("fin-shaft")
    assert drive_for(fin) is None
    assert perturbed_spec(fin, 2) != fin
    with pytest.raises(ValueError, match="seed"):
        perturbed_spec(spec, -1)


def test_random_cycles():
    """16 h, a standstill start and a 2 h standstill end, non-monotonic steps that reach the
    top speed; loaded ones hold 0-40 N m; the same seed gives the same cycle."""
    for seed in range(5):
        c = random_cycle(np.random.default_rng(seed), 6000.0, loaded=seed % 2 == 1)
        assert c.duration_s == pytest.approx(16 * 3600.0)
        speeds = [s.speed_rpm for s in c.steps]
        assert speeds[0] == 0.0 and speeds[-1] == 0.0 and c.steps[-1].duration_s >= 7200.0
        assert max(speeds) == 6000.0
        inner = speeds[1:-1]
        assert any(b < a for a, b in zip(inner, inner[1:], strict=False))  # goes down somewhere
        torques = [s.load_torque_Nm for s in c.steps]
        assert (max(torques) > 0) == (seed % 2 == 1) and max(torques) <= 40.0
    a = random_cycle(np.random.default_rng(7), 6000.0)
    b = random_cycle(np.random.default_rng(7), 6000.0)
    assert a.steps == b.steps


def test_ramped_load_cycle():
    """random-ramped-load: every speed step's torque rises then falls in 5 min pieces (a span
    of at least 10 N m), the speed held; whole minutes, so the pieces keep the 60 s grid; the
    plain cycle stays unloaded."""
    pieces = ramped_steps(3000.0, 3725.0, 10.0, 30.0)
    torques = [p.load_torque_Nm for p in pieces]
    assert {p.speed_rpm for p in pieces} == {3000.0}
    assert sum(p.duration_s for p in pieces) == pytest.approx(3725.0)
    assert all(p.duration_s == 300.0 for p in pieces[:-1])
    k = int(np.argmax(torques))
    assert np.all(np.diff(torques[:k + 1]) >= 0) and np.all(np.diff(torques[k:]) <= 0)
    for seed in range(3):
        c = random_cycle(np.random.default_rng(seed), 6000.0, ramped=True)
        assert c.duration_s == pytest.approx(16 * 3600.0) and c.name == "random-ramped-load"
        assert max(s.speed_rpm for s in c.steps) == 6000.0
        assert all(s.duration_s % 60.0 == 0.0 for s in c.steps[:-1])
        level = {}
        for s in c.steps:
            if s.speed_rpm > 0:
                level.setdefault(s.speed_rpm, []).append(s.load_torque_Nm)
        assert all(max(v) - min(v) >= 5.0 for v in level.values())
    plain = random_cycle(np.random.default_rng(0), 6000.0)
    assert all(s.load_torque_Nm == 0.0 for s in plain.steps)


def test_synth_with_mismatch_records_it(tmp_path, spl):
    """A short loaded run on a mismatched spindle: the truth sidecar holds the mismatch and its
    FEM level; the run reads as a bench export and logs the load torque, without which a fit
    would take the whole electrical power for losses."""
    from compare.synth.bench import synth
    from spindle.bench import read_bench

    cycle = tmp_path / "short.toml"
    cycle.write_text('[cycle]\nname = "short"\ndescription = "1 h"\nsource = "test"\n'
                     'steps = [ { speed_rpm = 0.0, duration_h = 0.1 },\n'
                     '  { speed_rpm = 3000.0, duration_h = 0.5, load_torque_Nm = 20.0 },\n'
                     '  { speed_rpm = 1500.0, duration_h = 0.4 } ]\n'
                     '[ambient]\nT_C = 20.0\n[coolant]\nT_C = 20.0\n')
    run = tmp_path / "run.csv"
    truth = synth(spl[0], str(cycle), "clean", 4, run, mismatch=True)
    saved = json.loads(run.with_suffix(".truth.json").read_text())
    assert saved["mismatch"] == truth["mismatch"]
    assert saved["fem_level"] == saved["mismatch"]["fem_level"]
    bench = read_bench(run)
    assert bench.duration_s > 0.9 * 3600.0
    assert bench.load_torque_measured
    M = bench.columns["load_torque_Nm"]
    assert set(np.unique(M[np.isfinite(M)])) == {0.0, 20.0}


def test_synth_records_each_effects_size_as_the_peers_truth_does(tmp_path, spl):
    """The truth sidecar gives the largest change the injected effects make in each channel,
    as the peer's truth.json does (``effect_size_by_channel``; by effect for several). A
    fixture's term is analytic: P1 moves by k (T_env - T_env(0)), so on a room drifting by
    2 K its size is |k| 2 K in um, and no temperature moves (the test's tolerance is the
    sidecar's 4 decimals); a lag on T1 alone moves T1 alone."""
    from compare.synth.bench import synth

    cycle = tmp_path / "drift.toml"
    cycle.write_text('[cycle]\nname = "drift"\ndescription = "2 h"\nsource = "test"\n'
                     'steps = [ { speed_rpm = 3000.0, duration_h = 1.0 },\n'
                     '  { speed_rpm = 1000.0, duration_h = 1.0 } ]\n'
                     '[ambient]\nmodel = "drift"\nT_start_C = 20.0\nT_peak_C = 22.0\n'
                     't_peak_h = 2.0\nT_end_C = 22.0\nsample_s = 60.0\n'
                     '[coolant]\nT_C = 20.0\n')
    truths = {"fixture_expansion": {"k_fix_um_K": -1.5},
              "sensor_lag": {"channel": "T1", "tau_s": 600.0}}
    one = synth(spl[0], str(cycle), "fixture_expansion", 1, tmp_path / "a.csv", level=0,
                truths=truths)
    size = one["effect_size_by_channel"]
    assert size["P1"] == pytest.approx(1.5 * 2.0, abs=1e-4)
    assert size["T1"] == size["T2"] == size["T_stator"] == 0.0
    both = synth(spl[0], str(cycle), list(truths), 1, tmp_path / "b.csv", level=0,
                 truths=truths)
    by = both["effect_size_by_effect"]
    assert by["fixture_expansion"] == size
    assert by["sensor_lag"]["T1"] > 0.05 and by["sensor_lag"]["P1"] == 0.0
    assert both["effect_size_by_channel"]["T1"] == pytest.approx(by["sensor_lag"]["T1"])
    saved = json.loads((tmp_path / "b.truth.json").read_text())
    assert saved["effect_size_by_effect"] == by


def test_outside_causes_of_a_window_act_only_in_it(tmp_path, spl):
    """The causes outside the library that act for a window of hours: a coolant flow drop
    leaves the run as it was before its window (the same seed gives the same samples) and
    changes it after; an enclosure draft changes the spindle but not the logged room
    temperature, whose sensor hangs elsewhere."""
    from compare.synth.bench import synth
    from spindle.bench import read_bench

    cycle = tmp_path / "c.toml"
    cycle.write_text('[cycle]\nname = "c"\ndescription = "3 h"\nsource = "test"\n'
                     'steps = [ { speed_rpm = 4000.0, duration_h = 3.0 } ]\n'
                     '[ambient]\nT_C = 20.0\n[coolant]\nT_C = 20.0\n')
    window = {"start_h": 1.0, "duration_h": 1.0}
    truths = {"coolant_flow_drop": {**window, "R_K_W": 0.006},
              "enclosure_draft": {**window, "delta_K": 6.0}}
    runs = {}
    for name in ("clean", *truths):
        synth(spl[0], str(cycle), name, 3, tmp_path / f"{name}.csv", level=0, truths=truths)
        runs[name] = read_bench(tmp_path / f"{name}.csv")
    clean, drop, draft = runs["clean"], runs["coolant_flow_drop"], runs["enclosure_draft"]
    before = clean.time_s < 3600.0
    np.testing.assert_array_equal(drop.columns["T1_C"][before], clean.columns["T1_C"][before])
    late = (clean.time_s > 1.5 * 3600) & (clean.time_s < 2 * 3600)
    # the water warms by R Q along the jacket: the rings follow by kelvins (> 0.5 K)
    assert np.nanmean(drop.columns["T1_C"][late] - clean.columns["T1_C"][late]) > 0.5
    np.testing.assert_array_equal(draft.columns["T_env_C"], clean.columns["T_env_C"])
    assert np.nanmean(draft.columns["T1_C"][late] - clean.columns["T1_C"][late]) > 0.1


def test_a_rising_rotor_loss_moves_heat_and_leaves_the_power(tmp_path, spl):
    """compare.synth.losslaw's rotor_loss_rise: at a speed n the rotor gains share_rise (n /
    6000 rpm)^2 of the motor's no-load loss at n from the stator, whatever the load, and at
    standstill nothing; the two sources' sum is unchanged to round-off (1e-9 of the loss), and
    so is the logged power (the same seed gives the same power column): the loss moved, it
    did not grow. The stator warms less and the shaft (P1 grows with the rotor's heat) more
    than on the clean run."""
    from compare.synth.bench import synth
    from compare.synth.losslaw import LOSS_LAWS, RISE_AT_RPM
    from spindle.bench import read_bench
    from spindle.drive import cycle_load_case, spindle_cycle

    spec, drive = spl
    case = cycle_load_case(spec, spindle_cycle(spec, "random-loaded", 3), drive)
    moved, extra = LOSS_LAWS["rotor_loss_rise"].synth_case(case, spec, {"share_rise": 0.3})
    assert extra == {}
    t = np.linspace(0.0, case.duration_s, 4001)
    n = np.asarray(case.speed_rpm(t + 1e-6))
    before = {k: np.asarray(case.sources[k](t + 1e-6)) for k in ("rotor", "stator")}
    after = {k: np.asarray(moved.sources[k](t + 1e-6)) for k in ("rotor", "stator")}
    total = before["rotor"] + before["stator"]
    np.testing.assert_allclose(after["rotor"] + after["stator"], total,
                               atol=1e-9 * total.max())
    no_load = np.array([sum(drive.heat_W(float(v), 0.0, None)[k] for k in ("rotor", "stator"))
                        for v in n])
    expected = np.minimum(0.3 * (n / RISE_AT_RPM) ** 2 * no_load, before["stator"])
    np.testing.assert_allclose(after["rotor"] - before["rotor"], expected,
                               atol=1e-9 * total.max())
    assert np.all(after["rotor"][n == 0.0] == before["rotor"][n == 0.0])

    cycle = tmp_path / "c.toml"
    cycle.write_text('[cycle]\nname = "c"\ndescription = "2 h"\nsource = "test"\n'
                     'steps = [ { speed_rpm = 6000.0, duration_h = 2.0 } ]\n'
                     '[ambient]\nT_C = 20.0\n[coolant]\nT_C = 20.0\n')
    runs = {}
    for name in ("clean", "rotor_loss_rise"):
        synth(spec, str(cycle), name, 3, tmp_path / f"{name}.csv", level=0,
              truths={"rotor_loss_rise": {"share_rise": 0.3}})
        runs[name] = read_bench(tmp_path / f"{name}.csv")
    clean, law = runs["clean"], runs["rotor_loss_rise"]
    np.testing.assert_array_equal(law.columns["power_kW"], clean.columns["power_kW"])
    late = clean.time_s > 3600.0
    assert np.nanmean(law.columns["T_stator_C"][late] - clean.columns["T_stator_C"][late]) < 0
    assert np.nanmean(law.columns["P1_um"][late] - clean.columns["P1_um"][late]) > 0


def test_log_on_change_reports_by_exception(tmp_path):
    """The on-change logger of the drawn runs: a channel that holds still reports on its
    heartbeat only, one that moves reports each time it leaves its dead band, a scan where
    nothing reports writes no row, and the result reads as a bench export."""
    from compare.synth.bench import ON_CHANGE, log_on_change
    from spindle.bench import read_bench

    t = np.arange(0.0, 2400.0, 1.0)  # 40 min: a bench export needs 30 (spindle.bench)
    band_T1, beat_T2 = ON_CHANGE["T1_C"][0], ON_CHANGE["T2_C"][1]
    src = tmp_path / "run.csv"
    rows = [f"{x:.1f},3000,1.0,20.0,20.0,{20.0 + 0.002 * x:.4f},25.0,30.0,0.0" for x in t]
    src.write_text("# spindle: spl2782\n# rows: 2400\ntime_s,speed_rpm,power_kW,T_env_C,"
                   "T_coolant_C,T1_C,T2_C,T_stator_C,P1_um\n" + "\n".join(rows) + "\n")
    n = log_on_change(src, tmp_path / "oc.csv")
    run = read_bench(tmp_path / "oc.csv")
    assert n == len(run.time_s) < len(t) / 3  # one scan in three at most
    t2, _ = run.channel("T2")
    # the steady T2 reports on its heartbeat: every beat_T2 s to within a 3 s scan
    assert np.all(np.abs(np.diff(t2) - beat_T2) <= 3.0 + 1e-9)
    t1, y1 = run.channel("T1")
    # T1 climbs 0.002 K/s: it reports each time it has moved past its band, which takes
    # band / rate s, to within a 3 s scan (0.006 K), unless its heartbeat came first
    steps = np.diff(y1)
    assert np.all(steps <= band_T1 + 0.006 + 1e-9)
    assert np.all((steps > band_T1 - 1e-9) | (np.diff(t1) >= ON_CHANGE["T1_C"][1] - 1e-9))
