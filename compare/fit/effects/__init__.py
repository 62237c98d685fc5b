"""The library of candidate effects, one plug-in module each (compare.fit.effects.base says
what an effect declares). The grey box, the selection, the synthetic runs and the report
iterate over :data:`LIBRARY` and never name an effect.

A user adds an effect of their own with :func:`register` (docs/examples/ex05_own_effect.py):

    from compare.fit.effects import Effect, register
    register(MyEffect())

The library's order is the order the signature tests run in (a test may read an earlier one).
"""

from __future__ import annotations

from compare.fit.effects.base import CHANNELS, Effect, Feedback, label, parse_label
from compare.fit.effects.centrifugal import CentrifugalShortening
from compare.fit.effects.coolant import CoolantDynamics
from compare.fit.effects.fixture import FixtureExpansion
from compare.fit.effects.lag import SensorLag
from compare.fit.effects.mount import MountConduction
from compare.fit.effects.preload import BearingPreload
from compare.fit.effects.windage import WindageLoss

__all__ = ["CHANNELS", "HYPOTHESES", "LIBRARY", "Effect", "Feedback", "candidates",
           "effect_of", "hypothesis", "label", "parse_label", "register", "unregister"]

#: the library, by name (names are fixed: users' scripts and reports read them)
LIBRARY: dict[str, Effect] = {}
#: hypotheses outside the library the grey box can hold (compare.fit.competitor's), by label
HYPOTHESES: dict[str, Effect] = {}


def register(effect: Effect) -> Effect:
    """Add ``effect`` to the library (its name must be new and its parameters' names not used
    by another effect); returns it."""
    if not effect.name or effect.name in LIBRARY:
        raise ValueError(f"an effect needs a name of its own, not {effect.name!r}")
    taken = {p.name for e in LIBRARY.values() for p in e.params}
    if clash := [p.name for p in effect.params if p.name in taken]:
        raise ValueError(f"{effect.name}: parameter names {clash} are another effect's")
    LIBRARY[effect.name] = effect
    return effect


def unregister(name: str) -> None:
    """Take an effect out of the library (a user's, after its use)."""
    LIBRARY.pop(name, None)


def effect_of(text: str) -> Effect:
    """The effect of a candidate label (``sensor_lag(T2)`` -> the lag), or a hypothesis
    outside the library (:data:`HYPOTHESES`)."""
    return HYPOTHESES[text] if text in HYPOTHESES else LIBRARY[parse_label(text)[0]]


def hypothesis(effect: Effect) -> str:
    """Make ``effect`` (a hypothesis outside the library) known to the grey box under its
    name; returns its label."""
    HYPOTHESES[effect.name] = effect
    return effect.name


def candidates(channels, names=None) -> list[str]:
    """The candidate labels for a run measuring ``channels``: every effect of the library (or
    of ``names``) that acts on a measured channel, a per-channel effect once per channel."""
    out = []
    for e in LIBRARY.values():
        if names is not None and e.name not in names:
            continue
        if e.per_channel:
            out += [label(e.name, c) for c in channels]
        elif set(e.channels) & set(channels):
            out.append(e.name)
    return out


for _effect in (CentrifugalShortening(), BearingPreload(), FixtureExpansion(), CoolantDynamics(),
                SensorLag(), WindageLoss(), MountConduction()):
    register(_effect)
