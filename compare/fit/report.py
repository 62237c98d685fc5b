"""The fit's report: ``report.json`` (format :data:`REPORT_FORMAT`), ``report.html`` and its
pictures, and the text ``fit`` prints. Each begins with the verdict: the effects named, with
their values and intervals and the error before and after per channel against the
tolerances, or "nothing named, base adequate", "nothing named, base inadequate", or
"unexplained" and where. The evidence follows: every candidate's criteria, the signature
tests, the adequacy of the base model, the cross-validation, the parameters."""

from __future__ import annotations

import html
import math
import re
from collections.abc import Sequence
from dataclasses import asdict
from pathlib import Path

import numpy as np

from compare.fit.calibrate import TOLERANCE, Fit, at_bound, over_tolerance, parameters_table
from compare.fit.competitor import LAWS
from compare.fit.effects import effect_of, parse_label
from compare.fit.params import BASE_PARAMS, base_params, default_theta
from compare.report import html_figure, html_page, html_table
from spindle.drive import drive_for
from spindle.drive_file import FRICTION_REF_RPM
from spindle.outputs import jsonable
from spindle.tolerances import edge_absolute, edge_scale, edge_unit

#: 3: ``calibration_model`` and ``fem_calibration`` gone with ``--model fem``; the verdict's
#: ``residual`` (where an unexplained residual lives)
REPORT_FORMAT = "spindle-verify-fit/3"


def _place_of(rep, verdict: dict) -> dict | None:
    """:func:`residual_place` of an unexplained verdict: in the competitor's window, or on
    the validation window for a held-out misfit; None otherwise."""
    if not verdict.get("unexplained"):
        return None
    h = verdict.get("hypothesis") if verdict.get("basis") == "something else" else None
    return residual_place(rep, h["t0_s"], h["t1_s"]) if h else residual_place(rep)


def p_text(p: float | None) -> str:
    """A p-value as people read it (one below double precision's range is not 0)."""
    if p is None or not math.isfinite(p):
        return "n/a"
    return "p < 1e-300" if p < 1e-300 else f"p = {p:.2g}"


def _number(x: float | None, fmt: str) -> str:
    """A figure of report.json, where a non-finite one is None: "n/a" for it."""
    return "n/a" if x is None or not math.isfinite(x) else format(x, fmt)


def _errors(fit: Fit) -> dict:
    keys = ("rmse", "max", "bias", "unit", "rmse_tolerances", "within_tolerance", "n")
    return {window: {c: {k: e["rmse_w" if k == "rmse_tolerances" else k] for k in keys}
                     for c, e in chans.items() if e.get("n")}
            for window, chans in fit.errors.items()}


def _effect_entry(rep, step) -> dict:
    """One named effect: its parameters at the final fit, intervals, units, evidence and the
    criteria it passed."""
    final, j, lab = rep.selection.final, step.judgement, step.label
    name, channel = parse_label(lab)
    e = effect_of(lab)
    params: dict = {p.name: final.theta[p.name] for p in e.params}
    if channel:
        params["channel"] = channel
    test = rep.signatures.get(lab)
    return {"name": name, "label": lab, "channel": channel, "parameters": params,
            "confidence_intervals": {p.name: list(final.ci95[p.name]) for p in e.params},
            "units": {p.name: p.unit for p in e.params},
            "p_value": j.p_value, "lr": j.lr, "gain": j.gain, "peak_tolerances": j.peak,
            "evidence": test.to_dict() if test is not None and test.applies else None,
            "criteria": j.criteria, "route": j.route, "explanation": e.explanation, "hint": e.hint,
            "at_bound": at_bound(final, lab, rep.criteria.at_bound_rel),
            "validation_rms_before": step.before.validation_score(),
            "validation_rms_after": step.fit.validation_score()}


def verdict_kind(rep) -> str:
    """"named", "unexplained", "base adequate" or "base inadequate"."""
    sel = rep.selection
    if sel.steps:
        return "named"
    if sel.verdict is not None and sel.verdict.unexplained:
        return "unexplained"
    return ("base inadequate" if over_tolerance(sel.final.errors["validation"])
            else "base adequate")


