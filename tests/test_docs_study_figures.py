"""The figures of docs/harness.md, verification.md, rom.md, sensors.md, crosscheck.md and
commands.md, held to what makes them (issue 34): each marked block of those docs
(tests/docs_blocks.py) is rebuilt here, from a figures file in docs/figures/ (written by the
script named in its ``made_by``) or from the same computation the verification tests run,
at the precision the doc prints. A changed result fails the test until the doc is
regenerated; the message shows the text to paste.

Figures files and the scripts that write them:

- docs/figures/study.json: ``python benchmarks/bench_main_job.py`` (or ``--study-only``)
- docs/figures/main-job.json: ``python benchmarks/bench_main_job.py`` (the README's)
- docs/figures/p1-fields.json: ``python benchmarks/p1_fields.py``
- docs/figures/crosscheck.json: ``python benchmarks/crosscheck_figures.py``
- docs/figures/sensors.json: ``python benchmarks/sensors_figures.py``
- docs/figures/rom.json: ``python benchmarks/rom_figures.py``
- docs/figures/rom-speed.json: ``OPENBLAS_NUM_THREADS=1 python benchmarks/bench_rom.py``
- docs/figures/solvers.json: ``python benchmarks/bench_solvers.py``
- tests/baselines/spl2782.json: ``spindle-verify baseline spl2782 --out tests/baselines/spl2782.json``
"""

from __future__ import annotations

import json
import re
import statistics
from pathlib import Path

import numpy as np
import pytest

from tests.docs_blocks import assert_block, block, doc_text

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"


def figures(name: str) -> dict:
    return json.loads((FIGURES / name).read_text(encoding="utf-8"))


def sci(x: float, digits: int = 2) -> str:
    """``x`` in scientific notation with ``digits`` significant digits and a short exponent
    (``1.4e-6``, not Python's ``1.4e-06``)."""
    text = f"{x:.{digits - 1}e}"
    mantissa, exp = text.split("e")
    return f"{mantissa}e{int(exp)}"


def listed(items: list[str]) -> str:
    items = list(items)
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def thousands(n: int) -> str:
    return f"{n:,}".replace(",", " ")


def made(doc: dict) -> str:
    """Where a figures file's figures come from: date, commit and command."""
    return f"{doc['date']}, commit {doc['commit']}, `{doc['made_by']}`"


# ====================================================================== docs/harness.md
# docs/figures/study.json: the study of `python benchmarks/bench_main_job.py`

def harness_ground_truth(study: dict) -> str:
    c = study["convergence"]
    worst = c["worst_GCI_pct_per_level"]
    gt, finest = c["ground_truth_level"], c["levels"][-1]
    p = {q: v for q, v in c["observed_order"].items() if v is not None}
    lo, hi = min(p, key=p.get), max(p, key=p.get)
    # the GCI to two digits, as the README prints it; orders to one decimal (they are
    # estimates from three levels, and the doc compares them with the integer 3 of P2)
    truth = f"- **Ground truth:** level {gt}, worst GCI {worst[str(gt)]:.2g} %"
    if gt != finest:
        truth += f"; at level {finest} the worst is {worst[str(finest)]:.2g} %"
    flagged = c["flagged"]
    orders = (f"- **Observed orders** on the finest triplet: median "
              f"{statistics.median(p.values()):.1f}, from {p[lo]:.1f} ({lo}) to {p[hi]:.1f} "
              f"({hi})")
    by_flag: dict[str, list[str]] = {}
    for q, f in flagged.items():
        by_flag.setdefault(f, []).append(q)
    if flagged:
        orders += "; flagged, with none: " + "; ".join(
            f"{len(qs)} {f} ({listed(qs)})" for f, qs in by_flag.items())
    return truth + ".\n" + orders + "."


def study_caption(study: dict, case: str) -> str:
    s, run = study[case], study["study"]
    what = ("Steady" if case == "steady" else
            "Transient (errors over the sensors and over time)")
    return (f"{what}, `{s['case']}`. Reference: {s['reference']}. From the study of "
            f"{made(study)} (docs/figures/study.json); its runtimes at a load average of "
            f"{run['load_average']:.1f} on 2 cores:")


def harness_eq14(study: dict) -> str:
    eq14 = next(m for m in study["steady"]["models"] if m["model"] == "eq. 14")
    # whole kelvins: the point is its size (tens of K) against a 1 K tolerance
    return (f"**Eq. 14 on {study['spec']}** takes Q1 and Q2 from the inner-ring half of the "
            "bearing losses. Eq. 14 has no way to carry the rotor's heat, which is why it is "
            f"{eq14['worst_K']:.0f} K off at the nominal point.")


def test_harness_quotes_the_study():
    """docs/harness.md's ground truth, observed orders, eq. 14 and its three tables are the
    study's of docs/figures/study.json (the tables as the study writes them)."""
    study = figures("study.json")
    assert_block("docs/harness.md", "harness-ground-truth", harness_ground_truth(study))
    assert_block("docs/harness.md", "harness-convergence", study["convergence"]["markdown"])
    assert_block("docs/harness.md", "harness-eq14", harness_eq14(study))
    for case in ("steady", "transient"):
        assert_block("docs/harness.md", f"harness-{case}",
                     study_caption(study, case) + "\n\n" + study[case]["markdown"])


def test_the_study_figures_and_the_readme_figures_agree():
    """docs/figures/study.json (the harness's tables) and docs/figures/main-job.json (the
    README's findings) come from runs of the same study: the README's text built from
    either is the same (a regenerated one without the other fails here)."""
    from tests.test_docs_snippets import study_findings

    study, main = figures("study.json"), figures("main-job.json")
    assert study_findings({"findings": study["findings"]}) == study_findings(main)


# ================================================================= docs/verification.md
def test_verification_md_states_no_suite_time():
    """The suite's run time is the README's business (measured by CI), not a hand figure."""
    assert "about 20 s" not in doc_text("docs/verification.md")


