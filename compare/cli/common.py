"""Helpers shared by the commands: the options several commands take, the progress printer
and reading a ``--case``/``--cycle`` argument.

Kept free of numpy and the feature packages so that building the parser stays fast; the
helpers that need more import it when they run.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from spindle.loads import LoadCase
    from spindle.spec import Spec


def add_spec(parser: argparse.ArgumentParser) -> None:
    """The positional SPEC: a shipped spec name or a path to a .toml file."""
    parser.add_argument("spec", metavar="SPEC")


def add_out(parser: argparse.ArgumentParser, default: str) -> None:
    """``--out``: the output folder, ``default`` as the help shows it (e.g. results/<spec>)."""
    parser.add_argument("--out", help=f"output folder (default {default})")


def add_no_pictures(parser: argparse.ArgumentParser, what: str = "PNGs") -> None:
    """``--no-pictures``: skip the figures (``what`` names them in the help)."""
    parser.add_argument("--no-pictures", action="store_true", help=f"skip the {what}")


def add_quiet(parser: argparse.ArgumentParser) -> None:
    """``--quiet``: no progress messages on stderr."""
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")


def progress(quiet: bool) -> Callable[[str], None]:
    """A progress printer: one indented line per message on stderr, nothing when ``quiet``."""
    def say(msg: str) -> None:
        if not quiet:
            print(f"  ... {msg}", file=sys.stderr, flush=True)

    return say


def load_case_input(spec: Spec, source: str, base: LoadCase, inputs: list[str]) -> LoadCase:
    """The load case of a ``--case``/``--cycle`` argument (a shipped cycle name or a file),
    what a time-series file leaves out taken from ``base``. A file is appended to ``inputs``,
    the paths ``spindle.outputs.output_dir`` refuses to overwrite with an output."""
    from spindle.drive import load_case

    case = load_case(spec, source, base)
    if Path(source).is_file():
        inputs.append(source)
    return case
