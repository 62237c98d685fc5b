"""Design measures of paper section 4 (compare/design/): the simplified formulas
(eq. 22-32) against hand values, the FEM reference where their assumptions hold exactly and
where they do not, the inverse problem, the sweeps, the measures file and the command.

Test bodies (tests/data), both solid cylinders R = 0.05 m, L = 0.2 m with 100 W spread over
the volume:

- uniform_body.toml: ideal conductor, h = 10 W/m2/K on every face (sum(A) = 0.0785398 m2):
  the formulas' assumptions hold; its non-uniformity is 3.1e-6 of the rise
  (tests/test_stiffness.py), so lambda_ref matches the formulas to about 1e-6.
- conducting_rod.toml: k = 1 W/m/K, h = 10 W/m2/K on the lateral surface only (ends
  adiabatic): the exact solution T - T_amb = Q / (h A) + q (R^2 - r^2) / (4 k) is quadratic
  in r, so P2 elements reproduce it to round-off; its volume-mean rise is
  Q / (h A) + q R^2 / (8 k), and the formulas miss the internal resistance.
"""

from __future__ import annotations

import json
import math
import tomllib
from fnmatch import fnmatch
from pathlib import Path

import pytest

from compare import cli
from compare.design.cases import MeasureCase, SweepCase, measure_result, reference_model, solve_inverse
from compare.design.formulas import (
    lambda_added,
    lambda_added_as_printed,
    lambda_added_equal_alpha,
    lambda_both,
    lambda_both_equal_alpha,
    lambda_from_xi,
    lambda_improved,
    lambda_improved_equal_alpha,
    temperature_drop_K,
    xi_pct,
)
from compare.design.measure import Measure, apply_measure, formula_lambda
from compare.design.measure_file import (
    InverseTarget,
    MeasureFileError,
    SweepSpec,
    read_measures,
    shipped_measures,
)
from reference import ReferenceModel
from spindle.cycle_files import load_cycle
from spindle.drive import cycle_load_case
from spindle.spec_reader import load_spec

ROOT = Path(__file__).resolve().parents[1]
DATA = Path(__file__).parent / "data"
R, L, H, Q = 0.05, 0.2, 10.0, 100.0
A_LAT = 2 * math.pi * R * L  # 0.0628319 m2
SUM_A = A_LAT + 2 * math.pi * R * R  # 0.0785398 m2
Q_VOL = Q / (math.pi * R * R * L)  # 63 662 W/m3
#: uniform body: lambda_ref against the formulas; the body's non-uniformity is 3.1e-6 of its
#: rise (module doc); measured |lambda_ref / lambda_formula - 1| <= 2.8e-6 (mean), 6.1e-6 (max)
UNIFORM_REL = 1e-5
#: conducting rod: P2 contains the exact solution, so only round-off remains (measured 7e-15)
EXACT_REL = 1e-9


def rod_mean_rise(h_W_m2K: float, k: float = 1.0) -> float:
    """Volume-mean rise of the conducting rod [K], by hand (module doc)."""
    return Q / (h_W_m2K * A_LAT) + Q_VOL * R * R / (8 * k)


@pytest.fixture(scope="module")
def body():
    return load_spec(DATA / "uniform_body.toml")


@pytest.fixture(scope="module")
def rod():
    return load_spec(DATA / "conducting_rod.toml")


@pytest.fixture(scope="module")
def body_measures(body):
    return {m.name: m for m in read_measures(DATA / "uniform_body_measures.toml", body).measures}


# ----------------------------------------------------------------------------- formulas


