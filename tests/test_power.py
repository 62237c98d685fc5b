"""spindle/power.py: each formula against a value worked out here independently, the branches
of the correlations, monotonicity in speed, the R(T) law, the power bound, and the SPL2782.1
nominal point against the paper's 5146 W.

Tolerances: ``REL_FP`` where the test re-evaluates the same closed formula (floating-point
rounding only); ``REL_HAND`` where the reference number was worked out by hand with 4-5
significant digits in the intermediate steps (stated next to each).
"""

import dataclasses
import math

import numpy as np
import pytest

from spindle import power
from spindle.loads import SpeedTable
from spindle.power import (
    SPL2782_FRONT_BEARINGS,
    SPL2782_MOTOR,
    SPL2782_REAR_BEARINGS,
    BearingParams,
    MotorParams,
)

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
        power.h_rotating_shaft_W_m2K(-1.0, 0.1)


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
    pb = power.spl2782_nominal_point()
    assert pb.motor.P_mech_W == pytest.approx(38_000.0, rel=1e-12)
    assert pb.total_heat_W == pytest.approx(5146.0, rel=0.05)
    assert pb.motor.total_W == pytest.approx(5146.0 - pb.bearing_heat_W, rel=0.05)
    src = pb.heat_sources_W()
    assert set(src) == {"stator", "rotor", "front_bearing", "rear_bearing"}
    assert sum(src.values()) == pytest.approx(pb.total_heat_W, rel=1e-12)
    assert src["rear_bearing"] < src["front_bearing"]


def test_power_balance_adds_bearing_torque_to_load():
    pb = power.power_balance(SPL2782_MOTOR, power.SPL2782_BEARINGS, 4300.0, 20.0, 330.0)
    friction = sum(b.torque_Nm for b in pb.bearings.values())
    assert pb.motor.torque_Nm == pytest.approx(20.0 + friction, rel=1e-12)
    # with P_el: heat = P_el - process power (bearing heat counted once)
    P_el = 12_000.0
    pb = power.power_balance(SPL2782_MOTOR, power.SPL2782_BEARINGS, 4300.0, 20.0, 330.0, P_el_W=P_el)
    assert pb.total_heat_W == pytest.approx(P_el - 20.0 * W_4300, rel=1e-12)


# ------------------------------------------------------------------------ properties


def test_property_tables():
    a = power.air_properties(300.0)
    assert (a.nu_m2_s, a.k_W_mK, a.Pr) == (15.89e-6, 26.3e-3, 0.707)
    w = power.water_properties(300.0)
    assert w.nu_m2_s == pytest.approx(855e-6 * 1.003e-3, rel=1e-12)
    assert w.Pr == 5.83
    for f, T in ((power.air_properties, 200.0), (power.water_properties, 350.0)):
        with pytest.raises(ValueError, match="outside"):
            f(T)


# --------------------------------------------------------------------- rotating shaft


def test_rotating_shaft_hand_value_at_4300_rpm():
    # d 0.13 m, air at 300 K (nu 15.89e-6, k 0.0263, Pr 0.707): u = 450.29 * 0.065 = 29.269 m/s
    # Re = 29.269 * 0.13 / 15.89e-6 = 2.3946e5; Re^(2/3) = 3855.0; Pr^(1/3) = 0.89086
    # Nu = 0.133 * 3855.0 * 0.89086 = 456.76; h = 456.76 * 0.0263 / 0.13 = 92.41 W/m2/K
    h = power.h_rotating_shaft_W_m2K(4300.0, 0.13, T_air_K=300.0)
    assert h == pytest.approx(92.41, rel=REL_HAND)


def test_rotating_shaft_floor_is_churchill_chu_at_standstill():
    # d 0.13 m, dT 20 K above air at 290 K: film 300 K (nu 15.89e-6, alpha 22.475e-6, Pr 0.707)
    # Ra = 9.80665 * 20/300 * 0.13^3 / (15.89e-6 * 22.475e-6) = 4.0248e6; Ra^(1/6) = 12.610
    # [1 + (0.559/0.707)^(9/16)]^(8/27) = 1.8762^(0.2963) = 1.2049
    # Nu = (0.60 + 0.387 * 12.610 / 1.2049)^2 = 4.6502^2 = 21.624; h = 21.624 * 0.0263 / 0.13
    h0 = power.h_rotating_shaft_W_m2K(0.0, 0.13, T_air_K=290.0, dT_K=20.0)
    assert h0 == pytest.approx(4.3747, rel=REL_HAND)
    assert power.h_rotating_shaft_W_m2K(0.0, 0.13, h_floor_W_m2K=8.0) == 8.0
    # forced convection takes over once it exceeds the floor
    assert power.h_rotating_shaft_W_m2K(4300.0, 0.13, h_floor_W_m2K=8.0) > 80.0


def test_rotating_shaft_monotonic_in_speed():
    speeds = np.linspace(0, 15000, 61)
    h = [power.h_rotating_shaft_W_m2K(n, 0.13) for n in speeds]
    assert np.all(np.diff(h) >= 0) and h[-1] > h[0]


# ----------------------------------------------------------------------------- air gap


def test_taylor_geometry_factor_narrow_gap_limit():
    # e/R -> 0: P -> 0.05766, F_g -> pi^4 / (1697 * 0.05766) = 0.99546
    assert power.taylor_geometry_factor(1.0, 1e-7) == pytest.approx(0.99546, rel=REL_HAND)
    assert power.taylor_geometry_factor(0.0595, 0.00075) > 1.0


