"""spindle/correlations.py: each film correlation against a value worked out here
independently, the branches of the correlations, monotonicity in speed, the property tables
and the tabulation into speed tables for a spec.

Tolerances: ``REL_FP`` where the test re-evaluates the same closed formula (floating-point
rounding only); ``REL_HAND`` where the reference number was worked out by hand with 4-5
significant digits in the intermediate steps (stated next to each).
"""

import numpy as np
import pytest

from spindle import correlations
from spindle.loads import SpeedTable

REL_FP = 1e-12  # same formula re-evaluated: rounding only
REL_HAND = 2e-3  # hand-rounded intermediate values (4 significant digits)


# ------------------------------------------------------------------------ properties


def test_property_tables():
    a = correlations.air_properties(300.0)
    assert (a.nu_m2_s, a.k_W_mK, a.Pr) == (15.89e-6, 26.3e-3, 0.707)
    w = correlations.water_properties(300.0)
    assert w.nu_m2_s == pytest.approx(855e-6 * 1.003e-3, rel=1e-12)
    assert w.Pr == 5.83
    for f, T in ((correlations.air_properties, 200.0), (correlations.water_properties, 350.0)):
        with pytest.raises(ValueError, match="outside"):
            f(T)


# --------------------------------------------------------------------- rotating shaft


def test_rotating_shaft_hand_value_at_4300_rpm():
    # d 0.13 m, air at 300 K (nu 15.89e-6, k 0.0263, Pr 0.707): u = 450.29 * 0.065 = 29.269 m/s
    # Re = 29.269 * 0.13 / 15.89e-6 = 2.3946e5; Re^(2/3) = 3855.0; Pr^(1/3) = 0.89086
    # Nu = 0.133 * 3855.0 * 0.89086 = 456.76; h = 456.76 * 0.0263 / 0.13 = 92.41 W/m2/K
    h = correlations.h_rotating_shaft_W_m2K(4300.0, 0.13, T_air_K=300.0)
    assert h == pytest.approx(92.41, rel=REL_HAND)


def test_rotating_shaft_floor_is_churchill_chu_at_standstill():
    # d 0.13 m, dT 20 K above air at 290 K: film 300 K (nu 15.89e-6, alpha 22.475e-6, Pr 0.707)
    # Ra = 9.80665 * 20/300 * 0.13^3 / (15.89e-6 * 22.475e-6) = 4.0248e6; Ra^(1/6) = 12.610
    # [1 + (0.559/0.707)^(9/16)]^(8/27) = 1.8762^(0.2963) = 1.2049
    # Nu = (0.60 + 0.387 * 12.610 / 1.2049)^2 = 4.6502^2 = 21.624; h = 21.624 * 0.0263 / 0.13
    h0 = correlations.h_rotating_shaft_W_m2K(0.0, 0.13, T_air_K=290.0, dT_K=20.0)
    assert h0 == pytest.approx(4.3747, rel=REL_HAND)
    assert correlations.h_rotating_shaft_W_m2K(0.0, 0.13, h_floor_W_m2K=8.0) == 8.0
    # forced convection takes over once it exceeds the floor
    assert correlations.h_rotating_shaft_W_m2K(4300.0, 0.13, h_floor_W_m2K=8.0) > 80.0


def test_rotating_shaft_monotonic_in_speed():
    speeds = np.linspace(0, 15000, 61)
    h = [correlations.h_rotating_shaft_W_m2K(n, 0.13) for n in speeds]
    assert np.all(np.diff(h) >= 0) and h[-1] > h[0]


# ----------------------------------------------------------------------------- air gap


def test_taylor_geometry_factor_narrow_gap_limit():
    # e/R -> 0: P -> 0.05766, F_g -> pi^4 / (1697 * 0.05766) = 0.99546
    assert correlations.taylor_geometry_factor(1.0, 1e-7) == pytest.approx(0.99546, rel=REL_HAND)
    assert correlations.taylor_geometry_factor(0.0595, 0.00075) > 1.0