def test_formulas_against_hand_values():
    # eq. 25 (consistent form): sum(alpha A) = 100 W/K, alpha_M A_M = 10 * 5 = 50 W/K
    assert lambda_added(100.0, 10.0, 5.0) == pytest.approx(1.5)
    assert lambda_added_as_printed(100.0, 10.0, 5.0) == pytest.approx(1 / 1.5)  # the misprint
    # eq. 26: the paper's example, an area ratio 1:1 gives lambda = 2
    assert lambda_added_equal_alpha(1.0, 1.0) == pytest.approx(2.0)
    # eq. 27: surfaces (10 W/m2K, 2 m2) and (50 W/m2K, 1 m2): sum = 70 W/K; the second
    # improved to 120 W/m2K adds 70 W/K
    assert lambda_improved(70.0, 120.0, [50.0], [1.0]) == pytest.approx(2.0)
    # eq. 28: alpha_M2 / alpha = 3 on a quarter of the area: 1 + 2 * 0.25
    assert lambda_improved_equal_alpha(30.0, 10.0, 1.0, 4.0) == pytest.approx(1.5)
    # eq. 29: 1 + 20/100 + (40 - 10) * 1 / 100
    assert lambda_both(100.0, 10.0, 2.0, 40.0, [10.0], [1.0]) == pytest.approx(1.5)
    # eq. 30: 1 + 0.2 + (3 - 1) * 0.25
    assert lambda_both_equal_alpha(0.8, 30.0, 10.0, 1.0, 4.0) == pytest.approx(1.7)
    # eq. 29 with all alpha equal is eq. 30: alpha = 10 on 4 m2 (40 W/K), A_M = 0.8,
    # 1 m2 raised to 30
    assert lambda_both(40.0, 10.0, 0.8, 30.0, [10.0], [1.0]) == pytest.approx(1.7)
    # eq. 32 and its inverse; eq. 24
    assert xi_pct(2.0) == pytest.approx(50.0)
    assert xi_pct(4.0) == pytest.approx(75.0)
    assert xi_pct(1.0) == 0.0
    assert lambda_from_xi(75.0) == pytest.approx(4.0)
    assert temperature_drop_K(40.0, 2.0) == pytest.approx(20.0)
    assert temperature_drop_K(40.0, 5.0) == pytest.approx(32.0)


def test_formula_lambda_of_a_spec(body, body_measures):
    # hand values in tests/data/uniform_body_measures.toml: eq. 26, 28, 30
    assert formula_lambda(body, body_measures["fins"], 0.0)[0] == pytest.approx(1.5)
    assert formula_lambda(body, body_measures["blown"], 0.0)[0] == pytest.approx(
        1 + (30 / 10 - 1) * A_LAT / SUM_A)  # 2.6
    lam, G0, dG = formula_lambda(body, body_measures["fins_blown"], 0.0)
    assert lam == pytest.approx(1 + 0.5 + 2 * A_LAT / SUM_A)  # 3.1
    assert G0 == pytest.approx(H * SUM_A)
    assert dG == pytest.approx(H * SUM_A / 2 + 20 * A_LAT)


def test_apply_measure_sets_the_film_coefficients(body, body_measures):
    def h(spec, name):
        return next(s for s in spec.surfaces if s.name == name).h_W_m2K(0.0)

    fins = apply_measure(body, body_measures["fins"])
    # fins of SUM_A / 2 at 10 W/m2K spread over the lateral surface: 10 + 10 * 0.625
    assert h(fins, "lateral") == pytest.approx(10 + 10 * (SUM_A / 2) / A_LAT)  # 16.25
    assert h(fins, "rear_face") == 10.0 and h(fins, "front_face") == 10.0
    assert h(apply_measure(body, body_measures["blown"]), "lateral") == 30.0
    assert h(apply_measure(body, body_measures["fins_blown"]), "lateral") == pytest.approx(36.25)
    assert apply_measure(body, None) is body


def test_added_surface_keeps_a_speed_table():
    spec = load_spec("spl2782")
    s = next(x for x in spec.surfaces if x.name == "shaft_front_free")
    area = 0.063650  # the nose and tool surface open to the air [m2] (tests/test_meshes.py)
    new = apply_measure(spec, Measure("m", "added_surface", (s.name,), 0.1, 20.0))
    t = next(x for x in new.surfaces if x.name == s.name).h_W_m2K
    assert t.speed_rpm == s.h_W_m2K.speed_rpm
    # 20 W/m2K on 0.1 m2 spread over 0.0637 m2 adds 31.4 W/m2K at every speed (the area to
    # the 5 digits written here: 1e-4)
    for a, b in zip(t.values, s.h_W_m2K.values, strict=True):
        assert a - b == pytest.approx(20 * 0.1 / area, rel=1e-4)