def mms_table(spec_from) -> str:
    """The MMS errors over levels 1..4 and the observed L2 orders, computed as
    tests/test_verification_mms.py computes them."""
    from tests.conftest import observed_order
    from tests.test_verification_mms import SPEC, solve_mms

    spec = spec_from(SPEC, "mms")
    lines = ["| element | errors (levels 1..4) | observed order | expected |",
             "|---|---|---|---|"]
    for order in (1, 2):
        hs, errs = zip(*(solve_mms(spec, lv, order) for lv in range(1, 5)), strict=True)
        # three significant digits: the errors are far from round-off (1e-7 and up)
        lines.append(f"| P{order} | {', '.join(sci(e, 3) for e in errs)} | "
                     f"{observed_order(list(hs), list(errs)):.2f} | {order + 1} |")
    return "\n".join(lines)


def test_verification_mms_block(spec_from):
    assert_block("docs/verification.md", "mms", mms_table(spec_from))


def fin_table(tmp_path) -> str:
    """FEM against eq. 14 on thinner and thinner shafts, as tests/test_verification_fin.py."""
    from tests.test_verification_fin import H, K, fem_vs_eq14

    lines = ["| R [m] | Biot h R/k | max abs(FEM − eq. 14) / max rise | "
             "max abs(FEM − eq. 14) [K] |", "|---|---|---|---|"]
    shipped = None
    for radius in (0.025, 0.0125, 0.00625):
        fem, fin = fem_vs_eq14(tmp_path, radius)
        rel = float(np.max(np.abs(fem - fin)) / np.max(fin))
        shipped = rel if shipped is None else shipped
        # three significant digits: the differences are a model-form error (1e-3 and up),
        # far above the FEM's own error at level 2
        lines.append(f"| {radius:.5f} | {sci(H * radius / K, 3)} | {sci(rel, 3)} | "
                     f"{np.max(np.abs(fem - fin)):.3f} |")
    return "\n".join(lines) + (f"\n\nFor the shipped `fin-shaft` (R = 25 mm) the difference is "
                               f"{100 * shipped:.2f} % of the peak rise.")


def test_verification_fin_block(tmp_path):
    assert_block("docs/verification.md", "fin-biot", fin_table(tmp_path))


def gps_p1_text(spec_from) -> str:
    """P1 elements on the long free pipe (tests/test_verification_elastic.py's case): the
    axial strain's largest relative error at levels 0-2 and the observed orders, for both
    Poisson ratios of the test (the doc prints them once where they agree)."""
    from meshes import build_mesh
    from reference import ThermalModel
    from reference.elastic import ThermoelasticModel
    from tests.test_verification_elastic import PIPE, gps_axial_strain

    a, b, dT, alpha = 0.02, 0.05, 50.0, 1.2e-5
    radii = np.linspace(a, b, 7)
    texts = set()
    for nu in (0.3, 0.45):
        spec = spec_from(PIPE.replace("z_end = 0.04", "z_end = 1.0").replace(
            "nu = 0.3", f"nu = {nu}"), f"gps{nu}")
        errs = []
        for level in (0, 1, 2):
            th = ThermalModel(build_mesh(spec, level), 1)
            el = ThermoelasticModel(th)
            u = el.displacement(el.T_ref + dT * (th.basis.doflocs[1] / b) ** 2)
            uz = [(el.basis.probes(np.vstack([np.full(7, z), radii])).tocsr() @ u)[:7]
                  for z in (0.4, 0.6)]
            strain = (uz[1] - uz[0]) / 0.2
            errs.append(float(np.max(np.abs(strain / gps_axial_strain(a, b, alpha, dT) - 1))))
        # three decimals: the case is built so the order is exactly 2 (2.000 shows it);
        # errors to three digits (1e-4 and up, far from round-off)
        orders = sorted({f"{o:.3f}" for o in np.log2(np.array(errs[:-1]) / np.array(errs[1:]))})
        texts.add(f"- **P1 elements.** The strain converges at observed order "
                  f"{' and '.join(orders)}: {listed([f'{100 * e:.3g} %' for e in errs])} at "
                  "levels 0-2.")
    return "\n".join(sorted(texts))


def test_verification_generalised_plane_strain_block(spec_from):
    assert_block("docs/verification.md", "gps-p1", gps_p1_text(spec_from))


def time_order_table(spec_from) -> str:
    """Observed orders of backward Euler and Crank-Nicolson on the lumped-capacitance decay
    (tests/test_verification_transient.py::test_time_order)."""
    from meshes import build_mesh
    from reference import ThermalModel
    from tests.test_verification_transient import LUMP, TAU, decay_error

    model = ThermalModel(build_mesh(spec_from(LUMP, "lump"), 0), 1)
    dts = [TAU / n for n in (10, 20, 40, 80)]
    lines = ["| scheme | observed order | expected |", "|---|---|---|"]
    for name, theta, expected in (("backward Euler", 1.0, 1), ("Crank-Nicolson", 0.5, 2)):
        errs = [decay_error(model, dt, theta) for dt in dts]
        rate = np.polyfit(np.log(dts), np.log(errs), 1)[0]
        # two decimals: enough to see the order against the test's tolerance of 0.1
        lines.append(f"| {name} | {rate:.2f} | {expected} |")
    return "\n".join(lines)


def test_verification_time_order_block(spec_from):
    assert_block("docs/verification.md", "time-order", time_order_table(spec_from))


