"""Property-based fuzzing of the bench and cycle readers (issue 14): a mutated file is read or
refused with one SpindleVerifyError that names the file, the field (or line/column) and the
fix; never another exception, never a hang. Valid variants (CRLF, a byte-order mark, quoted
cells, padded headers, unknown columns with a 1 MB cell) are read. 200 + 150 examples here;
``pytest -m slow`` runs 2000 of each."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from spindle.errors import SpindleVerifyError

BUDGET = int(os.environ.get("SPINDLE_FUZZ_EXAMPLES", "0"))  # 0: the defaults below
FUZZ = settings(deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                      HealthCheck.function_scoped_fixture])


def _bench_text(n: int = 240) -> str:
    """A valid 40 min bench export at 10 s: 0 rpm, then 3000 rpm, the channels warming."""
    head = ("# spindle: spl2782\n# bench: fuzz\n"
            "time_s,speed_rpm,power_kW,T_env_C,T_coolant_C,T1_C,T2_C,T_stator_C,P1_um\n")
    rows = []
    for i in range(n):
        t = 10.0 * i
        n_rpm = 0.0 if t < 600 else 3000.0
        warm = 0.0 if t < 600 else 1.0 - np.exp(-(t - 600) / 900)
        rows.append(f"{t:g},{n_rpm:g},{0.4 * (n_rpm > 0):.3f},20.0,19.8,{20 + 3 * warm:.2f},"
                    f"{20 + 2 * warm:.2f},{20 + 4 * warm:.2f},{1.5 * warm:.2f}")
    return head + "\n".join(rows) + "\n"


BENCH = _bench_text()
BAD_CELLS = ["nan", "inf", "-inf", "1e308", "-1e308", "1e400", "abc", "", "0x10", "1,5", '"3"',
             " 3 ", "∞", "\x00", "-0", "1e-320", "9" * 400, "NaN", "+", "--1", "1e", "١٢"]


def _cell_mutation(text: str, data) -> str:
    lines = text.split("\n")
    body = [i for i, ln in enumerate(lines) if ln and not ln.startswith("#")][1:]
    i = data.draw(st.sampled_from(body))
    cells = lines[i].split(",")
    j = data.draw(st.integers(0, len(cells) - 1))
    cells[j] = data.draw(st.sampled_from(BAD_CELLS))
    lines[i] = ",".join(cells)
    return "\n".join(lines)


def _with_header(lines: list[str], header: int, cols: list[str]) -> str:
    return "\n".join([*lines[:header], ",".join(cols), *lines[header + 1:]])


def _rows(lines: list[str], header: int, f) -> str:
    """Every data row (after the header, not empty) through ``f``."""
    return "\n".join(ln if k <= header or not ln else f(ln) for k, ln in enumerate(lines))


def _swap(lines: list[str], k: int) -> str:
    lines = list(lines)
    lines[k], lines[k + 1] = lines[k + 1], lines[k]
    return "\n".join(lines)


def _repeat_time(lines: list[str], k: int) -> str:
    lines = list(lines)
    lines[k] = ",".join([lines[k - 1].split(",")[0], *lines[k].split(",")[1:]])
    return "\n".join(lines)


def _renamed(cols: list[str], data) -> list[str]:
    cols = list(cols)
    cols[data.draw(st.integers(0, len(cols) - 1))] = data.draw(st.sampled_from(
        ["time", "speed", "T1", "P1_mm", "power_W", "", " ", "T1_C T2_C"]))
    return cols


def _truncated(raw: bytes, data) -> bytes:
    return raw[:data.draw(st.integers(0, len(raw) - 1))]


def _with_garbage(raw: bytes, data) -> bytes:
    k = data.draw(st.integers(0, len(raw)))
    return raw[:k] + data.draw(st.binary(min_size=1, max_size=64)) + raw[k:]


def _blank_column(ln: str, j: int) -> str:
    return ",".join("" if m == j else c for m, c in enumerate(ln.split(",")))


#: structural breaks: name -> f(lines, header index, header cells, hypothesis data)
STRUCTURAL = {
    "drop_column_name": lambda ls, h, cols, d: (lambda j: _with_header(
        ls, h, [c for k, c in enumerate(cols) if k != j]))(d.draw(st.integers(0, len(cols) - 1))),
    "drop_header": lambda ls, h, cols, d: "\n".join(ls[:h] + ls[h + 1:]),
    "duplicate_column": lambda ls, h, cols, d: _with_header(
        ls, h, [*cols[:-1], cols[d.draw(st.integers(0, len(cols) - 1))]]),
    "truncate": lambda ls, h, cols, d: _truncated("\n".join(ls).encode(), d),
    "binary": lambda ls, h, cols, d: _with_garbage("\n".join(ls).encode(), d),
    "swap_rows": lambda ls, h, cols, d: _swap(ls, d.draw(st.integers(h + 1,
                                                                     max(h + 1, len(ls) - 3)))),
    "semicolons": lambda ls, h, cols, d: "\n".join(ls).replace(",", ";"),
    "empty": lambda ls, h, cols, d: b"",
    "comments_only": lambda ls, h, cols, d: "\n".join(ls[:h]),
    "kelvin": lambda ls, h, cols, d: _with_header(ls, h, [
        c.rsplit("_", 1)[0] + "_K" if c.endswith("_C") else c for c in cols]),
    "trailing_comma": lambda ls, h, cols, d: "\n".join(
        ln + "," if ln and not ln.startswith("#") else ln for ln in ls),
    "repeat_time": lambda ls, h, cols, d: _repeat_time(ls, d.draw(st.integers(
        h + 2, max(h + 2, len(ls) - 2)))),
    "rename_column": lambda ls, h, cols, d: _with_header(ls, h, _renamed(cols, d)),
    "only_header": lambda ls, h, cols, d: "\n".join(ls[:h + 1]),
    "huge_time": lambda ls, h, cols, d: "\n".join([*ls[:-2], ",".join(
        [d.draw(st.sampled_from(["1e15", "1e300", "3.6e9"])), *ls[-2].split(",")[1:]]), ls[-1]]),
    "all_empty_channel": lambda ls, h, cols, d: (lambda j: _rows(
        ls, h, lambda ln: _blank_column(ln, j)))(d.draw(st.integers(0, len(cols) - 1))),
}


def _structural_mutation(text: str, data) -> str | bytes:
    lines = text.split("\n")
    header = next(i for i, ln in enumerate(lines) if ln and not ln.startswith("#"))
    kind = data.draw(st.sampled_from(sorted(STRUCTURAL)))
    return STRUCTURAL[kind](lines, header, lines[header].split(","), data)


def _write(tmp_path_factory, name: str, content: str | bytes) -> Path:
    p = tmp_path_factory.mktemp("fuzz") / name
    p.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8", "replace"))
    return p


def _ingest_bench(path: Path) -> None:
    """What ``fit`` does with a bench file before calibrating."""
    from compare.fit.criteria import Criteria
    from compare.fit.run import _measured
    from spindle.bench import check_against_spec, read_bench
    from spindle.bench_inputs import interval_inputs
    from spindle.spec_reader import load_spec

    run = read_bench(path)
    channels = check_against_spec(run, load_spec("spl2782"))
    inputs = interval_inputs(run, 60.0)
    _measured(run, channels, inputs.grid_s, 0.6, 1, Criteria())
    assert np.all(np.isfinite(inputs.speed_rpm)) and np.all(np.isfinite(inputs.T_env_K))


def _refused_cleanly(exc: SpindleVerifyError, path: Path) -> None:
    problems = getattr(exc, "problems", None) or [exc.problem]
    assert len(problems) == 1, problems  # one root cause
    pr = problems[0]
    assert pr.field and pr.fix and pr.message, pr
    assert str(path) in pr.file or path.name in pr.file or pr.file == "command line", pr


def _check_bench(path: Path) -> None:
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            _ingest_bench(path)
        except SpindleVerifyError as exc:
            _refused_cleanly(exc, path)


@pytest.mark.parametrize("where", ["first line", "data row after a comment"])
def test_a_bare_carriage_return_is_read_or_refused_cleanly(tmp_path_factory, where):
    """Found by the larger budget (2026-11-29): '\r\x80' before the first line made the
    header's csv.reader fail ("new-line character seen in unquoted field"), an internal
    error. A carriage return is a line end or nothing, never a cell's text."""
    lines = BENCH.split("\n")
    if where == "first line":
        text = "\r\x80" + BENCH
    else:  # a comment among the rows takes the reader's line-by-line path
        k = next(i for i, ln in enumerate(lines) if ln.startswith("time_s")) + 3
        text = "\n".join(lines[:k] + ["# a note", "\r" + lines[k]] + lines[k + 1:])
    _check_bench(_write(tmp_path_factory, "run.csv", text))


