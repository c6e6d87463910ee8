r"""The thermal submodel of Zohdi 2014: the lumped heat balance of each particle (eqs. 31-37).

:math:`m_i C_i \, d\theta_i/dt = Q_i + H_i` (eq. 31): :math:`Q_i` the heat conducted through the particle's contacts
(with walls that carry a temperature: isothermal planes) and :math:`H_i` its Joule heating (eq. 35;
:mod:`dem.engines.contact_current`). The contact conductance is the scene's ``[conductance] law`` on each contact as
it is, exactly as for a static packing: ``law = "zohdi"`` is the paper's :math:`K_{ij} A_{ij} / |r_i - r_j|` (eq. 33
with the lens area of eqs. 7-12; compiled on the Verlet list, :func:`dem.laws.lens_conductance.lens_list_conductances`),
any other law is evaluated on the bonds of the touching pairs (:func:`dem.geometry.bonds.find_bonds`,
:func:`dem.laws.conductance.bond_conductances`), ``"fit"`` the FE-verified neck law; with a pair-neck reading,
particles whose necks meet are handed over to the union of spheres at each accepted step (:mod:`dem.engines.handover`).

:math:`Q` is the flux of the contact network (:meth:`dem.network.laplacian.BoundedLaplacian.flux`, :math:`-L \theta`
plus the walls' terms) whose edges are the pairs of the mechanics' Verlet list and its particle-wall pairs with the
temperature-carrying walls, the pairs not in contact with :math:`K = 0`: between two rebuilds of the list the network
keeps its edges and only its conductances are rewritten (:meth:`~dem.network.laplacian.BoundedLaplacian.refresh`).

Integrated by the trapezoidal rule of eq. (36) with the weight :math:`\phi` of the mechanics, and solved -- as the
positions are -- by the fixed-point iteration of eq. (37), with the positions frozen at the iterate of the mechanics
(the staggering of eqs. 45-46):

.. math::

    \theta^K = \theta^L + \frac{\Delta t}{C} \Big(\phi \big(Q(\theta^{K-1}; r^K) + H\big)
    + (1 - \phi) (Q^L + H^L)\Big).

The current is refreshed when a step is accepted (Algorithm 1, step 6d), so :math:`H` is the Joule heating of the
configuration at the start of the step, at both ends of it. Every iteration's heat balance is exact: the change of
:math:`\sum C \theta` equals the heat that entered through the walls (and from fixed particles), weighted as in the
step, plus the Joule heat, to round-off (:meth:`LumpedHeat.energy_error`).

This is not the network's :math:`\theta` step (:class:`dem.network.theta.ThetaStepper`, at :math:`\theta = 1/2` the
trapezoid too; there :math:`\theta` is the method's weight and :math:`T` the temperatures), which solves
:math:`(C/\Delta t + \theta A)\,T^{+} = (C/\Delta t - (1-\theta) A)\,T + r` with one matrix :math:`A` to the linear
solver's tolerance. Here the two ends of a step see two networks: :math:`Q^L` on the contacts at the positions
:math:`r^L`, the new end on those at the iterate's positions :math:`r^K`, whose contacts grow, open and close within the
step (its conductances, even its edges, change); the weight is the mechanics' :math:`\phi`, any value in :math:`[0, 1]`,
shared with the positions; and the end is found by the fixed-point iteration above, each iterate explicit in the last
one and stopped where positions and temperatures together meet the step's tolerance (Zohdi 2014, eq. 48), not by a
linear solve. Only with the positions frozen and the iteration run to convergence is its limit that step at
:math:`\theta = \phi = 1/2`; the scheme is the paper's, kept as it is.
"""

from __future__ import annotations

import numpy as np

from dem.engines.handover import Handover
from dem.geometry.bonds import find_bonds
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.laws.lens_conductance import LENS_POLICY, lens_list_conductances
from dem.geometry.particles import Particles
from dem.engines.staggered import kernels
from dem.network.laplacian import BoundedLaplacian


