"""The grey box of a bench run: the lumped model with declared, bounded uncertain base
parameters (compare.fit.params) and the effects of the library (compare.fit.effects) it
holds, simulated exactly (zero-order hold) on the run's per-interval inputs.

The engine knows no effect by name: each effect of the set enters through its hooks (network
options and blocks, the conductances of the edges it owns, its heat, its read-out of P1, how
its sensor reads). Labels name the effects, with the channel of a per-channel one
(``sensor_lag(T2)``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from dataclasses import replace as dc_replace

import numpy as np

from compare.fit.effects import effect_of, parse_label
from compare.fit.effects.base import CHANNELS
from compare.fit.params import EXTRA_BASE_PARAMS, PREHISTORY, PREHISTORY_HEAT, Param, base_params
from lumped.blocks import Convection, FixedTemperature, conductance_at, varies_with_speed
from lumped.build import build_network
from lumped.simulation import LumpedModel
from spindle.bench_inputs import Inputs, interval_heat_W
from spindle.drive import Drive
from spindle.drive_file import MOTOR_SOURCES
from spindle.errors import InputError
from spindle.spec import ContactLink, Spec
from spindle.streaming import modal_recursion
from spindle.stretch import stretch_axially

ROTATING = ("shaft", "tool", "rotor")
#: the parameters that scale a group of the network's edges (films, contacts)
_GROUPS = ("h_coolant", "h_air", "h_rotating", "contact", "stator_contact")
#: the base parameters that change the conductance matrix K (an effect declares its own)
_K_PARAMS = (*_GROUPS, "heat_capacity", "axial_scale", "G_seat_W_K")


#: the most nodes a grey box takes: it keeps each parameter's trajectory of every node, and 161
#: took 237 s and 4.5 GB on a 16 h run (2026-12-02, memory about n^1.8), so 500 would need
#: tens of GB (the lumped solver alone takes lumped.build.MAX_NODES)
MAX_NODES = 161


def _geometric(x: np.ndarray, floor: float, rel: float) -> np.ndarray:
    """``x`` (at least ``floor`` taken) rounded to the nearest point of the geometric grid of
    relative step ``rel``."""
    step = np.log1p(rel)
    return np.exp(np.round(np.log(np.maximum(x, floor)) / step) * step)


def source_group(name: str) -> str:
    """"motor" for a source the motor's losses heat (MOTOR_SOURCES), else "bearings"."""
    return "motor" if name in MOTOR_SOURCES else "bearings"


def heat_groups(heat_W: dict[str, float]) -> dict[str, float]:
    """The heat [W] of ``heat_W`` summed by :func:`source_group`."""
    out: dict[str, float] = {}
    for k, v in heat_W.items():
        out[source_group(k)] = out.get(source_group(k), 0.0) + v
    return out


