"""Structural mismatch for synthetic bench runs (issue 13 §2): data from a spindle that the
spec describes only approximately, and cycles that are not the spec's own.

A real bench run never comes from the spec ``fit`` calibrates. :func:`draw_mismatch` draws,
per seed, a spindle that differs from the spec by amounts a spec written from CAD and
catalogue data plausibly misses, and :meth:`Mismatch.apply` builds it:

- geometry: the whole spindle stretched along the axis by 0.85-1.15 (every z: sections,
  surfaces, sensors; 10-20 % is the CAD assumption's spread on the undisclosed lengths);
- film coefficients x 0.5-2 per surface group (coolant jacket, housing to air, rotating
  surfaces), log-uniform: correlations scatter by that much between installations;
- contact conductances of the fitted joints x 0.5-2, log-uniform;
- bearing friction: f0 x 0.7-1.4 and a speed exponent -0.3..0.3 (``Drive.friction_exponent``);
- the motor's loss split: rotor share 0.03-0.15 (the spec: 0.06);
- the FEM level the data come from (1 or 2; ``fit`` anchors on level 0).

:func:`random_cycle` makes a cycle the spec does not have: non-monotonic speed steps up to
the drive's maximum speed, optionally loaded, with the ambient drift and chiller cycling of
the shipped cycles. Everything is drawn from the seed, so a run is reproducible from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from compare.fit.greybox import film_groups
from spindle.cycles import Cycle, Step, chiller_cycling, drifting_ambient
from spindle.drive import Drive
from spindle.spec import ContactLink, Spec, stretch_axially


@dataclass(frozen=True)
class Mismatch:
    """How the data's spindle differs from the spec (factors are multiplicative)."""

    films: dict[str, float]  # per film group (compare.fit.greybox.film_groups): factor
    contact: float
    axial_scale: float
    f0_factor: float
    friction_exponent: float
    rotor_share: float
    fem_level: int

    def apply(self, spec: Spec, drive: Drive) -> tuple[Spec, Drive]:
        """The mismatched spindle: its spec and its drive."""
        d = (drive.with_f0(drive.bearings[next(iter(drive.bearings))].f0 * self.f0_factor)
             .with_friction_exponent(self.friction_exponent)
             .with_rotor_share(self.rotor_share))
        return self.apply_to_spec(spec), d

    def apply_to_spec(self, spec: Spec) -> Spec:
        """The spec part of the mismatch: film groups, contacts, axial stretch."""
        groups = film_groups(spec)
        surfaces = tuple(
            s if s.h_W_m2K is None or groups.get(s.name) not in self.films else
            replace(s, h_W_m2K=s.h_W_m2K.scaled(self.films[groups[s.name]]))
            for s in spec.surfaces)
        links = tuple(replace(lk, h_W_m2K=lk.h_W_m2K * self.contact)
                      if isinstance(lk, ContactLink) else lk for lk in spec.links)
        return stretch_axially(replace(spec, surfaces=surfaces, links=links), self.axial_scale)

    def to_dict(self) -> dict:
        return {"films": dict(self.films), "contact": self.contact,
                "axial_scale": self.axial_scale, "f0_factor": self.f0_factor,
                "friction_exponent": self.friction_exponent, "rotor_share": self.rotor_share,
                "fem_level": self.fem_level}


