"""``spindle-verify crosscheck``: the FEM reference against CalculiX (ccx) on the same P2 mesh."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    add_out,
    add_quiet,
    add_spec,
    load_case_input,
    load_spec_with_sensors,
    out_folder,
    spec_files,
    with_progress,
)
from spindle.units import ZERO_C_K

if TYPE_CHECKING:
    from compare.crosscheck import CrosscheckResult
    from compare.progress import Progress


def _print_comparison(spec_name: str, result: CrosscheckResult) -> None:
    """Sensor temperatures [°C] and growth readings [µm] of both codes and their differences."""
    s = result.summary()
    print(f"{spec_name}: scikit-fem reference against CalculiX {result.ccx_version}, P2 level "
          f"{result.level} ({s['mesh']['nodes']} nodes, {s['mesh']['elements']} elements), "
          f"case '{result.case}' at {result.speed_rpm:g} rpm")
    print(f"  {'sensor':<16} {'T_skfem_C':>10} {'T_ccx_C':>10} {'diff_K':>10}")
    for i, n in enumerate(result.sensors):
        print(f"  {n:<16} {result.T_skfem_K[i] - ZERO_C_K:10.4f} {result.T_ccx_K[i] - ZERO_C_K:10.4f} "
              f"{result.diff_K[i]:10.1e}")
    if result.growth_skfem_m:
        print(f"  {'reading':<16} {'skfem_um':>10} {'ccx_um':>10} {'diff_um':>10}")
        for k, v in result.growth_skfem_m.items():
            c = result.growth_ccx_m[k]
            print(f"  {k + '_um':<16} {v * 1e6:10.4f} {c * 1e6:10.4f} {(c - v) * 1e6:10.1e}")
    print(f"max |T_ccx - T_skfem| = {s['max_abs_diff_K']:.1e} K at the sensors, "
          f"{result.nodal['max_abs_diff_K']:.1e} K over all nodes; against the reference "
          f"with ccx's quadrature {result.nodal['max_abs_ccx_minus_twin_K']:.1e} K (print "
          f"precision {result.nodal['max_print_bound_K']:.1e} K)")


@with_progress("crosscheck")
def _cmd_crosscheck(args: argparse.Namespace, progress: Progress) -> int:
    """``spindle-verify crosscheck``: print the comparison table, write JSON and CSV."""
    # imported here so that building the parser stays fast (compare/cli/common.py)
    from compare.crosscheck import crosscheck
    from spindle.outputs import output_dir, safe_name

    spec = load_spec_with_sensors(args.spec)
    inputs = spec_files(spec)
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/crosscheck", inputs,
                     force=args.force)
    case = (None if args.case is None
            else load_case_input(spec, args.case, spec.default_load_case(), inputs))
    progress.stage(f"solving level {args.level} with scikit-fem and with CalculiX")
    with output_dir(out, inputs=inputs, force=args.force) as tmp:
        result = crosscheck(spec, args.level, case,
                            keep_dir=(tmp / "ccx") if args.keep_deck else None)
        files = result.save(tmp)
    progress.done()
    _print_comparison(spec.name, result)
    print("wrote " + ", ".join(str(out / f.name) for f in files)
          + (f", {out / 'ccx'}/" if args.keep_deck else ""))
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``crosscheck SPEC [--level N] [--case CYCLE] [--out DIR] [--keep-deck]``."""
    cp = subparsers.add_parser(
        "crosscheck", help="cross-check the FEM reference with CalculiX (ccx) on the same P2 "
                           "mesh: sensor temperatures and axial growth (P1, TCP)",
        description="Cross-check the FEM reference with CalculiX (ccx, Debian package "
                    "calculix-ccx) on the same P2 mesh: sensor temperatures and axial growth "
                    "(P1, TCP) from both codes and their differences.")
    add_spec(cp)
    cp.add_argument("--level", type=MESH_LEVEL, default=1, help="mesh level (default 1)")
    cp.add_argument("--case", metavar="CYCLE",
                    help="steady load case from a cycle's first step, e.g. 'nominal' (default: "
                         "the spec's operating point)")
    add_out(cp, "results/<spec>/crosscheck")
    cp.add_argument("--keep-deck", action="store_true",
                    help="keep the ccx decks, result files and logs in <out>/ccx")
    add_quiet(cp)
    cp.set_defaults(func=_cmd_crosscheck)
