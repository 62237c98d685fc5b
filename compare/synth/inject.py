"""Measurement-side effects injected into a recorded bench run (issue 13: test against data
this project did not make).

A peer's control run (tests/data/peer-runs/bench-runs, truth ``none``) carries the base misfit of a real
spindle that the spec describes only approximately: this project's model did not make it.
The library's effects that act on the measurement alone (``measurement_only``: a centrifugal
jump, a fixture's term, a sensor's lag) can be added to such a run through their own
``measure`` hook, giving a run whose truth is known exactly and whose every other detail stays
the peer's. A lag also smooths the channel's noise, so noise of the size the channel had (its
sample-to-sample scatter) is added back after it.

Injected values are rounded to the decimals the column was logged with (the bench's
quantisation), empty cells stay empty, and a comment line records what was injected. Units:
um, K, s, rpm, as the bench format (tests/data/peer-runs/bench-format.md).
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Mapping

import numpy as np

from compare.fit.effects import LIBRARY
from lumped.elastic import first_order_lag as lumped_lag
from spindle.commented_csv import split_commented_csv
from spindle.tolerances import edge_absolute
from spindle.units import ZERO_C_K

#: the channels a lag may be injected on
LAG_CHANNELS = ("T1", "T2", "T_stator", "P1")


def injectable() -> list[str]:
    """The library's effects that act on the measurement alone."""
    return [name for name, e in LIBRARY.items() if e.measurement_only]


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
    """``text`` (a bench CSV) with ``effect`` injected at ``params`` (the effect's parameter
    names; ``channel`` for a per-channel effect). Returns the new CSV text."""
    e = LIBRARY.get(effect)
    if e is None or not e.measurement_only:
        raise ValueError(f"{effect!r} acts on the physics, not only on the measurement; "
                         f"injectable: {', '.join(injectable())}")
    missing = [p.name for p in e.params if p.name not in params]
    if missing:
        raise ValueError(f"{effect} needs {', '.join(missing)}")
    if e.per_channel and channel not in LAG_CHANNELS:
        raise ValueError(f"{effect} needs a channel: one of {', '.join(LAG_CHANNELS)}")
    doc = split_commented_csv(text)
    header, rows = doc.rows[0], [list(r) for r in doc.rows[1:]]
    t = _floats(rows, _column(header, "time"))
    cols = {"speed_rpm": _floats(rows, _column(header, "speed")),
            "T_env_K": _floats(rows, _column(header, "T_env")) + ZERO_C_K}
    for c in LAG_CHANNELS:
        j = _column(header, c)
        scale, off, _ = edge_absolute(c)
        cols[c] = (_floats(rows, j) + off) / scale
    new = e.measure(t, cols, params, channel)
    changed = [c for c in LAG_CHANNELS if new[c] is not cols[c]]
    rng = np.random.default_rng(seed)
    for c in changed:
        j = _column(header, c)
        x = _floats(rows, j)
        scale, off, _ = edge_absolute(c)
        y = new[c] * scale - off
        if e.per_channel:
            # a lag smooths the channel's noise too: noise of the size the channel had (its
            # sample-to-sample scatter) is added back after it
            ok = np.isfinite(x)
            scatter = float(np.nanstd(np.diff(x[ok])) / math.sqrt(2.0)) if ok.sum() > 2 else 0.0
            y = y + rng.normal(0.0, scatter, len(x))
        d = _decimals(rows, j)
        for i, r in enumerate(rows):
            if np.isfinite(x[i]) and np.isfinite(y[i]):
                r[j] = f"{y[i]:.{d}f}"
    what = f"{effect}" + (f" on {channel}" if channel else "") + ", " + ", ".join(
        f"{k} = {v:g}" for k, v in params.items())
    out = io.StringIO()
    header_line = doc.line_no[0]
    for _ln, c in doc.comments:
        if _ln < header_line:
            out.write(f"#{c}\n")
    out.write(f"# injected (compare.synth.inject): {what}\n")
    w = csv.writer(out, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return out.getvalue()
