"""The one progress style (compare/progress.py): a rewritten bar on a terminal, a line per
stage and per 10 % in a log, nothing but the final line for a short run; and the commands
that use it (solve: few lines for a quick run, the set-up named before the heavy work)."""

from __future__ import annotations

import io
import subprocess
import sys
from pathlib import Path

import pytest

from compare.progress import DELAY_S, Progress
from spindle.outputs import atomic_write, expect_pictures

ROOT = Path(__file__).resolve().parents[1]


class FakeClock:
    """Seconds that move only when the test says so."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def make(tty: bool, quiet: bool = False) -> tuple[Progress, io.StringIO, FakeClock]:
    stream, clock = io.StringIO(), FakeClock()
    return Progress("solve", quiet=quiet, stream=stream, tty=tty, clock=clock, ticker=False), \
        stream, clock


def test_log_mode_writes_a_line_per_stage_and_per_10_percent_with_elapsed_seconds():
    progress, stream, clock = make(tty=False)
    progress.stage("meshing level 2 and assembling P2")
    clock.now = 2.0
    progress.tick()  # the ticker's call: the stage has run past the delay
    progress.stage("transient", 0.0)
    for k in range(1, 101):  # 100 steps of 1 % over 10 s: lines at 0, 10, ... 100 %
        clock.now = 2.0 + k / 10
        progress.fraction(k / 100)
    progress.fraction(1.0)  # reported again by the solver: not written twice
    progress.done()
    lines = stream.getvalue().splitlines()
    assert lines[0] == "solve: meshing level 2 and assembling P2  (2.0 s)"
    assert lines[1] == "solve: transient   0 %  (2.0 s)"
    assert [ln.split("transient")[1].split("%")[0].strip() for ln in lines[2:-1]] == \
        [str(p) for p in range(10, 101, 10)]
    assert lines[-2] == "solve: transient 100 %  (12.0 s)"
    assert lines[-1] == "solve: done in 12.0 s"
    assert "\r" not in stream.getvalue()  # a log gets plain lines


def test_log_mode_writes_a_quick_stage_once():
    """The lumped transient of a longer run (0.1 s after a 2 s set-up) writes its first line
    only: a stage's lines come at most every DELAY_S."""
    progress, stream, clock = make(tty=False)
    progress.stage("reading the spec")
    clock.now = 2.0
    progress.tick()
    progress.stage("transient", 0.0)
    for k in range(1, 961):
        clock.now = 2.0 + 0.1 * k / 960
        progress.fraction(k / 960)
        progress.tick()
    progress.done()
    assert stream.getvalue().splitlines() == ["solve: reading the spec  (2.0 s)",
                                              "solve: transient   0 %  (2.0 s)",
                                              "solve: done in 2.1 s"]


def test_terminal_mode_rewrites_one_bar_line():
    progress, stream, clock = make(tty=True)
    clock.now = 1.0
    progress.stage("transient", 0.0)
    clock.now = 3.1
    progress.fraction(0.42)
    progress.fraction(0.421)  # the same whole percent: no redraw
    text = stream.getvalue()
    assert "\n" not in text  # one line, rewritten in place
    assert text.count("\r") == 2
    assert text.endswith("solve: transient [####......]  42 %  3.1 s")
    progress.done()
    assert stream.getvalue().endswith("\r\033[Ksolve: done in 3.1 s\n")  # bar cleared, final line


def test_a_short_run_prints_only_its_final_line():
    """A 0.1 s lumped transient reported 11 lines before (0, 10, ... 100 %); now 1."""
    for tty in (False, True):
        progress, stream, clock = make(tty=tty)
        progress.stage("building the lumped model (11 nodes)")
        progress.stage("transient", 0.0)
        for k in range(1, 961):
            clock.now = 0.1 * k / 960
            progress.fraction(k / 960)
            progress.tick()
        progress.done()
        assert stream.getvalue().replace("\r\033[K", "") == "solve: done in 0.1 s\n"


def test_a_long_set_up_is_named_once_the_delay_has_passed():
    """No silence beyond the delay: the ticker (here called by hand) shows the stage."""
    progress, stream, clock = make(tty=False)
    progress.stage("meshing level 2 and assembling P2")
    progress.tick()
    assert stream.getvalue() == ""
    clock.now = DELAY_S
    progress.tick()
    progress.tick()  # written once, not at every tick
    assert stream.getvalue() == "solve: meshing level 2 and assembling P2  (0.5 s)\n"


def test_failures_are_kept_and_counted_messages_set_the_fraction():
    progress, stream, clock = make(tty=False)
    progress.say("[1/4] A_M=0.02 m2 FAILED: no convergence")  # at once, despite the delay
    clock.now = 1.0
    progress.say("[2/4] A_M=0.03 m2 done 0.4 s")
    lines = stream.getvalue().splitlines()
    assert lines == ["solve: [1/4] A_M=0.02 m2 FAILED: no convergence",
                     "solve: [2/4] A_M=0.03 m2 done 0.4 s  50 %  (1.0 s)"]


def test_quiet_prints_nothing():
    progress, stream, clock = make(tty=False, quiet=True)
    clock.now = 5.0
    progress.stage("transient", 0.5)
    progress.say("[1/2] x FAILED: y")
    progress.done()
    assert stream.getvalue() == ""


