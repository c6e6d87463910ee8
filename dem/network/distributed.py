"""The heat network of a packing shared out among MPI ranks: each rank's rows, the groups that span ranks, the steady
solve and the theta-method steps, all on PETSc (:mod:`dem.parallel.petsc`); the steps are the serial loop
(:func:`dem.network.heat.integrate`) with this rank's part of the network (its sums and flows over the ranks) and the
solve over the ranks (:class:`RankSolves`) plugged in.

Each rank holds the particles it owns and a halo (:mod:`dem.geometry.bisection`), and a
:class:`dem.network.heat.Network` of them whose bonds are those with at least one owned particle. An owned particle
has all its bonds there, in the order of the serial run's (both sorted by particle index), so its row of the matrix,
its boundary terms and its right-hand side are those of the serial network to the bit; the halo's rows are
incomplete and never used. The unknowns are numbered rank after rank, each rank's in the order of its particles.

Groups of free particles (:meth:`DistributedNetwork.groups`) are the connected components of the graph over all
ranks: each rank labels its local components with their smallest particle index, passes the labels of its owned
particles to the ranks that hold them as halo, and takes the smallest label in each local component again, until no
label changes anywhere. Anchored, gauged (periodic) and floating groups are then treated as the serial
:func:`dem.network.heat.steady` treats them: a floating group at its capacity-weighted mean temperature, a gauged
one solved with its first particle at 0 and shifted to keep its mean.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from dem.parallel import comm as mpi
from dem.network.heat import Network, TransientResult, integrate, surely_stiff
from dem.network.theta import balancing_shift
from dem.parallel.petsc import PetscSolver, matrix


@dataclass
class Groups:
    """The groups of free particles over all ranks: ``label`` per local free particle (the smallest particle index
    of its group), and the labels of the groups that are ``anchored``, ``jumping`` (a periodic temperature jump)
    and ``floating`` (neither), each sorted.

    Parameters
    ----------
    label : numpy.ndarray
        Per local free particle, its group's label (the smallest global particle index in it).
    anchored : numpy.ndarray
        Labels of the groups joined to a fixed temperature, a wall or an ambient.
    jumping : numpy.ndarray
        Labels of the groups with a periodic temperature jump that are not anchored.
    floating : numpy.ndarray
        Labels of the other groups.
    """

    label: np.ndarray
    anchored: np.ndarray
    jumping: np.ndarray
    floating: np.ndarray

    def member(self, labels: np.ndarray) -> np.ndarray:
        """Mask over the local free particles: in one of the groups ``labels``.

        Parameters
        ----------
        labels : numpy.ndarray
            Group labels.

        Returns
        -------
        numpy.ndarray
            Bool per local free particle.
        """
        return np.isin(self.label, labels)


class RankSolves:
    r"""The linear solves of :math:`\theta` steps over the ranks (:mod:`dem.network.theta`'s plug-in): every rank's owned rows
    of the step's system on PETSc (:class:`dem.parallel.petsc.PetscSolver`, CG + AMG), the halo's temperatures from
    their owners, and the uniform shift that makes the residuals summed over the ranks vanish
    (:func:`dem.network.theta.balancing_shift`). :meth:`release` frees the solvers built.

    Parameters
    ----------
    part : DistributedNetwork
        This rank's part of the network.
    rtol : float
        The relative residual of the solves.
    """

    #: CG on PETSc starts from the step's start temperatures (:meth:`dem.network.theta.ThetaStepper.guess`).
    extrapolated_starts = False

    def __init__(self, part: "DistributedNetwork", rtol: float):
        self.part, self.rtol = part, rtol
        self.row, self.n_global = part.numbering(np.ones(len(part.net.free), dtype=bool))
        self.built: list = []  # the systems built, in order

    @staticmethod
    def everything_fixed(net) -> bool:
        """False: a rank with no free particle still takes part in the others' solves.

        Parameters
        ----------
        net : dem.network.heat.Network
            This rank's network.

        Returns
        -------
        bool
            False.
        """
        return False

    def build(self, M: sp.csr_matrix, laplacian_diagonal: np.ndarray, previous=None) -> "_RankSystem":
        r"""The solver of the step's system ``M`` over the ranks (``laplacian_diagonal`` and ``previous`` unused: the
        preconditioner is PETSc's).

        Parameters
        ----------
        M : scipy.sparse.csr_matrix
            :math:`C/\Delta t + \theta A` over the local free particles (W/K).
        laplacian_diagonal : numpy.ndarray
            Unused.
        previous : object or None
            Unused.

        Returns
        -------
        object
            The system and its solver (private to this module).
        """
        system = _RankSystem(M, self.part.solver(M, self.row, self.n_global, self.rtol))
        self.built.append(system)
        return system

    def solve(self, system: "_RankSystem", rhs: np.ndarray, guess: np.ndarray) -> np.ndarray:
        """The step's temperatures of the local free particles (owned ones solved, the halo's from their owners),
        balanced over the ranks.

        Parameters
        ----------
        system : object
            A system of :meth:`build`.
        rhs : numpy.ndarray
            The right-hand side per local free particle (W; owned entries used).
        guess : numpy.ndarray
            The start of CG per local free particle (K or degC; owned entries used).

        Returns
        -------
        numpy.ndarray
            The free temperatures after the step.
        """
        own, M = self.part.own_free, system.M
        T_new = guess.copy()
        T_new[own] = system.solver.solve(rhs[own], guess[own])
        T_new = self.part.halo_filled(T_new)[self.part.net.free]
        residual, weight = self.part.total(np.array([float(np.sum((rhs - M @ T_new)[own])), float(M[own].sum())]))
        T_new += balancing_shift(residual, weight)
        return T_new

    @property
    def iterations(self) -> int:
        """The CG iterations of all solves so far."""
        return sum(system.solver.iterations for system in self.built)

    def release(self) -> None:
        """Free the PETSc solvers built (:meth:`dem.parallel.petsc.PetscSolver.destroy`)."""
        for system in self.built:
            system.solver.destroy()


@dataclass
class _RankSystem:
    """A step's system over the local free particles (``M``, W/K) and its PETSc solver over the ranks."""

    M: sp.csr_matrix
    solver: PetscSolver

    @property
    def name(self) -> str:
        """The solver's name (``petsc-cg-...``)."""
        return self.solver.name


