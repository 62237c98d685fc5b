"""Output folders (issues 14, 31): a run replaces what an earlier run wrote or leaves it as it
was; a folder holding anything spindle-verify did not write there (a file a user added, one of
the tool's files the user edited) is refused with exit 2, and with ``--force`` those files are
moved aside, never deleted; a run killed by SIGTERM leaves nothing behind, one killed by
SIGKILL leaves a hidden folder that the next run removes."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from spindle.errors import InputError
from spindle.outputs import MARKER, check_output_dir, output_dir

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
    with pytest.raises(InputError, match="did not write.*thesis.tex"), output_dir(out):
        pytest.fail("the body must not run")
    assert (out / "thesis.tex").read_text(encoding="utf-8") == "precious"
    assert sorted(p.name for p in out.iterdir()) == ["thesis.tex"]


def test_a_file_added_to_an_earlier_runs_folder_is_refused(tmp_path):
    out = tmp_path / "res"
    _write(out, "table.csv")
    (out / "sub").mkdir()
    (out / "sub" / "notes.txt").write_text("mine", encoding="utf-8")
    with pytest.raises(InputError, match="sub/notes.txt") as err, output_dir(out):
        pytest.fail("the body must not run")
    assert "--force" in str(err.value)
    assert (out / "sub" / "notes.txt").read_text(encoding="utf-8") == "mine"
    assert (out / "table.csv").exists()


def test_a_file_of_the_tools_edited_by_the_user_is_refused(tmp_path):
    out = tmp_path / "res"
    _write(out, "table.csv", "1,2")
    (out / "table.csv").write_text("1,2 and my remark", encoding="utf-8")
    with pytest.raises(InputError, match="table.csv was edited since"), output_dir(out):
        pytest.fail("the body must not run")
    assert (out / "table.csv").read_text(encoding="utf-8") == "1,2 and my remark"


def test_force_moves_the_users_files_aside_and_deletes_none(tmp_path, capsys):
    out = tmp_path / "res"
    _write(out, "table.csv", "1,2")
    (out / "table.csv").write_text("edited", encoding="utf-8")
    (out / "sub").mkdir()
    (out / "sub" / "notes.txt").write_text("mine", encoding="utf-8")
    with output_dir(out, force=True) as tmp:
        (tmp / "table.csv").write_text("3,4", encoding="utf-8")
    kept = [p for p in tmp_path.iterdir() if p.name.startswith("res.kept-")]
    assert len(kept) == 1, list(tmp_path.iterdir())
    assert (kept[0] / "table.csv").read_text(encoding="utf-8") == "edited"
    assert (kept[0] / "sub" / "notes.txt").read_text(encoding="utf-8") == "mine"
    assert (out / "table.csv").read_text(encoding="utf-8") == "3,4"
    assert not (out / "sub").exists()
    assert str(kept[0]) in capsys.readouterr().err
    assert _hidden(tmp_path) == []
    _write(out, "table.csv", "5,6")  # the new folder is the tool's alone again: no --force


def test_a_file_added_during_the_run_is_refused_at_the_replacement(tmp_path):
    out = tmp_path / "res"
    _write(out, "old.txt", "kept")
    with pytest.raises(InputError, match="late.txt"), output_dir(out) as tmp:
        (tmp / "new.txt").write_text("new", encoding="utf-8")
        (out / "late.txt").write_text("mine", encoding="utf-8")
    assert (out / "late.txt").read_text(encoding="utf-8") == "mine"
    assert (out / "old.txt").read_text(encoding="utf-8") == "kept"
    assert not (out / "new.txt").exists()
    assert _hidden(tmp_path) == []


def test_a_folder_of_an_older_version_without_a_manifest_is_refused(tmp_path):
    """A plain-text marker lists nothing, so nothing in the folder is known to be the tool's."""
    out = tmp_path / "res"
    out.mkdir()
    (out / MARKER).write_text("written by spindle-verify\n", encoding="utf-8")
    (out / "table.csv").write_text("1,2", encoding="utf-8")
    with pytest.raises(InputError, match="table.csv"), output_dir(out):
        pytest.fail("the body must not run")


