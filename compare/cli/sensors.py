"""``spindle-verify sensors``: how many lumped nodes a spec needs, and which sensors to measure."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    NODE_COUNT,
    POSITIVE,
    TIME_STEP_S,
    add_out,
    input_files,
    load_spec_with_sensors,
    number,
    out_folder,
    spec_files,
    with_progress,
)
from compare.verify.accuracy import (
    NODES,
    TOL_GROWTH_UM,
    TOL_TEMP_K,
)
from compare.verify.cases import load_cases
from compare.verify.nodecount import choose_nodes
from compare.verify.placement import METHODS, TRAIN_FRACTION, rank_sensors
from spindle.errors import InputError

if TYPE_CHECKING:
    from compare.progress import Progress


# ============================================================================ command line
@with_progress("sensors")
def run(args: argparse.Namespace, progress: Progress) -> int:
    """``spindle-verify sensors``: the node count, and with ``--rank K`` the sensor ranking.
    Returns the exit status (0; bad input raises :class:`spindle.errors.InputError`)."""
    from spindle.outputs import output_dir, safe_name

    spec = load_spec_with_sensors(args.spec)
    inputs = [*spec_files(spec), *input_files(*(args.cases or []), args.rank_case)]
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/sensors", inputs, force=args.force)
    say = progress.say
    cases = load_cases(spec, args.cases) if args.cases else None
    if args.rank is not None and args.rank < 1:
        raise InputError("command line", "--rank", f"{args.rank} sensors", "give --rank K >= 1")
    choice = choose_nodes(spec, cases, args.tol_temp, args.tol_growth, args.nodes, args.level,
                          args.dt, say, rom=args.rom)
    ranking = None
    if args.rank is not None:
        rank_case = (load_cases(spec, [args.rank_case], steady_cycles=False)[0]
                     if args.rank_case else None)
        say(f"FEM level {args.rank_level} transient for the sensor ranking "
            f"(dt {args.rank_dt:g} s)")
        ranking = rank_sensors(spec, rank_case, args.rank, args.candidates, None, args.method,
                               args.rank_level, args.rank_dt, args.tol_temp, args.tol_growth)
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        files = choice.save(tmp, pictures=not args.no_pictures)
        if ranking is not None:
            files += ranking.save(tmp, pictures=not args.no_pictures)
    progress.done()
    print(f"{spec.name}: lumped node count against {choice.curves[0].reference_label.split(',')[0]}"
          f" ({choice.runtime_s:.1f} s)")
    for c in choice.curves:
        print(f"  case {c.name}: {c.kind}, reference {c.reference_label}")
    print(choice.text())
    print(choice.message())
    if ranking is not None:
        print(f"sensor ranking ({ranking.method}, {ranking.case_name}, FEM level "
              f"{ranking.reference_level}, dt {ranking.dt_s:g} s): affine least squares fitted "
              f"on the first {ranking.n_train} samples ({100 * TRAIN_FRACTION:g} %), errors on "
              f"the last {ranking.n_valid} (from t = {ranking.split_time_s / 3600:.2f} h):")
        print(ranking.text())
    print("wrote " + ", ".join(str(out / f.name) for f in files))
    return 0


def register(subparsers) -> argparse.ArgumentParser:
    """Add the ``sensors`` command to ``subparsers`` (from ``add_subparsers``); its
    ``func`` is :func:`run`."""
    p = subparsers.add_parser(
        "sensors", help="the lumped node count that meets the tolerances on every case, and "
                        "a ranking of sensor positions that reconstruct shaft temperature and P1")
    p.add_argument("spec", metavar="SPEC")
    p.add_argument("--tol-temp", type=POSITIVE, default=TOL_TEMP_K,
                   help=f"tolerance on the worst sensor temperature error [K] (default "
                        f"{TOL_TEMP_K:g})")
    p.add_argument("--tol-growth", type=POSITIVE, default=TOL_GROWTH_UM,
                   help=f"tolerance on the P1 error [um] (default {TOL_GROWTH_UM:g})")
    p.add_argument("--nodes", type=NODE_COUNT, nargs="+", default=list(NODES),
                   help="lumped node counts (default " + " ".join(map(str, NODES)) + ")")
    p.add_argument("--cases", nargs="+", metavar="CYCLE",
                   help="shipped cycle names, rated / rated-16h (the spindle's own rating) or "
                        "cycle files; a steady cycle (nominal, rated) is a steady state, the "
                        "others transients (default: the study's two cases, rated and "
                        "rated-16h: for spl2782 nominal and spl-16h)")
    p.add_argument("--level", type=MESH_LEVEL, default=2,
                   help="FEM level of the reference for the node count (default 2)")
    p.add_argument("--dt", type=TIME_STEP_S, default=60.0,
                   help="time step of the transient cases [s] (default 60)")
    p.add_argument("--rom", action="store_true",
                   help="also consider a reduced-order model of the reference level sized for "
                        "the tolerances (spindle-verify rom; 40-100 s more at level 2)")
    p.add_argument("--rank", type=number(1, 1000, integer=True), metavar="K",
                   help="also rank the first K sensor positions")
    p.add_argument("--method", choices=METHODS, default="greedy",
                   help="ranking: greedy forward selection (default) or pivoted QR")
    p.add_argument("--candidates", nargs="+", metavar="NAME",
                   help="ranking: candidate sensors or arrays (default: every temperature "
                        "sensor of the spec)")
    p.add_argument("--rank-case", metavar="CYCLE",
                   help="ranking: transient cycle (default: the study's transient case)")
    p.add_argument("--rank-level", type=MESH_LEVEL, default=1,
                   help="ranking: FEM level (default 1)")
    p.add_argument("--rank-dt", type=TIME_STEP_S, default=300.0,
                   help="ranking: time step [s] (default 300)")
    add_out(p, "results/<spec>/sensors")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNGs")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=run)
    return p
