"""Thermal performance indicators of paper section 4, from the FEM reference and from the
lumped models (docs/measures.md).

For a steady load case with losses Q [W]:

- **heat stiffness** K_alpha [K/W]: temperature rise per watt of loss, once with the
  spindle's *mean* temperature (volume mean over every part) and once with its *maximum*
  (paper: "the maximum and average spindle temperature can be determined as the products of
  this coefficient on the input power"). The rise is taken above the sink temperature
  T_sink = sum(G_i T_ref,i) / sum(G_i), G_i = h_i A_i the film conductance of every
  convective surface: the temperature of the one environment the simplified formulas
  (eq. 25-30) assume. With coolant and ambient at the same temperature (spl2782 nominal)
  T_sink is simply that temperature.
- **temperature stiffness** K_T [K/µm]: shaft rise (volume mean of the ``shaft`` parts above
  ambient) per µm of axial growth (``TCP`` if a tool is clamped, else ``P1``), read as
  :class:`compare.design.paper.PaperFigures` reads the paper's 41.6 K / 79.7 µm.
- **thermal stiffness** K_Q [W/µm]: losses per µm of that growth.

SI inside; µm only in the names of the reported indicators (``K_T_K_um``, ``K_Q_W_um``).
"""

from __future__ import annotations

import math
import time
import weakref
from dataclasses import asdict, dataclass

import numpy as np

from spindle.errors import SolverError
from spindle.faces import exposed_faces, surface_faces
from spindle.loads import LoadCase
from spindle.spec import Spec

#: the paper's indicators for SPL2782.1 at the nominal point (section 4)
PAPER = {"K_alpha_K_W": 0.00019, "K_T_K_um": 0.52, "K_Q_W_um": 64.53}
#: the paper's own figures they should follow from (section 3: 5146 W of losses, shaft
#: +41.6 K, housing +46.1 K, growth 79.7 µm)
PAPER_FIGURES = {"losses_W": 5146.0, "shaft_rise_K": 41.6, "housing_rise_K": 46.1,
                 "growth_um": 79.7}


def paper_consistency() -> dict[str, float]:
    """The paper's section-4 indicators recomputed from its own section-3 figures.

    K_T = 41.6 / 79.7 = 0.522 K/µm and K_Q = 5146 / 79.7 = 64.57 W/µm reproduce the printed
    0.52 and 64.53; K_alpha from the shaft (41.6 / 5146 = 0.0081 K/W) or the housing
    (46.1 / 5146 = 0.0090 K/W) does not give the printed 0.00019 K/W, which equals 1 K / Q
    (1 / 5146 = 1.94e-4 K/W).
    """
    f = PAPER_FIGURES
    return {"K_T_K_um": f["shaft_rise_K"] / f["growth_um"],
            "K_Q_W_um": f["losses_W"] / f["growth_um"],
            "K_alpha_shaft_K_W": f["shaft_rise_K"] / f["losses_W"],
            "K_alpha_housing_K_W": f["housing_rise_K"] / f["losses_W"],
            "one_kelvin_per_losses_K_W": 1.0 / f["losses_W"],
            "K_alpha_printed_K_W": PAPER["K_alpha_K_W"]}


@dataclass(frozen=True)
class SurfaceFilm:
    """One convective surface at one speed: film coefficient h [W/m2/K], exposed area A
    [m2] (spindle.faces, the same selection as the mesh's), conductance G = h A [W/K]."""

    name: str
    T_ref: str
    h_W_m2K: float
    A_m2: float

    @property
    def G_W_K(self) -> float:
        return self.h_W_m2K * self.A_m2


def surface_films(spec: Spec, speed_rpm: float) -> list[SurfaceFilm]:
    """Every surface of ``spec`` with a film coefficient, at ``speed_rpm``: the surfaces the
    simplified formulas' sum(alpha_i A_i) runs over (coolant jacket included)."""
    faces = exposed_faces(spec)
    return [SurfaceFilm(s.name, str(s.T_ref), s.h_W_m2K(speed_rpm),
                        float(sum(f.area_m2 for f in surface_faces(s, faces, spec))))
            for s in spec.surfaces if s.h_W_m2K is not None]


def sum_alpha_A_W_K(spec: Spec, speed_rpm: float) -> float:
    """sum(alpha_i A_i) [W/K] over every convective surface (see :func:`surface_films`)."""
    return float(sum(f.G_W_K for f in surface_films(spec, speed_rpm)))