def backward_euler_limit_text() -> str:
    """Backward Euler at 60, 15 and 3.75 s against the exact read-outs on fin-shaft level 0
    (tests/test_time_convergence.py's case)."""
    from compare.verify.study import study_cases
    from reference import ReferenceModel
    from spindle.spec_reader import load_spec
    from tests.test_time_convergence import _be_error

    spec = load_spec("fin-shaft")
    _, case = study_cases(spec)
    model = ReferenceModel(spec, 0)
    T0 = float(case.T_ambient_K(0.0))
    t, S, _, _ = model.exact_readouts(case, 60.0, T0, method="cram")
    errs = [_be_error(model, case, T0, t, S, dt) for dt in (60.0, 15.0, 3.75)]
    orders = np.log(np.array(errs[:-1]) / np.array(errs[1:])) / np.log(4.0)
    # orders to two decimals (the test holds them within 0.15 of 1), errors to three digits
    return (f"- Backward Euler at 60, 15 and 3.75 s converges to the exact read-outs at "
            f"observed orders {orders[0]:.2f} and {orders[1]:.2f} "
            f"({listed([f'{e:.3g}' for e in errs])} K on fin-shaft level 0): they are its "
            "limit.")


def test_verification_backward_euler_limit_block():
    assert_block("docs/verification.md", "be-limit", backward_euler_limit_text())


def krylov_cram_fin_text() -> str:
    """The Krylov read-outs against CRAM-16 on fin-shaft levels 0 and 1
    (tests/test_time_convergence.py::_krylov_against_cram): the largest difference and the
    stated estimate, two and one significant digits (the estimate is a bound's order)."""
    from tests.test_time_convergence import _krylov_against_cram

    runs = [_krylov_against_cram("fin-shaft", lv) for lv in (0, 1)]
    return (f"On fin-shaft levels 0 and 1 the Krylov read-outs are "
            f"{listed([sci(r[0]) for r in runs])} K from CRAM-16, under the stated "
            f"{listed([sci(r[1], 1) for r in runs])} K.")


def test_verification_krylov_against_cram_fin_shaft():
    assert_block("docs/verification.md", "krylov-cram-fin", krylov_cram_fin_text())


@pytest.mark.slow
def test_verification_krylov_against_cram_spl2782():
    """spl2782 level 0 (CRAM-16 takes about half a minute there, hence slow; the fast test
    above runs the same code on fin-shaft)."""
    from tests.test_time_convergence import _krylov_against_cram

    err_K, est_K, err_m, est_m, _ = _krylov_against_cram("spl2782", 0)
    assert_block("docs/verification.md", "krylov-cram-spl2782",
                 f"On spl2782 level 0: {sci(err_K)} K under {sci(est_K)} K, and P1 "
                 f"{sci(err_m)} m under {sci(est_m)} m.")


def krylov_study_text(study: dict) -> str:
    ti = study["time_integration"]
    # two digits for the error and the share (an estimate; only its size against the 1 %
    # limit matters); the growth error to one (it is a sum of estimates near 1e-6 µm)
    return (f"On {study['spec']} (`spindle-verify study {study['spec']}`, docs/figures/study.json"
            f") the stated temporal error is {sci(ti['time_error_K'])} K and "
            f"{sci(ti['time_error_um'], 1)} µm: {100 * ti['share']:.2g} % of the spatial "
            f"uncertainty ({ti['spatial_uncertainty_K']:.2g} K, "
            f"{ti['spatial_uncertainty_um']:.2g} µm), under the limit of "
            f"{100 * ti['limit']:g} %.")


def test_verification_quotes_the_study_time_error():
    assert_block("docs/verification.md", "krylov-study", krylov_study_text(figures("study.json")))


def dt_table(study: dict, baseline: dict) -> str:
    """The worst transient errors of the models both runs hold, at the study's dt (60 s) and
    at the committed baseline's (300 s), with the verdicts against the paper's tolerances."""
    fig = baseline["figures"]
    rows = {m["model"]: m for m in study["transient"]["models"]}
    names = list(dict.fromkeys(k.split("/")[1] for k in fig if k.startswith("transient/")))
    dt_b = baseline["settings"]["dt_s"]
    lines = [f"| model | dt 60 s (study) | dt {dt_b:g} s (baseline) | verdict at 60 s / "
             f"{dt_b:g} s |", "|---|---:|---:|---|"]
    for name in names:
        r = rows[name]
        worst = max(v for k, v in fig.items() if k.startswith(f"transient/{name}/err_")
                    and k.endswith("_max_K") and v is not None)
        p1 = fig[f"transient/{name}/err_P1_max_um"]
        word = "PASS" if worst <= 1.0 and p1 <= 1.5 else "FAIL"  # the paper's 1 K, 1.5 µm
        label = name + (f" ({r['preset']})" if r["preset"] else "")
        # three decimals: the two step lengths differ by hundredths of a kelvin (the lumped
        # models' zero-order hold), which two decimals would hide
        lines.append(f"| {label} | {r['worst_K']:.3f} K, {r['P1_um']:.3f} µm | {worst:.3f} K, "
                     f"{p1:.3f} µm | {r['verdict']} / {word} |")
    return "\n".join(lines)


def test_verification_dt_table():
    """The dt table: the study's transient errors (docs/figures/study.json) beside the
    committed baseline's (tests/baselines/spl2782.json, which CI checks to 0.01 K)."""
    baseline = json.loads((ROOT / "tests" / "baselines" / "spl2782.json").read_text(
        encoding="utf-8"))
    assert_block("docs/verification.md", "dt-verdicts", dt_table(figures("study.json"), baseline))


P1_FIELDS = {"uniform": "uniform 10 K", "r_linear": "linear in r, 0-10 K",
             "r_quadratic": "quadratic in r, 0-10 K", "z_linear": "linear in z, 0-10 K",
             "nominal": "nominal steady field"}


