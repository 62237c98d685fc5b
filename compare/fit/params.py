"""The grey box's base parameters: what a designer knows before any bench run, as bounded,
uncertain factors or values with priors around the spec's values.

======================  =====================================================  ===========
name                    meaning                                                bounds
======================  =====================================================  ===========
``f0``                  Palmgren bearing friction factor (all pairs)           0.05 .. 3
``rotor_share``         rotor share of the motor losses                        0.01 .. 0.5
``h_coolant``           factor on the coolant-jacket film conductances         0.2 .. 5
``h_air``               factor on the housing-to-air film conductances         0.2 .. 5
``h_rotating``          factor on the rotating surfaces' film conductances     0.2 .. 5
``contact``             factor on the interface conductances of contact links  0.2 .. 5
``stator_contact``      the same for the stator's contacts (to the sleeve)     0.1 .. 20
``alpha_eff``           factor on the expansion coefficients of the growth     0.5 .. 2
``G_seat_W_K``          bearing outer rings to the coolant [W/K] (default on)  0 .. 200
``heat_capacity``       factor on every heat capacity of the network           0.1 .. 3
``friction_exponent``   bearing friction x (n / 3000 rpm)^e                    -1 .. 1
``axial_scale``         the spindle's axial lengths x (default on)             0.8 .. 1.25
======================  =====================================================  ===========

The last four are extras (``fit --base-extra``); G_seat_W_K, axial_scale and
friction_exponent are calibrated by default (:data:`DEFAULT_BASE_EXTRA`). An effect's own
parameters are declared by the effect (compare.fit.effects).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from spindle.drive import Drive
from spindle.drive_file import FRICTION_REF_RPM


@dataclass(frozen=True)
class Param:
    """A fitted parameter: default, bounds, unit; ``log`` fits it on a log scale."""

    name: str
    unit: str
    default: float
    lo: float
    hi: float
    doc: str
    log: bool = True
    #: prior standard deviation around the spec's value (compare.fit.calibrate), on the fitted
    #: scale (natural log for ``log`` parameters); None: no prior
    prior_sd: float | None = None
    #: where the bounds and the prior width come from
    source: str = ""


# Prior widths (1 sigma, natural log of the factor) are what a designer knows before any
# bench run, stated as assumptions: Palmgren's f0 spans a factor 2-3 over lubrication and
# preload (Harris, Rolling Bearing Analysis), 0.4; the rotor's share of a motor spindle's
# losses is among the least known inputs: the spec's drive gives 0.06, while the classic
# spindle power-flow model (Bossmanns and Tu 1999, followed by much of the literature)
# books a third of the motor losses to the rotor, a factor 5.5 apart, so 0.9 (that factor at
# 1.9 sigma); Dittus-Boelter / Gnielinski for the jacket
# +-25 %, 0.25; natural and mixed convection correlations on the housing +-35 %, 0.35;
# rotating-surface correlations +-50 %, 0.4; contact conductances scatter by a factor 2-4
# between assemblies, 0.7; the stator's fit to the cooling sleeve apart from them, 1.0: the
# winding-to-jacket path (interference fit over a laminated stack, impregnation, the winding's
# own conduction to the core) is the least known conductance of a motor spindle, with
# interface coefficients quoted from a few hundred to several thousand W/(m2 K) (a factor
# 10 at 2.3 sigma; a peer's SPL2782-family runs call for the bound of 20, issue 13);
# expansion coefficients of steels +-10 %, 0.1. Two more freedoms
# for a spindle its spec describes only approximately (issue 13, ``fit --base-extra``; a
# peer's SPL2782-family runs need both): the effective heat capacity, since how much of the
# CAD masses takes part on a cycle's time scales depends on contacts and films the spec only
# approximates (a factor 2 at 1 sigma, 0.7); and the speed dependence of the bearing
# friction, Palmgren's (nu n)^(2/3) law being an average over lubrication regimes (exponent
# shift 0.5 at 1 sigma, per Harris's spread of measured friction-speed curves).
BASE_PARAMS: dict[str, Param] = {p.name: p for p in (
    # defaults of f0 and rotor_share: placeholders; a model takes the drive's (base_params)
    Param("f0", "-", 0.30, 0.05, 3.0, "Palmgren bearing friction factor of all pairs",
          prior_sd=0.4),
    Param("rotor_share", "-", 0.06, 0.01, 0.5, "rotor share of the motor losses", prior_sd=0.9),
    Param("h_coolant", "x", 1.0, 0.2, 5.0, "factor on the coolant-jacket film conductances",
          prior_sd=0.25),
    Param("h_air", "x", 1.0, 0.2, 5.0, "factor on the housing-to-air film conductances",
          prior_sd=0.35),
    Param("h_rotating", "x", 1.0, 0.2, 5.0, "factor on the rotating surfaces' films",
          prior_sd=0.4),
    Param("contact", "x", 1.0, 0.2, 5.0, "factor on the contact-link interface conductances",
          prior_sd=0.7),
    Param("stator_contact", "x", 1.0, 0.1, 20.0, "factor on the contact conductances of the "
          "stator (its fit to the cooling sleeve: the winding-to-jacket path)", prior_sd=1.0),
    Param("alpha_eff", "x", 1.0, 0.5, 2.0, "factor on the expansion coefficients of the "
          "thermoelastic chain (effective expansion coefficient)", prior_sd=0.1),
)}
#: base parameters that ``fit --base-extra`` adds for a spindle its spec describes only
#: approximately. heat_capacity is off by default (on the spec's own synthetic runs it absorbs
#: part of a bearing preload, and on a peer's runs it lowered the validation error without
#: better verdicts); G_seat_W_K (a conductance the spec does not have: spec value 0, no prior,
#: the data decide), axial_scale and friction_exponent are on (DEFAULT_BASE_EXTRA; docs/fit-history.md)
EXTRA_BASE_PARAMS: dict[str, Param] = {p.name: p for p in (
    Param("heat_capacity", "x", 1.0, 0.1, 3.0, "factor on every heat capacity of the network "
          "(effective thermal mass)", prior_sd=0.7),
    Param("G_seat_W_K", "W/K", 0.0, 0.0, 200.0, "conductance from each bearing's outer ring "
          "to the coolant (a cooled bearing seat the spec does not describe)", log=False),
    Param("friction_exponent", "-", 0.0, -1.0, 1.0, "bearing friction times "
          f"(n / {FRICTION_REF_RPM:g} rpm)^e: its speed dependence beyond Palmgren's",
          log=False, prior_sd=0.5),
    # a spec's axial lengths come from CAD drawings whose undisclosed lengths (bearing
    # spacing, motor and housing lengths) a designer reconstructs to 10-20 %: 0.15 at 1 sigma
    Param("axial_scale", "x", 1.0, 0.8, 1.25, "factor on every axial length of the spindle "
          "(spindle.stretch.stretch_axially): axial conductances / s, radial ones, films and heat "
          "capacities x s, the growth chain x s", prior_sd=0.15),
)}

#: the extras calibrated by default (``fit`` without ``--base-extra``; the lumped calibration
#: only): the bearing seats' conductance to the coolant. A peer's SPL2782-family runs hold
#: their bearing rings within 0.1 K of the coolant at standstill, with the room 2.7 K warmer,
#: and settle within minutes of a speed step: a cooled seat that the spec's geometry (a
#: jacket around the stator only) lacks. Without it every other conductance factor ran to its
#: bound to imitate it, and T1 missed by 1.3-1.8 K where the room warmed (docs/fit-history.md).
#: On runs of a spindle that has no such path it calibrates to about 0.
#: And the axial scale: a spec whose lengths are 10-15 % off (this project's mismatched
#: synthetic runs) otherwise calibrates its jacket film to a third of the truth and the
#: stator's contact to 2.5 times it, to imitate the longer paths from the bearings to the
#: water (seed 3: h_coolant 0.27 for 0.71; with the true lengths 0.91; docs/fit-history.md).
#: And the friction's speed exponent: Palmgren's (nu n)^(2/3) is the spec's law, a real
#: bearing's friction departs from it (lubricant, preload, temperature), and without the
#: exponent the films take up the difference (mismatch seed 5, exponent -0.26: h_air x2.0 for
#: 0.96, h_rotating x3.1 for 1.3, and its mount and coolant runs missed; with it 54 of 54 on
#: seeds 1-6, docs/fit-history.md *The friction exponent*).
DEFAULT_BASE_EXTRA: tuple[str, ...] = ("G_seat_W_K", "axial_scale", "friction_exponent")


def base_params(drive: Drive) -> dict[str, Param]:
    """:data:`BASE_PARAMS` with the spec's own values of the drive's parameters as defaults
    (prior centres): f0 of its bearing sets (when they share one; else the default stands)
    and the rotor's share of the motor loss."""
    from dataclasses import replace as dc_replace

    out = dict(BASE_PARAMS)
    f0s = {float(b.f0) for b in drive.bearings.values()}
    if len(f0s) == 1:
        out["f0"] = dc_replace(out["f0"], default=f0s.pop())
    out["rotor_share"] = dc_replace(out["rotor_share"],
                                    default=float(drive.motor.rotor_loss_share))
    return out


def default_theta(params: dict[str, Param], names: Sequence[str] | None = None) -> dict:
    """Each parameter's default (the spec's value; an effect's neutral value), by name."""
    return {k: p.default for k, p in params.items() if names is None or k in names}
