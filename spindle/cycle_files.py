"""Cycle files (format: docs/cycles.md): :func:`load_cycle` takes a shipped cycle's name or a
file, read by the TOML reader (:func:`read_cycle_toml`) or the CSV step table
(:func:`read_cycle_steps_csv`), and checks its limits (:func:`check_cycle_limits`).

Temperatures are in degC in files (fields ending ``_C``) and in K in memory. Every problem
in a file raises :class:`~spindle.errors.InputError` naming the file, the field (with the
step, row or line) and the fix.
"""

from __future__ import annotations

import math
import tomllib
from collections.abc import Mapping
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from spindle.commented_csv import split_commented_csv
from spindle.cycles import (
    DEFAULT_T_C,
    GENERATOR_KEYS,
    GENERATORS,
    T_MAX_C,
    T_MIN_C,
    Cycle,
    ParameterError,
    Step,
)
from spindle.errors import InputError
from spindle.loads import TimeSeries
from spindle.units import CYCLE_MAX_S, POWER_MAX_KW, SPEED_MAX_RPM, TORQUE_MAX_NM, ZERO_C_K

# --------------------------------------------------------------------------- TOML reader


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool)


class _File:
    """Error helpers bound to one file. They raise at the first problem, where
    spindle.spec's reader collects every problem of a spec; the two word their messages
    differently (the tests check the words), so they stay apart."""

    def __init__(self, path: Path):
        self.name = str(path)

    def error(self, fld: str, message: str, fix: str) -> InputError:
        return InputError(self.name, fld, message, fix)

    def number(self, d: Mapping[str, Any], key: str, where: str, *, required: bool = True,
               default: float | None = None, lo: float | None = None,
               strict_lo: bool = False, unit: str = "") -> float | None:
        fld = f"{where}.{key}" if where else key
        if key not in d:
            if required:
                raise self.error(fld, "required field is missing", f"add {key} = <number> [{unit}]")
            return default
        v = d[key]
        if not _is_number(v):
            raise self.error(fld, f"{v!r} is not a number", f"write {key} = <number> [{unit}]")
        v = float(v)
        if not math.isfinite(v):
            raise self.error(fld, "is not finite", "write a finite number")
        if lo is not None and (v < lo or (strict_lo and v == lo)):
            word = "negative" if v < 0 else "zero" if v == 0 else f"below {lo:g}"
            rel = ">" if strict_lo else ">="
            raise self.error(fld, f"{v:g} is {word}", f"give {key} {rel} {lo:g} {unit}".rstrip())
        return v

    def temperature(self, v: Any, fld: str) -> float:
        if not _is_number(v) or not math.isfinite(v):
            raise self.error(fld, f"{v!r} is not a number", "write the temperature in degC")
        if not T_MIN_C <= v <= T_MAX_C:
            raise self.error(fld, f"{v:g} degC is outside {T_MIN_C:g}..{T_MAX_C:g} degC",
                             "give temperatures in degrees Celsius")
        return float(v)

    def unknown_keys(self, d: Mapping[str, Any], allowed: tuple[str, ...], where: str) -> None:
        extra = [k for k in d if k not in allowed]
        if extra:
            fld = f"{where}.{extra[0]}" if where else extra[0]
            raise self.error(fld, "is not a field here", f"use one of {list(allowed)}")


_STEP_KEYS = ("speed_rpm", "duration_s", "duration_h", "load_torque_Nm", "power_kW")


def _read_step(f: _File, d: Any, where: str) -> Step:
    if not isinstance(d, dict):
        raise f.error(where, "is not a table", "write each step as { speed_rpm = ..., duration_h = ... }")
    f.unknown_keys(d, _STEP_KEYS, where)
    speed = f.number(d, "speed_rpm", where, lo=0.0, unit="rpm")
    if ("duration_s" in d) == ("duration_h" in d):
        raise f.error(f"{where}.duration_s", "give exactly one of duration_s and duration_h",
                      "write duration_s = <seconds> or duration_h = <hours>")
    if "duration_s" in d:
        dur = f.number(d, "duration_s", where, lo=0.0, strict_lo=True, unit="s")
    else:
        dur = f.number(d, "duration_h", where, lo=0.0, strict_lo=True, unit="h") * 3600.0
    torque = f.number(d, "load_torque_Nm", where, required=False, default=0.0, lo=0.0, unit="N m")
    power = f.number(d, "power_kW", where, required=False, lo=0.0, unit="kW")
    return Step(speed, dur, torque, power)  # type: ignore[arg-type]