def sink_temperature_K(spec: Spec, case: LoadCase, t: float = 0.0,
                       speed_rpm: float | None = None) -> float:
    """Film-conductance weighted mean of the surfaces' reference temperatures [K]."""
    n = float(case.speed_rpm(t)) if speed_rpm is None else speed_rpm
    T_ref = {"ambient": float(case.T_ambient_K(t)), "coolant": float(case.T_coolant_K(t))}
    films = surface_films(spec, n)
    G = sum(f.G_W_K for f in films)
    if G <= 0:
        return T_ref["ambient"]
    return float(sum(f.G_W_K * T_ref[f.T_ref] for f in films) / G)


@dataclass(frozen=True)
class Indicators:
    """Section-4 indicators of one model at one steady load case (SI; see module doc)."""

    model: str
    losses_W: float
    T_ambient_K: float
    T_sink_K: float
    mean_rise_K: float  # volume mean of all parts above T_sink
    max_rise_K: float  # hottest point (FEM) or mass (lumped) above T_sink
    shaft_rise_K: float  # volume mean of the shaft parts above ambient (nan without one)
    housing_rise_K: float  # volume mean of the housing parts above ambient
    growth_reading: str  # "TCP", "P1" or "" (no growth reading)
    growth_m: float  # axial growth [m] (nan without a reading)
    runtime_s: float = 0.0

    @property
    def K_alpha_mean_K_W(self) -> float:
        """Heat stiffness from the mean temperature [K/W]."""
        return self.mean_rise_K / self.losses_W if self.losses_W else math.nan

    @property
    def K_alpha_max_K_W(self) -> float:
        """Heat stiffness from the maximum temperature [K/W]."""
        return self.max_rise_K / self.losses_W if self.losses_W else math.nan

    @property
    def growth_um(self) -> float:
        return self.growth_m * 1e6

    @property
    def K_T_K_um(self) -> float:
        """Temperature stiffness: shaft rise per µm of growth [K/µm]."""
        return self.shaft_rise_K / self.growth_um if self.growth_m else math.nan

    @property
    def K_Q_W_um(self) -> float:
        """Thermal stiffness: losses per µm of growth [W/µm]."""
        return self.losses_W / self.growth_um if self.growth_m else math.nan

    def to_row(self) -> dict[str, float | str]:
        """A flat row with the derived indicators (units in the keys)."""
        row = asdict(self)
        row.update(growth_um=self.growth_um, K_alpha_mean_K_W=self.K_alpha_mean_K_W,
                   K_alpha_max_K_W=self.K_alpha_max_K_W, K_T_K_um=self.K_T_K_um,
                   K_Q_W_um=self.K_Q_W_um)
        del row["growth_m"]
        return row


def growth_reading(readings) -> str:
    """The growth the indicators use: ``TCP`` (tool tip) if there is one, else ``P1``,
    else the first reading, else ''."""
    names = list(readings)
    for k in ("TCP", "P1"):
        if k in names:
            return k
    return names[0] if names else ""


def _parts_volumes(spec: Spec, role: str | None = None) -> dict[str, float]:
    return {p.name: float(sum(s.volume_m3 for s in p.sections)) for p in spec.parts
            if role is None or p.role == role}


_FEM_WEIGHTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _fem_weights(thermal) -> dict[str | None, np.ndarray | None]:
    """w . T = volume mean over all parts (key None), the shaft and the housing parts."""
    if thermal not in _FEM_WEIGHTS:
        spec = thermal.spec
        per_part = {p: thermal.mean_functional(p) for p in _parts_volumes(spec)}
        out: dict[str | None, np.ndarray | None] = {}
        for key, role in ((None, None), ("shaft", "shaft"), ("housing", "housing")):
            vols = _parts_volumes(spec, role)
            total = sum(vols.values())
            out[key] = (sum(per_part[p] * v for p, v in vols.items()) / total) if total else None
        _FEM_WEIGHTS[thermal] = out
    return _FEM_WEIGHTS[thermal]


def fem_indicators(result, label: str | None = None, runtime_s: float = 0.0) -> Indicators:
    """Indicators of a FEM steady result (:class:`reference.results.SteadyResult`)."""
    model = result.model
    spec = model.spec
    w = _fem_weights(model)
    T_amb = float(result.case.T_ambient_K(result.time_s))
    T_sink = sink_temperature_K(spec, result.case, result.time_s, result.speed_rpm)
    reading = growth_reading(result.growth_m)

    def mean(key):
        return float(w[key] @ result.T) if w[key] is not None else math.nan

    return Indicators(
        model=label or f"FEM P{model.order} level {model.smesh.level}",
        losses_W=float(result.heat_in_W), T_ambient_K=T_amb, T_sink_K=T_sink,
        mean_rise_K=mean(None) - T_sink, max_rise_K=float(result.T.max()) - T_sink,
        shaft_rise_K=mean("shaft") - T_amb, housing_rise_K=mean("housing") - T_amb,
        growth_reading=reading,
        growth_m=float(result.growth_m[reading]) if reading else math.nan,
        runtime_s=runtime_s)