def p1_ccx_text(p1: dict) -> str:
    ccx = p1["ccx"]
    lines = [f"({p1['spec']} level {p1['level']}, {ccx['solver']}; {made(p1)}, "
             "docs/figures/p1-fields.json)", "",
             "| field (rise) | reference P1 [µm] | CalculiX P1 [µm] | relative |",
             "|---|---|---|---|"]
    for r in ccx["rows"]:
        # five decimals of µm: ccx prints six significant digits; the relative difference to
        # two (it is 1e-7 to 1e-5, the quadrature difference and ccx's printing)
        rel = (r["ccx_um"] - r["reference_um"]) / r["reference_um"]
        lines.append(f"| {P1_FIELDS[r['field']]} | {r['reference_um']:.5f} | {r['ccx_um']:.5f}"
                     f" | {sci(rel)} |")
    return "\n".join(lines)


def p1_modulus_text(p1: dict) -> str:
    head = "| layer modulus | " + " | ".join(
        P1_FIELDS[f].split(",")[0].replace(" 10 K", "").replace(" steady field", "")
        for f in p1["fields"]) + " |"
    lines = [head, "|---|" + "---|" * len(p1["fields"])]
    spec_row = next(r for r in p1["moduli"] if r["factor"] == 1.0)
    for r in p1["moduli"]:
        label = f"×{r['factor']:g}" + (" (spec)" if r["factor"] == 1.0 else "")
        lines.append(f"| {label} | " + " | ".join(f"{r['P1_um'][f]:.4f}" for f in p1["fields"])
                     + " |")
    # P1 to 1e-4 µm (well inside the spread over the moduli); the span to 0.1 %
    rel = [100 * (r["P1_um"]["nominal"] / spec_row["P1_um"]["nominal"] - 1)
           for r in p1["moduli"]]
    return ("\n".join(lines) + f"\n\nAt the nominal field P1 spans {max(rel):+.1f} % to "
            f"{min(rel):+.1f} % over these moduli.")


def test_verification_quotes_the_p1_fields():
    p1 = figures("p1-fields.json")
    assert_block("docs/verification.md", "p1-ccx", p1_ccx_text(p1))
    assert_block("docs/verification.md", "p1-modulus", p1_modulus_text(p1))


def solver_notes(doc: dict) -> str:
    """CHOLMOD's and PARDISO's time and memory against SuperLU's, from
    docs/figures/solvers.json."""
    rows = {(r["matrix"], r["solver"]): r for r in doc["rows"] if r["installed"]}
    matrices = list(dict.fromkeys(r["matrix"] for r in doc["rows"]))
    largest = max(matrices, key=lambda m: next(r["n"] for r in doc["rows"] if r["matrix"] == m))
    v = doc["versions"]

    def faster(solver: str) -> list[str]:
        return [m for m in matrices if rows[(m, solver)]["factor_s"]
                < rows[(m, "superlu")]["factor_s"]]

    def where(names: list[str]) -> str:
        return ("every matrix" if len(names) == len(matrices) else
                "none" if not names else listed(names))

    fast = faster("cholmod")
    cholmod = (f"- **CHOLMOD** (scikit-sparse {v['scikit-sparse']}) factorises faster than "
               f"SuperLU on {where(fast)} and slower on "
               f"{where([m for m in matrices if m not in fast])}, and needs less memory, as a "
               f"Cholesky factor should ({rows[(largest, 'cholmod')]['peak_MB']} against "
               f"{rows[(largest, 'superlu')]['peak_MB']} MB on the largest).")
    # memory ratios to one decimal: the peaks are whole MB of a single measurement
    ratio = [rows[(m, "pardiso")]["peak_MB"] / rows[(m, "superlu")]["peak_MB"] for m in matrices]
    pardiso = (f"- **PARDISO** (pypardiso {v['pypardiso']} with MKL, both cores) is faster than "
               f"SuperLU on {where(faster('pardiso'))} and needs {min(ratio):.1f} to "
               f"{max(ratio):.1f} times SuperLU's memory.")
    return cholmod + "\n" + pardiso


def test_verification_solver_notes():
    assert_block("docs/verification.md", "solver-notes", solver_notes(figures("solvers.json")))


# ========================================================================== docs/rom.md
def rom_lumped_text(study: dict) -> str:
    steady = study["steady"]
    lumped = [m for m in steady["models"] if m["kind"] == "lumped"]
    eleven = next(m for m in lumped if m["preset"] == "paper11")
    best = min(lumped, key=lambda m: m["worst_K"])
    # one decimal, as the README prints the 11-node model's errors
    return (f"The lumped function-block models cannot meet the paper's tolerances on "
            f"{study['spec']}: at the nominal point the 11-node model is "
            f"{eleven['worst_K']:.1f} K / {eleven['P1_um']:.1f} µm off, and adding nodes levels "
            f"off at a model-form floor: no lumped model comes closer than "
            f"{best['worst_K']:.1f} K ({best['model']}; docs/figures/study.json, "
            "[harness.md](harness.md)).")


