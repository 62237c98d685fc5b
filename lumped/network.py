"""A network of function blocks, assembled into eq. 8: C dT/dt + K(n) T = Q(t).

Ports joined by :meth:`Network.connect` form a node. A node holding a
:class:`~lumped.blocks.FixedTemperature` is an input; every other node is an unknown, with
the sum of its capacitors as capacity. Nodes without capacity (pure junctions) are condensed
out (static condensation), so the state is the set of thermal masses.

With inputs u = [heat-source powers (W) ..., fixed temperatures (K) ...] the assembled
:class:`ThermalSystem` is::

    C dT/dt + K(n, u_q) T = B(n) u      (eq. 8-11)

K depends on speed n through the speed-dependent conductances, and on the heat-source powers
only through temperature-dependent heat flows (copper loss).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from lumped.blocks import (
    Block,
    Conductance,
    Convection,
    FixedTemperature,
    HeatCapacitor,
    HeatPort,
    PrescribedHeatFlow,
    ThermalConductor,
    conductance_at,
    varies_with_speed,
)
from spindle.errors import SpindleVerifyError
from spindle.loads import SpeedTable


def _step(dt_s: float) -> float:
    """A time step [s] to 1 ns: steps that differ by less (a grid on a time-of-day clock,
    58.7 against 58.69999999999709 s) are one step, computed with the rounded value, so a
    cached step's matrices do not depend on which of them was asked for first."""
    return round(float(dt_s), 9)


class NetworkError(SpindleVerifyError):
    """A network that cannot be assembled: each line names the block and the fix."""

    def __init__(self, name: str, problems: list[str]):
        self.problems = problems
        super().__init__("\n".join(f"network '{name}': {p}" for p in problems))


