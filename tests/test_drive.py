"""Cycles to heat sources through the power balance; drive files and the spec's preset."""

import dataclasses

import pytest

from spindle import drive_file
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES, cycle_load_case, drive_for
from spindle.drive_file import read_drive_toml
from spindle.errors import InputError, SpecError
from spindle.power import BearingParams, MotorParams, power_balance
from spindle.spec_reader import load_spec


def test_each_step_gets_its_power_balance():
    spec = load_spec("spl2782")
    cycle = load_cycle("spl-16h")
    case = cycle_load_case(spec, cycle)
    drive = drive_for(spec)
    for step, t0 in zip(cycle.steps, cycle.boundaries_s[:-1], strict=False):
        pb = power_balance(drive.motor, drive.bearings, step.speed_rpm, step.load_torque_Nm,
                           drive.T_winding_K).heat_sources_W()
        for name, value in pb.items():
            # held over the whole step (sampled mid-step and just before its end)
            assert case.sources[name](t0 + 0.5 * step.duration_s) == pytest.approx(value)
            assert case.sources[name](t0 + step.duration_s - 1.0) == pytest.approx(value)
    # standstill: no friction, no iron loss, no current
    assert all(case.sources[k](15.5 * 3600) == 0.0 for k in case.sources)
    assert case.duration_s == 16 * 3600


def test_nominal_case_closes_the_paper_balance():
    """38 kW electrical at 4300 rpm with 72.96 N m at the tool: P_el - P_tool = 5146 W."""
    spec = load_spec("spl2782")
    case = cycle_load_case(spec, load_cycle("nominal"))
    assert sum(float(v(0.0)) for v in case.sources.values()) == pytest.approx(5146.0, rel=1e-3)


def test_spec_without_drive_keeps_its_sources():
    spec = load_spec("fin-shaft")
    assert drive_for(spec) is None
    case = cycle_load_case(spec, load_cycle("spl-16h"))
    # sources a case does not name keep the spec's own power (LoadCase semantics)
    assert "Q2_front_bearing_B" not in case.sources
    assert case.duration_s == 16 * 3600


def test_unknown_preset_is_a_clear_error_when_the_spec_is_read(tmp_path):
    """Refused by the spec's reader (issue 31: a steady solve, which needs no drive, used to
    accept it), not first when a cycle needs the drive."""
    src = open(load_spec("fin-shaft").path).read() + '\n[power_balance]\npreset = "nope"\n'
    path = tmp_path / "x.toml"
    path.write_text(src)
    with pytest.raises(SpecError, match="power_balance.preset"):
        load_spec(path)


def test_drive_variants():
    d = DRIVES["spl2782"]
    assert all(b.f0 == 1.3 for b in d.with_f0(1.3).bearings.values())
    assert d.with_rotor_share(0.2).motor.rotor_loss_share == 0.2


# ------------------------------------------------------------------------------ drive files

# The SPL2782.1 parameter set as the Python constants of spindle/power.py held it before it
# moved to spindle/data/drives/spl2782.toml, copied literally (f0 since recalibrated: 0.30 -> 0.26,
# issue 15, docs/paper.md).
OLD_MOTOR = dict(name="Siemens 1FE1084-4WN31 (SPL2782.1)", R20_ohm=0.195, kT_Nm_A=1.2,
                 pole_pairs=4, k_h_W_HzT2=0.6, k_e_W_Hz2T2=3.0e-3, B_T=1.5, phases=3,
                 rotor_loss_share=0.06, alpha_cu_1_K=0.00393)
OLD_BEARINGS = {
    "front_bearing": dict(name="SPL2782.1 front pair 2 x 7018", f0=0.26, dm_m=0.115,
                          nu_mm2_s=12.0, preload_N=400.0, C0_N=52_000.0, count=2,
                          inner_ring_share=0.5),
    "rear_bearing": dict(name="SPL2782.1 rear pair 2 x 7016", f0=0.26, dm_m=0.1025,
                         nu_mm2_s=12.0, preload_N=300.0, C0_N=40_000.0, count=2,
                         inner_ring_share=0.5),
}
OLD_T_WINDING_K = 393.15
OLD_NOMINAL = dict(speed_rpm=4300.0, P_mech_W=38_000.0, losses_W=5146.0)

