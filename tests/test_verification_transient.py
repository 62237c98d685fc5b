"""Transient verification: a lumped-capacitance body follows the exponential decay; backward
Euler converges at first order and Crank-Nicolson at second order in time; long runs reach
the steady state; energy is conserved by the discrete scheme."""

import math

import numpy as np
import pytest

from meshes import build_mesh
from reference import ThermalModel
from spindle.loads import LoadCase, TimeSeries

# k so high that the Biot number h R / k is 1e-7: the body is isothermal and its mean
# temperature obeys C dT/dt = -h A (T - T_amb) exactly up to O(Bi)
LUMP = """
[materials.lump]
k_W_mK = 1e6
rho_kg_m3 = 1000.0
c_J_kgK = 1000.0
E_Pa = 1e9
nu = 0.3
alpha_1_K = 1e-5

[mesh]
h0_m = 0.005

[[parts]]
name = "body"
role = "shaft"
material = "lump"
sections = [{ z_start = 0.0, z_end = 0.02, r_inner = 0.0, r_outer = 0.01 }]

[[surfaces]]
name = "all"
parts = ["body"]
side = "any"
h_W_m2K = 10.0
T_ref = "ambient"

[[sensors]]
name = "centre"
z = 0.01
r = 0.0
"""

R, L, H, RHOC = 0.01, 0.02, 10.0, 1e6
TAU = RHOC * math.pi * R**2 * L / (H * (2 * math.pi * R * L + 2 * math.pi * R**2))


def decay_error(model, dt: float, theta: float) -> float:
    case = LoadCase("cool-down", TimeSeries.constant(0.0), TimeSeries.constant(300.0),
                    TimeSeries.constant(300.0), duration_s=TAU)
    res = model.solve_transient(case, dt, theta=theta, T0=400.0)
    exact = 300.0 + 100.0 * np.exp(-res.times_s / TAU)
    return float(np.max(np.abs(res.sensor("centre") - exact)))


@pytest.mark.parametrize("theta, expected", [(1.0, 1.0), (0.5, 2.0)])
def test_time_order(spec_from, theta, expected):
    model = ThermalModel(build_mesh(spec_from(LUMP, "lump"), 0), 1)
    dts = [TAU / n for n in (10, 20, 40, 80)]
    errs = [decay_error(model, dt, theta) for dt in dts]
    rate = np.polyfit(np.log(dts), np.log(errs), 1)[0]
    assert abs(rate - expected) < 0.1, (rate, errs)


def test_lumped_capacitance_decay(spec_from):
    """Crank-Nicolson with tau/200 steps: the exponential within 1e-3 K of 100 K (its
    truncation error (dt/tau)^2/12 * 100 K * e^-1 = 8e-5 K)."""
    model = ThermalModel(build_mesh(spec_from(LUMP, "lump"), 0), 2)
    assert decay_error(model, TAU / 200, 0.5) < 1e-3


def test_long_run_reaches_steady_state(spec_from, tmp_path):
    from tests.test_verification_analytic import ROD, radial_sensors

    spec = spec_from(ROD.format(ri=0.02, sensors=radial_sensors([0.02, 0.05])), "rod")
    model = ThermalModel(build_mesh(spec, 0), 2)
    steady = model.solve_steady()
    # slowest time constant ~ rho c V / (h A) = 7800*460*0.03/(2*50*0.05)... ~ 3.7e3 s
    case = LoadCase("warm-up", TimeSeries.constant(0.0), TimeSeries.constant(300.0),
                    TimeSeries.constant(300.0), duration_s=2e5)
    res = model.solve_transient(case, 2000.0, T0=300.0)
    for name in ("r0", "r1"):
        assert res.sensor(name)[-1] == pytest.approx(steady.sensors[name], abs=1e-6)


@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_spl2782_transient_energy_balance(theta):
    """Speed, ambient, coolant and a source all change during the run: the cumulative
    balance in - out - stored closes to round-off (the scheme conserves energy exactly)."""
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    model = ThermalModel(build_mesh(spec, 0), 2)
    case = spec.default_load_case()
    case = LoadCase(
        "steps", TimeSeries((0, 1800, 3600), (2000, 4300, 0), "previous"),
        TimeSeries((0, 7200), (293.15, 296.15)), TimeSeries((0, 3600, 7200), (293, 295, 292)),
        {**case.sources, "stator": TimeSeries((0, 3600, 3601), (1000, 1000, 0))},
        duration_s=7200.0)
    res = model.solve_transient(case, 300.0, theta=theta)
    e = res.energy
    assert e["relative_imbalance"] < 1e-10, e
    assert e["energy_stored_J"] > 0


def test_spl2782_steady_energy_balance_and_residual():
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    res = ThermalModel(build_mesh(spec, 1), 2).solve_steady()
    assert res.residual <= 1e-8
    assert res.energy["relative_imbalance"] < 1e-10
    # the spec's four sources (the nominal power balance to 0.1 W each, 5146.6 W in all)
    assert res.energy["heat_in_W"] == pytest.approx(sum(h.power_W(0) for h in spec.heat_sources),
                                                    rel=1e-12)
    assert res.energy["heat_in_W"] == pytest.approx(5146.0, abs=0.7)


@pytest.mark.parametrize("theta", [1.0, 0.5])
def test_a_held_input_switching_at_a_step_end_acts_from_there_on(spec_from, theta):
    """A held ('previous') source that switches on at a grid time t acts from t on, never over
    the step that ends there (a zero-order hold of the step's own value, as the lumped model
    integrates it). Read at the step's end instead, every switch acted one step early: on a
    bench's 60 s grid that put the stator 4 K ahead of the data at a speed step
    (docs/fit-history.md). Up to t the run equals the one without the source (to round-off); the
    step after t warms by about q dt / C."""
    dt, t_on, q = 10.0, 50.0, 1.0  # s, s, W (TAU is 333 s)

    def run(source: TimeSeries):
        case = LoadCase("switch", TimeSeries.constant(0.0), TimeSeries.constant(300.0),
                        TimeSeries.constant(300.0), {"heat": source}, duration_s=10 * dt)
        return model.solve_transient(case, dt, theta=theta, T0=300.0)

    heat_spec = spec_from(LUMP + HEAT_SOURCE, "lump")
    model = ThermalModel(build_mesh(heat_spec, 0), 1)
    on = run(TimeSeries((0.0, t_on), (0.0, q), "previous"))
    off = run(TimeSeries.constant(0.0))
    k = int(np.argmin(np.abs(on.times_s - t_on)))
    assert on.times_s[k] == pytest.approx(t_on)
    np.testing.assert_allclose(on.sensor("centre")[:k + 1], off.sensor("centre")[:k + 1],
                               atol=1e-9)
    C = RHOC * math.pi * R**2 * L
    rise = on.sensor("centre")[k + 1] - off.sensor("centre")[k + 1]
    # the first step after t: q dt / C less what the film and (CN) the scheme take, < 10 %
    assert 0.9 * q * dt / C < rise < q * dt / C * (1.0 if theta == 1.0 else 1.01), rise


HEAT_SOURCE = """
[[heat_sources]]
name = "heat"
part = "body"
power_W = 0.0
"""
