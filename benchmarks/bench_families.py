"""How ``fit`` generalises: rates with confidence intervals over runs drawn from families,
not verdicts on named runs (issue 32 §7).

    python benchmarks/bench_families.py [--runs-per-family 50] [--families effect clean ...]
                                        [--workers 2] [--cache DIR] [--json OUT.json]
                                        [--peers tests/data/peer-runs/bench-runs ...]
                                        [--reports DIR] [--summary FILE] [--synth-only]
                                        [--geometry RADIAL AXIAL [--fit-own-spec]]
                                        [--ambient-shift-K 1e-5] [--every-s 60]

Families (each run drawn from its seed: the spindle's mismatch to the spec, the cycle, the
effect and its size, the noise and sampling; ``synth --mismatch``):

- ``effect``: one effect of the library, drawn uniformly, on a drawn cycle (random, loaded,
  or ramped load);
- ``clean``: none;
- ``outside``: one cause outside the library (compare.synth.outside), drawn uniformly;
- ``two``: two different effects of the library together;
- ``mixed``: one effect of the library and one cause outside it together (each drawn
  uniformly): the library's effect should be named and something else said to remain;
- ``losslaw``: no effect, but a loss law the spec lacks (compare.synth.losslaw, drawn
  uniformly: the rotor's share of the motor losses rising with speed), which the base's one
  loss split cannot follow: a control (nothing should be named) whose base is off;
- ``peers``: the peer's runs in the folders of ``--peers`` (a fixed set, each fitted once).

``--every-s SECONDS`` fits each drawn run as a logger that scans once every SECONDS records
it (:func:`sampled_every`: the run's first row at or after each multiple), in place of the
run's own logging (1 s, or by exception for half of them): how the verdicts hold where a
bench logs once a minute. The peer's runs are fitted as they are.

``--geometry RADIAL AXIAL`` draws the runs from another spindle: the spec's radii times
RADIAL and its lengths times AXIAL (spindle.stretch), before the drawn mismatch, and fits them
with the shipped spec, which does not describe that spindle (or, with ``--fit-own-spec``,
with the other spindle's own spec, as its user would). Such runs are kept in a cache folder
of their own.

Half the drawn runs (a stream of their own) are logged by exception, as the peer's second bench
logs (compare.synth.bench.log_on_change: dead bands and heartbeats, rows with a few channels).
Each drawn run's truth gives its effects' sizes; the rates are also given on the runs whose
every effect reaches the peer's stated floor, 1.5 K or 2 um in some channel.

The synthetic runs are kept in ``--cache`` (default benchmarks/.families-cache, ignored by
git) and fitted again on the next call: they do not depend on the fit. On a fresh machine the
cache is empty, and each drawn run is first synthesised by the FEM reference at level 2 with its
drawn spindle (``--synth-only`` does only that): 20 s to several minutes a run (effect-1 75 s,
effect-2 22 s on a slow 2-core machine, 2026-12-02), hours for the main set's 223 runs. Prints per family the
share of runs with the right verdict, and the issue's rates with 95 % Wilson intervals: the
true effect named first, nothing named on clean runs, ``unexplained`` and nothing named on
runs outside the library, a false second effect, a wrong effect named on any run, and the
validation RMS within the tolerances where the verdict names an effect or says the base is
adequate, and where an "unexplained" verdict locates an event, whether its window meets the
span its cause acts over (verdicts.located); then the fit's time.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from verdicts import (
    fit_outcome,
    judge_verdict,
    located,
    missed_by,
    named_text,
    run_verdicts,
    within_tolerances,
)

import compare.entry  # noqa: F401  (one BLAS thread, as the spindle-verify command runs)

ROOT = Path(__file__).resolve().parents[1]
#: the peer's runs, kept in the repository (tests/data/peer-runs/README.md)
PEER_RUNS = ROOT / "tests" / "data" / "peer-runs"
CYCLES = ("random", "random-loaded", "random-ramped-load")
#: appended in this order: a family's index seeds its draws, so the earlier families' runs stay
FAMILIES = ("effect", "clean", "outside", "two", "mixed", "losslaw")
#: the size every effect of the peer's runs has (tests/data/peer-runs/bench-runs-2/README.md:
#: "every effect moves some channel by at least 1.5 K or 2 um"): the rates are also given on
#: the drawn runs whose every effect (or cause outside the library) is at least that large
FLOOR = {"K": 1.5, "um": 2.0}


def effect_sizes(truth_doc: dict) -> list[dict] | None:
    """Each effect's size by channel [K; um for P1] from a truth file (the synthetic sidecar
    or a peer's truth.json entry, whose ``Tst`` is T_stator), one dict per effect; None
    where the file gives none (the peer's first batch)."""
    by_effect = truth_doc.get("effect_size_by_effect")
    sizes = list(by_effect.values()) if by_effect else (
        [truth_doc["effect_size_by_channel"]] if truth_doc.get("effect_size_by_channel")
        else None)
    if sizes is None:
        return None
    return [{("T_stator" if c == "Tst" else c): float(v) for c, v in s.items()} for s in sizes]


def at_floor(sizes: list[dict] | None) -> bool | None:
    """Every effect moves some channel by at least :data:`FLOOR` (None: sizes unknown)."""
    if sizes is None:
        return None
    return all(any(v >= (FLOOR["um"] if c == "P1" else FLOOR["K"]) for c, v in s.items())
               for s in sizes)


@dataclass(frozen=True)
class FamilyRun:
    family: str
    seed: int
    cache: str
    spec: str = "spl2782"
    path: str | None = None  # a peer's run (family "peers")
    truth: object = None  # a peer's truth
    truth_doc: dict | None = None  # a peer's whole truth.json entry (its effect sizes)
    reports: str | None = None  # a folder for each run's report.json (--reports)
    criteria: tuple = ()  # (name, value) pairs set in compare.fit.criteria.Criteria
    geometry: tuple = ()  # (radial, axial) factors of the spindle the drawn runs come from
    fit_own_spec: bool = False  # fit with that spindle's own spec, not the shipped one
    ambient_shift_K: float = 0.0  # fit a copy whose ambient reads this much higher
    every_s: float = 0.0  # fit a copy sampled once every this many seconds (0: as logged)

    @property
    def label(self) -> str:
        return Path(self.path).stem if self.path else f"{self.family}-{self.seed}"


def logs_on_change(family: str, seed: int) -> bool:
    """Half the drawn runs are logged by exception, as the peer's second bench logs
    (compare.synth.bench.log_on_change), from a stream of their own."""
    import numpy as np

    return bool(np.random.default_rng([seed, 5, FAMILIES.index(family)]).random() < 0.5)


def draw(family: str, seed: int, spec=None) -> tuple[list[str], str]:
    """The effects (or cause outside the library) and the cycle of a family's run ``seed``,
    from a stream of its own (the run's other draws are synth's); of a ``spec`` other than
    the shipped one, only those that can act on it (Effect.missing_in: an air-cooled spindle
    has no coolant to act through; the shipped spec's draws are as they were)."""
    import numpy as np

    from compare.fit.effects import LIBRARY
    from compare.synth.losslaw import LOSS_LAWS
    from compare.synth.outside import OUTSIDE

    def acting(kinds: dict) -> list[str]:
        return [k for k, e in kinds.items() if spec is None or not e.missing_in(spec)]

    rng = np.random.default_rng([seed, 7, FAMILIES.index(family)])
    cycle = str(rng.choice(CYCLES))
    if family == "effect":
        return [str(rng.choice(acting(LIBRARY)))], cycle
    if family == "outside":
        return [str(rng.choice(acting(OUTSIDE)))], cycle
    if family == "two":
        return [str(x) for x in rng.choice(acting(LIBRARY), size=2, replace=False)], cycle
    if family == "mixed":
        return [str(rng.choice(acting(LIBRARY))), str(rng.choice(acting(OUTSIDE)))], cycle
    if family == "losslaw":
        return [str(rng.choice(acting(LOSS_LAWS)))], cycle
    return ["clean"], cycle


def one(case: FamilyRun, synth_only: bool = False) -> dict:
    """Synthesise the run (or reuse it from the cache), fit it, judge the verdict."""
    from compare.fit.run import run_fit
    from compare.synth.bench import synth
    from spindle.spec_reader import load_spec

    spec = load_spec(case.spec)
    data_spec = spec
    if case.geometry and not case.path:
        from spindle.stretch import scale_radially, stretch_axially

        radial, axial = case.geometry
        data_spec = stretch_axially(scale_radially(spec, radial), axial)
    t0 = time.perf_counter()
    if case.path:
        run, truth = Path(case.path), case.truth
        truth_doc = case.truth_doc or {}
        sizes = effect_sizes(truth_doc)
    else:
        effects, cycle = draw(case.family, case.seed, spec)
        run = Path(case.cache) / f"{case.family}-{case.seed}.csv"
        sidecar = run.with_suffix(".truth.json")
        if not (run.exists() and sidecar.exists()):
            synth(data_spec, cycle, effects if len(effects) > 1 else effects[0], case.seed, run,
                  mismatch=True)
        if case.every_s:
            run = sampled_every(run, case.every_s, Path(case.cache) / f"every-{case.every_s:g}s")
        elif logs_on_change(case.family, case.seed):
            from compare.synth.bench import log_on_change

            thinned = run.with_name(f"{run.stem}-onchange.csv")
            if not thinned.exists():
                log_on_change(run, thinned)
            run = thinned
        truth_doc = json.loads(sidecar.read_text(encoding="utf-8"))
        truth = truth_doc["effect"]
        sizes = effect_sizes(truth_doc)
        if case.family == "outside":
            truth = "unexplained"
        elif truth == "clean" or case.family == "losslaw":  # a control: nothing to name
            truth = None
    t_synth = time.perf_counter() - t0
    if synth_only:
        return {"family": case.family, "run": case.label, "truth": truth, "synth_s": t_synth,
                "sizes": sizes}
    from compare.fit.criteria import Criteria

    if case.ambient_shift_K:
        run = shifted_ambient(run, case.ambient_shift_K, Path(case.cache) / "ambient-shifted")
    fit_spec = data_spec if case.fit_own_spec else spec
    rep = run_fit(run, fit_spec, criteria=Criteria().with_options(**dict(case.criteria)))
    doc = rep.to_dict()
    if case.reports:
        from spindle.outputs import atomic_write, jsonable

        atomic_write(Path(case.reports) / f"{case.label}.json",
                     lambda tmp: tmp.write_text(json.dumps(jsonable(doc), indent=1),
                                                encoding="utf-8"))
    out = fit_outcome(doc)
    verdict = judge_verdict(truth, out["named_plain"], out["unexplained"])
    rms_ok = within_tolerances(out["validation_rmse"])
    return {"family": case.family, "run": case.label, "truth": truth,
            "named": out["named"], "verdict": out["verdict"],
            "unexplained": out["unexplained"], **verdict,
            "rms_within_tolerance": rms_ok, "validation_rmse": out["validation_rmse"],
            "missed_by": missed_by(doc, truth),
            "fit_s": rep.runtime_s, "synth_s": t_synth, "sizes": sizes,
            "on_change": bool(not case.path and not case.every_s
                              and logs_on_change(case.family, case.seed)),
            **({"every_s": case.every_s} if case.every_s and not case.path else {}),
            "at_floor": at_floor(sizes),
            "located": located(doc, truth_doc),
            **({"geometry": list(case.geometry), "fit_own_spec": case.fit_own_spec}
               if case.geometry and not case.path else {})}


def shifted_ambient(run: Path, shift_K: float, folder: Path) -> Path:
    """A copy of the bench file ``run`` (in ``folder``) whose every T_env_C reading is
    ``shift_K`` higher, the rest as it is, to the character: a perturbation far below a
    sensor's resolution must not move a verdict (``--ambient-shift-K``)."""
    lines = run.read_text(encoding="utf-8").splitlines()
    head = next(i for i, t in enumerate(lines) if t.startswith("time_s"))
    col = lines[head].split(",").index("T_env_C")
    out = lines[:head + 1]
    for t in lines[head + 1:]:
        cells = t.split(",")
        if len(cells) > col and cells[col].strip():
            cells[col] = repr(float(cells[col]) + shift_K)
        out.append(",".join(cells))
    from spindle.outputs import atomic_write

    folder.mkdir(parents=True, exist_ok=True)
    copy = folder / f"{run.stem}-env{shift_K:+g}K{run.suffix}"
    # two benchmarks may share the cache: a fit never reads a half-written copy
    atomic_write(copy, lambda tmp: tmp.write_text("\n".join(out) + "\n", encoding="utf-8"))
    return copy


def sampled_every(run: Path, every_s: float, folder: Path) -> Path:
    """A copy of the bench file ``run`` (in ``folder``) as a logger that scans once every
    ``every_s`` [s] records it: the first row at or after each multiple of ``every_s``, its
    cells as they are (``--every-s``)."""
    lines = run.read_text(encoding="utf-8").splitlines()
    head = next(i for i, t in enumerate(lines) if t.startswith("time_s"))
    out = [t for t in lines[:head] if not t.startswith("# rows")] + [lines[head]]
    due = -math.inf
    for t in lines[head + 1:]:
        time_s = float(t.split(",", 1)[0])
        if time_s >= due:
            out.append(t)
            due = (math.floor(time_s / every_s) + 1) * every_s
    from spindle.outputs import atomic_write

    folder.mkdir(parents=True, exist_ok=True)
    copy = folder / run.name
    atomic_write(copy, lambda tmp: tmp.write_text("\n".join(out) + "\n", encoding="utf-8"))
    return copy


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float, float]:
    """(share, lower, upper) of k in n with the Wilson score interval (95 % at z = 1.96)."""
    if n == 0:
        return math.nan, math.nan, math.nan
    p = k / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return p, max(c - h, 0.0), min(c + h, 1.0)


