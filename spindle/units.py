"""Unit conversions at the edges: the code works in SI (K, m, W, rad/s) and converts here only.

One home for the Celsius offset and the rpm conversion, so no module carries its own copy.
"""

from __future__ import annotations

import math

ZERO_C_K = 273.15
"""0 °C in kelvin: T_C = T_K - ZERO_C_K."""

RPM_TO_RAD_S = 2.0 * math.pi / 60.0
"""Angular speed [rad/s] of one revolution per minute."""

