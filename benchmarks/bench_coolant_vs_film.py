"""Is a coolant that warms by the heat it carries only a weaker jacket film? (issue 13)

    python benchmarks/bench_coolant_vs_film.py [--seed 1] [--R 0.0035] [--level 1]

On the FEM reference of the shipped spec (mesh ``--level``) over the random no-load cycle of
``--seed`` (``synth``'s cycle, no mismatch): the run with ``coolant_dynamics`` (the films see
the coolant's mean temperature, supply + R Q, solved as ``synth`` solves it), then clean runs
with the coolant film group scaled by a factor f, f fitted to the coolant run (bounded scalar
search on the sum of mean squares in tolerance units, 1 K and 1.5 um). Then the same on the
11-node lumped model. Prints, per channel, the coolant effect's size (coolant run minus spec)
and what the best film factor leaves of it (RMS, max; K, P1 in um). What the best factor
leaves is what the temperatures can tell the two apart by, against sensor noise of
0.03-0.1 K; ``fit`` frees the other base parameters as well, which can take more of it.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import figures  # noqa: F401  (it checks that the checkout's code is the code measured)
import numpy as np

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)
from spindle.tolerances import channel_tolerance, edge_scale

#: tolerance units [K; m for P1] of the fit
TOL = {c: channel_tolerance(c) for c in ("T1", "T2", "T_stator", "P1")}


def _best_factor(simulate, target: dict[str, np.ndarray]) -> tuple[float, dict]:
    """The jacket factor in 0.05..1 whose run is closest to ``target``, and that run."""
    from scipy.optimize import minimize_scalar

    runs: dict[float, dict] = {}

    def cost(log_f: float) -> float:
        f = float(np.exp(log_f))
        y = runs.setdefault(f, simulate(f))
        return sum(float(np.mean(((y[k] - target[k]) / TOL[k]) ** 2)) for k in TOL if k in y)

    r = minimize_scalar(cost, bounds=(np.log(0.05), 0.0), method="bounded",
                        options={"xatol": 0.01})
    f = float(np.exp(r.x))
    return f, runs[f]


def _table(label: str, f: float, spec_run: dict, coolant: dict, film: dict) -> None:
    print(f"{label}: best jacket factor {f:.3f}")
    print(f"  {'channel':9} {'effect RMS':>10} {'max':>7}   {'left RMS':>8} {'max':>7}")
    for k in TOL:
        u = edge_scale(k)
        d, e = coolant[k] - spec_run[k], coolant[k] - film[k]
        print(f"  {k:9} {u * np.sqrt(np.mean(d ** 2)):10.3f} {u * np.max(np.abs(d)):7.3f}   "
              f"{u * np.sqrt(np.mean(e ** 2)):8.3f} {u * np.max(np.abs(e)):7.3f}")


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seed", type=int, default=1, help="the random cycle's seed (default 1)")
    ap.add_argument("--R", type=float, default=0.0035,
                    help="the coolant's advection resistance [K/W] (default 0.0035, within "
                    "synth's 0.002-0.005)")
    ap.add_argument("--level", type=int, default=1, help="FEM mesh level (default 1)")
    args = ap.parse_args(argv)
    if args.R <= 0.0 or args.seed < 0 or args.level < 0:
        ap.error("--R must be > 0, --seed and --level >= 0")

    from compare.fit.greybox import GreyBox
    from compare.fit.params import default_theta
    from compare.synth.bench import reference_run, synth
    from compare.synth.mismatch import Mismatch
    from spindle.bench import read_bench
    from spindle.bench_inputs import interval_inputs
    from spindle.cycles import drawn_cycle
    from spindle.drive import cycle_load_case, drive_for
    from spindle.spec_reader import load_spec

    t0 = time.perf_counter()
    spec = load_spec("spl2782")
    drive = drive_for(spec)
    cycle = drawn_cycle("random", args.seed)

    def fem(f: float, effect: str = "clean", truth: dict | None = None) -> dict:
        s = Mismatch({"h_coolant": f}, 1.0, 1.0, 1.0, 0.0, 0.06,
                     args.level).apply_to_spec(spec) if f != 1.0 else spec
        return reference_run(s, cycle_load_case(s, cycle, drive), effect, truth or {},
                             args.level)[1]

    coolant = fem(1.0, "coolant_dynamics", {"R_adv_K_W": args.R})
    spec_run = fem(1.0)
    f, film = _best_factor(fem, coolant)
    print(f"seed {args.seed}, R {args.R} K/W, FEM level {args.level} "
          f"({time.perf_counter() - t0:.0f} s)")
    _table("FEM", f, spec_run, coolant, film)

    # the lumped model on the same cycle: its inputs sampled as a bench logs them
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / "clean.csv"
        synth(spec, "random", "clean", args.seed, run, level=0)
        inputs = interval_inputs(read_bench(run), 60.0)
    gb = GreyBox(spec, drive, inputs, 11)
    theta = default_theta(gb.parameters())
    cool_gb = gb.variant(("coolant_dynamics",))
    y_cool = cool_gb.simulate({**theta, "R_adv_K_W": args.R})
    y_spec = gb.simulate(theta)
    f_l, y_film = _best_factor(lambda x: gb.simulate({**theta, "h_coolant": x}), y_cool)
    _table("lumped (11 nodes)", f_l, y_spec, y_cool, y_film)
    print(f"wall time {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
