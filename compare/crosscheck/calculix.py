"""Independent cross-check of the FEM reference with CalculiX (``ccx``, tested with 2.20).

The reference's P2 mesh is written to CalculiX input decks node for node and element for
element, ccx solves them, and its results are read back and compared at the temperature
sensors and the axial-growth readings (P1, TCP). Two decks per run:

- ``<name>.inp``: steady heat transfer with DCAX6 elements;
- ``<name>_elastic.inp``: linear static thermoelasticity with CAX6 elements, driven by the
  nodal temperatures of the heat-transfer run, written into the deck (ccx 2.20's
  ``*TEMPERATURE, FILE=`` leaves an axisymmetric model unloaded).

Besides the reference itself, the results are compared with its "twin": the reference's
discrete problem assembled with ccx's quadrature (scikit-fem). ccx equals the twin to the
print precision of its result file; reference - twin is the quadrature difference, which
falls under mesh refinement (docs/crosscheck.md).

Units are SI throughout: m, K, W, Pa, W/m/K, W/m2/K, W/m3. Temperatures are written as rises
above a datum ``T_datum_K`` (the ambient temperature of the case): the problem is linear, so
this changes nothing but the printed precision of ccx's result file (six significant digits).

CalculiX conventions handled here (see docs/crosscheck.md): axisymmetric elements live in the
x-y plane with x = radius and y = axial coordinate, so our (z, r) become (r, z) and every
element is renumbered counterclockwise in that plane; ccx's 6-node triangle has the corner
nodes first, then the mid-side nodes of edges 1-2, 2-3, 3-1, and face k of a triangle is its
edge k (S1/F1 = nodes 1-2, S2/F2 = 2-3, S3/F3 = 3-1); distributed fluxes and films are per
unit area of the real surface (W/m2), body fluxes per unit volume (W/m3).
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree
from skfem import Basis, ElementTriP0, ElementTriP2, ElementVector, FacetBasis, asm

from reference.elastic import FLOATING_SHEAR
from reference.forms import conduction, elasticity, film, surface_flux, thermal_coupling, volume_source
from reference.simulation import ReferenceModel
from reference.thermal import TWO_PI, factorize, layer_conductivity_factor
from spindle.errors import InputError, SolverError
from spindle.loads import LoadCase
from spindle.spec import BearingLink, ContactLink, Spec, load_spec
from spindle.units import ZERO_C_K

CCX_MISSING = "ccx not found; fix: install the Debian package calculix-ccx"
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


# --------------------------------------------------------------------------- mesh


@dataclass
class _Mesh:
    """The reference's P2 mesh in ccx numbering: node id = scikit-fem DOF index + 1."""

    rz: np.ndarray  # (N, 2) node coordinates r, z [m]
    conn: np.ndarray  # (ne, 6) ccx connectivity, 1-based, counterclockwise in (r, z)
    face_of: dict[int, tuple[int, int]]  # boundary facet -> (element id, ccx face 1..3)
    facet_nodes: np.ndarray  # (3, nfacets) 0-based DOFs of each facet: ends and middle


def _ccx_mesh(model: ReferenceModel) -> _Mesh:
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
    return _Mesh(xy.T.copy(), conn, face_of, facet_nodes)


# --------------------------------------------------------------------------- ingredients


@dataclass
class _Thermal:
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


def _thermal_inputs(model: ReferenceModel, case: LoadCase, t: float = 0.0) -> _Thermal:
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
    data = _Thermal(kr, kz, q_body, q_face, films, contacts, n, T_ref["ambient"], checks)
    # the same load vector as the reference's?
    F_mine = _load_vector(model, data, intorder=2 * th.order + 1)
    F_ref = th.op.F(case, t, n)
    checks["load_rel_diff"] = float(np.abs(F_mine - F_ref).max() / np.abs(F_ref).max())
    return data


