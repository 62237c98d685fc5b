"""The geometry checks of a spec, made once its tables read cleanly: its size and units,
overlapping parts, links that join what they name, parts joined into one spindle, sensors
inside the solid, and a heat path from every part to a fixed temperature."""

from __future__ import annotations

import math

from spindle.geometry import TOL_M, contact_length, overlap
from spindle.spec import (
    BEARING_ROLES,
    MAX_AIR_GAP_M,
    AirGapLink,
    ContactLink,
    Link,
    Part,
    Section,
    Sensor,
    Surface,
)
from spindle.spec_fields import FieldReader

#: the largest dimension [m] of a motor spindle (the SPL2782 is 0.6 m long); beyond this a
#: spec is taken to be in millimetres
MAX_SIZE_M = 5.0
#: the most elements a spec's level-0 mesh may have (spl2782: 1379); every level adds 4x
MAX_LEVEL0_ELEMENTS = 200_000


def check_size(r: FieldReader, parts: list[Part], h0_m: float) -> None:
    """A spec in millimetres, and a mesh too fine to build, before any work is done."""
    secs = [s for p in parts for s in p.sections]
    size = max(max(abs(s.z_start), abs(s.z_end), *s.r_outer) for s in secs)
    if size > MAX_SIZE_M:
        unit = "millimetres" if size < MAX_SIZE_M * 1000 else "no plausible unit"
        r.add("parts", f"the geometry reaches {size:g} m from the origin, more than a motor "
              f"spindle's {MAX_SIZE_M:g} m: the dimensions look like {unit}",
              "give every length in metres (z, r and mesh.h0_m: divide millimetres by 1000)")
        return
    if h0_m > size:
        r.add("mesh.h0_m", f"{h0_m:g} m is larger than the whole spindle ({size:g} m)",
              "give an element size of millimetres to centimetres (spl2782 uses 0.01 m)")
        return
    area = sum(0.5 * (s.z_end - s.z_start) * ((s.r_outer[0] - s.r_inner[0])
                                              + (s.r_outer[1] - s.r_inner[1])) for s in secs)
    n0 = (area / h0_m) / h0_m if area > 0 else 0.0  # h0_m >= 1e-300: no overflow to inf
    if n0 > MAX_LEVEL0_ELEMENTS:
        h_min = math.sqrt(area / MAX_LEVEL0_ELEMENTS)
        r.add("mesh.h0_m", f"{h0_m:g} m meshes the {area * 1e4:.3g} cm2 section into about "
              f"{n0:.3g} elements at level 0 (limit {MAX_LEVEL0_ELEMENTS:g}; each level "
              "multiplies by 4)", f"give h0_m >= {h_min:.2g} m (spl2782 uses 0.01 m)")


def check_geometry(r: FieldReader, parts: list[Part], links: list[Link],
                    surfaces: list[Surface], sensors: list[Sensor]) -> None:
    """Overlaps, gaps where a link is required, sensors outside, and heat paths."""
    secs = [(p, j, s) for p in parts for j, s in enumerate(p.sections)]
    touching = _check_overlaps(r, parts, secs)
    if r.problems:
        return
    joined = _check_links(r, parts, links, touching)
    _check_parts_joined(r, parts, links, touching, joined)
    _check_sensors_inside(r, sensors, secs)
    if r.problems:
        return
    _check_heat_paths(r, parts, surfaces, joined)


def _check_overlaps(r: FieldReader, parts: list[Part],
                    secs: list[tuple[Part, int, Section]]) -> dict[str, set[str]]:
    """Sections must not overlap; returns the parts each part touches."""
    touching: dict[str, set[str]] = {p.name: set() for p in parts}
    for a in range(len(secs)):
        pa, ja, sa = secs[a]
        for b in range(a + 1, len(secs)):
            pb, jb, sb = secs[b]
            if overlap(sa, sb):
                r.add(f"parts[{parts.index(pb)}].sections[{jb}]",
                      f"part '{pb.name}' overlaps part '{pa.name}' (section {ja}) "
                      f"near z = {max(sa.z_start, sb.z_start):.4g} m",
                      "change the radii or z limits so the sections only touch")
            elif pa.name != pb.name and contact_length(sa, sb) > 0:
                touching[pa.name].add(pb.name)
                touching[pb.name].add(pa.name)
    return touching


def _check_links(r: FieldReader, parts: list[Part], links: list[Link],
                 touching: dict[str, set[str]]) -> dict[str, set[str]]:
    """An air gap must be a real, narrow gap; a contact link needs touching parts. Returns
    the parts each part exchanges heat with (touching or across an air gap)."""
    joined = {k: set(v) for k, v in touching.items()}
    for i, link in enumerate(links):
        if isinstance(link, AirGapLink):
            gaps = _air_gap_widths(parts, link)
            if not gaps:
                r.add(f"links[{i}]", f"'{link.inner}' and '{link.outer}' do not face each "
                      "other over any axial length", "make their z ranges overlap")
            elif min(gaps) <= TOL_M or max(gaps) > MAX_AIR_GAP_M:
                r.add(f"links[{i}]", f"the gap between '{link.inner}' and '{link.outer}' is "
                      f"{min(gaps) * 1e3:.3g}..{max(gaps) * 1e3:.3g} mm",
                      f"give the outer part's r_inner above the inner part's r_outer by "
                      f"0 < gap <= {MAX_AIR_GAP_M * 1e3:g} mm")
            else:
                joined[link.inner].add(link.outer)
                joined[link.outer].add(link.inner)
        elif isinstance(link, ContactLink):
            a, b = link.parts
            if b not in touching[a]:
                r.add(f"links[{i}].parts", f"'{a}' and '{b}' do not touch",
                      "a contact link needs parts that share a boundary: fix the radii")
    return joined


