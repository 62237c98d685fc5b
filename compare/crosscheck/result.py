"""The cross-check's result: the reference against CalculiX and the quadrature twin at the
sensors and the growth readings, as tables, a JSON summary and CSV files."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from spindle.units import ZERO_C_K


@dataclass
class CrosscheckResult:
    """scikit-fem reference against CalculiX at the sensors and growth readings.

    Temperatures in K, growth in m. ``*_twin`` is the reference's discrete problem assembled
    with ccx's quadrature (scikit-fem): ccx should equal it to the print precision of its
    result file (``*_print``, a bound), so ``reference - ccx`` is the quadrature difference,
    which falls under mesh refinement. ``growth_twin_ccxT_m`` is the twin's elastic problem
    driven by ccx's own temperatures (checks the elastic deck alone).
    """

    spec: str
    level: int
    case: str
    speed_rpm: float
    T_ambient_K: float
    sensors: list[str]
    z_m: np.ndarray
    r_m: np.ndarray
    T_skfem_K: np.ndarray
    T_ccx_K: np.ndarray
    T_twin_K: np.ndarray
    T_print_K: np.ndarray
    growth_skfem_m: dict[str, float]
    growth_ccx_m: dict[str, float]
    growth_twin_m: dict[str, float]
    growth_twin_ccxT_m: dict[str, float]
    growth_print_m: dict[str, float]
    growth_expansion_m: dict[str, float]
    nodal: dict[str, float]
    deck: dict
    timings_s: dict[str, float]
    ccx_version: str = ""

    @property
    def diff_K(self) -> np.ndarray:
        """T_ccx - T_skfem at each sensor [K]."""
        return self.T_ccx_K - self.T_skfem_K

    def sensor_table(self) -> dict[str, list]:
        """Per sensor: position [m], temperatures [°C] of both codes and the twin, the
        differences [K] and the print bound [K] (one list per column)."""
        return {"sensor": list(self.sensors), "z_m": self.z_m.tolist(), "r_m": self.r_m.tolist(),
                "T_skfem_C": (self.T_skfem_K - ZERO_C_K).tolist(),
                "T_ccx_C": (self.T_ccx_K - ZERO_C_K).tolist(), "diff_K": self.diff_K.tolist(),
                "T_twin_C": (self.T_twin_K - ZERO_C_K).tolist(),
                "ccx_minus_twin_K": (self.T_ccx_K - self.T_twin_K).tolist(),
                "print_bound_K": self.T_print_K.tolist()}

    def growth_table(self) -> dict[str, list]:
        """Per growth reading: both codes, the twin, their differences and the bounds [µm]
        (one list per column)."""
        names = list(self.growth_skfem_m)
        um = 1e6
        return {"reading": names,
                "skfem_um": [self.growth_skfem_m[k] * um for k in names],
                "ccx_um": [self.growth_ccx_m[k] * um for k in names],
                "diff_um": [(self.growth_ccx_m[k] - self.growth_skfem_m[k]) * um for k in names],
                "twin_um": [self.growth_twin_m[k] * um for k in names],
                "ccx_minus_twin_ccxT_um": [(self.growth_ccx_m[k] - self.growth_twin_ccxT_m[k]) * um
                                           for k in names],
                "print_bound_um": [self.growth_print_m[k] * um for k in names],
                "expansion_bound_um": [self.growth_expansion_m[k] * um for k in names]}

    def to_pandas(self):
        """The sensor table as a DataFrame (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return pd.DataFrame(self.sensor_table())

    def summary(self) -> dict:
        """The JSON summary: mesh, case, largest differences, per-sensor and per-reading
        values, the deck's checks and the timings [s]."""
        d = np.abs(self.diff_K)
        g = self.growth_table()
        return {"spec": self.spec, "kind": "crosscheck", "solver": f"CalculiX {self.ccx_version}",
                "mesh": {"level": self.level, "order": 2, "nodes": self.deck.get("nodes"),
                         "elements": self.deck.get("elements")},
                "case": self.case, "speed_rpm": self.speed_rpm,
                "T_ambient_C": self.T_ambient_K - ZERO_C_K,
                "max_abs_diff_K": float(d.max(initial=0.0)),
                "max_abs_ccx_minus_twin_K": float(np.abs(self.T_ccx_K - self.T_twin_K)
                                                  .max(initial=0.0)),
                "sensors": {n: {"T_skfem_C": a, "T_ccx_C": b, "diff_K": c}
                            for n, a, b, c in zip(self.sensors, self.T_skfem_K - ZERO_C_K,
                                                  self.T_ccx_K - ZERO_C_K, self.diff_K.tolist(),
                                                  strict=True)},
                "growth_um": {k: {"skfem": g["skfem_um"][i], "ccx": g["ccx_um"][i],
                                  "diff": g["diff_um"][i]} for i, k in enumerate(g["reading"])},
                "nodal": self.nodal, "checks": self.deck.get("checks", {}),
                "timings_s": self.timings_s}

    def save(self, out: str | Path) -> list[Path]:
        """``crosscheck.json`` (summary), ``crosscheck_sensors.csv`` and
        ``crosscheck_growth.csv``, each written atomically."""
        from spindle.outputs import write_csv, write_json

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        files = [out / "crosscheck.json", out / "crosscheck_sensors.csv",
                 out / "crosscheck_growth.csv"]
        write_json(files[0], self.summary())
        table = self.sensor_table()
        write_csv(files[1], list(table), zip(*table.values(), strict=True))
        gt = self.growth_table()
        write_csv(files[2], list(gt), zip(*gt.values(), strict=True))
        return files
