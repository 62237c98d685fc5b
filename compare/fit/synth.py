"""Synthetic bench runs from the FEM reference, with one effect injected (issue 6 §5).

``spindle-verify synth --cycle spl-16h --effect NAME --seed S --out RUN.csv`` solves the FEM
reference (not the lumped model the fit uses) over the cycle with the effect built into the
physics or the measurement, then samples it the way a bench logs: irregular times (about 1 Hz),
sensor noise and quantisation, a gap, empty cells, comment metadata and an extra column, in
the bench format (../shared/bench-format.md). The truth (effect, its parameters, the seed) goes
to ``RUN.truth.json`` beside the CSV; ``fit`` never reads it.

How each effect enters the reference:

- ``centrifugal_shortening``: the FEM's own centrifugal load (rho omega^2 r on the rotating
  parts), scaled by a factor (the spl2782 shaft at 4300 rpm shortens only 0.26 µm; the scale
  stands for a more compliant rotor so that the effect is worth detecting);
- ``bearing_preload``: bearing heat times (1 + k (T_inner - T_outer)) from the FEM's own ring
  temperatures, by fixed-point iteration; the extra friction is a torque the motor supplies,
  so the logged electrical power carries it too;
- ``fixture_expansion``: P1 + k (T_env - T_env(0));
- ``coolant_dynamics``: coolant temperature = supply + R Q_coolant(t) from the FEM's own heat
  into the coolant, by fixed-point iteration;
- ``sensor_lag``: a first-order lag on T1 or P1;
- ``windage_loss``: c (n / 1000)^3 W more into the rotor, a drag the motor supplies (the
  logged electrical power carries it, as a bench's does);
- ``mount_conduction``: a conductance G from the housing's front face to ambient;
- ``clean``: none; ``electronics_drift`` (outside the library, for the tests): a slow
  sinusoidal drift of the P1 electronics.
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from compare.fit.greybox import EFFECTS
from lumped.elastic import first_order_lag
from spindle.loads import LoadCase, SpeedTable, TimeSeries
from spindle.spec import Spec
from spindle.tolerances import edge_absolute
from spindle.units import RPM_TO_RAD_S, ZERO_C_K

OUTSIDE = ("electronics_drift",)
#: noise (standard deviation) and quantisation of the bench channels
NOISE = {"T1_C": (0.03, 0.01), "T2_C": (0.03, 0.01), "T_stator_C": (0.1, 0.1),
         "P1_um": (0.05, 0.1), "T_env_C": (0.05, 0.01), "T_coolant_C": (0.02, 0.01)}


def draw_truth(effect: str, rng: np.random.Generator) -> dict:
    """The injected effect's parameters for this seed: magnitudes a bench could show, above
    what `fit` can tell apart on the spl-16h cycle (docs/fit.md, detection limits). Below
    them an effect is real but indistinguishable from the base parameters or a neighbour:
    bearing_preload below about 0.08 1/K (ring differences of 1-2 K on this no-load cycle
    make it less than 15 % more bearing heat, which windage_loss or f0 imitate)."""
    if effect == "centrifugal_shortening":
        return {"scale": float(rng.uniform(8.0, 15.0))}
    if effect == "bearing_preload":
        k = float(rng.uniform(0.10, 0.20))  # both bearing sets alike
        return {"k_preload_1_K": k, "k_preload_rear_1_K": k}
    if effect == "fixture_expansion":
        return {"k_fix_um_K": float(rng.choice([-1, 1]) * rng.uniform(0.8, 2.0))}
    if effect == "coolant_dynamics":
        return {"R_adv_K_W": float(rng.uniform(0.002, 0.005))}
    if effect == "sensor_lag":
        return {"channel": str(rng.choice(["T1", "P1"])), "tau_s": float(rng.uniform(400, 900))}
    if effect == "windage_loss":
        return {"c_w_W_krpm3": float(rng.uniform(0.6, 1.5))}
    if effect == "mount_conduction":
        return {"G_mount_W_K": float(rng.uniform(2.0, 5.0))}
    if effect == "electronics_drift":
        return {"amplitude_um": float(rng.uniform(1.0, 2.0)), "period_h": 5.0}
    return {}


def _with_mount(spec: Spec, G_W_K: float) -> Spec:
    """The housing's front-face film raised by G / A (A its area)."""
    from spindle.faces import exposed_faces, surface_faces

    faces = exposed_faces(spec)
    front = [s for s in spec.surfaces if s.side == "front" and s.h_W_m2K is not None
             and any(spec.part(p).role == "housing" for p in s.parts)]
    if not front:
        raise ValueError("mount_conduction needs a convective front face of the housing")
    s = front[0]
    area = sum(f.area_m2 for f in surface_faces(s, faces, spec))
    h = SpeedTable(s.h_W_m2K.speed_rpm, tuple(v + G_W_K / area for v in s.h_W_m2K.values))
    surfaces = tuple(replace(x, h_W_m2K=h) if x is s else x for x in spec.surfaces)
    return replace(spec, surfaces=surfaces)


