"""The paper's function-block network built from the spec (CAD description): N thermal masses
along the shaft and N along the housing, plus the bearings, rotor, stator, sleeve, tool.

Discretisation (vertex-centred, like the paper's 11 virtual sensors spaced l/10):

- A part of role ``shaft`` or ``housing`` gets ``nodes`` masses at z_i = z_0 + i L/(N-1);
  mass i owns the slice [z_i - h/2, z_i + h/2] (half slices at the ends). Any other part gets
  max(1, round((N-1) L_part / L_shaft) + 1) masses the same way, so refining N refines all
  of them (one mass sits at the part's middle).
- A bearing part with a bearing link is the paper's bearing: each ring is one mass and the
  rolling layer's conductance G(n) joins them (its small capacity is split between the rings).
- Capacity: rho c of each section's material times its volume in the slice (eq. 6, 9).
- Axial conductance between neighbouring masses: 1 / integral dz / (k_z A(z)).
- Two touching parts exchange heat through each overlap of their slices, in series:
  conduction from each mass to the interface (radial: ln(r_face / r_c) / (2 pi k_r dz) from
  the slice's mean radius r_c = sqrt((r_i^2 + r_o^2) / 2); axial: from the slice's middle),
  and the contact conductance h A of a contact link (eq. 7, alpha_ijcont). Without a contact
  link the parts are bonded.
- The rotor-stator air gap and the bearings are :class:`~lumped.blocks.Convection` blocks
  whose conductance follows the speed.
- Each named surface with a film coefficient is a convection to ambient or coolant from the
  masses whose slices carry its exposed faces (same faces as the mesh: spindle.faces),
  with the conduction from the mass to the face in series.
- Heat sources go into the masses by volume (part or section) or by area (surface).

Approximations of the model form, which the comparison with the FEM reference measures:
one temperature per slice (no radial gradient inside a slice beyond the series conduction to
its faces), radially stacked sections of a non-bearing part share their slice's mass, and a
bearing's rolling layer exchanges heat only with its own rings.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lumped.blocks import (
    Block,
    Convection,
    FixedTemperature,
    HeatCapacitor,
    HeatPort,
    PrescribedHeatFlow,
    ThermalConductor,
    TwoPort,
)
from lumped.network import Network, ThermalSystem
from spindle.arguments import whole_number
from spindle.errors import Problem, SpecError
from spindle.faces import (
    Face,
    exposed_faces,
    faces_overlap,
    film_clash_problem,
    no_face_problem,
    surface_faces,
)
from spindle.geometry import TOL_M
from spindle.loads import SpeedTable
from spindle.spec import BEARING_ROLES, AirGapLink, BearingLink, ContactLink, HeatSource, Part, Section, Spec
from spindle.spec_reader import as_spec

#: the paper's models: 5 masses along shaft and housing (Fig. 5), and 11 (the 11 virtual
#: sensors of [6], extended by the two bearing temperatures)
PRESETS = {"paper5": 5, "paper11": 11}
CHAIN_ROLES = ("shaft", "housing")
_GAUSS = np.polynomial.legendre.leggauss(6)


@dataclass
class Mass:
    """One thermal mass: a z slice of a part, or one ring of a bearing."""

    name: str
    part: str
    z_m: float  # node position [m]
    z_lo: float  # slice [m]
    z_hi: float
    section: Section | None = None  # bearing ring
    block: HeatCapacitor | None = None
    index: int = -1  # position in the state vector


@dataclass
class PartMasses:
    part: Part
    masses: list[Mass]
    ring: bool = False

    def at(self, z: float, section: Section | None = None) -> Mass | None:
        """The mass holding (z, section): ring by section, slice by z."""
        if self.ring:
            return next((m for m in self.masses if m.section is section), None)
        for m in self.masses:
            if m.z_lo - TOL_M <= z <= m.z_hi + TOL_M:
                return m
        return None

    def interpolation(self, z: float) -> dict[int, float]:
        """Weights on the masses' state indices giving the temperature at z (linear between
        node positions, constant beyond the end nodes)."""
        ms = self.masses
        if len(ms) == 1:
            return {ms[0].index: 1.0}
        zs = np.array([m.z_m for m in ms])
        k = int(np.clip(np.searchsorted(zs, z) - 1, 0, len(ms) - 2))
        s = float(np.clip((z - zs[k]) / (zs[k + 1] - zs[k]), 0.0, 1.0))
        return {ms[k].index: 1.0 - s, ms[k + 1].index: s}


@dataclass
class LumpedNetwork:
    """The network of a spec with its masses, ready to assemble."""

    spec: Spec
    nodes: int
    network: Network
    parts: dict[str, PartMasses]
    masses: list[Mass] = field(default_factory=list)
    system: ThermalSystem | None = None


def _section_area(sec: Section, z: np.ndarray) -> np.ndarray:
    return np.pi * (np.asarray(sec.r_out(z)) ** 2 - np.asarray(sec.r_in(z)) ** 2)


def _volume(sec: Section, lo: float, hi: float) -> float:
    a, b = max(lo, sec.z_start), min(hi, sec.z_end)
    if b - a <= TOL_M:
        return 0.0
    z = [a, 0.5 * (a + b), b]  # Simpson is exact: the area is quadratic in z
    A = _section_area(sec, np.array(z))
    return float((b - a) * (A[0] + 4 * A[1] + A[2]) / 6.0)


def _r_mean(sec: Section, z: float) -> float:
    ri, ro = float(sec.r_in(z)), float(sec.r_out(z))
    return float(np.sqrt(0.5 * (ri * ri + ro * ro)))


def _axial_resistance(spec: Spec, part: Part, z0: float, z1: float) -> float:
    """integral dz / (k_z A(z)) from z0 to z1 [K/W], Gauss-Legendre per section piece."""
    x, w = _GAUSS
    edges = sorted({z0, z1, *[s.z_start for s in part.sections], *[s.z_end for s in part.sections]})
    edges = [e for e in edges if z0 - TOL_M <= e <= z1 + TOL_M]
    total = 0.0
    for a, b in zip(edges, edges[1:], strict=False):
        if b - a <= TOL_M:
            continue
        z = 0.5 * (a + b) + 0.5 * (b - a) * x
        kA = np.zeros_like(z)
        for s in part.sections:
            inside = (z >= s.z_start) & (z <= s.z_end)
            kA += np.where(inside, spec.materials[s.material].k_z_W_mK * _section_area(s, z), 0.0)
        if np.any(kA <= 0):
            raise SpecError([Problem(spec.path, f"parts.{part.name}", f"has no cross-section "
                                     f"between z = {a:g} and {b:g} m", "make its sections "
                                     "follow each other without axial gaps")])
        total += 0.5 * (b - a) * float(np.sum(w / kA))
    return total


def _node_count(spec: Spec, part: Part, nodes: int) -> int:
    if part.role in CHAIN_ROLES:
        return nodes
    shafts = spec.parts_with_role("shaft")
    ref = shafts[0] if shafts else part
    L_ref = max(s.z_end for s in ref.sections) - min(s.z_start for s in ref.sections)
    L = max(s.z_end for s in part.sections) - min(s.z_start for s in part.sections)
    return max(1, int(round((nodes - 1) * L / L_ref)) + 1)


def _slices(part: Part, n: int) -> list[tuple[float, float, float]]:
    z0 = min(s.z_start for s in part.sections)
    z1 = max(s.z_end for s in part.sections)
    if n == 1:
        return [(0.5 * (z0 + z1), z0, z1)]
    zs = np.linspace(z0, z1, n)
    h = (z1 - z0) / (n - 1)
    return [(float(z), float(max(z0, z - h / 2)), float(min(z1, z + h / 2))) for z in zs]


def _bearing_sections(spec: Spec, part: Part) -> tuple[Section, Section, Section, BearingLink] | None:
    """(inner ring, rolling layer, outer ring, link) of a bearing part, or None."""
    link = next((lk for lk in spec.links if isinstance(lk, BearingLink) and lk.part == part.name),
                None)
    if link is None or part.role not in BEARING_ROLES:
        return None
    rolling = next(s for s in part.sections if s.name == link.section)
    z = 0.5 * (rolling.z_start + rolling.z_end)
    inner = next((s for s in part.sections if s is not rolling
                  and abs(float(s.r_out(z)) - float(rolling.r_in(z))) <= TOL_M), None)
    outer = next((s for s in part.sections if s is not rolling
                  and abs(float(s.r_in(z)) - float(rolling.r_out(z))) <= TOL_M), None)
    if inner is None or outer is None or len(part.sections) != 3:
        raise SpecError([Problem(spec.path, f"parts.{part.name}", "a bearing part is an inner "
                                 f"ring, the rolling section '{link.section}' and an outer ring",
                                 "give it exactly these three sections, rings against the "
                                 "rolling section")])
    return inner, rolling, outer, link


def _radial_R(spec: Spec, sec: Section, r_face: float, dz: float) -> float:
    """Conduction from the slice's mean radius to a line face at r_face [K/W]."""
    rc = _r_mean(sec, 0.5 * (sec.z_start + sec.z_end))
    k = spec.materials[sec.material].k_r_W_mK
    return abs(np.log(max(r_face, 1e-12) / rc)) / (2 * np.pi * k * dz)


