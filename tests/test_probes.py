"""Sensor probes on the mesh boundary (reference.thermal.ThermalModel.probe_matrix)."""

import numpy as np
import pytest

from reference import ReferenceModel
from reference.probes import PROBE_NUDGE_M
from spindle.spec_reader import load_spec


def test_a_point_a_rounding_outside_the_boundary_is_probed_at_the_boundary():
    """A P2 field linear in z is interpolated exactly; a point 1e-12 m beyond the shaft's end
    face (a sensor on an end face after a stretched spec's rounding) reads the end face's
    value to within the nudge; a point 1 mm outside is still an error."""
    model = ReferenceModel(load_spec("fin-shaft"), level=0)
    th = model.thermal
    mesh = th.basis.mesh
    z_end = float(mesh.p[0].max())
    r = 0.5 * float(mesh.p[1].max())
    T = th.quadrature_basis().project(lambda x: x[0])  # T = z [K]
    outside = np.array([[z_end + 1e-12], [r]])
    with pytest.raises(ValueError):  # scikit-fem alone: outside the mesh
        th.basis.probes(outside)
    P = th.probe_matrix(outside)
    assert (P @ T)[0] == pytest.approx(z_end, abs=2 * PROBE_NUDGE_M)
    with pytest.raises(ValueError):
        th.probe_matrix(np.array([[z_end + 1e-3], [r]]))


def test_a_tool_tip_with_more_digits_than_the_mesh_is_probed():
    """spl2782 slimmed to 0.75 and stretched by 1.25 and 1.125...: the tool tip's z
    (1.025938182497583 m) lies 5e-10 m beyond the mesh, whose axial cuts are rounded to 1 nm,
    at the axis, where the direction to the nearest element's centroid is nearly radial, so a
    move of 1 nm did not bring it inside and the TCP reading raised "Point is outside of the
    mesh" (found by bench_families --geometry 0.75 1.25, run effect-7). The reading is now
    made."""
    from spindle.stretch import scale_radially, stretch_axially

    spec = stretch_axially(stretch_axially(scale_radially(load_spec("spl2782"), 0.75), 1.25),
                           1.1250864235751425)
    model = ReferenceModel(spec, level=0)
    z, r = model.spec.growth_points()["TCP"][:2]
    assert z > float(model.elastic.basis.mesh.p[0].max())  # the tip lies beyond the mesh
    g, _ = model.elastic.gain("TCP")
    assert np.all(np.isfinite(g)) and np.abs(g).max() > 0
