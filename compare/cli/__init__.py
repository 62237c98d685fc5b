"""``spindle-verify``: the command line.

Every user error (a malformed spec or cycle, a singular problem) prints one message per
problem naming the file, the field and the fix, and exits with status 2.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from typing import NoReturn

from spindle.errors import InputError, SpindleVerifyError, request_stop


def package_version() -> str:
    """The installed distribution's version (pyproject.toml), or "unknown" when the tree
    runs without being installed."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("spindle-verify")
    except PackageNotFoundError:
        return "unknown (not installed)"


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose error is one line on stderr, exit status 2: what is wrong
    with which option and where the options are listed (argparse's own prints the usage
    block first, which buries the message under the options)."""

    def error(self, message: str) -> NoReturn:
        message = message.removeprefix("argument ")
        self.exit(2, f"{self.prog}: {message}; '{self.prog} --help' lists the options\n")


def build_parser() -> argparse.ArgumentParser:
    p = OneLineParser(
        prog="spindle-verify",
        description="How far can you trust a thermal model of a motor spindle? FEM reference, "
                    "lumped models and the harness that compares them. SPEC is a shipped spec "
                    "name (see 'spindle-verify specs') or a path to a .toml file.")
    p.add_argument("--version", action="version", version=f"%(prog)s {package_version()}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    from compare.cli import (
        fit,
        measures,
        mesh,
        regression,
        solve,
        specs,
        study,
        synth,
    )

    specs.register(sub)
    mesh.register(sub)
    solve.register(sub)
    study.register(sub)
    regression.register(sub)
    fit.register(sub)
    synth.register(sub)
    measures.register(sub)

    from compare.cli import crosscheck, rom, sensors

    sensors.register(sub)
    crosscheck.register(sub)
    rom.register(sub)
    return p


def _check_args(args: argparse.Namespace) -> None:
    for name in ("out", "case", "cycle"):  # an unset shell variable: not "the default"
        if getattr(args, name, None) == "":
            raise InputError("command line", f"--{name}", "is empty",
                             f"give a value, or leave --{name} out for its default")
    if getattr(args, "dt", 1.0) <= 0:
        raise InputError("command line", "--dt", "must be > 0 s", "give a positive time step")
    if not 0.0 <= getattr(args, "theta", 1.0) <= 1.0:
        raise InputError("command line", "--theta", "must be within [0, 1]",
                         "use 1 (backward Euler) or 0.5 (Crank-Nicolson)")
    if (getattr(args, "speed", None) or 0) < 0:
        raise InputError("command line", "--speed", "is negative", "give |n| in rpm")
    levels = getattr(args, "levels", None)
    if levels is not None:
        if any(not 0 <= lv <= 5 for lv in levels):
            raise InputError("command line", "--levels", f"{levels} has a level outside 0..5",
                             "give levels between 0 and 5")
        if len(set(levels)) < 3:
            raise InputError("command line", "--levels", f"{levels} has fewer than 3 levels",
                             "give three or more levels, e.g. --levels 0 1 2 3")
    nodes = getattr(args, "nodes", None)
    if isinstance(nodes, list) and min(nodes) < 2:
        raise InputError("command line", "--nodes", "a lumped model needs >= 2 nodes",
                         "give node counts >= 2")


def _terminate(signum: int, frame: object) -> None:
    """SIGTERM as Ctrl-C: unwind, so that the temporary output folder is removed; and put
    no output in place even if this KeyboardInterrupt is lost (spindle.errors.STOP)."""
    request_stop()
    raise KeyboardInterrupt


_PYTHON_FORMAT = warnings.formatwarning


def _format_warning(message, category, filename, lineno, line=None) -> str:
    """The tool's own warnings (about the user's input) as one line naming the input, not
    the source line that raised them; any other warning as Python shows it."""
    if category.__module__.split(".")[0] in ("spindle", "compare", "lumped", "reference"):
        return f"spindle-verify: warning: {message}\n"
    return _PYTHON_FORMAT(message, category, filename, lineno, line)


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
    except SystemExit as exc:  # argparse refused an option (exit 2, message printed) or --help
        return int(exc.code or 0)
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGTERM, _terminate)
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, _terminate)
    warnings.formatwarning = _format_warning
    try:
        _check_args(args)
        return args.func(args)
    except SpindleVerifyError as exc:
        for line in str(exc).splitlines():
            print(f"spindle-verify: error: {line}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("spindle-verify: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`, which closed early
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # a path the system refuses (too long, no permission, disk full)
        what = exc.filename if exc.filename is not None else "a file"
        print(f"spindle-verify: error: {what}: {exc.strerror or exc}; fix: check the path (its "
              "length, its folder's permissions) and the free disk space", file=sys.stderr)
        return 2
    except MemoryError:  # the problem asked for is larger than the machine: no bug
        print("spindle-verify: error: memory: this machine ran out of memory for the problem "
              "asked (the mesh level and mesh.h0_m, the node count, the run's length); fix: "
              "a coarser --level or mesh.h0_m, fewer --nodes, or a machine with more free "
              "memory", file=sys.stderr)
        return 2
    except Exception as exc:  # a bug, not the user's input: one line, the traceback in a file
        print(f"spindle-verify: internal error: {type(exc).__name__}: {exc}; this is a bug, "
              f"not your input: please report it with the command and {_crash_file(exc, argv)}",
              file=sys.stderr)
        return 1


def _crash_file(exc: BaseException, argv: list[str] | None) -> str:
    """The command ``argv`` and the traceback of ``exc`` written to a new file in the
    temporary folder: where to find them."""
    import tempfile
    import traceback

    try:
        fd, path = tempfile.mkstemp(prefix="spindle-verify-crash-", suffix=".txt")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(f"spindle-verify {' '.join(sys.argv[1:] if argv is None else argv)}\n")
            f.write("".join(traceback.format_exception(exc)))
        return f"the traceback in {path}"
    except OSError:
        return "the input"



if __name__ == "__main__":
    sys.exit(main())
