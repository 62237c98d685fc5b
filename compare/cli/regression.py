"""``spindle-verify baseline`` and ``check``: store a study's figures as a baseline, check
them later."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    NODE_COUNT,
    POSITIVE,
    TIME_STEP_S,
    add_quiet,
    add_spec,
    input_files,
    load_spec_with_sensors,
    spec_files,
    with_progress,
)

if TYPE_CHECKING:
    from compare.progress import Progress


@with_progress("baseline")
def _cmd_baseline(args: argparse.Namespace, progress: Progress) -> int:
    from compare.verify.regression import make_baseline
    from spindle.outputs import check_output_file, write_output_file

    spec = load_spec_with_sensors(args.spec)  # validates before the long run
    out = check_output_file(args.out, input_files(*spec_files(spec)), args.force)
    settings = {"levels": sorted(set(args.levels)), "nodes": sorted(set(args.nodes)),
                "dt_s": args.dt, "transient": not args.steady_only}
    tolerances = {"temperature_K": args.tol_temp, "growth_um": args.tol_growth}
    doc = make_baseline(args.spec, settings, tolerances, progress.say)
    write_output_file(out, lambda tmp: tmp.write_text(json.dumps(doc, indent=1) + "\n", "utf-8"),
                      force=args.force)
    progress.done()
    print(f"{spec.name}: {len(doc['figures'])} figures in {doc['created_with_runtime_s']:.1f} s; "
          f"wrote {out}")
    return 0


@with_progress("check")
def _cmd_check(args: argparse.Namespace, progress: Progress) -> int:
    from compare.verify.regression import check, read_baseline
    from spindle.errors import InputError, SpindleVerifyError
    from spindle.spec_reader import load_spec

    doc = read_baseline(args.file)
    try:  # the spec the baseline names: its problem is the baseline's field, named as such
        load_spec(doc["spec"])
    except SpindleVerifyError as exc:
        raise InputError(args.file, "spec", f"names {doc['spec']!r}, which is no spec it can "
                         f"read ({str(exc).splitlines()[0]})", "give the name of a shipped "
                         "spec or the path of the spec the baseline was written from"
                         ) from None
    changes = check(doc, progress=progress.say)
    progress.done()
    moved = [c for c in changes if c.moved]
    if moved:
        print(f"{args.file}: {len(moved)} of {len(changes)} figures moved beyond their "
              "tolerance:")
        for c in moved:
            print(c.line())
        return 1
    print(f"{args.file}: all {len(changes)} figures within their tolerances")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    bp = subparsers.add_parser("baseline", help="store the figures of a study (values, errors, "
                        "tolerances) as JSON for regression checks")
    add_spec(bp)
    bp.add_argument("--out", required=True, help="the JSON file to write; a run replaces what "
                    "an earlier run wrote there and refuses a file of yours")
    bp.add_argument("--force", action="store_true", help="write over a file at --out that "
                    "spindle-verify did not write: it is moved aside to "
                    "'<name>.kept-<time>.json', never deleted")
    bp.add_argument("--levels", type=MESH_LEVEL, nargs="+", default=[0, 1, 2],
                    help="FEM levels, three or more (default 0 1 2)")
    bp.add_argument("--nodes", type=NODE_COUNT, nargs="+", default=[5, 11],
                    help="lumped node counts (default 5 11)")
    bp.add_argument("--dt", type=TIME_STEP_S, default=300.0, help="transient time step [s] (300)")
    bp.add_argument("--steady-only", action="store_true", help="skip the transient figures")
    bp.add_argument("--tol-temp", type=POSITIVE, default=0.01,
                    help="how far a temperature may move [K] (default 0.01)")
    bp.add_argument("--tol-growth", type=POSITIVE, default=0.01,
                    help="how far a growth may move [um] (default 0.01)")
    add_quiet(bp)
    bp.set_defaults(func=_cmd_baseline)

    cp = subparsers.add_parser("check", help="recompute a baseline's figures; exit 1 with a diff when "
                        "any moved beyond its tolerance")
    cp.add_argument("file", metavar="FILE")
    add_quiet(cp)
    cp.set_defaults(func=_cmd_check)