def rom_run_text(rom: dict) -> str:
    tr, tm, tol = rom["training"], rom["timings_s"], rom["tolerances"]
    run = rom["timing"]
    lines = [f"`{rom['command']}` ({made(rom)}; docs/figures/rom.json"
             + (f", load average {run['load_average']:.1f} on 2 cores" if run else "") + "):",
             "", "| cycle | kind | worst sensor error K | P1 µm | TCP µm | FEM run s | "
             "ROM run s | estimated K |", "|---|---|---:|---:|---:|---:|---:|---:|"]
    e = tr["errors"][-1]
    # errors to 1e-4 (the targets are 0.05 K and 0.1 µm); FEM runtimes to 0.1 s, the ROM's
    # to the millisecond (they are tens of ms)
    lines.append(f"| {tr['case']} (training) | transient | {e['temperature_max_K']:.4f} | "
                 f"{e['P1_max_um']:.4f} | {e['TCP_max_um']:.4f} | {tm['fem_training']:.1f} | | |")
    for h in rom["held_out"]:
        er = h["errors"]
        est = (h.get("error_estimate") or {}).get("estimated_max_K")
        lines.append(f"| {h['case']} | {h['kind']} | {er['temperature_max_K']:.4f} | "
                     f"{er['P1_max_um']:.4f} | {er['TCP_max_um']:.4f} | {h['fem_runtime_s']:.1f}"
                     f" | {h['rom_runtime_s']:.3f} | {'' if est is None else f'{est:.4f}'} |")
    tried = [f"{r}: {x['temperature_max_K']:.2g} K" for r, x in zip(tr["sizes"], tr["errors"],
                                                                     strict=True)]
    tried[-1] = f"**{tried[-1]}**" + (" (chosen)" if tr["chosen"] is not None else " (none met)")
    safety = tol["training_safety_factor"]
    lines += ["", f"Transients at dt = {tr['dt_s']:g} s, errors as the maximum over time and over "
              "every sensor (the 11 shaft and 11 housing array sensors, T1, T2) or growth "
              f"reading. The candidate space: {tr['candidates']} independent directions from "
              f"{len(tr['speeds_rpm'])} speeds and {len(tr['shifts_per_s'])} shifts. Size choice "
              f"on the training cycle (tolerances / {safety:g} = "
              f"{tol['temperature_K'] / safety:g} K, {tol['growth_um'] / safety:g} µm): r = "
              + "; ".join(tried) + " (`rom_size.png`). Build "
              f"{tm['build_total_excluding_fem']:.0f} s wall without the training FEM run "
              f"(candidate vectors {tm['candidates']:.0f} s: "
              f"{len(tr['speeds_rpm']) * len(tr['shifts_per_s'])} sparse LUs of "
              f"{thousands(rom['fem_unknowns'])} unknowns; indicator "
              f"{tm.get('indicator', 0.0):.0f} s; POD and size choice "
              f"{tm['pod'] + tm['size_choice']:.1f} s), the training FEM run "
              f"{tm['fem_training']:.0f} s"
              + (f"; the whole command {run['wall_s']:.0f} s wall with the held-out FEM runs, "
                 f"peak memory {run['peak_MB']} MB (`/usr/bin/time -v`)." if run else ".")]
    held = rom["held_out"]
    tcp = all(h["errors"]["TCP_max_um"] <= tol["growth_um"] for h in held)
    lines += ["", f"Every held-out error is {'below' if rom['meets_tolerances_on_held_out'] else 'NOT below'}"
              f" the targets (≤ {tol['temperature_K']:g} K at every sensor, ≤ "
              f"{tol['growth_um']:g} µm on P1) with **{rom['states']} states**"
              + ("; TCP too." if tcp else "; TCP is not.")]
    return "\n".join(lines)


def rom_indicator_text(rom: dict) -> str:
    ratios = []
    for h in rom["held_out"]:
        est = (h.get("error_estimate") or {}).get("estimated_max_K")
        if est:
            true = h["errors"]["temperature_max_K"]
            ratios.append(max(est / true, true / est))
    # one decimal: the doc compares it with the test's factor of 10
    return (f"On {rom['spec']} level {rom['fem_level']} (table above) the estimate is within a "
            f"factor {max(ratios):.1f} of the true worst sensor error on the held-out cycles; "
            "the test checks a factor 10 and that the bound grows as r shrinks.")


def rom_speed_text(sp: dict) -> str:
    tm, tg = sp["timings_s"], sp["targets"]
    build, fem = tm["build_total_excluding_fem"], tm["fem_training"]

    def met(value: float, target: float) -> str:
        return "met" if value <= target else "missed"

    step, cycle, c = sp["step"], sp["cycle"], sp["c_step"]
    # timings as bench_rom.py prints them: s and ms to 0.1, µs to 0.01, ns whole
    lines = [f"`{sp['made_by']}` ({sp['date']}, commit {sp['commit']}, load average "
             f"{sp['load_average']:.1f} on {sp['cores']} cores; docs/figures/rom-speed.json): "
             f"{sp['spec']} level {sp['level']}, {thousands(sp['dofs'])} DOFs to {sp['states']} "
             "states.", "",
             f"- **Build ≤ {tg['build_s']:g} s**: {met(build, tg['build_s'])}, {build:.1f} s wall "
             f"({tm['build_cpu_excluding_fem']:.1f} s CPU) without the training FEM run, "
             f"{build + fem:.1f} s with it (the size choice needs it).",
             f"- **Streaming step ≤ {tg['step_us']:g} µs**: {met(step['wall_us'], tg['step_us'])}, "
             f"{step['wall_us']:.2f} µs wall, {step['cpu_us']:.2f} µs CPU (one "
             f"{step['matrix'][0]} × {step['matrix'][1]} matrix-vector product: the fused step "
             "and read-out on [z, u, 1]).",
             f"- **16 h at 1 s ≤ {tg['cycle_ms']:g} ms**: {met(cycle['wall_ms'], tg['cycle_ms'])} "
             f"in wall time ({cycle['wall_ms']:.1f} ms), {met(cycle['cpu_ms'], tg['cycle_ms'])} in "
             f"CPU time ({cycle['cpu_ms']:.1f} ms); {tg['simulink_s'] / cycle['wall_ms'] * 1e3:.0f}"
             f" times faster than the paper's {tg['simulink_s']:g} s Simulink run."]
    if c:
        lines.append(f"- **C step**: {c['ns']:.0f} ns per sample (CPU time, gcc -O2, no "
                     f"vectorisation flags), {c['cycle_ms']:.1f} ms for the 16 h cycle at 1 s.")
    return "\n".join(lines)


