"""The FEM reference as a grey box: the seven base parameters applied to the FEM itself.

``spindle-verify fit --model fem`` calibrates the base parameters (:data:`BASE_PARAMS`) on
this model instead of the anchored lumped one, so the calibrated values carry the FEM's
sensitivities, not the 11-node model's (compare.fit.run). It has the interface
:class:`compare.fit.Calibrator` uses from :class:`compare.fit.greybox.GreyBox` (``spec``,
``drive``, ``inputs``, ``nodes``, ``effects``, ``_cache``, ``discrepancy``,
``parameters()``, ``variant()``, ``simulate()``), for the base parameters only: the candidate
effects live in the lumped model (``variant`` with an effect raises).

How each parameter enters, on one :class:`reference.ReferenceModel` built once:

- ``f0``, ``rotor_share``: the heat sources, from the power balance exactly as the grey box
  computes them (:meth:`GreyBox.sources`), driven through
  :func:`compare.fit.discrepancy.load_case_from_inputs`;
- ``h_coolant``, ``h_air``, ``h_rotating``: factors on the film coefficients h of the spec's
  surfaces, grouped as the grey box groups them (:func:`compare.fit.greybox.film_groups`);
- ``contact`` and ``stator_contact``: factors on the interface coefficient h_c of the spec's
  contact links, the second on those of the stator, the first on every other
  (``op.contacts`` holds exactly the spec's ContactLinks; the grey box's contact edges are
  the lumped edges between parts joined by a ContactLink, the same joints). Note that the
  lumped grey box multiplies its whole contact edge, interface *and* the solid conduction to
  the mass centres, while here only h_c is scaled, as the spec's value means;
- ``alpha_eff``: multiplies P1 (below).

Film and contact factors are applied as :meth:`compare.design.paper.PaperStudy.apply` does, by
swapping coefficients in the assembled operator (no reassembly), then dropping the cached LU
factors. Results are kept for the last few parameter sets (a Jacobian revisits points); the
thermal solve does not depend on ``alpha_eff``, so its Jacobian column costs no FEM run.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from compare.fit.greybox import GreyBox, Inputs, film_groups
from compare.fit.params import BASE_PARAMS, Param, base_params
from spindle.drive import Drive
from spindle.spec import Spec

#: parameters that enter the thermal solve (alpha_eff only scales P1 afterwards)
_THERMAL = tuple(k for k in BASE_PARAMS if k != "alpha_eff")
#: FEM results kept (a Jacobian of the six thermal parameters, its centre and a step)
_KEEP = 10


@dataclass
class FemGreyBox:
    """The FEM reference of ``spec`` (mesh ``level``) with the base parameters, simulated on
    ``inputs`` (same channels and grid as :class:`GreyBox`)."""

    spec: Spec
    drive: Drive
    inputs: Inputs
    nodes: int = 11  # the lumped model whose _sources supplies the heat (same power balance)
    level: int = 0
    effects: tuple[str, ...] = ()
    _cache: dict = field(default_factory=dict, repr=False)
    #: per channel, added to every simulation (as in GreyBox; None here in fitrun)
    discrepancy: dict[str, np.ndarray] | None = field(default=None, repr=False)
    #: called with one line per FEM run (fitrun passes its progress)
    progress: Callable[[str], None] | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.effects:
            raise ValueError(_NO_EFFECTS.format(effects=", ".join(self.effects)))

    # ------------------------------------------------------------------ interface
    def variant(self, effects: tuple[str, ...]) -> FemGreyBox:
        """The same model; any effect raises (FEM calibration is of the base parameters)."""
        if tuple(effects):
            raise ValueError(_NO_EFFECTS.format(effects=", ".join(effects)))
        return self

    def parameters(self) -> dict[str, Param]:
        return base_params(self.drive)

    @property
    def fem_runs(self) -> int:
        return self._cache.get("fem_runs", 0)

    @property
    def fem_seconds(self) -> float:
        return self._cache.get("fem_seconds", 0.0)

    # ------------------------------------------------------------------ FEM
    def _reference(self):
        """The ReferenceModel, built once, with the operator's original coefficients."""
        key = ("fem_model", self.level)
        if key not in self._cache:
            from reference import ReferenceModel

            ref = ReferenceModel(self.spec, self.level)
            op = ref.thermal.op
            groups = film_groups(self.spec)
            films = [(s, R, b, groups.get(s.name)) for s, R, b in op.films]
            self._cache[key] = (ref, films, list(op.contacts), list(op.links))
            self._cache["fem_applied"] = None
        return self._cache[key]

    def _apply(self, th: dict[str, float]) -> object:
        """Swap the film and contact coefficients for ``th``'s factors (PaperStudy.apply)."""
        ref, films, contacts, links = self._reference()
        names = ("h_coolant", "h_air", "h_rotating", "contact", "stator_contact")
        factors = tuple(float(th[k]) for k in names)
        if self._cache.get("fem_applied") != factors:
            f = dict(zip(names, factors, strict=True))
            stator = {p.name for p in self.spec.parts if p.role == "stator"}
            # a factor of exactly 1 keeps the spec's own object: the default point is then the
            # FEM reference of compare.fit.discrepancy bit for bit
            ref.thermal.set_coefficients(
                films=[(s if g is None or f[g] == 1.0 else
                        replace(s, h_W_m2K=s.h_W_m2K.scaled(f[g])), R, b)
                       for s, R, b, g in films],
                contacts=[(lk if f[g] == 1.0 else replace(lk, h_W_m2K=lk.h_W_m2K * f[g]), C)
                          for lk, C in contacts
                          for g in ["stator_contact" if set(lk.parts) & stator else "contact"]],
                links=links)  # no air-gap parameter in the grey box
            self._cache["fem_applied"] = factors
        return ref

    def _thermal_run(self, th: dict[str, float]) -> dict[str, np.ndarray]:
        """T1, T2, T_stator [K] and P1 at alpha_eff = 1 [m, zeroed at the start] on the grid."""
        key = ("fem", self.level, *(round(float(th[k]), 12) for k in _THERMAL))
        hit = self._cache.get(key)
        if hit is not None:
            self._cache[key] = self._cache.pop(key)  # most recently used last
            return hit
        from compare.fit.discrepancy import fem_readings

        t0 = time.perf_counter()
        ref = self._apply(th)
        lumped = GreyBox(self.spec, self.drive, self.inputs, self.nodes, _cache=self._cache)
        src = lumped.sources(float(th["f0"]), float(th["rotor_share"]))
        # the same read-out as compare.fit.discrepancy's reference_channels, so the default
        # point is that run exactly
        out = fem_readings(ref, self.spec, self.inputs, src, ("T1", "T2", "T_stator", "P1"))
        runs = [k for k in self._cache if isinstance(k, tuple) and k[:1] == ("fem",)]
        for k in runs[:max(len(runs) - _KEEP + 1, 0)]:
            del self._cache[k]
        self._cache[key] = out
        seconds = time.perf_counter() - t0
        self._cache["fem_runs"] = self.fem_runs + 1
        self._cache["fem_seconds"] = self.fem_seconds + seconds
        if self.progress is not None:
            self.progress(f"FEM run {self.fem_runs} ({seconds:.1f} s): " + ", ".join(
                f"{k}={th[k]:.4g}" for k in _THERMAL))
        return out

    def simulate(self, theta: dict[str, float], x0_K: float | None = None
                 ) -> dict[str, np.ndarray]:
        """Channel values at the grid points [K; m for P1, zeroed at the start] for the base
        parameters ``theta`` (missing names take their defaults)."""
        if x0_K is not None:
            raise ValueError("FemGreyBox starts from the inputs' start temperature only")
        th = {k: float(theta.get(k, p.default)) for k, p in base_params(self.drive).items()}
        out = {c: v.copy() for c, v in self._thermal_run(th).items()}
        if "P1" in out:
            # the thermoelastic growth is linear in a uniform scale of the expansion
            # coefficients (thermal strain alpha (T - T_ref) is the only load, and the
            # elastic problem is linear), so scaling them by alpha_eff scales P1 by alpha_eff:
            # the same read-out factor the lumped grey box applies to its growth chain
            out["P1"] = th["alpha_eff"] * out["P1"]
        for c, d in (self.discrepancy or {}).items():
            if c in out:
                out[c] = out[c] + d
        return out


_NO_EFFECTS = ("the FEM grey box calibrates the base parameters only, not effects "
               "({effects}): select effects on the lumped grey box anchored at the "
               "FEM-calibrated point (compare.fit.run, --model fem)")
