"""Where a bench run starts: the spindle's state at the log's first sample.

The grey box starts at the room's temperature, uniform: a spindle that stood in the room
long enough. A log can start elsewhere: warm from running before the logger was started, or
soaked by a chiller that holds the coolant below the room. Its first samples then contradict
that start. Where one of them misses it by more than ``Criteria.start_within_tolerances``,
the model starts instead from the run's first operating point (speed, power, room and
coolant of its first interval) held for a time tau before the log, from the room's
temperature. tau = 0 is the uniform start; a long tau is that point's steady state (a soak at
rest, or a spindle that ran there). Where no tau reaches the first samples, the spindle ran
elsewhere before the log (a log begun lightly loaded after heavy work): the prehistory's heat
is read as well, a fraction of the run's own largest heat in the motor and, apart, in the
bearings (:func:`_elsewhere`). tau is first the one value that best reproduces the first
samples of the temperature channels with the spec's model; the FEM anchor starts from it, and
the grey box calibrates it (and a prehistory elsewhere's heat, PREHISTORY_HEAT) with the base
parameters from there (compare.fit.params.PREHISTORY):
the first hours' relaxation says more of the unsensed slow masses than three first samples
(docs/fit.md, step 1; docs/fit-history.md, "2026-11-29 (17)").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, minimize_scalar

from compare.fit.calibrate import TOLERANCE
from compare.fit.criteria import Criteria
from compare.fit.greybox import GreyBox, heat_groups
from spindle.bench import BenchRun

#: the tried prehistories per decade between the grid's step and Criteria.prehistory_max_s,
#: before the best is refined between its neighbours
_PER_DECADE = 12


@dataclass(frozen=True)
class Start:
    """A run's start: the first samples [K] of the temperature channels that log one in
    the grid's first interval, the uniform start's misfit and the chosen start's [tolerances]
    per channel, and the prehistory [s] (0: the uniform start)."""

    first_K: dict[str, float]
    uniform_misfit: dict[str, float]
    misfit: dict[str, float]
    prehistory_s: float
    #: Criteria.start_within_tolerances of the fit
    within: float = 1.0
    #: the prehistory's heat [W] by source, where it is not the first interval's
    heat_W: dict[str, float] | None = None

    def text(self) -> str:
        """The warning for a start off the uniform one ("" where the first samples agree)."""
        if not self.moved:
            return ""
        worst = max(self.uniform_misfit, key=lambda c: abs(self.uniform_misfit[c]))
        text = (f"the run does not start at the room's temperature: {worst}'s first sample is "
                f"{self.uniform_misfit[worst] * TOLERANCE[worst]:+.1f} K from a uniform start")
        if self.prehistory_s > 0:
            if self.heat_W:
                text += (", so the model starts from a prehistory that ran elsewhere (no time "
                         "at the run's first operating point reaches the first samples): "
                         f"{self.group_W('motor'):.0f} W in the motor and "
                         f"{self.group_W('bearings'):.0f} W in the bearings for "
                         f"{self.prehistory_s / 3600:.2f} h, read from the first samples")
            else:
                text += (", so the model starts from the run's first operating point held "
                         "for a prehistory before the log: read from the first samples as "
                         f"{self.prehistory_s / 3600:.2f} h")
            text += (", which leaves " + ", ".join(f"{c} {v * TOLERANCE[c]:+.2f} K"
                                           for c, v in self.misfit.items())
                     + " there, and calibrated with the base from it ("
                     + ("prehistory_h and its heat's multiples, prehistory_motor_x and "
                        "prehistory_bearings_x" if self.heat_W else "prehistory_h") + ")")
        if not self.reached:
            text += ("; no prehistory of the run's heat reaches the logged start, so part of "
                     "the first hours' misfit is the start's")
        return text + " (compare.fit.start)"

    def group_W(self, group: str) -> float:
        """The prehistory's heat [W] in the motor's sources or the bearings'
        (compare.fit.greybox.heat_groups)."""
        return heat_groups(self.heat_W or {}).get(group, 0.0)

    @property
    def moved(self) -> bool:
        """Whether the first samples contradict the uniform start (beyond ``within``)."""
        return any(abs(v) > self.within for v in self.uniform_misfit.values())

    @property
    def reached(self) -> bool:
        """Whether the chosen start meets every first sample within ``within``."""
        return all(abs(v) <= self.within for v in self.misfit.values())

    def to_dict(self) -> dict:
        return {"prehistory_s": self.prehistory_s, "prehistory_heat_W": self.heat_W,
                "reached": self.reached,
                "first_K": self.first_K, "uniform_misfit_tolerances": self.uniform_misfit,
                "misfit_tolerances": self.misfit}


def first_samples(run: BenchRun, channels: list[str], grid_s: np.ndarray) -> dict[str, float]:
    """The first sample [K] of each temperature channel of ``channels`` logged in the grid's
    first interval: the state at the start (a median over the interval would blur it where
    the coolant acts within the first minute, as on the peer's dev-03)."""
    out = {}
    for c in channels:
        if c == "P1":
            continue
        t, y = run.channel(c)
        if len(t) and t[0] <= grid_s[1]:
            out[c] = float(y[0])
    return out


def run_start(gb: GreyBox, theta: dict[str, float], first_K: dict[str, float],
              criteria: Criteria) -> Start:
    """The start of a run whose first samples are ``first_K``, for the grey box ``gb`` at
    ``theta`` (the spec's values: module docstring)."""
    readings = gb.start_readings(theta)

    def misfit(tau: float, heat_W: dict[str, float] | None = None) -> dict[str, float]:
        y = readings(tau, heat_W)
        return {c: (v - y[c]) / TOLERANCE[c] for c, v in first_K.items() if c in y}

    def cost(tau: float) -> float:
        return float(sum(v * v for v in misfit(tau).values()))

    uniform = misfit(0.0)
    if not uniform or max(abs(v) for v in uniform.values()) <= criteria.start_within_tolerances:
        return Start(first_K, uniform, uniform, 0.0, criteria.start_within_tolerances)
    step = float(np.median(np.diff(gb.inputs.grid_s)))
    decades = np.log10(criteria.prehistory_max_s / step)
    taus = np.r_[0.0, np.geomspace(step, criteria.prehistory_max_s,
                                   max(int(decades * _PER_DECADE), 2))]
    costs = [cost(t) for t in taus]
    i = int(np.argmin(costs))
    if costs[i] >= costs[0] * (1.0 - 1e-9):  # no gain beyond rounding: the uniform start
        i = 0
    best = float(taus[i])
    if 0 < i < len(taus) - 1:  # refined in log tau between the neighbours
        res = minimize_scalar(lambda u: cost(float(np.exp(u))),
                              bounds=(np.log(max(taus[i - 1], step)), np.log(taus[i + 1])),
                              method="bounded", options={"xatol": 1e-3})
        if res.fun < costs[i]:
            best = float(np.exp(res.x))
    begins = Start(first_K, uniform, misfit(best), best, criteria.start_within_tolerances)
    if begins.reached:
        return begins
    return _elsewhere(gb, theta, begins, misfit, step, criteria) or begins


def _elsewhere(gb: GreyBox, theta: dict[str, float], held: Start, misfit, step_s: float,
               criteria: Criteria) -> Start | None:
    """Where no time at the first operating point reaches the first samples, the spindle ran
    elsewhere before the log: its prehistory's heat is read as well, a fraction in [0, 1] of
    the run's own largest heat in the motor and, apart, in the bearings (the two heat T_stator
    and the rings in other proportions; a spindle runs before its log as within it, so no
    more). None where that does not start nearer the first samples than ``held``; ``misfit``
    (tau [s], heat [W] by source): the first samples' misfit [tolerances] from that start."""
    hottest = gb.hottest(theta)
    first = heat_groups({k: float(v[0]) for k, v in gb.sources(
        theta["f0"], theta["rotor_share"], theta.get("friction_exponent", 0.0)).items()})
    peaks = list(hottest.values())
    top = [sum(peak.values()) for peak in peaks]
    f0 = [float(np.clip(first[g] / t, 0.0, 1.0)) if t > 0 else 0.0
          for g, t in zip(hottest, top, strict=True)]

    def heat(f) -> dict[str, float]:
        return {k: float(fg) * v for fg, peak in zip(f, peaks, strict=True)
                for k, v in peak.items()}

    def at(z) -> dict[str, float]:
        return misfit(float(np.exp(z[0])), heat(z[1:]))

    lo = np.r_[np.log(step_s), np.zeros(len(peaks))]
    hi = np.r_[np.log(criteria.prehistory_max_s), np.ones(len(peaks))]
    z0 = np.clip(np.r_[np.log(max(held.prehistory_s, step_s)), f0], lo, hi)
    sol = least_squares(lambda z: list(at(z).values()), z0, bounds=(lo, hi))
    end = at(sol.x)
    if sum(v * v for v in end.values()) >= sum(v * v for v in held.misfit.values()):
        return None
    return Start(held.first_K, held.uniform_misfit, end, float(np.exp(sol.x[0])), held.within,
                 heat(sol.x[1:]))
