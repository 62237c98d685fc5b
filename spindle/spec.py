"""The spindle description (spec): CAD dimensions, materials, links, boundary conditions,
heat sources and sensors, in SI units, as frozen dataclasses. See docs/spec.md for every
field.

:func:`spindle.spec_reader.load_spec` reads and validates a TOML file; every problem found
is reported at once, each naming the file, the field and the fix
(:class:`~spindle.errors.SpecError`).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from spindle.geometry import Trapezoid
from spindle.loads import LoadCase, SpeedTable, TimeSeries

ROLES = ("shaft", "tool", "rotor", "stator", "housing", "cooling_sleeve",
         "front_bearing", "rear_bearing")
BEARING_ROLES = ("front_bearing", "rear_bearing")
SIDES = ("outer", "inner", "front", "rear", "any")
T_REFS = ("ambient", "coolant")
LINK_TYPES = ("bearing", "air_gap", "contact")
#: A rotor-stator gap wider than this is not an air gap of a built-in motor [m].
MAX_AIR_GAP_M = 5e-3


@dataclass(frozen=True)
class Material:
    """Thermal and elastic properties, SI. ``k_r``/``k_z``: radial/axial conductivity [W/m/K]."""

    name: str
    k_r_W_mK: float
    k_z_W_mK: float
    rho_kg_m3: float
    c_J_kgK: float
    E_Pa: float
    nu: float
    alpha_1_K: float
    source: str = ""

    @property
    def isotropic(self) -> bool:
        return self.k_r_W_mK == self.k_z_W_mK


@dataclass(frozen=True)
class Section(Trapezoid):
    """One axisymmetric section of a part: geometry [m], its material and optional name."""

    material: str = ""
    name: str = ""


@dataclass(frozen=True)
class Part:
    name: str
    role: str
    sections: tuple[Section, ...]


@dataclass(frozen=True)
class BearingLink:
    """Rolling-contact conductance between the raceways [W/K]; its ``section`` of the bearing
    ``part`` is meshed with the conductivity that gives this conductance radially."""

    part: str
    section: str
    G_W_K: SpeedTable


@dataclass(frozen=True)
class AirGapLink:
    """Effective rotor-stator air-gap coefficient [W/m2/K] on the rotor surface; the gap
    between ``inner`` and ``outer`` is meshed as a layer with the matching conductivity."""

    inner: str
    outer: str
    h_W_m2K: SpeedTable


@dataclass(frozen=True)
class ContactLink:
    """Fitted-joint contact conductance [W/m2/K] on the interface of two touching parts."""

    parts: tuple[str, str]
    h_W_m2K: float


Link = BearingLink | AirGapLink | ContactLink


@dataclass(frozen=True)
class Surface:
    """Named exposed surface: the boundary of ``parts`` facing ``side``, within z limits [m].

    With ``h_W_m2K`` it is a convective boundary towards ``T_ref`` (ambient or coolant);
    without, it only names the place for a surface heat source.
    """

    name: str
    parts: tuple[str, ...]
    side: str
    z_min: float
    z_max: float
    h_W_m2K: SpeedTable | None
    T_ref: str | None


@dataclass(frozen=True)
class HeatSource:
    """Heat [W] into a part (or one named section of it) by volume, or into a surface."""

    name: str
    power_W: TimeSeries
    part: str | None = None
    section: str | None = None
    surface: str | None = None


@dataclass(frozen=True)
class Sensor:
    """A virtual sensor at (z, r) [m]. ``axial_displacement`` sensors also have a reference
    point (z_ref, r_ref) and read the axial displacement of (z, r) relative to it."""

    name: str
    kind: str
    z: float
    r: float
    z_ref: float | None = None
    r_ref: float | None = None
    array: str | None = None


@dataclass(frozen=True)
class SensorArray:
    """``count`` temperature sensors spaced evenly over the axial length of ``part``."""

    name: str
    part: str
    count: int
    radius: str | float


@dataclass(frozen=True)
class Spec:
    """A validated spindle description (SI units)."""

    name: str
    path: str
    description: str
    source: str
    speed_rpm: float
    T_ambient_K: float
    T_coolant_K: float
    T_initial_K: float
    h0_m: float
    materials: dict[str, Material]
    parts: tuple[Part, ...]
    links: tuple[Link, ...]
    surfaces: tuple[Surface, ...]
    heat_sources: tuple[HeatSource, ...]
    sensors: tuple[Sensor, ...]
    sensor_arrays: tuple[SensorArray, ...] = field(default_factory=tuple)
    power_preset: str | None = None  # [power_balance] preset: motor and bearing parameters

    def part(self, name: str) -> Part:
        return next(p for p in self.parts if p.name == name)

    def sections(self) -> Iterator[tuple[Part, Section]]:
        for p in self.parts:
            for s in p.sections:
                yield p, s

    def parts_with_role(self, role: str) -> list[Part]:
        return [p for p in self.parts if p.role == role]

    def sources_with_role(self, *roles: str) -> list[HeatSource]:
        """The heat sources on parts of any of ``roles``, in the spec's order."""
        return [h for h in self.heat_sources if h.part and self.part(h.part).role in roles]

    def mass_kg(self, part: str, section: str | None = None) -> float:
        return float(sum(self.materials[s.material].rho_kg_m3 * s.volume_m3
                         for s in self.part(part).sections
                         if section is None or s.name == section))

    @property
    def liquid_cooled(self) -> bool:
        """Whether a surface has a film towards the coolant (a jacket): without one the
        coolant's temperature drives nothing."""
        return any(s.T_ref == "coolant" and s.h_W_m2K is not None for s in self.surfaces)

    def temperature_sensors(self) -> list[Sensor]:
        return [s for s in self.sensors if s.kind == "temperature"]

    def growth_points(self) -> dict[str, tuple[float, float, float, float]]:
        """Axial-growth readings (z, r, z_ref, r_ref) [m]: every displacement sensor and, when a
        tool is clamped, ``TCP`` (tool tip on the axis, or on its bore) against the first
        sensor's reference point (paper sec. 2.1: the TCP is at the tool tip)."""
        pts = {s.name: (s.z, s.r, s.z_ref, s.r_ref) for s in self.sensors
               if s.kind == "axial_displacement"}
        tools = self.parts_with_role("tool")
        if tools and pts:
            ref = next(iter(pts.values()))
            tip = max(tools[0].sections, key=lambda s: s.z_end)
            pts["TCP"] = (tip.z_end, 0.0 if tip.r_inner[1] == 0 else tip.r_inner[1],
                          ref[2], ref[3])
        return pts

    def default_load_case(self) -> LoadCase:
        """Constant inputs from the spec's [operating] table and heat sources."""
        return LoadCase(
            name="steady",
            speed_rpm=TimeSeries.constant(self.speed_rpm),
            T_ambient_K=TimeSeries.constant(self.T_ambient_K),
            T_coolant_K=TimeSeries.constant(self.T_coolant_K),
            sources={h.name: h.power_W for h in self.heat_sources},
        )
