"""Checks of the Python API's arguments: a wrong type or value is named by its argument,
not met deep inside numpy, scipy or scikit-fem (found by fuzzing the API: a level of '1' was
"'<' not supported between instances of 'str' and 'int'", a level of 1.5 an IndexError in
skfem, a nodes of None "int() argument must be ...")."""

from __future__ import annotations

import math
import numbers


def whole_number(value, name: str, lo: int, hi: int | None = None) -> int:
    """``value`` as an int: TypeError unless it is a whole number (not a bool, not text),
    ValueError outside lo..hi."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or (
            not isinstance(value, numbers.Integral)
            and not (math.isfinite(value) and float(value).is_integer())):
        raise TypeError(f"{name} must be a whole number, not {value!r}")
    if value < lo or (hi is not None and value > hi):
        raise ValueError(f"{name} is {value}, outside {lo}..{'' if hi is None else hi}")
    return int(value)


def real_number(value, name: str, lo: float | None = None, hi: float | None = None,
                unit: str = "") -> float:
    """``value`` as a float: TypeError unless it is a number (not a bool, not text),
    ValueError where it is not finite or outside lo..hi."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a number{f' in {unit}' if unit else ''}, not "
                        f"{value!r}")
    v = float(value)
    if not math.isfinite(v) or (lo is not None and v < lo) or (hi is not None and v > hi):
        span = f"{'' if lo is None else f'{lo:g}'}..{'' if hi is None else f'{hi:g}'}"
        raise ValueError(f"{name} is {value!r}, not a finite number in {span} {unit}".rstrip())
    return v


def model_choice(model) -> tuple[str, int | str]:
    """``"fem:L"`` (the reference at mesh level L; ``"fem"``: 2) or ``"lumped:N"`` (N masses,
    or a preset's name; ``"lumped"``: 11) as (kind, level or nodes)."""
    from spindle.units import MESH_LEVEL_MAX

    if not isinstance(model, str):
        raise TypeError(f"model must be 'fem:L' or 'lumped:N' (text), not {model!r}")
    kind, _, size = model.partition(":")
    if kind == "fem":
        if size and not size.isdigit():
            raise ValueError(f"model '{model}': L is a mesh level 0..{MESH_LEVEL_MAX}")
        return kind, int(size or 2)
    if kind == "lumped":
        return kind, int(size) if size.isdigit() else (size or 11)
    raise ValueError(f"model '{model}': use 'fem:L' or 'lumped:N'")
