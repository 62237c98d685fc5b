"""The paper's tolerances, in SI, in one place, and a bench channel's unit at the edges.

The paper accepts "small temperature deviations of 1 K" and "position deviations of
±1.5 µm" (section 3). Every verdict of the project (the study's PASS/FAIL, the node count,
the sensor placement, the fit's tolerance units and its materiality) reads them from here;
µm appear only where a figure is shown (:func:`edge_scale`).
"""

from __future__ import annotations

from spindle.units import ZERO_C_K

#: the temperature error the paper accepts [K]
TEMPERATURE_TOLERANCE_K = 1.0
#: the position error the paper accepts, either way [m]
GROWTH_TOLERANCE_M = 1.5e-6

#: the growth readings (axial displacements [m]); every other channel is a temperature [K]
GROWTH_CHANNELS = ("P1", "TCP")


def channel_tolerance(channel: str) -> float:
    """The paper's tolerance of a channel in its SI unit: m for a growth reading, else K."""
    return GROWTH_TOLERANCE_M if channel in GROWTH_CHANNELS else TEMPERATURE_TOLERANCE_K


def edge_scale(channel: str) -> float:
    """The factor from a channel's SI value to the unit it is shown in (m -> µm, K -> K)."""
    return 1e6 if channel in GROWTH_CHANNELS else 1.0


def edge_absolute(channel: str) -> tuple[float, float, str]:
    """(scale, offset, unit): a channel's absolute SI value v is shown as v * scale - offset
    in unit: µm for a growth reading, °C for a temperature [K]."""
    if channel in GROWTH_CHANNELS:
        return 1e6, 0.0, "µm"
    return 1.0, ZERO_C_K, "°C"


def edge_unit(channel: str, ascii: bool = False) -> str:
    """The unit a channel is shown in: µm (``um`` with ``ascii``, for machine fields) or K."""
    if channel in GROWTH_CHANNELS:
        return "um" if ascii else "µm"
    return "K"
