"""Bad specs: one clear problem per fault, naming the file, the field and the fix."""

import pytest

from spindle.errors import SpecError
from spindle.spec_reader import load_spec, shipped_specs
from tests.conftest import write_spec

GOOD = """
[[parts]]
name = "shaft"
role = "shaft"
material = "mat_a"
sections = [{ z_start = 0.0, z_end = 0.2, r_inner = 0.0, r_outer = 0.02 }]

[[parts]]
name = "sleeve"
role = "housing"
material = "mat_b"
sections = [{ z_start = 0.05, z_end = 0.15, r_inner = 0.02, r_outer = 0.04 }]

[[surfaces]]
name = "out"
parts = ["sleeve"]
side = "outer"
h_W_m2K = 10.0
T_ref = "ambient"

[[sensors]]
name = "T1"
z = 0.1
r = 0.03
"""


def problems(tmp_path, body: str) -> list:
    with pytest.raises(SpecError) as exc:
        load_spec(write_spec(tmp_path, body))
    for p in exc.value.problems:
        assert p.file.endswith("case.toml") and p.field and p.message and p.fix
    return exc.value.problems


def test_good_spec_loads(tmp_path):
    spec = load_spec(write_spec(tmp_path, GOOD))
    assert [p.name for p in spec.parts] == ["shaft", "sleeve"]


@pytest.mark.parametrize("old, new, field, words", [
    ("r_outer = 0.04", "r_outer = 0.045 }, { z_start = 0.1, z_end = 0.12, r_inner = 0.0, "
     "r_outer = 0.03", "parts[1].sections[1]", "overlaps"),
    ("r_inner = 0.02, r_outer = 0.04", "r_inner = 0.025, r_outer = 0.04", "parts[1]",
     "separated from every other part by a gap"),
    ("r_inner = 0.0, r_outer = 0.02", "r_inner = 0.02, r_outer = 0.02",
     "parts[0].sections[0].r_inner", "not below r_outer"),
    ('material = "mat_a"', 'material = "unobtainium"', "parts[0].material", "unknown material"),
    ('role = "shaft"', 'role = "spoke"', "parts[0].role", "not one of"),
    ("r = 0.03", "r = 0.09", "sensors.T1", "outside every part"),
    ("z_end = 0.2,", "", "parts[0].sections[0].z_end", "required field is missing"),
    ("h_W_m2K = 10.0", "h_W_m2K = 0.0", "surfaces", "no heat path"),
    ('T_ref = "ambient"', "", "surfaces[0].T_ref", "required field is missing"),
    ("z_end = 0.2", "z_end = -0.2", "parts[0].sections[0].z_end", "not after z_start"),
])
def test_each_fault_is_named(tmp_path, old, new, field, words):
    assert old in GOOD
    found = problems(tmp_path, GOOD.replace(old, new, 1))
    assert any(p.field == field and words in p.message for p in found), found


def test_negative_conductivity_and_zero_heat_capacity(tmp_path):
    bad = GOOD + """
[materials.weird]
k_W_mK = -1.0
rho_kg_m3 = 1000.0
c_J_kgK = 0.0
E_Pa = 1e9
nu = 0.3
alpha_1_K = 1e-5
"""
    found = problems(tmp_path, bad)
    fields = {p.field for p in found}
    assert {"materials.weird.k_W_mK", "materials.weird.c_J_kgK"} <= fields
    assert all("not physical" in p.message for p in found)


def test_isolated_group_without_fixed_temperature(tmp_path):
    """Two parts that touch each other but not the rest, and have no film: singular."""
    body = GOOD + """
[[parts]]
name = "island"
role = "tool"
material = "mat_a"
sections = [{ z_start = 0.3, z_end = 0.4, r_inner = 0.0, r_outer = 0.02 }]
"""
    found = problems(tmp_path, body)
    assert any("separated from every other part" in p.message for p in found)


