"""spindle-verify: how far can you trust a thermal model of a machine-tool motor spindle?

The public API under one name. Temperatures are in K and lengths in m inside; results print
and summarise in °C and µm. ``spec`` is a shipped spec's name (``"spl2782"``,
``"fin-shaft"``), the path of a spec TOML or a loaded :class:`spindle.spec.Spec`; ``case`` a
cycle's name or file (``"nominal"``, ``"spl-16h"``, a cycle TOML or CSV), a
:class:`spindle.loads.LoadCase`, or None for the spec's own steady case.

- :func:`solve`: the FEM reference or a lumped model, steady or over a cycle;
- :func:`reference_model`, :func:`lumped_model`: the models themselves;
- :func:`study`: the verification study (grid convergence, accuracy against unknowns);
- :func:`fit`: a test-bench run: calibrate, and find the effect the model lacks
  (``report.save(folder)``); :func:`synth`: a synthetic bench run with effects of your
  choice; :func:`register_effect`: an effect of your own (a subclass of :class:`Effect`
  with :class:`Param` parameters) for ``fit`` and ``synth`` to consider;
- :func:`model_error`, :func:`assert_within`: one model against the reference, for tests
  (the pytest fixture ``spindle_verify`` calls them: spindle_verify.pytest_plugin).

Everything is imported when first used, so ``import spindle_verify`` is quick.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the types, for readers and type checkers; imported lazily at run time
    from compare.fit.run import FitReport
    from compare.verify.study import StudyResult
    from compare.verify.within import Verdict
    from lumped.simulation import LumpedModel
    from reference.simulation import ReferenceModel

__all__ = ["Effect", "FitReport", "LumpedModel", "Param", "ReferenceModel", "StudyResult",
           "TimeSeries", "Verdict", "__version__", "assert_within", "fit", "lumped_model",
           "model_error", "reference_model", "register_effect", "solve", "study", "synth",
           "unregister_effect"]

_TYPES = {"FitReport": "compare.fit.run", "StudyResult": "compare.verify.study",
          "Verdict": "compare.verify.within", "LumpedModel": "lumped.simulation",
          "ReferenceModel": "reference.simulation", "Effect": "compare.fit.effects",
          "Param": "compare.fit.params", "TimeSeries": "spindle.loads"}


def __getattr__(name: str) -> Any:
    if name in _TYPES:
        import importlib

        return getattr(importlib.import_module(_TYPES[name]), name)
    if name == "__version__":
        from compare.cli import package_version

        return package_version()
    raise AttributeError(f"module 'spindle_verify' has no attribute '{name}'")


def reference_model(spec, level: int = 2, order: int = 2, centrifugal: bool = False
                    ) -> ReferenceModel:
    """The FEM reference of ``spec`` on mesh ``level`` (0 coarsest; each level halves the
    edges) with P``order`` elements; ``centrifugal`` adds the rotating parts' body force."""
    from reference.simulation import ReferenceModel

    return ReferenceModel(spec, level, order, centrifugal)


def lumped_model(spec, nodes: int | str = 11, **options) -> LumpedModel:
    """The paper's function-block model of ``spec`` with ``nodes`` masses along shaft and
    housing (an integer >= 2, or "paper5" / "paper11"); ``options`` as
    :class:`lumped.simulation.LumpedModel`."""
    from lumped.simulation import LumpedModel

    return LumpedModel(spec, nodes, **options)


def solve(spec, case=None, dt_s: float | None = None, model: str = "fem:2"):
    """``model`` (``"fem:L"``, the reference at level L, or ``"lumped:N"``) on ``case``:
    its steady state when ``dt_s`` is None, else the transient over the case read every
    ``dt_s`` [s] (backward Euler for the FEM, the exact zero-order hold for a lumped model).
    Returns the result object (``.summary()``, ``.to_pandas()``, ``.plot()``, ``.save()``)."""
    from spindle.arguments import model_choice

    kind, size = model_choice(model)
    m = reference_model(spec, size) if kind == "fem" else lumped_model(spec, size)
    return m.steady(case) if dt_s is None else m.transient(case, dt_s)


def study(spec, **options) -> StudyResult:
    """The verification study of ``spec`` (what ``spindle-verify study`` runs; options as
    :func:`compare.verify.study.run_study`: ``levels``, ``nodes``, ``dt_s``, ``transient``,
    ``workers``, ``rom`` ...). Returns the result (``.summary()``, ``.verdicts()``,
    ``.save(folder)``)."""
    from compare.verify.study import run_study
    from spindle.spec_reader import as_spec

    return run_study(as_spec(spec), **options)


def fit(run: str | Path, spec="spl2782", **options) -> FitReport:
    """A test-bench run (CSV in the bench format, docs/bench.md) fitted with ``spec``: the
    calibrated model, the effect it lacks or "unexplained", and the validation error before
    and after (what ``spindle-verify fit`` runs; options as :func:`compare.fit.run.run_fit`)."""
    from compare.fit.run import run_fit
    from spindle.spec_reader import as_spec

    return run_fit(run, as_spec(spec), **options)


def synth(spec, cycle: str, effect, seed: int, out_csv: str | Path, **options) -> dict:
    """A synthetic bench run of ``spec`` over ``cycle``: the FEM reference with ``effect``
    (an effect's name, several in a list, ``"clean"``, or a cause outside the library) of a
    size drawn from ``seed``, written as a bench CSV to ``out_csv`` with its truth beside it
    (``RUN.truth.json``; ``fit`` never reads it). Returns the truth. Options as
    :func:`compare.synth.bench.synth` (``level``, ``dt_s``, ``mismatch``)."""
    from compare.synth.bench import synth as make
    from spindle.arguments import whole_number
    from spindle.spec_reader import as_spec

    return make(as_spec(spec), cycle, effect, whole_number(seed, "seed", 0), Path(out_csv),
                **options)


def register_effect(effect) -> None:
    """Add an effect of your own (an :class:`Effect` instance) to the library that ``fit``
    and ``synth`` use (docs/examples/ex05_own_effect.py)."""
    from compare.fit.effects import register

    register(effect)


def unregister_effect(name: str) -> None:
    """Remove the effect ``name`` from the library."""
    from compare.fit.effects import unregister

    unregister(name)


def model_error(spec, model: str, case: str | None = None, reference_level: int = 2,
                dt_s: float = 120.0) -> Verdict:
    """``model`` (``"lumped:N"`` or ``"fem:L"``) against the FEM at ``reference_level`` on
    ``case`` (None: the spec's own steady case; ``"nominal"`` steady; another cycle a
    transient read every ``dt_s`` [s]): the worst temperature error [K] and the P1 error
    [µm]."""
    from compare.verify.within import model_error as error

    return error(spec, model, case, reference_level, dt_s)


def assert_within(spec, model: str, case: str | None = None, tol_temp_K: float = 1.0,
                  tol_growth_um: float = 1.5, reference_level: int = 2,
                  dt_s: float = 120.0) -> Verdict:
    """:func:`model_error`, raising ``AssertionError`` with a readable message when the
    temperature error exceeds ``tol_temp_K`` [K] or the P1 error ``tol_growth_um`` [µm]
    (the paper's tolerances by default); returns the errors when within."""
    from compare.verify.within import assert_within as within

    return within(spec, model, case, tol_temp_K, tol_growth_um, reference_level, dt_s)
