"""Reading and validating a spec file (TOML, docs/spec.md) into a :class:`spindle.spec.Spec`.

:func:`load_spec` reads every table, collects
every problem at once (each naming the file, the field and the fix) and raises
:class:`~spindle.errors.SpecError` with all of them; the geometry is checked once the tables
read cleanly. Also here: the shipped specs, materials and drives, and where a
``[power_balance] preset`` points.
"""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from spindle.errors import Problem, SpecError
from spindle.geometry import TOL_M, contact_length, overlap
from spindle.spec import (
    LINK_TYPES,
    ROLES,
    SIDES,
    T_REFS,
    AirGapLink,
    BearingLink,
    ContactLink,
    HeatSource,
    Link,
    Material,
    Part,
    Section,
    Sensor,
    SensorArray,
    Spec,
    Surface,
)
from spindle.spec_checks import check_geometry, check_size
from spindle.spec_fields import (
    KNOWN_FIELDS,
    MAX_FILM_W_M2K,
    MAX_G_W_K,
    PLAUSIBLE_FILM,
    FieldReader,
    finite_number,
    show_value,
)

#: the least conductivity [W/(m K)] a material may have: an order below the least conducting
#: solids and gases (aerogels 0.013, air 0.026)
K_MIN_W_MK = 1e-3


def _read_material(r: FieldReader, name: str, d: dict, path: str) -> Material | None:
    # upper limits: beyond every engineering solid (diamond conducts 2200 W/m/K, osmium is
    # 22600 kg/m3, E of diamond 1.2e12 Pa, thermal expansion of polymers 2e-4 1/K); k up to
    # 1e6 W/m/K for the near-ideal conductors of verification cases. Lower limits: below any
    # solid or gas the spec may mesh (air's layer: 0.026 W/m/K, 1.18 kg/m3, its E 1e5 Pa so that
    # it carries no load; lead's 129 J/kg/K), so that a unit slip (c in kJ/kg/K, E in GPa) or
    # an exponent is named rather than solved
    n0 = len(r.problems)
    r.keys(d, KNOWN_FIELDS["materials"], path)
    if "k_W_mK" in d and ("k_r_W_mK" in d or "k_z_W_mK" in d):
        r.add(f"{path}.k_W_mK", "is given together with k_r_W_mK / k_z_W_mK",
              "give either k_W_mK (isotropic) or both k_r_W_mK and k_z_W_mK")
        kr = kz = None
    elif "k_W_mK" in d:
        kr = kz = r.number(d, "k_W_mK", path, "W/m/K", lo=K_MIN_W_MK, hi=1e6)
    else:
        kr = r.number(d, "k_r_W_mK", path, "W/m/K", lo=K_MIN_W_MK, hi=1e6)
        kz = r.number(d, "k_z_W_mK", path, "W/m/K", lo=K_MIN_W_MK, hi=1e6)
    rho = r.number(d, "rho_kg_m3", path, "kg/m3", lo=0.1, hi=30000.0)
    c = r.number(d, "c_J_kgK", path, "J/kg/K", lo=50.0, hi=20000.0)
    E = r.number(d, "E_Pa", path, "Pa", lo=1e3, hi=2e12)
    nu = r.number(d, "nu", path, "-", lo=-1.0, lo_open=True, hi=0.4999)
    alpha = r.number(d, "alpha_1_K", path, "1/K", lo=0.0, hi=1e-3)
    if len(r.problems) > n0:
        return None
    return Material(name, kr, kz, rho, c, E, nu, alpha, str(d.get("source", "")))


def shipped_materials() -> dict[str, Material]:
    """The shipped material table (spindle/data/materials.toml), each with its source."""
    text = resources.files("spindle").joinpath("data/materials.toml").read_text("utf-8")
    r = FieldReader("spindle/data/materials.toml")
    out = {}
    for name, d in tomllib.loads(text).items():
        m = _read_material(r, name, d, f"{name}")
        if m is not None:
            out[name] = m
    if r.problems:  # a broken shipped table is a bug, but say where
        raise SpecError(r.problems)
    return out


def shipped_specs() -> dict[str, Path]:
    """Shipped specs by name (``spindle-verify specs`` lists them)."""
    root = resources.files("spindle").joinpath("data/specs")
    return {Path(str(p)).stem: Path(str(p)) for p in root.iterdir() if str(p).endswith(".toml")}


