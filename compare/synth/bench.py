"""Synthetic bench runs from the FEM reference, with effects injected (issue 6 §5).

``spindle-verify synth --cycle spl-16h --effect NAME --seed S --out RUN.csv`` solves the FEM
reference (not the lumped model the fit uses) over the cycle with the effects built into the
physics or the measurement, then samples it the way a bench logs: irregular times (about
1 Hz), sensor noise and quantisation, a gap, empty cells, comment metadata and an extra
column, in the bench format (tests/data/peer-runs/bench-format.md). The truth (effects, their
parameters, the seed) goes to ``RUN.truth.json`` beside the CSV; ``fit`` never reads it.

Each effect enters through its own hooks (compare.fit.effects.base.Effect): the spindle (a
mount's conductance), the load case (windage's heat, and the drag the logged power carries),
a feedback from the FEM's own temperatures solved to a fixed point (a preload's friction, the
coolant's warming), or the measurement (a centrifugal jump, a fixture's term, a lag). Several
effects can be injected together; causes outside the library (compare.synth.outside) use the
same hooks.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from compare.fit.effects import LIBRARY
from compare.synth.losslaw import LOSS_LAWS
from compare.synth.outside import OUTSIDE
from spindle.loads import LoadCase
from spindle.spec import Spec
from spindle.tolerances import edge_absolute
from spindle.units import RPM_TO_RAD_S, ZERO_C_K

#: noise (standard deviation) and quantisation of the bench channels
NOISE = {"T1_C": (0.03, 0.01), "T2_C": (0.03, 0.01), "T_stator_C": (0.1, 0.1),
         "P1_um": (0.05, 0.1), "T_env_C": (0.05, 0.01), "T_coolant_C": (0.02, 0.01)}


def kind_of(name: str):
    """The effect (library), the cause outside it or the loss law (compare.synth.losslaw) of
    a synthetic run's ``name``."""
    for kinds in (LIBRARY, OUTSIDE, LOSS_LAWS):
        if name in kinds:
            return kinds[name]
    raise ValueError(f"unknown effect {name!r}: use "
                     f"{', '.join([*LIBRARY, 'clean', *OUTSIDE, *LOSS_LAWS])}")


def draw_truth(effect: str, rng: np.random.Generator) -> dict:
    """The injected effect's parameters for this seed (its :meth:`Effect.draw`): magnitudes a
    bench could show. ``clean``: none."""
    return {} if effect == "clean" else kind_of(effect).draw(rng)


#: the largest max |G(x) - x| [K] of a fed-back temperature series still taken as solved when
#: the fixed point's tolerance is not reached in the FEM runs allowed: a tenth of the loggers'
#: 0.01 K quantisation (NOISE), so no logged value moves but by a rounding. Anderson's iterates
#: can stall above a tighter tolerance at the FEM solver's own round-off.
SOLVED_K = 1e-3


def _anderson(G, x0: np.ndarray, tol: float, max_iter: int = 25, memory: int = 5,
              accept: float | None = None) -> tuple[np.ndarray, int, float]:
    """Solve x = G(x) by Anderson acceleration (type II; Walker and Ni 2011): (x, iterations,
    max |G(x) - x|). The coolant loop's plain iteration contracts by only R sum g / (1 + R
    sum g) ~ 0.9 per FEM run; Anderson needs a handful. Where ``tol`` is not reached in
    ``max_iter`` steps, the best iterate is returned if its max |G(x) - x| is below ``accept``
    (default ``tol``: RuntimeError)."""
    x, g = x0, G(x0)
    f = g - x
    dF: list[np.ndarray] = []
    dG: list[np.ndarray] = []
    best = (math.inf, x, 0)
    for it in range(1, max_iter + 1):
        err = float(np.max(np.abs(f)))
        if err < tol:
            return x, it, err
        best = min(best, (err, x, it), key=lambda b: b[0])
        if dF:
            F = np.column_stack(dF[-memory:])
            gamma = np.linalg.lstsq(F, f, rcond=None)[0]
            x_new = g - np.column_stack(dG[-memory:]) @ gamma
        else:
            x_new = g
        g_new = G(x_new)
        f_new = g_new - x_new
        dF.append(f_new - f)
        dG.append(g_new - g)
        x, g, f = x_new, g_new, f_new
    err = float(np.max(np.abs(f)))
    best = min(best, (err, x, max_iter + 1), key=lambda b: b[0])
    if best[0] < (tol if accept is None else accept):
        return best[1], best[2], best[0]
    raise RuntimeError(f"the injected feedback did not converge: max |G(x) - x| = "
                       f"{best[0]:.3g} at best in {max_iter} FEM runs")


