"""Exposed faces of the spec's sections, and the faces a named surface selects.

Each section of the half-section has four faces: its ``outer`` and ``inner`` lines (radius as
a function of z) and its ``rear`` (z_start) and ``front`` (z_end) discs. A piece of a face is
exposed where no other section (of any part, or an air-gap layer) lies against it. This is
the same selection the mesh makes on boundary facets (meshes.build), done on the CAD lines,
so models that are not meshed (the lumped networks) see the same surfaces. Lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spindle.errors import Problem
from spindle.geometry import TOL_M, Trapezoid
from spindle.spec import AirGapLink, Section, Spec, Surface


@dataclass(frozen=True)
class Face:
    """A piece of a section face: lines span z in [lo, hi]; discs (rear, front) sit at ``z``
    and span r in [lo, hi]."""

    part: str
    section: Section
    side: str  # outer, inner, rear, front
    lo: float
    hi: float
    z: float = float("nan")

    @property
    def is_line(self) -> bool:
        return self.side in ("outer", "inner")

    def radius(self, z: float) -> float:
        """Radius of a line face at z [m]."""
        r = self.section.r_out if self.side == "outer" else self.section.r_in
        return float(r(z))

    @property
    def area_m2(self) -> float:
        """Area of the surface of revolution [m2] (exact for conical lines)."""
        if self.is_line:
            r0, r1 = self.radius(self.lo), self.radius(self.hi)
            return float(np.pi * (r0 + r1) * np.hypot(self.hi - self.lo, r1 - r0))
        return float(np.pi * (self.hi**2 - self.lo**2))

    def clip(self, z_min: float, z_max: float) -> Face | None:
        """The part of the face within z_min <= z <= z_max (None if nothing is left)."""
        if self.is_line:
            lo, hi = max(self.lo, z_min), min(self.hi, z_max)
            if hi - lo <= TOL_M:
                return None
            return Face(self.part, self.section, self.side, lo, hi)
        return self if z_min - TOL_M <= self.z <= z_max + TOL_M else None


def _subtract(lo: float, hi: float, cover: list[tuple[float, float]]) -> list[tuple[float, float]]:
    pieces = [(lo, hi)]
    for a, b in cover:
        nxt = []
        for p, q in pieces:
            if b <= p + TOL_M or a >= q - TOL_M:
                nxt.append((p, q))
                continue
            if a > p + TOL_M:
                nxt.append((p, a))
            if b < q - TOL_M:
                nxt.append((b, q))
        pieces = nxt
    return [(p, q) for p, q in pieces if q - p > TOL_M]


def _gap_layers(spec: Spec) -> list[Trapezoid]:
    """The air-gap layers between rotor and stator (meshed as regions by meshes.build)."""
    out = []
    for lk in spec.links:
        if not isinstance(lk, AirGapLink):
            continue
        for si in spec.part(lk.inner).sections:
            for so in spec.part(lk.outer).sections:
                z0, z1 = max(si.z_start, so.z_start), min(si.z_end, so.z_end)
                if z1 - z0 > TOL_M:
                    out.append(Trapezoid(z0, z1, (float(si.r_out(z0)), float(si.r_out(z1))),
                                         (float(so.r_in(z0)), float(so.r_in(z1)))))
    return out


def exposed_faces(spec: Spec) -> list[Face]:
    """Every exposed face piece of every section (not against another section or a gap)."""
    shapes: list[Trapezoid] = [s for _, s in spec.sections()] + _gap_layers(spec)
    faces: list[Face] = []
    for part, s in spec.sections():
        others = [t for t in shapes if t is not s]
        for side, mine, theirs in (("outer", s.r_out, "r_in"), ("inner", s.r_in, "r_out")):
            if side == "inner" and max(s.r_inner) <= TOL_M:
                continue  # on the axis
            cover = []
            for t in others:
                a, b = max(s.z_start, t.z_start), min(s.z_end, t.z_end)
                if b - a > TOL_M and all(abs(float(getattr(t, theirs)(z)) - float(mine(z)))
                                         <= TOL_M for z in (a, b)):
                    cover.append((a, b))
            faces += [Face(part.name, s, side, p, q)
                      for p, q in _subtract(s.z_start, s.z_end, sorted(cover))]
        for side, z, touching in (("rear", s.z_start, "z_end"), ("front", s.z_end, "z_start")):
            lo, hi = float(s.r_in(z)), float(s.r_out(z))
            cover = [(max(lo, float(t.r_in(z))), min(hi, float(t.r_out(z)))) for t in others
                     if abs(getattr(t, touching) - z) <= TOL_M]
            faces += [Face(part.name, s, side, p, q, z)
                      for p, q in _subtract(lo, hi, sorted(c for c in cover if c[1] > c[0]))]
    return faces


def closed_radii(spec: Spec, side: str, z: float) -> list[tuple[float, float]]:
    """The radii [m] at which a disc face at ``z`` facing ``side`` ("front": +z, "rear": -z)
    looks into a closed cavity rather than the open air: where its normal ray meets another
    section (a pocket between two parts), or where the air just beyond it lies inside a bore
    (radially inside another section: the bore of a shaft, a housing's interior). Sorted,
    possibly overlapping intervals. meshes.build applies the same test to boundary facets."""
    sign = 1.0 if side == "front" else -1.0
    z_next = z + sign * 10.0 * TOL_M
    out = []
    for _, t in spec.sections():
        beyond = (t.z_end > z + TOL_M) if sign > 0 else (t.z_start < z - TOL_M)
        if beyond:  # the ray meets it somewhere along its z span
            out.append((min(float(t.r_in(t.z_start)), float(t.r_in(t.z_end))),
                        max(float(t.r_out(t.z_start)), float(t.r_out(t.z_end)))))
        if t.z_start - TOL_M <= z_next <= t.z_end + TOL_M:
            r_in = float(t.r_in(z_next))
            if r_in > TOL_M:  # everything inside its bore
                out.append((0.0, r_in))
    return sorted(out)


def open_to_air(spec: Spec, face: Face) -> list[Face]:
    """The pieces of ``face`` that the open air reaches (what ``side = "any"`` selects): an
    outer line whole; an inner line (a bore) never; a disc where :func:`closed_radii` leaves
    it. The spec's cavity faces (a bore, a pocket between two parts, the inside of the
    housing) are adiabatic, as its comments say."""
    if face.is_line:
        return [face] if face.side == "outer" else []
    return [Face(face.part, face.section, face.side, p, q, face.z)
            for p, q in _subtract(face.lo, face.hi, closed_radii(spec, face.side, face.z))]


def no_face_problem(spec: Spec, surface: Surface) -> Problem:
    """The problem of a named surface that selects no exposed boundary (the FEM's mesh and
    the lumped network refuse it alike: a film or a source on it would vanish unseen)."""
    return Problem(spec.path, f"surfaces.{surface.name}", "selects no exposed boundary of "
                   f"{list(surface.parts)} (side '{surface.side}', z {surface.z_min:g}.."
                   f"{surface.z_max:g} m)", "check side and z limits: surfaces that touch "
                   "another part are not exposed")


def film_clash_problem(spec: Spec, surface: Surface, other: str) -> Problem:
    """The problem of a film surface on a boundary another film surface already covers (the
    FEM's mesh and the lumped network refuse it alike: the boundary would lose heat twice)."""
    return Problem(spec.path, f"surfaces.{surface.name}", "has a film coefficient on the same "
                   f"boundary as '{other}'", "narrow one of them with side or z_min/z_max")


def faces_overlap(a: Face, b: Face) -> bool:
    """Two face pieces share a piece of boundary longer than the geometric tolerance."""
    if a.part != b.part or a.section != b.section or a.side != b.side:
        return False
    if not a.is_line and abs(a.z - b.z) > TOL_M:
        return False
    return min(a.hi, b.hi) - max(a.lo, b.lo) > TOL_M


def surface_faces(surface: Surface, faces: list[Face], spec: Spec) -> list[Face]:
    """The exposed face pieces (``faces``: :func:`exposed_faces` of ``spec``) a named surface
    selects: its parts, its side, its z range; ``side = "any"`` selects what the open air
    reaches (:func:`open_to_air`)."""
    out = []
    for f in faces:
        if f.part not in surface.parts or (surface.side != "any" and f.side != surface.side):
            continue
        c = f.clip(surface.z_min, surface.z_max)
        if c is None:
            continue
        out.extend(open_to_air(spec, c) if surface.side == "any" else [c])
    return out
