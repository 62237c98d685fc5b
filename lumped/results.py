"""Results of the lumped model, with the same interface as the FEM reference's
(``.sensors``, ``.sensor_table()``, ``.to_pandas()``, ``.summary()``, ``.plot()``, ``.save()``,
``.energy``, ``.growth_m``). Temperatures in K; files name their unit (``T_C``, ``P1_um``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from spindle import plots
from spindle.outputs import write_csv, write_json

KELVIN = 273.15


def _model_info(model) -> dict:
    return {"kind": "lumped", "nodes": model.nodes, "masses": model.n_states}


@dataclass
class LumpedSteadyResult:
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

    @property
    def energy(self) -> dict[str, float]:
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

    def mass_table(self) -> dict[str, list]:
        table = self.model.mass_table()
        return {**table, "T_C": [float(self.T[i]) - KELVIN for i in range(len(self.T))]}

    def to_pandas(self):
        """The sensor table as a DataFrame (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return pd.DataFrame(self.sensor_table())

    def summary(self) -> dict:
        table = self.sensor_table()
        return {"spec": self.model.spec.name, "kind": "steady", "model": _model_info(self.model),
                "speed_rpm": self.speed_rpm,
                "T_ambient_C": float(self.case.T_ambient_K(self.time_s)) - KELVIN,
                "T_coolant_C": float(self.case.T_coolant_K(self.time_s)) - KELVIN,
                "relative_residual": self.residual, "energy": self.energy,
                "T_max_C": float(self.T.max() - KELVIN),
                "sensors_C": dict(zip(table["sensor"], table["T_C"], strict=True)),
                "growth_um": {k: v * 1e6 for k, v in self.growth_m.items()}}

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

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        table = self.sensor_table()
        masses = self.mass_table()
        write_json(out / "summary.json", self.summary())
        write_csv(out / "sensors.csv", list(table), zip(*table.values(), strict=True))
        write_csv(out / "masses.csv", list(masses), zip(*masses.values(), strict=True))
        files = ["summary.json", "sensors.csv", "masses.csv"]
        if pictures:
            plt = plots.pyplot()
            ax = self.plot()
            atomic_write(out / "masses.png", lambda tmp: ax.figure.savefig(tmp, dpi=130))
            plt.close(ax.figure)
            plots.sensor_profile_png(table, out / "sensor_profile.png", self._title())
            files += ["masses.png", "sensor_profile.png"]
        return [out / f for f in files]


@dataclass
class LumpedTransientResult:
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

    @property
    def energy(self) -> dict[str, float]:
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
                "model": _model_info(self.model), "duration_s": float(self.times_s[-1]),
                "steps": len(self.times_s) - 1, "energy": self.energy,
                "peak_C": dict(zip(self.names, peak.tolist(), strict=True)),
                "final_C": dict(zip(self.names, (self.sensor_K[-1] - KELVIN).tolist(),
                                    strict=True)),
                "peak_growth_um": {k: float(v.max() * 1e6) for k, v in self.growth_m.items()},
                "final_growth_um": {k: float(v[-1] * 1e6) for k, v in self.growth_m.items()}}

    def plot(self, ax=None):
        plt = plots.pyplot()
        if ax is None:
            _, ax = plt.subplots(figsize=(9, 4.5), layout="constrained")
        for j, n in enumerate(self.names):
            ax.plot(self.times_s / 3600, self.sensor_K[:, j] - KELVIN, label=n)
        ax.set_xlabel("time [h]")
        ax.set_ylabel("temperature [°C]")
        return ax

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        """Summary JSON, sensor time series CSV, PNGs (sensors; T1 and P1 with the band)."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        write_json(out / "summary.json", self.summary())
        growth = np.array(list(self.growth_m.values())).T * 1e6 if self.growth_m else \
            np.zeros((len(self.times_s), 0))
        write_csv(out / "sensors_timeseries.csv",
                  ["time_s"] + [f"{n}_C" for n in self.names] + [f"{k}_um" for k in self.growth_m],
                  ([t, *row, *g] for t, row, g in zip(self.times_s, self.sensor_K - KELVIN,
                                                       growth, strict=True)))
        files = ["summary.json", "sensors_timeseries.csv"]
        if pictures:
            title = f"{self.model.spec.name}: {self.case.name}, lumped {self.model.nodes} nodes"
            arrays = {s.name: s.array for s in self.model.spec.temperature_sensors() if s.array}
            plots.timeseries_png(self.times_s, self.names, self.sensor_K - KELVIN,
                                 out / "sensors_timeseries.png", title, arrays)
            files.append("sensors_timeseries.png")
            if "P1" in self.growth_m and "T1" in self.names:
                plots.growth_band_png(self.times_s, self.sensor("T1") - KELVIN,
                                      self.growth_m["P1"] * 1e6, out / "T1_P1_tolerance.png",
                                      title)
                files.append("T1_P1_tolerance.png")
        return [out / f for f in files]
