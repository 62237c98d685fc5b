"""``spindle-verify solve``: one solve of the FEM reference or a lumped model, steady or transient."""

from __future__ import annotations

import argparse
import time
from dataclasses import replace
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    POSITIVE,
    SPEED_RPM,
    TIME_STEP_S,
    add_no_pictures,
    add_out,
    add_quiet,
    add_spec,
    input_files,
    load_case_input,
    load_spec_with_sensors,
    number,
    out_folder,
    spec_files,
    with_progress,
)
from spindle.errors import InputError
from spindle.units import ZERO_C_K

if TYPE_CHECKING:
    from compare.progress import Progress


def _print_sensor_table(table: dict, title: str) -> None:
    print(title)
    print(f"  {'sensor':<16} {'z_mm':>7} {'r_mm':>7} {'T_C':>9} {'rise_K':>8}")
    for i, name in enumerate(table["sensor"]):
        print(f"  {name:<16} {table['z_m'][i] * 1e3:7.1f} {table['r_m'][i] * 1e3:7.2f} "
              f"{table['T_C'][i]:9.3f} {table['rise_K'][i]:8.3f}")


@with_progress("solve")
def _cmd_solve(args: argparse.Namespace, progress: Progress) -> int:
    from spindle.loads import TimeSeries
    from spindle.outputs import output_dir, safe_name

    if args.case and args.cycle:
        raise InputError("command line", "--case", "--case (a steady load point) and --cycle (a "
                         "transient) exclude each other", "give one of them")
    if args.speed is not None and args.cycle:
        raise InputError("command line", "--speed", "sets a steady solve's speed, and --cycle "
                         "gives the transient its own speeds, so it would be ignored",
                         "drop --speed, or drop --cycle for a steady solve at that speed")
    if args.speed is not None and args.case:
        # the case's losses are its own speed's (its power balance), so a new speed beside
        # them gave 4300 rpm's 5146 W at 1000 rpm
        raise InputError("command line", "--speed", "sets a steady solve's speed, and --case "
                         "gives its own speed with the losses of that speed",
                         "drop --speed, or drop --case for the spec's operating point at that "
                         "speed")
    progress.stage("reading the spec")
    spec = load_spec_with_sensors(args.spec)
    inputs = [*spec_files(spec), *input_files(args.case, args.cycle)]
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/solve", inputs, force=args.force)
    t0 = time.perf_counter()
    if args.model == "lumped":
        from lumped import build

        nodes = int(args.nodes) if args.nodes.isdigit() else args.nodes
        progress.stage(f"building the lumped model ({nodes} nodes)")
        ref = build(spec, nodes)
        header = (f"{spec.name}: lumped function-block model, {ref.nodes} nodes along shaft "
                  f"and housing, {ref.n_states} masses")
    else:
        progress.stage(f"meshing level {args.level} and assembling P{args.order}")
        from reference import ReferenceModel

        ref = ReferenceModel(spec, args.level, args.order, centrifugal=args.centrifugal,
                             elastic=not args.thermal_only)
        c = ref.thermal.smesh.counts(args.order)
        header = (f"{spec.name}: FEM P{args.order}, level {args.level}, {c['elements']} "
                  f"elements, {ref.thermal.basis.N} DOFs")
    t_asm = time.perf_counter() - t0
    case = spec.default_load_case()
    inputs = spec_files(spec)
    if args.case:
        case = load_case_input(spec, args.case, case, inputs)
    if args.speed is not None:
        case = replace(case, speed_rpm=TimeSeries.constant(args.speed))
    if args.cycle:
        case = load_case_input(spec, args.cycle, case, inputs)
        progress.stage(f"transient '{case.name}'", 0.0)
        if args.model == "lumped":  # exact zero-order hold: no theta, no fields
            result = ref.transient(case, args.dt, T0=float(case.T_ambient_K(0.0)),
                                   progress=progress.fraction)
        else:
            result = ref.transient(case, args.dt, theta=args.theta,
                                   T0=float(case.T_ambient_K(0.0)),
                                   save_every=max(1, int(round(args.save_every / args.dt))),
                                   progress=progress.fraction)
    else:
        progress.stage("steady solve")
        result = ref.steady(case)
    t_solve = time.perf_counter() - t0 - t_asm
    result.check_plausible(spec.path)
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        files = result.save(tmp, pictures=not args.no_pictures)
    progress.done()
    _print_result(args, ref, result, case, header, t_asm, t_solve)
    print("wrote " + ", ".join(str(out / f.name) for f in files))
    return 0


def _print_result(args: argparse.Namespace, ref, result, case, header: str, t_asm: float,
                  t_solve: float) -> None:
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
        heat = sum(float(v(0.0)) for v in case.sources.values())
        origin = (f"the power balance of '{case.name}'" if args.case
                  else "the spec's [[heat_sources]]")
        _print_sensor_table(result.sensor_table(),
                            f"steady state at {result.speed_rpm:g} rpm, ambient "
                            f"{case.T_ambient_K(0) - ZERO_C_K:.2f} degC, heat {heat:.1f} W "
                            f"from {origin}:")
        for n, v in result.growth_m.items():
            print(f"  {n + '_um':<16} {v * 1e6:9.3f}  axial growth relative to the housing "
                  "fixation below the front bearing")
        e = result.energy
        print(f"energy: in {e['heat_in_W']:.3f} W, out {e['heat_out_W']:.3f} W, relative "
              f"imbalance {e['relative_imbalance']:.1e}; relative residual {result.residual:.1e}")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    so = subparsers.add_parser("solve", help="temperatures and axial growth (P1) from the FEM reference "
                        "or a lumped model, steady or over a transient cycle")
    add_spec(so)
    so.add_argument("--model", choices=("fem", "lumped"), default="fem",
                    help="fem: the FEM reference (default); lumped: the paper's function-block "
                         "model")
    so.add_argument("--nodes", default="11",
                    help="lumped model: masses along shaft and housing, an integer >= 2 or "
                         "paper5 / paper11 (default 11)")
    so.add_argument("--level", type=MESH_LEVEL, default=2, help="mesh level (default 2)")
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
    so.add_argument("--speed", type=SPEED_RPM, help="spindle speed for a steady solve [rpm]")
    so.add_argument("--dt", type=TIME_STEP_S, default=60.0, help="time step [s] (default 60)")
    so.add_argument("--theta", type=number(0.5, 1.0), default=1.0,
                    help="1 = backward Euler (default), 0.5 = Crank-Nicolson")
    so.add_argument("--save-every", type=POSITIVE, default=1800.0,
                    help="keep a field for ParaView every this many seconds (default 1800)")
    so.add_argument("--centrifugal", action="store_true",
                    help="add the centrifugal load of the rotating parts (off by default)")
    so.add_argument("--thermal-only", action="store_true",
                    help="skip the thermoelastic growth (P1, TCP)")
    add_out(so, "results/<spec>/solve")
    add_no_pictures(so)
    add_quiet(so)
    so.set_defaults(func=_cmd_solve)
