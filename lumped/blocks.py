"""Function blocks of a lumped thermal network, after Modelica's Thermal.HeatTransfer.

Every block exposes heat ports (:class:`HeatPort`: a temperature T [K] and a heat flow Q_flow
[W] into the block). Ports are joined by :meth:`lumped.network.Network.connect`; the ports
joined together form one node of the network (one temperature), like a Modelica connect set.

- :class:`HeatCapacitor`: c m [J/K] at one port (eq. 6).
- :class:`ThermalConductor`: G [W/K] between two ports (Fourier; contact, eq. 7).
- :class:`Convection`: a conductance Gc [W/K] that may vary with speed (alpha A of eq. 7, or a
  bearing or air-gap conductance), between a solid and a fluid port.
- :class:`FixedTemperature`: a port held at a named input temperature (ambient, coolant) or at
  a constant [K].
- :class:`PrescribedHeatFlow`: heat [W] into a port from a named input series, optionally
  temperature dependent, Q = share * Q_in(t) * (1 + tc * (T - T_ref)) (e.g. copper loss with
  R(T) = R20 (1 + 0.00393 (T - 20 degC)), paper eq. 16-17); the temperature term stays linear,
  so the network keeps the form C dT/dt + K T = Q of eq. 8.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from spindle.loads import SpeedTable

#: A conductance [W/K]: a constant, a table over speed, or any function of speed [rpm].
Conductance = float | SpeedTable | Callable[[float], float]


def conductance_at(G: Conductance, speed_rpm: float) -> float:
    """Value of a conductance [W/K] at a speed [rpm]."""
    if isinstance(G, SpeedTable):
        return float(G(speed_rpm))
    if callable(G):
        return float(G(speed_rpm))
    return float(G)


def varies_with_speed(G: Conductance) -> bool:
    if isinstance(G, SpeedTable):
        return len(set(G.values)) > 1
    return callable(G)


@dataclass(eq=False)
class HeatPort:
    """A thermal connector of a block: temperature T [K] and heat flow Q_flow [W] into it."""

    block: Block
    name: str = "port"

    def __repr__(self) -> str:
        return f"{self.block.name}.{self.name}"


@dataclass(eq=False)
class Block:
    """Base of all blocks: a unique ``name`` and its ports."""

    name: str

    @property
    def ports(self) -> tuple[HeatPort, ...]:
        return ()


@dataclass(eq=False)
class OnePort(Block):
    port: HeatPort = field(init=False)

    def __post_init__(self) -> None:
        self.port = HeatPort(self, "port")

    @property
    def ports(self) -> tuple[HeatPort, ...]:
        return (self.port,)


@dataclass(eq=False)
class TwoPort(Block):
    port_a: HeatPort = field(init=False)
    port_b: HeatPort = field(init=False)

    def __post_init__(self) -> None:
        self.port_a = HeatPort(self, "port_a")
        self.port_b = HeatPort(self, "port_b")

    @property
    def ports(self) -> tuple[HeatPort, ...]:
        return (self.port_a, self.port_b)


@dataclass(eq=False)
class HeatCapacitor(OnePort):
    """Thermal mass C = c m [J/K]; ``z_m`` [m] and ``part`` say where it sits (optional)."""

    C_J_K: float = 0.0
    part: str = ""
    z_m: float = float("nan")


@dataclass(eq=False)
class ThermalConductor(TwoPort):
    """Constant conductance G [W/K] between port_a and port_b."""

    G_W_K: float = 0.0


@dataclass(eq=False)
class Convection(TwoPort):
    """Conductance Gc [W/K] between a solid (port_a) and a fluid (port_b) that may depend on
    speed (film coefficient times area, bearing or air-gap conductance)."""

    Gc_W_K: Conductance = 0.0


@dataclass(eq=False)
class FixedTemperature(OnePort):
    """Port held at an input temperature: ``source`` names a series of the load case
    (``"ambient"`` or ``"coolant"``) or is a constant [K]."""

    source: str | float = "ambient"


@dataclass(eq=False)
class PrescribedHeatFlow(OnePort):
    """Heat [W] into the port: ``share`` of the input series ``source`` (a heat-source name
    of the load case) or of a constant [W], times (1 + tc_1_K (T - T_ref_K)).

    With ``across`` = (port_a, port_b) the factor is (1 + tc_1_K (T_a - T_b)) instead: heat that
    rises with a temperature difference elsewhere (bearing friction rising with the
    shaft-housing difference as thermal expansion raises the preload)."""

    source: str | float = 0.0
    share: float = 1.0
    tc_1_K: float = 0.0
    T_ref_K: float = 293.15
    across: tuple[HeatPort, HeatPort] | None = None
