"""``spindle-verify mesh``: meshes of a spec at refinement levels 0..N."""

from __future__ import annotations

import argparse
import json
from typing import TYPE_CHECKING

from compare.cli.common import (
    MESH_LEVEL,
    add_no_pictures,
    add_out,
    add_quiet,
    add_spec,
    out_folder,
    spec_files,
    with_progress,
)

if TYPE_CHECKING:
    from compare.progress import Progress


@with_progress("mesh")
def _cmd_mesh(args: argparse.Namespace, progress: Progress) -> int:
    from meshes import build_mesh
    from meshes.build import check_level
    from meshes.io import mesh_png, save_mesh_vtu
    from spindle.outputs import output_dir, safe_name
    from spindle.spec_reader import load_spec

    spec = load_spec(args.spec)
    inputs = spec_files(spec)
    out = out_folder(args.out, f"results/{safe_name(spec.name)}/mesh", inputs, force=args.force)
    check_level(spec, args.level)  # before levels 0 .. N - 1 are made
    rows = []
    print(f"{'level':>5} {'elements':>9} {'nodes':>8} {'dofs_P1':>8} {'dofs_P2':>8} {'h_max_mm':>9}")
    for level in range(args.level + 1):
        progress.stage(f"meshing level {level} of {args.level}", level / (args.level + 1))
        sm = build_mesh(spec, level)
        c1, c2 = sm.counts(1), sm.counts(2)
        rows.append({**c2, "dofs_P1": c1["dofs_P1"], "h_max_m": sm.h_max_m})
        print(f"{level:5d} {c2['elements']:9d} {c2['nodes']:8d} {c1['dofs_P1']:8d} "
              f"{c2['dofs_P2']:8d} {sm.h_max_m * 1e3:9.3f}")
    with output_dir(out, inputs=inputs, force=args.force) as tmp, progress.pictures():
        save_mesh_vtu(sm, tmp / f"mesh_level{args.level}.vtu")
        (tmp / "mesh.json").write_text(json.dumps(
            {"spec": spec.name, "parts": sm.part_names, "levels": rows,
             "surfaces": {k: int(len(v)) for k, v in sm.surfaces.items()}}, indent=2) + "\n")
        if not args.no_pictures:
            mesh_png(sm, tmp / f"mesh_level{args.level}.png")
    progress.done()
    print(f"wrote {out}/mesh_level{args.level}.vtu, mesh.json"
          + ("" if args.no_pictures else f", mesh_level{args.level}.png"))
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the command's sub-parser."""
    mp = subparsers.add_parser("mesh", help="mesh a spec at refinement levels 0..N; VTU and PNG")
    add_spec(mp)
    mp.add_argument("--level", type=MESH_LEVEL, default=2, help="finest level (default 2)")
    add_out(mp, "results/<spec>/mesh")
    add_no_pictures(mp, "PNG")
    add_quiet(mp)
    mp.set_defaults(func=_cmd_mesh)