# ----------------------------------------------------------------------------- reference


def _lambda_ref(spec, measure, level=0):
    case = spec.default_load_case()
    base = MeasureCase(spec, case, None, level).run()
    after = MeasureCase(spec, case, measure, level).run()
    return measure_result(spec, case, measure, base, after)


@pytest.mark.parametrize("name, lam", [("fins", 1.5), ("blown", 1 + 2 * A_LAT / SUM_A),
                                       ("fins_blown", 1.5 + 2 * A_LAT / SUM_A)])
def test_reference_agrees_with_the_formulas_where_they_hold(body, body_measures, name, lam):
    r = _lambda_ref(body, body_measures[name])
    assert r.lambda_formula == pytest.approx(lam, rel=1e-12)
    assert r.lambda_ref_mean == pytest.approx(lam, rel=UNIFORM_REL)
    assert r.lambda_ref_max == pytest.approx(lam, rel=UNIFORM_REL)
    assert abs(r.to_row()["gap_lambda"]) < UNIFORM_REL * lam
    assert r.effect_ratio == pytest.approx(1.0, abs=UNIFORM_REL * lam / (lam - 1))


@pytest.mark.parametrize("level", [0, 1])
def test_reference_shows_the_gap_where_they_do_not_hold(rod, level):
    """Fins doubling the film conductance: eq. 26 says lambda = 2; the rod's internal
    resistance keeps it at (1/h + R/(4k)) / (1/(2h) + R/(4k)) = 0.1125 / 0.0625 = 1.8
    (per unit of lateral heat flux, by hand)."""
    m = Measure("fins", "added_surface", ("lateral",), A_LAT, H)  # eq. 26: 1 + A_LAT / A_LAT
    r = _lambda_ref(rod, m, level)
    lam_exact = rod_mean_rise(H) / rod_mean_rise(2 * H)  # 179.049 / 99.472 = 1.8
    assert lam_exact == pytest.approx(1.8)
    assert r.lambda_formula == pytest.approx(2.0, rel=1e-12)
    assert r.before.mean_rise_K == pytest.approx(rod_mean_rise(H), rel=EXACT_REL)
    assert r.lambda_ref_mean == pytest.approx(lam_exact, rel=EXACT_REL)
    row = r.to_row()  # the gap is reported
    assert row["gap_lambda"] == pytest.approx(1.8 - 2.0, rel=1e-8)
    assert row["gap_xi_pct_points"] == pytest.approx(xi_pct(1.8) - 50.0, rel=1e-8)  # -5.56
    assert row["effect_ratio"] == pytest.approx(0.8, rel=1e-8)
    # the hottest point (the axis) gains less: its rise keeps q R^2 / (4 k) = 39.8 K
    max_exact = (Q / (H * A_LAT) + Q_VOL * R * R / 4) / (Q / (2 * H * A_LAT) + Q_VOL * R * R / 4)
    assert r.lambda_ref_max == pytest.approx(max_exact, rel=EXACT_REL)


def test_cached_model_equals_a_fresh_build():
    """Swapping film coefficients in the cached assembly is the modified spec's solve."""
    spec = load_spec("spl2782")
    case = cycle_load_case(spec, load_cycle("nominal"))
    m = Measure("coolant", "improved_coefficient", ("coolant_housing", "coolant_sleeve"),
                alpha_M2_W_m2K=7922.0)
    reference_model(spec, 0).steady(case)  # cache the unmodified spec first
    cached = reference_model(apply_measure(spec, m), 0).steady(case)
    fresh = ReferenceModel(apply_measure(spec, m), 0).steady(case)
    scale = float(abs(fresh.T).max())
    assert float(abs(cached.T - fresh.T).max()) <= 1e-12 * scale  # round-off (measured 0)
    assert cached.growth_m["TCP"] == pytest.approx(fresh.growth_m["TCP"], rel=1e-12)
    assert cached.heat_out_W == pytest.approx(fresh.heat_out_W, rel=1e-12)


