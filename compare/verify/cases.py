"""Load cases, option checks and the result writer shared by the node-count choice
(:mod:`.nodecount`) and the sensor placement (:mod:`.placement`)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from spindle.errors import InputError
from spindle.loads import LoadCase
from spindle.spec import Spec
from spindle.units import MESH_LEVEL_MAX


# ============================================================================ load cases
def default_cases(spec: Spec) -> list[LoadCase]:
    """The two cases of :func:`compare.verify.study.study_cases`: the steady one (its duration set
    to 0 s, so it runs as a steady state) and the transient one (spl-16h, or the 8 h warm-up
    of a spec without a power balance)."""
    from compare.verify.study import study_cases

    steady, transient = study_cases(spec)
    return [replace(steady, duration_s=0.0), transient]


def load_cases(spec: Spec, names: Sequence[str], steady_cycles: bool = True) -> list[LoadCase]:
    """Load cases from shipped cycle names, ``rated`` / ``rated-16h`` (the spindle's own
    rating: spindle.drive.rated_cycles) or cycle files, through the spec's power balance
    (:func:`spindle.drive.cycle_load_case`). A cycle marked ``steady`` (``nominal``) becomes a
    steady case (duration 0 s) when ``steady_cycles``; every other cycle is a transient."""
    from spindle.drive import cycle_load_case, spindle_cycle

    out = []
    for name in names:
        cycle = spindle_cycle(spec, name)
        case = cycle_load_case(spec, cycle)
        if cycle.steady and steady_cycles:
            case = replace(case, duration_s=0.0)
        out.append(case)
    return out


def transient_default(spec: Spec) -> LoadCase:
    from compare.verify.study import study_cases

    return study_cases(spec)[1]


def save_result(result, out: Path, stem: str, pictures: bool) -> list[Path]:
    """``<stem>.csv`` (``result.table()``), ``<stem>.json`` (``result.summary()``) and
    ``<stem>.png`` (``result.plot()``), each written atomically."""
    from spindle.outputs import atomic_write, write_csv, write_json
    from spindle.plots import pyplot

    out.mkdir(parents=True, exist_ok=True)
    t = result.table()
    write_csv(out / f"{stem}.csv", list(t), zip(*t.values(), strict=True))
    write_json(out / f"{stem}.json", result.summary())
    files = [out / f"{stem}.csv", out / f"{stem}.json"]
    if pictures:
        fig = result.plot()
        atomic_write(out / f"{stem}.png", lambda tmp: fig.savefig(tmp, dpi=130))
        pyplot().close(fig)
        files.append(out / f"{stem}.png")
    return files


def check_level(level: int, option: str) -> None:
    if not 0 <= int(level) <= MESH_LEVEL_MAX:
        raise InputError("command line", option, f"{level} is out of range",
                         f"give a level between 0 and {MESH_LEVEL_MAX}")


def check_positive(value: float, option: str, unit: str) -> None:
    if not (math.isfinite(value) and value > 0):
        raise InputError("command line", option, f"{value:g} {unit} must be > 0",
                         f"give a positive value in {unit}")
