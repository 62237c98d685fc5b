"""Measurement-side effects injected into a recorded bench run (issue 13: test against data
this project did not make).

A peer's control run (../shared/bench-runs, truth ``none``) carries the base misfit of a real
spindle that the spec describes only approximately: this project's model did not make it.
Three library effects act on the measurement alone, so adding them to such a run gives a run
whose truth is known exactly and whose every other detail stays the peer's:

- ``centrifugal_shortening``: P1 drops by c (n / 1000 rpm)^2 at once;
- ``fixture_expansion``: P1 moves by k (T_env - T_env at the start);
- ``sensor_lag``: one channel reads through a first-order lag of time constant tau; the lag
  also smooths the channel's noise, so noise of the size the channel had (its sample-to-sample
  scatter) is added back after it.

Injected values are rounded to the decimals the column was logged with (the bench's
quantisation), empty cells stay empty, and a comment line records what was injected. Units:
um, K, s, rpm, as the bench format (../shared/bench-format.md).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping

import numpy as np

from lumped.elastic import first_order_lag as lumped_lag
from spindle.commented_csv import split_commented_csv

#: the effects this module injects, with their parameter names
INJECTABLE = {"centrifugal_shortening": ("c_cf_um_krpm2",),
              "fixture_expansion": ("k_fix_um_K",),
              "sensor_lag": ("tau_s",)}
LAG_CHANNELS = ("T1", "T2", "T_stator", "P1")


def _column(header: list[str], name: str) -> int:
    for j, h in enumerate(header):
        if h.strip() == name or h.strip().startswith(name + "_"):
            return j
    raise ValueError(f"the run has no column {name!r} (header: {', '.join(header)})")


def _floats(rows: list[list[str]], j: int) -> np.ndarray:
    out = np.full(len(rows), np.nan)
    for i, r in enumerate(rows):
        cell = r[j].strip() if j < len(r) else ""
        if cell:
            try:
                out[i] = float(cell)
            except ValueError:
                pass
    return out


def _decimals(rows: list[list[str]], j: int) -> int:
    d = 0
    for r in rows:
        cell = r[j].strip() if j < len(r) else ""
        if "." in cell:
            d = max(d, len(cell.split(".", 1)[1]))
    return d


def first_order_lag(t_s: np.ndarray, x: np.ndarray, tau_s: float) -> np.ndarray:
    """``x`` read through a first-order lag of ``tau_s`` [s] at the sample times ``t_s`` [s]
    (strictly increasing, as a bench run's), the input taken linear between the measured
    samples (lumped.elastic.first_order_lag over them: exact for a piecewise-linear input);
    an empty (NaN) sample stays empty."""
    ok = np.isfinite(x)
    y = np.full_like(x, np.nan)
    y[ok] = lumped_lag(t_s[ok], x[ok], tau_s)
    return y


def inject(text: str, effect: str, params: Mapping[str, float], channel: str | None = None,
           seed: int = 0) -> str:
    """``text`` (a bench CSV) with ``effect`` injected at ``params`` (names as
    compare.fit.greybox.EFFECTS; ``channel`` for ``sensor_lag``). Returns the new CSV text."""
    if effect not in INJECTABLE:
        raise ValueError(f"{effect!r} acts on the physics, not only on the measurement; "
                         f"injectable: {', '.join(INJECTABLE)}")
    missing = [p for p in INJECTABLE[effect] if p not in params]
    if missing:
        raise ValueError(f"{effect} needs {', '.join(missing)}")
    doc = split_commented_csv(text)
    header, rows = doc.rows[0], [list(r) for r in doc.rows[1:]]
    t = _floats(rows, _column(header, "time"))
    if effect == "sensor_lag":
        if channel not in LAG_CHANNELS:
            raise ValueError(f"sensor_lag needs a channel: one of {', '.join(LAG_CHANNELS)}")
        j = _column(header, channel)
        x = _floats(rows, j)
        ok = np.isfinite(x)
        scatter = float(np.nanstd(np.diff(x[ok])) / math.sqrt(2.0)) if ok.sum() > 2 else 0.0
        rng = np.random.default_rng(seed)
        new = first_order_lag(t, x, float(params["tau_s"])) + rng.normal(0.0, scatter, len(x))
        what = f"sensor_lag on {channel}, tau_s = {params['tau_s']:g}"
    else:
        j = _column(header, "P1")
        x = _floats(rows, j)
        if effect == "centrifugal_shortening":
            n = np.nan_to_num(_floats(rows, _column(header, "speed")))
            new = x - float(params["c_cf_um_krpm2"]) * (n / 1000.0) ** 2
            what = f"centrifugal_shortening, c_cf_um_krpm2 = {params['c_cf_um_krpm2']:g}"
        else:
            env = _floats(rows, _column(header, "T_env"))
            env0 = env[np.isfinite(env)][0]
            new = x + float(params["k_fix_um_K"]) * np.where(np.isfinite(env), env - env0, 0.0)
            what = f"fixture_expansion, k_fix_um_K = {params['k_fix_um_K']:g}"
    d = _decimals(rows, j)
    for i, r in enumerate(rows):
        if np.isfinite(x[i]) and np.isfinite(new[i]):
            r[j] = f"{new[i]:.{d}f}"
    out = io.StringIO()
    header_line = doc.line_no[0]
    for _ln, c in doc.comments:
        if _ln < header_line:
            out.write(f"#{c}\n")
    out.write(f"# injected (compare.fit.inject): {what}\n")
    w = csv.writer(out, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return out.getvalue()