# ----------------------------------------------------------------------------- inverse


def test_inverse_where_the_formulas_hold(body, body_measures):
    t = InverseTarget("half", "fins", "A_M_m2", xi_pct=50.0)
    res = solve_inverse(body, body.default_load_case(), body_measures["fins"], t, level=0)
    assert res.reached
    assert res.size_formula == pytest.approx(SUM_A, rel=1e-12)  # eq. 26: lambda 2 at 1:1
    # lambda_ref deviates by <= UNIFORM_REL, and d(A_M) / A_M = d(lambda) / (lambda - 1)
    assert res.size_ref == pytest.approx(SUM_A, rel=UNIFORM_REL)
    assert res.value_at_size == pytest.approx(50.0, rel=1e-6)  # Brent's rtol on the size


def test_inverse_where_they_do_not(rod):
    m = Measure("fins", "added_surface", ("lateral",), A_LAT, H)
    t = InverseTarget("half", "fins", "A_M_m2", xi_pct=50.0)
    res = solve_inverse(rod, rod.default_load_case(), m, t, level=0)
    # by hand: lambda = 2 needs (0.1 + 0.0125) / (1/h' + 0.0125) = 2, h' = 160/7 W/m2K,
    # so A_M = (h' - h) / alpha_M * A_LAT = 9/7 A_LAT
    assert rod_mean_rise(H) / rod_mean_rise(160 / 7) == pytest.approx(2.0)
    assert res.reached
    assert res.size_ref == pytest.approx(9 / 7 * A_LAT, rel=1e-5)  # Brent's rtol 1e-6
    assert res.size_formula == pytest.approx(A_LAT, rel=1e-12)  # eq. 26 says 1:1
    assert res.to_row()["formula_over_ref"] == pytest.approx(7 / 9, rel=1e-5)


def test_inverse_reports_an_unreachable_target(rod):
    m = Measure("fins", "added_surface", ("lateral",), A_LAT, H)
    t = InverseTarget("half", "fins", "A_M_m2", xi_pct=50.0, size_max=0.01)
    res = solve_inverse(rod, rod.default_load_case(), m, t, level=0)
    assert not res.reached and math.isnan(res.size_ref)
    h_max = H + H * 0.01 / A_LAT  # all 0.01 m2 of fins at 10 W/m2K
    assert res.best_value == pytest.approx(xi_pct(rod_mean_rise(H) / rod_mean_rise(h_max)),
                                           rel=EXACT_REL)  # 11.7 %
    assert "not reachable" in res.note


def test_inverse_growth_target_on_spl2782():
    spec = load_spec("spl2782")
    case = cycle_load_case(spec, load_cycle("nominal"))
    m = Measure("nose", "improved_coefficient", ("shaft_front_free",), alpha_M2_W_m2K=100.0)
    t = InverseTarget("g25", "nose", "alpha_M2_W_m2K", growth_um=25.0)
    res = solve_inverse(spec, case, m, t, level=0)
    assert res.reached
    # an independent solve at the size found gives the target (Brent's rtol 1e-6 on the
    # size; d(growth)/d(alpha) is -0.48 um per W/m2K there (measured), so 1e-3 um is generous)
    check = ReferenceModel(apply_measure(spec, m.with_size("alpha_M2_W_m2K", res.size_ref)),
                           0).steady(case)
    assert check.growth_m["TCP"] * 1e6 == pytest.approx(25.0, abs=1e-3)
    # the formulas, blind to where the heat goes, ask for a far larger coefficient
    assert res.size_formula > 10 * res.size_ref


# ----------------------------------------------------------------------------- sweeps


