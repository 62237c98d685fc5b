"""``spindle-verify rom``: a reduced-order model of the FEM reference that meets given
tolerances, checked on held-out cycles, exported for a controller (docs/rom.md)."""

from __future__ import annotations

import argparse
import json

from compare.cli.common import (
    MESH_LEVEL,
    POSITIVE,
    TIME_STEP_S,
    add_no_pictures,
    add_out,
    add_quiet,
    add_spec,
    input_files,
    load_spec_with_sensors,
    number,
    out_folder,
    pass_fail,
    spec_files,
    with_progress,
)
from compare.progress import Progress
from spindle.errors import InputError

#: the held-out cycles of the issue: the paper's 16 h cycle and the rated steady state (the
#: SPL2782.1's spl-16h and nominal; another spindle's at its own rated point), a loaded
#: random cycle and a no-load random cycle (seeds other than the training's)
HELD_OUT = ("rated-16h", "rated", "random-loaded:1", "random:2")


def _check_cycles(texts: list[str]) -> None:
    from spindle.cycle_files import shipped_cycles
    from spindle.cycles import RANDOM_CYCLES
    from spindle.drive import RATED_CYCLES

    for text in texts:
        name, _, seed = text.partition(":")
        if seed and not seed.isdigit():
            raise InputError("command line", "--cycle/--held-out", f"'{text}': the seed "
                             f"'{seed}' is not a whole number >= 0 (a seed of the random "
                             "stream)", "write NAME or NAME:SEED, e.g. random:0")
        if name not in (*RANDOM_CYCLES, *RATED_CYCLES) and name not in shipped_cycles():
            from pathlib import Path

            if not Path(name).is_file():
                raise InputError("command line", "--cycle/--held-out", f"'{name}' is neither "
                                 "a shipped cycle, random, random-loaded nor a cycle file",
                                 "give one of " + ", ".join([*shipped_cycles(), *RANDOM_CYCLES,
                                                             *RATED_CYCLES]))


@with_progress("rom")
def run(args: argparse.Namespace, progress: Progress) -> int:
    from compare.verify.romstudy import rom_study
    from reference.rom.export import export
    from reference.rom.realtime import ROMPredictor
    from spindle.drive import drive_for
    from spindle.outputs import output_dir, safe_name

    spec = load_spec_with_sensors(args.spec)
    inputs = [*spec_files(spec), *input_files(args.cycle, *args.held_out)]
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/rom", inputs, force=args.force)
    _check_cycles([args.cycle, *args.held_out])
    study = rom_study(spec, args.level, args.cycle, args.held_out, args.dt, args.tol_temp,
                      args.tol_growth, args.safety, progress.say)
    rom = study.rom
    top = max(study.report.speeds_rpm)
    speeds = [k * args.export_speed_step for k in range(int(top // args.export_speed_step) + 1)]
    pred = ROMPredictor(rom, args.sample_time)
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        files = study.save(tmp, pictures=not args.no_pictures)
        files += export(pred, speeds, tmp / "controller", drive=drive_for(spec))
    progress.done()
    r = study.report
    print(f"{spec.name}: ROM of FEM level {study.level} ({study.n_full} DOFs): "
          f"{rom.n_states} states, {study.runtime_s:.1f} s")
    print(f"  size chosen on {r.training_case} (dt {r.dt_s:g} s) as the smallest meeting "
          f"{args.tol_temp:g} K / {args.tol_growth:g} µm divided by {r.safety:g}"
          + ("" if r.chosen is not None else f": NONE of {r.sizes} did; the largest kept"))
    t = study.table()
    for i, case in enumerate(t["case"]):
        um = ", ".join(f"{k.split('_')[0]} {t[k][i]:.3g} µm" for k in t if k.endswith("_max_um"))
        print(f"  {case:<28} {t['kind'][i]:<9} {t['temperature_max_K'][i]:.3g} K, {um}")
    print(f"held-out cycles: {pass_fail(study.meets_all())} ({args.tol_temp:g} K at every "
          f"sensor, {args.tol_growth:g} µm on every growth reading)")
    print(f"controller export: {args.sample_time:g} s, {len(speeds)} speeds "
          f"(0..{speeds[-1]:g} rpm every {args.export_speed_step:g} rpm)")
    interp = json.loads((out / "controller" / "spindle_rom.json").read_text())["interpolation"]
    print(f"  between speeds (interpolated): outputs within "
          f"{interp['speed_staircase_K']:.2g} K, {interp['speed_staircase_m'] * 1e6:.2g} µm"
          + ("" if interp["losses_W"] is None else
             f"; losses from speed and torque within {interp['losses_W']:.2g} W"))
    print("wrote " + ", ".join(str(out / f.relative_to(tmp)) for f in files))
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    p = subparsers.add_parser(
        "rom", help="a reduced-order model of the FEM reference that meets given tolerances, "
                    "checked on held-out cycles and exported for a controller (C, JSON, NPZ)")
    add_spec(p)
    p.add_argument("--level", type=MESH_LEVEL, default=2,
                   help="FEM level of the reference (default 2, the ground truth of spl2782)")
    p.add_argument("--cycle", "--case", default="random-loaded:0", metavar="CYCLE[:SEED]",
                   help="training cycle: a shipped cycle, a cycle file, rated / rated-16h "
                        "(the spindle's rated point held, the paper's 16 h cycle at its rated "
                        "speed), or random / random-loaded with a seed, scaled to the "
                        "spindle's rated point (default random-loaded:0)")
    p.add_argument("--held-out", nargs="+", default=list(HELD_OUT), metavar="CYCLE[:SEED]",
                   help=f"cycles to check the ROM on (default {' '.join(HELD_OUT)}: for "
                        "spl2782 rated-16h and rated are spl-16h and nominal; a steady cycle "
                        "is a steady state)")
    p.add_argument("--dt", type=TIME_STEP_S, default=60.0,
                   help="time step of the FEM and ROM runs compared [s] (default 60)")
    p.add_argument("--tol-temp", type=POSITIVE, default=0.05,
                   help="tolerance on every sensor [K] (default 0.05)")
    p.add_argument("--tol-growth", type=POSITIVE, default=0.1,
                   help="tolerance on every growth reading [µm] (default 0.1)")
    p.add_argument("--safety", type=number(1.0, 100.0), default=2.0,
                   help="the training cycle must meet the tolerances divided by this "
                        "(default 2)")
    p.add_argument("--sample-time", type=TIME_STEP_S, default=1.0,
                   help="sample time of the controller export [s] (default 1)")
    p.add_argument("--export-speed-step", type=number(1.0, 10000.0), default=100.0,
                   help="the export tabulates the discrete step every this many rpm "
                        "(default 100)")
    add_out(p, "results/<spec>/rom")
    add_no_pictures(p)
    add_quiet(p)
    p.set_defaults(func=run)
    return p
