"""FEM reference benchmark: per mesh level, size, assembly, factorisation, steady solve,
time per transient step and peak memory; then a 16 h cycle at 60 s steps.

    python benchmarks/bench_reference.py [SPEC] [--levels 0 1 2 3] [--order 2] [--cycle-level 2]

Each level runs in its own process so that peak memory (VmHWM; getrusage's ru_maxrss would
carry the parent's over exec) belongs to that level. The figures go to ``--out`` (default
docs/figures/reference-speed.json), from which docs/commands.md's table is checked
(tests/test_docs_snippets.py).
Targets (issue 2, 2-core machine): a steady solve at >= 1e5 DOF in <= 1 s; the 16 h cycle
on the ground-truth level in <= 30 s.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from figures import memory_MB, write_figures

ROOT = Path(__file__).resolve().parents[1]


def one_level(spec_name: str, level: int, order: int) -> dict:
    from meshes import build_mesh
    from reference import ThermalModel
    from reference.thermal import factorize
    from spindle.spec_reader import load_spec

    spec = load_spec(spec_name)
    t = time.perf_counter()
    sm = build_mesh(spec, level)
    t_mesh = time.perf_counter() - t
    t = time.perf_counter()
    model = ThermalModel(sm, order)
    t_asm = time.perf_counter() - t
    case = spec.default_load_case()
    n = float(case.speed_rpm(0))
    K, F = model.op.K(n), model.op.F(case, 0.0, n)
    t = time.perf_counter()
    lu = factorize(K)
    t_fact = time.perf_counter() - t
    t = time.perf_counter()
    lu.solve(F)
    t_subst = time.perf_counter() - t
    t = time.perf_counter()
    model.solve_steady(case)
    t_steady = time.perf_counter() - t
    A = (model.op.M / 60.0 + K).tocsc()
    lu = factorize(A)
    T = F.copy()
    t = time.perf_counter()
    for _ in range(20):
        T = lu.solve(model.op.M @ T / 60.0 + F)
    t_step = (time.perf_counter() - t) / 20
    c = sm.counts(order)
    return {"level": level, "elements": c["elements"], "dofs": int(model.basis.N),
            "mesh_s": t_mesh, "assembly_s": t_asm, "factorisation_s": t_fact,
            "substitution_s": t_subst, "steady_solve_s": t_steady, "step_s": t_step,
            "peak_MB": memory_MB()}


def cycle(spec_name: str, level: int, order: int, hours: float = 16.0) -> dict:
    from reference import ReferenceModel
    from spindle.loads import LoadCase, TimeSeries
    from spindle.spec_reader import load_spec

    spec = load_spec(spec_name)
    base = spec.default_load_case()
    # a stand-in for spl-16h (issue 3): speed steps every 2 h up to 4300 rpm, drifting air
    steps = [0, 1000, 2000, 3000, 4300, 3000, 2000, 0]
    times = tuple(float(2 * 3600 * k) for k in range(len(steps)))
    case = LoadCase("16h-steps", TimeSeries(times, tuple(map(float, steps)), "previous"),
                    TimeSeries((0.0, hours * 3600), (293.15, 295.15)),
                    TimeSeries((0.0, hours * 3600), (293.15, 293.15)),
                    {k: TimeSeries(times, tuple(v(0) * s / 4300 for s in steps), "previous")
                     for k, v in base.sources.items()}, duration_s=hours * 3600)
    t = time.perf_counter()
    model = ReferenceModel(spec, level, order)  # thermal + thermoelastic (P1, TCP)
    t_setup = time.perf_counter() - t
    t = time.perf_counter()
    model.steady()
    t_steady = time.perf_counter() - t
    t = time.perf_counter()
    res = model.transient(case, 60.0)
    t_run = time.perf_counter() - t
    return {"level": level, "dofs": int(model.thermal.basis.N),
            "dofs_u": int(model.elastic.basis.N), "steps": len(res.times_s) - 1,
            "setup_s": t_setup, "steady_te_s": t_steady, "cycle_s": t_run,
            "P1_peak_um": float(res.growth_m["P1"].max() * 1e6),
            "relative_imbalance": res.energy["relative_imbalance"],
            "peak_MB": memory_MB()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("spec", nargs="?", default="spl2782")
    ap.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2, 3])
    ap.add_argument("--order", type=int, default=2)
    ap.add_argument("--cycle-level", type=int, default=2)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "reference-speed.json")
    ap.add_argument("--child", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child:
        kind, level = args.child
        fn = one_level if kind == "level" else cycle
        print(json.dumps(fn(args.spec, int(level), args.order)))
        return

    def child(kind: str, level: int) -> dict:
        out = subprocess.run([sys.executable, __file__, args.spec, "--order", str(args.order),
                              "--child", kind, str(level)], capture_output=True, text=True,
                             cwd=ROOT, check=True)
        return json.loads(out.stdout.strip().splitlines()[-1])

    print(f"FEM thermal reference, {args.spec}, P{args.order} "
          f"(python {sys.version.split()[0]}, {__import__('os').cpu_count()} cores)")
    hdr = (f"{'level':>5} {'elements':>9} {'DOFs':>8} {'assembly_s':>10} {'factor_s':>9} "
           f"{'steady_s':>9} {'step_ms':>8} {'peak_MB':>8}")
    print(hdr)
    rows = []
    for level in args.levels:
        r = child("level", level)
        rows.append(r)
        print(f"{r['level']:5d} {r['elements']:9d} {r['dofs']:8d} {r['assembly_s']:10.3f} "
              f"{r['factorisation_s']:9.3f} {r['steady_solve_s']:9.3f} "
              f"{r['step_s'] * 1e3:8.2f} {r['peak_MB']:8.0f}")
    big = [r for r in rows if r["dofs"] >= 1e5]
    if big:
        r = big[0]
        print(f"steady solve at {r['dofs']} DOFs: {r['steady_solve_s']:.3f} s "
              f"(target <= 1 s: ratio {r['steady_solve_s'] / 1.0:.2f})")
    c = child("cycle", args.cycle_level)
    print(f"thermoelastic reference, level {c['level']}: {c['dofs']} temperature + "
          f"{c['dofs_u']} displacement DOFs; setup (both assemblies, both factorisations) "
          f"{c['setup_s']:.2f} s; steady temperature + growth {c['steady_te_s']:.2f} s")
    print(f"16 h cycle (thermal + growth) at 60 s steps, {c['steps']} steps: {c['cycle_s']:.2f} s"
          f" + setup {c['setup_s']:.2f} s (target <= 30 s: ratio "
          f"{(c['cycle_s'] + c['setup_s']) / 30:.2f}); energy imbalance "
          f"{c['relative_imbalance']:.1e}; peak {c['peak_MB']:.0f} MB")
    write_figures(args.out, "python benchmarks/bench_reference.py",
                  {"spec": args.spec, "order": args.order, "cores": os.cpu_count(),
                   "python": sys.version.split()[0], "levels": rows, "cycle": c})


if __name__ == "__main__":
    main()
