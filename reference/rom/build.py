"""Building a reduced model of the reference whose size meets given tolerances.

:func:`build_rom`: the candidate space (rom.model.krylov_candidates), its POD ordering on the
training cycle, and the smallest r whose backward-Euler run of the training cycle stays
within ``tol_temp_K`` at every sensor and ``tol_growth_um`` on every growth reading of the
FEM's backward-Euler run on the same grid (the same scheme, so the difference is the
projection error alone).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from reference.rom.model import (
    DEFAULT_SHIFTS,
    SPEED_FRACTIONS,
    FullSystem,
    ReducedModel,
    fem_transient,
    full_system,
    krylov_candidates,
    pod_directions,
    project,
    reduced_model,
    zeroed_readings,
)
from spindle.errors import SolverError
from spindle.loads import LoadCase, start_temperature_K, time_grid

#: reduced sizes tried, smallest first (the issue's budget: at most 100 states)
SIZES = (4, 6, 8, 10, 12, 15, 20, 25, 30, 40, 50, 60, 80, 100)
#: the training cycle must be met with tolerances this many times tighter: the held-out
#: cycles' errors exceed the training cycle's by up to 2.0x on spl2782 (docs/rom.md)
SAFETY = 2.0
#: the top of the speed range the basis covers [rpm]: the random cycles' top speed
#: (spindle.cycles.RANDOM_MAX_SPEED_RPM), above spl-16h's 4300 rpm
TOP_SPEED_RPM = 6000.0


def output_errors(full_or_rom, Y: np.ndarray, Y_ref: np.ndarray) -> dict[str, float]:
    """Max over time of |Y - Y_ref| per output: sensors [K], growth readings [µm]."""
    d = np.abs(np.atleast_2d(Y) - np.atleast_2d(Y_ref)).max(axis=0)
    ns = len(full_or_rom.sensor_names)
    out = {"temperature_max_K": float(d[:ns].max()) if ns else 0.0}
    for j, k in enumerate(full_or_rom.readings):
        out[f"{k}_max_um"] = float(d[ns + j] * 1e6)
    return out


def meets(err: dict[str, float], tol_temp_K: float, tol_growth_um: float) -> bool:
    return err["temperature_max_K"] <= tol_temp_K and all(
        v <= tol_growth_um for k, v in err.items() if k.endswith("_um"))


@dataclass
class BuildReport:
    """How the ROM was chosen: per tried size, its errors on the training cycle."""

    training_case: str
    dt_s: float
    candidates: int
    sizes: list[int]
    errors: list[dict]
    chosen: int | None
    tol_temp_K: float
    tol_growth_um: float
    safety: float
    timings_s: dict[str, float] = field(default_factory=dict)
    speeds_rpm: list[float] = field(default_factory=list)
    shifts: list[float] = field(default_factory=list)


def build_rom(reference, training: LoadCase, dt_s: float = 60.0, tol_temp_K: float = 0.05,
              tol_growth_um: float = 0.1, sizes: Sequence[int] = SIZES,
              speeds_rpm: Sequence[float] | None = None, shifts: Sequence[float] = DEFAULT_SHIFTS,
              fem_training: tuple[np.ndarray, np.ndarray] | None = None, keep_basis: bool = True,
              safety: float = SAFETY, level: int = -1, indicator: bool = True,
              progress: Callable[[str], None] | None = None) -> tuple[ReducedModel, BuildReport]:
    """A ROM of ``reference`` (a :class:`reference.ReferenceModel` of mesh ``level``) with the
    smallest size of ``sizes`` that meets the tolerances divided by ``safety`` on ``training``
    (see the module docstring).
    ``fem_training``: the FEM's (times, outputs) of the training run, if already computed.
    If no size meets them, the largest is returned and ``report.chosen`` is None."""
    say = progress or (lambda _m: None)
    timings = {}
    t0, c0 = time.perf_counter(), time.process_time()
    full = full_system(reference)
    reference.release()  # the elastic LU of the growth gains is no longer needed
    timings["read-outs"] = time.perf_counter() - t0
    if speeds_rpm is None:
        grid = time_grid(training, dt_s)
        top = max(TOP_SPEED_RPM, float(np.max(training.speed_rpm(grid))))
        speeds_rpm = [f * top for f in SPEED_FRACTIONS]
    t1 = time.perf_counter()
    W = krylov_candidates(full, speeds_rpm, shifts, say)
    cand = project(full, W)
    timings["candidates"] = time.perf_counter() - t1
    say(f"{W.shape[1]} candidate directions; POD on {training.name}")
    t2 = time.perf_counter()
    T0 = start_temperature_K(training)  # where fem_transient starts
    _, Zc = cand.simulate(full.inputs, training, dt_s, cand.z_one * T0, "be")
    Phi, _ = pod_directions(cand, Zc - np.outer(np.ones(len(Zc)), cand.z_one * T0),
                            _response_columns(cand, full, training, dt_s, speeds_rpm, shifts))
    timings["pod"] = time.perf_counter() - t2
    if fem_training is None:
        say(f"FEM backward Euler on {training.name} (dt {dt_s:g} s) for the size choice")
        t3, c3 = time.perf_counter(), time.process_time()
        fem_training = fem_transient(full, training, dt_s)
        timings["fem_training"] = time.perf_counter() - t3
        timings["fem_training_cpu"] = time.process_time() - c3
    _, Y_ref = fem_training
    t4 = time.perf_counter()
    tried, errors, chosen = [], [], None
    for r in sizes:
        if r > Phi.shape[1]:
            break
        red = cand.truncated(Phi[:, :r])
        _, Z = red.simulate(full.inputs, training, dt_s, red.z_one * T0, "be")
        err = output_errors(full, zeroed_readings(Z @ red.O.T + red.offset,
                                                  len(full.sensor_names)), Y_ref)
        tried.append(r)
        errors.append(err)
        say(f"r = {r}: {err['temperature_max_K']:.3g} K, " + ", ".join(
            f"{k.split('_')[0]} {v:.3g} µm" for k, v in err.items() if k.endswith("_um")))
        if meets(err, tol_temp_K / safety, tol_growth_um / safety):
            chosen = r
            break
    if not tried:
        raise SolverError("the candidate space is smaller than the smallest size tried")
    timings["size_choice"] = time.perf_counter() - t4
    r = chosen if chosen is not None else tried[-1]
    V = W @ Phi[:, :r]
    red = project(full, V)
    info = {"level": level, "training": training.name, "safety": safety,
            "dt_s": dt_s, "candidates": int(W.shape[1])}
    rom = reduced_model(reference, red, V if keep_basis else None, full, info)
    if indicator:
        t5 = time.perf_counter()
        rom.indicator = _calibrated_indicator(full, V, rom, training, dt_s, Y_ref)
        timings["indicator"] = time.perf_counter() - t5
    timings["build_total_excluding_fem"] = time.perf_counter() - t0 - timings.get("fem_training", 0)
    # CPU time of this process (the machine may be shared: wall time then overstates it)
    timings["build_cpu_excluding_fem"] = time.process_time() - c0 - timings.get(
        "fem_training_cpu", 0)
    report = BuildReport(training.name, dt_s, int(W.shape[1]), tried, errors, chosen, tol_temp_K,
                         tol_growth_um, safety, timings, [float(s) for s in speeds_rpm], list(shifts))
    return rom, report


def _calibrated_indicator(full: FullSystem, V: np.ndarray, rom: ReducedModel,
                          training: LoadCase, dt_s: float, Y_ref: np.ndarray):
    """The residual indicator (rom.indicator) of basis V, its sensor calibration the ratio of
    the true worst sensor error on the training cycle to its bound there."""
    from reference.rom.indicator import residual_indicator

    ind = residual_indicator(full, V)
    z0 = rom.initial(start_temperature_K(training))  # where Y_ref starts (fem_transient)
    grid, Z = rom.system.simulate(rom.inputs, training, dt_s, z0, "be")
    true = output_errors(full, rom.outputs(Z), Y_ref)["temperature_max_K"]
    ind.calibration_K = true / max(float(ind.bound(rom, training, grid, Z).max()), 1e-300)
    return ind


def _response_columns(cand, full: FullSystem, training: LoadCase, dt_s: float,
                      speeds_rpm: Sequence[float], shifts: Sequence[float]) -> np.ndarray:
    """Reduced responses (K_r(n) + s I)^-1 B_r(n) to each input at each basis speed n and
    shift s (s = 0: the steady response; s > 0: about the step response at t = 1/s), scaled
    to the input's swing on the training cycle (at least 100 W for a source, 1 K for a
    temperature), so that inputs and time scales the training cycle barely excites still
    get their directions."""
    grid = time_grid(training, dt_s)
    U = full.inputs(training, grid)
    swing = U.max(axis=0) - U.min(axis=0)
    m = len(full.source_names)
    swing[:m] = np.maximum(swing[:m], 100.0)
    swing[m:] = np.maximum(swing[m:], 1.0)
    cols = []
    eye = np.eye(cand.r)
    for n in speeds_rpm:
        K, B = cand.K(float(n)), cand.B(float(n))
        for s in shifts:
            cols.append(np.linalg.solve(K + s * eye, B * swing[None, :]))
    return np.hstack(cols)

