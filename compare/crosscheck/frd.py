"""Reading CalculiX's ASCII result file (.frd): nodal temperatures and displacements, and the
precision that file holds them to."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def read_frd(path: str | Path) -> dict:
    """Nodal results of an ASCII ``.frd`` file (the last block of each name).

    Returns ``{"node_ids", "coords" (n x 3, m), "results": {name: {"components",
    "node_ids", "values"}}, "T": temperatures by node id - 1 (NaN if absent), "U": (N x 3)
    displacements [m] by node id - 1}``; ``T`` and ``U`` are None when not in the file.
    """
    lines = Path(path).read_text(encoding="ascii", errors="replace").splitlines()
    node_ids: list[int] = []
    coords: list[list[float]] = []
    results: dict[str, dict] = {}
    i, nl = 0, len(lines)

    def values(line: str) -> list[float]:
        body = line[13:]
        return [float(body[k:k + 12]) for k in range(0, len(body.rstrip()), 12)]

    while i < nl:
        line = lines[i]
        key = line[:7].strip()
        if key == "2C":  # node block
            i += 1
            while i < nl and lines[i].startswith(" -1"):
                node_ids.append(int(lines[i][3:13]))
                coords.append(values(lines[i]))
                i += 1
            continue
        if key == "100CL":  # result block
            i += 1
            name = lines[i][5:13].strip()
            comps = []
            i += 1
            while i < nl and lines[i].startswith(" -5"):
                comps.append(lines[i][5:13].strip())
                i += 1
            ids, vals = [], []
            while i < nl and (lines[i].startswith(" -1") or lines[i].startswith(" -2")):
                if lines[i].startswith(" -1"):
                    ids.append(int(lines[i][3:13]))
                    vals.append(values(lines[i]))
                else:
                    vals[-1].extend(values(lines[i]))
                i += 1
            width = min((len(v) for v in vals), default=0)
            results[name] = {"components": comps[:width] if width else comps,
                             "node_ids": np.array(ids, dtype=np.int64),
                             "values": np.array([v[:width] for v in vals])}
            continue
        i += 1
    out: dict = {"node_ids": np.array(node_ids, dtype=np.int64),
                 "coords": np.array(coords), "results": results, "T": None, "U": None}
    n = max([0, *node_ids] + [int(r["node_ids"].max(initial=0)) for r in results.values()])
    if "NDTEMP" in results:
        T = np.full(n, np.nan)
        r = results["NDTEMP"]
        T[r["node_ids"] - 1] = r["values"][:, 0]
        out["T"] = T
    if "DISP" in results:
        U = np.full((n, 3), np.nan)
        r = results["DISP"]
        U[r["node_ids"] - 1] = r["values"][:, :3]
        out["U"] = U
    return out


def half_ulp(values: np.ndarray) -> np.ndarray:
    """Bound of the rounding of a value in ccx's result file: ccx casts to single precision
    (relative 2^-24) and prints ``%12.5E`` (6 significant digits: half a unit 0.5e-5 of the
    leading digit's place)."""
    v = np.abs(np.asarray(values, dtype=float))
    out = np.zeros_like(v)
    nz = v > 0
    out[nz] = 0.5 * 10.0 ** (np.floor(np.log10(v[nz])) - 5) + 2.0 ** -24 * v[nz]
    return out
