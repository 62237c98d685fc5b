"""The figures of docs/power.md, bench.md, cycles.md, measures.md, reference.md, spec.md,
lumped.md and paper.md (issue 34): every figure they quote sits in a marked block
(tests/docs_blocks.py) whose text is built here, either by the project's code (the cheap,
deterministic figures, so that a changed result breaks this test) or from the figures file a
script in benchmarks/ wrote (timings, which no test can reproduce under load, and results of
runs too slow for the default run; a slow test recomputes those).

Each builder returns the block's text; a failing test prints the text to paste. A block
compares its figures at the digits the doc prints, so a change a reader would see breaks the
test and round-off does not; a coarser rounding says why beside it.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib
from functools import cache

import numpy as np
import pytest

from tests.docs_blocks import ROOT, assert_block

FIGURES = ROOT / "docs" / "figures"
K0 = 273.15  # K at 0 °C, for the °C the docs print


def figures(name: str) -> dict:
    """A figures file of docs/figures/ (written by a script in benchmarks/)."""
    return json.loads((FIGURES / name).read_text(encoding="utf-8"))


def spaced(v: float, digits: int = 0) -> str:
    """A number with a space between thousands, as the docs print them (12 430)."""
    return f"{v:,.{digits}f}".replace(",", " ")


def sci(v: float, digits: int = 2) -> str:
    """A number as the docs write powers of ten: 4.9e5, 7e-5."""
    m, e = f"{v:.{digits - 1}e}".split("e")
    return f"{m}e{int(e)}"


@cache
def spec_toml(name: str = "spl2782") -> dict:
    """A shipped spec as its TOML (the correlation parameters are not kept by the reader)."""
    with open(ROOT / "spindle" / "data" / "specs" / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def surface_toml(name: str) -> dict:
    return next(s for s in spec_toml()["surfaces"] if s["name"] == name)


# ---------------------------------------------------------------------------- docs/power.md


@cache
def drive():
    from spindle.drive import DRIVES

    return DRIVES["spl2782"]


def drive_checks_text() -> str:
    """What the shipped bearing values give at the rated speed: the friction of the front
    pair with the calibrated f0 and with Harris's catalogue value, and M1's share."""
    from spindle.power import bearing_friction

    d = drive()
    n = d.nominal.speed_rpm
    front = d.bearings["front_bearing"]
    shipped = bearing_friction(front, n)
    harris = bearing_friction(d.with_f0(2.0).bearings["front_bearing"], n)
    m1_share = shipped.M1_Nm / shipped.torque_Nm
    return (f"At {n:.0f} rpm (n dm = {sci(n * front.dm_m * 1e3)} mm/min) the front pair makes "
            f"{shipped.heat_W:.1f} W with the shipped f0 = {front.f0:g}; with Harris's catalogue "
            f"value f0 = 2 it would make {harris.heat_W:.0f} W, {harris.heat_W / shipped.heat_W:.1f} "
            f"times as much. The load term M1 is {100 * m1_share:.0f} % of its friction torque.")


def nominal_split_text() -> str:
    """The nominal point's power balance (the `nominal` cycle through the shipped drive with
    the measured power) and the drive's rating point, with its winding-temperature spread."""
    from spindle.cycle_files import load_cycle
    from spindle.power import power_balance

    d = drive()
    step = load_cycle("nominal").steps[0]
    pb = power_balance(d.motor, d.bearings, step.speed_rpm, step.load_torque_Nm, d.T_winding_K,
                       P_el_W=step.power_kW * 1e3)
    m, h = pb.motor, pb.heat_sources_W()
    iron = m.iron_hysteresis_W + m.iron_eddy_W
    rating = d.nominal_point()
    r = rating.motor
    cold, hot = (d.nominal_point(T + K0).total_heat_W for T in (80.0, 150.0))
    return "\n".join([
        "| source | W |", "|---|---:|",
        f"| front bearing pair | {h['front_bearing']:.1f} |",
        f"| rear bearing pair | {h['rear_bearing']:.1f} |",
        f"| motor copper | {m.copper_W:.1f} |",
        f"| motor iron (hysteresis {m.iron_hysteresis_W:.1f} + eddy {m.iron_eddy_W:.1f}) | "
        f"{iron:.1f} |",
        f"| motor total (stator {m.stator_W:.1f}, rotor {m.rotor_W:.1f}) | {m.total_W:.1f} |",
        f"| **total** | **{pb.total_heat_W:.1f}** (paper: {d.nominal.losses_W:.0f}) |", "",
        f"With the power measured, the motor's loss is what the {step.power_kW:g} kW leave after "
        f"the shaft's {m.P_mech_W / 1e3:.2f} kW: the motor model alone gives "
        f"{m.model_total_W:.1f} W at this torque, and the balance scales it by {m.scale:.3f} "
        "(`PowerBalance.motor.scale`).", "",
        f"`Drive.nominal_point()` is the drive file's rating instead "
        f"({d.nominal.P_mech_W / 1e3:g} kW *mechanical* at {d.nominal.speed_rpm:g} rpm, motor "
        f"model only): {r.torque_Nm:.1f} N m at {r.current_A:.1f} A rms and "
        f"{r.frequency_Hz:.0f} Hz, {rating.total_heat_W:.1f} W in all (front "
        f"{rating.bearings['front_bearing'].heat_W:.1f}, rear "
        f"{rating.bearings['rear_bearing'].heat_W:.1f}, copper {r.copper_W:.1f}, iron "
        f"{r.iron_hysteresis_W + r.iron_eddy_W:.1f}; stator {r.stator_W:.1f}, rotor "
        f"{r.rotor_W:.1f}). It checks the motor parameters against the paper's losses and is "
        f"not used as a load point. Its total moves with the assumed winding temperature "
        f"({d.T_winding_K - K0:.0f} °C): {cold:.0f} W at 80 °C, {hot:.0f} W at 150 °C."])


def film_table_text() -> str:
    """The correlations of docs/power.md at the spl2782 geometry (read from the spec file)
    before the spec's factors."""
    from spindle.correlations import (
        coolant_channel_reynolds,
        h_air_gap_W_m2K,
        h_coolant_channel_W_m2K,
        h_rotating_shaft_W_m2K,
    )

    nose = surface_toml("shaft_front_free")["h_W_m2K"]
    gap = next(lk for lk in spec_toml()["links"] if lk["type"] == "air_gap")["h_W_m2K"]
    jacket = surface_toml("coolant_housing")["h_W_m2K"]
    d, r, e = nose["d_m"], gap["r_rotor_m"], gap["gap_m"]
    q, w, hh = jacket["flow_l_min"], jacket["width_m"], jacket["height_m"]
    h_cool = h_coolant_channel_W_m2K(q, w, hh)
    Re, Dh, u = coolant_channel_reynolds(q, w, hh)
    rows = [f"| {n:.0f} | {h_rotating_shaft_W_m2K(n, d):.1f}"
            + (" (natural, ΔT 20 K)" if n == 0 else "")
            + f" | {h_air_gap_W_m2K(n, r, e):.1f} | {h_cool:.0f} |" for n in (0.0, 4300.0, 8000.0)]
    return "\n".join([
        f"Film coefficients for the spl2782 geometry (W/m²/K; the spec multiplies the rotating "
        f"surfaces' by {nose['factor']:g} and the jacket's by its wetted fraction "
        f"{jacket['factor']:g}):", "",
        f"| speed rpm | shaft nose d = {d:g} m | air gap r = {r * 1e3:g} mm, e = {e * 1e3:g} mm | "
        f"coolant {q:g} l/min, {hh * 1e3:g} × {w * 1e3:g} mm |", "|---:|---:|---:|---:|", *rows, "",
        # Re to tens: the water's viscosity is interpolated in a table of 3-4 digits
        f"The coolant figure is on the wetted channel wall (Re {spaced(round(Re, -1))}, "
        f"D_h {Dh * 1e3:.1f} mm, {u:.2f} m/s); an axisymmetric model that spreads it over the "
        "whole jacket must scale it by the wetted fraction."])


