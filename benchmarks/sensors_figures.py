"""The figures of docs/sensors.md and of rom.md's node-count section, on spl2782: the lumped
node count against the FEM reference (with the reduced-order model sized for the same
tolerances) and the sensor rankings.

    python benchmarks/sensors_figures.py [--out docs/figures/sensors.json]

What ``spindle-verify sensors spl2782 --rom --rank 11 [--method qr]
[--candidates housing T1 T2 T_stator]`` computes, through the same functions
(compare.verify.nodecount.choose_nodes and compare.verify.placement.rank_sensors): the node
count on the default cases (nominal, spl-16h; FEM level 2, dt 60 s) with the ROM, the
chosen N at other tolerances (NodeChoice.choose), and the greedy and QR rankings of all the
temperature sensors and of the stationary ones (spl-16h, FEM level 1, dt 300 s). Written
with the date and the commit; docs/sensors.md and docs/rom.md quote them
(tests/test_docs_study_figures.py). About 3 minutes on 2 cores, most of it the FEM level 2
transient and the ROM's build.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: (temperature K, growth µm) tolerances at which the chosen N is recorded
TOLERANCES = ((1.0, 1.5), (2.0, 1.5), (3.0, 1.5), (3.5, 1.5), (5.0, 1.5), (5.0, 3.0),
              (20.0, 3.0))
#: the sensors that do not rotate: what can be instrumented on a running spindle
STATIONARY = ("housing", "T1", "T2", "T_stator")


def ranking_figures(ranking) -> dict:
    """A ranking as the docs quote it: the order and the validation errors per k."""
    s = ranking.summary()
    return {"method": ranking.method, "candidates": list(ranking.candidates),
            "reference": s["reference"], "fit": s["fit"], "selected": list(ranking.selected),
            "table": s["table"], "runtime_s": ranking.runtime_s}


def main(argv: list[str] | None = None) -> None:
    from compare.verify.nodecount import choose_nodes
    from compare.verify.placement import rank_sensors
    from spindle.spec_reader import load_spec

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "sensors.json")
    args = ap.parse_args(argv)
    spec = load_spec("spl2782")
    t = time.perf_counter()
    choice = choose_nodes(spec, rom=True, progress=lambda m: print(m, file=sys.stderr))
    nodes = choice.summary()
    nodes["masses"] = choice.curves[0].masses
    nodes["text"] = choice.text()
    nodes["choose"] = [{"temperature_K": a, "growth_um": b, "chosen": choice.choose(a, b)}
                       for a, b in TOLERANCES]
    print(choice.text() + "\n" + choice.message(), flush=True)
    rankings = {}
    for label, cands in (("all", None), ("stationary", list(STATIONARY))):
        snap = None
        for method in ("greedy", "qr"):
            r = rank_sensors(spec, k_max=11, candidates=cands, method=method, snap=snap)
            snap = r.snap
            rankings[f"{label}_{method}"] = ranking_figures(r)
            print(f"{label} {method}: {', '.join(r.selected[:5])}", flush=True)
    write_figures(args.out, "python benchmarks/sensors_figures.py",
                  {"spec": spec.name, "nodes": nodes, "rankings": rankings,
                   "runtime_s": round(time.perf_counter() - t, 1)})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