def _fixed_point(ref, case: LoadCase, feedbacks: list, dt_s: float, T0: float,
                 tol_K: float = 1e-4, max_iter: int = 40):
    """(result, the fed-back series, their grid): the transient with every feedback from the
    FEM's own temperatures (compare.fit.effects.base.Feedback), solved to ``tol_K`` [K] on the
    fed-back series together, in at most ``max_iter`` FEM runs (a feedback switched on and off
    within the run, as a coolant flow drop's, converges more slowly than one that holds)."""
    th = ref.thermal
    functionals = {k: v for fb in feedbacks for k, v in fb.functionals.items()}
    first = th.solve_transient(case, dt_s, 1.0, T0, 0, None, functionals)
    t = first.times_s  # the inputs below are given on this grid, so it stays the grid
    sizes = []

    def apply(x: np.ndarray) -> LoadCase:
        out = case
        for fb, part in zip(feedbacks, np.split(x, np.cumsum(sizes)[:-1]), strict=True):
            out = fb.apply(out, part, t)
        return out

    def G(x: np.ndarray) -> np.ndarray:
        res = th.solve_transient(apply(x), dt_s, 1.0, T0, 0, None, functionals)
        return np.concatenate([fb.update(res.functionals, case, t) for fb in feedbacks])

    starts = [fb.start(first.functionals, case, t) for fb in feedbacks]
    sizes = [len(s) for s in starts]
    x, _, _ = _anderson(G, np.concatenate(starts), tol_K, max_iter, accept=SOLVED_K)
    parts = np.split(x, np.cumsum(sizes)[:-1])
    return ref.transient(apply(x), dt_s, T0=T0), parts, t


def reference_run(spec: Spec, case: LoadCase, injected: Sequence[tuple[str, dict]],
                  level: int = 1, dt_s: float = 60.0
                  ) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, Callable]]:
    """Times [s] and the channels T1, T2, T_stator [K], P1 [m] of the FEM with the effects
    ``injected`` (name, truth parameters), and the instantaneous additions evaluated at the
    bench's own sample times: ``power_W`` (what the motor supplies against an effect: the
    logged electrical power carries it), a channel's name [K; m], or a logged input
    (``T_coolant``, ``T_env`` [K])."""
    from reference import ReferenceModel

    kinds = [(kind_of(n), truth) for n, truth in injected]
    T0 = float(case.T_ambient_K(0.0))
    instant: dict[str, Callable] = {}

    def add(name: str, f: Callable) -> None:
        old = instant.get(name)
        instant[name] = f if old is None else (lambda ts, a=old, b=f: a(ts) + b(ts))

    for k, truth in kinds:
        spec = k.synth_spec(spec, truth)
    for k, truth in kinds:
        case, more = k.synth_case(case, spec, truth)
        for name, f in more.items():
            add(name, f)
    ref = ReferenceModel(spec, level)
    feedbacks = [fb for k, truth in kinds if (fb := k.feedback(ref.thermal, spec, truth))]
    if feedbacks:
        res, xs, tx = _fixed_point(ref, case, feedbacks, dt_s, T0)
        for fb, x in zip(feedbacks, xs, strict=True):
            for name, f in fb.instant.items():
                add(name, lambda ts, f=f, x=x: f(ts, case, tx, x))
    else:
        res = ref.transient(case, dt_s, T0=T0)
    ch = {n: res.sensor(n) for n in ("T1", "T2", "T_stator") if n in res.names}
    ch["P1"] = res.growth_m["P1"].copy()
    t = res.times_s
    for k, truth in kinds:
        for name, f in k.synth_measure(t, ch, case, truth, ref).items():
            add(name, f)
    return t, ch, instant


