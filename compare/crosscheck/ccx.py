"""Finding and running the CalculiX executable (``ccx``, tested with 2.20)."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

from spindle.errors import InputError, SolverError

CCX_MISSING = "ccx not found; fix: install the Debian package calculix-ccx"


def run_ccx(deck_path: str | Path, timeout_s: float = 600) -> Path:
    """Run ``ccx -i <name>`` in the deck's folder; return the ``.frd`` result file.

    Raises :class:`~spindle.errors.SolverError` if ccx is missing, times out or reports an
    error (the message quotes ccx's own lines).
    """
    exe = shutil.which("ccx")
    if exe is None:
        raise SolverError(CCX_MISSING)
    deck = Path(deck_path)
    if deck.suffix != ".inp":
        deck = deck.with_suffix(".inp")
    if not deck.is_file():
        raise InputError(str(deck), "deck", "does not exist", "write it with export_deck first")
    env = {**os.environ, "OMP_NUM_THREADS": "2", "CCX_NPROC_EQUATION_SOLVER": "2"}
    frd = deck.with_suffix(".frd")
    frd.unlink(missing_ok=True)
    try:
        proc = subprocess.run([exe, "-i", deck.stem], cwd=deck.parent, env=env, timeout=timeout_s,
                              capture_output=True, text=True, errors="replace")
    except subprocess.TimeoutExpired:
        raise SolverError(f"{deck}: ccx did not finish within {timeout_s:g} s; fix: use a "
                          "coarser --level or a longer timeout") from None
    out = proc.stdout + proc.stderr
    deck.with_suffix(".log").write_text(out, encoding="utf-8")
    errors = [ln.strip() for ln in out.splitlines() if "ERROR" in ln]
    if proc.returncode != 0 or errors or not frd.is_file() or "Job finished" not in out:
        detail = "; ".join(errors[:3]) or (out.strip().splitlines() or ["no output"])[-1]
        raise SolverError(f"{deck}: ccx failed (exit status {proc.returncode}): {detail}; "
                          f"fix: see {deck.with_suffix('.log')}")
    return frd


def ccx_version(log: Path) -> str:
    """The version ccx printed in its log (e.g. ``2.20``), or "" if it cannot be read."""
    try:
        for line in log.read_text(encoding="utf-8", errors="replace").splitlines():
            if "CalculiX Version" in line:
                return line.split("Version", 1)[1].split(",")[0].strip()
    except OSError:
        pass
    return ""
