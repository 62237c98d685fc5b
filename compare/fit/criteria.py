"""Every threshold, window and level the fit's rules use, in one table: :class:`Criteria`.

The table is data, compare/fit/criteria.toml: each entry has its value, its unit and its
reason (a statistical argument, a physical bound, a sensor's resolution or a computing
budget). ``fit``'s options (``--alpha``, ``--min-gain``, ``--cv-blocks``) set the entries of
the same names, ``fit --criteria FILE`` any of them (:meth:`Criteria.with_file`), and every
rule that reads them reads them here; the report lists the table it ran with
(:meth:`Criteria.table`) and, for each candidate, which named criteria it passed.
"""

from __future__ import annotations

import math
import tomllib
import typing
from dataclasses import dataclass, field, fields, replace
from importlib.resources import files
from pathlib import Path

from compare.fit.signatures import OnsetScale
from spindle.bench_inputs import HOLD_STEPS, SPEED_BAND_REL, SPEED_BAND_RPM
from spindle.errors import InputError
from spindle.spec import ROLES
from spindle.typed_values import conform, in_range

TABLE_FILE = "criteria.toml"
#: the keys of an entry in the table's form
_ENTRY_KEYS = {"value", "unit", "reason", "range", "excluded"}


def _from_table(cls):
    """Each annotated entry of ``cls`` becomes a field whose default, unit and reason are the
    table's; an entry with a value in the code (one shared with another module) keeps it."""
    table = tomllib.loads(files("compare.fit").joinpath(TABLE_FILE).read_text("utf-8"))
    hints = typing.get_type_hints(cls)
    if set(hints) != set(table):
        raise RuntimeError(f"compare/fit/{TABLE_FILE} and Criteria differ in "
                           f"{sorted(set(hints) ^ set(table))}")
    for name, hint in hints.items():
        entry = table[name]
        meta = {k: entry.get(k) for k in ("unit", "reason", "range", "excluded")}
        value = getattr(cls, name) if "value" not in entry else in_range(conform(
            entry["value"], hint, (TABLE_FILE, name)), meta["range"], (TABLE_FILE, name),
            meta["excluded"])
        setattr(cls, name, field(default=value, metadata=meta))
    return cls


