"""Function blocks and their network (lumped.blocks, lumped.network): small networks with
hand solutions, the exact zero-order hold, and the checks on bad networks."""

import numpy as np
import pytest

from lumped.blocks import (
    Convection,
    FixedTemperature,
    HeatCapacitor,
    PrescribedHeatFlow,
    ThermalConductor,
)
from lumped.network import Network, NetworkError
from spindle.loads import SpeedTable

T_AMB = 293.15


def one_mass(C=1000.0, G=2.0, Q=10.0, tc=0.0):
    """A mass C [J/K] heated by Q [W] and cooled through G [W/K] to ambient."""
    net = Network("one")
    m = net.add(HeatCapacitor("m", C_J_K=C))
    g = net.add(ThermalConductor("g", G_W_K=G))
    amb = net.add(FixedTemperature("amb", source="ambient"))
    q = net.add(PrescribedHeatFlow("q", source="Q", tc_1_K=tc))
    net.connect(m.port, g.port_a)
    net.connect(g.port_b, amb.port)
    net.connect(q.port, m.port)
    return net.assemble()


def test_one_mass_steady_and_exact_zero_order_hold():
    sys = one_mass()
    u = np.array([10.0, T_AMB])  # inputs: source power, then ambient
    assert sys.input_names == ["Q", "ambient"]
    assert sys.steady(u, 0.0)[0] == pytest.approx(T_AMB + 10.0 / 2.0, abs=1e-12)
    # exact solution of C dT/dt = Q - G (T - T_amb) from T_amb: tau = C / G = 500 s
    for dt in (1.0, 60.0, 3600.0):
        Phi, Gam = sys.discretize(dt, 0.0)
        x1 = Phi @ np.array([T_AMB]) + Gam @ u
        # exact up to the round-off of expm on a ~300 K state (a few ulp)
        assert x1[0] == pytest.approx(T_AMB + 5.0 * (1 - np.exp(-dt / 500.0)), rel=1e-14)


def test_temperature_dependent_heat_flow_stays_linear():
    """Q = Q0 (1 + tc (T - T_ref)) with G to ambient: T = (Q0 (1 - tc T_ref) + G T_a) /
    (G - Q0 tc), the copper-loss form of eq. 16-17."""
    tc, Q0, G = 0.00393, 10.0, 2.0
    sys = one_mass(G=G, Q=Q0, tc=tc)
    T = sys.steady(np.array([Q0, T_AMB]), 0.0)[0]
    assert T == pytest.approx((Q0 * (1 - tc * 293.15) + G * T_AMB) / (G - Q0 * tc), rel=1e-14)
    assert sys.heat_in(np.array([T, T_AMB]), np.array([Q0])) == pytest.approx(G * (T - T_AMB))


def test_junction_without_capacity_is_condensed():
    """Two conductors in series through a massless junction act as G1 G2 / (G1 + G2)."""
    net = Network("series")
    m = net.add(HeatCapacitor("m", C_J_K=50.0))
    g1 = net.add(ThermalConductor("g1", G_W_K=3.0))
    g2 = net.add(ThermalConductor("g2", G_W_K=6.0))
    amb = net.add(FixedTemperature("amb", source=300.0))
    q = net.add(PrescribedHeatFlow("q", source=4.0))
    net.connect(m.port, g1.port_a)
    net.connect(g1.port_b, g2.port_a)  # the junction
    net.connect(g2.port_b, amb.port)
    net.connect(q.port, m.port)
    sys = net.assemble()
    assert sys.n_states == 1 and len(sys.junction) == 1
    u = np.array([4.0, 300.0])
    x = sys.steady(u, 0.0)
    assert x[0] == pytest.approx(300.0 + 4.0 / 2.0, abs=1e-12)
    T_all = sys.node_temperatures(x, u, 0.0)
    assert sorted(T_all) == pytest.approx([300.0, 300.0 + 4.0 / 6.0, 302.0])


def test_convection_follows_speed():
    net = Network("conv")
    m = net.add(HeatCapacitor("m", C_J_K=10.0))
    c = net.add(Convection("c", Gc_W_K=SpeedTable((0.0, 1000.0), (1.0, 5.0))))
    amb = net.add(FixedTemperature("amb", source="ambient"))
    q = net.add(PrescribedHeatFlow("q", source="Q"))
    net.connect(m.port, c.port_a)
    net.connect(c.port_b, amb.port)
    net.connect(q.port, m.port)
    sys = net.assemble()
    u = np.array([10.0, T_AMB])
    assert sys.steady(u, 0.0)[0] - T_AMB == pytest.approx(10.0)
    assert sys.steady(u, 500.0)[0] - T_AMB == pytest.approx(10.0 / 3.0)