def _load_vector(model: ReferenceModel, data: _Thermal, intorder: int,
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


# --------------------------------------------------------------------------- deck writing


def _ids(values) -> list[str]:
    vals = [str(int(v)) for v in values]
    return [", ".join(vals[i:i + _PER_LINE]) for i in range(0, len(vals), _PER_LINE)]


def _g(x: float) -> str:
    """A float for ccx, which reads at most 20 characters a field: 14 significant digits."""
    s = repr(float(x))
    return s if len(s) <= 20 else f"{x:.13e}"


def _write_mesh(lines: list[str], cm: _Mesh, etype: str) -> None:
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


def _export(model: ReferenceModel, case: LoadCase, path: Path, t: float = 0.0):
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
    info, cm, _, con = _export(model, case or model.spec.default_load_case(), Path(path), t)
    if temperatures is not None:
        stem = info["thermal_deck"].stem
        info["elastic_deck"] = _write_elastic(model, cm, con, info["thermal_deck"].with_name(
            f"{stem}_elastic.inp"), temperatures, info["T_datum_K"])
    return info


def export_elastic_deck(model: ReferenceModel, path: str | Path, temperatures: np.ndarray,
                        datum: float | None = None) -> Path:
    """Write the thermoelastic ccx deck (CAX6, linear static) for nodal ``temperatures`` [K].

    The stress-free temperature is the spec's ``T_initial_K``; temperatures are written as
    rises above ``datum`` [K] (default: the spec's ambient). Returns the deck's path.
    """
    cm = _ccx_mesh(model)
    return _write_elastic(model, cm, _elastic_constraints(model, cm), Path(path), temperatures,
                          model.spec.T_ambient_K if datum is None else float(datum))


def _write_elastic(model: ReferenceModel, cm: _Mesh, con: dict, path: Path,
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


def _thermal_deck(model: ReferenceModel, cm: _Mesh, data: _Thermal, datum: float) -> list[str]:
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


def _contact_cards(cm: _Mesh, data: _Thermal) -> list[str]:
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


def _elastic_constraints(model: ReferenceModel, cm: _Mesh) -> dict:
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


def _elastic_materials(model: ReferenceModel) -> list[tuple]:
    """(E [Pa], nu, alpha [1/K], floating) per element, as the reference's regions."""
    sm, spec = model.thermal.smesh, model.spec
    floating = {(lk.part, lk.section) for lk in spec.links
                if isinstance(lk, BearingLink) and spec.part(lk.part).role == "rear_bearing"}
    rows = [(r.material.E_Pa, r.material.nu, r.material.alpha_1_K,
             r.kind == "bearing" and (r.part, r.section) in floating) for r in sm.regions]
    return [rows[k] for k in sm.element_region.tolist()]


def _elastic_deck(model: ReferenceModel, cm: _Mesh, datum: float, T: np.ndarray,
                  con: dict) -> list[str]:
    """The thermoelastic deck for nodal temperatures ``T`` [K]."""
    spec = model.spec
    lines = ["*HEADING",
             f"spindle-verify crosscheck: {spec.name}, level {model.thermal.smesh.level}, P2 as "
             f"CAX6; SI units; temperatures are rises above {datum:.6f} K",
             "** x = radius r [m], y = axial coordinate z [m] (axisymmetric elements)"]
    _write_mesh(lines, cm, "CAX6")
    groups = _groups(_elastic_materials(model))
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


def _vector_dofs(basis) -> tuple[np.ndarray, np.ndarray]:
    """(u_z, u_r) DOF of every P2 node in a scikit-fem ElementVector(P2) basis."""
    return (np.r_[basis.nodal_dofs[0], basis.facet_dofs[0]],
            np.r_[basis.nodal_dofs[1], basis.facet_dofs[1]])


def _reduction(con: dict, dz: np.ndarray, dr: np.ndarray, n_dofs: int) -> sp.csr_matrix:
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


def _elastic_checks(model: ReferenceModel, cm: _Mesh, con: dict) -> dict:
    """Do the deck's elastic constants and constraints equal the reference's?"""
    el = model.elastic
    if el is None:
        return {}
    lam, mu, mu_s, alpha, _ = el.element_fields()
    mat = np.array(_elastic_materials(model), dtype=float)
    E, nu, a, fl = mat.T
    mine = np.vstack([E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu)),
                      E / (2 * (1 + nu)) * np.where(fl > 0, FLOATING_SHEAR, 1.0), a])
    ref = np.vstack([lam, mu, mu_s, alpha])
    rel = float(np.max(np.abs(mine - ref) / np.maximum(np.abs(ref), 1e-300)))
    dz, dr = _vector_dofs(el.basis)
    P_mine = _reduction(con, dz, dr, el.basis.N)
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


