"""Result objects of the FEM reference: data with ``.to_pandas()``, ``.plot()``, ``.save()``.

Temperatures are kept in K; tables and files name their unit (``T_C`` in degC).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from spindle import plots as shared_plots
from spindle.outputs import atomic_write, expect_pictures, jsonable, result_folder
from spindle.outputs import write_csv as _write_csv
from spindle.outputs import write_json as _write_json
from spindle.results import SteadyTable, TransientTable
from spindle.units import ZERO_C_K


def _mesh_info(model) -> dict:
    c = model.smesh.counts(model.order)
    return {"level": model.smesh.level, "order": model.order, "elements": c["elements"],
            "dofs": int(model.basis.N), "h_max_m": model.smesh.h_max_m}


@dataclass(repr=False)
class SteadyResult(SteadyTable):
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

    def summary(self) -> dict:
        return jsonable({**self.steady_summary({"mesh": _mesh_info(self.model)}),
                         "inputs_used": self.model.op.inputs_used(self.case, self.time_s,
                                                                  self.speed_rpm)})

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

        out = result_folder(out, pictures)
        table = self.sensor_table()
        _write_json(out / "summary.json", self.summary())
        _write_csv(out / "sensors.csv", list(table), zip(*table.values(), strict=True))
        grid = field_grid(self.model, self.T)
        if self.U is not None:
            add_displacement(grid, self.elastic, self.U)
        atomic_write(out / "temperature.vtu", lambda tmp: grid.save(str(tmp)))
        files = ["summary.json", "sensors.csv", "temperature.vtu"]
        if pictures:
            expect_pictures(3 + (self.U is not None))
        if self.U is not None and pictures:
            plots.deformed_png(grid, out / "deformation_section.png", self._title(), self.growth_m)
            files.append("deformation_section.png")
        if pictures:
            plots.section_png(self.model, self.T, out / "temperature_section.png", self._title())
            plots.revolved_png(self.model, self.T, out / "temperature_3d.png", self._title())
            shared_plots.sensor_profile_png(table, out / "sensor_profile.png", self._title())
            files += ["temperature_section.png", "temperature_3d.png", "sensor_profile.png"]
        return [out / f for f in files]


@dataclass(repr=False)
class TransientResult(TransientTable):
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

    def summary(self) -> dict:
        """The run's figures as plain numbers (the JSON summary)."""
        return jsonable({"spec": self.model.spec.name, "kind": "transient",
                         "case": self.case.name, "mesh": _mesh_info(self.model),
                         "theta": self.theta, "duration_s": float(self.times_s[-1]),
                         "steps": len(self.times_s) - 1, "energy": self.energy,
                         **self.peaks(), "inputs_used_by_speed": self.inputs_by_speed()})

    def inputs_by_speed(self) -> dict[str, dict]:
        """ThermalModel.op.inputs_used at the first output time of each speed the run held
        (films and links depend on the speed; sources and reference temperatures are those
        of that instant)."""
        out: dict[str, dict] = {}
        for t in self.times_s:
            n = float(self.case.speed_rpm(float(t)))
            key = f"{n:g} rpm"
            if key not in out:
                out[key] = {"first_at_s": float(t),
                            **self.model.op.inputs_used(self.case, float(t), n)}
        return out

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """Summary JSON, sensor time series CSV, VTU per saved time with a PVD, PNGs."""
        from reference import plots
        from reference.fields import add_displacement, field_grid

        out = result_folder(out, pictures)
        _write_json(out / "summary.json", self.summary())
        _write_csv(out / "sensors_timeseries.csv", *self.timeseries_rows())
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
            expect_pictures(3 + ("P1" in self.growth_m and "T1" in self.names))
            title = f"{self.model.spec.name}: {self.case.name}"
            arrays = {s.name: s.array for s in self.model.spec.temperature_sensors() if s.array}
            shared_plots.timeseries_png(self.times_s, self.names, self.sensor_K - ZERO_C_K,
                                 out / "sensors_timeseries.png", title, arrays)
            plots.section_png(self.model, self.fields_K[-1], out / "temperature_section.png",
                              f"{title}, t = {self.field_times_s[-1] / 3600:.2f} h")
            plots.revolved_png(self.model, self.fields_K[-1], out / "temperature_3d.png", title)
            files += ["sensors_timeseries.png", "temperature_section.png", "temperature_3d.png"]
            if "P1" in self.growth_m and "T1" in self.names:
                shared_plots.growth_band_png(self.times_s, self.sensor("T1") - ZERO_C_K,
                                      self.growth_m["P1"] * 1e6, out / "T1_P1_tolerance.png",
                                      title)
                files.append("T1_P1_tolerance.png")
        return [out / f for f in files]
