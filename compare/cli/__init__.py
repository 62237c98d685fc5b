"""``spindle-verify``: the command line.

Every user error (a malformed spec or cycle, a singular problem) prints one message per
problem naming the file, the field and the fix, and exits with status 2.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from dataclasses import replace
from pathlib import Path

from spindle.drive import load_case
from spindle.errors import InputError, SpindleVerifyError
from spindle.units import ZERO_C_K


def _cmd_specs(args: argparse.Namespace) -> int:
    from spindle.spec import load_spec, shipped_specs

    for name, path in sorted(shipped_specs().items()):
        spec = load_spec(path)
        print(f"{name:12s} {spec.description}")
        print(f"{'':12s} {path}")
    return 0


def _cmd_mesh(args: argparse.Namespace) -> int:
    from meshes import build_mesh
    from meshes.io import mesh_png, save_mesh_vtu
    from spindle.outputs import output_dir
    from spindle.spec import load_spec

    spec = load_spec(args.spec)
    rows = []
    print(f"{'level':>5} {'elements':>9} {'nodes':>8} {'dofs_P1':>8} {'dofs_P2':>8} {'h_max_mm':>9}")
    for level in range(args.level + 1):
        sm = build_mesh(spec, level)
        c1, c2 = sm.counts(1), sm.counts(2)
        rows.append({**c2, "dofs_P1": c1["dofs_P1"], "h_max_m": sm.h_max_m})
        print(f"{level:5d} {c2['elements']:9d} {c2['nodes']:8d} {c1['dofs_P1']:8d} "
              f"{c2['dofs_P2']:8d} {sm.h_max_m * 1e3:9.3f}")
    out = Path(args.out or f"results/{spec.name}/mesh")
    with output_dir(out, inputs=[spec.path]) as tmp:
        save_mesh_vtu(sm, tmp / f"mesh_level{args.level}.vtu")
        (tmp / "mesh.json").write_text(json.dumps(
            {"spec": spec.name, "parts": sm.part_names, "levels": rows,
             "surfaces": {k: int(len(v)) for k, v in sm.surfaces.items()}}, indent=2) + "\n")
        if not args.no_pictures:
            mesh_png(sm, tmp / f"mesh_level{args.level}.png")
    print(f"wrote {out}/mesh_level{args.level}.vtu, mesh.json"
          + ("" if args.no_pictures else f", mesh_level{args.level}.png"))
    return 0


def _print_sensor_table(table: dict, title: str) -> None:
    print(title)
    print(f"  {'sensor':<16} {'z_mm':>7} {'r_mm':>7} {'T_C':>9} {'rise_K':>8}")
    for i, name in enumerate(table["sensor"]):
        print(f"  {name:<16} {table['z_m'][i] * 1e3:7.1f} {table['r_m'][i] * 1e3:7.2f} "
              f"{table['T_C'][i]:9.3f} {table['rise_K'][i]:8.3f}")




def _cmd_solve(args: argparse.Namespace) -> int:
    from compare.progress import Progress
    from reference import ReferenceModel
    from spindle.loads import TimeSeries
    from spindle.outputs import output_dir
    from spindle.spec import load_spec

    spec = load_spec(args.spec)
    t0 = time.perf_counter()
    if args.model == "lumped":
        from lumped import build

        nodes = int(args.nodes) if args.nodes.isdigit() else args.nodes
        ref = build(spec, nodes)
        header = (f"{spec.name}: lumped function-block model, {ref.nodes} nodes along shaft "
                  f"and housing, {ref.n_states} masses")
    else:
        ref = ReferenceModel(spec, args.level, args.order, centrifugal=args.centrifugal,
                             elastic=not args.thermal_only)
        c = ref.thermal.smesh.counts(args.order)
        header = (f"{spec.name}: FEM P{args.order}, level {args.level}, {c['elements']} "
                  f"elements, {ref.thermal.basis.N} DOFs")
    t_asm = time.perf_counter() - t0
    case = spec.default_load_case()
    inputs = [spec.path]
    if args.case:
        case = load_case(spec, args.case, case)
        if Path(args.case).is_file():
            inputs.append(args.case)
    if args.speed is not None:
        case = replace(case, speed_rpm=TimeSeries.constant(args.speed))
    quiet = args.quiet
    if args.cycle:
        case = load_case(spec, args.cycle, case)
        if Path(args.cycle).is_file():
            inputs.append(args.cycle)
        if args.model == "lumped":  # exact zero-order hold: no theta, no fields
            result = ref.transient(case, args.dt, T0=float(case.T_ambient_K(0.0)),
                                   progress=Progress("transient", not quiet))
        else:
            result = ref.transient(case, args.dt, theta=args.theta,
                                   T0=float(case.T_ambient_K(0.0)),
                                   save_every=max(1, int(round(args.save_every / args.dt))),
                                   progress=Progress("transient", not quiet))
    else:
        result = ref.steady(case)
    t_solve = time.perf_counter() - t0 - t_asm
    out = Path(args.out or f"results/{spec.name}")
    with output_dir(out, inputs=inputs) as tmp:
        files = result.save(tmp, pictures=not args.no_pictures)
    print(f"{header}; {'build' if args.model == 'lumped' else 'assembly'} {t_asm:.2f} s, "
          f"solve {t_solve:.2f} s")
    if args.cycle:
        s = result.summary()
        scheme = "exact zero-order hold" if args.model == "lumped" else f"theta = {args.theta:g}"
        print(f"transient '{case.name}': {s['steps']} steps over {s['duration_s'] / 3600:.2f} h, "
              f"{scheme}")
        print(f"  {'sensor':<16} {'peak_C':>9} {'final_C':>9}")
        for n in result.names:
            print(f"  {n:<16} {s['peak_C'][n]:9.3f} {s['final_C'][n]:9.3f}")
        print(f"  {'growth':<16} {'peak_um':>9} {'final_um':>9}")
        for n in result.growth_m:
            print(f"  {n:<16} {s['peak_growth_um'][n]:9.3f} {s['final_growth_um'][n]:9.3f}")
        e = result.energy
        print(f"energy: in {e['energy_in_J'] / 3.6e6:.4f} kWh, out {e['energy_out_J'] / 3.6e6:.4f}"
              f" kWh, stored {e['energy_stored_J'] / 3.6e6:.4f} kWh, relative imbalance "
              f"{e['relative_imbalance']:.1e}")
    else:
        _print_sensor_table(result.sensor_table(),
                            f"steady state at {result.speed_rpm:g} rpm, ambient "
                            f"{case.T_ambient_K(0) - ZERO_C_K:.2f} degC:")
        for n, v in result.growth_m.items():
            print(f"  {n + '_um':<16} {v * 1e6:9.3f}  axial growth relative to the housing "
                  "fixation below the front bearing")
        e = result.energy
        print(f"energy: in {e['heat_in_W']:.3f} W, out {e['heat_out_W']:.3f} W, relative "
              f"imbalance {e['relative_imbalance']:.1e}; relative residual {result.residual:.1e}")
    print("wrote " + ", ".join(str(out / f.name) for f in files))
    return 0


def _cmd_study(args: argparse.Namespace) -> int:
    from compare.verify.accuracy import worst_temperature_K
    from compare.verify.study import run_study
    from spindle.outputs import output_dir
    from spindle.spec import load_spec

    spec = load_spec(args.spec)
    if args.workers < 1:
        raise InputError("command line", "--workers", f"{args.workers} is below 1",
                         "give --workers 1 (serial) or more")
    say = _progress(args.quiet)
    levels, nodes = sorted(set(args.levels)), sorted(set(args.nodes))
    result = run_study(spec, levels, nodes, transient=not args.steady_only, dt_s=args.dt,
                       threshold=args.threshold / 100.0, progress=say, workers=args.workers,
                       scheduler=args.scheduler)
    out = Path(args.out or f"results/{spec.name}/study")
    with output_dir(out, inputs=[spec.path]) as tmp:
        result.save(tmp, pictures=not args.no_pictures)
    conv = result.convergence
    gt = result.ground_truth_level
    print(f"{spec.name}: verification study, {result.runtime_s:.1f} s")
    print(f"FEM grid convergence ({conv.case_name}, levels {conv.levels}, "
          f"{conv.dofs[-1]} DOFs at the finest): ground truth = "
          + (f"level {gt} (GCI <= {args.threshold:g} % for every quantity)" if gt is not None
             else f"none within {args.threshold:g} %; using level {result.reference_level}"))
    worst = conv.summary()["worst_GCI_pct_per_level"]
    print("  worst GCI per level: " + ", ".join(f"level {k}: {v:.3g} %" for k, v in worst.items()
                                                 if v is not None))
    for acc in (result.steady, result.transient):
        if acc is None:
            continue
        t = acc.table()
        print(f"{'transient' if acc.transient else 'steady'} accuracy ({acc.case_name}) against "
              f"{acc.reference_label}:")
        print(f"  {'model':<22} {'unknowns':>8} {'worst T err K':>14} {'P1 err um':>10} "
              f"{'runtime s':>10}  verdict")
        for i, name in enumerate(t["model"]):
            worst = worst_temperature_K({k: t[k][i] for k in t if k.endswith("_max_K")})
            p1 = t.get("P1_max_um", [float("nan")] * len(t["model"]))[i]
            mark = f" ({t['preset'][i]})" if t["preset"][i] else ""
            print(f"  {name + mark:<22} {t['unknowns'][i]:8d} "
                  f"{worst:14.3f} {p1:10.3f} "
                  f"{t['runtime_s'][i]:10.3f}  {'ok' if t['meets_tolerances'][i] else '--'}")
        slopes = acc.slopes()
        if slopes:
            print("  fitted slopes of error against unknowns: "
                  + ", ".join(f"{k} {v:.2f}" for k, v in slopes.items()))
    for f in result.failures:
        print(f"  FAILED {f['label']}: {f['error']}")
    print(f"wrote {out}/report.html (and tables, plots, JSON)")
    return 1 if result.failures else 0


def _progress(quiet: bool):
    def say(msg: str) -> None:
        if not quiet:
            print(f"  ... {msg}", file=sys.stderr, flush=True)

    return say


def _cmd_baseline(args: argparse.Namespace) -> int:
    from compare.verify.regression import make_baseline
    from spindle.outputs import atomic_write
    from spindle.spec import load_spec

    spec = load_spec(args.spec)  # validates before the long run
    out = Path(args.out)
    if out.exists() and out.is_dir():
        raise InputError(str(out), "--out", "is a folder", "give a file name, e.g. baseline.json")
    if out.resolve() == Path(spec.path).resolve():
        raise InputError(str(out), "--out", "would overwrite the spec", "choose another file")
    settings = {"levels": sorted(set(args.levels)), "nodes": sorted(set(args.nodes)),
                "dt_s": args.dt, "transient": not args.steady_only}
    tolerances = {"temperature_K": args.tol_temp, "growth_um": args.tol_growth}
    doc = make_baseline(args.spec, settings, tolerances, _progress(args.quiet))
    out.parent.mkdir(parents=True, exist_ok=True)
    atomic_write(out, lambda tmp: tmp.write_text(json.dumps(doc, indent=1) + "\n", "utf-8"))
    print(f"{spec.name}: {len(doc['figures'])} figures in {doc['created_with_runtime_s']:.1f} s; "
          f"wrote {out}")
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    from compare.verify.regression import check, read_baseline

    doc = read_baseline(args.file)
    changes = check(doc, progress=_progress(args.quiet))
    moved = [c for c in changes if c.moved]
    if moved:
        print(f"{args.file}: {len(moved)} of {len(changes)} figures moved beyond their "
              "tolerance:")
        for c in moved:
            print(c.line())
        return 1
    print(f"{args.file}: all {len(changes)} figures within their tolerances")
    return 0


def _cmd_fit(args: argparse.Namespace) -> int:
    from compare.fit.run import report_summary_text, run_fit, save_report
    from spindle.outputs import output_dir
    from spindle.spec import load_spec

    if args.model == "fem" and args.lumped_only:
        raise InputError("command line", "--model", "--model fem calibrates on the FEM "
                         "reference, --lumped-only switches the FEM off",
                         "drop one of the two options")
    spec = load_spec(args.spec)
    rep = run_fit(args.run, spec, args.fit_fraction, args.alpha, args.nodes,
                  candidates=args.candidates, min_gain=args.min_gain / 100.0,
                  progress=_progress(args.quiet),
                  fem_level=None if args.lumped_only else args.fem_level, model=args.model)
    out = Path(args.out or f"results/{spec.name}/fit-{Path(args.run).stem}")
    with output_dir(out, inputs=[spec.path, args.run]) as tmp:
        save_report(rep, tmp, pictures=not args.no_pictures)
    print(report_summary_text(rep))
    print(f"wrote {out}/report.json, {out}/report.html")
    return 0


def _cmd_synth(args: argparse.Namespace) -> int:
    from compare.fit.greybox import EFFECTS
    from compare.fit.synth import OUTSIDE, synth
    from spindle.spec import load_spec

    spec = load_spec(args.spec)
    known = [*EFFECTS, "clean", *OUTSIDE]
    if args.effect not in known:
        raise InputError("command line", "--effect", f"unknown effect '{args.effect}'",
                         f"use one of {', '.join(known)}")
    out = Path(args.out)
    if out.suffix.lower() != ".csv":
        raise InputError(str(out), "--out", "is not a .csv file name", "give e.g. run.csv")
    truth = synth(spec, args.cycle, args.effect, args.seed, out, level=args.level)
    print(f"wrote {out} and {out.with_suffix('.truth.json')} (effect {truth['effect']}, "
          f"seed {truth['seed']})")
    return 0


def _cmd_measures(args: argparse.Namespace) -> int:
    from compare.design.measures import read_measures, run_measures, shipped_measures
    from compare.executor import stderr_progress
    from lumped.build import PRESETS
    from spindle.outputs import output_dir
    from spindle.spec import load_spec

    spec = load_spec(args.spec)
    for n in args.lumped_nodes:
        if n not in PRESETS and not (n.isdigit() and int(n) >= 2):
            raise InputError("command line", "--nodes", f"'{n}' is not a lumped model",
                             f"give integers >= 2 or {' / '.join(sorted(PRESETS))}")
    if args.points is not None and not 2 <= args.points <= 100:
        raise InputError("command line", "--points", f"{args.points} is outside 2..100",
                         "give --points 7, for example")
    if args.workers is not None and args.workers < 1:
        raise InputError("command line", "--workers", f"{args.workers} is below 1",
                         "give --workers 1 (serial) or more")
    mpath = args.measures or shipped_measures(spec.name)
    if mpath is None:
        raise InputError(spec.path, "--measures", f"no measures file is shipped for spec "
                         f"'{spec.name}'", "give --measures FILE (format: docs/measures.md)")
    mfile = read_measures(mpath, spec, args.points)
    case = spec.default_load_case()
    inputs = [spec.path, str(mpath)]
    if args.case:
        case = load_case(spec, args.case, case)
        if Path(args.case).is_file():
            inputs.append(args.case)
    elif spec.power_preset:
        case = load_case(spec, "nominal", case)
    rep = run_measures(spec, mfile, case, args.level, tuple(args.lumped_nodes),
                       sweeps=not args.no_sweeps, points=args.points or 7,
                       scheduler=args.scheduler, workers=args.workers,
                       progress=stderr_progress(not args.quiet))
    out = Path(args.out or f"results/{spec.name}-measures")
    with output_dir(out, inputs=inputs) as tmp:
        files = rep.save(tmp, pictures=not args.no_pictures)
    b = rep.baseline
    print(f"{spec.name}: thermal stiffness strategy at '{case.name}' ({rep.speed_rpm:g} rpm, "
          f"{b.losses_W:.0f} W), FEM level {args.level}; {rep.runtime_s:.1f} s")
    print(f"  {'model':<16} {'K_alpha mean K/W':>16} {'K_alpha max K/W':>16} {'K_T K/um':>9} "
          f"{'K_Q W/um':>9}")
    for ind in [b, *rep.lumped.values()]:
        print(f"  {ind.model:<16} {ind.K_alpha_mean_K_W:16.3e} {ind.K_alpha_max_K_W:16.3e} "
              f"{ind.K_T_K_um:9.3f} {ind.K_Q_W_um:9.2f}")
    print(f"  {'formulas':<16} {1.0 / rep.sum_alpha_A_W_K:16.3e}  (1 / sum(alpha A), "
          f"sum(alpha A) = {rep.sum_alpha_A_W_K:.4g} W/K)")
    print(f"  {'paper':<16} {0.00019:16.3e} {'':>16} {0.52:9.3f} {64.53:9.2f}")
    print(f"  {'measure':<22} {'lambda formula':>14} {'lambda FEM':>10} {'xi formula %':>12} "
          f"{'xi FEM %':>9} {'xi growth FEM %':>15}")
    for m in rep.measures:
        r = m.to_row()
        print(f"  {r['measure']:<22} {r['lambda_formula']:14.4f} {r['lambda_ref_mean']:10.4f} "
              f"{r['xi_formula_pct']:12.2f} {r['xi_ref_mean_pct']:9.2f} "
              f"{r['xi_growth_ref_pct']:15.2f}")
    for i in rep.inverse:
        goal = (f"xi {i.target.xi_pct:g} %" if i.target.xi_pct is not None
                else f"growth {i.target.growth_um:g} um")
        found = (f"{i.target.vary} = {i.size_ref:.4g} {i.unit} (formulas: {i.size_formula:.4g})"
                 if i.reached else i.note)
        print(f"  inverse {i.target.name} ({goal}): {found}")
    for f in rep.failures:
        print(f"  FAILED {f['label']}: {f['error']}")
    print("wrote " + ", ".join(str(out / f.name) for f in files))
    return 1 if rep.failures else 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="spindle-verify",
        description="How far can you trust a thermal model of a motor spindle? FEM reference, "
                    "lumped models and the harness that compares them. SPEC is a shipped spec "
                    "name (see 'spindle-verify specs') or a path to a .toml file.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    sp = sub.add_parser("specs", help="list the shipped spindle descriptions")
    sp.set_defaults(func=_cmd_specs)

    mp = sub.add_parser("mesh", help="mesh a spec at refinement levels 0..N; VTU and PNG")
    mp.add_argument("spec", metavar="SPEC")
    mp.add_argument("--level", type=int, default=2, help="finest level (default 2)")
    mp.add_argument("--out", help="output folder (default results/<spec>/mesh)")
    mp.add_argument("--no-pictures", action="store_true", help="skip the PNG")
    mp.set_defaults(func=_cmd_mesh)

    so = sub.add_parser("solve", help="temperatures and axial growth (P1) from the FEM reference "
                        "or a lumped model, steady or over a transient cycle")
    so.add_argument("spec", metavar="SPEC")
    so.add_argument("--model", choices=("fem", "lumped"), default="fem",
                    help="fem: the FEM reference (default); lumped: the paper's function-block "
                         "model")
    so.add_argument("--nodes", default="11",
                    help="lumped model: masses along shaft and housing, an integer >= 2 or "
                         "paper5 / paper11 (default 11)")
    so.add_argument("--level", type=int, default=2, help="mesh level (default 2)")
    so.add_argument("--order", type=int, choices=(1, 2), default=2,
                    help="element order (default 2)")
    mode = so.add_mutually_exclusive_group()
    mode.add_argument("--steady", action="store_true", help="steady state (the default)")
    mode.add_argument("--cycle", metavar="CYCLE",
                      help="transient: a shipped cycle (spl-16h, nominal), a cycle TOML, a "
                           "step-table CSV (speed_rpm, duration_s, load_torque_Nm) or a time "
                           "series CSV (time_s, speed_rpm, T_env_C, T_coolant_C, <source>_W)")
    so.add_argument("--case", metavar="CYCLE",
                    help="steady load case from a cycle's first step, e.g. 'nominal' "
                         "(38 kW / 4300 rpm); heat sources from the power balance")
    so.add_argument("--speed", type=float, help="spindle speed for a steady solve [rpm]")
    so.add_argument("--dt", type=float, default=60.0, help="time step [s] (default 60)")
    so.add_argument("--theta", type=float, default=1.0,
                    help="1 = backward Euler (default), 0.5 = Crank-Nicolson")
    so.add_argument("--save-every", type=float, default=1800.0,
                    help="keep a field for ParaView every this many seconds (default 1800)")
    so.add_argument("--centrifugal", action="store_true",
                    help="add the centrifugal load of the rotating parts (off by default)")
    so.add_argument("--thermal-only", action="store_true",
                    help="skip the thermoelastic growth (P1, TCP)")
    so.add_argument("--out", help="output folder (default results/<spec>)")
    so.add_argument("--no-pictures", action="store_true", help="skip the PNGs")
    so.add_argument("--quiet", action="store_true", help="no progress on stderr")
    so.set_defaults(func=_cmd_solve)

    st = sub.add_parser("study", help="verification study: FEM grid convergence (GCI), accuracy "
                        "of eq. 14, the lumped models and the FEM levels, HTML report")
    st.add_argument("spec", metavar="SPEC")
    st.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2, 3],
                    help="nested FEM levels, three or more (default 0 1 2 3)")
    st.add_argument("--nodes", type=int, nargs="+", default=[2, 3, 5, 7, 11, 15, 21, 31, 41],
                    help="lumped node counts (default 2 3 5 7 11 15 21 31 41)")
    st.add_argument("--threshold", type=float, default=1.0,
                    help="GCI [%%] a level must meet for every quantity to be the ground truth "
                         "(default 1)")
    st.add_argument("--dt", type=float, default=60.0, help="transient time step [s] (default 60)")
    st.add_argument("--steady-only", action="store_true", help="skip the transient comparison")
    st.add_argument("--scheduler", metavar="ADDRESS",
                    help="run the independent runs on a Dask cluster (tcp://host:8786, or "
                         "'local' with --workers processes); needs "
                         "pip install \"spindle-verify[dask]\" (default: no cluster)")
    st.add_argument("--workers", type=int, default=1,
                    help="processes for the independent runs (the lumped models, the FEM "
                         "transients): 1 runs them serially in this process, so the runtimes "
                         "in the tables are not disturbed by other runs (default 1); 2 runs "
                         "the independent runs in a process pool")
    st.add_argument("--out", help="output folder (default results/<spec>/study)")
    st.add_argument("--no-pictures", action="store_true", help="skip the PNGs")
    st.add_argument("--quiet", action="store_true", help="no progress on stderr")
    st.set_defaults(func=_cmd_study)

    bp = sub.add_parser("baseline", help="store the figures of a study (values, errors, "
                        "tolerances) as JSON for regression checks")
    bp.add_argument("spec", metavar="SPEC")
    bp.add_argument("--out", required=True, help="the JSON file to write")
    bp.add_argument("--levels", type=int, nargs="+", default=[0, 1, 2],
                    help="FEM levels, three or more (default 0 1 2)")
    bp.add_argument("--nodes", type=int, nargs="+", default=[5, 11],
                    help="lumped node counts (default 5 11)")
    bp.add_argument("--dt", type=float, default=300.0, help="transient time step [s] (300)")
    bp.add_argument("--steady-only", action="store_true", help="skip the transient figures")
    bp.add_argument("--tol-temp", type=float, default=0.01,
                    help="how far a temperature may move [K] (default 0.01)")
    bp.add_argument("--tol-growth", type=float, default=0.01,
                    help="how far a growth may move [um] (default 0.01)")
    bp.add_argument("--quiet", action="store_true", help="no progress on stderr")
    bp.set_defaults(func=_cmd_baseline)

    cp = sub.add_parser("check", help="recompute a baseline's figures; exit 1 with a diff when "
                        "any moved beyond its tolerance")
    cp.add_argument("file", metavar="FILE")
    cp.add_argument("--quiet", action="store_true", help="no progress on stderr")
    cp.set_defaults(func=_cmd_check)

    fp = sub.add_parser("fit", help="fit a bench run: calibrate, diagnose the residual, add the "
                        "effects it supports, report the error before and after")
    fp.add_argument("run", metavar="RUN.csv", help="bench export (format: docs/bench.md)")
    fp.add_argument("--spec", default="spl2782", help="the spindle (default spl2782)")
    fp.add_argument("--out", help="output folder (default results/<spec>/fit-<run>)")
    fp.add_argument("--fit-fraction", type=float, default=0.6,
                    help="fraction of the run used for fitting; the rest validates (0.6)")
    fp.add_argument("--alpha", type=float, default=0.01,
                    help="level of the likelihood-ratio test for adding an effect (0.01)")
    fp.add_argument("--min-gain", type=float, default=25.0,
                    help="an effect must remove at least this share [%%] of the validation "
                    "error above the floor (lumped-model error against the FEM and sensor "
                    "noise) (default 25)")
    fp.add_argument("--fem-level", type=int, default=0,
                    help="FEM reference level that anchors the model on the run's inputs "
                    "(default 0; docs/fit.md)")
    fp.add_argument("--lumped-only", action="store_true",
                    help="no FEM anchor and no priors: the lumped model alone, factors from "
                    "1 (faster; effects the base parameters can imitate go unnamed)")
    fp.add_argument("--model", choices=("lumped", "fem"), default="lumped",
                    help="model the base parameters are calibrated on (default lumped: the "
                    "lumped model anchored to the FEM at the spec's values; fast). fem: "
                    "calibrate the base parameters on the FEM reference itself (minutes), "
                    "then select effects on the lumped model anchored there")
    fp.add_argument("--nodes", type=int, default=11, help="lumped model nodes (default 11)")
    fp.add_argument("--candidates", nargs="+", help="candidate effects (default: all)")
    fp.add_argument("--no-pictures", action="store_true", help="skip the PNGs")
    fp.add_argument("--quiet", action="store_true", help="no progress on stderr")
    fp.set_defaults(func=_cmd_fit)

    sy = sub.add_parser("synth", help="a synthetic bench run from the FEM reference with one "
                        "effect injected; the truth goes to RUN.truth.json")
    sy.add_argument("--spec", default="spl2782")
    sy.add_argument("--cycle", default="spl-16h", help="cycle (default spl-16h)")
    sy.add_argument("--effect", default="clean", help="effect to inject (default clean)")
    sy.add_argument("--seed", type=int, default=0)
    sy.add_argument("--level", type=int, default=1, help="FEM level (default 1)")
    sy.add_argument("--out", required=True, help="the CSV to write")
    sy.set_defaults(func=_cmd_synth)

    me = sub.add_parser("measures", help="thermal stiffness strategy (paper section 4): "
                        "indicators K_alpha, K_T, K_Q from the FEM and lumped models; design "
                        "measures by the formulas (eq. 25-30) and by the FEM; inverse problem; "
                        "Fig. 15 and Fig. 16-style sensitivity sweeps")
    me.add_argument("spec", metavar="SPEC")
    me.add_argument("--measures", metavar="FILE",
                    help="measures TOML (docs/measures.md); default: the spec's shipped file, "
                         "spindle/data/measures/<spec>.toml (there is one for spl2782)")
    me.add_argument("--case", metavar="CYCLE",
                    help="steady load case from a cycle's first step (default: 'nominal' for a "
                         "spec with a power balance, else the spec's own inputs)")
    me.add_argument("--level", type=int, default=1, help="FEM mesh level (default 1)")
    me.add_argument("--nodes", dest="lumped_nodes", nargs="+", default=["paper5", "paper11"],
                    metavar="N", help="lumped models for the indicators and the measures: "
                                      "integers >= 2 or paper5 / paper11 (default paper5 paper11)")
    me.add_argument("--points", type=int,
                    help="points per sensitivity sweep (default: the file's, else 7)")
    me.add_argument("--no-sweeps", action="store_true", help="skip the Fig. 16 sweeps")
    me.add_argument("--scheduler", metavar="ADDRESS",
                    help="run the cases on a Dask cluster (tcp://host:8786, or 'local'); needs "
                         "pip install \"spindle-verify[dask]\" (default: a local process pool)")
    me.add_argument("--workers", type=int,
                    help="processes (default min(2, CPUs)); 1 runs the cases serially")
    me.add_argument("--out", help="output folder (default results/<spec>-measures)")
    me.add_argument("--no-pictures", action="store_true", help="skip the PNGs")
    me.add_argument("--quiet", action="store_true", help="no progress on stderr")
    me.set_defaults(func=_cmd_measures)

    from compare.crosscheck import calculix
    from compare.verify import sensors

    sensors.register(sub)
    calculix.register(sub)
    return p


def _check_args(args: argparse.Namespace) -> None:
    if not 0 <= getattr(args, "level", 0) <= 6:
        raise InputError("command line", "--level", f"{args.level} is out of range",
                         "give a level between 0 and 6")
    if getattr(args, "dt", 1.0) <= 0:
        raise InputError("command line", "--dt", "must be > 0 s", "give a positive time step")
    if not 0.0 <= getattr(args, "theta", 1.0) <= 1.0:
        raise InputError("command line", "--theta", "must be within [0, 1]",
                         "use 1 (backward Euler) or 0.5 (Crank-Nicolson)")
    if (getattr(args, "speed", None) or 0) < 0:
        raise InputError("command line", "--speed", "is negative", "give |n| in rpm")
    levels = getattr(args, "levels", None)
    if levels is not None:
        if any(not 0 <= lv <= 5 for lv in levels):
            raise InputError("command line", "--levels", f"{levels} has a level outside 0..5",
                             "give levels between 0 and 5")
        if len(set(levels)) < 3:
            raise InputError("command line", "--levels", f"{levels} has fewer than 3 levels",
                             "give three or more levels, e.g. --levels 0 1 2 3")
    nodes = getattr(args, "nodes", None)
    if isinstance(nodes, list) and min(nodes) < 2:
        raise InputError("command line", "--nodes", "a lumped model needs >= 2 nodes",
                         "give node counts >= 2")


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        _check_args(args)
        return args.func(args)
    except SpindleVerifyError as exc:
        for line in str(exc).splitlines():
            print(f"spindle-verify: error: {line}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("spindle-verify: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`, which closed early
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
