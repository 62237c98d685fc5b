"""What the result objects of both models share: energy balances, the sensor table and the
DataFrame views. The models' result classes (reference.results, lumped.results) add their
own fields, pictures and files. Temperatures in K; tables name their unit (``T_C``)."""

from __future__ import annotations

import numpy as np

from spindle.errors import SolverError
from spindle.units import ZERO_C_K

#: the largest relative energy imbalance a written result may have: the solvers close the
#: balance to round-off (steady, 1e-12) or to the time integration's bookkeeping (1e-9);
#: beyond this the problem is ill-conditioned (a conductance of 1e300 W/K gave 47 %)
MAX_RELATIVE_IMBALANCE = 1e-3


#: the least heat flow [W] a balance is judged against: a microwatt is below any flow a bench
#: can tell (a sensor's 0.01 K across a 1 W/K path is 10 mW). Without it a spindle with no
#: heat at its reference temperature, whose flows are round-off, had an "imbalance" of 100 %
FLOW_FLOOR_W = 1e-6

#: iron melts at 1811 K: a solid model's temperature above it is no result, it is a unit or
#: an exponent off in the spec (a conductivity in kW/(m K), a source of 1e300 W)
T_MELT_K = 1811.0


def check_plausible(T_K: np.ndarray, relative_imbalance: float, file: str) -> None:
    """Refuse a result that cannot be physical before anything is written: temperatures that
    are not finite, not above 0 K or above iron's melting point, or an energy balance that
    does not close."""
    T = np.asarray(T_K, dtype=float)
    if not np.isfinite(T).all() or T.min() <= 0.0 or T.max() > T_MELT_K:
        bad = ("not finite" if not np.isfinite(T).all() else f"down to {T.min():.4g} K"
               if T.min() <= 0.0 else f"up to {T.max():.4g} K, above the melting point of iron "
               f"({T_MELT_K:g} K)")
        raise SolverError(f"{file}: result: the temperatures are {bad}, which is not physical; "
                          "fix: check the spec's conductances, films and sources, and the cycle's "
                          "loads and heat, for values many orders of magnitude off (docs/spec.md "
                          "lists plausible ranges)")
    if not relative_imbalance <= MAX_RELATIVE_IMBALANCE:
        raise SolverError(f"{file}: result: the energy balance is off by "
                          f"{relative_imbalance:.2g} of the heat flows (limit "
                          f"{MAX_RELATIVE_IMBALANCE:g}): the problem is ill-conditioned; fix: "
                          "check the spec for conductances or films many orders of magnitude "
                          "apart (docs/spec.md lists plausible ranges)")


def _growth_text(growth_um: dict[str, float]) -> str:
    return "".join(f", {k} {v:.2f} µm" for k, v in growth_um.items())


class SteadyTable:
    """Needs ``model.spec``, ``case``, ``time_s``, ``speed_rpm``, ``T``, ``sensors``,
    ``heat_in_W``, ``heat_out_W``, ``residual`` and ``growth_m``. The result classes are
    dataclasses made with ``repr=False``, so that this short ``repr`` stands."""

    def __repr__(self) -> str:
        hot = max(self.sensors.items(), key=lambda kv: kv[1]) if self.sensors else None
        where = f", hottest sensor {hot[0]} {hot[1] - ZERO_C_K:.1f} °C" if hot else ""
        return (f"<{type(self).__name__} {self.model.spec.name}, {self.case.name}: "
                f"{self.speed_rpm:g} rpm, {self.heat_in_W:.0f} W in{where}"
                f"{_growth_text({k: v * 1e6 for k, v in self.growth_m.items()})}>")

    @property
    def energy(self) -> dict[str, float]:
        """Global balance [W]: heat in - heat out (no storage at steady state)."""
        out = sum(self.heat_out_W.values())
        imbalance = self.heat_in_W - out
        scale = max(abs(self.heat_in_W), sum(abs(v) for v in self.heat_out_W.values()),
                    FLOW_FLOOR_W)
        return {"heat_in_W": self.heat_in_W, "heat_out_W": out, "imbalance_W": imbalance,
                "relative_imbalance": abs(imbalance) / scale,
                **{f"out_{k}_W": v for k, v in self.heat_out_W.items()}}

    def check_plausible(self, file: str) -> None:
        """SolverError unless the field is above 0 K and the balance closes (before writing)."""
        check_plausible(self.T, self.energy["relative_imbalance"], file)

    def sensor_table(self) -> dict[str, list]:
        T_amb = float(self.case.T_ambient_K(self.time_s))
        sensors, values = self.model.spec.temperature_sensors(), self.sensors
        return {"sensor": [s.name for s in sensors], "array": [s.array or "" for s in sensors],
                "z_m": [s.z for s in sensors], "r_m": [s.r for s in sensors],
                "T_C": [values[s.name] - ZERO_C_K for s in sensors],
                "rise_K": [values[s.name] - T_amb for s in sensors]}

    def steady_summary(self, about: dict) -> dict:
        """The JSON summary; ``about`` describes the model (mesh, or lumped nodes)."""
        table = self.sensor_table()
        from spindle.outputs import jsonable  # plain numbers: no np.float64 in a summary

        return jsonable({"spec": self.model.spec.name, "kind": "steady", **about,
                         "speed_rpm": self.speed_rpm,
                         "T_ambient_C": float(self.case.T_ambient_K(self.time_s)) - ZERO_C_K,
                         "T_coolant_C": float(self.case.T_coolant_K(self.time_s)) - ZERO_C_K,
                         "relative_residual": self.residual, "energy": self.energy,
                         "T_max_C": float(self.T.max() - ZERO_C_K),
                         "sensors_C": dict(zip(table["sensor"], table["T_C"], strict=True)),
                         "growth_um": {k: v * 1e6 for k, v in self.growth_m.items()}})

    def to_pandas(self):
        """The sensor table as a DataFrame (needs pandas: pip install 'spindle-verify[data]')."""
        import pandas as pd

        return pd.DataFrame(self.sensor_table())


