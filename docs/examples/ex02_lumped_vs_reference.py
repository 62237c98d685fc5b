"""How far is the paper's 11-node function-block model from the FEM reference?

    python docs/examples/ex02_lumped_vs_reference.py

Builds the lumped model (eq. 7-13) and the FEM reference from the same spec, solves both at
the nominal point and prints the worst sensor temperature error and the P1 error against the
paper's tolerances (1 K, ±1.5 µm). ``spindle-verify study`` does this for every node count
and FEM level, with grid convergence; this is the one-case version.
"""

from __future__ import annotations

import lumped
from reference import ReferenceModel
from spindle.drive import load_case
from spindle.spec import load_spec

TOL_TEMP_K, TOL_GROWTH_UM = 1.0, 1.5  # the paper's tolerances (section 3)


def main() -> dict:
    spec = load_spec("spl2782")
    case = load_case(spec, "nominal")
    fem = ReferenceModel(spec, level=1).steady(case)
    lm = lumped.build(spec, nodes=11).steady(case)
    # the harness's rule: the shaft and housing sensor arrays and the bearing rings T1, T2
    names = [s.name for s in spec.temperature_sensors() if s.array or s.name in ("T1", "T2")]
    errors = {n: lm.sensors[n] - fem.sensors[n] for n in names}
    worst = max(errors, key=lambda n: abs(errors[n]))
    out = {"worst_sensor": worst, "worst_K": abs(errors[worst]),
           "P1_um": abs(lm.growth_m["P1"] - fem.growth_m["P1"]) * 1e6}
    print(f"11-node model against the FEM (level 1), nominal point: worst sensor {worst} "
          f"{out['worst_K']:.2f} K ({'within' if out['worst_K'] <= TOL_TEMP_K else 'beyond'} "
          f"{TOL_TEMP_K:g} K), P1 {out['P1_um']:.2f} µm "
          f"({'within' if out['P1_um'] <= TOL_GROWTH_UM else 'beyond'} ±{TOL_GROWTH_UM:g} µm)")
    return out


if __name__ == "__main__":
    main()
