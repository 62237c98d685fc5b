"""Solve the FEM reference of a shipped spindle at its nominal point and save the results.

    python docs/examples/ex01_solve_spec.py [OUT_DIR]

Loads the SPL2782.1 spec, takes the ``nominal`` operating point (38 kW / 4300 rpm, heat
sources from the power balance), solves the axisymmetric FEM (heat conduction and
thermoelasticity, P2) on mesh level 1, prints every temperature sensor in °C, the axial
growth P1 and TCP in µm and the energy balance, and writes summary.json, sensors.csv and the
VTU field (for ParaView) to OUT_DIR (a new temporary folder if not given). The same as
``spindle-verify solve spl2782 --level 1 --case nominal --out OUT_DIR``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import spindle_verify

ZERO_C_K = 273.15  # the models work in K: °C only at the edges


def main(out: Path, spec_ref: str = "spl2782", level: int = 1) -> dict:
    """Solve, print, save to ``out``; returns the printed figures (°C, µm, W)."""
    # a shipped name or the path of your TOML; any shipped cycle name or cycle file; level 2
    # is the study's truth
    result = spindle_verify.solve(spec_ref, "nominal", model=f"fem:{level}")
    spec, case = result.model.spec, result.case

    sensors_C = {n: T - ZERO_C_K for n, T in result.sensors.items()}  # the model works in K
    growth_um = {n: g * 1e6 for n, g in result.growth_m.items()}      # ... and in m
    energy = result.energy
    print(f"{spec.name}, {case.name}: {result.speed_rpm:g} rpm, {energy['heat_in_W']:.0f} W "
          f"of losses; FEM P{result.model.order}, mesh level {level}")
    # single sensors one per line; the shaft and housing arrays (front to rear) one line each
    arrays: dict[str, list[float]] = {}
    for s in spec.temperature_sensors():
        if s.array:
            arrays.setdefault(s.array, []).append(sensors_C[s.name])
        else:
            print(f"  {s.name:<16} {sensors_C[s.name]:7.2f} °C")
    for name, values in arrays.items():
        print(f"  {name} array °C: " + " ".join(f"{v:.1f}" for v in values))
    print("  growth: " + ", ".join(f"{n} = {g:.2f} µm" for n, g in growth_um.items()))
    # heat in = heat out at steady state; the FEM closes it to round-off
    print(f"  energy balance: in {energy['heat_in_W']:.1f} W, out {energy['heat_out_W']:.1f} W, "
          f"relative imbalance {energy['relative_imbalance']:.1e}")

    files = result.save(out, pictures=False)    # pictures=True adds the PNGs (pyvista)
    print(f"wrote {', '.join(f.name for f in files)} to {out}")
    return {"T_ambient_C": float(case.T_ambient_K(0.0)) - ZERO_C_K, "sensors_C": sensors_C,
            "T1_C": sensors_C["T1"], "P1_um": growth_um["P1"],
            "heat_in_W": energy["heat_in_W"],
            "relative_imbalance": energy["relative_imbalance"]}


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(tempfile.mkdtemp()))