def rate_line(label: str, rows: list[dict], hit, of=lambda r: True) -> str:
    pool = [r for r in rows if of(r)]
    k = sum(bool(hit(r)) for r in pool)
    p, lo, hi = wilson(k, len(pool))
    return (f"  {label:58} {k:3d} of {len(pool):3d}  {100 * p:5.1f} %  "
            f"[{100 * lo:5.1f}, {100 * hi:5.1f}]")


def summary(rows: list[dict]) -> list[str]:
    """The rates of the issue, pooled and per family (module docstring)."""
    families = [f for f in (*FAMILIES, "peers") if any(r["family"] == f for r in rows)]

    def rate(label: str, hit, of) -> list[str]:
        if not any(of(r) for r in rows):
            return []
        lines = [rate_line(label, rows, hit, of)]
        if len(families) > 1:
            lines += [rate_line(f"  ... {f}", rows, hit, lambda r, f=f: of(r) and
                                r["family"] == f) for f in families
                      if any(of(r) and r["family"] == f for r in rows)]
        return lines

    out = ["rates (95 % Wilson intervals):"]

    def floor_rate(label: str, hit, of) -> list[str]:
        """The same rate on the runs whose effects are at least the peer's floor (sizes
        known; the peer's first batch gives none)."""
        return rate(f"{label}, at the floor", hit, lambda r: of(r) and r.get("at_floor"))

    out += rate("true effect named first (runs with an effect)", lambda r: r["first"],
                lambda r: r["kind"] in ("effect", "effects"))
    def clean(r: dict) -> bool:  # a control whose spindle follows the spec's loss laws
        return r["kind"] == "control" and r["family"] != "losslaw"

    out += rate("nothing named on clean runs", lambda r: not r["named"], clean)
    out += rate("'unexplained' on clean runs (a false alarm)", lambda r: r["unexplained"], clean)
    out += rate("nothing named, a loss law the spec lacks", lambda r: not r["named"],
                lambda r: r["family"] == "losslaw")
    out += rate("'unexplained' beside a loss law the spec lacks", lambda r: r["unexplained"],
                lambda r: r["family"] == "losslaw")
    out += floor_rate("true effect named first", lambda r: r["first"],
                      lambda r: r["kind"] in ("effect", "effects"))
    out += rate("unexplained, nothing named (runs outside the library)", lambda r: r["right"],
                lambda r: r["kind"] == "outside")
    out += floor_rate("unexplained, nothing named", lambda r: r["right"],
                      lambda r: r["kind"] == "outside")
    out += rate("'unexplained' where the cause acts (its event's window meets the cause's)",
                lambda r: r["located"], lambda r: r.get("located") is not None)
    out += rate("'something else remains' beside a right verdict (a false alarm)",
                lambda r: r["unexplained"],
                lambda r: r["right"] and r["kind"] in ("effect", "effects"))
    out += rate("a false second effect (after a right first)", lambda r: r["false_second"],
                lambda r: bool(r["first"]))
    out += rate("a wrong effect named (any run)", lambda r: r["wrong"], lambda r: True)
    out += rate("validation RMS within the tolerances (named or adequate)",
                lambda r: r["rms_within_tolerance"],
                lambda r: r["verdict"] in ("named", "base adequate"))
    out += rate("both effects named (two-effect runs)", lambda r: r["right"],
                lambda r: r["kind"] == "effects")
    out += rate("the library's effect named first, beside a cause outside it",
                lambda r: r["first"], lambda r: r["kind"] == "effect+outside")
    # named as rates of their own: a line "  ... x" is a family's share of the rate above it
    out += rate("the library's effect named alone, something else said to remain",
                lambda r: r["right"], lambda r: r["kind"] == "effect+outside")
    out += rate("something else said to remain, beside a cause outside the library",
                lambda r: r["unexplained"], lambda r: r["kind"] == "effect+outside")
    out += _beside_lines(rows)
    out += rate("the verdict right as a whole", lambda r: r["right"], lambda r: True)
    names = sorted({r["truth"] for r in rows if r["kind"] == "effect"})
    for name in names:
        out.append(rate_line(f"  {name} named alone", rows, lambda r: r["right"],
                             lambda r, n=name: r["truth"] == n))
    out += missed_lines(rows, families)
    import numpy as np

    from spindle.tolerances import edge_unit

    for f in families:
        runs = [r for r in rows if r["family"] == f]
        medians = {c: float(np.median([r["validation_rmse"][c] for r in runs]))
                   for c in runs[0]["validation_rmse"]}
        out.append(f"  validation RMS after, median over {f}: " + ", ".join(
            f"{c} {v:.2f} {edge_unit(c, ascii=True)}" for c, v in medians.items()))
    for label, pick in (("", lambda r: True),
                        (" logged on change (drawn)", lambda r: r.get("on_change"))):
        times = sorted(r["fit_s"] for r in rows if pick(r))
        if times:
            out.append(f"fit time{label}: median {times[len(times) // 2]:.0f} s, max "
                       f"{times[-1]:.0f} s over {len(times)} runs")
    return out


