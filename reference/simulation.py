"""The FEM reference as one object: thermal solve plus the thermoelastic growth readings.

``ReferenceModel(spec, level, order)`` meshes the spec, assembles both operators once and
solves steady states and transients; results carry temperatures, the growth readings (P1,
TCP) in m and, for steady states, the displacement field.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from meshes import build_mesh
from reference.elastic import ThermoelasticModel
from reference.results import SteadyResult, TransientResult
from reference.thermal import ThermalModel
from spindle.arguments import whole_number
from spindle.drive import as_load_case
from spindle.loads import LoadCase
from spindle.spec import Spec
from spindle.spec_reader import as_spec
from spindle.units import MESH_LEVEL_MAX, RPM_TO_RAD_S


class ReferenceModel:
    """Thermal + thermoelastic FEM reference of ``spec`` on mesh ``level`` with P``order``.

    ``centrifugal`` adds the body force rho omega^2 r on the rotating parts (off by
    default; it shortens the shaft axially at speed).
    """

    def __init__(self, spec: Spec | str, level: int = 2, order: int = 2,
                 centrifugal: bool = False, elastic: bool = True):
        spec = as_spec(spec)
        level = whole_number(level, "level", 0, MESH_LEVEL_MAX)
        order = whole_number(order, "order", 1, 2)
        self.spec, self.centrifugal = spec, centrifugal
        self.thermal = ThermalModel(build_mesh(spec, level), order)
        self.elastic = ThermoelasticModel(self.thermal) if elastic else None

    @classmethod
    def from_parts(cls, thermal: ThermalModel, elastic: ThermoelasticModel | None,
                   centrifugal: bool = False) -> ReferenceModel:
        """A reference on models already assembled (e.g. a steady result's ``model`` and
        ``elastic``), sharing their matrices and factorisations."""
        self = cls.__new__(cls)
        self.spec, self.centrifugal = thermal.spec, centrifugal
        self.thermal, self.elastic = thermal, elastic
        return self

    @property
    def readings(self) -> list[str]:
        return list(self.elastic.growth_points()) if self.elastic else []

    def release(self) -> None:
        """Drop the thermal and elastic factorisations, keeping the mesh, the operators and
        every result (a study holding several levels' results needs no more)."""
        self.thermal.release()
        if self.elastic is not None:
            self.elastic.release()

    def steady(self, case: LoadCase | str | None = None, t: float = 0.0,
               keep_factorisations: bool = True) -> SteadyResult:
        """The steady state of ``case`` (a LoadCase, a cycle's name or file, or None for the
        spec's own) at time ``t`` [s], with the displacement field and the
        growth readings [m]. ``keep_factorisations=False`` drops the thermal factorisation
        and the elastic load operator before the elastic factorisation is made, and that one
        after (a single solve's peak memory: on spl2782 level 3 they take 0.15, 0.05 and
        0.6 GB); the next solve makes them again."""
        res = self.thermal.solve_steady(as_load_case(self.spec, case), t)
        if not keep_factorisations:
            self.thermal.release()
        if self.elastic is not None:
            res.elastic = self.elastic
            f = self.elastic.load(res.T, res.speed_rpm, self.centrifugal)
            if not keep_factorisations:  # B too goes before the factorisation is made
                self.elastic.release()
            res.U = self.elastic.solve(f)
            res.growth_m = self.elastic.growth(res.U)
            if not keep_factorisations:
                self.elastic.release()
        return res

    @staticmethod
    def _step_speeds(case: LoadCase, times_s: np.ndarray) -> np.ndarray:
        """Speed [rpm] at each output time: the value held over the step ending there (its
        mid-step value; the first sample: the start value)."""
        t = np.asarray(times_s, dtype=float)
        mid = np.concatenate([[t[0]], 0.5 * (t[1:] + t[:-1])])
        return np.asarray(case.speed_rpm(mid), dtype=float)

    def centrifugal_m(self, case: LoadCase, times_s: np.ndarray, reading: str = "P1"
                      ) -> np.ndarray:
        """The centrifugal part omega^2 c of a growth reading [m] at the output times (the
        speed held over each step), whether or not this model adds it."""
        omega2 = (self._step_speeds(case, times_s) * RPM_TO_RAD_S) ** 2
        return omega2 * self.elastic.gain(reading)[1]

    def exact_readouts(self, case: LoadCase | str, dt_s: float, T0: float | None = None,
                       method: str = "krylov", progress: Callable[[int, int], None] | None = None
                       ) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, np.ndarray],
                                  dict[str, float]]:
        """(times [s], sensors [K], growth readings [m], each read-out's time error [K or
        m]: the estimate for "krylov", the bound for "cram") on time_grid(case, dt_s), exact
        in time for inputs linear between grid points (ThermalModel.exact_readouts)."""
        case = as_load_case(self.spec, case)
        gains = self.growth_gains()
        if self.elastic is not None:  # the gains are kept; its LU is not needed (memory)
            self.elastic.release()
        t, names, S, F, bound = self.thermal.exact_readouts(
            case, dt_s, T0, {k: g for k, (g, _) in gains.items()}, method, progress=progress)
        growth = self._growth(gains, F, self._step_speeds(case, t))
        return (t, {n: S[:, j] for j, n in enumerate(names)}, zeroed_at_start(growth), bound)

    def growth_gains(self) -> dict[str, tuple[np.ndarray, float]]:
        """Each growth reading's thermal gain g [m/K per DOF] and centrifugal c [m s^2]."""
        return {k: self.elastic.gain(k) for k in self.readings} if self.elastic else {}

    def _growth(self, gains: dict, functionals: dict[str, np.ndarray],
                speed_rpm: np.ndarray) -> dict[str, np.ndarray]:
        """Growth readings [m] from the recorded g . T series and the speed held over each
        step [rpm] (the centrifugal part only if this model adds it)."""
        T_ref = self.elastic.T_ref if self.elastic else 0.0
        omega2 = (np.asarray(speed_rpm) * RPM_TO_RAD_S) ** 2
        return {k: functionals[k] - T_ref * g.sum() + (omega2 * c if self.centrifugal else 0.0)
                for k, (g, c) in gains.items()}

    def transient(self, case: LoadCase | str, dt_s: float, theta: float = 1.0,
                  T0: np.ndarray | float | None = None, save_every: int = 0,
                  progress: Callable[[float], None] | None = None) -> TransientResult:
        """The thermal transient (:meth:`ThermalModel.solve_transient`; T0 [K], default the
        case's ambient at t = 0) and its growth readings [m], zeroed at the start
        (:func:`zeroed_at_start`) as are the displacement fields. ``case``: a LoadCase or a
        cycle's name or file (``"spl-16h"``)."""
        case = as_load_case(self.spec, case)
        gains = self.growth_gains()
        res = self.thermal.solve_transient(case, dt_s, theta, T0, save_every, progress,
                                           functionals={k: g for k, (g, _) in gains.items()})
        t = res.times_s
        speed = self._step_speeds(case, t)
        res.growth_m.update(zeroed_at_start(self._growth(gains, res.functionals, speed)))
        if self.elastic is not None:  # displacement fields at the saved times, for ParaView
            res.elastic = self.elastic
            at = np.searchsorted(t, res.field_times_s)  # saved times are grid times
            U = np.array([self.elastic.displacement(T, speed[k], self.centrifugal)
                          for k, T in zip(at, res.fields_K, strict=True)])
            res.U_fields = U - U[0]  # from the start, as the readings (fields_K[0]: t = 0)
        return res


def zeroed_at_start(growth_m: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Each growth history [m] relative to its first value: a transient's read-outs start at
    0, as a bench zeroes its displacement sensor when the run starts (the stress-free
    temperature T_initial_K of a steady solve would leave an offset where the run starts at
    another temperature: -0.18 um of P1 at 19.5 degC against 20 degC on spl-16h)."""
    return {k: v - v[0] for k, v in growth_m.items()}
