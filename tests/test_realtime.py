"""The real-time predictor (lumped.realtime): streaming steps, batch replay and the model's
own zero-order-hold transient are the same discretisation, so they agree to round-off."""

import numpy as np
import pytest

from lumped import build
from lumped.blocks import FixedTemperature, HeatCapacitor, PrescribedHeatFlow, ThermalConductor
from lumped.realtime import RealTimePredictor
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES, cycle_load_case
from spindle.loads import LoadCase
from spindle.spec_reader import load_spec


@pytest.fixture(scope="module")
def setup():
    spec = load_spec("spl2782")
    full = cycle_load_case(spec, load_cycle("spl-16h"), DRIVES["spl2782"])
    # the first 3 h of the cycle: speed steps, drifting ambient, chiller cycling
    case = LoadCase("first3h", full.speed_rpm, full.T_ambient_K, full.T_coolant_K,
                    full.sources, duration_s=3 * 3600.0)
    return build(spec, 5), case


def sampled(model, case, dt):
    """Inputs held over each sample at its mid-time (as the model's own transient holds)."""
    t = np.arange(0.0, case.duration_s, dt)
    mid = t + 0.5 * dt
    return t + dt, model.inputs(case, mid), np.asarray(case.speed_rpm(mid), dtype=float)


def test_step_and_replay_agree_with_the_model_transient(setup):
    model, case = setup
    dt = 60.0
    T0 = float(case.T_ambient_K(0.0))
    ends, U, speeds = sampled(model, case, dt)
    tr = model.transient(case, dt, T0=T0)
    # the cycle's input samples all lie on the 60 s grid, so both use the same steps
    np.testing.assert_array_equal(tr.times_s[1:], ends)
    pred = RealTimePredictor(model, dt, x0=T0)
    Y, P1 = pred.run(U, speeds)
    np.testing.assert_allclose(Y, tr.sensor_K[1:], atol=1e-9)  # K, round-off of expm
    np.testing.assert_allclose(P1, tr.growth_m["P1"][1:], atol=1e-15)  # m
    stream = RealTimePredictor(model, dt, x0=T0)
    for k in range(len(U)):
        y, p = stream.step(U[k], speeds[k])
    np.testing.assert_allclose(y, Y[-1], atol=1e-9)
    assert p == pytest.approx(P1[-1], abs=1e-15)
    np.testing.assert_allclose(stream.state, pred.state, atol=1e-9)


def test_replay_at_one_second_matches_streaming(setup):
    model, case = setup
    _, U, speeds = sampled(model, case, 1.0)
    T0 = float(case.T_ambient_K(0.0))
    Y, P1 = RealTimePredictor(model, 1.0, x0=T0).run(U, speeds)
    stream = RealTimePredictor(model, 1.0, x0=T0)
    for k in range(len(U)):
        y, p = stream.step(U[k], speeds[k])
        if k in (0, 1799, 5399, len(U) - 1):  # across the speed steps
            np.testing.assert_allclose(y, Y[k], atol=1e-9)
            assert p == pytest.approx(P1[k], abs=1e-14)


def test_temperature_dependent_models_are_refused():
    from lumped.network import Network

    class Stub:
        pass

    net = Network("tc")
    m = net.add(HeatCapacitor("m", C_J_K=1.0))
    g = net.add(ThermalConductor("g", G_W_K=1.0))
    a = net.add(FixedTemperature("a"))
    q = net.add(PrescribedHeatFlow("q", source="Q", tc_1_K=0.004))
    net.connect(m.port, g.port_a)
    net.connect(g.port_b, a.port)
    net.connect(q.port, m.port)
    stub = Stub()
    stub.system = net.assemble()
    with pytest.raises(ValueError, match="temperature-dependent"):
        RealTimePredictor(stub, 1.0)

