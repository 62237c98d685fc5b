"""A bench run's sensor columns that cannot be what a sensor read.

- :func:`check_not_copies`: two columns that are one column twice (spindle.bench.read_bench
  refuses the run);
- :func:`spike_rows`: single samples that leave both neighbours and come back (compare.fit
  leaves them out with a warning);
- :func:`check_room_in_celsius`: a room far warmer than a machine tool may run in, as the
  room's reading in °F is (read_bench refuses the run).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from scipy.stats import norm

from spindle.errors import InputError

#: the columns read from a sensor of their own (the model's channels and its boundary
#: temperatures), in the format's order
SENSOR_COLUMNS = ("T1_C", "T2_C", "T_stator_C", "P1_um", "T_env_C", "T_coolant_C")
#: the boundary's columns, which may be read from one sensor
BOUNDARY_COLUMNS = ("T_env_C", "T_coolant_C")
#: two sensors' difference varies over a run by their noise at least; one constant to this
#: share of either column's own variation is a copy of the other (a float's rounding)
COPY_REL = 1e-9
#: rows both columns must log before they can be said to be copies
COPY_MIN_ROWS = 10
#: a machine tool's electrical equipment works in a room of +5 to +40 °C (IEC 60204-1,
#: 4.4.3); a room whose median is above this, with a margin, is not in °C: 20 °C is 68 °F
ROOM_MAX_C = 50.0


def check_not_copies(columns: dict[str, np.ndarray],
                     error: Callable[[str, str, str], InputError]) -> None:
    """Refuse two sensor columns (file units, NaN where empty) that differ by one constant in
    every row both log: two sensors at two places carry their own noise, so one column is a
    copy of the other (an export that mapped one channel twice). ``error(field, message,
    fix)`` makes the InputError. Columns that do not vary are left to
    spindle.bench.stuck_channels; the room and the coolant may be one sensor (an air-cooled
    spindle's coolant is the room's air)."""
    present = [c for c in SENSOR_COLUMNS if c in columns]
    for i, a in enumerate(present):
        for b in present[i + 1:]:
            if {a, b} == set(BOUNDARY_COLUMNS):
                continue
            x, y = columns[a], columns[b]
            both = ~np.isnan(x) & ~np.isnan(y)
            if both.sum() < COPY_MIN_ROWS:
                continue
            x, y = x[both], y[both]
            spread = min(float(np.ptp(x)), float(np.ptp(y)))
            d = y - x
            if spread > 0 and float(np.ptp(d)) <= COPY_REL * spread:
                offset = float(np.median(d))
                raise error(b, f"{b} is {a} {'+' if offset >= 0 else '-'} {abs(offset):g} in "
                            f"every one of the {int(both.sum())} rows that log both: two "
                            "sensors never differ by one constant, so one column is a copy "
                            "of the other",
                            "export each sensor's own column (check the export's channel "
                            "mapping)")


def _spike_bound(d: np.ndarray, tolerance: float, alpha: float) -> float:
    """The step a valid sample must exceed to be no reading (:func:`spike_rows`,
    :func:`first_sample_glitch`), from the first differences ``d`` of a channel's valid
    samples: the larger of ``tolerance`` and the largest step its noise makes among the
    len(d) + 1 samples at level ``alpha`` (the noise from the median absolute first
    difference, Bonferroni over the samples)."""
    noise_step = 1.4826 * float(np.median(np.abs(d - np.median(d))))
    return max(float(norm.isf(alpha / (2 * (len(d) + 1)))) * noise_step, tolerance)


def spike_rows(time_s: np.ndarray, y: np.ndarray, tolerance: float, alpha: float,
               within_s: float) -> np.ndarray:
    """Indices into ``y`` (one channel's column, NaN where not logged; ``time_s`` [s] its
    rows' times) of single-sample spikes: a valid sample whose logged neighbours both lie
    within ``within_s`` [s] of it (the model's grid step: a fit follows nothing faster), and
    that departs from both, in the same direction, by more than both the channel's
    ``tolerance`` (in its unit: a smaller excursion cannot move a verdict judged in
    tolerances) and the largest step its noise makes among all the samples at level
    ``alpha`` (the noise from the median absolute first difference, Bonferroni over the
    samples). A thermal reading cannot leave its neighbours and return that fast; an
    electrical spike can. A log sparser than ``within_s`` is not judged."""
    valid = np.flatnonzero(~np.isnan(y))
    v, t = y[valid], np.asarray(time_s, dtype=float)[valid]
    if len(v) < 10:
        return np.zeros(0, dtype=int)
    d = np.diff(v)
    bound = _spike_bound(d, tolerance, alpha)
    up, down = d[:-1], -d[1:]
    dt = np.diff(t)
    close = (dt[:-1] <= within_s) & (dt[1:] <= within_s)
    hit = close & (np.sign(up) == np.sign(down)) & (np.minimum(np.abs(up), np.abs(down)) > bound)
    return valid[np.flatnonzero(hit) + 1]


def first_sample_glitch(time_s: np.ndarray, y: np.ndarray, speed_rpm: np.ndarray,
                        tolerance: float, alpha: float, within_s: float,
                        speed_band_rel: float, standstill_rpm: float) -> int | None:
    """The row of ``y``'s first valid sample where it is a glitch, else None. The first
    sample has no neighbour before it, so :func:`spike_rows`, which asks a spike to come
    back, cannot judge it; here the samples after it stand in. It is a glitch where the
    valid samples within ``within_s`` [s] after it (at least two) agree with one another
    within the bound and it departs from their median by more than the bound, while the
    speed held (no logged speed moves from the first's by more than ``speed_band_rel`` of
    it, or ``standstill_rpm``): at one speed a thermal reading, or the growth, cannot move
    a tolerance within the grid step, while a speed start's shortening can. The bound is
    :func:`spike_rows`': the larger of ``tolerance`` and the noise's Bonferroni step."""
    valid = np.flatnonzero(~np.isnan(y))
    if len(valid) < 10:
        return None
    t = np.asarray(time_s, dtype=float)
    bound = _spike_bound(np.diff(y[valid]), tolerance, alpha)
    i0 = valid[0]
    after = valid[1:][t[valid[1:]] - t[i0] <= within_s]
    if len(after) < 2:
        return None
    ref = float(np.median(y[after]))
    if float(np.ptp(y[after])) > bound or abs(float(y[i0]) - ref) <= bound:
        return None
    n = np.asarray(speed_rpm, dtype=float)
    logged = np.flatnonzero(~np.isnan(n[:after[-1] + 1]))
    if not len(logged):
        return i0
    before = logged[logged <= i0]
    n0 = float(n[before[-1]] if len(before) else n[logged[0]])
    span = n[logged[logged >= i0]]
    if np.any(np.abs(span - n0) > max(speed_band_rel * n0, standstill_rpm)):
        return None
    return int(i0)


def drop_impossible_samples(columns: dict[str, np.ndarray], line_no: np.ndarray,
                            warn: Callable[[str], None],
                            limits: tuple[float, float, float, float]) -> None:
    """Read as not measured (NaN, in place, each column's with one ``warn``) a sensor
    column's single samples that no sensor reads: beyond the reader's limits ``limits`` =
    (lowest °C, highest median °C, highest °C, largest |P1| µm) while the samples logged
    before and after them are within them. A logger's "no data" code (-999, 9999) or an
    open PT100 (850 °C) between two readings is no temperature, and the same physics as a
    spike's says so: nothing thermal leaves its neighbours that far and comes back. Left to
    the reader's refusal: a run of such samples, a column whose median is beyond them (a
    unit), and a value that is a plausible temperature in kelvin (one row exported in K)."""
    t_min, t_kelvin_median, t_max, p1_max = limits
    for col in SENSOR_COLUMNS:
        y = columns.get(col)
        if y is None:
            continue
        valid = np.flatnonzero(~np.isnan(y))
        v = y[valid]
        if col == "P1_um":
            bad = np.abs(v) > p1_max
        else:
            kelvin = (v - 273.15 >= t_min) & (v - 273.15 <= t_kelvin_median)
            bad = ((v < t_min) | (v > t_max)) & ~kelvin
        if not bad.any() or bad.mean() > 0.5:
            continue
        alone = bad.copy()
        alone[1:] &= ~bad[:-1]
        alone[:-1] &= ~bad[1:]
        if not alone.any():
            continue
        rows = valid[alone]
        warn(f"{col}: {len(rows)} single sample(s) no sensor reads ({y[rows[0]]:g} on line "
             f"{line_no[rows[0]]}{', ...' if len(rows) > 1 else ''}) between plausible "
             "readings are read as not measured (a logger's no-data code or an open sensor)")
        y[rows] = np.nan


def check_room_in_celsius(columns: dict[str, np.ndarray], line_no: np.ndarray,
                          error: Callable[[str, str, str], InputError]) -> None:
    """Refuse a room temperature (T_env_C, °C) whose median is above :data:`ROOM_MAX_C`:
    no machine tool runs there, and a room in °F reads 60-80. ``line_no``: each row's file
    line; ``error(field, message, fix)`` makes the InputError."""
    y = columns.get("T_env_C")
    if y is None or np.isnan(y).all():
        return
    med = float(np.nanmedian(y))
    if med > ROOM_MAX_C:
        line = int(line_no[np.flatnonzero(y > ROOM_MAX_C)[0]])
        raise error(f"T_env_C (line {line})", f"the room's median is {med:g} °C, above the "
                    f"{ROOM_MAX_C:g} °C no machine tool runs in (IEC 60204-1: +5 to +40 °C): "
                    "it looks like °F", "export °C (°C = (°F - 32) / 1.8) in every temperature "
                    "column")
