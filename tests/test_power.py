"""spindle/power.py: each loss formula against a value worked out here independently, the R(T)
law, the power bound, and the SPL2782.1 nominal point against the paper's 5146 W. (The film
correlations are in tests/test_correlations.py.)

Tolerances: ``REL_FP`` where the test re-evaluates the same closed formula (floating-point
rounding only); ``REL_HAND`` where the reference number was worked out by hand with 4-5
significant digits in the intermediate steps (stated next to each).
"""

import dataclasses
import math

import numpy as np
import pytest

from spindle import correlations, power
from spindle.drive import DRIVES
from spindle.power import BearingParams, MotorParams

SPL2782 = DRIVES["spl2782"]
SPL2782_MOTOR = SPL2782.motor
SPL2782_BEARINGS = SPL2782.bearings
SPL2782_FRONT_BEARINGS = SPL2782_BEARINGS["front_bearing"]
SPL2782_REAR_BEARINGS = SPL2782_BEARINGS["rear_bearing"]

REL_FP = 1e-12  # same formula re-evaluated: rounding only
REL_HAND = 2e-3  # hand-rounded intermediate values (4 significant digits)
W_4300 = 4300 * 2 * math.pi / 60  # 450.2949 rad/s


def bearing(**kw) -> BearingParams:
    base = dict(name="test", f0=2.0, dm_m=0.046, nu_mm2_s=20.0, preload_N=500.0, C0_N=11_200.0,
                count=1)
    return BearingParams(**{**base, **kw})


# --------------------------------------------------------------------------- bearings


def test_palmgren_M0_hand_value():
    # 6206-size example: f0 2, nu 20 mm2/s, 3000 rpm, dm 46 mm -> nu n = 60000;
    # 60000^(2/3) = 1532.6, 46^3 = 97336: M0 = 1e-7 * 2 * 1532.6 * 97336 = 29.835 N mm
    assert power.palmgren_M0_Nmm(2.0, 20.0, 3000.0, 46.0) == pytest.approx(29.835, rel=REL_HAND)
    written_out = 1e-7 * 2.0 * (20.0 * 3000.0) ** (2 / 3) * 46.0**3
    assert power.palmgren_M0_Nmm(2.0, 20.0, 3000.0, 46.0) == pytest.approx(written_out, rel=REL_FP)


def test_palmgren_M0_low_speed_branch():
    # nu n < 2000: M0 = 160e-7 f0 dm^3 whatever the speed (46^3 = 97336 -> 3.1148 N mm)
    for n in (0.0, 10.0, 99.9):
        assert power.palmgren_M0_Nmm(2.0, 20.0, n, 46.0) == pytest.approx(160e-7 * 2 * 97336, rel=REL_FP)
    # just above the switch the speed formula applies (2000^(2/3) = 158.74 < 160)
    above = power.palmgren_M0_Nmm(2.0, 20.0, 100.0, 46.0)
    assert above == pytest.approx(1e-7 * 2 * 2000 ** (2 / 3) * 97336, rel=REL_FP)


def test_palmgren_f1_and_M1_hand_value():
    # P0/C0 = 500/11200 = 0.044643; ^0.33 = exp(0.33 ln 0.044643) = exp(-1.02571) = 0.35855
    f1 = power.palmgren_f1_angular_contact(500.0, 11_200.0)
    assert f1 == pytest.approx(0.35855e-3, rel=REL_HAND)
    # M1 = f1 P1 dm = 0.35855e-3 * 500 * 46 = 8.2467 N mm
    assert power.palmgren_M1_Nmm(f1, 500.0, 46.0) == pytest.approx(8.2467, rel=REL_HAND)


