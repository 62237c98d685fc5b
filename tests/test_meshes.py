"""Meshes from CAD dimensions: conforming, nested, geometrically exact, named."""

import math

import numpy as np
import pytest
from skfem import Basis, ElementTriP0, Functional

from meshes import build_mesh
from spindle.spec_reader import load_spec


@Functional
def _r_area(w):
    return w.x[1]


def part_volumes(sm) -> dict[str, float]:
    b = Basis(sm.mesh, ElementTriP0())
    per_el = _r_area.elemental(b) * 2 * math.pi
    return {name: float(per_el[sm.element_part == i].sum())
            for i, name in enumerate(sm.part_names)}


@pytest.mark.parametrize("name", ["spl2782", "fin-shaft"])
def test_volumes_are_exact(name):
    """Straight-sided sections are meshed exactly: 2 pi int r dA per part equals the CAD
    volume (Simpson on linear radii) to round-off, at every level."""
    spec = load_spec(name)
    for level in (0, 1):
        vols = part_volumes(build_mesh(spec, level))
        for p in spec.parts:
            exact = sum(s.volume_m3 for s in p.sections)
            assert vols[p.name] == pytest.approx(exact, rel=1e-12), p.name


def test_levels_are_nested_with_ratio_two():
    spec = load_spec("spl2782")
    m0, m1, m2 = (build_mesh(spec, k) for k in range(3))
    assert m1.mesh.nelements == 4 * m0.mesh.nelements
    assert m2.h_max_m == pytest.approx(m0.h_max_m / 4)
    # every vertex of level k is a vertex of level k + 1
    from scipy.spatial import cKDTree

    d, _ = cKDTree(m1.mesh.p.T).query(m0.mesh.p.T)
    assert d.max() < 1e-12
    assert m1.mesh.nvertices == m0.counts(2)["dofs_P2"]


def test_conforming_apart_from_contact_interfaces():
    """Every interior edge has two elements; boundary edges are the outer boundary, the
    axis, or one side of a contact interface (whose nodes are split on purpose)."""
    spec = load_spec("spl2782")
    sm = build_mesh(spec, 1)
    m = sm.mesh
    bf = m.boundary_facets()
    contact = np.concatenate([np.r_[fa, fb] for _, fa, fb in sm.contacts])
    on_axis = np.nonzero(np.all(m.p[1, m.facets[:, bf]] < 1e-12, axis=0))[0]
    assert len(bf) == len(sm.exposed) + len(contact) + len(on_axis)
    # a hanging node would show as an exposed edge inside the body: none lie strictly inside
    # the bounding box of a single part's interior
    assert len(np.intersect1d(sm.exposed, contact)) == 0


def test_named_subdomains_and_boundaries():
    spec = load_spec("spl2782")
    sm = build_mesh(spec, 0)
    for p in spec.parts:
        assert len(sm.elements_of(p.name)) > 0
    for s in spec.surfaces:
        assert len(sm.surfaces[s.name]) > 0
    assert len(sm.elements_of("front_bearing", "rolling")) > 0


def test_counts():
    sm = build_mesh(load_spec("fin-shaft"), 1)
    c1, c2 = sm.counts(1), sm.counts(2)
    assert c1["dofs_P1"] == sm.mesh.nvertices
    assert c2["dofs_P2"] == sm.mesh.nvertices + sm.mesh.nfacets


