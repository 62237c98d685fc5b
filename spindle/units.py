"""Unit conversions at the edges: the code works in SI (K, m, W, rad/s) and converts here only.

One home for the Celsius offset and the rpm conversion, so no module carries its own copy.
"""

from __future__ import annotations

import math

ZERO_C_K = 273.15
"""0 °C in kelvin: T_C = T_K - ZERO_C_K."""

RPM_TO_RAD_S = 2.0 * math.pi / 60.0
"""Angular speed [rad/s] of one revolution per minute."""


MESH_LEVEL_MAX = 6
"""The finest FEM mesh level a command or a baseline accepts: level 6 of spl2782 has 5.6
million elements (each level halves every edge of level 0)."""

SPEED_MAX_RPM = 100_000.0
"""The highest speed any input may give [rpm]: the fastest machine-tool motor spindles turn at
60 000-80 000 rpm; above this a value is taken to be in other units or a typo."""

TORQUE_MAX_NM = 10_000.0
"""The largest load torque any input may give [N m]: motor spindles deliver tens to a few
hundred N m (the SPL2782.1: 38 kW at 4300 rpm, 84 N m); above this a value is in other units."""

POWER_MAX_KW = 1000.0
"""The largest electrical power any input may give [kW]: motor spindles draw up to about a
hundred kW; above this a value is in W or corrupt."""

MAX_SERIES_POINTS = 1_000_000
"""The most samples a generated input series (an ambient drift, a chiller's cycling) or a
transient's output grid may hold: a 1000 h run sampled every 4 s; beyond it the memory and
the time a run takes are absurd (a sample step in other units or a typo)."""

CYCLE_MAX_S = 1000.0 * 3600.0
"""The longest cycle or run any input may describe [s] (1000 h, six weeks: bench runs last
hours to days); above this the time column is in other units or the file is corrupt."""
