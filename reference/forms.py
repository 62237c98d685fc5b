"""Axisymmetric weak forms in the (z, r) half-plane: ``x[0]`` is z, ``x[1]`` is r [m].

Every form carries the weight r of the cylindrical volume element dV = 2 pi r dr dz; the
common factor 2 pi is dropped throughout, so heat flows in W are 2 pi times the assembled
quantities. The axis r = 0 needs no boundary term: the weight r vanishes there, which is the
natural (symmetry) condition dT/dr = 0.
"""

from skfem import BilinearForm, LinearForm


@BilinearForm
def conduction(u, v, w):
    """Anisotropic Fourier conduction: k_z dT/dz dv/dz + k_r dT/dr dv/dr  [W/m/K]."""
    return (w.kz * u.grad[0] * v.grad[0] + w.kr * u.grad[1] * v.grad[1]) * w.x[1]


@BilinearForm
def capacity(u, v, w):
    """Heat capacity rho c [J/m3/K]."""
    return w.rhoc * u * v * w.x[1]


@BilinearForm
def film(u, v, w):
    """Robin (convection) term with film coefficient h [W/m2/K] on a facet basis."""
    return w.h * u * v * w.x[1]


@LinearForm
def film_load(v, w):
    """Robin right-hand side h T_inf [W/m2]."""
    return w.h * w.T_inf * v * w.x[1]


@LinearForm
def volume_source(v, w):
    """Volumetric heat source q [W/m3]."""
    return w.q * v * w.x[1]


@LinearForm
def surface_flux(v, w):
    """Heat flux into the body q_s [W/m2] on a facet basis."""
    return w.qs * v * w.x[1]


# --------------------------------------------------------------------- thermoelasticity
# Displacement u = (u_z, u_r). Axisymmetric strains (Voigt): e_zz = du_z/dz, e_rr = du_r/dr,
# e_tt = u_r / r (hoop), g_zr = du_z/dr + du_r/dz. Isotropic Hooke with Lame lam, mu; the shear
# modulus of the g_zr term is mu_s (= mu, except where a floating bearing lets the rings slide).


def _strains(u, r):
    return u.grad[0][0], u.grad[1][1], u[1] / r, u.grad[0][1] + u.grad[1][0]


@BilinearForm
def elasticity(u, v, w):
    """Strain energy density [Pa] of the axisymmetric body."""
    r = w.x[1]
    ezz, err, ett, gzr = _strains(u, r)
    fzz, frr, ftt, hzr = _strains(v, r)
    tr_u, tr_v = ezz + err + ett, fzz + frr + ftt
    return (w.lam * tr_u * tr_v + 2 * w.mu * (ezz * fzz + err * frr + ett * ftt)
            + w.mu_s * gzr * hzr) * r


@BilinearForm
def thermal_coupling(t, v, w):
    """Thermal load per kelvin: (3 lam + 2 mu) alpha tr(eps(v)) t; t is a temperature rise."""
    r = w.x[1]
    fzz, frr, ftt, _ = _strains(v, r)
    return (3 * w.lam + 2 * w.mu) * w.alpha * t * (fzz + frr + ftt) * r


@LinearForm
def centrifugal(v, w):
    """Centrifugal body force rho omega^2 r on rotating parts, per (rad/s)^2 [N/m3]."""
    return w.rho_rot * w.x[1] * v[1] * w.x[1]