def shipped_drives() -> dict[str, Path]:
    """Shipped drive files (spindle/data/drives/*.toml) by name (the file stem)."""
    root = resources.files("spindle").joinpath("data/drives")
    return {Path(str(p)).stem: Path(str(p)) for p in sorted(root.iterdir(), key=str)
            if str(p).endswith(".toml")}


def drive_file_path(spec_file: str | Path, preset: str) -> Path | None:
    """The drive file a ``[power_balance] preset`` names: a shipped drive's, else a path
    relative to the spec's folder (an absolute one as it is); None if there is no such
    file."""
    shipped = shipped_drives()
    if preset in shipped:
        return shipped[preset]
    path = Path(spec_file).parent / Path(preset).expanduser()
    return path if path.is_file() else None


def spec_files(spec: Spec) -> list[str]:
    """The files a spec is read from: its TOML and the drive file its ``[power_balance]
    preset`` names (a command's inputs, which no output may replace or move)."""
    files = [str(spec.path)]
    if spec.power_preset is not None:
        drive = drive_file_path(spec.path, spec.power_preset)
        if drive is not None:
            files.append(str(drive))
    return files


def resolve_spec_path(name_or_path: str | Path) -> Path:
    """A path to a TOML file, or the name of a shipped spec."""
    if not isinstance(name_or_path, str | Path):
        raise TypeError(f"a spec is a shipped name or a path, not {type(name_or_path).__name__}")
    p = Path(name_or_path)
    if p.is_file():
        return p
    shipped = shipped_specs()
    if str(name_or_path) in shipped:
        return shipped[str(name_or_path)]
    raise SpecError([Problem(str(name_or_path), "file", "is neither a file nor a shipped spec",
                             f"give a path to a .toml spec or one of: {', '.join(sorted(shipped))}")])


def read_toml(path: Path) -> dict:
    """A TOML file's tables; a syntax error or an unreadable file raises SpecError naming the
    file and the fix (every TOML input of the project reads through here)."""
    file = str(path)
    try:
        return tomllib.loads(path.read_text(encoding="utf-8-sig"))  # a BOM is accepted
    except tomllib.TOMLDecodeError as exc:
        raise SpecError([Problem(file, "syntax", str(exc), "fix the TOML syntax at that line")]) \
            from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecError([Problem(file, "file", f"cannot be read ({exc})",
                                 "check the path and that the file is UTF-8 text")]) from None


def load_spec(name_or_path: str | Path) -> Spec:
    """Read and validate a spec (a file path or a shipped name). Raises SpecError."""
    path = resolve_spec_path(name_or_path)
    return _build(FieldReader(str(path)), read_toml(path))


def as_spec(spec: Spec | str | Path) -> Spec:
    """``spec`` itself, or the spec a shipped name or a file path names (:func:`load_spec`):
    what every public constructor that takes a spec accepts, as the command line does."""
    if isinstance(spec, Spec):
        return spec
    if isinstance(spec, str | Path):
        return load_spec(spec)
    raise TypeError(f"a spec is a Spec, a shipped name or a path, not {type(spec).__name__}")


