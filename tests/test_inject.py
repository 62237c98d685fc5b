"""compare.synth.inject: measurement-side effects added to a recorded run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from compare.synth.inject import first_order_lag, inject, injectable
from spindle.commented_csv import split_commented_csv

HEADER = "time_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_C,T2_C,T_stator_C,P1_um"


def _run(n: int = 400, dt: float = 10.0) -> str:
    lines = ["# spindle: test", "# bench: none", HEADER]
    for i in range(n):
        t = i * dt
        speed = 4000.0 if t >= 1000.0 else 0.0
        env = 20.0 + 0.001 * t
        p1 = "" if i == 7 else f"{1.0:.1f}"
        lines.append(f"{t:g},{speed:g},0.1,{env:.2f},20.00,21.00,21.00,22.0,{p1}")
    return "\n".join(lines) + "\n"


def _col(text: str, name: str) -> np.ndarray:
    doc = split_commented_csv(text)
    j = [h.strip() for h in doc.rows[0]].index(name)
    return np.array([float(r[j]) if r[j].strip() else np.nan for r in doc.rows[1:]])


def test_first_order_lag_of_a_ramp_is_exact():
    # tau y' = x - y with x = a t, y(0) = 0: y = a (t - tau (1 - exp(-t / tau)));
    # irregular samples, so the recursion's step length varies
    t = np.cumsum(np.r_[0.0, np.random.default_rng(1).uniform(1.0, 30.0, 300)])
    y = first_order_lag(t, 0.5 * t, 200.0)
    exact = 0.5 * (t - 200.0 * (1.0 - np.exp(-t / 200.0)))
    assert np.max(np.abs(y - exact)) < 1e-9 * np.max(exact)  # rounding only


def test_centrifugal_shortening_follows_n_squared_and_keeps_the_format():
    out = inject(_run(), "centrifugal_shortening", {"c_cf_um_krpm2": 0.1})
    p1, n = _col(out, "P1_um"), _col(out, "speed_rpm")
    # 0.1 um/krpm^2 at 4000 rpm: 1.6 um, on the column's 0.1 um logging grid
    ok = np.isfinite(p1)
    assert np.allclose(p1[ok & (n == 0)], 1.0) and np.allclose(p1[ok & (n == 4000)], 1.0 - 1.6)
    assert math.isnan(p1[7])  # an empty cell stays empty
    assert "# injected (compare.synth.inject): centrifugal_shortening" in out
    assert out.splitlines()[:2] == ["# spindle: test", "# bench: none"]


def test_fixture_expansion_follows_the_ambient_change():
    out = inject(_run(), "fixture_expansion", {"k_fix_um_K": -2.0})
    p1, env = _col(out, "P1_um"), _col(out, "T_env_C")
    ok = np.isfinite(p1)
    # rounded to the column's 0.1 um: half a step at most
    assert np.max(np.abs(p1[ok] - (1.0 - 2.0 * (env[ok] - env[0])))) <= 0.05 + 1e-9


def test_sensor_lag_delays_one_channel_only():
    text = _run()
    out = inject(text, "sensor_lag", {"tau_s": 300.0}, channel="T_stator", seed=3)
    assert np.array_equal(_col(out, "T1_C"), _col(text, "T1_C"))
    # a constant channel through a lag stays constant (its scatter was 0: no noise added)
    assert np.allclose(_col(out, "T_stator_C"), 22.0)


def test_the_injectable_effects_are_the_libraries_measurement_effects():
    """The library's effects that act on the measurement alone, read from the effects
    themselves (compare.fit.effects), not from a list in the injector."""
    assert set(injectable()) == {"centrifugal_shortening", "fixture_expansion", "sensor_lag"}


def test_physics_effects_and_missing_parameters_are_refused():
    with pytest.raises(ValueError, match="acts on the physics"):
        inject(_run(), "windage_loss", {"c_w_W_krpm3": 1.0})
    with pytest.raises(ValueError, match="needs tau_s"):
        inject(_run(), "sensor_lag", {}, channel="T1")
    with pytest.raises(ValueError, match="needs a channel"):
        inject(_run(), "sensor_lag", {"tau_s": 10.0})