def test_sweep_points_where_the_formulas_hold(body):
    case = body.default_load_case()
    G = H * SUM_A

    def point(kind, x, **kw):
        return SweepCase(body, case, SweepSpec(kind, (x,), **kw), x, 0).run()

    p = point("heat", 150.0, source="heat")
    assert p.losses_W == pytest.approx(150.0)
    assert p.K_alpha_formula_K_W == pytest.approx(1 / G, rel=1e-12)
    assert p.K_alpha_mean_K_W == pytest.approx(1 / G, rel=UNIFORM_REL)
    p = point("area", SUM_A, surfaces=("lateral",), alpha_M_W_m2K=H)
    assert p.K_alpha_formula_K_W == pytest.approx(1 / (2 * G), rel=1e-12)
    assert p.K_alpha_mean_K_W == pytest.approx(1 / (2 * G), rel=UNIFORM_REL)
    p = point("film", 20.0, surfaces=("lateral", "rear_face", "front_face"))
    assert p.K_alpha_mean_K_W == pytest.approx(1 / (2 * G), rel=UNIFORM_REL)
    p = point("length", 0.3)  # stretched from 0.2 to 0.3 m: only the lateral area grows
    G3 = H * (2 * math.pi * R * 0.3 + 2 * math.pi * R * R)
    assert p.K_alpha_formula_K_W == pytest.approx(1 / G3, rel=1e-12)
    assert p.K_alpha_mean_K_W == pytest.approx(1 / G3, rel=UNIFORM_REL)


# ----------------------------------------------------------------------------- the file


def test_shipped_file_reads_and_is_package_data():
    spec = load_spec("spl2782")
    path = shipped_measures("spl2782")
    assert path is not None and path.name == "spl2782.toml"
    mf = read_measures(path, spec)
    assert [m.kind for m in mf.measures].count("improved_coefficient") >= 1
    assert {m.kind for m in mf.measures} == {"added_surface", "improved_coefficient", "both"}
    assert mf.inverse and mf.sweeps and {s.kind for s in mf.sweeps} == {"area", "length",
                                                                          "film", "heat"}
    data = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    globs = data["tool"]["setuptools"]["package-data"]["spindle"]
    assert any(fnmatch("data/measures/spl2782.toml", g) for g in globs)
    assert shipped_measures("fin-shaft") is None


def _write(tmp_path, text: str) -> Path:
    p = tmp_path / "m.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_bad_file_reports_every_problem_with_field_and_fix(tmp_path, body):
    p = _write(tmp_path, """
spec = "uniform-body"
colour = "red"

[[measure]]
name = "a"
kind = "fins"
surfaces = ["lateral"]

[[measure]]
name = "b"
kind = "added_surface"
surfaces = ["top"]
alpha_M_W_m2K = 10.0

[[measure]]
name = "c"
kind = "improved_coefficient"
surfaces = ["lateral"]
alpha_M2_W_m2K = -3
A_M_m2 = 1.0

[[inverse]]
name = "i"
measure = "nothing"
xi_pct = 10
""")
    with pytest.raises(MeasureFileError) as exc:
        read_measures(p, body)
    text = str(exc.value)
    fields = [q.field for q in exc.value.problems]
    assert "colour" in fields
    assert "measure[0].kind" in fields
    assert "measure[1].surfaces" in fields and "measure[1].A_M_m2" in fields
    assert "measure[2].alpha_M2_W_m2K" in fields and "measure[2].A_M_m2" in fields
    assert "inverse[0].measure" in fields
    assert all(str(p) in line and "fix:" in line for line in text.splitlines())
    assert "['lateral', 'rear_face', 'front_face']" in text  # the fix lists the surfaces


def test_other_file_problems(tmp_path, body):
    with pytest.raises(MeasureFileError, match="does not exist"):
        read_measures(tmp_path / "missing.toml", body)
    with pytest.raises(MeasureFileError, match="syntax"):
        read_measures(_write(tmp_path, "[[measure]\n"), body)
    with pytest.raises(MeasureFileError, match="written for spec 'spl2782'"):
        read_measures(_write(tmp_path, 'spec = "spl2782"\n[[measure]]\nname = "a"\n'
                             'kind = "improved_coefficient"\nsurfaces = ["lateral"]\n'
                             'alpha_M2_W_m2K = 20.0\n'), body)
    base = ('[[measure]]\nname = "a"\nkind = "improved_coefficient"\nsurfaces = ["lateral"]\n'
            'alpha_M2_W_m2K = 20.0\n')
    with pytest.raises(MeasureFileError, match="needs exactly one target"):
        read_measures(_write(tmp_path, base + '[[inverse]]\nname = "i"\nmeasure = "a"\n'
                             'xi_pct = 10\ngrowth_um = 5\n'), body)
    with pytest.raises(MeasureFileError, match="no growth reading"):
        read_measures(_write(tmp_path, base + '[[inverse]]\nname = "i"\nmeasure = "a"\n'
                             'growth_um = 5\n'), body)
    with pytest.raises(MeasureFileError, match="sweeps.heat.source"):
        read_measures(_write(tmp_path, base + '[sweeps]\nheat = { source = "x", max_W = 5 }\n'),
                      body)
    with pytest.raises(MeasureFileError, match="needs at least one"):
        read_measures(_write(tmp_path, 'spec = "uniform-body"\n'), body)


