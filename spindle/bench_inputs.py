"""The model's inputs from a bench run (spindle.bench.BenchRun) on a time grid: speed held,
ambient and coolant averaged per cell, heat sources from the drive's power balance per
interval (:func:`inputs`, a LoadCase for the spec's models), or the fit's grey box's
per-interval means (:func:`interval_inputs`, :class:`Inputs`), with the pieces both share: the
grid, the zero-order hold, the cell means, the drive's settled speed and one interval's heat.

SI inside (K, m, W, s); the run's columns keep the file's units (°C, kW, rpm).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from spindle.bench import DEFAULT_GRID_S, STANDSTILL_RPM, BenchRun, BenchWarning
from spindle.checks import omega_rad_s
from spindle.drive import Drive, check_drive_feeds, drive_for, rated_torque_Nm
from spindle.errors import InputError
from spindle.loads import LoadCase, TimeSeries
from spindle.power import bearing_friction, power_balance
from spindle.spec import Spec
from spindle.units import MAX_SERIES_POINTS, ZERO_C_K


def bench_grid(run: BenchRun, grid_s: float | None = None) -> np.ndarray:
    """Times of the model's inputs [s]: the multiples of ``grid_s`` (default 60 s) from the
    last one at or before the run's first sample to its end, plus the run's first and last
    sample times; strictly increasing (points closer than 1e-6 grid_s to the run's start or
    end are dropped in their favour). A run whose clock starts a multiple of ``grid_s`` late
    (a bench that logs the time of day from a full minute) gets the grid of the same run
    logged from 0, shifted; a start between two multiples moves the grid's phase against
    the samples, which can move a verdict that lies near a criterion's edge
    (benchmarks/bench_perturb.py, ``clock``)."""
    step = DEFAULT_GRID_S if grid_s is None else float(grid_s)
    if not math.isfinite(step) or step <= 0:
        raise InputError(str(run.path), "grid_s", f"{grid_s!r} is not a time step > 0 s",
                         "give the grid spacing in seconds, e.g. 60")
    t0, t1 = float(run.time_s[0]), float(run.time_s[-1])
    if (t1 - t0) / step > MAX_SERIES_POINTS:  # before the arange: 1e-3 s over 16 h is 5.8e7
        raise InputError(str(run.path), "grid_s", f"{step:g} s over the run's "
                         f"{(t1 - t0) / 3600:.4g} h is more than {MAX_SERIES_POINTS:.0e} grid "
                         "points", f"give grid_s >= {(t1 - t0) / MAX_SERIES_POINTS:.3g} s")
    pts = np.arange(math.floor(t0 / step) * step, t1, step)
    tol = 1e-6 * step
    pts = pts[(np.abs(pts - t0) > tol) & (np.abs(pts - t1) > tol)]
    return np.unique(np.concatenate([pts, [t0, t1]]))


def valid_samples(run: BenchRun, col: str) -> tuple[np.ndarray, np.ndarray]:
    """(times [s], values) of column ``col``'s non-empty cells."""
    y = run.columns[col]
    ok = ~np.isnan(y)
    return run.time_s[ok], y[ok]


def input_samples(run: BenchRun, col: str, grid_step_s: float, gap_s: float
                  ) -> tuple[np.ndarray, np.ndarray]:
    """(times [s], values) of an input column's non-empty cells, each time placed where the
    value most likely began. A value first logged after a silence longer than a grid step
    (``grid_step_s`` [s]) but not a gap (none longer than ``gap_s`` [s], the caller's hold:
    :func:`silence_s`) began somewhere in that silence:
    a regular logger that writes every 10 min sees a speed step up to 10 min late, and held
    from its row the step is late by half the silence on average, which the fit would read
    as a lag. Such a time moves to the silence's middle, the unbiased estimate (the value is
    then held from halfway, the nearest sample). A silence within a grid step is below the
    model's resolution, and a gap's change is placed by the fit (compare.fit.gaps): both
    keep the logged time."""
    t, y = valid_samples(run, col)
    rows = run.time_s
    k = np.searchsorted(rows, t, side="left")  # the cell's own row
    before = np.where(k > 0, t - rows[np.clip(k - 1, 0, None)], 0.0)
    centre = (before > grid_step_s) & (before <= gap_s)
    return np.where(centre, t - 0.5 * before, t), y