def _size(run_a, run_b) -> dict[str, float]:
    """The largest difference between two runs of :func:`reference_run` over the model grid,
    per channel, the instantaneous additions included [K; um for P1, as the peer's truth.json
    gives it]."""
    (t, a, ia), (_, b, ib) = run_a, run_b
    out = {}
    for c in a:
        ya = a[c] + (ia[c](t) if c in ia else 0.0)
        yb = b[c] + (ib[c](t) if c in ib else 0.0)
        scale, _, _ = edge_absolute(c)
        out[c] = round(float(np.max(np.abs(ya - yb))) * scale, 4)
    return out


def effect_sizes(spec: Spec, case: LoadCase, names: Sequence[str], params: dict,
                 run, level: int, dt_s: float) -> dict:
    """How much the injected effects change each channel, as a peer's truth.json records it
    (tests/data/peer-runs): ``effect_size_by_channel``, the largest difference over the run
    that they make against the same run without them [K; um for P1], and, for several
    effects, ``effect_size_by_effect``, each alone. ``run``: the run with all of them
    (:func:`reference_run`'s output). Costs one FEM transient more per effect."""
    plain = reference_run(spec, case, [], level, dt_s)
    out: dict = {"effect_size_by_channel": _size(run, plain)}
    if len(names) > 1:
        out["effect_size_by_effect"] = {
            n: _size(reference_run(spec, case, [(n, params[n])], level, dt_s), plain)
            for n in names}
    return out


def bench_rows(t_model: np.ndarray, ch: dict[str, np.ndarray], case: LoadCase, power_W,
               rng: np.random.Generator, rate_hz: float = 1.0, torque_Nm=None,
               instant: dict | None = None) -> tuple[list[str], np.ndarray]:
    """Sample like a bench: irregular times, a 20 min gap, noise, quantisation, empty cells.
    ``torque_Nm(t)``: the process load torque [N m], logged as ``load_torque_Nm`` (None: a
    no-load run, no such column, as the bench format has it). ``instant``: additions evaluated
    at the sample times rather than interpolated from ``t_model`` (:func:`reference_run`)."""
    instant = instant or {}
    dur = float(t_model[-1])
    n = int(dur * rate_hz * 1.05) + 10
    t = np.cumsum(rng.uniform(0.5, 1.5, n) / rate_hz)
    t = t[t < dur]
    gap0 = rng.uniform(0.3, 0.5) * dur  # a logging gap of 20 min
    t = t[(t < gap0) | (t > gap0 + 1200.0)]

    def plus(name: str, v: np.ndarray) -> np.ndarray:
        return v + instant[name](t) if name in instant else v

    cols: dict[str, np.ndarray] = {"time_s": t}
    cols["speed_rpm"] = np.asarray(case.speed_rpm(t), dtype=float)
    p_W = plus("power_W", np.asarray(power_W(t), dtype=float))
    cols["power_kW"] = p_W / 1e3 * (1 + rng.normal(0, 0.01, len(t)))
    if torque_Nm is not None:
        cols["load_torque_Nm"] = np.asarray(torque_Nm(t), dtype=float)
    cols["T_env_C"] = plus("T_env", np.asarray(case.T_ambient_K(t))) - ZERO_C_K
    cols["T_coolant_C"] = plus("T_coolant", np.asarray(case.T_coolant_K(t))) - ZERO_C_K
    for name, y in ch.items():
        v = plus(name, np.interp(t, t_model, y))
        scale, off, _ = edge_absolute(name)
        cols[f"{name}_um" if name == "P1" else f"{name}_C"] = v * scale - off
    cols["P1_um"] = cols["P1_um"] - cols["P1_um"][0]
    for key, (sd, q) in NOISE.items():
        if key in cols:
            cols[key] = np.round((cols[key] + rng.normal(0, sd, len(t))) / q) * q
    cols["vibration_mm_s"] = np.abs(rng.normal(0.3, 0.05, len(t)))  # an extra bench channel
    header = list(cols)
    data = np.column_stack([cols[h] for h in header])
    for j, h in enumerate(header):  # 0.5 % of the measured cells are empty
        if h.startswith(("T1", "T2", "T_stator", "P1")):
            data[rng.random(len(t)) < 0.005, j] = np.nan
    return header, data


