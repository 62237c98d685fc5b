"""A bench export as text: its bytes decoded, and the header's other spellings of the
format's columns named in the messages (bench-format.md; spindle.bench reads the rest)."""

from __future__ import annotations

import re

from spindle.errors import InputError

#: byte-order marks of UTF-16, which some spreadsheet programs save "Unicode text" in
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
#: the first bytes of the archives a bench export is sent in (their formats' magic numbers)
_ARCHIVES = {b"\x1f\x8b": "gzip", b"PK\x03\x04": "zip", b"7z\xbc\xaf\x27\x1c": "7z",
             b"BZh": "bzip2", b"\xfd7zXZ\x00": "xz"}


def split_unit(column: str) -> tuple[str, str]:
    """(quantity, unit) of a column name: the unit follows the LAST underscore."""
    q, sep, u = column.rpartition("_")
    return (q, u) if sep else (column, "")


def _spelled(name: str) -> str:
    """A column name with blanks and hyphens read as the format's underscore ("T1 C" and
    "T1-C" are T1_C spelled otherwise)."""
    return re.sub(r"[\s\-]+", "_", name.strip())


def hint_for(column: str, header: list[str]) -> str:
    """A hint when the header has the quantity of ``column`` under another unit or spelling."""
    q, u = split_unit(column)
    for h in header:
        hq, hu = split_unit(_spelled(h))
        if h != column and (hq.lower() == q.lower() or _spelled(h).lower() == column.lower()):
            return f" (the header has '{h}'{f' with unit {hu!r}' if hu != u else ''}: the " \
                   f"format wants '{column}')"
    return ""


def decoded(raw: bytes, name: str) -> str:
    """``raw`` as UTF-8 text (a byte-order mark, as spreadsheet exports write, dropped);
    InputError naming the file ``name``, the line and the byte where it is not."""
    kind = next((k for magic, k in _ARCHIVES.items() if raw.startswith(magic)), None)
    if kind:
        raise InputError(name, "file", f"is a {kind} archive, not text (its first bytes are "
                         f"{kind}'s)", "unpack it and give the CSV inside")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        if raw.startswith(_UTF16_BOMS):
            raise InputError(name, "file", "is UTF-16 text (its first bytes are a UTF-16 "
                             "byte-order mark)", "export or save the file as UTF-8 (in a "
                             "spreadsheet: CSV UTF-8, not Unicode text)") from None
        line = raw.count(b"\n", 0, exc.start) + 1
        col = exc.start - (raw.rfind(b"\n", 0, exc.start) + 1) + 1
        bad = raw[exc.start:exc.start + 1].hex()
        raise InputError(name, f"line {line}", f"is not UTF-8 text (byte 0x{bad} at character "
                         f"{col})", "export the file as UTF-8 (a '°' or 'µ' saved as "
                         "Latin-1/Windows-1252 does this)") from None


def text_lines(raw: bytes, name: str) -> list[str]:
    """The lines of the file ``raw`` (:func:`decoded`): a file whose lines end in a carriage
    return alone (a classic Mac "CSV (Macintosh)" export) is split there too, and a
    byte-order mark at a line's start (an export with its mark appended to comments) is
    dropped: it is no character of a name or a number."""
    text = decoded(raw, name)
    nul = text.find("\x00")
    if nul >= 0:  # no text holds them: a logger that lost power pads its file with zeros
        raise InputError(name, f"line {text.count(chr(10), 0, nul) + 1}", "holds NUL bytes "
                         "(zero bytes, no text): the file is damaged there",
                         "export the run again, or cut the damaged lines from a copy")
    if "\n" not in text:
        text = text.replace("\r", "\n")
    return [ln[1:] if ln.startswith("\ufeff") else ln for ln in text.split("\n")]
