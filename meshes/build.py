"""Level-0 triangulation of a spec's sections, uniform refinement and facet classification.

Coordinates: ``p[0]`` is z (axial, from the shaft's rear end towards the tool) and ``p[1]``
is r (radius), both in m. The axis r = 0 is a boundary with the natural (symmetry) condition.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy.spatial import cKDTree
from skfem import MeshTri

from spindle.errors import Problem, SpecError
from spindle.faces import closed_radii, film_clash_problem, no_face_problem
from spindle.geometry import TOL_M, Trapezoid
from spindle.spec import AirGapLink, BearingLink, ContactLink, Material, Spec
from spindle.spec_reader import as_spec

#: Facets whose normal is within 45 degrees of +r are "outer", of -r "inner", of +z "front".
_SIDE_OF = {(True, True): "outer", (True, False): "inner",
            (False, True): "front", (False, False): "rear"}


@dataclass(frozen=True)
class Region:
    """A meshed piece of the half-section: a spec section, or a generated air-gap layer.

    ``kind`` is ``solid``, ``bearing`` (rolling layer whose conductivity comes from the
    bearing link ``link``) or ``air_gap`` (layer whose conductivity comes from the air-gap
    link ``link``).
    """

    part: str
    section: str
    material: Material
    shape: Trapezoid
    kind: str = "solid"
    link: int | None = None


@dataclass
class SpindleMesh:
    """A mesh of one refinement level with its regions, parts and named boundaries."""

    spec: Spec
    level: int
    mesh: MeshTri
    regions: list[Region]
    element_region: np.ndarray  # region index per element
    surfaces: dict[str, np.ndarray] = field(default_factory=dict)  # name -> facet indices
    contacts: list[tuple[int, np.ndarray, np.ndarray]] = field(default_factory=list)
    exposed: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))

    @cached_property
    def part_names(self) -> list[str]:
        names: list[str] = []
        for reg in self.regions:
            if reg.part not in names:
                names.append(reg.part)
        return names

    @cached_property
    def element_part(self) -> np.ndarray:
        """Index into :attr:`part_names` per element."""
        idx = np.array([self.part_names.index(r.part) for r in self.regions])
        return idx[self.element_region]

    def elements_of(self, part: str, section: str | None = None) -> np.ndarray:
        regs = [i for i, r in enumerate(self.regions)
                if r.part == part and (section is None or r.section == section)]
        return np.nonzero(np.isin(self.element_region, regs))[0]

    def counts(self, order: int = 2) -> dict[str, int]:
        """Elements, vertices and temperature DOFs (P1: vertices; P2: plus edge midpoints)."""
        m = self.mesh
        dofs = m.nvertices + (m.nfacets if order == 2 else 0)
        return {"level": self.level, "elements": int(m.nelements), "nodes": int(m.nvertices),
                "facets": int(m.nfacets), f"dofs_P{order}": int(dofs)}

    @property
    def h_max_m(self) -> float:
        """Longest element edge [m]."""
        p, f = self.mesh.p, self.mesh.facets
        return float(np.max(np.linalg.norm(p[:, f[0]] - p[:, f[1]], axis=0)))


# --------------------------------------------------------------------------- level 0


def _regions(spec: Spec) -> list[Region]:
    bearing = {(lk.part, lk.section): i for i, lk in enumerate(spec.links)
               if isinstance(lk, BearingLink)}
    out = []
    for part, sec in spec.sections():
        name = sec.name or f"section{part.sections.index(sec)}"
        key = (part.name, sec.name)
        shape = Trapezoid(sec.z_start, sec.z_end, sec.r_inner, sec.r_outer)
        if key in bearing:
            out.append(Region(part.name, name, spec.materials[sec.material], shape, "bearing",
                              bearing[key]))
        else:
            out.append(Region(part.name, name, spec.materials[sec.material], shape))
    air = spec.materials.get("air")
    if air is None:
        from spindle.spec_reader import shipped_materials
        air = shipped_materials()["air"]
    for i, lk in enumerate(spec.links):
        if not isinstance(lk, AirGapLink):
            continue
        for si in spec.part(lk.inner).sections:
            for so in spec.part(lk.outer).sections:
                z0, z1 = max(si.z_start, so.z_start), min(si.z_end, so.z_end)
                if z1 - z0 <= TOL_M:
                    continue
                shape = Trapezoid(z0, z1, (float(si.r_out(z0)), float(si.r_out(z1))),
                                  (float(so.r_in(z0)), float(so.r_in(z1))))
                out.append(Region(f"air_gap_{lk.inner}_{lk.outer}", f"{z0:.4f}", air, shape,
                                  "air_gap", i))
    return out


def _level0(spec: Spec, regions: list[Region]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    h0 = spec.h0_m
    cuts = sorted({round(z, 9) for r in regions for z in (r.shape.z_start, r.shape.z_end)})
    # a film on outer or inner faces that ends inside a section ends on a node line, so its
    # area is the spec's at every level (between two nodes it took a level's share of a facet)
    cuts = sorted({*cuts, *(round(z, 9) for s in spec.surfaces if s.side not in ("front", "rear")
                            for z in (s.z_min, s.z_max) if cuts[0] < z < cuts[-1])})
    zs: list[float] = []
    for a, b in zip(cuts, cuts[1:], strict=False):
        n = max(1, math.ceil((b - a) / h0 - 1e-9))
        zs.extend(a + (b - a) * k / n for k in range(n))
    zs.append(cuts[-1])
    nr = [max(1, math.ceil(max(r.shape.r_outer[0] - r.shape.r_inner[0],
                               r.shape.r_outer[1] - r.shape.r_inner[1]) / h0 - 1e-9))
          for r in regions]

    nodes: dict[tuple[float, float], int] = {}
    lines: dict[int, list[tuple[float, int]]] = {i: [] for i in range(len(zs))}

    def node(iz: int, r: float) -> None:
        key = (round(zs[iz], 9), round(r, 9))
        if key not in nodes:
            nodes[key] = len(nodes)
            lines[iz].append((r, nodes[key]))

    columns = []
    for c in range(len(zs) - 1):
        za, zb = zs[c], zs[c + 1]
        present = [k for k, r in enumerate(regions)
                   if r.shape.z_start <= za + TOL_M and r.shape.z_end >= zb - TOL_M]
        columns.append(present)
        for k in present:
            sh = regions[k].shape
            for iz, z in ((c, za), (c + 1, zb)):
                ri, ro = float(sh.r_in(z)), float(sh.r_out(z))
                for j in range(nr[k] + 1):
                    node(iz, ri + (ro - ri) * j / nr[k])
    for v in lines.values():
        v.sort()
    radii = {iz: [r for r, _ in v] for iz, v in lines.items()}

    def on_line(iz: int, lo: float, hi: float) -> list[tuple[float, int]]:
        a = bisect.bisect_left(radii[iz], lo - 1e-9)
        b = bisect.bisect_right(radii[iz], hi + 1e-9)
        return lines[iz][a:b]

    tris, tags = [], []
    for c, present in enumerate(columns):
        for k in present:
            sh = regions[k].shape
            left = on_line(c, float(sh.r_in(zs[c])), float(sh.r_out(zs[c])))
            right = on_line(c + 1, float(sh.r_in(zs[c + 1])), float(sh.r_out(zs[c + 1])))
            for tri in _zipper(left, right):
                tris.append(tri)
                tags.append(k)
    p = np.zeros((2, len(nodes)))
    for (z, r), i in nodes.items():
        p[:, i] = (z, r)
    return p, np.array(tris, dtype=np.int64).T, np.array(tags, dtype=np.int64)


def _zipper(left: list[tuple[float, int]], right: list[tuple[float, int]]) -> list[tuple]:
    """Triangulate the strip between two vertical node lines (left at smaller z), CCW."""
    def param(line: list[tuple[float, int]]) -> list[float]:
        lo, hi = line[0][0], line[-1][0]
        return [(r - lo) / (hi - lo) for r, _ in line]

    sl, sr = param(left), param(right)
    i = j = 0
    out = []
    while i < len(left) - 1 or j < len(right) - 1:
        if j == len(right) - 1 or (i < len(left) - 1 and sl[i + 1] <= sr[j + 1]):
            out.append((left[i][1], right[j][1], left[i + 1][1]))
            i += 1
        else:
            out.append((left[i][1], right[j][1], right[j + 1][1]))
            j += 1
    return out


def _split_contacts(spec: Spec, regions: list[Region], p: np.ndarray, t: np.ndarray,
                    tags: np.ndarray) -> np.ndarray:
    """Duplicate the nodes on each contact interface so the temperature may jump there.

    The second part of each contact link gets the copies. A node that a third part also
    uses stays with the first part (documented limitation at triple points).
    """
    part_of_el = np.array([regions[k].part for k in tags])
    new_p = [p]
    n = p.shape[1]
    for lk in spec.links:
        if not isinstance(lk, ContactLink):
            continue
        a, b = lk.parts
        in_a, in_b = part_of_el == a, part_of_el == b
        shared = np.intersect1d(np.unique(t[:, in_a]), np.unique(t[:, in_b]))
        if len(shared) < 2:
            continue
        remap = np.arange(n + len(shared))
        remap[shared] = n + np.arange(len(shared))
        new_p.append(np.hstack(new_p)[:, shared])  # shared may include earlier copies
        t[:, in_b] = remap[t[:, in_b]]
        n += len(shared)
    return np.hstack(new_p)


# level-0 meshes of the last few specs; the spec object is kept so its id stays unique
_LEVEL0: dict[int, tuple[Spec, list[Region], MeshTri, np.ndarray]] = {}


#: the most elements a mesh may have: level 6 of spl2782 (5.6 million) takes 72 s and 2 GB to
#: mesh, and its P2 assembly and solve several times that; 2e7 is what a 24 GB machine can
#: still mesh (a spec with a fine h0_m asked for 90 million at level 6, killed after 3 min)
MAX_ELEMENTS = 20_000_000


def build_mesh(spec: Spec | str, level: int = 0) -> SpindleMesh:
    """Mesh of ``spec`` (a Spec, a shipped name or a path) at refinement ``level`` (each
    level halves every edge of level 0)."""
    spec = as_spec(spec)
    if level < 0 or level > 8:
        raise SpecError([Problem(spec.path, "level", f"{level} is out of range",
                                 "give a level between 0 and 8")])
    if id(spec) not in _LEVEL0 or _LEVEL0[id(spec)][0] is not spec:
        regions = _regions(spec)
        p, t, tags = _level0(spec, regions)
        p = _split_contacts(spec, regions, p, t, tags)
        if len(_LEVEL0) >= 4:
            _LEVEL0.pop(next(iter(_LEVEL0)))
        _LEVEL0[id(spec)] = (spec, regions, MeshTri(p, np.ascontiguousarray(t)), tags)
    _, regions, m0, tags = _LEVEL0[id(spec)]
    check_level(spec, level)  # before the refinement asks for the memory
    mesh = m0.refined(level) if level else m0
    # uniform refinement numbers the 4 children of element i as i + k * nelements
    element_region = np.tile(tags, 4 ** level)
    sm = SpindleMesh(spec, level, mesh, regions, element_region)
    _classify_facets(sm)
    # the same names on the scikit-fem mesh, for users who assemble their own forms
    sm.mesh = mesh.with_subdomains({n: sm.elements_of(n) for n in sm.part_names}) \
        .with_boundaries(dict(sm.surfaces))
    return sm


def check_level(spec: Spec, level: int) -> None:
    """SpecError naming ``level`` where its mesh would have more than :data:`MAX_ELEMENTS`
    (level 0's count times 4 per level; level 0 is meshed, and kept, to count)."""
    if id(spec) not in _LEVEL0 or _LEVEL0[id(spec)][0] is not spec:
        build_mesh(spec, 0)
    n0 = _LEVEL0[id(spec)][2].t.shape[1]
    if n0 * 4 ** level > MAX_ELEMENTS:
        raise SpecError([Problem(spec.path, "level", f"level {level} of this spec would have "
                                 f"{n0 * 4 ** level:.3g} elements, more than "
                                 f"{MAX_ELEMENTS:.0e}", "give a level of at most "
                                 f"{int(np.log(MAX_ELEMENTS / n0) / np.log(4))}, or a coarser "
                                 "mesh.h0_m")])


def _classify_facets(sm: SpindleMesh) -> None:
    m, spec = sm.mesh, sm.spec
    bf = m.boundary_facets()
    a, b = m.p[:, m.facets[0, bf]], m.p[:, m.facets[1, bf]]
    mid = 0.5 * (a + b)
    on_axis = (np.abs(a[1]) < TOL_M) & (np.abs(b[1]) < TOL_M)
    # contact interfaces: two boundary facets at the same place (split nodes)
    tree = cKDTree(mid.T)
    pairs = tree.query_pairs(r=1e-9 + 1e-6 * sm.h_max_m, output_type="ndarray")
    paired = np.zeros(len(bf), dtype=bool)
    paired[pairs.ravel()] = True
    elem = m.f2t[0, bf]
    part_idx = sm.element_part[elem]
    names = sm.part_names
    for i, lk in enumerate(spec.links):
        if not isinstance(lk, ContactLink):
            continue
        ia, ib = names.index(lk.parts[0]), names.index(lk.parts[1])
        pa, pb = part_idx[pairs[:, 0]], part_idx[pairs[:, 1]]
        fwd = (pa == ia) & (pb == ib)
        rev = (pa == ib) & (pb == ia)
        fa = np.concatenate([bf[pairs[fwd, 0]], bf[pairs[rev, 1]]])
        fb = np.concatenate([bf[pairs[fwd, 1]], bf[pairs[rev, 0]]])
        sm.contacts.append((i, fa, fb))
    exposed = ~on_axis & ~paired
    # outward normal: perpendicular to the facet, pointing away from the element centroid
    d = b - a
    normal = np.vstack([d[1], -d[0]])
    centroid = m.p[:, m.t[:, elem]].mean(axis=1)
    flip = np.sum(normal * (mid - centroid), axis=0) < 0
    normal[:, flip] *= -1
    radial = np.abs(normal[1]) >= np.abs(normal[0])
    positive = np.where(radial, normal[1] > 0, normal[0] > 0)
    side = np.array([_SIDE_OF[(bool(r), bool(s))] for r, s in zip(radial, positive, strict=True)])
    sm.exposed = bf[exposed]
    owner: dict[int, str] = {}
    problems = []
    for s in spec.surfaces:
        sel = (exposed & np.isin(part_idx, [names.index(x) for x in s.parts])
               & (mid[0] >= s.z_min - TOL_M) & (mid[0] <= s.z_max + TOL_M))
        if s.side != "any":
            sel &= side == s.side
        else:  # what the open air reaches (spindle.faces.open_to_air): no bore, no pocket
            sel &= side != "inner"
            closed: dict[tuple[str, float], list] = {}
            for k in np.nonzero(sel & np.isin(side, ("front", "rear")))[0]:
                key = (str(side[k]), round(float(mid[0, k]), 9))
                if key not in closed:
                    closed[key] = closed_radii(spec, *key)
                r = float(mid[1, k])
                sel[k] = not any(a + TOL_M < r < b - TOL_M for a, b in closed[key])
        facets = bf[sel]
        if len(facets) == 0:
            problems.append(no_face_problem(spec, s))
            continue
        if s.h_W_m2K is not None:
            clash = [owner[f] for f in facets if f in owner]
            if clash:
                problems.append(film_clash_problem(spec, s, clash[0]))
            owner.update(dict.fromkeys(facets.tolist(), s.name))
        sm.surfaces[s.name] = facets
    if problems:
        raise SpecError(problems)