def rom_sensors_text(sensors: dict, rom: dict) -> str:
    n = sensors["nodes"]
    tol = n["tolerances"]
    return (f"`spindle-verify sensors {sensors['spec']} --rom` ({made(sensors)}, "
            f"docs/figures/sensors.json): {n['message']}.\n\n"
            f"The ROM is sized for the tolerances given (here {tol['temperature_K']:g} K / "
            f"{tol['growth_um']:g} µm, so {n['rom']['states']} states suffice; the "
            f"{rom['tolerances']['temperature_K']:g} K / "
            f"{rom['tolerances']['growth_um']:g} µm of the `rom` command need {rom['states']}). "
            "`nodes.json` has it under `\"rom\"`; the node table is in "
            "[sensors.md](sensors.md#node-count).")


def test_rom_md_quotes_its_figures():
    """docs/rom.md: the lumped models' floor (docs/figures/study.json), the run of record
    (docs/figures/rom.json), the indicator's factor, bench_rom's speed
    (docs/figures/rom-speed.json) and sensors --rom (docs/figures/sensors.json)."""
    rom = figures("rom.json")
    assert_block("docs/rom.md", "rom-lumped", rom_lumped_text(figures("study.json")))
    assert_block("docs/rom.md", "rom-run", rom_run_text(rom))
    assert_block("docs/rom.md", "rom-indicator", rom_indicator_text(rom))
    assert_block("docs/rom.md", "rom-speed", rom_speed_text(figures("rom-speed.json")))
    assert_block("docs/rom.md", "rom-sensors", rom_sensors_text(figures("sensors.json"), rom))


def test_rom_md_states_no_test_counts():
    """How many tests and how long they take is not a user's figure (and went stale)."""
    assert not re.search(r"\d+ fast tests", doc_text("docs/rom.md"))


# ====================================================================== docs/sensors.md
def sensors_nodes_text(sensors: dict) -> str:
    n = sensors["nodes"]
    cases = n["cases"]
    head = "| N | masses | " + " | ".join(f"{c['case']}: worst T err K | {c['case']}: P1 err µm"
                                        for c in cases) + " |"
    lines = [f"From {made(sensors)} (docs/figures/sensors.json). Reference: "
             + "; ".join(f"{c['case']}, {c['reference']}" for c in cases) + ".", "", head,
             "|---:|---:|" + "---:|---:|" * len(cases)]
    for i, N in enumerate(n["nodes"]):
        # two decimals, against tolerances of 1 K and 1.5 µm
        lines.append(f"| {N} | {n['masses'][i]} | " + " | ".join(
            f"{c['worst_err_K'][i]:.2f} | {c['err_P1_um'][i]:.2f}" for c in cases) + " |")
    tol = n["tolerances"]
    best = n["best"]
    lines.append("")
    if n["chosen_nodes"] is None:
        lines.append(f"- **At the paper's tolerances ({tol['temperature_K']:g} K, "
                     f"{tol['growth_um']:g} µm) no N qualifies on every case.** The command says "
                     "so, per case which N meets them alone, and recommends, if a lumped model "
                     f"must serve, the N with the smallest worst error relative to the tolerances "
                     f"(N = {best['nodes']}, {best['worst_err_K']:.3g} K / "
                     f"{best['err_P1_um']:.3g} µm in this run), knowing it misses them.")
    else:
        lines.append(f"- **At the paper's tolerances N = {n['chosen_nodes']} qualifies** on "
                     "every case.")
    floors = [f"{min(c['worst_err_K']):.2g} K on {c['case']}" for c in cases]
    lines.append("- **The cause is a model-form floor.** The lumped models converge with N to "
                 f"their own limit: no N comes closer than {listed(floors)}.")
    lines += ["- **Looser tolerances** (from `choice.choose(tol_temp, tol_growth)`, the same "
              "run):", "", "  | tol_temp K | tol_growth µm | chosen N |", "  |---:|---:|---:|"]
    for c in n["choose"]:
        lines.append(f"  | {c['temperature_K']:g} | {c['growth_um']:g} | "
                     f"{'none' if c['chosen'] is None else c['chosen']} |")
    p1 = cases[0]["err_P1_um"]
    up = next((j for j in range(1, len(p1)) if p1[j] > p1[j - 1]), None)
    if up is not None:
        lines += ["", f"- **The P1 error does not fall monotonically with N** ({cases[0]['case']}:"
                  f" {p1[up - 1]:.2f} µm at N = {n['nodes'][up - 1]}, {p1[up]:.2f} µm at N = "
                  f"{n['nodes'][up]}). Coarse models can match P1 through cancelling errors. "
                  "This is why the choice requires both tolerances on every case."]
    return "\n".join(lines)


def ranking_table(sensors: dict, label: str, ks=(1, 3, 5)) -> str:
    lines = ["| method | top 5 (in order) | k | shaft err K | P1 err µm |",
             "|---|---|---:|---:|---:|"]
    for method in ("greedy", "qr"):
        r = sensors["rankings"][f"{label}_{method}"]
        t = r["table"]
        for j, k in enumerate(ks):
            i = k - 1
            first = (f"| {method} | {', '.join(r['selected'][:5])} |" if j == 0 else "| | |")
            # three significant digits, trailing zeros kept ("#"): errors of 0.05-2 K
            lines.append(f"{first} {k} | {t['err_shaft_rms_K'][i]:#.3g} / "
                         f"{t['err_shaft_max_K'][i]:#.3g} | {t['err_P1_rms_um'][i]:#.3g} / "
                         f"{t['err_P1_max_um'][i]:#.3g} |")
    return "\n".join(lines)


def ranking_caption(sensors: dict) -> str:
    r = sensors["rankings"]["all_greedy"]
    return (f"From {made(sensors)} (docs/figures/sensors.json): spl-16h, {r['reference']}; "
            f"{r['fit']}. Each cell gives RMS / max.")


