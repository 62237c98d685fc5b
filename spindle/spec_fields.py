"""The field reader of a spec file: typed reads of TOML tables (numbers with units and
ranges, radii, speed tables, film correlations, power series) that collect every problem,
each naming the file, the field and the fix, and never stop at the first."""

from __future__ import annotations

import math
from typing import Any

from spindle.errors import Problem
from spindle.loads import SpeedTable, TimeSeries

#: the fields every table of a spec may hold (docs/spec.md); ``description``, ``source`` and
#: ``note`` document an entry anywhere
_DOC = ("description", "source", "note")
KNOWN_FIELDS: dict[str, tuple[str, ...]] = {
    "": ("spindle", "operating", "power_balance", "mesh", "materials", "parts", "links",
         "surfaces", "heat_sources", "sensors", "sensor_arrays"),
    "spindle": ("name", *_DOC),
    "operating": ("speed_rpm", "T_ambient_K", "T_coolant_K", "T_initial_K", *_DOC),
    "power_balance": ("preset", *_DOC),
    "mesh": ("h0_m", *_DOC),
    "materials": ("k_W_mK", "k_r_W_mK", "k_z_W_mK", "rho_kg_m3", "c_J_kgK", "E_Pa", "nu",
                  "alpha_1_K", *_DOC),
    "parts": ("name", "role", "material", "sections", *_DOC),
    "sections": ("z_start", "z_end", "r_inner", "r_outer", "material", "name", *_DOC),
    "links.bearing": ("type", "part", "section", "G_W_K", *_DOC),
    "links.air_gap": ("type", "inner", "outer", "h_W_m2K", *_DOC),
    "links.contact": ("type", "parts", "h_W_m2K", *_DOC),
    "surfaces": ("name", "parts", "part", "side", "z_min", "z_max", "h_W_m2K", "T_ref", *_DOC),
    "heat_sources": ("name", "power_W", "part", "section", "surface", *_DOC),
    "sensors": ("name", "kind", "z", "r", "z_ref", "r_ref", *_DOC),
    "sensor_arrays": ("name", "part", "count", "radius", *_DOC),
}
def finite_number(v: Any) -> float | None:
    """``v`` as a finite float, or None (not a number, a bool, NaN, inf, or an integer too
    large for a float)."""
    if isinstance(v, bool) or not isinstance(v, int | float):
        return None
    try:
        f = float(v)
    except OverflowError:
        return None
    return f if math.isfinite(f) else None


def exact(v: float) -> str:
    """``v`` as short as ``:g`` writes it where that is the same number, else in full, so that
    a value just beyond a bound does not read as the bound's other side (0.4999999999, not
    0.5, against a bound of 0.4999)."""
    short = f"{v:g}"
    return short if float(short) == v else repr(float(v))


def show_value(v: Any) -> str:
    """A short text for a bad value in a message (no 400-digit integers)."""
    text = repr(v)
    return text if len(text) <= 40 else text[:37] + "..."


#: plausibility limits of a motor spindle's description, with the reason (docs/spec.md)
MAX_POWER_W = 1e6
#: film coefficients: forced water convection reaches 1e4-1e5 W/m2/K; 1e6 is boiling
MAX_FILM_W_M2K = 1e6
PLAUSIBLE_FILM = "air films are 5-500 W/m2/K, water jackets up to 1e5"
#: bearing conductances: a pair conducts 5-50 W/K (docs/spec.md)
MAX_G_W_K = 1e5
PLAUSIBLE_POWER = "a motor spindle's losses are watts to kilowatts (SPL2782: 5.1 kW in all)"


