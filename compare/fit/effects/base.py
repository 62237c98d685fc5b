"""What an effect of the library is: a plug-in that the grey box, the selection, the synthetic
runs and the report use through these hooks alone.

An :class:`Effect` declares

- its parameters (:class:`compare.fit.params.Param`: unit, neutral value, bounds, source),
  whose neutral values give the base model, so the base is nested in the extended one;
- how it enters the grey box: options of the lumped network, blocks it adds, conductances of
  the edges it owns, heat it adds to the sources, what it does to P1 or to a channel as
  measured;
- its signature test on the raw samples, where it has one (:meth:`Effect.signature`);
- how it enters a synthetic run (the spec, the load case, a feedback from the FEM's own
  temperatures, or the measurement) and how to draw its size;
- the hint the verdict gives when it is named;
- what it needs of a spindle, where it needs something (:meth:`Effect.missing_in`: a coolant
  film for an effect that acts through the coolant, ``needs_coolant``).

An effect that acts on one sensor (a lag) is ``per_channel``: it is tried on each measured
channel, and its candidate label names the channel, ``sensor_lag(T2)``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from compare.fit.params import Param
from lumped.blocks import PrescribedHeatFlow
from spindle.drive_file import MOTOR_SOURCES

if TYPE_CHECKING:
    from spindle.loads import LoadCase
    from spindle.spec import Spec

CHANNELS = ("T1", "T2", "T_stator", "P1")


@dataclass(frozen=True)
class Feedback:
    """How a synthetic run feeds an effect back from the FEM's own temperatures: the linear
    read-outs of the temperature field it needs (name -> row over the field), the input it
    changes as a function ``apply(case, x, t)`` of the fed-back series x on the grid t, the map
    ``update(readings, case, t) -> x`` from the read-outs of a run to x, and x of a run
    without the feedback, ``start(readings, case, t)``."""

    functionals: dict[str, np.ndarray]
    apply: Callable[[LoadCase, np.ndarray, np.ndarray], LoadCase]
    update: Callable[[dict[str, np.ndarray], LoadCase, np.ndarray], np.ndarray]
    start: Callable[[dict[str, np.ndarray], LoadCase, np.ndarray], np.ndarray]
    #: instantaneous additions to the bench's channels from the fed-back x (name -> f(ts, t, x))
    instant: dict[str, Callable] = field(default_factory=dict)


class Effect:
    """A candidate effect (the module docstring); subclasses set the attributes and override
    the hooks they need. Every hook's default leaves the model as it is."""

    name: str = ""
    explanation: str = ""
    params: tuple[Param, ...] = ()
    #: the channels its signature shapes (the selection judges it on these)
    channels: tuple[str, ...] = CHANNELS
    #: one candidate per measured channel (its label names the channel)
    per_channel: bool = False
    #: parameters that change the system's matrices (the engine caches systems by them, and
    #: configures the effect's flows for them before every use)
    in_conductance: tuple[str, ...] = ()
    #: what the verdict says to look at in the spindle or its spec when the effect is named
    hint: str = ""
    #: a cause outside the library that leaves the same mark in the measured channels (a noun
    #: phrase): where the open loop names the effect, the verdict says the two are not told
    #: apart there (its signature, where it applies, tells them apart)
    look_alike: str = ""
    #: acts on the measurement alone (a recorded run can carry it injected: compare.synth.inject)
    measurement_only: bool = False
    #: acts through the coolant, so a spindle needs a coolant film (Spec.liquid_cooled)
    needs_coolant: bool = False

    #: roles of the parts whose heat source its synthetic injection (synth_case) changes
    synth_sources: tuple[str, ...] = ()

    def missing_in(self, spec: Spec, synth: bool = False) -> str:
        """What the spindle ``spec`` lacks for this effect to act ("" where nothing): one that
        cannot act on a spindle is no candidate of its fit, and no synthetic run of it can
        carry it; with ``synth``, also the heat sources its injection changes."""
        if self.needs_coolant and not spec.liquid_cooled:
            return 'a coolant film (a [[surfaces]] entry with T_ref = "coolant")'
        lacking = [r for r in (self.synth_sources if synth else ())
                   if not spec.sources_with_role(r)]
        if lacking:
            return " and ".join(f'a heat source on a part with role = "{r}"' for r in lacking)
        return ""

    # ------------------------------------------------------------------ the grey box
    def network_options(self) -> dict[str, Any]:
        """Keyword options of lumped.build.build_network this effect needs."""
        return {}

    def extend_network(self, net, spec: Spec, power_measured: bool) -> Any:
        """Add blocks to the lumped network ``net`` (lumped.build.LumpedNetwork); returns a
        handle the other hooks get back (None by default)."""
        return None

    def edge_conductances(self, theta: Mapping[str, float]) -> dict[str, float]:
        """Conductance [W/K] of the network edges this effect owns, by edge name."""
        return {}

    def configure(self, handle: Any, theta: Mapping[str, float]) -> None:
        """Set the coefficients of the flows in ``handle`` for a parameter set."""

    def heat(self, sources_W: dict[str, np.ndarray], theta: Mapping[str, float],
             inputs) -> dict[str, np.ndarray]:
        """The heat sources [W per interval], with this effect's heat."""
        return sources_W

    def p1(self, p1_m: np.ndarray, theta: Mapping[str, float], inputs) -> np.ndarray:
        """P1 [m] at the grid points with this effect's read-out (before it is zeroed)."""
        return p1_m

    def as_measured(self, out: dict[str, np.ndarray], theta: Mapping[str, float], inputs,
                    channel: str | None) -> dict[str, np.ndarray]:
        """The channels as the sensors read them (after the FEM anchor): a lag acts here."""
        return out

    # ------------------------------------------------------------------ evidence
    def signature(self, ctx) -> dict:
        """Its signature tests on the raw samples (compare.fit.signatures.Context): label ->
        compare.fit.signatures.EventTest. None by default: the open-loop fit alone judges."""
        return {}

    # ------------------------------------------------------------------ synthetic runs
    def draw(self, rng: np.random.Generator) -> dict:
        """The effect's parameters for a synthetic run (a size a bench could show)."""
        return {}

    def synth_spec(self, spec: Spec, truth: Mapping[str, Any]) -> Spec:
        """The spindle of a synthetic run with the effect built in."""
        return spec

    def synth_case(self, case: LoadCase, spec: Spec, truth: Mapping[str, Any]
                   ) -> tuple[LoadCase, dict[str, Callable]]:
        """The load case with the effect, and instantaneous additions to what the bench logs
        (``power_W``: power the motor supplies against it; a channel's name; ``T_coolant``,
        ``T_env``), evaluated at its sample times."""
        return case, {}

    def feedback(self, thermal, spec: Spec, truth: Mapping[str, Any]) -> Feedback | None:
        """The effect's feedback from the FEM's temperatures (None: it has none)."""
        return None

    def synth_measure(self, t_s: np.ndarray, channels: dict[str, np.ndarray], case: LoadCase,
                      truth: Mapping[str, Any], reference) -> dict[str, Callable]:
        """Change the model's channels [K; m for P1, on the grid ``t_s``] as the measurement
        reads them (in place); returns instantaneous additions evaluated at the bench's own
        sample times (name -> f(times))."""
        return {}

    def measure(self, t_s: np.ndarray, columns: dict[str, np.ndarray],
                truth: Mapping[str, Any], channel: str | None) -> dict[str, np.ndarray]:
        """A recorded run's columns (SI: ``speed_rpm``, ``T_env_K``, the channels in K, P1 in
        m) with this measurement-side effect injected (``measurement_only`` effects)."""
        raise NotImplementedError(f"{self.name} acts on the physics, not on the measurement")


