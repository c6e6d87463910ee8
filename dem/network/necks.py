r"""The heat network with a node per neck: each particle an element joining its centre to its necks.

``[conductance] nodes = "necks"`` (:class:`dem.laws.conductance.ConductanceSpec`) solves the ``shared-body`` law's
particle model exactly instead of reducing it to one factor per neck on one node per particle
(:mod:`dem.laws.shared_body`).

**The element.** A particle with ``z`` necks is a ``(z + 1)``-terminal element: its centre node (the particle's
temperature :math:`T_c`, which holds its heat capacity) and one node per neck. With ``R`` the particle's
multi-terminal resistance (flows :math:`Q` into the particle through its necks raise neck ``b`` to
:math:`T_b - T_c = \sum_c R_{bc} Q_c`: the cut-body halves :math:`1/K_b` on the diagonal, the sphere's Neumann function
between necks, its free-space part taken between the necks' faces), :math:`Q = R^{-1} (T_\mathrm{necks} - T_c
\mathbf 1)` and the centre takes :math:`-\sum Q`: the element's conductance matrix is

.. math::

    E = \begin{pmatrix} R^{-1} & -R^{-1} \mathbf 1 \\ -\mathbf 1^T R^{-1} & \mathbf 1^T R^{-1} \mathbf 1
    \end{pmatrix},

symmetric, positive semidefinite (``R`` is positive definite: :func:`dem.laws.shared_body.particle_elements` drops the
interactions of a particle where it is not), its rows summing to zero. The law's trace cap scales ``E`` as it scales a
particle's factors today: where the trace of the particle's tensor :math:`N^T Y N` (``Y`` the Schur complement of ``E``
on the necks, :math:`N_b = l_b n_b`) exceeds :math:`3 \kappa V_k`. A neck node is shared by the two particles of its
bond; a wall bond's neck sits at the wall (its node is the wall's temperature). A particle whose necks are collinear
(a pair, a chain) has ``R`` diagonal: its halves from the centre to each neck, the bonds' halves in series -- today's
network, to round-off.

**Assembly.** The unknowns are the particles' centres first (``0 .. n-1``), then the live pair bonds' necks
(``n + b``; a neck hidden inside a third sphere has a half conductance 0 and no node). The elements' entries are
computed per particle in one compiled loop (:func:`dem.laws.shared_body.particle_elements`), placed by index arithmetic
(numpy, no Python loop over particles) and summed into one CSR matrix ``A`` (COO to CSR). Each element sees every
node at its own offset ``o``: a bond to the image of ``j`` across a periodic face (``shift``) has its neck node in the
frame of ``i``, and ``j``'s element sees it at :math:`T_b + g`, :math:`g = \mathrm{drop} \cdot \mathrm{shift}` (the
mean gradient's jump, as :mod:`dem.network.heat` gives a bond), so the element adds :math:`-E o` to the right-hand
side. A wall's neck is a known value: its column moves to the right-hand side (:math:`-E_{pw} T_w`). Fixed particles
(Dirichlet layers) are fixed centre nodes; their necks stay free. A group of nodes that reaches no fixed node or wall
(a periodic box) is solved with one node held at 0, then shifted so that the capacity-weighted mean of its particles'
temperatures is their initial one (the long-time limit; neck nodes are massless). The heat flow across the period is
:math:`\sum_b q_b \, \mathrm{shift}_b` over the necks' flows :math:`q_b` from ``i`` to ``j``, and :math:`k_\mathrm{eff}`
follows as in the one-node network. The solve is :func:`dem.network.linsolve.make_solver` (direct on small networks,
AMG-CG on large): ``A`` is SPD on the anchored groups, though not an M-matrix (``R^{-1}`` may couple two necks with a
positive entry).

**Transient.** Neck nodes hold no heat: the capacity matrix is :math:`M = \mathrm{diag}(C_1 \dots C_n, 0 \dots 0)`,
only semidefinite. The :math:`\theta` scheme :math:`(M/\Delta t + \theta A) T^+ = (M/\Delta t - (1 - \theta) A) T + r`
stays well-posed for :math:`\theta > 0`: :math:`M/\Delta t + \theta A` is SPD on every anchored group and on a group
with a particle (any group: a neck node always has two particles), since :math:`x^T (M/\Delta t + \theta A) x = 0`
needs :math:`x` constant on the group (:math:`A` is a Laplacian-like matrix whose kernel on a connected group is the
constants) and zero on its centres. The neck rows are algebraic constraints (a differential-algebraic system of index
1) that the step holds at :math:`\theta T^+ + (1 - \theta) T`; eliminating them there gives the same scheme on the
condensed matrix :math:`A_{cc} - A_{cn} A_{nn}^{-1} A_{nc}` of the centres, so a chain (collinear necks: the condensed
matrix is the halves in series) steps as today's network. :class:`NeckHeat` hands :func:`dem.network.heat.integrate`
these matrices (its :math:`\theta` scheme, step control, energy bookkeeping and checkpoints are the one of the
particle network); the necks start where their rows hold at the initial temperatures, which Crank-Nicolson then keeps
(it would carry an inconsistent start on, alternating). An explicit step (:math:`\theta = 0`) cannot invert :math:`M`
and is refused: it would have to condense the necks every step (a sparse solve on them, what an implicit step costs,
without its stability), under the stable limit of the condensed matrix, which :func:`dem.network.heat.stable_limit`
computes (it decides Crank-Nicolson's implicit start-up).

**MPI (not yet implemented).** A neck node is owned by the lower of the two ranks that own its particles; the other
rank holds it as a ghost (like a particle across the cut), and the element of a particle is assembled by the rank that
owns the particle, its rows for a ghost neck sent to the neck's owner (the same exchange the distributed Laplacian
makes for its halo rows, :mod:`dem.network.distributed`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from dem.geometry.bonds import Bonds
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.laws.ambient import Sources
from dem.laws.conductance import ConductanceSpec, bond_halves, union_halves, wall_normals
from dem.network.linsolve import make_solver


@dataclass
class NeckNetwork:
    """The assembled network with a node per neck (module docstring).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (temperatures: the fixed ones' values and the initial ones; capacities; heat sources, W).
    bonds : dem.geometry.bonds.Bonds
        All pair and wall bonds.
    live : numpy.ndarray
        Indices of the pair bonds that have a neck node (node ``n + k`` for ``live[k]``).
    live_walls : numpy.ndarray
        Indices of the wall bonds that carry heat.
    A : scipy.sparse.csr_matrix
        The matrix over all nodes, centres then necks (W/K), the walls' columns moved to the right-hand side.
    rhs : numpy.ndarray
        The right-hand side over all nodes from the periodic offsets, the walls and the sources (W).
    entries : tuple
        ``(row, col, value, known, end)`` of every element entry: its row and column nodes (``-1``: a wall's
        neck), its value (W/K), the offset or wall temperature its column is seen at (K), and the bond end of
        its row (``-1``: the centre), from which :meth:`end_flows` sums the flows.
    n_ends : int
        The number of bond ends (twice the live pair bonds and the live wall bonds).
    plain : int
        The number of particles whose interactions were dropped (``R`` not positive definite).
    jump : numpy.ndarray
        Per live pair bond, the temperature drop its ``j`` sees across the periodic faces (K; 0 without a box).
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    union : tuple or None
        The ``shared-body`` halves on the cut spheres the elements are made of (what
        :func:`dem.laws.conductance.union_halves` returned), from which the one-node law's conductances follow without
        computing them again (``union`` of :func:`dem.laws.conductance.bond_conductances`).
    """

    particles: Particles
    bonds: Bonds
    live: np.ndarray
    live_walls: np.ndarray
    A: sp.csr_matrix
    rhs: np.ndarray
    entries: tuple
    n_ends: int
    plain: int
    jump: np.ndarray
    box: PeriodicBox | None = None
    union: tuple | None = None

    @property
    def n_nodes(self) -> int:
        """Centres and neck nodes."""
        return self.A.shape[0]

    def end_flows(self, T: np.ndarray) -> np.ndarray:
        """The heat flowing into each particle through each of its neck ends (W) at node temperatures ``T``: end
        ``k < m`` is live pair bond ``k`` on its ``i``, ``m <= k < 2 m`` the same on its ``j``, the rest the live wall
        bonds (``m`` live pair bonds).

        Parameters
        ----------
        T : numpy.ndarray
            The temperatures of all nodes, centres then necks (K or degC).

        Returns
        -------
        numpy.ndarray
            W per end.
        """
        row, col, value, known, end = self.entries
        seen = known + np.where(col >= 0, T[np.maximum(col, 0)], 0.0)
        at = end >= 0
        return np.bincount(end[at], value[at] * seen[at], self.n_ends)


def neck_network(spec: ConductanceSpec, particles: Particles, bonds: Bonds, *, box: PeriodicBox | None = None,
                 walls=(), closing_pores: dict | None = None) -> NeckNetwork:
    """Assemble the network with a node per neck (module docstring) of the ``shared-body`` law under the union of
    spheres.

    Parameters
    ----------
    spec : dem.laws.conductance.ConductanceSpec
        The law (``shared-body``, ``neck = "union"``).
    particles : dem.geometry.particles.Particles
        The particles.
    bonds : dem.geometry.bonds.Bonds
        The union bonds.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    walls : sequence of dem.geometry.walls.Wall
        The walls the wall bonds index (their normals and temperatures).
    closing_pores : dict or None
        The closing pores' calibration (:func:`dem.laws.conductance.bond_conductances`); None: the shipped one.

    Returns
    -------
    NeckNetwork
        The assembled network.

    Raises
    ------
    ValueError
        ``spec`` is not the ``shared-body`` law under the union of spheres, or wall bonds without their walls.
    """
    from dem.laws.shared_body import particle_elements

    if spec.law != "shared-body" or spec.neck != "union" or spec.contact_conductance is not None:
        raise ValueError(f"conductance.nodes = \"necks\": only with law = \"shared-body\", neck = \"union\" and no "
                         f"contact_conductance (here law = {spec.law!r}, neck = {spec.neck!r})")
    n, r = particles.n, particles.radius
    kappa = particles.conductivity
    k_i, k_j, k_w = bond_halves(spec, particles, bonds, kappa)
    normals = wall_normals(bonds, walls)
    vectors = bonds.vectors(particles.position, box)
    union = union_halves(particles, bonds, vectors, normals, kappa, k_i, k_j, k_w, closing_pores, box, walls)
    k_i, k_j, k_w, pairs, live_walls, volume = union
    live, live_walls = np.flatnonzero(pairs), np.flatnonzero(live_walls)
    sub = bonds.subset(live, live_walls)
    el = particle_elements(n, r, sub, vectors[live], k_i[live], k_j[live], k_w[live_walls], kappa,
                           np.reshape(normals, (-1, 3))[live_walls], volume)
    m = len(live)
    # each end's node (a wall's: -1) and the offset it is seen at by its particle (a wall's: its temperature)
    jump = sub.shifts @ box.drop if box is not None else np.zeros(m)
    wall_T = np.array([w.temperature for w in walls], dtype=float)[sub.wall_index] if len(live_walls) else np.zeros(0)
    # (one more place at the end of each: the centre, end -1, seen at offset 0)
    node = np.concatenate([n + np.arange(m), n + np.arange(m), np.full(len(live_walls), -1), [0]])
    offset = np.concatenate([np.zeros(m), jump, wall_T, [0.0]])
    ends = np.append(el.ends, -1)
    # the entries: particle k's block is (z + 1)^2 values row by row, local node p < z its p-th end, z its centre
    z = np.diff(el.offsets)
    size = z + 1
    owner = np.repeat(np.arange(n), size * size)
    local = np.arange(len(el.values)) - el.start[:-1][owner]
    p_row, p_col = local // size[owner], local % size[owner]
    first = el.offsets[:-1][owner]
    end_row = ends[np.where(p_row == z[owner], len(el.ends), first + p_row)]
    end_col = ends[np.where(p_col == z[owner], len(el.ends), first + p_col)]
    row = np.where(end_row < 0, owner, node[end_row])
    col = np.where(end_col < 0, owner, node[end_col])
    known = offset[end_col]
    value = el.values
    inner, rows = (row >= 0) & (col >= 0), row >= 0  # a wall's row has no equation: the wall takes what it is given
    size_all = n + m
    A = sp.coo_matrix((value[inner], (row[inner], col[inner])), shape=(size_all, size_all)).tocsr()
    A = 0.5 * (A + A.T)  # symmetric to round-off (the blocks are; their sums need not be bit for bit)
    rhs = -np.bincount(row[rows], value[rows] * known[rows], size_all)
    rhs[:n] += particles.heat
    return NeckNetwork(particles, bonds, live, live_walls, A.tocsr(), rhs, (row, col, value, known, end_row),
                       2 * m + len(live_walls), int(np.count_nonzero(el.plain)), jump, box, union)


@dataclass
class NeckSteady:
    """What :func:`steady_necks` found.

    Parameters
    ----------
    T : numpy.ndarray
        (N,) the particles' (centres') temperatures (K or degC).
    T_necks : numpy.ndarray
        The live pair bonds' neck temperatures, in the frame of each bond's ``i`` (K or degC).
    bond_flow : numpy.ndarray
        Per pair bond (all of them), the heat flowing from ``i`` to ``j`` through its neck (W; 0 for a dead one).
    wall_flow : numpy.ndarray
        Per wall bond (all of them), the heat flowing from its particle into the wall (W).
    fixed_flow : numpy.ndarray
        Per particle, the heat its fixed temperature feeds into the network (W; 0 for a free particle).
    periodic_heat_flow : numpy.ndarray
        (3,) the heat flow across the period along x, y, z (W).
    energy_error : float
        The heat balance's mismatch relative to the flows through the boundaries.
    solver : str
        The linear solver that ran.
    """

    T: np.ndarray
    T_necks: np.ndarray
    bond_flow: np.ndarray
    wall_flow: np.ndarray
    fixed_flow: np.ndarray
    periodic_heat_flow: np.ndarray
    energy_error: float
    solver: str


def steady_necks(net: NeckNetwork, floating: str = "mean", linear: str = "auto", rtol: float = 1e-12) -> NeckSteady:
    """The steady temperatures of the network with a node per neck (module docstring).

    Parameters
    ----------
    net : NeckNetwork
        The network.
    floating : str
        What a group of particles that reaches no fixed temperature or wall and holds no bond across a periodic face
        with a temperature drop does: ``"mean"`` keeps it at its particles' capacity-weighted mean initial
        temperature, ``"error"`` refuses (as :func:`dem.network.heat.steady`).
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol : float
        The relative residual of iterative linear solves.

    Returns
    -------
    NeckSteady
        Temperatures and flows.

    Raises
    ------
    ValueError
        A group of particles that reaches no fixed temperature or wall has a net heat source, or floats with
        ``floating = "error"``; a bad ``floating``.
    """
    if floating not in ("mean", "error"):
        raise ValueError(f"solver.floating = {floating!r}: must be error or mean")
    p = net.particles
    n, N = p.n, net.n_nodes
    fixed = np.zeros(N, dtype=bool)
    fixed[:n] = p.fixed
    T = np.zeros(N)
    T[:n] = p.temperature
    # the groups: anchored where they hold a fixed node or a wall's neck
    row, col = net.entries[0], net.entries[1]
    n_comp, label = connected_components(net.A, directed=False)
    anchored = np.zeros(n_comp, dtype=bool)
    anchored[label[fixed]] = True
    anchored[label[row[(col < 0) & (row >= 0)]]] = True
    heat = np.bincount(label[:n], p.heat, n_comp)
    if np.any(~anchored & (np.abs(heat) > 1e-12 * np.maximum(np.bincount(label[:n], np.abs(p.heat), n_comp), 1e-300))):
        raise ValueError("steady problem has no solution: a floating group of particles (no fixed temperature or "
                         "wall) has a net internal heat source, so it heats up forever")
    jumping = np.zeros(n_comp, dtype=bool)
    jumping[label[n + np.flatnonzero(net.jump != 0.0)]] = True
    lost = ~anchored & ~jumping
    if floating == "error" and np.any(lost):
        first = np.flatnonzero(lost[label[:n]])[:8].tolist()
        raise ValueError(f"steady problem is singular: {int(lost.sum())} connected group(s) of particles (e.g. "
                         f"{first}) touch no fixed particle or wall, so their temperature is undetermined; fix a "
                         f"particle's temperature, add a wall, or set solver.floating = \"mean\"")
    ground = np.zeros(N, dtype=bool)  # one centre of every floating group held at 0
    floating = np.flatnonzero(~anchored)
    centre_of = np.full(n_comp, -1)
    centre_of[label[:n][::-1]] = np.arange(n)[::-1]
    ground[centre_of[floating]] = True
    T[ground] = 0.0
    free = ~fixed & ~ground
    A = net.A[free][:, free].tocsr()
    b = net.rhs[free] - net.A[free][:, fixed] @ T[fixed]
    solver = make_solver(A, linear, None, rtol) if A.shape[0] else None
    if A.shape[0]:
        T[free] = solver.solve(b)
    if len(floating):  # each floating group to its particles' capacity-weighted mean initial temperature
        C = p.capacity
        target = np.bincount(label[:n], C * p.temperature, n_comp)
        weight = np.bincount(label[:n], C, n_comp)
        now = np.bincount(label[:n], C * T[:n], n_comp)
        shift = np.where(anchored, 0.0, (target - now) / np.where(weight > 0, weight, 1.0))
        T += shift[label]
    bond_flow, wall_flow, fixed_flow = neck_flows(net, T)
    m = len(net.live)
    shifts = net.bonds.shifts[net.live] if m else np.zeros((0, 3))
    periodic = bond_flow[net.live] @ shifts if m else np.zeros(3)
    boundary = [fixed_flow[p.fixed], -wall_flow, p.heat]
    net_in = float(sum(x.sum() for x in boundary))
    scale = float(sum(np.abs(x).sum() for x in boundary))
    energy_error = abs(net_in) / scale if scale > 0 else 0.0
    return NeckSteady(T[:n].copy(), T[n:].copy(), bond_flow, wall_flow, fixed_flow, np.asarray(periodic, float),
                      energy_error, "none" if solver is None else solver.name)


def neck_flows(net: NeckNetwork, T: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The heat flows through the necks, into the walls and out of the fixed centres at node temperatures ``T``.

    Parameters
    ----------
    net : NeckNetwork
        The network.
    T : numpy.ndarray
        The temperatures of all nodes, centres then necks (K or degC).

    Returns
    -------
    tuple of numpy.ndarray
        ``(bond_flow, wall_flow, fixed_flow)``: per pair bond (all of them) the heat flowing from ``i`` to ``j``
        through its neck (0 for a dead one), per wall bond (all of them) the heat flowing from its particle into the
        wall, per particle the heat its fixed temperature feeds into the network (0 for a free particle); W.
    """
    n, m = net.particles.n, len(net.live)
    Q = net.end_flows(T)
    bond_flow = np.zeros(net.bonds.n_pairs)
    bond_flow[net.live] = -Q[:m]  # out of i through the neck
    wall_flow = np.zeros(net.bonds.n_walls)
    wall_flow[net.live_walls] = -Q[2 * m:]
    # the heat fed by each fixed centre: its element's centre row (flows into the element there)
    row, col, value, known, end = net.entries
    seen = known + np.where(col >= 0, T[np.maximum(col, 0)], 0.0)
    centre = end < 0
    fed = np.bincount(row[centre], value[centre] * seen[centre], len(T))[:n]
    return bond_flow, wall_flow, np.where(net.particles.fixed, fed, 0.0)