def reference_run(spec: Spec, case: LoadCase, effect: str, truth: dict, level: int = 1,
                  dt_s: float = 60.0) -> tuple[np.ndarray, dict[str, np.ndarray], dict]:
    """Times [s] and the channels T1, T2, T_stator [K], P1 [m] of the FEM with the effect, and
    the parts that follow the speed at once, by channel, as functions of the sample times [m]
    (the centrifugal shortening; added by :func:`bench_rows` at the bench's own times). The
    key ``"drag_W"`` of the latter, when present, is the extra mechanical power [W] the motor
    supplies against the effect (windage, the preload's extra friction), which the logged
    electrical power carries."""
    from reference import ReferenceModel

    T0 = float(case.T_ambient_K(0.0))
    if effect == "mount_conduction":
        spec = _with_mount(spec, truth["G_mount_W_K"])
    if effect == "windage_loss":
        rotor = [h.name for h in spec.heat_sources if h.part and spec.part(h.part).role == "rotor"]
        src = case.sources[rotor[0]]
        t = np.asarray(src.time_s)
        extra = truth["c_w_W_krpm3"] * (np.asarray(case.speed_rpm(t + 1e-6)) / 1000.0) ** 3
        case = case.with_sources({rotor[0]: TimeSeries(tuple(t), tuple(np.asarray(src.values)
                                                                       + extra),
                                                       src.interpolation)})
    ref = ReferenceModel(spec, level)
    instant = {}
    if effect == "windage_loss":
        instant["drag_W"] = lambda ts: truth["c_w_W_krpm3"] * (
            np.asarray(case.speed_rpm(ts), dtype=float) / 1000.0) ** 3
    if effect in ("coolant_dynamics", "bearing_preload"):
        res, x, tx = _fixed_point(ref, case, effect, truth, dt_s, T0)
        if effect == "bearing_preload":
            bearings = _bearing_sources(spec)
            extra = sum(np.asarray(case.sources[h.name](tx)) * _k_preload(spec, h, truth) * dT
                        for h, dT in zip(bearings, np.split(x, len(bearings)), strict=True))
            instant["drag_W"] = lambda ts, tx=tx, extra=extra: np.interp(ts, tx, extra)
    else:
        res = ref.transient(case, dt_s, T0=T0)
    ch = {n: res.sensor(n) for n in ("T1", "T2", "T_stator") if n in res.names}
    ch["P1"] = res.growth_m["P1"].copy()
    if effect == "centrifugal_shortening":
        # the FEM's centrifugal part, scaled, follows the speed at once: it is evaluated at the
        # bench's own sample times (bench_rows), not interpolated from the model grid, where
        # it would ramp over a whole time step after every speed step
        scale = truth["scale"]
        instant["P1"] = lambda ts: scale * ref.centrifugal_m(case, ts, "P1")
    t = res.times_s
    if effect == "fixture_expansion":
        env = np.asarray(case.T_ambient_K(t))
        ch["P1"] = ch["P1"] + truth["k_fix_um_K"] * 1e-6 * (env - env[0])
    if effect == "sensor_lag":
        ch[truth["channel"]] = first_order_lag(t, ch[truth["channel"]], truth["tau_s"])
    if effect == "electronics_drift":
        ch["P1"] = ch["P1"] + truth["amplitude_um"] * 1e-6 * np.sin(
            2 * np.pi * t / (truth["period_h"] * 3600.0))
    return t, ch, instant


def _bearing_sources(spec: Spec) -> list:
    """The spec's bearing heat sources, in the order the preload's fixed point stacks their
    ring differences."""
    return [h for h in spec.heat_sources
            if h.part and spec.part(h.part).role in ("front_bearing", "rear_bearing")]


