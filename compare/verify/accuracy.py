"""Accuracy against element count: eq. 14, the lumped models and the FEM levels against the
converged reference, on one load case, steady or transient.

Errors per model (temperatures in K, growth in µm): max and RMS over the 11 shaft and the 11
housing array sensors, T1, T2 and P1; for a transient, over the sensors and over time.
The verdict compares the worst temperature error with the paper's 1 K and the P1 error with
its ±1.5 µm (paper section 3, Fig. 13).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from compare.report import markdown_table
from spindle.loads import LoadCase
from spindle.spec import Spec
from spindle.tolerances import GROWTH_TOLERANCE_M, TEMPERATURE_TOLERANCE_K
from spindle.units import ZERO_C_K

TOL_TEMP_K = TEMPERATURE_TOLERANCE_K  # the paper's (spindle.tolerances)
TOL_GROWTH_UM = GROWTH_TOLERANCE_M * 1e6  # the same in µm, the unit of the tables
NODES = (2, 3, 5, 7, 11, 15, 21, 31, 41)
PRESET_NODES = {5: "paper5", 11: "paper11"}


@dataclass
class Entry:
    """One model's read-outs on the case: sensor temperatures [K] and growth [m], floats for a
    steady state or arrays over ``times_s`` for a transient."""

    name: str
    kind: str  # "eq14", "lumped", "fem"
    size: int  # unknowns: masses, FEM DOFs; 1 for eq. 14
    runtime_s: float
    sensors: dict[str, float | np.ndarray]
    growth: dict[str, float | np.ndarray] = field(default_factory=dict)
    preset: str = ""
    nodes: int | None = None
    level: int | None = None
    #: FEM transients: per sensor [K] and growth reading [m], the bound on the temporal error
    #: of the exact integration (CRAM-16's, ThermalModel.exact_readouts)
    time_error: dict[str, float] = field(default_factory=dict)


def _stats(d: np.ndarray) -> tuple[float, float]:
    d = np.asarray(d, dtype=float)
    if d.size == 0:
        return math.nan, math.nan
    return float(np.max(np.abs(d))), float(np.sqrt(np.mean(d * d)))


@dataclass
class AccuracyResult:
    """Error of every model against the reference, with runtimes and verdicts."""

    spec: Spec
    case_name: str
    transient: bool
    reference: Entry
    reference_label: str
    entries: list[Entry]
    times_s: np.ndarray | None = None
    tol_temp_K: float = TOL_TEMP_K
    tol_growth_um: float = TOL_GROWTH_UM
    #: the reference's own uncertainty, {"K": ..., "um": ...} (grid convergence index times
    #: value, plus the stated temporal error): a verdict whose margin to a tolerance is
    #: smaller is "borderline", not a bare PASS or FAIL (None: no uncertainty known)
    uncertainty: dict[str, float] | None = None

    def _arrays(self) -> dict[str, list[str]]:
        out: dict[str, list[str]] = {}
        for s in self.spec.temperature_sensors():
            if s.array:
                out.setdefault(s.array, []).append(s.name)
        return out

    def errors(self, e: Entry) -> dict[str, float]:
        ref = self.reference
        row: dict[str, float] = {}
        for arr, names in self._arrays().items():
            have = [n for n in names if n in e.sensors]
            d = np.array([np.asarray(e.sensors[n]) - np.asarray(ref.sensors[n]) for n in have])
            row[f"{arr}_max_K"], row[f"{arr}_rms_K"] = _stats(d)
        for n in ("T1", "T2"):
            if n in ref.sensors:
                d = np.asarray(e.sensors[n]) - np.asarray(ref.sensors[n]) if n in e.sensors \
                    else np.array([])
                mx, rms = _stats(d)
                row[f"{n}_max_K"] = mx
                if self.transient:
                    row[f"{n}_rms_K"] = rms
        if "P1" in ref.growth:
            d = (np.asarray(e.growth["P1"]) - np.asarray(ref.growth["P1"])) * 1e6 \
                if "P1" in e.growth else np.array([])
            mx, rms = _stats(d)
            row["P1_max_um"] = mx
            if self.transient:
                row["P1_rms_um"] = rms
        return row

    def borderline(self, row: dict[str, float]) -> bool:
        """Does the verdict on ``row`` hang on less than the reference's uncertainty? A pass
        whose margin to a tolerance is within it, or a fail whose every excess is."""
        if not self.uncertainty:
            return False
        checks = [(worst_temperature_K(row), self.tol_temp_K, self.uncertainty.get("K", 0.0)),
                  (row.get("P1_max_um", math.nan), self.tol_growth_um,
                   self.uncertainty.get("um", 0.0))]
        checks = [c for c in checks if not math.isnan(c[0])]
        if not checks:
            return False
        if _meets(row, self.tol_temp_K, self.tol_growth_um):
            return any(tol - err <= u for err, tol, u in checks)
        return all(err - tol <= u for err, tol, u in checks if err > tol)

    def verdict_word(self, row: dict[str, float]) -> str:
        """"PASS", "FAIL" or "borderline" (:meth:`borderline`)."""
        if self.borderline(row):
            return "borderline"
        return "PASS" if _meets(row, self.tol_temp_K, self.tol_growth_um) else "FAIL"

    def verdict(self, row: dict[str, float]) -> str:
        worst = worst_temperature_K(row)
        growth = row.get("P1_max_um", math.nan)
        parts = []
        if not math.isnan(worst):
            parts.append(f"temperature {'meets' if worst <= self.tol_temp_K else 'fails'} "
                         f"{self.tol_temp_K:g} K ({worst:.2f} K)")
        if not math.isnan(growth):
            parts.append(f"P1 {'meets' if growth <= self.tol_growth_um else 'fails'} "
                         f"±{self.tol_growth_um:g} µm ({growth:.2f} µm)")
        text = "; ".join(parts) if parts else "no comparable read-out"
        if self.borderline(row):
            u = self.uncertainty
            text += (f"; borderline: within the reference's uncertainty ({u.get('K', 0):.2g} K, "
                     f"{u.get('um', 0):.2g} µm) of a tolerance")
        return text

    def table(self) -> dict[str, list]:
        rows = []
        for e in self.entries:
            err = self.errors(e)
            rows.append({"model": e.name, "kind": e.kind, "preset": e.preset,
                         "unknowns": e.size, "runtime_s": e.runtime_s, **err,
                         "meets_tolerances": _meets(err, self.tol_temp_K, self.tol_growth_um),
                         "borderline": self.borderline(err), "verdict": self.verdict(err)})
        keys = list(dict.fromkeys(k for r in rows for k in r))
        return {k: [r.get(k, math.nan) for r in rows] for k in keys}

    def slopes(self) -> dict[str, float]:
        """Least-squares slope of log(worst temperature error) against log(unknowns), per
        model family (the lumped series and the FEM levels)."""
        t = self.table()
        out = {}
        for kind in ("lumped", "fem"):
            idx = [i for i, k in enumerate(t["kind"]) if k == kind]
            x, y = [], []
            for i in idx:
                worst = _worst_temp(t, i)
                if worst > 0 and not math.isnan(worst):
                    x.append(math.log(t["unknowns"][i]))
                    y.append(math.log(worst))
            if len(x) >= 2:
                out[kind] = float(np.polyfit(x, y, 1)[0])
        return out

    def to_pandas(self):
        import pandas as pd

        return pd.DataFrame(self.table())

    def markdown(self) -> str:
        """The table as Markdown (without the ``kind`` column); runtimes to the millisecond."""
        t = self.table()
        t["meets_tolerances"] = ["borderline" if b else "PASS" if v else "FAIL"
                                 for v, b in zip(t["meets_tolerances"], t["borderline"],
                                                 strict=True)]
        cols = [c for c in t if c not in ("kind", "borderline")]
        fmts = [".3f" if c == "runtime_s" else ".3g" for c in cols]
        return markdown_table(cols, list(zip(*(t[c] for c in cols), strict=True)), fmts)

    def summary(self) -> dict:
        t = self.table()
        return {"spec": self.spec.name, "case": self.case_name,
                "kind": "transient" if self.transient else "steady",
                "reference": self.reference_label, "tolerances": {
                    "temperature_K": self.tol_temp_K, "growth_um": self.tol_growth_um},
                "slopes": self.slopes(),
                "models": [{k: (None if isinstance(v[i], float) and math.isnan(v[i]) else v[i])
                            for k, v in t.items()} for i in range(len(t["model"]))]}

    # ------------------------------------------------------------------ pictures
    def plot(self, ax=None, against: str = "unknowns"):
        """Worst temperature error against unknowns (or ``against="runtime"``: against each
        model's runtime), log-log, with the fitted slopes (against unknowns)."""
        from spindle.plots import pyplot, wrapped

        plt = pyplot()
        if ax is None:
            _, ax = plt.subplots(figsize=(7.5, 5), layout="constrained")
        t = self.table()
        slopes = self.slopes()
        for kind, style, label in (("lumped", "o-", "lumped N nodes"), ("fem", "s-", "FEM levels"),
                                   ("eq14", "D", "eq. 14"), ("rom", "*", "ROM of the FEM")):
            idx = [i for i, k in enumerate(t["kind"]) if k == kind]
            xs = t["runtime_s" if against == "runtime" else "unknowns"]
            pts = [(xs[i], _worst_temp(t, i)) for i in idx]
            pts = [(x, y) for x, y in pts if x > 0 and y > 0 and not math.isnan(y)]
            if not pts:
                continue
            lab = label + (f" (slope {slopes[kind]:.2f})"
                           if kind in slopes and against != "runtime" else "")
            ax.loglog(*zip(*pts, strict=True), style, label=lab)
            for i in idx:
                if t["preset"][i]:
                    ax.annotate(t["preset"][i], (xs[i], _worst_temp(t, i)),
                                textcoords="offset points", xytext=(4, 6), fontsize=8)
        ax.axhline(self.tol_temp_K, color="tab:red", ls="--", lw=1,
                   label=f"tolerance {self.tol_temp_K:g} K")
        ran = set(t["kind"])
        if against == "runtime":
            parts = [("lumped", "lumped: build and run"), ("fem", "FEM: assembly and solve"),
                     ("rom", "ROM: run, its build excluded")]
            xlabel = "runtime [s] (" + "; ".join(w for k, w in parts if k in ran) + ")"
        else:
            parts = [("lumped", "lumped masses"), ("fem", "FEM DOFs"), ("rom", "ROM states")]
            xlabel = "unknowns (" + ", ".join(w for k, w in parts if k in ran) + ")"
        ax.set_xlabel(wrapped(xlabel, ax.figure.get_size_inches()[0], 10))
        ax.set_ylabel("worst sensor temperature error [K]")
        ax.set_title(wrapped(f"{self.spec.name}, {self.case_name}: error against the reference "
                             f"({self.reference_label})", ax.figure.get_size_inches()[0], 9),
                     fontsize=9)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        return ax

    def profile_plot(self, ax=None, array: str = "shaft"):
        """Sensor temperatures along the shaft per model against the reference (the paper's
        Fig. 4, extended); for a transient, at the time of the reference's peak."""
        from spindle.plots import pyplot, wrapped

        plt = pyplot()
        if ax is None:
            _, ax = plt.subplots(figsize=(10, 4.5), layout="constrained")
        sensors = [s for s in self.spec.temperature_sensors() if s.array == array]
        z = np.array([s.z for s in sensors]) * 1e3
        k = None
        if self.transient:
            k = int(np.argmax(np.asarray(self.reference.sensors[sensors[0].name])))

        def read(e: Entry, n: str) -> float:
            v = np.asarray(e.sensors[n])
            return float(v[k] if k is not None else v) - ZERO_C_K

        # the legend names the reference briefly; the tables carry its full description
        short = self.reference_label.split(",")[0].split(" (")[0]
        ax.plot(z, [read(self.reference, s.name) for s in sensors], "k-", lw=2.5,
                label=f"reference ({short})")
        for e in self.entries:
            if not all(s.name in e.sensors for s in sensors):
                continue
            if e.kind == "lumped" and e.nodes not in (2, 5, 11, 41):
                continue
            if e.kind == "fem" and e.level != 0:
                continue
            key = (e.kind, e.nodes if e.kind == "lumped" else e.level)
            ax.plot(z, [read(e, s.name) for s in sensors], "o--" if e.kind != "fem" else "s:",
                    ms=4, lw=1, color=PROFILE_COLOURS.get(key),
                    label=e.name + (f" ({e.preset})" if e.preset else ""))
        ax.set_xlabel("z [mm]")
        ax.set_ylabel("temperature [°C]")
        when = f" at t = {self.times_s[k] / 3600:.2f} h" if k is not None else ""
        ax.set_title(wrapped(f"{self.spec.name}, {self.case_name}: the {len(sensors)} {array} "
                             f"sensors{when}", 0.75 * ax.figure.get_size_inches()[0], 9),
                     fontsize=9)
        ax.grid(alpha=0.3)
        # beside the axes, where it covers no data
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
        return ax

    def save(self, out: Path, stem: str, pictures: bool = True) -> list[Path]:
        from spindle.outputs import atomic_write, write_csv, write_json
        from spindle.plots import pyplot

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        t = self.table()
        write_csv(out / f"{stem}.csv", list(t), zip(*t.values(), strict=True))
        write_json(out / f"{stem}.json", self.summary())
        atomic_write(out / f"{stem}.md", lambda tmp: tmp.write_text(self.markdown() + "\n",
                                                                      "utf-8"))
        files = [f"{stem}.csv", f"{stem}.json", f"{stem}.md"]
        if pictures:
            for suffix, ax in (("error", self.plot()), ("runtime", self.plot(against="runtime")),
                               ("shaft_profile", self.profile_plot())):
                name = f"{stem}_{suffix}.png"
                atomic_write(out / name, lambda tmp, f=ax.figure: f.savefig(tmp, dpi=130))
                pyplot().close(ax.figure)
                files.append(name)
        return [out / f for f in files]


#: one colour per model in every profile figure (steady and transient alike): (kind, nodes
#: for lumped models or level for the FEM) -> matplotlib colour
PROFILE_COLOURS = {("lumped", 2): "C0", ("lumped", 5): "C1", ("lumped", 11): "C2",
                   ("lumped", 41): "C3", ("fem", 0): "C4", ("eq14", None): "C5"}


def worst_temperature_K(row: dict) -> float:
    """The largest of a row's ``*_max_K`` temperature errors [K] (nan if it has none)."""
    vals = [v for k, v in row.items() if k.endswith("_max_K") and not math.isnan(v)]
    return max(vals) if vals else math.nan


def _worst_temp(t: dict[str, list], i: int) -> float:
    return worst_temperature_K({k: t[k][i] for k in t if k.endswith("_max_K")})


def _meets(row: dict[str, float], tol_T: float, tol_P: float) -> bool:
    worst = worst_temperature_K(row)
    growth = row.get("P1_max_um", math.nan)
    return worst <= tol_T and (math.isnan(growth) or growth <= tol_P)


# ---------------------------------------------------------------------- running the models
def _read_outs(model, case: LoadCase, dt_s: float | None, T0: float | None) -> tuple[dict, dict]:
    """Sensors [K] and growth [m] of a steady (dt_s None) or transient run of either model."""
    if dt_s is None:
        res = model.steady(case)
        return res.sensors, res.growth_m
    res = model.transient(case, dt_s, T0=T0)
    return {k: res.sensor(k) for k in res.names}, res.growth_m


def lumped_entries(spec: Spec, case: LoadCase, nodes: Sequence[int], dt_s: float | None,
                   T0: float | None, progress: Callable[[str], None] | None = None
                   ) -> list[Entry]:
    """Steady (dt_s None) or transient runs of the lumped model for each N."""
    from lumped import build

    out = []
    for n in nodes:
        if progress:
            progress(f"lumped {n} nodes")
        t = time.perf_counter()
        model = build(spec, n)
        sensors, growth = _read_outs(model, case, dt_s, T0)
        out.append(Entry(f"lumped {n}", "lumped", model.n_states, time.perf_counter() - t,
                         sensors, growth, PRESET_NODES.get(n, ""), nodes=n))
    return out


def eq14_entry(spec: Spec, case: LoadCase) -> Entry | None:
    """Eq. 14 on the shaft at the shaft array sensors (steady only). Q1 / Q2: the heat sources
    on the shaft's end faces, or the inner-ring half of the rear / front bearing sources; any
    other heat into the shaft (rotor) is outside eq. 14."""
    from lumped import Fin

    arrays = [a for a in spec.sensor_arrays if a.name == "shaft"]
    if not arrays:
        return None
    speed = float(case.speed_rpm(0.0))
    power = {h.name: float(case.sources.get(h.name, h.power_W)(0.0)) for h in spec.heat_sources}
    t = time.perf_counter()
    ends = _end_heat(spec, power)
    if ends is None:
        bearing = {p.role: p.name for p in spec.parts}
        ends = (0.5 * power.get(bearing.get("rear_bearing", ""), 0.0),
                0.5 * power.get(bearing.get("front_bearing", ""), 0.0))
    fin = Fin.from_spec(spec, arrays[0].part, speed, Q1_W=ends[0], Q2_W=ends[1])
    names = [s for s in spec.temperature_sensors() if s.array == "shaft"]
    z0 = min(s.z_start for s in spec.part(arrays[0].part).sections)
    T_amb = float(case.T_ambient_K(0.0))
    sensors = {s.name: float(T_amb + fin.rise_K(s.z - z0)) for s in names}
    return Entry("eq. 14", "eq14", 1, time.perf_counter() - t, sensors)


def _end_heat(spec: Spec, power: dict[str, float]) -> tuple[float, float] | None:
    """(Q1, Q2) [W] of the case's sources on end faces (rear, front), or None if none."""
    ends = {}
    for side in ("rear", "front"):
        names = {s.name for s in spec.surfaces if s.side == side and s.h_W_m2K is None}
        ends[side] = sum(power[h.name] for h in spec.heat_sources if h.surface in names)
    if not ends["rear"] and not ends["front"]:
        return None
    return ends["rear"], ends["front"]


def fem_entry(spec: Spec, level: int, case: LoadCase, dt_s: float | None, T0: float | None,
              order: int = 2, progress: Callable[[int, int], None] | None = None) -> Entry:
    from reference import ReferenceModel

    t = time.perf_counter()
    model = ReferenceModel(spec, level, order)
    if dt_s is None:
        sensors, growth = _read_outs(model, case, dt_s, T0)
        return Entry(f"FEM level {level}", "fem", int(model.thermal.basis.N),
                     time.perf_counter() - t, sensors, growth, level=level)
    # exact in time for inputs linear between grid points (Krylov, reference.krylov)
    _, sensors, growth, err = model.exact_readouts(case, dt_s, T0, progress=progress)
    return Entry(f"FEM level {level}", "fem", int(model.thermal.basis.N),
                 time.perf_counter() - t, sensors, growth, level=level, time_error=err)


def rom_entry(rom, case: LoadCase, dt_s: float | None, T0: float | None) -> Entry:
    """A reduced-order model (reference.rom.ReducedModel) as a row: steady (dt_s None) or
    transient, integrated exactly in time as the reference is (inputs linear between grid
    points), so that its error is the projection error."""
    t = time.perf_counter()
    if dt_s is None:
        sensors, growth = _read_outs(rom, case, None, T0)
    else:
        res = rom.transient(case, dt_s, T0=T0, method="exact")
        sensors, growth = {k: res.sensor(k) for k in res.names}, res.growth_m
    return Entry(f"ROM {rom.n_states} states", "rom", rom.n_states, time.perf_counter() - t,
                 sensors, growth, level=rom.level)