def correlation_limits_text() -> str:
    """Where the gap and shaft correlations reach their limits: the vortex branch at
    Ta_m = 1700, the speed at which the spl2782 nose passes Becker's Re = 4.3e5."""
    from spindle.correlations import air_properties
    from spindle.units import RPM_TO_RAD_S

    d = surface_toml("shaft_front_free")["h_W_m2K"]["d_m"]
    nu = air_properties(293.15).nu_m2_s
    rpm = 2 * nu * 4.3e5 / d**2 / RPM_TO_RAD_S  # Re = (omega d / 2) d / nu
    # the speed to 100 rpm ("near"): the limit Re = 4.3e5 itself has two digits
    return (f"The Becker–Kaye vortex branch gives Nu = {0.128 * 1700**0.367:.2f} at Ta_m = 1700, "
            f"so Nu is floored at 2 (conduction, h = k/e); above Ta_m = 1e7 it raises. The shaft "
            f"correlation is quoted up to Re ≈ 4.3e5 and is extrapolated above (d = {d:g} m in "
            f"20 °C air passes it near {round(rpm, -2):.0f} rpm).")


def test_power_drive_checks():
    assert_block("docs/power.md", "drive-checks", drive_checks_text())


def test_power_nominal_split():
    assert_block("docs/power.md", "nominal-split", nominal_split_text())


def test_power_film_table():
    assert_block("docs/power.md", "film-table", film_table_text())


def test_power_correlation_limits():
    assert_block("docs/power.md", "correlation-limits", correlation_limits_text())


def drive_table_cells() -> list[str]:
    """The start of each row of docs/power.md's table of shipped values, from the drive file
    (the table's reasons are prose; its values must be the file's)."""
    d = drive()
    m, f, r = d.motor, d.bearings["front_bearing"], d.bearings["rear_bearing"]
    mm = 1e3  # m to the table's mm
    return [f"| front pair | {f.count:d} × 7018 (90 × 140 × 24 mm), dm = {f.dm_m * mm:g} mm |",
            f"| rear pair | {r.count:d} × 7016 (80 × 125 × 22 mm), dm = {r.dm_m * mm:g} mm |",
            f"| f0 | {f.f0:g} per bearing |" if f.f0 == r.f0 else "| f0 | (differs per pair) |",
            f"| ν | {f.nu_mm2_s:g} mm²/s |",
            f"| preload, C0 | {f.preload_N:g} N / {f.C0_N / 1e3:g} kN front, {r.preload_N:g} N / "
            f"{r.C0_N / 1e3:g} kN rear |",
            f"| inner_ring_share | {f.inner_ring_share:g} |",
            f"| motor pole_pairs | {m.pole_pairs:d} |",
            f"| kT | {m.kT_Nm_A:g} N m/A |",
            f"| R20 | {m.R20_ohm:g} Ω per phase |",
            f"| k_h, k_e, B | {m.k_h_W_HzT2:g} W/(Hz T²), {m.k_e_W_Hz2T2:.1e} W/(Hz² T²), "
            f"{m.B_T:g} T |".replace("e-03", "e-3"),
            f"| rotor_loss_share | {m.rotor_loss_share:g} |",
            f"| winding temperature | {d.T_winding_K - K0:.0f} °C at the nominal point |"]


def test_power_table_quotes_the_drive_file():
    from tests.docs_blocks import doc_text

    text = doc_text("docs/power.md")
    missing = [c for c in drive_table_cells() if c not in text]
    assert not missing, "docs/power.md's table of shipped values should read:\n" + "\n".join(missing)


# ---------------------------------------------------------------------------- docs/bench.md


def no_load_friction_text() -> str:
    """The friction of the shipped bearings at 12 000 rpm without load (the power balance's
    P_mech when a bench reads the no-load power there)."""
    from spindle.power import bearing_friction

    d = drive()
    heat = {k: bearing_friction(b, 12_000.0).heat_W for k, b in d.bearings_at(12_000.0).items()}
    f0 = {b.f0 for b in d.bearings.values()}
    return (f"At 12 000 rpm without load the shipped `spl2782` bearings make "
            f"{sum(heat.values()):.0f} W of friction (front pair {heat['front_bearing']:.0f} W, "
            f"rear pair {heat['rear_bearing']:.0f} W; f0 = {', '.join(f'{v:g}' for v in f0)}), "
            "so a no-load reading below that trips the guard.")


def bench_read_text(doc: dict) -> str:
    """docs/bench.md's timing table from docs/figures/bench-read.json
    (benchmarks/bench_read.py)."""
    f = doc["files"]

    def cell(r: dict) -> str:
        return f"{r['min_s']:.3f} s / {r['median_s']:.3f} s"

    num = f["numeric"]
    return "\n".join([
        f"Measured {doc['date']} at commit {doc['commit']} (`{doc['made_by'].strip()}`) on "
        f"{doc['cores']} cores under a load average of {doc['load_average']:g}, Python "
        f"{doc['python']}, numpy {doc['numpy']}. The file is {spaced(num['rows'])} rows "
        f"(16 h at 1 s), {num['MB']:.1f} MB, with {num['columns']} columns: speed is logged on "
        "change, and every 7th P1 cell is empty.", "",
        f"| file | `read_bench` (min / median of {doc['repeat']}) |", "|---|---|",
        f"| numeric columns only (numpy's C parser) | {cell(f['numeric'])} |",
        f"| plus one unknown text column (`operator`) | {cell(f['text'])} |",
        f"| the text column quoted (the `csv` module, cell by cell) | {cell(f['quoted'])} |",
        f"| `inputs(run, spl2782)`: {doc['inputs']['intervals']} intervals | "
        f"{doc['inputs']['min_s']:.3f} s |",
        f"| one evaluation of the power balance | {doc['power_balance_us']:.0f} µs |"])


def test_bench_no_load_friction():
    assert_block("docs/bench.md", "no-load-friction", no_load_friction_text())


