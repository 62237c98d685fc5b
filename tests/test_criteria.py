"""The criteria table (compare/fit/criteria.toml) as ``Criteria`` reads it, and a user's own
criteria file (``fit --criteria FILE``): values typed as the fields declare them, every
entry with its unit and reason, and bad files refused with the file and the entry named."""

from __future__ import annotations

import fnmatch
import tomllib
import typing
from dataclasses import fields
from pathlib import Path

import pytest

from compare.fit.criteria import Criteria
from compare.fit.signatures import OnsetScale
from spindle.bench_inputs import HOLD_STEPS, SPEED_BAND_REL, SPEED_BAND_RPM
from spindle.errors import InputError

ROOT = Path(__file__).resolve().parents[1]
TABLE = tomllib.loads((ROOT / "compare" / "fit" / "criteria.toml").read_text("utf-8"))


def _is(value, hint) -> bool:
    """Whether ``value`` is of the type ``hint`` (tuples element by element)."""
    if typing.get_origin(hint) is tuple:
        args = typing.get_args(hint)
        kinds = [args[0]] * len(value) if Ellipsis in args else args
        return isinstance(value, tuple) and len(value) == len(kinds) and all(
            _is(v, k) for v, k in zip(value, kinds, strict=True))
    return type(value) is hint


def test_every_entry_of_the_table_is_a_typed_field_with_unit_and_reason():
    crit = Criteria()
    hints = typing.get_type_hints(Criteria)
    assert [f.name for f in fields(crit)] == list(TABLE)  # the table's order is the report's
    for f in fields(crit):
        assert _is(getattr(crit, f.name), hints[f.name]), f.name
        assert f.metadata["unit"] and f.metadata["reason"].strip(), f.name
        assert "\n" not in f.metadata["reason"] and "  " not in f.metadata["reason"], f.name


def test_entries_shared_with_another_module_take_its_value():
    """The table holds no copy of a value another module owns (it would go stale there)."""
    crit = Criteria()
    owned = {"speed_band_rpm": SPEED_BAND_RPM, "speed_band_rel": SPEED_BAND_REL,
             "gap_min_steps": HOLD_STEPS}
    assert {k: getattr(crit, k) for k in owned} == owned
    assert all(("value" in e) == (k not in owned) for k, e in TABLE.items())


def _toml(value) -> str:
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, OnsetScale):
        return "{" + ", ".join(f"{f.name} = {_toml(getattr(value, f.name))}"
                               for f in fields(value)) + "}"
    if isinstance(value, tuple):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return repr(value)


def test_a_file_of_every_entry_reads_back_as_the_table(tmp_path):
    crit = Criteria()
    own = tmp_path / "all.toml"
    own.write_text("".join(f"{f.name} = {_toml(getattr(crit, f.name))}\n"
                           for f in fields(crit)))
    assert crit.with_file(own) == crit


def test_a_copy_of_the_table_edited_sets_the_entries_it_changes(tmp_path):
    shipped = (ROOT / "compare" / "fit" / "criteria.toml").read_text("utf-8")
    own = tmp_path / "copy.toml"
    own.write_text(shipped)
    assert Criteria().with_file(own) == Criteria()
    own.write_text(shipped.replace("[alpha]\nvalue = 0.01", "[alpha]\nvalue = 0.05"))
    assert Criteria().with_file(own) == Criteria().with_options(alpha=0.05)
    own.write_text(shipped.replace('[gap_judge_s]\nvalue = 3600.0\nunit = "s"',
                                   '[gap_judge_s]\nvalue = 60.0\nunit = "min"'))
    with pytest.raises(InputError, match="gap_judge_s.unit: is 'min'"):
        Criteria().with_file(own)


def test_a_users_file_sets_its_entries_and_leaves_the_rest(tmp_path):
    own = tmp_path / "mine.toml"
    own.write_text("alpha = 0.05\nmaterial_peak = 1  # an integer where a float is asked\n"
                   "cv_blocks = 3\nheld_out_misfit_unexplained = false\n"
                   "lag_grid_s = [0, 60, 600]\njump_before_s = [-120.0, -10.0]\n"
                   'onset_scales = [{name = "5 min", before_s = [-300.0, -10.0], '
                   "early_s = [10.0, 150.0], late_s = [150.0, 300.0]}]\n")
    crit = Criteria().with_file(own)
    assert crit.alpha == 0.05 and crit.material_peak == 1.0
    assert type(crit.material_peak) is float and crit.cv_blocks == 3
    assert crit.held_out_misfit_unexplained is False
    assert crit.lag_grid_s == (0.0, 60.0, 600.0) and type(crit.lag_grid_s[1]) is float
    assert crit.jump_before_s == (-120.0, -10.0)
    assert crit.onset_scales == (OnsetScale("5 min", (-300.0, -10.0), (10.0, 150.0),
                                            (150.0, 300.0)),)
    assert crit.cv_gain == Criteria().cv_gain  # not in the file
    # the options of the command line apply over the file
    assert crit.with_options(alpha=0.02, cv_blocks=None).alpha == 0.02
    assert {r["name"]: r["value"] for r in crit.table()}["alpha"] == 0.05