def _build(r: FieldReader, data: dict[str, Any]) -> Spec:
    """Read the tables one after the other (the problems are listed in that order), then,
    if none was found, check the geometry; raises SpecError with every problem."""
    r.keys(data, KNOWN_FIELDS[""], "")
    for t in ("spindle", "operating", "power_balance", "mesh"):
        if isinstance(data.get(t), dict):
            r.keys(data[t], KNOWN_FIELDS[t], t)
    head = r.table(data, "spindle", "") or {}
    name = r.string(head, "name", "spindle") or "?"
    speed, T_amb, T_cool, T_init = _read_operating(r, data)
    mesh = r.table(data, "mesh", "", required=False) or {}
    h0 = r.number(mesh, "h0_m", "mesh", "m", required=False, default=0.01, lo=0.0, lo_open=True)
    materials = _read_materials(r, data)
    parts = _read_parts(r, data, materials)
    links = _read_links(r, data, parts)
    surfaces = _read_surfaces(r, data, parts)
    sources = _read_heat_sources(r, data, parts, surfaces)
    sensors, arrays = _read_sensors(r, data, parts)
    pb = r.table(data, "power_balance", "", required=False) or {}
    preset = r.string(pb, "preset", "power_balance", required=False)
    if preset is not None and drive_file_path(r.file, preset) is None:
        r.add("power_balance.preset", f"'{preset}' is neither a shipped drive nor a drive "
              f"file (no file {Path(r.file).parent / preset})",
              f"use one of: {', '.join(sorted(shipped_drives()))}, or the path of a drive "
              "TOML relative to the spec's folder (format: docs/power.md)")

    if not r.problems:
        check_size(r, parts, h0)
    if not r.problems:
        check_geometry(r, parts, links, surfaces, sensors)
    if r.problems:
        raise SpecError(r.problems)
    return Spec(
        name=name, path=r.file, description=str(head.get("description", "")),
        source=str(head.get("source", "")), speed_rpm=speed, T_ambient_K=T_amb,
        T_coolant_K=T_cool, T_initial_K=T_init, h0_m=h0,
        materials={m: materials[m] for m in {s.material for p in parts for s in p.sections}},
        parts=tuple(parts), links=tuple(links), surfaces=tuple(surfaces),
        heat_sources=tuple(sources), sensors=tuple(sensors), sensor_arrays=tuple(arrays),
        power_preset=preset)


def _read_operating(r: FieldReader, data: dict[str, Any]) -> tuple[float, float, float, float]:
    """[operating]: speed [rpm] and the ambient, coolant and initial temperatures [K]
    (coolant and initial default to the ambient)."""
    op = r.table(data, "operating", "") or {}
    speed = r.number(op, "speed_rpm", "operating", "rpm", required=False, default=0.0, lo=0.0, hi=1e5)
    T_amb = r.number(op, "T_ambient_K", "operating", "K", lo=150.0, hi=500.0)
    T_cool = r.number(op, "T_coolant_K", "operating", "K", required=False, default=T_amb, lo=150.0, hi=500.0)
    T_init = r.number(op, "T_initial_K", "operating", "K", required=False, default=T_amb, lo=150.0, hi=500.0)
    return speed, T_amb, T_cool, T_init


def _read_materials(r: FieldReader, data: dict[str, Any]) -> dict[str, Material]:
    """The shipped materials, overridden and extended by the spec's [materials] tables."""
    materials = dict(shipped_materials())
    for mname, md in (r.table(data, "materials", "", required=False) or {}).items():
        if not isinstance(md, dict):
            r.add(f"materials.{mname}", "must be a table", f"write it as [materials.{mname}]")
            continue
        m = _read_material(r, mname, md, f"materials.{mname}")
        if m is not None:
            materials[mname] = m
        else:
            r.broken["material"].add(mname)
            materials.pop(mname, None)
    return materials


def _read_parts(r: FieldReader, data: dict[str, Any], materials: dict[str, Material]) -> list[Part]:
    """[[parts]] with their sections; a part with a problem is left out."""
    parts: list[Part] = []
    for i, pd in enumerate(r.array(data, "parts", "")):
        path = f"parts[{i}]"
        n0 = len(r.problems)
        r.keys(pd, KNOWN_FIELDS["parts"], path)
        pname = r.string(pd, "name", path)
        role = r.string(pd, "role", path, choices=ROLES)
        pmat = pd.get("material")
        if pname is not None and any(p.name == pname for p in parts):
            r.add(f"{path}.name", f"part '{pname}' is defined twice", "give each part its own name")
        secs = pd.get("sections")
        if not isinstance(secs, list) or not secs or not all(isinstance(s, dict) for s in secs):
            r.add(f"{path}.sections", "required list of sections is missing or empty",
                  "add sections = [{z_start = 0.0, z_end = 0.1, r_inner = 0.0, r_outer = 0.04}]")
            secs = []
        sections = []
        for j, sd in enumerate(secs):
            sec = _read_section(r, sd, f"{path}.sections[{j}]", path, pmat, materials)
            if sec is not None:
                sections.append(sec)
            elif pname is not None and isinstance(sd.get("name"), str):
                r.broken["section"].add(f"{pname}/{sd['name']}")
        if len(sections) == len(secs):
            _check_sections_join(r, sections, path)
        ok = pname is not None and role is not None and bool(sections)
        if ok:
            parts.append(Part(pname, role, tuple(sections)))
        if pname is not None and (not ok or len(r.problems) > n0 or len(sections) < len(secs)):
            r.broken["part"].add(pname)
    return parts


