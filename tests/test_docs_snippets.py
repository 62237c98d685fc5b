"""Every Python snippet in the docs runs (the rest of the API is in docs/examples/, run by
tests/test_examples.py)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def _snippets() -> list[tuple[str, str]]:
    out = []
    for md in sorted([ROOT / "README.md", *(ROOT / "docs").glob("*.md")]):
        for k, code in enumerate(BLOCK.findall(md.read_text(encoding="utf-8"))):
            out.append((f"{md.relative_to(ROOT)}#{k}", code))
    return out


SNIPPETS = _snippets()


def test_the_docs_have_snippets():
    """The reader below finds the docs' snippets (so the parametrised test is not empty)."""
    assert len(SNIPPETS) >= 3


@pytest.mark.parametrize("where,code", SNIPPETS, ids=[w for w, _ in SNIPPETS])
def test_snippet_runs(where, code, tmp_path, monkeypatch):
    if "crosscheck" in code and shutil.which("ccx") is None:
        pytest.skip("CalculiX (ccx) is not installed; apt-get install calculix-ccx")
    monkeypatch.chdir(tmp_path)  # snippets write to relative folders such as out/
    exec(compile(code, where, "exec"), {"__name__": "__snippet__"})


def test_the_readme_quotes_the_measured_main_job():
    """The README's time and memory of the main job are those of
    docs/figures/main-job.json (written by benchmarks/bench_main_job.py), not a hand copy
    that goes stale when the study changes."""
    import json

    doc = json.loads((ROOT / "docs" / "figures" / "main-job.json").read_text(encoding="utf-8"))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert main_job_figures(doc) in readme, main_job_figures(doc)


def main_job_figures(doc: dict) -> str:
    """The README's sentence on the main job's cost, from the measured figures."""
    s, c = doc["study"], doc["check"]
    peak = f"{s['peak_MB']:,}".replace(",", " ")
    return (f"{s['wall_s']:.0f} s wall, {s['cpu_s']:.0f} s of CPU and {peak} MB at its peak "
            f"(the regression check: {c['wall_s']:.0f} s), measured {doc['date']} at commit "
            f"{doc['commit']}")


def test_verification_quotes_the_measured_solvers():
    """docs/verification.md's table of sparse solvers is docs/figures/solvers.json's (written
    by benchmarks/bench_solvers.py), so it cannot go stale."""
    import json

    doc = json.loads((ROOT / "docs" / "figures" / "solvers.json").read_text(encoding="utf-8"))
    text = (ROOT / "docs" / "verification.md").read_text(encoding="utf-8")
    assert solver_table(doc) in text, solver_table(doc)


