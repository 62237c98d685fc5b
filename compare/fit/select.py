"""Which effects a bench run supports: forward selection against "something else".

Each round linearizes the current model in its base parameters (compare.fit.linear) and fits
every candidate of the library not yet in it jointly with them (the candidate's own
parameters exactly, by a few Gauss-Newton iterations: compare.fit.linear.fit_effect), and the
competitor (compare.fit.competitor) the same way. Each candidate is judged by the named
criteria of :class:`compare.fit.criteria.Criteria` (their reasons are its table's; the method
is docs/fit.md, step 4):

- ``material`` and ``significant`` (a likelihood-ratio test against the current model
  refitted by the same step without the candidate) on both routes; then
- **its signature**: its test on the raw samples (compare.fit.signatures), where one
  applies, is significant too (an intersection of two tests at alpha: a joint test would
  name an effect the fit does not want on its signature alone); one that applies and is not
  vetoes the effect on both routes;
- or **the open loop**, where none applies: ``predicts`` (blocked cross-validation),
  ``beats_something_else`` (BIC; the scan's events and the laws of the speed,
  compare.fit.competitor.SpeedHeat), ``distinct`` from every alternative on its channels
  (:func:`complements` are none), and :func:`model_changes`.

One qualifying candidate joins the model (:func:`joins_first`: a signature's before the open
loop's, then the most likelihood) and is refitted (:func:`refit`); the next round judges the
rest against the model that holds it. When none qualifies, an effect named by the open loop
whose final model still misses one of its channels on held-out data is withdrawn
(:func:`withdraw_unsupported`) and the selection goes on from the model before it, without
it; when nothing is withdrawn, the competitor is scanned on the final model stepped to the
whole run (:func:`verdict_on`; stepped, since a model calibrated on the fit window misses the
validation window by its extrapolation, which a window there would take up): ``unexplained``
and where, or not.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from compare.fit.calibrate import Calibrator, Fit, over_tolerance
from compare.fit.competitor import (
    LAW_START,
    LAWS,
    Hypothesis,
    joint_gain,
    regressors,
    scan,
    scan_threshold,
)
from compare.fit.criteria import Criteria
from compare.fit.effects import effect_of, parse_label
from compare.fit.linear import Local, effect_held_out, fit_effect, local

#: the open loop's criteria that must all pass (then :func:`model_changes`)
OPEN_LOOP = ("predicts", "beats_something_else", "distinct")
#: every named criterion of a candidate, in the order :attr:`Judgement.route` asks them
CRITERIA_ORDER = ("significant", "material", "signature", *OPEN_LOOP, "changes_prediction",
                  "restores_plausible_base", "null_at_optimum", "final_model_adequate")


def model_changes(criteria: Mapping[str, bool | None]) -> bool:
    """The open loop's last criterion from a candidate's named criteria: the fitted model
    changes, in its prediction (``changes_prediction``) or else in its base, from implausible
    to plausible (``restores_plausible_base``); each None where switched off."""
    return (criteria.get("changes_prediction") is not False
            or bool(criteria.get("restores_plausible_base")))


@dataclass
class Judgement:
    """One candidate in one round: its refit and each named criterion's outcome (None where the
    criterion was not asked), and the route it qualified by ("signature", "open loop") or None."""

    label: str
    round: int
    fit: Fit | None  # the nonlinear refit, made for the candidate that joins the model
    gain: float
    lr: float
    p_value: float
    peak: float
    criteria: dict[str, bool | None]
    figures: dict[str, object] = field(default_factory=dict)

    @property
    def route(self) -> str | None:
        c = self.criteria
        # withdrawn after the selection, its gain the null's shortfall, or short of what
        # both routes ask
        if (c.get("final_model_adequate") is False or c.get("null_at_optimum") is False
                or not c["material"] or c["signature"] is False or not c["significant"]):
            return None
        if c["signature"]:
            return "signature"
        return "open loop" if all(c.get(k) for k in OPEN_LOOP) and model_changes(c) else None

    @property
    def qualifies(self) -> bool:
        return self.route is not None

    def to_dict(self) -> dict:
        return {"candidate": self.label, "round": self.round, "gain": self.gain,
                "lr": self.lr, "p_value": self.p_value, "peak_tolerances": self.peak,
                "criteria": self.criteria, "route": self.route, "qualifies": self.qualifies,
                **self.figures}


@dataclass
class Step:
    """One accepted effect: its judgement and the model before it."""

    judgement: Judgement
    before: Fit

    @property
    def label(self) -> str:
        return self.judgement.label

    @property
    def fit(self) -> Fit:
        return self.judgement.fit


@dataclass
class Verdict:
    """What the run says beyond the named effects: the competitor on the final model (its
    best hypothesis, the likelihood-ratio statistic, the threshold it had to pass) and
    whether that makes the run ``unexplained``."""

    hypothesis: Hypothesis | None
    lr: float
    threshold: float
    unexplained: bool
    #: channels whose held-out RMS exceeds one tolerance (tolerances), where that made the
    #: run unexplained (Criteria.held_out_misfit_unexplained) and the competitor did not
    misses: dict[str, float] = field(default_factory=dict)

    @property
    def basis(self) -> str:
        """What made the run unexplained: "something else" (the competitor's test),
        "held-out misfit" or "" (not unexplained)."""
        if not self.unexplained:
            return ""
        return "held-out misfit" if self.misses else "something else"

    def where(self) -> str | None:
        h = self.hypothesis
        if not self.misses:
            return None if h is None else h.text()
        text = ", ".join(f"{c} misses its tolerance on the held-out window ({r:.1f} times)"
                         for c, r in self.misses.items())
        if h is not None:
            text += f"; the likeliest single event, not significant alone: {h.text()}"
        return text

    def to_dict(self) -> dict:
        h = self.hypothesis
        return {"unexplained": self.unexplained, "lr": self.lr, "threshold": self.threshold,
                "basis": self.basis, "misses": dict(self.misses), "where": self.where(),
                "hypothesis": None if h is None else {
                    "kind": h.kind, "where": h.where, "t0_s": h.t0_s, "t1_s": h.t1_s,
                    "amplitude": h.amplitude, "unit": "W" if h.kind == "heat" else "tolerances",
                    "peak_tolerances": h.peak, "hypotheses_tried": h.tried}}


@dataclass
class Selection:
    base: Fit
    steps: list[Step]
    judged: list[Judgement]
    verdict: Verdict | None = None
    #: the signature tests by label, read at ``base`` (compare.fit.signatures.EventTest)
    signatures: dict = field(default_factory=dict)

    @property
    def final(self) -> Fit:
        return self.steps[-1].fit if self.steps else self.base


def _own(label: str) -> tuple[str, ...]:
    """The channels a candidate acts on (a per-channel effect: its channel)."""
    channel = parse_label(label)[1]
    return (channel,) if channel else effect_of(label).channels


def _cv_excess(cv: dict[str, float], floor: Mapping[str, float] | None,
               channels: Sequence[str]) -> float:
    """Cross-validated error above the noise floor on ``channels`` [tolerances squared]."""
    return sum(max(v * v - (floor or {}).get(c, 0.0) ** 2, 0.0)
               for c, v in cv.items() if c in channels)


def _signature_start(label: str, signature) -> dict[str, float] | None:
    """The effect's parameters as its signature test estimates them, where it does."""
    par = signature.parameter if signature is not None and signature.applies else None
    p = next((q for q in effect_of(label).params if par and q.name == par["name"]), None)
    if p is None:
        return None
    return {p.name: min(max(par["value"], p.lo + 1e-6 * (p.hi - p.lo)), p.hi)}


def signature_outcome(signature, alpha: float) -> bool | None:
    """True where the signature test is significant at ``alpha``; None where it does not apply (or
    there is none); False where it applies and is not significant: its own test could look for the
    effect and did not find it, so an attribution of a misfit to it is a guess, and weak evidence
    ends in 'nothing named' rather than a name. False as well where the run holds its conditions
    but its log is too sparse to read them (``unreadable``): the evidence that would tell the
    effect from the base's misfit is missing, so the open loop does not name it alone."""
    if signature is not None and signature.unreadable:
        return False
    if signature is None or not signature.applies:
        return None
    return bool(signature.significant(alpha))


def known_inputs(loc: Local, unknown_s: Sequence[tuple[float, float]]) -> np.ndarray:
    """The residual rows of ``loc`` outside the spans [t0, t1) [s] whose inputs are not known
    (a logging gap and the settling after it: compare.fit.gaps.unknown_input_spans)."""
    t = loc.cal.measured.grid_s[loc.point]
    out = np.ones(len(t), dtype=bool)
    for a, b in unknown_s:
        out &= ~((t >= a) & (t < b))
    return out


def select(cal: Calibrator, base: Fit, candidates: Sequence[str], criteria: Criteria,
           signatures: Callable[[Fit], Mapping[str, object]] | None = None,
           progress: Callable[[str], None] | None = None,
           unknown_inputs: Sequence[tuple[float, float]] = ()) -> Selection:
    """Forward selection of ``candidates`` (labels) from the calibrated ``base`` (module
    docstring); ``signatures``: reads the run's signature tests (by label) at a base model, called
    again where the selection replaces the base, since a test may read the base's values
    (compare.fit.signatures.Context). ``unknown_inputs``: spans [t0, t1) [s] where the run's
    inputs are not known (a logging gap and the settling after it): something else is not looked
    for there, since the model's misfit there says nothing but that the inputs are not known."""
    say = progress or (lambda _m: None)
    read = signatures or (lambda _fit: {})
    sig = dict(read(base))
    current = base
    steps: list[Step] = []
    judged: list[Judgement] = []
    withdrawn: set[str] = set()
    reg = regressors(cal, base, criteria)
    roles = {p.role for p in cal.gb.spec.parts}
    laws = [lab for role, lab in LAWS.items() if role in roles] if criteria.law_rivals else []
    while True:
        loc = local(cal, current)
        rnd = judged[-1].round + 1 if judged else 1
        have = {parse_label(e)[0] for e in current.effects}
        pending = [c for c in candidates if parse_label(c)[0] not in have and c not in withdrawn]
        fits = _fit_candidates(loc, pending, sig, rnd, say)
        for lab in laws if fits else []:  # something else: never judged or named
            say(f"round {rnd}: fitting {lab}")
            law = fit_effect(loc, lab, LAW_START)
            if law is not None:
                fits[lab] = law
        round_judged = _judge_round(loc, fits, sig, criteria, reg, unknown_inputs, rnd, say)
        judged += round_judged
        qualified = [j for j in round_judged if j.qualifies]
        if qualified:
            best = joins_first(qualified)
            say(f"round {rnd}: refitting with {best.label}")
            best.fit, best.figures["refit_from"] = refit(cal, loc, fits[best.label], criteria)
            if criteria.null_from_candidate:
                again, shortfall = null_from(cal, current, best.fit, criteria)
                best.figures["null_shortfall"] = shortfall
                best.criteria["null_at_optimum"] = shortfall <= criteria.distinct_margin()
                if not best.criteria["null_at_optimum"]:
                    say(f"round {rnd}: the model without {best.label} fits better from where "
                        f"{best.label}'s fit ended; judging the round again from there")
                    if not steps:  # the base was short of its optimum
                        base = again
                        cal.memo.pop("competitor", None)
                        reg = regressors(cal, base, criteria)
                        say("reading the effects' signatures again at the better base")
                        sig = dict(read(base))
                    current = again
                    continue
            steps.append(Step(best, current))
            current = best.fit
            continue
        # a withdrawn effect's failure says nothing of the candidates judged with it: the
        # selection goes on from the model before it, without it
        kept, gone = withdraw_unsupported(steps, current, criteria)
        if gone is None:
            break
        withdrawn.add(gone)
        current = kept
    say("fitting something else on the final model")
    return Selection(base, steps, judged, verdict_on(loc, reg, criteria, unknown_inputs), sig)


def _fit_candidates(loc: Local, pending: Sequence[str], sig: Mapping[str, object], rnd: int,
                    say: Callable[[str], None]) -> dict:
    """Each pending candidate fitted on the linearized model, by label (EffectFit), from a
    tenth into its range and from its signature's estimate where there is one; one that makes
    the model run away from every start is left out."""
    fits = {}
    for lab in pending:
        say(f"round {rnd}: fitting {lab}")
        tries = [fit_effect(loc, lab)]
        from_signature = _signature_start(lab, sig.get(lab))
        if from_signature:
            tries.append(fit_effect(loc, lab, from_signature))
        tries = [f for f in tries if f is not None]
        if tries:
            fits[lab] = max(tries, key=lambda f: f.gain)
        else:
            say(f"round {rnd}: {lab} makes the model run away wherever it was tried; not judged")
    return fits


def _judge_round(loc: Local, fits: Mapping, sig: Mapping[str, object], criteria: Criteria,
                 reg, unknown_inputs: Sequence[tuple[float, float]], rnd: int,
                 say: Callable[[str], None]) -> list[Judgement]:
    """Every fitted candidate of one round judged against the current model (``loc``), the
    competitor and each other (module docstring)."""
    if not fits:
        return []
    current = loc.fit
    say(f"round {rnd}: fitting something else")
    found, _ = scan(reg, loc.r0, loc.channel, loc.in_fit & known_inputs(loc, unknown_inputs),
                    current.sample_share)
    # the null of every test: the current model refitted by the same step without a
    # candidate (a nonlinear fit stopped short of its optimum leaves the step a gain of
    # its own, which is no candidate's)
    gain, delta = loc.gain()
    null = NullStep(gain, delta, loc.residual(delta))
    g_gain = joint_gain(loc, reg, found) - null.gain
    # every candidate's gain over the null, penalised by half ln(n_eff) per parameter (BIC)
    pen = 0.5 * math.log(max(current.n_eff, 2.0))
    penalised = {lab: f.gain - null.gain - pen * len(effect_of(lab).params)
                 for lab, f in fits.items()}
    margin = criteria.distinct_margin()
    # something else: the scan's events, or a law of the speed for the whole run (never a
    # complement: what it explains, no effect of the library needs to). A law nests
    # windage's, so it stops an effect only where it is better by a significant margin
    laws = {lab: penalised.pop(lab) for lab in list(penalised) if lab in LAWS.values()}
    competitor = max([g_gain - 3 * pen, *(v - margin for v in laws.values())])
    law = max(laws, key=laws.get, default=None)  # the likeliest, where it is the competitor
    law = law if law is not None and laws[law] - margin >= g_gain - 3 * pen else None
    cv_now = loc.rms_by_channel(loc.held_out(criteria.cv_blocks)) if criteria.cv_blocks else None
    out = []
    for lab, ef in fits.items():
        if lab in laws:
            continue
        near = {other: v for other, v in penalised.items() if other != lab
                and parse_label(other)[0] != parse_label(lab)[0]
                and set(_own(other)) & set(_own(lab))}
        # only a rival that could make it fail is asked whether it is a complement
        comp = [other for other, v in near.items() if criteria.distinct_among_alternatives
                and v + margin > penalised[lab]
                and complements(loc, ef, fits[other], margin)]
        rival = max((v for other, v in near.items() if other not in comp), default=-math.inf)
        out.append(judge(loc, ef, sig.get(lab), criteria, penalised[lab], competitor,
                         rival, cv_now, rnd, null, comp))
        if law is not None:
            out[-1].figures["law"] = {"label": law, "values": fits[law].values}
    return out


def joins_first(qualified: Sequence[Judgement]) -> Judgement:
    """The qualifying candidate that joins the model this round: one qualified by its
    signature before one the open loop alone supports, then the largest gain. A signature's
    evidence is the raw samples', whatever model it is judged against; the open loop's is the
    model's likelihood, which the signature's effect changes, so an open-loop candidate is
    judged again in the next round against the model that holds it."""
    return max(qualified, key=lambda j: (j.route == "signature", j.gain))


def refit(cal: Calibrator, loc: Local, ef, criteria: Criteria) -> tuple[Fit, str]:
    """The nonlinear fit of the current model (``loc.fit``, linearized as ``loc``) with the
    candidate ``ef`` (its compare.fit.linear.EffectFit) added, started twice: at the linearized
    step (the base parameters moved by its delta) and at the current model with only the effect's
    values added. The better log-posterior (Fit.log_posterior, in the current model's effective
    samples) is kept, with the start it came from ("step" or "nested"). The step extrapolates the
    linearization over the whole change, and where the base must move far it can land in another
    basin of the least squares than the current model's; the second start is the nested model's
    own optimum, from which the effect only adds."""
    current = loc.fit
    starts = {"step": {**loc.theta_after(ef.delta), **ef.values},
              "nested": {**current.theta, **ef.values}}
    fits = {name: cal.fit(current.effects + (ef.label,), start=start,
                          max_nfev=criteria.refit_nfev) for name, start in starts.items()}
    best = max(fits, key=lambda k: fits[k].log_posterior(current.sample_share))
    return fits[best], best


def null_from(cal: Calibrator, current: Fit, joined: Fit, criteria: Criteria
              ) -> tuple[Fit, float]:
    """The current model (``current``, without the candidate) refitted from where ``joined``
    (it with the candidate) ended, the candidate's own values dropped, and its log-posterior
    gain over ``current`` (in ``current``'s effective samples, as in :func:`refit`). A
    likelihood-ratio test holds only where the null is at its optimum: a candidate's refit can
    move the base into a better basin than its calibration found, and its gain is then the
    null's shortfall, which the null without it gains as well (Criteria.null_from_candidate)."""
    shrink = current.sample_share
    again = cal.fit(current.effects, start={k: v for k, v in joined.theta.items()
                                            if k in current.theta},
                    max_nfev=criteria.refit_nfev)
    return again, float(again.log_posterior(shrink) - current.log_posterior(shrink))


def withdraw_unsupported(steps: list[Step], final: Fit,
                         criteria: Criteria) -> tuple[Fit, str | None]:
    """Criteria.open_loop_adequate_model: where the ``final`` model misses the tolerance of one of
    an open-loop step's own channels on held-out data, the first such step and every step after it
    are withdrawn (``steps`` is cut; their judgements' ``final_model_adequate`` set False). A
    misfit on a channel the effect does not act on leaves its likelihood ratio as it was. Returns
    the model that remains and the first withdrawn step's label (None: nothing withdrawn)."""
    misses = held_out_misses(final.errors) if criteria.open_loop_adequate_model else {}
    first = next((i for i, s in enumerate(steps) if s.judgement.route == "open loop"
                  and set(_own(s.label)) & set(misses)), None)
    if first is None:
        return final, None
    kept, label = steps[first].before, steps[first].label
    for s in steps[first:]:
        s.judgement.criteria["final_model_adequate"] = False
    del steps[first:]
    return kept, label


#: the amplitude of a candidate's fitted shift in :func:`complements`: from none to twice its
#: own fit (the shift is the effect's at its estimate; the base's step takes the rest)
SHIFT_BOUNDS = (0.0, 2.0)


def complements(loc: Local, a, b, margin: float) -> bool:
    """Whether candidates ``a`` and ``b`` (compare.fit.linear.EffectFit) each add a significant
    gain over the other (a log-likelihood gain above ``margin``: Criteria.distinct_margin, one
    degree of freedom at alpha): each enters as the amplitude of its fitted shift, jointly with
    the base's step on the linearized model ``loc``. Such candidates explain different parts of
    the run, so neither is an alternative to the other (Criteria.distinct_among_alternatives)."""
    ca, cb = a.shift[:, None], b.shift[:, None]
    g_a, g_b = (loc.gain(c, [SHIFT_BOUNDS])[0] for c in (ca, cb))
    g_ab = loc.gain(np.hstack([ca, cb]), [SHIFT_BOUNDS, SHIFT_BOUNDS])[0]
    return bool(g_ab - g_a > margin and g_ab - g_b > margin)


@dataclass(frozen=True)
class NullStep:
    """The current model refitted by one step of the linearized model without a candidate:
    its log-posterior gain over the current fit, its step and its residual (every row)."""

    gain: float
    delta: np.ndarray
    residual: np.ndarray


def judge(loc: Local, ef, signature, criteria: Criteria, penalised: float,
          competitor: float, rival: float, cv_now: dict | None, rnd: int,
          null: NullStep, complements_: Sequence[str] = ()) -> Judgement:
    """The named criteria of one candidate fitted on the linearized model (module
    docstring). ``penalised``: its gain over the ``null`` (the current model refitted by the
    same step, :class:`NullStep`) less half ln(n_eff) per parameter; ``competitor`` and
    ``rival``: the same of the competitor's best hypothesis and of the best other candidate on
    its channels that is an alternative to it, the others (``complements_``) being its
    complements (:func:`complements`)."""
    from scipy.stats import chi2

    cal = loc.cal
    gain = ef.gain - null.gain
    lr = max(2.0 * gain, 0.0)
    pv = float(chi2.sf(lr, len(effect_of(ef.label).params)))
    own = _own(ef.label)
    rows = np.isin(loc.channel, [cal.channels.index(c) for c in own if c in cal.channels])
    peak = float(np.max(np.abs(ef.shift[rows]))) if rows.any() else 0.0
    # what the fitted model's prediction moves by against the null, the base's
    # re-adjustment around the effect included
    net = float(np.max(np.abs(null.residual[rows] - ef.residual[rows]))) if rows.any() else 0.0
    # the largest |prior z| of the base parameters without the candidate and with it
    z_null = float(np.max(np.abs(loc.prior_sds(null.delta)), initial=0.0))
    z_with = float(np.max(np.abs(loc.prior_sds(ef.delta)), initial=0.0))
    out: dict[str, bool | None] = {
        "significant": pv < criteria.alpha,
        "material": peak >= criteria.material_peak,
        "signature": signature_outcome(signature, criteria.alpha),
        "predicts": None,
        "changes_prediction": (net >= criteria.material_peak
                               if criteria.open_loop_material_change else None),
        "restores_plausible_base": (z_null > criteria.implausible_z() >= z_with
                                    if criteria.plausible_base_route else None),
        "beats_something_else": bool(penalised >= competitor),
        "distinct": bool(penalised >= rival + criteria.distinct_margin()),
        "null_at_optimum": None,  # asked of the candidate that joins, after its refit
        "final_model_adequate": None,  # asked of the open loop's names after the selection
    }
    figures: dict[str, object] = {
        "values": ef.values, "penalised_gain": penalised,
        "competitor_penalised_gain": competitor if math.isfinite(competitor) else None,
        "rival_penalised_gain": rival if math.isfinite(rival) else None,
        "complements": list(complements_),
        "net_change_peak": net, "base_prior_z_without": z_null, "base_prior_z_with": z_with,
        "cv_before": None, "cv_after": None}
    if criteria.cv_blocks and out["significant"] and out["material"] and not out["signature"]:
        before = _cv_excess(cv_now or {}, cal.floor, own)
        after = _cv_excess(effect_held_out(loc, ef, criteria.cv_blocks), cal.floor, own)
        out["predicts"] = bool(after <= (1.0 - criteria.cv_gain) * before)
        figures.update(cv_before=before, cv_after=after)
    return Judgement(ef.label, rnd, None, gain, lr, pv, peak, out, figures)


def verdict_on(loc: Local, reg, criteria: Criteria,
               unknown_inputs: Sequence[tuple[float, float]] = ()) -> Verdict:
    """The competitor on the final model (linearized as ``loc``) stepped to the whole run:
    unexplained where it is significant (its scan's largest statistic against the same scan on
    white noise: compare.fit.competitor.scan_threshold) and material; and, whatever was
    named, where the final model misses a tolerance on held-out data (:func:`held_out_misses`,
    Criteria.held_out_misfit_unexplained)."""
    r = loc.residual(loc.step(np.ones(len(loc.r0), dtype=bool)))
    rows = known_inputs(loc, unknown_inputs)
    found, _ = scan(reg, r, loc.channel, rows, loc.fit.sample_share, top=1)
    h = found[0] if found else None
    lr = 2.0 * h.gain if h is not None else 0.0
    threshold = (scan_threshold(reg, loc.channel, rows, criteria.alpha, criteria.scan_null_tail)
                 if h is not None else math.inf)
    if h is not None and lr > threshold and h.peak >= criteria.material_peak:
        return Verdict(h, lr, threshold, True)
    misses = held_out_misses(loc.fit.errors) if criteria.held_out_misfit_unexplained else {}
    return Verdict(h, lr, threshold, bool(misses), misses)


def held_out_misses(errors: dict) -> dict[str, float]:
    """Channels whose open-loop RMS on the validation window exceeds one tolerance, with that
    RMS in tolerances (``errors``: compare.fit.calibrate.Fit.errors)."""
    return over_tolerance(errors.get("validation", {}))