def ramped_steps(speed_rpm: float, duration_s: float, low_Nm: float, high_Nm: float,
                 step_s: float = 300.0) -> list[Step]:
    """One speed step of ``duration_s`` [s] cut into ``step_s`` pieces (the last takes the
    remainder, so the pieces keep a time step's grid: a FEM run factorises once per step
    length) whose process torque [N m] rises linearly from ``low_Nm`` to ``high_Nm`` over the
    first half and falls back over the second (rounded to 0.1 N m)."""
    k = max(int(duration_s // step_s), 2)
    edges = np.concatenate([np.arange(k) * (duration_s / k if duration_s < 2 * step_s
                                            else step_s), [duration_s]])
    mid = 0.5 * (edges[:-1] + edges[1:]) / duration_s
    shape = 1.0 - np.abs(2.0 * mid - 1.0)
    return [Step(speed_rpm, float(b - a), round(low_Nm + (high_Nm - low_Nm) * float(f), 1))
            for a, b, f in zip(edges[:-1], edges[1:], shape, strict=True)]


def _log_uniform(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def draw_mismatch(rng: np.random.Generator) -> Mismatch:
    """A mismatched spindle for this random state (ranges: the module docstring)."""
    return Mismatch(
        films={g: _log_uniform(rng, 0.5, 2.0) for g in ("h_coolant", "h_air", "h_rotating")},
        contact=_log_uniform(rng, 0.5, 2.0),
        axial_scale=float(rng.choice([-1.0, 1.0]) * rng.uniform(0.10, 0.15) + 1.0),
        f0_factor=float(rng.uniform(0.7, 1.4)),
        friction_exponent=float(rng.uniform(-0.3, 0.3)),
        rotor_share=float(rng.uniform(0.03, 0.15)),
        fem_level=int(rng.choice([1, 2])))


def perturbed_spec(spec: Spec, seed: int) -> Spec:
    """``spec`` with the geometry, film groups and contacts of seed ``seed``'s mismatch
    (:func:`draw_mismatch`; the drive's parameters stay the spec's): a spec that is yet
    further off a bench's spindle, to check that ``fit``'s verdicts do not hang on the spec
    being close (benchmarks/bench_devruns.py --spec-mismatch). ``seed`` >= 0."""
    if seed < 0:
        raise ValueError(f"the seed of a spec's perturbation is >= 0, not {seed}")
    return draw_mismatch(np.random.default_rng([seed, 1])).apply_to_spec(spec)


def random_cycle(rng: np.random.Generator, max_speed_rpm: float, loaded: bool = False,
                 duration_h: float = 16.0, ramped: bool = False) -> Cycle:
    """A 16 h cycle the spec does not have: a standstill start, speed steps of 45-120 min in a
    random (non-monotonic) order over 15-100 % of ``max_speed_rpm`` [rpm], rounded to
    100 rpm, the top speed among them, and a 2 h cool-down; loaded runs hold a process torque
    of 0-40 N m per step. ``ramped`` (a loaded run as a bench logs one, e.g. a peer's
    ../shared/bench-runs/dev-08): within each speed step the torque ramps from a low level of
    5-20 N m up to 10-25 N m above it and back, in 5 min steps (:func:`ramped_steps`). Ambient
    drift and chiller cycling as the shipped cycles."""
    total = duration_h * 3600.0
    cool = 7200.0
    steps = [Step(0.0, 900.0)]
    plateau_of = [-1]  # the speed plateau (index into speeds) of each step
    t = 900.0
    speeds = []
    while t < total - cool - 1800.0:
        dur = min(float(rng.uniform(45, 120)) * 60.0, total - cool - t)
        n = round(float(rng.uniform(0.15, 1.0)) * max_speed_rpm / 100.0) * 100.0
        speeds.append(n)
        torque = round(float(rng.uniform(0.0, 40.0)), 1) if loaded else 0.0
        if ramped:  # whole minutes, so that the 5 min pieces keep the 60 s grid
            dur = 60.0 * round(dur / 60.0)
            low = float(rng.uniform(5.0, 20.0))
            pieces = ramped_steps(n, dur, low, low + float(rng.uniform(10.0, 25.0)))
        else:
            pieces = [Step(n, dur, torque)]
        steps.extend(pieces)
        plateau_of.extend([len(speeds) - 1] * len(pieces))
        t += dur
    if max_speed_rpm not in speeds:  # the top speed at least once, somewhere in the middle
        middle = (1 + len(speeds)) // 2  # that plateau's steps, all of them when ramped
        steps = [replace(s, speed_rpm=float(max_speed_rpm)) if plateau == middle else s
                 for s, plateau in zip(steps, plateau_of, strict=True)]
    steps.append(Step(0.0, total - t))
    name = "random-ramped-load" if ramped else f"random{'-loaded' if loaded else ''}"
    return Cycle(name=name,
                 description="random non-monotonic speed steps (compare.fit.mismatch)",
                 source="generated", steps=tuple(steps),
                 T_ambient_K=drifting_ambient(total), T_coolant_K=chiller_cycling(total))
