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

The cycles such a run follows are drawn too (:func:`spindle.cycles.drawn_cycle`).
Everything is drawn from the seed, so a run is reproducible from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from compare.fit.greybox import film_groups
from spindle.drive import Drive
from spindle.spec import ContactLink, Spec
from spindle.stretch import stretch_axially


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
