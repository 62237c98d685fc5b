"""Atomic outputs: a run writes into a hidden temporary folder and moves each finished file
into the output folder only when everything succeeded, so a failed run leaves no
half-written output; an output never replaces one of the run's inputs."""

from __future__ import annotations

import csv
import hashlib
import json
import math
import os
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

from spindle.errors import InputError, stop_if_requested

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
    reported to :data:`PICTURE_LISTENERS`); not after the user asked the run to stop."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        write(Path(tmp))
        os.chmod(tmp, 0o666 & ~_UMASK)  # mkstemp makes 0600; outputs are ordinary files
        stop_if_requested()
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


#: file in every output folder: the manifest of what spindle-verify wrote there (each file's
#: path and SHA-256), so that a later run replaces only those and refuses anything else
MARKER = ".spindle-verify"
MANIFEST_FORMAT = "spindle-verify-outputs/1"


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _manifest(folder: Path, marker: str = MARKER) -> dict[str, str]:
    """What the marker of ``folder`` (:data:`MARKER`, or :data:`FILE_MARKER` for single files)
    says the tool wrote (relative POSIX path -> SHA-256); empty for a marker of an older
    version (plain text) or none."""
    try:
        data = json.loads((folder / marker).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return {}
    files = data.get("files") if isinstance(data, dict) else None
    return {str(k): str(v) for k, v in files.items()} if isinstance(files, dict) else {}


def _write_manifest(folder: Path) -> None:
    files = {}
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if p.is_file() and rel != MARKER:
            files[rel] = _sha256(p)
        elif p.is_dir() and not any(p.iterdir()):
            files[rel + "/"] = "folder"
    text = _manifest_text(files, "the files the run wrote; the next run into this folder "
                          "replaces these and refuses (or with --force moves aside) anything else")
    (folder / MARKER).write_text(text, encoding="utf-8")


def _manifest_text(files: dict[str, str], note: str) -> str:
    """A marker's JSON (:func:`_manifest` reads it): the files the tool wrote and their
    SHA-256."""
    return json.dumps({"format": MANIFEST_FORMAT, "written_by": "spindle-verify",
                       "note": note, "files": files}, indent=1) + "\n"


def foreign_files(folder: str | Path) -> list[str]:
    """The entries of ``folder`` that spindle-verify did not write there (relative paths,
    sorted): files its manifest does not list, files edited since (another SHA-256), links,
    and empty folders. A folder that does not exist holds none."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    known = _manifest(folder)
    found = []
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        if p.is_symlink() or (p.is_file() and rel != MARKER and known.get(rel) != _sha256(p)):
            found.append(rel)
        elif p.is_dir() and not any(p.iterdir()) and rel + "/" not in known:
            found.append(rel + "/")
        elif not p.is_dir() and not p.is_file():  # a socket, a fifo
            found.append(rel)
    return found


def _list_some(names: Sequence[str], most: int = 5) -> str:
    shown = ", ".join(names[:most])
    return shown + (f" and {len(names) - most} more" if len(names) > most else "")


def _refuse_foreign(path: Path, found: Sequence[str]) -> InputError:
    edited = [n for n in found if n in _manifest(path)]
    what = (f"holds {len(found)} file{'s' if len(found) > 1 else ''} spindle-verify did not "
            f"write there ({_list_some(found)})")
    if edited:
        what += f"; {_list_some(edited)} {'was' if len(edited) == 1 else 'were'} edited since"
    return InputError(str(path), "--out", what, "give a new or empty folder, move those files "
                      "away, or add --force to have them moved aside into a sibling "
                      f"'{path.name}.kept-<time>' folder (nothing is deleted)")


def check_output_dir(path: str | Path, inputs: Sequence[str | Path] = (),
                     force: bool = False) -> Path:
    """Refuse, before any work is done, an output folder that cannot be one: a file, an input,
    a folder holding one of the inputs, a place that cannot be created or written, or (unless
    ``force``) a folder holding anything spindle-verify did not write there
    (:func:`foreign_files`)."""
    path = Path(path)
    if path.is_symlink():  # replacing it would put a folder where the user's link was
        raise InputError(str(path), "--out", f"is a link (to {os.readlink(path)})",
                         "give the folder it points to, or a new folder")
    if path.exists() and not path.is_dir():
        raise InputError(str(path), "--out", "is a file, not a folder",
                         "give a folder for the outputs")
    target = path.resolve()
    for p in inputs:
        q = Path(p).resolve()
        if q == target or target in q.parents:
            raise InputError(str(path), "--out", f"holds the input {p}, which an output could "
                             "overwrite", "choose an output folder apart from the inputs")
    _check_writable(path, target)
    if path.is_dir():
        nested = next((q.parent for q in path.glob(f"*/**/{MARKER}")), None)
        if nested is not None and not force:
            raise InputError(str(path), "--out", f"holds the output of another run "
                             f"({nested.relative_to(path)}), which replacing it would move",
                             "give a folder of its own, e.g. a subfolder or a sibling")
        found = foreign_files(path)
        if found and not force:
            raise _refuse_foreign(path, found)
    return path


def _check_writable(path: Path, target: Path, option: str = "--out") -> None:
    """``path`` (resolved: ``target``) can be created and written: nothing is created here
    (a run refused later must leave nothing behind), so the nearest existing folder on the
    way must be one we can write into."""
    base = target
    while not base.exists() and base != base.parent:
        base = base.parent
    if not base.is_dir():
        raise InputError(str(path), option, f"cannot be created: {base} is a file",
                         "give a folder in a place you can write to")
    if not os.access(base, os.W_OK | os.X_OK):
        raise InputError(str(path), option, f"cannot be written ({base} is not writable)",
                         "give a folder in a place you can write to")
    try:  # the permission bits may allow what the place refuses (/proc, a read-only mount)
        os.rmdir(tempfile.mkdtemp(prefix=".spindle-verify-probe-", dir=base))
    except OSError as exc:
        raise InputError(str(path), option, f"cannot be created in {base} "
                         f"({exc.strerror or exc})",
                         "give a folder in a place you can write to") from None


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


#: file beside single output files (synth's run and truth, a baseline): their names and
#: SHA-256, so that a later run replaces those and refuses a file of the user's
FILE_MARKER = ".spindle-verify-files"


def _kept_path(name_for: Callable[[str], Path]) -> Path:
    """Where a user's entry is moved aside: the first of ``name_for(<time>)``,
    ``name_for(<time>-2)``, ... that does not exist (nor is a dangling link)."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    kept, n = name_for(stamp), 1
    while kept.exists() or kept.is_symlink():
        n += 1
        kept = name_for(f"{stamp}-{n}")
    return kept


def _foreign_file(path: Path) -> bool:
    """``path`` exists and is not a file spindle-verify wrote (or it was edited since)."""
    if not (path.exists() or path.is_symlink()):
        return False
    return (path.is_symlink() or not path.is_file()
            or _manifest(path.parent, FILE_MARKER).get(path.name) != _sha256(path))


def _refuse_file(path: Path, option: str) -> InputError:
    return InputError(str(path), option, "exists and spindle-verify did not write it (or it "
                      "was edited since)", "give a new file name, move the file away, or add "
                      f"--force to have it moved aside to '{path.stem}.kept-<time>"
                      f"{path.suffix}' (nothing is deleted)")


def check_output_file(path: str | Path, inputs: Sequence[str | Path] = (),
                      force: bool = False, option: str = "--out") -> Path:
    """Refuse, before any work is done, an output file that cannot be one: a folder, one of
    the run's ``inputs``, a place that cannot be written, or (unless ``force``) an existing
    file spindle-verify did not write there (its folder's :data:`FILE_MARKER`)."""
    path = Path(path)
    if path.is_dir():
        raise InputError(str(path), option, "is a folder", "give a file name")
    for p in inputs:
        if Path(p).resolve() == path.resolve():
            raise InputError(str(path), option, f"is the input {p}", "give another file name: "
                             "an output never replaces an input")
    _check_writable(path, path.parent.resolve(), option)
    if _foreign_file(path) and not force:
        raise _refuse_file(path, option)
    return path


def write_output_file(path: str | Path, write: Callable[[Path], Any], force: bool = False,
                      option: str = "--out") -> None:
    """:func:`atomic_write` into ``path``, which :func:`check_output_file` allows (asked
    again here: the file may have appeared during the run); a file of the user's there is
    first moved aside to ``<stem>.kept-<time><suffix>`` with ``force``. The file is recorded
    in its folder's :data:`FILE_MARKER`."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if _foreign_file(path):
        if not force:
            raise _refuse_file(path, option)
        kept = _kept_path(lambda tag: path.with_name(f"{path.stem}.kept-{tag}{path.suffix}"))
        os.rename(path, kept)
        print(f"spindle-verify: moved {path} aside to {kept} (--force)", file=sys.stderr)
    atomic_write(path, write)
    files = {**_manifest(path.parent, FILE_MARKER), path.name: _sha256(path)}
    text = _manifest_text(files, "single files spindle-verify wrote into this folder; a later "
                          "run replaces these and refuses (or with --force moves aside) any "
                          "other file")
    atomic_write(path.parent / FILE_MARKER, lambda tmp: tmp.write_text(text, encoding="utf-8"))


@contextmanager
def output_dir(path: str | Path, inputs: Sequence[str | Path] = (),
               force: bool = False) -> Iterator[Path]:
    """Yield a temporary folder to write into; on success it replaces ``path`` as a whole
    (an earlier run's folder is moved aside, the new one renamed into place, the old one
    removed), so the folder never mixes two runs' files and a failed run leaves the old one
    as it was. Only what an earlier run wrote is ever removed: anything else in ``path`` is
    refused (before the work and again at the replacement), or with ``force`` moved into a
    sibling ``<name>.kept-<time>`` folder."""
    path = check_output_dir(path, inputs, force)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _clean_leftovers(path.parent, path.name)
        # a place the permission bits allow may still refuse a folder (/proc, a read-only
        # mount): the first write there is the test
        tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.tmp-{os.getpid()}-", dir=path.parent))
    except OSError as exc:
        raise InputError(str(path), "--out", f"cannot be created ({exc.strerror or exc})",
                         "give a folder in a place you can write to") from None
    try:
        yield tmp  # no input lies inside path (check_output_dir), so none is replaced
        _write_manifest(tmp)
        os.chmod(tmp, 0o777 & ~_UMASK)  # mkdtemp makes 0700; outputs are ordinary folders
        stop_if_requested()
        _replace_folder(tmp, path, force)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _keep_aside(path: Path, found: Sequence[str]) -> Path:
    """Move the entries ``found`` of ``path`` into a new sibling ``<name>.kept-<time>``
    folder, keeping their relative paths; say so on stderr."""
    kept = _kept_path(lambda tag: path.parent / f"{path.name}.kept-{tag}")
    for rel in found:
        src = path / rel.rstrip("/")
        dst = kept / rel.rstrip("/")
        dst.parent.mkdir(parents=True, exist_ok=True)
        os.rename(src, dst)
    print(f"spindle-verify: moved {len(found)} entr{'ies' if len(found) > 1 else 'y'} it did "
          f"not write from {path} into {kept} (--force): {_list_some(found)}", file=sys.stderr)
    return kept


def _replace_folder(new: Path, path: Path, force: bool = False) -> None:
    """Rename ``new`` to ``path``. From an existing ``path`` what the user put there is first
    moved into a sibling folder (:func:`_keep_aside`; only with ``force``, without it the run
    is refused as before its work); the rest, all the tool's, is moved aside (restored if the
    rename fails) and removed."""
    if not path.exists():
        os.rename(new, path)
        return
    found = foreign_files(path)  # again: the user may have added files during the run
    if found and not force:
        raise _refuse_foreign(path, found)
    if found:  # first, so that what is moved aside and removed below is only the tool's
        _keep_aside(path, found)
    old = Path(tempfile.mkdtemp(prefix=f".{path.name}.old-{os.getpid()}-", dir=path.parent))
    os.rmdir(old)
    os.rename(path, old)
    try:
        os.rename(new, path)
    except OSError:
        os.rename(old, path)
        raise
    shutil.rmtree(old, ignore_errors=True)


#: significant digits of a float in a CSV: far beyond any figure the models resolve (their
#: round-off is 1e-12 relative), and no 19.500000000000057 for 19.5
CSV_DIGITS = 10


def csv_cell(v: Any) -> Any:
    """A value as a CSV cell: a float to CSV_DIGITS significant digits, a missing value (NaN,
    None, infinite) empty; anything else as it is (the project's one number format:
    docs/spec.md, "Outputs")."""
    if v is None:
        return ""
    if isinstance(v, bool | np.bool_):
        return bool(v)
    if isinstance(v, float | np.floating):
        return format(float(v), f".{CSV_DIGITS}g") if math.isfinite(v) else ""
    return v


def write_csv(path: Path, header: list[str], rows) -> None:
    """A CSV file with a header row, written atomically; cells as :func:`csv_cell` makes
    them."""
    def write(tmp: Path) -> None:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(header)
            w.writerows([csv_cell(c) for c in r] for r in rows)

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


def result_folder(out, pictures: bool = True) -> Path:
    """The folder ``out`` for a result's ``save``, made with its parents: TypeError unless
    ``out`` is a path and ``pictures`` True or False (a ``pictures='no'`` drew them),
    NotADirectoryError where ``out`` is a file."""
    if not isinstance(out, str | os.PathLike):
        raise TypeError(f"out must be a folder's path, not {type(out).__name__}")
    if not isinstance(pictures, bool):
        raise TypeError(f"pictures must be True or False, not {pictures!r}")
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise NotADirectoryError(f"{out} is a file, not a folder for the result's files")
    out.mkdir(parents=True, exist_ok=True)
    return out

