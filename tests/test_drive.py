"""Cycles to heat sources through the power balance."""

import pytest

from spindle.cycles import load_cycle
from spindle.drive import DRIVES, cycle_load_case, drive_for
from spindle.errors import InputError
from spindle.power import power_balance
from spindle.spec import load_spec


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


def test_unknown_preset_is_a_clear_error(tmp_path):
    src = open(load_spec("fin-shaft").path).read() + '\n[power_balance]\npreset = "nope"\n'
    path = tmp_path / "x.toml"
    path.write_text(src)
    with pytest.raises(InputError, match="power_balance.preset"):
        drive_for(load_spec(path))


def test_drive_variants():
    d = DRIVES["spl2782"]
    assert all(b.f0 == 1.3 for b in d.with_f0(1.3).bearings.values())
    assert d.with_rotor_share(0.2).motor.rotor_loss_share == 0.2
