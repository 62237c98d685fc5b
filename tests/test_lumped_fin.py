"""Eq. 14 and the N-node lumped fin (lumped.fin, lumped.build on fin-shaft).

The vertex-centred lumped fin is a second-order finite-volume scheme of the fin equation, so
its 11 sensor temperatures converge to eq. 14 with observed order 2 as N grows. With the
conduction from the slice's mean radius to its surface (the default) the limit is eq. 14 with
the effective film coefficient 1 / (1/h + R ln(sqrt 2) / k_r); without it (eq. 7 as printed),
eq. 14 itself.
"""

import numpy as np
import pytest

from lumped import Fin, build
from spindle.spec_reader import load_spec
from tests.conftest import observed_order


@pytest.fixture(scope="module")
def spec():
    return load_spec("fin-shaft")


def fin_for(spec, radial: bool) -> Fin:
    mat = spec.materials["steel_42CrMo4"]
    R, h = 0.025, 10.0  # fin-shaft.toml
    h_eff = 1.0 / (1.0 / h + R * np.log(np.sqrt(2.0)) / mat.k_r_W_mK) if radial else h
    return Fin.solid_shaft(0.5, R, mat.k_z_W_mK, h_eff, 15.0, 45.0)


def sensor_error(spec, nodes: int, radial: bool) -> float:
    res = build(spec, nodes, radial_conduction=radial).steady()
    rise = np.array([res.sensors[f"shaft_{i:02d}"] for i in range(11)]) - spec.T_ambient_K
    return float(np.max(np.abs(rise - fin_for(spec, radial).sensors_rise_K(11))))


def test_fin_from_spec_reads_the_benchmark(spec):
    f = Fin.from_spec(spec)
    assert (f.length_m, f.Q1_W, f.Q2_W, f.h_W_m2K) == pytest.approx((0.5, 15.0, 45.0, 10.0))
    assert f.area_m2 == pytest.approx(np.pi * 0.025**2)
    assert f.perimeter_m == pytest.approx(2 * np.pi * 0.025)
    spl = load_spec("spl2782")
    g = Fin.from_spec(spl, Q1_W=15.0, Q2_W=45.0)  # the spl2782 shaft with an effective alpha
    assert g.length_m == pytest.approx(0.5295) and 0 < g.h_W_m2K < 100
    with pytest.raises(Exception, match="give Q1_W explicitly"):
        Fin.from_spec(spl)


def test_paper_presets_against_eq14(spec):
    """The 5- and 11-node models of fin-shaft: the error falls with N."""
    e5, e11 = sensor_error(spec, 5, True), sensor_error(spec, 11, True)
    assert e11 < 0.25 * e5  # second order: (4/10)^2 = 0.16 on the node spacing


@pytest.mark.parametrize("radial", [False, True])
def test_lumped_fin_converges_to_eq14_with_order_two(spec, radial):
    nodes = [11, 21, 41, 81]
    errs = [sensor_error(spec, n, radial) for n in nodes]
    p = observed_order([1.0 / (n - 1) for n in nodes], errs)
    assert p == pytest.approx(2.0, abs=0.1)
    assert errs[-1] < 0.05  # K, at N = 81