def build_network(spec: Spec | str, nodes: int | str = 11, radial_conduction: bool = True,
                  coolant_advection_W_K: float | None = None, bearing_tc_1_K: float = 0.0
                  ) -> LumpedNetwork:
    """The function-block network of ``spec`` with ``nodes`` masses along shaft and housing
    (an int >= 2, or a preset name of :data:`PRESETS`). ``radial_conduction=False`` drops the
    conduction from a mass to its faces (film and contact resistances only), as eq. 7 does.

    Extensions (off by default; the measured-data loop switches them on):
    ``coolant_advection_W_K`` = 2 m_dot c_p [W/K] lets the coolant warm along the jacket with
    the heat it carries (its mean temperature is the supply plus Q / (2 m_dot c_p)), instead of
    staying at the supply temperature; ``bearing_tc_1_K`` makes each bearing's friction heat
    rise with the inner-outer ring temperature difference, Q (1 + tc (T_inner - T_outer)), as
    thermal expansion raises the preload. ``spec``: a Spec, a shipped name or a path."""
    spec = as_spec(spec)
    nodes = _node_number(nodes)
    b = _Builder(spec, Network(f"{spec.name}-{nodes}"), rad=1.0 if radial_conduction else 0.0,
                 coolant_advection_W_K=coolant_advection_W_K, bearing_tc_1_K=bearing_tc_1_K)
    # the blocks are added in this order, which fixes the network's block order
    b.add_masses(nodes)
    b.add_axial_chains()
    b.add_interfaces()
    b.add_bearings()
    b.add_air_gaps()
    surface_pieces = b.add_films()
    b.add_sources(surface_pieces)
    return LumpedNetwork(spec, nodes, b.net, b.parts, b.masses)


