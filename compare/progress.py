"""Progress of every command on stderr, in one style.

A :class:`Progress` names the stage a run is in ("meshing level 2 and assembling",
"transient", "rendering pictures") and, where it is known, the fraction of that stage done.

- On a terminal: one line, rewritten in place: ``solve: transient [####......]  42 %  3.1 s``.
- In a log (stderr not a terminal): a line when a stage begins, then one per 10 % of it, each
  with the elapsed seconds (``solve: transient  40 %  (3.1 s)``), but at most one line every
  ``delay_s`` (0.5 s) within a stage: a 0.1 s transient writes one line, not eleven.
- A run that ends within ``delay_s`` prints nothing but its final line
  (``solve: done in 0.1 s``); a longer one shows the stage it is in at ``delay_s``, so a long
  set-up is never silent for more than half a second.
- Failures (a message containing ``FAILED``) are always printed, on a line of their own.
- ``quiet``: nothing at all.

Commands hand :meth:`Progress.say` to code that reports with one message per stage
(``Callable[[str], None]``), :meth:`Progress.fraction` to code that reports a fraction
(``Callable[[float], None]``, the transients), and wrap their output writing in
:meth:`Progress.pictures`, which reports every PNG :func:`spindle.outputs.atomic_write` writes.
Messages starting ``[k/n]`` (the executor's finished cases; k may be fractional, ``[3.4/20]``,
counting the running cases' own progress) make one stage whose fraction is ``k/n``: a log
gets a line per 10 % of the cases, not one per case.
"""

from __future__ import annotations

import math
import os
import re
import shutil
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TextIO

#: a run that ends sooner prints only its final line [s]
DELAY_S = 0.5
#: how often the terminal line is redrawn (the elapsed seconds move on) [s]
REDRAW_S = 0.2
_BAR = 10
_COUNT = re.compile(r"^\s*\[(\d+(?:\.\d+)?)/(\d+)\]")


