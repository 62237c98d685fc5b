"""Thermoelastic verification: exact free expansion, the classical plane-strain hollow
cylinder, the fixed/floating bearing arrangement, and convergence of P1."""

import numpy as np
import pytest

from meshes import build_mesh
from reference import ThermalModel
from reference.elastic import ThermoelasticModel
from spindle.spec_reader import load_spec

TWO_BODIES = """
[materials.soft]
k_W_mK = 10.0
rho_kg_m3 = 2000.0
c_J_kgK = 500.0
E_Pa = 5e10
nu = 0.25
alpha_1_K = 1.2e-5

[materials.stiff]
k_W_mK = 40.0
rho_kg_m3 = 8000.0
c_J_kgK = 450.0
E_Pa = 2e11
nu = 0.3
alpha_1_K = 1.2e-5

[mesh]
h0_m = 0.01

[[parts]]
name = "core"
role = "shaft"
material = "stiff"
sections = [{ z_start = 0.0, z_end = 0.06, r_inner = 0.0, r_outer = 0.02 }]

[[parts]]
name = "ring"
role = "rotor"
material = "soft"
sections = [{ z_start = 0.01, z_end = 0.05, r_inner = 0.02, r_outer = [0.03, 0.035] }]

[[links]]
type = "contact"
parts = ["core", "ring"]
h_W_m2K = 1000.0

[[surfaces]]
name = "out"
parts = ["ring"]
side = "outer"
h_W_m2K = 10.0
T_ref = "ambient"
"""


@pytest.mark.parametrize("order", [1, 2])
def test_uniform_rise_on_a_free_body_is_exact(spec_from, order):
    """Same alpha, different E, bonded across a (thermally split) joint, conical ring: a
    uniform rise is stress-free, u = alpha dT x from the axial support (lowest z on the
    axis). Linear fields are in the P1 and P2 spaces, so the match is to round-off."""
    spec = spec_from(TWO_BODIES, "free")
    th = ThermalModel(build_mesh(spec, 1), order)
    el = ThermoelasticModel(th)
    dT = 40.0
    u = el.displacement(np.full(th.basis.N, el.T_ref + dT))
    x = el.basis.doflocs
    a = 1.2e-5 * dT
    np.testing.assert_allclose(u[el.iz], a * x[0, el.iz], atol=1e-14)
    np.testing.assert_allclose(u[el.ir], a * x[1, el.ir], atol=1e-14)


PIPE = """
[materials.pipe_steel]
k_W_mK = 40.0
rho_kg_m3 = 7800.0
c_J_kgK = 460.0
E_Pa = 2e11
nu = 0.3
alpha_1_K = 1.2e-5

[mesh]
h0_m = 0.01

[[parts]]
name = "pipe"
role = "shaft"
material = "pipe_steel"
sections = [{ z_start = 0.0, z_end = 0.04, r_inner = 0.02, r_outer = 0.05 }]

[[surfaces]]
name = "out"
parts = ["pipe"]
side = "outer"
h_W_m2K = 10.0
T_ref = "ambient"

[[surfaces]]
name = "front"
parts = ["pipe"]
side = "front"

[[surfaces]]
name = "rear"
parts = ["pipe"]
side = "rear"
"""


def plane_strain_ur(r, a, b, nu, alpha, dT):
    """Hollow cylinder, free radial surfaces, plane strain, T = dT (r/b)^2 above T_ref.

    (lam + 2 mu) (u'' + u'/r - u/r^2) = (3 lam + 2 mu) alpha T' gives
    u = k alpha I(r)/r + C1 r + C2/r with k = (1+nu)/(1-nu), I(r) = int_a^r T s ds
    (Timoshenko & Goodier, Theory of Elasticity, sec. 151); C1, C2 from sigma_r(a) =
    sigma_r(b) = 0 are solved here as a 2x2 system, independently of the FEM code.
    """
    E = 1.0  # sigma_r = 0 does not depend on E
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    k = (1 + nu) / (1 - nu)

    def T(s):
        return dT * (s / b) ** 2

    def integral(s):
        return dT * (s**4 - a**4) / (4 * b**2)

    def sigma_r_parts(s):
        # sigma_r = (lam+2mu) u' + lam u/s - (3lam+2mu) alpha T, split by unknown
        part = (lam + 2 * mu) * (k * alpha * T(s) - k * alpha * integral(s) / s**2) \
            + lam * k * alpha * integral(s) / s**2 - (3 * lam + 2 * mu) * alpha * T(s)
        c1 = (lam + 2 * mu) + lam
        c2 = -(lam + 2 * mu) / s**2 + lam / s**2
        return part, c1, c2

    rows = [sigma_r_parts(a), sigma_r_parts(b)]
    C = np.linalg.solve([[x[1], x[2]] for x in rows], [-x[0] for x in rows])
    r = np.asarray(r)
    return k * alpha * integral(r) / r + C[0] * r + C[1] / r


