"""The lumped model of a spec as one object, with the reference's interface.

``LumpedModel(spec, nodes=11)`` builds the function-block network (lumped.build), assembles
eq. 8 and solves steady states and transients (exact zero-order hold, inputs held at their
mid-step values over each step); results carry the virtual sensors (interpolated at the same
points as the reference's) and the growth readings (P1, TCP) of the thermoelastic chain.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from lumped.build import LumpedNetwork, build_network
from lumped.elastic import GrowthChain, KelvinVoigt
from lumped.results import LumpedSteadyResult, LumpedTransientResult
from spindle.drive import as_load_case
from spindle.errors import SolverError
from spindle.geometry import TOL_M
from spindle.loads import (
    LoadCase,
    check_start_temperature,
    start_temperature_K,
    time_grid,
    time_step_s,
)
from spindle.spec import Spec
from spindle.spec_reader import as_spec


class LumpedModel:
    """Lumped thermal + thermoelastic model of ``spec`` with ``nodes`` masses along shaft and
    housing (an int >= 2 or ``"paper5"`` / ``"paper11"``).

    ``radial_conduction=False`` drops the conduction between a mass and its faces (eq. 7 as
    printed); ``lags`` puts a Kelvin-Voigt element on growth readings by name.
    """

    def __init__(self, spec: Spec | str, nodes: int | str = 11, radial_conduction: bool = True,
                 lags: dict[str, KelvinVoigt] | None = None, network: LumpedNetwork | None = None):
        spec = as_spec(spec)
        self.spec = spec
        # a prebuilt (possibly extended) network of the spec may be given instead
        self.net = network if network is not None else build_network(spec, nodes,
                                                                     radial_conduction)
        self.nodes = self.net.nodes
        self.system = self.net.network.assemble()
        sys = self.system
        # state index of every mass (the network orders them; masses are never junctions)
        free = np.asarray(sys.free)
        node_of = {lab: i for i, labs in enumerate(sys.labels) for lab in labs}
        state_of = {int(free[s]): k for k, s in enumerate(sys.state)}
        for m in self.net.masses:
            m.index = state_of[node_of[m.name]]
        self.masses = sorted(self.net.masses, key=lambda m: m.index)
        self.sensor_names, self.S = self._sensor_matrix()
        self.chain = GrowthChain(spec, self.net.parts, sys.n_states, lags)

    # ------------------------------------------------------------------ read-outs
    @property
    def n_states(self) -> int:
        return self.system.n_states

    @property
    def readings(self) -> list[str]:
        return list(self.chain.rows)

    def _sensor_matrix(self) -> tuple[list[str], np.ndarray]:
        """Rows that interpolate each temperature sensor from the mass temperatures."""
        sensors = self.spec.temperature_sensors()
        arrays = {a.name: a.part for a in self.spec.sensor_arrays}
        S = np.zeros((len(sensors), self.system.n_states))
        for j, s in enumerate(sensors):
            part, sec = None, None
            if s.array in arrays:
                part = arrays[s.array]
            for p, q in self.spec.sections():
                if (part is None or p.name == part) and q.contains(s.z, s.r):
                    part, sec = p.name, q
                    break
            pm = self.net.parts[part]
            if pm.ring:
                m = pm.at(s.z, sec)
                weights = {m.index: 1.0} if m is not None else \
                    {pm.masses[0].index: 0.5, pm.masses[1].index: 0.5}  # in the rolling layer
            else:
                weights = pm.interpolation(s.z)
            for i, c in weights.items():
                S[j, i] += c
        return [s.name for s in sensors], S

    def mass_table(self) -> dict[str, list]:
        """Name, part, node position z [m] and capacity [J/K] of every mass (state order)."""
        return {"mass": [m.name for m in self.masses], "part": [m.part for m in self.masses],
                "z_m": [m.z_m for m in self.masses],
                "C_J_K": [float(self.system.C[m.index]) for m in self.masses]}

    # ------------------------------------------------------------------ inputs
    def inputs(self, case: LoadCase, t: float | np.ndarray) -> np.ndarray:
        """Input vector(s) u at time(s) t: source powers [W], then fixed temperatures [K]."""
        own = {h.name: h.power_W for h in self.spec.heat_sources}
        cols = []
        for name in self.system.source_names:
            series = case.sources.get(name, own.get(name))
            cols.append(np.broadcast_to(np.asarray(series(t), dtype=float), np.shape(t)))
        for src in self.system.fixed_sources:
            series = {"ambient": case.T_ambient_K, "coolant": case.T_coolant_K}.get(src)
            val = series(t) if series is not None else float(src)
            cols.append(np.broadcast_to(np.asarray(val, dtype=float), np.shape(t)))
        return np.stack(cols, axis=-1) if cols else np.zeros((*np.shape(t), 0))

    # ------------------------------------------------------------------ solves
    def steady(self, case: LoadCase | str | None = None, t: float = 0.0) -> LumpedSteadyResult:
        """Steady state for the inputs of ``case`` (a LoadCase, a cycle's name or file, or
        None for the spec's own) at time ``t`` [s]."""
        case = as_load_case(self.spec, case)
        sys = self.system
        u = self.inputs(case, t)
        n = float(case.speed_rpm(t))
        try:
            x = sys.steady(u, n)
        except np.linalg.LinAlgError:
            raise SolverError(f"{self.spec.path}: the lumped network is singular at "
                              f"{n:g} rpm; fix: give every part a heat path to a fixed "
                              "temperature") from None
        T_all = sys.node_temperatures(x, u, n)
        q = u[:len(sys.source_names)]
        K, B, _, _ = sys.matrices(n, q)
        residual = float(np.linalg.norm(K @ x - B @ u) / max(np.linalg.norm(B @ u), 1e-300))
        return LumpedSteadyResult(self, case, t, n, x, sys.heat_in(T_all, q),
                                  sys.heat_to_fixed(T_all, n), residual, self.chain.growth(x))

    def transient(self, case: LoadCase | str, dt_s: float, T0: np.ndarray | float | None = None,
                  progress: Callable[[float], None] | None = None) -> LumpedTransientResult:
        """Exact zero-order-hold integration over ``case.duration_s`` on the reference's time
        grid (every dt_s [s] and every input sample); inputs held at their mid-step values.
        ``case``: a LoadCase or a cycle's name or file (``"spl-16h"``). ``T0``
        [K]: the mass temperatures at the start, a uniform one, or None for the case's
        ambient at t = 0; the growth readings are zeroed at the start, as a bench zeroes
        P1."""
        case = as_load_case(self.spec, case)
        if time_step_s(dt_s) <= 0 or case.duration_s <= 0:
            raise SolverError("a transient run needs dt_s > 0 and a duration > 0")
        sys = self.system
        grid = time_grid(case, dt_s)
        mid = 0.5 * (grid[1:] + grid[:-1])
        U = self.inputs(case, mid)
        speeds = np.asarray(case.speed_rpm(mid), dtype=float)
        x = self.initial_state(T0, case)
        X = np.empty((len(grid), sys.n_states))
        X[0] = x
        m = len(sys.source_names)
        E_in = 0.0
        out_by: dict[str, float] = {}
        for k in range(len(grid) - 1):
            dt, u, n = grid[k + 1] - grid[k], U[k], float(speeds[k])
            Phi, Gam, Psi, Lam = sys.discretize(dt, n, u[:m], integrals=True)
            x_int = Psi @ x + Lam @ u  # integral of x over the step [K s]
            T_int = sys.node_temperatures(x_int, u * dt, n)  # node temperatures, integrated
            E_in += sys.heat_in(T_int / dt, u[:m]) * dt
            for key, v in sys.heat_to_fixed(T_int, n).items():
                out_by[key] = out_by.get(key, 0.0) + v
            x = Phi @ x + Gam @ u
            X[k + 1] = x
            if progress is not None:
                progress(grid[k + 1] / case.duration_s)
        E_out = sum(out_by.values())
        E_stored = float(sys.C @ (X[-1] - X[0]))
        return LumpedTransientResult(self, case, grid, self.sensor_names, X @ self.S.T, X,
                                     E_in, E_out, E_stored, out_by,
                                     self.chain.history(grid, X))

    def initial_state(self, T0: np.ndarray | float | None, case: LoadCase | None = None
                 ) -> np.ndarray:
        """Mass temperatures [K] from T0 (per mass, uniform, or None: the case's ambient at
        t = 0, without a case the spec's T_initial_K)."""
        n = self.system.n_states
        if T0 is None and case is None:
            return np.full(n, self.spec.T_initial_K)
        if T0 is None or np.isscalar(T0):
            return np.full(n, start_temperature_K(case, T0))
        check_start_temperature(T0)
        x = np.asarray(T0, dtype=float)
        if x.shape != (n,):
            raise SolverError(f"T0 has shape {x.shape}; the model has {n} masses")
        return x.copy()

    def mass_at(self, part: str, z: float) -> int:
        """State index of the mass of ``part`` holding z [m] (tests and plots)."""
        m = self.net.parts[part].at(z) if not self.net.parts[part].ring else None
        if m is None:
            raise KeyError(f"no mass of {part} at z = {z:g} m (tol {TOL_M:g})")
        return m.index
