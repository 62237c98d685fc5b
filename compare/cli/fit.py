"""``spindle-verify fit``: fit a bench run: calibrate, diagnose the residual, name the effects it supports."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from compare.cli.common import (
    WORKERS,
    add_no_pictures,
    add_out,
    add_quiet,
    number,
    out_folder,
    spec_files,
    with_progress,
)
from compare.executor import default_workers
from spindle.errors import InputError

if TYPE_CHECKING:
    from compare.progress import Progress

def _criterion(name: str, *, integer: bool = False, percent: bool = False):
    """An argparse ``type`` for the criterion ``name``: what compare/fit/criteria.toml's entry
    allows (its range, less the values it excludes; ``percent``: a share given in %)."""
    from compare.fit.criteria import Criteria

    lo, hi = Criteria.range_of(name)
    k = 100.0 if percent else 1.0
    parse = number(lo * k, hi * k, integer=integer)

    def checked(text: str):
        value = parse(text)
        try:
            Criteria.checked(name, value / k if percent else value)
        except InputError as err:
            raise argparse.ArgumentTypeError(f"{err.problem.message}; {err.problem.fix}") from None
        return value

    return checked


#: compare.fit.greybox.MAX_NODES (not imported: numpy)
FIT_NODES_MAX = 161
FIT_NODE_COUNT = number(2, FIT_NODES_MAX, integer=True)


def _base_extra(names: list[str] | None) -> tuple[str, ...] | None:
    """--base-extra as run_fit takes it: None (not given) for the default, () for none."""
    if names is None:
        return None
    if "none" in names and len(names) > 1:
        raise InputError("command line", "--base-extra", "none with other parameters",
                         "give either none or the parameters")
    return tuple(n for n in names if n != "none")


@with_progress("fit")
def _cmd_fit(args: argparse.Namespace, progress: Progress) -> int:
    from compare.fit.criteria import Criteria
    from compare.fit.report import save_report, summary_text
    from compare.fit.run import run_fit
    from spindle.outputs import output_dir, safe_name
    from spindle.spec_reader import load_spec

    base_extra = _base_extra(args.base_extra)
    spec = load_spec(args.spec)
    criteria = Criteria().with_file(args.criteria) if args.criteria else None
    inputs = [*spec_files(spec), args.run, *([args.criteria] if args.criteria else [])]
    default = f"results/{safe_name(spec.name)}/fit-{safe_name(Path(args.run).stem)}"
    out = out_folder(args.out, default, inputs, force=args.force)
    rep = run_fit(args.run, spec, args.fit_fraction, args.alpha, args.nodes,
                  candidates=args.candidates,
                  min_gain=None if args.min_gain is None else args.min_gain / 100.0,
                  progress=progress.say,
                  fem_level=None if args.lumped_only else args.fem_level,
                  base_extra=base_extra, blocks=args.blocks,
                  cv_blocks=args.cv_blocks, criteria=criteria, workers=args.workers)
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        save_report(rep, tmp, pictures=not args.no_pictures)
        # composed before the outputs are committed: it reads the spec's drive again, and a
        # refusal then must leave no report behind
        text = summary_text(rep)
    progress.done()
    print(text)
    print(f"wrote {out}/report.json, {out}/report.html")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    from compare.fit.criteria import Criteria
    from compare.fit.effects import LIBRARY
    from compare.fit.params import DEFAULT_BASE_EXTRA, EXTRA_BASE_PARAMS

    table = Criteria()
    fp = subparsers.add_parser("fit", help="fit a bench run: calibrate, diagnose the residual, add the "
                        "effects it supports, report the error before and after")
    fp.add_argument("run", metavar="RUN.csv", help="bench export (format: docs/bench.md)")
    fp.add_argument("--spec", default="spl2782", help="the spindle (default spl2782)")
    add_out(fp, "results/<spec>/fit-<run>")
    fp.add_argument("--fit-fraction", type=number(0.2, 0.9), default=0.6,
                    help="fraction of the run used for fitting; the rest validates (0.6)")
    fp.add_argument("--blocks", type=number(1, 20, integer=True), default=1,
                    help="windows for selecting effects: cut the run into this many blocks, "
                    "of which about 1 - fit-fraction, spread over the run, validate (default "
                    "1: the fit window is the run's start; docs/fit.md says why)")
    fp.add_argument("--cv-blocks", type=_criterion("cv_blocks", integer=True),
                    help="blocked cross-validation of the base and the final model: each of "
                    "this many blocks held out in turn, the model refitted without it and "
                    f"simulated over it (default {table.cv_blocks}; 0: none, and then only "
                    "an effect with a signature test in the raw samples can be named, as the "
                    "others' evidence is the cross-validated prediction)")
    fp.add_argument("--alpha", type=_criterion("alpha"),
                    help="the level of every test: an effect's likelihood-ratio test, the "
                    "signature tests, the competitor's scan (against the same scan on noise) and the "
                    "plausible range of the base parameters (default "
                    f"{table.alpha:g}; {' to '.join(f'{v:g}' for v in table.range_of('alpha'))}, "
                    "the table's range)")
    fp.add_argument("--min-gain", type=_criterion("cv_gain", percent=True),
                    help="an effect judged by the open-loop fit must remove at least this "
                    "share [%%] of the blocked cross-validated error above the noise floor on "
                    f"its channels (default {100 * table.cv_gain:g})")
    fp.add_argument("--criteria", metavar="FILE.toml",
                    help="criteria of your own: a TOML file of name = value lines, or an "
                    "edited copy of the table compare/fit/criteria.toml, with its names, units "
                    "and types (the report lists the table it ran with); --alpha, --min-gain "
                    "and --cv-blocks override it")
    fp.add_argument("--fem-level", type=number(0, 4, integer=True), default=0,
                    help="FEM reference level that anchors the model on the run's inputs "
                    "(default 0; docs/fit.md)")
    fp.add_argument("--lumped-only", action="store_true",
                    help="no FEM anchor and no priors: the lumped model alone, factors from "
                    "1 (faster; effects the base parameters can imitate go unnamed)")
    fp.add_argument("--base-extra", nargs="+", metavar="PARAM",
                    choices=(*EXTRA_BASE_PARAMS, "none"),
                    help="the extra base parameters to calibrate, for a spindle its spec "
                    "describes only approximately: G_seat_W_K (a conductance from the bearing "
                    "rings to the coolant), axial_scale (every axial length times s), "
                    "heat_capacity (a factor on every heat capacity), "
                    "friction_exponent (bearing friction times (n / 3000 rpm)^e), or none "
                    f"(default: {' '.join(DEFAULT_BASE_EXTRA)}; "
                    "docs/fit.md)")
    fp.add_argument("--nodes", type=FIT_NODE_COUNT, default=11,
                    help=f"lumped model nodes (default 11; at most {FIT_NODES_MAX}: time and memory "
                    "grow fast with them, on a 16 h run about 45 s and 1.3 GB at 81 nodes, 4 min "
                    "and 4.5 GB at 161)")
    fp.add_argument("--workers", type=WORKERS, default=default_workers(),
                    help="processes that share each calibration's finite-difference columns "
                    "(forked copies of this one, on Linux; the report is the same to the "
                    "last bit with any number; 1: this process alone; default "
                    f"{default_workers()} here, min(2, CPUs))")
    fp.add_argument("--candidates", nargs="+", choices=list(LIBRARY), metavar="EFFECT",
                    help="candidate effects (default: the whole library: "
                    f"{', '.join(LIBRARY)})")
    add_no_pictures(fp)
    add_quiet(fp)
    fp.set_defaults(func=_cmd_fit)