class Progress:
    """The progress of one command (``label``, e.g. ``solve``) on ``stream`` (stderr).

    ``tty``: terminal style (default: whether ``stream`` is a terminal). ``clock``: seconds
    (tests pass a fake one). ``ticker``: redraw from a background thread (off in tests, which
    call :meth:`tick`).
    """

    def __init__(self, label: str, quiet: bool = False, stream: TextIO | None = None,
                 tty: bool | None = None, delay_s: float = DELAY_S,
                 clock: Callable[[], float] = time.perf_counter, ticker: bool = True):
        self.label, self.quiet, self.delay_s, self.clock = label, quiet, delay_s, clock
        self.stream = stream if stream is not None else sys.stderr
        if tty is None:  # a terminal that cannot clear a line (TERM=dumb) gets the log style
            tty = getattr(self.stream, "isatty", lambda: False)() and os.environ.get("TERM") != "dumb"
        self.tty = bool(tty)
        self.start = clock()
        self.stage_name = ""
        self.stage_fraction: float | None = None
        self._counted: int | None = None  # the n of a stage of "[k/n] ..." messages
        self._stage_written = -math.inf  # when this stage's last line was written
        self.shown = False  # something was written (the short-run rule no longer holds)
        self._pending = False  # the current state is not yet written
        self._last_step = -1  # log mode: the last 10 % step written of this stage
        self._line_open = False  # terminal: a rewritten line is on screen
        self._lock = threading.RLock()
        self._ticker: threading.Thread | None = None
        self._stop = threading.Event()
        self._pictures = 0
        self._pictures_total: int | None = None
        if ticker and not quiet:
            self._ticker = threading.Thread(target=self._tick_loop, daemon=True)
            self._ticker.start()

    # ---------------------------------------------------------------- what the run reports
    def stage(self, name: str, fraction: float | None = None) -> None:
        """A new stage (``fraction`` of it done, if known)."""
        with self._lock:
            self.stage_name, self.stage_fraction = name, None
            self._counted = None
            self._stage_written = -math.inf  # when this stage's last line was written
            self._last_step = -1
            self._pending = True
            if fraction is not None:
                self.fraction(fraction)
            else:
                self._show()

    def say(self, message: str) -> None:
        """A message from code that reports in words: a new stage, or a failure (kept)."""
        if "FAILED" in message:
            self.keep(message.strip())
            return
        m = _COUNT.match(message)
        if m is None:
            self.stage(message.strip())
            return
        done, total = float(m[1]), max(int(m[2]), 1)
        with self._lock:
            if self._counted == total:  # the next of the same cases: the stage goes on
                self._continue(message.strip(), done / total)
                return
            self.stage(message.strip(), done / total)
            self._counted = total

    def fraction(self, fraction: float) -> None:
        """The fraction of the current stage done (0..1); 100 % is written once."""
        with self._lock:
            f = min(max(float(fraction), 0.0), 1.0)
            if self.stage_fraction is not None and f == self.stage_fraction:
                return
            self.stage_fraction = f
            step = int(100 * f) if self.tty else int(100 * f) // 10  # 1 % on a terminal
            if step != self._last_step:
                self._pending = True
                self._show(new_step=step)

    __call__ = fraction  # a Progress is a Callable[[float], None] for the transients

    def keep(self, message: str) -> None:
        """A line that stays (a failure): written at once, whatever the elapsed time."""
        if self.quiet:
            return
        with self._lock:
            self._clear()
            self._write(f"{self.label}: {message}\n")
            self.shown = True
            if self.tty and self.stage_name:
                self._pending = True
                self._show()

    def done(self, summary: str = "") -> None:
        """The final line (``label: done in 3.1 s``, ``summary`` appended); stops the ticker."""
        self._stop.set()
        if self.quiet:
            return
        with self._lock:
            self._clear()
            extra = f"; {summary}" if summary else ""
            self._write(f"{self.label}: done in {self.clock() - self.start:.1f} s{extra}\n")

    def close(self) -> None:
        """Stop the ticker and end the terminal line, without a final line (a failed run)."""
        self._stop.set()
        with self._lock:
            self._clear()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextmanager
    def pictures(self, total: int | None = None) -> Iterator[None]:
        """A stage "writing the outputs"; while the block runs, each PNG written is reported
        (``rendering 4 pictures: 2/4 written, x.png``). ``total``: the number expected, if
        known; a writer that knows it announces it through
        :func:`spindle.outputs.expect_pictures`."""
        from spindle import outputs

        self._pictures, self._pictures_total = 0, total
        if total:
            self.stage(self._pictures_stage(), 0.0)
        else:  # tables and fields first, pictures announced or counted as they come
            self.stage("writing the outputs")
        outputs.PICTURE_LISTENERS.append(self._picture)
        try:
            yield
        finally:
            outputs.PICTURE_LISTENERS.remove(self._picture)

    # -------------------------------------------------------------------------- internals
    def _pictures_stage(self, name: str = "") -> str:
        n, total = self._pictures, self._pictures_total
        head = f"rendering {total} pictures" if total else "rendering pictures"
        if not name:
            return head
        return f"{head}: {n}/{total} written, {name}" if total else f"{head}: {n} written, {name}"

    def _picture(self, path: Path | None, total: int | None = None) -> None:
        if path is None:  # an announcement: ``total`` more pictures are coming
            self._pictures_total = self._pictures + (total or 0)
            self._continue(self._pictures_stage(), self._pictures / max(self._pictures_total, 1))
            return
        self._pictures += 1
        total = self._pictures_total
        if total is not None and self._pictures > total:
            self._pictures_total = total = None
        self._continue(self._pictures_stage(Path(path).name),
                       self._pictures / total if total else None)

    def _continue(self, name: str, fraction: float | None) -> None:
        """The stage goes on under a new name (the latest case, picture): its clock runs on."""
        with self._lock:
            self.stage_name = name
            if fraction is None:
                self.stage_fraction = None
                self._pending = True
                self._show()
            else:
                self.fraction(fraction)

    def tick(self) -> None:
        """Write what is due: the pending state once ``delay_s`` has passed; on a terminal
        the line again (its elapsed seconds)."""
        with self._lock:
            if self.tty and self._line_open:
                self._pending = True
            self._show()

    def _tick_loop(self) -> None:
        while not self._stop.wait(REDRAW_S):
            self.tick()

    def _show(self, new_step: int | None = None) -> None:
        if self.quiet or not self._pending or not self.stage_name:
            return
        now = self.clock()
        elapsed = now - self.start
        if not self.shown and elapsed < self.delay_s:
            return  # the short-run rule: wait, the run may be over before anyone looks
        if not self.tty and now - self._stage_written < self.delay_s:
            return  # a log: a stage's further lines come at most every delay_s
        if new_step is not None:
            self._last_step = new_step
        elif self.stage_fraction is not None:
            self._last_step = int(100 * self.stage_fraction) // (1 if self.tty else 10)
        self._pending = False
        self.shown = True
        self._stage_written = now
        f = self.stage_fraction
        if self.tty:
            if f is None:
                line = f"{self.label}: {self.stage_name} ...  {elapsed:.1f} s"
            else:
                bar = "#" * int(round(_BAR * f)) + "." * (_BAR - int(round(_BAR * f)))
                line = f"{self.label}: {self.stage_name} [{bar}] {int(100 * f):3d} %  {elapsed:.1f} s"
            width = shutil.get_terminal_size((100, 20)).columns - 1
            if len(line) > width:
                line = line[:max(width - 3, 10)] + "..."
            self._write("\r\033[K" + line)
            self._line_open = True
        else:
            pct = "" if f is None else f" {int(100 * f):3d} %"
            self._write(f"{self.label}: {self.stage_name}{pct}  ({elapsed:.1f} s)\n")

    def _clear(self) -> None:
        if self._line_open:
            self._write("\r\033[K")
            self._line_open = False

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):  # stderr closed (a pipe gone): progress is optional
            self.quiet = True


def command_progress(label: str, quiet: bool) -> Progress:
    """The progress of the command ``label`` on stderr (nothing with ``--quiet``); use it as
    a context manager, so that a run that fails stops its ticker and ends its line."""
    return Progress(label, quiet=quiet, delay_s=DELAY_S)