def _k_preload(spec: Spec, source, truth: dict) -> float:
    """The injected preload coefficient [1/K] of a bearing heat source (a truth written before
    the rear coefficient existed holds one for both)."""
    if spec.part(source.part).role == "rear_bearing":
        return truth.get("k_preload_rear_1_K", truth["k_preload_1_K"])
    return truth["k_preload_1_K"]


def _anderson(G, x0: np.ndarray, tol: float, max_iter: int = 25, memory: int = 5
              ) -> tuple[np.ndarray, int, float]:
    """Solve x = G(x) by Anderson acceleration (type II; Walker and Ni 2011): (x, iterations,
    max |G(x) - x|). The coolant loop's plain iteration contracts by only R sum g / (1 + R
    sum g) ~ 0.9 per FEM run; Anderson needs a handful."""
    x, g = x0, G(x0)
    f = g - x
    dF: list[np.ndarray] = []
    dG: list[np.ndarray] = []
    for it in range(1, max_iter + 1):
        err = float(np.max(np.abs(f)))
        if err < tol:
            return x, it, err
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
    raise RuntimeError(f"the injected feedback did not converge: max |G(x) - x| = "
                       f"{float(np.max(np.abs(f))):.3g} after {max_iter} FEM runs")


def _fixed_point(ref, case: LoadCase, effect: str, truth: dict, dt_s: float, T0: float,
                 tol_K: float = 1e-4):
    """(result, fed-back input [K], its times [s]): the transient with the effect's
    feedback from the FEM's own temperatures, solved to ``tol_K`` [K] on the fed-back input
    (the coolant's mean temperature, or each bearing's inner-outer ring difference)."""
    th = ref.thermal
    spec = th.spec
    if effect == "coolant_dynamics":
        from reference.thermal import TWO_PI

        # coolant films do not depend on speed (Dittus-Boelter on the flow)
        rows = [TWO_PI * s.h_W_m2K(0.0) * b for s, _, b in th.op.films if s.T_ref == "coolant"]
        g = np.sum(rows, axis=0)
        functionals = {"coolant_bT": g}
    else:
        pts, names = [], []
        for p in spec.parts:
            if p.role not in ("front_bearing", "rear_bearing"):
                continue
            for sec in p.sections:
                if sec.name in ("inner_ring", "outer_ring"):
                    z = 0.5 * (sec.z_start + sec.z_end)
                    pts.append((z, 0.5 * float(sec.r_in(z) + sec.r_out(z))))
                    names.append(f"{p.name}.{sec.name}")
        P = th.probe_matrix(np.array(pts).T).toarray()
        functionals = {n: P[i] for i, n in enumerate(names)}
    bearings = _bearing_sources(spec)
    first = th.solve_transient(case, dt_s, 1.0, T0, 0, None, functionals)
    t = first.times_s  # inputs below are given on this grid, so it stays the grid

    def with_input(x: np.ndarray) -> LoadCase:
        if effect == "coolant_dynamics":  # x: the coolant's mean temperature [K]
            return replace(case, T_coolant_K=TimeSeries(tuple(t), tuple(x)))
        parts = np.split(x, len(bearings))  # x: each bearing's ring difference [K]
        return case.with_sources({
            h.name: TimeSeries(tuple(t), tuple(np.asarray(case.sources[h.name](t))
                                               * (1 + _k_preload(spec, h, truth) * dT)))
            for h, dT in zip(bearings, parts, strict=True)})

    def G(x: np.ndarray) -> np.ndarray:
        res = th.solve_transient(with_input(x), dt_s, 1.0, T0, 0, None, functionals)
        if effect == "coolant_dynamics":
            # the films see the mean coolant temperature Tm, with sum g (T - Tm) = (Tm - Ts) / R
            # (Ts the supply): Tm = (Ts + R g.T) / (1 + R sum g)
            Ts = np.asarray(case.T_coolant_K(t))
            R, Gs = truth["R_adv_K_W"], float(functionals["coolant_bT"].sum())
            return (Ts + R * res.functionals["coolant_bT"]) / (1.0 + R * Gs)
        return np.concatenate([res.functionals[f"{h.part}.inner_ring"]
                               - res.functionals[f"{h.part}.outer_ring"] for h in bearings])

    if effect == "coolant_dynamics":
        x0 = np.asarray(case.T_coolant_K(t), dtype=float)
    else:
        x0 = np.concatenate([first.functionals[f"{h.part}.inner_ring"]
                             - first.functionals[f"{h.part}.outer_ring"] for h in bearings])
    x, _, _ = _anderson(G, x0, tol_K)
    return ref.transient(with_input(x), dt_s, T0=T0), x, t


