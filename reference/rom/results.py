"""Results of the reduced model, with the interface of the other models' (``.sensors``,
``.sensor_table()``, ``.to_pandas()``, ``.summary()``, ``.plot()``, ``.growth_m``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from spindle.results import SteadyTable, TransientTable


def _model_info(model) -> dict:
    return {"kind": "rom", "states": model.n_states, "fem_level": model.level,
            "fem_unknowns": model.n_full}


@dataclass
class ROMSteadyResult(SteadyTable):
    model: object
    case: object
    time_s: float
    speed_rpm: float
    z: np.ndarray  # reduced state
    sensor_values: np.ndarray
    growth_m: dict[str, float] = field(default_factory=dict)

    @property
    def T(self) -> np.ndarray:
        return self.sensor_values

    @property
    def sensors(self) -> dict[str, float]:
        return dict(zip(self.model.sensor_names, self.sensor_values.tolist(), strict=True))

    # a ROM has no heat-flow bookkeeping of its own in steady state: the balance of the
    # projected system is exact by construction (the uniform field is in the basis)
    heat_in_W = 0.0
    heat_out_W: dict = field(default_factory=dict)
    residual: float = 0.0

    def summary(self) -> dict:
        return self.steady_summary({"model": _model_info(self.model)})

    def plot(self, ax=None):
        from spindle.plots import pyplot

        plt = pyplot()
        if ax is None:
            _, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
        t = self.sensor_table()
        ax.plot(np.array(t["z_m"]) * 1e3, t["T_C"], "o")
        ax.set_xlabel("z [mm]")
        ax.set_ylabel("temperature [°C]")
        ax.set_title(f"{self.model.spec.name}: steady, ROM {self.model.n_states} states",
                     fontsize=10)
        return ax


@dataclass
class ROMTransientResult(TransientTable):
    model: object
    case: object
    times_s: np.ndarray
    names: list[str]
    sensor_K: np.ndarray
    growth_m: dict[str, np.ndarray]
    states: np.ndarray
    method: str
    runtime_s: float
    #: the residual-based error estimate of this run (rom.indicator), when the model has one
    error_estimate: dict | None = None
    energy_in_J: float = float("nan")
    energy_out_J: float = float("nan")
    energy_stored_J: float = float("nan")

    def save(self, out, pictures: bool = True) -> list:
        """Summary JSON, sensor and growth time series CSV, PNG of the sensors."""
        from pathlib import Path

        from spindle import plots
        from spindle.outputs import write_csv, write_json
        from spindle.units import ZERO_C_K

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "summary.json", self.summary())
        write_csv(out / "sensors_timeseries.csv", *self.timeseries_rows())
        files = [out / "summary.json", out / "sensors_timeseries.csv"]
        if pictures:
            title = (f"{self.model.spec.name}: {self.case.name}, ROM {self.model.n_states} states "
                     f"of FEM level {self.model.level}")
            plots.timeseries_png(self.times_s, self.names, self.sensor_K - ZERO_C_K,
                                 out / "sensors_timeseries.png", title,
                                 {t.name: t.array for t in self.model.spec.temperature_sensors()
                                  if t.array})
            files.append(out / "sensors_timeseries.png")
        return files

    def summary(self) -> dict:
        return {"spec": self.model.spec.name, "kind": "transient", "case": self.case.name,
                "model": _model_info(self.model), "method": self.method,
                "duration_s": float(self.times_s[-1]), "steps": len(self.times_s) - 1,
                "runtime_s": self.runtime_s, "error_estimate": self.error_estimate,
                **self.peaks()}
