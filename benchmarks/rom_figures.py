"""The run of record of docs/rom.md: ``spindle-verify rom spl2782 --level 2`` with its wall
time, CPU time and peak memory, and what docs/rom.md quotes of its rom.json (the size, the
candidate directions, the size choice on the training cycle, the held-out errors with the
FEM and ROM runtimes and the error estimates, the build's timings).

    python benchmarks/rom_figures.py [--out docs/figures/rom.json] [--from DIR]

The command runs under ``/usr/bin/time -v`` in a fresh process, into a temporary folder
(about 3 minutes and 1 GB on 2 cores). ``--from DIR`` reads the rom.json of an earlier
``spindle-verify rom spl2782 --level 2 --out DIR`` instead (no timing then). The figures go
to ``--out`` with the date and the commit; tests/test_docs_study_figures.py checks that
docs/rom.md quotes them.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

from bench_main_job import measure
from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]
COMMAND = ["spindle-verify", "rom", "spl2782", "--level", "2", "--quiet", "--out", "{out}"]


def read_rom_json(folder: Path) -> dict:
    """The rom.json of a ``rom`` run's folder; a missing or broken one ends the script with
    one message and exit status 2."""
    path = Path(folder) / "rom.json"
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        print(f"error: {path}: cannot be read ({exc}); --from must name the --out folder of "
              "'spindle-verify rom spl2782 --level 2'", file=sys.stderr)
        sys.exit(2)


def quoted(rom: dict) -> dict:
    """What docs/rom.md quotes of a rom.json."""
    keep = ("spec", "fem_level", "fem_unknowns", "states", "tolerances", "training",
            "timings_s", "runtime_s", "held_out", "meets_tolerances_on_held_out")
    return {k: rom[k] for k in keep if k in rom}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "rom.json")
    ap.add_argument("--from", dest="folder", type=Path,
                    help="the folder of an earlier 'spindle-verify rom spl2782 --level 2' run")
    args = ap.parse_args(argv)
    command = " ".join(COMMAND).replace(" --quiet --out {out}", "")
    if args.folder is not None:
        fig = {"command": command, "timing": None, **quoted(read_rom_json(args.folder))}
    else:
        with tempfile.TemporaryDirectory() as tmp:
            out = Path(tmp) / "rom"
            timing = measure([c.format(out=out) for c in COMMAND])
            timing["command"] = command
            timing["load_average"] = round(os.getloadavg()[0], 1)
            fig = {"command": command, "timing": timing, **quoted(read_rom_json(out))}
            print(f"rom: {timing['wall_s']:.0f} s wall, {timing['cpu_s']:.0f} s CPU, "
                  f"{timing['peak_MB']} MB peak")
    write_figures(args.out, "python benchmarks/rom_figures.py"
                  + (f" --from {args.folder}" if args.folder else ""), fig)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