class DistributedNetwork:
    """This rank's part of the network (module docstring). ``net``: the
    :class:`~dem.network.heat.Network` of the held particles,
    ``held`` their global indices (sorted), ``owner`` the rank owning each of them.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    net : dem.network.heat.Network
        The network of the particles this rank holds.
    held : numpy.ndarray
        Global indices of the held particles, sorted.
    owner : numpy.ndarray
        The rank owning each held particle.
    exchange : dem.parallel.comm.HaloExchange or None
        What brings the halo's values from their owners (:meth:`fill`); None: that of all held particles.
    """

    def __init__(self, comm, net: Network, held: np.ndarray, owner: np.ndarray, exchange=None):
        self.comm, self.net, self.held = comm, net, held
        self.rank, self.size = comm.Get_rank(), comm.Get_size()
        self.mine = owner == self.rank  # over the held particles
        self.own_free = self.mine[net.free]  # over the local free particles
        self.exchange = mpi.HaloExchange(comm, held, owner) if exchange is None else exchange
        self.linear_iterations = 0

    # ------------------------------------------------------------------------------------------- reductions
    def total(self, value):
        """Sum over ranks (:func:`dem.parallel.comm.total`).

        Parameters
        ----------
        value : float or array_like
            This rank's part.

        Returns
        -------
        float or numpy.ndarray
            The sum.
        """
        return mpi.total(self.comm, value)

    def maximum(self, value: float) -> float:
        """Largest over ranks (:func:`dem.parallel.comm.maximum`).

        Parameters
        ----------
        value : float
            This rank's value.

        Returns
        -------
        float
            The largest.
        """
        return mpi.maximum(self.comm, value)

    def minimum(self, value: float) -> float:
        """Smallest over ranks (:func:`dem.parallel.comm.minimum`).

        Parameters
        ----------
        value : float
            This rank's value.

        Returns
        -------
        float
            The smallest.
        """
        return mpi.minimum(self.comm, value)

    def agree(self, action):
        """``action()`` on every rank, a ValueError on one raised on all (:func:`dem.parallel.comm.agree`).

        Parameters
        ----------
        action : callable
            Called without arguments.

        Returns
        -------
        object
            This rank's result.
        """
        return mpi.agree(self.comm, action)

    def above_stable_limit(self, dt: float, T_F: np.ndarray) -> bool:
        """Whether a fixed step ``dt`` is surely above the stable limit at ``T_F``, over the ranks without an
        eigenvalue solve (:func:`dem.network.heat.surely_stiff` on the owned rows): where a Crank-Nicolson run starts
        with implicit Euler steps (:func:`dem.network.heat.integrate`).

        Parameters
        ----------
        dt : float
            The step (s).
        T_F : numpy.ndarray
            Temperatures of the local free particles (K or degC), where the ambient terms are linearised.

        Returns
        -------
        bool
            ``dt`` is surely above the limit.
        """
        return surely_stiff(dt, self.net.matrix(self.net.sinks(T_F)), self.net.C, self.own_free, self.maximum)

    def fill(self, values: np.ndarray) -> np.ndarray:
        """``values`` over the held nodes (owned entries valid) with the halo's entries set from their owners
        (:meth:`dem.parallel.comm.HaloExchange.fill`).

        Parameters
        ----------
        values : numpy.ndarray
            One value per held node (any unit), changed in place.

        Returns
        -------
        numpy.ndarray
            ``values``.
        """
        return self.exchange.fill(values)

    def held_values(self, T_F: np.ndarray) -> np.ndarray:
        """The temperatures of all held nodes from those of the local free ones (fixed ones their own), before the
        halo's are brought from their owners.

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free nodes (K or degC).

        Returns
        -------
        numpy.ndarray
            Temperatures of all held nodes (K or degC).
        """
        return self.net.full(T_F)

    def halo_filled(self, T_F: np.ndarray) -> np.ndarray:
        """All held temperatures (fixed ones too) from the owned entries of ``T_F`` (over the local free ones).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free particles (owned entries valid; K or degC).

        Returns
        -------
        numpy.ndarray
            Temperatures of all held particles, the halo's from their owners.
        """
        return self.fill(self.held_values(T_F))

    def flows(self, T_F: np.ndarray, sinks: dict) -> dict:
        """Heat flow (W) into all free particles through each boundary
        (:meth:`~dem.network.heat.Network.flows` over the ranks).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free particles (owned entries valid; K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`dem.network.heat.Network.sinks`): W/K and W per particle.

        Returns
        -------
        dict
            ``{boundary: W}``, summed over the ranks.
        """
        part = self.net.flows(T_F, sinks, self.own_free)
        sums = self.total(np.array(list(part.values())))
        return dict(zip(part, map(float, sums)))

    def flow_magnitude(self, T_F: np.ndarray, sinks: dict) -> float:
        r"""The scale of the heat flows over the ranks: the net flow, at least :math:`\sqrt{\epsilon}` times the gross one (W).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the local free particles (owned entries valid; K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`dem.network.heat.Network.sinks`): W/K and W per particle.

        Returns
        -------
        float
            The scale (W).
        """
        net, gross = self.total(np.array(self.net.flow_sums(T_F, sinks, self.own_free)))
        return float(max(net, np.sqrt(np.finfo(float).eps) * gross))

    # ------------------------------------------------------------------------------------------ numbering
    def numbering(self, unknown: np.ndarray) -> tuple[np.ndarray, int]:
        """Global row of every local free particle in ``unknown`` (a mask over them; -1 elsewhere), rank after rank,
        and the global count. The halo's rows come from their owners.

        Parameters
        ----------
        unknown : numpy.ndarray
            Bool per local free particle: an unknown of the system.

        Returns
        -------
        tuple of (numpy.ndarray, int)
            The global rows and the global count.
        """
        mine = unknown & self.own_free
        count = int(mine.sum())
        offset = self.comm.exscan(count) or 0  # None on rank 0
        n_global = self.total(count)
        row = np.full(len(self.net.free), -1.0)
        row[mine] = offset + np.arange(count)
        held = np.full(len(self.held), -1.0)
        held[self.net.free] = row
        self.fill(held)
        return held[self.net.free].astype(np.int64), n_global

    def rows(self, M: sp.csr_matrix, row: np.ndarray) -> sp.csr_matrix:
        """The owned rows of ``M`` (over the local free particles) among the unknowns numbered ``row``, with their
        columns numbered globally (sorted).

        Parameters
        ----------
        M : scipy.sparse.csr_matrix
            The system matrix over the local free particles (W/K).
        row : numpy.ndarray
            The global row of each local free particle, -1 where it is no unknown (:meth:`numbering`).

        Returns
        -------
        scipy.sparse.csr_matrix
            This rank's rows, columns numbered globally.
        """
        take = np.flatnonzero(self.own_free & (row >= 0))
        cols = np.flatnonzero(row >= 0)
        local = M[take][:, cols].tocsr()
        out = sp.csr_matrix((local.data, row[cols][local.indices], local.indptr), shape=(len(take), len(cols)))
        out.has_sorted_indices = False
        out.sort_indices()
        return out

    def solver(self, M: sp.csr_matrix, row: np.ndarray, n_global: int, rtol: float) -> PetscSolver:
        """CG + AMG on the unknowns numbered ``row`` of the system ``M`` (over the local free particles).

        Parameters
        ----------
        M : scipy.sparse.csr_matrix
            The system matrix over the local free particles (W/K).
        row : numpy.ndarray
            The global row of each local free particle, -1 where it is no unknown (:meth:`numbering`).
        n_global : int
            The global count of unknowns.
        rtol : float
            The relative residual at which CG stops.

        Returns
        -------
        dem.parallel.petsc.PetscSolver
            The solver.
        """
        return PetscSolver(matrix(self.comm, self.rows(M, row), n_global), rtol)

    # --------------------------------------------------------------------------------------------- groups
    def groups(self, anchor: np.ndarray) -> Groups:
        """The groups over all ranks (module docstring); ``anchor`` (per local free particle) > 0 where a particle
        is joined to a fixed one, a wall or an ambient.

        Parameters
        ----------
        anchor : numpy.ndarray
            Per local free particle, its conductance to fixed particles, walls and ambients (W/K).

        Returns
        -------
        Groups
            The groups.
        """
        net, n_free = self.net, len(self.net.free)
        g = net.graph
        where = np.full(net.particles.n, -1, dtype=np.int64)
        where[net.free] = np.arange(n_free)
        a, b = where[g.i], where[g.j]
        live = (g.K > 0.0) & (a >= 0) & (b >= 0)
        label = self.components(a[live], b[live], self.held[net.free])
        own = self.own_free
        anchored = self._union(label[own & (anchor > 0)])
        jumping = np.zeros(0, dtype=np.int64)
        if net.periodic:
            position = np.full(net.particles.n, -1)
            position[net.free] = np.arange(n_free)
            free_i = position[net.bonds.i[(net.jump != 0.0) & self.mine[net.bonds.i]]]
            jumping = self._union(label[free_i[free_i >= 0]])
        others = self._union(label[own])
        floating = np.setdiff1d(others, np.union1d(anchored, jumping))
        return Groups(label, anchored, np.setdiff1d(jumping, anchored), floating)

    def components(self, a: np.ndarray, b: np.ndarray, start: np.ndarray) -> np.ndarray:
        """The connected components of the graph over all ranks (module docstring): per local free node, the
        smallest of ``start`` over its component. The edges ``(a, b)`` (local free nodes) must hold every edge of an
        owned node; the others may be missing.

        Parameters
        ----------
        a, b : numpy.ndarray
            The two local free nodes of each edge.
        start : numpy.ndarray
            Per local free node, its own label (a global number, distinct over the ranks; owned entries valid).

        Returns
        -------
        numpy.ndarray
            Per local free node, its component's label (int).
        """
        net, n_free = self.net, len(self.net.free)
        graph = sp.csr_matrix((np.ones(len(a)), (a, b)), shape=(n_free, n_free))
        n_comp, comp = connected_components(graph, directed=False)
        label = np.asarray(start, dtype=float)
        while True:
            smallest = np.full(n_comp, np.inf)
            np.minimum.at(smallest, comp, label)
            new = smallest[comp]
            held = np.full(len(self.held), -1.0)
            held[net.free] = new
            new = self.fill(held)[net.free]
            changed = self.total(int(np.any(new != label)))
            label = new
            if not changed:
                break
        return label.astype(np.int64)

    def _union(self, labels: np.ndarray) -> np.ndarray:
        """The labels found on any rank, sorted and once each."""
        parts = self.comm.allgather(np.unique(labels))
        return np.unique(np.concatenate(parts)) if parts else np.zeros(0, dtype=np.int64)

    def group_sums(self, labels: np.ndarray, group: np.ndarray, values: np.ndarray) -> np.ndarray:
        """Per group of ``labels`` (sorted): the sum of ``values`` over its owned members (``group`` per local free
        particle, the groups' labels).

        Parameters
        ----------
        labels : numpy.ndarray
            The groups' labels, sorted.
        group : numpy.ndarray
            The group label of each local free particle.
        values : numpy.ndarray
            One value per local free particle (any unit).

        Returns
        -------
        numpy.ndarray
            The sums per group, over the ranks.
        """
        inside = self.own_free & np.isin(group, labels)
        where = np.searchsorted(labels, group[inside])
        return self.total(np.bincount(where, values[inside], len(labels)))

    # --------------------------------------------------------------------------------------------- steady
    def steady(self, floating: str = "error", rtol: float = 1e-10):
        """Steady temperatures of the free particles (this rank's entries: over the local free ones, owned ones
        valid): :func:`dem.network.heat.steady` over the ranks, without radiation. Returns ``(T_F, flows,
        energy_error, floating groups, solver name)``.

        Parameters
        ----------
        floating : str
            ``"error"`` (refuse a floating group) or ``"mean"`` (keep it at its capacity-weighted mean).
        rtol : float
            The relative residual of the linear solves.

        Returns
        -------
        tuple
            ``(T_F, flows, energy_error, floating groups, solver name)``.

        Raises
        ------
        ValueError
            A floating group with ``floating = "error"``, or one whose sources do not sum to zero.
        """
        net = self.net
        T_F = net.particles.temperature[net.free].astype(float)
        sinks = net.sinks(T_F)
        extra = sum((gs for gs, _ in sinks.values()), np.zeros(len(T_F)))
        anchor = net.fixed_diag + net.wall_diag + extra
        G = self.groups(anchor)
        n_groups = len(self._union(G.label[self.own_free]))
        gauged_labels = G.jumping

        def no_solution(labels):
            heat = self.group_sums(labels, G.label, net.heat)
            scale = self.group_sums(labels, G.label, np.abs(net.heat))
            if np.any(np.abs(heat) > 1e-12 * np.maximum(scale, 1e-300)):
                raise ValueError("steady problem has no solution: a floating group of particles (no fixed "
                                 "temperature, wall or ambient) has a net internal heat source, so it heats up "
                                 "forever")

        n_float = len(G.floating)
        if n_float:
            lost = G.member(G.floating)
            if floating == "error":
                count = self.total(int(np.sum(lost & self.own_free)))
                first = sorted(np.concatenate(self.comm.allgather(self.held[net.free][lost & self.own_free][:8])))
                raise ValueError(f"steady problem is singular: {n_float} of {n_groups} connected group(s) of free "
                                 f"particles ({count} particles, e.g. {[int(k) for k in first[:8]]}) touch no fixed "
                                 f"particle, wall, convection or radiation, so their temperature is undetermined; fix "
                                 f"a particle's temperature, add a wall or an ambient, set solver.floating = "
                                 f"\"mean\", or use mode = \"transient\"")
            no_solution(G.floating)
            energy = self.group_sums(G.floating, G.label, net.C * T_F)
            cap = self.group_sums(G.floating, G.label, net.C)
            where = np.searchsorted(G.floating, G.label[lost])
            T_F[lost] = energy[where] / cap[where]
        ground = np.zeros(len(T_F), dtype=bool)
        if len(gauged_labels):
            no_solution(gauged_labels)
            ground = G.label == self.held[net.free]  # a gauged group's first particle holds it at 0
            ground &= G.member(gauged_labels)
            target = self.group_sums(gauged_labels, G.label, net.C * T_F)
            T_F[ground] = 0.0
        unknown = (G.member(G.anchored) | G.member(gauged_labels)) & ~ground
        row, n_global = self.numbering(unknown)
        solver_name = "none"
        if n_global:
            A = net.matrix(sinks)
            solver = self.solver(A, row, n_global, rtol)
            solver_name = solver.name
            take = self.own_free & unknown
            try:
                T_F[take] = solver.solve(net.rhs(sinks)[take], T_F[take])
            finally:
                solver.destroy()
            self.linear_iterations += solver.iterations
        if len(gauged_labels):
            cap = self.group_sums(gauged_labels, G.label, net.C)
            shift = (target - self.group_sums(gauged_labels, G.label, net.C * T_F)) / cap
            inside = G.member(gauged_labels)
            T_F[inside] += shift[np.searchsorted(gauged_labels, G.label[inside])]
        T_F = self.halo_filled(T_F)[net.free]
        flows = self.flows(T_F, sinks)
        total = self.flow_magnitude(T_F, sinks)
        err = abs(sum(flows.values())) / total if total > 0 else 0.0
        return T_F, flows, err, n_float, solver_name

    # ------------------------------------------------------------------------------------------ transient
    def integrate(self, integrator: str, dt: float, t_end: float, rtol_linear: float = 1e-10, observer=None,
                  progress=None) -> TransientResult:
        """Theta-method steps of fixed size ``dt`` to ``t_end``: the serial loop (:func:`dem.network.heat.integrate`)
        with this part and the solves over the ranks (:class:`RankSolves`) plugged in; ``observer(step, t, T_F,
        flows)`` after every step and at the start, with this rank's local free temperatures.

        Parameters
        ----------
        integrator : str
            ``"implicit"`` or ``"crank-nicolson"`` (``dem.network.heat.INTEGRATORS``).
        dt : float
            The step (s).
        t_end : float
            The time to integrate to (s).
        rtol_linear : float
            The relative residual of the linear solves.
        observer : callable or None
            ``observer(step, t, T_F, flows)``; None: not called.
        progress : callable or None
            ``progress(t)`` with the simulated time (s) after every step; None: not called.

        Returns
        -------
        dem.network.heat.TransientResult
            What the serial integrator reports, ``T`` the held particles' temperatures (owned ones valid).

        Raises
        ------
        ValueError
            An integrator other than implicit or Crank-Nicolson, a step that is not a number, or temperatures that
            came out wrong as the serial integrator refuses them: on every rank alike.
        """
        if integrator not in ("implicit", "crank-nicolson") or isinstance(dt, str):
            raise ValueError(f"solver.integrator = {integrator!r}, dt = {dt!r}: on MPI ranks only fixed steps (s) of "
                             f"\"implicit\" or \"crank-nicolson\"")
        solves = RankSolves(self, rtol_linear)
        try:  # the PETSc solvers freed however the steps end (PetscSolver.destroy)
            return integrate(self.net, integrator, dt, t_end, observer=observer, progress=progress, part=self,
                             solves=solves)
        finally:
            self.linear_iterations = solves.iterations
            solves.release()