def test_becker_kaye_branches():
    assert correlations.nusselt_becker_kaye(0.0) == 2.0
    assert correlations.nusselt_becker_kaye(1699.0) == 2.0
    # vortex branch: 0.128 * 5000^0.367 = 0.128 * exp(0.367 * 8.51719) = 0.128 * 22.795 = 2.9178
    assert correlations.nusselt_becker_kaye(5000.0) == pytest.approx(2.9178, rel=REL_HAND)
    # turbulent branch: 0.409 * 1e5^0.241 = 0.409 * exp(0.241 * 11.5129) = 0.409 * 16.032 = 6.557
    assert correlations.nusselt_becker_kaye(1e5) == pytest.approx(6.557, rel=REL_HAND)
    # floored at conduction where the published vortex fit dips to 1.96
    assert correlations.nusselt_becker_kaye(1700.0) == 2.0
    with pytest.raises(ValueError, match="1e7"):
        correlations.nusselt_becker_kaye(2e7)


def test_air_gap_standstill_is_conduction_and_hand_value():
    air = correlations.air_properties(323.15)
    assert correlations.h_air_gap_W_m2K(0.0, 0.0595, 0.00075) == pytest.approx(air.k_W_mK / 0.00075,
                                                                          rel=REL_FP)
    # 4300 rpm, r 0.0595, e 0.00075, air 323.15 K: nu = 18.219e-6, k = 0.028013
    # R_m = 0.00075 / ln(0.06025/0.0595) = 0.059876; F_g = 1.01628
    # Ta = 450.29^2 * 0.059876 * 0.00075^3 / 18.219e-6^2 = 15430; Ta_m = 15183
    # Nu = 0.409 * 15183^0.241 = 4.1633; h = 4.1633 * 0.028013 / 0.0015 = 77.75 W/m2/K
    assert correlations.modified_taylor_number(4300.0, 0.0595, 0.00075, air.nu_m2_s) == pytest.approx(
        15183.0, rel=REL_HAND)
    assert correlations.h_air_gap_W_m2K(4300.0, 0.0595, 0.00075) == pytest.approx(77.75, rel=REL_HAND)


def test_air_gap_monotonic_in_speed():
    speeds = np.linspace(0, 20000, 201)
    h = [correlations.h_air_gap_W_m2K(n, 0.0595, 0.00075) for n in speeds]
    assert np.all(np.diff(h) >= 0) and h[-1] > 2 * h[0]


# -------------------------------------------------------------------------- coolant


def test_dittus_boelter_branches():
    assert correlations.nusselt_dittus_boelter(1000.0, 7.0) == 4.36
    assert correlations.nusselt_dittus_boelter(1000.0, 7.0, laminar_Nu=3.66) == 3.66
    # turbulent: 0.023 * 2e4^0.8 * 5^0.4 = 0.023 * 2759.6 * 1.9037 = 120.83
    assert correlations.nusselt_dittus_boelter(2e4, 5.0) == pytest.approx(120.83, rel=REL_HAND)
    # transitional: linear between 4.36 at 2300 and DB(1e4) at 1e4
    lo, hi = 4.36, 0.023 * 1e4**0.8 * 5.0**0.4
    mid = correlations.nusselt_dittus_boelter(6150.0, 5.0)
    assert mid == pytest.approx(0.5 * (lo + hi), rel=REL_FP)
    nu = [correlations.nusselt_dittus_boelter(r, 5.0) for r in np.linspace(0, 3e4, 301)]
    assert np.all(np.diff(nu) >= 0)


