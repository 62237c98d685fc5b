"""Sparse direct solvers on the reference's own matrices: SuperLU (the project's, symmetric
mode with minimum degree on A^T + A), SuperLU with scipy's default COLAMD, and, where they
are installed, CHOLMOD (scikit-sparse), UMFPACK (scikit-umfpack) and PARDISO (pypardiso).

    python benchmarks/bench_solvers.py [--levels 2 3] [--out docs/figures/solvers.json]

The matrices are those the study factorises: the thermal conductance K(n) at the nominal
speed and the reduced elastic stiffness, of spl2782 at each level. Each (matrix, solver)
runs in a fresh process that loads the matrix from a file, so its peak memory is its own:
the figure is the peak resident memory above the process after loading [MB]. The wall
times of the factorisation with its first solve [s] and of a further solve [ms] are the
best of ``--repeat``; the
residual ||A x - b|| / ||b|| checks each answer. A solver that is not installed is listed
as such, not skipped silently. Run it on an idle machine.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from figures import memory_MB, write_figures

ROOT = Path(__file__).resolve().parents[1]

SOLVERS = ("superlu", "superlu-colamd", "cholmod", "umfpack", "pardiso")
#: where each optional solver comes from (pip names)
SOURCES = {"cholmod": "scikit-sparse", "umfpack": "scikit-umfpack", "pardiso": "pypardiso"}


def _factoriser(name: str):
    """A function A (CSC) -> solve(b), or None when the solver is not installed."""
    from scipy.sparse.linalg import splu

    if name == "superlu":
        from reference.thermal import factorize

        return lambda A: factorize(A).solve
    if name == "superlu-colamd":
        return lambda A: splu(A).solve
    try:
        if name == "cholmod":
            from sksparse.cholmod import cholesky

            return lambda A: cholesky(A)
        if name == "umfpack":
            from scikits.umfpack import splu as usplu

            return lambda A: usplu(A).solve
        if name == "pardiso":
            import pypardiso  # noqa: F401

            return _pardiso
    except ImportError:
        return None
    raise ValueError(name)


def _pardiso(A):
    """A fresh PARDISO solver per factorisation (pypardiso's module-level one would reuse a
    factorisation of the same matrix, and the repeats would time nothing)."""
    from pypardiso import PyPardisoSolver

    solver, A = PyPardisoSolver(), A.tocsr()
    solver.factorize(A)
    return lambda b: solver.solve(A, b)


def run_one(matrix: Path, solver: str, repeat: int) -> dict:
    """One (matrix, solver) in this process: times, peak memory above the loaded matrix."""
    import numpy as np
    import scipy.sparse as sp

    A = sp.load_npz(matrix).tocsc()
    b = np.random.default_rng(0).standard_normal(A.shape[0])
    make = _factoriser(solver)
    if make is None:
        return {"solver": solver, "installed": False}
    base = memory_MB("VmRSS")
    best_f = best_s = float("inf")
    for _ in range(repeat):
        # the first solve is counted with the factorisation: PARDISO's factorized() is lazy
        t = time.perf_counter()
        solve = make(A)
        solve(b)
        best_f = min(best_f, time.perf_counter() - t)
        t = time.perf_counter()
        x = solve(b)
        best_s = min(best_s, time.perf_counter() - t)
        del solve
    peak = memory_MB("VmHWM")
    res = float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))
    return {"solver": solver, "installed": True, "factor_s": round(best_f, 3),
            "solve_ms": round(1e3 * best_s, 1), "peak_MB": round(peak - base),
            "residual": float(f"{res:.1e}")}


def _matrices(levels: list[int], folder: Path) -> list[dict]:
    import scipy.sparse as sp

    from compare.verify.study import study_cases
    from reference import ReferenceModel
    from spindle.spec_reader import as_spec

    spec = as_spec("spl2782")
    case, _ = study_cases(spec)
    out = []
    for lv in levels:
        print(f"assembling spl2782 level {lv}", file=sys.stderr, flush=True)
        model = ReferenceModel(spec, lv)
        n = float(case.speed_rpm(0.0))
        for kind, A in (("thermal", model.thermal.op.K(n)), ("elastic", model.elastic.K_red)):
            path = folder / f"{kind}-{lv}.npz"
            sp.save_npz(path, A.tocsc())
            out.append({"matrix": f"{kind}, level {lv}", "path": path, "n": A.shape[0],
                        "nnz": int(A.nnz)})
        del model
    return out


def _versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for pkg in ("scipy", "scikit-sparse", "scikit-umfpack", "pypardiso", "mkl"):
        try:
            out[pkg] = version(pkg)
        except PackageNotFoundError:
            out[pkg] = "not installed"
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--levels", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "figures" / "solvers.json")
    ap.add_argument("--one", nargs=2, metavar=("MATRIX", "SOLVER"), help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.one:
        print(json.dumps(run_one(Path(args.one[0]), args.one[1], args.repeat)))
        return
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for m in _matrices(args.levels, Path(tmp)):
            for solver in SOLVERS:
                run = subprocess.run([sys.executable, __file__, "--repeat", str(args.repeat),
                                      "--one", str(m["path"]), solver], capture_output=True,
                                     text=True, cwd=ROOT)
                if run.returncode != 0:
                    sys.exit(f"{solver} on {m['matrix']} failed:\n{run.stderr[-2000:]}")
                r = {"matrix": m["matrix"], "n": m["n"], "nnz": m["nnz"],
                     **json.loads(run.stdout.strip().splitlines()[-1])}
                rows.append(r)
                if r["installed"]:
                    print(f"{r['matrix']:>17} ({r['n']:>7} unknowns): {solver:>14}  "
                          f"factor {r['factor_s']:7.3f} s  solve {r['solve_ms']:7.1f} ms  "
                          f"peak {r['peak_MB']:5d} MB  residual {r['residual']:.0e}",
                          flush=True)
                else:
                    print(f"{r['matrix']:>17}: {solver:>14}  not installed "
                          f"(pip install {SOURCES[solver]})", flush=True)
    write_figures(args.out, "python benchmarks/bench_solvers.py", {
        "versions": _versions(),
        "threads": f"{os.cpu_count()} cores; PARDISO (MKL) uses them all, the others one",
        "rows": rows})

if __name__ == "__main__":
    main()
