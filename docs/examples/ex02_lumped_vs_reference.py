"""How far is the paper's 11-node function-block model from the FEM reference?

    python docs/examples/ex02_lumped_vs_reference.py [OUT_DIR]

Builds the lumped model (eq. 7-13) and the FEM reference from the same spec, solves both at
the nominal point, prints the worst sensor temperature error and the P1 error against the
paper's tolerances (1 K, ±1.5 µm) and writes the per-sensor errors to OUT_DIR/errors.csv.
``spindle-verify study`` does this for every node count and FEM level, with grid convergence
(its figures are against the extrapolated reference; level 1 is within 0.07 K and 0.04 µm of
it at these sensors, docs/harness.md); this is the one-case version, with the public API.
"""

from __future__ import annotations

import csv
import sys
import tempfile
from pathlib import Path

import spindle_verify

# the paper's tolerances (section 3), the growth's in µm as printed
TOL_TEMP_K, TOL_GROWTH_UM = 1.0, 1.5
ZERO_C_K = 273.15  # the models work in K: °C only at the edges


def main(out: Path, nodes: int | str = 11) -> dict:
    """Compare, print, write ``out/errors.csv``; returns the worst errors (K, µm)."""
    fem = spindle_verify.solve("spl2782", "nominal", model="fem:1")  # the reference: level 1
    lm = spindle_verify.solve("spl2782", "nominal", model=f"lumped:{nodes}")  # the same case
    spec, case = fem.model.spec, fem.case

    # the sensors the harness judges (compare.verify.accuracy): the 11 shaft and 11 housing
    # array sensors and the bearing rings T1, T2
    names = [s.name for s in spec.temperature_sensors() if s.array or s.name in ("T1", "T2")]
    errors = {n: lm.sensors[n] - fem.sensors[n] for n in names}  # K (a difference in °C too)
    worst = max(errors, key=lambda n: abs(errors[n]))
    result = {"worst_sensor": worst, "worst_K": abs(errors[worst]),
              "P1_um": abs(lm.growth_m["P1"] - fem.growth_m["P1"]) * 1e6}

    def verdict(error: float, tol: float) -> str:
        return "within" if error <= tol else "beyond"

    print(f"{nodes}-node model against the FEM (level 1), {spec.name} at {case.name}:")
    print(f"  worst sensor {worst}: {result['worst_K']:.2f} K "
          f"({verdict(result['worst_K'], TOL_TEMP_K)} the {TOL_TEMP_K:g} K tolerance)")
    print(f"  P1: {result['P1_um']:.2f} µm "
          f"({verdict(result['P1_um'], TOL_GROWTH_UM)} ±{TOL_GROWTH_UM:g} µm)")

    out.mkdir(parents=True, exist_ok=True)
    with open(out / "errors.csv", "w", newline="", encoding="utf-8") as f:
        rows = csv.writer(f)
        rows.writerow(["sensor", "T_fem_C", "T_lumped_C", "error_K"])
        rows.writerows((n, fem.sensors[n] - ZERO_C_K, lm.sensors[n] - ZERO_C_K, errors[n])
                       for n in names)
    print(f"wrote {out / 'errors.csv'}")
    return result


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
