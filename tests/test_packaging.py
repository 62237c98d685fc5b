"""The installed package holds every package of the source tree: pyproject.toml's package
discovery finds each folder with an ``__init__.py`` below the five top-level folders. The
tests run from the checkout, where a package missing from the distribution still imports; a
user's ``pip install .`` would not have it (compare.fit.effects was left out once, and every
``spindle-verify`` command failed at start-up)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from setuptools import find_namespace_packages, find_packages

ROOT = Path(__file__).resolve().parents[1]
TOP = ("spindle", "meshes", "reference", "lumped", "compare")


def _configured() -> set[str]:
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    find = cfg["tool"]["setuptools"]["packages"]["find"]
    return set(find_packages(where=str(ROOT), include=find["include"],
                             exclude=find.get("exclude", ())))


def _in_tree() -> set[str]:
    return {".".join(p.relative_to(ROOT).parts) for top in TOP
            for p in [ROOT / top, *(ROOT / top).rglob("*")]
            if p.is_dir() and (p / "__init__.py").is_file()}


def test_every_package_of_the_tree_is_distributed():
    found = _configured()
    assert _in_tree() <= found, sorted(_in_tree() - found)
    assert "compare.fit.effects" in found and "reference.rom" in found


def test_no_folder_of_python_modules_lacks_its_init():
    """A folder of modules without ``__init__.py`` is a namespace package that find_packages
    skips: each must be a regular package."""
    namespace = {p for p in find_namespace_packages(where=str(ROOT), include=[f"{t}*" for t in TOP])
                 if any((ROOT.joinpath(*p.split("."))).glob("*.py"))}
    assert namespace <= _in_tree(), sorted(namespace - _in_tree())
