"""``fit`` on this project's synthetic runs from a mismatched spindle (``synth --mismatch``:
the spindle's geometry, films, contacts and friction law drawn away from the spec). Slow: each
case synthesises a 16 h run on FEM level 1 or 2 (15-30 s) and fits it (10-40 s). The rates
over many drawn runs are benchmarks/bench_families.py's; these cases pin a few of them: mounts,
coolant warmings and a clean run of drawn spindles on the random no-load cycle (one mount and
one coolant warming are measured misses, xfail(strict): nothing is named on them). The fast path
(synth with mismatch, the selection) is in tests/test_mismatch.py and tests/test_select.py."""

from __future__ import annotations

import pytest

#: measured misses (python -m pytest -m slow tests/test_mismatch_fit.py, 2026-11-26; on
#: 2026-11-28 seeds 1 and 5 were named and only seed 3 still missed): a mount of 2-5 W/K has no
#: signature test, and on this spindle the open loop does not qualify it (nothing is named);
#: the drawn families' rate is in docs/figures/fit-families.txt ("mount_conduction named alone")
MOUNT_MISSED = pytest.mark.xfail(strict=True, reason="mount not named: open loop does not "
                                 "qualify it on this spindle (docs/fit.md)")
#: and a coolant warming (seed 3; seed 2 named on 2026-11-28), named by the open loop until
#: open_loop_material_change: with the base re-adjusted around it, it moves the prediction by
#: under half a tolerance (nothing is named; the trade is measured in docs/fit.md, "Trades
#: measured")
COOLANT_MISSED = pytest.mark.xfail(strict=True, reason="coolant not named: the fitted "
                                   "prediction moves by under half a tolerance (docs/fit.md)")


@pytest.mark.slow
@pytest.mark.parametrize(("effect", "seed", "named"), [
    # mounts 1 and 5 and the coolant warming 2: missed on 2026-11-26, named on 2026-11-28
    ("mount_conduction", 1, ["mount_conduction"]),
    ("clean", 1, []),
    pytest.param("mount_conduction", 3, ["mount_conduction"], marks=MOUNT_MISSED),
    # passes at d5dcfec^, fails from d5dcfec (the speed of a cell's mean friction; the slow
    # set run whole on 2026-12-01: docs/fit-history.md, 2026-12-01 (23))
    pytest.param("coolant_dynamics", 2, ["coolant_dynamics"], marks=pytest.mark.xfail(
        strict=True, reason="coolant not named since the speed of a cell's mean friction "
        "(d5dcfec)")),
    ("mount_conduction", 5, ["mount_conduction"]),
    pytest.param("coolant_dynamics", 3, ["coolant_dynamics"], marks=COOLANT_MISSED)])
def test_fit_on_a_mismatched_run(tmp_path, effect, seed, named):
    from compare.fit.run import run_fit
    from compare.synth.bench import synth
    from spindle.spec_reader import load_spec

    spec = load_spec("spl2782")
    run = tmp_path / f"{effect}.csv"
    truth = synth(spec, "random", effect, seed, run, mismatch=True)
    doc = run_fit(run, spec).to_dict()
    # the friction's speed exponent is recovered: on the matrix's 54 runs (seeds 1-6) within
    # 0.06 of the drawn one on the clean runs and within 0.093 on every clean, mount and
    # coolant run (docs/fit-history.md, *The friction exponent*); a preload or windage, heats that
    # also rise with speed, trade with it up to 0.19, and those cases are not here
    calibrated = {p["name"]: p["value"] for p in doc["parameters"]}
    assert abs(calibrated["friction_exponent"]
               - truth["mismatch"]["friction_exponent"]) <= 0.1, calibrated
    if seed == 2:  # its 20 min logging gap holds the 3600 -> 2800 rpm change of 21 543 s:
        # placed by the calibrated model within 3 grid steps (the spec's model alone: 243 s
        # early on this cycle; docs/fit-history.md, *Input timing*)
        assert [round(g["speed_after_rpm"]) for g in doc["gap_switches"]] == [2800]
        assert abs(doc["gap_switches"][0]["switch_s"] - 21543.0) <= 180.0
    assert [e["name"] for e in doc["effects"]] == named
    for e in doc["effects"]:
        assert e["route"] in ("signature", "open loop"), e
