"""What ``fit`` leaves out of a bench run before fitting: a channel that reads one value
throughout (spindle.bench.stuck_channels) and single-sample spikes
(spindle.sensor_faults.spike_rows), each said in a BenchWarning and a line for the report."""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np

from spindle.bench import CHANNEL_COLUMNS, STANDSTILL_RPM, BenchRun, BenchWarning, stuck_channels
from spindle.bench_inputs import HOLD_STEPS, SPEED_BAND_REL
from spindle.errors import InputError
from spindle.sensor_faults import first_sample_glitch, spike_rows
from spindle.tolerances import channel_tolerance, edge_scale, edge_unit


def without_stuck(run: BenchRun, channels: list[str]) -> tuple[list[str], list[str]]:
    """``channels`` less those whose sensor reads one value throughout
    (spindle.bench.stuck_channels), each left out with a BenchWarning, and the report's
    lines saying so; InputError where none is left."""
    stuck = stuck_channels(run, channels)
    for c in stuck:
        col = CHANNEL_COLUMNS[c]
        y = run.columns[col]
        warnings.warn(BenchWarning(
            f"{run.path}: {col}: reads {float(y[~np.isnan(y)][0]):g} in each of its "
            f"{int(np.sum(~np.isnan(y)))} samples: a sensor on a spindle shows at least its "
            "noise, so it is stuck or not connected; the channel is left out (fix: check the "
            "sensor, or drop the column)"), stacklevel=3)
    kept = [c for c in channels if c not in stuck]
    if not kept:
        raise InputError(str(run.path), ", ".join(CHANNEL_COLUMNS[c] for c in channels),
                         "every measured channel reads one value throughout: no sensor "
                         "measured the spindle", "check the sensors and their export")
    return kept, [f"{CHANNEL_COLUMNS[c]} reads one value in every row (a stuck or "
                  "disconnected sensor) and is left out" for c in stuck]


def without_spikes(run: BenchRun, channels: list[str], alpha: float, grid_s: float
                    ) -> tuple[BenchRun, list[str]]:
    """``run`` with each channel's single-sample spikes (spindle.sensor_faults.spike_rows,
    within a grid step ``grid_s`` [s]) and a glitch on its first sample
    (spindle.sensor_faults.first_sample_glitch, judged by the samples of the hold's two
    steps after it; P1 then zeroed at the next one, as the format zeroes it at its first)
    left out, each channel's with a BenchWarning, and the report's lines saying so."""
    columns, said = dict(run.columns), []
    p1_ref = run.P1_reference_um
    for c in channels:
        col = CHANNEL_COLUMNS[c]
        y = columns[col]
        unit_tol = channel_tolerance(c) * edge_scale(c)  # the file's unit (µm, K)
        first = first_sample_glitch(run.time_s, y, run.columns["speed_rpm"], unit_tol, alpha,
                                    HOLD_STEPS * grid_s, SPEED_BAND_REL, STANDSTILL_RPM)
        if first is not None:
            y = y.copy()
            y[first] = np.nan
            nxt = np.flatnonzero(~np.isnan(y))[0]
            off = float(run.columns[col][first] - y[nxt])
            text = (f"{col}: its first sample (line {run.lines[first] if len(run.lines) else '?'})"
                    f" lies {off:+.3g} {edge_unit(c, ascii=True)} off the samples of the next "
                    f"{HOLD_STEPS * grid_s:g} s, which agree, at one speed: a glitch, left out")
            if c == "P1":  # the format zeroes P1 at its first valid sample: that one now
                p1_ref = (p1_ref or 0.0) + float(y[nxt])
                y = y - y[nxt]
                text += "; P1 is zeroed at the next sample"
            warnings.warn(BenchWarning(f"{run.path}: {text} (fix: check the sensor's first "
                                       "reading)"), stacklevel=3)
            said.append(text)
            columns[col] = y
        rows = spike_rows(run.time_s, y, unit_tol, alpha, grid_s)
        if not len(rows):
            continue
        valid = np.flatnonzero(~np.isnan(y))
        at = np.searchsorted(valid, rows)
        sizes = [y[r] - 0.5 * (y[valid[k - 1]] + y[valid[k + 1]]) for r, k in zip(rows, at, strict=True)]
        big = max(sizes, key=abs)
        unit = edge_unit(c, ascii=True)
        where = f", the first on line {run.lines[rows[0]]}" if len(run.lines) else ""
        text = (f"{col}: {len(rows)} single-sample spikes (up to {big:+.3g} {unit} off the "
                f"neighbours{where}) are left out: a thermal reading cannot leave its "
                f"neighbours by a tolerance and return within {grid_s:g} s")
        warnings.warn(BenchWarning(f"{run.path}: {text} (fix: check the sensor's wiring and "
                                   "shielding)"), stacklevel=3)
        said.append(text)
        y = y.copy()
        y[rows] = np.nan
        columns[col] = y
    return (replace(run, columns=columns, P1_reference_um=p1_ref) if said else run), said


def coolant_as_room(run: BenchRun, spec) -> str | None:
    """A warning where the spec cools the spindle with a liquid (a film towards the coolant:
    Spec.liquid_cooled) but ``run``'s coolant reads the room's value in every row that logs both: two
    sensors carry their own noise, and a chiller's supply is regulated apart from the
    room, so that is the room's column twice (an air-cooled spindle's coolant is the room's
    air, which check_not_copies lets pass). None otherwise."""
    if not spec.liquid_cooled:
        return None
    env, cool = run.columns["T_env_C"], run.columns["T_coolant_C"]
    both = ~np.isnan(env) & ~np.isnan(cool)
    if np.count_nonzero(both) < 2 or not np.array_equal(env[both], cool[both]):
        return None
    return ("T_coolant_C reads T_env_C's value in every row that logs both, while the spec "
            f"'{spec.name}' cools the spindle with a liquid (surfaces with T_ref = "
            "\"coolant\"): the coolant column looks like the room's, copied; it is fitted as "
            "logged (fix: export the coolant's supply temperature)")
