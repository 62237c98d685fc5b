"""The ``rom`` command's work: build a ROM (reference/rom/) at a FEM level, check it on held-out cycles.

:func:`rom_study` builds the ROM (rom.build.build_rom) on the training cycle, runs the FEM
(backward Euler on the same grid, or the steady solve for a steady cycle) and the ROM on
every held-out cycle, and times both; :class:`ROMStudy` writes the outputs.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from reference.rom.build import BuildReport, build_rom, meets, output_errors
from reference.rom.model import ReducedModel, fem_steady, fem_transient, full_system
from spindle.loads import LoadCase


def named_case(spec, name: str, seed: int = 0) -> LoadCase:
    """The load case of a shipped cycle (or cycle file) through the spec's power balance, or
    of ``random`` / ``random-loaded`` / ``random-ramped-load``: the cycle ``spindle-verify
    synth`` draws from ``seed`` (spindle.cycles.drawn_cycle), named with its seed."""
    from dataclasses import replace

    from spindle.cycles import RANDOM_CYCLES
    from spindle.drive import cycle_load_case, spindle_cycle

    cycle = spindle_cycle(spec, name, seed)
    case = cycle_load_case(spec, cycle)
    if name in RANDOM_CYCLES:
        return replace(case, name=f"{name} (seed {seed})")
    return replace(case, duration_s=0.0) if cycle.steady else case


def parse_cycle(text: str) -> tuple[str, int]:
    """``NAME`` or ``NAME:SEED`` (the seed of a random cycle; default 0)."""
    name, _, seed = text.partition(":")
    return name, int(seed) if seed else 0


@dataclass
class HeldOut:
    case: str
    kind: str  # "transient" / "steady"
    errors: dict[str, float]
    fem_runtime_s: float
    rom_runtime_s: float
    error_estimate: dict | None = None


@dataclass
class ROMStudy:
    spec_name: str
    level: int
    n_full: int
    rom: ReducedModel
    report: BuildReport
    held_out: list[HeldOut]
    tol_temp_K: float
    tol_growth_um: float
    runtime_s: float
    extra: dict = field(default_factory=dict)

    def meets_all(self) -> bool:
        return all(meets(h.errors, self.tol_temp_K, self.tol_growth_um) for h in self.held_out)

    def table(self) -> dict[str, list]:
        rows = [{"case": f"{self.report.training_case} (training)", "kind": "transient",
                 **self.report.errors[-1], "fem_runtime_s": self.report.timings_s.get(
                     "fem_training", math.nan), "rom_runtime_s": math.nan}]
        for h in self.held_out:
            rows.append({"case": h.case, "kind": h.kind, **h.errors,
                         "fem_runtime_s": h.fem_runtime_s, "rom_runtime_s": h.rom_runtime_s,
                         "estimated_max_K": (h.error_estimate or {}).get("estimated_max_K",
                                                                         math.nan)})
        keys = list(dict.fromkeys(k for r in rows for k in r))
        return {k: [r.get(k, math.nan) for r in rows] for k in keys}

    def summary(self) -> dict:
        r = self.report
        return {"spec": self.spec_name, "fem_level": self.level, "fem_unknowns": self.n_full,
                "states": self.rom.n_states, "method": "Galerkin projection, one basis for "
                "every speed (affine K(n), B(n) kept): rational Krylov at speeds x shifts, "
                "POD-ordered on the training cycle",
                "tolerances": {"temperature_K": self.tol_temp_K, "growth_um": self.tol_growth_um,
                               "training_safety_factor": r.safety},
                "training": {"case": r.training_case, "dt_s": r.dt_s, "candidates": r.candidates,
                             "speeds_rpm": r.speeds_rpm, "shifts_per_s": r.shifts,
                             "sizes": r.sizes, "errors": r.errors, "chosen": r.chosen},
                "timings_s": r.timings_s, "runtime_s": self.runtime_s,
                "held_out": [vars(h) for h in self.held_out],
                "meets_tolerances_on_held_out": self.meets_all(), **self.extra}

    def plot(self):
        from spindle.plots import pyplot

        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
        r = self.report
        ax.semilogy(r.sizes, [e["temperature_max_K"] for e in r.errors], "o-",
                    label="worst sensor error [K]")
        for key in [k for k in r.errors[0] if k.endswith("_um")]:
            ax.semilogy(r.sizes, [e[key] for e in r.errors], "s--", label=key.replace(
                "_max_um", " error [µm]"))
        ax.axhline(self.tol_temp_K / r.safety, color="tab:red", ls=":", lw=1,
                   label=f"{self.tol_temp_K:g} K / {r.safety:g}")
        ax.set_xlabel("reduced states r")
        ax.set_ylabel("max error on the training cycle")
        ax.set_title(f"{self.spec_name}: ROM of FEM level {self.level} ({self.n_full} DOFs), "
                     f"training {r.training_case}", fontsize=9)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
        return fig

    def save(self, out: Path, pictures: bool = True) -> list[Path]:
        from spindle.outputs import atomic_write, write_csv, write_json
        from spindle.plots import pyplot

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        t = self.table()
        write_csv(out / "rom_errors.csv", list(t), zip(*t.values(), strict=True))
        write_json(out / "rom.json", self.summary())
        s = self.rom.system
        atomic_write(out / "rom.npz", lambda tmp: np.savez(
            tmp, K_terms=s.Kj, film_b=s.bj, F_sources=s.F_src, readout=s.O, offset=s.offset,
            z_uniform=s.z_one, film_terms=np.array([j for j, _ in s.film_rows]),
            film_refs=np.array([ref for _, ref in s.film_rows])))
        files = [out / "rom_errors.csv", out / "rom.json", out / "rom.npz"]
        if pictures:
            fig = self.plot()
            atomic_write(out / "rom_size.png", lambda tmp: fig.savefig(tmp, dpi=130))
            pyplot().close(fig)
            files.append(out / "rom_size.png")
        return files


def rom_study(spec, level: int, training: str, held_out: Sequence[str], dt_s: float,
              tol_temp_K: float, tol_growth_um: float, safety: float,
              progress: Callable[[str], None] | None = None) -> ROMStudy:
    from reference import ReferenceModel
    from spindle.errors import InputError

    say = progress or (lambda _m: None)
    t0 = time.perf_counter()
    say(f"FEM level {level}: assembly")
    ref = ReferenceModel(spec, level)
    name, seed = parse_cycle(training)
    train = named_case(ref.spec, name, seed)
    if train.duration_s == 0:  # a steady case has no snapshots in time to reduce
        raise InputError("command line", "--cycle", f"'{training}' is a steady case; a ROM is "
                         "trained on a cycle that runs in time",
                         "train on a transient cycle, e.g. random-loaded (the default) or "
                         "spl-16h; a steady case may be held out (--held-out nominal)")
    rom, report = build_rom(ref, train, dt_s, tol_temp_K, tol_growth_um, safety=safety,
                            level=level, progress=say)
    full = full_system(ref)
    rows = []
    for text in held_out:
        name, seed = parse_cycle(text)
        case = named_case(ref.spec, name, seed)
        if case.duration_s == 0:
            t1 = time.perf_counter()
            y_ref = fem_steady(full, case)
            t2 = time.perf_counter()
            st = rom.steady(case)
            y = np.r_[st.sensor_values, [st.growth_m[k] for k in rom.readings]]
            rows.append(HeldOut(case.name, "steady", output_errors(full, y, y_ref), t2 - t1,
                                time.perf_counter() - t2))
            continue
        say(f"held-out {case.name}: FEM backward Euler (dt {dt_s:g} s)")
        t1 = time.perf_counter()
        _, Y_ref = fem_transient(full, case, dt_s)
        t2 = time.perf_counter()
        res = rom.transient(case, dt_s)
        growth = np.array([res.growth_m[k] for k in rom.readings]).T  # none: a spec without P1
        Y = np.hstack([res.sensor_K, growth.reshape(len(res.sensor_K), len(rom.readings))])
        err = output_errors(full, Y, Y_ref)
        rows.append(HeldOut(case.name, "transient", err, t2 - t1, res.runtime_s,
                            res.error_estimate))
        say(f"held-out {case.name}: {err['temperature_max_K']:.3g} K, P1 "
            f"{err.get('P1_max_um', math.nan):.3g} µm")
    ref.release()
    return ROMStudy(ref.spec.name, level, full.n, rom, report, rows, tol_temp_K, tol_growth_um,
                    time.perf_counter() - t0)
