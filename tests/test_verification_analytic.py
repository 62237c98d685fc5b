"""Analytic cases through the whole production path: TOML spec -> mesh -> solve -> sensors."""

import math

import numpy as np
import pytest

from meshes import build_mesh
from reference import ThermalModel

K_ROD = 20.0  # W/m/K

ROD = """
[materials.rod_steel]
k_W_mK = 20.0
rho_kg_m3 = 7800.0
c_J_kgK = 460.0
E_Pa = 2e11
nu = 0.3
alpha_1_K = 1.2e-5

[mesh]
h0_m = 0.01

[[parts]]
name = "rod"
role = "shaft"
material = "rod_steel"
sections = [{{ z_start = 0.0, z_end = 0.1, r_inner = {ri}, r_outer = 0.05 }}]

[[surfaces]]
name = "outer"
parts = ["rod"]
side = "outer"
h_W_m2K = 50.0
T_ref = "ambient"

[[heat_sources]]
name = "q"
part = "rod"
power_W = 200.0

{sensors}
"""


def radial_sensors(radii):
    return "\n".join(f'[[sensors]]\nname = "r{i}"\nz = 0.05\nr = {r}\n'
                     for i, r in enumerate(radii))


def cylinder_exact(r, ri, ro=0.05, L=0.1, P=200.0, k=K_ROD, h=50.0, T_inf=300.0):
    """Long (ends adiabatic) cylinder, uniform source P/V, inner face adiabatic, outer Robin.

    T = -q r^2/(4k) + C1 ln r + C2 with C1 = q ri^2 / (2k) (zero flux at ri) and C2 from
    -k T'(ro) = h (T(ro) - T_inf). Solid: ri = 0, C1 = 0.
    """
    q = P / (math.pi * (ro**2 - ri**2) * L)
    c1 = q * ri**2 / (2 * k)
    dT_ro = -q * ro / (2 * k) + c1 / ro
    T_ro = T_inf - k * dT_ro / h
    c2 = T_ro + q * ro**2 / (4 * k) - (c1 * math.log(ro) if ri > 0 else 0.0)
    return -q * np.asarray(r) ** 2 / (4 * k) + (c1 * np.log(r) if ri > 0 else 0.0) + c2


def test_solid_cylinder_is_exact_in_p2(spec_from):
    """T is quadratic in r, so it lies in the P2 space and Galerkin returns it exactly:
    any error above round-off would be an assembly error (weights, source scaling, Robin)."""
    radii = [0.0, 0.013, 0.031, 0.05]
    spec = spec_from(ROD.format(ri=0.0, sensors=radial_sensors(radii)), "solid")
    res = ThermalModel(build_mesh(spec, 1), 2).solve_steady()
    got = np.array([res.sensors[f"r{i}"] for i in range(len(radii))])
    np.testing.assert_allclose(got, cylinder_exact(radii, 0.0), rtol=0, atol=1e-9)
    assert res.energy["relative_imbalance"] < 1e-10


@pytest.mark.parametrize("order, min_rate", [(1, 1.8), (2, 2.8)])
def test_hollow_cylinder_converges(spec_from, order, min_rate):
    """ln r is not polynomial: point errors fall at the L2 rate p + 1 (within 0.2; the
    sensor points are mesh nodes of all levels, so no superconvergence is relied on)."""
    ri = 0.02
    radii = [0.02, 0.0275, 0.035, 0.05]
    spec = spec_from(ROD.format(ri=ri, sensors=radial_sensors(radii)), "hollow")
    exact = cylinder_exact(radii, ri)
    errs = []
    for level in range(3):
        res = ThermalModel(build_mesh(spec, level), order).solve_steady()
        got = np.array([res.sensors[f"r{i}"] for i in range(len(radii))])
        errs.append(np.max(np.abs(got - exact)))
    rates = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(rates > min_rate), (errs, rates)
    rise = exact.max() - 300.0
    assert errs[-1] < 1e-3 * rise


SLAB = """
[mesh]
h0_m = 0.02

[[parts]]
name = "a"
role = "shaft"
material = "mat_a"
sections = [{ z_start = 0.0, z_end = 0.1, r_inner = 0.0, r_outer = 0.03 }]

[[parts]]
name = "b"
role = "tool"
material = "mat_b"
sections = [{ z_start = 0.1, z_end = 0.25, r_inner = 0.0, r_outer = 0.03 }]

[[links]]
type = "contact"
parts = ["a", "b"]
h_W_m2K = 800.0

[[surfaces]]
name = "heated_end"
parts = ["a"]
side = "rear"

[[surfaces]]
name = "cooled_end"
parts = ["b"]
side = "front"
h_W_m2K = 100.0
T_ref = "ambient"

[[heat_sources]]
name = "P"
surface = "heated_end"
power_W = 2.0

[[sensors]]
name = "z0"
z = 0.0
r = 0.01
[[sensors]]
name = "z05"
z = 0.05
r = 0.02
[[sensors]]
name = "a_side"
z = 0.0999999
r = 0.0
[[sensors]]
name = "b_side"
z = 0.1000001
r = 0.0
[[sensors]]
name = "z25"
z = 0.25
r = 0.03
"""