# ----------------------------------------------------------------------------- command


def test_command_on_the_uniform_body(tmp_path, capsys):
    out = tmp_path / "out"
    rc = cli.main(["measures", str(DATA / "uniform_body.toml"), "--measures",
                   str(DATA / "uniform_body_measures.toml"), "--level", "0", "--nodes", "3",
                   "--workers", "2", "--out", str(out)])
    captured = capsys.readouterr()
    # alpha = 0 on every surface is singular: that one sweep point fails, is reported, and
    # the command says so with exit status 1; everything else is written
    assert rc == 1
    assert "FAILED sweep film alpha=0 W/m2K" in captured.out
    # progress (compare/progress.py): the failed case is always written, on its own line,
    # with its count; the run ends with the final line
    failed = [ln for ln in captured.err.splitlines() if "FAILED: " in ln]
    assert len(failed) == 1 and failed[0].startswith("measures: [")
    assert "sweep film alpha=0 W/m2K" in failed[0]
    assert captured.err.splitlines()[-1].startswith("measures: done in ")
    for f in ("measures.csv", "indicators.csv", "inverse.csv", "sweeps.csv", "measures.md",
              "measures.json", "fig15_temperature_drop.png", "fig16_sensitivity.png"):
        assert (out / f).is_file(), f
    doc = json.loads((out / "measures.json").read_text())
    assert len(doc["failures"]) == 1 and "singular" in doc["failures"][0]["error"]
    rows = {r["measure"]: r for r in doc["measures"]}
    assert rows["fins"]["lambda_formula"] == pytest.approx(1.5)  # hand values of the file
    assert rows["fins_blown"]["lambda_formula"] == pytest.approx(1.5 + 2 * A_LAT / SUM_A)
    assert rows["fins"]["lambda_ref_mean"] == pytest.approx(1.5, rel=UNIFORM_REL)
    assert rows["fins"]["lambda_lumped_3"] == pytest.approx(1.5, rel=UNIFORM_REL)
    assert len(doc["sweeps"]) == 4 * 3 - 1
    assert doc["inverse"][0]["size_ref"] == pytest.approx(SUM_A, rel=UNIFORM_REL)
    md = (out / "measures.md").read_text()
    assert "## Measures" in md and "## Failed cases" in md


def test_command_on_spl2782_with_its_shipped_file(tmp_path, capsys):
    out = tmp_path / "spl"
    rc = cli.main(["measures", "spl2782", "--level", "0", "--points", "2", "--nodes", "paper5",
                   "--no-pictures", "--quiet", "--out", str(out)])
    captured = capsys.readouterr()
    assert rc == 0, captured.out + captured.err
    assert captured.err == ""  # --quiet
    assert "housing_fins" in captured.out and "inverse fins_for_1pct" in captured.out
    doc = json.loads((out / "measures.json").read_text())
    assert doc["measures_file"].endswith("spl2782.toml")
    assert doc["failures"] == []
    row = next(r for r in doc["measures"] if r["measure"] == "coolant_flow_x2")
    # the water jacket is 99 % of sum(alpha A): the formulas see a 74 % stiffer spindle, the
    # reference (internal resistance between the heat and the jacket) only a few %
    assert row["lambda_formula"] > 1.7 and row["lambda_ref_mean"] < 1.1
    assert not (out / "fig15_temperature_drop.png").exists()