def test_rotor_and_stator_need_an_air_gap_link(tmp_path):
    body = """
[[parts]]
name = "rotor"
role = "rotor"
material = "mat_a"
sections = [{ z_start = 0.0, z_end = 0.1, r_inner = 0.0, r_outer = 0.02 }]

[[parts]]
name = "stator"
role = "stator"
material = "mat_b"
sections = [{ z_start = 0.0, z_end = 0.1, r_inner = 0.0205, r_outer = 0.04 }]

[[surfaces]]
name = "out"
parts = ["stator", "rotor"]
side = "outer"
h_W_m2K = 10.0
T_ref = "ambient"
"""
    found = problems(tmp_path, body)
    assert any(p.field == "links" and "air-gap" in p.message for p in found)
    ok = body + '\n[[links]]\ntype = "air_gap"\ninner = "rotor"\nouter = "stator"\nh_W_m2K = 50.0\n'
    spec = load_spec(write_spec(tmp_path, ok, "ok"))
    assert spec.links[0].h_W_m2K(0) == 50.0


def test_toml_syntax_error(tmp_path):
    found = problems(tmp_path, GOOD + "\n[[parts]\n")
    assert found[0].field == "syntax"


def test_all_problems_reported_at_once(tmp_path):
    bad = GOOD.replace('material = "mat_a"', 'material = "nope"').replace(
        'role = "housing"', 'role = "hat"')
    assert len(problems(tmp_path, bad)) >= 2


def test_unknown_spec_name():
    with pytest.raises(SpecError, match="neither a file nor a shipped spec"):
        load_spec("no-such-spindle")


def test_shipped_specs_load():
    assert {"spl2782", "fin-shaft"} <= set(shipped_specs())
    for path in shipped_specs().values():
        load_spec(path)


def test_film_from_a_correlation(tmp_path):
    from spindle.power import h_rotating_shaft_W_m2K

    body = GOOD.replace("h_W_m2K = 10.0",
                        'h_W_m2K = { correlation = "rotating_shaft", d_m = 0.08, factor = 2.0 }')
    spec = load_spec(write_spec(tmp_path, body))
    h = spec.surfaces[0].h_W_m2K
    assert h(4300.0) == pytest.approx(2.0 * h_rotating_shaft_W_m2K(4300.0, 0.08))
    bad = GOOD.replace("h_W_m2K = 10.0", 'h_W_m2K = { correlation = "magic", d_m = 0.08 }')
    assert any(p.field == "surfaces[0].h_W_m2K.correlation" for p in problems(tmp_path, bad))
    bad = GOOD.replace("h_W_m2K = 10.0", 'h_W_m2K = { correlation = "air_gap", d_m = 0.08 }')
    assert any("not a parameter" in p.message for p in problems(tmp_path, bad))
    # a diameter of 1e300 m overflowed the correlation's Rayleigh number (d^3): a problem of
    # the field, not an internal error
    bad = GOOD.replace("h_W_m2K = 10.0",
                       'h_W_m2K = { correlation = "rotating_shaft", d_m = 1e300 }')
    assert any(p.field == "surfaces[0].h_W_m2K" and "overflows" in p.message
               for p in problems(tmp_path, bad))
    # a parameter's unit is its name's (it was "SI")
    bad = GOOD.replace("h_W_m2K = 10.0", 'h_W_m2K = { correlation = "coolant_channel", '
                       'flow_l_min = -6.0, width_m = 0.006, height_m = 0.01 }')
    (p,) = [p for p in problems(tmp_path, bad) if p.field.endswith("flow_l_min")]
    assert "-6 l/min" in p.message and "l/min" in p.fix and "SI" not in str(p)


def test_python_api_takes_a_spec_name_or_path():
    """Issue 16: wherever the Python API takes a spec, a shipped name or a path works, as on
    the command line; anything else is a TypeError naming what is accepted."""
    import lumped
    from lumped import Fin
    from meshes import build_mesh
    from reference import ReferenceModel
    from spindle.spec_reader import load_spec, resolve_spec_path

    by_name = lumped.build("fin-shaft", 5)
    by_path = lumped.build(resolve_spec_path("fin-shaft"), 5)
    by_spec = lumped.build(load_spec("fin-shaft"), 5)
    assert by_name.n_states == by_path.n_states == by_spec.n_states
    assert build_mesh("fin-shaft", 0).mesh.nelements == build_mesh(load_spec("fin-shaft"), 0
                                                                    ).mesh.nelements
    assert ReferenceModel("fin-shaft", 0).spec.name == "fin-shaft"
    assert Fin.from_spec("fin-shaft") == Fin.from_spec(load_spec("fin-shaft"))
    with pytest.raises(TypeError, match="shipped name or a path"):
        lumped.build(3)


