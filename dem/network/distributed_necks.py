r"""The network with a node per neck (:mod:`dem.network.necks`) shared out among MPI ranks: each rank's rows, the
groups that span ranks, the steady solve and the :math:`\theta` steps on PETSc, as
:mod:`dem.network.distributed` has them for one node per particle.

**Ownership.** A particle's centre node is owned by the rank that owns the particle; a neck node by the rank that owns
its bond's first particle ``i`` (the lower index; the rank that counts the bond across a periodic face in the one-node
network). The rows a rank solves for are those of its nodes: a centre's is its particle's element, a neck's the sum of
the elements of its bond's two particles, one of which may be another rank's.

**The halo.** Each rank holds the particles within three bond lengths of its own (``dem.geometry.bisection.NECK_HALO``,
:func:`dem.geometry.bisection.halo`) and assembles the serial network of them (:func:`dem.network.necks.neck_network`).
A particle's element is exact where all that shapes it is held: its necks (partners within one bond length), which of
them are live (a neck hidden inside a third sphere is none: the cut bodies of its partners, whose necks reach one bond
length further) and its pores' cells (neighbours within 1.5 bond lengths). The elements of the particles within one bond
length of a rank's own, the partners of its necks, are therefore exact with a halo of three bond lengths, and so is
every row the rank owns: the serial matrix's row, up to the order of its sums. The nodes those rows reach are the rank's
*used* nodes; the rest of the halo (its fringe, whose elements miss neighbours) is held but never solved for nor
exchanged.

**Numbering.** A node is known to every rank by a global key: a centre by its particle's index, a neck's mode ``d``
by its first particle's index, its place among that particle's bonds (sorted by partner and image shift: the same on
every rank that holds the particle's bonds, which the halo ensures for every used neck) and ``d``. With the Trefftz
element (``modes`` 3, :mod:`dem.network.necks`, "Flux modes") a rank builds it for its own particles only
(:class:`dem.network.elements.SceneElements`' ``own``: the expensive part of such a run shared out), the law's
one-mode element for the rest of its halo, and receives the elements of its own particles' partners, whose elements
its rows sum, from their owners (:func:`shared_elements`: each particle's element is the same on every rank that holds
all its necks, its ends in the same order) before it assembles its network, once (the live necks found first,
:func:`dem.network.necks.live_necks`, the network of them and the elements after, :func:`dem.network.necks.assembled`):
every used neck then has a Trefftz particle and its three modes, as in the serial network, and the fringe's necks,
never used, may have one. The unknowns of a solve are numbered
rank after rank (:meth:`dem.network.distributed.DistributedNetwork.numbering`).

**Groups and the steady solve.** The groups of free nodes are the connected components over the ranks
(:meth:`dem.network.distributed.DistributedNetwork.components`, on the edges of the owned rows). A group anchored by a
fixed centre, a wall or an ambient is solved as it is; any other group (a periodic box's, whose jumps drive it, or a
floating one) has its first node held at 0 and is then shifted so that its particles' capacity-weighted mean
temperature is their initial one, as :func:`dem.network.necks.steady_necks` does.

**Time steps.** The serial loop (:func:`dem.network.heat.integrate`) with this rank's part and the solves over the ranks
(:class:`dem.network.distributed.RankSolves`); the necks start where their rows hold at the initial temperatures, solved
over the ranks (:meth:`DistributedNecks.initial`). A Crank-Nicolson run starts with implicit Euler steps where the step
is above the stable limit of the centres' condensed matrix (:func:`dem.network.heat.integrate`): its largest eigenvalue
comes from the Lanczos estimate of ``LANCZOS_STEPS`` conjugate gradient steps on the condensed operator over the ranks
(:meth:`DistributedNecks.stable_limit`; on the packings of ``tests/mpi`` within 3e-5 of the serial limit, each step one
solve of the necks' rows).
"""

from __future__ import annotations

import numpy as np

from dem.network.distributed import DistributedNetwork
from dem.network.necks import LiveNecks, NeckHeat, NeckNetwork, first_modes, uniform_level
from dem.parallel import comm as mpi
from dem.parallel.petsc import largest_eigenvalue

LANCZOS_STEPS = 100  # the Lanczos steps of the stable limit's eigenvalue (DistributedNecks.stable_limit)