@dataclass(frozen=True)
@_from_table
class Criteria:
    """The criteria of one fit (module docstring; compare/fit/criteria.toml holds each
    entry's value, unit and reason). Frozen: derive another with :meth:`with_options` or
    :meth:`with_file`."""

    # statistics
    alpha: float
    material_peak: float
    open_loop_material_change: bool
    plausible_base_route: bool
    law_rivals: bool
    cv_blocks: int
    cv_gain: float
    held_out_misfit_unexplained: bool
    distinct_among_alternatives: bool
    open_loop_adequate_model: bool
    null_from_candidate: bool
    competitor_step_s: float
    scan_null_tail: int
    competitor_masses: tuple[str, ...]
    speed_bin_rel: float
    # input check
    growth_unit_gain: float
    # base model
    at_bound_rel: float
    missing_path_W_K: float
    optimizer_tol: float
    refit_nfev: int
    # input timing
    gap_min_steps: float = HOLD_STEPS
    start_within_tolerances: float
    prehistory_max_s: float
    gap_judge_s: float
    gap_level_s: float
    # signatures: steps
    step_rpm: float
    moving_rpm: float
    no_load_Nm: float
    speed_band_rpm: float = SPEED_BAND_RPM
    speed_band_rel: float = SPEED_BAND_REL
    step_ramp_s: float
    line_min_samples: int
    line_min_span: float
    onset_min_late_z: float
    jump_min_dn2_krpm2: float
    jump_before_s: tuple[float, float]
    jump_after_s: tuple[float, float]
    jump_se_floor_um: float
    onset_scales: tuple[OnsetScale, ...]
    concave_ratio: float
    lag_grid_s: tuple[float, ...]
    # signatures: power
    drift_min_segment_s: float
    drift_min_segments: int
    drift_early_s: tuple[float, float]
    drift_late_s: float
    window_min_samples: int
    power_resolution_W: float
    level_min_s: float
    level_rpm: float
    min_levels: int
    min_speed_span: float
    # signatures: load
    load_plateau_min_s: float
    load_settle_s: float
    load_block_s: float
    load_span_Nm: float
    load_min_plateaus: int
    load_probe_R_K_W: float
    max_path_correlation: float

    # ---------------------------------------------------------------- derived
    def implausible_z(self) -> float:
        """The prior |z| beyond which a base parameter is implausible: two-sided at alpha."""
        from scipy.stats import norm

        return float(norm.isf(self.alpha / 2))

    def distinct_margin(self) -> float:
        """The log-likelihood margin of ``distinct`` and of :func:`compare.fit.select.complements`:
        half the chi-square quantile of one degree of freedom at alpha (3.3 at 1 %)."""
        return 0.5 * chi2_threshold(self.alpha, 1)

    @classmethod
    def range_of(cls, name: str) -> tuple[float, float]:
        """An entry's range (lo, hi): the table's ``range``, else not negative."""
        return tuple({f.name: f for f in fields(cls)}[name].metadata["range"] or (0, math.inf))

    @classmethod
    def checked(cls, name: str, value, where: tuple[str, str] | None = None):
        """``value`` for the entry ``name`` if the table allows it, else InputError at
        ``where`` (file, field; default criteria, name): each number (of an array too) in the
        entry's range and not one it excludes; each part role one a spec knows."""
        meta = {f.name: f for f in fields(cls)}[name].metadata
        where = where or ("criteria", name)
        if meta["unit"] == "part roles" and (bad := [v for v in value if v not in ROLES]):
            raise InputError(*where, f"names the unknown role {bad[0]!r}",
                             f"use roles of {', '.join(ROLES)}")
        for v in value if isinstance(value, tuple) else (value,):
            in_range(v, cls.range_of(name), where, meta["excluded"])
        return value

    def with_options(self, **values) -> Criteria:
        """These criteria with some entries set (None leaves one as it is), of the entry's
        type (a '0.01' for alpha failed deep in scipy after the base's calibration) and
        range-checked."""
        hints = typing.get_type_hints(Criteria)
        return replace(self, **{
            k: self.checked(k, conform(list(v) if isinstance(v, tuple) else v, hints[k],
                                       ("criteria", k)))
            for k, v in values.items() if v is not None})

    def with_file(self, path: str | Path) -> Criteria:
        """These criteria with the entries a TOML file sets: ``name = value`` lines, or
        entries as compare/fit/criteria.toml writes them (a copy of it, edited; an entry
        without a value sets nothing). An unknown name, a value of another type or outside
        the entry's range, a unit other than the table's or a file that is not TOML is an
        InputError naming the file and the entry."""
        try:
            given = tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))
        except OSError as err:
            raise InputError(str(path), "--criteria", f"cannot be read ({err.strerror or err})",
                             "check the path of the criteria file") from None
        except (UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
            raise InputError(str(path), "-", f"cannot be read as TOML ({err})",
                             "give a TOML file of name = value lines") from None
        hints = typing.get_type_hints(Criteria)
        units = {f.name: f.metadata["unit"] for f in fields(self)}
        values = {}
        for name, v in given.items():
            if name not in hints:
                raise InputError(str(path), name, "is no criterion",
                                 f"use the names of compare/fit/criteria.toml, e.g. "
                                 f"{', '.join(list(hints)[:3])}")
            if isinstance(v, dict) and not _ENTRY_KEYS >= set(v):
                raise InputError(str(path), name, "is a table with the keys "
                                 f"{', '.join(sorted(set(v) - _ENTRY_KEYS))}, which an entry "
                                 "does not have", f"write {name} = VALUE, or the entry's "
                                 f"table with {', '.join(sorted(_ENTRY_KEYS))}")
            if isinstance(v, dict):  # the table's form
                if v.get("unit", units[name]) != units[name]:
                    raise InputError(str(path), f"{name}.unit", f"is {v['unit']!r}",
                                     f"give the value in {units[name]!r}, the table's unit")
                if "value" not in v:
                    continue
                v = v["value"]
            values[name] = self.checked(name, conform(v, hints[name], (str(path), name)),
                                        (str(path), name))
        return replace(self, **values)

    def table(self) -> list[dict]:
        """Every entry: name, value, unit, reason (the report's criteria table)."""
        out = []
        for f in fields(self):
            v = getattr(self, f.name)
            if isinstance(v, tuple) and v and isinstance(v[0], OnsetScale):
                v = [s.name for s in v]
            out.append({"name": f.name, "value": v, "unit": f.metadata["unit"],
                        "reason": f.metadata["reason"]})
        out.append({"name": "implausible_z", "value": round(self.implausible_z(), 3),
                    "unit": "prior sd", "reason": "derived: two-sided normal quantile at "
                    "alpha, so the verdict's plausible range and the selection agree"})
        return out


def chi2_threshold(alpha: float, df: int, tests: int = 1) -> float:
    """The chi-square quantile at level ``alpha`` / ``tests`` (Bonferroni) with ``df``
    degrees of freedom."""
    from scipy.stats import chi2

    return float(chi2.isf(alpha / max(tests, 1), df)) if alpha > 0 else math.inf
