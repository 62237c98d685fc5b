"""The README's main job, measured: wall time, CPU time and peak memory of
``spindle-verify study spl2782`` and of ``spindle-verify check`` on the committed baseline;
and what the docs quote of that study.

    python benchmarks/bench_main_job.py [--out docs/figures/main-job.json]
                                        [--study-out docs/figures/study.json] [--study-only]

Each command runs under ``/usr/bin/time -v`` in a fresh process, into a temporary folder.
The timings and the study's findings go to ``--out`` (JSON, with the date and the commit),
from which the README quotes them (tests/test_docs_snippets.py checks that it does, so they
cannot go stale). The same study's tables and figures (its own Markdown tables, the worst
GCI per level, the observed orders, the temporal error, each model's errors and verdict)
go to ``--study-out``, from which docs/harness.md and docs/verification.md quote them
(tests/test_docs_study_figures.py). ``--study-only`` runs the study alone and writes only
``--study-out``, leaving the README's timings as they are (for a machine that is not idle).
Run it on an otherwise idle machine: the figures are the wall time a user waits.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]

COMMANDS = {
    "study": ["spindle-verify", "study", "spl2782", "--out", "{tmp}/study"],
    "check": ["spindle-verify", "check", "tests/baselines/spl2782.json", "--quiet"],
}


def measure(argv: list[str]) -> dict:
    """Wall [s], CPU [s] and peak resident memory [MB] of one command."""
    if not Path("/usr/bin/time").is_file():
        print("error: /usr/bin/time not found; install GNU time (apt-get install time)",
              file=sys.stderr)
        sys.exit(2)
    run = subprocess.run(["/usr/bin/time", "-v", *argv], cwd=ROOT, capture_output=True,
                         text=True)
    if run.returncode != 0:
        sys.exit(f"{' '.join(argv)} failed ({run.returncode}):\n{run.stderr[-2000:]}")
    err = run.stderr

    def field(name: str) -> str:
        return re.search(rf"{re.escape(name)}: (.+)", err).group(1).strip()

    parts = [float(x) for x in field("Elapsed (wall clock) time (h:mm:ss or m:ss)").split(":")]
    wall = sum(p * 60 ** i for i, p in enumerate(reversed(parts)))
    cpu = float(field("User time (seconds)")) + float(field("System time (seconds)"))
    return {"command": " ".join(argv), "wall_s": round(wall, 1), "cpu_s": round(cpu, 1),
            "peak_MB": round(int(field("Maximum resident set size (kbytes)")) / 1024)}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "main-job.json")
    ap.add_argument("--study-out", type=Path, default=ROOT / "docs" / "figures" / "study.json")
    ap.add_argument("--study-only", action="store_true",
                    help="run only the study and write only --study-out")
    args = ap.parse_args(argv)
    rows = {}
    commands = {"study": COMMANDS["study"]} if args.study_only else COMMANDS
    with tempfile.TemporaryDirectory() as tmp:
        for name, cmd in commands.items():
            rows[name] = measure([c.format(tmp=tmp) for c in cmd])
            r = rows[name]
            print(f"{name:>6}: {r['wall_s']:.0f} s wall, {r['cpu_s']:.0f} s CPU, "
                  f"{r['peak_MB']} MB peak   ({r['command']})", flush=True)
        # the 1-minute load average at the study's end: how busy the cores were for the
        # runtimes of the study's tables
        rows["study"]["load_average"] = round(os.getloadavg()[0], 1)
        folder = Path(tmp) / "study"
        study = read_json(folder / "study.json")
        rows["findings"] = findings(study)
        figures = study_figures(folder, study, rows["study"])
    if not args.study_only:
        write_figures(args.out, "python benchmarks/bench_main_job.py", rows)
    write_figures(args.study_out, "python benchmarks/bench_main_job.py"
                  + (" --study-only" if args.study_only else ""), figures)
    print(f"wrote {args.study_out}" + ("" if args.study_only else f" and {args.out}"))


def read_json(path: Path) -> dict:
    """A JSON file the study wrote; a missing one ends the script with one message and exit
    status 2 (the study's own messages are above it)."""
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        print(f"error: {path}: cannot be read ({exc}); the study did not write it",
              file=sys.stderr)
        sys.exit(2)


def study_figures(folder: Path, study: dict, timing: dict) -> dict:
    """What docs/harness.md and docs/verification.md quote of the study in ``folder``: its
    Markdown tables as written, the ground truth, the worst GCI per level, the observed order
    of every quantity on the finest triplet, the time integration record, each model's worst
    errors and verdict per case, and the README's findings (to check that both files agree)."""
    conv = read_json(folder / "convergence.json")
    t = conv["table"]
    out = {"study": timing, "spec": study["spec"], "runtime_s": round(study["runtime_s"], 1),
           "convergence": {
               "case": conv["case"], "levels": conv["levels"], "dofs": conv["dofs"],
               "ground_truth_level": conv["ground_truth_level"],
               "worst_GCI_pct_per_level": conv["worst_GCI_pct_per_level"],
               "flagged": conv["flagged"],
               "observed_order": {q: (None if p is None or math.isnan(p) else p)
                                  for q, p in zip(t["quantity"], t["p"], strict=True)},
               "markdown": (folder / "convergence.md").read_text(encoding="utf-8")},
           "time_integration": study["time_integration"]}
    for case in ("steady", "transient"):
        acc = study[case]
        if acc is None:
            continue
        out[case] = {"case": acc["case"], "reference": acc["reference"],
                     "markdown": (folder / f"accuracy_{case}.md").read_text(encoding="utf-8"),
                     "models": [{"model": r["model"], "preset": r["preset"], "kind": r["kind"],
                                 "unknowns": r["unknowns"], "worst_K": _worst(r),
                                 "P1_um": r.get("P1_max_um"), "verdict": _word(r)}
                                for r in acc["models"]]}
    out["findings"] = findings(study)
    return out


def _worst(row: dict) -> float | None:
    vals = [v for k, v in row.items() if k.endswith("_max_K") and v is not None]
    return max(vals) if vals else None


def findings(study: dict) -> dict:
    """What the README says the study finds, from the study's own study.json: the ground
    truth's worst GCI, the paper's 11-node model's errors and verdicts per case, the other
    lumped models that pass or are borderline over the cycle, and the temporal error."""
    conv = study["convergence"]
    gt = study["reference_level"]
    out = {"ground_truth_level": gt,
           "worst_GCI_pct": conv["worst_GCI_pct_per_level"][str(gt)],
           "time_error_K": study["time_integration"]["time_error_K"]}
    for case in ("steady", "transient"):
        rows = study[case]["models"]
        eleven = next(r for r in rows if r["preset"] == "paper11")
        out[case] = {
            "case": study[case]["case"],
            "paper11_worst_K": max(v for k, v in eleven.items()
                                   if k.endswith("_max_K") and v is not None),
            "paper11_P1_um": eleven["P1_max_um"],
            "paper11_verdict": _word(eleven),
            "lumped_passing": [r["model"] for r in rows if r["kind"] == "lumped"
                               and r["meets_tolerances"] and not r.get("borderline")],
            "lumped_borderline": [r["model"] for r in rows if r["kind"] == "lumped"
                                  and r.get("borderline")]}
    return out


def _word(row: dict) -> str:
    return "borderline" if row.get("borderline") else (
        "PASS" if row["meets_tolerances"] else "FAIL")

if __name__ == "__main__":
    main()