def ranking_findings(sensors: dict) -> str:
    g = sensors["rankings"]["all_greedy"]["table"]
    q = sensors["rankings"]["all_qr"]["table"]
    s = sensors["rankings"]["stationary_greedy"]["table"]
    rms = s["err_shaft_rms_K"]
    low = int(np.argmin(rms[:8]))
    high = low + 1 + int(np.argmax(rms[low + 1:])) if low + 1 < len(rms) else low
    grows = (f"with the stationary candidates it goes from {rms[low]:#.2g} K at k = {low + 1} to "
             f"{rms[high]:#.2g} K at k = {high + 1}" if rms[high] > rms[low]
             else "here it does not")
    return "\n".join([
        f"- **One sensor** (greedy, all candidates) reconstructs the shaft sensors to "
        f"{g['err_shaft_rms_K'][0]:#.2g} K RMS and P1 to {g['err_P1_rms_um'][0]:#.2g} µm RMS; "
        f"three to {g['err_shaft_rms_K'][2]:#.2g} K RMS (max {g['err_shaft_max_K'][2]:#.2g} K) "
        f"and {g['err_P1_rms_um'][2]:#.2g} µm RMS (max {g['err_P1_max_um'][2]:#.2g} µm); of the "
        f"stationary sensors, three reach {s['err_shaft_rms_K'][2]:#.2g} K RMS and "
        f"{s['err_P1_rms_um'][2]:#.2g} µm RMS.",
        f"- **QR picks for independence in the snapshot space, not for the targets**: at "
        f"k = 3 its shaft error is {q['err_shaft_rms_K'][2]:#.2g} K RMS against greedy's "
        f"{g['err_shaft_rms_K'][2]:#.2g} K.",
        f"- **Greedy minimises the training residual only**: its training error never grows "
        f"with k (a test checks this), but the validation error can: {grows}. Choose k from "
        "the validation columns."])


def test_sensors_md_quotes_its_figures():
    """docs/sensors.md's node table, its conclusions and the rankings are those of
    docs/figures/sensors.json (benchmarks/sensors_figures.py)."""
    s = figures("sensors.json")
    assert_block("docs/sensors.md", "sensors-nodes", sensors_nodes_text(s))
    assert_block("docs/sensors.md", "sensors-ranking-caption", ranking_caption(s))
    assert_block("docs/sensors.md", "sensors-ranking-all", ranking_table(s, "all"))
    assert_block("docs/sensors.md", "sensors-ranking-stationary", ranking_table(s, "stationary"))
    assert_block("docs/sensors.md", "sensors-ranking-findings", ranking_findings(s))
    # the candidate counts the prose names
    text = doc_text("docs/sensors.md")
    n_all = len(s["rankings"]["all_greedy"]["candidates"])
    n_stat = len(s["rankings"]["stationary_greedy"]["candidates"])
    assert f"({n_all} on spl2782)" in text and f"All {n_all} temperature sensors" in text
    assert f"; {n_stat} candidates)" in text


def test_sensors_md_points_to_rom_md_for_the_rom():
    """The ROM's figures are rom.md's; sensors.md only points there."""
    tail = doc_text("docs/sensors.md").split("## A model that meets the tolerances")[1]
    assert "rom.md" in tail and not re.search(r"\d\.\d+ K", tail)


# =================================================================== docs/crosscheck.md
def crosscheck_text(cc: dict) -> str:
    runs = cc["runs"]
    first = {r["spec"]: r for r in reversed(runs)}
    fin, spl = first["fin-shaft"], first["spl2782"]
    floor = max(r["nodal"]["max_print_bound_K"] for r in runs)
    lines = [f"Steady, the spec's own operating point (`spec.default_load_case()`: fin-shaft "
             f"{fin['heat_W']:.0f} W at standstill; spl2782 at {spl['speed_rpm']:g} rpm with "
             f"{spl['heat_W']:.0f} W), P2, {runs[0]['solver']} ({made(cc)}, "
             "docs/figures/crosscheck.json). Temperatures in K, readings in µm.", "",
             "| spec, level | nodes | max \\|ΔT\\| sensors (ref − ccx) | max \\|ΔT\\| nodes "
             "(ref − ccx) | max \\|ref − twin\\| nodes | max \\|ccx − twin\\| nodes (print ≤ "
             f"{sci(floor, 1)}) |", "|---|---:|---:|---:|---:|---:|"]
    for r in runs:
        nd = r["nodal"]
        lines.append(f"| {r['spec']} {r['level']} | {thousands(r['nodes'])} | "
                     f"{sci(r['sensors_max_abs_diff_K'])} | {sci(nd['max_abs_diff_K'], 3)} | "
                     f"{sci(nd['max_abs_skfem_minus_twin_K'], 3)} | "
                     f"{sci(nd['max_abs_ccx_minus_twin_K'])} |")

    def factor(spec: str) -> tuple[float, int]:
        # per-level factor of the reference - twin difference over the levels where it stands
        # clear of the print floor (twice the print bound: below, rounding takes over)
        d = [r["nodal"]["max_abs_skfem_minus_twin_K"] for r in runs if r["spec"] == spec]
        k = max(i for i, v in enumerate(d) if v > 2 * floor)
        return (d[0] / d[k]) ** (1 / k), k

    (f_fin, k_fin), (f_spl, k_spl) = factor("fin-shaft"), factor("spl2782")
    # differences to two or three digits: they are 1e-5 to 1e-2 K, above ccx's print floor
    # (5e-4 K) except where the doc says they reach it
    rises = sorted(r["nodal"]["max_rise_K"] for r in runs)
    spl_twin = max(r["sensors_max_abs_ccx_minus_twin_K"] for r in runs if r["spec"] == "spl2782")
    lines += ["", "The reference − ccx difference is the quadrature difference: it equals "
              "reference − twin to the print floor, and ccx equals the twin to it (the last "
              f"column). It falls by a factor of "
              f"{f_fin:.1f} (fin-shaft, levels 0-{k_fin}) and {f_spl:.1f} (spl2782, with the "
              f"contact joints, levels 0-{k_spl}) per level, until it reaches the print floor of "
              f"{sci(floor, 1)} K on rises of {rises[0]:.0f}-{rises[-1]:.0f} K. At the spl2782 "
              f"sensors, ccx − twin stays below {sci(spl_twin, 1)} K."]
    return "\n".join(lines)


