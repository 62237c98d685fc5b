"""Marked blocks of the docs, for the tests that hold a doc's figures to the file or the
computation that makes them (issue 34: a figure in the docs cannot go stale).

A doc marks a generated part as

    <!-- NAME:begin -->
    ...text a test builds from a generated file or a computation...
    <!-- NAME:end -->

and a test asserts ``block(doc, NAME) == expected``; where a changed result changes the
expected text, the test fails until the doc is regenerated. Dated history that records what
was measured once (``<!-- history:begin -->`` ... ``<!-- history:end -->``, each with its
date and commit) is not checked: it says what was, not what is.
"""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def doc_text(doc: str) -> str:
    """The text of ``doc``: a path relative to the repository (``docs/power.md``)."""
    return (ROOT / doc).read_text(encoding="utf-8")


def block(doc: str, name: str) -> str:
    """The text between ``<!-- name:begin -->`` and ``<!-- name:end -->`` in ``doc``, without
    the newline after the opening marker and with the one before the closing marker."""
    m = re.search(rf"<!-- {re.escape(name)}:begin -->\n(.*?)<!-- {re.escape(name)}:end -->",
                  doc_text(doc), re.S)
    assert m, f"{doc} has no '{name}' block"
    return m.group(1)


def assert_block(doc: str, name: str, expected: str) -> None:
    """``doc``'s block ``name`` is ``expected`` (trailing whitespace of each line and of the
    whole ignored); the message shows the text to paste."""
    def norm(text: str) -> str:
        return "\n".join(line.rstrip() for line in text.strip().splitlines())

    got = norm(block(doc, name))
    want = norm(expected)
    assert got == want, (f"{doc}: block '{name}' is stale; regenerate it. It should read:\n"
                         f"{want}\n--- it reads:\n{got}")