class Network:
    """A composition of blocks joined at their heat ports (Modelica ``connect``)."""

    def __init__(self, name: str = "network"):
        self.name = name
        self.blocks: list[Block] = []
        self._names: set[str] = set()
        self._parent: dict[HeatPort, HeatPort] = {}
        self._connected: set[HeatPort] = set()

    def add(self, *blocks: Block) -> Block:
        """Add blocks; returns the last one (so ``cap = net.add(HeatCapacitor(...))``)."""
        for b in blocks:
            if b.name in self._names:
                raise NetworkError(self.name, [f"block name '{b.name}' is used twice; fix: give "
                                               "every block its own name"])
            self._names.add(b.name)
            self.blocks.append(b)
            for p in b.ports:
                self._parent[p] = p
        return blocks[-1]

    def _root(self, p: HeatPort) -> HeatPort:
        while self._parent[p] is not p:
            self._parent[p] = self._parent[self._parent[p]]
            p = self._parent[p]
        return p

    def connect(self, a: HeatPort, b: HeatPort) -> None:
        """Join two ports: they share one temperature, and their heat flows sum to zero."""
        for p in (a, b):
            if p not in self._parent:
                raise NetworkError(self.name, [f"port {p!r} belongs to a block that was not "
                                               "added; fix: net.add(block) before connecting"])
        ra, rb = self._root(a), self._root(b)
        if ra is not rb:
            self._parent[ra] = rb
        self._connected |= {a, b}

    def assemble(self) -> ThermalSystem:
        """Check the network and build :class:`ThermalSystem`; raises :class:`NetworkError`
        listing every unconnected port, conflicting fixed temperature and node group without a
        path to a fixed temperature."""
        problems = self._port_problems() + self._value_problems()
        if problems:
            raise NetworkError(self.name, problems)

        roots: dict[HeatPort, int] = {}
        for b in self.blocks:
            for p in b.ports:
                roots.setdefault(self._root(p), len(roots))
        n_all = len(roots)

        def node(p: HeatPort) -> int:
            return roots[self._root(p)]

        capacity, labels, fixed, where = self._nodes(n_all, node, problems)
        edges: list[tuple[int, int, Conductance, str]] = []
        for b in self.blocks:
            if isinstance(b, ThermalConductor):
                edges.append((node(b.port_a), node(b.port_b), float(b.G_W_K), b.name))
            elif isinstance(b, Convection):
                edges.append((node(b.port_a), node(b.port_b), b.Gc_W_K, b.name))
        flows = [(node(b.port), b) for b in self.blocks if isinstance(b, PrescribedHeatFlow)]
        across = {id(b): (node(b.across[0]), node(b.across[1])) for _, b in flows
                  if b.across is not None}
        problems += _unheld_groups(n_all, edges, fixed, labels)
        if problems:
            raise NetworkError(self.name, problems)

        free = [i for i in range(n_all) if i not in fixed]
        fixed_nodes = sorted(fixed)
        fixed_sources = [fixed[i] for i in fixed_nodes]
        source_names = list(dict.fromkeys(f.source for _, f in flows))
        return ThermalSystem(
            name=self.name, n_all=n_all, free=free, fixed_nodes=fixed_nodes,
            fixed_sources=fixed_sources, capacity=capacity, labels=labels, where=where,
            edges=edges, flows=flows, source_names=source_names, across=across)

    def _port_problems(self) -> list[str]:
        """Every port left unconnected."""
        return [f"port {p!r} is not connected; fix: connect it or remove block '{b.name}'"
                for b in self.blocks for p in b.ports if p not in self._connected]

    def _value_problems(self) -> list[str]:
        """Every negative capacity or conductance."""
        problems = []
        for b in self.blocks:
            bad = [(k, v) for k, v in (("C_J_K", getattr(b, "C_J_K", 0.0)),
                                       ("G_W_K", getattr(b, "G_W_K", 0.0))) if v < 0]
            if isinstance(b, Convection) and isinstance(b.Gc_W_K, SpeedTable) \
                    and b.Gc_W_K.min < 0:
                bad.append(("Gc_W_K", b.Gc_W_K.min))
            elif isinstance(b, Convection) and isinstance(b.Gc_W_K, int | float) \
                    and b.Gc_W_K < 0:
                bad.append(("Gc_W_K", b.Gc_W_K))
            problems += [f"block '{b.name}': {k} = {v:g} is negative; fix: give a value >= 0"
                         for k, v in bad]
        return problems

    def _nodes(self, n_all: int, node, problems: list[str]) -> tuple:
        """Per node: capacity [J/K], block labels, fixed temperature source and location;
        clashing fixed temperatures are appended to ``problems``."""
        capacity = np.zeros(n_all)
        labels: list[list[str]] = [[] for _ in range(n_all)]
        fixed: dict[int, str | float] = {}
        where: dict[int, tuple[str, float]] = {}
        for b in self.blocks:
            if isinstance(b, HeatCapacitor):
                i = node(b.port)
                capacity[i] += b.C_J_K
                labels[i].append(b.name)
                where.setdefault(i, (b.part, b.z_m))
            elif isinstance(b, FixedTemperature):
                i = node(b.port)
                if i in fixed and fixed[i] != b.source:
                    problems.append(f"block '{b.name}' holds a node at '{b.source}' that "
                                    f"another block holds at '{fixed[i]}'; fix: connect them "
                                    "through a conductor")
                fixed[i] = b.source
                labels[i].append(b.name)
        return capacity, labels, fixed, where


def _unheld_groups(n_all: int, edges, fixed: dict, labels: list[list[str]]) -> list[str]:
    """Every group of unknown nodes joined by conductances needs a fixed temperature: one
    problem per group without one (the system would be singular)."""
    adj: dict[int, set[int]] = {i: set() for i in range(n_all)}
    for i, j, G, _ in edges:
        if _may_conduct(G):
            adj[i].add(j)
            adj[j].add(i)
    problems, seen = [], set()
    for start in range(n_all):
        if start in seen or start in fixed:
            continue
        group, stack = set(), [start]
        while stack:
            k = stack.pop()
            if k not in group:
                group.add(k)
                stack.extend(adj[k] - group)
        seen |= group
        if not group & set(fixed):
            names = sorted({lab for k in group for lab in labels[k]}) or ["(junction)"]
            problems.append(f"nodes {names[:6]}{' ...' if len(names) > 6 else ''} have no "
                            "heat path to a fixed temperature (the system would be "
                            "singular); fix: add a Convection or ThermalConductor to a "
                            "FixedTemperature")
    return problems