#: the most masses along shaft and housing: 1000 is a hundred times the paper's 11 and finer
#: than the FEM reference's axial resolution; a spl2782 of 2000 takes 7 s to build, and a
#: count of 1e5 (a typo) would run for hours
MAX_NODES = 1000


def _node_number(nodes: int | str) -> int:
    """The number of masses along shaft and housing: an int >= 2 or a preset's number."""
    if isinstance(nodes, str):
        if nodes not in PRESETS:
            raise SpecError([Problem("command line", "--nodes", f"unknown preset '{nodes}'",
                                     f"use an integer >= 2 or one of {sorted(PRESETS)}")])
        nodes = PRESETS[nodes]
    try:
        return whole_number(nodes, "nodes", 2, MAX_NODES)
    except (TypeError, ValueError):
        raise SpecError([Problem("command line", "--nodes",
                                 f"{nodes!r} is not an integer in 2..{MAX_NODES}",
                                 "give the number of masses along shaft and housing, "
                                 f"2 to {MAX_NODES}")]) from None


def _capacity_J_K(spec: Spec, sec: Section, volume_m3: float) -> float:
    """rho c V [J/K] of ``volume_m3`` of the section's material (eq. 6, 9)."""
    m = spec.materials[sec.material]
    return m.rho_kg_m3 * m.c_J_kgK * volume_m3