def test_bad_networks_name_the_block_and_the_fix():
    net = Network("bad")
    m = net.add(HeatCapacitor("lonely", C_J_K=1.0))
    with pytest.raises(NetworkError, match=r"port lonely.port is not connected; fix:"):
        net.assemble()

    net = Network("floating")
    a = net.add(HeatCapacitor("a", C_J_K=1.0))
    b = net.add(HeatCapacitor("b", C_J_K=1.0))
    g = net.add(ThermalConductor("g", G_W_K=1.0))
    net.connect(a.port, g.port_a)
    net.connect(g.port_b, b.port)
    with pytest.raises(NetworkError, match=r"\['a', 'b'\] have no heat path to a fixed "
                                           r"temperature.*fix: add a Convection"):
        net.assemble()

    net = Network("clash")
    m = net.add(HeatCapacitor("m", C_J_K=1.0))
    t1 = net.add(FixedTemperature("t1", source="ambient"))
    t2 = net.add(FixedTemperature("t2", source="coolant"))
    net.connect(m.port, t1.port)
    net.connect(m.port, t2.port)
    with pytest.raises(NetworkError, match="'t2' holds a node at 'coolant'"):
        net.assemble()

    net = Network("negative")
    m = net.add(HeatCapacitor("m", C_J_K=-1.0))
    amb = net.add(FixedTemperature("amb"))
    g = net.add(ThermalConductor("g", G_W_K=1.0))
    net.connect(m.port, g.port_a)
    net.connect(g.port_b, amb.port)
    with pytest.raises(NetworkError, match=r"'m': C_J_K = -1 is negative; fix"):
        net.assemble()

    net = Network("names")
    net.add(HeatCapacitor("m", C_J_K=1.0))
    with pytest.raises(NetworkError, match="block name 'm' is used twice"):
        net.add(HeatCapacitor("m", C_J_K=1.0))
    with pytest.raises(NetworkError, match="was not added"):
        net.connect(HeatCapacitor("x").port, HeatCapacitor("y").port)


def _loop_matrices(sys_, speed_rpm, q):
    """K and B of the free nodes written out entry by entry, as eq. 8 states them: the
    independent statement :meth:`ThermalSystem._full`'s stamps are held to."""
    from lumped.blocks import conductance_at

    pos = {n: k for k, n in enumerate(sys_.free)}
    m = len(sys_.source_names)
    fixed_col = {n: m + k for k, n in enumerate(sys_.fixed_nodes)}
    K = np.zeros((len(pos), len(pos)))
    B = np.zeros((len(pos), sys_.n_inputs))
    for i, j, G, _ in sys_.edges:
        g = conductance_at(G, speed_rpm)
        for a, b in ((i, j), (j, i)):
            if a in pos:
                K[pos[a], pos[a]] += g
                if b in pos:
                    K[pos[a], pos[b]] -= g
                else:
                    B[pos[a], fixed_col[b]] += g
    col = {s: k for k, s in enumerate(sys_.source_names)}
    for n, f in sys_.flows:
        if n not in pos:
            continue
        c = col[f.source]
        if id(f) in sys_.across:
            B[pos[n], c] += f.share
            if q is not None:
                a, b = sys_.across[id(f)]
                K[pos[n], pos[a]] -= f.share * f.tc_1_K * q[c]
                K[pos[n], pos[b]] += f.share * f.tc_1_K * q[c]
        else:
            B[pos[n], c] += f.share * (1.0 - f.tc_1_K * f.T_ref_K)
            if q is not None:
                K[pos[n], pos[n]] -= f.share * f.tc_1_K * q[c]
    return K, B


