"""The README's main job, measured: wall time, CPU time and peak memory of
``spindle-verify study spl2782`` and of ``spindle-verify check`` on the committed baseline.

    python benchmarks/bench_main_job.py [--out docs/figures/main-job.json]

Each command runs under ``/usr/bin/time -v`` in a fresh process, into a temporary folder.
The figures go to ``--out`` (JSON, with the date and the commit), from which the README
quotes them (tests/test_docs_snippets.py checks that it does, so they cannot go stale).
Run it on an otherwise idle machine: the figures are the wall time a user waits.
"""

from __future__ import annotations

import argparse
import json
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
    args = ap.parse_args(argv)
    rows = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name, cmd in COMMANDS.items():
            rows[name] = measure([c.format(tmp=tmp) for c in cmd])
            r = rows[name]
            print(f"{name:>6}: {r['wall_s']:.0f} s wall, {r['cpu_s']:.0f} s CPU, "
                  f"{r['peak_MB']} MB peak   ({r['command']})", flush=True)
        study = json.loads((Path(tmp) / "study" / "study.json").read_text(encoding="utf-8"))
    rows["findings"] = findings(study)
    write_figures(args.out, "python benchmarks/bench_main_job.py", rows)


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