@settings(FUZZ, max_examples=BUDGET or 200)
@given(data=st.data(), structural=st.booleans())
def test_a_mutated_bench_file_is_read_or_refused_cleanly(tmp_path_factory, data, structural):
    text = _structural_mutation(BENCH, data) if structural else _cell_mutation(BENCH, data)
    _check_bench(_write(tmp_path_factory, "run.csv", text))


STEP_CSV = "speed_rpm,duration_s,load_torque_Nm\n1000,3600,0\n3000,1800,10\n0,3600,0\n"
SERIES_CSV = ("time_s,speed_rpm,T_env_C,T_coolant_C\n0,0,20,19.8\n600,3000,20.2,19.9\n"
              "3600,3000,20.5,20.0\n7200,0,20.4,19.9\n")


def _check_cycle(path: Path) -> None:
    from spindle.drive import load_case
    from spindle.loads import time_grid
    from spindle.spec_reader import load_spec

    try:
        case = load_case(load_spec("spl2782"), path)
        grid = time_grid(case, 60.0)
        assert np.all(np.isfinite(grid)) and len(grid) < 10_000_000
    except SpindleVerifyError as exc:
        _refused_cleanly(exc, path)


@settings(FUZZ, max_examples=BUDGET or 150)
@given(data=st.data(), base=st.sampled_from([STEP_CSV, SERIES_CSV]), structural=st.booleans())
def test_a_mutated_cycle_file_is_read_or_refused_cleanly(tmp_path_factory, data, base,
                                                         structural):
    text = _structural_mutation(base, data) if structural else _cell_mutation(base, data)
    _check_cycle(_write(tmp_path_factory, "cycle.csv", text))


