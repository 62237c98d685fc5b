"""How well a run logged once a minute gives the drive's losses: of drawn runs, the mean of
P_el - M omega [W] over each 10 min window from the run's own 1 s log against the same mean
from the copy a logger scanning once a minute records (bench_families.sampled_every), held
from sample to sample (as the fit holds its inputs: spindle.bench_inputs.held) or
interpolated linearly between samples.

    python benchmarks/bench_families.py --families clean --runs-per-family 25 --synth-only
    python benchmarks/cadence_losses.py [--runs clean-1 clean-2 ...] [--every-s 60]

Prints per run the mean and largest absolute error of the 10 min means [W], held and linear,
and the median over the runs.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from bench_families import sampled_every

ROOT = Path(__file__).resolve().parents[1]
WINDOW_S = 600.0


def losses_W(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(times [s], P_el - M omega [W]) of a bench file's rows that log all three."""
    from spindle.bench import read_bench

    run = read_bench(path)
    c = run.columns
    q = c["power_kW"] * 1e3 - c["load_torque_Nm"] * c["speed_rpm"] * 2 * np.pi / 60
    ok = np.isfinite(q)
    return run.time_s[ok], q[ok]


def window_means(y: np.ndarray, at: np.ndarray) -> np.ndarray:
    """The means of ``y`` over each WINDOW_S window of its times ``at`` [s]."""
    k = np.floor(at / WINDOW_S).astype(int)
    return np.array([y[k == j].mean() for j in np.unique(k)])


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", nargs="+", default=[f"clean-{s}" for s in range(1, 26)])
    ap.add_argument("--every-s", type=float, default=60.0)
    ap.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".families-cache")
    args = ap.parse_args(argv)
    from spindle.bench_inputs import held

    held_err, lin_err = [], []
    print(f"{'run':10} {'held: mean':>11} {'max':>6} {'linear: mean':>13} {'max':>6}  [W]")
    for name in args.runs:
        full = args.cache / f"{name}.csv"
        if not full.is_file():
            print(f"{name:10} not in {args.cache}: synthesise it first (module docstring)")
            continue
        t, q = losses_W(full)
        ts, qs = losses_W(sampled_every(full, args.every_s, args.cache / f"every-{args.every_s:g}s"))
        truth = window_means(q, t)
        hold = window_means(held(ts, qs, t), t)
        lin = window_means(np.interp(t, ts, qs), t)
        h, li = np.abs(hold - truth), np.abs(lin - truth)
        held_err.append(h.mean())
        lin_err.append(li.mean())
        print(f"{name:10} {h.mean():11.1f} {h.max():6.0f} {li.mean():13.1f} {li.max():6.0f}")
    if held_err:
        print(f"median over {len(held_err)} runs of the mean error of a {WINDOW_S / 60:g} min "
              f"mean: held {np.median(held_err):.1f} W, linear {np.median(lin_err):.1f} W")


if __name__ == "__main__":
    main()