def contact_pairs(particles: Particles, mech, x, T, wall_ids) -> tuple:
    """``(particles at x, walls, pairs)``: the touching pairs ``(i, j)`` of the Verlet list of ``mech`` at positions
    ``x``, and the walls ``wall_ids`` where the mechanics has them.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles (radii in m, materials, fixed flags, heat sources).
    mech : dem.engines.staggered.mechanics.StaggeredMechanics
        The mechanics: its Verlet lists, walls and periodic box.
    x : numpy.ndarray
        (N, 3) particle positions (m).
    T : numpy.ndarray
        (N,) temperatures (K).
    wall_ids : sequence of int
        Indices of the walls whose contacts are wanted.

    Returns
    -------
    tuple
        The particles at ``x`` with temperatures ``T``, the walls (:class:`dem.geometry.walls.Wall`) and the pairs.
    """
    closed = kernels.closed_pairs(x, particles.radius, mech.pi, mech.pj, mech.box)
    now = Particles(x, particles.radius, T, particles.material, particles.fixed, particles.heat, particles.materials)
    planes = [mech.walls[k].at(float(mech.w.q[k])) for k in wall_ids]
    return now, planes, (mech.pi[closed], mech.pj[closed])


def contact_bonds(particles: Particles, mech, x, T, wall_ids, contact: str, out_of_range: str):
    """``(particles at x, bonds)``: the bonds of :func:`contact_pairs`, with contact radii from the geometry
    ``contact`` (:func:`dem.geometry.bonds.find_bonds`; in the periodic box of ``mech`` across its faces).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles (radii in m, materials, fixed flags, heat sources).
    mech : dem.engines.staggered.mechanics.StaggeredMechanics
        The mechanics: its Verlet lists, walls and periodic box.
    x : numpy.ndarray
        (N, 3) particle positions (m).
    T : numpy.ndarray
        (N,) temperatures (K).
    wall_ids : sequence of int
        Indices of the walls whose contacts are wanted.
    contact : str
        The contact geometry (``dem.geometry.bonds.CONTACT_MODELS``).
    out_of_range : str
        The policy for contacts beyond the geometry's range: ``"error"``, ``"clip"`` or ``"drop"``.

    Returns
    -------
    tuple of (dem.geometry.particles.Particles, dem.geometry.bonds.Bonds)
        The particles at ``x`` with temperatures ``T``, and the bonds.

    Raises
    ------
    ValueError
        A contact beyond the geometry's range with ``out_of_range = "error"``.
    """
    now, planes, pairs = contact_pairs(particles, mech, x, T, wall_ids)
    return now, find_bonds(now, planes, contact, out_of_range, pairs=pairs, box=mech.periodic_box)