def power_balance_text(doc: dict) -> str:
    """docs/bench.md's table of the input checks' bounds from docs/figures/power-balance.json
    (benchmarks/bench_power_balance.py)."""
    figures = (("no_torque", "losses / bound, no torque column (no-load runs)", "below 1"),
               ("friction_share", "median P_el / bearing friction at f0 / 3, no-load runs",
                "above 1"),
               ("loaded", "losses / bound, loaded runs", "below 1"),
               ("loaded_without_torque", "losses / bound, loaded runs read without torque",
                "(what it catches)"),
               ("efficiency", "median M·ω / P_el, loaded runs", "below 1"),
               ("no_load_share", "median (P_el - M ω) / the drive's no-load losses, without a load",
                "below 3"),
               ("standstill_kW", "median P_el at standstill [kW]", "below 4.03"),
               ("growth_gain", "P1 / the spec's predicted growth", "0.0316 to 31.6"),
               ("below_friction_run", "running intervals in a row below the friction floor",
                "below 3"))
    rows = [f"Measured {doc['date']} at commit {doc['commit']}. Each figure must stay within "
            "its bound; the rows read without torque show what the loss bound catches.", "",
            "| runs | figure | bound | runs | min | median | max |",
            "|---|---|---|---:|---:|---:|---:|"]
    for group, name in (("peers", "the peer's (tests/data/peer-runs)"),
                        ("families", "the drawn families (benchmarks/.families-cache)")):
        for key, text, bound in figures:
            s = doc[group].get(key, {"runs": 0})
            if s["runs"]:
                rows.append(f"| {name} | {text} | {bound} | {s['runs']} | {s['min']:.2f} | "
                            f"{s['median']:.2f} | {s['max']:.2f} |")
    return "\n".join(rows)


def test_bench_power_balance_is_the_benchmarks():
    """The families' runs are not in a clean checkout (a cache of synthesised runs): the
    table is the figures file's; the peer's rows are recomputed by tests/test_bench.py."""
    assert_block("docs/bench.md", "power-balance", power_balance_text(figures("power-balance.json")))


def test_bench_read_timings_are_the_benchmarks():
    """Timings cannot be recomputed under load: they are the figures file's."""
    assert_block("docs/bench.md", "bench-read", bench_read_text(figures("bench-read.json")))


