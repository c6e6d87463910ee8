r"""The thermal pipe network: steady solve and time integration of :math:`C_i \, dT_i/dt = Q_i` (Rojek 2022, eqs.
2-4).

With the pipes :math:`Q_{ij} = K_{ij} (T_j - T_i)` (eq. 4), the heat balance of the free (not fixed) particles is
linear apart from radiation:

.. math::

    C \frac{dT}{dt} = r - A T, \qquad A = L_{FF} + \mathrm{diag}(K_\mathrm{wall} + g), \qquad
    r = -L_{FD} T_D + K_\mathrm{wall} T_\mathrm{wall} + Q_\mathrm{int} + b,

with :math:`L` the weighted graph Laplacian of the bonds (symmetric positive semidefinite, rows summing to zero),
:math:`F`/:math:`D` the free/fixed particles, :math:`(g, b)` the ambient exchange :math:`Q = b - g T` (convection;
radiation linearised about the current temperature, :func:`dem.laws.ambient.linear_sink_terms`). :math:`A` is built
once as a CSR matrix; it is SPD when every connected group of free particles reaches a fixed particle, a wall or the
ambient.

* :func:`steady` -- :math:`A T = r` (Newton on the radiation term); singular systems are detected and explained.
* :func:`integrate` -- the :math:`\theta` method
  :math:`(C/\Delta t + \theta A) T^+ = (C/\Delta t - (1 - \theta) A) T + r` with :math:`\theta = 0` (explicit
  forward Euler), 1 (implicit backward Euler), 1/2 (Crank-Nicolson); the matrix is factorised once per step size
  and reused. Explicit steps are stable only for :math:`\Delta t \le 2/\lambda_\max(C^{-1} A)`: a larger ``dt`` is
  refused with a message giving the limit. ``dt = "auto"`` controls the error: each step estimates its local
  error (explicit: the difference to Heun's step, free; implicit and Crank-Nicolson: step doubling, one step of
  :math:`\Delta t` against two of :math:`\Delta t/2`, the latter kept), rejects and redoes a step whose error
  exceeds the per-step tolerance and sets the next step by
  :math:`\Delta t \, \mathrm{clip}(0.9 \, (\mathrm{tol}/\mathrm{err})^{1/(q+1)}, 0.2, 5)` (:math:`q` the order: 1
  for explicit and implicit, 2 for Crank-Nicolson). The per-step tolerance :func:`step_tolerance` is set so that
  the global error, relative to the temperature range, is about ``rtol``. Implicit steps are
  :math:`t_\mathrm{end} / 2^k` on the dyadic grid of :math:`[0, t_\mathrm{end}]`, so the few step sizes used are
  factorised once each and the run ends exactly on :math:`t_\mathrm{end}`; explicit steps stay below 0.9 of the
  stable limit.

  Stiff steps: Crank-Nicolson's amplification factor :math:`(1 - z/2)/(1 + z/2)`, :math:`z = \lambda \Delta t`,
  turns negative for :math:`\Delta t > 2/\lambda` and tends to -1 for :math:`z \gg 1`: a fixed step far above the
  stiffest time constant keeps the initial temperature difference alternating for ever (a pair stays at 100 and
  0 C). Such a run (fixed ``dt`` above the stable limit :math:`2/\lambda_\max`) starts with ``STARTUP_STEPS``
  implicit Euler steps (Rannacher's start-up; amplification :math:`1/(1 + z)`, L-stable), which damp the stiff part
  of the initial data; the finite number of first-order steps keeps the run second order, and a step within the
  stable limit runs plain Crank-Nicolson as before. Whatever the integrator, a run whose
  ``max_principle_violation`` exceeds ``MAX_PRINCIPLE_TOLERANCE`` of the scene's temperature range (a run without
  internal heat and without a periodic temperature drop, either of which drives the network beyond it), or whose
  ``energy_error`` exceeds ``ENERGY_TOLERANCE``, is refused with a message naming ``dt``: its temperatures are
  wrong.

  ``python -m benchmarks dem`` measures steps, error and time of each integrator, fixed and ``"auto"`` at rtol
  1e-2 ... 1e-4, on the decay of a 2048-particle packing between plates (section "DEM transient: error against
  time"). The dyadic grid rounds every step down to a power of 2: it costs some more steps for the same error, but
  saves the second factorisation per step that free step sizes would need.

Periodic packings (:mod:`dem.geometry.periodic`): a bond to the image ``shift`` of particle :math:`j` sees that
image at :math:`T_j - g`, :math:`g = \mathrm{drop} \cdot \mathrm{shift}` (the temperature drop per period of the
box), so it adds the constant flow :math:`-K g` to :math:`i` and :math:`+K g` to :math:`j`; these enter :math:`r` as
the heat flow ``periodic``, which sums to zero over a group of free particles. Such a group (no fixed particle, wall
or ambient) has a steady state only up to a constant: :func:`steady` fixes it by keeping the group's
capacity-weighted mean temperature at its initial value (heat is conserved, so the transient ends there too), and
:func:`periodic_heat_flow` gives the heat flow across the period along each axis.

Energy bookkeeping: the heat flowing into the free particles through each boundary (fixed particles, walls,
convection, radiation, internal sources) is integrated with the same :math:`\theta` weighting as the step, so the
change of :math:`\sum_i C_i T_i` must match it to round-off; the relative mismatch is ``energy_error``. (An
iterative linear solve is shifted uniformly, by an amount of the order of its tolerance, so that its residuals sum
to zero.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from dem.geometry.bonds import Bonds, find_bonds
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.network.linsolve import make_solver
from dem.network.theta import ORDER, LocalSolves, ThetaStepper
from dem.network.laplacian import BoundedLaplacian, laplacian  # noqa: F401  (laplacian: part of this module's API)
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.laws.ambient import Sources, linear_sink_terms

INTEGRATORS = {"explicit": 0.0, "implicit": 1.0, "crank-nicolson": 0.5}
AUTO_LOCAL = {1: 10.0, 2: 15.0}  # dt = "auto": local tolerance k_q rtol^((q+1)/q) per step, :func:`step_tolerance`
AUTO_SAFETY = 0.9  # dt = "auto": safety factor of the step controller; explicit stays below this x the stable limit
AUTO_MIN_FACTOR, AUTO_MAX_FACTOR = 0.2, 5.0  # dt = "auto": bounds of the change of step per step
AUTO_LEVELS = 40  # implicit dt = "auto": steps t_end / 2^k, k <= AUTO_LEVELS
AUTO_CONDITION = 1e8  # dt = "auto": steps at most this x min(C_i / A_ii), the fastest time constant (conditioning)
AUTO_PROJECTION = 10.0  # dt = "auto": refuse once the current step projects this many x max_steps (after 100)
AUTO_MIN_STEP = 2.0**-AUTO_LEVELS  # dt = "auto": steps this small (x t_end) are accepted whatever their error
STARTUP_STEPS = 2  # fixed-step Crank-Nicolson above the stable limit: this many implicit Euler steps first
MAX_PRINCIPLE_TOLERANCE = 0.01  # max_principle_violation allowed, x the scene's temperature range
ROUND_OFF = math.sqrt(np.finfo(float).eps)  # ... and never below this x the largest prescribed |temperature|
ENERGY_TOLERANCE = 1e-6  # energy_error allowed at the end of a transient run


class BalanceScales:
    """The scales a heat balance is judged against, for a network that gives ``flow_sums(T_F, sinks)``, its
    ``particles``, ``wall_temperature`` and ``sources``: one particle per node (:class:`Network`) or a node per neck as
    well (:class:`dem.network.necks.NeckHeat`)."""

    def flow_magnitude(self, T_F: np.ndarray, sinks: dict) -> float:
        r"""Sum of the absolute heat flows into or out of each free node through its boundaries (W, the network's
        ``flow_sums``): the scale of the energy balance (hot and cold ends do not cancel in it).

        Each flow is a difference of terms :math:`K T`. Where (almost) no heat flows, the flows are the round-off of
        those terms and a balance relative to them means nothing, so the scale is never taken below
        :math:`\sqrt{\epsilon} \sum |K T|` (:math:`\epsilon` the machine precision): temperature differences below ~1e-8
        of the temperatures count as no flow.

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free nodes (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (the network's ``sinks``): W/K and W per free node.

        Returns
        -------
        float
            The scale (W).
        """
        net, gross = self.flow_sums(T_F, sinks)
        return float(max(net, np.sqrt(np.finfo(float).eps) * gross))

    def temperature_bounds(self) -> tuple[float, float]:
        """Lowest and highest temperature the scene prescribes (initial, fixed, walls, ambient)."""
        temps = [self.particles.temperature, self.wall_temperature]
        temps += [[s.T_inf] for s in (self.sources.convection, self.sources.radiation) if s is not None]
        allt = np.concatenate([np.ravel(t) for t in temps])
        return float(allt.min()), float(allt.max())

    def temperature_range(self) -> float:
        """The spread of :meth:`temperature_bounds` (K): the scale of the maximum-principle check."""
        lo, hi = self.temperature_bounds()
        return hi - lo


@dataclass
class Network(BalanceScales):
    """The linear(ised) heat balance of the free particles (module docstring), assembled once: the generic
    :class:`dem.network.laplacian.BoundedLaplacian` (the same solve serves the electrical current) with the particles'
    capacities, sources and fixed temperatures.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles: capacities (J/K), heat sources (W), fixed flags and temperatures (K or degC).
    bonds : dem.geometry.bonds.Bonds
        The pair and wall bonds.
    K_pairs : numpy.ndarray
        The pair bonds' conductances (W/K).
    K_walls : numpy.ndarray
        The wall bonds' conductances (W/K).
    wall_temperature : numpy.ndarray
        Each wall's temperature (K or degC), in the order of the walls the bonds index.
    sources : dem.laws.ambient.Sources
        The exchanges with the surroundings.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box, whose temperature drop per period drives the network; None: none.
    """

    particles: Particles
    bonds: Bonds
    K_pairs: np.ndarray
    K_walls: np.ndarray
    wall_temperature: np.ndarray
    sources: Sources = field(default_factory=Sources)
    box: PeriodicBox | None = None

    def __post_init__(self):
        p, b = self.particles, self.bonds
        self.graph = BoundedLaplacian(p.n, b.i, b.j, self.K_pairs, p.fixed, b.wall_particle, b.wall_index,
                                      self.K_walls, len(self.wall_temperature))
        self.free, self.fixed = self.graph.free, self.graph.fixed
        self.T_D = p.temperature[self.fixed]
        self.heat = p.heat[self.free]
        self.C = p.capacity[self.free]
        self.radius = p.radius[self.free]
        self.sources = self.sources.resolved(p.position, p.radius, self.free)  # "exposed" areas from the packing
        self._boundary_terms()

    # the Laplacian and its blocks live in the graph (refresh() rewrites them in place)
    L = property(lambda self: self.graph.L, doc="The pair bonds' Laplacian over all particles (W/K, CSR).")
    L_FF = property(lambda self: self.graph.L_FF, doc="Its block of the free particles (W/K, CSR).")
    L_FD = property(lambda self: self.graph.L_FD, doc="Its block coupling the free particles to the fixed (W/K, CSR).")

    def _boundary_terms(self):
        """The terms that follow from the conductances: wall and fixed-particle coefficients and the constant
        right-hand side."""
        g = self.graph
        self.wall_diag = g.plane_diag
        self.wall_rhs = g.plane_rhs(self.wall_temperature)
        self.fixed_rhs = -(g.L_FD @ self.T_D)
        self.fixed_diag = g.fixed_diag
        self.base_diag = g.laplacian_diagonal
        # the temperature jump of every bond across a periodic face (module docstring), zero without one
        n = self.particles.n
        self.jump = self.bonds.shifts @ self.box.drop if self.box is not None else np.zeros(self.bonds.n_pairs)
        self.periodic = bool(np.any(self.jump != 0.0))
        if self.periodic:
            jump_flow = self.K_pairs * self.jump
            self.jump_rhs = np.bincount(self.bonds.j, jump_flow, n) - np.bincount(self.bonds.i, jump_flow, n)
        else:  # what the sums give without a jump, without two passes over the bonds
            self.jump_rhs = np.zeros(n)
        self.periodic_rhs = self.jump_rhs[self.free]
        self.r_const = self.fixed_rhs + self.wall_rhs + self.heat + self.periodic_rhs

    def refresh(self, bonds: Bonds, K_pairs: np.ndarray, K_walls: np.ndarray) -> None:
        """New conductances (and bond geometry) on the same bonds, in the same order: the matrices keep their
        sparsity and only their entries are rewritten (no re-assembly, no new sparsity analysis).

        Parameters
        ----------
        bonds : dem.geometry.bonds.Bonds
            The same bonds, in the same order, with their geometry now.
        K_pairs : numpy.ndarray
            The pair bonds' conductances (W/K).
        K_walls : numpy.ndarray
            The wall bonds' conductances (W/K).

        Raises
        ------
        ValueError
            The bonds are not those of the network.
        """
        if not self.graph.same_edges(bonds.i, bonds.j, bonds.wall_particle, bonds.wall_index):
            raise ValueError("Network.refresh: the bonds changed; build a new Network")
        self.graph.refresh(bonds.i, bonds.j, K_pairs, bonds.wall_particle, bonds.wall_index, K_walls)
        self.bonds, self.K_pairs, self.K_walls = bonds, K_pairs, K_walls
        self._boundary_terms()

    @property
    def n_free(self) -> int:
        """The number of free particles (the unknowns)."""
        return len(self.free)

    @property
    def initial(self) -> np.ndarray:
        """The free particles' initial temperatures (K or degC), where :func:`integrate` starts."""
        return self.particles.temperature[self.free].astype(float)

    @property
    def flow_names(self) -> tuple:
        """The boundaries through which heat enters the free particles (keys of :meth:`flows`)."""
        return ("fixed", "walls", "internal", *self.sources.names) + (("periodic",) if self.periodic else ())

    def sinks(self, T_F: np.ndarray) -> dict:
        """The ambient exchange of the free particles as :math:`Q = b - g T`
        (:func:`dem.laws.ambient.linear_sink_terms`).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC).

        Returns
        -------
        dict
            ``{name: (g, b)}``: W/K and W per free particle.
        """
        return linear_sink_terms(self.sources, self.radius, T_F)

    def matrix(self, sinks: dict, shared: bool = False) -> sp.csr_matrix:
        r"""The system matrix :math:`A = L_{FF} + \mathrm{diag}(K_\mathrm{wall} + g)`, CSR.

        Parameters
        ----------
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`): W/K and W per free particle.
        shared : bool
            True: ``L_FF`` itself where ``A`` would be its copy, for a caller that neither writes into ``A`` nor keeps
            it past a :meth:`refresh` (:meth:`dem.network.laplacian.BoundedLaplacian.matrix`); False: a new matrix.

        Returns
        -------
        scipy.sparse.csr_matrix
            ``A`` (W/K).
        """
        return self.graph.matrix(sum((g for g, _ in sinks.values()), np.zeros(self.n_free)), shared)

    def rhs(self, sinks: dict) -> np.ndarray:
        """The right-hand side ``r`` of the module docstring.

        Parameters
        ----------
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`): W/K and W per free particle.

        Returns
        -------
        numpy.ndarray
            ``r`` per free particle (W).
        """
        return self.r_const + sum((b for _, b in sinks.values()), np.zeros(self.n_free))

    def flows(self, T_F: np.ndarray, sinks: dict, rows=None) -> dict:
        """Heat flow into the free particles (W) through each boundary at temperatures ``T_F``; ``rows``: into
        those free particles only (a mask over them: a rank's own in a distributed run).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`): W/K and W per free particle.
        rows : numpy.ndarray or None
            A mask over the free particles to sum over; None: all.

        Returns
        -------
        dict
            ``{boundary: W}`` for :attr:`flow_names`.
        """
        s = slice(None) if rows is None else rows
        out = {"fixed": float(self.fixed_rhs[s].sum() - self.fixed_diag[s] @ T_F[s]),
               "walls": float(self.wall_rhs[s].sum() - self.wall_diag[s] @ T_F[s]),
               "internal": float(self.heat[s].sum())}
        for name, (g, b) in sinks.items():
            out[name] = float(b[s].sum() - g[s] @ T_F[s])
        if self.periodic:
            out["periodic"] = float(self.periodic_rhs[s].sum())
        return out

    def flow_sums(self, T_F: np.ndarray, sinks: dict, rows=None) -> tuple[float, float]:
        """``(sum |flow|, sum |K T|)`` over the boundaries of the free particles (or of ``rows``, as in
        :meth:`flows`): the two sums behind :meth:`BalanceScales.flow_magnitude`.

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`sinks`): W/K and W per free particle.
        rows : numpy.ndarray or None
            A mask over the free particles to sum over; None: all.

        Returns
        -------
        tuple of (float, float)
            The two sums (W).
        """
        s = slice(None) if rows is None else rows
        pairs = [(self.fixed_diag, self.fixed_rhs), (self.wall_diag, self.wall_rhs), *sinks.values()]  # (g, b)
        net = gross = float(np.abs(self.heat[s]).sum() + np.abs(self.periodic_rhs[s]).sum())
        for g, b in pairs:
            net += float(np.abs(b[s] - g[s] * T_F[s]).sum())
            gross += float(np.abs(b[s]).sum() + np.abs(g[s] * T_F[s]).sum())
        return net, gross

    def full(self, T_F: np.ndarray) -> np.ndarray:
        """All particles' temperatures: ``T_F`` on the free ones, the fixed ones' own.

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC).

        Returns
        -------
        numpy.ndarray
            (N,) temperatures (K or degC).
        """
        T = self.particles.temperature.copy()
        T[self.free] = T_F
        return T


def build_network(particles: Particles, walls=(), spec=None, sources: Sources | None = None, *, pairs=None,
                  bonds: Bonds | None = None, box: PeriodicBox | None = None) -> Network:
    """The thermal network of a packing in one call: bonds from the overlaps (:func:`dem.geometry.bonds.find_bonds`,
    with the contact model and out-of-range policy of ``spec``), their conductances
    (:func:`~dem.laws.conductance.bond_conductances`, Rojek 2022 eqs. 5-9), and the assembled :class:`Network`
    holding both.

    ``walls`` are :class:`dem.geometry.walls.Wall` planes, ``spec`` a :class:`~dem.laws.conductance.ConductanceSpec`
    (default: the ``rojek`` law), ``sources`` the ambient exchange and ``pairs = (i, j)`` the pair bonds to use
    instead of searching for overlaps. ``bonds`` already found (e.g. to time the search apart) skip the search. To
    impose other pair conductances, replace them: ``dataclasses.replace(net, K_pairs=K)``. ``box``: a periodic box
    (:mod:`dem.geometry.periodic`), whose faces bonds cross and whose temperature drop per period drives the network.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (positions and radii in m, temperatures, materials).
    walls : sequence of dem.geometry.walls.Wall
        The walls; those with a temperature are bonded to the particles touching them.
    spec : dem.laws.conductance.ConductanceSpec or None
        The contact geometry and conductance law; None: the ``rojek`` law.
    sources : dem.laws.ambient.Sources or None
        The exchanges with the surroundings; None: none.
    pairs : tuple of numpy.ndarray or None
        ``(i, j)`` pair bonds to use instead of searching for overlaps; None: search.
    bonds : dem.geometry.bonds.Bonds or None
        Bonds already found (the search is skipped); None: find them.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.

    Returns
    -------
    Network
        The assembled network.

    Raises
    ------
    ValueError
        A bond beyond the contact model's range (with ``out_of_range = "error"``) or a conductance that is not finite.
    """
    spec = ConductanceSpec() if spec is None else spec
    walls = tuple(walls)
    bonds, K_pairs, K_walls = bonds_and_conductances(particles, walls, spec, pairs=pairs, bonds=bonds, box=box)
    wall_temperature = np.array([w.temperature for w in walls], dtype=float)
    return Network(particles, bonds, K_pairs, K_walls, wall_temperature,
                   Sources() if sources is None else sources, box)


def bonds_and_conductances(particles: Particles, walls, spec, *, pairs=None, bonds: Bonds | None = None,
                           box: PeriodicBox | None = None) -> tuple[Bonds, np.ndarray, np.ndarray]:
    """The bonds of ``particles`` (and ``walls``) and their pair and wall conductances: the first half of
    :func:`build_network`, for a network whose bonds change while its particles stay (:mod:`dem.engines.contact_heat`).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (positions and radii in m, temperatures, materials).
    walls : sequence of dem.geometry.walls.Wall
        The walls; those with a temperature are bonded to the particles touching them.
    spec : dem.laws.conductance.ConductanceSpec
        The contact geometry and conductance law.
    pairs : tuple of numpy.ndarray or None
        ``(i, j)`` pair bonds to use instead of searching for overlaps; None: search.
    bonds : dem.geometry.bonds.Bonds or None
        Bonds already found (the search is skipped); None: find them.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.

    Returns
    -------
    tuple
        ``(bonds, K_pairs, K_walls)``: the bonds and their conductances (W/K).

    Raises
    ------
    ValueError
        A bond beyond the contact model's range (with ``out_of_range = "error"``) or a conductance that is not finite.
    """
    if bonds is None:
        bonds = find_bonds(particles, tuple(walls), spec.contact, spec.out_of_range, pairs=pairs, box=box)
    return (bonds, *bond_conductances(spec, particles, bonds, box=box, walls=tuple(walls)))


def boundary_heat_flow(net: Network, T: np.ndarray) -> dict:
    """W into each fixed particle (from its bonds and walls) and into each wall, at full temperatures ``T``.

    Parameters
    ----------
    net : Network
        The network.
    T : numpy.ndarray
        (N,) the temperatures of all particles (K or degC).

    Returns
    -------
    dict
        ``{"particles": {index: W}, "walls": (W,) array of W}``.
    """
    p, b = net.particles, net.bonds
    into_fixed = -(net.L @ T) + net.jump_rhs
    to_wall = net.K_walls * (T[b.wall_particle] - net.wall_temperature[b.wall_index])
    into_fixed -= np.bincount(b.wall_particle, to_wall, p.n)
    n_walls = len(net.wall_temperature)
    walls = np.bincount(b.wall_index, to_wall, n_walls) if n_walls else np.zeros(0)
    return {"particles": {int(k): float(into_fixed[k]) for k in net.fixed}, "walls": walls}


def periodic_heat_flow(net: Network, T: np.ndarray) -> np.ndarray:
    """Heat flow (W) across the period along x, y and z at full temperatures ``T``: every bond's flow from ``i``
    to the image ``shift`` of ``j``, ``K (T_i - T_j + g)``, times ``shift`` (a bond spanning ``s`` periods crosses
    ``s`` of the period's planes). In a steady state it is the flow through any plane normal to that axis.

    Parameters
    ----------
    net : Network
        The network.
    T : numpy.ndarray
        (N,) the temperatures of all particles (K or degC).

    Returns
    -------
    numpy.ndarray
        (3,) the heat flow along x, y, z (W).
    """
    b = net.bonds
    q = net.K_pairs * (T[b.i] - T[b.j] + net.jump)
    return q @ b.shifts

# -------------------------------------------------------------------------------------------------- steady
@dataclass
class SteadyResult:
    """What :func:`steady` found.

    Parameters
    ----------
    T : numpy.ndarray
        (N,) the steady temperatures of all particles (K or degC).
    flows : dict
        Heat flow into the free particles through each boundary (W).
    energy_error : float
        The relative mismatch of the heat balance.
    iterations : int
        Newton iterations (1 without radiation).
    solver : str
        The linear solver that ran.
    floating : int
        Number of floating groups held at their mean temperature.
    """

    T: np.ndarray
    flows: dict
    energy_error: float
    iterations: int
    solver: str
    floating: int = 0


def _components(net: Network):
    """Connected components of the free particles, whether each is anchored (reaches a fixed temperature, a wall
    or an ambient), and whether it holds a bond across a periodic face with a temperature jump."""
    sinks = net.sinks(net.particles.temperature[net.free])
    n_comp, label, anchored = net.graph.components(sum((g for g, _ in sinks.values()), np.zeros(net.n_free)))
    jumping = np.zeros(n_comp, dtype=bool)
    if net.periodic:
        position = np.full(net.particles.n, -1)
        position[net.free] = np.arange(net.n_free)
        free_i = position[net.bonds.i[net.jump != 0.0]]
        jumping[label[free_i[free_i >= 0]]] = True
    return n_comp, label, anchored, jumping


def steady(net: Network, floating: str = "error", linear: str = "auto", max_newton: int = 50,
           rtol: float = 1e-10) -> SteadyResult:
    """Steady temperatures ``A T = r`` (Rojek 2022, eq. 2 with dT/dt = 0).

    A connected group of free particles with no fixed particle, wall or ambient exchange makes ``A`` singular.
    Where the group holds bonds across a periodic face with a temperature jump it has a steady state up to a
    constant, fixed by keeping its capacity-weighted mean temperature at the initial one. Otherwise
    ``floating = "error"`` explains and refuses; ``"mean"`` keeps such a group at the capacity-weighted mean of its
    initial temperatures (the long-time limit of the transient), provided its internal sources sum to zero.

    Parameters
    ----------
    net : Network
        The network.
    floating : str
        ``"error"`` or ``"mean"`` (above).
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    max_newton : int
        The most Newton iterations on radiation.
    rtol : float
        The relative residual of iterative linear solves.

    Returns
    -------
    SteadyResult
        The temperatures and heat flows.

    Raises
    ------
    ValueError
        A floating group with ``floating = "error"`` or with a net source, a bad ``floating``, or a Newton iteration
        that did not converge.
    """
    T_F = net.particles.temperature[net.free].astype(float)
    n_comp, label, anchored, jumping = _components(net)
    gauged = ~anchored & jumping
    n_float = int((~anchored & ~jumping).sum())

    def no_solution(lost):
        comp = label[lost]
        net_heat = np.bincount(comp, net.heat[lost], n_comp)
        scale = np.bincount(comp, np.abs(net.heat[lost]), n_comp)
        if np.any(np.abs(net_heat) > 1e-12 * np.maximum(scale, 1e-300)):
            raise ValueError("steady problem has no solution: a floating group of particles (no fixed temperature, "
                             "wall or ambient) has a net internal heat source, so it heats up forever")

    if n_float:
        lost = np.flatnonzero(~anchored[label] & ~jumping[label])
        if floating == "error":
            first = net.free[lost[:8]].tolist()
            raise ValueError(f"steady problem is singular: {n_float} of {n_comp} connected group(s) of free particles "
                             f"({len(lost)} particles, e.g. {first}) touch no fixed particle, wall, convection or "
                             f"radiation, so their temperature is undetermined; fix a particle's temperature, add a "
                             f"wall or an ambient, set solver.floating = \"mean\", or use mode = \"transient\"")
        if floating != "mean":
            raise ValueError(f"solver.floating = {floating!r}: must be error or mean")
        no_solution(lost)
        comp = label[lost]
        energy = np.bincount(comp, net.C[lost] * T_F[lost], n_comp)
        cap = np.bincount(comp, net.C[lost], n_comp)
        T_F[lost] = energy[comp] / cap[comp]
    # a gauged group is solved with one particle (its first) held at 0, then shifted to its initial mean
    solve = anchored[label] | gauged[label]
    ground = np.zeros(net.n_free, dtype=bool)
    if np.any(gauged):
        no_solution(np.flatnonzero(gauged[label]))
        first = np.full(n_comp, -1)
        members = np.flatnonzero(gauged[label])
        first[label[members[::-1]]] = members[::-1]
        ground[first[gauged]] = True
        target = np.bincount(label, net.C * T_F, n_comp)
        T_F[ground] = 0.0
        solve &= ~ground
    iterations, backend = solve_steady(net, T_F, np.flatnonzero(solve), linear, max_newton, rtol)
    if np.any(gauged):
        cap = np.bincount(label, net.C, n_comp)
        shift = (target - np.bincount(label, net.C * T_F, n_comp)) / cap
        in_gauged = gauged[label]
        T_F[in_gauged] += shift[label[in_gauged]]
    # radiation: report the exact T^4 flow at the solution
    sinks = net.sinks(T_F)
    flows = net.flows(T_F, sinks)
    total = net.flow_magnitude(T_F, sinks)
    err = abs(sum(flows.values())) / total if total > 0 else 0.0
    return SteadyResult(net.full(T_F), flows, err, iterations, backend, n_float)


def solve_steady(net, T_F: np.ndarray, solve_idx: np.ndarray, linear: str = "auto", max_newton: int = 50,
                 rtol: float = 1e-10) -> tuple[int, str]:
    """The steady balance ``A(T) T = r(T)`` of ``net`` on its free nodes ``solve_idx``, written into ``T_F``: one
    linear solve, or with radiation Newton's iteration on its :math:`T^4` (linearised about the last iterate,
    :func:`dem.laws.ambient.linear_sink_terms`; the matrix changes on its diagonal only, so the last AMG hierarchy
    serves again) until no temperature changes by more than 1e-12 of the temperatures' scale. The nodes left out
    are held where ``T_F`` has them and must not drive the others (held at 0, or in groups of their own). The one
    solve of :func:`steady` and of the network with a node per neck (:func:`dem.network.necks.steady_necks`).

    Parameters
    ----------
    net : Network or dem.network.necks.NeckHeat
        The network: its ``sinks``, ``matrix``, ``rhs``, ``base_diag``, ``sources`` and ``temperature_range``.
    T_F : numpy.ndarray
        Temperatures of its free nodes (K or degC): the start of the iteration; overwritten on ``solve_idx``.
    solve_idx : numpy.ndarray
        Positions in the free nodes to solve for.
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    max_newton : int
        The most Newton iterations on radiation.
    rtol : float
        The relative residual of iterative linear solves.

    Returns
    -------
    tuple of (int, str)
        The iterations taken (1 without radiation) and the linear solver that ran.

    Raises
    ------
    ValueError
        Newton's iteration did not converge in ``max_newton`` iterations.
    """
    T_sub = T_F[solve_idx]
    restrict = None if len(solve_idx) == net.n_free else solve_idx
    iterations, backend, solver = 0, "none", None
    for iterations in range(1, max_newton + 1):
        T_F[solve_idx] = T_sub
        sinks = net.sinks(T_F)
        A, r = net.matrix(sinks, shared=True), net.rhs(sinks)  # the solver, discarded here, only reads A
        if restrict is not None:
            A, r = A[restrict][:, restrict], r[restrict]
        if len(r) == 0:
            break
        solver = make_solver(A, linear, net.base_diag if restrict is None else net.base_diag[restrict], rtol,
                             previous=solver)
        backend = solver.name
        T_new = solver.solve(r, T_sub)
        change = np.max(np.abs(T_new - T_sub)) if net.sources.radiation is not None else 0.0
        T_sub = T_new
        if change <= 1e-12 * max(net.temperature_range(), np.max(np.abs(T_sub)), 1e-300):
            break
    else:
        raise ValueError(f"steady radiation (Newton) did not converge in {max_newton} iterations")
    T_F[solve_idx] = T_sub
    return iterations, backend


# ------------------------------------------------------------------------------------------------ transient
def stable_limit(net: Network, sinks: dict | None = None) -> float:
    r"""Largest stable explicit step :math:`2 / \lambda_\max(C^{-1} A)` (``inf`` without any coupling).

    :math:`\lambda_\max` from Lanczos on the symmetric :math:`C^{-1/2} A C^{-1/2}` (dense for small systems); where
    Lanczos fails the Gershgorin bound :math:`\lambda_\max \le \max_i 2 A_{ii} / C_i` gives a safe (smaller)
    limit. Massless nodes (``C = 0``: the necks of :mod:`dem.network.necks`) are condensed out first: the limit is
    that of the Schur complement :math:`S = A_{cc} - A_{cn} A_{nn}^{-1} A_{nc}` on the nodes with a capacity, whose
    largest eigenvalue is at most that of :math:`A_{cc}` (so the Gershgorin bound on :math:`A_{cc}` stays safe).

    Parameters
    ----------
    net : Network
        The network (or one with massless nodes, :class:`dem.network.necks.NeckHeat`).
    sinks : dict or None
        The ambient terms to linearise with; None: at the initial temperatures.

    Returns
    -------
    float
        The limit (s).
    """
    sinks = net.sinks(net.initial) if sinks is None else sinks
    A = net.matrix(sinks)
    if net.n_free == 0 or A.nnz == 0 or not np.any(A.diagonal() > 0):
        return math.inf
    heavy = net.C > 0.0
    C, A_cc = (net.C, A) if np.all(heavy) else (net.C[heavy], A[heavy][:, heavy])
    s = 1.0 / np.sqrt(C)
    if A_cc is A:
        S = sp.diags(s) @ A @ sp.diags(s)
    else:  # the massless nodes condensed out (the docstring)
        A_nc, lu = A[~heavy][:, heavy], spl.splu(A[~heavy][:, ~heavy].tocsc())
        S = spl.LinearOperator(A_cc.shape, dtype=float, matvec=lambda x: s * (
            A_cc @ (s * np.ravel(x)) - A_nc.T @ lu.solve(A_nc @ (s * np.ravel(x)))))
    if len(C) <= 400:
        lam = float(np.linalg.eigvalsh(S @ np.eye(len(C)) if A_cc is not A else S.toarray())[-1])
    else:
        try:
            lam = float(spl.eigsh(S, k=1, which="LA", tol=1e-8, return_eigenvectors=False,
                                  maxiter=5000)[0]) * (1 + 1e-7)
        except spl.ArpackNoConvergence:
            lam = float(np.max(2.0 * A_cc.diagonal() / C))
    return 2.0 / lam if lam > 0 else math.inf


def surely_stiff(dt: float, A: sp.csr_matrix, C: np.ndarray, rows=None, largest=None) -> bool:
    r"""Whether the step ``dt`` is surely above the stable limit :math:`2 / \lambda_\max(C^{-1} A)`
    (:func:`stable_limit`) without computing an eigenvalue: :math:`\Delta t > 2 / \max_i (A_{ii} / C_i)`, the largest
    :math:`A_{ii} / C_i` being a lower bound of :math:`\lambda_\max` (the Rayleigh quotient of a unit vector). Where
    it is not, Crank-Nicolson keeps the maximum principle (its explicit half :math:`C/\Delta t - A/2` has no negative
    entry) and no mode's amplification factor is below -1/3
    (:math:`z = \lambda \Delta t \le 2 \Delta t \max_i A_{ii} / C_i \le 4`, Gershgorin): no start-up is needed.

    Parameters
    ----------
    dt : float
        The step (s).
    A : scipy.sparse.csr_matrix
        The system matrix (W/K, :meth:`dem.network.heat.Network.matrix`).
    C : numpy.ndarray
        The capacities of its rows (J/K).
    rows : numpy.ndarray or None
        A mask over the rows to take (a rank's own in a distributed run); None: all.
    largest : callable or None
        The largest of a value over the processes that share the network (a rank's over the ranks); None: this
        process holds it all.

    Returns
    -------
    bool
        ``dt`` is above ``2 / max_i (A_ii / C_i)``.
    """
    s = slice(None) if rows is None else rows
    rate = float(np.max(A.diagonal()[s] / C[s], initial=0.0))
    rate = rate if largest is None else largest(rate)
    return rate > 0.0 and dt > 2.0 / rate


@dataclass
class TransientResult:
    """What :func:`integrate` found.

    Parameters
    ----------
    T : numpy.ndarray
        (N,) the temperatures of all particles at the end (K or degC).
    t : float
        The time reached (s).
    steps : int
        Accepted steps.
    rejected : int
        Rejected steps (``dt = "auto"``).
    energy_error : float
        The relative mismatch of the heat balance.
    heat_in : dict
        Energy that entered the free particles through each boundary (J).
    stable_limit : float or None
        The explicit stability limit (s), where it was computed.
    dt_min : float
        The smallest step taken (s).
    dt_max : float
        The largest step taken (s).
    solver : str
        The linear solver that ran.
    factorizations : int
        Number of system solvers built.
    max_principle_violation : float or None
        The largest excursion beyond the prescribed temperatures (K); None with internal sources.
    startup_steps : int
        Implicit Euler steps that started a stiff Crank-Nicolson run.
    """

    T: np.ndarray
    t: float
    steps: int
    rejected: int
    energy_error: float
    heat_in: dict
    stable_limit: float | None
    dt_min: float
    dt_max: float
    solver: str
    factorizations: int
    max_principle_violation: float | None = None
    startup_steps: int = 0  # implicit Euler steps that started a stiff Crank-Nicolson run (module docstring)


def theta_step(net: Network, T_F: np.ndarray, dt: float, integrator: str = "implicit", linear: str = "auto",
               rtol_linear: float = 1e-10) -> tuple[np.ndarray, dict]:
    """One theta-method step of size ``dt`` from the free temperatures ``T_F`` on ``net`` (a network whose
    conductances change between steps, e.g. necks that grow): ``(T_new, heat)`` with ``heat`` the energy (J) that
    entered the free particles through each boundary during the step, integrated with the step's own weighting so
    that ``C . (T_new - T_F)`` equals its sum to round-off.

    Parameters
    ----------
    net : Network
        The network.
    T_F : numpy.ndarray
        Temperatures of the free particles (K or degC).
    dt : float
        The step (s).
    integrator : str
        ``"explicit"``, ``"implicit"`` or ``"crank-nicolson"``.
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol_linear : float
        The relative residual of iterative linear solves.

    Returns
    -------
    tuple of (numpy.ndarray, dict)
        The free temperatures after the step, and ``{boundary: J}``.
    """
    T_new, T_theta, sinks = ThetaStepper(net, INTEGRATORS[integrator], LocalSolves(linear, rtol_linear)).step(T_F, dt)
    return T_new, {k: dt * v for k, v in net.flows(T_theta, sinks).items()}


def check_step_count(t_end: float, dt: float, max_steps: int, what: str):
    """Refuse a fixed-step run of more than ``max_steps`` steps up front.

    Parameters
    ----------
    t_end : float
        The run's end (s).
    dt : float
        The step (s).
    max_steps : int
        The most steps allowed.
    what : str
        What the message names first (``"solver.dt = 1e-3 s"``, say).

    Raises
    ------
    ValueError
        ``t_end / dt > max_steps``.
    """
    steps = t_end / dt
    if steps > max_steps:
        raise ValueError(f"{what}: t_end / dt = {steps:.3g} steps exceeds solver.max_steps = {max_steps}; "
                         f"raise max_steps, shorten t_end or use a larger dt (implicit or crank-nicolson)")


def step_tolerance(rtol: float, order: int) -> float:
    r"""Local error allowed per step (relative to the temperature range) for a global error of about ``rtol``.

    An order-:math:`q` method whose steps each make a local error :math:`\tau` ends :math:`\sim c \tau^{q/(q+1)}` off
    (the steps shrink with :math:`\tau^{1/(q+1)}`), so
    :math:`\tau = \min(\mathrm{rtol}, k_q \mathrm{rtol}^{(q+1)/q})`; :math:`k_q` (``AUTO_LOCAL``) is calibrated
    on the decay of a pair and of a packing between plates (global errors 0.1-1 x rtol for rtol 1e-2 ... 1e-4).

    Parameters
    ----------
    rtol : float
        The global error wanted, relative to the temperature range.
    order : int
        The method's order q: 1 or 2.

    Returns
    -------
    float
        :math:`\tau`, relative to the temperature range.
    """
    return min(rtol, AUTO_LOCAL[order] * rtol ** ((order + 1) / order))


def _controller_factor(err: float, tol: float, order: int) -> float:
    """The standard step-size factor ``clip(safety (tol/err)^(1/(q+1)), 0.2, 5)`` (Hairer, Norsett & Wanner,
    Solving ODEs I, sec. II.4)."""
    if err <= 0.0:
        return AUTO_MAX_FACTOR
    return min(AUTO_MAX_FACTOR, max(AUTO_MIN_FACTOR, AUTO_SAFETY * (tol / err) ** (1.0 / (order + 1))))


@dataclass
class Checkpoint:
    r"""Where :func:`integrate` stands after an accepted step: everything its loop carries, so that a run resumed
    from it ends bit for bit where the uninterrupted run ends (the linear solvers' warm starts included).

    Parameters
    ----------
    T : numpy.ndarray
        The free particles' temperatures (K or degC).
    t : float
        The time (s).
    steps : int
        Accepted steps so far.
    rejected : int
        Rejected steps so far.
    units : int
        The time on the dyadic grid, :math:`t = t_\mathrm{end} \cdot \mathrm{units} / 2^{\mathrm{AUTO\_LEVELS}}`
        (implicit ``dt = "auto"``).
    dt_want : float
        The step the controller asks for next (s).
    heat_in : dict
        Energy that entered through each boundary so far (J).
    abs_in : float
        The sum of the absolute heat exchanged so far (J), the energy balance's scale.
    dt_min : float
        The smallest step so far (s).
    dt_max : float
        The largest step so far (s).
    violation : float
        The largest excursion beyond the prescribed temperatures so far (K).
    energy0 : float
        ``sum C T`` at the start (J).
    history : list
        The stepper's ``(T, dt)`` of the last accepted steps (its warm starts).
    """

    T: np.ndarray
    t: float
    steps: int
    rejected: int
    units: int
    dt_want: float
    heat_in: dict
    abs_in: float
    dt_min: float
    dt_max: float
    violation: float
    energy0: float
    history: list  # the stepper's (T, dt) of the last accepted steps

    def arrays(self) -> dict:
        """As arrays for ``numpy.savez`` (:meth:`from_arrays` reads them back)."""
        out = {"T": self.T, "heat_keys": np.array(list(self.heat_in), dtype=str),
               "heat_values": np.array(list(self.heat_in.values()), dtype=float),
               "history_T": np.array([h[0] for h in self.history]).reshape(len(self.history), -1),
               "history_dt": np.array([h[1] for h in self.history], dtype=float)}
        for key in ("t", "steps", "rejected", "units", "dt_want", "abs_in", "dt_min", "dt_max", "violation",
                    "energy0"):
            out[key] = np.array(getattr(self, key))
        return out

    @classmethod
    def from_arrays(cls, data: dict) -> "Checkpoint":
        """The checkpoint of :meth:`arrays`.

        Parameters
        ----------
        data : dict
            The arrays, as loaded from the ``.npz``.

        Returns
        -------
        Checkpoint
            The checkpoint.
        """
        history = [(data["history_T"][k], float(data["history_dt"][k])) for k in range(len(data["history_dt"]))]
        heat = {str(k): float(v) for k, v in zip(data["heat_keys"], data["heat_values"])}
        return cls(np.array(data["T"], dtype=float), float(data["t"]), int(data["steps"]), int(data["rejected"]),
                   int(data["units"]), float(data["dt_want"]), heat, float(data["abs_in"]), float(data["dt_min"]),
                   float(data["dt_max"]), float(data["violation"]), float(data["energy0"]), history)


class WholeNetwork:
    """The network held whole by this one process, as :func:`integrate` takes the processes that share it
    (``part``): its sums and extremes are this process's own values and its rows all of them. The counterpart on
    MPI ranks is :class:`dem.network.distributed.DistributedNetwork`, one rank's part of the network.

    Parameters
    ----------
    net : Network
        The network.
    """

    own_free = slice(None)  # the rows of the free particles this process answers for: all

    def __init__(self, net: Network):
        self.net = net

    @staticmethod
    def total(value):
        """``value`` itself: the sum over the one process.

        Parameters
        ----------
        value : float or int
            This process's part.

        Returns
        -------
        float or int
            The sum.
        """
        return value

    minimum = maximum = total

    @staticmethod
    def agree(action):
        """``action()``: what raises here raises on every process (the one).

        Parameters
        ----------
        action : callable
            Called without arguments.

        Returns
        -------
        object
            Its result.
        """
        return action()

    def flows(self, T_F: np.ndarray, sinks: dict) -> dict:
        """Heat flow (W) into the free particles through each boundary (:meth:`Network.flows`).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`Network.sinks`): W/K and W per particle.

        Returns
        -------
        dict
            ``{boundary: W}``.
        """
        return self.net.flows(T_F, sinks)

    def flow_magnitude(self, T_F: np.ndarray, sinks: dict) -> float:
        """The scale of the heat flows (W, :meth:`BalanceScales.flow_magnitude`).

        Parameters
        ----------
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC).
        sinks : dict
            The ambient terms ``{name: (g, b)}`` (:meth:`Network.sinks`): W/K and W per particle.

        Returns
        -------
        float
            The scale (W).
        """
        return self.net.flow_magnitude(T_F, sinks)

    def above_stable_limit(self, dt: float, T_F: np.ndarray) -> bool:
        """Whether a fixed step ``dt`` is above the stable limit at ``T_F`` (:func:`stable_limit`, from the largest
        eigenvalue): where a Crank-Nicolson run starts with implicit Euler steps (module docstring).

        Parameters
        ----------
        dt : float
            The step (s).
        T_F : numpy.ndarray
            Temperatures of the free particles (K or degC), where the ambient terms are linearised.

        Returns
        -------
        bool
            ``dt`` is above the limit.
        """
        return dt > stable_limit(self.net, self.net.sinks(T_F))


def integrate(net: Network, integrator: str = "crank-nicolson", dt="auto", t_end: float = 1.0, rtol: float = 1e-3,
              linear: str = "auto", max_steps: int = 1_000_000, observer=None, progress=None,
              rtol_linear: float = 1e-10, resume: Checkpoint | None = None, checkpoint=None, part=None,
              solves=None) -> TransientResult:
    """Integrate from the particles' initial temperatures to ``t_end`` (module docstring).

    One loop for one process and for MPI ranks: ``part`` is the processes that share the network (sums, extremes
    and flows over them, refusals on all alike) and ``solves`` the linear solves of the steps
    (:mod:`dem.network.theta`); on ranks :meth:`dem.network.distributed.DistributedNetwork.integrate` plugs in its
    part and :class:`dem.network.distributed.RankSolves` (fixed implicit or Crank-Nicolson steps only).

    ``observer(step, t, T_F, flows)`` is called after every accepted step (and at t = 0 with step 0);
    ``progress(t)`` reports the simulated time. ``checkpoint(make)`` is called after every accepted step and at the
    end with ``make()`` building the :class:`Checkpoint` (the caller decides how often to build and keep one);
    ``resume`` starts from such a checkpoint instead of t = 0.

    Parameters
    ----------
    net : Network
        The network, or one with massless nodes (:class:`dem.network.necks.NeckHeat`: no explicit steps; the
        maximum principle checked on the nodes with a capacity).
    integrator : str
        ``"explicit"``, ``"implicit"`` or ``"crank-nicolson"``.
    dt : float or str
        The step (s), or ``"auto"`` (error-controlled).
    t_end : float
        The time to integrate to (s), > 0.
    rtol : float
        The global error wanted with ``dt = "auto"``, relative to the temperature range.
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    max_steps : int
        The most steps.
    observer : callable or None
        ``observer(step, t, T_F, flows)``; None: not called.
    progress : callable or None
        ``progress(t)`` with the simulated time (s); None: not called.
    rtol_linear : float
        The relative residual of iterative linear solves.
    resume : Checkpoint or None
        The checkpoint to go on from; None: start at t = 0.
    checkpoint : callable or None
        ``checkpoint(make)`` after every accepted step, ``checkpoint(make, final=True)`` at the end; None: not called.
    part : WholeNetwork or dem.network.distributed.DistributedNetwork or None
        The processes that share ``net`` (this one's part of it); None: :class:`WholeNetwork`.
    solves : dem.network.theta.LocalSolves or dem.network.distributed.RankSolves or None
        The linear solves of the steps; None: :class:`dem.network.theta.LocalSolves` of ``linear`` and
        ``rtol_linear``.

    Returns
    -------
    TransientResult
        The temperatures at ``t_end`` and the run's account.

    Raises
    ------
    ValueError
        A bad argument, a step above the explicit stability limit, too many steps, or temperatures that came out
        wrong (a heat balance or maximum-principle violation beyond its tolerance).
    """
    if integrator not in INTEGRATORS:
        raise ValueError(f"solver.integrator = {integrator!r}: must be one of {', '.join(INTEGRATORS)}")
    if not (np.isfinite(t_end) and t_end > 0):
        raise ValueError(f"solver.t_end = {t_end!r}: must be finite and > 0 (s)")
    theta = INTEGRATORS[integrator]
    if theta == 0.0 and np.any(net.C == 0.0):
        raise ValueError("solver.integrator = \"explicit\": an explicit step cannot carry the massless nodes of this "
                         "network (its necks); use \"implicit\" or \"crank-nicolson\"")
    part = WholeNetwork(net) if part is None else part
    solves = LocalSolves(linear, rtol_linear) if solves is None else solves
    stepper = ThetaStepper(net, theta, solves)
    own = part.own_free
    T = net.initial
    limit = None
    startup = None  # fixed-step Crank-Nicolson above the stable limit: implicit Euler start-up (module docstring)
    if theta == 0.5 and not isinstance(dt, str) and np.isfinite(dt) and dt > 0 \
            and part.above_stable_limit(float(dt), T):
        startup = ThetaStepper(net, 1.0, solves)
    if theta < 0.5:
        # radiation: the stiffest linearisation within the prescribed temperatures (maximum principle)
        t_hot = np.full(net.n_free, net.temperature_bounds()[1])
        limit = stable_limit(net, net.sinks(t_hot if net.sources.radiation else T))
    auto = isinstance(dt, str)
    if auto:
        if dt != "auto":
            raise ValueError(f"solver.dt = {dt!r}: must be a number (s) or \"auto\"")
        if not (np.isfinite(rtol) and rtol > 0):
            raise ValueError(f"solver.rtol = {rtol!r}: must be finite and > 0")
        scale = net.temperature_range() or max(float(np.max(np.abs(T), initial=0.0)), 1.0)
        tol = step_tolerance(rtol, ORDER[theta]) * scale
        rate = np.max(np.abs(stepper.rate(T)[0]), initial=0.0)
        dt_cap = AUTO_SAFETY * limit if limit is not None else math.inf
        # conditioning: C/dt + theta A loses the heat balance once C/dt falls far below A (a group with no fixed
        # temperature makes A singular): measured energy errors 1e-10, 1e-7, 5e-4 at C/dt = 2e-7, 2e-10, 1e-11 of
        # the bond conductance of a free pair. Steps stay below AUTO_CONDITION x the fastest time constant.
        diagonal = net.matrix(net.sinks(T)).diagonal() if net.n_free else np.zeros(0)
        coupled = (diagonal > 0.0) & (net.C > 0.0)  # an unbonded particle without sinks, a massless node: none
        tau_min = float(np.min(net.C[coupled] / diagonal[coupled])) if np.any(coupled) else math.inf
        dt_condition = AUTO_CONDITION * tau_min
        dt_cap = min(dt_cap, dt_condition)
        dt_want = min(t_end, tol / rate if rate > 0 else t_end, dt_cap)
        if limit is not None and math.isfinite(limit):
            check_step_count(t_end, dt_cap, max_steps, "explicit dt = \"auto\" at 0.9 x the stable limit "
                                                       f"{limit:.6g} s")
    else:
        dt = float(dt)
        if not (np.isfinite(dt) and dt > 0):
            raise ValueError(f"solver.dt = {dt!r}: must be finite and > 0 (s) or \"auto\"")
        if limit is not None and dt > limit:
            raise ValueError(f"solver.dt = {dt:.6g} s exceeds the explicit stability limit {limit:.6g} s "
                             f"(2/lambda_max of C^-1 A); use dt <= {limit:.6g}, dt = \"auto\", or an implicit "
                             f"integrator")
        check_step_count(t_end, dt, max_steps, f"solver.dt = {dt:.6g} s")
        dt_want = dt
        n_fixed = max(1, math.ceil(t_end / dt * (1.0 - 1e-12)))  # the last step ends exactly on t_end
    # implicit dt = "auto": steps t_end / 2^k on the dyadic grid of [0, t_end] (a step only grows where the grid
    # allows it), so the solvers of the few step sizes used are built once and the run ends exactly on t_end
    dyadic = auto and theta > 0.0
    grid = 2**AUTO_LEVELS
    units = 0  # dyadic: the time t = t_end * units / grid
    energy0 = part.total(float(net.C[own] @ T[own]))
    # maximum principle: without internal sources and without a periodic temperature drop (the jumps across the
    # box's faces drive the network as sources do: a cell at a uniform temperature settles to a drop's spread) the
    # temperatures stay within the prescribed ones (initial, fixed, walls, ambient); backward Euler keeps them there
    # exactly (an M-matrix), Crank-Nicolson and explicit steps only for small enough steps. The largest excursion (in
    # the scene's temperature unit) is reported.
    lo, hi = net.temperature_bounds()
    lo, hi = part.minimum(lo), part.maximum(hi)
    bounded = not part.total(int(np.any(net.heat[own]) or net.periodic))
    # the nodes that hold heat (a massless neck across a periodic face is in the frame of its particle i)
    watched = net.C > 0.0 if np.any(net.C == 0.0) else own
    violation = 0.0
    heat_in = {k: 0.0 for k in net.flow_names}
    abs_in = 0.0
    t, steps, rejected = 0.0, 0, 0
    dt_min, dt_max = math.inf, 0.0
    order = ORDER[theta]
    if resume is not None:
        r = resume
        T, t, steps, rejected, units, dt_want = r.T.astype(float), r.t, r.steps, r.rejected, r.units, r.dt_want
        heat_in, abs_in, dt_min, dt_max, violation = dict(r.heat_in), r.abs_in, r.dt_min, r.dt_max, r.violation
        energy0 = r.energy0
        stepper.history = [(np.array(h[0]), h[1]) for h in r.history]
    elif observer is not None:
        observer(0, 0.0, T, part.flows(T, net.sinks(T)))

    def state():
        return Checkpoint(T.copy(), t, steps, rejected, units, dt_want, dict(heat_in), abs_in, dt_min, dt_max,
                          violation, energy0, [(h[0].copy(), h[1]) for h in stepper.history])

    while t < t_end:
        remaining = t_end - t
        if dyadic:
            level = min(AUTO_LEVELS, max(0, math.ceil(math.log2(t_end / dt_want) - 1e-9)))
            while units % (grid >> level):
                level += 1
            h = t_end / 2**level
            last = units + (grid >> level) == grid
        elif not auto:  # fixed steps: t = k dt (not a running sum, whose round-off could add a step at the end)
            last = steps + 1 >= n_fixed
            h = t_end - steps * dt_want if last else dt_want
            if abs(h - dt_want) <= 1e-9 * dt_want:  # a full last step: the same size, the same factorisation
                h = dt_want
        else:
            last = dt_want >= remaining * (1 - 1e-9)
            h = remaining if dt_want > remaining * (1 + 1e-9) else dt_want
        if auto:
            T_new, parts, err = stepper.estimated_step(T, h)
            factor = _controller_factor(err, tol, order)
            if err > tol and h > AUTO_MIN_STEP * t_end:
                rejected += 1
                if rejected > max_steps:
                    raise ValueError(f"more than solver.max_steps = {max_steps} rejected steps before t_end = "
                                     f"{t_end:g} s")
                dt_want = h * min(factor, AUTO_SAFETY)
                continue
        else:
            first = startup is not None and steps < STARTUP_STEPS
            T_new, T_theta, sinks = (startup if first else stepper).step(T, h)
            parts = [(h, T_theta, sinks)]
        flows = {}
        for h_part, T_theta, sinks in parts:
            for k, v in part.flows(T_theta, sinks).items():
                heat_in[k] += h_part * v
                flows[k] = flows.get(k, 0.0) + h_part * v / h
            abs_in += h_part * part.flow_magnitude(T_theta, sinks)
        stepper.accept(T, h)
        T, steps = T_new, steps + 1
        if dyadic:
            units += grid >> level
            t = t_end * (units / grid)
        else:
            t = t_end if last else (steps * dt_want if not auto else t + h)
        dt_min, dt_max = min(dt_min, h), max(dt_max, h)
        if not part.minimum(int(np.all(np.isfinite(T[own])))):
            raise ValueError(f"temperatures became non-finite at t = {t:.6g} s (step {steps})")
        if bounded:
            top = part.maximum(float(T[watched].max(initial=-np.inf)))
            bottom = part.minimum(float(T[watched].min(initial=np.inf)))
            violation = max(violation, top - hi, lo - bottom)
            part.agree(lambda: refuse_out_of_range(violation, lo, hi, t, integrator, dt))
        if observer is not None:
            observer(steps, t, T, flows)
        if progress is not None:
            progress(t)
        if auto:
            dt_want = min(h * factor, dt_cap)
            projected = steps + (t_end - t) / dt_want
            capped = dt_want >= dt_condition
            if capped and projected > max_steps:
                raise ValueError(f"solver.t_end = {t_end:g} s: dt = \"auto\" steps are capped at {dt_condition:.3g}"
                                 f" s ({AUTO_CONDITION:g} x the fastest time constant, beyond which the solve "
                                 f"loses the heat balance), so t_end needs ~{projected:.3g} steps, beyond "
                                 f"solver.max_steps = {max_steps}; the network is steady long before: shorten "
                                 "t_end (or use mode = \"steady\")")
            if steps >= max(100, max_steps // 100) and projected > AUTO_PROJECTION * max_steps:
                raise ValueError(f"solver.rtol = {rtol:g}: at t = {t:.4g} s dt = \"auto\" takes steps of {h:.3g} s, "
                                 f"so t_end = {t_end:g} s needs ~{projected:.3g} steps, far beyond solver.max_steps "
                                 f"= {max_steps}; raise rtol or max_steps, or shorten t_end")
        if steps >= max_steps and t < t_end:
            raise ValueError(f"more than solver.max_steps = {max_steps} steps before t_end = {t_end:g} s")
        if checkpoint is not None and t < t_end:
            checkpoint(state)
    if checkpoint is not None:
        checkpoint(state, final=True)
    energy = part.total(float(net.C[own] @ T[own]))
    scale_e = part.total(float(net.C[own].sum())) * (hi - lo) + abs_in
    err = abs(energy - energy0 - sum(heat_in.values())) / scale_e if scale_e > 0 else 0.0
    part.agree(lambda: refuse_energy_error(err, integrator, dt))
    heat_in = {k: float(v) for k, v in heat_in.items()}
    factorizations = stepper.factorizations + (startup.factorizations if startup is not None else 0)
    return TransientResult(net.full(T), t, steps, rejected, err, heat_in, limit, dt_min, dt_max, stepper.backend,
                           factorizations, violation if bounded else None,
                           min(steps, STARTUP_STEPS) if startup is not None else 0)


ROUND_OFF_HINT = ("even the smallest step dt = \"auto\" takes is far above the network's fastest time constant "
                  "C/K, so the capacities are lost to round-off next to the conductances: check the materials' "
                  "density and specific heat against the conductivity, or use mode = \"steady\"")


def refuse_out_of_range(violation: float, lo: float, hi: float, t: float, integrator: str, dt) -> None:
    """Refuse a transient run whose temperatures left the prescribed range ``[lo, hi]`` by more than
    ``MAX_PRINCIPLE_TOLERANCE`` of it (and more than round-off of the temperatures): one line naming ``dt``
    (module docstring). The serial and the distributed integrators both end a run here.

    Parameters
    ----------
    violation : float
        The largest excursion beyond ``[lo, hi]`` so far (the scene's temperature unit, K or degC).
    lo, hi : float
        The lowest and highest temperature the scene prescribes (K or degC).
    t : float
        The time reached (s).
    integrator : str
        ``"explicit"``, ``"implicit"`` or ``"crank-nicolson"``.
    dt : float or str
        The step asked for (s), or ``"auto"``.

    Raises
    ------
    ValueError
        ``violation`` is beyond the tolerance.
    """
    if violation > max(MAX_PRINCIPLE_TOLERANCE * (hi - lo), ROUND_OFF * max(abs(lo), abs(hi))):
        raise ValueError(_wrong(f"at t = {t:.6g} s the temperatures left the prescribed range [{lo:g}, {hi:g}] by "
                                f"{violation:.4g} (max_principle_violation, more than {MAX_PRINCIPLE_TOLERANCE:g} of "
                                f"the range)", integrator, dt,
                                "the step is too large for the network's fastest time constant: use a smaller dt, "
                                "dt = \"auto\" or integrator = \"implicit\""))


def refuse_energy_error(err: float, integrator: str, dt) -> None:
    """Refuse a transient run whose heat balance is off by more than ``ENERGY_TOLERANCE``: one line naming ``dt``
    (module docstring). The serial and the distributed integrators both end a run here.

    Parameters
    ----------
    err : float
        The run's ``energy_error`` (relative).
    integrator : str
        ``"explicit"``, ``"implicit"`` or ``"crank-nicolson"``.
    dt : float or str
        The step asked for (s), or ``"auto"``.

    Raises
    ------
    ValueError
        ``err`` is beyond the tolerance (or not a number).
    """
    if not err <= ENERGY_TOLERANCE:
        raise ValueError(_wrong(f"the heat balance is off by energy_error = {err:.3g} (more than "
                                f"{ENERGY_TOLERANCE:g})", integrator, dt,
                                "the capacities are lost to round-off next to the conductances at this step: use a "
                                "smaller dt (or mode = \"steady\")"))


def _wrong(what: str, integrator: str, dt, hint: str) -> str:
    """The one-line refusal of a transient run whose temperatures came out wrong (module docstring); with ``dt =
    "auto"`` the hint is ``ROUND_OFF_HINT`` (the controller's smallest step was still too large)."""
    auto = isinstance(dt, str)
    step = f"{dt!r}" if auto else f"{dt:.6g} s"
    return f"solver.dt = {step} ({integrator}): {what}, so the temperatures are wrong; " + (ROUND_OFF_HINT if auto
                                                                                           else hint)
