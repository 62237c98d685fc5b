"""CalculiX input decks from the reference's assembled data: the P2 mesh node for node (r-z
swapped, elements renumbered counterclockwise), DCAX6 steady heat transfer and CAX6 static
thermoelasticity, with the reference's films, sources, contacts and bearing layers.

CalculiX conventions handled here (see docs/crosscheck.md): axisymmetric elements live in the
x-y plane with x = radius and y = axial coordinate, so our (z, r) become (r, z); ccx's 6-node
triangle has the corner nodes first, then the mid-side nodes of edges 1-2, 2-3, 3-1, and face k
of a triangle is its edge k; distributed fluxes and films are per unit area of the real surface
(W/m2), body fluxes per unit volume (W/m3). Units SI; temperatures as rises above a datum."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from skfem import Basis, ElementTriP0, ElementTriP2, FacetBasis, asm

from reference.elastic import FLOATING_SHEAR
from reference.forms import conduction, surface_flux, volume_source
from reference.simulation import ReferenceModel
from reference.thermal import TWO_PI, layer_conductivity_factor
from spindle.errors import InputError, SolverError
from spindle.loads import LoadCase
from spindle.spec import BearingLink, ContactLink

#: Quadrature of ccx's DCAX6/CAX6 (found by reproducing single-element ccx results with
#: scikit-fem): the 3-point rule of degree 2 over the triangle, 2-point Gauss on a face.
CCX_VOLUME_INTORDER = 2


CCX_FACE_INTORDER = 3


#: ccx's face-to-face gap conductance integrates the matching interface exactly (as the
#: reference does)
CCX_CONTACT_INTORDER = 5


#: ccx expands a CAX6 section into a 2-degree C3D15 wedge (+-1 degree): the hoop strain of the
#: expanded element is exact only to O(theta^2), theta = 1 degree in radians
EXPANSION_REL = (math.pi / 180.0) ** 2


_PER_LINE = 10  # ids per line in *ELSET / *NSET (ccx reads at most 16 per line)


@dataclass
class CcxMesh:
    """The reference's P2 mesh in ccx numbering: node id = scikit-fem DOF index + 1."""

    rz: np.ndarray  # (N, 2) node coordinates r, z [m]
    conn: np.ndarray  # (ne, 6) ccx connectivity, 1-based, counterclockwise in (r, z)
    face_of: dict[int, tuple[int, int]]  # boundary facet -> (element id, ccx face 1..3)
    facet_nodes: np.ndarray  # (3, nfacets) 0-based DOFs of each facet: ends and middle


def _ccx_mesh(model: ReferenceModel) -> CcxMesh:
    th = model.thermal
    if th.order != 2:
        raise InputError("crosscheck", "order", f"the CalculiX deck needs P2 elements, not "
                         f"P{th.order}", "build the ReferenceModel with order=2")
    mesh, basis = th.smesh.mesh, th.basis
    dofs = basis.element_dofs  # (6, ne): vertices t0, t1, t2, then edges (t0t1, t1t2, t0t2)
    loc = basis.doflocs
    for k, (a, b) in enumerate(((0, 1), (1, 2), (0, 2))):
        mid = 0.5 * (loc[:, dofs[a]] + loc[:, dofs[b]])
        if np.max(np.abs(loc[:, dofs[3 + k]] - mid)) > 1e-12:
            raise SolverError("unexpected scikit-fem P2 DOF layout (edge midpoints)")
    xy = loc[::-1]  # ccx's (x, y) = our (r, z): swapping the axes flips the orientation
    a = xy[:, dofs[1]] - xy[:, dofs[0]]
    b = xy[:, dofs[2]] - xy[:, dofs[0]]
    ccw = a[0] * b[1] - a[1] * b[0] > 0
    # ccx order: corners counterclockwise, then mid-sides of 1-2, 2-3, 3-1
    conn = np.where(ccw, dofs[[0, 1, 2, 3, 4, 5]], dofs[[0, 2, 1, 5, 4, 3]]).T + 1
    # ccx face k joins corner k and corner k+1 (1-based, cyclic)
    face_of: dict[int, tuple[int, int]] = {}
    nv = mesh.nvertices
    facet_nodes = np.vstack([mesh.facets, nv + np.arange(mesh.nfacets)])
    bf = mesh.boundary_facets()
    elem = mesh.f2t[0, bf]
    for f, e in zip(bf.tolist(), elem.tolist(), strict=True):
        ends = {int(mesh.facets[0, f]) + 1, int(mesh.facets[1, f]) + 1}
        c = conn[e]
        for k in range(3):
            if {int(c[k]), int(c[(k + 1) % 3])} == ends:
                face_of[f] = (e + 1, k + 1)
                break
        else:  # pragma: no cover - a facet always belongs to its element
            raise SolverError(f"boundary facet {f} is not an edge of element {e}")
    return CcxMesh(xy.T.copy(), conn, face_of, facet_nodes)


