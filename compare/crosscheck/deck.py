"""CalculiX input decks: DCAX6 steady heat transfer and CAX6 static thermoelasticity, written
from the reference's P2 mesh in ccx numbering (:mod:`.ccx_mesh`) and its assembled data
(:mod:`.thermal_data`, :mod:`.elastic_data`).

ccx reads distributed fluxes and films per unit area of the real surface (W/m2) and body
fluxes per unit volume (W/m3), so the decks never need the 2 pi of the reference's forms.
Units SI; temperatures are written as rises above a datum (the case's ambient), which keeps
more of ccx's six printed digits for the rise (docs/crosscheck.md)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from compare.crosscheck.ccx_mesh import CcxMesh, ccx_mesh
from compare.crosscheck.elastic_data import elastic_checks, elastic_constraints, elastic_materials
from compare.crosscheck.thermal_data import ThermalData, thermal_inputs
from reference.elastic import FLOATING_SHEAR
from reference.simulation import ReferenceModel
from spindle.errors import InputError
from spindle.loads import LoadCase

_PER_LINE = 10  # ids per line in *ELSET / *NSET (ccx reads at most 16 per line)


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


def write_thermal_deck(model: ReferenceModel, case: LoadCase, path: Path,
                       t: float = 0.0) -> tuple[dict, CcxMesh, ThermalData, dict]:
    """Write the heat-transfer deck of ``case`` at ``t`` [s]; return (description, mesh,
    thermal data, elastic constraints), the pieces the elastic deck and the twin reuse."""
    if path.suffix != ".inp":
        path = path.with_suffix(".inp")
    cm = ccx_mesh(model)
    data = thermal_inputs(model, case, t)
    datum = data.T_ambient_K
    path.write_text("\n".join(_thermal_deck(model, cm, data, datum)) + "\n", encoding="utf-8")
    con = elastic_constraints(model, cm)
    info = {"thermal_deck": path, "elastic_deck": None, "nodes": len(cm.rz),
            "elements": len(cm.conn), "T_datum_K": datum, "speed_rpm": data.speed_rpm,
            "films": len(data.films), "contacts": len(data.contacts),
            "ties": con["ties"], "support_node": con["support"] + 1,
            "axis_nodes": int(con["fixed_r"].sum()),
            "checks": {**data.checks, **elastic_checks(model, con)}}
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
    info, cm, _, con = write_thermal_deck(model, case or model.spec.default_load_case(),
                                          Path(path), t)
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
    cm = ccx_mesh(model)
    return write_elastic(model, cm, elastic_constraints(model, cm), Path(path), temperatures,
                         model.spec.T_ambient_K if datum is None else float(datum))


def write_elastic(model: ReferenceModel, cm: CcxMesh, con: dict, path: Path,
                  temperatures: np.ndarray, datum: float) -> Path:
    """Write the thermoelastic deck for nodal ``temperatures`` [K] (rises above ``datum``
    [K]) under the constraints ``con``; return its path."""
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
