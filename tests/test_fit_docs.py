"""docs/fit.md cannot go stale: its library table is the registry's, its criteria rows are
``Criteria().table()``'s, and its generalisation figures are the file the benchmark wrote
(docs/figures/fit-families.txt, from ``python benchmarks/bench_families.py``)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOC = (ROOT / "docs" / "fit.md").read_text(encoding="utf-8")


def _block(name: str) -> str:
    m = re.search(rf"<!-- {name}:begin -->\n(.*?)<!-- {name}:end -->", DOC, re.S)
    assert m, f"docs/fit.md has no {name} block"
    return m.group(1)


def _rows(block: str) -> list[list[str]]:
    rows = [[c.strip() for c in line.strip().strip("|").split("|")]
            for line in block.splitlines() if line.startswith("|")]
    return rows[2:]  # header and rule


def test_the_library_table_is_the_registry():
    from compare.fit.effects import LIBRARY
    from compare.fit.effects.base import Effect

    rows = {re.match(r"`(\w+)`", r[0]).group(1): r for r in _rows(_block("library"))}
    assert set(rows) == set(LIBRARY)
    for name, effect in LIBRARY.items():
        documented = re.findall(r"`(\w+)`", rows[name][1])
        assert documented == [p.name for p in effect.params], name
        has_test = type(effect).signature is not Effect.signature
        assert (not rows[name][2].startswith("none")) == has_test, name
        assert ("per channel" in rows[name][0]) == effect.per_channel, name


def test_the_criteria_rows_are_the_table_the_fit_runs_with():
    from compare.fit.criteria import Criteria

    table = {r["name"]: r for r in Criteria().table()}
    rows = _rows(_block("criteria"))
    assert rows
    for name, value, unit in rows:
        name = name.strip("`")
        assert name in table, name
        assert value == str(table[name]["value"]), (name, value, table[name]["value"])
        assert unit == table[name]["unit"], name


def test_the_generalisation_figures_are_the_benchmarks_file():
    generated = (ROOT / "docs" / "figures" / "fit-families.txt").read_text(encoding="utf-8")
    block = _block("families").strip()
    assert block.startswith("```") and block.endswith("```"), "a fenced copy of the file"
    assert block.strip("`").strip() == generated.strip()


@pytest.mark.parametrize(("block", "off_file", "on_file"), [
    ("trade", "fit-families-material-change-off.txt", "fit-families-before-held-out-misfit.txt"),
    ("trade-held-out", "fit-families-before-held-out-misfit.txt", "fit-families.txt")])
def test_the_trade_table_is_the_two_files(block, off_file, on_file):
    """docs/fit.md's tables of a rule's trade quote the rates of the run without the rule and
    with it (the generated summaries), line by line."""
    figures = ROOT / "docs" / "figures"
    off = (figures / off_file).read_text(encoding="utf-8")
    on = (figures / on_file).read_text(encoding="utf-8")
    rows = _rows(_block(block))
    assert rows
    for rate, a, b in rows:
        for text, cell in ((off, a), (on, b)):
            k, n = (int(x) for x in cell.split(" of "))
            assert re.search(rf"^  {re.escape(rate)}\s+{k} of\s+{n}\s", text, re.M), (rate, cell)
