"""``fit`` on this project's synthetic runs from a mismatched spindle (issue 13 §2; the
matrix is benchmarks/bench_mismatch.py, 27 runs, docs/fit.md "The mismatch matrix"). Slow:
each case synthesises a 16 h run on FEM level 1 or 2 (15-30 s) and fits it (10-25 s).

Cases on the random no-load cycle: seed 1's mount, which the plausibility rule of the
cross-validation guard was changed for (compare.fit.calibrate.cv_gain_asked; before it the
run was left unnamed), and the clean run of the same spindle, where nothing may be named;
seed 3's mount and seed 2's coolant warming, named only since the base calibrates the axial
scale (compare.fit.greybox, axial_scale: these spindles are 12-15 % longer than the spec,
and without it the jacket film went to its bound and took the effects up); seed 5's mount
and seed 3's coolant warming, named only since the base calibrates the bearing friction's
speed exponent (seed 5's friction falls with speed, exponent -0.26, and without it the air
and rotating films took it up; docs/fit.md, *The friction exponent*).
The fast path (synth with mismatch, the rule itself) is in tests/test_mismatch.py and
tests/test_greybox.py."""

from __future__ import annotations

import pytest


@pytest.mark.slow
@pytest.mark.parametrize(("effect", "seed", "named"), [
    ("mount_conduction", 1, ["mount_conduction"]), ("clean", 1, []),
    ("mount_conduction", 3, ["mount_conduction"]), ("coolant_dynamics", 2, ["coolant_dynamics"]),
    ("mount_conduction", 5, ["mount_conduction"]), ("coolant_dynamics", 3, ["coolant_dynamics"])])
def test_fit_on_a_mismatched_run(tmp_path, effect, seed, named):
    from compare.fit.run import run_fit
    from compare.fit.synth import synth
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    run = tmp_path / f"{effect}.csv"
    truth = synth(spec, "random", effect, seed, run, mismatch=True)
    doc = run_fit(run, spec).to_dict()
    # the friction's speed exponent is recovered: on the matrix's 54 runs (seeds 1-6) within
    # 0.06 of the drawn one on the clean runs and within 0.093 on every clean, mount and
    # coolant run (docs/fit.md, *The friction exponent*); a preload or windage, heats that
    # also rise with speed, trade with it up to 0.19, and those cases are not here
    calibrated = {p["name"]: p["value"] for p in doc["parameters"]}
    assert abs(calibrated["friction_exponent"]
               - truth["mismatch"]["friction_exponent"]) <= 0.1, calibrated
    if seed == 2:  # its 20 min logging gap holds the 3600 -> 2800 rpm change of 21 543 s:
        # placed by the calibrated model within 3 grid steps (the spec's model alone: 243 s
        # early on this cycle; docs/fit.md, *Input timing*)
        assert [round(g["speed_after_rpm"]) for g in doc["gap_switches"]] == [2800]
        assert abs(doc["gap_switches"][0]["switch_s"] - 21543.0) <= 180.0
    assert [e["name"] for e in doc["effects"]] == named
    for e in doc["effects"]:
        assert e["p_value"] < doc["alpha"] and e["needed_by"]
