"""The pytest plugin of spindle-verify (entry point ``pytest11``): the ``spindle_verify``
fixture, to assert in one line that a model of a spindle stays within a tolerance of the
FEM reference::

    def test_my_spindle(spindle_verify):
        spindle_verify.assert_within("my_spindle.toml", "lumped:11", case="nominal",
                                     tol_temp_K=1.0, tol_growth_um=1.5)

pytest loads this module in every session of an environment where spindle-verify is
installed, so it imports nothing but pytest: the models, and the project's top-level packages
(``compare``, ``spindle``, ...) whose names a user's own project may also use, are imported
only when a test asks for the fixture.
"""

from __future__ import annotations

import pytest


class SpindleVerify:
    """The fixture's object: :func:`spindle_verify.assert_within` and
    :func:`spindle_verify.model_error`, a failure reported as a test failure without a
    traceback into the tool."""

    def error(self, spec: str, model: str, case: str | None = None, reference_level: int = 2,
              dt_s: float = 120.0):
        from spindle_verify import model_error

        return model_error(spec, model, case, reference_level, dt_s)

    def assert_within(self, spec: str, model: str, case: str | None = None,
                      tol_temp_K: float = 1.0, tol_growth_um: float = 1.5,
                      reference_level: int = 2, dt_s: float = 120.0):
        from spindle_verify import assert_within

        try:
            return assert_within(spec, model, case, tol_temp_K, tol_growth_um,
                                 reference_level, dt_s)
        except AssertionError as exc:
            pytest.fail(str(exc), pytrace=False)


@pytest.fixture
def spindle_verify() -> SpindleVerify:
    """Assert that a model of a spindle stays within a tolerance of the FEM reference."""
    return SpindleVerify()
