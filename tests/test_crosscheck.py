"""Cross-check of the FEM reference with CalculiX (ccx) on the same P2 mesh (docs/crosscheck.md).

Both codes solve the same discrete problem on the same nodes and elements except for one
thing the deck cannot change: ccx integrates its DCAX6/CAX6 elements with the 3-point rule
of degree 2 (the reference integrates exactly, degree 5). So every comparison below has two
parts:

1. ccx against the "twin" (the reference's problem assembled with ccx's quadrature in
   scikit-fem): equal up to the rounding of ccx's result file (``%12.5E`` of single-precision
   values, bound ``*_print``) plus direct-solver round-off: the deck is exact;
2. ccx against the reference: the difference is the quadrature difference reference - twin
   (computed in double precision), which falls under mesh refinement (level 0 -> 1).

Skipped only when ``ccx`` is not installed (CI installs the Debian package calculix-ccx).
"""

from __future__ import annotations

import argparse
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

if shutil.which("ccx") is None:  # the importorskip of an executable
    pytest.skip("CalculiX (ccx) is not installed; apt-get install calculix-ccx",
                allow_module_level=True)

from compare.cli.crosscheck import register  # noqa: E402 - after the skip
from compare.crosscheck import (  # noqa: E402
    CCX_MISSING,
    crosscheck,
    read_frd,
    run_ccx,
)
from spindle.errors import SolverError  # noqa: E402

#: direct-solver round-off allowance, relative to the largest temperature rise (SPOOLES and
#: SuperLU in double precision reach ~1e-13 on these well-conditioned problems)
SOLVER_RTOL = 1e-9


@pytest.fixture(scope="module")
def fin():
    return {level: crosscheck("fin-shaft", level) for level in (0, 1)}


@pytest.fixture(scope="module")
def spl():
    return {level: crosscheck("spl2782", level) for level in (0, 1)}


def _solver_tol(res) -> float:
    return SOLVER_RTOL * res.nodal["max_rise_K"]


def _assert_deck_holds_reference(res) -> None:
    c = res.deck["checks"]
    # the deck's coefficients re-assembled equal the reference's operator to round-off
    # (summation order only: 1e-12 is ~1e4 ulp)
    assert c["conduction_rel_diff"] < 1e-12
    assert c["load_rel_diff"] < 1e-12
    assert c["elastic_constants_rel_diff"] < 1e-12
    # the air gap, 0 in the reference, needs a modulus in ccx: 1e-14 of steel or less
    assert c.get("air_gap_modulus_ratio", 0.0) < 1e-12
    # the deck's ties, axis and support fix and tie exactly the reference's DOFs
    assert c["constraints_as_reference"]


def _assert_sensors(res) -> None:
    tol = res.T_print_K + _solver_tol(res)
    # same discrete problem as the twin: only ccx's print rounding and solver round-off
    assert np.all(np.abs(res.T_ccx_K - res.T_twin_K) <= tol), res.to_pandas()
    # against the reference: the quadrature difference (exact vs ccx's degree-2 rule,
    # computed in double precision) plus the same rounding
    quad = np.abs(res.T_skfem_K - res.T_twin_K)
    assert np.all(np.abs(res.diff_K) <= quad + tol), res.to_pandas()


@pytest.mark.parametrize("level", [0, 1])
def test_fin_shaft_sensor_temperatures_agree(fin, level):
    res = fin[level]
    _assert_deck_holds_reference(res)
    assert len(res.sensors) == 11
    _assert_sensors(res)
    # and over all nodes: ccx - twin within the largest print bound (plus round-off)
    assert res.nodal["max_abs_ccx_minus_twin_K"] <= (res.nodal["max_print_bound_K"]
                                                     + _solver_tol(res))


def test_fin_shaft_difference_falls_under_refinement(fin):
    d0, d1 = fin[0].nodal["max_abs_diff_K"], fin[1].nodal["max_abs_diff_K"]
    # the quadrature consistency error of P2 with a degree-2 rule is O(h^2): a factor 4 per
    # level (measured 4.0); at least 3, well above the print floor (5e-4 K) at both levels
    assert d1 <= d0 / 3
    assert d1 > 4 * fin[1].nodal["max_print_bound_K"]
    # at the sensors the level-1 differences already touch the print floor: they fall too
    assert np.abs(fin[1].diff_K).max() < np.abs(fin[0].diff_K).max()