def test_hollow_cylinder_plane_strain(spec_from):
    """u_z = 0 on both end faces (radially free) makes the pipe exactly plane strain."""
    spec = spec_from(PIPE, "pipe")
    radii = np.array([0.02, 0.03, 0.041, 0.05])
    exact = plane_strain_ur(radii, 0.02, 0.05, 0.3, 1.2e-5, 50.0)
    errs = []
    for level in range(3):
        th = ThermalModel(build_mesh(spec, level), 2)
        el = ThermoelasticModel(th, fixed_axial=["front", "rear"])
        x = th.basis.doflocs
        u = el.displacement(el.T_ref + 50.0 * (x[1] / 0.05) ** 2)
        pm = el.basis.probes(np.vstack([np.full(4, 0.02), radii])).tocsr()
        errs.append(np.max(np.abs((pm @ u)[4:] - exact)))
    assert errs[-1] < 1e-4 * np.max(np.abs(exact)), errs
    assert errs[2] < errs[1] < errs[0]


@pytest.fixture(scope="module")
def spl_level0():
    spec = load_spec("spl2782")
    th = ThermalModel(build_mesh(spec, 0), 2)
    return spec, th, ThermoelasticModel(th)


def test_front_bearing_locates_rear_floats(spl_level0):
    """Heat only the rotating parts uniformly: the shaft grows from the fixed front pair,
    so P1 = alpha dT (z_face - z0) with z0 inside the front bearing (0.430..0.478 m). A
    rear bearing that did not float would push z0 rearwards, out of that span."""
    spec, th, el = spl_level0
    dT = 30.0
    rot = np.concatenate([th.smesh.elements_of(p) for p in ("shaft", "rotor", "tool")]
                         + [th.smesh.elements_of(b, "inner_ring")
                            for b in ("front_bearing", "rear_bearing")])
    T = np.full(th.basis.N, el.T_ref)
    T[np.unique(th.basis.element_dofs[:, rot])] += dT
    p1 = float(el.read("P1", T))
    z0 = 0.5295 - p1 / (11.1e-6 * dT)
    assert 0.43 < z0 < 0.478, z0


def test_centrifugal_shortens_the_shaft(spl_level0):
    spec, th, el = spl_level0
    T = np.full(th.basis.N, el.T_ref)
    short = [float(el.read("P1", T, n, centrifugal=True)) for n in (4300, 8600)]
    assert short[0] < 0
    assert short[1] == pytest.approx(4 * short[0], rel=1e-12)  # proportional to n^2


def test_p1_converges_under_refinement():
    """P2, levels 0..2 on spl2782 at the nominal point: P1 differences shrink by > 2 per
    level (re-entrant corners limit the rate below 3)."""
    spec = load_spec("spl2782")
    p1 = []
    for level in range(3):
        th = ThermalModel(build_mesh(spec, level), 2)
        p1.append(float(ThermoelasticModel(th).read("P1", th.solve_steady().T)))
    d = np.abs(np.diff(p1))
    assert d[1] < d[0] / 2, p1
    assert abs(p1[2] - p1[1]) < 0.005 * abs(p1[2])


