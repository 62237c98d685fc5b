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
