"""The thermoelastic chain of the lumped model (paper eq. 12, 13, 20, Fig. 5).

The front bearing pair is the fixed bearing: shaft and housing share their axial position at
its middle z_b; the rear pair floats, so nothing else constrains the axial growth. Each
growth reading (every axial-displacement sensor, and TCP when a tool is clamped, as
:meth:`spindle.spec.Spec.growth_points` lists them) is then

    delta = int_{z_b}^{z} beta (T_rot - T_0) dz'  -  int_{z_b}^{z_ref} beta (T_hou - T_0) dz'

along the rotating chain (shaft, then tool) to the reading point and along the housing to
its reference point (eq. 12-13 with the constants fixed by the bearing; eq. 20 for a uniform
temperature). T along a part is linear between its masses, beta is the section's expansion
coefficient, T_0 the stress-free temperature (spec T_initial_K). Each reading is therefore a
fixed row vector on the mass temperatures.

Hooke (spring) and Newton (damper) elements: in a series chain without external load every
spring carries zero force, so quasi-statically springs do not change the growth. A
:class:`KelvinVoigt` element (spring k parallel to damper c) between the chain and a reading
makes the reading lag the elongation, tau = c / k; the paper gives no values, so no reading
has one unless asked (the FEM reference is quasi-static).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from spindle.errors import Problem, SpecError
from spindle.geometry import TOL_M
from spindle.spec import Spec


@dataclass(frozen=True)
class KelvinVoigt:
    """Hooke spring k [N/m] parallel to a Newton damper c [N s/m]: the reading follows the
    free thermal elongation x with k y + c dy/dt = k x, a first-order lag tau = c / k [s]."""

    stiffness_N_m: float
    damping_N_s_m: float

    @property
    def tau_s(self) -> float:
        return self.damping_N_s_m / self.stiffness_N_m

    def filter(self, times_s: np.ndarray, x: np.ndarray) -> np.ndarray:
        """Exact response to x linear between samples, starting at rest on x[0]."""
        return first_order_lag(times_s, x, self.tau_s)


def first_order_lag(times_s: np.ndarray, x: np.ndarray, tau_s: float) -> np.ndarray:
    """Response of tau y' + y = x [s] for x linear between the samples, from y(0) = x(0);
    exact over each step."""
    y = np.empty_like(x)
    y[0] = x[0]
    for k in range(1, len(x)):
        h = times_s[k] - times_s[k - 1]
        a = np.exp(-h / tau_s)
        slope = (x[k] - x[k - 1]) / h
        # y' = (x - y) / tau with x = x0 + slope t: exact over the step
        y[k] = a * y[k - 1] + (1 - a) * x[k - 1] + slope * (h - tau_s * (1 - a))
    return y


def _chain_part(parts: list, z: float):
    for pm in parts:
        z0 = min(s.z_start for s in pm.part.sections)
        z1 = max(s.z_end for s in pm.part.sections)
        if z0 - TOL_M <= z <= z1 + TOL_M:
            return pm
    return None


class GrowthChain:
    """Growth readings [m] as row vectors on the mass temperatures."""

    def __init__(self, spec: Spec, parts: dict, n_states: int,
                 lags: dict[str, KelvinVoigt] | None = None):
        self.spec = spec
        self.T_ref = spec.T_initial_K
        self.lags = dict(lags or {})
        points = spec.growth_points()
        self.rows: dict[str, np.ndarray] = {}
        if not points:
            return
        fixed = spec.parts_with_role("front_bearing")
        if not fixed:
            raise SpecError([Problem(spec.path, "parts", "growth readings need the fixed "
                                     "bearing (a part with role front_bearing)",
                                     "add the front bearing pair, or drop the displacement "
                                     "sensors")])
        fb = fixed[0]
        self.z_fixed = 0.5 * (min(s.z_start for s in fb.sections)
                              + max(s.z_end for s in fb.sections))
        rotating = [parts[p.name] for p in spec.parts if p.role in ("shaft", "tool")]
        housing = [parts[p.name] for p in spec.parts if p.role == "housing"]
        for name, (z, _, z_ref, _) in points.items():
            self.rows[name] = (self._integral(rotating, z, n_states, name)
                               - self._integral(housing, z_ref, n_states, name))
        unknown = set(self.lags) - set(self.rows)
        if unknown:
            raise SpecError([Problem(spec.path, "lags", f"no growth reading {sorted(unknown)}",
                                     f"use one of {sorted(self.rows)}")])

    def _integral(self, chain: list, z_end: float, n: int, name: str) -> np.ndarray:
        """Row w with w . (T - T_0) = integral from z_fixed to z_end of beta (T - T_0) dz."""
        lo, hi = sorted((self.z_fixed, z_end))
        sign = 1.0 if z_end >= self.z_fixed else -1.0
        breaks = {lo, hi}
        for pm in chain:
            breaks |= {m.z_m for m in pm.masses}
            breaks |= {e for s in pm.part.sections for e in (s.z_start, s.z_end)}
        grid = np.array(sorted(b for b in breaks if lo - TOL_M <= b <= hi + TOL_M))
        w = np.zeros(n)
        for p, q in zip(grid, grid[1:], strict=False):
            if q - p <= TOL_M:
                continue
            zm = 0.5 * (p + q)
            pm = _chain_part(chain, zm)
            if pm is None:
                raise SpecError([Problem(self.spec.path, f"sensors.{name}", f"no rotating or "
                                         f"housing part covers z = {zm:.4g} m between the fixed "
                                         "bearing and the reading", "make the shaft/tool and "
                                         "the housing reach the reading's points")])
            sec = max((s for s in pm.part.sections if s.z_start - TOL_M <= zm <= s.z_end + TOL_M),
                      key=lambda s: float(s.r_out(zm) ** 2 - s.r_in(zm) ** 2))
            beta = self.spec.materials[sec.material].alpha_1_K
            for zz in (p, q):  # trapezoid: exact, the temperature is linear between breaks
                for i, c in pm.interpolation(min(max(zz, p), q)).items():
                    w[i] += sign * beta * 0.5 * (q - p) * c
        return w

    def growth(self, x: np.ndarray) -> dict[str, float]:
        """Quasi-static readings [m] from mass temperatures x [K] (no lag)."""
        return {k: float(w @ (x - self.T_ref)) for k, w in self.rows.items()}

    def history(self, times_s: np.ndarray, X: np.ndarray) -> dict[str, np.ndarray]:
        """Readings over time [m] from X (n_times x n_states), lags applied, zeroed at the
        start X[0] (a transient's read-outs are relative to its initial state, as a bench
        zeroes its displacement sensor)."""
        out = {}
        for k, w in self.rows.items():
            y = (X - X[0]) @ w
            out[k] = self.lags[k].filter(times_s, y) if k in self.lags else y
        return out
