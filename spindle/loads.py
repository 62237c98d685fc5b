"""Time series and load cases: what drives a solve (speed, heat sources, ambient, coolant).

A :class:`LoadCase` holds, for one run, the spindle speed [rpm], the ambient and coolant
temperatures [K] and the power of each named heat source [W], each as a time series.
A steady solve evaluates them at one instant; a transient solve follows them.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import numpy as np

from spindle.commented_csv import CommentedCsv, split_commented_csv
from spindle.errors import InputError
from spindle.units import CYCLE_MAX_S, MAX_SERIES_POINTS, POWER_MAX_KW, SPEED_MAX_RPM, ZERO_C_K

Interpolation = Literal["linear", "previous"]


@dataclass(frozen=True)
class TimeSeries:
    """A scalar signal of time: samples ``values`` at ``time_s`` [s].

    ``linear`` interpolates between samples; ``previous`` holds each value until the next
    sample (a step signal, as spindle speeds in a test cycle are). Outside the samples the
    first or last value is held. A single sample is a constant.
    """

    time_s: tuple[float, ...]
    values: tuple[float, ...]
    interpolation: Interpolation = "linear"

    def __post_init__(self) -> None:
        if len(self.time_s) != len(self.values) or not self.values:
            raise ValueError("TimeSeries needs as many times as values, at least one")
        try:
            finite = bool(np.isfinite(np.asarray((*self.time_s, *self.values), dtype=float)).all())
        except (TypeError, ValueError):
            raise TypeError("TimeSeries times [s] and values must be numbers") from None
        if not finite:  # a NaN compares false with everything: it ran to NaN results
            raise ValueError("TimeSeries times [s] and values must be finite numbers")
        if any(b <= a for a, b in zip(self.time_s, self.time_s[1:], strict=False)):
            raise ValueError("TimeSeries times must increase strictly")
        if self.interpolation not in ("linear", "previous"):
            raise ValueError(f"unknown interpolation {self.interpolation!r}")

    @classmethod
    def constant(cls, value: float) -> TimeSeries:
        return cls((0.0,), (float(value),))

    @property
    def is_constant(self) -> bool:
        return len(set(self.values)) <= 1

    def __call__(self, t: float | np.ndarray) -> float | np.ndarray:
        times = np.asarray(self.time_s)
        vals = np.asarray(self.values)
        if len(vals) == 1:
            return np.full_like(np.asarray(t, dtype=float), vals[0])[()]
        if self.interpolation == "previous":
            idx = np.searchsorted(times, t, side="right") - 1
            return vals[np.clip(idx, 0, len(vals) - 1)][()]
        return np.interp(t, times, vals)[()]

    def breakpoints(self) -> np.ndarray:
        """The sample times [s]: a time stepper should land on them."""
        return np.asarray(self.time_s) if len(self.values) > 1 else np.zeros(0)


@dataclass(frozen=True)
class SpeedTable:
    """A coefficient that depends on spindle speed, linear between table points.

    ``speed_rpm`` ascending; a single point is a constant. Units are those of the field
    the table stands for (W/m2/K for film coefficients, W/K for conductances).
    """

    speed_rpm: tuple[float, ...]
    values: tuple[float, ...]

    @classmethod
    def constant(cls, value: float) -> SpeedTable:
        return cls((0.0,), (float(value),))

    def __call__(self, speed_rpm: float) -> float:
        if len(self.values) == 1:
            return float(self.values[0])
        return float(np.interp(speed_rpm, self.speed_rpm, self.values))

    def scaled(self, factor: float) -> SpeedTable:
        """The same table with every value multiplied by ``factor``."""
        return SpeedTable(self.speed_rpm, tuple(v * factor for v in self.values))

    @property
    def max(self) -> float:
        return float(max(self.values))

    @property
    def min(self) -> float:
        return float(min(self.values))


@dataclass(frozen=True)
class LoadCase:
    """Inputs of one run. Temperatures in K, speed in rpm, source powers in W.

    ``sources`` maps each heat source of the spec by name to its power series; sources not
    named keep the spec's own value. ``duration_s`` is the length of a transient run.
    """

    name: str
    speed_rpm: TimeSeries
    T_ambient_K: TimeSeries
    T_coolant_K: TimeSeries
    sources: Mapping[str, TimeSeries] = field(default_factory=dict)
    duration_s: float = 0.0
    #: further times [s] every transient of this case lands on (with_jump_ladder)
    extra_times_s: tuple[float, ...] = ()

    def __post_init__(self) -> None:
        # a number where a TimeSeries belongs failed only at solve time ("'float' object is
        # not callable"): say which input, here
        for name in ("speed_rpm", "T_ambient_K", "T_coolant_K"):
            if not isinstance(getattr(self, name), TimeSeries):
                raise TypeError(f"LoadCase {name} must be a TimeSeries (TimeSeries.constant(x) "
                                f"for a constant), not {type(getattr(self, name)).__name__}")
        bad = next((k for k, v in dict(self.sources).items() if not isinstance(v, TimeSeries)),
                   None)
        if bad is not None:
            raise TypeError(f"LoadCase sources['{bad}'] must be a TimeSeries of W, not "
                            f"{type(self.sources[bad]).__name__}")
        if not (isinstance(self.duration_s, int | float) and math.isfinite(self.duration_s)
                and self.duration_s >= 0):
            raise ValueError(f"LoadCase duration_s must be a finite number >= 0 s, not "
                             f"{self.duration_s!r}")

    def breakpoints(self) -> np.ndarray:
        """All sample times of all inputs [s] and the extra times, sorted and unique."""
        series = [self.speed_rpm, self.T_ambient_K, self.T_coolant_K, *self.sources.values()]
        pts = np.concatenate([s.breakpoints() for s in series]
                             + [np.zeros(1), np.asarray(self.extra_times_s, dtype=float)])
        return np.unique(pts[(pts >= 0) & (pts <= self.duration_s)])

    def jumps(self) -> np.ndarray:
        """Times [s] where the speed or a heat source may step: their samples."""
        series = [self.speed_rpm, *self.sources.values()]
        pts = np.concatenate([s.breakpoints() for s in series] + [np.zeros(1)])
        return np.unique(pts[(pts >= 0) & (pts < self.duration_s)])

    def with_jump_ladder(self, first_s: float = 1.0, last_s: float = 64.0) -> LoadCase:
        """This case with output times first_s, 2 first_s, 4 first_s, ... up to last_s [s]
        after every jump (issue 15 §1): the response to a step in heat is steepest just after
        it, and a comparison sampled only every dt misses its peak error, so that the
        verdicts would depend on dt. The ladder is the same for every dt."""
        steps = first_s * 2.0 ** np.arange(int(np.floor(np.log2(last_s / first_s))) + 1)
        pts = (self.jumps()[:, None] + steps[None, :]).ravel()
        return replace(self, extra_times_s=tuple(sorted(set(self.extra_times_s)
                                                        | set(pts.tolist()))))

    def with_sources(self, sources: Mapping[str, TimeSeries]) -> LoadCase:
        return replace(self, sources={**self.sources, **sources})


def start_temperature_K(case: LoadCase, T0: float | None = None) -> float:
    """The uniform temperature [K] a transient of ``case`` starts from: ``T0``, or by default
    the case's ambient at t = 0 (a spindle at rest in its room). Every model starts there,
    and their growth read-outs are zeroed there."""
    if T0 is None:
        return float(case.T_ambient_K(0.0))
    check_start_temperature(T0)
    return float(T0)


def check_start_temperature(T0) -> None:
    """ValueError unless ``T0`` [K] (a number, or one per mass or node) is finite and above
    0 K: a NaN ran to the end and wrote empty cells, a negative one solved."""
    try:
        x = np.asarray(T0, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(f"T0 must be a temperature in K (or one per mass or node), not "
                        f"{type(T0).__name__}") from None
    if not (np.isfinite(x).all() and (x > 0).all()):
        raise ValueError("T0 must be finite temperatures above 0 K (kelvin, not °C)")


def time_grid(case: LoadCase, dt_s: float) -> np.ndarray:
    """Output times of a transient run [s]: every dt_s, plus every sample time of the
    inputs, so that steps land on the inputs' corners (both models use the same grid). More
    than MAX_SERIES_POINTS steps is refused (:func:`check_time_step`) before anything is
    allocated."""
    check_time_step(case, dt_s)
    grid = np.unique(np.concatenate([np.arange(0.0, case.duration_s, dt_s),
                                     case.breakpoints(), [case.duration_s]]))
    return grid[np.concatenate([[True], np.diff(grid) > 1e-9 * dt_s])]


def time_step_s(dt_s) -> float:
    """``dt_s`` [s] as a float; TypeError naming it where it is no number (a '60' failed as
    "'<=' not supported between instances of 'str' and 'int'")."""
    if isinstance(dt_s, bool) or not isinstance(dt_s, int | float | np.integer | np.floating):
        raise TypeError(f"dt_s must be a time step in s (a number), not {type(dt_s).__name__}")
    return float(dt_s)


def check_time_step(case: LoadCase, dt_s: float) -> None:
    """InputError naming --dt where dt_s [s] is not positive or gives ``case`` more than
    MAX_SERIES_POINTS time steps (a command asks this before its work)."""
    dt_s = time_step_s(dt_s)
    if not (math.isfinite(dt_s) and dt_s > 0):
        raise InputError("command line", "--dt", f"{dt_s:g} s is not a positive time step",
                         "give a time step > 0 s, e.g. 60")
    steps = case.duration_s / dt_s + len(case.breakpoints())
    if steps > MAX_SERIES_POINTS:
        raise InputError("command line", "--dt", f"{dt_s:g} s over {case.duration_s / 3600:.4g} h "
                         f"is {steps:.3g} time steps, more than {MAX_SERIES_POINTS:.0e}",
                         f"give --dt >= {case.duration_s / MAX_SERIES_POINTS:.3g} s")


_KNOWN_CYCLE_COLUMNS = {"time_s", "speed_rpm", "T_env_C", "T_coolant_C"}


#: the largest heat a cycle CSV may give one source [W]: a bench's power limit
SOURCE_MAX_W = POWER_MAX_KW * 1e3


def read_cycle_csv(path: str | Path, source_names: list[str], base: LoadCase) -> LoadCase:
    """Read a transient load cycle from CSV (comment lines start with ``#``).

    Columns: ``time_s`` (required, strictly increasing), and any of ``speed_rpm`` (held
    between samples), ``T_env_C`` and ``T_coolant_C`` (linear), and ``<source>_W`` for each
    heat source of the spec (linear). Columns not given keep the values of ``base``.
    """
    path = Path(path)
    name = str(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except OSError as exc:
        raise InputError(name, "file", f"cannot be read ({exc.strerror})",
                         "check the path given to --cycle") from None
    except UnicodeDecodeError as exc:
        raise InputError(name, "file", f"is not UTF-8 text (byte {exc.start})",
                         "export the cycle as a UTF-8 (or ASCII) CSV file") from None
    table = split_commented_csv(text)
    if not table.line_no:
        raise InputError(name, "header", "the file has no header row",
                         "add a header such as 'time_s,speed_rpm,T_env_C'")
    line_no = table.line_no  # file line of each row, comments counted
    _check_cycle_header(name, table.header, source_names)
    data = _read_cycle_columns(name, table)
    times = _cycle_times(name, data["time_s"], line_no)

    def series(col: str, offset: float = 0.0, interp: Interpolation = "linear") -> TimeSeries:
        return TimeSeries(times, tuple(v + offset for v in data[col]), interp)

    if times[-1] > CYCLE_MAX_S:
        raise InputError(name, f"time_s (line {line_no[-1]})", f"the run lasts "
                         f"{times[-1] / 3600:.4g} h, more than {CYCLE_MAX_S / 3600:g} h",
                         "give time_s in seconds since the start")
    case = replace(base, name=path.stem, duration_s=times[-1])
    if "speed_rpm" in data:
        if min(data["speed_rpm"]) < 0:
            raise InputError(name, "speed_rpm", "is negative", "give the speed as |n| [rpm]")
        if max(data["speed_rpm"]) > SPEED_MAX_RPM:
            k = int(np.argmax(np.asarray(data["speed_rpm"]) > SPEED_MAX_RPM))
            raise InputError(name, f"speed_rpm (line {line_no[k + 1]})",
                             f"{data['speed_rpm'][k]:g} rpm is above {SPEED_MAX_RPM:g} rpm, "
                             "faster than any motor spindle", "give the speed in rpm (1/min)")
        case = replace(case, speed_rpm=series("speed_rpm", interp="previous"))
    for col, attr in (("T_env_C", "T_ambient_K"), ("T_coolant_C", "T_coolant_K")):
        if col in data:
            out = [k for k, v in enumerate(data[col]) if not -60 <= v <= 200]
            if out:
                raise InputError(name, f"{col} (line {line_no[out[0] + 1]})",
                                 f"{data[col][out[0]]:g} is outside -60..200 degC",
                                 "give temperatures in degrees Celsius (not kelvin)")
            case = replace(case, **{attr: series(col, ZERO_C_K)})
    for col in (f"{s}_W" for s in source_names if f"{s}_W" in data):
        # a loss is heat into the spindle: >= 0, and below the 1000 kW a bench logs at most
        out = [k for k, v in enumerate(data[col]) if not 0.0 <= v <= SOURCE_MAX_W]
        if out:
            raise InputError(name, f"{col} (line {line_no[out[0] + 1]})",
                             f"{data[col][out[0]]:g} W is outside 0..{SOURCE_MAX_W:g} W",
                             "give the heat the source puts into the spindle, in W (a loss is "
                             "never negative)")
    sources = {s: series(f"{s}_W") for s in source_names if f"{s}_W" in data}
    kept = [s for s in source_names if s not in sources]
    if sources and kept:  # some heat follows the file, some stays constant: say which
        import warnings

        from spindle.errors import CycleWarning

        warnings.warn(CycleWarning(
            f"{name}: no column {', '.join(f'{s}_W' for s in kept)}: "
            f"{'that source keeps' if len(kept) == 1 else 'those sources keep'} the spec's "
            "constant power throughout, at standstill too (fix: add the column, with 0 where "
            "the source is off)"), stacklevel=2)
    return case.with_sources(sources)


def _check_cycle_header(name: str, header: list[str], source_names: list[str]) -> None:
    """time_s is required; every column is a known one or ``<source>_W``."""
    for k, h in enumerate(header):
        if not h.strip():
            raise InputError(name, f"header (column {k + 1})", "has an empty column name",
                             "name every column, and end the rows without a trailing comma")
        if h in header[:k]:
            raise InputError(name, f"header (column {k + 1})", f"'{h}' appears twice",
                             "keep one column of each name")
    if "time_s" not in header:
        raise InputError(name, "time_s", "required column is missing",
                         "add a 'time_s' column with the time since the start [s]")
    allowed = _KNOWN_CYCLE_COLUMNS | {f"{s}_W" for s in source_names}
    unknown = [h for h in header if h not in allowed]
    if unknown:
        raise InputError(name, unknown[0], "is not a cycle column",
                         f"use one of {sorted(allowed)}")


def _read_cycle_columns(name: str, table: CommentedCsv) -> dict[str, list[float]]:
    """The values of each column, by name: a finite number in every cell."""
    header = table.header
    data: dict[str, list[float]] = {h: [] for h in header}
    for k, row in enumerate(table.rows[1:], start=1):
        lineno = table.line_no[k]
        if len(row) != len(header):
            raise InputError(name, f"line {lineno}", f"has {len(row)} cells, header has "
                             f"{len(header)}", "give every row one cell per column")
        for h, cell in zip(header, row, strict=True):
            try:
                v = float(cell)
            except ValueError:
                raise InputError(name, f"{h} (line {lineno})", f"'{cell}' is not a number",
                                 "write a decimal number with '.' as the separator") from None
            if not np.isfinite(v):
                raise InputError(name, f"{h} (line {lineno})", "is not finite",
                                 "write a finite number")
            data[h].append(v)
    return data


def _cycle_times(name: str, time_s: list[float], line_no: list[int]) -> tuple[float, ...]:
    """The times [s] from the first row (at least two rows, >= 0, strictly increasing)."""
    t = np.asarray(time_s)
    if len(t) < 2:
        raise InputError(name, "time_s", "a cycle needs at least two rows",
                         "add rows up to the end time of the run")
    bad = np.nonzero(np.diff(t) <= 0)[0]
    if len(bad):
        raise InputError(name, f"time_s (line {line_no[bad[0] + 2]})", "time does not increase",
                         "sort the rows by time and remove duplicates")
    if t[0] < 0:
        raise InputError(name, f"time_s (line {line_no[1]})", "is negative",
                         "start the cycle at 0 s")
    return tuple(float(x) for x in t - t[0])
