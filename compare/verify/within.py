"""One model of a spindle against the FEM reference, as one figure each: the worst
temperature error over the spec's sensors (K; over time for a transient) and the P1 error
(µm), as compare.verify.accuracy computes them. :func:`model_error` returns them,
:func:`assert_within` raises ``AssertionError`` when one exceeds its tolerance. The public
names are ``spindle_verify.model_error`` and ``spindle_verify.assert_within``; the pytest
fixture ``spindle_verify`` (spindle_verify.pytest_plugin) calls them.

``model`` is ``"lumped:N"`` (N an integer or paper5 / paper11) or ``"fem:L"`` (mesh level);
``case`` a shipped cycle name (``nominal`` is steady, other cycles are transients) or None
for the spec's own steady load case. The reference is the FEM at ``reference_level``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from compare.verify.accuracy import (
    TOL_GROWTH_UM,
    TOL_TEMP_K,
    AccuracyResult,
    Entry,
    fem_entry,
    lumped_entries,
    worst_temperature_K,
)


@dataclass
class Verdict:
    """A model's errors against the reference: the worst temperature error [K], the P1 error
    [µm] (nan where the model has no P1) and the whole row of errors."""

    model: str
    worst_temp_K: float
    P1_um: float
    row: dict


def model_error(spec_ref: str, model: str, case: str | None = None, reference_level: int = 2,
                dt_s: float = 120.0) -> Verdict:
    """Errors of ``model`` against the FEM reference on ``case`` (see the module doc)."""
    from spindle.arguments import model_choice, real_number, whole_number
    from spindle.drive import as_load_case
    from spindle.spec_reader import as_spec
    from spindle.units import MESH_LEVEL_MAX

    spec = as_spec(spec_ref)
    kind, size = model_choice(model)
    reference_level = whole_number(reference_level, "reference_level", 0, MESH_LEVEL_MAX)
    dt_s = real_number(dt_s, "dt_s", 1e-9, unit="s")
    load = as_load_case(spec, case)  # None: the spec's own steady case
    transient = case is not None and case != "nominal"
    dt = dt_s if transient else None
    T0 = float(load.T_ambient_K(0.0)) if transient else None
    ref = fem_entry(spec, reference_level, load, dt, T0)
    if kind == "lumped":
        nodes = size
        if isinstance(nodes, str):
            from lumped import PRESETS

            if nodes not in PRESETS:
                raise ValueError(f"model '{model}': N is a number of masses or one of "
                                 f"{sorted(PRESETS)}")
            nodes = PRESETS[nodes]
        entry: Entry = lumped_entries(spec, load, [nodes], dt, T0)[0]
    else:
        entry = fem_entry(spec, size, load, dt, T0)
    acc = AccuracyResult(spec, load.name, transient, ref, f"FEM level {reference_level}",
                         [entry])
    row = acc.errors(entry)
    return Verdict(model, worst_temperature_K(row), row.get("P1_max_um", math.nan), row)


def assert_within(spec: str, model: str, case: str | None = None,
                  tol_temp_K: float = TOL_TEMP_K, tol_growth_um: float = TOL_GROWTH_UM,
                  reference_level: int = 2, dt_s: float = 120.0) -> Verdict:
    """:func:`model_error`, and ``AssertionError`` with a readable message when the worst
    temperature error exceeds ``tol_temp_K`` [K] or the P1 error ``tol_growth_um`` [µm]
    (defaults: the paper's 1 K and 1.5 µm). Returns the errors when within."""
    from spindle.arguments import real_number

    tol_temp_K = real_number(tol_temp_K, "tol_temp_K", 0.0, unit="K")
    tol_growth_um = real_number(tol_growth_um, "tol_growth_um", 0.0, unit="µm")
    v = model_error(spec, model, case, reference_level, dt_s)
    msgs = []
    if not v.worst_temp_K <= tol_temp_K:
        worst = max((k for k in v.row if k.endswith("_max_K")), key=lambda k: v.row[k])
        msgs.append(f"temperature error {v.worst_temp_K:.3f} K > {tol_temp_K:g} K "
                    f"(worst: {worst})")
    if not math.isnan(v.P1_um) and v.P1_um > tol_growth_um:
        msgs.append(f"P1 error {v.P1_um:.3f} µm > {tol_growth_um:g} µm")
    if msgs:
        raise AssertionError(f"{model} of {spec} ({case or 'own load case'}) against FEM level "
                             f"{reference_level}: " + "; ".join(msgs))
    return v
