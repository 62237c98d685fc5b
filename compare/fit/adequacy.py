"""Verdicts on the calibrated base model before any effect is named (docs/fit-history.md,
issue 13 §4-5).

- :func:`base_adequacy`: how well the calibrated base model alone explains the run (open-loop
  RMS per channel against the paper's tolerances, 1 K and 1.5 µm), which base parameters
  moved where (in prior standard deviations from the spec's values), and, where it falls
  short, a plain statement: which channel, by how much, and what in the spec to look at.
- :func:`extrapolation_warnings`: operating points of the validation window that the fit
  window never saw, so a validation error there is an extrapolation, not a check.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from compare.fit.calibrate import over_tolerance

#: conductances the spec does not have (base extras whose spec value is 0): the run is said
#: to need one above Criteria.missing_path_W_K
MISSING_PATHS = ("G_seat_W_K",)

#: where in the spec (or drive file) each base parameter lives: what to look at when the
#: calibration drives it out of its prior range
WHERE_IN_SPEC = {
    "f0": "the bearing friction factor f0 in the drive file ([bearings.*] f0)",
    "friction_exponent": "the speed dependence of the bearing friction (the drive file's "
                         "bearing sets: viscosity, pitch diameter, lubrication)",
    "rotor_share": "the rotor's share of the motor losses in the drive file "
                   "([motor] rotor_loss_share)",
    "h_coolant": "the coolant-jacket films (surfaces with T_ref = \"coolant\": the flow, the "
                 "channel's hydraulic diameter, the correlation)",
    "h_air": "the housing's films to the ambient air (surfaces with T_ref = \"ambient\" on the "
             "housing)",
    "h_rotating": "the rotating surfaces' film correlation (shaft and tool surfaces, "
                  "correlation d_m)",
    "contact": "the fitted-joint contact conductances ([[links]] kind = \"contact\", h_W_m2K)",
    "stator_contact": "the stator's contact to the cooling sleeve ([[links]] kind = \"contact\" "
                      "with the stator, h_W_m2K) and the winding's conduction to the core "
                      "(the stator's k_W_mK)",
    "alpha_eff": "the expansion coefficients of the growth chain's materials (alpha_1_K) and "
                 "the P1 sensor's position",
    "G_seat_W_K": "the cooling of the bearing seats: the spec's coolant films end at the "
                  "cooling sleeve, and this run's bearing rings follow the coolant more "
                  "closely than conduction through the housing allows (a coolant channel or "
                  "film at the bearing bores: surfaces with T_ref = \"coolant\" there)",
    "heat_capacity": "the parts' volumes and materials (rho_kg_m3, c_J_kgK): the thermal mass "
                     "that takes part on the run's time scales",
    "axial_scale": "the axial dimensions (the parts' sections z_start_m / z_end_m, the "
                   "surfaces' z limits, the sensors' z): bearing spacing, motor and housing "
                   "lengths",
}


def base_adequacy(errors: Mapping[str, Mapping[str, Mapping[str, float]]],
                  theta: Mapping[str, float], spec_values: Mapping[str, float],
                  prior_z: Mapping[str, float] | None,
                  bounds: Mapping[str, tuple[float, float]] | None = None,
                  criteria=None,
                  partners: Mapping[str, tuple[str, float]] | None = None) -> dict:
    """The base-adequacy verdict of a calibrated base model.

    ``errors``: :meth:`compare.fit.calibrate.Calibrator.errors` of the base fit (per window
    and channel, with ``rmse_w``, the RMS in units of the channel's tolerance); ``theta`` its
    parameters; ``spec_values`` the spec's values (prior centres); ``prior_z`` the parameters'
    distances from them in prior standard deviations (empty without priors); ``bounds`` the
    parameters' ranges (lo, hi), to say which ran to a bound (a bound that is the spec's own
    value is no advice: a path the spec lacks calibrated to nothing); ``criteria``
    (compare.fit.criteria.Criteria; default the defaults) gives the plausible range (at its
    alpha), the bound's width and the least missing conductance; ``partners``
    (:attr:`compare.fit.calibrate.Fit.partners`) the parameter each one the run does not
    determine alone moves with: its advice names the pair, since the run pushed the two
    together and either may be the one that is off.

    Returns ``{"adequate": bool, "channels": {c: {window: rmse_w}}, "inadequate_channels":
    [...], "moved": [{name, spec, calibrated, z}], "implausible": [...], "at_bound": [...],
    "missing_paths": [...], "statement": str}``. A parameter on a bound of its range that is
    not implausible (a range inside the prior's 1 % tails, as axial_scale's) is said, not
    judged: the run asked for more than the range allows, or the freedom took up another
    misfit.
    A channel is inadequate when its open-loop RMS exceeds its tolerance on either window.
    The statement is a clause to follow a subject ("the base model ...").
    """
    from compare.fit.criteria import Criteria

    criteria = criteria or Criteria()
    z_crit = criteria.implausible_z()
    channels: dict[str, dict[str, float]] = {}
    worst: dict[str, tuple[str, float]] = {}  # each channel's largest miss: window, rmse_w
    for window in ("fit", "validation"):
        for c, e in errors.get(window, {}).items():
            if e.get("n"):
                channels.setdefault(c, {})[window] = float(e["rmse_w"])
        for c, r in over_tolerance(errors.get(window, {})).items():
            if r > worst.get(c, ("", 0.0))[1]:
                worst[c] = (window, r)
    z = dict(prior_z or {})
    moved = [{"name": k, "spec": float(spec_values[k]), "calibrated": float(theta[k]),
              "z": float(z[k]) if k in z else None}
             for k in spec_values if k in theta]
    implausible = sorted((k for k, v in z.items() if abs(v) > z_crit), key=lambda k: -abs(z[k]))
    # paths the spec lacks (no prior: the spec's value is 0) that the run needed
    missing = [k for k in MISSING_PATHS
               if k in theta and float(theta[k]) > criteria.missing_path_W_K]
    at_bound = []
    for k, (lo, hi) in (bounds or {}).items():
        if k in theta and k not in implausible and k in spec_values:
            tol = criteria.at_bound_rel * (hi - lo)
            v, spec = float(theta[k]), float(spec_values[k])
            on_lo, on_hi = v <= lo + tol, v >= hi - tol
            # a bound that is the spec's own value (a conductance the spec lacks, at 0) is
            # where the calibration says "not needed": no advice
            if (on_lo and abs(spec - lo) > tol) or (on_hi and abs(spec - hi) > tol):
                at_bound.append(k)

    def where(k: str, default: str) -> str:
        text = WHERE_IN_SPEC.get(k, default)
        if k in (partners or {}):
            other, r = partners[k]
            said = other in (*implausible, *at_bound, *missing)  # its own advice follows
            text += (f"; this run does not determine {k} alone but together with {other} "
                     f"(correlation {r:+.2f})"
                     + (f": look at {WHERE_IN_SPEC[other]} too"
                        if other in WHERE_IN_SPEC and not said else ""))
        return text

    parts = []
    if worst:
        parts.append("misses " + "; ".join(
            f"{c} by {r:.1f} times its tolerance (open-loop RMS, {w} window)"
            for c, (w, r) in sorted(worst.items(), key=lambda kv: -kv[1][1])))
    if implausible:  # after a miss, a clause of its own: "...; it needs ..."
        parts.append(("it " if parts else "") + "needs implausible values to fit the run: "
                     + "; ".join(  # no parentheses around the advice: it has its own
                         f"{k} {theta[k]:.3g}, {z[k]:+.1f} prior sd from the spec's "
                         f"{spec_values[k]:.3g}: look at {where(k, 'its value in the spec')}"
                         for k in implausible))
    adequate = not worst and not implausible
    statement = ("explains the run within the tolerances with every base parameter inside its "
                 "prior range" if adequate else "; ".join(parts))
    if at_bound:
        statement += ("; " + "; ".join(
            f"{k} ran to the bound of its range ({theta[k]:.3g}, spec {spec_values[k]:.3g}): "
            f"look at {where(k, 'its value in the spec')}" for k in at_bound))
    if missing:  # the calibrated base has it; the spec does not: say so either way
        statement += ("; it needed a path the spec lacks: " + "; ".join(
            f"{k} = {theta[k]:.3g} (spec 0): look at {where(k, 'the spec')}"
            for k in missing))
    return {"adequate": adequate, "channels": channels,
            "inadequate_channels": sorted(worst), "moved": moved,
            "implausible": implausible, "at_bound": at_bound, "missing_paths": missing,
            "statement": statement}


def extrapolation_warnings(grid_s: np.ndarray, speed_rpm: np.ndarray,
                           load_torque_Nm: np.ndarray, in_fit: np.ndarray,
                           rel: float = 0.05) -> list[str]:
    """Operating points of the validation window (grid points where ``in_fit`` is False,
    compare.fit.calibrate.Measured.fit_points) outside what the
    fit window saw: speeds [rpm] or load torques [N m] beyond the fit window's largest by more
    than ``rel``, or speed levels the fit window never held (none within ``rel``). Per
    interval arrays, ``grid_s`` its edges."""
    fit = np.asarray(in_fit, dtype=bool)[:len(grid_s) - 1]
    val = ~fit
    out = []
    for name, x, unit in (("speed", np.asarray(speed_rpm), "rpm"),
                          ("load torque", np.asarray(load_torque_Nm), "N m")):
        if not val.any() or not fit.any():
            continue
        top_fit, top_val = float(np.max(x[fit])), float(np.max(x[val]))
        if top_val > (1.0 + rel) * top_fit + 1e-9:
            out.append(f"the validation window reaches {name} {top_val:.0f} {unit}, above the "
                       f"fit window's {top_fit:.0f} {unit}: the validation error there is an "
                       "extrapolation")
    levels_fit = np.unique(np.round(speed_rpm[fit]))
    unseen = sorted({float(v) for v in np.unique(np.round(speed_rpm[val]))
                     if v > 0 and not np.any(np.abs(levels_fit - v) <= rel * v)})
    if unseen:
        share = float(np.mean([np.any(np.abs(np.array(unseen) - v) <= 0.5)
                               for v in np.round(speed_rpm[val])]))
        out.append("speeds " + ", ".join(f"{v:.0f}" for v in unseen) + " rpm hold "
                   f"{100 * share:.0f} % of the validation window and never occur in the fit "
                   "window")
    return out