def _read_temperature(f: _File, data: Mapping[str, Any], key: str, duration_s: float,
                      default: TimeSeries) -> TimeSeries:
    """[ambient] or [coolant]: constant, table or generator; in degC, returned in K."""
    d = data.get(key)
    if d is None:
        return default
    if not isinstance(d, dict):
        raise f.error(key, "is not a table", f"write a [{key}] table with T_C = 20.0")
    model = d.get("model")
    if model is None:
        model = "table" if isinstance(d.get("T_C"), list) else "constant"
    models = ("constant", "table", *GENERATORS)
    if model not in models:
        raise f.error(f"{key}.model", f"unknown model {model!r}", f"use one of {list(models)}")
    if model == "constant":
        f.unknown_keys(d, ("model", "T_C"), key)
        if "T_C" not in d:
            raise f.error(f"{key}.T_C", "required field is missing", "add T_C = <degC>")
        return TimeSeries.constant(f.temperature(d["T_C"], f"{key}.T_C") + ZERO_C_K)
    if model == "table":
        return _read_temperature_table(f, d, key)
    return _generated_temperature(f, d, key, model, duration_s)


def _read_temperature_table(f: _File, d: dict[str, Any], key: str) -> TimeSeries:
    """A table of T_C against time_s or time_h (increasing), linear between entries [K]."""
    f.unknown_keys(d, ("model", "T_C", "time_s", "time_h"), key)
    if ("time_s" in d) == ("time_h" in d):
        raise f.error(f"{key}.time_h", "a table needs exactly one of time_s and time_h",
                      "write time_h = [0, 8, 16] and T_C = [20, 22, 21]")
    tkey = "time_s" if "time_s" in d else "time_h"
    times, temps = d[tkey], d.get("T_C")
    if not isinstance(times, list) or not times:
        raise f.error(f"{key}.{tkey}", "is not a non-empty list", f"write {tkey} = [0, ...]")
    if not isinstance(temps, list) or len(temps) != len(times):
        raise f.error(f"{key}.T_C", f"needs a list of {len(times)} values (one per {tkey})",
                      f"give one T_C value per {tkey} entry")
    scale = 1.0 if tkey == "time_s" else 3600.0
    t = []
    for i, v in enumerate(times):
        if not _is_number(v) or not math.isfinite(v):
            raise f.error(f"{key}.{tkey}[{i}]", f"{v!r} is not a number", "write a number")
        t.append(float(v) * scale)
    if t[0] < 0:
        raise f.error(f"{key}.{tkey}[0]", "is negative", "start the table at 0 or later")
    for i in range(1, len(t)):
        if t[i] <= t[i - 1]:
            raise f.error(f"{key}.{tkey}[{i}]", "time does not increase",
                          "sort the entries by time and remove duplicates")
    T = [f.temperature(v, f"{key}.T_C[{i}]") + ZERO_C_K for i, v in enumerate(temps)]
    return TimeSeries(tuple(t), tuple(T), "linear")


def _generated_temperature(f: _File, d: dict[str, Any], key: str, model: str,
                           duration_s: float) -> TimeSeries:
    """The temperature [K] of one of the :data:`GENERATORS` over ``duration_s``."""
    allowed = GENERATOR_KEYS[model]
    f.unknown_keys(d, ("model", *allowed), key)
    kwargs: dict[str, float] = {}
    for p in allowed:
        if p in d:
            v = d[p]
            if not _is_number(v):
                raise f.error(f"{key}.{p}", f"{v!r} is not a number", f"write {p} = <number>")
            kwargs[p] = float(v)
    try:
        return GENERATORS[model](duration_s, **kwargs)
    except ParameterError as exc:
        raise f.error(f"{key}.{exc.param}", exc.message, exc.fix) from None


def _read_text(path: Path, f: _File) -> str:
    try:
        return path.read_text(encoding="utf-8-sig")  # a BOM (some editors write one) is no text
    except (OSError, UnicodeDecodeError) as exc:
        raise f.error("file", f"cannot be read ({exc})",
                      "check the path and that the file is UTF-8 text") from None