def spread_heat(net, masses, source: str, prefix: str) -> None:
    """Heat flows of ``source`` into ``masses`` of the lumped network ``net``, shared by
    their heat capacities (block names ``prefix:mass``)."""
    total = sum(m.block.C_J_K for m in masses)
    for m in masses:
        q = net.network.add(PrescribedHeatFlow(f"{prefix}:{m.name}", source=source,
                                               share=m.block.C_J_K / total))
        net.network.connect(m.block.port, q.port)


def heat_from_motor(sources_W: dict[str, np.ndarray], name: str, heat_W: np.ndarray,
                    power_kW: np.ndarray) -> dict[str, np.ndarray]:
    """The heat sources [W per interval] with ``heat_W`` into the source ``name``. A heat the
    drive supplies (a drag) is already in the measured electrical power, which the power
    balance booked as motor loss: where the power is measured it is taken from the motor
    sources (stator and rotor in proportion; at most what they hold), so the total heat stays
    the measured one; where it is not (nan: a cycle's motor model gives the losses) it comes
    on top."""
    w = np.asarray(heat_W, dtype=float)
    measured = ~np.isnan(np.asarray(power_kW, dtype=float))
    motor = [k for k in MOTOR_SOURCES if k in sources_W]
    out = dict(sources_W)
    if motor and measured.any():
        total = sum(sources_W[k] for k in motor)
        take = np.where(measured, np.minimum(w, total), 0.0)
        keep = np.divide(total - take, total, out=np.ones_like(total), where=total > 0)
        for k in motor:
            out[k] = sources_W[k] * keep
        w = np.where(measured, take, w)
    out[name] = w
    return out


def label(effect: str, channel: str | None = None) -> str:
    """A candidate's label: the effect's name, with the channel of a per-channel effect."""
    return f"{effect}({channel})" if channel else effect


def parse_label(text: str) -> tuple[str, str | None]:
    """(effect name, channel or None) of a candidate label."""
    if text.endswith(")") and "(" in text:
        name, channel = text[:-1].split("(", 1)
        return name, channel
    return text, None