def test_bearing_friction_torque_and_heat():
    b = bearing(count=2, inner_ring_share=0.3)
    r = power.bearing_friction(b, 3000.0)
    M_one_Nmm = 1e-7 * 2 * 60000 ** (2 / 3) * 46**3 + 0.001 * (500 / 11200) ** 0.33 * 500 * 46
    assert r.torque_Nm == pytest.approx(2 * M_one_Nmm * 1e-3, rel=REL_FP)
    assert r.M0_Nm + r.M1_Nm == pytest.approx(r.torque_Nm, rel=REL_FP)
    assert r.heat_W == pytest.approx(r.torque_Nm * 3000 * 2 * math.pi / 60, rel=REL_FP)
    assert r.inner_ring_W == pytest.approx(0.3 * r.heat_W, rel=REL_FP)
    assert r.inner_ring_W + r.outer_ring_W == pytest.approx(r.heat_W, rel=REL_FP)
    # at standstill there is a torque but no heat
    s = power.bearing_friction(b, 0.0)
    assert s.torque_Nm > 0 and s.heat_W == 0.0


def test_bearing_radial_load_raises_equivalent_load():
    b = bearing()
    base = power.bearing_friction(b, 3000.0)
    # Fr = 2000 N > Fa - 0.1 Fr = 300 N: P1 = Fr
    loaded = power.bearing_friction(b, 3000.0, radial_load_N=2000.0)
    f1 = 0.001 * (2000 / 11200) ** 0.33
    assert loaded.M1_Nm == pytest.approx(f1 * 2000 * 46 * 1e-3, rel=REL_FP)
    assert loaded.M0_Nm == base.M0_Nm and loaded.M1_Nm > base.M1_Nm


def test_bearing_heat_monotonic_in_speed():
    speeds = [0, 500, 1000, 2000, 3000, 4300, 6000, 8000, 12000]
    for p in (SPL2782_FRONT_BEARINGS, SPL2782_REAR_BEARINGS):
        heat = [power.bearing_friction(p, n).heat_W for n in speeds]
        assert np.all(np.diff(heat) > 0), heat


def test_spl2782_bearing_sanity_at_4300_rpm():
    front = power.bearing_friction(SPL2782_FRONT_BEARINGS, 4300.0).heat_W
    rear = power.bearing_friction(SPL2782_REAR_BEARINGS, 4300.0).heat_W
    assert 20.0 < front < 150.0  # the brief's range: tens to ~150 W
    assert 0.5 * front < rear < front  # smaller pair: somewhat less


def test_viscosity_override_and_walther():
    b = bearing()
    assert power.bearing_friction(b, 3000.0, nu_mm2_s=40.0).M0_Nm == pytest.approx(
        2 ** (2 / 3) * power.bearing_friction(b, 3000.0).M0_Nm, rel=1e-12)
    # Walther reproduces its two anchor points and lies between them
    assert power.walther_viscosity_mm2_s(23.0, 4.7, 313.15) == pytest.approx(23.0, rel=1e-9)
    assert power.walther_viscosity_mm2_s(23.0, 4.7, 373.15) == pytest.approx(4.7, rel=1e-9)
    assert 4.7 < power.walther_viscosity_mm2_s(23.0, 4.7, 333.15) < 23.0


@pytest.mark.parametrize("kw", [dict(f0=0.0), dict(dm_m=115.0), dict(nu_mm2_s=-1.0),
                                dict(preload_N=-5.0), dict(count=0), dict(count=1.5),
                                dict(inner_ring_share=1.2), dict(C0_N=math.nan)])
def test_bearing_params_reject_non_physical(kw):
    with pytest.raises(ValueError):
        bearing(**kw)


def test_negative_speed_is_rejected():
    with pytest.raises(ValueError, match="negative"):
        power.bearing_friction(bearing(), -100.0)
    with pytest.raises(ValueError, match="negative"):
        power.motor_losses(SPL2782_MOTOR, -100.0, 10.0, 300.0)
    with pytest.raises(ValueError, match="negative"):
        correlations.h_rotating_shaft_W_m2K(-1.0, 0.1)


# ---------------------------------------------------------------------------- motor


def test_resistance_law_eq17():
    R20 = 0.2
    assert power.winding_resistance_ohm(R20, 293.15) == pytest.approx(R20, rel=REL_FP)
    # +100 K: 1 + 0.00393 * 100 = 1.393 (+39.3 %)
    assert power.winding_resistance_ohm(R20, 393.15) == pytest.approx(1.393 * R20, rel=REL_FP)
    with pytest.raises(ValueError):
        power.winding_resistance_ohm(R20, -1.0)