@pytest.mark.parametrize("variant", ["crlf", "bom", "quoted", "padded", "unknown_1MB",
                                     "reordered", "comment_lines"])
def test_valid_bench_variants_are_read(tmp_path, variant):
    from spindle.bench import read_bench

    text = BENCH
    if variant == "crlf":
        text = text.replace("\n", "\r\n")
    elif variant == "bom":
        text = "\ufeff" + text
    elif variant == "quoted":
        text = "\n".join(ln if ln.startswith("#") or not ln else
                         ",".join(f'"{c}"' for c in ln.split(",")) for ln in text.split("\n"))
    elif variant == "padded":
        text = text.replace("time_s,speed_rpm,power_kW", " time_s , speed_rpm ,power_kW ")
    elif variant == "unknown_1MB":
        lines = text.split("\n")
        lines[2] += ",notes_text"
        lines[3] += "," + "x" * 1_000_000
        lines[4:] = [ln + "," if ln else ln for ln in lines[4:]]
        text = "\n".join(lines)
    elif variant == "reordered":
        lines = text.split("\n")
        rows = [ln.split(",") for ln in lines[2:] if ln]
        order = [8, 0, 2, 1, 3, 4, 7, 6, 5]
        text = "\n".join(lines[:2] + [",".join(r[k] for k in order) for r in rows]) + "\n"
    elif variant == "comment_lines":
        text = text.replace("# bench: fuzz\n", "# bench: fuzz\n#\n# started: 2026-03-02\n")
    p = tmp_path / "run.csv"
    p.write_bytes(text.encode("utf-8"))
    run = read_bench(p)
    assert len(run.time_s) == 240
    t, y = run.channel("T1")
    assert abs(float(np.nanmax(y)) - (273.15 + 20 + 3 * (1 - np.exp(-1800 / 900)))) < 0.02


@pytest.mark.slow
def test_fuzz_at_a_larger_budget():
    """The two properties above at 2000 examples each (about ten minutes)."""
    import subprocess
    import sys

    env = dict(os.environ, SPINDLE_FUZZ_EXAMPLES="2000")
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", __file__,
                        "-k", "mutated"], env=env, capture_output=True, text=True,
                       cwd=Path(__file__).resolve().parents[1])
    assert r.returncode == 0, r.stdout[-4000:]