def bench_rows(t_model: np.ndarray, ch: dict[str, np.ndarray], case: LoadCase, power_W,
               rng: np.random.Generator, rate_hz: float = 1.0, torque_Nm=None,
               instant: dict | None = None) -> tuple[list[str], np.ndarray]:
    """Sample like a bench: irregular times, a 20 min gap, noise, quantisation, empty cells.
    ``torque_Nm(t)``: the process load torque [N m], logged as ``load_torque_Nm`` (None: a
    no-load run, no such column, as the bench format has it). ``instant``: parts of channels
    evaluated at the sample times rather than interpolated from ``t_model``
    (:func:`reference_run`)."""
    dur = float(t_model[-1])
    n = int(dur * rate_hz * 1.05) + 10
    t = np.cumsum(rng.uniform(0.5, 1.5, n) / rate_hz)
    t = t[t < dur]
    gap0 = rng.uniform(0.3, 0.5) * dur  # a logging gap of 20 min
    t = t[(t < gap0) | (t > gap0 + 1200.0)]
    cols: dict[str, np.ndarray] = {"time_s": t}
    cols["speed_rpm"] = np.asarray(case.speed_rpm(t), dtype=float)
    p_W = np.asarray(power_W(t), dtype=float)
    if instant and "drag_W" in instant:
        p_W = p_W + instant["drag_W"](t)
    cols["power_kW"] = p_W / 1e3 * (1 + rng.normal(0, 0.01, len(t)))
    if torque_Nm is not None:
        cols["load_torque_Nm"] = np.asarray(torque_Nm(t), dtype=float)
    cols["T_env_C"] = np.asarray(case.T_ambient_K(t)) - ZERO_C_K
    cols["T_coolant_C"] = np.asarray(case.T_coolant_K(t)) - ZERO_C_K
    for name, y in ch.items():
        v = np.interp(t, t_model, y)
        if instant and name in instant:
            v = v + instant[name](t)
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


def synth(spec: Spec, cycle_name: str, effect: str, seed: int, out_csv: Path, level: int = 1,
          dt_s: float = 60.0, mismatch: bool = False) -> dict:
    """Write the synthetic run and its truth sidecar; returns the truth.

    ``cycle_name``: a shipped cycle or cycle file, or ``random`` / ``random-loaded`` /
    ``random-ramped-load`` (a cycle drawn from the seed,
    :func:`spindle.cycles.drawn_cycle`). ``mismatch``: the data
    come from a spindle that differs from ``spec`` (:func:`compare.fit.mismatch.draw_mismatch`,
    drawn from the seed; its FEM level replaces ``level``), recorded in the truth."""
    from compare.fit.mismatch import draw_mismatch
    from spindle.cycle_files import load_cycle
    from spindle.cycles import RANDOM_CYCLES, drawn_cycle
    from spindle.drive import cycle_load_case, drive_for
    from spindle.outputs import atomic_write

    if effect not in (*EFFECTS, "clean", *OUTSIDE):
        raise ValueError(effect)
    rng = np.random.default_rng(seed)
    truth = {"effect": effect, "parameters": draw_truth(effect, rng), "seed": seed,
             "cycle": cycle_name, "fem_level": level, "spec": spec.name}
    # the mismatch and the random cycle have streams of their own, so that a seed's effect
    # and bench sampling stay what they were without them
    cycle = drawn_cycle(cycle_name, seed) if cycle_name in RANDOM_CYCLES else \
        load_cycle(cycle_name)
    drive = drive_for(spec)
    if mismatch:
        mm = draw_mismatch(np.random.default_rng([seed, 1]))
        spec, drive = mm.apply(spec, drive)
        level = mm.fem_level
        truth["mismatch"] = mm.to_dict()
        truth["fem_level"] = level
    case = cycle_load_case(spec, cycle, drive)
    t_model, ch, instant = reference_run(spec, case, effect, truth["parameters"], level, dt_s)
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
    atomic_write(out_csv, lambda tmp: tmp.write_text("\n".join(lines) + "\n", "utf-8"))
    sidecar = out_csv.with_suffix(".truth.json")
    atomic_write(sidecar, lambda tmp: tmp.write_text(json.dumps(truth, indent=2) + "\n", "utf-8"))
    return truth