def held(t_samples: np.ndarray, y_samples: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Zero-order hold: at each ``t`` the last sample at or before it; before the first
    sample, the first value (units of y)."""
    idx = np.searchsorted(t_samples, t, side="right") - 1
    return y_samples[np.clip(idx, 0, len(y_samples) - 1)]


#: a logged value holds for at most this many steps, of the grid or of the run's own logging
#: where it logs more sparsely (:func:`silence_s`): a bench that logs on change writes at
#: least a heartbeat that often, so a longer silence is a gap (the fit's criterion
#: gap_min_steps takes this value)
HOLD_STEPS = 2.0


def logging_step_s(time_s: np.ndarray) -> float:
    """A run's logging step [s]: the median spacing of its rows' times ``time_s`` [s] (a
    regular logger's period; a heartbeat or less where it logs on change). 0 with fewer than
    two rows."""
    t = np.asarray(time_s, dtype=float)
    return float(np.median(np.diff(t))) if len(t) > 1 else 0.0


def silence_s(steps: float, grid_step_s: float, time_s: np.ndarray) -> float:
    """The longest stretch without a row [s] that is not a logging gap: ``steps`` steps of
    the model grid (``grid_step_s`` [s]) or of the run's own logging (:func:`logging_step_s`
    of its rows' times ``time_s``), whichever is longer. A logger writing every 10 min has
    no gap between its rows; one writing every second has one after two silent minutes."""
    return float(steps) * max(float(grid_step_s), logging_step_s(time_s))

#: speed scatter a drive shows around its set speed: a logged speed within this band of the
#: current operating step belongs to it (the spindle's drive holds 0.1-0.3 % in practice)
SPEED_BAND_REL = 0.01
SPEED_BAND_RPM = 20.0


def settled_speed(speed_rpm: np.ndarray, rel: float = SPEED_BAND_REL,
                  band_rpm: float = SPEED_BAND_RPM) -> np.ndarray:
    """The operating steps of a logged speed [rpm]: consecutive values within
    max(``band_rpm``, ``rel`` x level) of the step's first value form one step, which takes
    their median. The drive's few-rpm scatter then does not make every interval a new
    operating point (each one costs the models a new set of film coefficients and modes)."""
    n = np.asarray(speed_rpm, dtype=float)
    out = np.empty_like(n)
    start = 0
    for k in range(1, len(n) + 1):
        if k == len(n) or abs(n[k] - n[start]) > max(band_rpm, rel * abs(n[start])):
            out[start:k] = np.median(n[start:k])
            start = k
    return out


def speed_changed(before_rpm, after_rpm):
    """Whether two logged speeds [rpm] differ beyond the drive's scatter band,
    max(SPEED_BAND_RPM, SPEED_BAND_REL x speed) (scalars or arrays, element by element)."""
    before, after = np.abs(before_rpm), np.abs(after_rpm)
    return np.abs(after_rpm - before_rpm) > np.maximum(
        SPEED_BAND_RPM, SPEED_BAND_REL * np.maximum(before, after))


def cell_means(t_samples: np.ndarray, y_samples: np.ndarray, edges: np.ndarray,
               centres: np.ndarray, hold_s: float | None = None) -> np.ndarray:
    """The mean of a logged signal in each cell [edges[i], edges[i+1]) (the last cell closed),
    one per cell; a cell without data gets the samples interpolated linearly at
    ``centres[i]`` (the first or last value held outside them). Units of y.

    ``hold_s`` None: the mean of the samples in the cell. ``hold_s`` [s]: the time mean of the
    signal as the bench logged it, each sample holding until the next one or for ``hold_s``,
    whichever comes first (a time not covered so is no data). A bench that logs on change
    writes a value when it moves: samples then crowd where the signal changes, and their plain
    mean over a cell weighs the change, not the time; with regular samples the two agree."""
    t_samples = np.asarray(t_samples, dtype=float)
    y_samples = np.asarray(y_samples, dtype=float)
    n = len(edges) - 1
    out = np.interp(centres, t_samples, y_samples)
    if hold_s is None:
        k = np.searchsorted(edges, t_samples, side="right") - 1
        k[t_samples == edges[-1]] = n - 1
        inside = (k >= 0) & (k < n)
        weight = np.bincount(k[inside], minlength=n).astype(float)
        total = np.bincount(k[inside], weights=y_samples[inside], minlength=n)
    else:
        ends = np.minimum(np.append(t_samples[1:], np.inf), t_samples + hold_s)
        pts = np.unique(np.concatenate([t_samples, ends[np.isfinite(ends)], edges]))
        pts = pts[(pts >= edges[0]) & (pts <= edges[-1])]
        a, b = pts[:-1], pts[1:]
        mid = 0.5 * (a + b)
        i = np.searchsorted(t_samples, mid, side="right") - 1
        j = np.clip(i, 0, len(t_samples) - 1)
        covered = (i >= 0) & (mid < ends[j])
        k = np.clip(np.searchsorted(edges, mid, side="right") - 1, 0, n - 1)
        w = (b - a) * covered
        weight = np.bincount(k, weights=w, minlength=n)
        total = np.bincount(k, weights=w * y_samples[j], minlength=n)
    has = weight > 0
    out[has] = total[has] / weight[has]
    return out


def resample(t_s: np.ndarray, y: np.ndarray, grid_s: np.ndarray, gap_steps: float,
             logging_step: float = 0.0) -> np.ndarray:
    """A logged channel's values at the grid points [s] (units of y): linear between valid
    samples; NaN outside the samples and inside gaps longer than ``gap_steps`` steps of the
    grid, of the run's logging (``logging_step`` [s], :func:`logging_step_s`) or of the
    channel's own (the median spacing of its valid samples: a bench may log temperatures
    every 10 min beside a drive every 10 s), whichever is longest (the fit's criterion
    gap_min_steps)."""
    ok = ~np.isnan(y)
    t, v = t_s[ok], y[ok]
    out = np.full(len(grid_s), np.nan)
    if len(t) < 2:
        return out
    inside = (grid_s >= t[0]) & (grid_s <= t[-1])
    out[inside] = np.interp(grid_s[inside], t, v)
    step = max(float(np.median(np.diff(grid_s))), float(logging_step), logging_step_s(t))
    k = np.clip(np.searchsorted(t, grid_s), 1, len(t) - 1)
    gap = (t[k] - t[k - 1]) > gap_steps * step
    out[gap & inside] = np.nan
    return out


def held_product(t_a: np.ndarray, a: np.ndarray, t_b: np.ndarray, b: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The product of two logged signals, each held between its samples (zero-order hold,
    :func:`held`), at every time either was logged: (times [s], a b)."""
    t = np.union1d(t_a, t_b)
    return t, held(t_a, a, t) * held(t_b, b, t)


def interval_heat_W(drive: Drive, speed_rpm: float, load_torque_Nm: float,
                    power_kW: float) -> tuple[dict[str, float], bool]:
    """Heat per source [W] at one bench operating point, and whether the power was clipped.

    ``drive.heat_W(speed, torque, P)`` with the measured electrical power P [kW] clipped at
    >= 0. Below ``STANDSTILL_RPM`` the spindle stands: every source is 0 W. If P is below the
    mechanical power (bearing friction plus load torque) at this speed, as a noisy no-load
    reading or an interval that straddles a speed step can be, the motor losses are set to 0
    (P = P_mech) and the bool is True."""
    if speed_rpm < STANDSTILL_RPM:
        return {k: 0.0 for k in drive.heat_W(0.0, 0.0, 0.0)}, False
    P = max(float(power_kW), 0.0)
    try:
        return drive.heat_W(speed_rpm, load_torque_Nm, P), False
    except ValueError:
        pb = power_balance(drive.motor, drive.bearings_at(speed_rpm), speed_rpm, load_torque_Nm,
                           drive.T_winding_K)
        return drive.heat_W(speed_rpm, load_torque_Nm, pb.motor.P_mech_W / 1e3), True


#: a process torque up to this is no load (a load cell's zero drift) [N m]; the fit's
#: criterion no_load_Nm takes the same value
LOAD_CELL_ZERO_NM = 0.5


@dataclass(frozen=True)
class LossExcess:
    """How far a run's losses go beyond what the drive can make (:func:`loss_excess`): the
    largest ratio of an interval's losses to the bound [-], that interval's index, and the
    number of running intervals over 1 and in all."""

    ratio: float
    interval: int
    over: int
    running: int


def loss_excess(drive: Drive, speed_rpm: np.ndarray, power_kW: np.ndarray,
                load_torque_Nm: np.ndarray) -> LossExcess | None:
    """Each running interval's losses, its mean electrical power [kW] less the load's
    mechanical power M omega (torque [N m], speed [rpm]), against the losses of ``drive`` at
    its speed and the larger of the load's torque and the rated one, its bearings' friction
    taken :data:`PALMGREN_SPREAD` times (the most a bearing set's f0 is off from its
    spec's). A torque only adds losses, so no spindle makes more: for spl2782 at no load
    five times its no-load losses at the nominal speed, thirty times at 1000 rpm. None
    without a nominal point or a running interval with a measured power."""
    rated = rated_torque_Nm(drive)
    if rated is None:
        return None
    limits: dict[tuple[int, float], float] = {}
    best: tuple[float, int] | None = None
    over = running = 0
    for i, (n, P, M) in enumerate(zip(speed_rpm, power_kW, load_torque_Nm, strict=True)):
        if n < STANDSTILL_RPM or not math.isfinite(P):
            continue
        running += 1
        key = (round(float(n)), max(abs(float(M)), rated))
        if key not in limits:  # above its rated speed a spindle's friction can dominate
            heat = drive.heat_W(float(key[0]), key[1], None)
            limits[key] = sum(q * (PALMGREN_SPREAD if k in drive.bearings else 1.0)
                              for k, q in heat.items())
        ratio = (P * 1e3 - M * omega_rad_s(float(n))) / limits[key]
        over += ratio > 1.0
        if best is None or ratio > best[0]:
            best = (ratio, i)
    return None if best is None else LossExcess(best[0], best[1], over, running)


#: Palmgren's friction factor f0 spans a factor 2-3 over lubrication and preload (Harris,
#: Rolling Bearing Analysis): a bearing set turns with at least its f0 / 3
PALMGREN_SPREAD = 3.0


def _per_rpm(watts: Callable[[float], float]) -> Callable[[float], float]:
    """``watts`` [W] of a speed [rpm], evaluated at the speed rounded to 1 rpm and once per
    such speed: a run's intervals repeat a few speeds."""
    cache: dict[int, float] = {}

    def at(speed_rpm: float) -> float:
        key = round(float(speed_rpm))
        if key not in cache:
            cache[key] = watts(float(key))
        return cache[key]
    return at


def friction_floor_W(drive: Drive) -> Callable[[float], float]:
    """The bearings' friction [W] at a speed [rpm] with their friction factors divided by
    :data:`PALMGREN_SPREAD`: the least a spindle turning at that speed draws."""
    low = [replace(b, f0=b.f0 / PALMGREN_SPREAD) for b in drive.bearings.values()]
    return _per_rpm(lambda n: sum(bearing_friction(b, n).heat_W for b in low))


def friction_share(drive: Drive, speed_rpm: np.ndarray, power_kW: np.ndarray) -> float:
    """The median, over the running intervals with a measured power, of the power [kW]
    against the bearings' friction at the speed [rpm] with their friction factors divided by
    :data:`PALMGREN_SPREAD` [-]: a spindle turning without a load draws at least that, its
    motor's losses aside (the peer's no-load runs draw 6 times it and more: docs/bench.md).
    nan without such an interval."""
    floor = friction_floor_W(drive)
    shares = [P * 1e3 / floor(n) for n, P in zip(speed_rpm, power_kW, strict=True)
              if n >= STANDSTILL_RPM and not math.isnan(P)]
    return float(np.median(shares)) if shares else float("nan")


def below_friction_stretch(drive: Drive, speed_rpm: np.ndarray, power_kW: np.ndarray,
                           load_torque_Nm: np.ndarray, loaded_Nm: float = LOAD_CELL_ZERO_NM
                           ) -> tuple[int, int]:
    """(first interval, length) of the longest stretch of consecutive running intervals
    without a load (torque [N m] at most ``loaded_Nm``) whose power [kW] lies below the
    bearings' friction at the speed [rpm] with their factors divided by
    :data:`PALMGREN_SPREAD`. A speed step inside an interval can put it and its neighbour
    there (the interval's speed is its middle's); three in a row cannot be a step: the
    spindle did not turn at the speed the log holds. (0, 0) without one."""
    floor = friction_floor_W(drive)
    best = (0, 0)
    start = None
    for i, (n, P, M) in enumerate(zip(speed_rpm, power_kW, load_torque_Nm, strict=True)):
        below = (n >= STANDSTILL_RPM and abs(M) <= loaded_Nm and math.isfinite(P)
                 and P * 1e3 < floor(n))
        if below and start is None:
            start = i
        if not below:
            start = None
        elif i - start + 1 > best[1]:
            best = (start, i - start + 1)
    return best


def no_load_share(drive: Drive, speed_rpm: np.ndarray, power_kW: np.ndarray,
                  load_torque_Nm: np.ndarray, loaded_Nm: float = LOAD_CELL_ZERO_NM
                  ) -> tuple[float, int]:
    """(median [-], intervals) over the running intervals without a load (torque [N m] at
    most ``loaded_Nm``) of the losses, the power [kW] less the logged torque's M omega,
    against the drive's no-load losses at the speed [rpm]: a spindle's losses lie within a
    few times its spec's (:data:`PALMGREN_SPREAD`), so a median far above it says the speeds
    are too low for the power. (At 24 000 rpm a load cell's zero, 0.5 N m, is 1.3 kW, as
    much as a grinder loses: its M omega is taken out.) nan without such an interval."""
    no_load = _per_rpm(lambda n: sum(drive.heat_W(n, 0.0, None).values()))
    shares = [(P * 1e3 - M * omega_rad_s(float(n))) / no_load(n)
              for n, P, M in zip(speed_rpm, power_kW, load_torque_Nm, strict=True)
              if n >= STANDSTILL_RPM and abs(M) <= loaded_Nm and math.isfinite(P)]
    return (float(np.median(shares)) if shares else float("nan")), len(shares)


def standstill_power(speed_rpm: np.ndarray, power_kW: np.ndarray) -> tuple[float, int]:
    """(median power [kW], intervals) over the standstill intervals (speed [rpm] below
    STANDSTILL_RPM) whose neighbours stand too: an interval next to a start or a stop may
    hold a ramp's power. nan without such an interval."""
    n = np.asarray(speed_rpm, dtype=float)
    still = n < STANDSTILL_RPM
    inner = still.copy()
    inner[1:] &= still[:-1]
    inner[:-1] &= still[1:]
    inner[[0, -1]] = False
    P = np.asarray(power_kW, dtype=float)[inner]
    P = P[np.isfinite(P)]
    return (float(np.median(P)) if len(P) else float("nan")), len(P)


def load_efficiency(speed_rpm: np.ndarray, power_kW: np.ndarray, load_torque_Nm: np.ndarray,
                    loaded_Nm: float = LOAD_CELL_ZERO_NM) -> tuple[float, int]:
    """(median of M omega / P_el [-], intervals): the share of the electrical power [kW]
    that the load's torque [N m] takes at the speed [rpm], over the running intervals with
    a load above ``loaded_Nm`` (a power at or below 0 counts as infinite). A motor delivers
    at most what it draws, so the median lies below 1 (bench runs: docs/bench.md); nan
    without a loaded interval."""
    ratios = [float("inf") if not P > 0 else M * omega_rad_s(float(n)) / (P * 1e3)
              for n, P, M in zip(speed_rpm, power_kW, load_torque_Nm, strict=True)
              if n >= STANDSTILL_RPM and M > loaded_Nm and not math.isnan(P)]
    return (float(np.median(ratios)) if ratios else float("nan")), len(ratios)


def check_power_balance(run: BenchRun, drive: Drive, grid_s: np.ndarray,
                        speed_rpm: np.ndarray, power_kW: np.ndarray,
                        load_torque_Nm: np.ndarray,
                        loaded_Nm: float = LOAD_CELL_ZERO_NM) -> None:
    """Refuse a run whose power, torque and speed cannot belong together, by energy
    conservation, before they become heat sources (per interval arrays on ``grid_s`` [s]):

    - a load that takes more than the drive draws (:func:`load_efficiency` above 1): a
      torque in N cm, a power in MW; without a load, less power than the bearings' friction
      alone (:func:`friction_share` below 1): a power in MW or not logged;
    - losses beyond what the drive makes even at its rated torque (:func:`loss_excess`):
      without a torque column a run is a no-load run whose power is all heat, so a loaded run
      exported without its torque; with one, power and torque swapped, a torque of the
      wrong sign, or a speed not in rpm;
    - without a load, a median power above :data:`PALMGREN_SPREAD` times the drive's no-load
      losses at the logged speed (:func:`no_load_share`): a speed in rad/s or Hz, or a load
      the run does not give;
    - at standstill, a median power above the drive's losses holding its rated torque
      (:func:`standstill_power`): the spindle turned where the speed says it stood;
    - three or more running intervals in a row without a load below the friction floor
      (:func:`below_friction_stretch`): the spindle stood where the speed says it turned.

    The margins on runs this project did not make: docs/bench.md. InputError naming the
    column and the largest excess; and a power column that reads one value in every row
    while the speed changes (:func:`check_power_moves`)."""
    path = str(run.path)
    if run.load_torque_measured:
        eta, n_loaded = load_efficiency(speed_rpm, power_kW, load_torque_Nm, loaded_Nm)
        if eta > 1.0:
            raise InputError(
                path, "load_torque_Nm",
                f"the load takes more power than the drive draws: over the {n_loaded} loaded "
                f"running intervals the median of M omega / P_el is {eta:.3g}, where a motor "
                "delivers at most what it draws",
                "export load_torque_Nm in N m (a torque in N cm is 100 times too large) and "
                "power_kW in kW (a power in MW is 1000 times too small)")
    else:
        share = friction_share(drive, speed_rpm, power_kW)
        if share < 1.0:
            raise InputError(
                path, "power_kW",
                f"the spindle turns, but in most running intervals it draws less than its "
                f"bearings' friction alone at a third of the spec's friction factor (median "
                f"{share:.3g} of it), which no turning spindle can",
                "export the drive's electrical power in kW (a power in MW is 1000 times too "
                "small; a column of zeros was not logged)")
    check_power_moves(run)
    # an interval at a logging gap holds inputs from either side of it (a speed changed in
    # the gap), which no energy balance can judge: the fit places the change (compare.fit.gaps)
    at_gap = gap_intervals(run.time_s, grid_s)
    ex = loss_excess(drive, speed_rpm, np.where(at_gap, np.nan, power_kW), load_torque_Nm)
    if ex is not None and ex.over > 0:
        _refuse_loss_excess(run, drive, grid_s, speed_rpm, power_kW, load_torque_Nm, ex)
    first, length = below_friction_stretch(drive, speed_rpm, power_kW, load_torque_Nm,
                                           loaded_Nm)
    if length >= 3:
        raise InputError(
            path, "speed_rpm",
            f"from t = {grid_s[first] / 3600:.2f} h for {length} intervals "
            f"({length * float(np.median(np.diff(grid_s))) / 3600:.2f} h) the spindle draws "
            "less than its bearings' friction alone at a third of the spec's friction factor "
            f"while speed_rpm holds {float(speed_rpm[first]):.0f} rpm: it did not turn at the "
            "speed the log holds",
            "export the speed the bench logged in that stretch (a log on change still writes "
            "the speed when it changes, and a heartbeat), or leave those rows out")
    share, n_free = no_load_share(drive, speed_rpm, power_kW, load_torque_Nm, loaded_Nm)
    if share > PALMGREN_SPREAD:
        raise InputError(
            path, "speed_rpm",
            f"without a load the spindle draws a median {share:.3g} times what the drive "
            f"'{drive.name}' loses at the logged speeds (over {n_free} running intervals), "
            f"where a spindle whose friction and motor losses are within {PALMGREN_SPREAD:g} "
            "times its spec's draws at most that: the speeds are too low for the power",
            "export speed_rpm in rpm (a speed in rad/s is 9.55 times too small, in Hz 60 "
            "times); if the spindle worked against a load, add the load_torque_Nm column the "
            "bench logged (docs/bench.md); if both are right, check that the spec's "
            "[power_balance] preset is this spindle's drive")
    rated = rated_torque_Nm(drive)
    P_still, n_still = standstill_power(speed_rpm, power_kW)
    if rated is not None and P_still > 0:
        holding_kW = sum(drive.heat_W(0.0, rated, None).values()) / 1e3
        if P_still > holding_kW:
            raise InputError(
                path, "speed_rpm",
                f"in its {n_still} standstill intervals (speed below {STANDSTILL_RPM:g} rpm) "
                f"the drive draws a median {P_still:.3g} kW, more than the drive "
                f"'{drive.name}' loses holding its rated {rated:.0f} N m at standstill "
                f"({holding_kW:.3g} kW): a spindle that stands turns no power into motion, "
                "so it turned while speed_rpm says it stood",
                "export speed_rpm as the bench logged it (a column of zeros, or another "
                "channel mapped to it)")


def logging_gaps(time_s: np.ndarray, grid_step_s: float, hold_steps: float = HOLD_STEPS
                 ) -> list[tuple[float, float]]:
    """(start, end) [s] of each stretch without a row (``time_s``, the rows' times [s])
    longer than :func:`silence_s` allows on a grid of ``grid_step_s`` [s]."""
    t = np.asarray(time_s, dtype=float)
    if len(t) < 2:
        return []
    longest = silence_s(hold_steps, grid_step_s, t)
    return [(float(t[k]), float(t[k + 1])) for k in np.flatnonzero(np.diff(t) > longest)]


def gap_intervals(time_s: np.ndarray, grid_s: np.ndarray,
                  hold_steps: float = HOLD_STEPS) -> np.ndarray:
    """Per interval of ``grid_s`` [s], whether it overlaps a logging gap of the rows'
    ``time_s`` [s] (:func:`logging_gaps`) or is the first interval after one."""
    g = np.asarray(grid_s, dtype=float)
    out = np.zeros(len(g) - 1, dtype=bool)
    if len(g) < 2:
        return out
    step = float(np.median(np.diff(g)))
    for start, end in logging_gaps(time_s, step, hold_steps):
        out |= (g[1:] > start) & (g[:-1] < end + step)
    return out


def check_power_moves(run: BenchRun) -> None:
    """InputError where ``run``'s power_kW holds one value in every logged row while its
    speed takes more than one: the bearings' friction and the motor's losses follow the
    speed, so a drive's measured power moves with it; one value throughout is a setpoint or
    a placeholder, not the measurement the losses are made of."""
    P = run.columns["power_kW"]
    P = P[~np.isnan(P)]
    n = run.columns["speed_rpm"]
    levels = np.unique(n[~np.isnan(n)])
    if len(P) > 1 and float(P.min()) == float(P.max()) and len(levels) > 1:
        raise InputError(str(run.path), "power_kW",
                         f"reads {P[0]:g} kW in every row while speed_rpm takes {len(levels)} "
                         f"values from {levels.min():g} to {levels.max():g} rpm: a measured "
                         "power moves with the speed (friction and motor losses)",
                         "export the drive's measured electrical power (a setpoint or a "
                         "placeholder column holds one value)")


def _refuse_loss_excess(run: BenchRun, drive: Drive, grid_s: np.ndarray,
                        speed_rpm: np.ndarray, power_kW: np.ndarray,
                        load_torque_Nm: np.ndarray, ex: LossExcess) -> None:
    """The InputError of :func:`check_power_balance` for losses beyond the bound."""
    path = str(run.path)
    i = ex.interval
    n, P, M = float(speed_rpm[i]), float(power_kW[i]), float(load_torque_Nm[i])
    where = f"at {n:.0f} rpm (t = {grid_s[i] / 3600:.2f} h)"
    rated = rated_torque_Nm(drive)
    if run.load_torque_measured:
        raise InputError(
            path, "power_kW",
            f"the losses, the power less the load's M omega, exceed in {ex.over} of the "
            f"{ex.running} running intervals what the drive '{drive.name}' loses at that "
            f"speed and torque (at least its rated {rated:.0f} N m), up to {ex.ratio:.1f} "
            f"times that {where}: {P:.2f} kW drawn against {M:.1f} N m",
            "check that power_kW is the drive's electrical power in kW, load_torque_Nm the "
            "process torque in N m (positive where it loads the spindle) and speed_rpm in rpm: "
            "swapped columns, a torque's sign or a speed in rad/s or Hz show this way")
    rated_input_kW = drive.nominal_point().motor.P_el_W / 1e3
    if P > rated_input_kW:
        raise InputError(
            path, "power_kW",
            f"up to {P:.4g} kW {where}, more than the drive '{drive.name}' draws at its "
            f"nominal point ({rated_input_kW:.1f} kW): the column looks like watts",
            "export the electrical power in kW (W / 1000)")
    raise InputError(
        path, "load_torque_Nm",
        f"the run has no load torque, so it is a no-load run whose electrical power is all "
        f"heat; but in {ex.over} of its {ex.running} running intervals it draws more than the "
        f"drive '{drive.name}' loses even at its rated torque ({rated:.0f} N m), up to "
        f"{P:.2f} kW {where}, {ex.ratio:.1f} times those losses: the spindle worked "
        "against a load the run does not give",
        "add the load_torque_Nm column the bench logged (docs/bench.md); if the spindle ran "
        "without a load, check that the spec's [power_balance] preset is this spindle's drive")


def inputs(run: BenchRun, spec: Spec, drive: Drive | None = None,
           grid_s: float | None = None) -> tuple[LoadCase, np.ndarray]:
    """The model inputs of a bench run on a time grid: ``(LoadCase, grid [s])``.

    Grid: :func:`bench_grid` (every ``grid_s``, default 60 s, over the run, plus the run's
    first and last sample). Speed [rpm]: the bench logs it on change, so it is held (the last
    valid sample at or before each grid point; before the first, the first value), a
    'previous' series on the grid. Ambient and coolant [K]: the time mean of the logged
    signal (each sample held until the next, :data:`HOLD_STEPS` grid steps at most:
    :func:`cell_means`) in the cell around each grid point (half-way to its neighbours),
    linear between grid points. Power [kW] and load torque [N m] (0 when not measured): the
    same time mean over each grid interval [t_i, t_i+1); where an interval or cell has no data
    (a gap) the samples are interpolated linearly at its centre. Heat sources [W]: per interval,
    :func:`interval_heat_W` (the power balance ``drive.heat_W(speed at t_i, torque, power)``),
    held over the interval ('previous' series at t_i); the spec's sources the power balance
    does not feed get 0 W. ``drive`` defaults to the spec's ``[power_balance] preset``; without
    one, InputError. A :class:`BenchWarning` reports intervals where the power was below the
    mechanical power (motor losses set to 0 there). The case's time runs from the grid's
    start (its t = 0 is ``grid[0]``, the run's first sample or the multiple of ``grid_s``
    before it, so that a run whose clock logs the time of day is simulated from its start) to
    the run's last sample. Returns the case and ``grid`` (the run's own times [s]).
    """
    drive = drive if drive is not None else drive_for(spec)
    if drive is None:
        raise InputError(spec.path, "power_balance.preset", "the spec names no drive, so the bench "
                         "run's electrical power cannot be turned into heat sources",
                         "add [power_balance] preset = \"spl2782\" (or the preset of this spindle) to "
                         "the spec, or pass drive=")
    grid = bench_grid(run, grid_s)
    mids = 0.5 * (grid[:-1] + grid[1:])
    dual = np.concatenate([[grid[0]], mids, [grid[-1]]])

    step = float(np.median(np.diff(grid)))
    hold = silence_s(HOLD_STEPS, step, run.time_s)
    ts, ys = input_samples(run, "speed_rpm", step, hold)
    speed = held(ts, ys, grid)
    T_env = cell_means(*input_samples(run, "T_env_C", step, hold), dual, grid, hold) + ZERO_C_K
    T_cool = cell_means(*input_samples(run, "T_coolant_C", step, hold), dual, grid, hold) + ZERO_C_K
    power = cell_means(*input_samples(run, "power_kW", step, hold), grid, mids, hold)
    torque = (cell_means(*input_samples(run, "load_torque_Nm", step, hold), grid, mids, hold)
              if run.load_torque_measured else np.zeros(len(mids)))

    check_power_balance(run, drive, grid, speed[:-1], power, torque)
    heats: list[dict[str, float]] = []
    clipped: list[float] = []
    for i, (n, M, P) in enumerate(zip(speed[:-1], torque, power, strict=True)):
        h, was_clipped = interval_heat_W(drive, float(n), float(M), float(P))
        heats.append(h)
        if was_clipped:
            clipped.append(float(grid[i]))
    if clipped:
        warnings.warn(BenchWarning(
            f"{run.path}: power_kW: in {len(clipped)} of {len(mids)} intervals (first at "
            f"t = {clipped[0]:g} s) the mean electrical power is below the mechanical power of the "
            "bearing friction and load torque at the held speed; the motor losses are 0 there"),
            stacklevel=2)
    check_drive_feeds(spec, drive)
    names = [h.name for h in spec.heat_sources]
    rel = grid - grid[0]
    starts = tuple(float(x) for x in rel[:-1])
    sources = {k: TimeSeries.constant(0.0) for k in names}
    sources.update({k: TimeSeries(starts, tuple(float(h[k]) for h in heats), "previous")
                    for k in heats[0]})
    times = tuple(float(x) for x in rel)
    case = LoadCase(
        name=run.name,
        speed_rpm=TimeSeries(times, tuple(float(x) for x in speed), "previous"),
        T_ambient_K=TimeSeries(times, tuple(float(x) for x in T_env), "linear"),
        T_coolant_K=TimeSeries(times, tuple(float(x) for x in T_cool), "linear"),
        sources=sources,
        duration_s=float(rel[-1]),
    )
    return case, grid


@dataclass
class Inputs:
    """Model inputs on a time grid (interval k runs from grid[k] to grid[k + 1]): speed
    [rpm], electrical power [kW], load torque [N m], ambient and coolant [K], per interval."""

    grid_s: np.ndarray
    speed_rpm: np.ndarray
    power_kW: np.ndarray
    load_torque_Nm: np.ndarray
    T_env_K: np.ndarray
    T_coolant_K: np.ndarray
    T_start_K: float | None = None  # uniform initial temperature [K] (default: T_env_K[0])
    #: the first interval's inputs held for this long [s] before grid[0], from T_start_K:
    #: where the run starts (compare.fit.start; 0: at T_start_K, uniform)
    prehistory_s: float = 0.0
    #: the heat [W] of the named sources during that prehistory, where it is not the first
    #: interval's (a spindle that ran elsewhere before the log; compare.fit.start)
    prehistory_heat_W: dict[str, float] | None = None


def interval_inputs(run: BenchRun, grid_s: float = 60.0, hold_steps: float = HOLD_STEPS,
                    friction_W: Callable[[float], float] | None = None) -> Inputs:
    """Per-interval inputs of the fit's grey box on the run's grid (:func:`bench_grid`):

    - speed [rpm]: the one logged at the interval's middle (held), settled to the drive's
      scatter band (a step inside an interval is at most half an interval off); where the
      speed changes inside the interval and ``friction_W`` (the bearings' friction [W] at a
      speed: spindle.interval_speed.bearing_friction_W) is given, the speed of the interval's
      mean friction (spindle.interval_speed.friction_speed);
    - power [kW], ambient and coolant [K]: the time mean over the interval of the signal as
      logged, each sample held until the next one, for ``hold_steps`` steps of the grid or
      of the run's logging at most (:func:`silence_s`: a bench that logs on change writes
      at least a heartbeat that often; the fit's criterion gap_min_steps);
    - load torque [N m]: the torque that at the interval's speed does the interval's mean
      mechanical work, mean(M n) / n (torque and speed each held). The losses the power
      balance takes from the interval are then mean(P_el - M omega), as the samples give
      them; mean(P_el) - mean(M) omega_mid is not: a 5000 -> 1000 rpm ramp at 42 N m inside
      one interval gives 5271 W of heat where the samples give about 900 W.
    """
    grid = bench_grid(run, grid_s)
    mids = 0.5 * (grid[:-1] + grid[1:])
    hold = silence_s(hold_steps, grid_s, run.time_s)
    t_n, n = input_samples(run, "speed_rpm", grid_s, hold)
    speed = settled_speed(held(t_n, n, mids))
    if friction_W is not None:
        from spindle.interval_speed import friction_speed

        speed = friction_speed(t_n, n, grid, hold, speed, friction_W)
    power = cell_means(*input_samples(run, "power_kW", grid_s, hold), grid, mids, hold)
    if run.load_torque_measured:
        t_m, m = input_samples(run, "load_torque_Nm", grid_s, hold)
        # mean M n [N m rpm], each held
        work = cell_means(*held_product(t_m, m, t_n, n), grid, mids, hold)
        moving = speed >= STANDSTILL_RPM
        torque = np.where(moving, work / np.where(moving, speed, 1.0),
                          cell_means(t_m, m, grid, mids, hold))
    else:
        torque = np.zeros(len(mids))
    t_env, y_env = input_samples(run, "T_env_C", grid_s, hold)
    T_env = cell_means(t_env, y_env, grid, mids, hold) + ZERO_C_K
    T_cool = cell_means(*input_samples(run, "T_coolant_C", grid_s, hold), grid, mids, hold) + ZERO_C_K
    return Inputs(grid, speed, power, torque, T_env, T_cool, float(y_env[0]) + ZERO_C_K)