@dataclass
class ThermalData:
    """Everything the heat-transfer deck needs, per element or per boundary facet."""

    k_r: np.ndarray  # (ne,) radial conductivity [W/m/K]
    k_z: np.ndarray  # (ne,) axial conductivity [W/m/K]
    q_body: np.ndarray  # (ne,) volumetric source [W/m3]
    q_face: dict[int, float]  # boundary facet -> flux into the body [W/m2]
    films: list[tuple[int, float, float, str]]  # (facet, h [W/m2/K], T_sink [K], surface)
    contacts: list[tuple[ContactLink, np.ndarray, np.ndarray]]  # (link, facets A, facets B)
    speed_rpm: float
    T_ambient_K: float
    checks: dict[str, float] = field(default_factory=dict)


def _facet_r_ds(mesh, facets: np.ndarray) -> np.ndarray:
    """int r ds over each straight facet [m2] (exact: r is linear along it)."""
    p = mesh.p[:, mesh.facets[:, facets]]  # (2, 2, n)
    length = np.linalg.norm(p[:, 1] - p[:, 0], axis=0)
    return length * 0.5 * (p[1, 0] + p[1, 1])


def _thermal_inputs(model: ReferenceModel, case: LoadCase, t: float = 0.0) -> ThermalData:
    """Per-element conductivities and sources, films and contacts of ``case`` at ``t`` [s].

    The element conductivities are those the reference assembles (solid k_r, k_z, plus the
    bearing and air-gap layers' link value times the layer factor); they are checked by
    re-assembling them and comparing with the reference's operator (``checks``).
    """
    th, spec = model.thermal, model.spec
    sm, mesh = th.smesh, th.smesh.mesh
    n = float(case.speed_rpm(t))
    kr, kz, _ = th.element_fields()
    kr, kz = kr.astype(float).copy(), kz.astype(float).copy()
    for li, lk in enumerate(spec.links):
        if isinstance(lk, ContactLink):
            continue
        value = lk.G_W_K(n) if isinstance(lk, BearingLink) else lk.h_W_m2K(n)
        for ri, reg in enumerate(sm.regions):
            if reg.link == li:
                els = sm.element_region == ri
                k = layer_conductivity_factor(reg.shape, reg.kind) * value
                kr[els] += k
                kz[els] += k
    # the same matrix as the reference's K_solid + sum_l g_l(n) K_l ?
    p0 = th.basis.with_element(ElementTriP0())
    K_mine = asm(conduction, th.basis, kr=p0.interpolate(kr), kz=p0.interpolate(kz))
    K_ref = th.op.K_solid.copy()
    for lk, A in th.op.links:
        K_ref = K_ref + (lk.G_W_K(n) if isinstance(lk, BearingLink) else lk.h_W_m2K(n)) * A
    checks = {"conduction_rel_diff": float(abs(K_mine - K_ref).max() / abs(K_ref).max())}

    # sources: uniform per part/section volume, or per surface area, as the reference
    ne = mesh.nelements
    q_body = np.zeros(ne)
    q_face: dict[int, float] = {}
    pv = mesh.p[:, mesh.t]  # (2, 3, ne)
    area = 0.5 * np.abs((pv[0, 1] - pv[0, 0]) * (pv[1, 2] - pv[1, 0])
                        - (pv[0, 2] - pv[0, 0]) * (pv[1, 1] - pv[1, 0]))
    vol = TWO_PI * area * pv[1].mean(axis=0)  # exact volume of each revolved triangle [m3]
    for src in spec.heat_sources:
        P = float(case.sources.get(src.name, src.power_W)(t))
        if src.surface is not None:
            facets = sm.surfaces[src.surface]
            q = P / (TWO_PI * _facet_r_ds(mesh, facets).sum())
            for f in facets.tolist():
                q_face[f] = q_face.get(f, 0.0) + q
        else:
            els = sm.elements_of(src.part, src.section)
            q_body[els] += P / vol[els].sum()
    T_ref = {"ambient": float(case.T_ambient_K(t)), "coolant": float(case.T_coolant_K(t))}
    films = []
    for s in spec.surfaces:
        if s.h_W_m2K is None:
            continue
        h = s.h_W_m2K(n)
        films.extend((f, h, T_ref[s.T_ref], s.name) for f in sm.surfaces[s.name].tolist())
    contacts = [(spec.links[li], fa, fb) for li, fa, fb in sm.contacts if len(fa)]
    data = ThermalData(kr, kz, q_body, q_face, films, contacts, n, T_ref["ambient"], checks)
    # the same load vector as the reference's?
    F_mine = load_vector(model, data, intorder=2 * th.order + 1)
    F_ref = th.op.F(case, t, n)
    checks["load_rel_diff"] = float(np.abs(F_mine - F_ref).max() / np.abs(F_ref).max())
    return data