SMALL_DRIVE = """
[drive]
T_winding_K = 373.15

[motor]
R20_ohm = 0.5
kT_Nm_A = 0.8
pole_pairs = 2
k_h_W_HzT2 = 0.2
k_e_W_Hz2T2 = 1e-3
B_T = 1.2

[bearings.front_bearing]
f0 = 1.0
dm_m = 0.06
nu_mm2_s = 20.0
preload_N = 200.0
C0_N = 15000.0

[bearings.rear_bearing]
f0 = 1.0
dm_m = 0.05
nu_mm2_s = 20.0
preload_N = 150.0
C0_N = 12000.0
"""


def test_shipped_drive_equals_the_former_constants():
    d = DRIVES["spl2782"]
    assert d is drive_for(load_spec("spl2782"))
    for key, value in OLD_MOTOR.items():
        got = getattr(d.motor, key)
        assert got == value and type(got) is type(value), key
    assert list(d.bearings) == list(OLD_BEARINGS)  # order: front, then rear
    for name, old in OLD_BEARINGS.items():
        for key, value in old.items():
            got = getattr(d.bearings[name], key)
            assert got == value and type(got) is type(value), (name, key)
    assert d.T_winding_K == OLD_T_WINDING_K
    assert (d.nominal.speed_rpm, d.nominal.P_mech_W, d.nominal.losses_W) == tuple(OLD_NOMINAL.values())
    # the sources keep their status labels and reasons
    assert d.motor.source.startswith("ASSUMED: pole_pairs 4 (1FE1 PMSM")
    assert d.motor.source.endswith("(magnet and sleeve eddy losses of a PMSM rotor)")
    for b, size in zip(d.bearings.values(), ("7018", "7016"), strict=True):
        assert b.source.startswith(f"The paper (grease-lubricated pairs); {size} dimensions ISO 15; "
                                   "CALIBRATED f0 = 0.26 per bearing (docs/paper.md: fitted")
        assert b.source.endswith("25 deg super-precision bearings of this size (the split of M: "
                                 "docs/power.md).")


def test_drive_file_fields_cover_the_parameter_classes():
    for fields, cls in ((drive_file.MOTOR_FIELDS, MotorParams),
                        (drive_file.BEARING_FIELDS, BearingParams)):
        keys = {f.key for f in fields} | set(drive_file.TEXT_KEYS)
        assert keys == {f.name for f in dataclasses.fields(cls)}, cls


def _spec_with_preset(tmp_path, preset: str):
    src = open(load_spec("spl2782").path).read().replace('preset = "spl2782"',
                                                         f"preset = {preset!r}")
    path = tmp_path / "spec.toml"
    path.write_text(src)
    return load_spec(path)


def test_spec_preset_can_be_a_drive_file_next_to_the_spec(tmp_path):
    (tmp_path / "drives").mkdir()
    (tmp_path / "drives" / "my-motor.toml").write_text(SMALL_DRIVE)
    spec = _spec_with_preset(tmp_path, "drives/my-motor.toml")
    d = drive_for(spec)
    assert d.name == "my-motor" and d.T_winding_K == 373.15 and d.nominal is None
    assert d.motor.R20_ohm == 0.5 and d.motor.phases == 3 and d.motor.rotor_loss_share == 0.06
    assert d.bearings["rear_bearing"].dm_m == 0.05 and d.bearings["rear_bearing"].count == 2
    # its heat reaches the spec's sources through the cycle
    case = cycle_load_case(spec, load_cycle("nominal"))
    expected = d.heat_W(4300.0, *[(s.load_torque_Nm, s.power_kW)
                                  for s in load_cycle("nominal").steps][0])
    assert case.sources["front_bearing"](0.0) == pytest.approx(expected["front_bearing"])
    # an absolute path works from anywhere
    assert drive_for(_spec_with_preset(tmp_path, str(tmp_path / "drives" / "my-motor.toml"))) == d
    with pytest.raises(ValueError, match="no nominal point"):
        d.nominal_point()


def test_preset_that_is_no_drive_names_the_spec_field_and_the_options(tmp_path):
    with pytest.raises(SpecError) as err:
        _spec_with_preset(tmp_path, "drives/missing.toml")
    [p] = err.value.problems
    assert (p.file, p.field) == (str(tmp_path / "spec.toml"), "power_balance.preset")
    assert "spl2782" in p.fix and "relative to the spec's folder" in p.fix