def test_spl2782_sensors_and_growth_agree(spl):
    res = spl[1]
    assert res.case == "steady" and res.speed_rpm == 4300.0  # spec.default_load_case()
    _assert_deck_holds_reference(res)
    assert res.deck["contacts"] == 6 and res.deck["ties"] > 0
    _assert_sensors(res)
    assert set(res.growth_ccx_m) == {"P1", "TCP"}
    for k in ("P1", "TCP"):
        skfem, ccx = res.growth_skfem_m[k], res.growth_ccx_m[k]
        twin, twin_ccxT = res.growth_twin_m[k], res.growth_twin_ccxT_m[k]
        # elastic deck alone (both driven by ccx's temperatures): ccx's print rounding of
        # u_z plus the O(theta^2) bound of ccx's 2-degree expansion of CAX6 sections
        allow = res.growth_print_m[k] + res.growth_expansion_m[k]
        assert abs(ccx - twin_ccxT) <= allow, (k, ccx, twin_ccxT)
        # against the reference: the quadrature difference (reference - twin, thermal and
        # elastic), the twin's response to ccx's rounded temperatures, and the same allowance
        assert abs(ccx - skfem) <= abs(skfem - twin) + abs(twin - twin_ccxT) + allow, k


def test_spl2782_difference_falls_under_refinement(spl):
    n0, n1 = spl[0].nodal["max_abs_diff_K"], spl[1].nodal["max_abs_diff_K"]
    # O(h^2) quadrature difference (measured factor 3.3 with the contact joints); >= 2.5
    assert n1 <= n0 / 2.5
    _assert_sensors(spl[0])
    g0 = max(abs(spl[0].growth_ccx_m[k] - spl[0].growth_skfem_m[k]) for k in ("P1", "TCP"))
    g1 = max(abs(spl[1].growth_ccx_m[k] - spl[1].growth_skfem_m[k]) for k in ("P1", "TCP"))
    # growth readings: measured factor 3.8 (TCP); the level-1 value is near the print floor
    assert g1 <= g0 / 2


def test_result_views_and_cli(tmp_path, capsys, fin):
    res = fin[0]
    df = res.to_pandas()
    assert list(df.columns[:6]) == ["sensor", "z_m", "r_m", "T_skfem_C", "T_ccx_C", "diff_K"]
    s = res.summary()
    assert s["max_abs_diff_K"] == pytest.approx(np.abs(res.diff_K).max())
    files = res.save(tmp_path / "saved")
    assert [f.name for f in files] == ["crosscheck.json", "crosscheck_sensors.csv",
                                       "crosscheck_growth.csv"]
    parser = argparse.ArgumentParser(prog="spindle-verify")
    register(parser.add_subparsers(dest="command", required=True))
    out = tmp_path / "cli"
    args = parser.parse_args(["crosscheck", "fin-shaft", "--level", "0", "--out", str(out),
                              "--keep-deck"])
    assert args.func(args) == 0
    printed = capsys.readouterr().out
    assert "T_skfem_C" in printed and "T_ccx_C" in printed and "shaft_05" in printed
    assert (out / "crosscheck.json").is_file() and (out / "crosscheck_sensors.csv").is_file()
    assert sorted(p.suffix for p in (out / "ccx").iterdir()) == [".frd", ".inp", ".log"]
    # the kept deck runs again by hand and gives the same temperatures
    deck = next((out / "ccx").glob("*.inp"))
    again = read_frd(run_ccx(deck))["T"]
    kept = read_frd(deck.with_suffix(".frd"))["T"]
    assert np.array_equal(again, kept)


def test_read_frd_fixed_width_and_continuation(tmp_path):
    text = "\n".join([
        "    1C",
        "    2C                             2                                     1",
        " -1         1 1.00000E+00 0.00000E+00 0.00000E+00",
        " -1         2 2.00000E+00-5.00000E-01 0.00000E+00",
        " -3",
        "  100CL  101 1.000000000           2                     0    1           1",
        " -4  NDTEMP      1    1",
        " -5  T           1    1    0    0",
        " -1         1 3.01000E+02",
        " -1         2-1.25000E+00",
        " -3",
        "  100CL  102 1.000000000           2                     0    1           1",
        " -4  DISP        4    1",
        " -5  D1          1    2    1    0",
        " -5  D2          1    2    2    0",
        " -5  D3          1    2    3    0",
        " -5  ALL         1    2    0    0    1ALL",
        " -1         1 1.00000E-06-2.00000E-06 0.00000E+00",
        " -1         2-3.00000E-06 4.00000E-06 0.00000E+00",
        " -3",
        " 9999", ""])
    path = tmp_path / "x.frd"
    path.write_text(text, encoding="ascii")
    r = read_frd(path)
    assert r["coords"][1].tolist() == [2.0, -0.5, 0.0]
    assert r["T"].tolist() == [301.0, -1.25]
    assert r["U"][:, :2].tolist() == [[1e-6, -2e-6], [-3e-6, 4e-6]]
    assert r["results"]["DISP"]["components"] == ["D1", "D2", "D3"]


