"""The installed package holds every package of the source tree: pyproject.toml's package
discovery finds each folder with an ``__init__.py`` below the six top-level folders. The
tests run from the checkout, where a package missing from the distribution still imports; a
user's ``pip install .`` would not have it (compare.fit.effects was left out once, and every
``spindle-verify`` command failed at start-up)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from setuptools import find_namespace_packages, find_packages

ROOT = Path(__file__).resolve().parents[1]
TOP = ("spindle", "meshes", "reference", "lumped", "compare", "spindle_verify")


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


def test_the_plugin_imports_nothing_a_users_project_may_shadow():
    """pytest loads spindle_verify.pytest_plugin in every session of the environment: it must
    import only pytest, not the project's generic top-level names (issue 34)."""
    import subprocess
    import sys

    code = ("import sys, spindle_verify.pytest_plugin; "
            "print(sorted(m for m in ('compare', 'spindle', 'reference', 'lumped', 'meshes', "
            "'numpy', 'scipy', 'skfem') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"


def test_a_project_with_its_own_compare_package_runs_its_tests(tmp_path):
    """A user's project with its own ``compare/`` and ``spindle/`` packages at its root, in an
    environment where spindle-verify is installed: ``python -m pytest`` there imports the
    user's packages, and the session (our plugin loaded by its entry point) runs their test;
    the fixture is offered to it."""
    import subprocess
    import sys

    for name in ("compare", "spindle"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "__init__.py").write_text(f"WHO = 'the user of {name}'\n")
    (tmp_path / "tests").mkdir()
    (tmp_path / "tests" / "test_mine.py").write_text(
        "import compare\n"
        "import spindle\n"
        "\n"
        "def test_my_packages(request):\n"
        "    assert compare.WHO == 'the user of compare'\n"
        "    assert spindle.WHO == 'the user of spindle'\n"
        "    request.getfixturevalue('spindle_verify')  # our plugin is loaded\n")
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                          "tests"], cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    assert "1 passed" in run.stdout
