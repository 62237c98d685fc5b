"""Solve the FEM reference of a shipped spindle at its nominal point and save the results.

    python docs/examples/ex01_solve_spec.py [OUT_DIR]

Loads the SPL2782.1 spec, takes the ``nominal`` operating point (38 kW / 4300 rpm, heat
sources from the power balance), solves the axisymmetric FEM (heat conduction and
thermoelasticity) on mesh level 1, prints the front-bearing temperature T1, the axial growth
P1 and the energy balance, and writes summary.json, sensors.csv and the VTU field.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from reference import ReferenceModel
from spindle.drive import load_case
from spindle.spec import load_spec
from spindle.units import ZERO_C_K


def main(out: Path) -> dict:
    spec = load_spec("spl2782")                 # a shipped name, or the path of your TOML
    case = load_case(spec, "nominal")           # any shipped cycle name or cycle file
    result = ReferenceModel(spec, level=1).steady(case)
    figures = {"T1_C": result.sensors["T1"] - ZERO_C_K,
               "P1_um": result.growth_m["P1"] * 1e6,
               "relative_imbalance": result.energy["relative_imbalance"]}
    print(f"T1 = {figures['T1_C']:.2f} °C, P1 = {figures['P1_um']:.2f} µm, energy balance "
          f"closes to {figures['relative_imbalance']:.1e}")
    result.save(out, pictures=False)            # pictures=True adds the PNGs (pyvista)
    print(f"wrote {out}")
    return figures


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