def _may_conduct(G: Conductance) -> bool:
    if isinstance(G, SpeedTable):
        return G.max > 0
    if callable(G):
        return True
    return float(G) > 0


@dataclass(frozen=True)
class _Stamps:
    """K and B of a system as K0 + Kv g(n) and B0 + Bv g(n), flattened, with g the varying
    conductances at the speed n [W/K]; the temperature-dependent flows' terms come on top."""

    K0: np.ndarray
    B0: np.ndarray
    Kv: object  # sparse (free x free, varying): four entries per varying edge at most
    Bv: object  # sparse (free x inputs, varying)
    varying: list


@dataclass
class ThermalSystem:
    """Eq. 8 for a network: matrices at a speed, inputs, and node bookkeeping.

    Inputs: ``u = [q_1..q_m, T_1..T_d]``, the heat-source series named in ``source_names``
    (W; a constant source is a name ``"<value> W"``) and the fixed temperatures named in
    ``fixed_sources`` (K).
    """

    name: str
    n_all: int
    free: list[int]
    fixed_nodes: list[int]
    fixed_sources: list[str | float]
    capacity: np.ndarray
    labels: list[list[str]]
    where: dict[int, tuple[str, float]]
    edges: list[tuple[int, int, Conductance, str]]
    flows: list[tuple[int, PrescribedHeatFlow]]
    source_names: list[str | float]
    across: dict[int, tuple[int, int]] = field(default_factory=dict)  # flow -> (node a, node b)
    _cache: dict = field(default_factory=dict, repr=False)
    _stamp: _Stamps | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self._stamp = None  # a system made by replace() has edges of its own
        pos = {n: k for k, n in enumerate(self.free)}
        self._pos = pos
        C = self.capacity[self.free]
        self.state = np.nonzero(C > 0)[0]  # positions (in free) of the thermal masses
        self.junction = np.nonzero(C <= 0)[0]
        self.C = C[self.state]
        self.input_names = [f"{s} W" if not isinstance(s, str) else s for s in self.source_names] \
            + [f"{s} K" if not isinstance(s, str) else s for s in self.fixed_sources]
        self.temperature_dependent = any(f.tc_1_K != 0 for _, f in self.flows)
        #: each heat source's column in u (and in B)
        self._source_col = {s: k for k, s in enumerate(self.source_names)}
        self._tc_columns = sorted({self._source_col[f.source] for _, f in self.flows
                                   if f.tc_1_K != 0})

    # ------------------------------------------------------------------ matrices
    def _q_key(self, q: np.ndarray | None) -> tuple | None:
        """Cache key of the source powers that enter K (those of temperature-dependent flows
        only: the others change B u, not the matrices)."""
        if not self.temperature_dependent or q is None:
            return None
        # exact: a key rounded to 12 decimals handed out the matrices of an earlier, nearly
        # equal q, so a result depended on what was evaluated before it (compare.fit.greybox)
        return tuple(np.asarray(q, dtype=float)[self._tc_columns].tolist())

    @property
    def n_states(self) -> int:
        return len(self.state)

    @property
    def n_inputs(self) -> int:
        return len(self.source_names) + len(self.fixed_nodes)

    def _stamps(self) -> _Stamps:
        """The edges and flows as fixed stamps (computed once per system): what does not vary
        with speed summed, and each conductance that does as a column, so that K and B at a
        speed are one product (:meth:`_full`, called for every speed of every parameter set a
        fit tries) and not a loop over the edges."""
        if self._stamp is not None:
            return self._stamp
        nf, ni, m = len(self.free), self.n_inputs, len(self.source_names)
        pos = self._pos
        fixed_col = {n: m + k for k, n in enumerate(self.fixed_nodes)}
        import scipy.sparse as sp

        K0, B0 = np.zeros((nf, nf)), np.zeros((nf, ni))
        varying = [k for k, (_, _, G, _) in enumerate(self.edges) if varies_with_speed(G)]
        column = {k: c for c, k in enumerate(varying)}
        # the varying edges' unit stamps as (flat index, column, value) triplets
        kv: tuple[list, list, list] = ([], [], [])
        bv: tuple[list, list, list] = ([], [], [])

        def stamp(flat: tuple[list, list, list], dense: np.ndarray, row: int, col: int,
                  c: int | None, g: float) -> None:
            if c is None:
                dense[row, col] += g
            else:
                flat[0].append(row * dense.shape[1] + col)
                flat[1].append(c)
                flat[2].append(g)

        for k, (i, j, G, _) in enumerate(self.edges):
            c = column.get(k)
            # a constant edge adds its value, a varying one a unit into its column
            g = conductance_at(G, 0.0) if c is None else 1.0
            for a, b in ((i, j), (j, i)):
                if a in pos:
                    stamp(kv, K0, pos[a], pos[a], c, g)
                    if b in pos:
                        stamp(kv, K0, pos[a], pos[b], c, -g)
                    else:
                        stamp(bv, B0, pos[a], fixed_col[b], c, g)
        col = self._source_col
        for n, f in self.flows:
            if n not in pos:
                continue  # heat into a fixed temperature leaves the network at once
            # Q = share q (1 + tc (T_a - T_b)) across two nodes; else
            # Q = share q (1 + tc (T - T_ref)) = share q (1 - tc T_ref) + share q tc T
            B0[pos[n], col[f.source]] += (f.share if id(f) in self.across
                                          else f.share * (1.0 - f.tc_1_K * f.T_ref_K))
        n_var = len(varying)
        Kv = sp.csr_matrix((kv[2], (kv[0], kv[1])), shape=(nf * nf, n_var))
        Bv = sp.csr_matrix((bv[2], (bv[0], bv[1])), shape=(nf * ni, n_var))
        self._stamp = _Stamps(K0, B0, Kv, Bv, [self.edges[k][2] for k in varying])
        return self._stamp

    def _full(self, speed_rpm: float, q: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """K over all free nodes and B (free x inputs) at a speed, for source powers q."""
        feedback = q is not None and self.temperature_dependent
        if feedback and ("full", speed_rpm) in self._cache:
            # the speed's part is the same for every q: a fit asks many q at a speed
            K, B = (a.copy() for a in self._cache[("full", speed_rpm)])
        else:
            st = self._stamps()
            K, B = st.K0.copy(), st.B0.copy()
            if st.varying:
                g = np.array([conductance_at(G, speed_rpm) for G in st.varying])
                K += (st.Kv @ g).reshape(K.shape)
                B += (st.Bv @ g).reshape(B.shape)
            if not feedback:
                return K, B
            self._cache[("full", speed_rpm)] = (K.copy(), B.copy())
        pos = self._pos
        col = self._source_col
        for n, f in self.flows:  # the temperature-dependent flows' terms in K
            if n not in pos or not f.tc_1_K:
                continue
            g = f.share * f.tc_1_K * q[col[f.source]]
            if id(f) in self.across:
                for node_, sign in zip(self.across[id(f)], (1.0, -1.0), strict=True):
                    if node_ in pos:
                        K[pos[n], pos[node_]] -= sign * g
                    else:
                        raise ValueError("a heat flow across a fixed temperature")
            else:
                K[pos[n], pos[n]] -= g
        return K, B

    def matrices(self, speed_rpm: float, q: np.ndarray | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(K, B, R, S) at a speed: C dT/dt + K T = B u for the masses; the junction
        temperatures follow as T_j = R T + S u (static condensation)."""
        key = (float(speed_rpm), self._q_key(q))
        if key in self._cache:
            return self._cache[key]
        Kf, Bf = self._full(speed_rpm, q)
        s, j = self.state, self.junction
        if len(j):
            Kjj = Kf[np.ix_(j, j)]
            R = -np.linalg.solve(Kjj, Kf[np.ix_(j, s)])
            S = np.linalg.solve(Kjj, Bf[j])
            K = Kf[np.ix_(s, s)] + Kf[np.ix_(s, j)] @ R
            B = Bf[s] - Kf[np.ix_(s, j)] @ S
        else:
            R = np.zeros((0, len(s)))
            S = np.zeros((0, self.n_inputs))
            K, B = Kf, Bf
        if len(self._cache) > 256:
            self._cache.clear()
        self._cache[key] = (K, B, R, S)
        return K, B, R, S

    def node_temperatures(self, x: np.ndarray, u: np.ndarray, speed_rpm: float) -> np.ndarray:
        """Temperature of every network node [K] from the mass temperatures x and inputs u
        (junctions from the condensation; fixed nodes from u)."""
        _, _, R, S = self.matrices(speed_rpm, u[:len(self.source_names)])
        T = np.empty(self.n_all)
        free = np.asarray(self.free)
        T[free[self.state]] = x
        if len(self.junction):
            T[free[self.junction]] = R @ x + S @ u
        T[self.fixed_nodes] = u[len(self.source_names):]
        return T

    def heat_to_fixed(self, T_all: np.ndarray, speed_rpm: float) -> dict[str, float]:
        """Heat [W] leaving into each fixed temperature (ambient, coolant, ...)."""
        key = ("out", float(speed_rpm))
        if key not in self._cache:
            fixed = dict(zip(self.fixed_nodes, self.fixed_sources, strict=True))
            names = list(dict.fromkeys(str(v) for v in self.fixed_sources))
            H = np.zeros((len(names), self.n_all))
            for i, j, G, _ in self.edges:
                g = conductance_at(G, speed_rpm)
                for a, b in ((i, j), (j, i)):
                    if b in fixed and a not in fixed:
                        row = names.index(str(fixed[b]))
                        H[row, a] += g
                        H[row, b] -= g
            self._cache[key] = (names, H)
        names, H = self._cache[key]
        return dict(zip(names, (H @ T_all).tolist(), strict=True))

    def heat_in(self, T_all: np.ndarray, q: np.ndarray) -> float:
        """Heat [W] from the prescribed heat flows at node temperatures T_all."""
        col = self._source_col
        total = 0.0
        for n, f in self.flows:
            if id(f) in self.across:
                a, b = self.across[id(f)]
                total += f.share * q[col[f.source]] * (1 + f.tc_1_K * (T_all[a] - T_all[b]))
            else:
                total += f.share * q[col[f.source]] * (1 + f.tc_1_K * (T_all[n] - f.T_ref_K))
        return float(total)

    # ------------------------------------------------------------------ solves
    def steady(self, u: np.ndarray, speed_rpm: float) -> np.ndarray:
        """Mass temperatures [K] at steady state for inputs u."""
        K, B, _, _ = self.matrices(speed_rpm, u[:len(self.source_names)])
        return np.linalg.solve(K, B @ u)

    def modes(self, dt_s: float, speed_rpm: float) -> tuple | None:
        """Modal form of the exact zero-order-hold step for a symmetric network (None
        otherwise): (a, Bm, to_modal, from_modal) with z = to_modal x, z+ = a z + Bm u and
        x = from_modal z (eigenvectors of C^-1/2 K C^-1/2)."""
        dt_s = _step(dt_s)
        key = ("modes", dt_s, float(speed_rpm))
        if key not in self._cache:
            K, B, _, _ = self.matrices(speed_rpm, None)
            # np.allclose(K, K.T, rtol=1e-12, atol=0) for a finite K, without its checks for
            # infinities and nan: a fit asks this at every speed of every parameter set
            if self.temperature_dependent or not np.all(np.abs(K - K.T) <= 1e-12 * np.abs(K.T)):
                self._cache[key] = None
            else:
                s = 1.0 / np.sqrt(self.C)
                lam, V = np.linalg.eigh(s[:, None] * K * s[None, :])
                self._cache[key] = self._modal_form(lam, V, B, dt_s)
        return self._cache[key]

    def _modal_form(self, lam: np.ndarray, V: np.ndarray, B: np.ndarray, dt_s: float) -> tuple:
        """(a, Bm, to_modal, from_modal) of :meth:`modes` from the eigenpairs (lam, V) of
        C^-1/2 K C^-1/2, the condensed B and the step dt_s [s]."""
        s = 1.0 / np.sqrt(self.C)
        g = -np.expm1(-lam * dt_s) / lam
        return (np.exp(-lam * dt_s), (V.T * s[None, :]) @ B * g[:, None],
                V.T * (1.0 / s)[None, :], s[:, None] * V)

    def prepare_modes(self, dts_s: np.ndarray, speeds_rpm: np.ndarray) -> None:
        """:meth:`modes` for a sequence of steps [s] and speeds [rpm] at once, into the same
        cache (nothing for a temperature-dependent network, which has no modes). The
        matrices, their condensation and the eigenproblems of all new speeds go to numpy as
        stacks, so a new set of conductances costs a few calls, not a few per speed. The
        numbers are those of :meth:`modes` called along the sequence: each stacked slice
        runs the same LAPACK and BLAS routine on the same values (tests/test_lumped_network.py)."""
        if self.temperature_dependent:
            return
        todo: dict[tuple, None] = {}  # the new cache keys ("modes", step, speed), in order
        for dt, n in zip(np.asarray(dts_s, dtype=float).tolist(),
                         np.asarray(speeds_rpm, dtype=float).tolist(), strict=True):
            key = ("modes", _step(dt), n)
            if key not in self._cache:
                todo.setdefault(key)
        if len(todo) < 2:
            return
        speeds = list(dict.fromkeys(key[2] for key in todo))
        full = [self._full(n, None) for n in speeds]
        K, B = np.array([f[0] for f in full]), np.array([f[1] for f in full])
        s_, j = self.state, self.junction
        if len(j):
            Kjj = K[:, j][:, :, j]
            R = -np.linalg.solve(Kjj, K[:, j][:, :, s_])
            S = np.linalg.solve(Kjj, B[:, j])
            Ksj = K[:, s_][:, :, j]
            K = K[:, s_][:, :, s_] + Ksj @ R
            B = B[:, s_] - Ksj @ S
        KT = K.transpose(0, 2, 1)
        sym = np.all(np.abs(K - KT) <= 1e-12 * np.abs(KT), axis=(1, 2))
        sc = 1.0 / np.sqrt(self.C)
        eig = {}
        if sym.any():
            lam, V = np.linalg.eigh(sc[None, :, None] * K[sym] * sc[None, None, :])
            eig = {speeds[k]: (lam[i], V[i], B[k]) for i, k in enumerate(np.flatnonzero(sym))}
        if len(self._cache) > 256:
            self._cache.clear()
        for key in todo:  # the rest as modes() writes it, per step
            self._cache[key] = (self._modal_form(*eig[key[2]], key[1]) if key[2] in eig
                                else None)

    def discretize(self, dt_s: float, speed_rpm: float, q: np.ndarray | None = None,
                   integrals: bool = False) -> tuple[np.ndarray, ...]:
        """Exact zero-order-hold step: x+ = Phi x + Gamma u for inputs held over dt_s [s]
        (from :meth:`modes` for a symmetric network, else the matrix exponential of the
        augmented system, scipy.linalg.expm). With ``integrals``
        also (Psi, Lambda) with integral_0^dt x dt = Psi x + Lambda u, for exact energy
        bookkeeping."""
        dt_s = _step(dt_s)
        key = ("zoh", dt_s, float(speed_rpm), integrals, self._q_key(q))
        if key in self._cache:
            return self._cache[key]
        K, B, _, _ = self.matrices(speed_rpm, q)
        n, m = K.shape[0], B.shape[1]
        modal = None if integrals else self.modes(dt_s, speed_rpm)
        if modal is not None:  # symmetric network: exact through its eigenvectors
            a, Bm, to_modal, from_modal = modal
            self._cache[key] = ((from_modal * a) @ to_modal, from_modal @ Bm)
            return self._cache[key]
        from scipy.linalg import expm

        size = 2 * n + m if integrals else n + m
        M = np.zeros((size, size))
        M[:n, :n] = -K / self.C[:, None] * dt_s
        M[:n, n:n + m] = B / self.C[:, None] * dt_s
        if integrals:
            M[n + m:, :n] = np.eye(n)  # in time scaled by dt: d(integral of x)/dtau = x
        E = expm(M)
        out = (E[:n, :n], E[:n, n:n + m])
        if integrals:
            out += (E[n + m:, :n] * dt_s, E[n + m:, n:n + m] * dt_s)
        self._cache[key] = out
        return out
