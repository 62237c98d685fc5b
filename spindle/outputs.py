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
from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from spindle.errors import InputError

_UMASK = os.umask(0)
os.umask(_UMASK)


def atomic_write(path: Path, write) -> None:
    """Call ``write(tmp_path)`` and move the result into ``path`` in one step."""
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


def safe_name(name: str) -> str:
    """``name`` (a spec's or a run's) made safe as one folder name: no path separators, no
    leading dots, nothing but letters, digits, ``-``, ``_`` and ``.`` (a spec named
    ``../../etc/evil`` must not write outside ``results/``)."""
    text = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).lstrip(".")
    return text[:100] or "unnamed"


def check_output_dir(path: str | Path, inputs: Sequence[str | Path] = ()) -> Path:
    """Refuse, before any work is done, an output folder that cannot be one: a file, an input,
    a folder holding one of the inputs, or a place that cannot be created or written."""
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
    return path


def _clean_leftovers(parent: Path, name: str) -> None:
    """Remove the temporary folders of earlier runs into ``name`` that were killed before they
    could clean up (their process is gone)."""
    for old in parent.glob(f".{name}.tmp-*"):
        m = re.match(rf"\.{re.escape(name)}\.tmp-(\d+)-", old.name)
        if not m or not old.is_dir():
            continue
        try:
            os.kill(int(m.group(1)), 0)
        except ProcessLookupError:
            shutil.rmtree(old, ignore_errors=True)
        except (PermissionError, OverflowError):
            pass


@contextmanager
def output_dir(path: str | Path, inputs: Sequence[str | Path] = ()) -> Iterator[Path]:
    """Yield a temporary folder to write into; on success move its files into ``path``."""
    path = check_output_dir(path, inputs)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(str(path), "--out", f"cannot be created ({exc.strerror})",
                         "give a folder in a place you can write to") from None
    _clean_leftovers(path.parent, path.name)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.tmp-{os.getpid()}-", dir=path.parent))
    try:
        yield tmp
        files = [f for f in tmp.rglob("*") if f.is_file()]
        protected = {Path(p).resolve() for p in inputs}
        for f in files:
            dest = (path / f.relative_to(tmp)).resolve()
            if dest in protected:
                raise InputError(str(dest), "--out", "an output would overwrite this input",
                                 "choose another output folder")
        for f in files:
            dest = path / f.relative_to(tmp)
            dest.parent.mkdir(parents=True, exist_ok=True)
            os.replace(f, dest)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


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