def _check_sections_join(r: FieldReader, sections: list[Section], path: str) -> None:
    """A part is one body: its sections, in z order, must meet without a gap along z, and
    each must share a face with another (a ring on a shaft, a step in diameter)."""
    order = sorted(range(len(sections)), key=lambda j: sections[j].z_start)
    a = order[0]  # of the sections so far, the one reaching furthest along z
    for b in order[1:]:
        gap = sections[b].z_start - sections[a].z_end
        if gap > TOL_M:
            r.add(f"{path}.sections[{b}].z_start",
                  f"a {gap * 1e3:.3g} mm gap after sections[{a}] (z = {sections[a].z_end:g} to "
                  f"{sections[b].z_start:g} m): a part is one body",
                  f"give z_start = {sections[a].z_end:g} (or make the piece beyond the gap a "
                  "part of its own, joined by a link)")
            return
        a = b if sections[b].z_end > sections[a].z_end else a
    # no gap along z, but sections may still meet in a point or not at all (a bore wider
    # than the neighbour's outside): the sections joined by a shared face, from the first
    joined, grown = {order[0]}, True
    while grown:
        grown = False
        for j in order:
            if j not in joined and any(contact_length(sections[j], sections[k]) > TOL_M
                                       or overlap(sections[j], sections[k]) for k in joined):
                joined.add(j)
                grown = True
    alone = next((j for j in order if j not in joined), None)
    if alone is not None:
        sj = sections[alone]
        r.add(f"{path}.sections[{alone}]",
              f"shares no face with the part's sections[{order[0]}] and those joined to it "
              f"(z = {sj.z_start:g} to {sj.z_end:g} m, r = {sj.r_inner[0]:g} to "
              f"{sj.r_outer[0]:g} m): a part is one body",
              "make its radii meet a neighbour's (one's r_outer the other's r_inner, or "
              "overlapping radial ranges where one ends and the next starts), or make it a "
              "part of its own, joined by a link")


def _read_section(r: FieldReader, sd: dict, sp: str, path: str, pmat: Any,
                  materials: dict[str, Material]) -> Section | None:
    """One section ``sp`` of part ``path``; its material defaults to the part's ``pmat``."""
    r.keys(sd, KNOWN_FIELDS["sections"], sp)
    z0 = r.number(sd, "z_start", sp, "m")
    z1 = r.number(sd, "z_end", sp, "m")
    ri = r.radius(sd, "r_inner", sp)
    ro = r.radius(sd, "r_outer", sp)
    mat = sd.get("material", pmat)
    if mat is None:
        r.add(f"{sp}.material", "no material for this section or its part",
              f"add material = \"...\" to {path} (one of: {', '.join(sorted(materials))})")
    elif not isinstance(mat, str):
        r.add(f"{sp}.material" if "material" in sd else f"{path}.material",
              f"must be a material name, not {show_value(mat)}", "write material = \"steel\"")
        mat = None
    elif mat not in materials:
        r.unknown("material", mat, f"{sp}.material" if "material" in sd else f"{path}.material",
                  f"use one of: {', '.join(sorted(materials))}, or define [materials.{mat}]")
        mat = None
    if None in (z0, z1, ri, ro, mat):
        return None
    if z1 - z0 <= TOL_M:
        r.add(f"{sp}.z_end", f"z_end = {z1:g} m is not after z_start = {z0:g} m",
              "give z_end > z_start (z grows from the rear towards the tool)")
        return None
    if ri[0] >= ro[0] - TOL_M or ri[1] >= ro[1] - TOL_M:
        r.add(f"{sp}.r_inner", f"r_inner {list(ri)} m is not below r_outer {list(ro)} m",
              "give r_inner < r_outer at both ends (r_inner = 0 for a solid section)")
        return None
    return Section(z0, z1, ri, ro, material=mat, name=str(sd.get("name", "")))