def test_transient_growth_readings_match_direct_solves():
    """The per-step readings (adjoint gains) equal full elastic solves on the saved fields,
    both taken from the start (the readings and the saved displacement fields are zeroed at
    t = 0, as a bench zeroes P1; the centrifugal part at the start's 4300 rpm included)."""
    from reference import ReferenceModel
    from spindle.loads import LoadCase, TimeSeries

    spec = load_spec("spl2782")
    ref = ReferenceModel(spec, level=0, centrifugal=True)
    base = spec.default_load_case()
    case = LoadCase("warm", TimeSeries((0.0, 1800.0), (4300.0, 2000.0), "previous"),
                    TimeSeries.constant(293.15), TimeSeries.constant(293.15), base.sources,
                    duration_s=3600.0)
    res = ref.transient(case, 300.0, save_every=6)
    el = ref.elastic
    p = el.axial_probe(0.5295, 0.05) - el.axial_probe(0.5, 0.095)
    start = float((p @ el.displacement(res.fields_K[0], 4300.0, centrifugal=True))[0])
    assert res.field_times_s[0] == 0.0 and res.growth_m["P1"][0] == 0.0
    for i, (t, T) in enumerate(zip(res.field_times_s, res.fields_K, strict=True)):
        k = int(np.argmin(np.abs(res.times_s - t)))
        n = 4300.0 if t <= 1800.0 else 2000.0
        direct = float((p @ el.displacement(T, n, centrifugal=True))[0]) - start
        assert res.growth_m["P1"][k] == pytest.approx(direct, rel=1e-9, abs=1e-15)
        assert float((p @ res.U_fields[i])[0]) == pytest.approx(direct, rel=1e-9, abs=1e-15)
    assert res.growth_m["P1"][-1] > 0 and "TCP" in res.growth_m


def gps_axial_strain(a: float, b: float, alpha: float, dT: float) -> float:
    """Generalised plane strain of a long free hollow cylinder (a <= r <= b [m]) with
    T = dT (r/b)^2 [K] above the reference: zero axial force makes the axial strain uniform,
    eps_z = 2 alpha / (b^2 - a^2) int_a^b T r dr = alpha dT (a^2 + b^2) / (2 b^2),
    independent of nu (Timoshenko & Goodier, sec. 151; Boley & Weiner, sec. 9.10)."""
    return alpha * dT * (a * a + b * b) / (2 * b * b)


@pytest.mark.parametrize("nu", [0.3, 0.45])
def test_long_free_cylinder_generalised_plane_strain(spec_from, nu):
    """The case that isolates the axial strain of a field varying with r alone (issue 15 §2):
    a 1 m pipe (a = 20 mm, b = 50 mm), free but for one axial support; u_z between
    z = 0.4 and 0.6 m (Saint-Venant end effects decay within a few wall thicknesses, 30 mm)
    over 0.2 m is eps_z at every radius. P2 elements hold the solution: the match is to
    1e-6 (measured: 1e-9 at level 0); P1 elements converge at the observed order 2
    (measured 2.000: 1.15 %, 0.287 %, 0.072 % at levels 0-2)."""
    a, b, dT, alpha = 0.02, 0.05, 50.0, 1.2e-5
    spec = spec_from(PIPE.replace("z_end = 0.04", "z_end = 1.0").replace(
        "nu = 0.3", f"nu = {nu}"), "gps")
    exact = gps_axial_strain(a, b, alpha, dT)
    radii = np.linspace(a, b, 7)

    def strain(level: int, order: int) -> np.ndarray:
        th = ThermalModel(build_mesh(spec, level), order)
        el = ThermoelasticModel(th)
        u = el.displacement(el.T_ref + dT * (th.basis.doflocs[1] / b) ** 2)

        def uz(z: float) -> np.ndarray:
            return (el.basis.probes(np.vstack([np.full(7, z), radii])).tocsr() @ u)[:7]

        return (uz(0.6) - uz(0.4)) / 0.2

    assert np.max(np.abs(strain(0, 2) / exact - 1)) < 1e-6
    errs = [float(np.max(np.abs(strain(level, 1) / exact - 1))) for level in (0, 1, 2)]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.1), (errs, orders)


def test_the_air_gap_carries_no_load():
    """The rotor-stator air-gap layer has no stiffness (issue 15 §3): P1 does not change when
    the modulus given to air goes from 1e5 to 1e9 Pa (it moved 0.074 µm at level 2 while the
    layer had E = 1e5 Pa); a stiff air gap would couple rotor and stator axially."""
    from dataclasses import replace

    from spindle.spec_reader import shipped_materials

    spec = load_spec("spl2782")
    air = spec.materials.get("air") or shipped_materials()["air"]
    p1 = []
    for E in (1e5, 1e9):
        s = replace(spec, materials={**spec.materials, "air": replace(air, E_Pa=E)})
        th = ThermalModel(build_mesh(s, 0), 2)
        T = np.full(th.basis.N, spec.T_initial_K)
        rot = np.concatenate([th.smesh.elements_of(p) for p in ("shaft", "rotor")])
        T[np.unique(th.basis.element_dofs[:, rot])] += 30.0  # rotor hot, stator cold
        p1.append(float(ThermoelasticModel(th).read("P1", T)))
    assert p1[1] == pytest.approx(p1[0], rel=1e-9, abs=1e-12), p1