@dataclass
class GreyBox:
    """The lumped model of ``spec`` with parameters and the effects ``effects`` (labels),
    simulated on ``inputs``."""

    spec: Spec
    drive: Drive
    inputs: Inputs
    nodes: int = 11
    effects: tuple[str, ...] = ()
    _cache: dict = field(default_factory=dict, repr=False)
    #: per channel, FEM reference minus this lumped model at the reference point, added to
    #: every simulation [K; m for P1] (compare.fit.discrepancy): the lumped model then supplies
    #: only the change that parameters and effects make, the FEM the trajectory itself
    discrepancy: dict[str, np.ndarray] | None = field(default=None, repr=False)
    #: names of EXTRA_BASE_PARAMS calibrated with the base parameters
    base_extra: tuple[str, ...] = ()
    #: the speed-dependent conductances (films, bearings) are evaluated at the interval's
    #: speed rounded to a geometric grid of this relative step (0: exactly); the heat
    #: sources always at the exact speed (compare.fit.criteria.Criteria.speed_bin_rel)
    speed_bin_rel: float = 0.0
    #: the time [s] the P1 column was zeroed at (its first valid sample, the format's
    #: reference) where it is later than the grid's first interval: P1 is then the growth
    #: since that time, not since the run's start (None: since the start)
    p1_reference_s: float | None = None

    def variant(self, effects: tuple[str, ...]) -> GreyBox:
        """The same model with another effect set (sharing caches and discrepancy)."""
        return dc_replace(self, effects=tuple(effects))

    def plain(self) -> GreyBox:
        """The spec's lumped model on the same inputs: no effects, no base extras, no
        discrepancy (sharing the caches)."""
        return GreyBox(self.spec, self.drive, self.inputs, self.nodes, _cache=self._cache,
                       speed_bin_rel=self.speed_bin_rel)

    def on_inputs(self, inputs: Inputs) -> GreyBox:
        """The base model (with its extras, no effects, no anchor) on other inputs."""
        return GreyBox(self.spec, self.drive, inputs, self.nodes, base_extra=self.base_extra,
                       speed_bin_rel=self.speed_bin_rel)

    def _binned(self, q: np.ndarray) -> np.ndarray:
        """Source powers [W] on the geometric grid of :attr:`speed_bin_rel` (for the
        matrices of a feedback whose heat enters them: a 5 % grid moves a preload's feedback
        term by at most 2.5 %, a fraction of a percent of the bearing's heat)."""
        if self.speed_bin_rel <= 0:
            return q
        q = np.asarray(q, dtype=float)
        return np.where(np.abs(q) > 1e-9,
                        np.sign(q) * _geometric(np.abs(q), 1e-9, self.speed_bin_rel), 0.0)

    def conductance_speeds(self) -> np.ndarray:
        """Per interval, the speed [rpm] the conductances are evaluated at
        (:attr:`speed_bin_rel`; speeds below 1 rpm as they are)."""
        n = np.asarray(self.inputs.speed_rpm, dtype=float)
        if self.speed_bin_rel <= 0:
            return n
        return np.where(n >= 1.0, _geometric(n, 1.0, self.speed_bin_rel), n)

    def _effects(self) -> list[tuple[object, str | None]]:
        return [(effect_of(lab), parse_label(lab)[1]) for lab in self.effects]

    @property
    def _seats(self) -> bool:
        """Whether the network has the bearing seats' links to the coolant (G_seat_W_K)."""
        return "G_seat_W_K" in self.base_extra and "G_seat_W_K" not in self.inert_params()

    def inert_params(self) -> frozenset[str]:
        """The base parameters (and extras) that act on nothing in this spec's network, so
        that no run can tell their value: a film or contact group without an edge (h_coolant
        of an air-cooled spindle) and the bearing seats' link where there is no coolant to
        link them to (G_seat_W_K). None on a water-cooled spec with every group."""
        key = ("inert", self.nodes)
        if key not in self._cache:
            inert = set(_GROUPS) - set(self.plain()._structure()[1])
            if not self.spec.liquid_cooled:
                inert.add("G_seat_W_K")
            self._cache[key] = frozenset(inert)
        return self._cache[key]

    def parameters(self) -> dict[str, Param]:
        inert = self.inert_params()
        out = {k: p for k, p in base_params(self.drive).items() if k not in inert}
        out.update({k: EXTRA_BASE_PARAMS[k] for k in self.base_extra if k not in inert})
        if self.inputs.prehistory_s > 0:  # a moved start (compare.fit.start)
            out[PREHISTORY.name] = dc_replace(PREHISTORY, default=min(max(
                self.inputs.prehistory_s / 3600.0, PREHISTORY.lo), PREHISTORY.hi))
        for group, most in self._prehistory_caps().items():
            out[PREHISTORY_HEAT[group].name] = dc_replace(PREHISTORY_HEAT[group], hi=most)
        out.update({p.name: p for e, _ in self._effects() for p in e.params})
        return out

    def _prehistory_caps(self) -> dict[str, float]:
        """For a prehistory that ran elsewhere (Inputs.prehistory_heat_W), the largest
        multiple of its heat in the motor and in the bearings that the run's own largest heat
        there allows (at the spec's values), by group; a group without heat has none."""
        heat = self.inputs.prehistory_heat_W
        if not heat:
            return {}
        # parameters() asks it on every simulation; under "src", as all that the inputs decide
        key = ("src", "prehistory_caps")
        if key not in self._cache:
            spec = base_params(self.drive)
            hottest = self.hottest({k: spec[k].default for k in ("f0", "rotor_share")})
            read = heat_groups(heat)
            self._cache[key] = {g: max(sum(peak.values()) / read[g], 1.0 + 1e-6)
                                for g, peak in hottest.items() if read.get(g, 0.0) > 0}
        return self._cache[key]

    def hottest(self, theta: dict[str, float]) -> dict[str, dict[str, float]]:
        """Per group of sources (:func:`heat_groups`' "motor", "bearings"), each source's
        heat [W] in the interval where the group's total is largest, at ``theta``'s f0,
        rotor_share and friction_exponent (0 where it names none)."""
        src = self.sources(theta["f0"], theta["rotor_share"], theta.get("friction_exponent", 0.0))
        out = {}
        for group in ("motor", "bearings"):
            names = [k for k in src if source_group(k) == group]
            if names:
                i = int(np.argmax(sum(src[k] for k in names)))
                out[group] = {k: float(src[k][i]) for k in names}
        return out

    def prehistory_heat(self, theta: dict[str, float]) -> dict[str, float] | None:
        """The prehistory's heat [W] by source at ``theta`` (the read heat times its group's
        multiple; None: the first interval's)."""
        heat = self.inputs.prehistory_heat_W
        if not heat:
            return None
        return {k: v * theta.get(PREHISTORY_HEAT[source_group(k)].name, 1.0)
                for k, v in heat.items()}

    def full_theta(self, theta: dict[str, float]) -> dict[str, float]:
        """``theta`` with every parameter it does not name at its default."""
        return {k: theta.get(k, p.default) for k, p in self.parameters().items()}

    # ------------------------------------------------------------------ sources
    def sources(self, f0: float, rotor_share: float, friction_exponent: float = 0.0
                ) -> dict[str, np.ndarray]:
        """Heat per source [W] and interval: the power balance with friction factor ``f0``
        times (n / FRICTION_REF_RPM)^``friction_exponent`` (Drive.with_friction_exponent) and
        the rotor share of the motor losses."""
        # exact keys: rounded ones handed out a nearly equal set's entry (fit-history (12))
        key = ("src", float(f0), float(rotor_share), float(friction_exponent))
        if key not in self._cache:
            # the motor loss does not depend on its split, so the power balances are made
            # once per friction law, at a rotor share of 0 (stator = the whole loss), and
            # split here as spindle.power.motor_losses splits it: rotor = share x loss,
            # stator = loss - rotor, the same floats
            whole = self._balances(f0, friction_exponent)
            rotor = rotor_share * whole["stator"]
            out = {**whole, "rotor": rotor, "stator": whole["stator"] - rotor}
            srcs = [k2 for k2 in self._cache if isinstance(k2, tuple) and k2[:1] == ("src",)
                    and not isinstance(k2[1], str)]  # not the balances, points, caps
            for k2 in srcs[:-7]:  # keep the last few: a Jacobian visits f0 and the split
                del self._cache[k2]
            self._cache[key] = out
        return self._cache[key]

    def _balances(self, f0: float, friction_exponent: float) -> dict[str, np.ndarray]:
        """Heat per source [W] and interval at a rotor share of 0 (sources; under a key
        ("src", ...), as everything that depends on the inputs)."""
        key = ("src", "balances", float(f0), float(friction_exponent))
        if key not in self._cache:
            d = self.drive.with_f0(f0).with_rotor_share(0.0).with_friction_exponent(
                friction_exponent)
            points, which = self._operating_points()
            # P unknown (None): the motor model gives the losses; measured P: standstill
            # and P < P_mech handled as the bench does
            heats = [d.heat_W(n, M, None) if P is None else interval_heat_W(d, n, M, P)[0]
                     for n, M, P in points]
            old = [k2 for k2 in self._cache if isinstance(k2, tuple)
                   and k2[:2] == ("src", "balances")]
            for k2 in old[:-3]:  # a Jacobian visits f0 and the friction exponent
                del self._cache[k2]
            self._cache[key] = {s: np.array([h[s] for h in heats])[which] for s in heats[0]}
        return self._cache[key]

    def _operating_points(self) -> tuple[list[tuple], np.ndarray]:
        """The run's distinct operating points (speed [rpm] to 1e-3, torque [N m] to 0.01,
        measured power [kW] to 0.01 or None) and, per interval, its point's index: the
        power balances are made once per point."""
        key = ("src", "points")
        if key not in self._cache:
            inp = self.inputs
            index: dict[tuple, int] = {}
            # measured power to 10 W: below the losses' own uncertainty, and it keeps the
            # number of distinct operating points (power-balance calls) small
            which = [index.setdefault((round(float(n), 3), round(float(M), 2),
                                       None if np.isnan(P) else round(float(P), 2)), len(index))
                     for n, M, P in zip(inp.speed_rpm, inp.load_torque_Nm, inp.power_kW,
                                        strict=True)]
            self._cache[key] = (list(index), np.array(which, dtype=np.intp))
        return self._cache[key]

    # ------------------------------------------------------------------ model
    def _structure(self) -> tuple:
        """The network of this effect set, built and assembled once: (model, film or contact
        group per edge, the effects' handles by name)."""
        key = ("structure", self.nodes, self.effects, self._seats)
        if key in self._cache:
            return self._cache[key]
        effects = self._effects()
        options = {k: v for e, _ in effects for k, v in e.network_options().items()}
        net = build_network(self.spec, self.nodes, **options)
        handles = {e.name: e.extend_network(net, self.spec, self.power_measured)
                   for e, _ in effects}
        if self._seats:
            cool_port = _coolant_port(net)
            for p in net.parts.values():
                if p.part.role in ("front_bearing", "rear_bearing"):
                    outer = [m for m in p.masses if m.name.endswith("outer")] or p.masses[-1:]
                    c = net.network.add(Convection(f"seat:{p.part.name}", Gc_W_K=1.0))
                    net.network.connect(outer[0].block.port, c.port_a)
                    net.network.connect(c.port_b, cool_port)
        model = LumpedModel(self.spec, network=net)
        groups = film_groups(self.spec)
        edge_group = [_edge_group(self.spec, groups, e[3]) for e in model.system.edges]
        self._cache[key] = (model, edge_group, handles)
        return self._cache[key]

    def structure_model(self) -> LumpedModel:
        """The assembled lumped model of this effect set (its network, masses and rows)."""
        return self._structure()[0]

    def _stretch(self) -> tuple[dict, dict]:
        """Per side of ``axial_scale`` = 1 (``True``: longer), the exponents e with which the
        structure's edge conductances, node capacities and P1 chain follow s^e (from the
        plain networks of the spec stretched by ``STRETCH_PROBE`` and its inverse; edges
        the plain network lacks, effects' and seats', keep theirs)."""
        key = ("stretch", self.nodes, self.effects, self._seats)
        if key not in self._cache:
            # the exponents belong to the plain network: read once per node count, shared by
            # every effect set's structure
            plain_key = ("stretch_exponents", self.nodes)
            if plain_key not in self._cache:
                self._cache[plain_key] = stretch_exponents(self.spec, self.nodes)
            model = self._structure()[0]
            names = [e[3] for e in model.system.edges]
            sides, chain = {}, {}
            for longer, (ge, gc, gp) in self._cache[plain_key].items():
                sides[longer] = (
                    np.array([ge.get(n, 0.0) for n in names]),
                    np.array([max((gc.get(lab, 0.0) for lab in labs), key=abs, default=0.0)
                              for labs in model.system.labels]))
                chain[longer] = gp
            self._cache[key] = (sides, chain)
        return self._cache[key]

    def _p1(self, th: dict[str, float], growth_m: np.ndarray) -> np.ndarray:
        """P1 [m] from the chain's growth at the grid points (expansion at alpha_eff = 1), with
        the effects' read-outs, zeroed at the start as the bench zeroes it."""
        p1 = th["alpha_eff"] * growth_m
        scale = th.get("axial_scale", 1.0)
        if scale != 1.0:
            p1 = p1 * scale ** self._stretch()[1][scale > 1.0]
        for e, _ in self._effects():
            p1 = e.p1(p1, th, self.inputs)
        return p1 - p1[0]

    @property
    def power_measured(self) -> bool:
        """Whether the inputs carry a measured electrical power (a bench run)."""
        return bool(np.isfinite(np.asarray(self.inputs.power_kW, dtype=float)).any())

    def _model(self, theta: dict[str, float]) -> LumpedModel:
        """The structure's model with this parameter set's conductances (a new
        ThermalSystem over the same network; nothing is rebuilt)."""
        model, edge_group, handles = self._structure()
        base = model.system
        owned: dict[str, float] = {}
        for e, _ in self._effects():
            e.configure(handles[e.name], theta)
            owned.update(e.edge_conductances(theta))
        # systems (and their cached modes) are kept per set of the parameters that enter the
        # matrices: a Jacobian column for a source or read-out parameter reuses them (the
        # effects' flows, shared by the systems, were configured for these values above)
        kkey = ("system", self.nodes, self.effects, self._seats,
                *(float(theta.get(k, 0.0)) for k in self.matrix_params()))  # exact, as in sources
        system = self._cache.get(kkey)
        if system is None:
            systems = [k for k in self._cache if isinstance(k, tuple) and k[:1] == ("system",)]
            if len(systems) > 64:
                for k in systems[:32]:
                    del self._cache[k]
            scale = theta.get("axial_scale", 1.0)
            edge_exp, cap_exp = (self._stretch()[0][scale > 1.0] if scale != 1.0
                                 else (np.zeros(len(base.edges)), np.zeros(len(base.capacity))))
            # one memo per edge, made once per structure
            memos = self._cache.setdefault(("conductance_memos", self.nodes, self.effects,
                                            self._seats), [{} for _ in base.edges])
            edges = []
            for k, (i, j, G, name) in enumerate(base.edges):
                g = edge_group[k]
                factor = (theta[g] if g is not None else 1.0) * scale ** edge_exp[k]
                if factor != 1.0 or varies_with_speed(G):
                    G = _scaled(G, factor, memos[k])
                G = owned.get(name, G)
                if name.startswith("seat:"):
                    G = theta.get("G_seat_W_K", 0.0)
                edges.append((i, j, G, name))
            system = dc_replace(base, edges=edges, _cache={},
                                capacity=base.capacity * theta.get("heat_capacity", 1.0)
                                * scale ** cap_exp)
            self._cache[kkey] = system
        out = LumpedModel.__new__(LumpedModel)
        out.__dict__.update(model.__dict__)
        out.system = system
        return out

    def matrix_params(self) -> tuple[str, ...]:
        """The parameters that enter the network's matrices: a new value of one needs new
        modes at every speed level of the run."""
        return (*_K_PARAMS, *(k for e, _ in self._effects() for k in e.in_conductance))

    def _input_matrix(self, th: dict[str, float], sys) -> np.ndarray:
        """The network's inputs per interval: the heat sources [W] (with the effects'),
        then the room and the coolant [K]."""
        inp = self.inputs
        src = self.sources(th["f0"], th["rotor_share"], th.get("friction_exponent", 0.0))
        for e, _ in self._effects():
            src = e.heat(src, th, inp)
        n_int = len(inp.grid_s) - 1
        return np.column_stack([src[n] if n in src else np.zeros(n_int)
                                for n in sys.source_names]
                               + [inp.T_env_K if f == "ambient" else inp.T_coolant_K
                                  for f in sys.fixed_sources])

    def _start(self, sys, u0: np.ndarray, speed_rpm: float, prehistory_s: float,
               heat_W: dict[str, float] | None = None) -> np.ndarray:
        """The state at grid[0] [K]: uniform at the inputs' start temperature, then the first
        interval's inputs ``u0`` (at ``speed_rpm``) held for ``prehistory_s`` [s], exact;
        the sources ``heat_W`` names [W] (default the inputs' prehistory_heat_W) at those
        values instead of the first interval's."""
        inp = self.inputs
        x = np.full(sys.n_states, inp.T_start_K if inp.T_start_K is not None else inp.T_env_K[0])
        if prehistory_s <= 0:
            return x
        heat_W = inp.prehistory_heat_W if heat_W is None else heat_W
        if heat_W:
            u0 = u0.copy()
            for i, name in enumerate(sys.source_names):
                u0[i] = heat_W.get(name, u0[i])
        modal = None if sys.temperature_dependent else sys.modes(prehistory_s, speed_rpm)
        if modal is not None:
            a, Bm, to_modal, from_modal = modal
            return from_modal @ (a * (to_modal @ x) + Bm @ u0)
        Phi, Gam = sys.discretize(prehistory_s, speed_rpm, self._binned(u0[:len(sys.source_names)]))
        return Phi @ x + Gam @ u0

    def start_readings(self, theta: dict[str, float]):
        """The temperature sensors' readings at grid[0] [K] as a function of the prehistory
        [s] and its heat [W] by source (:meth:`_start`), for the parameters ``theta``."""
        th = self.full_theta(theta)
        model = self._model(th)
        sys = model.system
        u0 = self._input_matrix(th, sys)[0]
        speed = float(self.conductance_speeds()[0])
        rows = {n: model.S[model.sensor_names.index(n)] for n in model.sensor_names
                if n in CHANNELS and n != "P1"}

        def readings(prehistory_s: float, heat_W: dict[str, float] | None = None
                     ) -> dict[str, float]:
            x = self._start(sys, u0, speed, prehistory_s, heat_W)
            return {n: float(r @ x) for n, r in rows.items()}

        return readings

    def simulate(self, theta: dict[str, float],
                 extra_rows: dict[str, np.ndarray] | None = None) -> dict[str, np.ndarray]:
        """Channel values at the grid points [K; m for P1] for parameters ``theta`` (missing
        names take their defaults). Zero-order hold over each interval, exact.
        ``extra_rows``: more read-outs, each a row over the model's states (mass
        temperatures), returned under their names."""
        th = self.full_theta(theta)
        model = self._model(th)
        sys = model.system
        inp = self.inputs
        n_int = len(inp.grid_s) - 1
        U = self._input_matrix(th, sys)
        m = len(sys.source_names)
        n_K = self.conductance_speeds()
        # a moved start's prehistory is a parameter (parameters()); else there is none
        x = self._start(sys, U[0], float(n_K[0]), 3600.0 * th.get(PREHISTORY.name, 0.0),
                        self.prehistory_heat(th))
        names = [n for n in model.sensor_names if n in CHANNELS]
        rows = [model.S[model.sensor_names.index(n)] for n in names]
        has_p1 = "P1" in model.chain.rows
        if has_p1:
            rows.append(model.chain.rows["P1"])
        extra = extra_rows or {}
        rows.extend(extra.values())
        readout = np.array(rows)
        Y = np.empty((n_int + 1, len(rows)))
        Y[0] = readout @ x
        dts = np.diff(inp.grid_s)
        # runs of equal (dt, speed): one set of modes and one modal recursion each
        first = np.flatnonzero(np.r_[True, (dts[1:] != dts[:-1]) | (n_K[1:] != n_K[:-1])])[:n_int]
        sys.prepare_modes(dts[first], n_K[first])
        bounds = [*first.tolist(), n_int]
        heats = heat_keys = None
        for k, j in zip(bounds[:-1], bounds[1:], strict=True):
            modal = None if sys.temperature_dependent else sys.modes(float(dts[k]), float(n_K[k]))
            if modal is not None:
                a, Bm, to_modal, from_modal = modal
                Yseg, z = modal_recursion(a, Bm, U[k:j], to_modal @ x, readout @ from_modal)
                Y[k + 1:j + 1] = Yseg
                x = from_modal @ z
            else:  # a feedback of the heat on temperatures: its heat enters the matrices
                if heats is None:  # binned once a simulation, the same floats as per row
                    heats = self._binned(U[:, :m])
                    heat_keys = list(map(tuple, heats.tolist()))
                steps: dict[tuple, tuple] = {}  # a step per distinct heat of this segment
                for i in range(k, j):
                    step = steps.get(heat_keys[i])
                    if step is None:
                        step = steps[heat_keys[i]] = sys.discretize(float(dts[k]),
                                                                    float(n_K[k]), heats[i])
                    Phi, Gam = step
                    x = Phi @ x + Gam @ U[i]
                    Y[i + 1] = readout @ x
        out: dict[str, np.ndarray] = {n: Y[:, i] for i, n in enumerate(names)}
        out.update({n: Y[:, len(rows) - len(extra) + i] for i, n in enumerate(extra)})
        if has_p1:
            out["P1"] = self._p1(th, Y[:, len(names)])
        for c, d in (self.discrepancy or {}).items():
            if c in out:  # before a sensor's lag: a lagging sensor lags the whole signal
                out[c] = out[c] + d
        for e, channel in self._effects():
            out = e.as_measured(out, th, inp, channel)
        if "P1" in out and self.p1_reference_s is not None:
            out["P1"] = out["P1"] - np.interp(self.p1_reference_s, inp.grid_s, out["P1"])
        return out


