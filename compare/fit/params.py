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
``prehistory_h``        a moved start's prehistory [h] (compare.fit.start)     1/60 .. 48
======================  =====================================================  ===========

``heat_capacity`` to ``axial_scale`` are extras (``fit --base-extra``); G_seat_W_K,
axial_scale and friction_exponent are calibrated by default (:data:`DEFAULT_BASE_EXTRA`).
``prehistory_h`` is calibrated on a run whose start moved (:data:`PREHISTORY`). An effect's
own parameters are declared by the effect (compare.fit.effects).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

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


# Prior widths (1 sigma, on the fitted scale: the natural log of a factor) are what a designer
# knows before any bench run, stated as assumptions with their sources.
BASE_PARAMS: dict[str, Param] = {p.name: p for p in (
    # defaults of f0 and rotor_share: placeholders; a model takes the drive's (base_params)
    Param("f0", "-", 0.30, 0.05, 3.0, "Palmgren bearing friction factor of all pairs",
          prior_sd=0.4, source="Palmgren's f0 spans a factor 2-3 over lubrication and "
          "preload (Harris, Rolling Bearing Analysis)"),
    Param("rotor_share", "-", 0.06, 0.01, 0.5, "rotor share of the motor losses", prior_sd=0.9,
          source="among the least known inputs: a drive's 0.06 against the third of "
          "Bossmanns and Tu's (1999) power-flow model, a factor 5.5 at 1.9 sigma"),
    Param("h_coolant", "x", 1.0, 0.2, 5.0, "factor on the coolant-jacket film conductances",
          prior_sd=0.25, source="Dittus-Boelter / Gnielinski, +-25 %"),
    Param("h_air", "x", 1.0, 0.2, 5.0, "factor on the housing-to-air film conductances",
          prior_sd=0.35, source="natural and mixed convection correlations, +-35 %"),
    Param("h_rotating", "x", 1.0, 0.2, 5.0, "factor on the rotating surfaces' films",
          prior_sd=0.4, source="rotating-surface correlations, +-50 %"),
    Param("contact", "x", 1.0, 0.2, 5.0, "factor on the contact-link interface conductances",
          prior_sd=0.7, source="contact conductances scatter by a factor 2-4 between "
          "assemblies"),
    Param("stator_contact", "x", 1.0, 0.1, 20.0, "factor on the contact conductances of the "
          "stator (its fit to the cooling sleeve: the winding-to-jacket path)", prior_sd=1.0,
          source="the least known conductance of a motor spindle (interference fit over a "
          "laminated stack, impregnation, the winding's conduction to the core): interface "
          "coefficients from a few hundred to several thousand W/(m2 K), a factor 10 at 2.3 "
          "sigma"),
    Param("alpha_eff", "x", 1.0, 0.5, 2.0, "factor on the expansion coefficients of the "
          "thermoelastic chain (effective expansion coefficient)", prior_sd=0.1,
          source="expansion coefficients of steels, +-10 %"),
)}
#: base parameters that ``fit --base-extra`` adds for a spindle its spec describes only
#: approximately (their trades, measured: docs/fit-history.md)
EXTRA_BASE_PARAMS: dict[str, Param] = {p.name: p for p in (
    Param("heat_capacity", "x", 1.0, 0.1, 3.0, "factor on every heat capacity of the network "
          "(effective thermal mass)", prior_sd=0.7, source="how much of the CAD masses takes "
          "part on a cycle's time scales depends on contacts and films the spec only "
          "approximates: a factor 2 at 1 sigma"),
    Param("G_seat_W_K", "W/K", 0.0, 0.0, 200.0, "conductance from each bearing's outer ring "
          "to the coolant (a cooled bearing seat the spec does not describe)", log=False,
          source="a path the spec lacks (value 0, no prior): the run decides"),
    Param("friction_exponent", "-", 0.0, -1.0, 1.0, "bearing friction times "
          f"(n / {FRICTION_REF_RPM:g} rpm)^e: its speed dependence beyond Palmgren's",
          log=False, prior_sd=0.5, source="Palmgren's (nu n)^(2/3) averages over "
          "lubrication regimes: Harris's spread of measured friction-speed curves"),
    Param("axial_scale", "x", 1.0, 0.8, 1.25, "factor on every axial length of the spindle "
          "(spindle.stretch.stretch_axially): axial conductances / s, radial ones, films and heat "
          "capacities x s, the growth chain x s", prior_sd=0.15, source="lengths a designer "
          "reconstructs from CAD drawings (bearing spacing, motor and housing) to 10-20 %"),
)}

#: the start of a run whose first samples moved it (compare.fit.start): its prehistory,
#: calibrated with the base from the first samples' estimate (GreyBox.parameters gives that
#: as the default); the upper bound is Criteria.prehistory_max_s's default
PREHISTORY = Param("prehistory_h", "h", 1.0, 1.0 / 60.0, 48.0, "the run's first operating "
                   "point held this long before the log, from the room's temperature",
                   source="the first samples' estimate (compare.fit.start) as its start, no "
                   "prior: the run's first hours decide")

#: a prehistory that ran elsewhere (compare.fit.start): its heat in the motor and in the
#: bearings as multiples of the first samples' estimate, calibrated with the base as its
#: length is; the upper bound (GreyBox.parameters) is the run's own largest heat
PREHISTORY_HEAT = {group: Param(
    f"prehistory_{group}_x", "x", 1.0, 0.0, 1.0, f"the heat in the {group} during a "
    "prehistory that ran elsewhere, a multiple of the first samples' estimate",
    log=False, source="the first samples' estimate (compare.fit.start) as its start, no "
    "prior: the run's first hours decide") for group in ("motor", "bearings")}

#: the extras calibrated by default (``fit`` without ``--base-extra``). heat_capacity is not:
#: it takes up part of a bearing preload and, on a peer's runs, lowered the validation error
#: without better verdicts. The three that are each give the base a freedom that, missing,
#: the films and contacts imitate out of their prior ranges: bearing seats that follow the
#: coolant through a path the spec's geometry lacks (about 0 where the spindle has none),
#: axial lengths 10-15 % off, and a friction-speed law other than Palmgren's
#: (docs/fit-history.md, *The friction exponent* and the issue-13 entries).
DEFAULT_BASE_EXTRA: tuple[str, ...] = ("G_seat_W_K", "axial_scale", "friction_exponent")


def base_params(drive: Drive) -> dict[str, Param]:
    """:data:`BASE_PARAMS` with the spec's own values of the drive's parameters as defaults
    (prior centres): f0 of its bearing sets (when they share one; else the default stands)
    and the rotor's share of the motor loss."""
    out = dict(BASE_PARAMS)
    f0s = {float(b.f0) for b in drive.bearings.values()}
    if len(f0s) == 1:
        out["f0"] = replace(out["f0"], default=f0s.pop())
    out["rotor_share"] = replace(out["rotor_share"], default=float(drive.motor.rotor_loss_share))
    return out


def default_theta(params: dict[str, Param], names: Sequence[str] | None = None) -> dict:
    """Each parameter's default (the spec's value; an effect's neutral value), by name."""
    return {k: p.default for k, p in params.items() if names is None or k in names}