def _beside_lines(rows: list[dict]) -> list[str]:
    """Per cause outside the library, of the runs that hold it beside a library effect: how
    many named that effect first, and how many said something else remains."""
    from compare.fit.effects import LIBRARY

    mixed = [r for r in rows if r["kind"] == "effect+outside"]
    causes = sorted({c for r in mixed for c in r["truth"] if c not in LIBRARY})
    out = [f"  {'beside':24} runs  effect named first  something else said  a wrong name"]
    for cause in causes:
        mine = [r for r in mixed if cause in r["truth"]]
        out.append(f"    {cause:22} {len(mine):4d}  {sum(bool(r['first']) for r in mine):18d}  "
                   f"{sum(r['unexplained'] for r in mine):19d}  "
                   f"{sum(r['wrong'] for r in mine):11d}")
    return out if causes else []


def missed_lines(rows: list[dict], families: list[str]) -> list[str]:
    """Why the true effect was not named first: each set of first-round criteria it failed
    (verdicts.missed_by), with its runs in all and per family. Rows saved before the field
    existed give no lines."""
    from collections import Counter

    from compare.fit.select import CRITERIA_ORDER as ORDER

    missed = [r for r in rows if r.get("missed_by")]
    if not missed or any("missed_by" not in r for r in rows if r["kind"] in ("effect", "effects")):
        return []
    def first(r: dict) -> str:
        return min(r["missed_by"], key=lambda c: ORDER.index(c) if c in ORDER else len(ORDER))

    out = [f"  why the true effect was not named first ({len(missed)} runs): the first criterion "
           "it failed in the first round, in select's order (alone: the only one it failed)"]
    for reason, n in Counter(first(r) for r in missed).most_common():
        mine = [r for r in missed if first(r) == reason]
        alone = sum(len(r["missed_by"]) == 1 for r in mine)
        per = ", ".join(f"{f} {k}" for f in families
                        if (k := sum(r["family"] == f for r in mine)))
        out.append(f"    {reason:40} {n:3d}, alone {alone:3d}   ({per})")
    return out


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs-per-family", type=int, default=50)
    ap.add_argument("--first-seed", type=int, default=1,
                    help="the first seed of each family (default 1; the held-out tests use "
                    "others)")
    ap.add_argument("--families", nargs="+", default=[*FAMILIES, "peers"],
                    choices=[*FAMILIES, "peers"])
    ap.add_argument("--peers", nargs="*", type=Path,
                    default=[PEER_RUNS / "bench-runs",
                             PEER_RUNS / "bench-runs-2"])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".families-cache")
    ap.add_argument("--json", type=Path, help="also write the rows to this JSON file")
    ap.add_argument("--summary", type=Path,
                    help="also write the rates to this text file (docs/figures/fit-families.txt "
                    "is this file, which docs/fit.md quotes)")
    ap.add_argument("--criterion", action="append", default=[], metavar="NAME=VALUE",
                    help="set an entry of compare.fit.criteria.Criteria for every fit, e.g. "
                    "open_loop_material_change=false (repeatable): a rule's trade, measured")
    ap.add_argument("--rows", type=Path,
                    help="print (and --summary) the rates of rows saved by --json, fitting "
                    "nothing")
    ap.add_argument("--reports", type=Path,
                    help="also keep each run's report.json in this folder (named by run); "
                    "with --rows, read 'located' off them for rows written without it")
    ap.add_argument("--synth-only", action="store_true",
                    help="only synthesise the drawn runs into the cache (no fits)")
    ap.add_argument("--geometry", nargs=2, type=float, metavar=("RADIAL", "AXIAL"),
                    help="draw the runs from another spindle: the spec's radii and lengths "
                    "times these factors; fitted with the shipped spec")
    ap.add_argument("--fit-own-spec", action="store_true",
                    help="with --geometry: fit with the other spindle's own spec")
    ap.add_argument("--spec", default="spl2782",
                    help="draw the runs from this spindle and fit them with its spec (a shipped "
                    "name or a spec file, e.g. tests/data/own-specs/gs24.toml; default spl2782); "
                    "its runs are kept in a cache folder of its own")
    ap.add_argument("--ambient-shift-K", type=float, default=0.0, metavar="K",
                    help="fit every run from a copy whose ambient (T_env_C) reads K higher, "
                    "e.g. 1e-5, a thousandth of the loggers' 0.01 K: compare the rows with "
                    "an unshifted benchmark's (compare_reports.py) for the verdicts that "
                    "round-off decides")
    ap.add_argument("--every-s", type=float, default=0.0, metavar="SECONDS",
                    help="fit each drawn run as a logger scanning once every SECONDS records it "
                    "(the first row at or after each multiple), e.g. 60; the peer's runs as "
                    "they are")
    args = ap.parse_args(argv)
    if args.rows:
        return _from_rows(args, argv)
    if args.runs_per_family < 1:
        ap.error("--runs-per-family: at least 1")
    if args.every_s < 0 or not math.isfinite(args.every_s):
        ap.error("--every-s: a cadence in seconds above 0 (or 0: the runs as logged)")
    geometry = tuple(args.geometry or ())
    if geometry:
        if not all(0.5 <= g <= 2.0 for g in geometry):
            ap.error("--geometry: factors between 0.5 and 2")
        args.cache = args.cache / f"geometry-{geometry[0]:g}-{geometry[1]:g}"
    elif args.fit_own_spec:
        ap.error("--fit-own-spec: only with --geometry")
    if args.spec != "spl2782":
        from spindle.spec_reader import load_spec

        args.cache = args.cache / f"spec-{load_spec(args.spec).name}"
    args.cache.mkdir(parents=True, exist_ok=True)
    criteria = _criteria(ap, args.criterion)
    reports = None
    if args.reports:
        args.reports.mkdir(parents=True, exist_ok=True)
        reports = str(args.reports)
    cases = [FamilyRun(f, s, str(args.cache), spec=args.spec, reports=reports,
                       criteria=criteria, geometry=geometry, fit_own_spec=args.fit_own_spec,
                       ambient_shift_K=args.ambient_shift_K, every_s=args.every_s)
             for f in args.families
             if f in FAMILIES
             for s in range(args.first_seed, args.first_seed + args.runs_per_family)]
    if "peers" in args.families:
        from verdicts import read_truth

        for folder in args.peers:
            if not (folder / "truth.json").is_file():
                print(f"note: {folder}/truth.json not found; its runs are left out")
                continue
            truth = read_truth(folder)
            cases += [FamilyRun("peers", 0, str(args.cache), path=str(folder / f"{k}.csv"),
                                truth=v.get("truth"), truth_doc=v, reports=reports,
                                criteria=criteria, ambient_shift_K=args.ambient_shift_K)
                      for k, v in sorted(truth.items())]

    if args.synth_only:
        import functools

        from compare.executor import run_cases, stderr_progress

        drawn = [c for c in cases if not c.path]
        done = run_cases(functools.partial(one, synth_only=True), drawn,
                         workers=args.workers, progress=stderr_progress())
        failed = [o for o in done if o.error]
        for o in failed:
            print(f"{o.label} failed: {o.error}")
        print(f"synthesised {len(done) - len(failed)} of {len(drawn)} runs into {args.cache}")
        return

    def line(r: dict) -> str:
        return (f"{r['family']:8} {r['run']:14} {str(r['truth'])[:40]:40} "
                f"{named_text(r['named'], r['unexplained'])[:44]:44} "
                f"{'yes' if r['right'] else 'NO ':3} {r['fit_s']:5.0f}")

    rows = run_verdicts(one, cases, workers=args.workers, line=line, json_path=args.json,
                        group=lambda r: r["family"],
                        header=f"{'family':8} {'run':14} {'truth':40} {'named':44} ok      s")
    _report(rows, args, argv)


