"""Probe (not a signature of the fit): windage's n^3 term read off loaded runs.

    python benchmarks/probe_loaded_windage.py [--cache benchmarks/.families-cache]

Windage's signature (compare.fit.effects.windage.cube_test) reads the settled no-load power
levels, which a loaded cycle lacks. Under load the same term is in P_el - M omega, beside the
copper loss (proportional to M^2, its resistance rising with the winding's temperature). This
probe regresses the mean of P_el - M omega over every constant speed-and-torque plateau of the
second half of each constant-speed segment on n, n^(5/3), n^2, n^3, M^2 and M^2 (T_stator -
300 K) and tests the n^3 term (one-sided t), on the cached drawn runs of loaded cycles that
carry a true windage (effect, two, mixed) and on the loss-law family's (a rotor share rising
with speed, which adds nothing to the logged power). Prints, for each group, how many runs
the test finds significant at 1 % and the median standard error of the n^3 term.
docs/fit-history.md "2026-12-02 (28)" has the figures and why it was not built.
"""

from __future__ import annotations

import argparse
import json
import math
import warnings
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def plateaus(run, criteria) -> np.ndarray:
    """(n [krpm], M [N m], mean P_el - M omega [W], mean T_stator [K]) per plateau."""
    from compare.fit.signatures import segments
    from spindle.bench_inputs import held, valid_samples
    from spindle.units import ZERO_C_K

    t = np.asarray(run.time_s, dtype=float)
    # each row's last logged value of each column (a log by exception leaves cells empty)
    n, P, M, T_C = (held(*valid_samples(run, c), t)
                    for c in ("speed_rpm", "power_kW", "load_torque_Nm", "T_stator_C"))
    T = T_C + ZERO_C_K
    rows = []
    for s in segments(run, criteria):
        if s.speed_rpm < criteria.moving_rpm or s.duration_s < criteria.level_min_s:
            continue
        idx = np.where((t >= s.t0_s + 0.5 * s.duration_s) & (t < s.t1_s))[0]
        cuts = np.concatenate([[0], np.where(np.abs(np.diff(M[idx])) > 0.5)[0] + 1, [len(idx)]])
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            if b - a < criteria.window_min_samples:
                continue
            k = idx[a:b]
            loss = P[k] * 1e3 - M[k] * n[k] * 2 * math.pi / 60
            rows.append((np.nanmean(n[k]) / 1e3, np.nanmean(M[k]), np.nanmean(loss),
                         np.nanmean(T[k])))
    return np.array(rows)


def cube_under_load(rows: np.ndarray) -> tuple[float, float, float] | None:
    """(n^3 coefficient [W/krpm^3], its standard error, one-sided p), None with too few rows."""
    from scipy.stats import t as student

    if len(rows) < 8:
        return None
    nk, Mq, L, Ts = rows.T
    A = np.column_stack([nk, nk ** (5 / 3), nk ** 2, nk ** 3, Mq ** 2, Mq ** 2 * (Ts - 300.0)])
    coef, *_ = np.linalg.lstsq(A, L, rcond=None)
    dof = len(L) - A.shape[1]
    if dof < 3:
        return None
    r = L - A @ coef
    se = math.sqrt(float(r @ r) / dof * float(np.linalg.pinv(A.T @ A)[3, 3]))
    return float(coef[3]), se, float(student.sf(coef[3] / se, dof))


def main(argv: list[str] | None = None) -> None:
    from compare.fit.criteria import Criteria
    from spindle.bench import read_bench

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".families-cache")
    args = ap.parse_args(argv)
    criteria = Criteria()
    groups: dict[str, list[tuple[float, float, float]]] = {"windage": [], "loss law": []}
    for truth_path in sorted(args.cache.glob("*.truth.json")):
        truth = json.loads(truth_path.read_text(encoding="utf-8"))
        effects = truth["effect"] if isinstance(truth["effect"], list) else [truth["effect"]]
        group = ("windage" if "windage_loss" in effects else
                 "loss law" if truth_path.name.startswith("losslaw-") else None)
        if group is None or truth.get("cycle") == "random":  # unloaded: cube_test's ground
            continue
        stem = truth_path.name[:-len(".truth.json")]
        path = next(p for p in (args.cache / f"{stem}-onchange.csv", args.cache / f"{stem}.csv")
                    if p.exists())
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out = cube_under_load(plateaus(read_bench(path), criteria))
        if out is not None:
            groups[group].append(out)
    for group, outs in groups.items():
        if outs:
            found = sum(p < 0.01 for *_, p in outs)
            print(f"{group:9} {len(outs):3d} loaded runs: n^3 term significant at 1 % on "
                  f"{found}; median standard error {np.median([se for _, se, _ in outs]):.2f} "
                  "W/krpm^3")


if __name__ == "__main__":
    main()
