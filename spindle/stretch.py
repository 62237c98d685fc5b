"""A spec stretched along the axis: the same spindle longer or shorter (a spec's undisclosed
lengths are uncertain by 10-20 %). Fitting calibrates a spindle's axial scale with it and the
design study tries a longer or shorter spindle."""

from __future__ import annotations

import math
from dataclasses import replace

from spindle.spec import Spec


def stretch_axially(spec: Spec, factor: float) -> Spec:
    """The spec stretched along the axis by ``factor`` (every z: sections, surface limits,
    sensors); radii, materials, links, powers and the mesh size h0 stay."""
    def z(v: float) -> float:
        return v * factor if math.isfinite(v) else v

    parts = tuple(replace(p, sections=tuple(replace(s, z_start=z(s.z_start), z_end=z(s.z_end))
                                            for s in p.sections)) for p in spec.parts)
    surfaces = tuple(replace(s, z_min=z(s.z_min), z_max=z(s.z_max)) for s in spec.surfaces)
    sensors = tuple(replace(s, z=z(s.z), z_ref=None if s.z_ref is None else z(s.z_ref))
                    for s in spec.sensors)
    return replace(spec, parts=parts, surfaces=surfaces, sensors=sensors)


def scale_radially(spec: Spec, factor: float) -> Spec:
    """The spec scaled in radius by ``factor`` (every r: sections, sensors and their
    reference points, numeric sensor-array radii): a slimmer or stouter spindle of the same
    lengths; materials, films, links, powers and the mesh size h0 stay."""
    def scaled(pair: tuple[float, float]) -> tuple[float, float]:
        return (pair[0] * factor, pair[1] * factor)

    parts = tuple(replace(p, sections=tuple(replace(s, r_inner=scaled(s.r_inner),
                                                    r_outer=scaled(s.r_outer))
                                            for s in p.sections)) for p in spec.parts)
    sensors = tuple(replace(s, r=s.r * factor, r_ref=None if s.r_ref is None else s.r_ref * factor)
                    for s in spec.sensors)
    arrays = tuple(a if isinstance(a.radius, str) else replace(a, radius=a.radius * factor)
                   for a in spec.sensor_arrays)
    return replace(spec, parts=parts, sensors=sensors, sensor_arrays=arrays)
