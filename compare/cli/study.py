"""``spindle-verify study``: the verification study: grid convergence, accuracy, verdicts, report."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    NODE_COUNT,
    POSITIVE,
    TIME_STEP_S,
    WORKERS,
    add_no_pictures,
    add_out,
    add_quiet,
    add_spec,
    load_spec_with_sensors,
    out_folder,
    pass_fail,
    spec_files,
    with_progress,
)
from spindle.errors import InputError

if TYPE_CHECKING:
    from compare.progress import Progress


@with_progress("study")
def _cmd_study(args: argparse.Namespace, progress: Progress) -> int:
    from compare.report import fmt
    from compare.verify.accuracy import worst_temperature_K
    from compare.verify.study import run_study
    from spindle.outputs import output_dir, safe_name
    from spindle.plots import levels_text

    spec = load_spec_with_sensors(args.spec)
    inputs = spec_files(spec)
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/study", inputs, force=args.force)
    if args.workers < 1:
        raise InputError("command line", "--workers", f"{args.workers} is below 1",
                         "give --workers 1 (serial) or more")
    levels, nodes = sorted(set(args.levels)), sorted(set(args.nodes))
    result = run_study(spec, levels, nodes, transient=not args.steady_only, dt_s=args.dt,
                       threshold=args.threshold / 100.0, progress=progress.say, workers=args.workers,
                       scheduler=args.scheduler, rom=args.rom)
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        result.save(tmp, pictures=not args.no_pictures)
    progress.done()
    conv = result.convergence
    gt = result.ground_truth_level
    print(f"{spec.name}: verification study, {result.runtime_s:.1f} s; {result.cases_text()}")
    print(f"FEM grid convergence ({conv.case_name}, levels {levels_text(conv.levels)}, "
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
                  f"{fmt(worst, '.3f'):>14} {fmt(p1, '.3f'):>10} "
                  f"{t['runtime_s'][i]:10.3f}  "
                  f"{pass_fail(t['meets_tolerances'][i], t['borderline'][i])}")
        slopes = acc.slopes()
        if slopes:
            print("  fitted slopes of error against unknowns: "
                  + ", ".join(f"{k} {v:.2f}" for k, v in slopes.items()))
    for f in result.failures:
        print(f"  FAILED {f['label']}: {f['error']}")
    print(result.headline())
    print(f"wrote {out}/report.html (and tables, plots, JSON)")
    return 1 if result.failures else 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    st = subparsers.add_parser("study", help="verification study: FEM grid convergence (GCI), accuracy "
                        "of eq. 14, the lumped models and the FEM levels, HTML report")
    add_spec(st)
    st.add_argument("--levels", type=MESH_LEVEL, nargs="+", default=[0, 1, 2, 3],
                    help="nested FEM levels, three or more (default 0 1 2 3)")
    st.add_argument("--nodes", type=NODE_COUNT, nargs="+", default=[2, 3, 5, 7, 11, 15, 21, 31, 41],
                    help="lumped node counts (default 2 3 5 7 11 15 21 31 41)")
    st.add_argument("--threshold", type=POSITIVE, default=1.0,
                    help="GCI [%%] a level must meet for every quantity to be the ground truth "
                         "(default 1)")
    st.add_argument("--dt", type=TIME_STEP_S, default=60.0,
                    help="transient time step [s]: every model is read every dt and 1-64 s after "
                         "each step; the reference is exact in time (default 60)")
    st.add_argument("--steady-only", action="store_true", help="skip the transient comparison")
    st.add_argument("--rom", action="store_true",
                    help="add a reduced-order model of the reference level (spindle-verify rom, "
                         "0.05 K / 0.1 µm) as a row of the tables; 40-100 s more on "
                         "spl2782 (default off)")
    st.add_argument("--scheduler", metavar="ADDRESS",
                    help="run the independent runs on a Dask cluster (tcp://host:8786, or "
                         "'local' with --workers processes); needs "
                         "pip install \"spindle-verify[dask]\" (default: no cluster)")
    st.add_argument("--workers", type=WORKERS, default=1,
                    help="processes for the independent runs (the lumped models, the FEM "
                         "transients): 1 runs them serially in this process, so the runtimes "
                         "in the tables are not disturbed by other runs (default 1); 2 runs "
                         "the independent runs in a process pool")
    add_out(st, "results/<spec>/study")
    add_no_pictures(st)
    add_quiet(st)
    st.set_defaults(func=_cmd_study)
