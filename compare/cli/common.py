"""Helpers shared by the commands: the options several commands take, their progress
(:func:`with_progress`) and reading a ``--case``/``--cycle`` argument.

Kept free of numpy and the feature packages so that building the parser stays fast; the
helpers that need more import it when they run.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from spindle.units import MESH_LEVEL_MAX

if TYPE_CHECKING:
    from compare.progress import Progress
    from spindle.loads import LoadCase
    from spindle.spec import Spec


def number(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False,
           integer: bool = False, unit: str = "") -> Callable[[str], float]:
    """An argparse ``type``: a finite number (an integer with ``integer``) within [lo, hi]
    (``lo_open``: above lo); anything else is refused by argparse with exit status 2 and a
    message naming the option, before any work is done."""
    def parse(text: str) -> float:
        try:
            v = int(text) if integer else float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"'{text}' is not {'an integer' if integer else 'a number'}") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"'{text}' is not a finite number")
        u = f" {unit}" if unit else ""
        if lo is not None and (v <= lo if lo_open else v < lo):
            raise argparse.ArgumentTypeError(f"{text}{u} is too small: give a value "
                                             f"{'>' if lo_open else '>='} {lo:g}{u}")
        if hi is not None and v > hi:
            raise argparse.ArgumentTypeError(f"{text}{u} is too large: give a value <= {hi:g}{u}")
        return v

    parse.__name__ = "integer" if integer else "number"
    return parse


#: option types shared by the commands (limits: the reason in the help of each option)
TIME_STEP_S = number(0.0, 86400.0, lo_open=True, unit="s")
SPEED_RPM = number(0.0, 100_000.0, unit="rpm")  # spindle.units.SPEED_MAX_RPM
MESH_LEVEL = number(0, MESH_LEVEL_MAX, integer=True)
POSITIVE = number(0.0, lo_open=True)
WORKERS = number(1, 256, integer=True)
NODE_COUNT = number(2, 1000, integer=True)  # lumped.build.MAX_NODES (not imported: numpy)


def add_spec(parser: argparse.ArgumentParser) -> None:
    """The positional SPEC: a shipped spec name or a path to a .toml file."""
    parser.add_argument("spec", metavar="SPEC")


def add_out(parser: argparse.ArgumentParser, default: str) -> None:
    """``--out``: the output folder, ``default`` as the help shows it (e.g. results/<spec>)."""
    parser.add_argument("--out", help=f"output folder (default {default}); a run replaces "
                        "what an earlier run wrote there and refuses a folder holding anything "
                        "else")
    parser.add_argument("--force", action="store_true",
                        help="write into an output folder that holds files spindle-verify did "
                        "not write (or that were edited since): they are moved into a sibling "
                        "'<folder>.kept-<time>' folder, never deleted")


def out_folder(out: str | None, default: str, inputs: list, force: bool = False) -> Path:
    """The output folder: ``out``, else ``default`` (a path under results/ whose spec and run
    names the caller made safe with :func:`spindle.outputs.safe_name`), checked before any
    work (:func:`spindle.outputs.check_output_dir`; ``force``: files the tool did not write
    are allowed, to be moved aside)."""
    from spindle.outputs import check_output_dir

    return check_output_dir(Path(out) if out else Path(default), inputs, force)


def load_spec_with_sensors(name: str):
    """The spec ``name`` (spindle.spec_reader.load_spec) for a command that compares models
    at its temperature sensors: one without them is refused (it stopped such commands with
    an internal error)."""
    from spindle.errors import InputError
    from spindle.spec_reader import load_spec

    spec = load_spec(name)
    if not spec.temperature_sensors():
        raise InputError(spec.path, "sensors", "the spec has no temperature sensor, and this "
                         "command compares the models there", "add [[sensors]] with kind = "
                         '"temperature", or [[sensor_arrays]] along a part (docs/spec.md)')
    return spec


def input_files(*texts: str | None) -> list[str]:
    """The files among command-line values (a cycle given as ``FILE`` or ``FILE:SEED``): an
    output folder must not hold them, and ``--force`` must not move them aside."""
    from pathlib import Path

    out = []
    for text in texts:
        if text:
            for name in (text, text.rpartition(":")[0]):
                if name and Path(name).is_file():
                    out.append(name)
                    break
    return out


def add_no_pictures(parser: argparse.ArgumentParser, what: str = "PNGs") -> None:
    """``--no-pictures``: skip the figures (``what`` names them in the help)."""
    parser.add_argument("--no-pictures", action="store_true", help=f"skip the {what}")


def add_quiet(parser: argparse.ArgumentParser) -> None:
    """``--quiet``: no progress messages on stderr."""
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")


def with_progress(label: str) -> Callable[[Callable[[argparse.Namespace, Progress], int]],
                                         Callable[[argparse.Namespace], int]]:
    """Decorate a command ``fn(args, progress)`` into ``fn(args)``: ``progress`` is the
    command's :class:`compare.progress.Progress` (stderr, silent with ``--quiet``), closed
    when the command ends, also by an error."""
    import functools

    def wrap(fn: Callable[[argparse.Namespace, Progress], int]) -> Callable[[argparse.Namespace], int]:
        @functools.wraps(fn)
        def run(args: argparse.Namespace) -> int:
            from compare.progress import command_progress

            with command_progress(label, getattr(args, "quiet", False)) as progress:
                return fn(args, progress)

        return run

    return wrap


def load_case_input(spec: Spec, source: str, base: LoadCase, inputs: list[str]) -> LoadCase:
    """The load case of a ``--case``/``--cycle`` argument (a shipped cycle name or a file),
    what a time-series file leaves out taken from ``base``. A file is appended to ``inputs``,
    the paths ``spindle.outputs.output_dir`` refuses to overwrite with an output."""
    from spindle.drive import load_case

    case = load_case(spec, source, base)
    if Path(source).is_file():
        inputs.append(source)
    return case


def pass_fail(ok: bool, borderline: bool = False) -> str:
    """PASS, FAIL or "borderline" (the margin within the reference's uncertainty) for the
    console: in green, red or yellow on a colour terminal, plain words otherwise (a log, a
    pipe, NO_COLOR set)."""
    import os
    import sys

    word = "borderline" if borderline else "PASS" if ok else "FAIL"
    if sys.stdout.isatty() and not os.environ.get("NO_COLOR"):
        colour = "33" if borderline else "32" if ok else "31"
        return f"\033[{colour};1m{word}\033[0m"
    return word


def spec_files(spec: Spec) -> list[str]:
    """The files ``spec`` was read from (spindle.spec_reader.spec_files): a command's inputs,
    which no output may replace or move."""
    from spindle.spec_reader import spec_files as files

    return files(spec)
