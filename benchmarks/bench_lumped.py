"""Lumped-model benchmark: build, steady solve, the 16 h cycle, and real-time prediction.

    python benchmarks/bench_lumped.py [SPEC] [--nodes 5 11 21 41] [--repeat 9]
                                      [--out docs/figures/lumped-speed.json]

Per node count: masses, build + assemble time, steady solve, the spl-16h cycle with the exact
zero-order hold on the reference's 60 s grid, and the real-time predictor over the whole
16 h cycle at 1 s samples (57 600 samples): batch replay (best of --repeat runs, inputs
sampled beforehand) and one streaming step (amortised over the cycle).
Targets (issue 4, 2-core machine, 11-node model): the 16 h cycle at 1 s in <= 20 ms (the
paper's Simulink model needs 12 s); one streaming step <= 5 µs amortised.
The rows go to ``--out`` (JSON with the date, the commit and the load average), from which
docs/lumped.md's table is checked (tests/test_docs_figures.py). Run it on an idle machine:
the timings of a busy one are several times longer.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np
from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]
PAPER_SIMULINK_S = 12.0  # seed paper, section 2.2: 12 s for a 16 h cycle


def bench(spec_name: str, nodes: int, repeat: int) -> dict:
    from lumped import build
    from lumped.realtime import RealTimePredictor
    from spindle.cycle_files import load_cycle
    from spindle.drive import cycle_load_case, drive_for
    from spindle.spec_reader import load_spec

    spec = load_spec(spec_name)
    t = time.perf_counter()
    model = build(spec, nodes)
    t_build = time.perf_counter() - t
    drive = drive_for(spec)
    nominal = cycle_load_case(spec, load_cycle("nominal"), drive) if drive else None
    t = time.perf_counter()
    model.steady(nominal)
    t_steady = time.perf_counter() - t
    case = cycle_load_case(spec, load_cycle("spl-16h"), drive) if drive else None
    out = {"nodes": nodes, "masses": model.n_states, "build_s": t_build, "steady_s": t_steady}
    if case is None:
        return out
    T0 = float(case.T_ambient_K(0.0))
    t = time.perf_counter()
    model.transient(case, 60.0, T0=T0)
    out["cycle_60s_grid_s"] = time.perf_counter() - t
    dt = 1.0
    mid = np.arange(0.0, case.duration_s, dt) + 0.5 * dt
    t = time.perf_counter()
    U = model.inputs(case, mid)
    speeds = np.asarray(case.speed_rpm(mid), dtype=float)
    out["sample_inputs_s"] = time.perf_counter() - t
    t = time.perf_counter()
    pred = RealTimePredictor(model, dt, x0=T0, speeds_rpm=np.unique(speeds))
    for s in np.unique(speeds):
        pred.modes(s)
    out["precompute_s"] = time.perf_counter() - t
    runs = []
    for _ in range(repeat):
        pred.state = T0
        t = time.perf_counter()
        _, P1 = pred.run(U, speeds)
        runs.append(time.perf_counter() - t)
    out["samples"] = len(U)
    out["replay_16h_1s_s"] = min(runs)
    out["P1_peak_um"] = float(P1.max() * 1e6)
    pred.state = T0
    t = time.perf_counter()
    step = pred.step
    for k in range(len(U)):
        step(U[k], speeds[k])
    out["stream_step_us"] = (time.perf_counter() - t) / len(U) * 1e6
    out["step_matrix"] = list(pred.fused(float(speeds[-1])).shape)  # the fused step's matrix
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec", nargs="?", default="spl2782")
    ap.add_argument("--nodes", type=int, nargs="+", default=[5, 11, 21, 41])
    ap.add_argument("--repeat", type=int, default=9)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "lumped-speed.json")
    args = ap.parse_args(argv)
    from spindle.errors import SpindleVerifyError

    rows = []
    print(f"{'nodes':>5} {'masses':>6} {'build':>8} {'steady':>8} {'cycle60s':>9} "
          f"{'replay16h@1s':>13} {'vs paper':>9} {'step':>8} {'P1peak':>7}")
    for n in args.nodes:
        try:
            r = bench(args.spec, n, args.repeat)
        except SpindleVerifyError as exc:  # a spec missing or not valid: one message
            print(f"error: {exc}", file=sys.stderr)
            sys.exit(2)
        rows.append(r)
        if "replay_16h_1s_s" not in r:
            print(f"{n:5d} {r['masses']:6d} {r['build_s'] * 1e3:6.1f}ms {r['steady_s'] * 1e3:6.2f}ms")
            continue
        print(f"{n:5d} {r['masses']:6d} {r['build_s'] * 1e3:6.1f}ms {r['steady_s'] * 1e3:6.2f}ms "
              f"{r['cycle_60s_grid_s'] * 1e3:7.1f}ms {r['replay_16h_1s_s'] * 1e3:11.1f}ms "
              f"{PAPER_SIMULINK_S / r['replay_16h_1s_s']:8.0f}x {r['stream_step_us']:6.2f}us "
              f"{r['P1_peak_um']:6.2f}")
    if "samples" in r:
        print(f"({r['samples']} samples of 1 s; paper's Simulink model: {PAPER_SIMULINK_S:g} s "
              "for 16 h; 'vs paper' = 12 s / replay time; targets for 11 nodes: replay "
              "<= 20 ms, step <= 5 us)")
    write_figures(args.out, " ".join(["python benchmarks/bench_lumped.py",
                            *(argv if argv is not None else sys.argv[1:])]),
                  {"spec": args.spec, "cycle": "spl-16h", "repeat": args.repeat,
                   "cores": os.cpu_count(), "python": sys.version.split()[0],
                   "numpy": np.__version__, "load_average": round(os.getloadavg()[0], 1),
                   "paper_simulink_s": PAPER_SIMULINK_S, "rows": rows})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