@pytest.mark.parametrize("text, entry, words", [
    ("alfa = 0.05\n", "alfa", "is no criterion"),
    ('alpha = "0.05"\n', "alpha", "not a float"),
    ("alpha = nan\n", "alpha", "not a float"),
    ("cv_blocks = 2.5\n", "cv_blocks", "not an int"),
    ("material_peak = true\n", "material_peak", "not a float"),
    ("held_out_misfit_unexplained = 1\n", "held_out_misfit_unexplained", "not a bool"),
    ("jump_before_s = [-120.0]\n", "jump_before_s", "not an array of 2 values"),
    ("lag_grid_s = 60.0\n", "lag_grid_s", "not an array"),
    ("competitor_masses = [1, 2]\n", "competitor_masses", "not a str"),
    ('onset_scales = [{name = "x", before_s = [-1.0, 0.0]}]\n', "onset_scales",
     "give each of name, before_s, early_s, late_s"),
    ("alpha = \n", "-", "cannot be read as TOML"),
    ("alpha = 0.0\n", "alpha", "outside 0.001..0.5"),  # the table's range, --alpha's bound
    ("cv_gain = 1.5\n", "cv_gain", "outside 0.0..1.0"),
    ("material_peak = -0.5\n", "material_peak", "outside 0..inf"),  # no number is negative
    ("[alpha]\nvalue = 0.7\n", "alpha", "outside 0.001..0.5"),  # in the table's form too
    # values that passed the types and then stopped fit with an internal error (exit 1) or ran
    # on as nonsense (found by fuzzing the command line)
    ("lag_grid_s = []\n", "lag_grid_s", "is an empty array"),  # an IndexError
    ("lag_grid_s = [0.0, -60.0]\n", "lag_grid_s", "outside 0..inf"),
    ("competitor_step_s = 0.0\n", "competitor_step_s", "outside 600.0..14400.0"),  # / 0
    ("competitor_step_s = 0.001\n", "competitor_step_s", "outside"),  # 1.6 TiB asked for
    ("scan_null_tail = 0\n", "scan_null_tail", "outside 1..20"),  # an IndexError
    ("scan_null_tail = 100000000\n", "scan_null_tail", "outside 1..20"),  # 74 GiB
    ('competitor_masses = ["propeller"]\n', "competitor_masses", "unknown role"),  # dropped
    ("competitor_masses = []\n", "competitor_masses", "is an empty array"),
    # a misspelt key of the table's form was shown as a Python dict (fuzzing round 6)
    ("[alpha]\nvalu = 0.05\n", "alpha", "is a table with the keys valu, which an entry"),
    ("jump_before_s = [-10.0, -180.0]\n", "jump_before_s", "does not increase"),
    ('onset_scales = [{name = "x", before_s = [-10.0, -300.0], early_s = [10.0, 120.0], '
     'late_s = [120.0, 360.0]}]\n', "onset_scales", "does not increase"),
    ("min_levels = 4\n", "min_levels", "outside 5..inf"),
    ("refit_nfev = 0\n", "refit_nfev", "outside 1..inf"),
])
def test_a_bad_file_names_the_file_and_the_entry(tmp_path, text, entry, words):
    own = tmp_path / "mine.toml"
    own.write_text(text)
    with pytest.raises(InputError) as err:
        Criteria().with_file(own)
    assert err.value.problem.file == str(own) and err.value.problem.field == entry
    assert words in str(err.value)


def test_fit_refuses_a_bad_criteria_file_with_exit_2_and_no_output(tmp_path):
    from compare.cli import main

    own = tmp_path / "mine.toml"
    own.write_text("alfa = 0.05\n")
    assert main(["fit", str(tmp_path / "run.csv"), "--criteria", str(own), "--out",
                 str(tmp_path / "o"), "--quiet"]) == 2
    assert not (tmp_path / "o").exists()