def _change_text(doc: dict) -> str:
    """The validation error before and after per channel, against the tolerances."""
    before = doc["error_before"].get("validation", {})
    return ", ".join(f"{c} {before.get(c, a)['rmse']:.2f} -> {a['rmse']:.2f} {edge_unit(c)} "
                     f"(tolerance {TOLERANCE[c] * edge_scale(c):g})"
                     for c, a in doc["error_after"].get("validation", {}).items())


def shown_unit(unit: str) -> str:
    """A parameter's unit as a reader sees it: the code's ASCII ``um/krpm^2`` as µm/krpm²
    (report.json keeps the code's spelling)."""
    return re.sub(r"\bum\b", "µm", unit).replace("^2", "²").replace("^3", "³")


def verdict_lines(doc: dict) -> list[str]:
    """The verdict in sentences: what was found, then the error before and after."""
    v = doc["verdict"]
    place = place_text(v.get("residual"))  # where an unexplained residual lives
    where = str(v.get("where")) + (f"; {place}" if place else "")
    lines = []
    if v["kind"] == "named":
        for e in doc["effects"]:
            vals = "; ".join(
                f"{k} = {x:.3g} {shown_unit(e['units'].get(k, ''))} (95 %: {ci[0]:.3g} to "
                f"{ci[1]:.3g})"
                for k, x in e["parameters"].items() if isinstance(x, int | float)
                for ci in [e["confidence_intervals"].get(k, (math.nan, math.nan))])
            ev = e["evidence"]
            how = (f"its signature in the raw samples (z = {ev['z']:.1f}, {p_text(ev['p_value'])})"
                   if e["route"] == "signature" else
                   f"the open-loop fit ({p_text(e['p_value'])}): it predicts held-out blocks and "
                   "explains the run better than something else and than every other effect"
                   + ("; without it the calibrated base needs a value outside its prior's range"
                      if e["criteria"].get("changes_prediction") is False
                      and e["criteria"].get("restores_plausible_base") else ""))
            lines.append(f"Named: {e['label']}, {vals}. Evidence: {how}.")
            look = effect_of(e["label"]).look_alike
            if look and e["route"] != "signature":  # the name holds only so far
                sig = (doc.get("signatures") or {}).get(e["label"]) or {}
                lines.append(f"Not told apart: {e['label']} and {look} leave the same mark in "
                             "the channels; its signature tells them apart and does not apply "
                             "to this run" + (f": {sig['meaning']}" if sig.get("meaning") else "")
                             + ".")
        if v["unexplained"]:
            lines.append(f"Something else remains: {where}.")
    elif v["kind"] == "unexplained" and v.get("basis") == "held-out misfit":
        lines.append("Unexplained: the calibrated model misses the tolerances on held-out data "
                     f"and no effect of the library explains it: {where}. A spindle unlike its "
                     "spec shows the same way: see the base's adequacy below.")
    elif v["kind"] == "unexplained":
        lines.append("Unexplained: no effect of the library explains this run, and something "
                     f"else does: {where}.")
    elif v["kind"] == "base adequate":
        # adequate to the tolerances; whether its values are plausible is the adequacy's
        # statement below, which this points to so that the two do not read as a contradiction
        far = (doc.get("base_adequacy") or {}).get("implausible") or []
        lines.append("Nothing named, base adequate: the calibrated base model explains the run "
                     "within the tolerances" + (
                         f", with {', '.join(far)} outside {'its' if len(far) == 1 else 'their'}"
                         " prior range (the base's adequacy, below)" if far else "") + ".")
    else:
        lines.append("Nothing named, base inadequate: the calibrated base model misses the "
                     "tolerances, and neither an effect of the library nor something at one "
                     "time of the run explains the misfit; look at the spec (below).")
    se = doc.get("something_else") or {}
    h, crit = se.get("hypothesis"), se.get("threshold")
    if v["kind"].startswith("base") and h and crit is not None and math.isfinite(crit):
        # how near the verdict's own test came, so that a near miss does not read as nothing;
        # above the critical value and still not unexplained, verdict_on found it immaterial
        stat = (f"likelihood ratio {se['lr']:.1f}, critical value {crit:.1f} at alpha "
                f"{doc.get('alpha', 0.01):g}")
        lines.append(
            f"Not significant: the likeliest event the library lacks, {se['where']} ({stat})."
            if se["lr"] <= crit else
            f"Too small to matter: the likeliest event the library lacks, {se['where']}, is "
            f"significant ({stat}) but moves no channel by more than "
            f"{h['peak_tolerances']:.2g} tolerances.")
    lines += _law_lines(doc)
    # one that joined after a withdrawn effect is withdrawn with it and may be named again
    named = {e["label"] for e in doc["effects"]}
    gone = list(dict.fromkeys(c["candidate"] for c in doc.get("candidates", [])
                              if c["criteria"].get("final_model_adequate") is False
                              and c["candidate"] not in named))
    if gone:
        them = "it" if len(gone) == 1 else "them"
        lines.append(f"Fitted and withdrawn: {', '.join(gone)}. The model with {them} still "
                     "misses the tolerances on held-out data, so the open loop's likelihood "
                     f"ratio does not tell the cause; the selection went on without {them}.")
    short = [c for c in doc.get("candidates", [])
             if c["criteria"].get("null_at_optimum") is False]
    if short:
        labels = list(dict.fromkeys(c["candidate"] for c in short))
        gain = max(c["null_shortfall"] for c in short)
        lines.append(f"Calibrated again: the model without {', '.join(labels)} fitted better "
                     f"from where {'its' if len(labels) == 1 else 'their'} refit ended (log-"
                     f"likelihood up by {gain:.1f}), so that gain named nothing; the base and "
                     "every test are the better fit's.")
    lines.append(f"Validation error before -> after: {_change_text(doc)}.")
    return lines


