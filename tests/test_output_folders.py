"""Output folders (issue 14): a run replaces its folder as a whole or leaves it as it was;
a folder with files spindle-verify did not write is refused; a run killed by SIGTERM leaves
nothing behind, one killed by SIGKILL leaves a hidden folder that the next run removes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from spindle.errors import InputError
from spindle.outputs import MARKER, output_dir

ROOT = Path(__file__).resolve().parents[1]


def _write(folder: Path, name: str, text: str = "x") -> None:
    with output_dir(folder) as tmp:
        (tmp / name).write_text(text, encoding="utf-8")


def _hidden(parent: Path) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith("."))


def test_a_second_run_replaces_the_folder_as_a_whole(tmp_path):
    out = tmp_path / "res"
    _write(out, "old.txt")
    _write(out, "new.txt")
    assert sorted(p.name for p in out.iterdir()) == sorted([MARKER, "new.txt"])
    assert _hidden(tmp_path) == []


def test_a_failed_run_leaves_the_earlier_folder_as_it_was(tmp_path):
    out = tmp_path / "res"
    _write(out, "old.txt", "kept")
    with pytest.raises(RuntimeError), output_dir(out) as tmp:
        (tmp / "new.txt").write_text("half", encoding="utf-8")
        raise RuntimeError("the run failed")
    assert (out / "old.txt").read_text(encoding="utf-8") == "kept"
    assert not (out / "new.txt").exists()
    assert _hidden(tmp_path) == []


def test_a_folder_with_foreign_files_is_refused_before_any_work(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious", encoding="utf-8")
    with pytest.raises(InputError, match="did not write"), output_dir(out):
        pytest.fail("the body must not run")
    assert (out / "thesis.tex").read_text(encoding="utf-8") == "precious"
    assert sorted(p.name for p in out.iterdir()) == ["thesis.tex"]


def test_an_empty_folder_is_accepted(tmp_path):
    out = tmp_path / "empty"
    out.mkdir()
    _write(out, "a.txt")
    assert (out / "a.txt").exists()


def test_a_folder_holding_another_runs_output_is_not_replaced(tmp_path):
    outer, inner = tmp_path / "study", tmp_path / "study" / "fit-run"
    _write(outer, "report.html")
    _write(inner, "report.json")
    with pytest.raises(InputError, match="output of another run"), output_dir(outer):
        pytest.fail("the body must not run")
    assert (inner / "report.json").exists()


def test_the_default_output_folders_do_not_nest(capsys):
    """Each command's default is its own folder below results/<spec>/ (none is
    results/<spec> itself, which would hold the others and be replaced with them)."""
    from compare.cli import main

    for cmd in ("solve", "study", "measures", "fit", "sensors", "crosscheck", "mesh", "rom"):
        assert main([cmd, "--help"]) == 0
        line = " ".join(capsys.readouterr().out.split())
        assert "results/<spec>/" in line, (cmd, line)


SCRIPT = textwrap.dedent("""
    import signal, sys, time
    from pathlib import Path
    from compare.cli import _terminate
    from spindle.outputs import output_dir
    signal.signal(signal.SIGTERM, _terminate)
    try:
        with output_dir(Path(sys.argv[1])) as tmp:
            (tmp / "new.txt").write_text("half", encoding="utf-8")
            print("writing", flush=True)
            time.sleep(60)
    except KeyboardInterrupt:
        sys.exit(130)
""")


def _start(out: Path) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, "-c", SCRIPT, str(out)], cwd=ROOT,
                            stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "writing"
    return proc


def test_sigterm_while_writing_leaves_nothing_behind(tmp_path):
    out = tmp_path / "res"
    _write(out, "old.txt", "kept")
    proc = _start(out)
    assert any(n.startswith(".res.tmp-") for n in _hidden(tmp_path))
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=30) == 130
    assert _hidden(tmp_path) == []
    assert (out / "old.txt").read_text(encoding="utf-8") == "kept"


def test_sigkill_leftovers_are_removed_by_the_next_run(tmp_path):
    out = tmp_path / "res"
    _write(out, "old.txt")
    proc = _start(out)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    assert any(n.startswith(".res.tmp-") for n in _hidden(tmp_path))  # what a kill leaves
    _write(out, "next.txt")
    assert _hidden(tmp_path) == []
    assert (out / "next.txt").exists()


def test_a_run_killed_between_its_two_renames_gets_its_folder_back(tmp_path):
    """The old folder moved aside (``.NAME.old-PID-*``) by a process that is gone, and the
    new one not yet in place: the next run into the folder puts the old one back first."""
    out = tmp_path / "res"
    _write(out, "old.txt", "kept")
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    aside = tmp_path / f".res.old-{dead.pid}-abc"
    os.rename(out, aside)
    from spindle.outputs import _clean_leftovers

    _clean_leftovers(tmp_path, "res")
    assert (out / "old.txt").read_text(encoding="utf-8") == "kept"
    assert _hidden(tmp_path) == []


def test_sigterm_during_a_cli_run_exits_130_and_writes_nothing(tmp_path):
    """The command line's own SIGTERM handling (compare.cli.main): a transient solve killed
    after two seconds exits 130 and leaves neither the folder nor a hidden one."""
    out = tmp_path / "res"
    proc = subprocess.Popen([sys.executable, "-m", "compare.cli", "solve", "spl2782",
                             "--cycle", "spl-16h", "--level", "2", "--out", str(out)],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    time.sleep(2.0)
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(timeout=60)
    err = proc.stderr.read()
    assert code == 130 or (code == 0 and out.exists()), err  # 0 only if it had finished
    assert "Traceback" not in err
    assert _hidden(tmp_path) == []
    if code == 130:
        assert not out.exists()