def load_vector(model: ReferenceModel, data: ThermalData, intorder: int,
                 face_intorder: int | None = None, datum: float = 0.0) -> np.ndarray:
    """Load vector (without the 2 pi) of the sources and film sinks of ``data``, assembled
    with the given quadrature; temperatures relative to ``datum`` [K]."""
    th = model.thermal
    mesh = th.smesh.mesh
    face_intorder = face_intorder or intorder
    b = Basis(mesh, ElementTriP2(), intorder=intorder)
    F = asm(volume_source, b, q=b.with_element(ElementTriP0()).interpolate(data.q_body))
    by_value: dict[float, list[int]] = {}
    for f, q in data.q_face.items():
        by_value.setdefault(q, []).append(f)
    for f, h, T, _ in data.films:
        by_value.setdefault(h * (T - datum), []).append(f)
    for q, facets in by_value.items():
        fb = FacetBasis(mesh, ElementTriP2(), facets=np.array(facets), intorder=face_intorder)
        F = F + asm(surface_flux, fb, qs=q)
    return F


def _ids(values) -> list[str]:
    vals = [str(int(v)) for v in values]
    return [", ".join(vals[i:i + _PER_LINE]) for i in range(0, len(vals), _PER_LINE)]


def _g(x: float) -> str:
    """A float for ccx, which reads at most 20 characters a field: 14 significant digits."""
    s = repr(float(x))
    return s if len(s) <= 20 else f"{x:.13e}"


def _write_mesh(lines: list[str], cm: CcxMesh, etype: str) -> None:
    lines.append("*NODE, NSET=NALL")
    lines.extend(f"{i + 1}, {_g(r)}, {_g(z)}, 0." for i, (r, z) in enumerate(cm.rz))
    lines.append(f"*ELEMENT, TYPE={etype}, ELSET=EALL")
    lines.extend(f"{e + 1}, " + ", ".join(str(int(v)) for v in c) for e, c in enumerate(cm.conn))


def _groups(keys: list[tuple]) -> dict[tuple, np.ndarray]:
    """Element ids (1-based) grouped by their property tuple."""
    out: dict[tuple, list[int]] = {}
    for e, k in enumerate(keys):
        out.setdefault(k, []).append(e + 1)
    return {k: np.array(v) for k, v in out.items()}


