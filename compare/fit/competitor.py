""""Something else": the hypothesis that competes with the library's effects.

The library's effects are laws of the run's inputs that hold for the whole run: the same speed,
load, room and coolant give the same extra signal whenever they occur. Something that happens
at one time during a run (a sensor re-seated, a filter clogging, a converter derating, grease
running in, a door opened) is none of them. The competitor is that, in the same likelihood,
with a freedom comparable to an effect's (an amplitude, a start and an end):

- **an unexplained heat** q [W] into one part of the spindle (one of each role a motor
  spindle's heat passes through: ``Criteria.competitor_masses``, spread over the part's masses
  by their capacity) during a window [t0, t1) (:class:`WindowHeat`);
- **an offset** d [tolerances] on one channel during a window (a column of
  :class:`Regressors`, the channel's indicator of the window): what a
  sensor or its electronics does.

Windows lie on a grid of ``Criteria.competitor_step_s``. :func:`scan` fits every hypothesis by
linear least squares on a residual (the model's response to a heat is linear in it; the
responses to a heat in each block are computed once, :func:`block_responses`) and ranks them
by the likelihood they add; the best few are then fitted jointly with the base parameters by
one Gauss-Newton step (:func:`joint_gain`, compare.fit.linear), as the effects are.
Its significance is a Monte Carlo test of the scan's largest statistic
(:func:`scan_threshold`): the same scan on white noise gives the critical value.

Beside the events, something else can be a law of the inputs for the whole run: **a heat
into the rotor or a bearing rising with speed** as a power of it (:class:`SpeedHeat`, the
drive supplying it: an amplitude and an exponent), which a motor whose loss split moves with
speed or a friction law the spec lacks leaves. These are fitted beside the candidates and
never named; one that explains the run better than a candidate by the distinct margin is the
something else the candidate does not beat (Criteria.law_rivals).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from compare.fit.calibrate import TOLERANCE, block_index
from compare.fit.effects import Effect, hypothesis
from compare.fit.effects.base import heat_from_motor, spread_heat
from compare.fit.params import Param
from spindle.drive_file import FRICTION_REF_RPM

#: the name every competitor hypothesis's label starts with (a report reads it)
NAME = "something_else"
#: largest heat [W] the competitor may put in a part: the SPL2782's losses at full power
#: are 5 kW; an unexplained heat of 2 kW in one part would melt it
Q_MAX_W = 2000.0
#: largest offset [tolerances]: ten tolerances, beyond which a sensor is broken, not off
D_MAX_TOL = 10.0


def _heat_role(net, role: str, source: str) -> None:
    """A heat source ``source`` spread over the masses of the first part of ``role``."""
    part = next(p for p in net.parts.values() if p.part.role == role)
    spread_heat(net, part.masses, source, f"source:{source}")


class WindowHeat(Effect):
    """An unexplained heat into the first part of ``role`` during [t0, t1) [s]."""

    def __init__(self, role: str, t0_s: float, t1_s: float):
        self.role, self.t0_s, self.t1_s = role, float(t0_s), float(t1_s)
        self.name = f"{NAME}[heat into the {role}, {t0_s / 3600:.1f}-{t1_s / 3600:.1f} h]"
        self.params = (Param("q_else_W", "W", 0.0, -Q_MAX_W, Q_MAX_W,
                             "unexplained heat into the part during the window", log=False),)

    def extend_network(self, net, spec, power_measured):
        _heat_role(net, self.role, NAME)

    def heat(self, sources_W, theta, inputs):
        # the heat flows on the grid's intervals whose middle lies in [t0, t1)
        g = inputs.grid_s
        mid = 0.5 * (g[1:] + g[:-1])
        on = ((mid >= self.t0_s) & (mid < self.t1_s)).astype(float)
        return {**sources_W, NAME: theta["q_else_W"] * on}


class SpeedHeat(Effect):
    """A heat into the first part of ``role`` of q (n / FRICTION_REF_RPM)^k [W], which the
    drive supplies: a law of the speed for the whole run that no effect of the library
    explains (a rotor share of the motor losses that moves with speed, a friction law the
    spec lacks). Windage is one such law, with k = 3 into the rotor; only its signature, the
    drag in the logged power, tells it from the others."""

    def __init__(self, role: str):
        self.role = role
        self.name = f"{NAME}[a heat into the {role} rising with speed]"
        self.params = (Param("q_law_W", "W", 0.0, 0.0, LAW_MAX_W, f"the heat into the {role} "
                             f"at {FRICTION_REF_RPM:g} rpm", log=False),
                       Param("k_law", "-", 2.0, 0.0, 4.0, "its exponent of the speed",
                             log=False))

    def extend_network(self, net, spec, power_measured):
        _heat_role(net, self.role, f"law:{self.role}")

    def heat(self, sources_W, theta, inputs):
        n = np.maximum(np.asarray(inputs.speed_rpm, dtype=float), 0.0)
        w = theta["q_law_W"] * (n / FRICTION_REF_RPM) ** theta["k_law"]
        return heat_from_motor(sources_W, f"law:{self.role}", w, inputs.power_kW)


#: largest heat [W] of a law at the reference speed: a fifth of the SPL2782's 5 kW losses
LAW_MAX_W = 1000.0
#: the laws of the speed, by the role of the part they heat (the parts the drive's heat
#: reaches first)
LAWS: dict[str, str] = {r: hypothesis(SpeedHeat(r))
                        for r in ("rotor", "front_bearing", "rear_bearing")}
#: where each law's fit starts: a tenth of its range, at the middle exponent
LAW_START = {"q_law_W": 0.1 * LAW_MAX_W, "k_law": 2.0}


@dataclass(frozen=True)
class Hypothesis:
    """One hypothesis of the scan: kind ("heat" or "offset"), where (a role or a channel), the
    window [s], its amplitude (W, or tolerances) and the likelihood it adds (the concentrated
    log-likelihood gain over the model it was scanned on, counted in effective samples), the
    largest change it makes in a channel [tolerances], and how many hypotheses the scan tried."""

    kind: str
    where: str
    t0_s: float
    t1_s: float
    amplitude: float
    gain: float
    peak: float
    tried: int

    def text(self) -> str:
        span = f"{self.t0_s / 3600:.1f}-{self.t1_s / 3600:.1f} h"
        if self.kind == "heat":
            # beyond Q_MAX_W no part holds such a heat: the window says where the misfit is
            # (a part that something cools less, a reading), not how much heat
            beyond = (f" (beyond the {Q_MAX_W:.0f} W a part could take: read it as where, not as "
                      "a heat)" if abs(self.amplitude) > Q_MAX_W else "")
            return f"a heat of {self.amplitude:+.0f} W into the {self.where}, {span}{beyond}"
        return f"{self.where} off by {self.amplitude:+.2f} tolerances, {span}"


def block_edges(grid_s: np.ndarray, step_s: float) -> np.ndarray:
    """The edges [s] of the scan's blocks over the run."""
    t0, t1 = float(grid_s[0]), float(grid_s[-1])
    n = max(int(math.ceil((t1 - t0) / step_s)), 1)
    return t0 + step_s * np.arange(n + 1)