def test_bench_read_script_runs(tmp_path):
    """benchmarks/bench_read.py on an hour of rows: it reads all three files through both
    parsers, builds the intervals and writes a figures file the table can be built from."""
    out = tmp_path / "bench-read.json"
    r = subprocess.run([sys.executable, "benchmarks/bench_read.py", "--rows", "3600",
                        "--repeat", "1", "--out", str(out)], cwd=ROOT, capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    doc = json.loads(out.read_text(encoding="utf-8"))
    assert [v["rows"] for v in doc["files"].values()] == [3600] * 3
    assert doc["inputs"]["intervals"] == 60  # an hour on the 60 s grid
    assert "| plus one unknown text column" in bench_read_text(doc)


# --------------------------------------------------------------------------- docs/cycles.md


@cache
def cycle_toml(name: str) -> dict:
    with open(ROOT / "spindle" / "data" / "cycles" / f"{name}.toml", "rb") as f:
        return tomllib.load(f)


def drift_interpolation_text() -> str:
    """How far the spl-16h ambient, linear between its samples, is from the two half-cosine
    legs it samples (the formula of docs/cycles.md, evaluated here on its own)."""
    from spindle.cycle_files import load_cycle

    a = cycle_toml("spl-16h")["ambient"]
    cycle = load_cycle("spl-16h")
    D, tp = cycle.duration_s, a["t_peak_h"] * 3600.0
    t = np.linspace(0.0, D, 57_601)  # every second: the error's peaks lie between samples
    leg = np.where(t <= tp, a["T_start_C"] + (a["T_peak_C"] - a["T_start_C"])
                   * (1 - np.cos(np.pi * t / tp)) / 2,
                   a["T_peak_C"] + (a["T_end_C"] - a["T_peak_C"])
                   * (1 - np.cos(np.pi * (t - tp) / (D - tp))) / 2)
    err_mK = np.max(np.abs(cycle.T_ambient_K(t) - K0 - leg)) * 1e3
    rise = a["T_peak_C"] - a["T_start_C"]
    return (f"For the spl-16h room ({rise:g} K over {a['t_peak_h']:g} h, sampled every "
            f"{a['sample_s'] / 60:g} min) the linear interpolation is within {err_mK:.1f} mK of "
            "the curve.")


def spl16h_temperatures_text() -> str:
    """The spl-16h ambient and coolant bullets: the file's parameters, the ambient at every
    hour and the coolant's sample count (from the cycle as loaded)."""
    from spindle.cycle_files import load_cycle

    c = load_cycle("spl-16h")
    a, w = cycle_toml("spl-16h")["ambient"], cycle_toml("spl-16h")["coolant"]
    hours = int(c.duration_s // 3600)
    start = 7  # o'clock: the run's assumed start, a morning shift (docs/cycles.md)

    def clock(h: float) -> str:
        return f"{(start + int(h)) % 24:02d}:00"

    hourly = ", ".join(f"{c.T_ambient_K(3600.0 * h) - K0:.2f}" for h in range(hours + 1))
    shape = "symmetric triangle" if w["rise_fraction"] == 0.5 else \
        f"rise fraction {w['rise_fraction']:g}"
    return "\n".join([
        f"- **Ambient** (`model = \"drift\"`): {a['T_start_C']:.1f} degC at the start "
        f"({clock(0)}), {a['T_peak_C']:.1f} degC at {a['t_peak_h']:g} h ({clock(a['t_peak_h'])}), "
        f"{a['T_end_C']:.1f} degC at {hours} h ({clock(hours)}), every {a['sample_s'] / 60:g} "
        f"min. Hourly values: {hourly} degC.",
        f"- **Coolant** (`model = \"chiller\"`): set point {w['setpoint_C']:.1f} degC, "
        f"±{w['band_K']:g} K, period {w['period_s'] / 60:g} min, {shape} "
        f"({w['setpoint_C'] - w['band_K']:.1f}..{w['setpoint_C'] + w['band_K']:.1f} degC; "
        f"{len(c.T_coolant_K.time_s)} samples over {hours} h)."])


def nominal_torque_text() -> str:
    """The `nominal` cycle's torque from the paper's 38 kW and 5146 W (the assumption the
    cycle file states), and the other reading of the 38 kW."""
    from compare.design.paper import TARGETS
    from spindle.cycle_files import load_cycle
    from spindle.units import RPM_TO_RAD_S

    step = load_cycle("nominal").steps[0]
    w = step.speed_rpm * RPM_TO_RAD_S
    P, loss = step.power_kW * 1e3, TARGETS["losses_W"]
    torque = (P - loss) / w
    assert torque == pytest.approx(step.load_torque_Nm, abs=0.005)  # the file's 2 decimals
    return (f"- `power_kW = {step.power_kW:.1f}` is the paper's \"nominal load power\", taken as "
            f"the drive's power reading.\n  **Assumed**: if that is the electrical input, the "
            f"shaft delivers {P / 1e3:.1f} − {loss / 1e3:.3f} = {(P - loss) / 1e3:.3f} kW, i.e. "
            f"{spaced(P - loss)} W / (2π · {step.speed_rpm:.0f} / 60 s⁻¹) = {torque:.2f} N·m. "
            f"(Read as the mechanical output, {P / 1e3:.0f} kW would be {P / w:.2f} N·m with an "
            f"electrical input of about {(P + loss) / 1e3:.1f} kW.)")


def test_cycles_drift_interpolation():
    assert_block("docs/cycles.md", "drift-interpolation", drift_interpolation_text())


def test_cycles_spl16h_temperatures():
    assert_block("docs/cycles.md", "spl16h-temperatures", spl16h_temperatures_text())


def test_cycles_nominal_torque():
    assert_block("docs/cycles.md", "nominal-torque", nominal_torque_text())


# ------------------------------------------------------------------------- docs/measures.md


@cache
def spl2782():
    from spindle.spec_reader import load_spec

    return load_spec("spl2782")


@cache
def nominal_speed_rpm() -> float:
    from spindle.cycle_files import load_cycle

    return load_cycle("nominal").steps[0].speed_rpm


@cache
def nominal_indicators() -> dict:
    """The indicators of spl2782 at the nominal point: FEM level 1 (the command's default) and
    the paper's 5- and 11-node models, as ``spindle-verify measures`` computes them."""
    from compare.design.cases import MeasureCase
    from spindle.drive import load_case

    case = load_case(spl2782(), "nominal")
    return MeasureCase(spl2782(), case, None, 1, ("paper5", "paper11")).run()


def indicators_text() -> str:
    """docs/measures.md's table of indicators, computed (about a second)."""
    from compare.design.stiffness import PAPER, PAPER_FIGURES, sum_alpha_A_W_K

    base = nominal_indicators()
    fem = base["fem"]
    n = nominal_speed_rpm()
    G = sum_alpha_A_W_K(spl2782(), n)

    def row(name: str, i) -> str:
        return (f"| {name} | {i.mean_rise_K:.2f} | {i.max_rise_K:.2f} | "
                f"{sci(i.K_alpha_mean_K_W, 3)} | {sci(i.K_alpha_max_K_W, 3)} | {i.shaft_rise_K:.2f} "
                f"| {i.growth_um:.2f} | {i.K_T_K_um:.3f} | {i.K_Q_W_um:.1f} |")

    p = PAPER_FIGURES
    return "\n".join([
        f"**spl2782, nominal point** ({fem.losses_W:.1f} W at {n:.0f} rpm, coolant and ambient at "
        f"{fem.T_ambient_K - K0:.0f} °C; FEM level 1; growth: {fem.growth_reading}):", "",
        "| model | mean rise K | max rise K | K_alpha mean K/W | K_alpha max K/W | shaft rise K "
        "| TCP µm | K_T K/µm | K_Q W/µm |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
        row("FEM level 1", fem),
        *(row(f"lumped {nodes}", i) for nodes, i in base["lumped"].items()),
        f"| formulas, 1 / Σ alpha A | {fem.losses_W / G:.2f} | | {sci(1 / G, 3)} | | | | | |",
        f"| paper | | | {sci(PAPER['K_alpha_K_W'], 2)} | | {p['shaft_rise_K']:g} | "
        f"{p['growth_um']:g} | {PAPER['K_T_K_um']:g} | {PAPER['K_Q_W_um']:g} |", "",
        f"The simplified formulas' K_alpha is {fem.K_alpha_mean_K_W * G:.1f} times below the "
        "FEM's."])


def surfaces_text() -> str:
    """docs/measures.md's table of what sum(alpha_i A_i) runs over, at the nominal speed."""
    from compare.design.stiffness import surface_films

    films = surface_films(spl2782(), nominal_speed_rpm())
    G = sum(f.G_W_K for f in films)
    rows = [f"| {f.name} | {f.T_ref} | {f.h_W_m2K:.4g} | {f.A_m2:.4g} | {f.G_W_K:.4g} | "
            f"{100 * f.G_W_K / G:.2f} % |" for f in sorted(films, key=lambda f: -f.G_W_K)]
    coolant = sum(f.G_W_K for f in films if f.T_ref == "coolant") / G
    return "\n".join([
        "| surface | T_ref | alpha W/m²K | A m² | alpha A W/K | share |",
        "|---|---|---:|---:|---:|---:|", *rows, f"| **Σ** | | | | **{G:.4g}** | |", "",
        f"The coolant jacket is {100 * coolant:.1f} % of the sum."])


def measures_figures() -> dict:
    return figures("measures.json")


def measures_runtime_text(doc: dict) -> str:
    """How long the command took for the figures file (a timing: from the file only)."""
    one = doc["level1"]
    return (f"`{one['command']}` ran its {one['cases']} cases in {one['wall_s']:.0f} s on "
            f"{doc['cores']} cores (pictures included), measured {doc['date']} at commit "
            f"{doc['commit']} under a load average of {doc['load_average']:g} "
            f"(`{doc['made_by'].strip()}`, which writes "
            "[docs/figures/measures.json](figures/measures.json)).")


def _size(row: dict) -> str:
    parts = []
    if row.get("A_M_m2"):
        parts.append(f"A_M = {row['A_M_m2']:g} m² at {row['alpha_M_W_m2K']:g} W/m²K")
    if row.get("alpha_M2_W_m2K"):
        parts.append(f"alpha_M2 = {row['alpha_M2_W_m2K']:g} W/m²K")
    return ", ".join(parts)


def measures_table_text(doc: dict) -> str:
    """docs/measures.md's table of the shipped measures (level 1) and what level 2 changes,
    from docs/figures/measures.json (benchmarks/measures_figures.py)."""
    rows, rows2 = doc["level1"]["measures"], {r["measure"]: r for r in doc["level2"]["measures"]}
    lines = ["| measure | kind | size | lambda formula | xi formula | lambda FEM (mean) | "
             "xi FEM (mean) | xi FEM (max) | gap xi | effect ratio | TCP µm after | "
             "xi growth FEM | lambda paper5 / paper11 |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(
            f"| {r['measure']} | {r['kind']} | {_size(r)} | {r['lambda_formula']:.4f} | "
            f"{r['xi_formula_pct']:.2f} % | {r['lambda_ref_mean']:.4f} | "
            f"{r['xi_ref_mean_pct']:.2f} % | {r['xi_ref_max_pct']:.2f} % | "
            f"{r['gap_xi_pct_points']:+.2f} pp | {r['effect_ratio']:.3g} | "
            f"{r['growth_after_um']:.2f} | {r['xi_growth_ref_pct']:.1f} % | "
            f"{r['lambda_lumped_paper5']:.3f} / {r['lambda_lumped_paper11']:.3f} |")
    d_lam = {r["measure"]: abs(rows2[r["measure"]]["lambda_ref_mean"] - r["lambda_ref_mean"])
             for r in rows}
    d_gro = {r["measure"]: abs(rows2[r["measure"]]["lambda_growth_ref"] - r["lambda_growth_ref"])
             for r in rows}
    worst = max(d_gro, key=d_gro.get)
    # the level-1/level-2 differences to one digit: they estimate a discretisation error
    return "\n".join([
        *lines, "",
        "(effect ratio = (lambda_FEM − 1) / (lambda_formula − 1), the share of the predicted "
        f"effect the reference confirms; TCP before: {rows[0]['growth_before_um']:.2f} µm.) "
        f"Level 2 changes lambda FEM (mean) by at most {sci(max(d_lam.values()), 1)} and the "
        f"growth ratio by at most {sci(d_gro[worst], 1)} ({worst})."])


def _side(doc: dict, row: dict) -> str:
    """'coolant' if every surface of a measure is cooled by the coolant, else 'air'."""
    t_ref = {s["surface"]: s["T_ref"] for s in doc["level1"]["surfaces"]}
    return "coolant" if all(t_ref[s] == "coolant" for s in row["surfaces"].split()) else "air"


def measures_findings_text(doc: dict) -> str:
    """The figures behind the findings on the measures (level 1)."""
    rows = doc["level1"]["measures"]
    cool = [r for r in rows if _side(doc, r) == "coolant"]
    air = [r for r in rows if _side(doc, r) == "air"]
    growth = max(rows, key=lambda r: r["xi_growth_ref_pct"] - r["xi_ref_mean_pct"])

    def names(rs: list[dict]) -> str:
        return ", ".join(f"`{r['measure']}`" for r in rs)

    ratios = [r["effect_ratio"] for r in air]
    out = [f"- **Coolant side** ({names([r])}): the formulas promise a "
           f"{r['xi_formula_pct']:.1f} % cooler spindle (mean), the reference gives "
           f"{r['xi_ref_mean_pct']:.2f} %: {r['xi_formula_pct'] / r['xi_ref_mean_pct']:.1f} times "
           "less." for r in cool]
    out += [f"- **Air side** ({names(air)}): the reference gives {min(ratios):.1f} to "
            f"{max(ratios):.1f} times the effect the formulas promise.",
            f"- **Growth** (`{growth['measure']}`): the mean temperature falls by "
            f"{growth['xi_ref_mean_pct']:.2f} % and the TCP growth by "
            f"{growth['xi_growth_ref_pct']:.1f} %; the one-body formulas predict "
            f"{growth['xi_formula_pct']:.2f} % for both.",
            f"- **Maximum temperature**: no measure lowers the hottest point by more than "
            f"{max(r['xi_ref_max_pct'] for r in rows):.2f} %."]
    return "\n".join(out)


def _inverse_size(v: float, unit: str) -> tuple[str, str]:
    """A size of an inverse problem to three digits (Brent's rtol is 1e-6) and its unit."""
    if unit == "m2":
        return f"{v:.3g}", "m²"
    v = float(f"{v:.3g}")
    return (spaced(v) if v >= 1000 else f"{v:g}"), "W/m²K"


def inverse_text(doc: dict) -> str:
    """docs/measures.md's inverse problems, level 1 with level 2 in brackets."""
    rows2 = {r["target"]: r for r in doc["level2"]["inverse"]}
    lines = ["| target | varies | FEM level 1 (level 2) | formulas | FEM solves |",
             "|---|---|---:|---:|---:|"]
    for r in doc["level1"]["inverse"]:
        goal = (f"xi = {r['target_xi_pct']:g} %" if r["target_xi_pct"] is not None
                else f"growth ≤ {r['target_growth_um']:g} µm")
        (v1, unit), (v2, _) = (_inverse_size(x["size_ref"], r["unit"])
                               for x in (r, rows2[r["target"]]))
        vf, _ = _inverse_size(r["size_formula"], r["unit"])
        vary = r["vary"].rsplit("_", 1 if r["unit"] == "m2" else 2)[0]  # A_M, alpha_M2
        lines.append(f"| {goal} with `{r['measure']}` | {vary} | {v1} {unit} ({v2}) | "
                     f"{vf} {unit} | {r['fem_solves']} |")
    coolant = {r["measure"] for r in doc["level1"]["measures"] if _side(doc, r) == "coolant"}
    cool = next(r for r in doc["level1"]["inverse"] if r["measure"] in coolant)
    two = rows2[cool["target"]]
    return "\n".join([
        *lines, "",
        f"The coolant target (`{cool['target']}`) needs {cool['size_ref'] / cool['size_start']:.1f} "
        f"times today's coefficient, and that answer moves by "
        f"{100 * abs(two['size_ref'] / cool['size_ref'] - 1):.0f} % from level 1 to level 2."])


def sweeps_text(doc: dict) -> str:
    """The shipped sweeps' ranges and how far K_alpha moves over each (level 1)."""
    by = {}
    for r in doc["level1"]["sweeps"]:
        by.setdefault(r["sweep"], []).append(r)

    def change(rows: list[dict], key: str) -> float:
        rows = sorted(rows, key=lambda r: r["x"])
        return 100 * (rows[-1][key] / rows[0][key] - 1)

    def span(kind: str, fmt: str = "g") -> str:
        xs = [r["x"] for r in by[kind]]
        return f"{min(xs):{fmt}}-{max(xs):{fmt}}"

    a, f, h = (by[k] for k in ("area", "film", "heat"))
    mean, top, form = "K_alpha_mean_K_W", "K_alpha_max_K_W", "K_alpha_formula_K_W"
    return "\n".join([
        f"For spl2782 the shipped sweeps run over A_M {span('area')} m² ({a[0]['where']}), "
        f"alpha {span('film')} W/m²K ({f[0]['where']}), Q {span('heat')} W ({h[0]['where']}) "
        f"and L {span('length', '.3g')} m, {len(a)} points each. From the first point to the "
        "last, on level 1:", "",
        "| sweep | K_alpha mean (FEM) | K_alpha max (FEM) | formula 1 / Σ alpha A |",
        "|---|---:|---:|---:|",
        *(f"| {k} | {change(by[k], mean):+.1f} % | {change(by[k], top):+.1f} % | "
          f"{change(by[k], form):+.1f} % |" for k in ("area", "film", "heat", "length"))])


def test_measures_indicators():
    assert_block("docs/measures.md", "indicators", indicators_text())


def test_measures_surfaces():
    assert_block("docs/measures.md", "surfaces", surfaces_text())


def test_measures_runtime_is_the_benchmarks():
    assert_block("docs/measures.md", "measures-runtime", measures_runtime_text(measures_figures()))


def test_measures_tables_are_the_figures_file():
    doc = measures_figures()
    assert_block("docs/measures.md", "measures-table", measures_table_text(doc))
    assert_block("docs/measures.md", "measures-findings", measures_findings_text(doc))
    assert_block("docs/measures.md", "inverse", inverse_text(doc))
    assert_block("docs/measures.md", "sweeps", sweeps_text(doc))


def test_measures_figures_file_is_this_code():
    """The figures file's indicators and surfaces are what the code computes now (the same
    computation as the blocks above; the measures, inverse problems and sweeps take 30 s,
    recomputed by the slow test below)."""
    doc = measures_figures()["level1"]
    base = nominal_indicators()
    fem = next(r for r in doc["indicators"] if r["model"] == "FEM level 1")
    # relative 1e-9: the same solve in another process; only round-off may differ
    assert fem["growth_um"] == pytest.approx(base["fem"].growth_um, rel=1e-9)
    assert fem["mean_rise_K"] == pytest.approx(base["fem"].mean_rise_K, rel=1e-9)
    assert doc["sum_alpha_A_W_K"] == pytest.approx(
        sum(r["G_W_K"] for r in doc["surfaces"]), rel=1e-12)


@pytest.mark.slow
def test_measures_figures_file_is_regenerated(tmp_path):
    """benchmarks/measures_figures.py now gives the tables the file holds, to the digits the
    doc prints (so the file is not stale)."""
    out = tmp_path / "measures.json"
    r = subprocess.run([sys.executable, "benchmarks/measures_figures.py", "--out", str(out)],
                       cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    now = json.loads(out.read_text(encoding="utf-8"))
    for build in (measures_table_text, measures_findings_text, inverse_text, sweeps_text):
        assert build(now) == build(measures_figures()), build.__name__


# ------------------------------------------------------------------------ docs/reference.md


def open_air_text() -> str:
    """The nose's and the rear end's convective areas with and without the open-air rule
    (spindle.faces, the selection the mesh makes)."""
    from spindle.faces import exposed_faces, surface_faces

    spec = spl2782()
    faces = exposed_faces(spec)
    out = []
    for name in ("shaft_front_free", "shaft_rear_free"):
        s = next(x for x in spec.surfaces if x.name == name)
        every = [c for f in faces if f.part in s.parts
                 for c in [f.clip(s.z_min, s.z_max)] if c is not None]
        open_ = surface_faces(s, faces, spec)
        out.append(f"`{name}` keeps {sum(f.area_m2 for f in open_):.4f} of "
                   f"{sum(f.area_m2 for f in every):.4f} m²")
    return f"On spl2782 {out[0]}, and {out[1]}."


@cache
def elastic_levels() -> dict:
    """P1 at the spec's own operating point on levels 0-2 (P2), and the growth readings'
    offset at the start of spl-16h (every temperature at its 19.5 °C, read from the spec's
    stress-free temperature): each a linear functional of the temperature, so the offset is
    the cycle's start minus T_initial times the sum of the reading's gain."""
    from compare.design.cases import reference_model
    from spindle.cycle_files import load_cycle

    spec = spl2782()
    p1, offset = [], {}
    for level in range(3):
        ref = reference_model(spec, level)
        p1.append(ref.steady().growth_m["P1"])
    dT = float(load_cycle("spl-16h").T_ambient_K(0.0)) - spec.T_initial_K
    offset = {k: dT * g.sum() for k, (g, _) in ref.growth_gains().items()}  # level 2
    return {"P1_m": p1, "offset_m": offset, "dT_K": dT}


def growth_offset_text() -> str:
    e = elastic_levels()
    return (f"Read from the spec's stress-free temperature instead, spl-16h's start "
            f"({e['dT_K']:+.1f} K from it) would leave P1 at {e['offset_m']['P1'] * 1e6:.2f} µm "
            f"and TCP at {e['offset_m']['TCP'] * 1e6:.2f} µm at t = 0 (level 2).")


def p1_convergence_text() -> str:
    p1 = elastic_levels()["P1_m"]
    return (f"P1 on spl2782 at the spec's own operating point converges: "
            f"{', '.join(f'{v * 1e6:.3f}' for v in p1)} µm on levels 0, 1 and 2 (P2).")


def test_reference_open_air_areas():
    assert_block("docs/reference.md", "open-air", open_air_text())


def test_reference_growth_offset():
    assert_block("docs/reference.md", "growth-offset", growth_offset_text())


def test_reference_p1_convergence():
    assert_block("docs/reference.md", "p1-levels", p1_convergence_text())


# ----------------------------------------------------------------------------- docs/spec.md


def spec_scale_text() -> str:
    """The shipped spl2782's length and level-0 mesh, for scale against the reader's limits."""
    from meshes import build_mesh

    spec = spl2782()
    z = [v for _, s in spec.sections() for v in (s.z_start, s.z_end)]
    elements = build_mesh(spec, 0).counts(2)["elements"]
    return (f"For scale: the shipped spl2782 is {max(z) - min(z):.2f} m long and has "
            f"{spaced(elements)} elements at level 0 (h0 = {spec.h0_m:g} m).")


def contract_tests_text() -> str:
    """The sizes of the input-contract tests, read from the test modules themselves."""
    import re

    from tests.test_input_contract import CORPUS

    contract = (ROOT / "tests" / "test_input_contract.py").read_text(encoding="utf-8")
    fuzz = (ROOT / "tests" / "test_fuzz_readers.py").read_text(encoding="utf-8")
    examples = re.search(r"max_examples=(\d+)", contract)[1]
    bench, cycles = re.findall(r"max_examples=BUDGET or (\d+)", fuzz)
    slow = re.search(r'SPINDLE_FUZZ_EXAMPLES="(\d+)"', fuzz)[1]
    return (f"Tests: `tests/test_input_contract.py` ({len(CORPUS)} malformed inputs from the "
            "issue's list and the limits above, option checks, a property test mutating every "
            f"numeric field of the shipped specs, {examples} examples), "
            "`tests/test_fuzz_readers.py` (bench files and cycle CSVs mutated cell by cell and "
            f"structurally, {bench} + {cycles} examples; {slow} each under `-m slow`; valid "
            "variants: CRLF, byte-order mark, quoted cells, padded headers, reordered columns, an "
            "unknown column with a 1 MB cell), `tests/test_output_folders.py` (replacement, "
            "refusal, SIGTERM, SIGKILL leftovers).")


def contract_measured_text(doc: dict) -> str:
    """docs/spec.md's measured input contract, from docs/figures/input-contract.json
    (benchmarks/bench_input_contract.py)."""
    k = doc["kinds"]
    clean = "all cleanly" if doc["refused_cleanly"] == doc["refused"] else \
        f"{doc['refused_cleanly']} cleanly"
    return (f"**Measured** (`{doc['made_by'].strip()}`, {doc['date']} at commit {doc['commit']}, "
            f"{doc['wall_s']:.0f} s on {doc['cores']} cores): {doc['cases']} malformed or mutated "
            f"inputs through the `spindle-verify` command ({k['spec']} spec mutations of "
            f"fin-shaft and spl2782, {k['cycle']} cycle mutations, {k['bench']} broken bench "
            f"files, {k['option']} bad options). {doc['refused']} refused, **{clean}** (exit 2, "
            f"one line naming the file, the field and the fix); {doc['accepted']} mutations "
            f"left a valid input and ran to a plausible result. {doc['tracebacks']} tracebacks, "
            f"{doc['refusals_multi_line']} refusals of more than one line, "
            f"{doc['slower_than_60_s']} runs past 60 s (slowest {doc['slowest_s']:.1f} s), "
            f"{doc['impossible_results']} impossible results written, {doc['inputs_modified']} "
            f"inputs modified, {doc['written_on_refusal']} files written on a refusal.")


def test_spec_scale():
    assert_block("docs/spec.md", "spec-scale", spec_scale_text())


def test_spec_contract_tests():
    assert_block("docs/spec.md", "contract-tests", contract_tests_text())


def test_spec_contract_measured_is_the_benchmarks():
    assert_block("docs/spec.md", "contract-measured",
                 contract_measured_text(figures("input-contract.json")))


def _benchmark(name: str, monkeypatch):
    """A script of benchmarks/ as a module (its folder on the path, as when run)."""
    import importlib

    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    return importlib.import_module(name)


def test_input_contract_counts_make_the_paragraph(monkeypatch):
    """benchmarks/bench_input_contract.py's counts (what --figures writes) make the paragraph
    (the 375 cases themselves take 25 s: `python benchmarks/bench_input_contract.py`)."""
    bench = _benchmark("bench_input_contract", monkeypatch)
    row = {"kind": "spec", "exit": 2, "clean": True, "one_line": True, "traceback": None,
           "seconds": 0.5, "impossible": False, "inputs_modified": False,
           "written_on_refusal": False}
    rows = [row, {**row, "kind": "option", "exit": 0, "seconds": 2.0}]
    c = bench.counts(rows, 3.0)
    assert (c["cases"], c["refused"], c["accepted"], c["slowest_s"]) == (2, 1, 1, 2.0)
    text = contract_measured_text({"made_by": "x", "date": "d", "commit": "c", "cores": 2, **c})
    assert "1 refused, **all cleanly**" in text and "1 mutations left a valid input" in text


# --------------------------------------------------------------------------- docs/lumped.md


def eq14_text() -> str:
    """fin-shaft's lumped models against eq. 14: the paper's presets and the observed order
    (the computation of tests/test_lumped_fin.py, half a second)."""
    from spindle.spec_reader import load_spec
    from tests.conftest import observed_order
    from tests.test_lumped_fin import sensor_error

    spec = load_spec("fin-shaft")
    e5, e11 = sensor_error(spec, 5, True), sensor_error(spec, 11, True)
    nodes = [11, 21, 41, 81]
    order = {radial: observed_order([1.0 / (n - 1) for n in nodes],
                                    [sensor_error(spec, n, radial) for n in nodes])
             for radial in (False, True)}
    return (f"On `fin-shaft` the largest error on the 11 sensors is {e5:.2f} K at N = 5 and "
            f"{e11:.2f} K at N = 11. Over N = {', '.join(map(str, nodes))} the observed order is "
            f"{order[False]:.2f} without the radial conduction and {order[True]:.2f} with it.")


def lumped_speed_text(doc: dict) -> str:
    """docs/lumped.md's benchmark table and targets from docs/figures/lumped-speed.json
    (benchmarks/bench_lumped.py)."""
    rows = doc["rows"]
    paper = doc["paper_simulink_s"]
    lines = [f"`{doc['made_by'].strip()}`, measured {doc['date']} at commit {doc['commit']} on "
             f"{doc['cores']} cores under a load average of {doc['load_average']:g} "
             f"({doc['spec']}, {doc['cycle']} at 1 s = {spaced(rows[0]['samples'])} samples; "
             f"best of {doc['repeat']}):", "",
             "| nodes | masses | build | steady | 16 h on the 60 s grid | replay 16 h at 1 s | "
             f"vs paper's {paper:g} s | one streaming step | P1 peak |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['nodes']} | {r['masses']} | {r['build_s'] * 1e3:.0f} ms | "
                     f"{r['steady_s'] * 1e3:.1f} ms | {r['cycle_60s_grid_s']:.2f} s | "
                     f"{r['replay_16h_1s_s'] * 1e3:.0f} ms | "
                     f"{paper / r['replay_16h_1s_s']:.0f}× | {r['stream_step_us']:.1f} µs | "
                     f"{r['P1_peak_um']:.2f} µm |")
    r11 = next(r for r in rows if r["nodes"] == 11)
    replay_ms, step_us = r11["replay_16h_1s_s"] * 1e3, r11["stream_step_us"]
    a, b = r11["step_matrix"]
    return "\n".join([
        *lines, "", "Targets for 11 nodes:", "",
        f"- **Replay ≤ 20 ms: {'met' if replay_ms <= 20 else 'missed'}**, {replay_ms:.0f} ms.",
        f"- **Step ≤ 5 µs: {'met' if step_us <= 5 else 'missed'}**, {step_us:.1f} µs: one "
        f"{a} × {b} matrix-vector product (state and read-out; state, inputs and 1)."])


def lumped_worth_text(doc: dict) -> str:
    """What the study found of the lumped models, from docs/figures/main-job.json's findings
    (benchmarks/bench_main_job.py)."""
    f = doc["findings"]
    s, t = f["steady"], f["transient"]

    def others(case: dict) -> str:
        ok, edge = case["lumped_passing"], case["lumped_borderline"]
        if not ok and not edge:
            return "no lumped model meets both tolerances"
        parts = [f"{', '.join(ok)} meet both tolerances"] if ok else []
        parts += [f"{', '.join(edge)} are borderline (within the reference's uncertainty)"] \
            if edge else []
        return "; ".join(parts)

    return (f"The paper's 11-node model is {s['paper11_worst_K']:.1f} K off on its worst sensor "
            f"and {s['paper11_P1_um']:.1f} µm off on P1 at the nominal point (verdict: "
            f"{s['paper11_verdict']}), {t['paper11_worst_K']:.1f} K and "
            f"{t['paper11_P1_um']:.1f} µm over spl-16h ({t['paper11_verdict']}). At the nominal "
            f"point {others(s)}; over the cycle {others(t)} (the study of {doc['date']} at "
            f"commit {doc['commit']}, [docs/figures/main-job.json](figures/main-job.json)).")


def test_lumped_eq14():
    assert_block("docs/lumped.md", "eq14-convergence", eq14_text())


def test_lumped_speed_is_the_benchmarks():
    assert_block("docs/lumped.md", "lumped-speed", lumped_speed_text(figures("lumped-speed.json")))


def test_lumped_speed_file_is_this_code():
    """The benchmark file's deterministic columns are what the code gives now: the masses of
    every model, and the 11-node model's P1 peak over spl-16h at 1 s (half a second; the
    other node counts are recomputed by the slow test below)."""
    from lumped import build
    from lumped.realtime import RealTimePredictor
    from spindle.cycle_files import load_cycle
    from spindle.drive import cycle_load_case, drive_for
    from spindle.spec_reader import load_spec

    doc = figures("lumped-speed.json")
    spec = load_spec(doc["spec"])
    for r in doc["rows"]:
        assert build(spec, r["nodes"]).n_states == r["masses"], r["nodes"]
    model = build(spec, 11)
    case = cycle_load_case(spec, load_cycle(doc["cycle"]), drive_for(spec))
    T0 = float(case.T_ambient_K(0.0))
    mid = np.arange(0.0, case.duration_s, 1.0) + 0.5  # the benchmark's 1 s samples
    speeds = np.asarray(case.speed_rpm(mid), dtype=float)
    pred = RealTimePredictor(model, 1.0, x0=T0, speeds_rpm=np.unique(speeds))
    _, P1 = pred.run(model.inputs(case, mid), speeds)
    r11 = next(r for r in doc["rows"] if r["nodes"] == 11)
    # to the table's 0.01 µm: the replay is exact up to rounding, whatever the machine
    assert f"{P1.max() * 1e6:.2f}" == f"{r11['P1_peak_um']:.2f}"


@pytest.mark.slow
def test_lumped_speed_file_is_regenerated(tmp_path):
    """benchmarks/bench_lumped.py gives the P1 peaks and masses the file holds (timings
    differ from run to run and are not compared)."""
    out = tmp_path / "lumped-speed.json"
    r = subprocess.run([sys.executable, "benchmarks/bench_lumped.py", "--repeat", "1", "--out",
                        str(out)], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    now = json.loads(out.read_text(encoding="utf-8"))["rows"]
    was = figures("lumped-speed.json")["rows"]
    assert [(r["nodes"], r["masses"], f"{r['P1_peak_um']:.2f}") for r in now] == \
        [(r["nodes"], r["masses"], f"{r['P1_peak_um']:.2f}") for r in was]


def test_lumped_worth_is_the_study():
    assert_block("docs/lumped.md", "lumped-worth", lumped_worth_text(figures("main-job.json")))


# ---------------------------------------------------------------------------- docs/paper.md

#: the paper's figures the shipped f0 and rotating film factor were fitted to, and the losses
#: the motor parameters were chosen for (tests/test_paper.py asserts them within 5 %)
CALIBRATION_TARGETS = ("losses_W", "T1_peak_C", "P1_peak_um")


def paper_figures_text(doc: dict) -> str:
    """docs/paper.md's table of the paper's figures on levels 1 and 2, from
    docs/figures/paper.json (benchmarks/paper_figures.py)."""
    lv = {r["level"]: r for r in doc["levels"]}
    one, two = lv[1], lv[2]
    t, ind = doc["targets"], doc["paper_indicators"]
    digits = {"losses_W": 1, "T1_peak_C": 2, "P1_peak_um": 2, "shaft_rise_K": 1,
              "housing_rise_K": 1, "TCP_um": 1}
    order = ("losses_W", "T1_peak_C", "P1_peak_um", "shaft_rise_K", "housing_rise_K", "TCP_um")
    lines = ["| figure | level 1 | level 2 | paper | deviation (level 2) | within 5 % |",
             "|---|---:|---:|---:|---:|---|"]
    for k in order:
        d = digits[k]
        dev = two[k] / t[k] - 1
        ok = "yes" if abs(dev) <= 0.05 else "**no**"
        if k in CALIBRATION_TARGETS:
            ok += " (calibration target)"
        lines.append(f"| {k} | {one[k]:.{d}f} | {two[k]:.{d}f} | {t[k]:g} | {100 * dev:+.1f} % "
                     f"| {ok} |")
    lines += [f"| K_T [K/µm] (shaft rise / TCP) | {one['K_T_K_um']:.2f} | {two['K_T_K_um']:.2f} | "
              f"{ind['K_T_K_um']:g} | | |",
              f"| K_Q [W/µm] (losses / TCP) | {one['K_Q_W_um']:.1f} | {two['K_Q_W_um']:.1f} | "
              f"{ind['K_Q_W_um']:g} | | |"]
    return "\n".join([
        *lines, "",
        f"(`{doc['made_by'].strip()}`, {doc['date']} at commit {doc['commit']}: level 1 in "
        f"{one['runtime_s']:.0f} s and level 2 in {two['runtime_s']:.0f} s on {doc['cores']} "
        f"cores under a load average of {doc['load_average']:g}. P1 at the nominal point: "
        f"{one['P1_nominal_um']:.2f} µm at level 1, {two['P1_nominal_um']:.2f} µm at level 2.)"])


def calibration_cells() -> list[str]:
    """The start of the rows of docs/paper.md's shipped-calibration table, from the drive
    and the spec files."""
    f0 = {b.f0 for b in drive().bearings.values()}
    rotating = {surface_toml(n)["h_W_m2K"]["factor"] for n in ("shaft_front_free",
                                                                "shaft_rear_free")}
    assert len(f0) == len(rotating) == 1, (f0, rotating)  # one value each, as the table says
    return [f"| bearing friction factor f0 (Palmgren) | **{f0.pop():g}** |",
            f"| film factor of the rotating surfaces | **{rotating.pop():g}** |"]


def test_paper_figures_are_the_figures_file():
    assert_block("docs/paper.md", "paper-figures", paper_figures_text(figures("paper.json")))


def test_paper_calibration_table_quotes_the_shipped_files():
    from tests.docs_blocks import doc_text

    text = doc_text("docs/paper.md")
    missing = [c for c in calibration_cells() if c not in text]
    assert not missing, "docs/paper.md's shipped calibration should read:\n" + "\n".join(missing)


@pytest.mark.slow
def test_paper_figures_file_is_regenerated(tmp_path):
    """benchmarks/paper_figures.py gives the figures the file holds, to the doc's digits
    (runtimes differ and are not compared). Level 1 and 2 take a minute; the default run
    checks level 0 against the file's K_T and K_Q (tests/test_stiffness.py) and level 1's
    calibration targets (tests/test_paper.py)."""
    out = tmp_path / "paper.json"
    r = subprocess.run([sys.executable, "benchmarks/paper_figures.py", "--out", str(out)],
                       cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    now, was = json.loads(out.read_text(encoding="utf-8")), figures("paper.json")
    for doc in (now, was):
        for row in doc["levels"]:
            row["runtime_s"] = 0.0
        doc.update(made_by="", date="", commit="", load_average=0.0)
    assert paper_figures_text(now) == paper_figures_text(was)


# ------------------------------------------------------------------------------ every block

#: the checked blocks of each doc of this file (a new block needs its test here, and a block
#: taken out of a doc must leave this list: both fail the test below until they agree)
BLOCKS = {
    "docs/power.md": {"drive-checks", "nominal-split", "film-table", "correlation-limits"},
    "docs/bench.md": {"no-load-friction", "bench-read", "power-balance"},
    "docs/cycles.md": {"drift-interpolation", "spl16h-temperatures", "nominal-torque"},
    "docs/measures.md": {"measures-runtime", "indicators", "surfaces", "measures-table",
                         "measures-findings", "inverse", "sweeps"},
    "docs/reference.md": {"open-air", "growth-offset", "p1-levels"},
    "docs/spec.md": {"spec-scale", "contract-tests", "contract-measured"},
    "docs/lumped.md": {"eq14-convergence", "lumped-speed", "lumped-worth"},
    "docs/paper.md": {"paper-figures"},
}


@pytest.mark.parametrize("doc", sorted(BLOCKS))
def test_every_block_of_the_doc_is_checked_here(doc):
    import re

    from tests.docs_blocks import doc_text

    text = doc_text(doc)
    begun = re.findall(r"<!-- ([\w-]+):begin -->", text)
    ended = re.findall(r"<!-- ([\w-]+):end -->", text)
    assert begun == ended, f"{doc}: unbalanced block markers"
    assert len(set(begun) - {"history"}) == len(begun) - begun.count("history"), \
        f"{doc}: a block name appears twice"
    assert set(begun) - {"history"} == BLOCKS[doc]