def write_thermal_deck(model: ReferenceModel, case: LoadCase, path: Path, t: float = 0.0):
    """Write the heat-transfer deck; return (description, mesh, thermal data, constraints)."""
    if path.suffix != ".inp":
        path = path.with_suffix(".inp")
    cm = _ccx_mesh(model)
    data = _thermal_inputs(model, case, t)
    datum = data.T_ambient_K
    path.write_text("\n".join(_thermal_deck(model, cm, data, datum)) + "\n", encoding="utf-8")
    con = _elastic_constraints(model, cm)
    info = {"thermal_deck": path, "elastic_deck": None, "nodes": len(cm.rz),
            "elements": len(cm.conn), "T_datum_K": datum, "speed_rpm": data.speed_rpm,
            "films": len(data.films), "contacts": len(data.contacts),
            "ties": con["ties"], "support_node": con["support"] + 1,
            "axis_nodes": int(con["fixed_r"].sum()),
            "checks": {**data.checks, **_elastic_checks(model, cm, con)}}
    return info, cm, data, con


def export_deck(model: ReferenceModel, case: LoadCase | None, path: str | Path,
                temperatures: np.ndarray | None = None, t: float = 0.0) -> dict:
    """Write the ccx heat-transfer deck of ``model`` (P2) under ``case`` at time ``t`` [s].

    ``path`` is the deck ``<name>.inp`` (DCAX6, steady heat transfer). With nodal
    ``temperatures`` [K] (one per P2 node, e.g. the heat-transfer run's results) the
    thermoelastic deck ``<name>_elastic.inp`` (CAX6, linear static) is written too. Units: m,
    K, W, Pa; temperatures in the decks are rises above ``T_datum_K`` (the case's ambient).

    Returns the deck paths, counts, the datum, and ``checks``: relative differences between
    the deck's coefficients re-assembled with scikit-fem and the reference's own operators,
    and whether the deck's constraints fix and tie the reference's DOFs (round-off / True
    when the deck holds what the reference solves).
    """
    info, cm, _, con = write_thermal_deck(model, case or model.spec.default_load_case(), Path(path), t)
    if temperatures is not None:
        stem = info["thermal_deck"].stem
        info["elastic_deck"] = write_elastic(model, cm, con, info["thermal_deck"].with_name(
            f"{stem}_elastic.inp"), temperatures, info["T_datum_K"])
    return info


def export_elastic_deck(model: ReferenceModel, path: str | Path, temperatures: np.ndarray,
                        datum: float | None = None) -> Path:
    """Write the thermoelastic ccx deck (CAX6, linear static) for nodal ``temperatures`` [K].

    The stress-free temperature is the spec's ``T_initial_K``; temperatures are written as
    rises above ``datum`` [K] (default: the spec's ambient). Returns the deck's path.
    """
    cm = _ccx_mesh(model)
    return write_elastic(model, cm, _elastic_constraints(model, cm), Path(path), temperatures,
                          model.spec.T_ambient_K if datum is None else float(datum))