def block_responses(gb, theta: dict[str, float], effects: tuple[str, ...], role: str,
                    edges: np.ndarray, channels) -> np.ndarray:
    """(blocks, channels, grid points): each channel's response [K; m for P1] to 1 W into the
    first part of ``role`` during each block, of the model ``gb`` with ``effects`` at
    ``theta`` (linear in the heat: the model with the block's heat minus the model without)."""
    probe = WindowHeat(role, 0.0, 0.0)  # an empty window until each block's is set below
    probe.name = f"{NAME}[probe {role}]"
    model = gb.variant((*effects, hypothesis(probe)))
    th = {**theta, "q_else_W": 1.0}
    base = model.simulate(th)
    out = np.empty((len(edges) - 1, len(channels), len(gb.inputs.grid_s)))
    for b in range(len(edges) - 1):
        probe.t0_s, probe.t1_s = edges[b], edges[b + 1]
        y = model.simulate(th)
        out[b] = [y[c] - base[c] for c in channels]
    return out


@dataclass
class Regressors:
    """The competitor's hypotheses as residual columns over a calibrator's residual rows
    (compare.fit.linear.residual_rows): per role, each block's heat column (rows, blocks);
    per channel, each block's indicator column; and the blocks' edges [s]."""

    edges: np.ndarray
    heat: dict[str, np.ndarray]
    offset: dict[str, np.ndarray]

    def column(self, h: Hypothesis) -> np.ndarray:
        """The hypothesis's column: its table's blocks from the one starting at t0 to the one
        ending at t1 (the window the scan fitted), summed."""
        a, b = np.searchsorted(self.edges, [h.t0_s - 1e-6, h.t1_s - 1e-6])
        table = self.heat[h.where] if h.kind == "heat" else self.offset[h.where]
        return table[:, a:b].sum(axis=1)


