"""Method of manufactured solutions on the axisymmetric operator.

The manufactured field crosses a conductivity jump (anisotropic k, different per part, the
flux k_z dT/dz continuous across the joint), has a volumetric source and Robin conditions
with a space-varying T_inf on every non-axis boundary. The conduction and Robin matrices
are the production ones (ThermalModel); only the manufactured loads are assembled here.
Expected L2 orders: p + 1 for P_p elements (Ciarlet; weighted spaces, Mercier & Raugel 1982).
"""

import numpy as np
from scipy.sparse.linalg import spsolve
from skfem import FacetBasis, asm

from meshes import build_mesh
from reference import ThermalModel
from reference.forms import film_load, volume_source
from tests.conftest import l2_error, observed_order

KA = (1.0, 2.0)  # (k_r, k_z) of part a [W/m/K], as in conftest MATERIALS
KB = (3.0, 6.0)
H = 5.0  # film coefficient on every outer boundary [W/m2/K]
ZJ = 0.5  # joint between the parts [m]

SPEC = """
[mesh]
h0_m = 0.25

[[parts]]
name = "a"
role = "shaft"
material = "mat_a"
sections = [{ z_start = 0.0, z_end = 0.5, r_inner = 0.0, r_outer = 1.0 }]

[[parts]]
name = "b"
role = "housing"
material = "mat_b"
sections = [{ z_start = 0.5, z_end = 1.0, r_inner = 0.0, r_outer = 1.0 }]

[[surfaces]]
name = "outer"
parts = ["a", "b"]
side = "outer"
h_W_m2K = 5.0
T_ref = "ambient"

[[surfaces]]
name = "rear"
parts = ["a"]
side = "rear"
h_W_m2K = 5.0
T_ref = "ambient"

[[surfaces]]
name = "front"
parts = ["b"]
side = "front"
h_W_m2K = 5.0
T_ref = "ambient"
"""


def g(r):
    return np.cos(np.pi * r) + 2.0  # g'(0) = 0: smooth on the axis


def g1(r):
    return -np.pi * np.sin(np.pi * r)


def g1_over_r(r):
    return -np.pi**2 * np.sinc(r)  # g'(r) / r, finite on the axis


def g2(r):
    return -np.pi**2 * np.cos(np.pi * r)


def f(z):
    c = KA[1] / KB[1] * np.exp(ZJ)
    return np.where(z <= ZJ, np.exp(z), np.exp(ZJ) + c * np.sin(z - ZJ))


def f1(z):
    c = KA[1] / KB[1] * np.exp(ZJ)
    return np.where(z <= ZJ, np.exp(z), c * np.cos(z - ZJ))


def f2(z):
    c = KA[1] / KB[1] * np.exp(ZJ)
    return np.where(z <= ZJ, np.exp(z), -c * np.sin(z - ZJ))


def exact(z, r):
    return 300.0 + f(z) * g(r)


def k_at(z):
    kr = np.where(z <= ZJ, KA[0], KB[0])
    kz = np.where(z <= ZJ, KA[1], KB[1])
    return kr, kz


def source(z, r):
    kr, kz = k_at(z)
    return -kr * f(z) * (g2(r) + g1_over_r(r)) - kz * g(r) * f2(z)


def t_inf(z, r, side):
    kr, kz = k_at(z)
    dn = {"outer": kr * f(z) * g1(r), "rear": -kz * f1(z) * g(r),
          "front": kz * f1(z) * g(r)}[side]
    return exact(z, r) + dn / H


def solve_mms(spec, level: int, order: int) -> tuple[float, float]:
    sm = build_mesh(spec, level)
    model = ThermalModel(sm, order)
    # elementwise-constant coefficients take the element's own part; evaluate the source
    # per part so the jump sits exactly on element boundaries
    b = model.quadrature_basis()
    z, r = np.asarray(b.global_coordinates())
    zc = b.mesh.p[0, b.mesh.t].mean(axis=0)[:, None] * np.ones_like(z)
    kr, kz = k_at(zc)
    q = (-kr * f(z) * (g2(r) + g1_over_r(r))
         - kz * g(r) * np.where(zc <= ZJ, np.exp(z), f2(z)))
    F = asm(volume_source, b, q=q)
    for side in ("outer", "rear", "front"):
        fb = FacetBasis(sm.mesh, b.elem, facets=sm.surfaces[side], intorder=2 * order + 1)
        zf, rf = np.asarray(fb.global_coordinates())
        F += asm(film_load, fb, h=H, T_inf=t_inf(zf, rf, side))
    T = spsolve(model.op.K(0.0).tocsc(), F)
    return sm.h_max_m, l2_error(model, T, exact)


class ConvergenceTest:
    """Observed L2 order over levels 1..4 must be within 0.15 of ``expected``."""

    order: int
    expected: float

    def test_rate(self, spec_from):
        spec = spec_from(SPEC, "mms")
        hs, errs = zip(*(solve_mms(spec, L, self.order) for L in range(1, 5)), strict=True)
        rate = observed_order(list(hs), list(errs))
        assert abs(rate - self.expected) <= 0.15, (rate, errs)
        assert all(e1 < e0 for e0, e1 in zip(errs, errs[1:], strict=False))


class TestMMSP1(ConvergenceTest):
    order, expected = 1, 2.0


class TestMMSP2(ConvergenceTest):
    order, expected = 2, 3.0


def test_manufactured_source_matches_operator():
    """The source formula is -div(k grad T) of the manufactured field (finite differences)."""
    z, r, d = 0.3, 0.4, 1e-4
    kr, kz = k_at(z)
    lap_r = (exact(z, r + d) - 2 * exact(z, r) + exact(z, r - d)) / d**2
    dr = (exact(z, r + d) - exact(z, r - d)) / (2 * d)
    lap_z = (exact(z + d, r) - 2 * exact(z, r) + exact(z - d, r)) / d**2
    fd = -kr * (lap_r + dr / r) - kz * lap_z
    assert abs(fd - source(z, r)) < 1e-5 * abs(source(z, r))