def synth(spec: Spec, cycle_name: str, effect: str | Sequence[str], seed: int, out_csv: Path,
          level: int = 1, dt_s: float = 60.0, mismatch: bool = False,
          truths: dict[str, dict] | None = None, write=None) -> dict:
    """Write the synthetic run and its truth sidecar; returns the truth. ``write(path,
    fill)`` writes each (default :func:`spindle.outputs.atomic_write`; the command line's
    refuses a file of the user's).

    ``effect``: ``clean``, an effect of the library, a cause outside it (compare.synth.outside),
    or several of them (a list: injected together). Their sizes are drawn from the seed
    (each kind's ``draw``) unless ``truths`` gives them (name -> parameters).
    ``cycle_name``: a shipped cycle or cycle file, ``rated`` / ``rated-16h``, or ``random`` /
    ``random-loaded`` / ``random-ramped-load`` (a cycle drawn from the seed, scaled to the
    spindle's rated point: :func:`spindle.drive.spindle_cycle`).
    ``mismatch``: the data come from a spindle that differs from ``spec``
    (:func:`compare.synth.mismatch.draw_mismatch`, drawn from the seed; its FEM level replaces
    ``level``), recorded in the truth."""
    from compare.synth.mismatch import draw_mismatch
    from spindle.drive import cycle_load_case, drive_for, spindle_cycle
    from spindle.errors import InputError
    from spindle.outputs import atomic_write

    drive = drive_for(spec)
    if drive is None:  # before any work: the bench logs the drive's power
        raise InputError(spec.path, "power_balance.preset", "synth writes a bench run, whose "
                         "power_kW column comes from the spec's drive, and this spec names none",
                         "add [power_balance] preset = <drive> to the spec, or use spl2782")
    if "P1" not in spec.growth_points():
        raise InputError(spec.path, "sensors", "synth writes a bench run with P1, and this spec "
                         "has no axial-displacement sensor named P1",
                         "add a [[sensors]] entry with name = \"P1\" and kind = "
                         "\"axial_displacement\" (docs/spec.md)")
    names = [effect] if isinstance(effect, str) else list(effect)
    twice = next((n for n in names if names.count(n) > 1), None)
    if twice is not None:  # its truth has one parameter set: injected twice, it would lie
        raise InputError("synth", "effect", f"'{twice}' is given twice",
                         "give each effect once (several different ones are injected together)")
    if "clean" in names and len(names) > 1:
        raise InputError("synth", "effect", "'clean' (no effect) is given with effects",
                         "give clean alone, or the effects without it")
    names = [n for n in names if n != "clean"]
    for n in names:
        lacks = kind_of(n).missing_in(spec, synth=True)
        if lacks:  # before any work: it would act on nothing, or on a port that is not there
            raise InputError(spec.path, "effect", f"{n} needs {lacks}, which the spec lacks",
                             "choose another effect, or a spec that has it")
    rng = np.random.default_rng(seed)
    params = {n: (truths or {}).get(n) or draw_truth(n, rng) for n in names}
    if len(names) == 1:
        effect_field, param_field = names[0], params[names[0]]
    else:  # clean (no parameters), or several effects (parameters by effect)
        effect_field, param_field = (names or "clean"), params
    truth = {"effect": effect_field, "parameters": param_field, "seed": seed,
             "cycle": cycle_name, "fem_level": level, "spec": spec.name}
    # the mismatch and the random cycle have streams of their own, so that a seed's effect
    # and bench sampling stay what they were without them
    cycle = spindle_cycle(spec, cycle_name, seed)
    if mismatch:
        mm = draw_mismatch(np.random.default_rng([seed, 1]))
        spec, drive = mm.apply(spec, drive)
        level = mm.fem_level
        truth["mismatch"] = mm.to_dict()
        truth["fem_level"] = level
    case = cycle_load_case(spec, cycle, drive)
    t_model, ch, instant = reference_run(spec, case, [(n, params[n]) for n in names], level,
                                         dt_s)
    if names:
        truth.update(effect_sizes(spec, case, names, params, (t_model, ch, instant), level,
                                  dt_s))
    # electrical power: losses plus mechanical output, per step (no-load cycles: losses)
    starts = np.asarray(cycle.boundaries_s[:-1])
    p_el = []
    for s in cycle.steps:
        heat = sum(drive.heat_W(s.speed_rpm, s.load_torque_Nm, s.power_kW).values())
        p_el.append(heat + s.load_torque_Nm * s.speed_rpm * RPM_TO_RAD_S)

    def step_values(values: list[float]):
        def at(t: np.ndarray) -> np.ndarray:
            i = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(values) - 1)
            return np.asarray(values)[i]
        return at

    torques = [s.load_torque_Nm for s in cycle.steps]
    header, data = bench_rows(t_model, ch, case, step_values(p_el), rng,
                              torque_Nm=step_values(torques) if any(torques) else None,
                              instant=instant)
    lines = [f"# spindle: {spec.name}", "# bench: synthetic run (spindle-verify synth)",
             f"# cycle: {cycle_name}", f"# rows: {len(data)}", ",".join(header)]
    fmt = {h: ("{:.2f}" if h in ("time_s", "speed_rpm") else "{:.4f}") for h in header}
    for row in data:
        lines.append(",".join("" if np.isnan(v) else fmt[h].format(v)
                              for h, v in zip(header, row, strict=True)))
    out_csv = Path(out_csv)
    out_csv.parent.mkdir(parents=True, exist_ok=True)
    write = write or atomic_write
    write(out_csv, lambda tmp: tmp.write_text("\n".join(lines) + "\n", "utf-8"))
    sidecar = out_csv.with_suffix(".truth.json")
    write(sidecar, lambda tmp: tmp.write_text(json.dumps(truth, indent=2) + "\n", "utf-8"))
    return truth


