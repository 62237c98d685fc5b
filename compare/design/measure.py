"""Design measures of the thermal stiffness strategy (paper section 4): what a measure is and
how it changes a spec.

A **measure** changes the spec's heat dissipation (docs/measures.md):

- ``added_surface``: an added heat-dissipating surface A_M [m2] with coefficient alpha_M
  [W/m2/K] (fins). The model is axisymmetric, so the fins are an added film conductance
  alpha_M A_M spread uniformly over the named host surfaces (fin efficiency 1):
  h_eff = h + alpha_M A_M / sum(A_host), towards the host's own T_ref.
- ``improved_coefficient``: the coefficient of the k named surfaces becomes alpha_M2 (at
  every speed).
- ``both``: the named surfaces get alpha_M2 *and* the added surface, h_eff = alpha_M2 +
  alpha_M A_M / sum(A_host)."""

from __future__ import annotations

from dataclasses import dataclass, replace

from compare.design.formulas import lambda_added, lambda_both, lambda_improved
from compare.design.stiffness import surface_films
from spindle.faces import exposed_faces, surface_faces
from spindle.loads import SpeedTable
from spindle.spec import Spec
from spindle.stretch import stretch_axially

KINDS = ("added_surface", "improved_coefficient", "both")

#: what a sensitivity sweep of the measures file may vary (Fig. 16)
SWEEPS = ("area", "length", "film", "heat")


#: the size an inverse problem varies, by kind (and what "both" may vary instead)
SIZE_FIELDS = {"added_surface": ("A_M_m2",), "improved_coefficient": ("alpha_M2_W_m2K",),
               "both": ("A_M_m2", "alpha_M2_W_m2K")}


@dataclass(frozen=True)
class Measure:
    """A change to the spec's heat dissipation (module doc). Sizes SI: A_M_m2 [m2],
    coefficients [W/m2/K]; fields a kind does not use are None."""

    name: str
    kind: str
    surfaces: tuple[str, ...]
    A_M_m2: float | None = None
    alpha_M_W_m2K: float | None = None
    alpha_M2_W_m2K: float | None = None
    description: str = ""

    def with_size(self, field_name: str, value: float) -> Measure:
        """The same measure with ``A_M_m2`` or ``alpha_M2_W_m2K`` set to ``value``."""
        return replace(self, **{field_name: float(value)})

    @property
    def size_text(self) -> str:
        """The measure's sizes for a report cell, e.g. ``A_M=0.1 m2 at 20 W/m2K``."""
        parts = []
        if self.A_M_m2 is not None:
            parts.append(f"A_M={self.A_M_m2:.4g} m2 at {self.alpha_M_W_m2K:.4g} W/m2K")
        if self.alpha_M2_W_m2K is not None:
            parts.append(f"alpha_M2={self.alpha_M2_W_m2K:.4g} W/m2K")
        return ", ".join(parts)


def _host_area_m2(spec: Spec, names: tuple[str, ...]) -> float:
    faces = exposed_faces(spec)
    return float(sum(f.area_m2 for s in spec.surfaces if s.name in names
                     for f in surface_faces(s, faces, spec)))


def apply_measure(spec: Spec, measure: Measure | None) -> Spec:
    """The spec with the measure's film coefficients (module doc); ``None``: unchanged.

    Speed tables keep their speeds: an added surface adds alpha_M A_M / sum(A_host) to every
    value; an improved coefficient replaces the table by the constant alpha_M2.
    """
    if measure is None:
        return spec
    names = set(measure.surfaces)
    add = 0.0
    if measure.kind in ("added_surface", "both"):
        add = float(measure.alpha_M_W_m2K) * float(measure.A_M_m2) / _host_area_m2(
            spec, measure.surfaces)
    new = []
    for s in spec.surfaces:
        if s.name in names:
            if measure.kind in ("improved_coefficient", "both"):
                h = SpeedTable.constant(float(measure.alpha_M2_W_m2K) + add)
            else:
                h = SpeedTable(s.h_W_m2K.speed_rpm, tuple(v + add for v in s.h_W_m2K.values))
            s = replace(s, h_W_m2K=h)
        new.append(s)
    return replace(spec, surfaces=tuple(new))


def formula_lambda(spec: Spec, measure: Measure, speed_rpm: float) -> tuple[float, float, float]:
    """(lambda_tr, sum(alpha_i A_i) [W/K], added conductance [W/K]) of the simplified
    formulas (eq. 25 consistent form, 27, 29) for ``measure`` on ``spec`` at ``speed_rpm``."""
    films = {f.name: f for f in surface_films(spec, speed_rpm)}
    G0 = sum(f.G_W_K for f in films.values())
    lam = 1.0
    if measure.kind == "added_surface":
        lam = lambda_added(G0, measure.alpha_M_W_m2K, measure.A_M_m2)
    else:
        j = [films[n] for n in measure.surfaces]
        alphas, areas = [f.h_W_m2K for f in j], [f.A_m2 for f in j]
        if measure.kind == "improved_coefficient":
            lam = lambda_improved(G0, measure.alpha_M2_W_m2K, alphas, areas)
        else:
            lam = lambda_both(G0, measure.alpha_M_W_m2K, measure.A_M_m2,
                              measure.alpha_M2_W_m2K, alphas, areas)
    return lam, G0, (lam - 1.0) * G0


def scale_axially(spec: Spec, factor: float) -> Spec:
    """The spec stretched along the axis by ``factor`` (spindle.stretch.stretch_axially); for the
    length sensitivity of Fig. 16."""
    return stretch_axially(spec, factor)


def axial_length_m(spec: Spec) -> float:
    """Axial extent of the spindle (all parts) [m]."""
    zs = [v for _, s in spec.sections() for v in (s.z_start, s.z_end)]
    return max(zs) - min(zs)
