"""The console entry point of ``spindle-verify``.

The command line works on small dense matrices (lumped networks of tens of masses, thousands
of times in a fit), where a multi-threaded BLAS spends more time synchronising its threads
than computing: on 2 cores one thread makes ``fit`` 1.7 times faster (benchmarks/bench_fit.py).
So the entry point asks for one BLAS thread before numpy loads, unless the user set the
variables; the FEM reference uses SuperLU and is not affected. Importing the packages as a
library changes nothing.
"""

from __future__ import annotations

import os

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")


def main() -> int:
    from compare.cli import main as cli_main

    return cli_main()