def write_elastic(model: ReferenceModel, cm: CcxMesh, con: dict, path: Path,
                   temperatures: np.ndarray, datum: float) -> Path:
    if path.suffix != ".inp":
        path = path.with_suffix(".inp")
    T = np.asarray(temperatures, dtype=float)
    if T.shape != (len(cm.rz),) or not np.all(np.isfinite(T)):
        raise InputError(str(path), "temperatures", f"need {len(cm.rz)} finite nodal values, "
                         f"got shape {T.shape}", "pass the P2 nodal temperatures in K")
    lines = _elastic_deck(model, cm, datum, T, con)
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _thermal_deck(model: ReferenceModel, cm: CcxMesh, data: ThermalData, datum: float) -> list[str]:
    spec = model.spec
    lines = ["*HEADING",
             f"spindle-verify crosscheck: {spec.name}, level {model.thermal.smesh.level}, P2 as "
             f"DCAX6; SI units; temperatures are rises above {datum:.6f} K",
             "** x = radius r [m], y = axial coordinate z [m] (axisymmetric elements)"]
    _write_mesh(lines, cm, "DCAX6")
    groups = _groups(list(zip(data.k_r.tolist(), data.k_z.tolist(), strict=True)))
    for i, ((kr, kz), els) in enumerate(groups.items(), start=1):
        lines.append(f"*ELSET, ELSET=K{i}")
        lines.extend(_ids(els))
        lines += [f"*MATERIAL, NAME=K{i}",
                  "** k_r (x), k_z (y), k_r (hoop: transversely isotropic about the axis)",
                  "*CONDUCTIVITY, TYPE=ORTHO", f"{_g(kr)}, {_g(kz)}, {_g(kr)}",
                  f"*SOLID SECTION, ELSET=K{i}, MATERIAL=K{i}"]
    lines += _contact_cards(cm, data)
    lines += ["*STEP", "*HEAT TRANSFER, STEADY STATE", "1., 1."]
    body = np.nonzero(data.q_body)[0]
    if len(body) or data.q_face:
        lines.append("*DFLUX")
        lines.extend(f"{e + 1}, BF, {_g(q)}" for e, q in zip(body, data.q_body[body], strict=True))
        for f, q in data.q_face.items():
            e, k = cm.face_of[f]
            lines.append(f"{e}, S{k}, {_g(q)}")
    if data.films:
        lines.append("*FILM")
        for f, h, T, _ in data.films:
            e, k = cm.face_of[f]
            lines.append(f"{e}, F{k}, {_g(T - datum)}, {_g(h)}")
    lines += ["*NODE FILE", "NT", "*END STEP"]
    return lines


def _contact_cards(cm: CcxMesh, data: ThermalData) -> list[str]:
    lines: list[str] = []
    for i, (lk, fa, fb) in enumerate(data.contacts, start=1):
        for side, facets in (("A", fa), ("B", fb)):
            lines.append(f"*SURFACE, NAME=C{i}{side}, TYPE=ELEMENT")
            for f in facets.tolist():
                e, k = cm.face_of[f]
                lines.append(f"{e}, S{k}")
        lines += [f"*SURFACE INTERACTION, NAME=I{i}",
                  "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TIED", "1e12",
                  "*GAP CONDUCTANCE", f"{_g(lk.h_W_m2K)}, 0.", f"{_g(lk.h_W_m2K)}, 1e30",
                  f"*CONTACT PAIR, INTERACTION=I{i}, TYPE=SURFACE TO SURFACE",
                  f"C{i}B, C{i}A"]
    return lines


def _union(pairs: list[tuple[int, int]], n: int) -> np.ndarray:
    """Representative (smallest member) of each node's group under the tie ``pairs``."""
    parent = np.arange(n)

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for a, b in pairs:
        ra, rb = find(a), find(b)
        if ra != rb:
            parent[max(ra, rb)] = min(ra, rb)
    return np.array([find(i) for i in range(n)])


