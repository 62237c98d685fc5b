"""Load cycles: a table of speed steps plus the ambient and coolant temperatures of a run.

A :class:`Cycle` is what a test bench runs (for example the paper's 16 h no-load bearing
run-in, Fig. 7) or a load point held to a steady state. It holds

* ``steps``: :class:`Step` rows of speed [rpm], duration [s], load torque [N m] and,
  optionally, the motor's electrical power [kW]; each step's values hold for its duration;
* ``T_ambient_K`` and ``T_coolant_K``: :class:`~spindle.loads.TimeSeries` in K.

:meth:`Cycle.to_load_case` turns it into the :class:`~spindle.loads.LoadCase` a solver
reads. Heat-source powers are not computed here (that is the power balance's job): they are
passed in as series.

Files (format: docs/cycles.md; read by :mod:`spindle.cycle_files`): a short TOML or a CSV
of steps. Temperatures are in degC in files (fields ending ``_C``) and in K in memory. The
ambient and coolant may be constant, a table, or one of two deterministic generators,
:func:`drifting_ambient` (a room that is not climate-controlled, paper Fig. 10) and
:func:`chiller_cycling` (a chiller's on/off hysteresis). :func:`random_cycle` draws a cycle
no spec ships (non-monotonic speed steps, optionally loaded or with ramped load), from a
seed: :func:`drawn_cycle` names them ``random``, ``random-loaded`` and
``random-ramped-load``. :func:`load_cycle` takes a shipped name or a file; every problem in
a file raises :class:`~spindle.errors.InputError` naming the file, the field (with the
step, row or line) and the fix.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Literal

import numpy as np

from spindle.errors import InputError
from spindle.loads import LoadCase, TimeSeries

if TYPE_CHECKING:  # only for the annotation: spec.py is not imported at run time
    from spindle.spec import Spec

#: 0 degC in K.
from spindle.units import (
    MAX_SERIES_POINTS,
    ZERO_C_K,
)

#: Temperatures accepted in cycle files [degC] (as spindle.loads.read_cycle_csv).
T_MIN_C, T_MAX_C = -60.0, 200.0
#: Ambient and coolant when a file gives none [degC].
DEFAULT_T_C = 20.0


class ParameterError(ValueError):
    """A generator parameter is out of its range; ``param`` is its name (as in the TOML)."""

    def __init__(self, param: str, message: str, fix: str):
        self.param, self.message, self.fix = param, message, fix
        super().__init__(f"{param}: {message}; fix: {fix}")


# --------------------------------------------------------------------------- steps and cycles


@dataclass(frozen=True)
class Step:
    """One plateau of a cycle: ``speed_rpm`` [1/min] held for ``duration_s`` [s] against a
    process ``load_torque_Nm`` [N m] (0: no load); ``power_kW`` is the motor's active
    electrical power [kW] from the drive when known (None: not given)."""

    speed_rpm: float
    duration_s: float
    load_torque_Nm: float = 0.0
    power_kW: float | None = None

    def __post_init__(self) -> None:
        values = {"speed_rpm": self.speed_rpm, "duration_s": self.duration_s,
                  "load_torque_Nm": self.load_torque_Nm}
        if self.power_kW is not None:
            values["power_kW"] = self.power_kW
        for key, v in values.items():
            if not math.isfinite(v) or v < 0:
                raise ValueError(f"Step.{key} must be a finite number >= 0, not {v!r}")
        if self.duration_s <= 0:
            raise ValueError(f"Step.duration_s must be > 0, not {self.duration_s!r}")


@dataclass(frozen=True)
class Cycle:
    """A load cycle: speed steps and the ambient and coolant temperatures [K] of one run.

    ``steady``: the cycle stands for a load point held until the temperatures stop changing
    (a steady solve evaluates it at t = 0); its duration is still used by a transient run.
    """

    name: str
    description: str
    source: str
    steps: tuple[Step, ...]
    T_ambient_K: TimeSeries
    T_coolant_K: TimeSeries
    steady: bool = False

    def __post_init__(self) -> None:
        object.__setattr__(self, "steps", tuple(self.steps))
        if not self.steps:
            raise ValueError("a Cycle needs at least one step")

    @property
    def duration_s(self) -> float:
        """Total duration [s]: the sum of the step durations."""
        return float(self.boundaries_s[-1])

    @property
    def boundaries_s(self) -> np.ndarray:
        """Start of every step and the end of the last, [s] (len(steps) + 1 values)."""
        return np.concatenate([[0.0], np.cumsum([s.duration_s for s in self.steps])])

    @property
    def max_speed_rpm(self) -> float:
        return float(max(s.speed_rpm for s in self.steps))

    def _steps_series(self, values: list[float]) -> TimeSeries:
        starts = tuple(float(t) for t in self.boundaries_s[:-1])
        return TimeSeries(starts, tuple(float(v) for v in values), "previous")

    @property
    def speed_rpm(self) -> TimeSeries:
        """Speed [rpm] as a step signal ("previous"): sample i at the start of step i."""
        return self._steps_series([s.speed_rpm for s in self.steps])

    @property
    def load_torque_Nm(self) -> TimeSeries:
        """Process load torque [N m] as a step signal."""
        return self._steps_series([s.load_torque_Nm for s in self.steps])

    @property
    def power_kW(self) -> TimeSeries | None:
        """Electrical motor power [kW] as a step signal; None unless every step gives it."""
        if any(s.power_kW is None for s in self.steps):
            return None
        return self._steps_series([float(s.power_kW) for s in self.steps])  # type: ignore[arg-type]

    def step_index(self, t_s: float) -> int:
        """Index of the step running at time ``t_s`` [s] (a boundary starts the next step;
        before 0 the first, after the end the last)."""
        i = int(np.searchsorted(self.boundaries_s, t_s, side="right")) - 1
        return min(max(i, 0), len(self.steps) - 1)

    def to_load_case(self, spec: Spec | None = None,
                     sources: Mapping[str, TimeSeries] | None = None,
                     *, others: Literal["spec", "zero"] = "spec") -> LoadCase:
        """The :class:`~spindle.loads.LoadCase` of this cycle: duration = :attr:`duration_s`,
        speed from the steps, ambient and coolant from the series.

        ``sources`` (heat-source name -> power series [W], from the power balance) is passed
        through. With a ``spec``, every name must be one of its heat sources, and the spec's
        sources not named keep their own (nominal) power (``others="spec"``, as LoadCase
        does) or get 0 W (``others="zero"``, for a run whose every loss is in ``sources``).
        """
        srcs = dict(sources or {})
        for key, series in srcs.items():
            if not isinstance(series, TimeSeries):
                raise TypeError(f"source '{key}' must be a TimeSeries, not {type(series).__name__}")
        if others not in ("spec", "zero"):
            raise ValueError(f"others must be 'spec' or 'zero', not {others!r}")
        if spec is not None:
            known = [h.name for h in spec.heat_sources]
            unknown = sorted(set(srcs) - set(known))
            if unknown:
                raise InputError(spec.path, f"heat_sources ({unknown[0]})",
                                 f"cycle '{self.name}' gives a power for a heat source the spec "
                                 "does not have", f"use one of {known}")
            if others == "zero":
                srcs = {**{k: TimeSeries.constant(0.0) for k in known}, **srcs}
        elif others == "zero":
            raise ValueError("others='zero' needs the spec (to know its heat sources)")
        return LoadCase(name=self.name, speed_rpm=self.speed_rpm, T_ambient_K=self.T_ambient_K,
                        T_coolant_K=self.T_coolant_K, sources=srcs, duration_s=self.duration_s)


# --------------------------------------------------------------------------- generators


def _check_number(param: str, value: float, lo: float | None = None, hi: float | None = None,
                  strict_lo: bool = False, unit: str = "") -> float:
    v = float(value)
    if not math.isfinite(v):
        raise ParameterError(param, "is not finite", "give a finite number")
    if lo is not None and (v < lo or (strict_lo and v == lo)):
        rel = ">" if strict_lo else ">="
        raise ParameterError(param, f"must be {rel} {lo:g} {unit}".rstrip(), f"give {param} {rel} {lo:g}")
    if hi is not None and v > hi:
        raise ParameterError(param, f"must be <= {hi:g} {unit}".rstrip(), f"give {param} <= {hi:g}")
    return v


def _check_points(param: str, points: float, smallest: float) -> None:
    """A generated series of ``points`` samples is refused beyond MAX_SERIES_POINTS, naming
    ``param`` and its ``smallest`` allowed value [s]."""
    if points > MAX_SERIES_POINTS:
        raise ParameterError(param, f"gives {points:.3g} samples, more than "
                             f"{MAX_SERIES_POINTS:.0e}", f"give {param} >= {smallest:.3g} s")


def _check_temperature(param: str, value: float) -> float:
    v = _check_number(param, value)
    if not T_MIN_C <= v <= T_MAX_C:
        raise ParameterError(param, f"{v:g} degC is outside {T_MIN_C:g}..{T_MAX_C:g} degC",
                             "give the temperature in degrees Celsius")
    return v


def _half_cosine(x: np.ndarray) -> np.ndarray:
    """0 at x = 0, 1 at x = 1, zero slope at both ends: (1 - cos(pi x)) / 2."""
    return 0.5 * (1.0 - np.cos(np.pi * np.clip(x, 0.0, 1.0)))


def drifting_ambient(duration_s: float, *, T_start_C: float = 19.5, T_peak_C: float = 22.5,
                     t_peak_h: float = 9.0, T_end_C: float | None = None,
                     sample_s: float = 900.0) -> TimeSeries:
    """Air temperature of a room that is not climate-controlled (paper Fig. 10) [K].

    A smooth day profile: from ``T_start_C`` at t = 0 to ``T_peak_C`` at ``t_peak_h``, then
    to ``T_end_C`` (default: stays at the peak) at ``duration_s``, each leg a half cosine
    (zero slope at the start, the peak and the end)::

        T(t) = T_start + (T_peak - T_start) (1 - cos(pi t / t_peak)) / 2,   t <= t_peak
        T(t) = T_peak + (T_end - T_peak) (1 - cos(pi (t - t_peak) / (D - t_peak))) / 2

    with D = ``duration_s``. Sampled every ``sample_s`` [s] from 0 to D, plus t_peak and D,
    and interpolated linearly (error below A (pi dt)^2 / (16 t_leg^2): 1.4 mK for 3 K over
    9 h at 15 min). If t_peak >= D only the rise is used (up to D).
    """
    D = _check_number("duration_s", duration_s, lo=0.0, strict_lo=True, unit="s")
    T0 = _check_temperature("T_start_C", T_start_C)
    Tp = _check_temperature("T_peak_C", T_peak_C)
    Te = Tp if T_end_C is None else _check_temperature("T_end_C", T_end_C)
    tp = _check_number("t_peak_h", t_peak_h, lo=0.0, strict_lo=True, unit="h") * 3600.0
    dt = _check_number("sample_s", sample_s, lo=0.0, strict_lo=True, unit="s")
    _check_points("sample_s", D / dt, D / MAX_SERIES_POINTS)
    t = np.unique(np.concatenate([np.arange(0.0, D, dt), [min(tp, D), D]]))
    rise = T0 + (Tp - T0) * _half_cosine(t / tp)
    if tp < D:
        fall = Tp + (Te - Tp) * _half_cosine((t - tp) / (D - tp))
        T = np.where(t <= tp, rise, fall)
    else:
        T = rise
    return TimeSeries(tuple(t.tolist()), tuple((T + ZERO_C_K).tolist()), "linear")


def chiller_cycling(duration_s: float, *, setpoint_C: float = 20.0, band_K: float = 0.5,
                    period_s: float = 1200.0, rise_fraction: float = 0.5) -> TimeSeries:
    """Coolant supply of an on/off chiller with a hysteresis of +-``band_K`` [K].

    The water warms linearly from ``setpoint_C - band_K`` to ``setpoint_C + band_K`` while
    the compressor is off (``rise_fraction`` of ``period_s``), then cools linearly back
    (the rest of the period): a triangle wave (a sawtooth as rise_fraction -> 0 or 1) with
    mean ``setpoint_C`` over a period. It starts at the set point, warming: with
    r = rise_fraction, P = period_s and s = (t / P + r / 2) mod 1 (the phase from the last
    minimum),

        T(t) = setpoint - band + 2 band s / r,                 s < r
        T(t) = setpoint + band - 2 band (s - r) / (1 - r),     s >= r

    so the maxima are at t = (k + r/2) P and the minima at t = (k + 1 - r/2) P. The series
    holds t = 0, every extremum before ``duration_s`` and ``duration_s``: linear
    interpolation reproduces the wave exactly.
    """
    D = _check_number("duration_s", duration_s, lo=0.0, strict_lo=True, unit="s")
    Ts = _check_temperature("setpoint_C", setpoint_C)
    b = _check_number("band_K", band_K, lo=0.0, unit="K")
    P = _check_number("period_s", period_s, lo=0.0, strict_lo=True, unit="s")
    _check_points("period_s", 2.0 * D / P, 2.0 * D / MAX_SERIES_POINTS)
    r = float(rise_fraction)
    if not (math.isfinite(r) and 0.0 < r < 1.0):
        raise ParameterError("rise_fraction", f"must be strictly between 0 and 1, not {r:g}",
                             "give 0.5 for a symmetric triangle")
    for name, v in (("setpoint_C - band_K", Ts - b), ("setpoint_C + band_K", Ts + b)):
        if not T_MIN_C <= v <= T_MAX_C:
            raise ParameterError("band_K", f"{name} = {v:g} degC is outside "
                                 f"{T_MIN_C:g}..{T_MAX_C:g} degC", "give a smaller band_K")
    k = np.arange(0, math.ceil(D / P) + 1)
    extrema = np.concatenate([(k + r / 2) * P, (k + 1 - r / 2) * P])
    t = np.unique(np.concatenate([[0.0, D], extrema[extrema < D]]))
    s = np.mod(t / P + r / 2, 1.0)
    T = np.where(s < r, Ts - b + 2 * b * s / r, Ts + b - 2 * b * (s - r) / (1 - r))
    return TimeSeries(tuple(t.tolist()), tuple((T + ZERO_C_K).tolist()), "linear")


#: Generators a cycle file can name in [ambient] or [coolant] with ``model = "..."``.
GENERATORS: dict[str, Callable[..., TimeSeries]] = {
    "drift": drifting_ambient,
    "chiller": chiller_cycling,
}
GENERATOR_KEYS = {
    "drift": ("T_start_C", "T_peak_C", "t_peak_h", "T_end_C", "sample_s"),
    "chiller": ("setpoint_C", "band_K", "period_s", "rise_fraction"),
}


# --------------------------------------------------------------------------- drawn cycles

#: cycles drawn from a seed (:func:`drawn_cycle`) rather than loaded
RANDOM_CYCLES = ("random", "random-loaded", "random-ramped-load")
#: the top speed of a drawn cycle [rpm]: the SPL2782 family's bench runs go to 6000 rpm
#: (a peer's runs in tests/data/peer-runs/bench-runs), above the spl-16h cycle's rated 4300 rpm
RANDOM_MAX_SPEED_RPM = 6000.0


def ramped_steps(speed_rpm: float, duration_s: float, low_Nm: float, high_Nm: float,
                 step_s: float = 300.0) -> list[Step]:
    """One speed step of ``duration_s`` [s] cut into ``step_s`` pieces (the last takes the
    remainder, so the pieces keep a time step's grid: a FEM run factorises once per step
    length) whose process torque [N m] rises linearly from ``low_Nm`` to ``high_Nm`` over the
    first half and falls back over the second (rounded to 0.1 N m)."""
    k = max(int(duration_s // step_s), 2)
    edges = np.concatenate([np.arange(k) * (duration_s / k if duration_s < 2 * step_s
                                            else step_s), [duration_s]])
    mid = 0.5 * (edges[:-1] + edges[1:]) / duration_s
    shape = 1.0 - np.abs(2.0 * mid - 1.0)
    return [Step(speed_rpm, float(b - a), round(low_Nm + (high_Nm - low_Nm) * float(f), 1))
            for a, b, f in zip(edges[:-1], edges[1:], shape, strict=True)]


def random_cycle(rng: np.random.Generator, max_speed_rpm: float, loaded: bool = False,
                 duration_h: float = 16.0, ramped: bool = False) -> Cycle:
    """A 16 h cycle the spec does not have: a standstill start, speed steps of 45-120 min in a
    random (non-monotonic) order over 15-100 % of ``max_speed_rpm`` [rpm], rounded to
    100 rpm, the top speed among them, and a 2 h cool-down; loaded runs hold a process torque
    of 0-40 N m per step. ``ramped`` (a loaded run as a bench logs one, e.g. a peer's
    tests/data/peer-runs/bench-runs/dev-08): within each speed step the torque ramps from a low level of
    5-20 N m up to 10-25 N m above it and back, in 5 min steps (:func:`ramped_steps`). Ambient
    drift and chiller cycling as the shipped cycles."""
    total = duration_h * 3600.0
    cool = 7200.0
    steps = [Step(0.0, 900.0)]
    plateau_of = [-1]  # the speed plateau (index into speeds) of each step
    t = 900.0
    speeds = []
    while t < total - cool - 1800.0:
        dur = min(float(rng.uniform(45, 120)) * 60.0, total - cool - t)
        n = round(float(rng.uniform(0.15, 1.0)) * max_speed_rpm / 100.0) * 100.0
        speeds.append(n)
        torque = round(float(rng.uniform(0.0, 40.0)), 1) if loaded else 0.0
        if ramped:  # whole minutes, so that the 5 min pieces keep the 60 s grid
            dur = 60.0 * round(dur / 60.0)
            low = float(rng.uniform(5.0, 20.0))
            pieces = ramped_steps(n, dur, low, low + float(rng.uniform(10.0, 25.0)))
        else:
            pieces = [Step(n, dur, torque)]
        steps.extend(pieces)
        plateau_of.extend([len(speeds) - 1] * len(pieces))
        t += dur
    if max_speed_rpm not in speeds:  # the top speed at least once, somewhere in the middle
        middle = (1 + len(speeds)) // 2  # that plateau's steps, all of them when ramped
        steps = [replace(s, speed_rpm=float(max_speed_rpm)) if plateau == middle else s
                 for s, plateau in zip(steps, plateau_of, strict=True)]
    steps.append(Step(0.0, total - t))
    name = "random-ramped-load" if ramped else f"random{'-loaded' if loaded else ''}"
    return Cycle(name=name,
                 description="random non-monotonic speed steps (spindle.cycles.random_cycle)",
                 source="generated", steps=tuple(steps),
                 T_ambient_K=drifting_ambient(total), T_coolant_K=chiller_cycling(total))


def drawn_cycle(name: str, seed: int) -> Cycle:
    """The cycle ``name`` (one of :data:`RANDOM_CYCLES`) drawn from ``seed``, top speed
    :data:`RANDOM_MAX_SPEED_RPM`: the one ``spindle-verify synth`` and the ROM study use for
    the same name and seed (its random stream is ``[seed, 2]``, apart from the streams a
    synthetic run draws its effect and mismatch from)."""
    if name not in RANDOM_CYCLES:
        raise ValueError(f"a drawn cycle is one of {RANDOM_CYCLES}, not {name!r}")
    return random_cycle(np.random.default_rng([seed, 2]), RANDOM_MAX_SPEED_RPM,
                        loaded=name == "random-loaded", ramped=name == "random-ramped-load")