def test_pictures_are_counted_as_they_are_written(tmp_path):
    progress, stream, clock = make(tty=False)

    def render(tmp: Path) -> None:  # each picture takes 0.5 s
        clock.now += 0.5
        tmp.write_bytes(b"png")

    with progress.pictures():
        atomic_write(tmp_path / "summary.json", lambda tmp: tmp.write_text("{}"))  # not a picture
        clock.now = 1.0
        progress.tick()
        expect_pictures(2)
        for name in ("temperature_section.png", "temperature_3d.png"):
            atomic_write(tmp_path / name, render)
    atomic_write(tmp_path / "after.png", render)  # not listened to
    assert stream.getvalue().splitlines() == [
        "solve: writing the outputs  (1.0 s)",  # then "0 %" at 1.0 s: too soon after it
        "solve: rendering 2 pictures: 1/2 written, temperature_section.png  50 %  (1.5 s)",
        "solve: rendering 2 pictures: 2/2 written, temperature_3d.png 100 %  (2.0 s)"]


def _solve(*args: str, out: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "compare", "solve", "spl2782", *args,
                           "--out", str(out)], cwd=ROOT, capture_output=True, text=True,
                          timeout=600)


def test_a_quick_lumped_solve_prints_few_progress_lines(tmp_path):
    """A lumped steady solve and a lumped 16 h transient (each well under 2 s of work) print
    at most their set-up, picture and final lines to stderr, not one per 10 %."""
    steady = _solve("--model", "lumped", "--nodes", "11", "--case", "nominal",
                    out=tmp_path / "steady")
    transient = _solve("--model", "lumped", "--nodes", "11", "--cycle", "spl-16h",
                       "--no-pictures", out=tmp_path / "transient")
    for r in (steady, transient):
        assert r.returncode == 0, r.stderr
        lines = r.stderr.splitlines()
        assert lines and lines[-1].startswith("solve: done in "), r.stderr
        assert len(lines) <= 5, r.stderr  # was 11 lines for the transient alone
        assert "wrote " in r.stdout and "done in" not in r.stdout  # stdout: results only
    assert not any("transient 'spl-16h'  10 %" in ln for ln in transient.stderr.splitlines())


def test_a_fem_transient_names_its_set_up_first(tmp_path, monkeypatch, capsys):
    """``solve --cycle`` says what it builds before the heavy work (there were 3 s of silence
    before its first line at level 2). The short-run delay is set to 0 here so that every
    stage is written whatever the machine's speed; the order is what is checked."""
    from compare import cli, progress

    monkeypatch.setattr(progress, "DELAY_S", 0.0)
    assert cli.main(["solve", "spl2782", "--cycle", "spl-16h", "--level", "0", "--no-pictures",
                     "--out", str(tmp_path / "x")]) == 0
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("solve: reading the spec")
    assert lines[1].startswith("solve: meshing level 0 and assembling P2")
    transient = [ln for ln in lines if "transient 'spl-16h'" in ln]
    assert lines.index(transient[0]) == 2
    assert sum(" 100 %" in ln for ln in transient) == 1  # 100 % once
    assert len(transient) == 11  # 0, 10, ... 100 %: a log gets a line per 10 %
    assert lines[-1].startswith("solve: done in ")


def test_counted_cases_are_one_stage_with_a_line_per_10_percent_at_most_every_delay():
    """36 finished cases (the executor's "[k/36] ... done"), one every 0.125 s, in a log: a
    line once the run has lasted 0.5 s (case 4), then one per 10 % but at most one per
    0.5 s: 9 lines, not 36."""
    progress, stream, clock = make(tty=False)
    for k in range(1, 37):
        clock.now = 0.125 * k
        progress.say(f"[{k}/36] sweep point {k} done 0.1 s")
    lines = stream.getvalue().splitlines()
    assert lines[0] == "solve: [4/36] sweep point 4 done 0.1 s  11 %  (0.5 s)"
    assert lines[-1] == "solve: [36/36] sweep point 36 done 0.1 s 100 %  (4.5 s)"
    seconds = [float(ln.rsplit("(", 1)[1].split()[0]) for ln in lines]
    # the lines come at least DELAY_S apart (0.05 s: the printed seconds' rounding)
    assert all(b - a >= DELAY_S - 0.05 for a, b in zip(seconds, seconds[1:], strict=False))
    assert len(lines) == 9


def test_a_fractional_count_sets_the_fraction_of_the_cases_stage():
    """The executor's [3.4/20] (cases done, the running ones' fractions counted) is read as
    a fraction of one counted stage, 17 %, as [3/20] is 15 %."""
    out = io.StringIO()
    p = Progress("study", stream=out, tty=False, delay_s=0.0, ticker=False)
    p.say("[3/20] FEM level 0 transient done 1.0 s")
    assert p.stage_fraction == pytest.approx(0.15)
    p.say("[3.4/20] FEM level 1 transient: 4 of 9")
    assert p.stage_fraction == pytest.approx(0.17)
    assert p._counted == 20  # the same stage, not a new one per message