class LumpedHeat:
    """The temperatures of the particles (module docstring).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles: initial temperatures (K), capacities, conductivities, fixed flags.
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls; those with a temperature are isothermal planes.
    spec : dem.laws.conductance.ConductanceSpec
        The conductance law of the contacts.
    """

    name = "thermal"

    def __init__(self, particles: Particles, walls, spec: ConductanceSpec):
        self.particles, self.walls, self.spec = particles, tuple(walls), spec
        self.thermal_walls = [k for k, w in enumerate(self.walls) if w.temperature is not None]
        self.wall_T = np.array([self.walls[k].temperature for k in self.thermal_walls], dtype=float)
        self._plane_of_wall = np.full(len(self.walls), -1, dtype=np.int64)  # wall -> its index among thermal walls
        self._plane_of_wall[self.thermal_walls] = np.arange(len(self.thermal_walls))
        self.kappa = particles.conductivity
        self.contact_conductance = np.inf if spec.contact_conductance is None else spec.contact_conductance
        self.C = particles.capacity
        self.free = ~particles.fixed
        self.T = particles.temperature.astype(float).copy()  # theta^L
        self.T0 = self.T.copy()
        self.heat_in = {"boundaries": 0.0, "joule": 0.0}
        self.Q = np.zeros(particles.n)  # conducted heat at the start of the step, Q^L (W per particle)
        self._Q_iter = np.zeros(particles.n)
        self.graph: BoundedLaplacian | None = None  # the network on the Verlet list (module docstring)
        self._lists = None  # the mechanics' wall list (wk, wm) the plane bonds come from
        self.assemblies = self.refreshes = 0
        self.handover = Handover(spec, particles.radius)  # the hand-over to the union (dem.engines.handover)

    def _plane_bonds(self, mech):
        """The network's plane bonds: the listed particle-wall pairs of the walls with a temperature, as
        ``(particle, index among those walls, wall)`` (made again when the mechanics rebuilds its wall list)."""
        if self._lists is None or self._lists[0] is not mech.wk or self._lists[1] is not mech.wm:
            on_plane = self._plane_of_wall[mech.wm] >= 0
            wall = mech.wm[on_plane]
            self._planes = (mech.wk[on_plane], self._plane_of_wall[wall], wall)
            self._lists = (mech.wk, mech.wm)
        return self._planes

    def conductances(self, mech, x, T, update: bool = False):
        """``(K, K_w, plane_node, plane_index)``: the conductances (W/K) of the listed pairs (0 where they do not
        touch) and of the plane bonds, at positions ``x``; with a pair-neck reading through the hand-over to the
        union (:class:`dem.engines.handover.Handover`).

        Parameters
        ----------
        mech : dem.engines.staggered.mechanics.StaggeredMechanics
            The mechanics: its Verlet lists, walls and periodic box.
        x : numpy.ndarray
            (N, 3) particle positions (m).
        T : numpy.ndarray
            (N,) temperatures (K).
        update : bool
            Whether to advance the hand-overs at ``x`` (an accepted step does; an iterate does not).

        Returns
        -------
        tuple
            ``(K, K_w, plane_node, plane_index)``: W/K, W/K and the plane bonds' particles and walls.
        """
        plane_node, plane_index, wall = self._plane_bonds(mech)
        K, K_w = np.empty(len(mech.pi)), np.empty(len(plane_node))
        if self.spec.law == "zohdi":
            bad = lens_list_conductances(x, self.particles.radius, self.kappa, self.contact_conductance,
                                         LENS_POLICY[self.spec.out_of_range], (mech.pi, mech.pj), mech.w,
                                         (plane_node, wall), K, K_w, mech.box)
            if bad:  # find_bonds names the first contact the policy cannot take
                contact_bonds(self.particles, mech, x, T, self.thermal_walls, "lens", self.spec.out_of_range)
                raise RuntimeError(f"{bad} lens contacts out of range that find_bonds accepts")
            return K, K_w, plane_node, plane_index
        if Handover.applies(self.spec, mech.state.dimension):
            now, planes, pairs = contact_pairs(self.particles, mech, x, T, self.thermal_walls)
            b, K_b, K_wb = self.handover.bonds(now, planes, pairs, mech.periodic_box, update)
        else:
            now, b = contact_bonds(self.particles, mech, x, T, self.thermal_walls, self.spec.contact,
                                   self.spec.out_of_range)
            K_b, K_wb = bond_conductances(self.spec, now, b, box=mech.periodic_box,
                                          walls=[self.walls[k].at(float(mech.w.q[k])) for k in self.thermal_walls])
        n = self.particles.n
        K[:] = 0.0
        K[np.searchsorted(mech.pi * n + mech.pj, b.i * n + b.j)] = K_b  # the list is sorted by (i, j)
        K_w[:] = 0.0
        if b.n_walls:
            key = plane_index * n + plane_node
            order = np.argsort(key, kind="stable")
            K_w[order[np.searchsorted(key[order], b.wall_index * n + b.wall_particle)]] = K_wb
        return K, K_w, plane_node, plane_index

    def conduction(self, mech, x, T, update: bool = False) -> np.ndarray:
        """``Q_i`` (W) of eq. (33) at positions ``x`` (the contacts of the Verlet list of the mechanics ``mech``,
        the walls where it has them) and temperatures ``T``: the flux of the network (module docstring).

        Parameters
        ----------
        mech : dem.engines.staggered.mechanics.StaggeredMechanics
            The mechanics: its Verlet lists, walls and periodic box.
        x : numpy.ndarray
            (N, 3) particle positions (m).
        T : numpy.ndarray
            (N,) temperatures (K).
        update : bool
            Whether to advance the hand-overs at ``x`` (:meth:`conductances`).

        Returns
        -------
        numpy.ndarray
            (N,) ``Q_i`` (W).
        """
        K, K_w, plane_node, plane_index = self.conductances(mech, x, T, update)
        g = self.graph
        if g is not None and g.same_edges(mech.pi, mech.pj, plane_node, plane_index):
            g.refresh(mech.pi, mech.pj, K, plane_node, plane_index, K_w)
            self.refreshes += 1
        else:
            self.graph = g = BoundedLaplacian(self.particles.n, mech.pi, mech.pj, K, self.particles.fixed,
                                              plane_node, plane_index, K_w, len(self.thermal_walls))
            self.assemblies += 1
        return g.flux(T, self.wall_T)

    def start(self, mech) -> None:
        """:math:`Q^L` at the state of ``mech`` (the first step).

        Parameters
        ----------
        mech : dem.engines.staggered.mechanics.StaggeredMechanics
            The mechanics: its Verlet lists, walls and periodic box.
        """
        self.Q = self.conduction(mech, mech.state.x, self.T)

    def iterate(self, dt: float, phi: float, mech, T_prev, H) -> np.ndarray:
        r""":math:`\theta^K` of eq. (37) from the previous iterate ``T_prev`` at the positions of the latest iterate of
        the mechanics ``mech`` with the Joule heating ``H`` (W per particle).

        Parameters
        ----------
        dt : float
            The step (s).
        phi : float
            The trapezoidal weight of eq. (36), in ``[0, 1]``.
        mech : dem.engines.staggered.mechanics.StaggeredMechanics
            The mechanics: its Verlet lists, walls and periodic box.
        T_prev : numpy.ndarray
            (N,) the previous iterate's temperatures (K).
        H : numpy.ndarray
            (N,) Joule heating of each particle (W).

        Returns
        -------
        numpy.ndarray
            (N,) :math:`\theta^K` (K); the fixed particles keep theirs.
        """
        self._Q_iter = self.conduction(mech, mech.x_iterate, T_prev)
        T = self.T + dt / self.C * (phi * self._Q_iter + (1.0 - phi) * self.Q + H)
        T[~self.free] = self.T[~self.free]
        return T

    def accept(self, dt: float, phi: float, T, mech, H) -> None:
        """The iterate ``T`` becomes the state: the heat of the step is booked (with the flows the iteration used)
        and :math:`Q^L` of the next step is taken at the accepted state.

        Parameters
        ----------
        dt : float
            The step (s).
        phi : float
            The trapezoidal weight of eq. (36), in ``[0, 1]``.
        T : numpy.ndarray
            (N,) the accepted iterate's temperatures (K).
        mech : dem.engines.staggered.mechanics.StaggeredMechanics
            The mechanics: its Verlet lists, walls and periodic box.
        H : numpy.ndarray
            (N,) Joule heating of each particle (W).
        """
        f = self.free
        self.heat_in["boundaries"] += dt * float(phi * self._Q_iter[f].sum() + (1.0 - phi) * self.Q[f].sum())
        self.heat_in["joule"] += dt * float(np.sum(H[f]))
        self.T = np.array(T, dtype=float)
        self.Q = self.conduction(mech, mech.state.x, self.T, update=True)

    def energy_error(self) -> float:
        r""":math:`|\sum C (\theta - \theta_0) - Q_\mathrm{in}| / \mathrm{scale}`, :math:`Q_\mathrm{in}` the heat in,
        over the free particles (relative; the scale is the capacity times the temperature range plus the heat
        exchanged)."""
        f = self.free
        change = float(self.C[f] @ (self.T[f] - self.T0[f]))
        heat = sum(self.heat_in.values())
        scale = float(self.C[f].sum()) * max(float(np.ptp(self.T)), 1e-300) + sum(abs(v) for v in self.heat_in.values())
        return abs(change - heat) / scale if scale > 0 else 0.0