class FieldReader:
    """Collects problems while reading nested TOML tables; never stops at the first."""

    def __init__(self, file: str):
        self.file = file
        self.problems: list[Problem] = []
        #: fields whose problems follow from one already reported (a misspelt or missing
        #: table): not reported again
        self.quiet: set[str] = set()
        #: names of parts, surfaces and materials that are defined but could not be read:
        #: a reference to one is not a second problem
        self.broken: dict[str, set[str]] = {"part": set(), "surface": set(), "material": set(),
                                            "section": set()}  # sections as "part/section"
        #: required lists (``parts``, ``surfaces``) that are missing or could not be read:
        #: every name a reference looks up in one is unknown, and not a problem of its own
        self.absent: set[str] = set()

    def add(self, fld: str, message: str, fix: str) -> None:
        if any(fld == q or fld.startswith(q + ".") or fld.startswith(q + "[")
               for q in self.quiet):
            return
        self.problems.append(Problem(self.file, fld, message, fix))

    def unknown(self, kind: str, name: str, fld: str, fix: str) -> None:
        """An unknown ``kind`` (part, surface, material) named ``name`` at ``fld``; nothing
        when that name is defined but broken, or its whole list is (its own problem is the
        root cause)."""
        if name not in self.broken[kind] and f"{kind}s" not in self.absent:
            self.add(fld, f"unknown {kind} '{name}'", fix)

    def keys(self, data: dict, known: tuple[str, ...], path: str) -> None:
        """Every key of ``data`` must be one of ``known``: an unknown one (a misspelling) is a
        problem with the nearest known name; the field it was meant for is then not reported
        missing as well."""
        import difflib

        for k in data:
            if k in known:
                continue
            near = difflib.get_close_matches(str(k), known, n=1, cutoff=0.6)
            where = f"{path}.{k}" if path else str(k)
            what = "table" if not path and isinstance(data[k], dict | list) else "field"
            if near:
                self.add(where, f"unknown {what} '{k}'", f"did you mean '{near[0]}'?")
                self.quiet.add(f"{path}.{near[0]}" if path else near[0])
            else:
                self.add(where, f"unknown {what} '{k}'",
                         f"use one of: {', '.join(known)} (docs/spec.md)")

    def table(self, data: dict, key: str, path: str, required: bool = True) -> dict | None:
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}{key}", "required table is missing", f"add a [{path}{key}] table")
                self.quiet.add(f"{path}{key}")  # its fields are not missing a second time
            return None
        if not isinstance(v, dict):
            self.add(f"{path}{key}", "must be a table", f"write it as [{path}{key}]")
            self.quiet.add(f"{path}{key}")
            return None
        return v

    def array(self, data: dict, key: str, path: str, required: bool = True) -> list[dict]:
        v = data.get(key)
        if v is None:
            if required:
                self.add(key, "required list is missing", f"add at least one [[{key}]] entry")
                self.absent.add(key)
            return []
        if not isinstance(v, list) or not all(isinstance(x, dict) for x in v):
            self.absent.add(key)
            self.add(f"{path}{key}", "must be a list of tables", f"write entries as [[{key}]]")
            return []
        if required and not v:
            self.absent.add(key)
            self.add(f"{path}{key}", "the list is empty", f"add at least one [[{key}]] entry")
        return v

    def string(self, data: dict, key: str, path: str, required: bool = True,
               choices: tuple[str, ...] | None = None, default: str | None = None) -> str | None:
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}.{key}", "required field is missing", f"add {key} = \"...\"")
            return default
        if not isinstance(v, str) or not v:
            self.add(f"{path}.{key}", f"must be a text, not {v!r}", f"write {key} = \"...\"")
            return default
        if choices is not None and v not in choices:
            self.add(f"{path}.{key}", f"'{v}' is not one of {', '.join(choices)}",
                     f"use one of {', '.join(choices)}")
            return default
        return v

    def number(self, data: dict, key: str, path: str, unit: str, required: bool = True,
               default: float | None = None, lo: float | None = None, lo_open: bool = False,
               hi: float | None = None) -> float | None:
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}.{key}", "required field is missing",
                         f"add {key} = <number in {unit}>")
            return default
        v = finite_number(v)
        if v is None:
            self.add(f"{path}.{key}", f"must be a finite number in {unit}, not "
                     f"{show_value(data.get(key))}", f"write {key} = <number in {unit}>")
            return default
        if lo is not None and (v <= lo if lo_open else v < lo):
            rel = ">" if lo_open else ">="
            self.add(f"{path}.{key}", f"{exact(v)} {unit} is not physical (must be {rel} {lo:g})",
                     f"give {key} {rel} {lo:g} {unit}")
            return default
        if hi is not None and v > hi:
            self.add(f"{path}.{key}", f"{exact(v)} {unit} is out of range (must be <= {hi:g})",
                     f"give {key} <= {hi:g} {unit}")
            return default
        return v

    def radius(self, data: dict, key: str, path: str) -> tuple[float, float] | None:
        v = data.get(key)
        ends = ([finite_number(x) for x in v] if isinstance(v, list) and len(v) == 2
                else [finite_number(v)] * 2)
        if None not in ends:
            pair = (ends[0], ends[1])
        elif v is None:
            self.add(f"{path}.{key}", "required field is missing",
                     f"add {key} = <radius in m> (or [start, end] for a cone)")
            return None
        else:
            self.add(f"{path}.{key}", f"must be a finite radius in m or [start, end], not "
                     f"{show_value(v)}", f"write {key} = 0.04 or {key} = [0.04, 0.05]")
            return None
        if min(pair) < 0:
            self.add(f"{path}.{key}", "a radius cannot be negative", "give radii >= 0 m")
            return None
        return pair

    def speed_table(self, data: dict, key: str, path: str, unit: str,
                    required: bool = True) -> SpeedTable | None:
        """A constant, or {speed_rpm = [...], value = [...]} interpolated in speed."""
        v = data.get(key)
        if v is None:
            if required:
                self.add(f"{path}.{key}", "required field is missing",
                         f"add {key} = <number in {unit}>")
            return None
        if isinstance(v, dict) and "correlation" in v:
            return self.correlation(v, f"{path}.{key}")
        if isinstance(v, dict):
            n, vals = v.get("speed_rpm"), v.get("value")
            ok = (isinstance(n, list) and isinstance(vals, list) and len(n) == len(vals) >= 1
                  and all(finite_number(x) is not None for x in [*n, *vals]))
            if not ok:
                self.add(f"{path}.{key}", "a speed table needs lists speed_rpm and value of "
                         "equal length", f"write {key} = {{speed_rpm = [0, 4300], value = [10, 60]}}")
                return None
            if any(b <= a for a, b in zip(n, n[1:], strict=False)):
                self.add(f"{path}.{key}.speed_rpm", "must increase", "sort the table by speed")
                return None
            if min(n) < 0:  # a speed is its magnitude, as in the cycles
                self.add(f"{path}.{key}.speed_rpm", f"{min(n):g} rpm is below 0",
                         "give speeds >= 0 rpm (the direction of rotation plays no part)")
                return None
            if min(vals) < 0:
                self.add(f"{path}.{key}.value", f"negative {unit} is not physical",
                         "give values >= 0")
                return None
            return SpeedTable(tuple(float(x) for x in n), tuple(float(x) for x in vals))
        num = self.number(data, key, path, unit, lo=0.0)
        return None if num is None else SpeedTable.constant(num)

    def correlation(self, d: dict, path: str) -> SpeedTable | None:
        """A film coefficient from a cited correlation of spindle.power, tabulated in speed:
        ``rotating_shaft`` (d_m), ``air_gap`` (r_rotor_m, gap_m) or ``coolant_channel``
        (flow_l_min, width_m, height_m); ``factor`` (default 1) scales the result, e.g. for
        the wetted fraction of a channel modelled as an annulus."""
        from spindle import power

        name = d.get("correlation")
        needs = {"rotating_shaft": ("d_m",), "air_gap": ("r_rotor_m", "gap_m"),
                 "coolant_channel": ("flow_l_min", "width_m", "height_m")}
        if name not in needs:
            self.add(f"{path}.correlation", f"unknown correlation {name!r}",
                     f"use one of: {', '.join(needs)}")
            return None
        extra = set(d) - {"correlation", "factor", *needs[name]}
        if extra:
            self.add(f"{path}.{sorted(extra)[0]}", f"is not a parameter of '{name}'",
                     f"give only {', '.join(needs[name])} (and factor)")
            return None
        n0 = len(self.problems)
        args = [self.number(d, k, path, "l/min" if k == "flow_l_min" else "m", lo=0.0,
                            lo_open=True) for k in needs[name]]
        factor = self.number(d, "factor", path, "-", required=False, default=1.0, lo=0.0,
                             lo_open=True)
        if len(self.problems) > n0:
            return None
        try:
            if name == "rotating_shaft":
                table = power.shaft_film_table(*args)
            elif name == "air_gap":
                table = power.air_gap_film_table(*args)
            else:
                table = SpeedTable.constant(power.h_coolant_channel_W_m2K(*args))
        except (ValueError, ArithmeticError) as exc:
            why = ("a parameter is so large that the correlation overflows" if
                   isinstance(exc, ArithmeticError) else str(exc))  # e.g. d_m = 1e300
            self.add(path, f"the correlation cannot be evaluated ({why})",
                     "check the parameters against the correlation's range in docs/power.md")
            return None
        return SpeedTable(table.speed_rpm, tuple(factor * h for h in table.values))

    def power(self, data: dict, path: str) -> TimeSeries | None:
        """A constant power [W] or {time_s = [...], value = [...]} (linear in time)."""
        v = data.get("power_W")
        if isinstance(v, dict):
            t, vals = v.get("time_s"), v.get("value")
            ok = (isinstance(t, list) and isinstance(vals, list) and len(t) == len(vals) >= 1
                  and all(finite_number(x) is not None for x in [*t, *vals]))
            if not ok or any(b <= a for a, b in zip(t or [], (t or [])[1:], strict=False)):
                self.add(f"{path}.power_W", "a power series needs increasing time_s and value "
                         "lists of equal length",
                         "write power_W = {time_s = [0, 3600], value = [40, 60]}")
                return None
            if min(vals) < 0 or max(vals) > MAX_POWER_W:
                self.add(f"{path}.power_W.value", f"values from {min(vals):g} to {max(vals):g} W "
                         f"are not plausible: {PLAUSIBLE_POWER}", "give values from 0 to "
                         f"{MAX_POWER_W:g} W")
                return None
            return TimeSeries(tuple(map(float, t)), tuple(map(float, vals)))
        num = self.number(data, "power_W", path, "W", lo=0.0, hi=MAX_POWER_W)
        return None if num is None else TimeSeries.constant(num)
