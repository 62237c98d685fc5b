"""Progress of long runs on stderr: a live percentage on a terminal, a line per 10 % in logs."""

from __future__ import annotations

import sys
import time


class Progress:
    def __init__(self, label: str, enabled: bool = True):
        self.label, self.enabled = label, enabled
        self.start = time.perf_counter()
        self.tty = sys.stderr.isatty()
        self.last = -1

    def __call__(self, fraction: float) -> None:
        if not self.enabled:
            return
        pct = int(100 * min(max(fraction, 0.0), 1.0))
        step = 1 if self.tty else 10
        if pct // step == self.last // step and pct != 100:
            return
        if pct == self.last:
            return
        self.last = pct
        elapsed = time.perf_counter() - self.start
        msg = f"{self.label}: {pct:3d} %  ({elapsed:.1f} s)"
        if self.tty:
            sys.stderr.write("\r" + msg + ("\n" if pct == 100 else ""))
        else:
            sys.stderr.write(msg + "\n")
        sys.stderr.flush()