def test_a_drive_file_removed_after_the_spec_was_read_is_still_named(tmp_path):
    """drive_for keeps its own check: the file may go between reading the spec and the run."""
    (tmp_path / "drives").mkdir()
    (tmp_path / "drives" / "my-motor.toml").write_text(SMALL_DRIVE)
    spec = _spec_with_preset(tmp_path, "drives/my-motor.toml")
    (tmp_path / "drives" / "my-motor.toml").unlink()
    with pytest.raises(InputError) as err:
        drive_for(spec)
    assert err.value.problem.field == "power_balance.preset"


def test_drive_file_reports_every_problem_with_file_field_and_fix(tmp_path):
    bad = (SMALL_DRIVE.replace("T_winding_K = 373.15", "T_winding_K = 120.0")
           .replace("pole_pairs = 2", "pole_pairs = 2.5")
           .replace("dm_m = 0.06", "dm_m = 60.0")
           .replace("kT_Nm_A = 0.8\n", "")
           .replace("B_T = 1.2", 'B_T = "strong"\nR20_Ohm = 0.5')
           + "\n[bearings.stator]\nf0 = 1.0\n")
    path = tmp_path / "bad.toml"
    path.write_text(bad)
    with pytest.raises(SpecError) as err:
        read_drive_toml(path)
    by_field = {p.field: p for p in err.value.problems}
    assert set(by_field) == {"drive.T_winding_K", "motor.pole_pairs", "bearings.front_bearing.dm_m",
                             "motor.kT_Nm_A", "motor.B_T", "motor.R20_Ohm", "bearings.stator"}
    assert all(p.file == str(path) for p in err.value.problems)
    assert "393.15 K" in by_field["drive.T_winding_K"].fix  # degC given for K
    assert "0.115 m" in by_field["bearings.front_bearing.dm_m"].fix  # mm given for m
    assert by_field["motor.kT_Nm_A"].message == "required field is missing"
    assert "typo" in by_field["motor.R20_Ohm"].message and "R20_ohm" in by_field["motor.R20_Ohm"].fix
    assert "whole number" in by_field["motor.pole_pairs"].message
    # one line per problem, each "FILE: FIELD: message; fix: ..."
    assert str(err.value).count("\n") == len(err.value.problems) - 1
    assert all(ln.startswith(f"{path}: ") and "; fix: " in ln for ln in str(err.value).splitlines())


@pytest.mark.parametrize("text, field", [
    ("[motor]\n", "drive"),
    ("[drive]\nT_winding_K = 350.0\n", "motor"),
    ("[drive]\nT_winding_K = 350.0\n[motr]\n", "motr"),
    ("not toml =", "syntax"),
])
def test_drive_file_structure_problems(tmp_path, text, field):
    path = tmp_path / "d.toml"
    path.write_text(text)
    with pytest.raises(SpecError) as err:
        read_drive_toml(path)
    assert field in {p.field for p in err.value.problems}


def test_friction_exponent_scales_the_bearing_friction_with_speed():
    """A drive's friction_exponent e multiplies every pair's f0 by (n / 3000 rpm)^e: the
    bearing heat is unchanged at 3000 rpm, and at 6000 rpm with e = 0.5 it is the heat of a
    drive whose f0 is sqrt(2) times larger (Palmgren's no-load heat is linear in f0)."""
    drive = DRIVES["spl2782"]
    steep = drive.with_friction_exponent(0.5)
    assert steep.heat_W(3000.0)["front_bearing"] == drive.heat_W(3000.0)["front_bearing"]
    f0 = drive.bearings["front_bearing"].f0
    ref = drive.with_f0(f0 * 2 ** 0.5).heat_W(6000.0)
    got = steep.heat_W(6000.0)
    for k in ("front_bearing", "rear_bearing"):
        assert got[k] == pytest.approx(ref[k], rel=1e-12)
    assert drive.with_friction_exponent(0.0).heat_W(6000.0) == drive.heat_W(6000.0)


