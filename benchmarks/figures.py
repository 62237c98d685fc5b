"""The figures file a benchmark writes for the docs to quote: its rows with the date, the
commit and the command that made them, written atomically (docs/figures/*.json; the tests
in tests/test_docs_snippets.py check that the docs quote them)."""

from __future__ import annotations

import datetime
import json
import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


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