def test_copper_iron_and_frequency_hand_values():
    # 3 phases, 50 A, 0.2 ohm: 3 * 2500 * 0.2 = 1500 W
    assert power.copper_loss_W(50.0, 0.2) == pytest.approx(1500.0, rel=REL_FP)
    # 4300 rpm, 4 pole pairs: f = 4300 * 4 / 60 = 286.667 Hz
    f = power.electrical_frequency_Hz(4300.0, 4)
    assert f == pytest.approx(286.667, rel=REL_HAND)
    # eq. 18: 0.6 * 286.667 * 1.5^2 = 387.0 W; eq. 19: 3e-3 * 286.667^2 * 2.25 = 554.70 W
    assert power.hysteresis_loss_W(0.6, f, 1.5) == pytest.approx(387.0, rel=REL_HAND)
    assert power.eddy_loss_W(3e-3, f, 1.5) == pytest.approx(554.70, rel=REL_HAND)


def test_eq15_motor_torque():
    assert power.motor_torque_Nm(10.0) == 10.0
    # M = M_L + J dw/dt = 10 + 0.05 * 40 = 12 N m
    assert power.motor_torque_Nm(10.0, 0.05, 40.0) == pytest.approx(12.0, rel=REL_FP)
    m = power.motor_losses(SPL2782_MOTOR, 3000.0, 10.0, 330.0, J_kgm2=0.05, dw_dt_rad_s2=40.0)
    assert m.torque_Nm == pytest.approx(12.0, rel=REL_FP)
    assert m.P_mech_W == pytest.approx(12.0 * 3000 * 2 * math.pi / 60, rel=REL_FP)


def test_motor_losses_model_hand_value():
    # 1FE1 set at 4300 rpm, 84.389 N m, 120 degC: I = 84.389 / 1.2 = 70.324 A;
    # R = 0.195 * 1.393 = 0.27164 ohm; P_cu = 3 * 70.324^2 * 0.27164 = 4030.1 W
    m = power.motor_losses(SPL2782_MOTOR, 4300.0, 84.389, 393.15)
    assert m.current_A == pytest.approx(70.324, rel=REL_HAND)
    assert m.copper_W == pytest.approx(4030.1, rel=REL_HAND)
    assert m.iron_hysteresis_W == pytest.approx(387.0, rel=REL_HAND)
    assert m.iron_eddy_W == pytest.approx(554.70, rel=REL_HAND)
    assert m.total_W == pytest.approx(m.copper_W + m.iron_hysteresis_W + m.iron_eddy_W, rel=REL_FP)
    assert m.rotor_W == pytest.approx(0.06 * m.total_W, rel=REL_FP)
    assert m.stator_W + m.rotor_W == pytest.approx(m.total_W, rel=REL_FP)
    assert m.scale == 1.0


def test_motor_losses_grow_with_speed_and_torque():
    speeds = [0, 1000, 2000, 4300, 8000]
    tot = [power.motor_losses(SPL2782_MOTOR, n, 20.0, 350.0).total_W for n in speeds]
    assert np.all(np.diff(tot) > 0)
    torques = [0, 10, 40, 80]
    tot = [power.motor_losses(SPL2782_MOTOR, 4300.0, t, 350.0).total_W for t in torques]
    assert np.all(np.diff(tot) > 0)
    hot = power.motor_losses(SPL2782_MOTOR, 4300.0, 40.0, 400.0).copper_W
    assert hot > power.motor_losses(SPL2782_MOTOR, 4300.0, 40.0, 300.0).copper_W