def solver_table(doc: dict) -> str:
    """The table of docs/verification.md from the benchmark's rows: one row per matrix, a
    column per solver with its factorisation time [s] and peak memory [MB]."""
    solvers = list(dict.fromkeys(r["solver"] for r in doc["rows"]))
    matrices = list(dict.fromkeys(r["matrix"] for r in doc["rows"]))
    cell = {(r["matrix"], r["solver"]): r for r in doc["rows"]}
    lines = ["| matrix | unknowns | " + " | ".join(solvers) + " |",
             "|---|---:|" + "---:|" * len(solvers)]
    for m in matrices:
        row = [m, f"{next(r['n'] for r in doc['rows'] if r['matrix'] == m):,}".replace(",", " ")]
        for s in solvers:
            r = cell[(m, s)]
            row.append(f"{r['factor_s']:.2f} s, {r['peak_MB']} MB" if r["installed"]
                       else "not installed")
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def study_findings(doc: dict) -> str:
    """The README's "What it finds" bullets, from docs/figures/main-job.json's ``findings``
    (benchmarks/bench_main_job.py reads them from the study's own study.json)."""
    f = doc["findings"]
    s, t = f["steady"], f["transient"]

    def verdict(case: dict) -> str:
        return {"PASS": "meets both tolerances", "FAIL": "fails",
                "borderline": "is borderline (within the reference's uncertainty)"}[
            case["paper11_verdict"]]

    def listed(names: list[str]) -> str:
        return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]

    def others(case: dict) -> str:
        passing, edge = case["lumped_passing"], case["lumped_borderline"]
        parts = []
        if passing:
            parts.append(f"{listed(passing)} meet{'s' if len(passing) == 1 else ''} both "
                         "tolerances")
        if edge:
            parts.append(f"{listed(edge)} {'is' if len(edge) == 1 else 'are'} borderline "
                         "(within the reference's uncertainty of a tolerance)")
        return "; ".join(parts) if parts else "no lumped model meets both tolerances"

    return "\n".join([
        f"- **FEM reference.** Ground truth at level {f['ground_truth_level']}, worst grid "
        f"convergence index {f['worst_GCI_pct']:.2g} %; the transient's temporal error "
        f"{f['time_error_K']:.1g} K.",
        f"- **The paper's 11-node model**, at the nominal point (`{s['case']}`): "
        f"{s['paper11_worst_K']:.1f} K and {s['paper11_P1_um']:.1f} µm off; it "
        f"{verdict(s)}. Over the cycle (`{t['case']}`): {t['paper11_worst_K']:.1f} K and "
        f"{t['paper11_P1_um']:.1f} µm; it {verdict(t)}.",
        f"- **More nodes.** At the nominal point {others(s)}: the error stops falling at the "
        f"model-form floor of one temperature per slice. Over the cycle, {others(t)}."])


def test_the_readme_quotes_the_study_findings():
    """The README's findings are those of the study in docs/figures/main-job.json, so a
    changed result breaks this test instead of leaving stale text."""
    import json

    doc = json.loads((ROOT / "docs" / "figures" / "main-job.json").read_text(encoding="utf-8"))
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    assert study_findings(doc) in readme, study_findings(doc)


def test_the_readme_is_short():
    """The README is for users: what the tool is for, the two commands, what it finds, the
    commands and where to read more; method and history live in docs/ (issue 34)."""
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 150


def reference_speed_text(doc: dict) -> str:
    """docs/commands.md's speed table of the reference and its cycle sentence, from
    docs/figures/reference-speed.json (benchmarks/bench_reference.py)."""
    def n(v: int) -> str:
        return f"{v:,}".replace(",", " ")

    lines = ["| level | elements | DOFs (P2) | assembly s | factorisation s | steady solve s "
             "| step ms | peak MB |", "|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in doc["levels"]:
        lines.append(f"| {r['level']} | {n(r['elements'])} | {n(r['dofs'])} | "
                     f"{r['assembly_s']:.2g} | {r['factorisation_s']:.2g} | "
                     f"{r['steady_solve_s']:.2g} | {r['step_s'] * 1e3:.2g} | "
                     f"{r['peak_MB']:.0f} |")
    c, big = doc["cycle"], doc["levels"][-1]
    lines += ["", f"Steady solve at {n(big['dofs'])} DOFs: **{big['steady_solve_s']:.2f} s** "
              f"(target ≤ 1 s). 16 h cycle at 60 s steps on level {c['level']} "
              f"({c['steps']} steps), with the thermoelastic growth at every step: "
              f"**{c['cycle_s']:.1f} s + {c['setup_s']:.1f} s set-up** (target ≤ 30 s). "
              f"Measured {doc['date']} at commit {doc['commit']}."]
    return "\n".join(lines)


def test_commands_md_quotes_the_measured_reference_speed():
    """The speed table of docs/commands.md is docs/figures/reference-speed.json's."""
    import json

    doc = json.loads((ROOT / "docs" / "figures" / "reference-speed.json").read_text(
        encoding="utf-8"))
    text = (ROOT / "docs" / "commands.md").read_text(encoding="utf-8")
    assert reference_speed_text(doc) in text, reference_speed_text(doc)