class RankNeckHeat(NeckHeat):
    """:class:`dem.network.necks.NeckHeat` over one rank's held nodes, counting the flows of its own particles
    (``own``); its necks' start is solved over the ranks by ``part`` (:meth:`DistributedNecks.initial`), set when the
    part is made."""

    part = None  # the DistributedNecks this network is part of

    @property
    def initial(self) -> np.ndarray:
        """Initial temperatures of the local free nodes (owned and used entries valid), K or degC."""
        return self.part.initial()


def node_keys(net: NeckNetwork, held: np.ndarray, owner: np.ndarray, comm) -> tuple[np.ndarray, np.ndarray]:
    """The global key and the owning rank of every local node (module docstring, "Numbering" and "Ownership").

    Parameters
    ----------
    net : dem.network.necks.NeckNetwork
        The rank's network of its held particles.
    held : numpy.ndarray
        Global index of each held particle, sorted.
    owner : numpy.ndarray
        The rank owning each held particle.
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).

    Returns
    -------
    tuple of numpy.ndarray
        ``(keys, owners)`` per node, centres then necks (each live neck's modes one after another): int64 keys,
        distinct over the ranks for distinct nodes.
    """
    i = net.bonds.i
    first = np.searchsorted(i, i)  # the bonds are sorted by i, then j and shift (dem.geometry.periodic)
    place = np.arange(len(i)) - first
    most = int(mpi.maximum(comm, int(place.max(initial=-1)) + 1))
    n_global = int(mpi.maximum(comm, int(held.max(initial=-1)) + 1))
    modes = net.bond_modes
    width = int(mpi.maximum(comm, int(modes.max(initial=1))))
    bond = np.repeat(net.live, modes)  # each neck node's bond, its modes in order
    mode = np.arange(len(bond)) - np.repeat(first_modes(modes), modes)
    necks = n_global + (held[i[bond]] * most + place[bond]) * width + mode
    return np.concatenate([held, necks]).astype(np.int64), np.concatenate([owner, owner[i[bond]]])


def shared_elements(comm, built, necks: LiveNecks, held: np.ndarray, owner: np.ndarray, mine: np.ndarray):
    """``built`` with the elements of the partners of this rank's own particles (over their live pair necks) taken
    from the ranks that own them (module docstring, "Numbering"): what the owned rows sum.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    built : dem.laws.shared_body.ParticleElements
        The held particles' elements as this rank built them (its own particles' the ones wanted), over ``necks``.
    necks : dem.network.necks.LiveNecks
        The live necks of the rank's held particles, of ``built``.
    held : numpy.ndarray
        Global index of each held particle, sorted.
    owner : numpy.ndarray
        The rank owning each held particle.
    mine : numpy.ndarray
        Per held particle, whether this rank owns it.

    Returns
    -------
    dem.laws.shared_body.ParticleElements
        ``built`` (the same type) with the partners' blocks and per-particle fields (``plain``, ``shrink``,
        ``modes``, ...) those of their owners.
    """
    n = len(held)
    i, j = necks.bonds.i[necks.live], necks.bonds.j[necks.live]
    need = np.zeros(n, dtype=bool)
    need[j[mine[i]]] = need[i[mine[j]]] = True
    wanted = np.flatnonzero(need & ~mine)
    asks = [held[wanted[owner[wanted] == r]] for r in range(comm.Get_size())]
    fields = [f for f in built._fields if f not in ("offsets", "ends", "start", "values")]
    per = {f: np.broadcast_to(np.asarray(getattr(built, f)), (n,)).copy() for f in fields}

    def block(k: int) -> tuple:
        return (built.values[built.start[k]:built.start[k + 1]], *(per[f][k] for f in fields))

    answers = comm.alltoall([[block(k) for k in np.searchsorted(held, keys)] for keys in comm.alltoall(asks)])
    blocks = [built.values[built.start[k]:built.start[k + 1]] for k in range(n)]
    for keys, answer in zip(asks, answers):
        for k, (values, *rest) in zip(np.searchsorted(held, keys), answer):
            blocks[k] = values
            for f, v in zip(fields, rest):
                per[f][k] = v
    start = np.concatenate([[0], np.cumsum([len(b) for b in blocks])])
    return built._replace(start=start, values=np.concatenate(blocks) if n else built.values, **per)


