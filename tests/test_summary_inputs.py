"""summary.json says what the reference used (issue 15 §3): each heat source [W], each film's
coefficient, area and reference temperature, each link's conductance; steady and transient.
An independent check rebuilds the problem from these."""

from __future__ import annotations

import json
import math

import pytest

from compare.cli import main


def _summary(tmp_path, *argv: str) -> dict:
    out = tmp_path / "out"
    assert main(["solve", *argv, "--out", str(out), "--quiet", "--no-pictures"]) == 0
    return json.loads((out / "summary.json").read_text(encoding="utf-8"))


def test_fin_shaft_steady_inputs_match_the_spec_by_hand(tmp_path):
    """fin-shaft.toml: a 0.5 m shaft of radius 25 mm, one lateral film of 10 W/m2/K to the
    20 degC ambient, 15 W and 45 W at the bearings (the paper's Q1, Q2)."""
    used = _summary(tmp_path, "fin-shaft", "--level", "0")["inputs_used"]
    assert used["heat_sources_W"] == {"Q1_rear_bearing_A": 15.0, "Q2_front_bearing_B": 45.0}
    lateral = used["films"]["lateral"]
    assert lateral["area_m2"] == pytest.approx(2 * math.pi * 0.025 * 0.5, rel=1e-12)
    assert lateral["h_W_m2K"] == 10.0 and lateral["T_ref"] == "ambient"
    assert lateral["T_ref_C"] == pytest.approx(20.0)


def test_spl2782_sources_sum_to_the_heat_in_and_links_are_listed(tmp_path):
    doc = _summary(tmp_path, "spl2782", "--level", "0")
    used = doc["inputs_used"]
    assert sum(used["heat_sources_W"].values()) == pytest.approx(doc["energy"]["heat_in_W"],
                                                                 rel=1e-12)
    kinds = {k.split(":")[0] for k in used["links"]}
    assert kinds == {"bearing", "air_gap", "contact"}
    assert all(v["G_W_K"] > 0 for k, v in used["links"].items() if k.startswith("bearing"))
    jacket = [f for f in used["films"].values() if f["T_ref"] == "coolant"]
    assert jacket and all(f["area_m2"] > 0 and f["h_W_m2K"] > 1000 for f in jacket)


def test_transient_summary_lists_the_inputs_per_speed(tmp_path):
    doc = _summary(tmp_path, "spl2782", "--level", "0", "--cycle", "spl-16h", "--dt", "600")
    by_speed = doc["inputs_used_by_speed"]
    # spl-16h holds 1000, 2000, 3000, 4300 rpm and the standstill (docs/cycles.md)
    assert set(by_speed) == {"1000 rpm", "2000 rpm", "3000 rpm", "4300 rpm", "0 rpm"}
    fast, slow = by_speed["4300 rpm"], by_speed["1000 rpm"]
    assert sum(fast["heat_sources_W"].values()) > sum(slow["heat_sources_W"].values())
