r"""The heat network with a node per neck: each particle an element joining its centre to its necks.

``[conductance] nodes = "necks"`` (:class:`dem.laws.conductance.ConductanceSpec`) solves the ``shared-body`` law's
particle model exactly instead of reducing it to one factor per neck on one node per particle
(:mod:`dem.laws.shared_body`).

**The element.** A particle with ``z`` necks is a ``(z + 1)``-terminal element: its centre node (the particle's
temperature :math:`T_c`, which holds its heat capacity) and one node per neck. With ``R`` the particle's
multi-terminal resistance (flows :math:`Q` into the particle through its necks raise neck ``b`` to
:math:`T_b - T_c = \sum_c R_{bc} Q_c`: the cut-body halves :math:`1/K_b` on the diagonal, the sphere's Neumann function
between necks, its free-space part taken between the necks' faces) describes heat passing through the particle
(flows that sum to zero: :math:`Y_0`, the Schur complement on the necks of :math:`R^{-1}` bordered by its sums), and
the net flow between the centre and its necks takes the one-node law's halves :math:`K_b = 1/R_{bb}`
(:func:`dem.laws.shared_body.particle_elements` says why): the element's conductance matrix is

.. math::

    E = \begin{pmatrix} Y_0 + K K^T / \textstyle\sum K & -K \\ -K^T & \sum K \end{pmatrix},

symmetric, positive semidefinite (``R`` is positive definite: :func:`dem.laws.shared_body.particle_elements` drops the
interactions of a particle where it is not), its rows summing to zero. The law's trace cap scales ``E`` as it scales a
particle's factors today: where the trace of the particle's tensor :math:`N^T Y N` (``Y`` the Schur complement of ``E``
on the necks, :math:`N_b = l_b n_b`) exceeds :math:`3 \kappa V_k`. A neck node is shared by the two particles of its
bond; a wall bond's neck sits at the wall (its node is the wall's temperature). A particle whose necks are collinear
(a pair, a chain) has ``R`` diagonal: its halves from the centre to each neck, the bonds' halves in series -- today's
network, to round-off.

**Pair necks.** Under a pair-neck reading (``neck`` ``newton``, ``first`` or ``coble``: Rojek 2022, eqs. 21-34) a
particle's element is made of the bonds' necks as the reading gives them: neck radius ``a`` and arm ``l`` (the
centre-to-contact distance), the ``shared-body`` law's pair-calibrated halves of the neck cylinder
(:func:`dem.laws.conductance.bond_halves`), both halves of a bond of unequal radii times the fit's correction
(:func:`dem.laws.conductance.unequal_factor`, which multiplies their series as the one-node law does), and its
sphere's volume :math:`\frac{4}{3} \pi r^3` (which the volume-conserving neck keeps) in the trace cap. No cut body
narrows the halves and no closing pore lowers the cap: those are the union's. A chain is the one-node law's halves
in series, to round-off; where necks are not collinear the element solves the particle the one-node law reduces to
one factor per neck (its interaction taken between the faces, not the cap bases' centres). A moving run hands a
particle whose necks meet over to the union (:mod:`dem.engines.handover`).

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

**Flux modes.** One number per neck carries the heat through it, not how that heat spreads over the face; on a loose
packing a neck's flux tilts across its face, which one number cannot carry (the verification guide's floor from
exact elements). An element may carry ``modes`` flux modes per neck (``modes`` of
:class:`~dem.laws.shared_body.ParticleElements`): mode 0, the monopole, a unit of heat spread over the face with a
profile :math:`w / \int w`; modes 1 and 2, the dipoles, :math:`w (\xi_d - \bar\xi_d) / (a \int w)` with
:math:`\xi_d = t_d \cdot x` along the neck's frame (:func:`neck_frames`: :math:`t_1, t_2` defined by the bond, so
both particles see the same functions on their common face; :math:`\bar\xi_d` the ``w``-weighted mean, ``a`` the
neck radius), which carry no net heat. Each mode's node holds the face temperature read with its own function (the
monopole's the ``w``-weighted mean, a dipole's the moment), so a particle's resistance ``R`` over its ``modes z`` modes
gives the flows :math:`Q = R^{-1} (\theta - T_c e)` into it (``e`` 1 on the monopoles, 0 on the dipoles: the centre
exchanges heat with the monopoles only) and its element is

.. math::

    E = \begin{pmatrix} R^{-1} & -R^{-1} e \\ -e^T R^{-1} & e^T R^{-1} e \end{pmatrix},

its local node ``modes p + d`` mode ``d`` of end ``p``, then the centre. ``modes`` is one number for all the
particles or one per particle (the three-mode element only where a particle needs it, the law's one-mode element
elsewhere: :func:`dem.network.trefftz_element.trefftz_elements`' ``where``). A live pair bond's neck carries the modes
of whichever of its two particles has more (a wall's neck: its particle's), and mode ``d`` of live pair bond ``b`` is
node ``n + o_b + d``, :math:`o_b` the modes of the live pair bonds before it (``n + modes b + d`` where all
particles' agree), shared by the bond's two particles: what flows into ``i`` through it leaves ``j`` (Kirchhoff at the
node) and its temperature moment is one value on both sides. A particle with fewer modes than one of its necks sees
only its own there, its element padded with zero rows and columns on the neck's other modes: it draws no flux through
them, so by Kirchhoff at their nodes the other particle's dipoles on that face are flux-free (both see the face's
flux as the monopole's profile alone: one flux on the common face, so the network stays a flux field of the bodies).
A uniform change of temperature moves
the centres and the monopoles and leaves the dipoles' moments (the kernel of ``A`` on a connected group is 1 there, 0
on the dipoles); the periodic jump and a wall's temperature act on the monopoles, a wall's dipole moments are 0 (it
is isothermal). The heat flows (:meth:`NeckNetwork.end_flows`, the flow across the period, ``k_eff``) are the
monopoles'; a dipole's row in ``entries`` has the bond end :data:`DIPOLE`. The law's elements have ``modes = 1``;
``modes = 3`` comes from elements built elsewhere through the ``elements`` hook of :func:`neck_network`
(:func:`dem.network.trefftz_element.trefftz_elements`, the element of ``[conductance] element = "trefftz"``,
:mod:`dem.network.elements`; ``python -m verification neck-node-bound``'s exact ones). With all modes 1, or all 3,
the network is the one of uniform modes, bit for bit. The current takes ``modes = 1`` only (the rows of ``E`` do not
sum to zero on the dipoles: no graph's Laplacian).

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

**Ambient.** Convection and radiation (:mod:`dem.laws.ambient`, Rojek 2022 eq. 3) act on a particle's exposed
surface (:mod:`dem.geometry.exposure`), whose temperature the network holds at its centre node, the node that holds
its heat capacity: the exchange :math:`Q_k = b_k - g_k T_k` of a free particle enters its centre's row as on one node
per particle (:math:`g` on the diagonal, :math:`b` on the right-hand side; none on a neck, which has no surface of its
own in the model). A particle whose necks are collinear is its halves in series between centre nodes with the same
:math:`g`: a chain is today's network with the ambient, steady and transient. Radiation's :math:`T^4` is linearised
about the last iterate and solved by the particle network's Newton iteration (:func:`dem.network.heat.solve_steady`)
on this matrix, whose diagonal alone changes; in time it is linearised about each step's start as there. Every group
of nodes with a centre that sees the ambient is anchored by it. The heat balance sums the flows through the walls,
the fixed centres, the sources and the ambient (:meth:`NeckHeat.flows`); the necks' rows add nothing to it.

**Current.** The current between electrodes (:mod:`dem.network.current`) obeys the same Laplace problem with the
electrical conductivity :math:`\sigma` for :math:`\kappa`: the half conductances, the faces' interaction and the trace
cap are each proportional to the particle's conductivity, so its electrical element is :math:`(\sigma_k/\kappa_k)
E_k`, the thermal one scaled (one assembly for both). Kirchhoff's solve (:func:`dem.network.current.kirchhoff`, its
superposition for an electrode driving a fixed current and its floating groups included) takes the elements as edges:
a symmetric matrix whose rows sum to zero is the Laplacian of the graph whose edge ``(p, q)`` has the conductance
:math:`-E_{pq}` (positive or, between two necks, possibly negative), so every pair of an element's nodes is an edge;
a wall end on an electrode is a plane bond to it, a wall end on another wall (no current crosses it) a node of its
own, joined only to its particle's element (which is then that element with the end's row condensed out). There is
no potential drop across a periodic box's faces: the necks' offsets are the heat's only. The Joule heat made in
particle ``k`` is its element's dissipation :math:`\Phi_k^T E_k^\sigma \Phi_k = \sum_{p<q} -E^\sigma_{pq} (\Phi_p -
\Phi_q)^2` (:math:`\Phi_k` the potentials of its centre and its necks), deposited on its centre (its absorbed part a
source of heat there); summed over the particles it is the power :math:`\sum_e V_e I_e` the electrodes deliver
(Tellegen's theorem), to round-off. A chain's elements are its halves in series, whose dissipations are the shares
of :math:`I^2/G` that the particle network gives each particle: today's current, potentials and Joule heat. A particle
touching two electrodes (its element would join them directly, an edge the solve has no place for) is refused.

**MPI.** :mod:`dem.network.distributed_necks` shares the network out among ranks: a centre node on the rank that
owns its particle, a neck node on the rank that owns its bond's first particle, each rank holding a halo of three bond
lengths so that every row it owns is the serial network's (:class:`NeckHeat`'s ``own``: each rank counts its own
particles' flows).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from dem.geometry.bonds import Bonds
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.laws.ambient import Sources, linear_sink_terms
from dem.laws.conductance import ConductanceSpec, bond_halves, unequal_factor, union_halves, wall_normals
from dem.network.current import CurrentFlow, Electrodes, kirchhoff
from dem.network.heat import BalanceScales, solve_steady
from dem.network.linsolve import make_solver

DIPOLE = -2  #: the bond end of a dipole mode's row or column in NeckNetwork.entries (it carries no net heat)


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
        The right-hand side over all nodes from the periodic offsets and the walls (W); the particles' heat sources
        and the ambient enter where the network is solved (:class:`NeckHeat`).
    entries : tuple
        ``(row, col, value, known, end)`` of every element entry: its row and column nodes (``-1``: a wall's
        neck), its value (W/K), the offset or wall temperature its column is seen at (K), and the bond end of
        its row (``-1``: the centre; :data:`DIPOLE`: a dipole mode of a neck, which carries no net heat), from which
        :meth:`end_flows` sums the flows.
    n_ends : int
        The number of bond ends (twice the live pair bonds and the live wall bonds).
    plain : int
        The number of particles whose interactions were dropped (``R`` not positive definite).
    jump : numpy.ndarray
        Per live pair bond, the temperature drop its ``j`` sees across the periodic faces (K; 0 without a box).
    owner : numpy.ndarray
        Per element entry (in the order of ``entries``), the particle whose element it belongs to.
    col_end : numpy.ndarray
        Per element entry, the bond end of its column (``-1``: the centre; :data:`DIPOLE`: a dipole mode).
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    union : tuple or None
        Under the union of spheres, the ``shared-body`` halves on the cut spheres the elements are made of (what
        :func:`dem.laws.conductance.union_halves` returned), from which the one-node law's conductances follow without
        computing them again (``union`` of :func:`dem.laws.conductance.bond_conductances`); None under a pair-neck
        reading.
    modes : int or numpy.ndarray
        Flux modes per neck (module docstring, "Flux modes"): 1, the neck's temperature alone (node ``n + k`` of live
        pair bond ``k``); 3 with two dipoles (mode ``d`` of bond ``k`` at node ``n + 3 k + d``, the monopole ``d = 0``);
        where the particles' elements differ, one number per live pair bond (its nodes follow those of the bonds
        before it: :attr:`monopoles`).
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
    owner: np.ndarray
    col_end: np.ndarray
    box: PeriodicBox | None = None
    union: tuple | None = None
    modes: int = 1

    @property
    def n_nodes(self) -> int:
        """Centres and neck nodes."""
        return self.A.shape[0]

    @property
    def bond_modes(self) -> np.ndarray:
        """Per live pair bond, its neck's flux modes."""
        return np.broadcast_to(np.asarray(self.modes, dtype=np.int64), (len(self.live),))

    @property
    def monopoles(self) -> np.ndarray:
        """Per live pair bond, the node of its monopole (its neck's temperature; its dipoles follow it)."""
        return self.particles.n + first_modes(self.bond_modes)

    def end_flows(self, T: np.ndarray) -> np.ndarray:
        """The heat flowing into each particle through each of its neck ends (W) at node temperatures ``T``: end
        ``k < m`` is live pair bond ``k`` on its ``i``, ``m <= k < 2 m`` the same on its ``j``, the rest the live wall
        bonds (``m`` live pair bonds); the monopole modes' flows (a dipole carries no net heat).

        Parameters
        ----------
        T : numpy.ndarray
            The temperatures of all nodes, centres then necks (K or degC; with several modes per neck, the dipoles'
            temperature moments among them).

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
                 walls=(), closing_pores: dict | None = None, elements=None, without=None) -> NeckNetwork:
    """Assemble the network with a node per neck (module docstring) of the ``shared-body`` law under the union of
    spheres or a pair-neck reading ("Pair necks"): its live necks (:func:`live_necks`), their particles' elements
    (``elements``) and the network of them (:func:`assembled`).

    Parameters
    ----------
    spec : dem.laws.conductance.ConductanceSpec
        The law (``shared-body``, without ``contact_conductance``) and its neck reading.
    particles : dem.geometry.particles.Particles
        The particles.
    bonds : dem.geometry.bonds.Bonds
        The bonds under that reading.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    walls : sequence of dem.geometry.walls.Wall
        The walls the wall bonds index (their normals and temperatures).
    closing_pores : dict or None
        The closing pores' calibration (:func:`dem.laws.conductance.bond_conductances`); None: the shipped one.
    elements : callable or None
        What builds the particles' elements, called with the arguments of
        :func:`dem.laws.shared_body.particle_elements` (``arguments`` of :class:`LiveNecks`) and returning its
        :class:`~dem.laws.shared_body.ParticleElements` (the same ends, another matrix per particle: e.g. an exact
        element computed elsewhere, with ``modes`` flux modes per neck, one number or one per particle, module
        docstring "Flux modes"); None: :func:`dem.laws.shared_body.particle_elements`.
    without : tuple of numpy.ndarray or None
        ``(pairs, walls)``: masks of the pair and wall bonds to leave without a neck node (as a neck hidden inside a
        third sphere is), whatever their halves; None: none.

    Returns
    -------
    NeckNetwork
        The assembled network.

    Raises
    ------
    ValueError
        ``spec`` is not the ``shared-body`` law without ``contact_conductance``, wall bonds without their walls,
        elements whose ``modes`` are not integers >= 1 (one, or one per particle), or whose blocks are not
        :math:`(m z + 1)^2` values (``m`` the particle's modes per neck).
    """
    from dem.laws.shared_body import particle_elements

    necks = live_necks(spec, particles, bonds, box=box, walls=walls, closing_pores=closing_pores, without=without)
    return assembled(necks, (elements or particle_elements)(*necks.arguments))


@dataclass
class LiveNecks:
    """The live necks of a network with a node per neck and their halves, before their particles' elements are built
    (:func:`live_necks`): what the elements are built from (``arguments``) and placed by (:func:`assembled`).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles.
    bonds : dem.geometry.bonds.Bonds
        All pair and wall bonds.
    live : numpy.ndarray
        Indices of the pair bonds that have a neck node.
    live_walls : numpy.ndarray
        Indices of the wall bonds that carry heat.
    arguments : tuple
        The arguments of :func:`dem.laws.shared_body.particle_elements` over the live bonds, with which an
        ``elements`` hook of :func:`neck_network` is called: the number of particles, their radii (m), the live
        bonds, their vectors ``x_j - x_i`` (m), half conductances (W/K), the particles' conductivities (W/(m K)),
        the live wall bonds' normals and the particles' solid volumes (m^3; None: their spheres').
    walls : sequence of dem.geometry.walls.Wall
        The walls the wall bonds index (their temperatures).
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    union : tuple or None
        Under the union of spheres, what :func:`dem.laws.conductance.union_halves` returned
        (``union`` of :class:`NeckNetwork`); None under a pair-neck reading.
    """

    particles: Particles
    bonds: Bonds
    live: np.ndarray
    live_walls: np.ndarray
    arguments: tuple
    walls: tuple = ()
    box: PeriodicBox | None = None
    union: tuple | None = None


def live_necks(spec: ConductanceSpec, particles: Particles, bonds: Bonds, *, box: PeriodicBox | None = None,
               walls=(), closing_pores: dict | None = None, without=None) -> LiveNecks:
    """The live necks of the network with a node per neck (:func:`neck_network`, whose parameters these are) and
    their halves: the ``shared-body`` law's under the union of spheres (its cut bodies) or a pair-neck reading
    ("Pair necks").

    Parameters
    ----------
    spec : dem.laws.conductance.ConductanceSpec
        The law (``shared-body``, without ``contact_conductance``) and its neck reading.
    particles : dem.geometry.particles.Particles
        The particles.
    bonds : dem.geometry.bonds.Bonds
        The bonds under that reading.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    walls : sequence of dem.geometry.walls.Wall
        The walls the wall bonds index (their normals and temperatures).
    closing_pores : dict or None
        The closing pores' calibration (:func:`dem.laws.conductance.bond_conductances`); None: the shipped one.
    without : tuple of numpy.ndarray or None
        ``(pairs, walls)``: masks of the pair and wall bonds to leave without a neck node; None: none.

    Returns
    -------
    LiveNecks
        The live necks.

    Raises
    ------
    ValueError
        ``spec`` is not the ``shared-body`` law without ``contact_conductance``, or wall bonds without their walls.
    """
    if spec.law != "shared-body" or spec.contact_conductance is not None:
        raise ValueError(f"conductance.nodes = \"necks\": only with law = \"shared-body\" and no contact_conductance "
                         f"(here law = {spec.law!r}, contact_conductance = {spec.contact_conductance!r})")
    n, r = particles.n, particles.radius
    kappa = particles.conductivity
    k_i, k_j, k_w = bond_halves(spec, particles, bonds, kappa)
    normals = wall_normals(bonds, walls)
    vectors = bonds.vectors(particles.position, box)
    if spec.neck == "union":
        union = union_halves(particles, bonds, vectors, normals, kappa, k_i, k_j, k_w, closing_pores, box, walls)
        k_i, k_j, k_w, pairs, live_walls, volume = union
    else:  # a pair-neck reading (module docstring, "Pair necks")
        union = volume = None
        unequal = unequal_factor(spec, r, bonds)
        if unequal is not None:
            k_i, k_j = k_i * unequal, k_j * unequal
        pairs, live_walls = (k_i > 0.0) & (k_j > 0.0), k_w > 0.0
    if without is not None:
        pairs, live_walls = pairs & ~without[0], live_walls & ~without[1]
    live, live_walls = np.flatnonzero(pairs), np.flatnonzero(live_walls)
    sub = bonds.subset(live, live_walls)
    arguments = (n, r, sub, vectors[live], k_i[live], k_j[live], k_w[live_walls], kappa,
                 np.reshape(normals, (-1, 3))[live_walls], volume)
    return LiveNecks(particles, bonds, live, live_walls, arguments, tuple(walls), box, union)


def assembled(necks: LiveNecks, el) -> NeckNetwork:
    """The network with a node per neck (module docstring, "Assembly") of ``necks`` and their particles' elements
    ``el``, in one sparse matrix.

    Parameters
    ----------
    necks : LiveNecks
        The live necks (:func:`live_necks`).
    el : dem.laws.shared_body.ParticleElements
        Their particles' elements (an ``elements`` hook's of :func:`neck_network`, called with
        ``arguments`` of :class:`LiveNecks`).

    Returns
    -------
    NeckNetwork
        The assembled network.

    Raises
    ------
    ValueError
        Elements whose ``modes`` are not integers >= 1 (one, or one per particle), or whose blocks are not
        :math:`(m z + 1)^2` values (``m`` the particle's modes per neck).
    """
    particles, live, live_walls, box = necks.particles, necks.live, necks.live_walls, necks.box
    n, sub = particles.n, necks.arguments[2]  # the live bonds
    m = len(live)
    M = _modes(el)
    # each live pair bond's modes: the most of its two particles' (module docstring, "Flux modes"); mode ``mode`` of
    # live pair bond b is node n + (the modes of the bonds before it) + mode
    bond_modes = np.maximum(M[sub.i], M[sub.j])
    monopole = n + first_modes(bond_modes)
    # each end's node (a wall's: -1) and the offset it is seen at by its particle (a wall's: its temperature)
    jump = sub.shifts @ box.drop if box is not None else np.zeros(m)
    wall_T = np.array([w.temperature for w in necks.walls], dtype=float)[sub.wall_index] if len(live_walls) \
        else np.zeros(0)
    # (one more place at the end of each: the centre, end -1, seen at offset 0)
    node = np.concatenate([monopole, monopole, np.full(len(live_walls), -1), [0]])
    offset = np.concatenate([np.zeros(m), jump, wall_T, [0.0]])
    ends = np.append(el.ends, -1)
    # the entries: particle k's block is (M_k z + 1)^2 values row by row, local node M_k p + mode (mode < M_k) the
    # mode of its p-th end, M_k z its centre (a particle with fewer modes than a neck: none on the neck's others)
    z = np.diff(el.offsets)
    size = M * z + 1
    owner = np.repeat(np.arange(n), size * size)
    local = np.arange(len(el.values)) - el.start[:-1][owner]
    p_row, p_col = local // size[owner], local % size[owner]
    first = el.offsets[:-1][owner]
    M_own, z_own = M[owner], z[owner]
    centre_row, centre_col = p_row == M_own * z_own, p_col == M_own * z_own
    mode_row, mode_col = np.where(centre_row, 0, p_row % M_own), np.where(centre_col, 0, p_col % M_own)
    end_row = ends[np.where(centre_row, len(el.ends), first + p_row // M_own)]
    end_col = ends[np.where(centre_col, len(el.ends), first + p_col // M_own)]
    row = np.where(end_row < 0, owner, np.where(node[end_row] < 0, -1, node[end_row] + mode_row))
    col = np.where(end_col < 0, owner, np.where(node[end_col] < 0, -1, node[end_col] + mode_col))
    known = np.where(mode_col == 0, offset[end_col], 0.0)  # a dipole sees no jump, and a wall's moment is 0
    end_row, end_col = np.where(mode_row == 0, end_row, DIPOLE), np.where(mode_col == 0, end_col, DIPOLE)
    value = el.values
    inner, rows = (row >= 0) & (col >= 0), row >= 0  # a wall's row has no equation: the wall takes what it is given
    size_all = n + int(bond_modes.sum())
    A = sp.coo_matrix((value[inner], (row[inner], col[inner])), shape=(size_all, size_all)).tocsr()
    A = 0.5 * (A + A.T)  # symmetric to round-off (the blocks are; their sums need not be bit for bit)
    rhs = -np.bincount(row[rows], value[rows] * known[rows], size_all)
    modes = bond_modes if np.any(M != M[:1]) else int(M[0]) if n else 1  # one number where all particles' agree
    return NeckNetwork(particles, necks.bonds, live, live_walls, A.tocsr(), rhs, (row, col, value, known, end_row),
                       2 * m + len(live_walls), int(np.count_nonzero(el.plain)), jump, owner, end_col, box,
                       necks.union, modes)


def first_modes(bond_modes: np.ndarray) -> np.ndarray:
    """Per live pair bond, the modes of the bonds before it: where its first mode (the monopole) follows the
    centres' nodes (module docstring, "Flux modes").

    Parameters
    ----------
    bond_modes : numpy.ndarray
        Per live pair bond, its neck's flux modes.

    Returns
    -------
    numpy.ndarray
        The offsets, int.
    """
    return np.cumsum(bond_modes) - bond_modes


def _modes(el) -> np.ndarray:
    """Per particle, the flux modes per neck of its element in ``el`` (``el.modes``: one number for all or one per
    particle), the blocks' sizes checked against them."""
    n = len(el.offsets) - 1
    given = np.asarray(getattr(el, "modes", 1))
    if given.ndim > 1 or (given.ndim == 1 and len(given) != n):
        raise ValueError(f"elements: modes has shape {given.shape}: must be one number or one per particle ({n})")
    wrong = np.flatnonzero(np.atleast_1d((given != np.round(given)) | (given < 1))) if given.dtype.kind in "iuf" \
        else np.zeros(1, dtype=np.int64)
    if len(wrong):
        k = int(wrong[0])
        raise ValueError(f"elements: modes = {np.atleast_1d(given)[k]}: must be an integer >= 1 (flux modes per neck)"
                         + (f", particle {k}" if given.ndim else ""))
    M = np.broadcast_to(given, (n,)).astype(np.int64)
    z = np.diff(el.offsets)
    bad = np.flatnonzero(np.diff(el.start) != (M * z + 1) ** 2)
    if len(bad) or len(el.values) != el.start[-1]:
        k = int(bad[0]) if len(bad) else len(z) - 1
        raise ValueError(f"elements: particle {k} has {int(el.start[k + 1] - el.start[k])} values; with {z[k]} necks "
                         f"and modes = {M[k]} its block needs (modes z + 1)^2 = {(M[k] * z[k] + 1) ** 2}")
    return M


def bordered(Y: np.ndarray, modes: int = 1) -> np.ndarray:
    r"""The element of a particle over its necks' ``modes`` flux modes and its centre from its conductance ``Y`` over
    the modes (module docstring, "Flux modes"): ``Y`` bordered by :math:`-Y e` and :math:`e^T Y e`, ``e`` 1 on the
    monopoles (every ``modes``-th, from the first), 0 on the dipoles: the centre joins the monopoles only.

    Parameters
    ----------
    Y : numpy.ndarray
        (modes z, modes z) conductance over the modes, W/K, symmetric.
    modes : int
        Flux modes per neck.

    Returns
    -------
    numpy.ndarray
        The conductance matrix, W/K (local nodes: the necks' modes, then the centre).
    """
    row = Y[:, ::modes].sum(axis=1)
    return np.block([[Y, -row[:, None]], [-row[None, :], np.array([[row[::modes].sum()]])]])


def neck_frames(vectors: np.ndarray) -> np.ndarray:
    r"""The dipole frame of each pair bond's neck: two unit vectors :math:`t_1, t_2` in the neck's plane, defined by
    the bond (its unit vector :math:`u` from ``i`` to ``j``) so that both particles see the same dipole modes
    (module docstring, "Flux modes"): :math:`t_1 = u \times h / |u \times h|` with :math:`h = e_x` where
    :math:`|u_x| < 0.9`, else :math:`e_y`, and :math:`t_2 = u \times t_1`.

    Parameters
    ----------
    vectors : numpy.ndarray
        (m, 3) ``x_j - x_i`` of the bonds (any length unit; not zero).

    Returns
    -------
    numpy.ndarray
        (m, 2, 3) the unit vectors ``t_1``, ``t_2`` of each bond.
    """
    u = np.reshape(np.asarray(vectors, dtype=float), (-1, 3))
    u = u / np.linalg.norm(u, axis=1)[:, None]
    h = np.where((np.abs(u[:, 0]) < 0.9)[:, None], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])
    t1 = np.cross(u, h)
    t1 /= np.linalg.norm(t1, axis=1)[:, None]
    return np.stack([t1, np.cross(u, t1)], axis=1)


@dataclass
class NeckSteady:
    """What :func:`steady_necks` found.

    Parameters
    ----------
    T : numpy.ndarray
        (N,) the particles' (centres') temperatures (K or degC).
    T_necks : numpy.ndarray
        The live pair bonds' neck temperatures, in the frame of each bond's ``i`` (K or degC); with several flux
        modes per neck (:attr:`NeckNetwork.bond_modes`), as many values per bond, its temperature (the monopole's)
        then its dipoles' moments (K).
    bond_flow : numpy.ndarray
        Per pair bond (all of them), the heat flowing from ``i`` to ``j`` through its neck (W; 0 for a dead one).
    wall_flow : numpy.ndarray
        Per wall bond (all of them), the heat flowing from its particle into the wall (W).
    fixed_flow : numpy.ndarray
        Per particle, the heat its fixed temperature feeds into the network (W; 0 for a free particle).
    periodic_heat_flow : numpy.ndarray
        (3,) the heat flow across the period along x, y, z (W).
    flows : dict
        The heat flowing into the free nodes through each boundary (W, :meth:`NeckHeat.flows`: fixed centres,
        walls, internal sources and each ambient exchange, radiation's by its exact :math:`T^4`).
    energy_error : float
        The heat balance's mismatch (the sum of ``flows``) relative to the flows through the boundaries.
    iterations : int
        Newton iterations on radiation (1 without).
    solver : str
        The linear solver that ran.
    """

    T: np.ndarray
    T_necks: np.ndarray
    bond_flow: np.ndarray
    wall_flow: np.ndarray
    fixed_flow: np.ndarray
    periodic_heat_flow: np.ndarray
    flows: dict
    energy_error: float
    iterations: int
    solver: str


def steady_necks(net: NeckNetwork, floating: str = "mean", linear: str = "auto", rtol: float = 1e-12,
                 sources: Sources | None = None, max_newton: int = 50) -> NeckSteady:
    """The steady temperatures of the network with a node per neck (module docstring), with the ambient exchange of
    ``sources`` on the free centres ("Ambient"): one solve of :class:`NeckHeat`'s balance, or Newton's iteration on
    radiation (:func:`dem.network.heat.solve_steady`, the one of the particle network).

    Parameters
    ----------
    net : NeckNetwork
        The network.
    floating : str
        What a group of particles that reaches no fixed temperature, wall or ambient and holds no bond across a
        periodic face with a temperature drop does: ``"mean"`` keeps it at its particles' capacity-weighted mean
        initial temperature, ``"error"`` refuses (as :func:`dem.network.heat.steady`).
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol : float
        The relative residual of iterative linear solves.
    sources : dem.laws.ambient.Sources or None
        Convection and radiation to an ambient; None: none.
    max_newton : int
        The most Newton iterations on radiation.

    Returns
    -------
    NeckSteady
        Temperatures and flows.

    Raises
    ------
    ValueError
        A group of particles that reaches no fixed temperature, wall or ambient has a net heat source, or floats with
        ``floating = "error"``; a bad ``floating``; Newton's iteration did not converge.
    """
    if floating not in ("mean", "error"):
        raise ValueError(f"solver.floating = {floating!r}: must be error or mean")
    system = NeckHeat(net, linear, rtol, sources)
    p = net.particles
    n, N = p.n, net.n_nodes
    fixed = np.zeros(N, dtype=bool)
    fixed[:n] = p.fixed
    T_F = np.concatenate([p.temperature[~p.fixed], np.zeros(N - n)]).astype(float)  # centres: initial
    # the groups: anchored where they hold a fixed node, a wall's neck or a centre with an ambient exchange
    row, col = net.entries[0], net.entries[1]
    n_comp, label = connected_components(net.A, directed=False)
    anchored = np.zeros(n_comp, dtype=bool)
    anchored[label[fixed]] = True
    anchored[label[row[(col < 0) & (row >= 0)]]] = True
    ambient = sum((g for g, _ in system.sinks(T_F).values()), np.zeros(system.n_free))
    anchored[label[system.free[ambient > 0]]] = True
    heat = np.bincount(label[:n], p.heat, n_comp)
    if np.any(~anchored & (np.abs(heat) > 1e-12 * np.maximum(np.bincount(label[:n], np.abs(p.heat), n_comp), 1e-300))):
        raise ValueError("steady problem has no solution: a floating group of particles (no fixed temperature, "
                         "wall or ambient) has a net internal heat source, so it heats up forever")
    jumping = np.zeros(n_comp, dtype=bool)
    jumping[label[net.monopoles[net.jump != 0.0]]] = True
    lost = ~anchored & ~jumping
    if floating == "error" and np.any(lost):
        first = np.flatnonzero(lost[label[:n]])[:8].tolist()
        raise ValueError(f"steady problem is singular: {int(lost.sum())} connected group(s) of particles (e.g. "
                         f"{first}) touch no fixed particle, wall or ambient, so their temperature is undetermined; "
                         f"fix a particle's temperature, add a wall, or set solver.floating = \"mean\"")
    ground = np.zeros(N, dtype=bool)  # one centre of every floating group held at 0
    floating = np.flatnonzero(~anchored)
    centre_of = np.full(n_comp, -1)
    centre_of[label[:n][::-1]] = np.arange(n)[::-1]
    ground[centre_of[floating]] = True
    held = ground[system.free]
    T_F[held] = 0.0
    iterations, backend = solve_steady(system, T_F, np.flatnonzero(~held), linear, max_newton, rtol)
    T = system.nodes(T_F)
    if len(floating):  # each floating group to its particles' capacity-weighted mean initial temperature
        C = p.capacity
        target = np.bincount(label[:n], C * p.temperature, n_comp)
        weight = np.bincount(label[:n], C, n_comp)
        now = np.bincount(label[:n], C * T[:n], n_comp)
        shift = np.where(anchored, 0.0, (target - now) / np.where(weight > 0, weight, 1.0))
        T += shift[label] * uniform_level(net)
    T_F = T[system.free]
    sinks = system.sinks(T_F)  # radiation: the exact T^4 flow at the solution
    flows = system.flows(T_F, sinks)
    scale = system.flow_magnitude(T_F, sinks)
    energy_error = abs(sum(flows.values())) / scale if scale > 0 else 0.0
    bond_flow, wall_flow, fixed_flow = neck_flows(net, T)
    m = len(net.live)
    shifts = net.bonds.shifts[net.live] if m else np.zeros((0, 3))
    periodic = bond_flow[net.live] @ shifts if m else np.zeros(3)
    return NeckSteady(T[:n].copy(), T[n:].copy(), bond_flow, wall_flow, fixed_flow, np.asarray(periodic, float),
                      flows, energy_error, iterations, backend)


def uniform_level(net: NeckNetwork) -> np.ndarray:
    """Per node, 1 where a uniform change of temperature moves it (the centres and the necks' monopoles), 0 on the
    dipoles' moments (the moment of a uniform temperature is 0): the kernel of ``A`` on a connected group.

    Parameters
    ----------
    net : NeckNetwork
        The network.

    Returns
    -------
    numpy.ndarray
        (n_nodes,) 1.0 or 0.0 per node.
    """
    level = np.ones(net.n_nodes)
    level[net.particles.n:] = 0.0
    level[net.monopoles] = 1.0
    return level


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
    centre = end == -1
    fed = np.bincount(row[centre], value[centre] * seen[centre], len(T))[:n]
    return bond_flow, wall_flow, np.where(net.particles.fixed, fed, 0.0)


class NeckHeat(BalanceScales):
    r"""The heat balance of the network with a node per neck over its free nodes (module docstring, "Transient" and
    "Ambient") in the terms in which :func:`dem.network.heat.integrate`, :class:`dem.network.theta.ThetaStepper` and
    :func:`dem.network.heat.solve_steady` take a network, so that one :math:`\theta` scheme and one steady solve serve
    both: the unknowns are the free centres (their capacities) and then the necks (massless, ``C = 0``), ``A`` the
    network's matrix on them and ``r`` its right-hand side with the fixed centres' columns moved into it and the
    particles' heat sources added; the ambient exchange :math:`Q = b - g T` (:func:`dem.laws.ambient.linear_sink_terms`)
    acts on the free centres only. The necks start where their rows hold at the initial temperatures (the
    constraint :math:`(A T)_n = r_n`), which keeps Crank-Nicolson's neck temperatures from alternating.

    Parameters
    ----------
    net : NeckNetwork
        The network.
    linear : str
        The linear solver of the necks' initial solve (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol : float
        The relative residual of that solve if iterative.
    sources : dem.laws.ambient.Sources or None
        Convection and radiation to an ambient (an ``"exposed"`` area fraction resolved against the packing); None:
        none.
    own : numpy.ndarray or None
        Per particle, whether :meth:`flows` and :meth:`flow_sums` count its wall ends, its fixed centre, its source
        and its ambient exchange (a rank's own particles, :mod:`dem.network.distributed_necks`); None: all.
    """

    def __init__(self, net: NeckNetwork, linear: str = "auto", rtol: float = 1e-12, sources: Sources | None = None,
                 own: np.ndarray | None = None):
        p = net.particles
        n, m = p.n, len(net.live)
        self.net, self.particles = net, p
        centres = np.flatnonzero(~p.fixed)
        held = np.flatnonzero(p.fixed)
        necks = net.n_nodes - n  # the necks' nodes: their modes
        self.free = np.concatenate([centres, n + np.arange(necks)])
        rows = net.A[self.free]
        self.A = rows[:, self.free].tocsr()
        self.C = np.concatenate([p.capacity[centres], np.zeros(necks)])
        self.heat = np.concatenate([p.heat[centres], np.zeros(necks)])
        self.r_const = net.rhs[self.free] - rows[:, held] @ p.temperature[held] + self.heat
        self.sources = (Sources() if sources is None else sources).resolved(p.position, p.radius, centres)
        self.radius = p.radius[centres]
        self.flow_names = ("fixed", "walls", "internal", *self.sources.names)
        self.periodic = bool(np.any(net.jump != 0.0))  # a temperature drop across the box's faces drives it
        self.base_diag = self.A.diagonal()
        self.n_free = len(self.free)
        self._centres = len(centres)
        # the boundary terms: the entries of the walls' rows (heat from a wall into the network) and of the fixed
        # centres' rows (heat a fixed centre feeds into it), grouped by wall end and by fixed centre
        row, col, value, known, end = net.entries
        wall = (row < 0) & (end >= 0)  # (a wall's dipole rows carry no heat)
        fed = (row >= 0) & (row < n) & p.fixed[np.clip(row, 0, n - 1)]
        self._walls = len(net.live_walls)
        group = np.where(wall, end - 2 * m, self._walls + np.searchsorted(held, np.where(fed, row, 0)))
        take = wall | fed
        self._counted = slice(None)  # the free nodes whose source and ambient exchange count
        if own is not None:
            own = np.asarray(own, dtype=bool)
            counted = np.concatenate([own[net.bonds.wall_particle[net.live_walls]], own[held]])
            take[take] = counted[group[take]]
            self._counted = np.concatenate([own[centres], np.zeros(necks, dtype=bool)])
        self._terms = (col[take], value[take], known[take], group[take], self._walls + len(held))
        self.wall_temperature = known[(col < 0) & (net.col_end >= 0)]
        self._solve = (linear, rtol)
        self._initial = None

    @property
    def initial(self) -> np.ndarray:
        """Initial temperatures of the free nodes, K or degC (the free centres' own, the necks' where their rows
        hold), solved for when first asked for."""
        if self._initial is None:
            k = self._centres
            T = np.concatenate([self.particles.temperature[self.free[:k]].astype(float), np.zeros(self.n_free - k)])
            if self.n_free > k:  # the necks where their rows hold (the docstring)
                A_nn, A_nc = self.A[k:, k:], self.A[k:, :k]
                T[k:] = make_solver(A_nn.tocsr(), self._solve[0], None, self._solve[1]).solve(
                    self.r_const[k:] - A_nc @ T[:k])
            self._initial = T
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
        T = np.concatenate([self.particles.temperature.astype(float), np.zeros(self.net.n_nodes - self.particles.n)])
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
        """The ambient exchange of the free centres as :math:`Q = b - g T` (:func:`dem.laws.ambient.linear_sink_terms`,
        radiation linearised about ``T_F``); 0 on the necks.

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).

        Returns
        -------
        dict
            ``{name: (g, b)}``: W/K and W per free node (``{}`` without an ambient).
        """
        k = self._centres
        necks = np.zeros(self.n_free - k)
        return {name: (np.concatenate([g, necks]), np.concatenate([b, necks]))
                for name, (g, b) in linear_sink_terms(self.sources, self.radius, T_F[:k]).items()}

    def matrix(self, sinks: dict, shared: bool = False) -> sp.csr_matrix:
        """The matrix over the free nodes: ``A`` and the ambient's :math:`g` on the centres' diagonal.

        Parameters
        ----------
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`).
        shared : bool
            As :meth:`dem.network.heat.Network.matrix` has it; without ambient terms ``A`` itself is returned either
            way (no caller writes into it).

        Returns
        -------
        scipy.sparse.csr_matrix
            The matrix (W/K).
        """
        return self.A if not sinks else (self.A + sp.diags(sum(g for g, _ in sinks.values()))).tocsr()

    def rhs(self, sinks: dict) -> np.ndarray:
        """The right-hand side over the free nodes: ``r`` and the ambient's :math:`b` on the centres.

        Parameters
        ----------
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`).

        Returns
        -------
        numpy.ndarray
            The right-hand side (W).
        """
        return self.r_const if not sinks else self.r_const + sum(b for _, b in sinks.values())

    def _boundary(self, T_F: np.ndarray) -> tuple[np.ndarray, float]:
        """Per wall end, then per fixed centre, the heat it gives the free nodes (W); and the sum of its terms' sizes
        (W)."""
        col, value, known, group, size = self._terms
        T = self.nodes(T_F)
        terms = value * (known + np.where(col >= 0, T[np.maximum(col, 0)], 0.0))
        return np.bincount(group, terms, size), float(np.abs(terms).sum())

    def flows(self, T_F: np.ndarray, sinks: dict) -> dict:
        """Heat flow into the free nodes through the fixed centres, the walls, the sources and the ambient: their sum
        is the change of the centres' heat (the neck rows sum their elements' rows, each of which sums to zero).

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`).

        Returns
        -------
        dict
            ``{"fixed": W, "walls": W, "internal": W}`` and a flow per ambient exchange.
        """
        q, s = self._boundary(T_F)[0], self._counted
        out = {"fixed": float(q[self._walls:].sum()), "walls": float(q[:self._walls].sum()),
               "internal": float(self.heat[s].sum())}
        for name, (g, b) in sinks.items():
            out[name] = float(b[s].sum() - g[s] @ T_F[s])
        return out

    def flow_sums(self, T_F: np.ndarray, sinks: dict) -> tuple[float, float]:
        """``(sum |flow|, sum |terms|)`` over each wall end, fixed centre, source and ambient exchange: the two sums
        behind :meth:`dem.network.heat.BalanceScales.flow_magnitude`.

        Parameters
        ----------
        T_F : numpy.ndarray
            The temperatures of the free nodes, free centres then necks (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`).

        Returns
        -------
        tuple of (float, float)
            The two sums (W).
        """
        q, gross = self._boundary(T_F)
        s = self._counted
        net = gross_all = float(np.abs(self.heat[s]).sum())
        net += float(np.abs(q).sum())
        gross_all += gross
        for g, b in sinks.values():
            net += float(np.abs(b[s] - g[s] * T_F[s]).sum())
            gross_all += float(np.abs(b[s]).sum() + np.abs(g[s] * T_F[s]).sum())
        return net, gross_all


def neck_current(net: NeckNetwork, walls, electrodes: Electrodes, linear: str = "auto") -> tuple[CurrentFlow,
                                                                                                  np.ndarray]:
    r"""The current between the electrodes through the network with a node per neck (module docstring, "Current"):
    Kirchhoff's solve (:func:`dem.network.current.kirchhoff`) on the elements' edges with :math:`\sigma` for
    :math:`\kappa`, and each particle's Joule heat its element's dissipation.

    Parameters
    ----------
    net : NeckNetwork
        The network (its elements with the thermal conductivity :math:`\kappa`).
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls (the bonds' wall indices refer to them).
    electrodes : dem.network.current.Electrodes
        The electrodes among ``walls``.
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).

    Returns
    -------
    tuple
        ``(flow, plane_index)``: the :class:`dem.network.current.CurrentFlow` with the particles' (centres')
        potentials (V), the floating particles, each particle's Joule heat (W) and their sum; its ``pair_current``
        and ``wall_current`` are those of the elements' edges (A). ``plane_index``: the electrode of each live wall
        bond to an electrode (for :func:`dem.network.current.require_paths`).

    Raises
    ------
    ValueError
        A particle touches two electrodes (its element would join them directly, which the solve has no edge for),
        no electrode is at a fixed potential, or the network has more than one flux mode per neck.
    """
    if np.any(net.col_end == DIPOLE):
        raise ValueError(f"neck_current: modes = {np.max(net.modes)}: the current takes one flux mode per neck (a "
                         f"dipole node is no node of Kirchhoff's graph)")
    p = net.particles
    n, m = p.n, len(net.live)
    row, col, value, _, end = net.entries
    owner, col_end = net.owner, net.col_end
    # each end's place: a neck's node, a wall end to an electrode that electrode (a plane), an insulated one a node
    electrode_of_wall = np.full(len(walls), -1, dtype=np.int64)
    electrode_of_wall[list(electrodes.walls)] = np.arange(len(electrodes))
    electrode = electrode_of_wall[net.bonds.wall_index[net.live_walls]]
    insulated = electrode < 0
    extra = n + m + np.cumsum(insulated) - 1
    n_nodes = n + m + int(insulated.sum())
    wall_node = np.concatenate([np.where(insulated, extra, -1), [-1]])  # per wall end (and a pad for a pair end)
    wall_plane = np.concatenate([electrode, [-1]])
    k_row, k_col = np.where(end >= 2 * m, end - 2 * m, -1), np.where(col_end >= 2 * m, col_end - 2 * m, -1)
    a, b = np.where(row >= 0, row, wall_node[k_row]), np.where(col >= 0, col, wall_node[k_col])
    plane_a, plane_b = np.where(row >= 0, -1, wall_plane[k_row]), np.where(col >= 0, -1, wall_plane[k_col])
    upper = end < col_end  # each pair of an element's nodes once (the centre is end -1)
    both = upper & (plane_a >= 0) & (plane_b >= 0)
    if np.any(both):
        k = int(owner[np.flatnonzero(both)[0]])
        raise ValueError(f"[conductance] nodes = \"necks\": particle {k} touches two electrodes, which its element "
                         f"would join directly; use nodes = \"particles\"")
    G = -value * (p.electrical_conductivity / p.conductivity)[owner]  # the element scaled by sigma / kappa
    edge = upper & (plane_a < 0) & (plane_b < 0)
    plane = upper & ~edge
    node = np.where(plane_a >= 0, b, a)[plane]
    plane_index = np.where(plane_a >= 0, plane_a, plane_b)[plane]
    flow = kirchhoff(n_nodes, a[edge], b[edge], G[edge], np.zeros(int(edge.sum())), node, plane_index, G[plane],
                     electrodes, linear)
    # each element's dissipation: sum over its pairs of nodes of G (phi_a - phi_b)^2 (floating nodes carry nothing)
    x = np.nan_to_num(flow.potential)
    V = np.nan_to_num(flow.electrode_potential)
    live = np.isfinite(flow.potential[node]) & np.isfinite(flow.electrode_potential[plane_index])
    joule = (np.bincount(owner[edge], G[edge] * (x[a[edge]] - x[b[edge]]) ** 2, n)
             + np.bincount(owner[plane], np.where(live, G[plane] * (V[plane_index] - x[node]) ** 2, 0.0), n))
    floating = flow.floating[flow.floating < n]
    return replace(flow, potential=flow.potential[:n].copy(), floating=floating, joule_particles=joule,
                   joule_heat=float(joule.sum())), plane_index
