"""``spindle-verify synth``: a synthetic bench run from the FEM reference with effects injected."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    add_quiet,
    input_files,
    number,
    spec_files,
    with_progress,
)
from spindle.errors import InputError

if TYPE_CHECKING:
    from compare.progress import Progress


@with_progress("synth")
def _cmd_synth(args: argparse.Namespace, progress: Progress) -> int:
    from compare.fit.effects import LIBRARY
    from compare.synth.bench import synth
    from compare.synth.losslaw import LOSS_LAWS
    from compare.synth.outside import OUTSIDE
    from spindle.spec_reader import load_spec

    spec = load_spec(args.spec)
    known = [*LIBRARY, "clean", *OUTSIDE, *LOSS_LAWS]
    bad = [e for e in args.effect if e not in known]
    if bad:
        raise InputError("command line", "--effect", f"unknown effect '{bad[0]}'",
                         f"use one of {', '.join(known)}")
    from functools import partial

    from spindle.outputs import check_output_file, write_output_file

    out = Path(args.out)
    if out.suffix.lower() != ".csv":
        raise InputError(str(out), "--out", "is not a .csv file name", "give e.g. run.csv")
    inputs = input_files(args.cycle, *spec_files(spec))
    for path in (out, out.with_suffix(".truth.json")):
        check_output_file(path, inputs, args.force)
    progress.stage(f"FEM level {args.level} run of '{args.cycle}' with "
                   f"{' and '.join(args.effect)}")
    effects = args.effect[0] if len(args.effect) == 1 else args.effect
    truth = synth(spec, args.cycle, effects, args.seed, out, level=args.level,
                  mismatch=args.mismatch, write=partial(write_output_file, force=args.force))
    progress.done()
    print(f"wrote {out} and {out.with_suffix('.truth.json')} (effect {truth['effect']}, "
          f"seed {truth['seed']})")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    sy = subparsers.add_parser("synth", help="a synthetic bench run from the FEM reference with one "
                        "effect injected; the truth goes to RUN.truth.json")
    from compare.fit.effects import LIBRARY
    from compare.synth.losslaw import LOSS_LAWS
    from compare.synth.outside import OUTSIDE

    sy.add_argument("--spec", default="spl2782",
                    help="the spindle the data come from: a shipped name or a spec file "
                         "(default spl2782)")
    sy.add_argument("--cycle", default="spl-16h",
                    help="cycle: a shipped name or cycle file, or random / random-loaded / "
                         "random-ramped-load (non-monotonic steps up to 6000 rpm drawn from the "
                         "seed; the last ramps the load within each speed step, as a loaded "
                         "bench run does) (default spl-16h)")
    sy.add_argument("--effect", default=["clean"], nargs="+", metavar="EFFECT",
                    help="effects to inject, together: clean (none, the default), the fit's "
                         f"library ({', '.join(LIBRARY)}) or causes outside it "
                         f"({', '.join(OUTSIDE)}, which fit should report unexplained) or "
                         f"loss laws the spec lacks ({', '.join(LOSS_LAWS)}, for which fit "
                         "should name nothing)")
    sy.add_argument("--seed", type=number(0, 2**32 - 1, integer=True), default=0,
                    help="random seed: the effect's magnitude, the noise and sampling, and "
                         "with --mismatch or a random cycle their draws (default 0)")
    sy.add_argument("--level", type=MESH_LEVEL, default=1, help="FEM level (default 1)")
    sy.add_argument("--mismatch", action="store_true",
                    help="make the data with a spindle that differs from the spec (films, "
                         "contacts, axial length, friction, loss split, FEM level; drawn from "
                         "the seed and recorded in the truth; docs/fit.md)")
    sy.add_argument("--out", required=True, help="the CSV to write (and RUN.truth.json beside "
                    "it); a run replaces what an earlier run wrote there and refuses a file of "
                    "yours")
    sy.add_argument("--force", action="store_true", help="write over a file at --out that "
                    "spindle-verify did not write: it is moved aside to "
                    "'<name>.kept-<time>.csv', never deleted")
    add_quiet(sy)
    sy.set_defaults(func=_cmd_synth)