def test_the_cli_refuses_a_users_file_with_exit_2_and_force_keeps_it(tmp_path):
    """Issue 31's steps: a steady lumped solve, a note added to its folder, the same solve
    again: exit 2 naming the note, which is still there; with --force it is moved aside."""
    out = tmp_path / "dl" / "out"
    cmd = [sys.executable, "-m", "compare.cli", "solve", "spl2782", "--model", "lumped",
           "--nodes", "5", "--no-pictures", "--quiet", "--out", str(out)]
    first = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr
    (out / "notes.txt").write_text("notes\n", encoding="utf-8")
    again = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    assert again.returncode == 2, again.stderr
    assert "notes.txt" in again.stderr and "--out" in again.stderr
    assert "Traceback" not in again.stderr
    assert (out / "notes.txt").read_text(encoding="utf-8") == "notes\n"
    forced = subprocess.run([*cmd, "--force"], cwd=ROOT, capture_output=True, text=True)
    assert forced.returncode == 0, forced.stderr
    kept = list((tmp_path / "dl").glob("out.kept-*/notes.txt"))
    assert [k.read_text(encoding="utf-8") for k in kept] == ["notes\n"]
    assert not (out / "notes.txt").exists()


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
    with output_dir(outer, force=True) as tmp:  # forced: the other run's folder moved aside
        (tmp / "report.html").write_text("new", encoding="utf-8")
    assert [p.relative_to(tmp_path).as_posix() for p in tmp_path.glob("study.kept-*/**/*.json")] \
        == [f"{p.name}/fit-run/report.json" for p in tmp_path.glob("study.kept-*")]


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
    once it is at work (its first progress line, printed after main installs the handler:
    a fixed two seconds was before the handler on a loaded machine, where Python's imports
    take longer) exits 130 and leaves neither the folder nor a hidden one."""
    import select

    out = tmp_path / "res"
    proc = subprocess.Popen([sys.executable, "-m", "compare.cli", "solve", "spl2782",
                             "--cycle", "spl-16h", "--level", "2", "--out", str(out)],
                            cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    assert select.select([proc.stderr], [], [], 60.0)[0], "no progress line within 60 s"
    first = proc.stderr.readline()
    proc.send_signal(signal.SIGTERM)
    code = proc.wait(timeout=60)
    err = first + proc.stderr.read()
    assert code == 130 or (code == 0 and out.exists()), err  # 0 only if it had finished
    assert "Traceback" not in err
    assert _hidden(tmp_path) == []
    if code == 130:
        assert not out.exists()


def test_a_single_output_file_replaces_its_own_and_refuses_the_users(tmp_path):
    """synth's run and a baseline are single files, often written into a folder of the
    user's: an existing file there is replaced only if spindle-verify wrote it (its folder's
    record of names and SHA-256), never an input; with force a file of the user's is moved
    aside, not deleted."""
    from spindle.outputs import FILE_MARKER, check_output_file, write_output_file

    mine = tmp_path / "run.csv"
    mine.write_text("user data\n")
    with pytest.raises(InputError) as err:
        check_output_file(mine)
    assert err.value.problem.field == "--out" and "--force" in str(err.value)
    with pytest.raises(InputError):
        write_output_file(mine, lambda p: p.write_text("new\n"))
    assert mine.read_text() == "user data\n"
    with pytest.raises(InputError, match="is the input"):
        check_output_file(mine, inputs=[mine], force=True)
    write_output_file(mine, lambda p: p.write_text("new\n"), force=True)
    (kept,) = tmp_path.glob("run.kept-*.csv")
    assert kept.read_text() == "user data\n" and mine.read_text() == "new\n"
    assert (tmp_path / FILE_MARKER).is_file()
    check_output_file(mine)  # its own now: replaced without force
    write_output_file(mine, lambda p: p.write_text("newer\n"))
    assert mine.read_text() == "newer\n" and len(list(tmp_path.glob("run.kept-*"))) == 1
    mine.write_text("edited by the user\n")
    with pytest.raises(InputError, match="edited since"):
        check_output_file(mine)
    with pytest.raises(InputError, match="is a folder"):
        check_output_file(tmp_path)


def test_synth_and_baseline_never_write_over_a_users_file(tmp_path, capsys):
    """synth once replaced its own --cycle file with the run it made from it, and synth and
    baseline replaced any file at --out (a read-only bench export included)."""
    from compare.cli import main

    cycle = tmp_path / "steps.csv"
    cycle.write_text("speed_rpm,duration_s,load_torque_Nm\n1000,3600,0\n4300,3600,10\n")
    export = tmp_path / "export.csv"
    export.write_text("time_s,T1_C\n0,20\n")
    export.chmod(0o444)
    quick = ["--level", "0", "--quiet"]
    assert main(["synth", "--cycle", str(cycle), "--out", str(cycle), *quick]) == 2
    assert main(["synth", "--cycle", str(cycle), "--out", str(export), *quick]) == 2
    assert "did not write it" in capsys.readouterr().err
    assert cycle.read_text().startswith("speed_rpm,duration_s") and export.stat().st_size == 17
    assert main(["synth", "--cycle", str(cycle), "--out", str(export), "--force", *quick]) == 0
    (kept,) = tmp_path.glob("export.kept-*.csv")
    assert kept.read_text() == "time_s,T1_C\n0,20\n"
    assert export.read_text().startswith("# spindle: spl2782")
    assert main(["synth", "--cycle", str(cycle), "--out", str(export), "--seed", "1",
                 *quick]) == 0  # its own run: replaced
    base = tmp_path / "base.json"
    base.write_text("{}\n")
    args = ["baseline", "fin-shaft", "--steady-only", "--nodes", "5", "--out", str(base),
            "--quiet"]
    assert main(args) == 2 and base.read_text() == "{}\n"
    assert main([*args, "--force"]) == 0 and main(args) == 0
    assert len(list(tmp_path.glob("base.kept-*.json"))) == 1


def test_nothing_is_put_in_place_once_the_user_asked_the_run_to_stop(tmp_path, monkeypatch):
    """A SIGTERM's KeyboardInterrupt raised inside a finalizer is lost (Python prints
    'Exception ignored' and goes on): a fit told to stop so once wrote its whole output
    folder. The signal handler also records the request, and no output folder or file is
    put in place after it."""
    import signal as signals

    from compare.cli import _terminate
    from spindle import errors
    from spindle.outputs import atomic_write

    monkeypatch.setitem(errors.STOP, "requested", False)
    with pytest.raises(KeyboardInterrupt):
        _terminate(signals.SIGTERM, None)
    assert errors.STOP["requested"]
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt), output_dir(out) as tmp:
        (tmp / "report.json").write_text("{}")
    with pytest.raises(KeyboardInterrupt):
        atomic_write(tmp_path / "one.json", lambda p: p.write_text("{}"))
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_link_as_the_output_folder_is_refused(tmp_path):
    """A link given as --out was replaced by a folder (the user's link gone, nothing in its
    target, a hidden folder left beside it)."""
    target = tmp_path / "target"
    target.mkdir()
    link = tmp_path / "link"
    link.symlink_to(target)
    with pytest.raises(InputError, match="is a link"):
        check_output_dir(link, force=True)
    assert link.is_symlink() and sorted(p.name for p in tmp_path.iterdir()) == ["link", "target"]


@pytest.mark.parametrize("command", [["rom", "fin-shaft", "--level", "0", "--held-out"],
                                     ["sensors", "fin-shaft", "--level", "0", "--cases"]])
def test_a_cycle_file_given_is_an_input_even_with_force(tmp_path, capsys, command):
    """rom's and sensors' cycle files were not counted as inputs: --force moved one out of
    the --out folder that held it."""
    from compare.cli import main

    cycle = tmp_path / "c.toml"
    cycle.write_text('[cycle]\nsteps = [{ speed_rpm = 2000, duration_h = 1 }]\n')
    assert main([*command, str(cycle), "--out", str(tmp_path), "--force", "--quiet"]) == 2
    assert "holds the input" in capsys.readouterr().err
    assert cycle.is_file() and not list(tmp_path.parent.glob(f"{tmp_path.name}.kept-*"))


@pytest.mark.parametrize("command", [["fit", "--spec", "{spec}", str(ROOT / "tests" / "data" /
                                      "peer-runs" / "bench-runs" / "dev-01.csv")],
                                     ["study", "{spec}", "--steady-only"], ["mesh", "{spec}"]])
def test_the_drive_file_a_spec_names_is_an_input_even_with_force(tmp_path, capsys, command):
    """A spec naming its drive by a file beside it ([power_balance] preset = "../drive/d.toml"):
    the drive file was not counted as an input, so --force moved it out of the --out folder
    that held it, and fit then refused its own finished report for the missing drive. The
    drive file is an input like the spec (spindle.spec_reader.spec_files): exit 2, the drive
    where it was, nothing moved aside."""
    from compare.cli import main
    from spindle.spec_reader import shipped_drives, shipped_specs

    (tmp_path / "spec").mkdir()
    drive = tmp_path / "drive" / "d.toml"
    drive.parent.mkdir()
    drive.write_bytes(shipped_drives()["spl2782"].read_bytes())
    text = shipped_specs()["spl2782"].read_text(encoding="utf-8")
    assert 'preset = "spl2782"' in text
    spec = tmp_path / "spec" / "my.toml"
    spec.write_text(text.replace('preset = "spl2782"', 'preset = "../drive/d.toml"'),
                    encoding="utf-8")
    before = drive.read_bytes()
    args = [str(spec) if a == "{spec}" else a for a in command]
    code = main([*args, "--out", str(drive.parent), "--force", "--quiet"])
    assert code == 2 and "holds the input" in capsys.readouterr().err
    assert drive.read_bytes() == before
    assert not list(tmp_path.glob("drive.kept-*"))


def test_fit_writes_no_report_when_its_summary_refuses(tmp_path, capsys, monkeypatch):
    """fit composes what it prints (which reads the spec's drive again) before its report is
    put in place: a refusal there (a drive file removed during the run) exits 2 with nothing
    written, where it had exited 2 beside a finished report."""
    import compare.fit.report as report
    from compare.cli import main

    def refuse(rep):
        raise InputError("my.toml", "power_balance.preset", "gone", "put it back")

    monkeypatch.setattr(report, "summary_text", refuse)
    out = tmp_path / "fit"
    run = ROOT / "tests" / "data" / "peer-runs" / "bench-runs" / "dev-01.csv"
    # the lightest fit that reaches the summary (the refusal comes after every stage)
    assert main(["fit", str(run), "--out", str(out), "--no-pictures", "--quiet",
                 "--lumped-only", "--candidates", "fixture_expansion", "--cv-blocks", "0"]) == 2
    assert "power_balance.preset" in capsys.readouterr().err
    assert not out.exists() and os.listdir(tmp_path) == []
