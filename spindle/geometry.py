"""Axisymmetric section geometry: trapezoids in the (z, r) half-plane, and how they touch.

A section spans ``z_start <= z <= z_end`` and, at each z, ``r_inner(z) <= r <= r_outer(z)``
with radii linear in z (a conical section has different radii at its two ends). Lengths in m.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Geometric tolerance [m]: CAD dimensions closer than this are taken as equal.
TOL_M = 1e-8


@dataclass(frozen=True)
class Trapezoid:
    """The region of one section in the (z, r) half-plane [m]."""

    z_start: float
    z_end: float
    r_inner: tuple[float, float]  # at z_start, z_end
    r_outer: tuple[float, float]

    def r_in(self, z: float | np.ndarray) -> float | np.ndarray:
        s = (np.asarray(z) - self.z_start) / (self.z_end - self.z_start)
        return self.r_inner[0] + s * (self.r_inner[1] - self.r_inner[0])

    def r_out(self, z: float | np.ndarray) -> float | np.ndarray:
        s = (np.asarray(z) - self.z_start) / (self.z_end - self.z_start)
        return self.r_outer[0] + s * (self.r_outer[1] - self.r_outer[0])

    @property
    def length(self) -> float:
        return self.z_end - self.z_start

    @property
    def volume_m3(self) -> float:
        """Volume of the solid of revolution [m3], exact for linear radii (Simpson)."""
        zm = 0.5 * (self.z_start + self.z_end)
        f = [float(self.r_out(z) ** 2 - self.r_in(z) ** 2) for z in (self.z_start, zm, self.z_end)]
        return float(np.pi * self.length * (f[0] + 4 * f[1] + f[2]) / 6.0)

    def contains(self, z: float, r: float, tol: float = TOL_M) -> bool:
        if not (self.z_start - tol <= z <= self.z_end + tol):
            return False
        zc = min(max(z, self.z_start), self.z_end)
        return bool(self.r_in(zc) - tol <= r <= self.r_out(zc) + tol)


def _z_overlap(a: Trapezoid, b: Trapezoid) -> tuple[float, float] | None:
    lo, hi = max(a.z_start, b.z_start), min(a.z_end, b.z_end)
    return (lo, hi) if hi - lo > TOL_M else None


def overlap(a: Trapezoid, b: Trapezoid) -> bool:
    """True when the two sections share area (not just a boundary)."""
    zz = _z_overlap(a, b)
    if zz is None:
        return False
    for z in (zz[0], 0.5 * (zz[0] + zz[1]), zz[1]):
        if min(a.r_out(z), b.r_out(z)) - max(a.r_in(z), b.r_in(z)) > TOL_M:
            return True
    return False


def contact_length(a: Trapezoid, b: Trapezoid) -> float:
    """Length [m] of the boundary the two sections share in the (z, r) plane (0 if none).

    Radial contact: one's outer line equals the other's inner line over a common z range.
    Axial contact: one ends where the other starts and their radial ranges overlap there.
    """
    zz = _z_overlap(a, b)
    if zz is not None:
        for lo, hi in ((a, b), (b, a)):
            if all(abs(lo.r_out(z) - hi.r_in(z)) <= TOL_M for z in zz):
                dz = zz[1] - zz[0]
                dr = float(lo.r_out(zz[1]) - lo.r_out(zz[0]))
                return float(np.hypot(dz, dr))
        return 0.0
    for first, second in ((a, b), (b, a)):
        if abs(first.z_end - second.z_start) <= TOL_M:
            z = first.z_end
            common = min(first.r_out(z), second.r_out(z)) - max(first.r_in(z), second.r_in(z))
            return float(max(common, 0.0)) if common > TOL_M else 0.0
    return 0.0
