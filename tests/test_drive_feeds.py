"""A spec's heat sources and its drive's power balance name the same sources
(spindle.drive.check_drive_feeds), in `fit` as in `solve`. Found by fuzzing round 6: a spec
whose stator source was renamed fitted with the stator's watts lost (T_stator 91 K off and
an effect named), and a drive file without the rear bearing set ended `fit` in an internal
error."""

import numpy as np
import pytest

from compare.cli import main
from compare.fit.effects.preload import ring_drag_W
from compare.fit.greybox import GreyBox
from compare.fit.params import default_theta
from spindle.bench_inputs import Inputs
from spindle.drive import check_drive_feeds, drive_for
from spindle.errors import InputError
from spindle.spec_reader import load_spec
from tests.test_bench import PEER_RUNS

SHIPPED = load_spec("spl2782")


def _spec_with(tmp_path, old: str, new: str, drive: str | None = None):
    """The shipped spec with its first ``old`` replaced by ``new`` and, where given, its
    drive a copy of the shipped drive file without the table ``drive``."""
    text = open(SHIPPED.path).read()
    assert old in text
    text = text.replace(old, new, 1)
    if drive is not None:
        src = open(SHIPPED.path.replace("specs", "drives")).read()
        head, _, rest = src.partition(f"[{drive}]")
        assert rest, drive
        tail = rest[rest.index("\n["):] if "\n[" in rest else ""
        (tmp_path / "mine.drive.toml").write_text(head + tail.lstrip("\n"))
        text = text.replace('preset = "spl2782"', 'preset = "mine.drive.toml"', 1)
        assert "mine.drive.toml" in text
    path = tmp_path / "mine.toml"
    path.write_text(text)
    return load_spec(str(path))


def test_the_shipped_spec_and_drive_agree():
    assert check_drive_feeds(SHIPPED, drive_for(SHIPPED)) == []


def test_a_source_the_drive_feeds_and_the_spec_lacks_is_refused_by_fit(tmp_path, capsys):
    """The watts of a source the spec does not have would heat nothing: `fit` refuses the
    spec, before any fitting, as `solve` does (exit 2, nothing written)."""
    spec = _spec_with(tmp_path, '[[heat_sources]]\nname = "stator"',
                      '[[heat_sources]]\nname = "stator_winding"')
    with pytest.raises(InputError, match=r"feeds sources \['stator'\]"):
        check_drive_feeds(spec, drive_for(spec))
    run = PEER_RUNS / "bench-runs" / "dev-01.csv"
    out = tmp_path / "o"
    assert main(["fit", str(run), "--spec", spec.path, "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{spec.path}: heat_sources:" in err
    # the spec's source the drive does not feed is named, and the fix points at both files
    assert "(the spec's ['stator_winding'] get nothing)" in err.split("fix")[0]
    assert "fix: name the drive file's sets ([bearings.NAME]) as the spec's heat sources" in err
    assert "or the spec's heat sources stator, rotor" in err
    assert "Traceback" not in err and not out.exists()


def test_a_bearing_the_drive_does_not_feed_gets_no_heat_and_no_drag(tmp_path):
    """A drive file without the rear bearing set: the spec's rear_bearing source gets 0 W
    (said by `fit` as a warning) and the preload's ring drag, which is the bearing's heat
    times its rings' difference, has no term for it (it raised KeyError)."""
    spec = _spec_with(tmp_path, "#", "#", drive="bearings.rear_bearing")
    drive = drive_for(spec)
    assert check_drive_feeds(spec, drive) == ["rear_bearing"]
    n = 60
    inputs = Inputs(np.arange(0.0, 60.0 * n + 1.0, 60.0), np.full(n, 4000.0),
                    np.full(n, 2.0), np.zeros(n), np.full(n, 293.15), np.full(n, 291.15))
    gb = GreyBox(spec, drive, inputs)
    drag = ring_drag_W(gb, default_theta(gb.parameters()))
    assert list(drag) == ["front_bearing"] and np.all(np.isfinite(drag["front_bearing"]))
