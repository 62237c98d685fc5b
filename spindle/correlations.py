"""Film correlations: speed-dependent heat-transfer coefficients [W/m2/K] and the fluid
properties they read.

The thermal models need the film coefficient of every convective surface as a function of
the spindle speed (the paper, Fig. 5, the power-balance block's second output):

* a shaft rotating in air, Becker (1963) with a Churchill-Chu natural-convection floor
  (:func:`h_rotating_shaft_W_m2K`);
* the rotor-stator air gap, Taylor-Couette flow after Becker and Kaye (1962)
  (:func:`h_air_gap_W_m2K`);
* the stator coolant channel, Dittus-Boelter with the laminar and transitional ranges
  (:func:`h_coolant_channel_W_m2K`);

and helpers that tabulate them into a :class:`~spindle.loads.SpeedTable` for a spec. Air and
water properties interpolate Incropera et al.'s tables. SI units throughout; a speed in rpm
appears only as an input named ``*_rpm``. Every correlation names its source in its
docstring; docs/power.md is the one-page summary.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from spindle.checks import finite, non_negative, omega_rad_s, positive
from spindle.loads import SpeedTable
from spindle.units import ZERO_C_K

#: Default air and coolant temperature, 20 degC [K]
T20_K = ZERO_C_K + 20.0
#: Standard gravity [m/s2]
G_M_S2 = 9.80665
#: Speeds at which the film tables are tabulated by default [rpm], up to the spec reader's
#: limit (spindle.units.SPEED_MAX_RPM): a table held its last value beyond its last point,
#: so a high-speed spindle's films would stop rising with speed
DEFAULT_SPEEDS_RPM: tuple[float, ...] = (0.0, 250.0, 500.0, 1000.0, 1500.0, 2000.0, 3000.0,
                                         4300.0, 6000.0, 8000.0, 10000.0, 12000.0, 15000.0,
                                         18000.0, 24000.0, 30000.0, 40000.0, 50000.0,
                                         60000.0, 80000.0, 100000.0)
#: up to this speed [rpm] a film table is the correlation's within its range, or an error;
#: beyond it the table ends where the correlation leaves its range (an air gap's Taylor
#: number above Becker and Kaye's 1e7) and holds its last value
STRICT_TO_RPM = 12000.0


# ------------------------------------------------------------------------ fluid properties

@dataclass(frozen=True)
class FluidProperties:
    """Properties of a fluid at ``T_K`` [K]: density [kg/m3], kinematic viscosity [m2/s],
    conductivity [W/m/K], Prandtl number [-], specific heat [J/kg/K]."""

    T_K: float
    rho_kg_m3: float
    nu_m2_s: float
    k_W_mK: float
    Pr: float
    cp_J_kgK: float
    source: str


# Incropera, DeWitt, Bergman, Lavine: Fundamentals of Heat and Mass Transfer, 6th ed. (2007),
# Table A.4, air at 1 atm. Columns: T [K], rho [kg/m3], cp [J/kg/K], nu [m2/s], k [W/m/K], Pr.
_AIR_TABLE = np.array([
    [250.0, 1.3947, 1006.0, 11.44e-6, 22.3e-3, 0.720],
    [300.0, 1.1614, 1007.0, 15.89e-6, 26.3e-3, 0.707],
    [350.0, 0.9950, 1009.0, 20.92e-6, 30.0e-3, 0.700],
    [400.0, 0.8711, 1014.0, 26.41e-6, 33.8e-3, 0.690],
])
_AIR_SOURCE = "Incropera et al., Fundamentals of Heat and Mass Transfer, 6th ed., Table A.4 (1 atm)"

# Incropera et al. (as above), Table A.6, saturated liquid water. Columns: T [K],
# specific volume v_f [m3/kg], cp [J/kg/K], dynamic viscosity mu [Pa s], k [W/m/K], Pr.
_WATER_TABLE = np.array([
    [275.0, 1.000e-3, 4211.0, 1652e-6, 0.569, 12.22],
    [280.0, 1.000e-3, 4198.0, 1422e-6, 0.582, 10.26],
    [285.0, 1.000e-3, 4189.0, 1225e-6, 0.590, 8.81],
    [290.0, 1.001e-3, 4184.0, 1080e-6, 0.598, 7.56],
    [295.0, 1.002e-3, 4181.0, 959e-6, 0.606, 6.62],
    [300.0, 1.003e-3, 4179.0, 855e-6, 0.613, 5.83],
    [305.0, 1.005e-3, 4178.0, 769e-6, 0.620, 5.20],
    [310.0, 1.007e-3, 4178.0, 695e-6, 0.628, 4.62],
    [315.0, 1.009e-3, 4179.0, 631e-6, 0.634, 4.16],
    [320.0, 1.011e-3, 4180.0, 577e-6, 0.640, 3.77],
    [325.0, 1.013e-3, 4182.0, 528e-6, 0.645, 3.42],
    [330.0, 1.016e-3, 4184.0, 489e-6, 0.650, 3.15],
])
_WATER_SOURCE = "Incropera et al., Fundamentals of Heat and Mass Transfer, 6th ed., Table A.6 (saturated)"


def _interp_row(table: np.ndarray, T_K: float, what: str) -> np.ndarray:
    """Row of a property ``table`` (first column T [K]) linear in T at ``T_K`` [K];
    ValueError outside the table."""
    T = finite("T_K", T_K)
    lo, hi = table[0, 0], table[-1, 0]
    if not lo <= T <= hi:
        raise ValueError(f"T_K = {T:g} is outside the {what} property table ({lo:g}..{hi:g} K)")
    return np.array([np.interp(T, table[:, 0], table[:, j]) for j in range(table.shape[1])])


def air_properties(T_K: float = 300.0) -> FluidProperties:
    """Dry air at 1 atm and ``T_K`` [K] (250..400 K), linear between the rows of
    Incropera et al., Fundamentals of Heat and Mass Transfer, 6th ed., Table A.4.

    Linear interpolation over the 50 K rows adds about 0.6 % to nu at the mid-points (nu is
    slightly convex in T; checked against Sutherland's law), far below the correlations' scatter.
    """
    T, rho, cp, nu, k, pr = _interp_row(_AIR_TABLE, T_K, "air")
    return FluidProperties(float(T), float(rho), float(nu), float(k), float(pr), float(cp),
                           _AIR_SOURCE)


def water_properties(T_K: float = T20_K) -> FluidProperties:
    """Liquid water at ``T_K`` [K] (275..330 K), linear between the 5 K rows of
    Incropera et al., Fundamentals of Heat and Mass Transfer, 6th ed., Table A.6.

    The kinematic viscosity is mu / rho of the interpolated row.
    """
    T, v_f, cp, mu, k, pr = _interp_row(_WATER_TABLE, T_K, "water")
    rho = 1.0 / v_f
    return FluidProperties(float(T), float(rho), float(mu / rho), float(k), float(pr),
                           float(cp), _WATER_SOURCE)


# ------------------------------------------------------------ convection: rotating shaft

def nusselt_rotating_cylinder(Re: float, Pr: float) -> float:
    """Nusselt number of a cylinder rotating in still fluid, Nu = 0.133 Re^(2/3) Pr^(1/3)
    (Becker, Int. J. Heat Mass Transfer 6 (1963) 1053-1062; used for spindle shafts by
    Bossmanns and Tu, Int. J. Mach. Tools Manuf. 39 (1999) 1345-1366). Re = u d / nu with u
    the surface speed; quoted for Re up to ~4.3e5, 0.7 < Pr < 670."""
    return 0.133 * non_negative("Re", Re) ** (2.0 / 3.0) * positive("Pr", Pr) ** (1.0 / 3.0)


def nusselt_churchill_chu(Ra: float, Pr: float) -> float:
    """Natural convection from a horizontal cylinder, all Ra <= 1e12 (Churchill and Chu, Int. J.
    Heat Mass Transfer 18 (1975) 1049-1053):
    Nu = {0.60 + 0.387 Ra^(1/6) / [1 + (0.559/Pr)^(9/16)]^(8/27)}^2."""
    Ra = non_negative("Ra", Ra)
    Pr = positive("Pr", Pr)
    return (0.60 + 0.387 * Ra ** (1.0 / 6.0) / (1.0 + (0.559 / Pr) ** (9.0 / 16.0)) ** (8.0 / 27.0)) ** 2


def h_natural_cylinder_W_m2K(d_m: float, dT_K: float = 20.0, T_air_K: float = T20_K) -> float:
    """Natural-convection film coefficient [W/m2/K] of a horizontal cylinder of diameter d [m],
    surface dT [K] above still air at T_air [K]: Churchill-Chu (:func:`nusselt_churchill_chu`),
    properties at the film temperature T_air + dT/2, beta = 1/T_film (ideal gas),
    Ra = g beta dT d^3 / (nu alpha), h = Nu k / d. Radiation is not included."""
    d = positive("d_m", d_m)
    dT = non_negative("dT_K", dT_K)
    air = air_properties(positive("T_air_K", T_air_K) + 0.5 * dT)
    alpha = air.nu_m2_s / air.Pr
    Ra = G_M_S2 * dT / air.T_K * d**3 / (air.nu_m2_s * alpha)
    return nusselt_churchill_chu(Ra, air.Pr) * air.k_W_mK / d


def h_rotating_shaft_W_m2K(speed_rpm: float, d_m: float, *, T_air_K: float = T20_K,
                           dT_K: float = 20.0, h_floor_W_m2K: float | None = None) -> float:
    """Film coefficient [W/m2/K] of a shaft of diameter d [m] rotating at ``speed_rpm`` in air
    at T_air [K]: h = Nu k / d with Nu of Becker (1963) (:func:`nusselt_rotating_cylinder`),
    Re = u d / nu, u = omega d / 2 [m/s].

    Floor: at low speed the forced value falls below natural convection; the result is
    max(forced, floor), the floor being ``h_floor_W_m2K`` if given, else Churchill-Chu for a
    surface ``dT_K`` [K] above the air (:func:`h_natural_cylinder_W_m2K`, a few W/m2/K for
    d = 0.13 m, dT = 20 K). Non-decreasing in speed.
    """
    w = omega_rad_s(speed_rpm)
    d = positive("d_m", d_m)
    air = air_properties(T_air_K)
    Re = w * d / 2.0 * d / air.nu_m2_s
    forced = nusselt_rotating_cylinder(Re, air.Pr) * air.k_W_mK / d
    floor = (h_natural_cylinder_W_m2K(d, dT_K, T_air_K) if h_floor_W_m2K is None
             else non_negative("h_floor_W_m2K", h_floor_W_m2K))
    return max(forced, floor)


# ------------------------------------------------------ convection: rotor-stator air gap

def taylor_geometry_factor(r_rotor_m: float, gap_m: float) -> float:
    """Geometric factor F_g [-] of the modified Taylor number for a gap ``gap_m`` [m] around a
    rotor of radius r [m] (Becker and Kaye, J. Heat Transfer 84 (1962) 97-104, after Taylor;
    as written in Fenot et al., Int. J. Thermal Sci. 50 (2011) 1138-1155)::

        F_g = pi^4 / (1697 P) (1 - e/(2 R_m))^-2,   R_m = e / ln(R2/R1),  x = 0.652 (e/R_m)/(1 - e/(2 R_m))
        P   = 0.0571 (1 - x) + 0.00056 / (1 - x)

    F_g -> 0.996 for a narrow gap, so instability sets in at Ta_m ~ 1700.
    """
    r1 = positive("r_rotor_m", r_rotor_m)
    e = positive("gap_m", gap_m)
    Rm = e / math.log((r1 + e) / r1)
    x = 0.652 * (e / Rm) / (1.0 - e / (2.0 * Rm))
    P = 0.0571 * (1.0 - x) + 0.00056 / (1.0 - x)
    return math.pi**4 / (1697.0 * P) / (1.0 - e / (2.0 * Rm)) ** 2


def modified_taylor_number(speed_rpm: float, r_rotor_m: float, gap_m: float, nu_m2_s: float) -> float:
    """Modified Taylor number [-] of the rotor-stator gap (inner cylinder rotating, outer at
    rest): Ta_m = omega^2 R_m e^3 / (nu^2 F_g), R_m = e / ln(R2/R1), F_g of
    :func:`taylor_geometry_factor` (Becker and Kaye 1962; Fenot et al. 2011)."""
    w = omega_rad_s(speed_rpm)
    r1 = positive("r_rotor_m", r_rotor_m)
    e = positive("gap_m", gap_m)
    nu = positive("nu_m2_s", nu_m2_s)
    Rm = e / math.log((r1 + e) / r1)
    return w**2 * Rm * e**3 / nu**2 / taylor_geometry_factor(r1, e)


def nusselt_becker_kaye(Ta_m: float) -> float:
    """Nusselt number of the annular gap (hydraulic diameter 2 e) versus the modified Taylor
    number, Becker and Kaye, J. Heat Transfer 84 (1962) 97-104::

        Nu = 2                    Ta_m < 1700        (laminar Couette flow: conduction, h = k/e)
        Nu = 0.128 Ta_m^0.367     1700 <= Ta_m < 1e4 (Taylor vortices)
        Nu = 0.409 Ta_m^0.241     1e4 <= Ta_m <= 1e7 (turbulent)

    The vortex branch gives 1.96 at Ta_m = 1700, 2 % below conduction; Nu is floored at 2 so
    that it never falls below conduction. Above 1e7 (outside the data) ValueError.
    """
    Ta = non_negative("Ta_m", Ta_m)
    if Ta > 1e7:
        raise ValueError(f"Ta_m = {Ta:.4g} is above 1e7, outside the Becker-Kaye correlation")
    if Ta < 1700.0:
        return 2.0
    if Ta < 1e4:
        return max(2.0, 0.128 * Ta**0.367)
    return 0.409 * Ta**0.241


def h_air_gap_W_m2K(speed_rpm: float, r_rotor_m: float, gap_m: float, *,
                    T_air_K: float = 323.15) -> float:
    """Rotor-stator air-gap film coefficient [W/m2/K] (Taylor-Couette flow):
    h = Nu k / (2 e) with Nu of Becker and Kaye (1962) (:func:`nusselt_becker_kaye`) at the
    modified Taylor number (:func:`modified_taylor_number`); air at ``T_air_K`` [K], by default
    323.15 K (50 degC, ASSUMED mean gap air temperature under load). At standstill
    h = k / e (conduction across the gap)."""
    air = air_properties(T_air_K)
    Ta = modified_taylor_number(speed_rpm, r_rotor_m, gap_m, air.nu_m2_s)
    return nusselt_becker_kaye(Ta) * air.k_W_mK / (2.0 * gap_m)


# ------------------------------------------------------------- convection: coolant jacket

#: Reynolds numbers bounding the transitional range [-]: laminar below, Dittus-Boelter above.
RE_LAMINAR = 2300.0
RE_TURBULENT = 1e4


def nusselt_dittus_boelter(Re: float, Pr: float, laminar_Nu: float = 4.36) -> float:
    """Nusselt number of fully developed duct flow, heated fluid:

    Re >= 1e4          Nu = 0.023 Re^0.8 Pr^0.4  (Dittus and Boelter 1930, as given in
                       Incropera et al., Fundamentals of Heat and Mass Transfer, 6th ed., ch. 8;
                       0.6 <= Pr <= 160)
    Re <  2300         Nu = ``laminar_Nu``: 4.36 fully developed, uniform heat flux (default; a
                       jacket heated by the stator), 3.66 uniform wall temperature (same chapter)
    2300 <= Re < 1e4   linear in Re between the two (Gnielinski's interpolation for the
                       transition region, VDI Heat Atlas, 2nd ed. (2010), chapter G1):
                       Dittus-Boelter is not valid there; this keeps Nu continuous and monotonic.
    """
    Re = non_negative("Re", Re)
    Pr = positive("Pr", Pr)
    lam = positive("laminar_Nu", laminar_Nu)
    if Re < RE_LAMINAR:
        return lam
    turb = 0.023 * max(Re, RE_TURBULENT) ** 0.8 * Pr**0.4
    if Re >= RE_TURBULENT:
        return turb
    g = (Re - RE_LAMINAR) / (RE_TURBULENT - RE_LAMINAR)
    return (1.0 - g) * lam + g * turb


def coolant_channel_reynolds(flow_l_min: float, width_m: float, height_m: float,
                             T_water_K: float = T20_K) -> tuple[float, float, float]:
    """(Re [-], hydraulic diameter D_h [m], mean velocity u [m/s]) of water flowing at
    ``flow_l_min`` [l/min] through a rectangular channel width x height [m]:
    A = w h, D_h = 4 A / (2 (w + h)), u = Q / A, Re = u D_h / nu."""
    Q = non_negative("flow_l_min", flow_l_min) / 60_000.0
    w = positive("width_m", width_m)
    h = positive("height_m", height_m)
    A = w * h
    Dh = 4.0 * A / (2.0 * (w + h))
    u = Q / A
    return u * Dh / water_properties(T_water_K).nu_m2_s, Dh, u


def h_coolant_channel_W_m2K(flow_l_min: float, width_m: float, height_m: float, *,
                            T_water_K: float = T20_K, laminar_Nu: float = 4.36) -> float:
    """Film coefficient [W/m2/K] on the wetted wall of a water-cooling channel:
    h = Nu k / D_h with Nu of :func:`nusselt_dittus_boelter` (Dittus-Boelter, heated fluid;
    laminar ``laminar_Nu`` below Re 2300) and Re of :func:`coolant_channel_reynolds`; water at
    ``T_water_K`` [K] (default 20 degC, the spl2782 coolant supply). It does not depend on
    the spindle speed; use ``SpeedTable.constant`` for a spec."""
    Re, Dh, _ = coolant_channel_reynolds(flow_l_min, width_m, height_m, T_water_K)
    water = water_properties(T_water_K)
    return nusselt_dittus_boelter(Re, water.Pr, laminar_Nu) * water.k_W_mK / Dh


# ----------------------------------------------------------------------- tabulation helpers

def speed_table(h_of_rpm: Callable[[float], float],
                speeds_rpm: Sequence[float] = DEFAULT_SPEEDS_RPM) -> SpeedTable:
    """Tabulate a speed-dependent coefficient ``h_of_rpm(speed_rpm)`` (any unit) at
    ``speeds_rpm`` (ascending, >= 0) into a :class:`~spindle.loads.SpeedTable` for a spec.

    The SpeedTable is linear between the points, so tabulate densely where the coefficient
    curves (near standstill for Re^(2/3) laws)."""
    speeds = tuple(non_negative("speeds_rpm", s) for s in speeds_rpm)
    if not speeds:
        raise ValueError("speeds_rpm is empty; give at least one speed")
    if any(b <= a for a, b in zip(speeds, speeds[1:], strict=False)):
        raise ValueError(f"speeds_rpm {speeds} must be strictly ascending")
    values = []
    for s in speeds:
        try:
            values.append(float(h_of_rpm(s)))
        except ValueError:
            if s <= STRICT_TO_RPM:
                raise
            break  # the correlation's range ends here: the table holds its last value
    return SpeedTable(speeds[:len(values)], tuple(values))


def shaft_film_table(d_m: float, speeds_rpm: Sequence[float] = DEFAULT_SPEEDS_RPM, *,
                     T_air_K: float = T20_K, dT_K: float = 20.0,
                     h_floor_W_m2K: float | None = None) -> SpeedTable:
    """SpeedTable [W/m2/K] of :func:`h_rotating_shaft_W_m2K` for a shaft of diameter d [m]."""
    return speed_table(lambda n: h_rotating_shaft_W_m2K(n, d_m, T_air_K=T_air_K, dT_K=dT_K,
                                                        h_floor_W_m2K=h_floor_W_m2K), speeds_rpm)


def air_gap_film_table(r_rotor_m: float, gap_m: float,
                       speeds_rpm: Sequence[float] = DEFAULT_SPEEDS_RPM, *,
                       T_air_K: float = 323.15) -> SpeedTable:
    """SpeedTable [W/m2/K] of :func:`h_air_gap_W_m2K` for a rotor of radius r [m] and gap e [m]."""
    return speed_table(lambda n: h_air_gap_W_m2K(n, r_rotor_m, gap_m, T_air_K=T_air_K), speeds_rpm)
