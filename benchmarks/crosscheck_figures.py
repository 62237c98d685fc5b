"""The cross-check's figures for docs/crosscheck.md: the FEM reference against CalculiX on the
same P2 mesh, steady, for fin-shaft at levels 0-3 and spl2782 at levels 0-2 (the spec's own
operating point), and spl2782 at level 0 on the nominal cycle point.

    python benchmarks/crosscheck_figures.py [--out docs/figures/crosscheck.json]

Each run is ``compare.crosscheck.crosscheck(spec, level, case)``, what
``spindle-verify crosscheck SPEC --level L [--case nominal]`` runs and saves as
crosscheck.json; this script keeps of each the mesh, the largest differences at the sensors
and over the nodes (against ccx and against the quadrature twin), the growth readings of both
codes with the twin's and the print bounds, and the timings, with the date, the commit and
the ccx version. docs/crosscheck.md quotes them (tests/test_docs_study_figures.py).
Needs ``ccx`` (apt-get install calculix-ccx); without it, one message and exit status 2.
"""

from __future__ import annotations

import argparse
import shutil
import sys
import time
from pathlib import Path

from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: (spec, levels) of the agreement table; the nominal point runs on spl2782 level 0
RUNS = (("fin-shaft", (0, 1, 2, 3)), ("spl2782", (0, 1, 2)))


def one_run(spec_name: str, level: int, case_name: str | None = None) -> dict:
    """One cross-check, as the figures docs/crosscheck.md quotes."""
    from compare.cli.common import load_case_input
    from compare.crosscheck import crosscheck
    from spindle.spec_reader import load_spec

    spec = load_spec(spec_name)
    case = (None if case_name is None
            else load_case_input(spec, case_name, spec.default_load_case(), []))
    t = time.perf_counter()
    res = crosscheck(spec, level, case)
    wall = time.perf_counter() - t
    s = res.summary()
    g = res.growth_table()
    used = case or spec.default_load_case()
    heat = sum(float(used.sources[h.name](0.0)) if h.name in used.sources else h.power_W(0)
               for h in spec.heat_sources)
    sensors = res.sensor_table()
    return {"spec": spec_name, "level": level, "case": s["case"], "speed_rpm": s["speed_rpm"],
            "heat_W": heat, "nodes": s["mesh"]["nodes"], "elements": s["mesh"]["elements"],
            "solver": s["solver"],
            "sensors_max_abs_diff_K": s["max_abs_diff_K"],
            "sensors_max_abs_ccx_minus_twin_K": max(abs(v) for v in
                                                    sensors["ccx_minus_twin_K"]),
            "nodal": s["nodal"],
            "growth": {k: {c: g[c][i] for c in g if c != "reading"}
                       for i, k in enumerate(g["reading"])},
            "timings_s": s["timings_s"], "wall_s": wall}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "crosscheck.json")
    args = ap.parse_args(argv)
    if shutil.which("ccx") is None:
        print("error: ccx not found; install the Debian package calculix-ccx "
              "(apt-get install calculix-ccx)", file=sys.stderr)
        sys.exit(2)
    runs = []
    for spec_name, levels in RUNS:
        for level in levels:
            runs.append(one_run(spec_name, level))
            r = runs[-1]
            print(f"{spec_name} level {level}: {r['nodes']} nodes, sensors "
                  f"{r['sensors_max_abs_diff_K']:.1e} K, nodes {r['nodal']['max_abs_diff_K']:.2e} K"
                  f", {r['wall_s']:.1f} s", flush=True)
    nominal = one_run("spl2782", 0, "nominal")
    print(f"spl2782 level 0, nominal: sensors {nominal['sensors_max_abs_diff_K']:.1e} K")
    write_figures(args.out, "python benchmarks/crosscheck_figures.py",
                  {"runs": runs, "nominal": nominal})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
