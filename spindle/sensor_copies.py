"""Two sensor columns of a bench run that are one column twice (spindle.bench.read_bench)."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

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
