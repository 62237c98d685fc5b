"""Power balance: spindle inputs -> heat-source powers [W] and speed-dependent film coefficients.

The paper's power-balance block (seed paper, section 2.2 and Fig. 5) turns the drive's
measured inputs (electrical power, speed, load torque) and the winding temperature into the
heat that the thermal models need:

* bearing friction heat, Palmgren's friction torque times the angular speed
  (:func:`bearing_friction`);
* motor losses: copper I^2 R(T) (eq. 16-17), iron hysteresis and eddy losses (eq. 18-19),
  bounded by the electrical input minus the mechanical output (eq. 15) (:func:`motor_losses`);
* film coefficients that depend on speed: a rotating shaft in air, the rotor-stator air gap
  and the stator coolant jacket (:func:`h_rotating_shaft_W_m2K`, :func:`h_air_gap_W_m2K`,
  :func:`h_coolant_channel_W_m2K`), and helpers that tabulate them into a
  :class:`~spindle.loads.SpeedTable` for a spec.

SI units throughout (W, K, rad/s, m, N, N m); a speed in rpm appears only as an input named
``*_rpm``; a few catalogue formulas are evaluated in their own units (N mm, mm, mm^2/s), which
the names then say. Every correlation names its source in its docstring; every shipped
parameter set states its source or assumption. docs/power.md is the one-page summary.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from spindle.loads import SpeedTable

#: rpm -> rad/s
from spindle.units import RPM_TO_RAD_S

#: Reference temperature of eq. 17 (20 degC) [K]
T20_K = 293.15
#: Temperature coefficient of copper resistance at 20 degC [1/K] (seed paper eq. 17, ref. [17])
ALPHA_CU_20_1_K = 0.00393
#: Standard gravity [m/s2]
G_M_S2 = 9.80665
#: Speeds at which the film tables are tabulated by default [rpm]
DEFAULT_SPEEDS_RPM: tuple[float, ...] = (0.0, 250.0, 500.0, 1000.0, 1500.0, 2000.0, 3000.0,
                                         4300.0, 6000.0, 8000.0, 10000.0, 12000.0)


# ----------------------------------------------------------------------------- validation

def _finite(name: str, value: float) -> float:
    """``value`` as a float (unit unchanged); ValueError naming ``name`` if not finite."""
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} = {value!r} is not a finite number")
    return v


def _positive(name: str, value: float) -> float:
    """``value`` as a float (unit unchanged); ValueError unless finite and > 0."""
    v = _finite(name, value)
    if v <= 0.0:
        raise ValueError(f"{name} = {v:g} must be > 0")
    return v


def _non_negative(name: str, value: float) -> float:
    """``value`` as a float (unit unchanged); ValueError unless finite and >= 0."""
    v = _finite(name, value)
    if v < 0.0:
        raise ValueError(f"{name} = {v:g} must be >= 0")
    return v


def _share(name: str, value: float) -> float:
    """A fraction [-]; ValueError unless it lies in 0..1."""
    v = _finite(name, value)
    if not 0.0 <= v <= 1.0:
        raise ValueError(f"{name} = {v:g} must lie in 0..1 (a fraction)")
    return v


def omega_rad_s(speed_rpm: float) -> float:
    """Angular speed [rad/s] of a speed ``speed_rpm`` [1/min]; raises ValueError below 0.

    The models here take the magnitude of the speed; a negative value is rejected rather than
    silently mirrored (give the direction, if needed, through the sign of the torque).
    """
    n = _finite("speed_rpm", speed_rpm)
    if n < 0.0:
        raise ValueError(f"speed_rpm = {n:g} is negative; give the speed magnitude |n| [rpm]")
    return n * RPM_TO_RAD_S


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
    T = _finite("T_K", T_K)
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


def walther_viscosity_mm2_s(nu40_mm2_s: float, nu100_mm2_s: float, T_K: float) -> float:
    """Kinematic viscosity [mm2/s] of a mineral or synthetic oil at ``T_K`` [K] from its
    viscosities at 40 and 100 degC [mm2/s]: the Walther equation of ASTM D341,
    log10(log10(nu + 0.7)) = A - B log10(T).

    Use it for the base oil of a grease when the bearing temperature is known (the thermal
    model's output), then pass the result to :func:`bearing_friction` as ``nu_mm2_s``.
    """
    n40 = _positive("nu40_mm2_s", nu40_mm2_s)
    n100 = _positive("nu100_mm2_s", nu100_mm2_s)
    if n100 >= n40:
        raise ValueError(f"nu100_mm2_s = {n100:g} must be below nu40_mm2_s = {n40:g}")
    T = _positive("T_K", T_K)

    def z(nu: float) -> float:
        """Walther's double logarithm of nu [mm2/s]."""
        return math.log10(math.log10(nu + 0.7))

    b = (z(n40) - z(n100)) / (math.log10(373.15) - math.log10(313.15))
    a = z(n40) + b * math.log10(313.15)
    return 10.0 ** (10.0 ** (a - b * math.log10(T))) - 0.7


# -------------------------------------------------------------------------- bearing friction

@dataclass(frozen=True)
class BearingParams:
    """A set of ``count`` identical angular-contact ball bearings for Palmgren's friction model.

    f0 [-]           speed-dependent (viscous) friction factor of ONE bearing
    dm_m [m]         pitch diameter (d + D) / 2
    nu_mm2_s [mm2/s] kinematic viscosity of the lubricant (base oil of a grease) at the
                     operating temperature
    preload_N [N]    axial preload carried by each bearing of the set
    C0_N [N]         basic static load rating of one bearing
    count [-]        bearings in the set (2 for a pair)
    inner_ring_share fraction of the friction heat that goes into the inner ring (rest: outer)
    source           where the values come from
    """

    name: str
    f0: float
    dm_m: float
    nu_mm2_s: float
    preload_N: float
    C0_N: float
    count: int = 2
    inner_ring_share: float = 0.5
    source: str = ""

    def __post_init__(self) -> None:
        """Reject non-physical values (ValueError naming the field)."""
        _positive("f0", self.f0)
        _positive("dm_m", self.dm_m)
        if self.dm_m > 2.0:
            raise ValueError(f"dm_m = {self.dm_m:g} m is not a bearing pitch diameter; give metres")
        _positive("nu_mm2_s", self.nu_mm2_s)
        _non_negative("preload_N", self.preload_N)
        _positive("C0_N", self.C0_N)
        if int(self.count) != self.count or self.count < 1:
            raise ValueError(f"count = {self.count!r} must be a whole number >= 1")
        _share("inner_ring_share", self.inner_ring_share)


@dataclass(frozen=True)
class BearingFriction:
    """Friction of one bearing set at one speed: torque [N m] and heat [W] of the whole set,
    split into the speed term M0 and the load term M1, and into inner and outer ring heat."""

    speed_rpm: float
    M0_Nm: float
    M1_Nm: float
    torque_Nm: float
    heat_W: float
    inner_ring_W: float
    outer_ring_W: float


def palmgren_M0_Nmm(f0: float, nu_mm2_s: float, speed_rpm: float, dm_mm: float) -> float:
    """Speed-dependent (viscous) friction torque of one bearing [N mm], Palmgren (1959), as in
    Harris and Kotzalas, Rolling Bearing Analysis, 5th ed. (2007), and the SKF General
    Catalogue (friction chapter, before 2004)::

        M0 = 1e-7 f0 (nu n)^(2/3) dm^3      for nu n >= 2000
        M0 = 160e-7 f0 dm^3                 for nu n <  2000

    with nu [mm2/s], n [rpm], dm [mm]. The published constant 160 rounds 2000^(2/3) = 158.7,
    so M0 steps down by 0.8 % where nu n crosses 2000.
    """
    f0 = _positive("f0", f0)
    nu = _positive("nu_mm2_s", nu_mm2_s)
    n = _finite("speed_rpm", speed_rpm)
    if n < 0.0:
        raise ValueError(f"speed_rpm = {n:g} is negative; give the speed magnitude |n| [rpm]")
    dm = _positive("dm_mm", dm_mm)
    if nu * n >= 2000.0:
        return 1e-7 * f0 * (nu * n) ** (2.0 / 3.0) * dm**3
    return 160e-7 * f0 * dm**3


def palmgren_f1_angular_contact(P0_N: float, C0_N: float) -> float:
    """Load-dependent friction factor f1 [-] of an angular-contact ball bearing,
    f1 = 0.001 (P0 / C0)^0.33 (Palmgren; Harris and Kotzalas, Rolling Bearing Analysis,
    5th ed., friction chapter), P0 the static equivalent load [N], C0 the static rating [N]."""
    P0 = _non_negative("P0_N", P0_N)
    C0 = _positive("C0_N", C0_N)
    return 0.001 * (P0 / C0) ** 0.33


def palmgren_M1_Nmm(f1: float, P1_N: float, dm_mm: float) -> float:
    """Load-dependent friction torque of one bearing [N mm], M1 = f1 P1 dm (Palmgren; Harris
    and Kotzalas, Rolling Bearing Analysis, 5th ed.), P1 [N], dm [mm]."""
    return _non_negative("f1", f1) * _non_negative("P1_N", P1_N) * _positive("dm_mm", dm_mm)


def bearing_friction(params: BearingParams, speed_rpm: float, *, nu_mm2_s: float | None = None,
                     radial_load_N: float = 0.0) -> BearingFriction:
    """Friction torque [N m] and heat [W] of a bearing set at ``speed_rpm`` (Palmgren).

    Per bearing M = M0 + M1 (:func:`palmgren_M0_Nmm`, :func:`palmgren_M1_Nmm`); the set gives
    ``count`` times that, and heat = M omega [W].

    Equivalent load P1 [N]: for an angular-contact bearing, Harris and Kotzalas (5th ed.)
    give P1 = Fa - 0.1 Fr, and at least Fr. Here Fa is the axial preload of each bearing and Fr
    the (optional) radial load per bearing ``radial_load_N``; with no external load the preload
    dominates and P1 = preload_N. The static equivalent load P0 in f1 is taken equal to P1
    (preload-dominated, no external moment). ``nu_mm2_s`` overrides the parameter set's
    viscosity (for a temperature-dependent one, see :func:`walther_viscosity_mm2_s`).
    """
    w = omega_rad_s(speed_rpm)
    nu = params.nu_mm2_s if nu_mm2_s is None else _positive("nu_mm2_s", nu_mm2_s)
    Fr = _non_negative("radial_load_N", radial_load_N)
    dm_mm = params.dm_m * 1e3
    P1 = max(params.preload_N - 0.1 * Fr, Fr)
    f1 = palmgren_f1_angular_contact(P1, params.C0_N)
    m0 = params.count * palmgren_M0_Nmm(params.f0, nu, speed_rpm, dm_mm) * 1e-3
    m1 = params.count * palmgren_M1_Nmm(f1, P1, dm_mm) * 1e-3
    torque = m0 + m1
    heat = torque * w
    inner = params.inner_ring_share * heat
    return BearingFriction(float(speed_rpm), m0, m1, torque, heat, inner, heat - inner)


# ------------------------------------------------------------------------------ motor losses

@dataclass(frozen=True)
class MotorParams:
    """A permanent-magnet synchronous built-in motor for the loss model of eq. 15-19.

    R20_ohm [ohm]        winding resistance of ONE phase at 20 degC (star equivalent)
    kT_Nm_A [N m/A]      torque constant: torque per rms phase current (id = 0 control)
    pole_pairs [-]       electrical frequency f = n pole_pairs / 60
    k_h_W_HzT2           hysteresis coefficient of the whole core, Q_h = k_h f B^2 (eq. 18)
    k_e_W_Hz2T2          eddy-current coefficient of the whole core, Q_e = k_e f^2 B^2 (eq. 19)
    B_T [T]              peak flux density of the core (the paper's Psi in eq. 18-19)
    phases [-]           number of phases m; copper loss m I^2 R(T) (eq. 16 per phase)
    rotor_loss_share     fraction of the total motor loss that heats the rotor (rest: stator)
    alpha_cu_1_K [1/K]   temperature coefficient of the winding resistance at 20 degC (eq. 17)
    source               where the values come from
    """

    name: str
    R20_ohm: float
    kT_Nm_A: float
    pole_pairs: int
    k_h_W_HzT2: float
    k_e_W_Hz2T2: float
    B_T: float
    phases: int = 3
    rotor_loss_share: float = 0.06
    alpha_cu_1_K: float = ALPHA_CU_20_1_K
    source: str = ""

    def __post_init__(self) -> None:
        """Reject non-physical values (ValueError naming the field)."""
        _positive("R20_ohm", self.R20_ohm)
        _positive("kT_Nm_A", self.kT_Nm_A)
        for name in ("pole_pairs", "phases"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise ValueError(f"{name} = {v!r} must be a whole number >= 1")
        _non_negative("k_h_W_HzT2", self.k_h_W_HzT2)
        _non_negative("k_e_W_Hz2T2", self.k_e_W_Hz2T2)
        _non_negative("B_T", self.B_T)
        _share("rotor_loss_share", self.rotor_loss_share)
        _non_negative("alpha_cu_1_K", self.alpha_cu_1_K)


@dataclass(frozen=True)
class MotorLosses:
    """Motor losses at one operating point [W], and the quantities they come from.

    ``copper_W + iron_hysteresis_W + iron_eddy_W == total_W == stator_W + rotor_W``.
    ``model_total_W`` is the component model's own sum; when the electrical power was given,
    ``total_W = P_el_W - P_mech_W`` and the components are the model's scaled by
    ``scale = total_W / model_total_W`` (1 when P_el_W is None).
    """

    speed_rpm: float
    torque_Nm: float
    current_A: float
    frequency_Hz: float
    R_ohm: float
    copper_W: float
    iron_hysteresis_W: float
    iron_eddy_W: float
    total_W: float
    stator_W: float
    rotor_W: float
    P_mech_W: float
    P_el_W: float
    model_total_W: float
    scale: float

    @property
    def efficiency(self) -> float:
        """P_mech / P_el [-] (motoring); nan when P_el is 0."""
        return self.P_mech_W / self.P_el_W if self.P_el_W != 0 else float("nan")


def winding_resistance_ohm(R20_ohm: float, T_K: float, alpha_1_K: float = ALPHA_CU_20_1_K) -> float:
    """Winding resistance [ohm] at ``T_K`` [K], seed paper eq. 17:
    R(T) = R20 (1 + beta20 (T - 20 degC)), beta20 = 0.00393 1/K for copper (paper ref. [17])."""
    R20 = _positive("R20_ohm", R20_ohm)
    T = _positive("T_K", T_K)
    R = R20 * (1.0 + _non_negative("alpha_1_K", alpha_1_K) * (T - T20_K))
    if R <= 0.0:
        raise ValueError(f"T_K = {T:g} gives a non-positive resistance by eq. 17")
    return R


def copper_loss_W(current_A: float, R_ohm: float, phases: int = 3) -> float:
    """Copper loss [W], seed paper eq. 16 per phase, summed: P_cu = m I^2 R(T), with I the rms
    phase current [A] and R the phase resistance [ohm]."""
    I_ = _finite("current_A", current_A)
    return float(phases) * I_**2 * _positive("R_ohm", R_ohm)


def electrical_frequency_Hz(speed_rpm: float, pole_pairs: int) -> float:
    """Electrical (stator field) frequency [Hz] of a synchronous motor, f = n p / 60."""
    omega_rad_s(speed_rpm)  # validates the speed
    return float(speed_rpm) * pole_pairs / 60.0


def hysteresis_loss_W(k_h_W_HzT2: float, f_Hz: float, B_T: float) -> float:
    """Iron hysteresis loss [W], seed paper eq. 18: Q_h = k_h f B^2 (Steinmetz form with
    exponent 2, as in the paper), k_h for the whole core [W/(Hz T^2)], f [Hz], B [T]."""
    return _non_negative("k_h", k_h_W_HzT2) * _non_negative("f_Hz", f_Hz) * _finite("B_T", B_T) ** 2


def eddy_loss_W(k_e_W_Hz2T2: float, f_Hz: float, B_T: float) -> float:
    """Iron eddy-current loss [W], seed paper eq. 19: Q_e = k_e f^2 B^2, k_e for the whole
    core [W/(Hz^2 T^2)], f [Hz], B [T]."""
    return _non_negative("k_e", k_e_W_Hz2T2) * _non_negative("f_Hz", f_Hz) ** 2 * _finite("B_T", B_T) ** 2


def motor_torque_Nm(load_torque_Nm: float, J_kgm2: float = 0.0, dw_dt_rad_s2: float = 0.0) -> float:
    """Motor (air-gap) torque [N m] from seed paper eq. 15, M - M_L = J dw/dt, i.e.
    M = M_L + J dw/dt; M_L [N m] is everything the motor drives (process torque, bearing
    friction, windage), J [kg m2] the inertia of the rotating assembly, dw/dt [rad/s2]."""
    return (_finite("load_torque_Nm", load_torque_Nm)
            + _non_negative("J_kgm2", J_kgm2) * _finite("dw_dt_rad_s2", dw_dt_rad_s2))


def motor_losses(params: MotorParams, speed_rpm: float, load_torque_Nm: float, T_winding_K: float,
                 *, P_el_W: float | None = None, J_kgm2: float = 0.0,
                 dw_dt_rad_s2: float = 0.0) -> MotorLosses:
    """Losses [W] of the built-in motor at one operating point.

    Torque: M = M_L + J dw/dt (eq. 15); mechanical power P_mech = M omega [W].
    Current: I = |M| / kT [A rms per phase]: the torque-constant route, valid for a PMSM under
    id = 0 control below base speed (field weakening, which adds d-axis current, is not
    modelled). Copper: m I^2 R(T_winding) (eq. 16-17). Iron: k_h f B^2 + k_e f^2 B^2
    (eq. 18-19), f = n p / 60, B constant (magnet excitation).

    Without ``P_el_W`` the total is the component sum. With it, the total IS the electrical
    input minus the mechanical output, total = P_el - P_mech, and the component model only
    distributes it (each component scaled by the same factor; all to copper if the model sum is
    0). So the bound total <= P_el - P_mech holds by construction. P_el < P_mech (an efficiency
    above 1) raises ValueError, as do a negative speed and a non-positive temperature.
    The total is split into rotor (``rotor_loss_share``) and stator heat.
    """
    w = omega_rad_s(speed_rpm)
    T = _positive("T_winding_K", T_winding_K)
    M = motor_torque_Nm(load_torque_Nm, J_kgm2, dw_dt_rad_s2)
    P_mech = M * w
    current = abs(M) / params.kT_Nm_A
    R = winding_resistance_ohm(params.R20_ohm, T, params.alpha_cu_1_K)
    f = electrical_frequency_Hz(speed_rpm, params.pole_pairs)
    cu = copper_loss_W(current, R, params.phases)
    hy = hysteresis_loss_W(params.k_h_W_HzT2, f, params.B_T)
    ed = eddy_loss_W(params.k_e_W_Hz2T2, f, params.B_T)
    model_total = cu + hy + ed
    if P_el_W is None:
        total, scale, P_el = model_total, 1.0, P_mech + model_total
    else:
        P_el = _finite("P_el_W", P_el_W)
        total = P_el - P_mech
        if total < -1e-9 * max(abs(P_el), abs(P_mech), 1.0):
            raise ValueError(
                f"P_el_W = {P_el:.6g} W is below the mechanical power M omega = {P_mech:.6g} W "
                f"(M = {M:.6g} N m at {float(speed_rpm):g} rpm): the efficiency would exceed 1; "
                "check the power reading, the load torque and the speed")
        total = max(total, 0.0)
        if model_total > 0.0:
            scale = total / model_total
            cu, hy, ed = cu * scale, hy * scale, ed * scale
        else:  # standstill without current in the model: the measured loss is resistive
            scale, cu, hy, ed = float("nan"), total, 0.0, 0.0
    rotor = params.rotor_loss_share * total
    return MotorLosses(float(speed_rpm), M, current, f, R, cu, hy, ed, total, total - rotor, rotor,
                       P_mech, P_el, model_total, scale)


# ------------------------------------------------------------------- whole power balance

@dataclass(frozen=True)
class PowerBalance:
    """Heat of every source at one operating point [W], named as the spec's heat sources.

    ``bearings`` maps a heat-source name (e.g. ``front_bearing``) to its friction; the motor's
    stator and rotor heat are ``motor.stator_W`` and ``motor.rotor_W``.
    """

    speed_rpm: float
    process_torque_Nm: float
    motor: MotorLosses
    bearings: Mapping[str, BearingFriction] = field(default_factory=dict)

    @property
    def bearing_heat_W(self) -> float:
        """Friction heat of all bearing sets [W]."""
        return float(sum(b.heat_W for b in self.bearings.values()))

    @property
    def total_heat_W(self) -> float:
        """Motor losses plus bearing friction [W]."""
        return self.motor.total_W + self.bearing_heat_W

    def heat_sources_W(self) -> dict[str, float]:
        """{'stator': W, 'rotor': W, <bearing name>: W, ...}: the heat-source powers of a spec."""
        out = {"stator": self.motor.stator_W, "rotor": self.motor.rotor_W}
        out.update({name: b.heat_W for name, b in self.bearings.items()})
        return out


def power_balance(motor: MotorParams, bearings: Mapping[str, BearingParams], speed_rpm: float,
                  process_torque_Nm: float, T_winding_K: float, *, P_el_W: float | None = None,
                  windage_torque_Nm: float = 0.0, J_kgm2: float = 0.0,
                  dw_dt_rad_s2: float = 0.0) -> PowerBalance:
    """Motor losses and bearing friction at one operating point (paper Fig. 5, power balance).

    The motor's load torque is M_L = process torque + bearing friction torques + windage [N m];
    the motor torque follows from eq. 15 and the losses from :func:`motor_losses` (bounded by
    P_el - P_mech when ``P_el_W`` [W] is given). Bearing friction is part of the mechanical
    output P_mech and appears as bearing heat, never twice.
    """
    fr = {name: bearing_friction(p, speed_rpm) for name, p in bearings.items()}
    # a standing shaft demands no friction torque (Palmgren's M0 is a running torque), so
    # friction adds to the motor's load only while the shaft turns
    friction_Nm = sum(b.torque_Nm for b in fr.values()) if speed_rpm > 0 else 0.0
    M_L = (_finite("process_torque_Nm", process_torque_Nm) + friction_Nm
           + _finite("windage_torque_Nm", windage_torque_Nm))
    ml = motor_losses(motor, speed_rpm, M_L, T_winding_K, P_el_W=P_el_W, J_kgm2=J_kgm2,
                      dw_dt_rad_s2=dw_dt_rad_s2)
    return PowerBalance(float(speed_rpm), float(process_torque_Nm), ml, fr)


# ---------------------------------------------------------------- shipped SPL2782.1 sets

#: SPL2782.1 nominal point (seed paper section 3): 38 kW mechanical at 4300 rpm, 5146 W losses.
SPL2782_NOMINAL_SPEED_RPM = 4300.0
SPL2782_NOMINAL_P_MECH_W = 38_000.0
SPL2782_NOMINAL_LOSSES_W = 5146.0
#: ASSUMED winding temperature at the nominal point [K] (120 degC): the usual rating
#: temperature of water-cooled built-in motors (insulation class F with reserve); the paper
#: gives no winding temperature.
SPL2782_NOMINAL_T_WINDING_K = 393.15

_BEARING_COMMON = (
    "CALIBRATED f0 = 0.30 per bearing (docs/paper.md: fitted with the rotating-surface film "
    "factor to the paper's measured spl-16h peaks T1 = 32.4 degC and P1 = 6.5 um, FEM level 1). "
    "Harris's catalogue value for grease-lubricated single angular-contact bearings (f0 = 2) "
    "gives, with this viscosity, about 7 times the front-pair heat of 0.30; run-in grease of "
    "super-precision pairs is known to sit well below the catalogue value. "
    "nu = 12 mm2/s: base oil of a spindle grease (ISO VG 22 class, assumed nu40 = 23, "
    "nu100 = 4.7 mm2/s) at ~60 degC (paper: housing 46 K above ambient at the nominal point), "
    "ASTM D341; light preload of a few hundred N per bearing and C0 of the order of the "
    "catalogue ratings of 25 deg super-precision bearings of this size (M1 is ~8 % of M)."
)

#: Front (fixed) pair of the SPL2782.1: 2 x 7018 (90 x 140 x 24 mm), dm = 115 mm, grease.
SPL2782_FRONT_BEARINGS = BearingParams(
    name="SPL2782.1 front pair 2 x 7018", f0=0.30, dm_m=0.115, nu_mm2_s=12.0, preload_N=400.0,
    C0_N=52_000.0, count=2, inner_ring_share=0.5,
    source="Seed paper (grease-lubricated pairs); 7018 dimensions ISO 15; " + _BEARING_COMMON)

#: Rear (floating) pair of the SPL2782.1: 2 x 7016 (80 x 125 x 22 mm), dm = 102.5 mm, grease.
SPL2782_REAR_BEARINGS = BearingParams(
    name="SPL2782.1 rear pair 2 x 7016", f0=0.30, dm_m=0.1025, nu_mm2_s=12.0, preload_N=300.0,
    C0_N=40_000.0, count=2, inner_ring_share=0.5,
    source="Seed paper (grease-lubricated pairs); 7016 dimensions ISO 15; " + _BEARING_COMMON)

#: Siemens 1FE1084-4WN31 built-in PMSM of the SPL2782.1. All values ASSUMED (no data sheet at
#: hand), chosen so that at the nominal point (38 kW, 4300 rpm, 120 degC winding) motor plus
#: bearing losses come to the paper's 5146 W; reasons in ``source`` and docs/power.md.
SPL2782_MOTOR = MotorParams(
    name="Siemens 1FE1084-4WN31 (SPL2782.1)", R20_ohm=0.195, kT_Nm_A=1.2, pole_pairs=4,
    k_h_W_HzT2=0.6, k_e_W_Hz2T2=3.0e-3, B_T=1.5, phases=3, rotor_loss_share=0.06,
    source=(
        "ASSUMED: pole_pairs 4 (1FE1 PMSM, 8 poles typical); kT 1.2 N m/A puts the nominal "
        "84.4 N m at 70 A rms, a 400 V-class converter's current for 38 kW; B 1.5 T peak core "
        "induction of electrical steel; k_h 0.6 W/(Hz T2) and k_e 3.0e-3 W/(Hz2 T2) give 940 W "
        "iron loss at 287 Hz, a build factor ~2 over 0.35 mm sheet data for a ~15 kg core; "
        "R20 0.195 ohm per phase makes copper (4030 W at 120 degC) close the paper's 5146 W "
        "with the bearings; rotor_loss_share 0.06 as the spl2782 spec (magnet and sleeve eddy "
        "losses of a PMSM rotor)"))

#: The SPL2782.1 bearing sets by heat-source name of the spl2782 spec.
SPL2782_BEARINGS: dict[str, BearingParams] = {"front_bearing": SPL2782_FRONT_BEARINGS,
                                              "rear_bearing": SPL2782_REAR_BEARINGS}


def spl2782_nominal_point(T_winding_K: float = SPL2782_NOMINAL_T_WINDING_K) -> PowerBalance:
    """The SPL2782.1 at its nominal point (seed paper section 3): the motor delivers 38 kW at
    4300 rpm; the process torque is what remains after the bearing friction torque."""
    w = omega_rad_s(SPL2782_NOMINAL_SPEED_RPM)
    friction = sum(bearing_friction(p, SPL2782_NOMINAL_SPEED_RPM).torque_Nm
                   for p in SPL2782_BEARINGS.values())
    return power_balance(SPL2782_MOTOR, SPL2782_BEARINGS, SPL2782_NOMINAL_SPEED_RPM,
                         SPL2782_NOMINAL_P_MECH_W / w - friction, T_winding_K)


# ------------------------------------------------------------ convection: rotating shaft

def nusselt_rotating_cylinder(Re: float, Pr: float) -> float:
    """Nusselt number of a cylinder rotating in still fluid, Nu = 0.133 Re^(2/3) Pr^(1/3)
    (Becker, Int. J. Heat Mass Transfer 6 (1963) 1053-1062; used for spindle shafts by
    Bossmanns and Tu, Int. J. Mach. Tools Manuf. 39 (1999) 1345-1366). Re = u d / nu with u
    the surface speed; quoted for Re up to ~4.3e5, 0.7 < Pr < 670."""
    return 0.133 * _non_negative("Re", Re) ** (2.0 / 3.0) * _positive("Pr", Pr) ** (1.0 / 3.0)


def nusselt_churchill_chu(Ra: float, Pr: float) -> float:
    """Natural convection from a horizontal cylinder, all Ra <= 1e12 (Churchill and Chu, Int. J.
    Heat Mass Transfer 18 (1975) 1049-1053):
    Nu = {0.60 + 0.387 Ra^(1/6) / [1 + (0.559/Pr)^(9/16)]^(8/27)}^2."""
    Ra = _non_negative("Ra", Ra)
    Pr = _positive("Pr", Pr)
    return (0.60 + 0.387 * Ra ** (1.0 / 6.0) / (1.0 + (0.559 / Pr) ** (9.0 / 16.0)) ** (8.0 / 27.0)) ** 2


def h_natural_cylinder_W_m2K(d_m: float, dT_K: float = 20.0, T_air_K: float = T20_K) -> float:
    """Natural-convection film coefficient [W/m2/K] of a horizontal cylinder of diameter d [m],
    surface dT [K] above still air at T_air [K]: Churchill-Chu (:func:`nusselt_churchill_chu`),
    properties at the film temperature T_air + dT/2, beta = 1/T_film (ideal gas),
    Ra = g beta dT d^3 / (nu alpha), h = Nu k / d. Radiation is not included."""
    d = _positive("d_m", d_m)
    dT = _non_negative("dT_K", dT_K)
    air = air_properties(_positive("T_air_K", T_air_K) + 0.5 * dT)
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
    surface ``dT_K`` [K] above the air (:func:`h_natural_cylinder_W_m2K`, 4.4 W/m2/K for
    d = 0.13 m, dT = 20 K). Non-decreasing in speed.
    """
    w = omega_rad_s(speed_rpm)
    d = _positive("d_m", d_m)
    air = air_properties(T_air_K)
    Re = w * d / 2.0 * d / air.nu_m2_s
    forced = nusselt_rotating_cylinder(Re, air.Pr) * air.k_W_mK / d
    floor = (h_natural_cylinder_W_m2K(d, dT_K, T_air_K) if h_floor_W_m2K is None
             else _non_negative("h_floor_W_m2K", h_floor_W_m2K))
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
    r1 = _positive("r_rotor_m", r_rotor_m)
    e = _positive("gap_m", gap_m)
    Rm = e / math.log((r1 + e) / r1)
    x = 0.652 * (e / Rm) / (1.0 - e / (2.0 * Rm))
    P = 0.0571 * (1.0 - x) + 0.00056 / (1.0 - x)
    return math.pi**4 / (1697.0 * P) / (1.0 - e / (2.0 * Rm)) ** 2


def modified_taylor_number(speed_rpm: float, r_rotor_m: float, gap_m: float, nu_m2_s: float) -> float:
    """Modified Taylor number [-] of the rotor-stator gap (inner cylinder rotating, outer at
    rest): Ta_m = omega^2 R_m e^3 / (nu^2 F_g), R_m = e / ln(R2/R1), F_g of
    :func:`taylor_geometry_factor` (Becker and Kaye 1962; Fenot et al. 2011)."""
    w = omega_rad_s(speed_rpm)
    r1 = _positive("r_rotor_m", r_rotor_m)
    e = _positive("gap_m", gap_m)
    nu = _positive("nu_m2_s", nu_m2_s)
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
    Ta = _non_negative("Ta_m", Ta_m)
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
    Re = _non_negative("Re", Re)
    Pr = _positive("Pr", Pr)
    lam = _positive("laminar_Nu", laminar_Nu)
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
    Q = _non_negative("flow_l_min", flow_l_min) / 60_000.0
    w = _positive("width_m", width_m)
    h = _positive("height_m", height_m)
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
    speeds = tuple(_non_negative("speeds_rpm", s) for s in speeds_rpm)
    if not speeds:
        raise ValueError("speeds_rpm is empty; give at least one speed")
    if any(b <= a for a, b in zip(speeds, speeds[1:], strict=False)):
        raise ValueError(f"speeds_rpm {speeds} must be strictly ascending")
    return SpeedTable(speeds, tuple(float(h_of_rpm(s)) for s in speeds))


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
