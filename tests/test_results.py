"""Result objects: tables, pictures and files, computed apart from plotting."""

import json
import re

import numpy as np
import pytest

from meshes import build_mesh
from reference import ThermalModel
from spindle.loads import LoadCase, TimeSeries
from spindle.spec_reader import load_spec


@pytest.fixture(scope="module")
def fin_model():
    return ThermalModel(build_mesh(load_spec("fin-shaft"), 0), 2)


def test_steady_to_pandas_and_plot(fin_model):
    pd = pytest.importorskip("pandas")
    res = fin_model.solve_steady()
    df = res.to_pandas()
    assert isinstance(df, pd.DataFrame)
    assert list(df.columns) == ["sensor", "array", "z_m", "r_m", "T_C", "rise_K"]
    assert len(df) == 11
    np.testing.assert_allclose(df["T_C"] + 273.15 - 293.15, df["rise_K"])
    ax = res.plot()
    assert ax.get_xlabel().startswith("z [mm]")


def test_transient_to_pandas_and_save(fin_model, tmp_path):
    pytest.importorskip("pandas")
    case = LoadCase("ramp", TimeSeries.constant(0.0), TimeSeries.constant(293.15),
                    TimeSeries.constant(293.15),
                    {"Q2_front_bearing_B": TimeSeries((0.0, 3600.0), (0.0, 90.0))},
                    duration_s=7200.0)
    res = fin_model.solve_transient(case, 600.0, save_every=6)
    df = res.to_pandas()
    assert df["time_s"].iloc[-1] == 7200.0 and "shaft_10_C" in df
    # heat enters at B (x = l): the sensor there warms first and most
    assert df["shaft_10_C"].iloc[-1] > df["shaft_00_C"].iloc[-1] > 20.0
    res.save(tmp_path)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["energy"]["relative_imbalance"] < 1e-10
    pvd = (tmp_path / "temperature.pvd").read_text()
    assert pvd.count("<DataSet") == len(res.field_times_s) == 3
    import pyvista as pv

    grid = pv.read(tmp_path / "fields" / "temperature_0002.vtu")
    assert grid.point_data["T_C"].max() == pytest.approx(res.fields_K[-1].max() - 273.15)


def test_transient_vtu_carries_displacement(tmp_path):
    import pyvista as pv

    from reference import ReferenceModel

    spec = load_spec("spl2782")
    ref = ReferenceModel(spec, level=0)
    case = spec.default_load_case()
    case = LoadCase("short", case.speed_rpm, case.T_ambient_K, case.T_coolant_K, case.sources,
                    duration_s=1800.0)
    res = ref.transient(case, 600.0, save_every=1)
    res.save(tmp_path, pictures=False)
    grid = pv.read(tmp_path / "fields" / "temperature_0003.vtu")
    # u_z at the probe points equals the P1 reading at the last time
    uz = grid.point_data["u_z_um"]
    assert np.ptp(uz) > 1.0
    assert res.growth_m["P1"][-1] * 1e6 == pytest.approx(
        ((ref.elastic.axial_probe(0.5295, 0.05) - ref.elastic.axial_probe(0.5, 0.095))
         @ res.U_fields[-1])[0] * 1e6, rel=1e-9)


def test_results_take_cycle_names_and_read_at_a_glance():
    """issue 34: a model's solves take a cycle's name as the CLI does; a result prints as one
    line in °C and µm, its summary holds plain numbers, and its plot is titled, has a legend
    and shows P1 against the ±1.5 µm band."""
    import lumped
    from spindle.tolerances import GROWTH_TOLERANCE_M

    model = lumped.build("spl2782", nodes=5)
    run = model.transient("spl-16h", dt_s=600.0)
    text = repr(run)
    # every 600 s and every input sample (the ambient's, every 15 min): more than 96 steps
    assert re.match(r"<LumpedTransientResult spl2782, spl-16h: 16 h in \d+ steps, ", text)
    assert "°C" in text and "P1" in text and "µm peak" in text and len(text) < 200
    assert "object at 0x" not in text
    steady = model.steady("nominal")
    assert steady.case.name == "nominal" and "4300 rpm" in repr(steady)
    summary = steady.summary()
    assert type(summary["speed_rpm"]) is float and "np.float64" not in str(summary)
    json.dumps(run.summary(), allow_nan=False)  # plain numbers throughout
    ax = run.plot()
    assert "spl-16h" in ax.get_title() and ax.get_legend() is not None
    p1_ax = ax.figure.axes[1]
    assert p1_ax.get_ylabel() == "P1 [µm]"
    labels = [t.get_text() for t in p1_ax.get_legend().get_texts()]
    assert f"±{GROWTH_TOLERANCE_M * 1e6:g} µm tolerance" in labels


def test_one_number_format_in_csv_and_headers_for_people(tmp_path):
    """A CSV holds floats to 10 significant digits and a missing value empty; a table for
    people heads its columns in words with units (docs/spec.md, 'Outputs')."""
    import csv
    import math

    from compare.report import human_header, markdown_table
    from spindle.outputs import write_csv

    write_csv(tmp_path / "t.csv", ["time_s", "P1_um", "ok"],
              [(19.500000000000057, math.nan, True), (1.0 / 3.0, None, False)])
    with open(tmp_path / "t.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[1] == ["19.5", "", "True"]
    assert rows[2] == ["0.3333333333", "", "False"]
    assert human_header("GCI_fine_pct") == "GCI fine [%]"
    assert human_header("P1_max_um") == "P1 max [µm]" and human_header("model") == "model"
    md = markdown_table(["model", "shaft_max_K"], [("eq. 14", math.nan)])
    assert "| model | shaft max [K] |" in md and "| eq. 14 | — |" in md