def test_vtu_and_png(tmp_path):
    import pyvista as pv

    from meshes.io import mesh_png, save_mesh_vtu

    sm = build_mesh(load_spec("spl2782"), 0)
    save_mesh_vtu(sm, tmp_path / "m.vtu")
    grid = pv.read(tmp_path / "m.vtu")
    assert grid.n_cells == sm.mesh.nelements
    assert set(np.unique(grid.cell_data["part_id"])) == set(range(len(sm.part_names)))
    mesh_png(sm, tmp_path / "m.png")
    assert (tmp_path / "m.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_names_on_the_skfem_mesh():
    sm = build_mesh(load_spec("spl2782"), 1)
    assert set(sm.mesh.subdomains) == set(sm.part_names)
    np.testing.assert_array_equal(sm.mesh.boundaries["housing_outer"], sm.surfaces["housing_outer"])


def _facet_area_m2(sm, facets) -> float:
    """2 pi int r ds over boundary facets (exact for straight facets)."""
    m = sm.mesh
    a, b = m.p[:, m.facets[0, facets]], m.p[:, m.facets[1, facets]]
    return float(np.sum(2 * math.pi * 0.5 * (a[1] + b[1]) * np.hypot(*(b - a))))


@pytest.mark.parametrize("name", ["spl2782", "fin-shaft"])
def test_mesh_films_are_the_cad_surfaces(name):
    """The mesh's facets of every named surface have the area of the faces spindle.faces
    selects on the CAD lines (the lumped models use those), at two levels."""
    from spindle.faces import exposed_faces, surface_faces

    spec = load_spec(name)
    faces = exposed_faces(spec)
    for level in (0, 1):
        sm = build_mesh(spec, level)
        for s in spec.surfaces:
            cad = sum(f.area_m2 for f in surface_faces(s, faces, spec))
            assert _facet_area_m2(sm, sm.surfaces[s.name]) == pytest.approx(cad, rel=1e-9), s.name


def test_open_air_surfaces_leave_the_cavities_out():
    """Issue 15 §3: ``side = "any"`` is what the open air reaches. Hand counts from the spec's
    dimensions: the nose (r 0.065, z 0.490-0.5295) outside and its front ring (r 0.040-0.065),
    the HSK flange (r 0.040, 30 mm) and its front ring (r 0.025-0.040), the dummy tool
    (r 0.025, 170 mm) and its end; the rear end (r 0.035, 20 mm) and its ring (r 0.0125-0.035).
    Not the HSK bore (r 0.030), the faces at z = 0.490, the tool's rear face in the bore, nor
    the drawbar bore (r 0.0125): cavities, adiabatic as the spec's comments say."""
    from spindle.faces import exposed_faces, surface_faces

    spec = load_spec("spl2782")
    faces = exposed_faces(spec)
    pi = math.pi
    front = (2 * pi * 0.065 * (0.5295 - 0.490) + pi * (0.065**2 - 0.040**2)
             + 2 * pi * 0.040 * 0.030 + pi * (0.040**2 - 0.025**2)
             + 2 * pi * 0.025 * 0.170 + pi * 0.025**2)
    rear = 2 * pi * 0.035 * 0.020 + pi * (0.035**2 - 0.0125**2)
    area = {s.name: sum(f.area_m2 for f in surface_faces(s, faces, spec)) for s in spec.surfaces}
    assert area["shaft_front_free"] == pytest.approx(front, rel=1e-9)
    assert area["shaft_rear_free"] == pytest.approx(rear, rel=1e-9)


def test_a_spec_scaled_in_radius_is_the_same_spindle_slimmer():
    """spindle.stretch.scale_radially (the other spindles of bench_families --geometry): the
    meshed volume (sum of 2 pi r_centroid x triangle area, exact for the straight-sided
    triangles) scales by the factor squared, to round-off, and the sensors' radii by the
    factor, each still inside a section."""
    from spindle.stretch import scale_radially

    def volume(m) -> float:
        p, t = m.mesh.p, m.mesh.t  # p[0] = z, p[1] = r
        a, b, c = p[:, t[0]], p[:, t[1]], p[:, t[2]]
        area = 0.5 * np.abs((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
        return float(np.sum(2 * math.pi * (a[1] + b[1] + c[1]) / 3 * area))

    spec = load_spec("spl2782")
    slim = scale_radially(spec, 0.8)
    assert volume(build_mesh(slim, 0)) == pytest.approx(0.64 * volume(build_mesh(spec, 0)),
                                                        rel=1e-12)
    assert [s.r for s in slim.sensors] == pytest.approx([0.8 * s.r for s in spec.sensors])
    sections = [sec for p in slim.parts for sec in p.sections]
    assert all(any(sec.contains(s.z, s.r) for sec in sections) for s in slim.sensors)


def test_a_film_that_ends_inside_a_section_has_the_same_area_at_every_level():
    """ms12 (a user's spec) ends its shaft_rear_free film at z = 14 mm, inside the shaft's
    rear section: its area was 28.9, 28.9, 26.5 and 27.7 cm2 at levels 0-3 (a facet across
    the limit counted or not by its midpoint), and the study's grid convergence oscillated.
    The limit is now a node line at every level (meshes.build._level0)."""
    from pathlib import Path

    spec = load_spec(Path(__file__).resolve().parent / "data" / "own-specs" / "ms12.toml")
    areas = []
    for level in range(3):
        sm = build_mesh(spec, level)
        p = sm.mesh.p[:, sm.mesh.facets[:, sm.surfaces["shaft_rear_free"]]]
        length = np.hypot(p[0, 0] - p[0, 1], p[1, 0] - p[1, 1])
        areas.append(float(np.sum(2 * np.pi * 0.5 * (p[1, 0] + p[1, 1]) * length)))
        assert np.max(p[0]) == pytest.approx(0.014, abs=1e-12)  # it ends at its limit
    assert areas == pytest.approx([areas[0]] * 3, rel=1e-12)