def regressors(cal, fit, criteria) -> Regressors:
    """The competitor's columns (:class:`Regressors`) for ``cal``'s residual rows; the heat
    responses are computed once per calibrator (at the first fit asked: the base), as the
    linearization's other columns hold the base parameters fixed."""
    from compare.fit.linear import residual_rows

    if "competitor" in cal.memo:
        return cal.memo["competitor"]
    channels = list(cal.channels)
    _, ch, pt, _ = residual_rows(cal, fit.model)
    edges = block_edges(cal.measured.grid_s, criteria.competitor_step_s)
    tol = np.array([TOLERANCE[c] for c in channels])
    roles = {p.role for p in cal.gb.spec.parts}
    heat = {}
    for role in (r for r in criteria.competitor_masses if r in roles):
        resp = block_responses(cal.gb, fit.theta, fit.effects, role, edges, channels)
        # the residual falls by the response: measured minus model
        heat[role] = -(resp[:, ch, pt] / tol[ch]).T
    # an offset's column: -1 on its channel's rows in the block (the residual falls by it)
    in_block = block_index(edges, cal.measured.grid_s[pt])[:, None] == np.arange(len(edges) - 1)
    offset = {c: np.where((ch == j)[:, None] & in_block, -1.0, 0.0)
              for j, c in enumerate(channels)}
    cal.memo["competitor"] = Regressors(edges, heat, offset)
    return cal.memo["competitor"]


def _window_gram(X: np.ndarray, masks: list[np.ndarray], i_lo: np.ndarray,
                 i_hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What the window fits of the column table ``X`` (rows, blocks) need of the table alone,
    whatever the residual: each channel's row count (``masks``: its rows, a boolean mask per
    channel) and each window's sum of squares per channel, (windows, channels)."""
    n = np.array([np.sum(m) for m in masks], dtype=float)
    gram = np.empty((X.shape[1], X.shape[1], len(masks)))
    for j, m in enumerate(masks):
        gram[:, :, j] = X[m].T @ X[m]
    C = np.pad(np.cumsum(np.cumsum(gram, axis=0), axis=1), ((1, 0), (1, 0), (0, 0)))
    return n, C[i_hi + 1, i_hi + 1] - C[i_lo, i_hi + 1] - C[i_hi + 1, i_lo] + C[i_lo, i_lo]


def _window_fits(X: np.ndarray, R: np.ndarray, masks: list[np.ndarray], i_lo: np.ndarray,
                 i_hi: np.ndarray, gram: tuple[np.ndarray, np.ndarray] | None = None):
    """Every window [block i_lo, block i_hi] of the column table ``X`` (rows, blocks) fitted
    alone by weighted least squares to each residual column of ``R`` (rows, draws) over each
    channel's rows (``masks``): its concentrated log-likelihood gain and its amplitude, each
    (windows, draws). ``gram``: the table's :func:`_window_gram`, where it was computed once
    for many calls."""
    n, den_w = gram if gram is not None else _window_gram(X, masks, i_lo, i_hi)
    num = np.empty((X.shape[1], len(masks), R.shape[1]))
    rss0 = np.empty((len(masks), R.shape[1]))
    for j, m in enumerate(masks):
        num[:, j] = X[m].T @ R[m]
        rss0[j] = np.sum(R[m] ** 2, axis=0)
    rss0 = np.maximum(rss0, 1e-300)
    w = n[:, None] / rss0  # inverse residual variance per channel
    P = np.concatenate([np.zeros((1, *num.shape[1:])), np.cumsum(num, axis=0)])
    num_w = P[i_hi + 1] - P[i_lo]  # (windows, channels, draws)
    tot_den = den_w @ w  # (windows, draws)
    ok = tot_den > 1e-12 * np.maximum(tot_den.max(axis=0), 1e-300)
    beta = np.where(ok, -np.einsum("kcd,cd->kd", num_w, w) / np.where(ok, tot_den, 1.0), 0.0)
    rss1 = rss0 + 2 * beta[:, None] * num_w + beta[:, None] ** 2 * den_w[:, :, None]
    rss1 = np.maximum(rss1, 1e-12 * rss0)
    gain = 0.5 * np.einsum("c,kcd->kd", n, np.log(rss0 / rss1))
    return np.where(ok, gain, -np.inf), beta