def _law_lines(doc: dict) -> list[str]:
    """Where a law of the speed the library lacks (compare.fit.competitor.SpeedHeat) stopped
    an effect that fitted, significant and material, a sentence naming the law's fit (as
    first fitted) and the effects it stopped. An effect its signature decided (named by it,
    or vetoed) or that the run names after all was not stopped by the law."""
    named = {e["label"] for e in doc["effects"]}
    stopped: dict[str, list[str]] = {}
    fitted: dict[str, dict] = {}
    for c in doc.get("candidates", []):
        law, crit, lab = c.get("law"), c["criteria"], c["candidate"]
        if (law and crit.get("beats_something_else") is False and crit["significant"]
                and crit["material"] and crit.get("signature") is None and lab not in named
                and lab not in stopped.get(law["label"], [])):
            stopped.setdefault(law["label"], []).append(lab)
            fitted.setdefault(law["label"], law["values"])
    role = {lab: r for r, lab in LAWS.items()}
    out = []
    for label, effects in stopped.items():
        v = fitted[label]
        out.append(f"A law the library lacks, a heat into the {role[label]} of "
                   f"{v['q_law_W']:.0f} W (n / {FRICTION_REF_RPM:g} "
                   f"rpm)^{v['k_law']:.1f}, explains the run better than "
                   f"{'this effect' if len(effects) == 1 else f'these {len(effects)} effects'}"
                   " of the library, by more than one degree of freedom's margin, so "
                   f"{'it is not' if len(effects) == 1 else 'none is'} named: "
                   f"{', '.join(effects)}.")
    return out


#: the inputs' names in sentences (compare.fit.run diagnoses the residual against these)
_INPUT_WORDS = {"speed": "the speed", "power": "the drive's power", "T_env": "the room"}