@pytest.mark.parametrize("old, new, field, words", [
    # a stray exponent overflowed the power balance (found by fuzzing the drive file)
    ("f0 = ", "f0 = 1e200 # ", "bearings.front_bearing.f0", "out of range"),
    ("B_T = 1.2", "B_T = 1e200", "motor.B_T", "out of range"),
    ("kT_Nm_A = 0.8", "kT_Nm_A = 1e-300", "motor.kT_Nm_A", "out of range"),
    # a static load rating given in kN: the preload over C0 made a torque of 1e98 N m
    ("C0_N = ", "C0_N = 40.0 # ", "bearings.front_bearing.C0_N", "out of range"),
    # a viscosity in m2/s (a user's drive file): the friction fell a million-fold, T1 36 K
    ("nu_mm2_s = ", "nu_mm2_s = 1.5e-5 # ", "bearings.front_bearing.nu_mm2_s", "out of range"),
])
def test_drive_values_beyond_any_spindle_are_refused_by_name(tmp_path, old, new, field, words):
    """The bounds sit a hundred to a thousand times beyond any motor spindle's value
    (spindle/drive_file.py), so an absurd value is named instead of overflowing."""
    assert old in SMALL_DRIVE
    path = tmp_path / "d.toml"
    path.write_text(SMALL_DRIVE.replace(old, new, 1))
    with pytest.raises(SpecError) as err:
        read_drive_toml(path)
    by_field = {p.field: p for p in err.value.problems}
    assert field in by_field and words in by_field[field].message
    if field.endswith("C0_N"):
        assert "40000 N" in by_field[field].fix
    if field.endswith("nu_mm2_s"):
        assert "15 mm2/s" in by_field[field].fix


def test_a_cycle_step_whose_power_is_below_its_mechanical_power_names_the_step(tmp_path):
    """P_el < M omega cannot close the power balance: the cycle file and its step are named
    (it was an internal error before)."""
    path = tmp_path / "c.toml"
    path.write_text('[cycle]\nname = "c"\nsteps = [\n  { speed_rpm = 1000.0, duration_h = 1.0 },\n'
                    '  { speed_rpm = 4000.0, duration_h = 1.0, load_torque_Nm = 100, '
                    'power_kW = 1.0 },\n]\n', encoding="utf-8")
    from spindle.drive import load_case

    with pytest.raises(InputError) as err:
        load_case(load_spec("spl2782"), path)
    p = err.value.problem
    assert p.file == str(path) and p.field == "steps[1]" and "mechanical power" in p.message
    assert "power_kW" in p.fix


def test_a_cycle_file_with_a_byte_order_mark_is_read(tmp_path):
    """Some editors save UTF-8 with a byte-order mark; the cycle is read as without it."""
    text = '[cycle]\nname = "c"\nsteps = [ { speed_rpm = 1000.0, duration_h = 1.0 } ]\n'
    plain, marked = tmp_path / "a.toml", tmp_path / "b.toml"
    plain.write_text(text, encoding="utf-8")
    marked.write_text(text, encoding="utf-8-sig")
    assert load_cycle(marked).steps == load_cycle(plain).steps


OWN_SPECS = __import__("pathlib").Path(__file__).resolve().parent / "data" / "own-specs"


def test_the_spl2782_is_rated_at_the_papers_cycles():
    """For the SPL2782.1 (its drive's nominal point is the paper's) 'rated' and 'rated-16h'
    are the shipped nominal and spl-16h, and the drawn cycles are drawn as they were: the
    study, the sensors, measures and the ROM give what they gave."""
    from spindle.cycles import drawn_cycle
    from spindle.drive import rated_scale, spindle_cycle

    spec = load_spec("spl2782")
    assert rated_scale(spec, drive_for(spec)) == (1.0, 1.0)
    assert spindle_cycle(spec, "rated") == load_cycle("nominal")
    assert spindle_cycle(spec, "rated-16h") == load_cycle("spl-16h")
    for name in ("random", "random-loaded", "random-ramped-load"):
        assert spindle_cycle(spec, name, 3) == drawn_cycle(name, 3)


