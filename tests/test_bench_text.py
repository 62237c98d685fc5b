"""A bench export's bytes and header spellings (spindle.bench_text): fuzzing round 5 found a
UTF-16 file hinted as Latin-1 and a "T1 C" header without a hint."""

import pytest

from spindle.bench_text import decoded, hint_for
from spindle.errors import InputError


@pytest.mark.parametrize("codec", ["utf-16", "utf-16-be"])
def test_a_utf16_file_is_named_as_such(codec):
    raw = "time_s,speed_rpm\n0,0\n".encode(codec)
    if codec == "utf-16-be":
        raw = b"\xfe\xff" + raw
    with pytest.raises(InputError) as exc:
        decoded(raw, "run.csv")
    assert "is UTF-16 text" in str(exc.value) and "Latin-1" not in str(exc.value)


@pytest.mark.parametrize("kind", ["gzip", "zip", "bzip2", "xz"])
def test_a_compressed_export_is_named_as_an_archive(kind, tmp_path):
    """A bench export sent compressed (fuzzing round 6: a gzip or zip file read as a CSV was
    hinted as Latin-1): the archive is made by Python's own modules, and the message names its
    kind and says to unpack it."""
    import bz2
    import gzip
    import lzma
    import zipfile

    text = b"time_s,speed_rpm\n" + b"".join(b"%d,%d\n" % (i, 3000) for i in range(200))
    if kind == "zip":
        path = tmp_path / "run.zip"
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("run.csv", text)
        raw = path.read_bytes()
    else:
        raw = {"gzip": gzip.compress, "bzip2": bz2.compress, "xz": lzma.compress}[kind](text)
    with pytest.raises(InputError) as exc:
        decoded(raw, "run.csv")
    assert f"is a {kind} archive" in str(exc.value) and "unpack" in str(exc.value)
    assert "Latin-1" not in str(exc.value)


def test_latin1_is_still_hinted_as_latin1():
    with pytest.raises(InputError) as exc:
        decoded("# room 20 °C\ntime_s\n".encode("latin-1"), "run.csv")
    assert "line 1" in str(exc.value) and "Latin-1" in str(exc.value)


def test_a_utf8_byte_order_mark_is_dropped():
    assert decoded("\ufefftime_s\n".encode(), "run.csv") == "time_s\n"


@pytest.mark.parametrize("header, expected", [
    ("T1 C", " (the header has 'T1 C': the format wants 'T1_C')"),
    ("t1-c", " (the header has 't1-c' with unit 'c': the format wants 'T1_C')"),
    ("T1_F", " (the header has 'T1_F' with unit 'F': the format wants 'T1_C')"),
    ("T2_C", ""),
])
def test_other_spellings_of_a_column_are_named(header, expected):
    assert hint_for("T1_C", [header]) == expected
