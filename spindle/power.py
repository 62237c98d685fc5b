"""Power balance: spindle inputs -> heat-source powers [W].

The paper's power-balance block (the paper, section 2.2 and Fig. 5) turns the drive's
measured inputs (electrical power, speed, load torque) and the winding temperature into the
heat that the thermal models need:

* bearing friction heat, Palmgren's friction torque times the angular speed
  (:func:`bearing_friction`);
* motor losses: copper I^2 R(T) (eq. 16-17), iron hysteresis and eddy losses (eq. 18-19),
  bounded by the electrical input minus the mechanical output (eq. 15) (:func:`motor_losses`);
* both together at one operating point (:func:`power_balance`).

The block's other output, the speed-dependent film coefficients, is in spindle.correlations;
a spindle's motor and bearing parameter set is a drive file (spindle/data/drives/*.toml, read
by spindle.drive_file). SI units throughout (W, K, rad/s, m, N, N m); a speed in rpm appears
only as an input named ``*_rpm``; a few catalogue formulas are evaluated in their own units
(N mm, mm, mm^2/s), which the names then say. Every formula names its source in its
docstring. docs/power.md is the one-page summary.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

from spindle.checks import finite, non_negative, omega_rad_s, positive, share

# spindle.spec and tests/test_spec_validation.py read these film correlations through their
# old home here; they live in spindle.correlations.
from spindle.correlations import (  # noqa: F401
    air_gap_film_table,
    h_coolant_channel_W_m2K,
    h_rotating_shaft_W_m2K,
    shaft_film_table,
)
from spindle.units import ZERO_C_K

#: Reference temperature of eq. 17 (20 degC) [K]
T20_K = ZERO_C_K + 20.0
#: Temperature coefficient of copper resistance at 20 degC [1/K] (the paper's eq. 17, ref. [17])
ALPHA_CU_20_1_K = 0.00393


# -------------------------------------------------------------------------- bearing friction

def walther_viscosity_mm2_s(nu40_mm2_s: float, nu100_mm2_s: float, T_K: float) -> float:
    """Kinematic viscosity [mm2/s] of a mineral or synthetic oil at ``T_K`` [K] from its
    viscosities at 40 and 100 degC [mm2/s]: the Walther equation of ASTM D341,
    log10(log10(nu + 0.7)) = A - B log10(T).

    Use it for the base oil of a grease when the bearing temperature is known (the thermal
    model's output), then pass the result to :func:`bearing_friction` as ``nu_mm2_s``.
    """
    n40 = positive("nu40_mm2_s", nu40_mm2_s)
    n100 = positive("nu100_mm2_s", nu100_mm2_s)
    if n100 >= n40:
        raise ValueError(f"nu100_mm2_s = {n100:g} must be below nu40_mm2_s = {n40:g}")
    T = positive("T_K", T_K)

    def z(nu: float) -> float:
        """Walther's double logarithm of nu [mm2/s]."""
        return math.log10(math.log10(nu + 0.7))

    b = (z(n40) - z(n100)) / (math.log10(373.15) - math.log10(313.15))
    a = z(n40) + b * math.log10(313.15)
    return 10.0 ** (10.0 ** (a - b * math.log10(T))) - 0.7


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
        positive("f0", self.f0)
        positive("dm_m", self.dm_m)
        if self.dm_m > 2.0:
            raise ValueError(f"dm_m = {self.dm_m:g} m is not a bearing pitch diameter; give metres")
        positive("nu_mm2_s", self.nu_mm2_s)
        non_negative("preload_N", self.preload_N)
        positive("C0_N", self.C0_N)
        if int(self.count) != self.count or self.count < 1:
            raise ValueError(f"count = {self.count!r} must be a whole number >= 1")
        share("inner_ring_share", self.inner_ring_share)


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
    f0 = positive("f0", f0)
    nu = positive("nu_mm2_s", nu_mm2_s)
    n = finite("speed_rpm", speed_rpm)
    if n < 0.0:
        raise ValueError(f"speed_rpm = {n:g} is negative; give the speed magnitude |n| [rpm]")
    dm = positive("dm_mm", dm_mm)
    if nu * n >= 2000.0:
        return 1e-7 * f0 * (nu * n) ** (2.0 / 3.0) * dm**3
    return 160e-7 * f0 * dm**3


def palmgren_f1_angular_contact(P0_N: float, C0_N: float) -> float:
    """Load-dependent friction factor f1 [-] of an angular-contact ball bearing,
    f1 = 0.001 (P0 / C0)^0.33 (Palmgren; Harris and Kotzalas, Rolling Bearing Analysis,
    5th ed., friction chapter), P0 the static equivalent load [N], C0 the static rating [N]."""
    P0 = non_negative("P0_N", P0_N)
    C0 = positive("C0_N", C0_N)
    return 0.001 * (P0 / C0) ** 0.33


def palmgren_M1_Nmm(f1: float, P1_N: float, dm_mm: float) -> float:
    """Load-dependent friction torque of one bearing [N mm], M1 = f1 P1 dm (Palmgren; Harris
    and Kotzalas, Rolling Bearing Analysis, 5th ed.), P1 [N], dm [mm]."""
    return non_negative("f1", f1) * non_negative("P1_N", P1_N) * positive("dm_mm", dm_mm)


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
    nu = params.nu_mm2_s if nu_mm2_s is None else positive("nu_mm2_s", nu_mm2_s)
    Fr = non_negative("radial_load_N", radial_load_N)
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
        positive("R20_ohm", self.R20_ohm)
        positive("kT_Nm_A", self.kT_Nm_A)
        for name in ("pole_pairs", "phases"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise ValueError(f"{name} = {v!r} must be a whole number >= 1")
        non_negative("k_h_W_HzT2", self.k_h_W_HzT2)
        non_negative("k_e_W_Hz2T2", self.k_e_W_Hz2T2)
        non_negative("B_T", self.B_T)
        share("rotor_loss_share", self.rotor_loss_share)
        non_negative("alpha_cu_1_K", self.alpha_cu_1_K)


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
    """Winding resistance [ohm] at ``T_K`` [K], the paper's eq. 17:
    R(T) = R20 (1 + beta20 (T - 20 degC)), beta20 = 0.00393 1/K for copper (paper ref. [17])."""
    R20 = positive("R20_ohm", R20_ohm)
    T = positive("T_K", T_K)
    R = R20 * (1.0 + non_negative("alpha_1_K", alpha_1_K) * (T - T20_K))
    if R <= 0.0:
        raise ValueError(f"T_K = {T:g} gives a non-positive resistance by eq. 17")
    return R


def copper_loss_W(current_A: float, R_ohm: float, phases: int = 3) -> float:
    """Copper loss [W], the paper's eq. 16 per phase, summed: P_cu = m I^2 R(T), with I the rms
    phase current [A] and R the phase resistance [ohm]."""
    I_ = finite("current_A", current_A)
    return float(phases) * I_**2 * positive("R_ohm", R_ohm)


def electrical_frequency_Hz(speed_rpm: float, pole_pairs: int) -> float:
    """Electrical (stator field) frequency [Hz] of a synchronous motor, f = n p / 60."""
    omega_rad_s(speed_rpm)  # validates the speed
    return float(speed_rpm) * pole_pairs / 60.0


def hysteresis_loss_W(k_h_W_HzT2: float, f_Hz: float, B_T: float) -> float:
    """Iron hysteresis loss [W], the paper's eq. 18: Q_h = k_h f B^2 (Steinmetz form with
    exponent 2, as in the paper), k_h for the whole core [W/(Hz T^2)], f [Hz], B [T]."""
    return non_negative("k_h", k_h_W_HzT2) * non_negative("f_Hz", f_Hz) * finite("B_T", B_T) ** 2


def eddy_loss_W(k_e_W_Hz2T2: float, f_Hz: float, B_T: float) -> float:
    """Iron eddy-current loss [W], the paper's eq. 19: Q_e = k_e f^2 B^2, k_e for the whole
    core [W/(Hz^2 T^2)], f [Hz], B [T]."""
    return non_negative("k_e", k_e_W_Hz2T2) * non_negative("f_Hz", f_Hz) ** 2 * finite("B_T", B_T) ** 2


def motor_torque_Nm(load_torque_Nm: float, J_kgm2: float = 0.0, dw_dt_rad_s2: float = 0.0) -> float:
    """Motor (air-gap) torque [N m] from the paper's eq. 15, M - M_L = J dw/dt, i.e.
    M = M_L + J dw/dt; M_L [N m] is everything the motor drives (process torque, bearing
    friction, windage), J [kg m2] the inertia of the rotating assembly, dw/dt [rad/s2]."""
    return (finite("load_torque_Nm", load_torque_Nm)
            + non_negative("J_kgm2", J_kgm2) * finite("dw_dt_rad_s2", dw_dt_rad_s2))


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
    T = positive("T_winding_K", T_winding_K)
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
        P_el = finite("P_el_W", P_el_W)
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
    M_L = (finite("process_torque_Nm", process_torque_Nm) + friction_Nm
           + finite("windage_torque_Nm", windage_torque_Nm))
    ml = motor_losses(motor, speed_rpm, M_L, T_winding_K, P_el_W=P_el_W, J_kgm2=J_kgm2,
                      dw_dt_rad_s2=dw_dt_rad_s2)
    return PowerBalance(float(speed_rpm), float(process_torque_Nm), ml, fr)