def crosscheck_growth_text(cc: dict) -> str:
    spl = [r for r in cc["runs"] if r["spec"] == "spl2782"]
    lines = ["| spl2782 | P1 ref | P1 ccx | ΔP1 | TCP ref | TCP ccx | ΔTCP | ccx − twin "
             "(ccx T) P1 / TCP, print bound |", "|---|---:|---:|---:|---:|---:|---:|---|"]
    for r in spl:
        p, t = r["growth"]["P1"], r["growth"]["TCP"]
        bound = max(p["print_bound_um"], t["print_bound_um"])
        lines.append(f"| level {r['level']} | {p['skfem_um']:.6f} | {p['ccx_um']:.6f} | "
                     f"{sci(p['diff_um'])} | {t['skfem_um']:.6f} | {t['ccx_um']:.6f} | "
                     f"{sci(t['diff_um'])} | {sci(p['ccx_minus_twin_ccxT_um'])} / "
                     f"{sci(t['ccx_minus_twin_ccxT_um'])}, {sci(bound, 1)} |")
    d = [max(abs(r["growth"][k]["diff_um"]) for k in ("P1", "TCP")) for r in spl]
    nom = cc["nominal"]
    lines += ["", f"The largest of ΔP1 and ΔTCP falls from {sci(d[0])} µm at level "
              f"{spl[0]['level']} to {sci(d[-1])} µm at level {spl[-1]['level']}, against "
              "ccx's print bound of the displacements above. `--case nominal` "
              f"({nom['heat_W']:.0f} W at {nom['speed_rpm']:g} rpm from the power balance) "
              f"behaves the same at level {nom['level']}: |ΔT| ≤ "
              f"{sci(nom['sensors_max_abs_diff_K'])} K at the sensors, ΔP1 = "
              f"{sci(nom['growth']['P1']['diff_um'])} µm."]
    one = next(r for r in spl if r["level"] == 1)
    two = next(r for r in spl if r["level"] == 2)
    tm = one["timings_s"]
    lines += ["", f"Run times (the run above, 2 threads): spl2782 level 1 takes "
              f"{one['wall_s']:.1f} s in all (reference {tm['reference_s']:.1f} s, ccx heat "
              f"{tm['ccx_thermal_s']:.1f} s, ccx elastic {tm['ccx_elastic_s']:.1f} s, twin "
              f"{tm['twin_s']:.1f} s); level 2 takes {two['wall_s']:.0f} s."]
    return "\n".join(lines)


def test_crosscheck_md_quotes_its_figures():
    cc = figures("crosscheck.json")
    assert_block("docs/crosscheck.md", "crosscheck-agreement", crosscheck_text(cc))
    assert_block("docs/crosscheck.md", "crosscheck-growth", crosscheck_growth_text(cc))


def test_crosscheck_md_has_no_hand_counts():
    """A count of ccx's contact elements (from its log, not in crosscheck.json) went stale."""
    assert "contact elements on" not in doc_text("docs/crosscheck.md")


# ===================================================================== docs/commands.md
def test_commands_md_points_to_the_figures_instead_of_repeating_them():
    """commands.md's cross-check sentence and its list of what is verified point to
    crosscheck.md and verification.md, whose figures are checked above; they quote no
    measured figure of their own (one left here would go stale unchecked)."""
    text = doc_text("docs/commands.md")
    verified = text.split("## What is verified")[1].split("\n## ")[0]
    cross = text.split("`crosscheck` needs CalculiX")[1].split("\n\n")[0]
    for part in (verified, cross):
        assert not re.search(r"\d\.\d+e-\d|\b\d\.\d\d\b", part), part
    assert "verification.md" in verified and "crosscheck.md" in cross


def test_history_blocks_are_dated():
    """Every history block of these docs names its date and commit (it records what was
    measured once, and is not checked)."""
    for doc in ("docs/harness.md", "docs/verification.md", "docs/rom.md", "docs/sensors.md",
                "docs/crosscheck.md"):
        for m in re.finditer(r"<!-- history:begin -->\n(.*?)<!-- history:end -->",
                             doc_text(doc), re.S):
            assert re.search(r"\d{4}-\d\d-\d\d", m.group(1)), (doc, m.group(1)[:80])
            assert re.search(r"commits? [0-9a-f]{7}", m.group(1)), (doc, m.group(1)[:80])


def test_block_reader_finds_every_block():
    """Every block name a test above asserts exists in its doc (a renamed marker fails
    loudly there too; this lists them in one place)."""
    names = {"docs/harness.md": ["harness-ground-truth", "harness-convergence", "harness-eq14",
                                 "harness-steady", "harness-transient"],
             "docs/verification.md": ["mms", "fin-biot", "gps-p1", "p1-ccx", "p1-modulus",
                                      "time-order", "be-limit", "krylov-cram-fin",
                                      "krylov-cram-spl2782", "krylov-study", "dt-verdicts",
                                      "solver-notes"],
             "docs/rom.md": ["rom-lumped", "rom-run", "rom-indicator", "rom-speed",
                             "rom-sensors"],
             "docs/sensors.md": ["sensors-nodes", "sensors-ranking-caption",
                                 "sensors-ranking-all", "sensors-ranking-stationary",
                                 "sensors-ranking-findings"],
             "docs/crosscheck.md": ["crosscheck-agreement", "crosscheck-growth"]}
    for doc, blocks in names.items():
        for name in blocks:
            assert block(doc, name).strip(), (doc, name)


def test_sci_writes_short_exponents():
    assert sci(1.44e-6) == "1.4e-6" and sci(9.1e-6, 1) == "9e-6" and sci(-5.5e-5) == "-5.5e-5"
