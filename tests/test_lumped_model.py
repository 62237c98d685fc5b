"""The N-node lumped model built from the spec (lumped.build, lumped.simulation,
lumped.elastic): conservation, the spec's masses, long-time transients, the growth chain, the
presets and the read-outs."""

import numpy as np
import pytest

from lumped import PRESETS, LumpedModel, build
from lumped.elastic import KelvinVoigt
from spindle.cycle_files import load_cycle
from spindle.drive import DRIVES, cycle_load_case
from spindle.errors import SpecError
from spindle.loads import LoadCase, TimeSeries
from spindle.spec_reader import load_spec


@pytest.fixture(scope="module")
def spl():
    return load_spec("spl2782")


@pytest.fixture(scope="module")
def nominal(spl):
    return cycle_load_case(spl, load_cycle("nominal"), DRIVES["spl2782"])


@pytest.mark.parametrize("name", ["spl2782", "fin-shaft"])
@pytest.mark.parametrize("nodes", [2, 5, 11, 21])
def test_steady_energy_balance_and_capacity(name, nodes):
    spec = load_spec(name)
    model = build(spec, nodes)
    res = model.steady()
    # conservation of the assembled network: round-off only
    assert res.energy["relative_imbalance"] < 1e-12
    assert res.heat_in_W == pytest.approx(sum(float(h.power_W(0)) for h in spec.heat_sources))
    # every kilogram of the spec is in some mass: sum rho c V from the CAD sections
    total = sum(spec.materials[s.material].rho_kg_m3 * spec.materials[s.material].c_J_kgK
                * s.volume_m3 for _, s in spec.sections())
    assert model.system.C.sum() == pytest.approx(total, rel=1e-12)


def test_node_counts_and_presets(spl):
    m = build(spl, "paper11")
    parts = m.mass_table()["part"]
    assert parts.count("shaft") == PRESETS["paper11"] == 11 and parts.count("housing") == 11
    assert parts.count("front_bearing") == 2  # inner and outer ring
    assert build(spl, "paper5").mass_table()["part"].count("shaft") == 5
    # the 11 shaft masses sit on the 11 virtual sensors (l/10 apart): reading is one mass
    rows = [i for i, n in enumerate(m.sensor_names) if n.startswith("shaft_")]
    assert np.all(np.sort(m.S[rows], axis=1)[:, -1] == 1.0)
    for bad in (1, 2.5, "paper7"):
        with pytest.raises(SpecError, match="nodes"):
            build(spl, bad)


def test_transient_reaches_the_steady_state_and_balances_energy(spl, nominal):
    model = build(spl, 5)
    case = LoadCase("hold", nominal.speed_rpm, nominal.T_ambient_K, nominal.T_coolant_K,
                    nominal.sources, duration_s=48 * 3600.0)
    tr = model.transient(case, 600.0, T0=293.15)
    st = model.steady(nominal)
    # slowest time constant of the 5-node model is ~0.5 h: after 48 h the rest is round-off
    np.testing.assert_allclose(tr.mass_K[-1], st.T, atol=1e-8)
    # the zero-order hold integrates heat flows exactly (augmented expm): round-off only
    assert tr.energy["relative_imbalance"] < 1e-10
    assert tr.growth_m["P1"][-1] == pytest.approx(st.growth_m["P1"], rel=1e-8)


def test_cycle_energy_balance(spl):
    case = cycle_load_case(spl, load_cycle("spl-16h"), DRIVES["spl2782"])
    tr = build(spl, 11).transient(case, 300.0, T0=float(case.T_ambient_K(0)))
    assert tr.energy["relative_imbalance"] < 1e-10
    df_cols = set(tr.to_pandas().columns)
    assert {"time_s", "T1_C", "P1_um", "TCP_um"} <= df_cols


def test_growth_chain_of_a_uniform_rise(spl):
    """Uniform rise dT: the shaft grows beta_s dT (z - z_b) from the fixed bearing's middle
    z_b, the housing beta_h dT (z_ref - z_b) to its reference (eq. 20 on each body)."""
    model = build(spl, 11)
    dT = 10.0
    g = model.chain.growth(np.full(model.n_states, spl.T_initial_K + dT))
    z_b = 0.5 * (0.430 + 0.478)  # front pair, spl2782.toml
    b_s = spl.materials["steel_42CrMo4"].alpha_1_K  # shaft and tool
    b_h = spl.materials["cast_iron_GJL250"].alpha_1_K  # housing
    P1 = next(s for s in spl.sensors if s.name == "P1")
    assert g["P1"] == pytest.approx(b_s * dT * (P1.z - z_b) - b_h * dT * (P1.z_ref - z_b),
                                    rel=1e-12)
    assert g["TCP"] == pytest.approx(b_s * dT * (0.7295 - z_b) - b_h * dT * (P1.z_ref - z_b),
                                     rel=1e-12)


def test_kelvin_voigt_lag():
    kv = KelvinVoigt(stiffness_N_m=2e8, damping_N_s_m=2e8 * 120.0)
    assert kv.tau_s == pytest.approx(120.0)
    t = np.linspace(0.0, 1200.0, 41)
    # a ramp from 0 to 1 over the first 30 s then held: exact first-order response
    x = np.minimum(t / 30.0, 1.0)
    y = kv.filter(t, x)
    ramp = t - 120.0 * (1 - np.exp(-t / 120.0))  # response to x = t (per second)
    late = ramp - np.where(t > 30, (t - 30) - 120.0 * (1 - np.exp(-(t - 30) / 120.0)), 0.0)
    np.testing.assert_allclose(y, late / 30.0, atol=1e-12)


def test_lagged_reading_in_a_transient(spl, nominal):
    case = LoadCase("hold", nominal.speed_rpm, nominal.T_ambient_K, nominal.T_coolant_K,
                    nominal.sources, duration_s=4 * 3600.0)
    plain = LumpedModel(spl, 5).transient(case, 300.0, T0=293.15)
    lagged = LumpedModel(spl, 5, lags={"P1": KelvinVoigt(1.0, 900.0)}).transient(
        case, 300.0, T0=293.15)
    assert np.all(lagged.growth_m["P1"][1:] < plain.growth_m["P1"][1:])
    np.testing.assert_array_equal(lagged.growth_m["TCP"], plain.growth_m["TCP"])
    with pytest.raises(SpecError, match="no growth reading"):
        LumpedModel(spl, 5, lags={"P9": KelvinVoigt(1.0, 1.0)})


def test_inputs_follow_the_load_case(spl, nominal):
    model = build(spl, 5)
    case = nominal.with_sources({"stator": TimeSeries((0.0, 100.0), (0.0, 1000.0))})
    u = model.inputs(case, np.array([0.0, 50.0]))
    col = model.system.input_names.index("stator")
    assert u[:, col] == pytest.approx([0.0, 500.0])
    assert u[0, model.system.input_names.index("ambient")] == pytest.approx(293.15)


def test_lumped_result_files(spl, nominal, tmp_path):
    res = build(spl, 5).steady(nominal)
    files = res.save(tmp_path / "steady")
    assert all(f.exists() and f.stat().st_size > 0 for f in files)
    assert set(res.to_pandas().columns) >= {"sensor", "T_C", "rise_K"}
    s = res.summary()
    assert s["model"]["nodes"] == 5 and "P1" in s["growth_um"]