def read_cycle_toml(path: str | Path) -> Cycle:
    """Read a cycle from TOML (format: docs/cycles.md). Raises InputError."""
    path = Path(path)
    f = _File(path)
    try:
        data = tomllib.loads(_read_text(path, f))
    except tomllib.TOMLDecodeError as exc:
        raise f.error("syntax", str(exc), "fix the TOML syntax at that line") from None
    f.unknown_keys(data, ("cycle", "ambient", "coolant"), "")
    head = data.get("cycle")
    if not isinstance(head, dict):
        raise f.error("cycle", "required table is missing", "add a [cycle] table with steps = [...]")
    f.unknown_keys(head, ("name", "description", "source", "steady", "steps"), "cycle")
    for key in ("name", "description", "source"):
        if key in head and not isinstance(head[key], str):
            raise f.error(f"cycle.{key}", "is not a string", f'write {key} = "..."')
    steady = head.get("steady", False)
    if not isinstance(steady, bool):
        raise f.error("cycle.steady", f"{steady!r} is not true or false", "write steady = true or false")
    raw = head.get("steps")
    if raw is None:
        raise f.error("cycle.steps", "required field is missing",
                      "add steps = [{ speed_rpm = 1000, duration_h = 1.0 }, ...]")
    if not isinstance(raw, list) or not raw:
        raise f.error("cycle.steps", "the step table is empty",
                      "give at least one { speed_rpm = ..., duration_s = ... }")
    steps = tuple(_read_step(f, d, f"cycle.steps[{i}]") for i, d in enumerate(raw))
    duration = float(sum(s.duration_s for s in steps))
    if duration > CYCLE_MAX_S:  # before the temperatures are sampled over it
        k = int(np.argmax([s.duration_s for s in steps]))
        key = "duration_h" if "duration_h" in raw[k] else "duration_s"
        raise f.error(f"cycle.steps[{k}].{key}", f"the steps last {duration / 3600:.4g} h, "
                      f"more than {CYCLE_MAX_S / 3600:g} h (this step: "
                      f"{steps[k].duration_s / 3600:.4g} h)", "give step durations in seconds "
                      "(duration_s) or hours (duration_h) for a run of hours to days")
    amb = _read_temperature(f, data, "ambient", duration, TimeSeries.constant(DEFAULT_T_C + ZERO_C_K))
    cool = _read_temperature(f, data, "coolant", duration, amb)
    return Cycle(name=head.get("name", path.stem), description=head.get("description", ""),
                 source=head.get("source", ""), steps=steps, T_ambient_K=amb, T_coolant_K=cool,
                 steady=steady)


# --------------------------------------------------------------------------- CSV reader

_CSV_REQUIRED = ("speed_rpm", "duration_s")
_CSV_OPTIONAL = ("load_torque_Nm", "power_kW")
_CSV_META = ("name", "description", "source", "steady", "T_ambient_C", "T_coolant_C")