def _elastic_constraints(model: ReferenceModel, cm: CcxMesh) -> dict:
    """Ties, axis and axial support of the reference, rebuilt from the mesh and the spec.

    Contact joints are bonded: every node of a side-B facet is tied to the side-A node at the
    same place (both displacement components). u_r = 0 on the axis; u_z = 0 at the housing
    node nearest the reference point of the first axial-displacement sensor (or, without
    one, at the lowest-z node on the axis). 0-based node indices.
    """
    sm, spec = model.thermal.smesh, model.spec
    n = len(cm.rz)
    pairs: list[tuple[int, int]] = []
    for li, fa, fb in sm.contacts:
        if not isinstance(spec.links[li], ContactLink) or not len(fa):
            continue
        na = np.unique(cm.facet_nodes[:, fa])
        nb = np.unique(cm.facet_nodes[:, fb])
        d, j = cKDTree(cm.rz[na]).query(cm.rz[nb])
        if np.max(d, initial=0.0) > 1e-9:
            raise SolverError("contact interface nodes do not match pairwise (mesh bug)")
        pairs.extend(zip(na[j].tolist(), nb.tolist(), strict=True))
    rep = _union(pairs, n)
    axis = np.nonzero(np.abs(cm.rz[:, 0]) < 1e-12)[0]
    disp = [s for s in spec.sensors if s.kind == "axial_displacement"]
    if disp:
        target = np.array([disp[0].r_ref, disp[0].z_ref])
        housing = next((p.name for p in spec.parts if p.role == "housing"), spec.parts[0].name)
        cand = np.unique(cm.conn[sm.elements_of(housing)] - 1)
    else:
        cand = np.arange(n)
        target = np.array([0.0, cm.rz[:, 1].min()])
    support = int(cand[np.argmin(np.linalg.norm(cm.rz[cand] - target, axis=1))])
    fixed_r = np.isin(rep, rep[axis])  # a group with a node on the axis
    fixed_z = rep == rep[support]
    return {"rep": rep, "fixed_r": fixed_r, "fixed_z": fixed_z, "support": support,
            "ties": int(np.sum(rep != np.arange(n)))}


def elastic_materials(model: ReferenceModel) -> list[tuple]:
    """(E [Pa], nu, alpha [1/K], floating) per element, as the reference's regions."""
    sm, spec = model.thermal.smesh, model.spec
    floating = {(lk.part, lk.section) for lk in spec.links
                if isinstance(lk, BearingLink) and spec.part(lk.part).role == "rear_bearing"}
    rows = [(r.material.E_Pa, r.material.nu, r.material.alpha_1_K,
             r.kind == "bearing" and (r.part, r.section) in floating) for r in sm.regions]
    return [rows[k] for k in sm.element_region.tolist()]


def _elastic_deck(model: ReferenceModel, cm: CcxMesh, datum: float, T: np.ndarray,
                  con: dict) -> list[str]:
    """The thermoelastic deck for nodal temperatures ``T`` [K]."""
    spec = model.spec
    lines = ["*HEADING",
             f"spindle-verify crosscheck: {spec.name}, level {model.thermal.smesh.level}, P2 as "
             f"CAX6; SI units; temperatures are rises above {datum:.6f} K",
             "** x = radius r [m], y = axial coordinate z [m] (axisymmetric elements)"]
    _write_mesh(lines, cm, "CAX6")
    groups = _groups(elastic_materials(model))
    for i, ((E, nu, alpha, floating), els) in enumerate(groups.items(), start=1):
        lines.append(f"*ELSET, ELSET=M{i}")
        lines.extend(_ids(els))
        lines.append(f"*MATERIAL, NAME=M{i}")
        if floating:
            G = E / (2 * (1 + nu))
            Gs = FLOATING_SHEAR * G
            # 1 = x = r, 2 = y = z (axial), 3 = hoop: the r-z shear modulus is G12; G23 is
            # scaled as well so that the material stays transversely isotropic about the axis,
            # as ccx's 2-degree 3-D expansion of the section requires
            lines += ["** floating bearing layer: shear moduli G12 (r-z) and G23 x 1e-6",
                      "*ELASTIC, TYPE=ENGINEERING CONSTANTS",
                      f"{_g(E)}, {_g(E)}, {_g(E)}, {_g(nu)}, {_g(nu)}, {_g(nu)}, {_g(Gs)}, {_g(G)}",
                      f"{_g(Gs)}"]
        else:
            lines += ["*ELASTIC", f"{_g(E)}, {_g(nu)}"]
        lines += ["*EXPANSION", _g(alpha), f"*SOLID SECTION, ELSET=M{i}, MATERIAL=M{i}"]
    rep, fixed_r, fixed_z = con["rep"], con["fixed_r"], con["fixed_z"]
    eqs = [(i, int(rep[i]), dof) for i in np.nonzero(rep != np.arange(len(rep)))[0].tolist()
           for dof, fixed in ((1, fixed_r), (2, fixed_z)) if not fixed[i]]
    if eqs:  # bonded joints: u(B node) - u(A node) = 0, the B node's DOF is the dependent one
        lines.append("*EQUATION")
        for i, j, dof in eqs:
            lines += ["2", f"{i + 1}, {dof}, 1., {j + 1}, {dof}, -1."]
    lines.append("*BOUNDARY")
    lines.extend(f"{i + 1}, 1, 1, 0." for i in np.nonzero(fixed_r)[0].tolist())
    lines.extend(f"{i + 1}, 2, 2, 0." for i in np.nonzero(fixed_z)[0].tolist())
    lines += ["*INITIAL CONDITIONS, TYPE=TEMPERATURE", f"NALL, {_g(spec.T_initial_K - datum)}",
              "*STEP", "*STATIC", "*TEMPERATURE"]
    lines.extend(f"{i + 1}, {_g(v - datum)}" for i, v in enumerate(T.tolist()))
    lines += ["*NODE FILE", "U", "*END STEP"]
    return lines


