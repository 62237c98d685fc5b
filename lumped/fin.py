"""Eq. 14 of the paper: the closed-form temperature of a shaft treated as a fin.

A rod of length l, cross-section A, perimeter P and conductivity lambda loses heat through
its lateral surface with film coefficient alpha to ambient; heat Q1 enters at x = 0 (rear
bearing A) and Q2 at x = l (front bearing B); the end faces are otherwise adiabatic::

    T(x) - T_amb = Q1 cosh(m (l - x)) / (A lambda m sinh(m l))
                 + Q2 cosh(m x)       / (A lambda m sinh(m l)),   m = sqrt(alpha P / (lambda A))

It solves lambda A T'' = alpha P (T - T_amb) with -lambda A T'(0) = Q1 and lambda A T'(l) = Q2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Fin:
    """A fin: length_m [m], area_m2 [m2], perimeter_m [m], k_W_mK [W/m/K], h_W_m2K [W/m2/K],
    Q1_W at x = 0 and Q2_W at x = l [W]."""

    length_m: float
    area_m2: float
    perimeter_m: float
    k_W_mK: float
    h_W_m2K: float
    Q1_W: float
    Q2_W: float

    @classmethod
    def solid_shaft(cls, length_m: float, radius_m: float, k_W_mK: float, h_W_m2K: float,
                    Q1_W: float, Q2_W: float) -> Fin:
        return cls(length_m, np.pi * radius_m**2, 2 * np.pi * radius_m, k_W_mK, h_W_m2K,
                   Q1_W, Q2_W)

    @property
    def m_1_m(self) -> float:
        """Fin parameter m [1/m]."""
        return float(np.sqrt(self.h_W_m2K * self.perimeter_m / (self.k_W_mK * self.area_m2)))

    def rise_K(self, x_m: float | np.ndarray) -> np.ndarray:
        """Temperature above ambient [K] at x [m] (eq. 14)."""
        x = np.asarray(x_m, dtype=float)
        m, length = self.m_1_m, self.length_m
        den = self.area_m2 * self.k_W_mK * m * np.sinh(m * length)
        return (self.Q1_W * np.cosh(m * (length - x)) + self.Q2_W * np.cosh(m * x)) / den

    def slope_K_m(self, x_m: float | np.ndarray) -> np.ndarray:
        """dT/dx [K/m]."""
        x = np.asarray(x_m, dtype=float)
        m, length = self.m_1_m, self.length_m
        den = self.area_m2 * self.k_W_mK * np.sinh(m * length)
        return (-self.Q1_W * np.sinh(m * (length - x)) + self.Q2_W * np.sinh(m * x)) / den

    def curvature_K_m2(self, x_m: float | np.ndarray) -> np.ndarray:
        """d2T/dx2 [K/m2]."""
        return self.m_1_m**2 * self.rise_K(x_m)
