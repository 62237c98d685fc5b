"""Shared helpers: small specs written on the fly, and solution-error measures."""

from __future__ import annotations

# first, before numpy loads: one BLAS thread, as the spindle-verify command runs (see
# compare/entry.py), so that the tests compute what the command computes, and two test workers
# on two cores do not each start two BLAS threads (on 2 cores the default run took 3:08 with one
# thread per worker and 5:43 with two; docs/verification.md, "Running the tests")
import compare.entry  # noqa: F401

# isort: split
import textwrap
from pathlib import Path

import numpy as np
import pytest
from skfem import Functional

from spindle.spec_reader import load_spec

MATERIALS = """
[materials.mat_a]
k_r_W_mK = 1.0
k_z_W_mK = 2.0
rho_kg_m3 = 1000.0
c_J_kgK = 500.0
E_Pa = 1e9
nu = 0.3
alpha_1_K = 1e-5

[materials.mat_b]
k_r_W_mK = 3.0
k_z_W_mK = 6.0
rho_kg_m3 = 2000.0
c_J_kgK = 400.0
E_Pa = 1e9
nu = 0.3
alpha_1_K = 1e-5
"""


def write_spec(tmp_path: Path, body: str, name: str = "case") -> Path:
    """Write a spec file with a [spindle] head and the two test materials."""
    path = tmp_path / f"{name}.toml"
    head = f'[spindle]\nname = "{name}"\n\n[operating]\nT_ambient_K = 300.0\n'
    path.write_text(head + MATERIALS + textwrap.dedent(body), encoding="utf-8")
    return path


@pytest.fixture
def spec_from(tmp_path):
    def make(body: str, name: str = "case"):
        return load_spec(write_spec(tmp_path, body, name))

    return make


@Functional
def _l2_sq(w):
    return (w.uh - w.exact) ** 2 * w.x[1]


def l2_error(model, T: np.ndarray, exact) -> float:
    """sqrt(int (T_h - T)^2 r dA) with the exact solution at the quadrature points."""
    b = model.quadrature_basis()
    return float(np.sqrt(_l2_sq.assemble(b, uh=b.interpolate(T),
                                         exact=exact(*np.asarray(b.global_coordinates())))))


def observed_order(h: list[float], err: list[float]) -> float:
    """Least-squares slope of log(err) against log(h)."""
    return float(np.polyfit(np.log(h), np.log(err), 1)[0])