def test_command_input_errors_exit_2(tmp_path, capsys):
    assert cli.main(["measures", "fin-shaft", "--out", str(tmp_path / "x")]) == 2
    assert "--measures: no measures file is shipped" in capsys.readouterr().err
    bad = _write(tmp_path, '[[measure]]\nname = "a"\nkind = "nope"\n')
    assert cli.main(["measures", str(DATA / "uniform_body.toml"), "--measures", str(bad),
                     "--out", str(tmp_path / "y")]) == 2
    err = capsys.readouterr().err
    assert "measure[0].kind" in err and "fix:" in err and "Traceback" not in err
    assert cli.main(["measures", "spl2782", "--nodes", "1", "--out", str(tmp_path / "z")]) == 2
    assert "--nodes" in capsys.readouterr().err
    assert not (tmp_path / "x").exists() and not (tmp_path / "y").exists()


def test_report_tables_as_rows_and_dataframes(body):
    from compare.design.measure_file import MeasureFile
    from compare.design.report import run_measures

    mf = read_measures(DATA / "uniform_body_measures.toml", body)
    rep = run_measures(body, MeasureFile(mf.path, mf.measures[:1]), body.default_load_case(),
                       level=0, nodes=(), sweeps=False, workers=1)
    rows = rep.to_rows()
    assert [r["measure"] for r in rows["measures"]] == ["fins"]
    assert rows["surfaces"][0]["A_m2"] == pytest.approx(A_LAT, rel=1e-12)
    pd = pytest.importorskip("pandas")
    frames = rep.to_pandas()
    assert isinstance(frames["measures"], pd.DataFrame)
    assert frames["measures"]["lambda_formula"].iloc[0] == pytest.approx(1.5)


def test_fig15_spreads_lambdas_near_one_and_survives_a_loss(tmp_path, monkeypatch):
    """Fig. 15's left panel is log-log in lambda_tr - 1 and Delta T, so measures whose
    lambdas lie within 1.002..1.08 (spl2782's) land apart; a measure that makes things worse
    (lambda < 1, no point on a log axis) is drawn at the axis's lower end, not dropped."""
    from types import SimpleNamespace

    from compare.design import plots

    rows = {"fins": (1.0024, 1.0188), "air": (1.0067, 1.0566), "worse": (1.003, 0.98)}

    def measure(name, lf, lr):
        row = {"lambda_formula": lf, "lambda_ref_mean": lr}
        return SimpleNamespace(measure=SimpleNamespace(name=name), to_row=lambda: row)

    rep = SimpleNamespace(spec_name="s", case_name="c",
                          baseline=SimpleNamespace(mean_rise_K=34.8),
                          measures=[measure(n, *v) for n, v in rows.items()])
    fig_axes = []
    plt = plots.pyplot()
    real_close = plt.close

    def keep(fig):  # the axes of the figure fig15_png closes
        fig_axes.extend(fig.axes)
        real_close(fig)

    monkeypatch.setattr(plt, "close", keep)
    plots.fig15_png(rep, tmp_path / "fig15.png")
    assert (tmp_path / "fig15.png").stat().st_size > 0
    left = fig_axes[0]
    assert left.get_xscale() == "log" and left.get_yscale() == "log"
    squares = [ln.get_xdata()[0] for ln in left.lines if ln.get_marker() == "s"]
    assert squares == pytest.approx([0.0188, 0.0566, plots._LAMBDA_EXCESS_RANGE[0]])
    assert "worse (lambda <= 1 + 1e-3 drawn at the axis)" in [
        t.get_text() for t in left.get_legend().get_texts()]
    labels = [t.get_text() for t in fig_axes[1].get_yticklabels()]
    assert labels[0].startswith("fins\no 0.08 K, ■ 0.64 K")  # eq. 24: 34.8 * 0.0188 / 1.0188