def _read_links(r: FieldReader, data: dict[str, Any], parts: list[Part]) -> list[Link]:
    """[[links]]: bearing, air_gap and contact; a link with a problem is left out."""
    readers = {"bearing": _read_bearing_link, "air_gap": _read_air_gap_link,
               "contact": _read_contact_link}
    links: list[Link] = []
    for i, ld in enumerate(r.array(data, "links", "", required=False)):
        path = f"links[{i}]"
        kind = r.string(ld, "type", path, choices=LINK_TYPES)
        if kind is not None:
            r.keys(ld, KNOWN_FIELDS[f"links.{kind}"], path)
        link = readers[kind](r, ld, path, parts) if kind is not None else None
        if link is not None:
            links.append(link)
    return links


def _read_bearing_link(r: FieldReader, ld: dict, path: str, parts: list[Part]) -> BearingLink | None:
    part_names = {p.name for p in parts}
    pn = r.string(ld, "part", path)
    sn = r.string(ld, "section", path)
    G = r.speed_table(ld, "G_W_K", path, "W/K")
    if pn is not None and pn not in part_names:
        r.unknown("part", pn, f"{path}.part", f"use one of: {sorted(part_names)}")
    elif G is not None and G.max > MAX_G_W_K:
        r.add(f"{path}.G_W_K", f"{G.max:g} W/K is not a bearing's conductance (typ. 5-50 W/K "
              f"per pair; above {MAX_G_W_K:g} W/K it would weld the rings)",
              f"give G_W_K <= {MAX_G_W_K:g} W/K")
    elif pn is not None and sn is not None and not any(
            s.name == sn for s in next(p for p in parts if p.name == pn).sections):
        if f"{pn}/{sn}" not in r.broken["section"]:  # else its own problem is reported
            r.add(f"{path}.section", f"part '{pn}' has no section named '{sn}'",
                  f"add name = \"{sn}\" to the rolling-element section of part '{pn}'")
    elif G is not None and G.min <= 0:
        r.add(f"{path}.G_W_K", "a bearing conductance must be > 0 W/K",
              "give G_W_K > 0 (typ. 5-50 W/K per bearing pair)")
    elif None not in (pn, sn, G):
        return BearingLink(pn, sn, G)
    return None


def _read_air_gap_link(r: FieldReader, ld: dict, path: str, parts: list[Part]) -> AirGapLink | None:
    part_names = {p.name for p in parts}
    a = r.string(ld, "inner", path)
    b = r.string(ld, "outer", path)
    h = r.speed_table(ld, "h_W_m2K", path, "W/m2/K")
    for key, v in (("inner", a), ("outer", b)):
        if v is not None and v not in part_names:
            r.unknown("part", v, f"{path}.{key}", f"use one of: {sorted(part_names)}")
    if h is not None and h.min <= 0:
        r.add(f"{path}.h_W_m2K", "an air-gap coefficient must be > 0 W/m2/K",
              "give h_W_m2K > 0")
    elif h is not None and h.max > MAX_FILM_W_M2K:
        r.add(f"{path}.h_W_m2K", f"{h.max:g} W/m2/K is not an air gap's film ({PLAUSIBLE_FILM})",
              f"give h_W_m2K <= {MAX_FILM_W_M2K:g}")
    elif a in part_names and b in part_names and h is not None:
        return AirGapLink(a, b, h)
    return None


def _read_contact_link(r: FieldReader, ld: dict, path: str, parts: list[Part]) -> ContactLink | None:
    part_names = {p.name for p in parts}
    pl = ld.get("parts")
    # a contact conducts 1e3-1e5 W/m2/K (pressed steel joints); 1e8 is a perfect bond
    h = r.number(ld, "h_W_m2K", path, "W/m2/K", lo=0.0, lo_open=True, hi=1e8)
    if not (isinstance(pl, list) and len(pl) == 2 and all(isinstance(x, str) for x in pl)):
        r.add(f"{path}.parts", "must name two parts", "write parts = [\"shaft\", \"rotor\"]")
    elif any(x not in part_names for x in pl):
        bad = next(x for x in pl if x not in part_names)
        r.unknown("part", bad, f"{path}.parts", f"use one of: {sorted(part_names)}")
    elif h is not None:
        return ContactLink((pl[0], pl[1]), h)
    return None