def _ring_masses(spec: Spec, part: Part, inner: Section, rolling: Section,
                 outer: Section) -> PartMasses:
    """A bearing's two ring masses; each takes half the rolling layer's capacity."""
    pm = PartMasses(part, [], ring=True)
    for tag, sec in (("inner", inner), ("outer", outer)):
        C = sum(_capacity_J_K(spec, s, s.volume_m3) * (1.0 if s is sec else 0.5)
                for s in (sec, rolling))
        m = Mass(f"{part.name}.{tag}", part.name, 0.5 * (sec.z_start + sec.z_end),
                 sec.z_start, sec.z_end, section=sec)
        m.block = HeatCapacitor(m.name, C_J_K=C, part=part.name, z_m=m.z_m)
        pm.masses.append(m)
    return pm


def _slice_masses(spec: Spec, part: Part, nodes: int) -> PartMasses:
    """The z-slice masses of a part (module docstring: vertex-centred slices)."""
    pm = PartMasses(part, [])
    for k, (z, lo, hi) in enumerate(_slices(part, _node_count(spec, part, nodes))):
        C = sum(_capacity_J_K(spec, s, _volume(s, lo, hi)) for s in part.sections)
        m = Mass(f"{part.name}[{k}]", part.name, z, lo, hi)
        m.block = HeatCapacitor(m.name, C_J_K=C, part=part.name, z_m=z)
        pm.masses.append(m)
    return pm


def _add_to(acc: dict, key, value: float) -> None:
    """acc[key] += value, starting from 0."""
    acc[key] = acc.get(key, 0.0) + value