def _air_gap_widths(parts: list[Part], link: AirGapLink) -> list[float]:
    """Radial gap [m] at both ends of every z range where the inner and outer part face."""
    return [float(so.r_in(z) - si.r_out(z))
            for si in next(p for p in parts if p.name == link.inner).sections
            for so in next(p for p in parts if p.name == link.outer).sections
            for z in (max(si.z_start, so.z_start), min(si.z_end, so.z_end))
            if min(si.z_end, so.z_end) - max(si.z_start, so.z_start) > TOL_M]


def _check_parts_joined(r: FieldReader, parts: list[Part], links: list[Link],
                        touching: dict[str, set[str]], joined: dict[str, set[str]]) -> None:
    """No part stands alone, bearings sit between shaft and housing, and a rotor and a
    stator have an air-gap link."""
    roles = {p.name: p.role for p in parts}
    if any(p.role in BEARING_ROLES for p in parts) and "shaft" not in roles.values():
        r.add("parts", "no part has the role \"shaft\", which the bearings sit on",
              "give the spindle's shaft role = \"shaft\" (docs/spec.md, roles)")
    for p in parts:
        if len(parts) > 1 and not joined[p.name]:
            r.add(f"parts[{parts.index(p)}]", f"part '{p.name}' is separated from every other "
                  "part by a gap", "close the gap in its sections or add a [[links]] entry "
                  "(air_gap) that bridges it")
        if p.role in BEARING_ROLES:
            others = {roles[q] for q in touching[p.name]}
            if not others & {"shaft", "rotor"} or not others & {"housing", "cooling_sleeve"}:
                r.add(f"parts[{parts.index(p)}]", f"bearing '{p.name}' must touch the shaft "
                      "(inner ring) and the housing (outer ring)",
                      "set its r_inner to the shaft seat radius and r_outer to the housing bore")
    has_rotor = [p.name for p in parts if p.role == "rotor"]
    has_stator = [p.name for p in parts if p.role == "stator"]
    if has_rotor and has_stator and not any(isinstance(x, AirGapLink) for x in links):
        r.add("links", f"rotor '{has_rotor[0]}' and stator '{has_stator[0]}' have no air-gap "
              "link", "add [[links]] type = \"air_gap\" with inner/outer and h_W_m2K")


def _check_sensors_inside(r: FieldReader, sensors: list[Sensor],
                          secs: list[tuple[Part, int, Section]]) -> None:
    """Every sensor point lies in a part. An array's sensors outside have one cause, its
    radius: one problem per array, not one per sensor."""
    outside_of_array: dict[str, list[Sensor]] = {}
    for s in sensors:
        pts = [(s.z, s.r)] + ([(s.z_ref, s.r_ref)] if s.kind == "axial_displacement" else [])
        for z, rr in pts:
            if any(sec.contains(z, rr) for _, _, sec in secs):
                continue
            if s.array is not None:
                outside_of_array.setdefault(s.array, []).append(s)
            else:
                r.add(f"sensors.{s.name}", f"point (z = {z:g} m, r = {rr:g} m) is outside every "
                      "part", "move it into a part's section (z along the axis, r radius)")
    for name, out in outside_of_array.items():
        of = sum(s.array == name for s in sensors)
        r.add(f"sensor_arrays.{name}.radius", f"r = {out[0].r:g} m puts {len(out)} of the array's "
              f"{of} sensors outside every part (first {out[0].name} at z = {out[0].z:g} m)",
              'write radius = "mid", "inner", "outer" or a radius in m within the part')


def _check_heat_paths(r: FieldReader, parts: list[Part], surfaces: list[Surface],
                      joined: dict[str, set[str]]) -> None:
    """Every group of joined parts needs a path to a fixed temperature."""
    anchored = {x for s in surfaces if s.h_W_m2K is not None and s.h_W_m2K.max > 0
                for x in s.parts}
    seen: set[str] = set()
    for p in parts:
        if p.name in seen:
            continue
        group, stack = set(), [p.name]
        while stack:
            q = stack.pop()
            if q not in group:
                group.add(q)
                stack.extend(joined[q] - group)
        seen |= group
        if not group & anchored:
            r.add("surfaces", f"parts {sorted(group)} have no heat path to a fixed temperature "
                  "(the problem would be singular)", "add a [[surfaces]] entry with h_W_m2K > 0 "
                  "and T_ref = \"ambient\" or \"coolant\" on one of them")