def _read_surfaces(r: FieldReader, data: dict[str, Any], parts: list[Part]) -> list[Surface]:
    """[[surfaces]]; a surface with a problem is left out."""
    part_names = {p.name for p in parts}
    surfaces: list[Surface] = []
    for i, sd in enumerate(r.array(data, "surfaces", "", required=False)):
        path = f"surfaces[{i}]"
        n0 = len(r.problems)
        r.keys(sd, KNOWN_FIELDS["surfaces"], path)
        sname = r.string(sd, "name", path)
        pl = sd.get("parts", sd.get("part"))
        pl = [pl] if isinstance(pl, str) else pl
        if not (isinstance(pl, list) and pl and all(isinstance(x, str) for x in pl)):
            r.add(f"{path}.parts", "must name one or more parts", "write parts = [\"housing\"]")
            pl = []
        for x in pl:
            if x not in part_names:
                r.unknown("part", x, f"{path}.parts", f"use one of: {sorted(part_names)}")
        side = r.string(sd, "side", path, required=False, choices=SIDES, default="any")
        zmin = r.number(sd, "z_min", path, "m", required=False, default=-np.inf)
        zmax = r.number(sd, "z_max", path, "m", required=False, default=np.inf)
        h = r.speed_table(sd, "h_W_m2K", path, "W/m2/K", required=False)
        if h is not None and h.max > MAX_FILM_W_M2K:
            r.add(f"{path}.h_W_m2K", f"{h.max:g} W/m2/K is not a film coefficient "
                  f"({PLAUSIBLE_FILM})", f"give h_W_m2K <= {MAX_FILM_W_M2K:g}")
        tref = r.string(sd, "T_ref", path, required=h is not None, choices=T_REFS)
        if sname is not None and any(s.name == sname for s in surfaces):
            r.add(f"{path}.name", f"surface '{sname}' is defined twice", "give each its own name")
        elif sname is not None and all(x in part_names for x in pl) and pl \
                and len(r.problems) == n0:
            surfaces.append(Surface(sname, tuple(pl), side, zmin, zmax, h, tref))
        elif sname is not None:
            r.broken["surface"].add(sname)
    return surfaces


def _read_heat_sources(r: FieldReader, data: dict[str, Any], parts: list[Part],
                       surfaces: list[Surface]) -> list[HeatSource]:
    """[[heat_sources]]; a source with a problem is left out."""
    sources: list[HeatSource] = []
    for i, hd in enumerate(r.array(data, "heat_sources", "", required=False)):
        src = _read_heat_source(r, hd, f"heat_sources[{i}]", parts, surfaces, sources)
        if src is not None:
            sources.append(src)
    return sources


def _read_heat_source(r: FieldReader, hd: dict, path: str, parts: list[Part],
                      surfaces: list[Surface], earlier: list[HeatSource]) -> HeatSource | None:
    part_names = {p.name for p in parts}
    surface_names = {s.name for s in surfaces}
    r.keys(hd, KNOWN_FIELDS["heat_sources"], path)
    hname = r.string(hd, "name", path)
    pw = r.power(hd, path)
    pn, sn, surf = hd.get("part"), hd.get("section"), hd.get("surface")
    if (pn is None) == (surf is None):
        r.add(path, "a heat source goes into either a part or a surface",
              "give exactly one of part = \"...\" or surface = \"...\"")
        return None
    if pn is not None and pn not in part_names:
        r.unknown("part", str(pn), f"{path}.part", f"use one of: {sorted(part_names)}")
        return None
    if sn is not None and not any(s.name == sn for s in
                                  next(p for p in parts if p.name == pn).sections):
        if f"{pn}/{sn}" not in r.broken["section"]:  # else its own problem is reported
            r.add(f"{path}.section", f"part '{pn}' has no section named '{sn}'",
                  f"name one of its sections '{sn}' or drop the section field")
        return None
    if surf is not None and surf not in surface_names:
        r.unknown("surface", str(surf), f"{path}.surface",
                  f"define it under [[surfaces]] (known: {sorted(surface_names)})")
        return None
    if hname is not None and any(h.name == hname for h in earlier):
        r.add(f"{path}.name", f"heat source '{hname}' is defined twice",
              "give each its own name")
        return None
    if hname is not None and pw is not None:
        return HeatSource(hname, pw, pn, sn, surf)
    return None


