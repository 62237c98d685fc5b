"""Values of a table of named entries read from TOML (compare/fit/criteria.toml): each checked
against its declared type and converted to it (:func:`conform`), and against its range and
the values it excludes (:func:`in_range`); a problem is an InputError naming the file and the
entry."""

from __future__ import annotations

import math
import typing
from collections.abc import Mapping, Sequence
from dataclasses import is_dataclass

from spindle.errors import InputError

FIX = "give it as the table compare/fit/criteria.toml does"


def conform(value, hint, where: tuple[str, str]):
    """``value`` as read from TOML, checked against the type ``hint`` and converted to it
    (arrays to tuples, tables to the dataclass, an integer to a float where a float is
    asked); ``where``: (file, entry) of the error message."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is tuple:
        kinds = [args[0]] * len(value) if Ellipsis in args and isinstance(value, list) else args
        if isinstance(value, list) and not value:
            raise InputError(*where, "is an empty array", "give at least one value" if
                             Ellipsis in args else f"give {len(args)} values")
        if not isinstance(value, list) or len(value) != len(kinds):
            raise InputError(*where, f"is {value!r}, not an array" + (
                " of values" if Ellipsis in args else f" of {len(args)} values"), FIX)
        out = tuple(conform(v, kind, where) for v, kind in zip(value, kinds, strict=True))
        if args == (float, float) and not out[0] < out[1]:  # a window [from, to]
            raise InputError(*where, f"is {value!r}, a window that does not increase",
                             "give [from, to] with from < to")
        return out
    if is_dataclass(hint):
        hints = typing.get_type_hints(hint)
        if not isinstance(value, dict) or set(value) != set(hints):
            raise InputError(*where, f"is {value!r}", f"give each of {', '.join(hints)}")
        return hint(**{k: conform(value[k], hints[k], where) for k in hints})
    ok = (isinstance(value, bool) if hint is bool else
          isinstance(value, int | float) and not isinstance(value, bool)
          and math.isfinite(value) and (hint is float or isinstance(value, int))
          if hint in (int, float) else isinstance(value, hint))
    if not ok:
        raise InputError(*where, f"is {value!r}, not a{'n' if hint is int else ''} "
                         f"{hint.__name__}", FIX)
    return float(value) if hint is float else value


def in_range(value, bounds: Sequence[float] | None, where: tuple[str, str],
              excluded: Mapping[str, str] | None = None):
    """``value`` unless it is a number outside ``bounds`` (the entry's ``range``; default: not
    negative, as each number of the table is a count, duration, level or share) or one the
    entry ``excluded`` (value as text: why): InputError."""
    lo, hi = bounds or (0, math.inf)
    if not isinstance(value, int | float) or isinstance(value, bool):
        return value
    if not lo <= value <= hi:
        raise InputError(*where, f"is {value}, outside {lo}..{hi}",
                         "give a value in that range (compare/fit/criteria.toml)")
    if why := (excluded or {}).get(f"{value:g}"):
        raise InputError(*where, f"is {value}: {why}", f"give a value in {lo}..{hi} other "
                         f"than {', '.join(excluded)} (compare/fit/criteria.toml)")
    return value