class _Builder:
    """The network under construction and the masses of each part; one method per kind of
    block, called in the order of :func:`build_network`."""

    def __init__(self, spec: Spec, net: Network, rad: float, coolant_advection_W_K: float | None,
                 bearing_tc_1_K: float):
        self.spec, self.net = spec, net
        self.rad = rad  # 1, or 0 to drop the conduction from a mass to its faces
        self.coolant_advection_W_K = coolant_advection_W_K
        self.bearing_tc_1_K = bearing_tc_1_K
        self.parts: dict[str, PartMasses] = {}
        self.masses: list[Mass] = []
        self.by_name: dict[str, Mass] = {}
        self.rings: dict[str, tuple] = {}  # bearing part -> (inner, rolling, outer, link)
        self.ports: dict[str, Block | None] = {"ambient": None, "coolant": None}

    # ------------------------------------------------------------------ lookups
    def owner(self, part: Part, sec: Section, z: float) -> Mass | None:
        """The mass holding section ``sec`` of ``part`` at z (None for a rolling layer)."""
        pm = self.parts[part.name]
        if pm.ring:
            inner, rolling, outer, _ = self.rings[part.name]
            if sec is rolling:
                return None  # the rolling layer touches only its rings (module docstring)
            return pm.at(z, sec)
        return pm.at(z)

    def edges_of(self, part: Part) -> list[float]:
        return [e for m in self.parts[part.name].masses for e in (m.z_lo, m.z_hi)]

    def cuts(self, lo: float, hi: float, *parts: Part) -> list[tuple[float, float]]:
        """[lo, hi] cut at the slice edges of ``parts``: pieces that each lie in one slice,
        none shorter than TOL_M. Two parts' slices that meet at one z, each computed in its own
        floating point (a spec stretched by 1.2), would otherwise leave a sliver of 1e-17 m: a
        link between masses that do not touch."""
        edges = [e for part in parts for e in self.edges_of(part) if lo < e < hi]
        cuts = sorted({lo, hi, *edges})
        return [(p, q) for p, q in zip(cuts, cuts[1:], strict=False) if q - p > TOL_M]

    def add_between(self, block: TwoPort, a: Mass, b: Mass) -> None:
        """Add a two-port block from mass ``a`` (port_a) to mass ``b`` (port_b)."""
        self.net.add(block)
        self.net.connect(a.block.port, block.port_a)
        self.net.connect(b.block.port, block.port_b)

    def fixed(self, ref: str) -> HeatPort:
        """The port of the ambient or coolant temperature (added on first use)."""
        ports, net = self.ports, self.net
        if ports[ref] is None:
            ports[ref] = net.add(FixedTemperature(ref, source=ref))
            if ref == "coolant" and self.coolant_advection_W_K is not None:
                # the films see the coolant's mean temperature: a junction behind the
                # advection conductance 2 m_dot c_p
                adv = net.add(ThermalConductor("coolant_advection", G_W_K=self.coolant_advection_W_K))
                net.connect(ports[ref].port, adv.port_b)
                ports["coolant_mean"] = adv
        if ref == "coolant" and "coolant_mean" in ports:
            return ports["coolant_mean"].port_a
        return ports[ref].port

    # ------------------------------------------------------------------ masses
    def add_masses(self, nodes: int) -> None:
        """Two ring masses per bearing part, z-slice masses for every other part."""
        for part in self.spec.parts:
            bs = _bearing_sections(self.spec, part)
            if bs is not None:
                self.rings[part.name] = bs
                pm = _ring_masses(self.spec, part, *bs[:3])
            else:
                pm = _slice_masses(self.spec, part, nodes)
            self.parts[part.name] = pm
            for m in pm.masses:
                self.net.add(m.block)
                self.masses.append(m)
        self.by_name = {m.name: m for m in self.masses}

    # ------------------------------------------------------------------ axial chains
    def add_axial_chains(self) -> None:
        """Axial conduction between neighbouring slices of a part."""
        for pm in self.parts.values():
            if pm.ring:
                continue
            for a, b in zip(pm.masses, pm.masses[1:], strict=False):
                R = _axial_resistance(self.spec, pm.part, a.z_m, b.z_m)
                self.add_between(ThermalConductor(f"axial:{a.name}-{b.name}", G_W_K=1.0 / R), a, b)

    # ------------------------------------------------------------------ interfaces
    def add_interfaces(self) -> None:
        """One conductor per pair of masses of touching parts, summed over the overlaps of
        their slices: radial where two sections' z ranges overlap, else axial where one
        section ends and the other starts."""
        contact_h = {frozenset(lk.parts): lk.h_W_m2K for lk in self.spec.links
                     if isinstance(lk, ContactLink)}
        conductance: dict[tuple[str, str], float] = {}
        sections = list(self.spec.sections())
        for ia, (pa, sa) in enumerate(sections):
            for pb, sb in sections[ia + 1:]:
                if pa.name == pb.name:
                    continue
                h = contact_h.get(frozenset((pa.name, pb.name)))
                a, b = max(sa.z_start, sb.z_start), min(sa.z_end, sb.z_end)
                if b - a > TOL_M:  # radial interface?
                    pieces = self._radial_interface(pa, sa, pb, sb, a, b, h)
                else:
                    pieces = self._axial_interface(pa, sa, pb, sb, h)
                for key, G in pieces:
                    _add_to(conductance, key, G)
        for (na, nb), G in conductance.items():
            self.add_between(ThermalConductor(f"contact:{na}-{nb}", G_W_K=G),
                             self.by_name[na], self.by_name[nb])

    def _radial_interface(self, pa: Part, sa: Section, pb: Part, sb: Section, a: float,
                          b: float, h: float | None) -> list[tuple[tuple[str, str], float]]:
        """(mass names, conductance) of each slice overlap where one section's outer radius
        is the other's inner radius over z in [a, b]."""
        out = []
        for lo, hi in ((sa, sb), (sb, sa)):
            if not all(abs(float(lo.r_out(z)) - float(hi.r_in(z))) <= TOL_M for z in (a, b)):
                continue
            plo, phi = (pa, pb) if lo is sa else (pb, pa)
            for p, q in self.cuts(a, b, plo, phi):
                zm, dz = 0.5 * (p + q), q - p
                ma, mb = self.owner(plo, lo, zm), self.owner(phi, hi, zm)
                if ma is None or mb is None or ma is mb:
                    continue
                r = float(lo.r_out(zm))
                R = self.rad * (_radial_R(self.spec, lo, r, dz) + _radial_R(self.spec, hi, r, dz))
                if h is not None:
                    R += 1.0 / (h * 2 * np.pi * r * dz)
                out.append(((ma.name, mb.name), 1.0 / R))
        return out

    def _axial_interface(self, pa: Part, sa: Section, pb: Part, sb: Section,
                         h: float | None) -> list[tuple[tuple[str, str], float]]:
        """(mass names, conductance) where one section ends at the z where the other starts,
        over the annulus their radii share."""
        out = []
        for first, second, pf, ps in ((sa, sb, pa, pb), (sb, sa, pb, pa)):
            if abs(first.z_end - second.z_start) > TOL_M:
                continue
            z = first.z_end
            r1 = max(float(first.r_in(z)), float(second.r_in(z)))
            r2 = min(float(first.r_out(z)), float(second.r_out(z)))
            if r2 - r1 <= TOL_M:
                continue
            A = np.pi * (r2 * r2 - r1 * r1)
            ma, mb = self.owner(pf, first, z - TOL_M), self.owner(ps, second, z + TOL_M)
            if ma is None or mb is None:
                continue
            R = 0.0
            for m, sec in ((ma, first), (mb, second)):
                mid = 0.5 * (m.z_lo + m.z_hi)
                R += self.rad * abs(z - mid) / (self.spec.materials[sec.material].k_z_W_mK * A)
            if h is not None:
                R += 1.0 / (h * A)
            if R <= 0:
                continue
            out.append(((ma.name, mb.name), 1.0 / R))
        return out

    # ------------------------------------------------------------------ bearings
    def add_bearings(self) -> None:
        """G(n) of each rolling layer between its rings, in series with the rings' conduction."""
        for name, (inner, rolling, outer, link) in self.rings.items():
            L = rolling.z_end - rolling.z_start
            z = 0.5 * (rolling.z_start + rolling.z_end)
            R_rings = self.rad * (_radial_R(self.spec, inner, float(rolling.r_in(z)), L)
                                  + _radial_R(self.spec, outer, float(rolling.r_out(z)), L))
            ring_in, ring_out = self.parts[name].masses
            self.add_between(Convection(f"bearing:{name}", Gc_W_K=_series(link.G_W_K, R_rings)),
                             ring_in, ring_out)

    # ------------------------------------------------------------------ air gap
    def add_air_gaps(self) -> None:
        """Rotor-stator gap films, one per pair of facing masses."""
        for lk in self.spec.links:
            if not isinstance(lk, AirGapLink):
                continue
            for (na, nb), pcs in self._air_gap_pieces(lk).items():
                self.add_between(Convection(f"air_gap:{na}-{nb}", Gc_W_K=_film(lk.h_W_m2K, pcs)),
                                 self.by_name[na], self.by_name[nb])

    def _air_gap_pieces(self, lk: AirGapLink) -> dict[tuple[str, str], list[tuple[float, float]]]:
        """(rotor-side area [m2], conduction resistance [K/W]) of each slice overlap across
        the gap, by pair of mass names."""
        pin, pout = self.spec.part(lk.inner), self.spec.part(lk.outer)
        pieces: dict[tuple[str, str], list[tuple[float, float]]] = {}
        for si in pin.sections:
            for so in pout.sections:
                a, b = max(si.z_start, so.z_start), min(si.z_end, so.z_end)
                if b - a <= TOL_M:
                    continue
                for p, q in self.cuts(a, b, pin, pout):
                    zm, dz = 0.5 * (p + q), q - p
                    ma, mb = self.owner(pin, si, zm), self.owner(pout, so, zm)
                    r = float(si.r_out(zm))
                    R = self.rad * (_radial_R(self.spec, si, r, dz)
                                    + _radial_R(self.spec, so, float(so.r_in(zm)), dz))
                    pieces.setdefault((ma.name, mb.name), []).append((2 * np.pi * r * dz, R))
        return pieces

    # ------------------------------------------------------------------ surfaces
    def face_pieces(self, f: Face) -> list[tuple[Mass, float, float]]:
        """(mass, area, conduction resistance to the face) for each slice the face crosses."""
        spec, rad = self.spec, self.rad
        part = spec.part(f.part)
        if f.is_line:
            out = []
            for p, q in self.cuts(f.lo, f.hi, part):
                piece = Face(f.part, f.section, f.side, p, q)
                zm = 0.5 * (p + q)
                m = self.owner(part, f.section, zm)
                if m is None:
                    continue
                out.append((m, piece.area_m2, rad * _radial_R(spec, f.section, f.radius(zm), q - p)))
            return out
        m = self.owner(part, f.section, f.z - TOL_M if f.side == "front" else f.z + TOL_M)
        if m is None:
            return []
        A = f.area_m2
        mid = 0.5 * (m.z_lo + m.z_hi)
        return [(m, A, rad * abs(f.z - mid) / (spec.materials[f.section.material].k_z_W_mK * A))]

    def add_films(self) -> dict[str, list[tuple[Mass, float, float]]]:
        """Film conductances of the surfaces with a film coefficient; returns the face pieces
        of every named surface (for the surface heat sources)."""
        faces = exposed_faces(self.spec)
        surface_map: dict[str, list[tuple[Mass, float, float]]] = {}
        problems = []
        filmed: list[tuple[str, Face]] = []  # (surface, face piece) of the films so far
        for s in self.spec.surfaces:
            selected = surface_faces(s, faces, self.spec)
            surface_map[s.name] = [p for f in selected for p in self.face_pieces(f)]
            if not surface_map[s.name]:  # its film or its source would vanish unseen
                problems.append(no_face_problem(self.spec, s))
            if s.h_W_m2K is None:
                continue
            clash = next((o for o, g in filmed for f in selected if faces_overlap(f, g)), None)
            if clash is not None:  # the boundary would lose its heat twice
                problems.append(film_clash_problem(self.spec, s, clash))
            filmed.extend((s.name, f) for f in selected)
            grouped: dict[str, list[tuple[float, float]]] = {}
            for m, A, R in surface_map[s.name]:
                grouped.setdefault(m.name, []).append((A, R))
            for mname, pcs in grouped.items():
                # the ambient or coolant port is added after the first film that uses it
                c = self.net.add(Convection(f"film:{s.name}:{mname}", Gc_W_K=_film(s.h_W_m2K, pcs)))
                self.net.connect(self.by_name[mname].block.port, c.port_a)
                self.net.connect(self.fixed(s.T_ref), c.port_b)
        if problems:  # as the FEM's mesh refuses them (meshes.build)
            raise SpecError(problems)
        return surface_map

    # ------------------------------------------------------------------ sources
    def add_sources(self, surface_map: dict[str, list[tuple[Mass, float, float]]]) -> None:
        """Each heat source split over masses by volume or area; bearing friction optionally
        rising with the ring temperature difference (``bearing_tc_1_K``)."""
        tc = self.bearing_tc_1_K
        for src in self.spec.heat_sources:
            if src.surface is not None:
                shares = _area_shares(surface_map[src.surface])
            else:
                shares = self._volume_shares(src)
            preload = None
            if tc and src.part is not None and self.parts[src.part].ring:
                inner_m, outer_m = self.parts[src.part].masses
                preload = (inner_m.block.port, outer_m.block.port)
            for mname, share in shares.items():
                q = self.net.add(PrescribedHeatFlow(f"source:{src.name}:{mname}", source=src.name,
                                                    share=share, tc_1_K=tc if preload else 0.0,
                                                    across=preload))
                self.net.connect(self.by_name[mname].block.port, q.port)

    def _volume_shares(self, src: HeatSource) -> dict[str, float]:
        """Fractions of a part (or section) source per mass, by volume; a bearing's rolling
        layer feeds both rings half each."""
        part = self.spec.part(src.part)
        secs = [s for s in part.sections if src.section is None or s.name == src.section]
        pm = self.parts[part.name]
        weights: dict[str, float] = {}
        for s in secs:
            if pm.ring:
                inner, rolling, outer, _ = self.rings[part.name]
                targets = [(pm.masses[0], 0.5), (pm.masses[1], 0.5)] if s is rolling else \
                    [(pm.at(0.0, s), 1.0)] if pm.at(0.0, s) else []
                for m, f in targets:
                    _add_to(weights, m.name, f * s.volume_m3)
            else:
                for m in pm.masses:
                    v = _volume(s, m.z_lo, m.z_hi)
                    if v > 0:
                        _add_to(weights, m.name, v)
        total = sum(weights.values())
        return {k: v / total for k, v in weights.items()}