def residual_place(rep, t0_s: float | None = None, t1_s: float | None = None) -> dict | None:
    """Where the final model's residual lives: the channel whose RMS in tolerances is largest
    over [t0, t1) [s] (default: the validation window), that RMS, and the input its residual
    follows most closely over the whole run (the largest cross-correlation of the residual
    diagnostics at lags >= 0 short of the largest tried, with its lag [s]: a residual that
    leads an input is no response to it, and a peak at the range's end is no lag found). None
    where no channel has samples there."""
    m, final = rep.measured, rep.selection.final
    g = m.grid_s
    if t0_s is None:
        rows = {c: m.mask(c, "validation") for c in rep.channels}
    else:
        rows = {c: (g >= t0_s) & (g < t1_s) & np.isfinite(m.values[c]) for c in rep.channels}
    rms = {c: float(np.sqrt(np.mean(((m.values[c] - final.model[c])[r] / TOLERANCE[c]) ** 2)))
           for c, r in rows.items() if r.any()}
    if not rms:
        return None
    c = max(rms, key=rms.get)
    out = {"channel": c, "rms_tolerances": rms[c], "input": None, "lag_s": None, "ccf": None}
    diag = rep.diagnostics_after.channels.get(c)
    peak = diag.best("input", after=True) if diag is not None else None
    if peak is not None and abs(peak.ccf_after) > peak.band:
        out.update(input=peak.name, lag_s=peak.lag_after_s, ccf=peak.ccf_after)
    return out


def place_text(place: dict | None) -> str:
    """:func:`residual_place` in words."""
    if not place:
        return ""
    text = (f"the residual is largest in {place['channel']} ({place['rms_tolerances']:.1f} "
            "tolerances RMS there)")
    if place["input"]:
        lag = place["lag_s"]
        when = "at once" if lag < 1 else f"{lag / 60:.0f} min after it"
        text += (f" and follows {_INPUT_WORDS.get(place['input'], place['input'])} most "
                 f"closely ({when}, correlation {place['ccf']:+.2f})")
    return text


def report_dict(rep) -> dict:
    """The JSON document of a :class:`compare.fit.run.FitReport` (module docstring)."""
    sel = rep.selection
    final = sel.final
    effects = [_effect_entry(rep, st) for st in sel.steps]
    verdict = sel.verdict.to_dict() if sel.verdict is not None else {"unexplained": False}
    doc = {
        "format": REPORT_FORMAT, "run": str(rep.run.path), "spec": rep.spec.name,
        "channels": rep.channels,
        "verdict": {"kind": verdict_kind(rep), "named": [e["label"] for e in effects],
                    "unexplained": bool(verdict["unexplained"]), "where": verdict.get("where"),
                    "basis": verdict.get("basis", ""), "residual": _place_of(rep, verdict)},
        "effects": effects,
        "something_else": verdict,
        "unexplained": {"unexplained": bool(verdict["unexplained"]),
                        "description": verdict.get("where") or ""},
        "error_before": _errors(sel.base), "error_after": _errors(final),
        "candidates": [j.to_dict() for j in sel.judged],
        "signatures": {k: t.to_dict() for k, t in rep.signatures.items()},
        "criteria": rep.criteria.table(),
        "run_summary": rep.run.summary(),
        "windows": {"blocks": rep.measured.blocks,
                    **{w: [[a, b] for a, b, x in rep.measured.spans() if x == w]
                       for w in ("fit", "validation")},
                    "inputs_unknown": [[a, b] for a, b in rep.unknown_inputs]},
        "cross_validation": rep.cross_validation,
        "tolerances": {"temperature_K": TOLERANCE["T1"],
                       "growth_um": TOLERANCE["P1"] * edge_scale("P1")},
        "alpha": rep.criteria.alpha,
        "base_adequacy": rep.base_adequacy,
        "warnings": rep.warnings,
        "gap_switches": [asdict(g) for g in rep.gap_switches],
        "start": None if rep.start is None else rep.start.to_dict(),
        "parameters": parameters_table(final),
        "parameters_before": parameters_table(sel.base),
        "parameters_prior_z": rep.prior_z,
        "correlation": {"names": final.free, "matrix": final.correlation.tolist()},
        "not_identifiable": [k for k, ok in final.identifiable.items() if not ok],
        "fem_anchor": None if rep.anchor is None else {
            "fem_level": rep.anchor.fem_level,
            "prior_centre": default_theta(base_params(drive_for(rep.spec))),
            "anchored_at": rep.anchor.theta_ref,
            "prior_sd": {k: p.prior_sd for k, p in BASE_PARAMS.items()},
            "fem_minus_lumped_rms": rep.anchor.rms,
            "validation_floor": rep.floor},
        "diagnostics_before": rep.diagnostics_before.to_dict(),
        "diagnostics_after": rep.diagnostics_after.to_dict(),
        "runtime_s": rep.runtime_s}
    doc["verdict"]["summary"] = " ".join(verdict_lines(doc))
    return jsonable(doc)