def _read_sensors(r: FieldReader, data: dict[str, Any],
                  parts: list[Part]) -> tuple[list[Sensor], list[SensorArray]]:
    """[[sensors]], then [[sensor_arrays]] (whose sensors follow); every name once."""
    sensors: list[Sensor] = []
    for i, sd in enumerate(r.array(data, "sensors", "", required=False)):
        s = _read_sensor(r, sd, f"sensors[{i}]")
        if s is not None:
            sensors.append(s)
    arrays: list[SensorArray] = []
    for i, ad in enumerate(r.array(data, "sensor_arrays", "", required=False)):
        arr = _read_sensor_array(r, ad, f"sensor_arrays[{i}]", parts)
        if arr is not None:
            arrays.append(arr)
            # a part with a problem of its own (a section left out) may not span its length:
            # its sensors wait for that problem's fix, which is reported already
            if arr.part not in r.broken["part"]:
                sensors.extend(array_sensors(arr, next(p for p in parts if p.name == arr.part)))
    seen: set[str] = set()
    for s in sensors:
        if s.name in seen:
            r.add(f"sensors.{s.name}", "sensor name is used twice", "give each sensor its own name")
        seen.add(s.name)
    return sensors, arrays


def _read_sensor(r: FieldReader, sd: dict, path: str) -> Sensor | None:
    r.keys(sd, KNOWN_FIELDS["sensors"], path)
    sname = r.string(sd, "name", path)
    kind = r.string(sd, "kind", path, required=False, default="temperature",
                    choices=("temperature", "axial_displacement"))
    z = r.number(sd, "z", path, "m")
    rr = r.number(sd, "r", path, "m", lo=0.0)
    zr = rr_ref = None
    if kind == "axial_displacement":
        zr = r.number(sd, "z_ref", path, "m")
        rr_ref = r.number(sd, "r_ref", path, "m", lo=0.0)
    if None in (sname, z, rr) or (kind == "axial_displacement" and None in (zr, rr_ref)):
        return None
    return Sensor(sname, kind, z, rr, zr, rr_ref)


def _read_sensor_array(r: FieldReader, ad: dict, path: str, parts: list[Part]) -> SensorArray | None:
    part_names = {p.name for p in parts}
    r.keys(ad, KNOWN_FIELDS["sensor_arrays"], path)
    aname = r.string(ad, "name", path)
    pn = r.string(ad, "part", path)
    cnt = ad.get("count", 11)
    rad = ad.get("radius", "mid")
    if not isinstance(cnt, int) or isinstance(cnt, bool) or not 2 <= cnt <= 1000:
        r.add(f"{path}.count", f"must be an integer from 2 to 1000, not {show_value(cnt)}",
              "write count = 11")
        return None
    if not (rad in ("mid", "inner", "outer") or (isinstance(rad, int | float)
                                                  and not isinstance(rad, bool))):
        r.add(f"{path}.radius", f"{rad!r} is not a radius", "write \"mid\", \"inner\", "
              "\"outer\" or a radius in m")
        return None
    if pn is not None and pn not in part_names:
        r.unknown("part", pn, f"{path}.part", f"use one of: {sorted(part_names)}")
        return None
    if isinstance(rad, int | float) and finite_number(rad) is None:
        r.add(f"{path}.radius", f"{show_value(rad)} is not a radius", "write a finite radius in m")
        return None
    if aname is not None and pn is not None:
        return SensorArray(aname, pn, cnt, rad)
    return None


def array_sensors(arr: SensorArray, part: Part) -> list[Sensor]:
    z0 = min(s.z_start for s in part.sections)
    z1 = max(s.z_end for s in part.sections)
    out = []
    for i, z in enumerate(np.linspace(z0, z1, arr.count)):
        # a point strictly inside a section takes that section; at a joint or an end, the
        # first section that reaches it
        sec = next((s for s in part.sections if s.z_start < z < s.z_end),
                   next(s for s in part.sections if s.z_start - TOL_M <= z <= s.z_end + TOL_M))
        zc = min(max(z, sec.z_start), sec.z_end)
        ri, ro = float(sec.r_in(zc)), float(sec.r_out(zc))
        rad = {"mid": 0.5 * (ri + ro), "inner": ri, "outer": ro}.get(arr.radius, arr.radius)
        out.append(Sensor(f"{arr.name}_{i:02d}", "temperature", float(z), float(rad),
                          array=arr.name))
    return out