#: an on-change logger (a peer's second bench): dead band [column unit] and heartbeat [s] per
#: column; a channel is written when it moves by more than its band since it was last written,
#: or when its heartbeat falls due. The bands are two to three times the channels' noise
#: and quantisation (:data:`NOISE`), as a logger is set up not to report its own noise
ON_CHANGE = {"speed_rpm": (10.0, 60.0), "power_kW": (0.02, 60.0), "load_torque_Nm": (0.5, 60.0),
             "T_env_C": (0.1, 120.0), "T_coolant_C": (0.05, 120.0), "T1_C": (0.1, 60.0),
             "T2_C": (0.1, 60.0), "T_stator_C": (0.35, 60.0), "P1_um": (0.25, 60.0)}


def log_on_change(src_csv: Path, out_csv: Path, scan_s: float = 3.0) -> int:
    """Rewrite a synthetic run as a bench that reports by exception would have logged it:
    the rows thinned to one scan every ``scan_s`` [s], and in each scan only the columns that
    moved past their dead band or whose heartbeat fell due (:data:`ON_CHANGE`; another column
    on a heartbeat of a minute); a scan where nothing reports is no row. Returns the rows written."""
    from spindle.outputs import atomic_write

    lines = Path(src_csv).read_text(encoding="utf-8").splitlines()
    comments = [s for s in lines if s.startswith("#")]
    k = len(comments)
    header = lines[k].split(",")
    data = np.array([[float(c) if c else np.nan for c in s.split(",")] for s in lines[k + 1:]])
    t = data[:, 0]
    scans = np.unique(np.searchsorted(t, np.arange(t[0], t[-1], scan_s)))
    last_v = np.full(len(header), np.nan)
    last_t = np.full(len(header), -np.inf)
    # a column the logger does not know reports on its heartbeat alone
    band = np.array([ON_CHANGE.get(h, (np.inf, 60.0))[0] for h in header])
    beat = np.array([ON_CHANGE.get(h, (np.inf, 60.0))[1] for h in header])
    out = [*(c for c in comments if not c.startswith("# rows")),
           "# logger: report by exception (dead bands and heartbeats per channel)",
           ",".join(header)]
    rows = 0
    for i in scans:
        row, due = data[i], np.zeros(len(header), dtype=bool)
        ok = np.isfinite(row)
        due[1:] = ok[1:] & ((np.abs(row[1:] - last_v[1:]) > band[1:]) | ~np.isfinite(last_v[1:])
                            | (t[i] - last_t[1:] >= beat[1:]))
        if not due[1:].any():
            continue
        last_v[due], last_t[due] = row[due], t[i]
        out.append(",".join([f"{t[i]:.1f}"] + [(f"{v:.4f}" if d else "")
                                                for v, d in zip(row[1:], due[1:], strict=True)]))
        rows += 1
    atomic_write(Path(out_csv), lambda tmp: tmp.write_text("\n".join(out) + "\n", "utf-8"))
    return rows