def _criteria(ap: argparse.ArgumentParser, items: list[str]) -> tuple:
    """``--criterion NAME=VALUE`` as (name, value) pairs, each value of its entry's type."""
    from dataclasses import fields

    from compare.fit.criteria import Criteria

    kinds = {f.name: type(f.default) for f in fields(Criteria)}
    out = []
    for item in items:
        name, _, text = item.partition("=")
        if name not in kinds or kinds[name] not in (bool, int, float) or not text:
            ap.error(f"--criterion {item}: give NAME=VALUE with NAME a number or switch of "
                     "compare/fit/criteria.py")
        if kinds[name] is bool:
            if text.lower() not in ("true", "false"):
                ap.error(f"--criterion {item}: {name} is true or false")
            out.append((name, text.lower() == "true"))
        else:
            try:
                out.append((name, kinds[name](text)))
            except ValueError:
                ap.error(f"--criterion {item}: {name} is a number")
    return tuple(out)


def _fitting_options(rows: list[dict], per: dict[str, int], args) -> str:
    """The options of the fitting call that saved ``rows`` (``per``: their runs per family),
    as far as the rows tell: runs per family, the first seed, the families where not all,
    and the criteria given now."""
    seeds = [int(r["run"].rsplit("-", 1)[1]) for r in rows if r["family"] != "peers"]
    out = f"--runs-per-family {max((n for f, n in per.items() if f != 'peers'), default=0)}"
    if seeds and min(seeds) != 1:
        out += f" --first-seed {min(seeds)}"
    if any(n == 0 for n in per.values()):
        out += " --families " + " ".join(f for f, n in per.items() if n)
    geometry = next((r["geometry"] for r in rows if r.get("geometry")), None)
    if geometry:
        out += f" --geometry {geometry[0]:g} {geometry[1]:g}"
        out += " --fit-own-spec" if any(r.get("fit_own_spec") for r in rows) else ""
    every = next((r["every_s"] for r in rows if r.get("every_s")), None)
    if every:
        out += f" --every-s {every:g}"
    return out + "".join(f" --criterion {c}" for c in args.criterion)


