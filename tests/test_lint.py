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


FEATURES = ("verify", "crosscheck", "fit", "design")


def _imports(path: Path) -> list[tuple[str, list[str]]]:
    """(module, imported names) of every import statement in a file, relative ones resolved."""
    import ast

    tree = ast.parse(path.read_text(encoding="utf-8"))
    inside = path.resolve().is_relative_to(ROOT)
    package = ".".join(path.resolve().relative_to(ROOT).parts[:-1]) if inside else ""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, []) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, base] if base else parts)
            out.append((base, [a.name for a in node.names]))
    return out


def test_nothing_below_compare_imports_compare():
    """spindle/, meshes/, reference/ (with its ROM) and lumped/ are the layers under compare/."""
    for pkg in ("spindle", "meshes", "reference", "lumped"):
        for f in (ROOT / pkg).rglob("*.py"):
            for mod, _ in _imports(f):
                assert not (mod == "compare" or mod.startswith("compare.")), (f, mod)


def test_features_use_no_private_names_of_another_feature():
    """A feature (compare/verify, crosscheck, fit, design) may import the lower layers and
    compare's shared modules (executor, progress, report), and another feature's public names,
    never another feature's private (underscore) names; nothing outside compare/cli imports
    compare/cli."""
    for feature in FEATURES:
        for f in (ROOT / "compare" / feature).rglob("*.py"):
            for mod, names in _imports(f):
                if mod.startswith("compare.cli"):
                    raise AssertionError(f"{f} imports the command line ({mod})")
                other = mod.split(".")[1] if mod.startswith("compare.") and mod.count(".") else None
                if other in FEATURES and other != feature:
                    private = [n for n in names if n.startswith("_")]
                    assert not private, f"{f} imports private {private} of {mod}"
                    assert not any(p.startswith("_") for p in mod.split(".")[2:]), (f, mod)


def test_lint_catches_a_private_import(tmp_path):
    """The import reader above sees a private name imported across features (so the rule
    can fail)."""
    f = tmp_path / "x.py"
    f.write_text("from compare.fit.greybox import _is_contact_link\nfrom . import y\n")
    assert ("compare.fit.greybox", ["_is_contact_link"]) in _imports(f)
