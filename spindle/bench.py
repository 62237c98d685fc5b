"""Test-bench runs (issue 6, section 1): read a bench export and build the model's inputs.

A motor-spindle test bench exports one run as a CSV file (the shared bench-format document;
rules, errors and decisions in docs/bench.md). This module reads it as it is:

* :func:`read_bench` parses and checks the file into a :class:`BenchRun` (file units: s, rpm,
  kW, °C, µm, N m; NaN where a cell is empty). Every problem raises
  :class:`~spindle.errors.InputError` naming the file, the column and/or the file line
  (comments and blank lines counted) and the fix; the command line turns it into exit status 2.
* :func:`check_against_spec` maps the measured channels (T1, T2, T_stator, P1) to the spec's
  sensors of the same name and kind.
* :func:`spindle.bench_inputs.inputs` turns the run into a :class:`~spindle.loads.LoadCase`
  on a time grid: speed held, ambient and coolant averaged, heat sources from the drive's
  power balance per grid interval.

SI inside (K, m, W, s); °C and µm appear only in the file's column names and in
:attr:`BenchRun.columns` (which keeps the file's units).
"""

from __future__ import annotations

import csv
import io
import re
import sys
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from spindle.bench_text import hint_for, text_lines
from spindle.errors import InputError
from spindle.sensor_faults import check_not_copies, check_room_in_celsius, drop_impossible_samples
from spindle.spec import Spec
from spindle.units import CYCLE_MAX_S, POWER_MAX_KW, SPEED_MAX_RPM, TORQUE_MAX_NM, ZERO_C_K

# a bench export may hold long cells in columns the tool does not read (notes, JSON): the
# csv module's default 128 kB field limit would refuse valid files
csv.field_size_limit(min(sys.maxsize, 2**31 - 1))

#: µm -> m
UM_TO_M = 1e-6

#: Columns every run must have, in the order of the format's table.
REQUIRED_COLUMNS: tuple[str, ...] = ("time_s", "speed_rpm", "power_kW", "T_env_C", "T_coolant_C")
#: Measured model channels and their columns, in the order :attr:`BenchRun.channels` lists them.
CHANNEL_COLUMNS: dict[str, str] = {"T1": "T1_C", "T2": "T2_C", "T_stator": "T_stator_C",
                                   "P1": "P1_um"}
#: Sensor kind of the spec that each channel maps to.
CHANNEL_KINDS: dict[str, str] = {"T1": "temperature", "T2": "temperature",
                                 "T_stator": "temperature", "P1": "axial_displacement"}
#: Optional inputs.
OPTIONAL_COLUMNS: tuple[str, ...] = ("load_torque_Nm",)
#: Every column the format defines.
KNOWN_COLUMNS: tuple[str, ...] = REQUIRED_COLUMNS + tuple(CHANNEL_COLUMNS.values()) + OPTIONAL_COLUMNS
#: Temperature columns [°C] (plausibility: kelvin check and lower limit).
TEMPERATURE_COLUMNS: tuple[str, ...] = ("T_env_C", "T_coolant_C", "T1_C", "T2_C", "T_stator_C")

#: Plausibility limits (file units).
T_MIN_C = -60.0
T_KELVIN_MEDIAN_C = 150.0
T_KELVIN_MAX_C = 250.0
POWER_LIMIT_KW = POWER_MAX_KW
#: |P1| [um] beyond which a reading is not a spindle's thermal growth: tens of um (the
#: SPL2782's 80 um at its nominal point, the peer's runs below 30 um); 5 mm is a broken
#: sensor or a value in nm
P1_LIMIT_UM = 5000.0
#: What a fit needs: rows with at least one measured channel, and their time span [s].
MIN_ROWS = 50
MIN_SPAN_S = 1800.0
#: Default spacing of the model's input grid [s].
DEFAULT_GRID_S = 60.0
#: Below this speed [rpm] the spindle stands still: the power balance gives no losses.
STANDSTILL_RPM = 1.0
#: A step between samples longer than this many median steps counts as a gap in the summary.
GAP_FACTOR = 10.0


class BenchWarning(UserWarning):
    """Something in a bench run was skipped or clipped (not an error): the message says what."""


# ============================================================================ the run