def summary_text(rep) -> str:
    """What ``fit`` prints: the verdict first, then the run, the adequacy of the base model,
    warnings and the cross-validated error."""
    doc = rep.to_dict()
    lines = verdict_lines(doc)
    unknown = rep.run.unknown_columns  # kept and reported, as the bench format asks
    lines.append(f"{rep.run.path}: {len(rep.run.time_s)} rows, {rep.run.duration_s / 3600:.2f} "
                 f"h, channels {', '.join(rep.channels)}"
                 + (f"; unknown columns kept, not used: {', '.join(unknown)}" if unknown else "")
                 + f"; {rep.runtime_s:.1f} s")
    ad = doc.get("base_adequacy")
    if ad:
        lines.append(f"The base model {ad['statement']}.")
    lines += [f"Warning: {w}." for w in doc.get("warnings") or []]
    cv = doc.get("cross_validation") or {}
    for key, label in (("base", "before"), ("final", "after")):
        if cv.get(key, {}).get("pooled"):
            lines.append(f"Cross-validated error {label} ({cv[key]['blocks']} blocks, each held "
                         "out): " + ", ".join(f"{c} {e['rmse']:.2f} {edge_unit(c)}"
                                              for c, e in cv[key]["pooled"].items()) + ".")
    bad = doc["not_identifiable"]
    if bad:
        lines.append(f"Not identifiable from this run: {', '.join(bad)}.")
    return "\n".join(lines)


def named_effects(doc: dict) -> list[str]:
    """The effects a report names, by label (a lag with its channel, ``sensor_lag(T1)``)."""
    return [e["label"] for e in doc["effects"]]


def selection_trace(doc: dict) -> dict:
    """What a benchmark keeps of a report to see why an effect was named or not: the
    signature tests (estimate, z, p), each judged candidate's criteria and figures, the
    competitor on the final model and the calibrated parameters."""
    return {"signatures": {k: {f: v.get(f) for f in ("estimate", "se", "z", "p_value")}
                           for k, v in doc.get("signatures", {}).items()},
            "candidates": doc.get("candidates", []),
            "something_else": doc.get("something_else"),
            "parameters": {p["name"]: p["value"] for p in doc.get("parameters", [])}}


# ---------------------------------------------------------------------- files
def save_report(rep, out: Path, pictures: bool = True) -> list[Path]:
    from spindle.outputs import atomic_write, write_json

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    doc = rep.to_dict()
    write_json(out / "report.json", doc)
    pngs = _pictures(rep, out) if pictures else []
    atomic_write(out / "report.html",
                 lambda tmp: tmp.write_text(_html(rep, doc, out, pngs), "utf-8"))
    return [out / "report.json", *(out / name for name, _ in pngs), out / "report.html"]