@pytest.mark.parametrize("order", [1, 2])
def test_two_material_slab_with_contact_conductance(spec_from, order):
    """1-D conduction in z through k_z = 2 and 6 W/m/K with a joint of 800 W/m2/K: the
    profile is piecewise linear with a jump q/h_c at the joint, exact in P1 and P2."""
    spec = spec_from(SLAB, "slab")
    res = ThermalModel(build_mesh(spec, 1), order).solve_steady()
    q = 2.0 / (math.pi * 0.03**2)  # W/m2
    T_front = 300.0 + q / 100.0
    T_b_joint = T_front + q * 0.15 / 6.0
    T_a_joint = T_b_joint + q / 800.0

    def T_a(z):
        return T_a_joint + q * (0.1 - z) / 2.0

    s = res.sensors
    expect = {"z0": T_a(0.0), "z05": T_a(0.05), "z25": T_front,
              "a_side": T_a(0.0999999), "b_side": T_b_joint - q * 1e-7 / 6.0}
    for name, value in expect.items():
        assert abs(s[name] - value) < 1e-8 * value, (name, s[name], value)
    # the jump: q / h_c, plus the two gradients over the 2e-7 m between the probes
    jump = q / 800.0 + q * 1e-7 * (1 / 2.0 + 1 / 6.0)
    assert s["a_side"] - s["b_side"] == pytest.approx(jump, rel=1e-7)


def test_probe_interpolates_between_nodes(spec_from):
    """A field linear in z and r is exact in P1; sampling between nodes must return the
    linear value (a nearest-node lookup would be off by up to half an element's slope)."""
    spec = spec_from(ROD.format(ri=0.0, sensors=""), "probe")
    model = ThermalModel(build_mesh(spec, 0), 1)
    p = model.basis.doflocs
    T = 300.0 + 100.0 * p[0] + 40.0 * p[1]
    pts = np.array([[0.0123, 0.0456, 0.0999], [0.0037, 0.0211, 0.0444]])
    got = model.probe_matrix(pts) @ T
    np.testing.assert_allclose(got, 300.0 + 100.0 * pts[0] + 40.0 * pts[1], rtol=1e-13)


LAYERS = """
[mesh]
h0_m = 0.005

[[parts]]
name = "inner"
role = "{inner_role}"
material = "mat_b"
sections = [{{ z_start = 0.0, z_end = 0.05, r_inner = 0.0, r_outer = 0.04 }}]

[[parts]]
name = "middle"
role = "{middle_role}"
material = "mat_b"
sections = [{middle}]

[[parts]]
name = "outer"
role = "housing"
material = "mat_b"
sections = [{{ z_start = 0.0, z_end = 0.05, r_inner = {r_house}, r_outer = 0.07 }}]

[[links]]
{link}

[[surfaces]]
name = "out"
parts = ["outer"]
side = "outer"
h_W_m2K = 100.0
T_ref = "ambient"

[[heat_sources]]
name = "P"
part = "inner"
power_W = 50.0

[[sensors]]
name = "a"
z = 0.025
r = 0.04
[[sensors]]
name = "b"
z = 0.025
r = {r_house}
"""


def test_bearing_layer_has_the_link_conductance(spec_from):
    """All 50 W cross the rolling layer radially (ends adiabatic): its temperature drop is
    P / G exactly in the continuum; P2 on level 2 resolves the ln r profile to 1e-5."""
    body = LAYERS.format(
        inner_role="shaft", middle_role="front_bearing", r_house=0.05,
        middle='{ name = "rolling", z_start = 0.0, z_end = 0.05, r_inner = 0.04, '
               'r_outer = 0.05, material = "rolling_layer_equivalent" }',
        link='type = "bearing"\npart = "middle"\nsection = "rolling"\nG_W_K = 20.0')
    # the spec needs the middle part to touch the shaft and housing: it does by radii
    res = ThermalModel(build_mesh(spec_from(body, "brg"), 2), 2).solve_steady()
    drop = res.sensors["a"] - res.sensors["b"]
    assert drop == pytest.approx(50.0 / 20.0, rel=1e-5)


def test_air_gap_layer_has_the_link_coefficient(spec_from):
    """The air-gap coefficient h acts on the rotor surface: drop = P / (h 2 pi r_i L)."""
    body = LAYERS.format(
        inner_role="rotor", middle_role="cooling_sleeve", r_house=0.0405,
        middle='{ z_start = 0.0, z_end = 0.05, r_inner = 0.07, r_outer = 0.08 }',
        link='type = "air_gap"\ninner = "inner"\nouter = "outer"\nh_W_m2K = 80.0')
    body = body.replace('role = "housing"', 'role = "stator"').replace(
        'parts = ["outer"]', 'parts = ["outer", "middle"]')
    res = ThermalModel(build_mesh(spec_from(body, "gap"), 2), 2).solve_steady()
    drop = res.sensors["a"] - res.sensors["b"]
    assert drop == pytest.approx(50.0 / (80.0 * 2 * math.pi * 0.04 * 0.05), rel=1e-5)