# --------------------------------------------------------------------------- running


def run_ccx(deck_path: str | Path, timeout_s: float = 600) -> Path:
    """Run ``ccx -i <name>`` in the deck's folder; return the ``.frd`` result file.

    Raises :class:`~spindle.errors.SolverError` if ccx is missing, times out or reports an
    error (the message quotes ccx's own lines).
    """
    exe = shutil.which("ccx")
    if exe is None:
        raise SolverError(CCX_MISSING)
    deck = Path(deck_path)
    if deck.suffix != ".inp":
        deck = deck.with_suffix(".inp")
    if not deck.is_file():
        raise InputError(str(deck), "deck", "does not exist", "write it with export_deck first")
    env = {**os.environ, "OMP_NUM_THREADS": "2", "CCX_NPROC_EQUATION_SOLVER": "2"}
    frd = deck.with_suffix(".frd")
    frd.unlink(missing_ok=True)
    try:
        proc = subprocess.run([exe, "-i", deck.stem], cwd=deck.parent, env=env, timeout=timeout_s,
                              capture_output=True, text=True, errors="replace")
    except subprocess.TimeoutExpired:
        raise SolverError(f"{deck}: ccx did not finish within {timeout_s:g} s; fix: use a "
                          "coarser --level or a longer timeout") from None
    out = proc.stdout + proc.stderr
    deck.with_suffix(".log").write_text(out, encoding="utf-8")
    errors = [ln.strip() for ln in out.splitlines() if "ERROR" in ln]
    if proc.returncode != 0 or errors or not frd.is_file() or "Job finished" not in out:
        detail = "; ".join(errors[:3]) or (out.strip().splitlines() or ["no output"])[-1]
        raise SolverError(f"{deck}: ccx failed (exit status {proc.returncode}): {detail}; "
                          f"fix: see {deck.with_suffix('.log')}")
    return frd


def read_frd(path: str | Path) -> dict:
    """Nodal results of an ASCII ``.frd`` file (the last block of each name).

    Returns ``{"node_ids", "coords" (n x 3, m), "results": {name: {"components",
    "node_ids", "values"}}, "T": temperatures by node id - 1 (NaN if absent), "U": (N x 3)
    displacements [m] by node id - 1}``; ``T`` and ``U`` are None when not in the file.
    """
    lines = Path(path).read_text(encoding="ascii", errors="replace").splitlines()
    node_ids: list[int] = []
    coords: list[list[float]] = []
    results: dict[str, dict] = {}
    i, nl = 0, len(lines)

    def values(line: str) -> list[float]:
        body = line[13:]
        return [float(body[k:k + 12]) for k in range(0, len(body.rstrip()), 12)]

    while i < nl:
        line = lines[i]
        key = line[:7].strip()
        if key == "2C":  # node block
            i += 1
            while i < nl and lines[i].startswith(" -1"):
                node_ids.append(int(lines[i][3:13]))
                coords.append(values(lines[i]))
                i += 1
            continue
        if key == "100CL":  # result block
            i += 1
            name = lines[i][5:13].strip()
            comps = []
            i += 1
            while i < nl and lines[i].startswith(" -5"):
                comps.append(lines[i][5:13].strip())
                i += 1
            ids, vals = [], []
            while i < nl and (lines[i].startswith(" -1") or lines[i].startswith(" -2")):
                if lines[i].startswith(" -1"):
                    ids.append(int(lines[i][3:13]))
                    vals.append(values(lines[i]))
                else:
                    vals[-1].extend(values(lines[i]))
                i += 1
            width = min((len(v) for v in vals), default=0)
            results[name] = {"components": comps[:width] if width else comps,
                             "node_ids": np.array(ids, dtype=np.int64),
                             "values": np.array([v[:width] for v in vals])}
            continue
        i += 1
    out: dict = {"node_ids": np.array(node_ids, dtype=np.int64),
                 "coords": np.array(coords), "results": results, "T": None, "U": None}
    n = max([0, *node_ids] + [int(r["node_ids"].max(initial=0)) for r in results.values()])
    if "NDTEMP" in results:
        T = np.full(n, np.nan)
        r = results["NDTEMP"]
        T[r["node_ids"] - 1] = r["values"][:, 0]
        out["T"] = T
    if "DISP" in results:
        U = np.full((n, 3), np.nan)
        r = results["DISP"]
        U[r["node_ids"] - 1] = r["values"][:, :3]
        out["U"] = U
    return out


