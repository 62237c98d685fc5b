"""The figures file a benchmark writes for the docs to quote: its rows with the date, the
commit and the command that made them, written atomically (docs/figures/*.json; the tests
in tests/test_docs_snippets.py check that the docs quote them)."""

from __future__ import annotations

import datetime
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the project's top-level packages (pyproject.toml's [tool.setuptools.packages.find])
PACKAGES = ("spindle", "meshes", "reference", "lumped", "compare", "spindle_verify")


def checkout_difference() -> str | None:
    """None when Python imports this checkout's code, else what differs: a benchmark run as
    ``python benchmarks/x.py`` puts benchmarks/, not the checkout, on the path, so it measures
    the installed copy, and a figures file would record HEAD for code that is not HEAD's."""
    import importlib.util

    for name in PACKAGES:
        spec = importlib.util.find_spec(name)
        if spec is None or spec.origin is None:
            return f"the package {name} is not installed"
        where = Path(spec.origin).resolve().parent
        mine = ROOT / name
        if where == mine:
            continue
        for src in sorted(mine.rglob("*.py")):
            rel = src.relative_to(ROOT)
            other = where / src.relative_to(mine)
            if not other.is_file() or other.read_bytes() != src.read_bytes():
                return f"{rel} differs from the copy Python imports, {other}"
    return None


def require_checkout() -> None:
    """Exit with status 2 and one message when the imported code is not this checkout's."""
    diff = checkout_difference()
    if diff is not None:
        print(f"benchmarks measure this checkout's code, but {diff}. Install the checkout "
              f"first: python -m pip install -e {ROOT}", file=sys.stderr)
        sys.exit(2)


# every script of benchmarks/ that writes figures or verdicts measures the checkout's code
require_checkout()


def write_figures(path: Path, made_by: str, fields: dict) -> None:
    """``fields`` with ``date``, ``commit`` (short hash of HEAD) and ``made_by`` in front,
    as indented JSON at ``path`` (replaced only once written)."""
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    doc = {"date": datetime.date.today().isoformat(), "commit": commit, "made_by": made_by,
           **fields}
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(".tmp")
    tmp.write_text(json.dumps(doc, indent=1) + "\n", encoding="utf-8")
    tmp.replace(path)


def memory_MB(field: str = "VmHWM") -> float:
    """A memory figure of this process from /proc [MB]: ``VmHWM`` its peak resident memory
    since exec (getrusage's ru_maxrss carries the parent's over exec), ``VmRSS`` now."""
    with open(f"/proc/{os.getpid()}/status") as f:
        for line in f:
            if line.startswith(field):
                return int(line.split()[1]) / 1024
    return float("nan")
