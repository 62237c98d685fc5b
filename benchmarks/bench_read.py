"""Bench-export reading speed: ``read_bench`` on a 16 h run at 1 s, and the model inputs.

    python benchmarks/bench_read.py [--rows 57600] [--repeat 7] [--out docs/figures/bench-read.json]

Writes three versions of the same run into a temporary folder (10 columns: speed logged on
change, every 7th P1 cell empty, a numeric unknown column ``humidity_pct``): numbers only,
plus an unknown text column ``operator`` (both read by numpy's C parser), and the text
column quoted (read cell by cell by the ``csv`` module, the general path). Times
``read_bench`` on each (min and median of ``--repeat``), one evaluation of the power balance,
and ``inputs(run, spl2782)`` on the 60 s grid. The figures go to ``--out`` (JSON with the
date, the commit and the load average), from which docs/bench.md's table is checked
(tests/test_docs_figures.py). Run it on an idle machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]
HEAD = "# spindle: spl2782\ntime_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_C,T2_C,T_stator_C,P1_um"
#: the three files: name -> (extra header, text appended to every row)
FILES = {"numeric": (",humidity_pct", ""), "text": (",humidity_pct,operator", ",anna"),
         "quoted": (",humidity_pct,operator", ',"anna"')}


def rows(n: int) -> list[str]:
    """``n`` data rows at 1 s: 4300 rpm until 40 000 s, then standstill (speed logged on
    change), T1 and P1 drifting, every 7th P1 cell empty, humidity 45 %."""
    t = np.arange(n, dtype=float)
    speed = np.where(t < 40_000, 4300.0, 0.0)
    return [f"{t[i]:g},{'' if i and speed[i] == speed[i - 1] else f'{speed[i]:g}'},1.2,20.0,"
            f"20.0,{22 + i * 1e-4:.4f},21.5,30.0,{'' if i % 7 == 3 else f'{i * 2e-4:.4f}'},45"
            for i in range(n)]


def timed(fn, repeat: int) -> tuple[list[float], object]:
    """Seconds of ``repeat`` calls of ``fn`` and its last result."""
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return times, out


def main(argv: list[str] | None = None) -> None:
    from spindle.bench import read_bench
    from spindle.bench_inputs import inputs
    from spindle.drive import drive_for
    from spindle.spec_reader import load_spec

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=57_600, help="data rows (default: 16 h at 1 s)")
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "bench-read.json")
    args = ap.parse_args(argv)
    if args.rows < 3600 or args.repeat < 1:
        print("error: --rows must be at least 3600 (an hour) and --repeat at least 1",
              file=sys.stderr)
        sys.exit(2)
    data = rows(args.rows)
    spec = load_spec("spl2782")
    files = {}
    with tempfile.TemporaryDirectory() as d:
        for name, (extra, cell) in FILES.items():
            path = Path(d) / f"{name}.csv"
            path.write_text(f"{HEAD}{extra}\n" + "\n".join(r + cell for r in data) + "\n",
                            encoding="utf-8")
            times, run = timed(lambda p=path: read_bench(p), args.repeat)
            files[name] = {"rows": len(run.time_s), "columns": len(run.columns) + len(run.extra),
                           "MB": round(path.stat().st_size / 1e6, 2),
                           "min_s": min(times), "median_s": statistics.median(times)}
            print(f"{name}.csv: {len(run.time_s)} rows, read_bench min {min(times):.3f} s, "
                  f"median {statistics.median(times):.3f} s", flush=True)
    drive = drive_for(spec)
    times, _ = timed(lambda: drive.heat_W(4300.0, 0.0, 1.2), 2000)
    balance_us = statistics.median(times) * 1e6
    times, (case, grid) = timed(lambda: inputs(run, spec), args.repeat)
    intervals = len(grid) - 1
    print(f"power balance: {balance_us:.0f} us per evaluation; inputs: {intervals} intervals "
          f"in {min(times):.3f} s (min of {args.repeat})")
    write_figures(args.out, " ".join(["python benchmarks/bench_read.py",
                            *(argv if argv is not None else sys.argv[1:])]),
                  {"cores": os.cpu_count(), "python": platform.python_version(),
                   "numpy": np.__version__, "load_average": round(os.getloadavg()[0], 1),
                   "repeat": args.repeat, "files": files,
                   "power_balance_us": balance_us,
                   "inputs": {"intervals": intervals, "min_s": min(times),
                              "median_s": statistics.median(times)}})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
