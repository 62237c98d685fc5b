"""``fit`` on this project's synthetic runs from a mismatched spindle (issue 13 §2; the
matrix is benchmarks/bench_mismatch.py, 27 runs, docs/fit.md "The mismatch matrix"). Slow:
each case synthesises a 16 h run on FEM level 1 or 2 (15-30 s) and fits it (10-25 s).

Two cases of seed 1 on the random no-load cycle: the mount the plausibility rule of the
cross-validation guard was changed for (compare.fit.calibrate.cv_gain_asked; before it the
run was left unnamed) and the clean run of the same spindle, where nothing may be named.
The fast path (synth with mismatch, the rule itself) is in tests/test_mismatch.py and
tests/test_greybox.py."""

from __future__ import annotations

import pytest


@pytest.mark.slow
@pytest.mark.parametrize(("effect", "named"), [("mount_conduction", ["mount_conduction"]),
                                                ("clean", [])])
def test_fit_on_a_mismatched_run(tmp_path, effect, named):
    from compare.fit.run import run_fit
    from compare.fit.synth import synth
    from spindle.spec import load_spec

    spec = load_spec("spl2782")
    run = tmp_path / f"{effect}.csv"
    synth(spec, "random", effect, 1, run, mismatch=True)
    doc = run_fit(run, spec).to_dict()
    assert [e["name"] for e in doc["effects"]] == named
    for e in doc["effects"]:
        assert e["p_value"] < doc["alpha"] and e["needed_by"]
