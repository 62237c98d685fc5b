"""User-facing errors: each names the file, the field and the fix.

The command line turns any :class:`SpindleVerifyError` into its message on stderr and exit
status 2, never a traceback.
"""

from __future__ import annotations

from dataclasses import dataclass


class SpindleVerifyError(Exception):
    """An error caused by the user's input (not a bug): printed as is, exit status 2."""


@dataclass(frozen=True)
class Problem:
    """One problem in an input file."""

    file: str
    field: str
    message: str
    fix: str

    def __str__(self) -> str:
        return f"{self.file}: {self.field}: {self.message}; fix: {self.fix}"


class SpecError(SpindleVerifyError):
    """One or more problems in a spindle description; each names file, field and fix."""

    def __init__(self, problems: list[Problem]):
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class InputError(SpindleVerifyError):
    """A problem in another input (a cycle CSV, a command-line value)."""

    def __init__(self, file: str, field: str, message: str, fix: str):
        self.problem = Problem(file, field, message, fix)
        super().__init__(str(self.problem))


class SolverError(SpindleVerifyError):
    """The numerical problem cannot be solved as posed (for example, it is singular)."""


#: set once the user asked the run to stop (the command line's SIGTERM and SIGINT): no output
#: is put in place after that (spindle.outputs), even where the KeyboardInterrupt the signal
#: raised was lost (Python ignores an exception raised in a finalizer or a weakref callback)
STOP = {"requested": False}


def request_stop() -> None:
    """Refuse to put any output in place from now on (:func:`stop_if_requested`)."""
    STOP["requested"] = True


def stop_if_requested() -> None:
    """KeyboardInterrupt if the user asked the run to stop."""
    if STOP["requested"]:
        raise KeyboardInterrupt


class CycleWarning(UserWarning):
    """A load cycle the tool runs but doubts (a load beyond the drive's rating)."""