def _pictures(rep, out: Path) -> list[tuple[str, str]]:
    from compare.residuals import plot_acf, plot_cumulated_periodogram
    from spindle.outputs import atomic_write
    from spindle.plots import pyplot

    plt = pyplot()
    g = rep.measured.grid_s / 3600
    sel = rep.selection
    n = len(rep.channels)
    fig, axes = plt.subplots(n, 2, figsize=(13, 2.8 * n), layout="constrained", squeeze=False)
    for i, c in enumerate(rep.channels):
        scale, off, unit = edge_absolute(c)
        tol = TOLERANCE[c] * scale
        meas = rep.measured.values[c] * scale - off
        for j, (fit, label) in enumerate(((sel.base, "before"), (sel.final, "after"))):
            ax = axes[i, j]
            model = fit.model[c] * scale - off
            ax.fill_between(g, model - tol, model + tol, color="tab:blue", alpha=0.15,
                            label=f"model ±{tol:g} {unit}")
            ax.plot(g, model, color="tab:blue", ls="--", lw=1, label="model")
            ax.plot(g, meas, color="black", lw=0.8, label="measured")
            for a, b, w in rep.measured.spans():
                if w == "validation":
                    ax.axvspan(a / 3600, b / 3600, color="tab:orange", alpha=0.08, lw=0)
            for a, b in rep.unknown_inputs:
                ax.axvspan(a / 3600, b / 3600, color="0.4", alpha=0.12, lw=0)
            ax.set_ylabel(f"{c} [{unit}]")
            ax.set_title(f"{c} {label}" + (f" (with {', '.join(fit.effects)})" if fit.effects
                                            else " (base model)"), fontsize=9)
            ax.grid(alpha=0.3)
            if i == 0:
                ax.legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("time [h]")
    fig.supxlabel("orange: validation window; grey: a logging gap and the hour after it "
                  "(inputs unknown, something else not looked for)", fontsize=9)
    atomic_write(out / "fit_channels.png", lambda tmp: fig.savefig(tmp, dpi=110))
    plt.close(fig)
    fig, axes = plt.subplots(n, 3, figsize=(14, 2.6 * n), layout="constrained", squeeze=False)
    dt = float(np.median(np.diff(rep.measured.grid_s)))
    for i, c in enumerate(rep.channels):
        ax = axes[i, 0]
        first = True
        for fit, colour, label in ((sel.base, "C0", "before"), (sel.final, "C1", "after")):
            r = (rep.measured.values[c] - fit.model[c]) / TOLERANCE[c]
            ax.plot(g, r, lw=0.8, color=colour, label=label)
            if (~np.isnan(r)).sum() > 20:
                plot_acf(axes[i, 1], r, 40, 0.01, dt, color=colour, label=label, band=first)
                plot_cumulated_periodogram(axes[i, 2], r, 0.01, dt, color=colour, label=label,
                                           band=first)
                first = False
        ax.axhspan(-1, 1, color="0.9")
        ax.set_ylabel(f"{c} residual / tol")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
        for k, at, what in ((1, "upper right", "ACF"), (2, "lower right", "cumulated periodogram")):
            axes[i, k].legend(fontsize=7, loc=at)
            axes[i, k].set_title(f"{c}: {what} (before, after)", fontsize=9)
    atomic_write(out / "fit_residuals.png", lambda tmp: fig.savefig(tmp, dpi=110))
    plt.close(fig)
    return [("fit_channels.png", "measured against the model, before and after, with the "
             "tolerance bands (paper Fig. 13)"),
            ("fit_residuals.png", "residuals before and after (in tolerance units), their "
             "autocorrelation and cumulated periodograms")]


