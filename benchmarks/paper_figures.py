"""The paper's SPL2782.1 figures reproduced by the FEM reference, for docs/paper.md.

    python benchmarks/paper_figures.py [--levels 1 2] [--out docs/figures/paper.json]

Per FEM level, what ``python -m compare.design.paper --level L`` prints (the losses, the
shaft and housing rises and the TCP growth at the nominal point, the spl-16h peaks T1 and P1,
K_T, K_Q and P1 at the nominal point) and the seconds it took. The figures go to ``--out``
(JSON with the date, the commit and the load average), from which docs/paper.md's table is
checked (tests/test_docs_figures.py); tests/test_stiffness.py reads K_T and K_Q from it.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from dataclasses import asdict
from pathlib import Path

from figures import write_figures

ROOT = Path(__file__).resolve().parents[1]


def one_level(level: int) -> dict:
    """The paper's figures on FEM ``level`` (SI and the units in the keys) and the runtime."""
    from compare.design.paper import PaperStudy

    t = time.perf_counter()
    fig = PaperStudy(level=level).figures()
    seconds = time.perf_counter() - t
    return {"level": level, **asdict(fig), "K_T_K_um": fig.K_T_K_um, "K_Q_W_um": fig.K_Q_W_um,
            "runtime_s": round(seconds, 1)}


def main(argv: list[str] | None = None) -> None:
    from compare.design.paper import PAPER_INDICATORS, TARGETS

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "paper.json")
    args = ap.parse_args(argv)
    rows = []
    for level in args.levels:
        r = one_level(level)
        rows.append(r)
        print(f"level {level}: T1 peak {r['T1_peak_C']:.2f} degC, P1 peak {r['P1_peak_um']:.2f} um, "
              f"TCP {r['TCP_um']:.1f} um, K_T {r['K_T_K_um']:.3f} K/um, "
              f"K_Q {r['K_Q_W_um']:.1f} W/um; {r['runtime_s']:.1f} s", flush=True)
    write_figures(args.out, " ".join(["python benchmarks/paper_figures.py",
                            *(argv if argv is not None else sys.argv[1:])]),
                  {"spec": "spl2782", "cores": os.cpu_count(),
                   "load_average": round(os.getloadavg()[0], 1), "targets": TARGETS,
                   "paper_indicators": PAPER_INDICATORS, "levels": rows})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