class NeckHeat:
    r"""The transient heat balance of the network with a node per neck (module docstring, "Transient") in the terms
    in which :func:`dem.network.heat.integrate` and :class:`dem.network.theta.ThetaStepper` take a network, so that
    one :math:`\theta` scheme serves both: the unknowns are the free centres (their capacities) and then the necks
    (massless, ``C = 0``), ``A`` the network's matrix on them and ``r`` its right-hand side with the fixed centres'
    columns moved into it. No ambient exchange. The necks start where their rows hold at the initial temperatures
    (the constraint :math:`(A T)_n = r_n`), which keeps Crank-Nicolson's neck temperatures from alternating.

    Parameters
    ----------
    net : NeckNetwork
        The network.
    linear : str
        The linear solver of the necks' initial solve (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol : float
        The relative residual of that solve if iterative.
    """

    sources = Sources()  # no ambient exchange
    flow_names = ("fixed", "walls", "internal")

    def __init__(self, net: NeckNetwork, linear: str = "auto", rtol: float = 1e-12):
        p = net.particles
        n, m = p.n, len(net.live)
        self.net, self.particles = net, p
        centres = np.flatnonzero(~p.fixed)
        held = np.flatnonzero(p.fixed)
        k = len(centres)
        self.free = np.concatenate([centres, n + np.arange(m)])
        rows = net.A[self.free]
        self.A = rows[:, self.free].tocsr()
        self.r_const = net.rhs[self.free] - rows[:, held] @ p.temperature[held]
        self.C = np.concatenate([p.capacity[centres], np.zeros(m)])
        self.heat = np.concatenate([p.heat[centres], np.zeros(m)])
        self.periodic = bool(np.any(net.jump != 0.0))  # a temperature drop across the box's faces drives it
        self.base_diag = self.A.diagonal()
        self.n_free = len(self.free)
        # the boundary terms: the entries of the walls' rows (heat from a wall into the network) and of the fixed
        # centres' rows (heat a fixed centre feeds into it), grouped by wall end and by fixed centre
        row, col, value, known, end = net.entries
        wall = row < 0
        fed = (row >= 0) & (row < n) & p.fixed[np.clip(row, 0, n - 1)]
        self._walls = len(net.live_walls)
        group = np.where(wall, end - 2 * m, self._walls + np.searchsorted(held, np.where(fed, row, 0)))
        take = wall | fed
        self._terms = (col[take], value[take], known[take], group[take], self._walls + len(held))
        self.wall_temperature = known[col < 0]
        self._initial = np.concatenate([p.temperature[centres].astype(float), np.zeros(m)])
        if m:  # the necks where their rows hold (the docstring)
            A_nn, A_nc = self.A[k:, k:], self.A[k:, :k]
            b = self.r_const[k:] - A_nc @ self._initial[:k]
            self._initial[k:] = make_solver(A_nn.tocsr(), linear, None, rtol).solve(b)

    @property
    def initial(self) -> np.ndarray:
        """Initial temperatures of the free nodes, K or degC (the free centres' own, the necks' where their rows
        hold)."""
        return self._initial.copy()

    def nodes(self, T_F: np.ndarray) -> np.ndarray:
        """The temperatures of all nodes from those of the free ones.

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).

        Returns
        -------
        numpy.ndarray
            All nodes' temperatures, centres then necks (K or degC).
        """
        T = np.concatenate([self.particles.temperature.astype(float), np.zeros(len(self.net.live))])
        T[self.free] = T_F
        return T

    def full(self, T_F: np.ndarray) -> np.ndarray:
        """The particles' (centres') temperatures from those of the free nodes.

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).

        Returns
        -------
        numpy.ndarray
            (N,) the particles' temperatures (K or degC).
        """
        return self.nodes(T_F)[:self.particles.n]

    def sinks(self, T_F: np.ndarray) -> dict:
        """The ambient exchange: none.

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).

        Returns
        -------
        dict
            ``{}``.
        """
        return {}

    def matrix(self, sinks: dict) -> sp.csr_matrix:
        """The matrix ``A`` over the free nodes.

        Parameters
        ----------
        sinks : dict
            The ambient terms (none: ``{}``, :meth:`sinks`).

        Returns
        -------
        scipy.sparse.csr_matrix
            ``A`` (W/K).
        """
        return self.A

    def rhs(self, sinks: dict) -> np.ndarray:
        """The right-hand side ``r`` over the free nodes.

        Parameters
        ----------
        sinks : dict
            The ambient terms (none: ``{}``, :meth:`sinks`).

        Returns
        -------
        numpy.ndarray
            ``r`` (W).
        """
        return self.r_const

    def _boundary(self, T_F: np.ndarray) -> tuple[np.ndarray, float]:
        """Per wall end, then per fixed centre, the heat it gives the free nodes (W); and the sum of its terms' sizes
        (W)."""
        col, value, known, group, size = self._terms
        T = self.nodes(T_F)
        terms = value * (known + np.where(col >= 0, T[np.maximum(col, 0)], 0.0))
        return np.bincount(group, terms, size), float(np.abs(terms).sum())

    def flows(self, T_F: np.ndarray, sinks: dict) -> dict:
        """Heat flow into the free nodes through the fixed centres, the walls and the sources: their sum is the
        change of the centres' heat (the neck rows sum their elements' rows, each of which sums to zero).

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).
        sinks : dict
            The ambient terms (none: ``{}``, :meth:`sinks`).

        Returns
        -------
        dict
            ``{"fixed": W, "walls": W, "internal": W}``.
        """
        q = self._boundary(T_F)[0]
        return {"fixed": float(q[self._walls:].sum()), "walls": float(q[:self._walls].sum()),
                "internal": float(self.heat.sum())}

    def flow_magnitude(self, T_F: np.ndarray, sinks: dict) -> float:
        """The scale of the heat balance, as :meth:`dem.network.heat.Network.flow_magnitude`: the sum of the sizes of
        the flows through each wall end, fixed centre and source, never below round-off of their terms.

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).
        sinks : dict
            The ambient terms (none: ``{}``, :meth:`sinks`).

        Returns
        -------
        float
            The scale (W).
        """
        q, gross = self._boundary(T_F)
        sources = float(np.abs(self.heat).sum())
        return max(sources + float(np.abs(q).sum()), np.sqrt(np.finfo(float).eps) * (sources + gross))

    def temperature_bounds(self) -> tuple[float, float]:
        """Lowest and highest temperature the scene prescribes (initial, fixed, walls)."""
        allt = np.concatenate([self.particles.temperature, self.wall_temperature])
        return float(allt.min()), float(allt.max())

    def temperature_range(self) -> float:
        """The spread of :meth:`temperature_bounds` (K)."""
        lo, hi = self.temperature_bounds()
        return hi - lo