# --------------------------------------------------------------------------- quadrature twin


def _half_ulp(values: np.ndarray) -> np.ndarray:
    """Bound of the rounding of a value in ccx's result file: ccx casts to single precision
    (relative 2^-24) and prints ``%12.5E`` (6 significant digits: half a unit 0.5e-5 of the
    leading digit's place)."""
    v = np.abs(np.asarray(values, dtype=float))
    out = np.zeros_like(v)
    nz = v > 0
    out[nz] = 0.5 * 10.0 ** (np.floor(np.log10(v[nz])) - 5) + 2.0 ** -24 * v[nz]
    return out


def _pair_matrix(cm: _Mesh, fa: np.ndarray, fb: np.ndarray, n: int) -> sp.csr_matrix:
    """Jump operator (D U)_i = U_i - U_twin(i) of an interface's side-A nodes."""
    na = np.unique(cm.facet_nodes[:, fa])
    nb = np.unique(cm.facet_nodes[:, fb])
    d, j = cKDTree(cm.rz[nb]).query(cm.rz[na])
    if np.max(d, initial=0.0) > 1e-9:
        raise SolverError("contact interface nodes do not match pairwise (mesh bug)")
    return sp.csr_matrix((np.r_[np.ones(len(na)), -np.ones(len(na))],
                          (np.r_[na, na], np.r_[na, nb[j]])), shape=(n, n))


def _twin_thermal(model: ReferenceModel, cm: _Mesh, data: _Thermal) -> np.ndarray:
    """Nodal temperatures [K] of the reference's discrete problem assembled with ccx's
    quadrature (see :data:`CCX_VOLUME_INTORDER`)."""
    mesh, n = model.thermal.smesh.mesh, len(cm.rz)
    b = Basis(mesh, ElementTriP2(), intorder=CCX_VOLUME_INTORDER)
    p0 = b.with_element(ElementTriP0())
    K = asm(conduction, b, kr=p0.interpolate(data.k_r), kz=p0.interpolate(data.k_z))
    by_h: dict[float, list[int]] = {}
    for f, h, _, _ in data.films:
        by_h.setdefault(h, []).append(f)
    for h, facets in by_h.items():
        fb = FacetBasis(mesh, ElementTriP2(), facets=np.array(facets), intorder=CCX_FACE_INTORDER)
        K = K + asm(film, fb, h=h)
    for lk, fa, fb_ in data.contacts:
        Ma = asm(film, FacetBasis(mesh, ElementTriP2(), facets=fa, intorder=CCX_CONTACT_INTORDER),
                 h=lk.h_W_m2K)
        D = _pair_matrix(cm, fa, fb_, n)
        K = K + D.T @ Ma @ D
    F = _load_vector(model, data, CCX_VOLUME_INTORDER, CCX_FACE_INTORDER, data.T_ambient_K)
    return data.T_ambient_K + factorize(K.tocsr()).solve(F)


