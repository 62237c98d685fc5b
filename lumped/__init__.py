"""Lumped function-block models of the paper (eq. 7-14): the blocks (lumped.blocks), their
network (lumped.network, eq. 8-11), the N-node model built from the spec (lumped.build,
lumped.simulation), the thermoelastic chain (lumped.elastic, eq. 12-13, 20), the closed-form
fin (lumped.fin, eq. 14) and the real-time predictor (lumped.realtime)."""

from lumped.build import PRESETS, build_network
from lumped.fin import Fin
from lumped.simulation import LumpedModel


def build(spec, nodes: int | str = 11, **options) -> LumpedModel:
    """The lumped model of ``spec`` with ``nodes`` masses along shaft and housing (an int
    >= 2, or "paper5" / "paper11"); options as :class:`LumpedModel`."""
    return LumpedModel(spec, nodes, **options)


__all__ = ["PRESETS", "Fin", "LumpedModel", "build", "build_network"]
