"""The benchmarks measure the checkout's code (benchmarks/figures.py): run as
``python benchmarks/x.py``, a script imports the installed package, not the folder beside it,
so a non-editable install of an older tree would be measured under the checkout's commit."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _figures(monkeypatch):
    monkeypatch.syspath_prepend(str(ROOT / "benchmarks"))
    import figures

    return figures


def test_this_environment_imports_the_checkout(monkeypatch):
    """Editable or not, the code the tests run is the checkout's (CI installs it with pip)."""
    assert _figures(monkeypatch).checkout_difference() is None


def test_a_tree_that_differs_from_the_imported_code_is_named(monkeypatch, tmp_path):
    """A copy of the checkout with one file changed: the file is named, as the imported copy
    no longer matches it."""
    figures = _figures(monkeypatch)
    for name in figures.PACKAGES:
        shutil.copytree(ROOT / name, tmp_path / name,
                        ignore=shutil.ignore_patterns("__pycache__"))
    changed = tmp_path / "compare" / "fit" / "linear.py"
    changed.write_text(changed.read_text(encoding="utf-8") + "\n# changed\n", encoding="utf-8")
    monkeypatch.setattr(figures, "ROOT", tmp_path)
    diff = figures.checkout_difference()
    assert diff is not None and diff.startswith("compare/fit/linear.py differs"), diff


def test_a_benchmark_refuses_other_code_with_status_2(monkeypatch, tmp_path):
    """The same from the command line: one message naming the file and the fix, status 2, no
    traceback (a copy of benchmarks/ beside a changed tree)."""
    shutil.copytree(ROOT / "benchmarks", tmp_path / "benchmarks",
                    ignore=shutil.ignore_patterns("__pycache__", ".families-cache"))
    for name in _figures(monkeypatch).PACKAGES:
        shutil.copytree(ROOT / name, tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    changed = tmp_path / "spindle" / "outputs.py"
    changed.write_text(changed.read_text(encoding="utf-8") + "\n# changed\n", encoding="utf-8")
    r = subprocess.run([sys.executable, str(tmp_path / "benchmarks" / "compare_reports.py"),
                        "a", "b"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "spindle/outputs.py differs" in r.stderr and "pip install -e" in r.stderr
    assert "Traceback" not in r.stderr
