"""Atomic outputs: a run writes into a hidden temporary folder and moves each finished file
into the output folder only when everything succeeded, so a failed run leaves no
half-written output; an output never replaces one of the run's inputs."""

from __future__ import annotations

import csv
import json
import math
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from spindle.errors import InputError

_UMASK = os.umask(0)
os.umask(_UMASK)


#: called as ``listener(path)`` after each PNG :func:`atomic_write` wrote, and as
#: ``listener(None, n)`` by :func:`expect_pictures` (``compare.progress`` reports them)
PICTURE_LISTENERS: list[Callable[..., None]] = []


def expect_pictures(n: int) -> None:
    """Tell the progress that ``n`` pictures are about to be rendered."""
    for listener in list(PICTURE_LISTENERS):
        listener(None, n)


def atomic_write(path: Path, write) -> None:
    """Call ``write(tmp_path)`` and move the result into ``path`` in one step (a PNG is
    reported to :data:`PICTURE_LISTENERS`)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; outputs are ordinary files
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    if path.suffix == ".png":
        for listener in list(PICTURE_LISTENERS):
            listener(path)


def safe_name(name: str) -> str:
    """``name`` (a spec's or a run's) made safe as one folder name: no path separators, no
    leading dots, nothing but letters, digits, ``-``, ``_`` and ``.`` (a spec named
    ``../../etc/evil`` must not write outside ``results/``)."""
    text = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).lstrip(".")
    return text[:100] or "unnamed"


#: file in every output folder: it marks the folder as one spindle-verify wrote, so that a
#: later run may replace it as a whole (a folder without it and not empty is refused)
MARKER = ".spindle-verify"


def check_output_dir(path: str | Path, inputs: Sequence[str | Path] = ()) -> Path:
    """Refuse, before any work is done, an output folder that cannot be one: a file, an input,
    a folder holding one of the inputs, a place that cannot be created or written, or a
    folder with files that an earlier run did not write (no :data:`MARKER`)."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(str(path), "--out", "is a file, not a folder",
                         "give a folder for the outputs")
    target = path.resolve()
    for p in inputs:
        q = Path(p).resolve()
        if q == target or target in q.parents:
            raise InputError(str(path), "--out", f"holds the input {p}, which an output could "
                             "overwrite", "choose an output folder apart from the inputs")
    # nothing is created here (a run refused later must leave nothing behind): the nearest
    # existing folder on the way must be one we can write into
    base = target
    while not base.exists() and base != base.parent:
        base = base.parent
    if not base.is_dir():
        raise InputError(str(path), "--out", f"cannot be created: {base} is a file",
                         "give a folder in a place you can write to")
    if not os.access(base, os.W_OK | os.X_OK):
        raise InputError(str(path), "--out", f"cannot be written ({base} is not writable)",
                         "give a folder in a place you can write to")
    if path.is_dir() and not (path / MARKER).exists() and any(path.iterdir()):
        raise InputError(str(path), "--out", "holds files spindle-verify did not write (an "
                         "output folder is replaced as a whole, and these would be lost)",
                         "give a new or empty folder, or one an earlier spindle-verify run "
                         "wrote")
    if path.is_dir():
        nested = next((q.parent for q in path.glob(f"*/**/{MARKER}")), None)
        if nested is not None:
            raise InputError(str(path), "--out", f"holds the output of another run "
                             f"({nested.relative_to(path)}), which replacing it would delete",
                             "give a folder of its own, e.g. a subfolder or a sibling")
    return path


def _clean_leftovers(parent: Path, name: str) -> None:
    """Remove the temporary folders of earlier runs into ``name`` that were killed before they
    could clean up (their process is gone); an old output a killed run had moved aside but
    not yet replaced is put back."""
    for old in [*parent.glob(f".{name}.tmp-*"), *parent.glob(f".{name}.old-*")]:
        m = re.match(rf"\.{re.escape(name)}\.(tmp|old)-(\d+)-", old.name)
        if not m or not old.is_dir():
            continue
        try:
            os.kill(int(m.group(2)), 0)
        except ProcessLookupError:
            target = parent / name
            if m.group(1) == "old" and not target.exists():
                os.rename(old, target)
            else:
                shutil.rmtree(old, ignore_errors=True)
        except (PermissionError, OverflowError):
            pass


@contextmanager
def output_dir(path: str | Path, inputs: Sequence[str | Path] = ()) -> Iterator[Path]:
    """Yield a temporary folder to write into; on success it replaces ``path`` as a whole
    (an earlier run's folder is moved aside, the new one renamed into place, the old one
    removed), so the folder never mixes two runs' files and a failed run leaves the old one
    as it was."""
    path = check_output_dir(path, inputs)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(str(path), "--out", f"cannot be created ({exc.strerror})",
                         "give a folder in a place you can write to") from None
    _clean_leftovers(path.parent, path.name)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.tmp-{os.getpid()}-", dir=path.parent))
    try:
        yield tmp  # no input lies inside path (check_output_dir), so none is replaced
        (tmp / MARKER).write_text("written by spindle-verify; the next run into this folder "
                                  "replaces it as a whole\n", encoding="utf-8")
        os.chmod(tmp, 0o777 & ~_UMASK)  # mkdtemp makes 0700; outputs are ordinary folders
        _replace_folder(tmp, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _replace_folder(new: Path, path: Path) -> None:
    """Rename ``new`` to ``path``; an existing ``path`` is first moved aside (restored if the
    rename fails) and removed after."""
    if not path.exists():
        os.rename(new, path)
        return
    old = Path(tempfile.mkdtemp(prefix=f".{path.name}.old-{os.getpid()}-", dir=path.parent))
    os.rmdir(old)
    os.rename(path, old)
    try:
        os.rename(new, path)
    except OSError:
        os.rename(old, path)
        raise
    shutil.rmtree(old, ignore_errors=True)


def write_csv(path: Path, header: list[str], rows) -> None:
    """A CSV file with a header row, written atomically."""
    def write(tmp: Path) -> None:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            w.writerows(rows)

    atomic_write(path, write)


def jsonable(v: Any) -> Any:
    """JSON-ready data: Python scalars, non-finite floats as None (NaN is not JSON), arrays and
    containers recursively, paths as strings."""
    if isinstance(v, Mapping):
        return {str(k): jsonable(x) for k, x in v.items()}
    if isinstance(v, list | tuple | np.ndarray):
        return [jsonable(x) for x in v]
    if isinstance(v, bool | np.bool_):
        return bool(v)
    if isinstance(v, int | np.integer):
        return int(v)
    if isinstance(v, float | np.floating):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, Path):
        return str(v)
    return v


def write_json(path: Path, data: dict) -> None:
    """An indented JSON file (made :func:`jsonable` first: valid JSON, no NaN), written
    atomically."""
    text = json.dumps(jsonable(data), indent=2, allow_nan=False) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text, "utf-8"))
