"""The grey box anchored to the FEM reference: the FEM gives the trajectory, the lumped
model the change that parameters and effects make.

The 11-node lumped model is not the FEM. On the same physics and the same inputs it is off by
a model-form error of up to a few tenths of a kelvin at the sensors, and it would need other
film and contact factors than 1 to imitate the FEM (on spl2782 the housing's air films want a
factor of about 3.6). Calibrated directly against a bench run, its base parameters absorb
that error and, with it, any effect whose signature resembles a parameter change: a mount
conduction hides in the air-film factor, and the validation error never shows it.

So the fit simulates

    model(theta) = lumped(theta) + [FEM(theta_spec) - lumped(theta_spec)]

on the run's own inputs: at the spec's parameter values the model *is* the FEM reference, and
away from them the lumped model supplies the sensitivities (a first-order discrepancy
correction, as in Kennedy and O'Hagan 2001). The base parameters get priors around the spec's
values with the widths declared in :data:`compare.fit.greybox.BASE_PARAMS` (``prior_sd``); an
effect is needed when the data would otherwise pull them far outside those widths.

Only the run's inputs (speed, heat from the power balance at the spec's values, ambient,
coolant) enter here, never its measured channels.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from compare.fit.greybox import GreyBox
from compare.fit.params import base_params, default_theta
from spindle.bench_inputs import Inputs
from spindle.loads import LoadCase, TimeSeries
from spindle.spec import Spec


@dataclass(frozen=True)
class Discrepancy:
    """FEM minus lumped at the spec's parameters on one run's inputs [K; m for P1] per
    channel, with its RMS and the FEM level used."""

    theta_ref: dict[str, float]
    offsets: dict[str, np.ndarray]
    rms: dict[str, float]
    fem_level: int


def load_case_from_inputs(spec: Spec, inputs: Inputs, sources_W: dict[str, np.ndarray]
                          ) -> LoadCase:
    """The FEM load case of grey-box inputs: per-interval speed [rpm], heat [W], ambient and
    coolant [K], each held over its interval (the grey box's zero-order hold)."""
    starts = tuple(float(t - inputs.grid_s[0]) for t in inputs.grid_s[:-1])

    def held(values: np.ndarray) -> TimeSeries:
        return TimeSeries(starts, tuple(float(v) for v in values), "previous")

    names = {h.name for h in spec.heat_sources}
    return LoadCase("bench inputs", held(inputs.speed_rpm), held(inputs.T_env_K),
                    held(inputs.T_coolant_K),
                    {k: held(v) for k, v in sources_W.items() if k in names},
                    float(inputs.grid_s[-1] - inputs.grid_s[0]))


def fem_readings(ref, spec: Spec, inputs: Inputs, sources_W: dict[str, np.ndarray],
                 channels: tuple[str, ...] | list[str]) -> dict[str, np.ndarray]:
    """The readings of the FEM reference ``ref`` (a ReferenceModel) at the grid points [K; m
    for P1, zeroed at the start], driven by ``inputs`` and the heat ``sources_W`` [W per
    interval]; channels the model does not read are left out."""
    case = load_case_from_inputs(spec, inputs, sources_W)
    t_rel = inputs.grid_s - inputs.grid_s[0]
    T0 = inputs.T_start_K if inputs.T_start_K is not None else float(inputs.T_env_K[0])
    dt = float(np.median(np.diff(t_rel)))
    if inputs.prehistory_s > 0:
        T0 = _after_prehistory(ref, spec, inputs, sources_W, T0, dt)
    res = ref.transient(case, dt, T0=T0)
    out = {}
    for c in channels:
        if c == "P1" and "P1" in res.growth_m:
            out[c] = np.interp(t_rel, res.times_s, res.growth_m["P1"] - res.growth_m["P1"][0])
        elif c != "P1" and c in res.names:
            out[c] = np.interp(t_rel, res.times_s, res.sensor(c))
    return out


#: steps of the FEM's prehistory at the most (backward Euler; the grey box's is exact): the
#: run's own step up to 400 of them, longer steps beyond (the settled part of a long soak)
PREHISTORY_STEPS = 400


def _after_prehistory(ref, spec: Spec, inputs: Inputs, sources_W: dict[str, np.ndarray],
                      T0: float, dt_s: float) -> np.ndarray:
    """The FEM's field [K] after the first interval's inputs (its heat as
    ``inputs.prehistory_heat_W`` names) held for ``inputs.prehistory_s`` from the uniform
    ``T0`` (compare.fit.start)."""
    tau = float(inputs.prehistory_s)
    first = Inputs(np.array([0.0, tau]), inputs.speed_rpm[:1], inputs.power_kW[:1],
                   inputs.load_torque_Nm[:1], inputs.T_env_K[:1], inputs.T_coolant_K[:1])
    held = inputs.prehistory_heat_W or {}  # a prehistory elsewhere (compare.fit.start)
    case = load_case_from_inputs(spec, first, {k: np.array([held.get(k, v[0])])
                                               for k, v in sources_W.items()})
    return ref.transient(case, max(dt_s, tau / PREHISTORY_STEPS), T0=T0).fields_K[-1]


def reference_channels(gb: GreyBox, channels: tuple[str, ...] | list[str], level: int = 0
                       ) -> dict[str, np.ndarray]:
    """The FEM reference's readings at the grid points [K; m for P1, zeroed at the start],
    driven by the grey box's inputs and its heat sources at the spec's parameter values."""
    from reference import ReferenceModel

    spec_values = base_params(gb.drive)
    src = gb.sources(spec_values["f0"].default, spec_values["rotor_share"].default)
    return fem_readings(ReferenceModel(gb.spec, level), gb.spec, gb.inputs, src, channels)


def fem_discrepancy(gb: GreyBox, channels: tuple[str, ...] | list[str], level: int = 0
                    ) -> Discrepancy:
    """FEM minus lumped (``gb`` without effects, at the spec's values) on ``gb``'s inputs."""
    fem = reference_channels(gb, channels, level)
    theta = default_theta(base_params(gb.drive))
    lumped = gb.plain().simulate(theta)
    offsets = {c: fem[c] - lumped[c] for c in channels}
    rms = {c: float(np.sqrt(np.mean(offsets[c] ** 2))) for c in channels}
    return Discrepancy(theta, offsets, rms, level)