class TransientTable:
    """Needs ``model.spec``, ``case``, ``times_s``, ``names``, ``sensor_K``, ``growth_m`` and
    the energy totals (dataclasses with ``repr=False``, as :class:`SteadyTable`)."""

    def __repr__(self) -> str:
        peaks = self.peaks()
        hot = max(peaks["peak_C"].items(), key=lambda kv: kv[1]) if peaks["peak_C"] else None
        where = f", hottest sensor {hot[0]} peaks at {hot[1]:.1f} °C" if hot else ""
        return (f"<{type(self).__name__} {self.model.spec.name}, {self.case.name}: "
                f"{self.times_s[-1] / 3600:.3g} h in {len(self.times_s) - 1} steps{where}"
                f"{_growth_text(peaks['peak_growth_um']).replace(' µm', ' µm peak')}>")

    @property
    def energy(self) -> dict[str, float]:
        """Cumulative balance [J]: in - out - stored, and its size relative to the flows."""
        imb = self.energy_in_J - self.energy_out_J - self.energy_stored_J
        scale = max(abs(self.energy_in_J), abs(self.energy_out_J),
                    abs(self.energy_stored_J),
                    FLOW_FLOOR_W * float(self.times_s[-1] - self.times_s[0]))
        return {"energy_in_J": self.energy_in_J, "energy_out_J": self.energy_out_J,
                "energy_stored_J": self.energy_stored_J, "imbalance_J": imb,
                "relative_imbalance": abs(imb) / scale}

    def check_plausible(self, file: str) -> None:
        """SolverError unless every sensor stays above 0 K and the balance closes."""
        check_plausible(self.sensor_K, self.energy["relative_imbalance"], file)

    def sensor(self, name: str) -> np.ndarray:
        """History of one sensor [K]."""
        if name not in self.names:
            raise KeyError(f"no sensor named {name!r}; the sensors are {list(self.names)}")
        return self.sensor_K[:, self.names.index(name)]

    def to_pandas(self):
        import pandas as pd

        df = pd.DataFrame(self.sensor_K - ZERO_C_K, columns=[f"{n}_C" for n in self.names])
        df.insert(0, "time_s", self.times_s)
        for k, v in self.growth_m.items():
            df[f"{k}_um"] = v * 1e6
        return df

    def peaks(self) -> dict:
        """Peak and final sensor temperatures [degC] and growth readings [µm]."""
        peak = self.sensor_K.max(axis=0) - ZERO_C_K
        return {"peak_C": dict(zip(self.names, peak.tolist(), strict=True)),
                "final_C": dict(zip(self.names, (self.sensor_K[-1] - ZERO_C_K).tolist(),
                                    strict=True)),
                "peak_growth_um": {k: float(v.max() * 1e6) for k, v in self.growth_m.items()},
                "final_growth_um": {k: float(v[-1] * 1e6) for k, v in self.growth_m.items()}}

    def timeseries_rows(self) -> tuple[list[str], object]:
        """Header and rows of the sensor and growth history CSV."""
        growth = np.array(list(self.growth_m.values())).T * 1e6 if self.growth_m else \
            np.zeros((len(self.times_s), 0))
        header = ["time_s"] + [f"{n}_C" for n in self.names] + [f"{k}_um" for k in self.growth_m]
        rows = ([t, *row, *g] for t, row, g in zip(self.times_s, self.sensor_K - ZERO_C_K, growth,
                                                   strict=True))
        return header, rows

    def plot(self, ax=None):
        """The sensors' temperatures over the run, titled, with a legend; without ``ax``, a
        figure that also shows P1 against the paper's ±1.5 µm band (where the run has P1).
        Returns the temperatures' axes."""
        from spindle.plots import pyplot
        from spindle.tolerances import GROWTH_TOLERANCE_M

        plt = pyplot()
        h = self.times_s / 3600
        growth = ax is None and "P1" in self.growth_m
        if ax is None:
            fig, axes = plt.subplots(2 if growth else 1, 1, figsize=(10, 7 if growth else 4.5),
                                     sharex=True, layout="constrained", squeeze=False)
            ax = axes[0, 0]
        for j, n in enumerate(self.names):
            ax.plot(h, self.sensor_K[:, j] - ZERO_C_K, label=n, lw=1)
        ax.set_ylabel("temperature [°C]")
        ax.set_title(f"{self.model.spec.name}: {self.case.name}, {len(self.names)} sensors")
        ax.legend(fontsize=7, ncols=2 if len(self.names) > 12 else 1, loc="upper left",
                  bbox_to_anchor=(1.01, 1.0), title="sensor", title_fontsize=8)
        ax.grid(alpha=0.3)
        if growth:
            a2, band = axes[1, 0], GROWTH_TOLERANCE_M * 1e6
            p1 = self.growth_m["P1"] * 1e6
            a2.fill_between(h, p1 - band, p1 + band, color="tab:blue", alpha=0.2,
                            label=f"±{band:g} µm tolerance")
            a2.plot(h, p1, color="tab:blue", label="P1 axial growth")
            a2.set_ylabel("P1 [µm]")
            a2.set_xlabel("time [h]")
            a2.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
            a2.grid(alpha=0.3)
        else:
            ax.set_xlabel("time [h]")
        return ax