def test_power_bound_when_P_el_is_given():
    model = power.motor_losses(SPL2782_MOTOR, 4300.0, 50.0, 350.0)
    P_mech = 50.0 * W_4300
    for P_el in (P_mech, P_mech + 100.0, P_mech + model.model_total_W, P_mech + 9000.0):
        m = power.motor_losses(SPL2782_MOTOR, 4300.0, 50.0, 350.0, P_el_W=P_el)
        assert m.total_W <= P_el - P_mech + 1e-9 * P_el
        assert m.total_W == pytest.approx(P_el - P_mech, rel=1e-12, abs=1e-9)
        # the component model only distributes the measured loss: ratios are kept
        if m.total_W == 0.0:
            assert m.copper_W == m.iron_hysteresis_W == m.iron_eddy_W == 0.0
            continue
        assert m.copper_W / m.total_W == pytest.approx(model.copper_W / model.total_W, rel=1e-12)
        assert m.copper_W + m.iron_hysteresis_W + m.iron_eddy_W == pytest.approx(m.total_W,
                                                                                  rel=1e-12)


def test_power_bound_random_operating_points():
    rng = np.random.default_rng(1)
    for _ in range(200):
        n, M, T = rng.uniform(0, 12000), rng.uniform(0, 120), rng.uniform(280, 420)
        P_mech = M * n * 2 * math.pi / 60
        P_el = P_mech * rng.uniform(1.0, 1.3) + rng.uniform(0, 500)
        m = power.motor_losses(SPL2782_MOTOR, n, M, T, P_el_W=P_el)
        assert 0.0 <= m.total_W <= P_el - P_mech + 1e-9 * max(P_el, 1.0)
        assert min(m.copper_W, m.iron_hysteresis_W, m.iron_eddy_W, m.rotor_W, m.stator_W) >= 0


def test_efficiency_above_one_is_rejected():
    P_mech = 50.0 * W_4300
    with pytest.raises(ValueError, match="efficiency would exceed 1"):
        power.motor_losses(SPL2782_MOTOR, 4300.0, 50.0, 350.0, P_el_W=0.99 * P_mech)


def test_standstill_measured_loss_goes_to_copper():
    m = power.motor_losses(SPL2782_MOTOR, 0.0, 0.0, 300.0, P_el_W=120.0)
    assert m.copper_W == 120.0 and m.iron_eddy_W == 0.0 and m.total_W == 120.0


@pytest.mark.parametrize("kw", [dict(R20_ohm=0.0), dict(kT_Nm_A=-1.0), dict(pole_pairs=0),
                                dict(rotor_loss_share=1.5), dict(B_T=math.inf)])
def test_motor_params_reject_non_physical(kw):
    with pytest.raises(ValueError):
        dataclasses.replace(SPL2782_MOTOR, **kw)
    assert isinstance(SPL2782_MOTOR, MotorParams)


# ------------------------------------------------------------------- power balance


def test_spl2782_nominal_point_matches_paper_total():
    pb = SPL2782.nominal_point()
    assert pb.motor.P_mech_W == pytest.approx(38_000.0, rel=1e-12)
    assert pb.total_heat_W == pytest.approx(5146.0, rel=0.05)
    assert pb.motor.total_W == pytest.approx(5146.0 - pb.bearing_heat_W, rel=0.05)
    src = pb.heat_sources_W()
    assert set(src) == {"stator", "rotor", "front_bearing", "rear_bearing"}
    assert sum(src.values()) == pytest.approx(pb.total_heat_W, rel=1e-12)
    assert src["rear_bearing"] < src["front_bearing"]


def test_power_balance_adds_bearing_torque_to_load():
    pb = power.power_balance(SPL2782_MOTOR, SPL2782_BEARINGS, 4300.0, 20.0, 330.0)
    friction = sum(b.torque_Nm for b in pb.bearings.values())
    assert pb.motor.torque_Nm == pytest.approx(20.0 + friction, rel=1e-12)
    # with P_el: heat = P_el - process power (bearing heat counted once)
    P_el = 12_000.0
    pb = power.power_balance(SPL2782_MOTOR, SPL2782_BEARINGS, 4300.0, 20.0, 330.0, P_el_W=P_el)
    assert pb.total_heat_W == pytest.approx(P_el - 20.0 * W_4300, rel=1e-12)


def test_old_import_paths_of_the_film_correlations():
    """spindle.spec and other code still find these four correlations in spindle.power."""
    for name in ("shaft_film_table", "air_gap_film_table", "h_coolant_channel_W_m2K",
                 "h_rotating_shaft_W_m2K"):
        assert getattr(power, name) is getattr(correlations, name)