def test_a_value_just_beyond_its_bound_is_written_in_full(tmp_path):
    """nu = 0.4999999999 was reported as "0.5 - is out of range (must be <= 0.4999)", a
    message that contradicts itself; the value is written as given."""
    found = problems(tmp_path, GOOD + """
[materials.rubbery]
k_W_mK = 1.0
rho_kg_m3 = 1000.0
c_J_kgK = 1000.0
E_Pa = 1e9
nu = 0.4999999999
alpha_1_K = 1e-5
""")
    nu = [p for p in found if p.field == "materials.rubbery.nu"]
    assert nu and "0.4999999999 - is out of range (must be <= 0.4999)" in nu[0].message, found


def _shipped_text() -> str:
    from spindle.spec_reader import shipped_specs

    return shipped_specs()["spl2782"].read_text(encoding="utf-8")


def problems_of_file(tmp_path, text: str) -> list:
    """The problems of a whole spec file (a shipped spec, changed)."""
    path = tmp_path / "case.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(SpecError) as exc:
        load_spec(path)
    return exc.value.problems


def _without_parts(text: str) -> str:
    import re

    return "".join(b for b in re.split(r"(?m)^(?=\[)", text) if not b.startswith("[[parts]]"))


@pytest.mark.parametrize("head, words", [
    ("", "required list is missing"),
    ("parts = []\n", "the list is empty"),
])
def test_a_spec_without_parts_is_one_problem(tmp_path, head, words):
    """Without parts, every link, surface, source and sensor array named an unknown part: 27
    lines for one cause; `parts = []` was not named at all, only its consequences."""
    found = problems_of_file(tmp_path, _without_parts(_shipped_text()).replace(
        "[spindle]", head + "[spindle]", 1))
    assert len(found) == 1 and found[0].field == "parts" and words in found[0].message, found


def test_an_array_radius_outside_its_part_is_one_problem(tmp_path):
    """A radius of 5 m put each of the array's 11 sensors outside every part: 11 lines for one
    field."""
    text = _shipped_text()
    old = 'name = "shaft"\npart = "shaft"\ncount = 11\nradius = "mid"'
    assert old in text
    found = problems_of_file(tmp_path, text.replace(old, old.replace('"mid"', "5.0")))
    assert len(found) == 1 and found[0].field == "sensor_arrays.shaft.radius", found
    assert "puts 11 of the array's 11 sensors outside every part" in found[0].message


def test_a_section_whose_material_is_broken_is_one_problem(tmp_path):
    """A conductivity of 0 in the bearings' rolling-layer material also gave four lines
    "part '...' has no section named 'rolling'" for the links and sources that use the
    sections of that material (found by fuzzing)."""
    text = _shipped_text() + """
[materials.rolling_layer_equivalent]
k_W_mK = 0.0
rho_kg_m3 = 7800.0
c_J_kgK = 470.0
E_Pa = 2.0e11
nu = 0.3
alpha_1_K = 1.1e-5
"""
    found = problems_of_file(tmp_path, text)
    assert [p.field for p in found] == ["materials.rolling_layer_equivalent.k_W_mK"], found


@pytest.mark.parametrize("sections, alone", [
    # a bore wider than the neighbour's outside: the two touch in no face (found by fuzzing)
    ("[{ z_start = 0.0, z_end = 0.25, r_inner = 0.0, r_outer = 0.01 }, "
     "{ z_start = 0.25, z_end = 0.5, r_inner = 0.02, r_outer = 0.025 }]", 1),
    # a ring around the shaft with a 1 mm gap between them, listed first
    ("[{ z_start = 0.1, z_end = 0.2, r_inner = 0.026, r_outer = 0.03 }, "
     "{ z_start = 0.0, z_end = 0.5, r_inner = 0.0, r_outer = 0.025 }]", 0),
])
def test_sections_that_share_no_face_are_not_one_part(tmp_path, sections, alone):
    """A part is one body: its sections were checked for gaps along z only, so two bodies
    that meet in a line or not at all were solved as one part."""
    text = shipped_specs()["fin-shaft"].read_text(encoding="utf-8")
    old = "sections = [{ z_start = 0.0, z_end = 0.5, r_inner = 0.0, r_outer = 0.025 }]"
    assert old in text
    found = problems_of_file(tmp_path, text.replace(old, f"sections = {sections}"))
    assert [p.field for p in found] == [f"parts[0].sections[{alone}]"], found
    assert "shares no face" in found[0].message


