"""Unit conversions at the edges: the code works in SI (K, m, W, rad/s) and converts here only.

One home for the Celsius offset and the rpm conversion, so no module carries its own copy.
"""

from __future__ import annotations

import math

ZERO_C_K = 273.15
"""0 °C in kelvin: T_C = T_K - ZERO_C_K."""

RPM_TO_RAD_S = 2.0 * math.pi / 60.0
"""Angular speed [rad/s] of one revolution per minute."""


SPEED_MAX_RPM = 100_000.0
"""The highest speed any input may give [rpm]: the fastest machine-tool motor spindles turn at
60 000-80 000 rpm; above this a value is taken to be in other units or a typo."""

CYCLE_MAX_S = 1000.0 * 3600.0
"""The longest cycle or run any input may describe [s] (1000 h, six weeks: bench runs last
hours to days); above this the time column is in other units or the file is corrupt."""