#: the stretch at which the axial scale's exponents are read (and its inverse): the prior's
#: 1.3 sigma, where the exponents of partial overlaps (a film or contact that covers part of a
#: mass) are still those of the range the calibration visits
STRETCH_PROBE = 1.2
#: the speed at which speed-dependent conductances are compared [rpm]
_STRETCH_RPM = 3000.0


def stretch_exponents(spec: Spec, nodes: int
                      ) -> dict[bool, tuple[dict[str, float], dict[str, float], float]]:
    """Per side of 1 (``True``: the spec stretched axially by ``STRETCH_PROBE``, ``False``: by
    its inverse), the exponents e, per edge name and per block label, with which the plain
    network's conductances and capacities change from ``spec`` to the stretched spec (value
    ratio = factor^e), and the P1 chain's (its largest row entry's)."""

    def plain(sp: Spec) -> LumpedModel:
        return LumpedModel(sp, network=build_network(sp, nodes))

    a = plain(spec)
    ea = a.system.edges
    names = [e[3] for e in ea]
    out = {}
    for longer, factor in ((True, STRETCH_PROBE), (False, 1.0 / STRETCH_PROBE)):
        b = plain(stretch_axially(spec, factor))
        eb = b.system.edges
        if names != [e[3] for e in eb] or len(set(names)) != len(names):
            raise InputError("command line", "--base-extra", "axial_scale cannot be "
                             f"calibrated on the spec {spec.name}: its lumped network's "
                             "layout changes when the spindle is stretched axially by "
                             f"{factor:g}, so its lengths do not scale as one parameter",
                             "leave axial_scale out of --base-extra, e.g. --base-extra "
                             "G_seat_W_K friction_exponent")
        log_f = np.log(factor)
        edge = {}
        for (_, _, Ga, name), (_, _, Gb, _) in zip(ea, eb, strict=True):
            ga, gb = conductance_at(Ga, _STRETCH_RPM), conductance_at(Gb, _STRETCH_RPM)
            edge[name] = float(np.log(gb / ga) / log_f) if ga > 0 and gb > 0 else 0.0
        cap = {lab: float(np.log(cb / ca) / log_f)
               for labs, ca, cb in zip(a.system.labels, a.system.capacity, b.system.capacity,
                                       strict=True)
               if ca > 0 and cb > 0 for lab in labs}
        chain = 0.0
        if "P1" in a.chain.rows:
            ra, rb = a.chain.rows["P1"], b.chain.rows["P1"]
            k = int(np.argmax(np.abs(ra)))
            chain = float(np.log(rb[k] / ra[k]) / log_f) if ra[k] != 0 and rb[k] != 0 else 0.0
        out[longer] = (edge, cap, chain)
    return out