def _tables(reg: Regressors):
    for kind, table in (("heat", reg.heat), ("offset", reg.offset)):
        for where, X in table.items():
            yield kind, where, X


def scan(reg: Regressors, r: np.ndarray, channel: np.ndarray, rows: np.ndarray,
         shrink: float, top: int = 5) -> tuple[list[Hypothesis], int]:
    """The ``top`` best hypotheses on the residual ``r`` over ``rows`` (each fitted alone by
    linear least squares, its gain the concentrated log-likelihood gain per channel times
    ``shrink``, the effective samples' share), and how many hypotheses were tried."""
    i_lo, i_hi = np.triu_indices(len(reg.edges) - 1)
    masks = [rows & (channel == c) for c in np.unique(channel[rows])]
    found: list[Hypothesis] = []
    tried = 0
    for kind, where, X in _tables(reg):
        gain, beta = _window_fits(X, r[:, None], masks, i_lo, i_hi)
        gain, beta = shrink * gain[:, 0], beta[:, 0]
        tried += int(np.isfinite(gain).sum())
        for k in np.argsort(-gain)[:top]:
            if not np.isfinite(gain[k]):
                continue
            a, b = int(i_lo[k]), int(i_hi[k])
            col = X[:, a:b + 1].sum(axis=1)
            peak = float(np.max(np.abs(beta[k] * col))) if len(col) else 0.0
            found.append(Hypothesis(kind, where, float(reg.edges[a]), float(reg.edges[b + 1]),
                                    float(beta[k]), float(gain[k]), peak, 0))
    found.sort(key=lambda h: -h.gain)
    return [replace(h, tried=tried) for h in found[:top]], tried


def scan_threshold(reg: Regressors, channel: np.ndarray, rows: np.ndarray, alpha: float,
                   tail: int, seed: int = 0) -> float:
    """The critical value of the scan's largest likelihood-ratio statistic (twice its best
    gain) at level ``alpha``: a Monte Carlo test (Besag and Clifford 1991). The scan is run
    on ``tail`` / ``alpha`` - 1 draws of white Gaussian noise over the same ``rows`` and
    hypotheses, and the critical value is the ``tail``-th largest of their maxima, so that
    rejecting above it has level ``alpha`` exactly. Unlike a Bonferroni bound over the
    hypotheses it counts, it knows that overlapping windows and neighbouring parts are
    nearly the same test. The observed statistic is counted in effective samples (the scan's
    ``shrink``), which puts autocorrelated residuals on the white noise's scale."""
    if alpha <= 0:
        return math.inf
    draws = scan_null_draws(alpha, tail)
    i_lo, i_hi = np.triu_indices(len(reg.edges) - 1)
    masks = [rows & (channel == c) for c in np.unique(channel[rows])]
    tables = [(X, _window_gram(X, masks, i_lo, i_hi)) for _kind, _where, X in _tables(reg)]
    rng = np.random.default_rng(seed)
    best = np.full(draws, -np.inf)
    for start in range(0, draws, 250):  # in chunks: the windows' table per draw is large
        noise = rng.standard_normal((len(channel), min(250, draws - start)))
        top = np.full(noise.shape[1], -np.inf)
        for X, gram in tables:
            gain = _window_fits(X, noise, masks, i_lo, i_hi, gram)[0]
            top = np.maximum(top, gain.max(axis=0))
        best[start:start + noise.shape[1]] = top
    return float(2.0 * np.sort(best)[-tail])


def scan_null_draws(alpha: float, tail: int) -> int:
    """How many noise draws :func:`scan_threshold` takes at level ``alpha``: ``tail`` /
    ``alpha`` - 1, so that its ``tail``-th largest maximum is the exact critical value."""
    return max(int(round(tail / alpha)) - 1, tail)


#: the bounds of the competitor's amplitudes in a joint step (W of heat; tolerances of offset)
BOUNDS = {"heat": (-Q_MAX_W, Q_MAX_W), "offset": (-D_MAX_TOL, D_MAX_TOL)}


def joint_gain(loc, reg: Regressors, hypotheses: list[Hypothesis]) -> float:
    """The best log-posterior gain of ``hypotheses``, each fitted jointly with the base
    parameters by one step of the linearized model ``loc`` (compare.fit.linear.Local) over
    the fit window (-inf for none)."""
    return max((loc.gain(reg.column(h)[:, None], [BOUNDS[h.kind]])[0] for h in hypotheses),
               default=-math.inf)
