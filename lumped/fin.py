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

    def sensors_rise_K(self, count: int = 11) -> np.ndarray:
        """Rise above ambient [K] at ``count`` points spaced l/(count-1), the paper's 11
        virtual sensors at l/10."""
        return self.rise_K(np.linspace(0.0, self.length_m, count))

    @classmethod
    def from_spec(cls, spec, part: str = "shaft", speed_rpm: float | None = None,
                  Q1_W: float | None = None, Q2_W: float | None = None,
                  h_W_m2K: float | None = None) -> Fin:
        """Eq. 14 for one part of a spec (SI).

        Length l = the part's axial extent; A = volume / l (mean cross-section); P = outer
        lateral area / l (mean perimeter); lambda = volume-weighted k_z of its materials.
        ``h_W_m2K`` defaults to the effective alpha: the film conductance of all the part's
        convective surfaces at ``speed_rpm`` (spec speed if None), spread over its lateral
        area. ``Q1_W`` / ``Q2_W`` default to the heat sources on the part's rear and front end
        faces; a part without such sources needs them given. ``spec``: a Spec, a shipped name
        or a path.
        """
        from spindle.errors import Problem, SpecError
        from spindle.faces import exposed_faces, surface_faces
        from spindle.spec_reader import as_spec

        spec = as_spec(spec)

        p = spec.part(part)
        z0 = min(s.z_start for s in p.sections)
        z1 = max(s.z_end for s in p.sections)
        length = z1 - z0
        volume = sum(s.volume_m3 for s in p.sections)
        k = sum(spec.materials[s.material].k_z_W_mK * s.volume_m3 for s in p.sections) / volume
        lateral = sum(np.pi * (s.r_outer[0] + s.r_outer[1])
                      * np.hypot(s.length, s.r_outer[1] - s.r_outer[0]) for s in p.sections)
        faces = exposed_faces(spec)
        n = spec.speed_rpm if speed_rpm is None else speed_rpm
        if h_W_m2K is None:
            hA = sum(s.h_W_m2K(n) * sum(f.area_m2 for f in surface_faces(s, faces, spec)
                                        if f.part == part)
                     for s in spec.surfaces if s.h_W_m2K is not None)
            h_W_m2K = hA / lateral
        Q = {"rear": Q1_W, "front": Q2_W}
        for end, value in Q.items():
            if value is not None:
                continue
            names = {s.name for s in spec.surfaces
                     if part in s.parts and s.side == end and s.h_W_m2K is None}
            found = [src for src in spec.heat_sources if src.surface in names]
            if not found:
                raise SpecError([Problem(spec.path, "heat_sources", f"no heat source on the "
                                         f"{end} end face of '{part}' for eq. 14",
                                         f"give Q{1 if end == 'rear' else 2}_W explicitly")])
            Q[end] = sum(float(src.power_W(0.0)) for src in found)
        return cls(float(length), float(volume / length), float(lateral / length), float(k),
                   float(h_W_m2K), float(Q["rear"]), float(Q["front"]))