def _coolant_port(net):
    """The port at the coolant's temperature the films of the lumped network ``net`` see
    (behind the coolant's advection where it has one); None without a coolant film."""
    blocks = net.network.blocks
    adv = next((b for b in blocks if getattr(b, "name", "") == "coolant_advection"), None)
    if adv is not None:
        return adv.port_a
    fixed = next((b for b in blocks if isinstance(b, FixedTemperature)
                  and b.source == "coolant"), None)
    return None if fixed is None else fixed.port


def film_groups(spec: Spec) -> dict[str, str]:
    """Surface name -> its film parameter: coolant, rotating or housing air."""
    roles = {p.name: p.role for p in spec.parts}
    return {s.name: ("h_coolant" if s.T_ref == "coolant"
                     else "h_rotating" if any(roles[p] in ROTATING for p in s.parts)
                     else "h_air")
            for s in spec.surfaces}


def _edge_parts(block_name: str) -> set[str]:
    """The two parts an edge block such as ``contact:shaft[3]-rotor[1]`` joins."""
    a, b = block_name.split(":", 1)[1].split("-", 1)
    return {a.split("[")[0].split(".")[0], b.split("[")[0].split(".")[0]}


def _edge_group(spec: Spec, groups: dict[str, str], block_name: str) -> str | None:
    """The parameter that scales the edge block ``block_name``: its film's group (``groups``,
    :func:`film_groups`), ``contact`` for a contact link or ``stator_contact`` for one that
    touches the stator; None for any other edge."""
    if block_name.startswith("film:"):
        return groups[block_name.split(":")[1]]
    if not block_name.startswith("contact:"):
        return None
    parts = _edge_parts(block_name)
    if not any(isinstance(lk, ContactLink) and set(lk.parts) == parts for lk in spec.links):
        return None
    return "stator_contact" if any(spec.part(p).role == "stator" for p in parts) else "contact"


def _scaled(G, factor: float, memo: dict[float, float]):
    """``factor`` times the conductance G [W/K]; a G that varies with speed is read once per
    speed into ``memo`` (shared by every parameter set's system, as G is), so a new set of
    films costs a product, not the film correlation, at each of the run's speed levels."""
    if callable(G) and not isinstance(G, int | float):
        return _Scaled(G, factor, memo)
    return float(G) * factor


@dataclass(frozen=True)
class _Scaled:
    G: object
    factor: float
    #: speed [rpm] -> conductance_at(G, speed) [W/K], given by _scaled; the product below is
    #: the same float as without it
    memo: dict[float, float] = field(compare=False, repr=False)

    def __call__(self, speed_rpm: float) -> float:
        g = self.memo.get(speed_rpm)
        if g is None:
            g = self.memo[speed_rpm] = conductance_at(self.G, speed_rpm)
        return self.factor * g
