"""Results of the lumped model, with the same interface as the FEM reference's
(``.sensors``, ``.sensor_table()``, ``.to_pandas()``, ``.summary()``, ``.plot()``, ``.save()``,
``.energy``, ``.growth_m``). Temperatures in K; files name their unit (``T_C``, ``P1_um``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from spindle import plots
from spindle.outputs import expect_pictures, jsonable, result_folder, write_csv, write_json
from spindle.results import SteadyTable, TransientTable
from spindle.units import ZERO_C_K


def _model_info(model) -> dict:
    return {"kind": "lumped", "nodes": model.nodes, "masses": model.n_states}


@dataclass(repr=False)
class LumpedSteadyResult(SteadyTable):
    """Steady mass temperatures with virtual sensors, growth and energy balance."""

    model: object
    case: object
    time_s: float
    speed_rpm: float
    T: np.ndarray  # mass temperatures [K], state order
    heat_in_W: float
    heat_out_W: dict[str, float]
    residual: float
    growth_m: dict[str, float] = field(default_factory=dict)

    @property
    def sensors(self) -> dict[str, float]:
        """Temperature at each temperature sensor [K], interpolated from the masses."""
        return dict(zip(self.model.sensor_names, (self.model.S @ self.T).tolist(), strict=True))

    def mass_table(self) -> dict[str, list]:
        table = self.model.mass_table()
        return {**table, "T_C": [float(self.T[i]) - ZERO_C_K for i in range(len(self.T))]}

    def summary(self) -> dict:
        return self.steady_summary({"model": _model_info(self.model)})

    def _title(self) -> str:
        return (f"{self.model.spec.name}: steady, {self.speed_rpm:g} rpm, "
                f"{self.heat_in_W:.0f} W in; lumped, {self.model.nodes} nodes "
                f"({self.model.n_states} masses)")

    def plot(self, ax=None):
        """Mass temperatures along z per part, sensors on top; returns the axes."""
        plt = plots.pyplot()
        if ax is None:
            _, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
        masses = self.mass_table()
        for part in dict.fromkeys(masses["part"]):
            rows = [i for i, p in enumerate(masses["part"]) if p == part]
            ax.plot([masses["z_m"][i] * 1e3 for i in rows], [masses["T_C"][i] for i in rows],
                    "o-", ms=3, lw=1, label=part)
        ax.set_xlabel("z [mm]")
        ax.set_ylabel("temperature [°C]")
        ax.set_title(self._title(), fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, ncol=2)
        return ax

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """JSON summary, sensor and mass CSVs, PNG profiles."""
        from spindle.outputs import atomic_write

        out = result_folder(out, pictures)
        table = self.sensor_table()
        masses = self.mass_table()
        write_json(out / "summary.json", self.summary())
        write_csv(out / "sensors.csv", list(table), zip(*table.values(), strict=True))
        write_csv(out / "masses.csv", list(masses), zip(*masses.values(), strict=True))
        files = ["summary.json", "sensors.csv", "masses.csv"]
        if pictures:
            expect_pictures(2)
            plt = plots.pyplot()
            ax = self.plot()
            atomic_write(out / "masses.png", lambda tmp: ax.figure.savefig(tmp, dpi=130))
            plt.close(ax.figure)
            plots.sensor_profile_png(table, out / "sensor_profile.png", self._title())
            files += ["masses.png", "sensor_profile.png"]
        return [out / f for f in files]


@dataclass(repr=False)
class LumpedTransientResult(TransientTable):
    """Sensor and mass histories of a zero-order-hold run, growth, energy balance."""

    model: object
    case: object
    times_s: np.ndarray
    names: list[str]
    sensor_K: np.ndarray  # (n_times, n_sensors)
    mass_K: np.ndarray  # (n_times, n_masses)
    energy_in_J: float
    energy_out_J: float
    energy_stored_J: float
    energy_out_by_J: dict[str, float]
    growth_m: dict[str, np.ndarray] = field(default_factory=dict)

    def summary(self) -> dict:
        """The run's figures as plain numbers (the JSON summary)."""
        return jsonable({"spec": self.model.spec.name, "kind": "transient",
                         "case": self.case.name, "model": _model_info(self.model),
                         "duration_s": float(self.times_s[-1]),
                         "steps": len(self.times_s) - 1, "energy": self.energy, **self.peaks()})

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """Summary JSON, sensor time series CSV, PNGs (sensors; T1 and P1 with the band)."""
        out = result_folder(out, pictures)
        write_json(out / "summary.json", self.summary())
        write_csv(out / "sensors_timeseries.csv", *self.timeseries_rows())
        files = ["summary.json", "sensors_timeseries.csv"]
        if pictures:
            expect_pictures(1 + ("P1" in self.growth_m and "T1" in self.names))
            title = f"{self.model.spec.name}: {self.case.name}, lumped {self.model.nodes} nodes"
            arrays = {s.name: s.array for s in self.model.spec.temperature_sensors() if s.array}
            plots.timeseries_png(self.times_s, self.names, self.sensor_K - ZERO_C_K,
                                 out / "sensors_timeseries.png", title, arrays)
            files.append("sensors_timeseries.png")
            if "P1" in self.growth_m and "T1" in self.names:
                plots.growth_band_png(self.times_s, self.sensor("T1") - ZERO_C_K,
                                      self.growth_m["P1"] * 1e6, out / "T1_P1_tolerance.png",
                                      title)
                files.append("T1_P1_tolerance.png")
        return [out / f for f in files]
