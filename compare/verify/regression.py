"""Regression verification: store the figures of a study, recompute them later, and fail
when one moved beyond its tolerance.

``spindle-verify baseline SPEC --out FILE`` writes a JSON file with the settings of the study
(spec, levels, node counts, time step), the tolerances, and a flat table of figures:
values (sensor temperatures in degC, growth in µm), errors against the reference, the
ground-truth level and the worst GCI. ``spindle-verify check FILE`` recomputes them with the
same settings and exits 1 with a readable diff when any figure moved by more than its
tolerance, 0 otherwise. Edit the tolerances in the file to suit; by default a temperature
may move 0.01 K, a growth 0.01 µm, a GCI 0.01 percentage points, a level not at all.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from lumped.build import MAX_NODES
from spindle.errors import InputError, SpindleVerifyError
from spindle.units import MESH_LEVEL_MAX, ZERO_C_K

FORMAT = "spindle-verify-baseline/1"
DEFAULT_TOLERANCES = {"temperature_K": 0.01, "growth_um": 0.01, "gci_pct": 0.01, "level": 0}
DEFAULT_SETTINGS = {"levels": [0, 1, 2], "nodes": [5, 11], "dt_s": 300.0, "transient": True,
                    "threshold_pct": 1.0}


def figures_of(study) -> dict[str, float | int | None]:
    """The flat table of figures of a :class:`compare.verify.study.StudyResult`."""
    fig: dict[str, float | int | None] = {}
    conv = study.convergence
    fig["convergence/ground_truth_level"] = study.ground_truth_level
    worst = conv.summary()["worst_GCI_pct_per_level"]
    for lv, v in worst.items():
        fig[f"convergence/level_{lv}/worst_GCI_pct"] = v
    for acc in (study.steady, study.transient):
        if acc is None:
            continue
        tag = "transient" if acc.transient else "steady"
        t = acc.table()
        for i, name in enumerate(t["model"]):
            for k, col in t.items():
                if (k.endswith("_K") or k.endswith("_um")) and isinstance(col[i], float):
                    fig[f"{tag}/{name}/err_{k}"] = None if math.isnan(col[i]) else col[i]
        for e in acc.entries:
            for s in ("T1", "T2"):
                if s in e.sensors:
                    v = e.sensors[s]
                    fig[f"{tag}/{e.name}/{s}_{'peak_' if acc.transient else ''}C"] = \
                        float(max(v) if acc.transient else v) - ZERO_C_K
            for g, v in e.growth.items():
                fig[f"{tag}/{e.name}/{g}_{'peak_' if acc.transient else ''}um"] = \
                    float(max(v) if acc.transient else v) * 1e6
    return fig


def _tolerance(name: str, tol: dict) -> float:
    if name.endswith("_level"):
        return float(tol.get("level", 0))
    if name.endswith("_pct"):
        return float(tol["gci_pct"])
    if name.endswith("_um"):
        return float(tol["growth_um"])
    return float(tol["temperature_K"])  # _C and _K


def compute(spec_ref: str, settings: dict, progress: Callable[[str], None] | None = None
            ) -> dict[str, float | int | None]:
    from compare.verify.study import run_study
    from spindle.spec_reader import load_spec

    spec = load_spec(spec_ref)
    study = run_study(spec, settings["levels"], settings["nodes"],
                      transient=settings["transient"], dt_s=settings["dt_s"],
                      threshold=settings["threshold_pct"] / 100.0, progress=progress)
    if study.failures:  # a partial table would store (or check) figures that are missing
        raise SpindleVerifyError(f"{spec_ref}: {len(study.failures)} run(s) of the study "
                                 "failed: " + "; ".join(f"{f['label']}: {f['error']}"
                                                        for f in study.failures))
    return figures_of(study)


def make_baseline(spec_ref: str, settings: dict | None = None,
                  tolerances: dict | None = None,
                  progress: Callable[[str], None] | None = None) -> dict:
    """The baseline document (a dict ready for JSON)."""
    settings = {**DEFAULT_SETTINGS, **(settings or {})}
    t = time.perf_counter()
    figures = compute(spec_ref, settings, progress)
    return {"format": FORMAT, "spec": spec_ref, "settings": settings,
            "tolerances": {**DEFAULT_TOLERANCES, **(tolerances or {})},
            "created_with_runtime_s": round(time.perf_counter() - t, 1), "figures": figures}


@dataclass
class Change:
    figure: str
    baseline: float | int | None
    now: float | int | None
    tolerance: float

    @property
    def moved(self) -> bool:
        if self.baseline is None or self.now is None:  # a figure appeared or vanished
            return self.baseline != self.now
        return abs(self.now - self.baseline) > self.tolerance

    def line(self) -> str:
        if self.baseline is None or self.now is None:
            return f"  {self.figure}: {self.baseline} -> {self.now}"
        return (f"  {self.figure}: {self.baseline:.6g} -> {self.now:.6g} "
                f"(change {self.now - self.baseline:+.3g}, tolerance {self.tolerance:g})")


def read_baseline(path: str | Path) -> dict:
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8-sig"))
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) else "not UTF-8 text"
        raise InputError(str(path), "file", f"cannot be read ({why})",
                         "give the file written by 'spindle-verify baseline'") from None
    except json.JSONDecodeError as exc:
        raise InputError(str(path), f"line {exc.lineno}", f"is not valid JSON ({exc.msg})",
                         "restore the file or write a new one with 'spindle-verify baseline'"
                         ) from None
    if not isinstance(doc, dict) or doc.get("format") != FORMAT:
        raise InputError(str(path), "format", f"is not a {FORMAT} file",
                         "write one with 'spindle-verify baseline SPEC --out FILE'")
    for key in ("spec", "settings", "tolerances", "figures"):
        if key not in doc:
            raise InputError(str(path), key, "is missing", "write a new baseline")
    _check_contents(doc, lambda fld, message, fix="write a new baseline with 'spindle-verify "
                    "baseline SPEC --out FILE'": InputError(str(path), fld, message, fix))
    return doc


def _check_contents(doc: dict, refuse: Callable[..., InputError]) -> None:
    """Every field ``check`` reads has its type and range (``refuse(field, message[, fix])``
    makes the error): a NaN tolerance passed every figure, a figure of text was a TypeError."""
    known = ("format", "spec", "settings", "tolerances", "created_with_runtime_s", "figures")
    for where, table, keys in (("", doc, known), ("tolerances.", doc["tolerances"],
                                                  DEFAULT_TOLERANCES),
                               ("settings.", doc["settings"], DEFAULT_SETTINGS)):
        # a misspelt tolerance or setting was ignored, and its default used without a word
        extra = next((k for k in table if k not in keys), None) if isinstance(table, dict) else None
        if extra is not None:
            raise refuse(f"{where}{extra}", "is not a field of a baseline",
                         f"remove it or use one of {list(keys)}")
    tol = doc["tolerances"]
    if not isinstance(tol, dict):
        raise refuse("tolerances", "must be a table of numbers")
    for key in ("temperature_K", "growth_um", "gci_pct"):
        if not _number(tol.get(key)) or tol[key] < 0:
            raise refuse(f"tolerances.{key}", "must be a finite number >= 0",
                         f"set it, e.g. {DEFAULT_TOLERANCES[key]}")
    if not isinstance(doc["spec"], str):
        raise refuse("spec", "must be the spec's name or path (text)")
    figs = doc["figures"]
    if not isinstance(figs, dict) or not figs:
        raise refuse("figures", "must be a non-empty table of figures")
    bad = next((k for k, v in figs.items() if v is not None and not _number(v)), None)
    if bad is not None:
        raise refuse(f"figures.{bad}", f"{figs[bad]!r} is not a finite number")
    settings = doc["settings"]
    if not isinstance(settings, dict):
        raise refuse("settings", "must be a table")
    settings = {**DEFAULT_SETTINGS, **settings}
    # the study's own ranges: mesh levels (three or more for a GCI), lumped nodes
    levels, nodes = settings["levels"], settings["nodes"]
    if not _integers(levels, 0, MESH_LEVEL_MAX) or len(set(levels)) < 3:
        raise refuse("settings.levels", f"{levels!r} is not three or more mesh levels "
                     f"0..{MESH_LEVEL_MAX}")
    if not _integers(nodes, 2, MAX_NODES) or not nodes:
        raise refuse("settings.nodes", f"{nodes!r} is not a list of node counts 2..{MAX_NODES}")
    for key in ("dt_s", "threshold_pct"):
        if not _number(settings[key]) or settings[key] <= 0:
            raise refuse(f"settings.{key}", f"{settings[key]!r} is not a number > 0")
    if not isinstance(settings["transient"], bool):
        raise refuse("settings.transient", f"{settings['transient']!r} is not true or false")


def _integers(v: object, lo: int, hi: int) -> bool:
    """Whether ``v`` is a list of whole numbers in lo..hi."""
    return isinstance(v, list) and all(isinstance(x, int) and not isinstance(x, bool)
                                       and lo <= x <= hi for x in v)


def _number(v: object) -> bool:
    """Whether ``v`` is a finite JSON number (not a boolean)."""
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def check(doc: dict, figures: dict | None = None,
          progress: Callable[[str], None] | None = None) -> list[Change]:
    """Recompute (unless ``figures`` are given) and list every figure with its change."""
    settings = {**DEFAULT_SETTINGS, **doc["settings"]}
    now = figures if figures is not None else compute(doc["spec"], settings, progress)
    names = list(dict.fromkeys([*doc["figures"], *now]))
    return [Change(n, doc["figures"].get(n), now.get(n), _tolerance(n, doc["tolerances"]))
            for n in names]
