"""Exact time steps of the linear heat equation on large sparse meshes (issue 15 §1).

Over one step [t0, t0 + h] at one speed, with the load linear in time::

    M x' = -K x + a + b (t - t0)

(M the capacity, K the conductance, both symmetric positive definite), the solution is::

    x_p(t) = K^-1 (a + b (t - t0)) - K^-1 M K^-1 b           (a particular solution)
    x(t0 + h) = x_p(t0 + h) + exp(-h M^-1 K) (x(t0) - x_p(t0))

The particular part takes a real sparse LU of K. The exponential's action is Chebyshev
rational approximation (CRAM, order 16) in the incomplete partial factorisation form of
M. Pusa, "Higher-Order Chebyshev Rational Approximation Method and Application to Burnup
Equations", Nucl. Sci. Eng. 182(3) 297-318 (2016)::

    exp(A) w ~ alpha0 prod_k (I + 2 Re alpha_k (A - theta_k I)^-1) w,  A = -h M^-1 K,

with (A - theta I)^-1 y = -(h K + theta M)^-1 M y: one complex sparse LU per pole, speed
and step length. A is self-adjoint in the M inner product with its spectrum on the
negative real axis, where the order-16 approximation's uniform error is alpha0 = 2.1e-16
(the best approximation equioscillates out to -infinity, where it equals alpha0), 2e-15
with the rounding of its evaluation (CRAM16_ERROR). Hence, per application, ||error||_M
<= CRAM16_ERROR ||w||_M, and a read-out c . x is off by at most sqrt(c M^-1 c)
CRAM16_ERROR sum ||w||_M over the applications (exp(-h M^-1 K) is a contraction in that
norm, so no error grows later): :attr:`ExactStepper.bound`. The rounding of the sparse
solves is outside that bound; tests/test_time_convergence.py measures it against the dense
modal integration (1e-10 to 1e-9 K on a 137 K rise).
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

# CRAM order 16, incomplete partial factorisation form: Pusa (2016), Table; the values as
# published and as hard-coded in OpenMC, openmc/deplete/cram.py (c16_alpha, c16_theta,
# c16_alpha0)
CRAM16_ALPHA = np.array([
    +5.464930576870210e+3 - 3.797983575308356e+4j,
    +9.045112476907548e+1 - 1.115537522430261e+3j,
    +2.344818070467641e+2 - 4.228020157070496e+2j,
    +9.453304067358312e+1 - 2.951294291446048e+2j,
    +7.283792954673409e+2 - 1.205646080220011e+5j,
    +3.648229059594851e+1 - 1.155509621409682e+2j,
    +2.547321630156819e+1 - 2.639500283021502e+1j,
    +2.394538338734709e+1 - 5.650522971778156e+0j])
CRAM16_THETA = np.array([
    +3.509103608414918 + 8.436198985884374j,
    +5.948152268951177 + 3.587457362018322j,
    -5.264971343442647 + 16.22022147316793j,
    +1.419375897185666 + 10.92536348449672j,
    +6.416177699099435 + 1.194122393370139j,
    +4.993174737717997 + 5.996881713603942j,
    -1.413928462488886 + 13.49772569889275j,
    -10.84391707869699 + 19.27744616718165j])
CRAM16_ALPHA0 = 2.124853710495224e-16
#: max |r(x) - exp(x)| for x <= 0 as evaluated in double precision: the approximation's
#: own uniform error alpha0 = 2.1e-16 and the rounding of the product form, measured at
#: 1.3e-15 near x = 0 (tests/test_time_convergence.py)
CRAM16_ERROR = 2.0e-15


def cram16(x: np.ndarray) -> np.ndarray:
    """The scalar CRAM-16 approximation r(x) of exp(x), for checking it (x <= 0)."""
    y = np.ones_like(np.asarray(x, dtype=float), dtype=complex)
    for alpha, theta in zip(CRAM16_ALPHA, CRAM16_THETA, strict=True):
        y = y + 2.0 * np.real(alpha / (x - theta)) * y
    return CRAM16_ALPHA0 * np.real(y)


def _complex_lu(A: sp.spmatrix):
    """LU of h K + theta M: complex symmetric with a positive definite imaginary part
    (Im theta M, Im theta > 0), so no principal minor vanishes and no pivoting is needed."""
    return splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                options={"SymmetricMode": True})


class ExactStepper:
    """Exact steps at one speed of M x' = -K x + a + b (t - t0) (see the module docstring).

    ``lu_K`` is the (real) LU of K. The eight complex LUs of one step length make a set; at
    most ``max_sets`` sets are kept (least recently used dropped: a set of spl2782 level 2 is
    about 450 MB). A step whose length is a whole multiple q <= ``max_substeps`` of a kept
    set's is taken as q exact sub-steps instead of a new set (the 1, 2, 4 ... s steps after
    each jump reuse the 1 s set). A ``regular`` length (the many steps of dt, and e.g. 60 s
    steps between them where the inputs have samples) is sub-stepped only on another
    regular length's set, so that alternating 120 s and 60 s steps share the 60 s set
    instead of factorising anew at each step. ``bound`` accumulates over the
    applications (CRAM16_ERROR ||w||_M each): times sqrt(c M^-1 c) it bounds a read-out's
    approximation error.
    """

    def __init__(self, K: sp.spmatrix, M: sp.spmatrix, lu_K, max_sets: int = 1,
                 max_substeps: int = 32, regular: frozenset[float] = frozenset()):
        self.K, self.M, self.lu_K = K, M, lu_K
        self.max_sets, self.max_substeps = max_sets, max_substeps
        self.regular = {round(h, 9) for h in regular}
        self._sets: OrderedDict[float, list] = OrderedDict()
        self.bound = 0.0
        self.factorisations = 0

    def _set(self, h: float) -> list:
        key = round(h, 9)
        if key in self._sets:
            self._sets.move_to_end(key)
        else:
            while len(self._sets) >= self.max_sets:
                self._sets.popitem(last=False)  # before the new set is made (memory)
            self._sets[key] = [_complex_lu(h * self.K + theta * self.M) for theta in CRAM16_THETA]
            self.factorisations += len(CRAM16_THETA)
        return self._sets[key]

    def _plan(self, h: float) -> tuple[float, int]:
        """(sub-step length, count) for a step of length h."""
        key = round(h, 9)
        if key in self._sets:
            return h, 1
        for k in reversed(self._sets):
            if key in self.regular and k not in self.regular:
                continue  # a regular step never runs on a rare step's set
            q = round(h / k)
            if 1 < q <= self.max_substeps and abs(q * k - h) <= 1e-9 * h:
                return k, q
        return h, 1

    def expm(self, w: np.ndarray, h: float) -> np.ndarray:
        """exp(-h M^-1 K) w by CRAM-16 (one set of LUs for h)."""
        lus = self._set(h)
        self.bound += CRAM16_ERROR * float(np.sqrt(max(w @ (self.M @ w), 0.0)))
        y = w.astype(complex)
        for alpha, lu in zip(CRAM16_ALPHA, lus, strict=True):
            y = y - 2.0 * np.real(alpha * lu.solve(self.M @ y))
        return CRAM16_ALPHA0 * np.real(y)

    def step(self, x0: np.ndarray, a: np.ndarray, b: np.ndarray, h: float) -> np.ndarray:
        """x(t0 + h) from x(t0) = x0 for the load a + b (t - t0)."""
        Ka, Kb = self.lu_K.solve(a), self.lu_K.solve(b)
        drift = self.lu_K.solve(self.M @ Kb)
        sub, q = self._plan(h)
        x = x0
        for i in range(q):  # sub-step i starts at s = i sub: load a + b s + b (t - t0 - s)
            xp0 = Ka + (i * sub) * Kb - drift
            x = xp0 + sub * Kb + self.expm(x - xp0, sub)
        return x


def readout_norms(M: sp.spmatrix, readout: np.ndarray,
                  factor: Callable[[sp.spmatrix], object]) -> np.ndarray:
    """sqrt(c M^-1 c) for each row c of ``readout`` (dense, n_readouts x N): with
    :attr:`ExactStepper.bound` it bounds each read-out's approximation error."""
    lu = factor(M)
    return np.sqrt(np.maximum(np.einsum("ij,ji->i", readout, lu.solve(readout.T)), 0.0))