def _fins_file(A_M_m2: float = 0.01, alpha_M_W_m2K: float = 10.0) -> str:
    """A measures file of the uniform body with one added surface."""
    return f"""
spec = "uniform-body"

[[measure]]
name = "fins"
kind = "added_surface"
surfaces = ["lateral"]
A_M_m2 = {A_M_m2}
alpha_M_W_m2K = {alpha_M_W_m2K}
"""


@pytest.mark.parametrize("key, value", [("A_M_m2", 1e300), ("alpha_M_W_m2K", 1e300)])
def test_a_measure_far_beyond_any_spindle_is_named(tmp_path, body, key, value):
    """An added surface of 1e300 m2 ran, printed numpy's overflow warnings, and wrote its
    folder with exit 1; the bounds (100 m2, 1e5 W/(m2 K): compare.design.measure_file) name
    it instead."""
    p = _write(tmp_path, _fins_file(**{key: value}))
    with pytest.raises(MeasureFileError) as exc:
        read_measures(p, body)
    assert [q.field for q in exc.value.problems] == [f"measure[0].{key}"]
    assert "is not within 0.." in str(exc.value)


@pytest.mark.parametrize("entry, field", [
    ('area = { surfaces = ["lateral"], alpha_M_W_m2K = 10.0, max_m2 = 1e300 }', "area.max_m2"),
    ('area = { surfaces = ["lateral"], alpha_M_W_m2K = 1e300, max_m2 = 1.0 }',
     "area.alpha_M_W_m2K"),
    ('film = { surfaces = ["lateral"], max_W_m2K = 1e300 }', "film.max_W_m2K"),
    ('heat = { source = "SOURCE", max_W = 2e7 }', "heat.max_W"),
    ("length = { min_factor = 1e-300, max_factor = 1.5 }", "length.min_factor"),
    ("length = { min_factor = 0.5, max_factor = 1e6 }", "length.max_factor"),
])
def test_a_sweep_far_beyond_any_spindle_is_named(tmp_path, body, entry, field):
    """Sweeps had no upper bounds (found by fuzzing): 1e300 ran with numpy's overflow warnings
    and exit 1, a length factor of 1e-300 stopped with "too many indices", 1e6 ran for
    minutes, and a heat of 2e7 W wrote a rise of about 3e6 K. The bounds are the measures'
    own (100 m2, 1e5 W/(m2 K)), the spec's largest source (1e6 W: spindle.spec_fields) and
    a length within 0.1-10 times the spindle's."""
    source = body.heat_sources[0].name
    p = _write(tmp_path, _fins_file() + f"""
[sweeps]
{entry.replace("SOURCE", source)}
""")
    with pytest.raises(MeasureFileError) as exc:
        read_measures(p, body)
    assert [q.field for q in exc.value.problems] == [f"sweeps.{field}"]
    assert "is not " in str(exc.value) and "fix: give" in str(exc.value)


def test_a_measures_file_with_a_byte_order_mark_reads_as_without(tmp_path, body):
    """Some editors start a file with a UTF-8 byte-order mark; the spec and cycle readers
    dropped it, the measures file read it as "Invalid statement" on line 1 (found by
    fuzzing)."""
    text = (DATA / "uniform_body_measures.toml").read_text(encoding="utf-8")
    p = _write(tmp_path, "\ufeff" + text)
    got, plain = read_measures(p, body), read_measures(DATA / "uniform_body_measures.toml", body)
    assert (got.measures, got.inverse, got.sweeps) == (plain.measures, plain.inverse,
                                                       plain.sweeps)


def test_a_target_of_a_broken_measure_is_not_a_second_problem(tmp_path, body):
    """A measure with A_M_m2 = 0 also gave "inverse[0].measure: 'fins' is not a measure of
    this file" (found by fuzzing): one problem, one message."""
    p = _write(tmp_path, _fins_file(A_M_m2=0.0) + """
[[inverse]]
name = "fins_for_1pct"
measure = "fins"
xi_pct = 1.0

[[inverse]]
name = "other"
measure = ["fins"]
xi_pct = 1.0
""")
    with pytest.raises(MeasureFileError) as exc:
        read_measures(p, body)
    assert [q.field for q in exc.value.problems] == ["measure[0].A_M_m2", "inverse[1].measure"]
