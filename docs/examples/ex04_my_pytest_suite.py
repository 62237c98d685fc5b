"""Guard a thermal model in your own pytest suite.

    python -m pytest docs/examples/ex04_my_pytest_suite.py

The ``spindle_verify`` fixture comes with the package (a pytest plugin). ``assert_within``
solves the model and the FEM reference on the case and fails with the worst sensor and the
error sizes when the model leaves the tolerance; ``error`` returns the errors without
asserting. Models: ``"lumped:N"``, ``"lumped:paper11"`` or ``"fem:L"``; cases: a shipped
cycle name (``nominal`` is steady) or None for the spec's own load case.
"""


def test_fine_fem_level_matches_the_reference(spindle_verify):
    # level 1 against the reference level 2 on the fin benchmark: a mesh-convergence guard
    spindle_verify.assert_within("fin-shaft", "fem:1", tol_temp_K=0.05, tol_growth_um=0.05)


def test_the_paper_5_node_model_misses_the_fin_by_kelvins(spindle_verify):
    # eq. 14's benchmark: 5 masses are several kelvin off (docs/lumped.md), 11 are closer
    five = spindle_verify.error("fin-shaft", "lumped:paper5")
    eleven = spindle_verify.error("fin-shaft", "lumped:paper11")
    assert eleven.worst_temp_K < five.worst_temp_K
