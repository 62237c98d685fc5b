"""What docs/measures.md quotes of ``spindle-verify measures spl2782``: the shipped measures,
their inverse problems and sweeps on FEM level 1, the same measures and inverse problems on
level 2, and the time the command takes.

    python benchmarks/measures_figures.py [SPEC] [--out docs/figures/measures.json]

Both runs go through the command in a fresh process, into a temporary folder; the level-1
run is the command as a user runs it (pictures included) and its wall time is recorded. The
tables of each run's measures.json go to ``--out`` (JSON with the date, the commit and the
load average), from which docs/measures.md's blocks are checked (tests/test_docs_figures.py).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]
#: the tables of measures.json the docs quote, per run
TABLES = ("indicators", "surfaces", "measures", "inverse", "sweeps")


def run(argv: list[str], folder: Path) -> dict:
    """One ``spindle-verify`` command into ``folder``: its measures.json tables and wall
    time [s]; a failed command ends the script with its message and exit status 2."""
    cmd = [sys.executable, "-c", "from compare.entry import main; raise SystemExit(main())",
           *argv, "--out", str(folder), "--quiet"]
    t = time.perf_counter()
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    wall = time.perf_counter() - t
    if done.returncode != 0:
        print(f"error: spindle-verify {' '.join(argv)} failed (exit {done.returncode}): "
              f"{done.stderr.strip()[-500:]}", file=sys.stderr)
        sys.exit(2)
    doc = json.loads((folder / "measures.json").read_text(encoding="utf-8"))
    cases = len(doc["measures"]) + len(doc["inverse"]) + len(doc["sweeps"])
    return {"command": "spindle-verify " + " ".join(argv), "wall_s": round(wall, 1),
            "cases": cases, "fem_level": doc["fem_level"], "speed_rpm": doc["speed_rpm"],
            "sum_alpha_A_W_K": doc["sum_alpha_A_W_K"], **{k: doc[k] for k in TABLES}}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec", nargs="?", default="spl2782")
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "measures.json")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        level1 = run(["measures", args.spec], Path(tmp) / "level1")
        load = round(os.getloadavg()[0], 1)  # how busy the cores were for level 1's time
        print(f"level 1: {level1['cases']} cases in {level1['wall_s']:.1f} s", flush=True)
        level2 = run(["measures", args.spec, "--level", "2", "--no-sweeps", "--no-pictures"],
                     Path(tmp) / "level2")
        print(f"level 2 (no sweeps): {level2['cases']} cases in {level2['wall_s']:.1f} s")
    write_figures(args.out, " ".join(["python benchmarks/measures_figures.py",
                            *(argv if argv is not None else sys.argv[1:])]),
                  {"spec": args.spec, "cores": os.cpu_count(), "load_average": load,
                   "level1": level1, "level2": level2})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