def _area_shares(pieces: list[tuple[Mass, float, float]]) -> dict[str, float]:
    """Fractions of a surface source per mass, by the area of its face pieces."""
    shares: dict[str, float] = {}
    total = sum(A for _, A, _ in pieces)
    for m, A, _ in pieces:
        _add_to(shares, m.name, A / total)
    return shares


def _series(G: SpeedTable, R_extra: float):
    """Conductance of G(n) in series with a fixed resistance [K/W]."""
    if len(G.values) == 1:
        return 1.0 / (1.0 / G.values[0] + R_extra)
    return SpeedTable(G.speed_rpm, tuple(1.0 / (1.0 / g + R_extra) for g in G.values)) \
        if R_extra == 0 else _SeriesConductance(G, R_extra)


@dataclass(frozen=True)
class _SeriesConductance:
    G: SpeedTable
    R_extra: float

    def __call__(self, speed_rpm: float) -> float:
        return 1.0 / (1.0 / self.G(speed_rpm) + self.R_extra)


@dataclass(frozen=True)
class _FilmConductance:
    """Sum over face pieces of 1 / (R_i + 1 / (h(n) A_i)) [W/K]."""

    h: SpeedTable
    A: tuple[float, ...]
    R: tuple[float, ...]

    def __call__(self, speed_rpm: float) -> float:
        h = self.h(speed_rpm)
        if h <= 0:
            return 0.0
        # a few pieces: plain floats, as a fit evaluates this a million times
        pieces = zip(self.A, self.R, strict=True)
        return float(sum(1.0 / (R + 1.0 / (h * A)) for A, R in pieces))


def _film(h: SpeedTable, pieces: list[tuple[float, float]]):
    f = _FilmConductance(h, tuple(A for A, _ in pieces), tuple(R for _, R in pieces))
    return f(0.0) if len(h.values) == 1 else f
