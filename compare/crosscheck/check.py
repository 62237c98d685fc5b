"""The cross-check: the reference against CalculiX and the quadrature twin at the sensors
and the growth readings (P1, TCP), with the result object (table, JSON, CSV)."""

from __future__ import annotations

import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from compare.crosscheck.ccx import CCX_MISSING, ccx_version, run_ccx
from compare.crosscheck.deck import EXPANSION_REL, write_elastic, write_thermal_deck
from compare.crosscheck.frd import read_frd
from compare.crosscheck.twin import half_ulp, reading_rows, twin_gains, twin_thermal
from reference.simulation import ReferenceModel
from spindle.errors import InputError, SolverError
from spindle.loads import LoadCase
from spindle.spec import Spec, load_spec
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
        return {"sensor": list(self.sensors), "z_m": self.z_m.tolist(), "r_m": self.r_m.tolist(),
                "T_skfem_C": (self.T_skfem_K - ZERO_C_K).tolist(),
                "T_ccx_C": (self.T_ccx_K - ZERO_C_K).tolist(), "diff_K": self.diff_K.tolist(),
                "T_twin_C": (self.T_twin_K - ZERO_C_K).tolist(),
                "ccx_minus_twin_K": (self.T_ccx_K - self.T_twin_K).tolist(),
                "print_bound_K": self.T_print_K.tolist()}

    def growth_table(self) -> dict[str, list]:
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


def crosscheck(spec: Spec | str | Path, level: int = 1, case: LoadCase | None = None, *,
               keep_dir: str | Path | None = None, timeout_s: float = 600) -> CrosscheckResult:
    """Solve ``spec`` at mesh ``level`` (P2) with the reference and with CalculiX; compare.

    ``case`` is a steady load case (default: the spec's own operating point), evaluated at
    t = 0. ccx runs in a temporary folder; ``keep_dir`` keeps its decks, result files and
    logs there. Raises SolverError when ccx is missing or fails.
    """
    if shutil.which("ccx") is None:
        raise SolverError(CCX_MISSING)
    if not isinstance(spec, Spec):
        spec = load_spec(spec)
    if not 0 <= int(level) <= 6:
        raise InputError("crosscheck", "level", f"{level} is out of range",
                         "give a level between 0 and 6")
    case = case or spec.default_load_case()
    times: dict[str, float] = {}
    t0 = time.perf_counter()
    model = ReferenceModel(spec, int(level), 2)
    res = model.steady(case)
    times["reference_s"] = time.perf_counter() - t0
    th = model.thermal
    names, pts = th.sensor_points()
    P = th.probe_matrix(pts)
    with tempfile.TemporaryDirectory(prefix="spindle-ccx-") as tmp:
        work = Path(tmp)
        t1 = time.perf_counter()
        name = "".join(c if c.isalnum() or c in "-_" else "_" for c in spec.name)
        info, cm, data, con = write_thermal_deck(model, case, work / f"{name}.inp")
        times["export_s"] = time.perf_counter() - t1
        t1 = time.perf_counter()
        frd = read_frd(run_ccx(info["thermal_deck"], timeout_s))
        times["ccx_thermal_s"] = time.perf_counter() - t1
        N = th.basis.N
        if frd["T"] is None or len(frd["T"]) < N or not np.all(np.isfinite(frd["T"][:N])):
            raise SolverError(f"{info['thermal_deck']}: ccx wrote no temperature for some "
                              "nodes; fix: see its .log")
        rise = frd["T"][:N]
        datum = info["T_datum_K"]
        T_ccx = datum + rise
        rows = reading_rows(model)
        g_ccx: dict[str, float] = {}
        g_print: dict[str, float] = {}
        U_ccx = None
        if rows:
            t1 = time.perf_counter()
            deck = write_elastic(model, cm, con, work / f"{name}_elastic.inp", T_ccx, datum)
            info["elastic_deck"] = deck
            U = read_frd(run_ccx(deck, timeout_s))["U"]
            times["ccx_elastic_s"] = time.perf_counter() - t1
            if U is None or len(U) < N or not np.all(np.isfinite(U[:N, :2])):
                raise SolverError(f"{deck}: ccx wrote no displacement for some nodes; fix: "
                                  "see its .log")
            U_ccx = U[:N, 1]
            ulp = half_ulp(U_ccx)
            for k, row in rows.items():
                g_ccx[k] = float(row @ U_ccx)
                g_print[k] = float(np.abs(row) @ ulp)
        version = ccx_version(info["thermal_deck"].with_suffix(".log"))
        if keep_dir is not None:
            keep = Path(keep_dir)
            keep.mkdir(parents=True, exist_ok=True)
            for f in work.iterdir():
                if f.suffix in (".inp", ".frd", ".log"):
                    shutil.copy2(f, keep / f.name)
    t1 = time.perf_counter()
    T_twin = twin_thermal(model, cm, data)
    gains = twin_gains(model, cm, con)
    times["twin_s"] = time.perf_counter() - t1
    T0 = spec.T_initial_K
    g_twin = {k: float(g @ (T_twin - T0)) for k, g in gains.items()}
    g_twin_ccx = {k: float(g @ (T_ccx - T0)) for k, g in gains.items()}
    g_exp = {k: float(EXPANSION_REL * (np.abs(rows[k]) @ np.abs(U_ccx))) for k in gains}
    nodal = {"max_abs_diff_K": float(np.abs(T_ccx - res.T).max()),
             "max_abs_ccx_minus_twin_K": float(np.abs(T_ccx - T_twin).max()),
             "max_abs_skfem_minus_twin_K": float(np.abs(res.T - T_twin).max()),
             "max_print_bound_K": float(half_ulp(rise).max()),
             "max_rise_K": float(np.abs(rise).max())}
    sensors = th.spec.temperature_sensors()
    return CrosscheckResult(
        spec=spec.name, level=int(level), case=case.name, speed_rpm=float(case.speed_rpm(0.0)),
        T_ambient_K=float(case.T_ambient_K(0.0)), sensors=names,
        z_m=np.array([s.z for s in sensors]), r_m=np.array([s.r for s in sensors]),
        T_skfem_K=P @ res.T, T_ccx_K=P @ T_ccx, T_twin_K=P @ T_twin,
        T_print_K=abs(P) @ half_ulp(rise),
        growth_skfem_m=dict(res.growth_m), growth_ccx_m=g_ccx, growth_twin_m=g_twin,
        growth_twin_ccxT_m=g_twin_ccx, growth_print_m=g_print, growth_expansion_m=g_exp,
        nodal=nodal, deck={k: (v.name if isinstance(v, Path) else v) for k, v in info.items()},
        timings_s=times, ccx_version=version)
