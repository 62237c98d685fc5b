"""``spindle-verify measures``: the paper's thermal stiffness strategy (indicators, design
measures, inverse problems, sweeps)."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    WORKERS,
    add_no_pictures,
    add_out,
    add_quiet,
    add_spec,
    load_case_input,
    number,
    out_folder,
    spec_files,
    with_progress,
)
from spindle.errors import InputError

if TYPE_CHECKING:
    from compare.progress import Progress


@with_progress("measures")
def _cmd_measures(args: argparse.Namespace, progress: Progress) -> int:
    from compare.design.measure_file import read_measures, shipped_measures
    from compare.design.report import run_measures
    from lumped.build import PRESETS
    from spindle.drive import load_case
    from spindle.outputs import output_dir, safe_name
    from spindle.spec_reader import load_spec

    spec = load_spec(args.spec)
    inputs = spec_files(spec)
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/measures", inputs, force=args.force)
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
    inputs.append(str(mpath))
    if args.case:
        case = load_case_input(spec, args.case, case, inputs)
    elif spec.power_preset:  # the spindle's rated point (the SPL2782.1's: nominal)
        case = load_case(spec, "rated", case)
    rep = run_measures(spec, mfile, case, args.level, tuple(args.lumped_nodes),
                       sweeps=not args.no_sweeps, points=args.points or 7,
                       scheduler=args.scheduler, workers=args.workers,
                       progress=progress.say)
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        files = rep.save(tmp, pictures=not args.no_pictures)
    progress.done()
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


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    me = subparsers.add_parser("measures", help="thermal stiffness strategy (paper section 4): "
                        "indicators K_alpha, K_T, K_Q from the FEM and lumped models; design "
                        "measures by the formulas (eq. 25-30) and by the FEM; inverse problem; "
                        "Fig. 15 and Fig. 16-style sensitivity sweeps")
    add_spec(me)
    me.add_argument("--measures", metavar="FILE",
                    help="measures TOML (docs/measures.md); default: the spec's shipped file, "
                         "spindle/data/measures/<spec>.toml (there is one for spl2782)")
    me.add_argument("--case", metavar="CYCLE",
                    help="steady load case from a cycle's first step (default: 'nominal' for a "
                         "spec with a power balance, else the spec's own inputs)")
    me.add_argument("--level", type=MESH_LEVEL, default=1, help="FEM mesh level (default 1)")
    me.add_argument("--nodes", dest="lumped_nodes", nargs="+", default=["paper5", "paper11"],
                    metavar="N", help="lumped models for the indicators and the measures: "
                                      "integers >= 2 or paper5 / paper11 (default paper5 paper11)")
    me.add_argument("--points", type=number(2, 10000, integer=True),
                    help="points per sensitivity sweep (default: the file's, else 7)")
    me.add_argument("--no-sweeps", action="store_true", help="skip the Fig. 16 sweeps")
    me.add_argument("--scheduler", metavar="ADDRESS",
                    help="run the cases on a Dask cluster (tcp://host:8786, or 'local'); needs "
                         "pip install \"spindle-verify[dask]\" (default: a local process pool)")
    me.add_argument("--workers", type=WORKERS,
                    help="processes (default min(2, CPUs)); 1 runs the cases serially")
    add_out(me, "results/<spec>/measures")
    add_no_pictures(me)
    add_quiet(me)
    me.set_defaults(func=_cmd_measures)
