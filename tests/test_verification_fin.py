"""fin-shaft against eq. 14: as the shaft gets thinner (Biot number h R / k -> 0) the FEM
sensor temperatures converge to the fin solution; what remains is eq. 14's model-form error
(it assumes an isothermal cross-section). The table is printed with -s and in docs."""

import numpy as np
import pytest

from lumped.fin import Fin
from meshes import build_mesh
from reference import ThermalModel
from spindle.spec_reader import load_spec

K = 42.6  # steel_42CrMo4 [W/m/K]
H = 10.0  # fin-shaft lateral film coefficient [W/m2/K]


def fin_spec(tmp_path, radius: float):
    text = load_spec("fin-shaft").path
    src = open(text, encoding="utf-8").read()
    src = src.replace("r_outer = 0.025", f"r_outer = {radius}")
    src = src.replace("h0_m = 0.025", f"h0_m = {min(0.025, radius)}")
    path = tmp_path / f"fin_{radius}.toml"
    path.write_text(src, encoding="utf-8")
    return load_spec(path)


def fem_vs_eq14(tmp_path, radius: float, level: int = 2):
    spec = fin_spec(tmp_path, radius)
    res = ThermalModel(build_mesh(spec, level), 2).solve_steady()
    names = [f"shaft_{i:02d}" for i in range(11)]
    z = np.array([s.z for s in spec.sensors if s.name in names])
    fem = np.array([res.sensors[n] for n in names]) - spec.T_ambient_K
    fin = Fin.solid_shaft(0.5, radius, K, H, 15.0, 45.0).rise_K(z)
    return fem, fin


def test_fin_shaft_converges_to_eq14_as_biot_goes_to_zero(tmp_path):
    rows = []
    for radius in (0.025, 0.0125, 0.00625):
        fem, fin = fem_vs_eq14(tmp_path, radius)
        biot = H * radius / K
        rel = np.max(np.abs(fem - fin)) / np.max(fin)
        rows.append((radius, biot, rel, np.max(np.abs(fem - fin))))
    print("\n R_m      Biot      max|FEM-eq14|/max rise   max|FEM-eq14|_K")
    for r in rows:
        print(f" {r[0]:.5f}  {r[1]:.2e}  {r[2]:.3e}               {r[3]:.3e}")
    rel = [r[2] for r in rows]
    # model-form error of a fin is O(Bi): the radial drop across a convecting cylinder is
    # Bi/2 of the surface excess (mean to mid-radius less); so it must stay below Bi and
    # halve with the radius
    assert all(r[2] < r[1] for r in rows), rows
    assert rel[1] < 0.6 * rel[0] and rel[2] < 0.6 * rel[1], rel


def test_fin_shaft_as_shipped_is_close_to_eq14(tmp_path):
    """Shipped fin-shaft (R = 25 mm, Bi = 5.9e-3): within 1 % of eq. 14 at all 11 sensors."""
    fem, fin = fem_vs_eq14(tmp_path, 0.025)
    assert np.max(np.abs(fem - fin) / fin) < 0.01


def test_eq14_solves_the_fin_equation():
    """T'' = m^2 T and the two end-flux conditions, to round-off."""
    fin = Fin.solid_shaft(0.5, 0.025, K, H, 15.0, 45.0)
    x = np.linspace(0, 0.5, 11)
    d = 1e-4
    fd2 = (fin.rise_K(x[1:-1] + d) - 2 * fin.rise_K(x[1:-1]) + fin.rise_K(x[1:-1] - d)) / d**2
    np.testing.assert_allclose(fd2, fin.m_1_m**2 * fin.rise_K(x[1:-1]), rtol=1e-5)
    kA = K * fin.area_m2
    assert -kA * fin.slope_K_m(0.0) == pytest.approx(15.0, rel=1e-13)
    assert kA * fin.slope_K_m(0.5) == pytest.approx(45.0, rel=1e-13)
