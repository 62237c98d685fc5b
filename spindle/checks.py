"""Checks of physical inputs shared by the loss models (spindle.power) and the film
correlations (spindle.correlations).

Each returns the value as a float (unit unchanged) or raises ValueError naming the value and
the limit, so a wrong call fails where it is made and says why.
"""

from __future__ import annotations

import math

from spindle.units import RPM_TO_RAD_S


def finite(name: str, value: float) -> float:
    """``value`` as a float (unit unchanged); ValueError naming ``name`` if not finite."""
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{name} = {value!r} is not a finite number")
    return v


def positive(name: str, value: float) -> float:
    """``value`` as a float (unit unchanged); ValueError unless finite and > 0."""
    v = finite(name, value)
    if v <= 0.0:
        raise ValueError(f"{name} = {v:g} must be > 0")
    return v


def non_negative(name: str, value: float) -> float:
    """``value`` as a float (unit unchanged); ValueError unless finite and >= 0."""
    v = finite(name, value)
    if v < 0.0:
        raise ValueError(f"{name} = {v:g} must be >= 0")
    return v


def share(name: str, value: float) -> float:
    """A fraction [-]; ValueError unless it lies in 0..1."""
    v = finite(name, value)
    if not 0.0 <= v <= 1.0:
        raise ValueError(f"{name} = {v:g} must lie in 0..1 (a fraction)")
    return v


def omega_rad_s(speed_rpm: float) -> float:
    """Angular speed [rad/s] of a speed ``speed_rpm`` [1/min]; raises ValueError below 0.

    The models here take the magnitude of the speed; a negative value is rejected rather than
    silently mirrored (give the direction, if needed, through the sign of the torque).
    """
    n = finite("speed_rpm", speed_rpm)
    if n < 0.0:
        raise ValueError(f"speed_rpm = {n:g} is negative; give the speed magnitude |n| [rpm]")
    return n * RPM_TO_RAD_S
