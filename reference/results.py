"""Result objects of the FEM reference: data with ``.to_pandas()``, ``.plot()``, ``.save()``.

Temperatures are kept in K; tables and files name their unit (``T_C`` in degC).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from spindle import plots as shared_plots
from spindle.outputs import atomic_write
from spindle.outputs import write_csv as _write_csv
from spindle.outputs import write_json as _write_json

KELVIN = 273.15


def _mesh_info(model) -> dict:
    c = model.smesh.counts(model.order)
    return {"level": model.smesh.level, "order": model.order, "elements": c["elements"],
            "dofs": int(model.basis.N), "h_max_m": model.smesh.h_max_m}


@dataclass
class SteadyResult:
    """A steady FEM temperature field with its sensors and energy balance."""

    model: object
    case: object
    time_s: float
    speed_rpm: float
    T: np.ndarray  # nodal temperatures [K]
    heat_in_W: float
    heat_out_W: dict[str, float]
    residual: float  # ||K T - F|| / ||F||
    growth_m: dict[str, float] = field(default_factory=dict)  # axial growth readings [m]
    U: np.ndarray | None = None  # displacement DOFs [m] (thermoelastic runs)
    elastic: object = None

    @property
    def sensors(self) -> dict[str, float]:
        """Temperature at each temperature sensor [K], interpolated from the field."""
        names, pts = self.model.sensor_points()
        return dict(zip(names, (self.model.probe_matrix(pts) @ self.T).tolist(), strict=True))

    @property
    def energy(self) -> dict[str, float]:
        """Global balance [W]: heat in - heat out (no storage at steady state)."""
        out = sum(self.heat_out_W.values())
        imbalance = self.heat_in_W - out
        scale = max(abs(self.heat_in_W), abs(out), 1e-300)
        return {"heat_in_W": self.heat_in_W, "heat_out_W": out, "imbalance_W": imbalance,
                "relative_imbalance": abs(imbalance) / scale,
                **{f"out_{k}_W": v for k, v in self.heat_out_W.items()}}

    def sensor_table(self) -> dict[str, list]:
        T_amb = float(self.case.T_ambient_K(self.time_s))
        sensors, values = self.model.spec.temperature_sensors(), self.sensors
        return {"sensor": [s.name for s in sensors], "array": [s.array or "" for s in sensors],
                "z_m": [s.z for s in sensors], "r_m": [s.r for s in sensors],
                "T_C": [values[s.name] - KELVIN for s in sensors],
                "rise_K": [values[s.name] - T_amb for s in sensors]}

    def to_pandas(self):
        """The sensor table as a DataFrame (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return pd.DataFrame(self.sensor_table())

    def summary(self) -> dict:
        table = self.sensor_table()
        return {"spec": self.model.spec.name, "kind": "steady", "mesh": _mesh_info(self.model),
                "speed_rpm": self.speed_rpm,
                "T_ambient_C": float(self.case.T_ambient_K(self.time_s)) - KELVIN,
                "T_coolant_C": float(self.case.T_coolant_K(self.time_s)) - KELVIN,
                "relative_residual": self.residual, "energy": self.energy,
                "T_max_C": float(self.T.max() - KELVIN),
                "sensors_C": dict(zip(table["sensor"], table["T_C"], strict=True)),
                "growth_um": {k: v * 1e6 for k, v in self.growth_m.items()}}

    def plot(self, ax=None):
        from reference.plots import plot_section

        return plot_section(self.model, self.T, ax=ax, title=self._title())

    def _title(self) -> str:
        return (f"{self.model.spec.name}: steady, {self.speed_rpm:g} rpm, "
                f"{self.heat_in_W:.0f} W in; FEM P{self.model.order}, level "
                f"{self.model.smesh.level}")

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """JSON summary, sensor CSV, VTU field, PNG half-section and 3-D cut-away."""
        from reference import plots
        from reference.fields import add_displacement, field_grid

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        table = self.sensor_table()
        _write_json(out / "summary.json", self.summary())
        _write_csv(out / "sensors.csv", list(table), zip(*table.values(), strict=True))
        grid = field_grid(self.model, self.T)
        if self.U is not None:
            add_displacement(grid, self.elastic, self.U)
        atomic_write(out / "temperature.vtu", lambda tmp: grid.save(str(tmp)))
        files = ["summary.json", "sensors.csv", "temperature.vtu"]
        if self.U is not None and pictures:
            plots.deformed_png(grid, out / "deformation_section.png", self._title(), self.growth_m)
            files.append("deformation_section.png")
        if pictures:
            plots.section_png(self.model, self.T, out / "temperature_section.png", self._title())
            plots.revolved_png(self.model, self.T, out / "temperature_3d.png", self._title())
            shared_plots.sensor_profile_png(table, out / "sensor_profile.png", self._title())
            files += ["temperature_section.png", "temperature_3d.png", "sensor_profile.png"]
        return [out / f for f in files]


@dataclass
class TransientResult:
    """Sensor histories and saved fields of a theta-method run, with its energy balance."""

    model: object
    case: object
    theta: float
    times_s: np.ndarray
    names: list[str]
    sensor_K: np.ndarray  # (n_times, n_sensors)
    field_times_s: np.ndarray
    fields_K: np.ndarray  # (n_saved, n_dofs)
    heat_in_W: np.ndarray
    heat_out_W: np.ndarray
    energy_in_J: float
    energy_out_J: float
    energy_stored_J: float
    functionals: dict[str, np.ndarray] = field(default_factory=dict)
    growth_m: dict[str, np.ndarray] = field(default_factory=dict)  # per reading, per time [m]
    U_fields: np.ndarray | None = None  # displacement DOFs at field_times_s [m]
    elastic: object = None

    @property
    def energy(self) -> dict[str, float]:
        """Cumulative balance [J]: in - out - stored, and its size relative to the flows."""
        imb = self.energy_in_J - self.energy_out_J - self.energy_stored_J
        scale = max(abs(self.energy_in_J), abs(self.energy_out_J),
                    abs(self.energy_stored_J), 1e-300)
        return {"energy_in_J": self.energy_in_J, "energy_out_J": self.energy_out_J,
                "energy_stored_J": self.energy_stored_J, "imbalance_J": imb,
                "relative_imbalance": abs(imb) / scale}

    def sensor(self, name: str) -> np.ndarray:
        """History of one sensor [K]."""
        return self.sensor_K[:, self.names.index(name)]

    def to_pandas(self):
        import pandas as pd

        df = pd.DataFrame(self.sensor_K - KELVIN, columns=[f"{n}_C" for n in self.names])
        df.insert(0, "time_s", self.times_s)
        for k, v in self.growth_m.items():
            df[f"{k}_um"] = v * 1e6
        return df

    def summary(self) -> dict:
        peak = self.sensor_K.max(axis=0) - KELVIN
        return {"spec": self.model.spec.name, "kind": "transient", "case": self.case.name,
                "mesh": _mesh_info(self.model), "theta": self.theta,
                "duration_s": float(self.times_s[-1]), "steps": len(self.times_s) - 1,
                "energy": self.energy,
                "peak_C": dict(zip(self.names, peak.tolist(), strict=True)),
                "final_C": dict(zip(self.names, (self.sensor_K[-1] - KELVIN).tolist(),
                                    strict=True)),
                "peak_growth_um": {k: float(v.max() * 1e6) for k, v in self.growth_m.items()},
                "final_growth_um": {k: float(v[-1] * 1e6) for k, v in self.growth_m.items()}}

    def plot(self, ax=None):
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        if ax is None:
            _, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
        for j, n in enumerate(self.names):
            ax.plot(self.times_s / 3600, self.sensor_K[:, j] - KELVIN, label=n)
        ax.set_xlabel("time [h]")
        ax.set_ylabel("temperature [°C]")
        return ax

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """Summary JSON, sensor time series CSV, VTU per saved time with a PVD, PNGs."""
        from reference import plots
        from reference.fields import add_displacement, field_grid

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        _write_json(out / "summary.json", self.summary())
        growth = np.array(list(self.growth_m.values())).T * 1e6 if self.growth_m else \
            np.zeros((len(self.times_s), 0))
        _write_csv(out / "sensors_timeseries.csv",
                   ["time_s"] + [f"{n}_C" for n in self.names] + [f"{k}_um" for k in self.growth_m],
                   ([t, *row, *g] for t, row, g in zip(self.times_s, self.sensor_K - KELVIN,
                                                        growth, strict=True)))
        (out / "fields").mkdir(exist_ok=True)
        entries = []
        for i, (t, T) in enumerate(zip(self.field_times_s, self.fields_K, strict=True)):
            name = f"fields/temperature_{i:04d}.vtu"
            grid = field_grid(self.model, T)
            if self.U_fields is not None:
                add_displacement(grid, self.elastic, self.U_fields[i])
            atomic_write(out / name, lambda tmp, g=grid: g.save(str(tmp)))
            entries.append(f'    <DataSet timestep="{t:.6g}" file="{name}"/>')
        pvd = ('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
               "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")
        atomic_write(out / "temperature.pvd", lambda tmp: tmp.write_text(pvd, "utf-8"))
        files = ["summary.json", "sensors_timeseries.csv", "temperature.pvd"]
        if pictures:
            title = f"{self.model.spec.name}: {self.case.name}"
            arrays = {s.name: s.array for s in self.model.spec.temperature_sensors() if s.array}
            shared_plots.timeseries_png(self.times_s, self.names, self.sensor_K - KELVIN,
                                 out / "sensors_timeseries.png", title, arrays)
            plots.section_png(self.model, self.fields_K[-1], out / "temperature_section.png",
                              f"{title}, t = {self.field_times_s[-1] / 3600:.2f} h")
            plots.revolved_png(self.model, self.fields_K[-1], out / "temperature_3d.png", title)
            files += ["sensors_timeseries.png", "temperature_section.png", "temperature_3d.png"]
            if "P1" in self.growth_m and "T1" in self.names:
                shared_plots.growth_band_png(self.times_s, self.sensor("T1") - KELVIN,
                                      self.growth_m["P1"] * 1e6, out / "T1_P1_tolerance.png",
                                      title)
                files.append("T1_P1_tolerance.png")
        return [out / f for f in files]