class DistributedNecks(DistributedNetwork):
    """This rank's part of the network with a node per neck (module docstring). ``net``: the
    :class:`RankNeckHeat` of its held nodes; ``held``: their global keys (:func:`node_keys`), ``owner`` the rank
    owning each, ``used`` the nodes its own rows reach.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    net : RankNeckHeat
        The heat balance of the held nodes.
    keys : numpy.ndarray
        Global key of every held node, centres then necks (:func:`node_keys`).
    owner : numpy.ndarray
        The rank owning each held node.
    """

    START_RTOL = 1e-12  # the relative residual of the necks' start (NeckHeat's own)

    def __init__(self, comm, net: RankNeckHeat, keys: np.ndarray, owner: np.ndarray):
        rank = comm.Get_rank()
        A = net.net.A
        mine = np.flatnonzero(owner == rank)
        reached = np.zeros(len(keys), dtype=bool)
        reached[mine] = True
        reached[A[mine].indices] = True
        used = np.flatnonzero(reached)
        self.used = used[np.argsort(keys[used], kind="stable")]  # sorted by key, as the exchange matches them
        super().__init__(comm, net, keys, owner, mpi.HaloExchange(comm, keys[self.used], owner[self.used]))
        net.part = self
        self._initial = None

    def fill(self, values: np.ndarray) -> np.ndarray:
        """``values`` over the held nodes (owned entries valid) with the used halo nodes' set from their owners.

        Parameters
        ----------
        values : numpy.ndarray
            One value per held node (any unit), changed in place.

        Returns
        -------
        numpy.ndarray
            ``values``.
        """
        values[self.used] = self.exchange.fill(values[self.used])
        return values

    def held_values(self, T_F: np.ndarray) -> np.ndarray:
        """All held nodes' temperatures (:meth:`dem.network.necks.NeckHeat.nodes`) from those of the free ones.

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free nodes (K or degC).

        Returns
        -------
        numpy.ndarray
            Temperatures of all held nodes, centres then necks (K or degC).
        """
        return self.net.nodes(T_F)

    def flows(self, T_F: np.ndarray, sinks: dict) -> dict:
        """Heat flow (W) into all free nodes through each boundary (:meth:`dem.network.necks.NeckHeat.flows`, each
        rank counting its own particles'), summed over the ranks.

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free nodes (used entries valid; K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`dem.network.necks.NeckHeat.sinks`): W/K and W per node.

        Returns
        -------
        dict
            ``{boundary: W}``, summed over the ranks.
        """
        part = self.net.flows(T_F, sinks)
        sums = self.total(np.array(list(part.values())))
        return dict(zip(part, map(float, sums)))

    def flow_magnitude(self, T_F: np.ndarray, sinks: dict) -> float:
        r"""The scale of the heat flows over the ranks (:meth:`dem.network.heat.BalanceScales.flow_magnitude`): the
        net flow, at least :math:`\sqrt{\epsilon}` times the gross one (W).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free nodes (used entries valid; K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}``: W/K and W per node.

        Returns
        -------
        float
            The scale (W).
        """
        net, gross = self.total(np.array(self.net.flow_sums(T_F, sinks)))
        return float(max(net, np.sqrt(np.finfo(float).eps) * gross))

    # ------------------------------------------------------------------------------------------- the start
    def initial(self) -> np.ndarray:
        """The initial temperatures of the local free nodes: the centres' own, the necks' where their rows hold at
        them (:attr:`dem.network.necks.NeckHeat.initial`), solved over the ranks once.

        Returns
        -------
        numpy.ndarray
            Per local free node (owned and used entries valid), K or degC.
        """
        if self._initial is None:
            net = self.net
            k = net.n_free - (net.net.n_nodes - net.particles.n)  # the free centres come first
            T = np.concatenate([net.particles.temperature[net.free[:k]].astype(float), np.zeros(net.n_free - k)])
            necks = np.arange(net.n_free) >= k
            row, n_global = self.numbering(necks)
            if n_global:
                rhs = net.r_const - net.A[:, :k] @ T[:k]
                take = self.own_free & necks
                solver = self.solver(net.A, row, n_global, self.START_RTOL)
                try:
                    T[take] = solver.solve(rhs[take], T[take])
                finally:
                    solver.destroy()
                self.linear_iterations += solver.iterations
            self._initial = self.halo_filled(T)[net.free]
        return self._initial.copy()

    def stable_limit(self, T_F: np.ndarray, steps: int = LANCZOS_STEPS) -> float:
        r"""The largest stable explicit step at ``T_F`` (s): :math:`2 / \lambda_\max` of the centres' condensed matrix
        :math:`C^{-1/2} (A_{cc} - A_{cn} A_{nn}^{-1} A_{nc}) C^{-1/2}`, as the serial run has it
        (:func:`dem.network.heat.stable_limit`), its largest eigenvalue estimated over the ranks in ``steps`` Lanczos
        steps (:func:`dem.parallel.petsc.largest_eigenvalue`; each product solves the necks' rows on PETSc).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free nodes (K or degC), where the ambient terms are linearised.
        steps : int
            The Lanczos steps (conjugate gradient iterations), >= 1.

        Returns
        -------
        float
            The limit (s; ``inf`` without any coupling).
        """
        net = self.net
        M = net.matrix(net.sinks(T_F))
        heavy = net.C > 0.0
        centres, necks = self.own_free & heavy, self.own_free & ~heavy
        s = 1.0 / np.sqrt(net.C[centres])
        row, n_necks = self.numbering(~heavy)
        solver = self.solver(M, row, n_necks, self.START_RTOL) if n_necks else None

        def condensed(x: np.ndarray) -> np.ndarray:
            v = np.zeros(net.n_free)
            v[centres] = s * x
            v = self.halo_filled(v)[net.free]
            if solver is not None:  # the necks where their rows hold, the centres at s x
                v[necks] = -solver.solve((M @ v)[necks])
                v = self.halo_filled(v)[net.free]
            return s * (M @ v)[centres]

        try:
            lam = largest_eigenvalue(self.comm, condensed, int(np.count_nonzero(centres)), max_iterations=steps)
        finally:
            if solver is not None:
                solver.destroy()
        return 2.0 / lam if lam > 0.0 else np.inf

    def above_stable_limit(self, dt: float, T_F: np.ndarray) -> bool:
        """Whether a fixed step ``dt`` is above the stable limit at ``T_F`` (:meth:`stable_limit`): where a
        Crank-Nicolson run starts with implicit Euler steps (:func:`dem.network.heat.integrate`).

        Parameters
        ----------
        dt : float
            The step (s).
        T_F : numpy.ndarray
            Temperatures of the local free nodes (K or degC), where the ambient terms are linearised.

        Returns
        -------
        bool
            ``dt`` is above the limit.
        """
        return dt > self.stable_limit(T_F)

    # --------------------------------------------------------------------------------------------- groups
    def anchors(self, sinks: dict) -> np.ndarray:
        """Per local free node: joined to a fixed centre, a wall or an ambient.

        Parameters
        ----------
        sinks : dict
            The ambient terms ``{name: (g, b)}`` per free node.

        Returns
        -------
        numpy.ndarray
            Bool per local free node.
        """
        net = self.net
        whole = net.net
        n_nodes = whole.n_nodes
        fixed = np.zeros(n_nodes, dtype=bool)
        fixed[:whole.particles.n] = whole.particles.fixed
        joined = np.zeros(n_nodes, dtype=bool)
        rows = whole.A[net.free]
        joined[net.free] = (rows[:, np.flatnonzero(fixed)].getnnz(axis=1) > 0)
        row, col = whole.entries[0], whole.entries[1]
        joined[row[(col < 0) & (row >= 0)]] = True  # a wall's column
        ambient = sum((g for g, _ in sinks.values()), np.zeros(net.n_free))
        return joined[net.free] | (ambient > 0.0)

    def neck_groups(self) -> tuple[np.ndarray, np.ndarray]:
        """Per local free node, the label of its group over the ranks (the smallest global row of its nodes,
        :meth:`dem.network.distributed.DistributedNetwork.components` on the edges of the owned rows), and its own
        global row.

        Returns
        -------
        tuple of numpy.ndarray
            ``(label, row)`` per local free node (owned and used entries valid).
        """
        net = self.net
        start, _ = self.numbering(np.ones(net.n_free, dtype=bool))
        rows = net.A[np.flatnonzero(self.own_free)].tocoo()
        a = np.flatnonzero(self.own_free)[rows.row]
        return self.components(a, rows.col, start), start

    # --------------------------------------------------------------------------------------------- steady
    def steady(self, floating: str = "mean", rtol: float = 1e-12):
        """Steady temperatures of the free nodes over the ranks (module docstring; no radiation): what
        :func:`dem.network.necks.steady_necks` finds. Returns ``(T_F, flows, energy_error, solver name)``.

        Parameters
        ----------
        floating : str
            ``"mean"`` (a group of particles that reaches no fixed temperature, wall or ambient and holds no bond
            across a periodic face with a temperature drop keeps its capacity-weighted mean initial temperature) or
            ``"error"`` (it is refused).
        rtol : float
            The relative residual of the linear solve (:func:`dem.network.necks.steady_necks`' own).

        Returns
        -------
        tuple
            ``(T_F, flows, energy_error, solver name)``: ``T_F`` per local free node (owned and used entries
            valid, K or degC), the flows into the free nodes through each boundary (W) summed over the ranks.

        Raises
        ------
        ValueError
            A floating group with ``floating = "error"``, or a group that reaches no fixed temperature, wall or
            ambient with a net heat source; on every rank alike.
        """
        if floating not in ("mean", "error"):
            raise ValueError(f"solver.floating = {floating!r}: must be error or mean")
        net = self.net
        k = net.n_free - (net.net.n_nodes - net.particles.n)  # the free centres, then the necks' modes
        T_F = np.concatenate([net.particles.temperature[net.free[:k]], np.zeros(net.n_free - k)]).astype(float)
        sinks = net.sinks(T_F)
        label, number = self.neck_groups()
        own = self.own_free
        anchored = self._union(label[own & self.anchors(sinks)])
        loose = np.setdiff1d(self._union(label[own]), anchored)  # held at one node, then shifted to their mean
        across = np.zeros(net.n_free, dtype=bool)  # the necks with a temperature drop across a periodic face
        across[net.net.monopoles[net.net.jump != 0.0] - net.particles.n + k] = True
        jumping = self._union(label[own & across])
        if len(loose):
            heat = self.group_sums(loose, label, net.heat)
            scale = self.group_sums(loose, label, np.abs(net.heat))
            if np.any(np.abs(heat) > 1e-12 * np.maximum(scale, 1e-300)):
                raise ValueError("steady problem has no solution: a floating group of particles (no fixed "
                                 "temperature, wall or ambient) has a net internal heat source, so it heats up "
                                 "forever")
            lost = np.setdiff1d(loose, jumping)
            if floating == "error" and len(lost):
                first = sorted(np.concatenate(self.comm.allgather(
                    self.held[net.free][:k][np.isin(label[:k], lost) & own[:k]][:8])))
                raise ValueError(f"steady problem is singular: {len(lost)} connected group(s) of particles (e.g. "
                                 f"{[int(p) for p in first[:8]]}) touch no fixed particle, wall or ambient, so "
                                 f"their temperature is undetermined; fix a particle's temperature, add a wall, or "
                                 f"set solver.floating = \"mean\"")
        ground = np.isin(label, loose) & (label == number)
        T_F[ground] = 0.0
        row, n_global = self.numbering(~ground)
        solver_name = "none"
        if n_global:
            solver = self.solver(net.matrix(sinks), row, n_global, rtol)
            solver_name = solver.name
            take = own & ~ground
            try:
                T_F[take] = solver.solve(net.rhs(sinks)[take], T_F[take])
            finally:
                solver.destroy()
            self.linear_iterations += solver.iterations
        if len(loose):  # each such group to its particles' capacity-weighted mean initial temperature
            T0 = np.concatenate([net.particles.temperature[net.free[:k]], np.zeros(net.n_free - k)])
            cap = self.group_sums(loose, label, net.C)
            shift = (self.group_sums(loose, label, net.C * T0) - self.group_sums(loose, label, net.C * T_F)) / cap
            inside = np.isin(label, loose)  # (a dipole's moment does not move with a uniform change)
            T_F[inside] += shift[np.searchsorted(loose, label[inside])] * uniform_level(net.net)[net.free][inside]
        T_F = self.halo_filled(T_F)[net.free]
        flows = self.flows(T_F, sinks)
        total = self.flow_magnitude(T_F, sinks)
        return T_F, flows, abs(sum(flows.values())) / total if total > 0 else 0.0, solver_name