def _from_rows(args, argv: list[str] | None) -> None:
    """``--rows``: the rates of rows a fitting call saved, fitting nothing (with
    ``--reports``, :func:`_fill_located` first)."""
    try:
        rows = json.loads(args.rows.read_text(encoding="utf-8"))
    except (OSError, ValueError) as e:
        print(f"error: --rows {args.rows}: {e}; give a file written by --json")
        raise SystemExit(2) from None
    if args.reports:
        _fill_located(rows, args.reports, args.cache, args.json, args.rows)
    return _report(rows, args, argv)


def _fill_located(rows: list[dict], reports: Path, cache: Path, out: Path | None,
                  source: Path) -> None:
    """Rows written before they recorded ``located``: read it off the run's kept report
    (``--reports``) and the cached truth; with ``--json``, write the rows so filled there
    (never over the ``--rows`` file read)."""
    for r in rows:
        doc, truth = reports / f"{r['run']}.json", cache / f"{r['run']}.truth.json"
        if "located" not in r and doc.exists() and truth.exists():
            r["located"] = located(*(json.loads(f.read_text(encoding="utf-8"))
                                     for f in (doc, truth)))
    if out is not None:
        if out.resolve() == source.resolve():
            print(f"error: --json {out} is the --rows file; write the filled rows elsewhere")
            raise SystemExit(2)
        from spindle.outputs import write_json

        write_json(out, rows)


def _report(rows: list[dict], args, argv: list[str] | None) -> None:
    """Print the rates of ``rows`` and write them to ``--summary``."""
    lines = summary(rows)
    print("\n".join(lines))
    if args.summary:
        from spindle.outputs import atomic_write

        runs = {f: sum(r["family"] == f for r in rows) for f in (*FAMILIES, "peers")}
        command = f"python benchmarks/bench_families.py {' '.join(argv or sys.argv[1:])}"
        if args.rows:  # the rates of rows a fitting call saved with --json
            command = (f"python benchmarks/bench_families.py {_fitting_options(rows, runs, args)} "
                       f"--json ROWS; python benchmarks/bench_families.py --rows ROWS "
                       f"--summary {args.summary}")
        head = [command, "runs: " + ", ".join(f"{f} {n}" for f, n in runs.items() if n)]
        text = "\n".join(head + lines) + "\n"
        atomic_write(args.summary, lambda tmp: tmp.write_text(text, encoding="utf-8"))


if __name__ == "__main__":
    main()