def vector_dofs(basis) -> tuple[np.ndarray, np.ndarray]:
    """(u_z, u_r) DOF of every P2 node in a scikit-fem ElementVector(P2) basis."""
    return (np.r_[basis.nodal_dofs[0], basis.facet_dofs[0]],
            np.r_[basis.nodal_dofs[1], basis.facet_dofs[1]])


def reduction(con: dict, dz: np.ndarray, dr: np.ndarray, n_dofs: int) -> sp.csr_matrix:
    """Map from the free DOFs to all DOFs of the constraints ``con`` (ties, axis, support)."""
    rows, cols = [], []
    ncol = 0
    for dofs, fixed in ((dz, con["fixed_z"]), (dr, con["fixed_r"])):
        free = np.nonzero(~fixed)[0]
        groups, col = np.unique(con["rep"][free], return_inverse=True)
        rows.append(dofs[free])
        cols.append(ncol + col)
        ncol += len(groups)
    return sp.csr_matrix((np.ones(sum(len(r) for r in rows)), (np.concatenate(rows),
                                                               np.concatenate(cols))),
                         shape=(n_dofs, ncol))


def _elastic_checks(model: ReferenceModel, cm: CcxMesh, con: dict) -> dict:
    """Do the deck's elastic constants and constraints equal the reference's?"""
    el = model.elastic
    if el is None:
        return {}
    lam, mu, mu_s, alpha, _ = el.element_fields()
    mat = np.array(elastic_materials(model), dtype=float)
    E, nu, a, fl = mat.T
    mine = np.vstack([E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu)),
                      E / (2 * (1 + nu)) * np.where(fl > 0, FLOATING_SHEAR, 1.0), a])
    ref = np.vstack([lam, mu, mu_s, alpha])
    rel = float(np.max(np.abs(mine - ref) / np.maximum(np.abs(ref), 1e-300)))
    dz, dr = vector_dofs(el.basis)
    P_mine = reduction(con, dz, dr, el.basis.N)
    same = _same_partition(el.P, P_mine)
    return {"elastic_constants_rel_diff": rel, "constraints_as_reference": same}


def _same_partition(A: sp.spmatrix, B: sp.spmatrix) -> bool:
    """Do two 0/1 reduction matrices fix the same DOFs and tie the same groups?"""
    def cols(M):
        M = sp.csr_matrix(M)
        c = -np.ones(M.shape[0], dtype=np.int64)
        nz = np.diff(M.indptr) > 0
        c[nz] = M.indices[M.indptr[:-1][nz]]
        return c

    a, b = cols(A), cols(B)
    if not np.array_equal(a < 0, b < 0):
        return False
    pairs = np.unique(np.vstack([a[a >= 0], b[b >= 0]]), axis=1)
    return len(np.unique(pairs[0])) == len(np.unique(pairs[1])) == pairs.shape[1]
