"""The code base passes ruff (configured in pyproject.toml)."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.skipif(importlib.util.find_spec("ruff") is None,
                    reason="ruff comes with the test extra")
def test_ruff_clean():
    r = subprocess.run([sys.executable, "-m", "ruff", "check", str(ROOT)], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_reference_and_lumped_never_import_each_other():
    """The brief's layering: both models read only the shared package (spindle/)."""
    for pkg, other in (("reference", "lumped"), ("lumped", "reference"),
                       ("spindle", "reference"), ("spindle", "lumped"), ("spindle", "compare"),
                       ("meshes", "reference"), ("meshes", "lumped")):
        for f in (ROOT / pkg).rglob("*.py"):
            text = f.read_text()
            assert f"from {other}" not in text and f"import {other}" not in text, (f, other)
