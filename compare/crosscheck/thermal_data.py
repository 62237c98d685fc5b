"""What the heat-transfer deck holds, taken from the reference's assembled data: conductivity
and sources per element, fluxes and films per boundary facet, contact pairs; checked against
the reference's own operator and load vector."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from skfem import Basis, ElementTriP0, ElementTriP2, FacetBasis, asm

from reference.forms import conduction, surface_flux, volume_source
from reference.simulation import ReferenceModel
from reference.thermal import TWO_PI, layer_conductivity_factor
from spindle.loads import LoadCase
from spindle.spec import BearingLink, ContactLink


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


def thermal_inputs(model: ReferenceModel, case: LoadCase, t: float = 0.0) -> ThermalData:
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
    K_mine = th.assemble(conduction, {"kr": kr, "kz": kz})
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
    """Load vector [W per radian: without the 2 pi] of the sources and film sinks of ``data``,
    assembled with the given quadrature; temperatures relative to ``datum`` [K]."""
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