def _criteria_html(doc: dict) -> str:
    """Every judged candidate and each named criterion's outcome."""
    from compare.fit.select import CRITERIA_ORDER as names

    rows = []
    for c in doc.get("candidates", []):
        crit = c["criteria"]
        rows.append([c["candidate"], c["round"], _number(c["gain"], ".1f"),
                     p_text(c["p_value"]), _number(c["peak_tolerances"], ".2f"),
                     *["—" if crit.get(k) is None else ("pass" if crit[k] else "FAIL")
                       for k in names], ", ".join(c.get("complements") or []),
                     c.get("route") or "no"])
    return ("<h2>Candidates and criteria</h2><p>Each candidate refitted with the base "
            "parameters, round by round, and the criteria it passed (— not asked). A "
            "candidate qualifies when it is significant and material and shows that it is "
            "this effect by its signature or by every open-loop criterion, of which the "
            "last is changes_prediction or, failing it, restores_plausible_base "
            "(compare.fit.select). Its complements each add to it as it adds to them, so "
            "distinct does not count them as rivals. The candidate that joins is last asked "
            "null_at_optimum: whether the model without it, refitted from where its refit "
            "ended, gains less than one degree of freedom's margin; where it gains more, the "
            "round is judged again from there.</p>"
            + html_table(["candidate", "round", "gain", "p", "peak [tol]", *names,
                          "complements", "qualifies by"], rows, ["s"] * (len(names) + 7)))


def _signatures_html(doc: dict) -> str:
    rows = []
    for label, t in (doc.get("signatures") or {}).items():
        applies = t["p_value"] is not None and math.isfinite(t["p_value"])
        rows.append([label, t["channel"],
                     f"{t['estimate']:.4g} ± {t['se']:.2g}" if applies else "",
                     t["unit"], f"{t['z']:.1f}" if applies else "", p_text(t["p_value"]),
                     t["meaning"]])
    if not rows:
        return ""
    return ("<h2>Signature tests (raw samples)</h2>"
            + html_table(["test", "channel", "estimate ± se", "unit", "z", "p", "what it reads"],
                         rows, ["s"] * 7))


def _html(rep, doc: dict, out: Path, pngs: Sequence[tuple[str, str]]) -> str:
    def err_table(block: dict) -> str:
        rows = [[window, c, e["rmse"], e["max"], e["bias"], e["unit"],
                 100 * e["within_tolerance"]]
                for window in ("fit", "validation") for c, e in block.get(window, {}).items()]
        return html_table(["window", "channel", "RMSE", "max", "bias", "unit",
                           "within tolerance [%]"], rows,
                          ["s", "s", ".3f", ".3f", "+.3f", "s", ".1f"])

    params = html_table(
        ["name", "value", "95 %", "unit", "identifiable", "meaning", "prior's source"],
        [[p["name"], p["value"], f"{p['ci95'][0]:.4g} .. {p['ci95'][1]:.4g}", p["unit"],
          "yes" if p["identifiable"] else "NO", p["meaning"], p["source"]]
         for p in doc["parameters"]],
        ["s", ".4g", "s", "s", "s", "s", "s"])
    ad = doc.get("base_adequacy") or {}
    crit = html_table(["criterion", "value", "unit", "reason"],
                      [[c["name"], str(c["value"]), c["unit"], c["reason"]]
                       for c in doc["criteria"]], ["s"] * 4)
    warns = "".join(f"<li>{html.escape(w)}</li>" for w in doc.get("warnings") or [])
    return html_page("spindle-verify fit", [
        f"<h1>Fit of {html.escape(str(rep.run.path))} to {html.escape(rep.spec.name)}</h1>",
        "".join(f"<p><b>{html.escape(line)}</b></p>" for line in verdict_lines(doc)),
        (f"<p><b>Warnings</b></p><ul>{warns}</ul>" if warns else ""),
        "<h2>Error before and after</h2>" + err_table(doc["error_before"])
        + err_table(doc["error_after"]),
        *[html_figure(out / n, c) for n, c in pngs[:1]],
        _criteria_html(doc),
        _signatures_html(doc),
        f"<h2>The base model</h2><p>The calibrated base model "
        f"{html.escape(ad.get('statement', ''))}.</p>",
        "<h2>Calibrated parameters (95 % intervals)</h2>" + params,
        *[html_figure(out / n, c) for n, c in pngs[1:]],
        f"<p>Channels {', '.join(rep.channels)}; {rep.runtime_s:.1f} s.</p>",
        "<details><summary>The criteria of this fit</summary>" + crit + "</details>"])