def read_cycle_steps_csv(path: str | Path, *, T_ambient_C: float | None = None,
                         T_coolant_C: float | None = None) -> Cycle:
    """Read a cycle's steps from CSV (comment lines start with ``#``).

    Columns: ``speed_rpm``, ``duration_s`` (required), ``load_torque_Nm`` (0 when absent or
    empty), ``power_kW`` (None when absent or empty); one row per step. Comment lines of the
    form ``# key: value`` may set ``name`` (default: the file stem), ``description``,
    ``source``, ``steady`` (true/false), ``T_ambient_C`` and ``T_coolant_C`` (constants;
    default 20 degC, coolant = ambient); other comments are ignored. The keyword arguments
    override those two temperatures. Errors name the field and the line of the file.
    """
    path = Path(path)
    f = _File(path)
    table = split_commented_csv(_read_text(path, f))
    meta: dict[str, tuple[str, int]] = {}  # key -> (value, file line); the last one counts
    for lineno, comment in table.comments:
        key, sep, value = comment.partition(":")
        if sep and key.strip() in _CSV_META:
            meta[key.strip()] = (value.strip(), lineno)
    if not table.line_no:
        raise f.error("header", "the file has no header row",
                      "add a header such as 'speed_rpm,duration_s,load_torque_Nm'")
    header, hline = table.header, table.line_no[0]
    _check_steps_header(f, header, hline)
    if len(table.rows) < 2:
        raise f.error("steps", "the step table is empty", "add one row per step below the header")
    steps = [_read_csv_step(f, header, row, lineno)
             for lineno, row in zip(table.line_no[1:], table.rows[1:], strict=True)]
    T_amb = _meta_temperature(f, meta, "T_ambient_C", T_ambient_C, DEFAULT_T_C)
    T_cool = _meta_temperature(f, meta, "T_coolant_C", T_coolant_C, T_amb)
    steady = False
    if "steady" in meta:
        value, lineno = meta["steady"]
        if value.lower() not in ("true", "false"):
            raise f.error(f"steady (line {lineno})", f"'{value}' is not true or false",
                          "write '# steady: true' or '# steady: false'")
        steady = value.lower() == "true"
    return Cycle(name=meta.get("name", (path.stem, 0))[0],
                 description=meta.get("description", ("", 0))[0],
                 source=meta.get("source", ("", 0))[0], steps=tuple(steps),
                 T_ambient_K=TimeSeries.constant(T_amb + ZERO_C_K),
                 T_coolant_K=TimeSeries.constant(T_cool + ZERO_C_K), steady=steady)


def _check_steps_header(f: _File, header: list[str], hline: int) -> None:
    """The required step columns are there; every column is a step column, once."""
    if len(header) == 1 and ";" in header[0]:
        raise f.error(f"header (line {hline})", "the columns are separated by ';'",
                      "export comma-separated values with '.' as the decimal separator")
    if "time_s" in header and "duration_s" not in header:
        raise f.error(f"time_s (line {hline})", "this is a time series of loads, and a cycle "
                      "here is a table of steps", "give a step table (header: "
                      f"{','.join(_CSV_REQUIRED + _CSV_OPTIONAL)}); 'spindle-verify solve "
                      "--cycle' runs a time series")
    for col in _CSV_REQUIRED:
        if col not in header:
            raise f.error(col, f"required column is missing from the header (line {hline})",
                          f"add a '{col}' column (header: {','.join(_CSV_REQUIRED + _CSV_OPTIONAL)})")
    for h in header:
        if h not in _CSV_REQUIRED + _CSV_OPTIONAL:
            raise f.error(f"{h or '(empty)'} (line {hline})", "is not a step column",
                          f"use only {list(_CSV_REQUIRED + _CSV_OPTIONAL)}")
        if header.count(h) > 1:
            raise f.error(f"{h} (line {hline})", "column appears twice", "keep one of them")


def _read_csv_step(f: _File, header: list[str], row: list[str], lineno: int) -> Step:
    """One step row (file line ``lineno``): a number >= 0 in each cell; an empty cell is
    allowed only in the optional columns."""
    if len(row) != len(header):
        raise f.error(f"line {lineno}", f"has {len(row)} cells, the header has {len(header)}",
                      "give every row one cell per column")
    vals = {h: _step_cell(f, h, cell.strip(), f"{h} (line {lineno})")
            for h, cell in zip(header, row, strict=True)}
    return Step(vals["speed_rpm"], vals["duration_s"],  # type: ignore[arg-type]
                vals.get("load_torque_Nm") or 0.0, vals.get("power_kW"))


def _step_cell(f: _File, h: str, cell: str, fld: str) -> float | None:
    """The value of a stripped cell of column ``h`` (None when empty and optional)."""
    if not cell:
        if h in _CSV_REQUIRED:
            raise f.error(fld, "is empty", "give a number in every row")
        return None
    try:
        v = float(cell)
    except ValueError:
        raise f.error(fld, f"'{cell}' is not a number",
                      "write a decimal number with '.' as the separator") from None
    if not math.isfinite(v):
        raise f.error(fld, "is not finite", "write a finite number")
    if v < 0:
        raise f.error(fld, f"{v:g} is negative", f"give {h} >= 0")
    if h == "duration_s" and v == 0:
        raise f.error(fld, "is zero", "give every step a duration > 0 s or drop the row")
    return v