def test_sections_joined_radially_or_end_to_end_are_one_part(tmp_path):
    """The joins a part may have: a ring on the shaft (one's r_outer the other's r_inner) and
    a step in diameter where one ends and the next starts (as the shipped specs' bearings
    and shafts)."""
    text = shipped_specs()["fin-shaft"].read_text(encoding="utf-8")
    old = "sections = [{ z_start = 0.0, z_end = 0.5, r_inner = 0.0, r_outer = 0.025 }]"
    path = tmp_path / "joined.toml"
    path.write_text(text.replace(old, (
        "sections = [{ z_start = 0.0, z_end = 0.25, r_inner = 0.0, r_outer = 0.025 }, "
        "{ z_start = 0.25, z_end = 0.5, r_inner = 0.0, r_outer = 0.02 }, "
        "{ z_start = 0.1, z_end = 0.2, r_inner = 0.025, r_outer = 0.03 }]")), encoding="utf-8")
    assert len(load_spec(path).parts[0].sections) == 3


@pytest.mark.parametrize("old, new, field", [
    # a unit slip or an exponent below any solid or gas a spec meshes (found by fuzzing:
    # E = 1 Pa solved to a TCP growth of 33.9 µm)
    ("E_Pa = 1e9", "E_Pa = 1.0", "materials.mat_a.E_Pa"),
    ("E_Pa = 1e9", "E_Pa = 200.0", "materials.mat_a.E_Pa"),  # GPa written as Pa
    ("c_J_kgK = 500.0", "c_J_kgK = 1e-300", "materials.mat_a.c_J_kgK"),
    ("c_J_kgK = 500.0", "c_J_kgK = 0.5", "materials.mat_a.c_J_kgK"),  # kJ/kg/K
    ("rho_kg_m3 = 1000.0", "rho_kg_m3 = 1e-3", "materials.mat_a.rho_kg_m3"),
    ("k_r_W_mK = 1.0", "k_r_W_mK = 1e-300", "materials.mat_a.k_r_W_mK"),
])
def test_a_material_below_any_solid_or_gas_is_named(tmp_path, old, new, field):
    """The lower bounds of spindle.spec_reader._read_material: air's layer (0.026 W/m/K,
    1.18 kg/m3, E 1e5 Pa) and lead's 129 J/kg/K pass, these do not."""
    from tests.conftest import MATERIALS

    assert old in MATERIALS  # its first occurrence is mat_a's
    path = write_spec(tmp_path, GOOD)
    path.write_text(path.read_text(encoding="utf-8").replace(old, new, 1), encoding="utf-8")
    with pytest.raises(SpecError) as exc:
        load_spec(path)
    assert [p.field for p in exc.value.problems] == [field], exc.value.problems
    assert "is not physical (must be >=" in exc.value.problems[0].message


def test_a_film_table_at_a_negative_speed_is_named(tmp_path):
    """A speed is its magnitude, as in the cycles: a table row at -100 rpm was accepted and
    never used (found by fuzzing)."""
    found = problems(tmp_path, GOOD.replace(
        "h_W_m2K = 10.0", "h_W_m2K = { speed_rpm = [-100.0, 0.0], value = [10.0, 10.0] }", 1))
    assert [p.field for p in found] == ["surfaces[0].h_W_m2K.speed_rpm"], found


def test_bearings_without_a_shaft_say_that_no_part_is_the_shaft(tmp_path):
    """A spec whose shaft has another role (a user's mutation: role = "tool") was told only
    that each bearing must touch the shaft; the first problem now says no part is one."""
    from pathlib import Path

    text = Path(load_spec("spl2782").path).read_text(encoding="utf-8")
    path = tmp_path / "case.toml"
    path.write_text(text.replace('role = "shaft"', 'role = "tool"', 1), encoding="utf-8")
    with pytest.raises(SpecError) as exc:
        load_spec(path)
    found = exc.value.problems
    assert found[0].field == "parts" and 'no part has the role "shaft"' in found[0].message
    assert 'role = "shaft"' in found[0].fix