def test_missing_ccx_names_the_fix(monkeypatch, tmp_path):
    monkeypatch.setattr(shutil, "which", lambda name: None)
    with pytest.raises(SolverError, match="install the Debian package calculix-ccx"):
        run_ccx(tmp_path / "none.inp")
    with pytest.raises(SolverError) as exc:
        crosscheck("fin-shaft", 0)
    assert str(exc.value) == CCX_MISSING


def test_a_failing_ccx_leaves_the_log_its_message_names(monkeypatch, tmp_path):
    """The message said "see its .log" of a temporary folder removed as the error left it; the
    folder of a failed solve is kept now, and the message names the log's path."""
    fake = tmp_path / "bin" / "ccx"
    fake.parent.mkdir()
    fake.write_text("#!/bin/sh\necho ' *ERROR in e_c3d: nonpositive jacobian'\nexit 201\n")
    fake.chmod(0o755)
    monkeypatch.setenv("PATH", f"{fake.parent}{os.pathsep}{os.environ['PATH']}")
    with pytest.raises(SolverError) as exc:
        crosscheck("fin-shaft", 0)
    msg = str(exc.value)
    log = Path(msg.rsplit("fix: see ", 1)[1])
    try:
        assert "exit status 201" in msg and "nonpositive jacobian" in msg
        assert log.suffix == ".log" and "nonpositive jacobian" in log.read_text()
    finally:
        shutil.rmtree(log.parent, ignore_errors=True)


@pytest.mark.parametrize("field", ["uniform", "r_linear", "r_quadratic"])
def test_spl2782_growth_of_radial_fields_agrees(field):
    """Issue 15 §2: a separately built model differed from the reference by 0.4-0.7 % in P1
    for temperature fields that vary with r alone. On the same mesh and constraints, ccx's
    P1 for such fields equals the reference's up to the quadrature difference (the twin),
    ccx's print rounding and its 2-degree expansion bound, as for the nominal field above;
    measured 1e-6 to 4e-6 relative (benchmarks/p1_fields.py). A 1 % error in the field
    handed to ccx fails every case."""
    import tempfile
    from pathlib import Path

    from compare.crosscheck.ccx_mesh import ccx_mesh
    from compare.crosscheck.check import EXPANSION_REL
    from compare.crosscheck.deck import write_elastic
    from compare.crosscheck.elastic_data import elastic_constraints
    from compare.crosscheck.frd import half_ulp
    from compare.crosscheck.twin import reading_rows, twin_gains
    from reference.simulation import ReferenceModel
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    model = ReferenceModel(spec, 0, 2)
    z, r = model.thermal.basis.doflocs
    rise = {"uniform": 10.0 + 0.0 * r, "r_linear": 10.0 * r / r.max(),
            "r_quadratic": 10.0 * (r / r.max()) ** 2}[field]
    T = spec.T_initial_K + rise
    skfem = model.elastic.growth(model.elastic.displacement(T))["P1"]
    cm = ccx_mesh(model)
    con = elastic_constraints(model, cm)
    with tempfile.TemporaryDirectory() as tmp:
        deck = write_elastic(model, cm, con, Path(tmp) / "radial.inp", T, spec.T_ambient_K)
        U = read_frd(run_ccx(deck, 600))["U"][:model.thermal.basis.N, 1]
    row = reading_rows(model)["P1"]
    ccx = float(row @ U)
    twin = float(twin_gains(model, cm, con)["P1"] @ rise)
    allow = float(np.abs(row) @ half_ulp(U)) + EXPANSION_REL * float(np.abs(row) @ np.abs(U))
    assert abs(ccx - twin) <= allow, (ccx, twin, allow)
    assert abs(ccx - skfem) <= abs(skfem - twin) + allow, (ccx, skfem, twin)
    # and far inside the gap: 0.1 % is its target for the P1 agreement
    assert abs(ccx - skfem) < 1e-3 * abs(skfem)