def test_becker_kaye_branches():
    assert power.nusselt_becker_kaye(0.0) == 2.0
    assert power.nusselt_becker_kaye(1699.0) == 2.0
    # vortex branch: 0.128 * 5000^0.367 = 0.128 * exp(0.367 * 8.51719) = 0.128 * 22.795 = 2.9178
    assert power.nusselt_becker_kaye(5000.0) == pytest.approx(2.9178, rel=REL_HAND)
    # turbulent branch: 0.409 * 1e5^0.241 = 0.409 * exp(0.241 * 11.5129) = 0.409 * 16.032 = 6.557
    assert power.nusselt_becker_kaye(1e5) == pytest.approx(6.557, rel=REL_HAND)
    # floored at conduction where the published vortex fit dips to 1.96
    assert power.nusselt_becker_kaye(1700.0) == 2.0
    with pytest.raises(ValueError, match="1e7"):
        power.nusselt_becker_kaye(2e7)


def test_air_gap_standstill_is_conduction_and_hand_value():
    air = power.air_properties(323.15)
    assert power.h_air_gap_W_m2K(0.0, 0.0595, 0.00075) == pytest.approx(air.k_W_mK / 0.00075,
                                                                          rel=REL_FP)
    # 4300 rpm, r 0.0595, e 0.00075, air 323.15 K: nu = 18.219e-6, k = 0.028013
    # R_m = 0.00075 / ln(0.06025/0.0595) = 0.059876; F_g = 1.01628
    # Ta = 450.29^2 * 0.059876 * 0.00075^3 / 18.219e-6^2 = 15430; Ta_m = 15183
    # Nu = 0.409 * 15183^0.241 = 4.1633; h = 4.1633 * 0.028013 / 0.0015 = 77.75 W/m2/K
    assert power.modified_taylor_number(4300.0, 0.0595, 0.00075, air.nu_m2_s) == pytest.approx(
        15183.0, rel=REL_HAND)
    assert power.h_air_gap_W_m2K(4300.0, 0.0595, 0.00075) == pytest.approx(77.75, rel=REL_HAND)


def test_air_gap_monotonic_in_speed():
    speeds = np.linspace(0, 20000, 201)
    h = [power.h_air_gap_W_m2K(n, 0.0595, 0.00075) for n in speeds]
    assert np.all(np.diff(h) >= 0) and h[-1] > 2 * h[0]


# -------------------------------------------------------------------------- coolant


def test_dittus_boelter_branches():
    assert power.nusselt_dittus_boelter(1000.0, 7.0) == 4.36
    assert power.nusselt_dittus_boelter(1000.0, 7.0, laminar_Nu=3.66) == 3.66
    # turbulent: 0.023 * 2e4^0.8 * 5^0.4 = 0.023 * 2759.6 * 1.9037 = 120.83
    assert power.nusselt_dittus_boelter(2e4, 5.0) == pytest.approx(120.83, rel=REL_HAND)
    # transitional: linear between 4.36 at 2300 and DB(1e4) at 1e4
    lo, hi = 4.36, 0.023 * 1e4**0.8 * 5.0**0.4
    mid = power.nusselt_dittus_boelter(6150.0, 5.0)
    assert mid == pytest.approx(0.5 * (lo + hi), rel=REL_FP)
    nu = [power.nusselt_dittus_boelter(r, 5.0) for r in np.linspace(0, 3e4, 301)]
    assert np.all(np.diff(nu) >= 0)


def test_coolant_channel_hand_value():
    # 6 l/min = 1e-4 m3/s in 6 x 10 mm: A = 6e-5 m2, D_h = 4 * 60 / 32 mm = 7.5 mm, u = 1.6667 m/s
    Re, Dh, u = power.coolant_channel_reynolds(6.0, 0.006, 0.010)
    assert Dh == pytest.approx(0.0075, rel=REL_FP) and u == pytest.approx(1e-4 / 6e-5, rel=REL_FP)
    # water at 20 degC, Table A.6 interpolated 290..295 K at 0.63: mu 1003.8e-6, v_f 1.00163e-3,
    # k 0.60304, Pr 6.9678 -> nu = 1.00544e-6; Re = 1.6667 * 0.0075 / 1.00544e-6 = 12433
    assert Re == pytest.approx(12433.0, rel=REL_HAND)
    # Nu = 0.023 * 12433^0.8 * 6.9678^0.4 = 0.023 * 1886.3 * 2.1739 = 94.31; h = Nu k / D_h
    h = power.h_coolant_channel_W_m2K(6.0, 0.006, 0.010)
    assert h == pytest.approx(94.31 * 0.60304 / 0.0075, rel=REL_HAND)
    assert power.h_coolant_channel_W_m2K(0.2, 0.006, 0.010) == pytest.approx(4.36 * 0.60304 / 0.0075,
                                                                            rel=REL_HAND)


# ------------------------------------------------------------------------ tabulation


def test_speed_tables_for_specs():
    t = power.shaft_film_table(0.13, (0.0, 4300.0, 8000.0))
    assert isinstance(t, SpeedTable)
    assert t(4300.0) == pytest.approx(power.h_rotating_shaft_W_m2K(4300.0, 0.13), rel=REL_FP)
    g = power.air_gap_film_table(0.0595, 0.00075)
    assert g.speed_rpm == power.DEFAULT_SPEEDS_RPM and np.all(np.diff(g.values) >= 0)
    c = power.speed_table(lambda n: 2.0 * n, (0.0, 10.0))
    assert c.values == (0.0, 20.0)
    with pytest.raises(ValueError, match="ascending"):
        power.speed_table(lambda n: n, (0.0, 10.0, 5.0))
    with pytest.raises(ValueError):
        power.speed_table(lambda n: n, (-1.0, 10.0))