def test_the_table_is_installed_with_the_package():
    """pip install . copies only the data files pyproject.toml names: each tracked data file
    below a package folder must be named there (tests run from the checkout, where a missing
    one is still found)."""
    import subprocess

    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    data = cfg["tool"]["setuptools"]["package-data"]
    tracked = subprocess.run(["git", "ls-files", "spindle", "meshes", "reference", "lumped",
                              "compare", "spindle_verify"], cwd=ROOT, capture_output=True,
                             text=True, check=True).stdout.split()
    for path in (p for p in tracked if not p.endswith(".py")):
        top, rest = path.split("/", 1)
        assert any(fnmatch.fnmatch(rest, g) for g in data.get(top, [])), path
    assert "fit/criteria.toml" in data["compare"]


def test_one_cross_validation_block_is_refused_wherever_it_is_given(tmp_path, capsys):
    """The table's cv_blocks entry excludes 1 (nothing would be left to fit on): refused by
    the options, by a user's file (naming the file) and by --cv-blocks, with exit 2 before
    any work; 0 and 2 pass."""
    from compare.cli import main

    with pytest.raises(InputError, match="cv_blocks: is 1: one block leaves nothing to fit on"):
        Criteria().with_options(cv_blocks=1)
    own = tmp_path / "mine.toml"
    own.write_text("cv_blocks = 1\n")
    with pytest.raises(InputError) as err:
        Criteria().with_file(own)
    assert (err.value.problem.file, err.value.problem.field) == (str(own), "cv_blocks")
    assert [Criteria().with_options(cv_blocks=n).cv_blocks for n in (0, 2)] == [0, 2]
    out = tmp_path / "o"
    for args in (["--cv-blocks", "1"], ["--criteria", str(own)]):
        assert main(["fit", str(tmp_path / "run.csv"), *args, "--out", str(out)]) == 2
        assert "one block leaves nothing to fit on" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("entry, value", [("alpha", 0.0005), ("alpha", 0.6), ("cv_gain", -0.1),
                                          ("cv_blocks", 21), ("material_peak", -1.0)])
def test_options_outside_the_range_are_refused_as_in_a_file(entry, value):
    """with_options (run_fit's alpha, min_gain, cv_blocks) checks the table's range as
    with_file does: a level of 0.0005 would cost 10 / alpha - 1 = 19,999 scan draws a test."""
    with pytest.raises(InputError) as err:
        Criteria().with_options(**{entry: value})
    assert err.value.problem.field == entry and "outside" in str(err.value)


@pytest.mark.parametrize("option, entry, percent", [("--alpha", "alpha", False),
                                                     ("--min-gain", "cv_gain", True),
                                                     ("--cv-blocks", "cv_blocks", False)])
def test_the_options_take_the_range_of_the_table(tmp_path, capsys, option, entry, percent):
    """fit's --alpha, --min-gain (a share in %) and --cv-blocks accept the ends of their
    entry's range and refuse what lies beyond, with exit 2 before any work."""
    from compare.cli import main

    lo, hi = Criteria.range_of(entry)
    k = 100.0 if percent else 1.0
    out = tmp_path / "o"
    for v in (lo * k - (1 if entry == "cv_blocks" else 1e-4 * k), hi * k + 1):
        assert main(["fit", str(tmp_path / "run.csv"), option, f"{v:g}", "--out",
                     str(out)]) == 2
        assert option in capsys.readouterr().err
    assert not out.exists()
    for v in (lo * k, hi * k):
        text = f"{int(v)}" if entry == "cv_blocks" else f"{v:g}"
        # accepted by the option; the missing run then stops the fit (exit 2, named)
        assert main(["fit", str(tmp_path / "run.csv"), option, text, "--out", str(out),
                     "--quiet"]) == 2
        assert "run.csv" in capsys.readouterr().err


def test_a_file_with_a_byte_order_mark_reads_as_without(tmp_path):
    """Some editors start a file with a UTF-8 byte-order mark; the spec and cycle readers
    dropped it, the criteria file read it as a "syntax" error on line 1 (found by fuzzing)."""
    own = tmp_path / "bom.toml"
    own.write_text("\ufeffalpha = 0.05\n", encoding="utf-8")
    assert Criteria().with_file(own) == Criteria().with_options(alpha=0.05)