def _reading_rows(model: ReferenceModel) -> dict[str, np.ndarray]:
    """Per growth reading, the dense row p with reading = p . u_z(nodes) [-]."""
    th = model.thermal
    out = {}
    for k, (z, r, zr, rr) in model.spec.growth_points().items():
        row = th.probe_matrix(np.array([[z, zr], [r, rr]]))
        out[k] = np.asarray((row[0] - row[1]).todense()).ravel()
    return out


def _twin_gains(model: ReferenceModel, cm: _Mesh, con: dict) -> dict[str, np.ndarray]:
    """Per reading, g with reading = g . (T - T_initial) [m/K]: the reference's elastic
    problem with ccx's quadrature and the deck's own constraints (adjoint solve)."""
    rows = _reading_rows(model)
    if not rows:
        return {}
    mesh = model.thermal.smesh.mesh
    b = Basis(mesh, ElementVector(ElementTriP2()), intorder=CCX_VOLUME_INTORDER)
    mat = np.array(_elastic_materials(model), dtype=float)
    E, nu, alpha, floating = mat.T
    mu = E / (2 * (1 + nu))
    p0 = b.with_element(ElementTriP0())
    f = {"lam": p0.interpolate(E * nu / ((1 + nu) * (1 - 2 * nu))), "mu": p0.interpolate(mu),
         "mu_s": p0.interpolate(mu * np.where(floating > 0, FLOATING_SHEAR, 1.0)),
         "alpha": p0.interpolate(alpha)}
    K = asm(elasticity, b, lam=f["lam"], mu=f["mu"], mu_s=f["mu_s"])
    tb = Basis(mesh, ElementTriP2(), quadrature=b.quadrature)
    B = asm(thermal_coupling, tb, b, lam=f["lam"], mu=f["mu"], alpha=f["alpha"])
    dz, dr = _vector_dofs(b)
    P = _reduction(con, dz, dr, b.N)
    lu = factorize((P.T @ K @ P).tocsr())
    gains = {}
    for k, row in rows.items():
        w = np.zeros(b.N)
        w[dz] = row
        gains[k] = B.T @ (P @ lu.solve(P.T @ w))
    return gains


# --------------------------------------------------------------------------- the cross-check


