"""Helpers shared by the commands."""

from __future__ import annotations

import sys
from collections.abc import Callable


def progress(quiet: bool) -> Callable[[str], None]:
    """A progress printer: one indented line per message on stderr, nothing when ``quiet``."""
    def say(msg: str) -> None:
        if not quiet:
            print(f"  ... {msg}", file=sys.stderr, flush=True)

    return say