@dataclass(frozen=True)
class BenchRun:
    """One test-bench run as read from its CSV export.

    ``time_s`` [s]: time since the start of the run, one value per data row, strictly
    increasing. ``columns``: the known columns present (format table), in the FILE's units
    (rpm, kW, °C, µm, N m), NaN where a cell was empty; ``P1_um`` is already zeroed at its
    first valid sample (the raw reading there is ``P1_reference_um``); ``load_torque_Nm`` is
    all zeros when the file has no such column (a no-load run, ``load_torque_measured`` False).
    ``extra``: unknown columns by name, as float arrays (NaN where empty) or, if a cell is not
    a number, as lists of the cell strings. ``channels``: the measured model channels present,
    a subset of T1, T2, T_stator, P1 in that order. ``duration_s`` [s]: the last time_s less the
    first (a bench that logs the time of day starts late). ``lines``: the file line of each
    data row (for messages).
    """

    path: Path
    metadata: dict[str, str]
    time_s: np.ndarray
    columns: dict[str, np.ndarray]
    extra: dict[str, np.ndarray | list[str]]
    unknown_columns: list[str]
    channels: list[str]
    duration_s: float
    lines: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0, dtype=int))
    P1_reference_um: float | None = None
    load_torque_measured: bool = False

    @property
    def name(self) -> str:
        """The file stem (the LoadCase's name)."""
        return self.path.stem

    def channel(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """Valid samples of a measured channel, in SI: ``(t [s], y)`` with y in K for the
        temperature channels T1, T2, T_stator and in m for P1 (axial growth of the shaft front
        end against the bearing shield, zeroed at its first valid sample; positive toward the
        tool). ``name`` is the channel (``"T1"``) or its column (``"T1_C"``). KeyError if the
        run has no such channel."""
        ch = next((c for c, col in CHANNEL_COLUMNS.items() if name in (c, col)), None)
        if ch is None or ch not in self.channels:
            raise KeyError(f"{self.path}: no measured channel {name!r}; the run has {self.channels}")
        y = self.columns[CHANNEL_COLUMNS[ch]]
        ok = ~np.isnan(y)
        t, v = self.time_s[ok], y[ok]
        return t, (v * UM_TO_M if ch == "P1" else v + ZERO_C_K)

    def summary(self) -> dict[str, Any]:
        """A plain dict for reports: rows, start/end/duration [s], sampling (median step, largest
        step, the number of gaps longer than ``GAP_FACTOR`` median steps), the valid samples of
        each channel, unknown columns and the metadata."""
        dt = np.diff(self.time_s)
        median = float(np.median(dt)) if len(dt) else float("nan")
        return {
            "file": str(self.path),
            "rows": int(len(self.time_s)),
            "start_s": float(self.time_s[0]),
            "end_s": float(self.time_s[-1]),
            "duration_s": float(self.duration_s),
            "median_dt_s": median,
            "max_gap_s": float(dt.max()) if len(dt) else 0.0,
            "gaps": int(np.count_nonzero(dt > GAP_FACTOR * median)) if len(dt) else 0,
            "gap_threshold_s": GAP_FACTOR * median,
            "channels": {c: int(np.count_nonzero(~np.isnan(self.columns[CHANNEL_COLUMNS[c]])))
                         for c in self.channels},
            "load_torque_measured": self.load_torque_measured,
            "P1_reference_um": self.P1_reference_um,
            "unknown_columns": list(self.unknown_columns),
            "metadata": dict(self.metadata),
        }


# ============================================================================ reading


def _parse_floats(cells: tuple[str, ...] | list[str]) -> tuple[np.ndarray | None, int]:
    """Cells -> float array with NaN for empty cells (and 'nan'); (None, index) at the first
    cell that is not a number (:func:`_is_number`)."""
    sep = next((k for k, c in enumerate(cells) if "_" in c), -1)
    if sep >= 0:
        return None, sep
    try:
        return np.array(cells, dtype=float), -1
    except ValueError:
        pass
    cleaned = [c.strip() or "nan" for c in cells]
    try:
        return np.array(cleaned, dtype=float), -1
    except ValueError:
        for k, c in enumerate(cleaned):
            try:
                float(c)
            except ValueError:
                return None, k
    raise AssertionError("unreachable")  # pragma: no cover


class _Table:
    """The data rows of a bench file. Fast path (no quotes, every row with one cell per
    column, every cell of the numeric columns a number or empty): numpy's C parser on the
    text, text-valued unknown columns split off by hand. Otherwise the csv module, cell by
    cell, which also finds the exact row or cell of a problem. ``line_no``: the file line
    of each data row."""

    def __init__(self, line_no: np.ndarray, body: list[str], ncol: int):
        self.line_no, self.body, self.ncol = line_no, body, ncol
        self.bad_row, self.row_lengths = -1, [ncol] * len(body)
        self._values: np.ndarray | None = None  # (rows, ncol) floats; NaN in text columns
        self._text: dict[int, list[str]] = {}  # text-valued columns of the fast path
        self._cells: list[tuple[str, ...]] | None = None  # general path: cells by column

    @classmethod
    def parse(cls, lines: list[str], header_idx: int, header: list[str]) -> _Table:
        ncol = len(header)
        rest = lines[header_idx + 1:]
        while rest and not rest[-1].strip():
            rest.pop()
        text = "\n".join(rest).replace("\r", "")
        if not _has_skipped_line(text):  # no blank or comment lines: row k is line h + 2 + k
            line_no = np.arange(header_idx + 2, header_idx + 2 + len(rest))
            body = text.split("\n") if rest else []
        else:
            kept = [(k + 1, ln.replace("\r", "")) for k, ln in enumerate(rest, start=header_idx + 1)
                    if ln.strip() and not ln.lstrip().startswith("#")]
            line_no = np.array([k for k, _ in kept], dtype=int)
            body = [ln for _, ln in kept]
            text = "\n".join(body)
        table = cls(line_no, body, ncol)
        if body and table._fast(text, header):
            return table
        rows = list(csv.reader(body))
        table.row_lengths = [len(r) for r in rows]
        table.bad_row = next((k for k, n in enumerate(table.row_lengths) if n != ncol), -1)
        if table.bad_row < 0:
            table._cells = list(zip(*rows, strict=True)) if rows else [() for _ in range(ncol)]
        return table

    def _fast(self, text: str, header: list[str]) -> bool:
        """Try the fast path; False leaves the table to the csv module."""
        if ('"' in text or "_" in text  # numpy, as Python, reads 1_0 as 10
                or any(ln.count(",") != self.ncol - 1 for ln in self.body)):
            return False
        first = self.body[0].split(",")
        text_cols = [j for j, c in enumerate(first) if c.strip() and not _is_number(c)]
        if any(header[j] in KNOWN_COLUMNS for j in text_cols):
            return False  # a known column holds text: the general path names the cell
        numeric = [j for j in range(self.ncol) if j not in text_cols]
        text = text.replace(",,", ",nan,").replace(",,", ",nan,")
        text = text.replace("\n,", "\nnan,").replace(",\n", ",nan\n")
        if text.startswith(","):
            text = "nan" + text
        if text.endswith(","):
            text += "nan"
        try:
            values = np.loadtxt(io.StringIO(text), delimiter=",", dtype=float, ndmin=2,
                                comments=None, usecols=numeric)
        except ValueError:
            return False
        if values.shape != (len(self.body), len(numeric)):
            return False
        self._values = np.full((len(self.body), self.ncol), np.nan)
        self._values[:, numeric] = values
        self._text = {j: [ln.split(",")[j] for ln in self.body] for j in text_cols}
        return True

    def column(self, j: int) -> tuple[np.ndarray | None, int]:
        """Column j as floats (NaN where empty), or (None, row of the first non-number)."""
        if self._values is not None and j not in self._text:
            return self._values[:, j].copy(), -1
        if j in self._text:
            return _parse_floats(self._text[j])
        assert self._cells is not None
        return _parse_floats(self._cells[j])

    def cell(self, j: int, k: int) -> str:
        """The text of column j in data row k (stripped)."""
        if self._cells is not None:
            return self._cells[j][k].strip()
        return next(csv.reader([self.body[k]]))[j].strip()

    def strings(self, j: int) -> list[str]:
        """Column j as stripped strings."""
        if j in self._text:
            return [c.strip() for c in self._text[j]]
        if self._cells is None:
            self._cells = list(zip(*csv.reader(self.body), strict=True))
        return [c.strip() for c in self._cells[j]]


#: A blank line or a comment line (data rows: lines that are neither).
_SKIPPED_LINE = re.compile(r"(?:^|\n)[ \t]*(?:#|\n|$)")


def _has_skipped_line(text: str) -> bool:
    """Whether ``text`` (lines joined by newlines, no carriage returns) has a blank or a
    comment line; substring tests first, the regular expression only for indented lines."""
    if not text or text[0] in "#\n" or "\n\n" in text or "\n#" in text:
        return True
    if text[0] in " \t" or "\n " in text or "\n\t" in text:
        return bool(_SKIPPED_LINE.search(text))
    return False


#: What every check of :func:`read_bench` raises: InputError(file, field, message, fix).
_ErrorFor = Callable[[str, str, str], InputError]


def read_bench(path: str | Path) -> BenchRun:
    """Read a test-bench run (CSV, format: docs/bench.md) into a :class:`BenchRun`.

    Checks the structure (header, duplicate columns, required columns, one cell per column),
    every cell of the known columns (numbers, finite), ``time_s`` (present in every row,
    >= 0, strictly increasing), plausibility (°C not kelvin, >= -60 °C; |speed| up to
    100 000 rpm, a negative one read as the spindle turning in reverse; power within
    ±1000 kW), no required column all empty (an optional one all empty was not
    measured: left out with a BenchWarning), and that there is enough data to fit
    (>= 50 rows with a measured channel over >= 30 min). Raises InputError naming the file,
    the column and/or the file line, and the fix.
    """
    if not isinstance(path, str | Path):
        raise TypeError(f"a bench run is the path of its CSV file, not {type(path).__name__}")
    if not str(path).strip():
        raise InputError("(no file)", "run", "the path of the bench run is empty",
                         "give the path of the run's CSV file")
    path = Path(path)
    name = str(path)

    def error(fld: str, message: str, fix: str) -> InputError:
        return InputError(name, fld, message, fix)

    lines = _read_lines(path, error)
    metadata, header_idx = _comments_before_header(lines, error)
    header, seen = _read_header(lines, header_idx, error)
    table = _read_rows(lines, header_idx, header, error)
    line_no = table.line_no
    t = _read_time(table, seen["time_s"], error)
    columns = _read_known_columns(table, seen, error, name)
    _read_reversed(columns, name)
    drop_impossible_samples(columns, line_no, lambda m: warnings.warn(BenchWarning(
        f"{name}: {m}"), stacklevel=4), (T_MIN_C, T_KELVIN_MEDIAN_C, T_KELVIN_MAX_C, P1_LIMIT_UM))
    _check_plausible(columns, line_no, error)
    check_room_in_celsius(columns, line_no, error)
    extra = _read_unknown_columns(table, header)
    unknown = list(extra)
    for h in unknown:
        hint = next((x for k in KNOWN_COLUMNS if (x := hint_for(k, [h]))), "")
        if hint:
            warnings.warn(BenchWarning(f"{name}: {h}: kept as an unknown column{hint}"), stacklevel=2)

    check_not_copies(columns, error)
    channels = [c for c, col in CHANNEL_COLUMNS.items() if col in columns]
    p1_ref = _zero_P1(columns)
    _check_enough_data(t, columns, channels, error)
    torque_measured = "load_torque_Nm" in columns
    if not torque_measured:
        columns["load_torque_Nm"] = np.zeros(len(t))
    return BenchRun(path=path, metadata=metadata, time_s=t, columns=columns, extra=extra,
                    unknown_columns=unknown, channels=channels, duration_s=float(t[-1] - t[0]),
                    lines=line_no, P1_reference_um=p1_ref, load_torque_measured=torque_measured)


def _read_lines(path: Path, error: _ErrorFor) -> list[str]:
    """The file's lines (UTF-8; a byte-order mark dropped)."""
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise error("file", f"cannot be read ({exc.strerror or exc})",
                    "check the path of the bench export") from None
    if not raw.strip():
        raise error("file", "is empty", "export the bench run again (a header row and data rows)")
    return text_lines(raw, str(path))


def _comments_before_header(lines: list[str], error: _ErrorFor) -> tuple[dict[str, str], int]:
    """The ``# key: value`` metadata of the comment lines before the header (a key without
    spaces), and the index of the header line (the first line that is not blank or a comment)."""
    metadata: dict[str, str] = {}
    for k, line in enumerate(lines):
        s = line.strip()
        if not s:
            continue
        if s.lower().startswith("sep=") and len(s) <= 5:  # a spreadsheet's separator hint
            continue
        if s.startswith("#"):
            key, sep, value = s[1:].partition(":")
            key = key.strip()
            if sep and key and not any(ch.isspace() for ch in key):
                metadata[key] = value.strip()
            continue
        return metadata, k
    raise error("header", "the file has no header row (only comments)",
                "export the run with its header row, e.g. 'time_s,speed_rpm,power_kW,"
                "T_env_C,T_coolant_C,T1_C'")


def _read_header(lines: list[str], header_idx: int,
                 error: _ErrorFor) -> tuple[list[str], dict[str, int]]:
    """The column names and the index of each: comma-separated, no duplicates, the required
    columns and at least one measured channel."""
    hline = header_idx + 1
    # a carriage return is a line end or nothing, never a cell's text (the body drops it too)
    header = [h.strip() for h in next(csv.reader([lines[header_idx].replace("\r", "")]))]
    if len(header) == 1 and any(sep in header[0] for sep in (";", "\t")):
        sep_name = "';'" if ";" in header[0] else "tabs"
        raise error(f"header (line {hline})", f"the columns are separated by {sep_name}, not commas",
                    "export the file comma-separated with '.' as the decimal separator")
    if not any(header):
        raise error(f"header (line {hline})", "the header row has no column names",
                    "put the header row (e.g. 'time_s,speed_rpm,...') before the data")
    if all(_is_number(h) for h in header if h):
        raise error(f"header (line {hline})", "the first non-comment line holds numbers, not column "
                    "names", "put the header row (e.g. 'time_s,speed_rpm,...') before the data")
    seen: dict[str, int] = {}
    for j, h in enumerate(header):
        if h and h in seen and h not in KNOWN_COLUMNS:  # unknown columns are never an error
            header[j] = h = f"{h} (column {j + 1})"
        elif h and h in seen:
            raise error(f"{h} (line {hline})", f"column name appears twice (columns {seen[h] + 1} "
                        f"and {j + 1})", "keep one of the two columns or rename one")
        seen[h] = j
    for col in REQUIRED_COLUMNS:
        if col not in seen:
            raise error(col, f"required column is missing from the header (line {hline})"
                        + hint_for(col, header),
                        f"export a '{col}' column (required: {', '.join(REQUIRED_COLUMNS)})")
    if not any(col in seen for col in CHANNEL_COLUMNS.values()):
        hints = "".join(hint_for(c, header) for c in CHANNEL_COLUMNS.values())
        raise error(f"header (line {hline})", "no measured channel: the run has none of the columns "
                    f"{', '.join(CHANNEL_COLUMNS.values())}{hints}",
                    "export at least one of the sensor columns the model is checked against")
    return header, seen


def _read_rows(lines: list[str], header_idx: int, header: list[str], error: _ErrorFor) -> _Table:
    """The data rows: at least one, each with one cell per column."""
    hline = header_idx + 1
    table = _Table.parse(lines, header_idx, header)
    line_no = table.line_no
    if table.bad_row >= 0:
        raise error(f"line {line_no[table.bad_row]}", f"has {table.row_lengths[table.bad_row]} cells, "
                    f"the header (line {hline}) has {len(header)}", "give every row one cell per "
                    "column (an empty cell for a value not measured)")
    if not len(line_no):
        raise error("rows", f"the file has a header (line {hline}) but no data rows",
                    "export the run with its data")
    return table


def _read_time(table: _Table, j: int, error: _ErrorFor) -> np.ndarray:
    """time_s (column j) [s]: a finite number in every row, >= 0, strictly increasing."""
    line_no = table.line_no
    t, _ = table.column(j)
    if t is None or np.isnan(t).any():
        if t is None:  # the first cell that is empty or not a number
            k = next(i for i, c in enumerate(table.strings(j))
                     if not _is_number(c) or c.lower() == "nan")
        else:
            k = int(np.flatnonzero(np.isnan(t))[0])
        cell = table.cell(j, k)
        what = "is empty" if not cell or cell.lower() == "nan" else f"'{cell}' is not a number"
        raise error(f"time_s (line {line_no[k]})", f"{what}; every row needs its time",
                    "give the time since the start of the run [s] in every row, or delete the row")
    if not np.isfinite(t).all():
        k = int(np.flatnonzero(~np.isfinite(t))[0])
        raise error(f"time_s (line {line_no[k]})", "is not finite", "write a finite time [s]")
    if t[0] < 0:
        raise error(f"time_s (line {line_no[0]})", f"{t[0]:g} s is negative: time_s is the time since "
                    "the start of the run", "export the time from the start of the run (>= 0 s)")
    back = np.flatnonzero(np.diff(t) <= 0)
    if len(back):
        k = int(back[0]) + 1
        what = f"{t[k]:g} s is not after {t[k - 1]:g} s on line {line_no[k - 1]}"
        if t[k] == t[k - 1]:
            fix = "export the rows in time order without duplicate rows"
        elif t[k] <= t[0] + 0.01 * (t[k - 1] - t[0]):
            # back to (near) the first row's time: a second run appended, not a row misplaced
            what += ": the time starts again, as if a second run followed the first"
            fix = f"export one run a file (the second starts at line {line_no[k]})"
        else:
            what += f": the time goes back by {t[k - 1] - t[k]:g} s"
            fix = ("export the rows in time order; if the bench's clock was set back, export "
                   "the time since the start of the run")
        raise error(f"time_s (line {line_no[k]})", f"{what}: time must increase strictly", fix)
    if t[-1] - t[0] > CYCLE_MAX_S:
        k = len(t) - 1
        raise error(f"time_s (line {line_no[k]})", f"the run spans {(t[-1] - t[0]) / 3600:.4g} h, "
                    f"more than {CYCLE_MAX_S / 3600:g} h: not a bench run in seconds",
                    "export time_s in seconds since the start of the run")
    return t


def _read_known_columns(table: _Table, seen: dict[str, int], error: _ErrorFor,
                        name: str) -> dict[str, np.ndarray]:
    """The known columns present except time_s, in file units: numbers or empty cells,
    finite. A required column empty in every row is an error; an optional one (a sensor,
    the load torque) was not measured: it is left out with a :class:`BenchWarning`, and at
    least one sensor column must remain."""
    line_no = table.line_no
    columns: dict[str, np.ndarray] = {}
    empty: list[str] = []
    for col in KNOWN_COLUMNS[1:]:
        if col not in seen:
            continue
        arr, bad = table.column(seen[col])
        if arr is None:
            raise error(f"{col} (line {line_no[bad]})", f"'{table.cell(seen[col], bad)}' is not a "
                        "number", "write a decimal number with '.' as the separator, or leave the "
                        "cell empty when not measured")
        inf = np.flatnonzero(np.isinf(arr))
        if len(inf):
            raise error(f"{col} (line {line_no[inf[0]]})", "is not finite",
                        "write a finite number, or leave the cell empty when not measured")
        if np.isnan(arr).all():
            if col in REQUIRED_COLUMNS:
                raise error(col, "the column is empty in every row", "export the measurement "
                            f"(required: {', '.join(REQUIRED_COLUMNS)})")
            empty.append(col)  # "not measured at this instant" (the format), at every one
            continue
        columns[col] = arr
    if not any(col in columns for col in CHANNEL_COLUMNS.values()):
        present = [c for c in CHANNEL_COLUMNS.values() if c in seen]
        raise error(", ".join(present), "no measured channel: every sensor column is empty in "
                    "every row", "export at least one of the sensor columns the model is "
                    f"checked against ({', '.join(CHANNEL_COLUMNS.values())}) with its values")
    for col in empty:  # never measured: as if the column were not there
        warnings.warn(BenchWarning(
            f"{name}: {col}: empty in every row, read as not measured"
            + (": the run is taken as a no-load run (no process torque), so the motor's losses "
               "are the electrical power less the bearings' friction only"
               if col == "load_torque_Nm" else " (the run is checked on the other channels)")),
            stacklevel=3)
    return columns


def _read_unknown_columns(table: _Table, header: list[str]) -> dict[str, np.ndarray | list[str]]:
    """Columns the format does not define, by name (an unnamed one as '(column j)'), as
    floats or, if a cell is not a number, as strings; an unnamed empty column (a trailing
    separator) is no column."""
    extra: dict[str, np.ndarray | list[str]] = {}
    for j, h in enumerate(header):
        if h in KNOWN_COLUMNS:
            continue
        arr, _ = table.column(j)
        if not h:
            if arr is not None and np.isnan(arr).all():
                continue  # a trailing separator: no column
            h = f"(column {j + 1})"
        extra[h] = arr if arr is not None else table.strings(j)
    return extra


def _read_reversed(columns: dict[str, np.ndarray], name: str) -> None:
    """A drive logs its speed signed: a spindle turning in reverse (M04), or a drive that counts
    the other direction as positive, reads negative. The losses follow |n|, and the process's
    power M n is the same in either sign convention, so the speed is read as |n| and, where
    it was negative, the load torque's sign turns with it (in place), with a warning."""
    n = columns["speed_rpm"]
    back = n < 0  # NaN (not measured) is not negative
    if not back.any():
        return
    columns["speed_rpm"] = np.abs(n)
    m = columns.get("load_torque_Nm")
    if m is not None:
        columns["load_torque_Nm"] = np.where(back, -m, m)
    warnings.warn(BenchWarning(
        f"{name}: speed_rpm: negative in {int(back.sum())} of {int(np.sum(~np.isnan(n)))} "
        "samples: the spindle turned in reverse there (or the drive counts the other direction "
        "as positive); its speed is read as |n|"
        + (", and the load torque's sign turned with it (the process's power M n unchanged)"
           if m is not None else "")), stacklevel=3)


def _zero_P1(columns: dict[str, np.ndarray]) -> float | None:
    """Zero P1_um at its first valid sample (in place); returns that raw reading."""
    if "P1_um" not in columns:
        return None
    p1 = columns["P1_um"]
    p1_ref = float(p1[np.flatnonzero(~np.isnan(p1))[0]])
    columns["P1_um"] = p1 - p1_ref
    return p1_ref


def _check_enough_data(t: np.ndarray, columns: dict[str, np.ndarray], channels: list[str],
                       error: _ErrorFor) -> None:
    """At least MIN_ROWS rows with a measured channel over MIN_SPAN_S."""
    measured = np.zeros(len(t), dtype=bool)
    for c in channels:
        measured |= ~np.isnan(columns[CHANNEL_COLUMNS[c]])
    tm = t[measured]
    span = float(tm[-1] - tm[0]) if len(tm) else 0.0
    if len(tm) < MIN_ROWS or span < MIN_SPAN_S:
        fix = (f"export a run with at least {MIN_ROWS} rows with a measured channel over at "
               f"least {MIN_SPAN_S / 60:.0f} min")
        if len(tm) >= MIN_ROWS and span > 0:  # rows enough, time too short: its unit?
            fix += (f"; {len(tm)} rows in {span:.4g} s is a row every {span / (len(tm) - 1):.3g} "
                    "s: if time_s is in minutes or hours, export seconds")
        raise error("rows", f"too little data to fit: {len(tm)} rows with a measured channel "
                    f"({', '.join(channels)}) spanning {span / 60:.1f} min", fix)


def _is_number(s: str) -> bool:
    if "_" in s:  # Python's float reads 1_0 as 10; no bench exports digit separators
        return False
    try:
        float(s)
    except ValueError:
        return False
    return True


def _check_plausible(columns: dict[str, np.ndarray], line_no: np.ndarray, error: _ErrorFor) -> None:
    """Temperatures in °C (not kelvin, >= -60 °C), speed 0..100 000 rpm, power within
    ±1000 kW, P1 within ±5 mm, load torque within ±10 000 N m; the first offending line is
    named."""

    def first(mask: np.ndarray) -> int:
        return int(line_no[np.flatnonzero(mask)[0]])

    for col in TEMPERATURE_COLUMNS:
        if col not in columns:
            continue
        y = columns[col]
        v = y[~np.isnan(y)]
        med, top = float(np.median(v)), float(v.max())
        # above the range in °C: kelvin where the median is, or where the reading less 273.15
        # is a plausible temperature in °C; a broken reading where it is not
        if med > T_KELVIN_MEDIAN_C or (top > T_KELVIN_MAX_C
                                       and T_MIN_C <= top - 273.15 <= T_KELVIN_MEDIAN_C):
            over = y > (T_KELVIN_MAX_C if top > T_KELVIN_MAX_C else T_KELVIN_MEDIAN_C)
            raise error(f"{col} (line {first(over)})", f"{top:g} (median {med:g}) looks like kelvin",
                        "export °C (°C = K - 273.15)")
        if top > T_KELVIN_MAX_C:
            raise error(f"{col} (line {first(y > T_KELVIN_MAX_C)})", f"{top:g} °C is above "
                        f"{T_KELVIN_MAX_C:g} °C while the column's median is {med:g} °C: a "
                        "broken reading", "check the sensor; leave the cell empty where it did "
                        "not measure")
        if v.min() < T_MIN_C:
            raise error(f"{col} (line {first(y < T_MIN_C)})", f"{v.min():g} °C is below "
                        f"{T_MIN_C:g} °C", "check the sensor and export temperatures in °C")
    n = columns["speed_rpm"]  # |n|: _read_reversed
    if (n > SPEED_MAX_RPM).any():
        raise error(f"speed_rpm (line {first(n > SPEED_MAX_RPM)})", f"{n[n > SPEED_MAX_RPM][0]:g} "
                    f"rpm is above {SPEED_MAX_RPM:g} rpm", "export the speed in rpm (1/min); check "
                    "the unit of the drive's speed channel")
    p = columns["power_kW"]
    big = np.abs(p) > POWER_LIMIT_KW
    if big.any():
        raise error(f"power_kW (line {first(big)})", f"{p[big][0]:g} kW is outside "
                    f"±{POWER_LIMIT_KW:g} kW", "export the electrical power in kW (a value in W is "
                    "1000 times too large)")
    g = columns.get(CHANNEL_COLUMNS["P1"])
    if g is not None:
        big = np.abs(np.nan_to_num(g)) > P1_LIMIT_UM
        if big.any():
            raise error(f"{CHANNEL_COLUMNS['P1']} (line {first(big)})", f"{g[big][0]:g} um is "
                        f"beyond ±{P1_LIMIT_UM:g} um, far more than a spindle grows thermally",
                        "export the axial growth in um (a value in nm is 1000 times too large); "
                        "leave the cell empty where the sensor did not measure")
    m = columns.get("load_torque_Nm")
    if m is not None:
        big = np.abs(np.nan_to_num(m)) > TORQUE_MAX_NM
        if big.any():
            raise error(f"load_torque_Nm (line {first(big)})", f"{m[big][0]:g} N m is beyond "
                        f"±{TORQUE_MAX_NM:g} N m, more than any motor spindle delivers",
                        "export the process load torque in N m")


# ============================================================================ spec


def stuck_channels(run: BenchRun, channels: list[str]) -> list[str]:
    """The ``channels`` whose valid samples all read one value. A sensor on a spindle shows
    at least its noise or its room's drift over a run, so such a channel is stuck or not
    connected; it carries nothing to fit."""
    out = []
    for c in channels:
        y = run.columns[CHANNEL_COLUMNS[c]]
        y = y[~np.isnan(y)]
        if len(y) > 1 and float(np.max(y)) == float(np.min(y)):
            out.append(c)
    return out


def check_against_spec(run: BenchRun, spec: Spec) -> list[str]:
    """The measured channels of ``run`` that map to a sensor of ``spec`` with the same name
    and kind (T1, T2, T_stator: ``temperature``; P1: ``axial_displacement``), in the order of
    :attr:`BenchRun.channels`.

    A channel without such a sensor is skipped with a :class:`BenchWarning` naming the column
    and the fix; if no channel maps, InputError.
    """
    sensors = {s.name: s for s in spec.sensors}
    mapped: list[str] = []
    for ch in run.channels:
        col, kind = CHANNEL_COLUMNS[ch], CHANNEL_KINDS[ch]
        s = sensors.get(ch)
        if s is not None and s.kind == kind:
            mapped.append(ch)
            continue
        why = (f"the spec '{spec.name}' has no sensor '{ch}'" if s is None
               else f"sensor '{ch}' of spec '{spec.name}' is of kind '{s.kind}', not '{kind}'")
        warnings.warn(BenchWarning(
            f"{run.path}: {col}: {why}; the column is skipped; fix: add a [[sensors]] entry "
            f"name = \"{ch}\" (kind {kind}) to {spec.path} to compare it"), stacklevel=2)
    if not mapped:
        cols = ", ".join(CHANNEL_COLUMNS[c] for c in run.channels)
        raise InputError(str(run.path), cols, f"no measured channel has a sensor of the same name "
                         f"and kind in the spec '{spec.name}' ({spec.path})",
                         f"add [[sensors]] named {', '.join(run.channels)} to the spec (T1, T2, "
                         "T_stator: temperature; P1: kind = \"axial_displacement\"), or use the "
                         "spec of the spindle on the bench")
    return mapped