@pytest.mark.parametrize("nodes, tc", [(5, 0.0), (11, 0.0), (11, 0.05), (21, 0.0)])
def test_the_stamped_matrices_are_the_entrywise_ones(nodes, tc):
    """K and B at a speed come from stamps summed once per system (a fit asks for them at
    every speed of every parameter set); they must be the matrices eq. 8 writes entry by
    entry, on spl2782's networks with speed-dependent films and bearings, and with the
    temperature-dependent bearing friction, at two heats per speed. Tolerance: the two sum the
    same terms in another order, 1e-13 of the largest entry is a few hundred roundings of
    1e-16."""
    from lumped.build import build_network
    from spindle.spec_reader import load_spec

    sys_ = build_network(load_spec("spl2782"), nodes, bearing_tc_1_K=tc,
                         coolant_advection_W_K=50.0 if tc else None).network.assemble()
    assert len(sys_._stamps().varying) > 0 and sys_.temperature_dependent == (tc != 0)
    q = np.linspace(10.0, 100.0, len(sys_.source_names))
    for speed in (0.0, 1234.5, 4300.0, 9000.0):
        # a second heat at the same speed reuses the speed's part of the first (_full)
        for power in (None, q, 1.7 * q):
            K, B = sys_._full(speed, power)
            K_ref, B_ref = _loop_matrices(sys_, speed, power if tc else None)
            np.testing.assert_allclose(K, K_ref, rtol=0, atol=1e-13 * np.abs(K_ref).max())
            np.testing.assert_allclose(B, B_ref, rtol=0, atol=1e-13 * np.abs(B_ref).max())


def test_the_stamps_of_a_fine_network_hold_four_entries_per_varying_conductance():
    """A dense column of free x free entries per speed-dependent conductance would take
    1487^2 x 501 x 8 bytes = 8.9 GB for spl2782 at 400 nodes; the stamps keep a varying
    edge's at most four entries in K and two in B."""
    import scipy.sparse as sp

    from lumped import build
    from spindle.spec_reader import load_spec

    sys_ = build(load_spec("spl2782"), 400).system
    st = sys_._stamps()
    n_var = len(st.varying)
    assert n_var > 400 and sp.issparse(st.Kv) and sp.issparse(st.Bv)
    assert st.Kv.nnz <= 4 * n_var and st.Bv.nnz <= 2 * n_var
    K, _ = sys_._full(4300.0, None)
    np.testing.assert_allclose(K, _loop_matrices(sys_, 4300.0, None)[0], rtol=0,
                               atol=1e-13 * np.abs(K).max())


@pytest.mark.parametrize("nodes, symmetric", [(5, True), (11, True), (11, False)])
def test_modes_prepared_for_many_speeds_are_those_of_one_speed(nodes, symmetric):
    """A fit's simulation asks for the modes along a run's steps and speed levels at once
    (prepare_modes: stacked matrices, one batched eigenproblem); they must be the modes
    that modes() gives along the same sequence, bit for bit, since a fit's result must not
    depend on which path filled the cache. Steps that differ below 1 ns
    (a grid on a time-of-day clock) are one step, the rounded one, whichever came first. A K
    that is not symmetric (made so here by one entry) has no modes: None on both paths."""
    from dataclasses import replace

    from lumped.build import build_network
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    speeds = [3000.0, 0.0, 120.0, 1234.5, 3000.0, 4300.0, 9000.0, 120.0, 4300.0]
    dts = [60.0 + 1e-11, 60.0, 60.0, 0.75, 60.0 - 1e-11, 60.0, 59.25, 60.0 + 2e-11, 60.0]
    systems = [build_network(spec, nodes).network.assemble() for _ in range(2)]
    for sys_ in systems:
        if not symmetric:
            st = sys_._stamps()
            K0 = st.K0.copy()
            K0[0, 1] *= 1.5
            sys_._stamp = replace(st, K0=K0)
    batched, single = systems
    batched.prepare_modes(np.array(dts), np.array(speeds))
    for dt, n in zip(dts, speeds, strict=True):
        got = batched._cache[("modes", round(dt, 9), n)]
        want = single.modes(dt, n)
        assert (got is None) == (want is None) == (not symmetric)
        for g, w in zip(got or (), want or (), strict=True):
            np.testing.assert_array_equal(g, w)
    # the entry of 3000 rpm at 60 s is the 60 s step's, whichever near step came first
    if symmetric:
        for first in (60.0 + 1e-11, 60.0, 60.0 - 1e-11):
            other = build_network(spec, nodes).network.assemble()
            other.modes(first, 3000.0)
            np.testing.assert_array_equal(other.modes(60.0 + 2e-11, 3000.0)[0],
                                          batched._cache[("modes", 60.0, 3000.0)][0])
        exact = build_network(spec, nodes).network.assemble()._modal_form(
            *np.linalg.eigh((1 / np.sqrt(single.C))[:, None] * single.matrices(3000.0, None)[0]
                            * (1 / np.sqrt(single.C))[None, :]), single.matrices(3000.0, None)[1],
            60.0)
        np.testing.assert_array_equal(batched._cache[("modes", 60.0, 3000.0)][0], exact[0])
