"""CSV text with comment lines, as the cycle files are (spindle.loads.read_cycle_csv and
spindle.cycle_files.read_cycle_steps_csv; formats in docs/cycles.md).

A line whose first non-blank character is ``#`` is a comment; blank lines are skipped. The
first other line is the header. Every reader keeps the file line of each row so that its
errors can name it (comments and blank lines counted); each reader checks the cells and
words its own messages.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass


@dataclass(frozen=True)
class CommentedCsv:
    """The lines of a commented CSV text.

    ``line_no``: the file line (from 1) of each CSV line, header first. ``rows``: those
    lines split by the csv module (``rows[0]`` is the header as written; a quoted cell that
    spans lines makes fewer rows than lines). ``comments``: (file line, the text after the
    ``#``) of each comment line, anywhere in the file.
    """

    line_no: list[int]
    rows: list[list[str]]
    comments: list[tuple[int, str]]

    @property
    def header(self) -> list[str]:
        """The column names, stripped (empty if the text has no header line)."""
        return [h.strip() for h in self.rows[0]] if self.rows else []


def split_commented_csv(text: str) -> CommentedCsv:
    """Split ``text`` into comment lines and CSV rows (blank lines dropped)."""
    line_no: list[int] = []
    lines: list[str] = []
    comments: list[tuple[int, str]] = []
    for lineno, line in enumerate(text.splitlines(), start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            comments.append((lineno, s[1:]))
            continue
        line_no.append(lineno)
        lines.append(line)
    return CommentedCsv(line_no, list(csv.reader(lines)), comments)