def test_coolant_channel_hand_value():
    # 6 l/min = 1e-4 m3/s in 6 x 10 mm: A = 6e-5 m2, D_h = 4 * 60 / 32 mm = 7.5 mm, u = 1.6667 m/s
    Re, Dh, u = correlations.coolant_channel_reynolds(6.0, 0.006, 0.010)
    assert Dh == pytest.approx(0.0075, rel=REL_FP) and u == pytest.approx(1e-4 / 6e-5, rel=REL_FP)
    # water at 20 degC, Table A.6 interpolated 290..295 K at 0.63: mu 1003.8e-6, v_f 1.00163e-3,
    # k 0.60304, Pr 6.9678 -> nu = 1.00544e-6; Re = 1.6667 * 0.0075 / 1.00544e-6 = 12433
    assert Re == pytest.approx(12433.0, rel=REL_HAND)
    # Nu = 0.023 * 12433^0.8 * 6.9678^0.4 = 0.023 * 1886.3 * 2.1739 = 94.31; h = Nu k / D_h
    h = correlations.h_coolant_channel_W_m2K(6.0, 0.006, 0.010)
    assert h == pytest.approx(94.31 * 0.60304 / 0.0075, rel=REL_HAND)
    assert correlations.h_coolant_channel_W_m2K(0.2, 0.006, 0.010) == pytest.approx(4.36 * 0.60304 / 0.0075,
                                                                            rel=REL_HAND)


# ------------------------------------------------------------------------ tabulation


def test_speed_tables_for_specs():
    t = correlations.shaft_film_table(0.13, (0.0, 4300.0, 8000.0))
    assert isinstance(t, SpeedTable)
    assert t(4300.0) == pytest.approx(correlations.h_rotating_shaft_W_m2K(4300.0, 0.13), rel=REL_FP)
    g = correlations.air_gap_film_table(0.0595, 0.00075)
    assert g.speed_rpm == correlations.DEFAULT_SPEEDS_RPM and np.all(np.diff(g.values) >= 0)
    c = correlations.speed_table(lambda n: 2.0 * n, (0.0, 10.0))
    assert c.values == (0.0, 20.0)
    with pytest.raises(ValueError, match="ascending"):
        correlations.speed_table(lambda n: n, (0.0, 10.0, 5.0))
    with pytest.raises(ValueError):
        correlations.speed_table(lambda n: n, (-1.0, 10.0))


def test_a_correlation_film_rises_beyond_12000_rpm():
    """The film tables had ended at 12 000 rpm, so a 24 000 rpm grinder's shaft film stayed
    at its 12 000 rpm value (74 W/m2K where the correlation gives 118). The table now reaches
    the spec reader's speed limit; at 24 000 rpm it is the correlation itself (a table point),
    and below 12 000 rpm nothing moved (the old points are kept)."""
    g = correlations.shaft_film_table(0.05)
    assert g.speed_rpm[-1] == 100000.0 and set(g.speed_rpm) >= {0.0, 4300.0, 12000.0}
    assert g(24000.0) == pytest.approx(correlations.h_rotating_shaft_W_m2K(24000.0, 0.05),
                                       rel=1e-12)
    assert g(24000.0) > 1.4 * g(12000.0)


def test_a_table_beyond_12000_rpm_ends_where_its_correlation_does():
    """A wide air gap leaves Becker and Kaye's range (Taylor number 1e7) at speeds the
    spindle never runs: beyond 12 000 rpm its table ends there and holds its last value, so
    the spec reads as it did (bs25, a user's 2500 rpm boring spindle, had been refused once
    the tables reached 100 000 rpm); up to 12 000 rpm a correlation out of range stays an
    error."""
    from pathlib import Path

    from spindle.spec import AirGapLink
    from spindle.spec_reader import load_spec

    spec = load_spec(Path(__file__).resolve().parent / "data" / "own-specs" / "bs25.toml")
    gap = next(lk for lk in spec.links if isinstance(lk, AirGapLink)).h_W_m2K
    assert correlations.STRICT_TO_RPM < gap.speed_rpm[-1] < 100000.0

    def h(n: float) -> float:  # a correlation whose range ends at 11 000 rpm
        if n > 11000.0:
            raise ValueError("outside the correlation's range")
        return 1.0 + n

    with pytest.raises(ValueError):
        correlations.speed_table(h, (0.0, 10000.0, 12000.0))
    assert correlations.speed_table(h, (0.0, 10000.0, 15000.0)).speed_rpm == (0.0, 10000.0)