def test_another_spindle_is_studied_at_its_own_rated_point():
    """A user's spec (gs24: 15 kW at 24000 rpm) had been studied at the SPL2782's 38 kW /
    4300 rpm and its 16 h cycle, which put 250 K on its shaft. Its rated point is its
    drive's [nominal]: the torque P_mech / omega held, and spl-16h's plateaus at the same
    shares of its rated speed; the drawn cycles are scaled by the same two ratios."""
    from compare.verify.study import study_cases
    from spindle.cycles import drawn_cycle
    from spindle.drive import spindle_cycle
    from spindle.units import RPM_TO_RAD_S

    spec = load_spec(OWN_SPECS / "gs24.toml")
    drive = drive_for(spec)
    torque = 15000.0 / (24000.0 * RPM_TO_RAD_S)  # the drive file's [nominal]
    steady, transient = study_cases(spec)
    assert steady.speed_rpm(0.0) == 24000.0
    for name, q in drive.heat_W(24000.0, torque).items():
        assert steady.sources[name](0.0) == pytest.approx(q, rel=1e-12)
    paper = load_cycle("spl-16h")
    shares = [s.speed_rpm / 4300.0 for s in paper.steps]
    rated16 = spindle_cycle(spec, "rated-16h")
    assert [s.speed_rpm / 24000.0 for s in rated16.steps] == pytest.approx(shares)
    assert transient.duration_s == paper.duration_s
    drawn, scaled = drawn_cycle("random-loaded", 1), spindle_cycle(spec, "random-loaded", 1)
    k = torque / (38000.0 / 4300.0 / RPM_TO_RAD_S)  # its rated torque over the paper's
    for a, b in zip(drawn.steps, scaled.steps, strict=True):
        assert b.speed_rpm == pytest.approx(a.speed_rpm * 24000.0 / 4300.0)
        assert b.load_torque_Nm == pytest.approx(a.load_torque_Nm * k)


def test_a_drive_without_a_nominal_point_draws_no_loads_it_cannot_scale(tmp_path):
    """Without [nominal] the rated torque is not known: a loaded drawn cycle is refused
    (naming the drive file's table), an unloaded one runs at the spec's operating speed."""
    from spindle.cycles import drawn_cycle
    from spindle.drive import spindle_cycle

    folder = tmp_path / "own"
    folder.mkdir()
    (folder / "drives").mkdir()
    text = (OWN_SPECS / "drives" / "ms12.toml").read_text(encoding="utf-8")
    start = text.index("[nominal]")
    end = text.index("[", start + 1)
    (folder / "drives" / "ms12.toml").write_text(text[:start] + text[end:], encoding="utf-8")
    (folder / "ms12.toml").write_text((OWN_SPECS / "ms12.toml").read_text(encoding="utf-8"),
                                      encoding="utf-8")
    spec = load_spec(folder / "ms12.toml")
    assert drive_for(spec).nominal is None
    with pytest.raises(InputError, match=r"no \[nominal\] point"):
        spindle_cycle(spec, "random-loaded", 0)
    plain = spindle_cycle(spec, "random", 0)
    top = max(s.speed_rpm for s in drawn_cycle("random", 0).steps)
    assert max(s.speed_rpm for s in plain.steps) == pytest.approx(top * spec.speed_rpm / 4300.0)


def test_a_load_beyond_the_drives_rating_is_warned_of(tmp_path):
    """A process torque above twice the rated torque (a spindle motor's short-time ratings
    are 1.3-1.6 times S1) is computed and warned of, naming the step; the paper's nominal
    point (0.86 of the SPL2782's rated torque) is not."""
    import warnings

    from spindle.errors import CycleWarning

    spec = load_spec(OWN_SPECS / "gs24.toml")
    cycle = tmp_path / "heavy.toml"
    cycle.write_text('[cycle]\nname = "heavy"\nsteps = [\n  { speed_rpm = 20000.0, duration_h '
                     '= 1.0 },\n  { speed_rpm = 20000.0, duration_h = 1.0, load_torque_Nm = '
                     '25.0 },\n]\n', encoding="utf-8")
    with pytest.warns(CycleWarning, match=r"steps\[1\]: a process torque of 25 N m is 4.2 "
                      r"times the drive's rated 5.97 N m"):
        cycle_load_case(spec, load_cycle(str(cycle)), where=str(cycle))
    with warnings.catch_warnings():
        warnings.simplefilter("error", CycleWarning)
        cycle_load_case(load_spec("spl2782"), load_cycle("nominal"))