@dataclass
class CrosscheckResult:
    """scikit-fem reference against CalculiX at the sensors and growth readings.

    Temperatures in K, growth in m. ``*_twin`` is the reference's discrete problem assembled
    with ccx's quadrature (scikit-fem): ccx should equal it to the print precision of its
    result file (``*_print``, a bound), so ``reference - ccx`` is the quadrature difference,
    which falls under mesh refinement. ``growth_twin_ccxT_m`` is the twin's elastic problem
    driven by ccx's own temperatures (checks the elastic deck alone).
    """

    spec: str
    level: int
    case: str
    speed_rpm: float
    T_ambient_K: float
    sensors: list[str]
    z_m: np.ndarray
    r_m: np.ndarray
    T_skfem_K: np.ndarray
    T_ccx_K: np.ndarray
    T_twin_K: np.ndarray
    T_print_K: np.ndarray
    growth_skfem_m: dict[str, float]
    growth_ccx_m: dict[str, float]
    growth_twin_m: dict[str, float]
    growth_twin_ccxT_m: dict[str, float]
    growth_print_m: dict[str, float]
    growth_expansion_m: dict[str, float]
    nodal: dict[str, float]
    deck: dict
    timings_s: dict[str, float]
    ccx_version: str = ""

    @property
    def diff_K(self) -> np.ndarray:
        """T_ccx - T_skfem at each sensor [K]."""
        return self.T_ccx_K - self.T_skfem_K

    def sensor_table(self) -> dict[str, list]:
        return {"sensor": list(self.sensors), "z_m": self.z_m.tolist(), "r_m": self.r_m.tolist(),
                "T_skfem_C": (self.T_skfem_K - ZERO_C_K).tolist(),
                "T_ccx_C": (self.T_ccx_K - ZERO_C_K).tolist(), "diff_K": self.diff_K.tolist(),
                "T_twin_C": (self.T_twin_K - ZERO_C_K).tolist(),
                "ccx_minus_twin_K": (self.T_ccx_K - self.T_twin_K).tolist(),
                "print_bound_K": self.T_print_K.tolist()}

    def growth_table(self) -> dict[str, list]:
        names = list(self.growth_skfem_m)
        um = 1e6
        return {"reading": names,
                "skfem_um": [self.growth_skfem_m[k] * um for k in names],
                "ccx_um": [self.growth_ccx_m[k] * um for k in names],
                "diff_um": [(self.growth_ccx_m[k] - self.growth_skfem_m[k]) * um for k in names],
                "twin_um": [self.growth_twin_m[k] * um for k in names],
                "ccx_minus_twin_ccxT_um": [(self.growth_ccx_m[k] - self.growth_twin_ccxT_m[k]) * um
                                           for k in names],
                "print_bound_um": [self.growth_print_m[k] * um for k in names],
                "expansion_bound_um": [self.growth_expansion_m[k] * um for k in names]}

    def to_pandas(self):
        """The sensor table as a DataFrame (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return pd.DataFrame(self.sensor_table())

    def summary(self) -> dict:
        d = np.abs(self.diff_K)
        g = self.growth_table()
        return {"spec": self.spec, "kind": "crosscheck", "solver": f"CalculiX {self.ccx_version}",
                "mesh": {"level": self.level, "order": 2, "nodes": self.deck.get("nodes"),
                         "elements": self.deck.get("elements")},
                "case": self.case, "speed_rpm": self.speed_rpm,
                "T_ambient_C": self.T_ambient_K - ZERO_C_K,
                "max_abs_diff_K": float(d.max(initial=0.0)),
                "max_abs_ccx_minus_twin_K": float(np.abs(self.T_ccx_K - self.T_twin_K)
                                                  .max(initial=0.0)),
                "sensors": {n: {"T_skfem_C": a, "T_ccx_C": b, "diff_K": c}
                            for n, a, b, c in zip(self.sensors, self.T_skfem_K - ZERO_C_K,
                                                  self.T_ccx_K - ZERO_C_K, self.diff_K.tolist(),
                                                  strict=True)},
                "growth_um": {k: {"skfem": g["skfem_um"][i], "ccx": g["ccx_um"][i],
                                  "diff": g["diff_um"][i]} for i, k in enumerate(g["reading"])},
                "nodal": self.nodal, "checks": self.deck.get("checks", {}),
                "timings_s": self.timings_s}

    def save(self, out: str | Path) -> list[Path]:
        """``crosscheck.json`` (summary), ``crosscheck_sensors.csv`` and
        ``crosscheck_growth.csv``, each written atomically."""
        from spindle.outputs import write_csv, write_json

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        files = [out / "crosscheck.json", out / "crosscheck_sensors.csv",
                 out / "crosscheck_growth.csv"]
        write_json(files[0], self.summary())
        table = self.sensor_table()
        write_csv(files[1], list(table), zip(*table.values(), strict=True))
        gt = self.growth_table()
        write_csv(files[2], list(gt), zip(*gt.values(), strict=True))
        return files




def crosscheck(spec: Spec | str | Path, level: int = 1, case: LoadCase | None = None, *,
               keep_dir: str | Path | None = None, timeout_s: float = 600) -> CrosscheckResult:
    """Solve ``spec`` at mesh ``level`` (P2) with the reference and with CalculiX; compare.

    ``case`` is a steady load case (default: the spec's own operating point), evaluated at
    t = 0. ccx runs in a temporary folder; ``keep_dir`` keeps its decks, result files and
    logs there. Raises SolverError when ccx is missing or fails.
    """
    if shutil.which("ccx") is None:
        raise SolverError(CCX_MISSING)
    if not isinstance(spec, Spec):
        spec = load_spec(spec)
    if not 0 <= int(level) <= 6:
        raise InputError("crosscheck", "level", f"{level} is out of range",
                         "give a level between 0 and 6")
    case = case or spec.default_load_case()
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    model = ReferenceModel(spec, int(level), 2)
    res = model.steady(case)
    times["reference_s"] = time.perf_counter() - t0
    th = model.thermal
    names, pts = th.sensor_points()
    P = th.probe_matrix(pts)
    with tempfile.TemporaryDirectory(prefix="spindle-ccx-") as tmp:
        work = Path(tmp)
        t1 = time.perf_counter()
        name = "".join(c if c.isalnum() or c in "-_" else "_" for c in spec.name)
        info, cm, data, con = _export(model, case, work / f"{name}.inp")
        times["export_s"] = time.perf_counter() - t1
        t1 = time.perf_counter()
        frd = read_frd(run_ccx(info["thermal_deck"], timeout_s))
        times["ccx_thermal_s"] = time.perf_counter() - t1
        N = th.basis.N
        if frd["T"] is None or len(frd["T"]) < N or not np.all(np.isfinite(frd["T"][:N])):
            raise SolverError(f"{info['thermal_deck']}: ccx wrote no temperature for some "
                              "nodes; fix: see its .log")
        rise = frd["T"][:N]
        datum = info["T_datum_K"]
        T_ccx = datum + rise
        rows = _reading_rows(model)
        g_ccx: dict[str, float] = {}
        g_print: dict[str, float] = {}
        U_ccx = None
        if rows:
            t1 = time.perf_counter()
            deck = _write_elastic(model, cm, con, work / f"{name}_elastic.inp", T_ccx, datum)
            info["elastic_deck"] = deck
            U = read_frd(run_ccx(deck, timeout_s))["U"]
            times["ccx_elastic_s"] = time.perf_counter() - t1
            if U is None or len(U) < N or not np.all(np.isfinite(U[:N, :2])):
                raise SolverError(f"{deck}: ccx wrote no displacement for some nodes; fix: "
                                  "see its .log")
            U_ccx = U[:N, 1]
            ulp = _half_ulp(U_ccx)
            for k, row in rows.items():
                g_ccx[k] = float(row @ U_ccx)
                g_print[k] = float(np.abs(row) @ ulp)
        version = _ccx_version(info["thermal_deck"].with_suffix(".log"))
        if keep_dir is not None:
            keep = Path(keep_dir)
            keep.mkdir(parents=True, exist_ok=True)
            for f in work.iterdir():
                if f.suffix in (".inp", ".frd", ".log"):
                    shutil.copy2(f, keep / f.name)
    t1 = time.perf_counter()
    T_twin = _twin_thermal(model, cm, data)
    gains = _twin_gains(model, cm, con)
    times["twin_s"] = time.perf_counter() - t1
    T0 = spec.T_initial_K
    g_twin = {k: float(g @ (T_twin - T0)) for k, g in gains.items()}
    g_twin_ccx = {k: float(g @ (T_ccx - T0)) for k, g in gains.items()}
    g_exp = {k: float(EXPANSION_REL * (np.abs(rows[k]) @ np.abs(U_ccx))) for k in gains}
    nodal = {"max_abs_diff_K": float(np.abs(T_ccx - res.T).max()),
             "max_abs_ccx_minus_twin_K": float(np.abs(T_ccx - T_twin).max()),
             "max_abs_skfem_minus_twin_K": float(np.abs(res.T - T_twin).max()),
             "max_print_bound_K": float(_half_ulp(rise).max()),
             "max_rise_K": float(np.abs(rise).max())}
    sensors = th.spec.temperature_sensors()
    return CrosscheckResult(
        spec=spec.name, level=int(level), case=case.name, speed_rpm=float(case.speed_rpm(0.0)),
        T_ambient_K=float(case.T_ambient_K(0.0)), sensors=names,
        z_m=np.array([s.z for s in sensors]), r_m=np.array([s.r for s in sensors]),
        T_skfem_K=P @ res.T, T_ccx_K=P @ T_ccx, T_twin_K=P @ T_twin,
        T_print_K=abs(P) @ _half_ulp(rise),
        growth_skfem_m=dict(res.growth_m), growth_ccx_m=g_ccx, growth_twin_m=g_twin,
        growth_twin_ccxT_m=g_twin_ccx, growth_print_m=g_print, growth_expansion_m=g_exp,
        nodal=nodal, deck={k: (v.name if isinstance(v, Path) else v) for k, v in info.items()},
        timings_s=times, ccx_version=version)


def _ccx_version(log: Path) -> str:
    try:
        for line in log.read_text(encoding="utf-8", errors="replace").splitlines():
            if "CalculiX Version" in line:
                return line.split("Version", 1)[1].split(",")[0].strip()
    except OSError:
        pass
    return ""


# --------------------------------------------------------------------------- command line
def _cmd_crosscheck(args: argparse.Namespace) -> int:
    """``spindle-verify crosscheck``: print the comparison table, write JSON and CSV."""
    from spindle.drive import load_case
    from spindle.outputs import output_dir

    spec = load_spec(args.spec)
    case = None if args.case is None else load_case(spec, args.case)
    inputs = [args.case] if args.case is not None and Path(args.case).is_file() else []
    out = Path(args.out or f"results/{spec.name}/crosscheck")
    with output_dir(out, inputs=[spec.path, *inputs]) as tmp:
        result = crosscheck(spec, args.level, case,
                            keep_dir=(tmp / "ccx") if args.keep_deck else None)
        files = result.save(tmp)
    s = result.summary()
    print(f"{spec.name}: scikit-fem reference against CalculiX {result.ccx_version}, P2 level "
          f"{result.level} ({s['mesh']['nodes']} nodes, {s['mesh']['elements']} elements), "
          f"case '{result.case}' at {result.speed_rpm:g} rpm")
    print(f"  {'sensor':<16} {'T_skfem_C':>10} {'T_ccx_C':>10} {'diff_K':>10}")
    for i, n in enumerate(result.sensors):
        print(f"  {n:<16} {result.T_skfem_K[i] - ZERO_C_K:10.4f} {result.T_ccx_K[i] - ZERO_C_K:10.4f} "
              f"{result.diff_K[i]:10.1e}")
    if result.growth_skfem_m:
        print(f"  {'reading':<16} {'skfem_um':>10} {'ccx_um':>10} {'diff_um':>10}")
        for k, v in result.growth_skfem_m.items():
            c = result.growth_ccx_m[k]
            print(f"  {k + '_um':<16} {v * 1e6:10.4f} {c * 1e6:10.4f} {(c - v) * 1e6:10.1e}")
    print(f"max |T_ccx - T_skfem| = {s['max_abs_diff_K']:.1e} K at the sensors, "
          f"{result.nodal['max_abs_diff_K']:.1e} K over all nodes; against the reference "
          f"with ccx's quadrature {result.nodal['max_abs_ccx_minus_twin_K']:.1e} K (print "
          f"precision {result.nodal['max_print_bound_K']:.1e} K)")
    print("wrote " + ", ".join(str(out / f.name) for f in files)
          + (f", {out / 'ccx'}/" if args.keep_deck else ""))
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crosscheck SPEC [--level N] [--case CYCLE] [--out DIR] [--keep-deck]``."""
    cp = subparsers.add_parser(
        "crosscheck", help="cross-check the FEM reference with CalculiX (ccx) on the same P2 "
                           "mesh: sensor temperatures and axial growth (P1, TCP)",
        description="Cross-check the FEM reference with CalculiX (ccx, Debian package "
                    "calculix-ccx) on the same P2 mesh: sensor temperatures and axial growth "
                    "(P1, TCP) from both codes and their differences.")
    cp.add_argument("spec", metavar="SPEC")
    cp.add_argument("--level", type=int, default=1, help="mesh level (default 1)")
    cp.add_argument("--case", metavar="CYCLE",
                    help="steady load case from a cycle's first step, e.g. 'nominal' (default: "
                         "the spec's operating point)")
    cp.add_argument("--out", help="output folder (default results/<spec>/crosscheck)")
    cp.add_argument("--keep-deck", action="store_true",
                    help="keep the ccx decks, result files and logs in <out>/ccx")
    cp.set_defaults(func=_cmd_crosscheck)