def _slice_volume(sec, lo: float, hi: float) -> float:
    """Volume [m3] of ``sec`` between z = lo and hi (Simpson: exact, the area is quadratic)."""
    a, b = max(lo, sec.z_start), min(hi, sec.z_end)
    if b <= a:
        return 0.0
    area = [float(np.pi * (sec.r_out(z) ** 2 - sec.r_in(z) ** 2)) for z in (a, 0.5 * (a + b), b)]
    return (b - a) * (area[0] + 4.0 * area[1] + area[2]) / 6.0


def lumped_mass_volumes(model) -> np.ndarray:
    """Volume [m3] each mass of a :class:`lumped.LumpedModel` stands for (state order): its
    slice of every section of its part; a bearing ring, its section plus its share of the
    rolling layer (as the network splits the capacity). They sum to the spec's volume."""
    vols = np.zeros(model.n_states)
    for pm in model.net.parts.values():
        if pm.ring:
            ring_ids = {id(m.section) for m in pm.masses}
            rest = sum(s.volume_m3 for s in pm.part.sections if id(s) not in ring_ids)
            for m in pm.masses:
                vols[m.index] = m.section.volume_m3 + rest / len(pm.masses)
        else:
            for m in pm.masses:
                vols[m.index] = sum(_slice_volume(s, m.z_lo, m.z_hi) for s in pm.part.sections)
    return vols


def lumped_indicators(result, label: str | None = None, runtime_s: float = 0.0) -> Indicators:
    """Indicators of a lumped steady result (:class:`lumped.results.LumpedSteadyResult`):
    means are volume-weighted over the masses, the maximum is the hottest mass."""
    model = result.model
    spec = model.spec
    vols = lumped_mass_volumes(model)
    T = np.asarray(result.T, dtype=float)
    T_amb = float(result.case.T_ambient_K(result.time_s))
    T_sink = sink_temperature_K(spec, result.case, result.time_s, result.speed_rpm)
    reading = growth_reading(result.growth_m)

    def mean(role):
        idx = [m.index for m in model.masses
               if role is None or spec.part(m.part).role == role]
        return float(vols[idx] @ T[idx] / vols[idx].sum()) if idx else math.nan

    return Indicators(
        model=label or f"lumped {model.nodes} nodes",
        losses_W=float(result.heat_in_W), T_ambient_K=T_amb, T_sink_K=T_sink,
        mean_rise_K=mean(None) - T_sink, max_rise_K=float(T.max()) - T_sink,
        shaft_rise_K=mean("shaft") - T_amb, housing_rise_K=mean("housing") - T_amb,
        growth_reading=reading,
        growth_m=float(result.growth_m[reading]) if reading else math.nan,
        runtime_s=runtime_s)


#: a steady solve whose residual or energy imbalance exceeds this is not a solution
MAX_RELATIVE_IMBALANCE = 1e-6


def check_solution(result) -> None:
    """Raise :class:`~spindle.errors.SolverError` when a steady result is no solution: a
    relative residual or energy imbalance above :data:`MAX_RELATIVE_IMBALANCE` (normally
    1e-12). Specs are checked for a heat path when read, but a modified spec (a measure
    that sets every film to zero) is not, and a singular system solves to garbage."""
    imbalance = float(result.energy["relative_imbalance"])
    if not (result.residual <= MAX_RELATIVE_IMBALANCE and imbalance <= MAX_RELATIVE_IMBALANCE):
        raise SolverError(f"{result.model.spec.path}: the steady problem is singular or "
                          f"ill-posed (relative residual {result.residual:.1e}, energy "
                          f"imbalance {imbalance:.1e}); fix: keep a film coefficient > 0 on "
                          "a surface of every group of parts")
    result.check_plausible(result.model.spec.path)  # temperatures a solid can have


def indicators(model, case: LoadCase | None = None, label: str | None = None) -> Indicators:
    """Solve ``model`` (a :class:`reference.ReferenceModel` or :class:`lumped.LumpedModel`)
    at the steady ``case`` (default: the spec's own inputs) and read its indicators."""
    t0 = time.perf_counter()
    res = model.steady(case or model.spec.default_load_case())
    dt = time.perf_counter() - t0
    check_solution(res)
    if hasattr(model, "thermal"):
        return fem_indicators(res, label, dt)
    return lumped_indicators(res, label or f"lumped {_nodes_label(model)}", dt)


def _nodes_label(model) -> str:
    return f"{model.nodes} nodes"
