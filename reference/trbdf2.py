"""TR-BDF2 steps of the linear heat equation, with an embedded estimate of each step's error.

Over one step [t0, t0 + h] at one speed, with the load linear in time::

    M x' = -K x + a + b (t - t0)

TR-BDF2 (Bank, Coughran, Fichtner, Grosse, Rose, Smith, "Transient simulation of silicon
devices and circuits", IEEE Trans. CAD 4 (1985) 436-451; analysed by Hosea and Shampine,
"Analysis and implementation of TR-BDF2", Appl. Numer. Math. 20 (1996) 21-37) takes a
trapezoidal stage to t0 + gamma h, then BDF2 to t0 + h. With gamma = 2 - sqrt(2) both stages
solve with the same matrix M + d h K, d = gamma / 2, so a step costs one real sparse LU per
speed and step length (kept) and two solves. The method is second order, L-stable (the
stiff modes after a jump are damped, not left ringing as Crank-Nicolson leaves them) and,
since M and K are symmetric positive definite, contractive in the M norm: an error made in
one step never grows later.

Each step's local error is estimated by the embedded third-order formula of Hosea and
Shampine (1996, section 4): TR-BDF2 is the ESDIRK with stages c = (0, gamma, 1), weights
b = (w, w, d), w = sqrt(2) / 4, and the companion b^ = ((1 - w) / 3, (3 w + 1) / 3, d / 3) is
third order through the same slopes. The difference, filtered by the step's own matrix as
they advise for stiff problems, is one more solve with the same LU::

    (M + d h K) e = h [ (4 w - 1) / 3 f_n - 1 / 3 f_gamma + 2 d / 3 f_(n+1) ],  f = a + b t - K x

Because the step is a contraction in the M norm, the global error in the M norm is at most
the sum of the local errors' M norms; a read-out c . x is then off by at most
sqrt(c M^-1 c) times that sum (:attr:`TRBDF2Stepper.bound`, the way :mod:`reference.exact`
bounds CRAM's error). The local estimate is asymptotic (exact as h -> 0), so the bound is an
estimate, not a guarantee; tests/test_time_convergence.py checks it against the exact
integration, where it holds with a wide margin (the sum of norms ignores the decay of
earlier errors).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

GAMMA = 2.0 - math.sqrt(2.0)
#: the diagonal coefficient of both stages: gamma / 2 = (1 - gamma) / (2 - gamma)
D = GAMMA / 2.0
#: the weight of the first two slopes in the step (b = (w, w, d))
_W = math.sqrt(2.0) / 4.0
# the BDF2 stage: x1 = c_gamma x_gamma - c_n x_n + d h M^-1 f1
_C_GAMMA = 1.0 / (GAMMA * (2.0 - GAMMA))
_C_N = (1.0 - GAMMA) ** 2 / (GAMMA * (2.0 - GAMMA))


class TRBDF2Stepper:
    """TR-BDF2 steps at one speed of M x' = -K x + a + b (t - t0) (module docstring).

    ``factor`` makes a sparse LU (an object with ``.solve``). At most ``max_lus`` LUs of
    M + d h K are kept, least recently used dropped. ``bound`` accumulates the local error
    estimates' M norms (sqrt(e . M e), M the capacity matrix [J/K]); times sqrt(c M^-1 c)
    it bounds a read-out's error (to the accuracy of the local estimates)."""

    def __init__(self, K: sp.spmatrix, M: sp.spmatrix, factor: Callable, max_lus: int = 4):
        self.K, self.M, self.factor = K, M, factor
        self.max_lus = max_lus
        self._lus: OrderedDict[float, object] = OrderedDict()
        self.bound = 0.0
        self.factorisations = 0
        self.solves = 0

    def _lu(self, h: float):
        key = round(h, 9)
        if key in self._lus:
            self._lus.move_to_end(key)
        else:
            while len(self._lus) >= self.max_lus:
                self._lus.popitem(last=False)
            self._lus[key] = self.factor((self.M + (D * h) * self.K).tocsc())
            self.factorisations += 1
        return self._lus[key]

    def step(self, x0: np.ndarray, a: np.ndarray, b: np.ndarray, h: float,
             estimate: bool = True) -> np.ndarray:
        """x(t0 + h) from x(t0) = x0 for the load a + b (t - t0); adds the step's local
        error estimate to :attr:`bound` if ``estimate``."""
        lu = self._lu(h)
        K, M = self.K, self.M
        f0 = a - K @ x0
        # trapezoidal stage to t0 + gamma h
        xg = lu.solve(M @ x0 + (D * h) * (f0 + a + (GAMMA * h) * b))
        # BDF2 stage to t0 + h
        x1 = lu.solve(M @ (_C_GAMMA * xg - _C_N * x0) + (D * h) * (a + h * b))
        self.solves += 2
        if estimate:
            fg = a + (GAMMA * h) * b - K @ xg
            f1 = a + h * b - K @ x1
            k1, k2, k3 = _ERR_WEIGHTS
            e = lu.solve(h * (k1 * f0 + k2 * fg + k3 * f1))
            self.solves += 1
            self.bound += float(np.sqrt(max(e @ (M @ e), 0.0)))
        return x1


#: b - b^ (module docstring): the weights of f_n, f_gamma, f_(n+1) in the error estimate
_ERR_WEIGHTS = ((4.0 * _W - 1.0) / 3.0, -1.0 / 3.0, 2.0 * D / 3.0)