def _meta_temperature(f: _File, meta: dict[str, tuple[str, int]], key: str,
                      override: float | None, default: float) -> float:
    """A ``# key: value`` temperature [degC]: the override, else the comment, else the default."""
    if override is not None:
        return f.temperature(override, key)
    if key not in meta:
        return default
    value, lineno = meta[key]
    try:
        v = float(value)
    except ValueError:
        raise f.error(f"{key} (line {lineno})", f"'{value}' is not a number",
                      f"write '# {key}: 20.0'") from None
    return f.temperature(v, f"{key} (line {lineno})")


# --------------------------------------------------------------------------- shipped cycles


#: the shortest step of a cycle [s]: shorter ones are a unit mistake (and vanish in the sum of
#: the durations: a 1e-320 s step after an hour does not advance the time)
STEP_MIN_S = 1e-3


def check_cycle_limits(cycle: Cycle, file: str) -> Cycle:
    """``cycle`` if its speeds and duration are those of a spindle's test cycle
    (``spindle.units.SPEED_MAX_RPM``, ``CYCLE_MAX_S``); otherwise an InputError naming the
    step: the work of simulating it would be absurd, and so would the result."""
    for k, s in enumerate(cycle.steps):
        if s.duration_s < STEP_MIN_S:
            raise InputError(file, f"steps[{k}].duration_s", f"{s.duration_s:g} s is shorter "
                             f"than {STEP_MIN_S:g} s", _durations_fix(file))
        if s.speed_rpm > SPEED_MAX_RPM:
            raise InputError(file, f"steps[{k}].speed_rpm", f"{s.speed_rpm:g} rpm is above "
                             f"{SPEED_MAX_RPM:g} rpm, faster than any motor spindle",
                             "give the speed in rpm (1/min)")
        if abs(s.load_torque_Nm) > TORQUE_MAX_NM:
            raise InputError(file, f"steps[{k}].load_torque_Nm", f"{s.load_torque_Nm:g} N m is "
                             f"beyond ±{TORQUE_MAX_NM:g} N m, more than any motor spindle "
                             "delivers", "give the process load torque in N m")
        if s.power_kW is not None and abs(s.power_kW) > POWER_MAX_KW:
            raise InputError(file, f"steps[{k}].power_kW", f"{s.power_kW:g} kW is beyond "
                             f"±{POWER_MAX_KW:g} kW", "give the electrical power in kW (a value "
                             "in W is 1000 times too large)")
    if cycle.duration_s > CYCLE_MAX_S:
        raise InputError(file, "duration_s", f"the steps last {cycle.duration_s / 3600:.4g} h, "
                         f"more than {CYCLE_MAX_S / 3600:g} h",
                         _durations_fix(file) + " for a run of hours to days")
    return cycle


def _durations_fix(file: str) -> str:
    """How to give a step's duration in ``file``: a step table (CSV) has duration_s only."""
    if str(file).lower().endswith(".csv"):
        return "give step durations in seconds (the duration_s column)"
    return "give step durations in seconds (duration_s) or hours (duration_h)"


def shipped_cycles() -> dict[str, Path]:
    """Shipped cycles (spindle/data/cycles/*.toml and *.csv) by name (the file stem)."""
    root = resources.files("spindle").joinpath("data/cycles")
    return {Path(str(p)).stem: Path(str(p)) for p in sorted(root.iterdir(), key=str)
            if str(p).endswith((".toml", ".csv"))}


def load_cycle(name_or_path: str | Path) -> Cycle:
    """A cycle from a file (``.toml`` or ``.csv``) or the name of a shipped cycle."""
    p = Path(name_or_path)
    if not p.is_file():
        shipped = shipped_cycles()
        if str(name_or_path) not in shipped:
            raise InputError(str(name_or_path), "file", "is neither a file nor a shipped cycle",
                             f"give the path of a .toml or .csv cycle or one of {sorted(shipped)}")
        p = shipped[str(name_or_path)]
    suffix = p.suffix.lower()
    if suffix == ".toml":
        return check_cycle_limits(read_cycle_toml(p), str(p))
    if suffix == ".csv":
        return check_cycle_limits(read_cycle_steps_csv(p), str(p))
    raise InputError(str(p), "file", f"unknown cycle file type '{p.suffix}'",
                     "give a .toml cycle or a .csv step table")
