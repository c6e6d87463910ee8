r"""Heat flow through the contacts of particles that move: the pipe network of Rojek 2022 (eqs. 1-9) on the
contacts of the mechanical submodel, with necks that grow as the particles sinter.

Every closed contact is a bond whose overlap is Rojek's ``h``: its neck radius comes from the scene's contact
geometry (the volume-conserving neck, :func:`fem_neck.geometry.neck_radius`, by default) and its conductance from
the scene's law, exactly as for a static packing (:func:`dem.geometry.bonds.find_bonds`,
:func:`dem.laws.conductance.bond_conductances`);
an overlap beyond the neck model's range stops the run with the contact named (or is clipped/dropped by
``conductance.out_of_range``). Walls that carry a temperature are isothermal planes bonded to the particles that
touch them.

The network takes its own implicit steps (backward Euler or Crank-Nicolson), each as long as many mechanical
steps, so neither physics forces the other's step down: the engine advances the mechanics over an interval, then
the temperatures over the same interval with the conductances of the contacts at its end (a sequential splitting).
When the set of contacts has not changed, the network keeps its matrices and only rewrites their entries
(:meth:`dem.network.heat.Network.refresh`); a new or lost contact re-assembles it. Each step's heat balance holds to
round-off (:func:`dem.network.heat.theta_step`), so the energy bookkeeping stays exact through contact changes.

Stiff steps: a thermal step is many mechanical steps long, and may be far above the network's stiffest time constant
``C/K`` (small particles, conductive necks). Crank-Nicolson's amplification factor tends to -1 there, so a
temperature difference across a contact would alternate from step to step instead of equalising (a column of
particles at 0, 100 and 0 C stayed at 66, -33 and 66 C). Each thermal step is a new network (its contacts and their
conductances changed), so each Crank-Nicolson step surely above the stable limit
(:func:`dem.network.heat.surely_stiff`) is taken as the implicit Euler step that starts a stiff static run
(:func:`dem.network.heat.integrate`, Rannacher's start-up; L-stable), and counted in ``startup_steps``. Such a step
is first order, as the run is anyway: mechanics and heat are split sequentially over the thermal interval. A step
within the limit is Crank-Nicolson's, as before; on several ranks each thermal step makes the same choice
(:meth:`dem.network.distributed.DistributedNetwork.integrate`).

The capacities use each particle's mass (constant: thermal expansion changes the radius, not the mass).

With a pair-neck reading (``newton``, ``first``, ``coble``) in 3D, a particle whose necks meet is handed over to the
union of spheres (:mod:`dem.engines.handover`): its bonds read the lens circles of the grown solid spheres, which
keep the particles' volumes, blended with the pair reading over the steps of the hand-over. Each thermal step
advances the hand-overs and solves the solid radii at the configuration of its end; the snapshots read them as the
last step left them.

**A node per neck** (``[conductance] nodes = "necks"``, :mod:`dem.network.necks`: the ``shared-body`` law on the
scene's neck reading; with a pair-neck reading in 3D through the hand-over, each particle's element blended from its
pair and union readings by its weight, :meth:`dem.engines.handover.Handover.neck_network`). Each thermal step
assembles the neck-node network of the contacts at its end (:func:`dem.network.necks.neck_network`; the elements from
the particles' radii now, the capacities from their masses, as the one-node network takes them) and takes the step on
it with the same :math:`\theta` step (:class:`dem.network.necks.NeckHeat`, whose necks start where their rows hold at
the step's starting temperatures, so each new network starts consistent). The necks are massless and re-solved every
step: nothing but the particles' temperatures (and the hand-over's steps and solid radii, as in a one-node run) is
carried from step to step, so a checkpoint holds what it holds without them. The stiffness test of a Crank-Nicolson
step takes the centres' rows only (a neck has no time constant).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dem.engines.handover import Handover
from dem.geometry.bonds import find_bonds
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.laws.ambient import Sources
from dem.network.heat import Network, bonds_and_conductances, surely_stiff, theta_step
from dem.network.necks import NeckHeat, NeckNetwork, neck_flows, neck_network


class ContactThermalModel:
    """The thermal network on the current contacts (module docstring).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles at the start: their temperatures (the scene's unit, K or degC) are the initial ones,
        their masses give the capacities, and their materials, ``fixed`` flags and heat sources (W) hold throughout.
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls; those with a temperature are isothermal planes bonded to the particles touching them.
    spec : dem.laws.conductance.ConductanceSpec
        The scene's contact geometry and conductance law.
    sources : dem.laws.ambient.Sources
        The heat exchanged with the surroundings (convection, radiation), if any.
    integrator : str
        The network's implicit step: ``"implicit"`` (backward Euler) or ``"crank-nicolson"``.
    linear : str
        The linear solver of each step (:func:`dem.network.heat.theta_step`), ``"auto"`` by default.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box (bonds across its faces, its temperature drop per period); None without one.

    Raises
    ------
    ValueError
        ``integrator`` is neither ``"implicit"`` nor ``"crank-nicolson"``.
    """

    name = "thermal"
    hands_over = True  # a pair-neck reading hands particles whose necks meet over to the union (module docstring)

    def __init__(self, particles: Particles, walls, spec: ConductanceSpec, sources: Sources,
                 integrator: str = "implicit", linear: str = "auto", box: PeriodicBox | None = None):
        if integrator not in ("implicit", "crank-nicolson"):
            raise ValueError(f"[solver] thermal_integrator = {integrator!r}: a network coupled to moving particles "
                             f"steps implicitly: implicit or crank-nicolson")
        self.particles = particles  # capacities, materials, fixed temperatures and sources
        self.walls = tuple(walls)
        self.thermal_walls = [k for k, w in enumerate(self.walls) if w.temperature is not None]
        self.spec, self.sources = spec, sources
        self.integrator, self.linear = integrator, linear
        self.box = box  # a periodic box: bonds across its faces, its temperature drop per period
        self.T = particles.temperature.astype(float).copy()
        self.rate = np.zeros_like(self.T)  # dT/dt over the last step: the mechanics extrapolates with it
        self.net: Network | None = None
        self.necks: NeckHeat | None = None  # with a node per neck: the last step's network (module docstring)
        self.free = np.flatnonzero(~particles.fixed)
        self.heat_in: dict = {}
        self.energy0 = float(particles.capacity @ self.T)
        self.assemblies = self.refreshes = 0
        self.startup_steps = 0  # Crank-Nicolson steps taken as implicit Euler steps (module docstring)
        self.handover = Handover(spec, particles.radius)
        self._kept: dict = {}  # what the contacts of one configuration give (``_configuration``)

    def handing_over(self, mechanics) -> bool:
        """Whether this run hands particles over to the union (:meth:`dem.engines.handover.Handover.applies`; not on
        several ranks).

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel (its dimension).

        Returns
        -------
        bool
            Whether it does.
        """
        return self.hands_over and Handover.applies(self.spec, mechanics.state.dimension)

    def bonds(self, mechanics, update: bool = False):
        """Bonds and conductances ``(bonds, K_pairs, K_walls)`` of the contacts of ``mechanics`` now.

        Handing over (:meth:`handing_over`), the bonds as :meth:`dem.engines.handover.Handover.bonds` reads them.
        Computed once per configuration (``_configuration``); handing over, once per state of the hand-overs too
        (an update is computed each time: it advances them).

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel: its current contacts, positions (m), radii (m) and wall offsets (m).
        update : bool
            Whether to update the hand-over weights and solid radii to this configuration first (a thermal step
            does; a snapshot reads them as they are).

        Returns
        -------
        tuple
            The bonds (:func:`dem.network.heat.bonds_and_conductances`), the pair conductances (W/K) and the
            wall conductances (W/K).
        """
        kept = self._configuration(mechanics)
        now, walls, pairs = kept["now"], kept["walls"], mechanics.contacts()[:2]
        if self.handing_over(mechanics):
            return self._handed_over(kept, "bonds", lambda advance: self.handover.bonds(now, walls, pairs, self.box,
                                                                                           advance), update)
        if "bonds" not in kept:
            if self.spec.nodes == "necks":  # the one-node law's from the halves the elements are of
                net = self._neck_network(mechanics)
                kept["bonds"] = (net.bonds, *bond_conductances(self.spec, now, net.bonds, box=self.box,
                                                               walls=tuple(walls), union=net.union))
            else:
                kept["bonds"] = bonds_and_conductances(now, walls, self.spec, pairs=pairs, box=self.box)
        return kept["bonds"]

    def _handed_over(self, kept: dict, key: str, read, update: bool):
        """``read(update)`` handing over, kept in ``kept[key]`` for as long as the hand-overs' state it was read at
        holds (an update advances that state and is read each time: a read kept before is of the old state)."""
        if update:
            kept.pop(key, None)
            return read(True)
        state = (self.handover.steps, self.handover.solid_radius)
        if key not in kept or not all(map(np.array_equal, kept[key + " at"], state)):
            kept[key] = read(False)
            kept[key + " at"] = tuple(a.copy() for a in state)
        return kept[key]

    def _configuration(self, mechanics) -> dict:
        """What the contacts of ``mechanics`` give where it stands now: the particles now (``"now"``) and the
        thermal walls (``"walls"``), and the bonds and conductances (``"bonds"``, :meth:`bonds`) and the neck-node
        network (``"necks"``, ``_neck_network``) once asked for; computed once and kept until the mechanics takes
        a step (or the law is another), so that a thermal step and the snapshots at the end of its interval share
        them (the temperatures of ``"now"``, which the step changes, are read by none of them)."""
        kept = self._kept
        if kept.get("mechanics") is not mechanics or kept["steps"] != mechanics.steps or kept["spec"] is not self.spec:
            self._kept = kept = {"mechanics": mechanics, "steps": mechanics.steps, "spec": self.spec,
                                 "now": self._particles_now(mechanics, mechanics.state.radius),
                                 "walls": self._walls_now(mechanics)}
        return kept

    def local(self, mechanics, values: np.ndarray) -> np.ndarray:
        """``values`` (per particle of the scene) for the particles ``mechanics`` holds: all of them, in order
        (a rank's model holds some, :class:`dem.engines.distributed.verlet.RankContactThermal`).

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel whose particles are wanted.
        values : numpy.ndarray
            One value per particle of the scene, any unit.

        Returns
        -------
        numpy.ndarray
            ``values`` itself (this model holds every particle).
        """
        return values

    def _particles_now(self, mechanics, radius) -> Particles:
        """The particles at their current positions with ``radius``: the current radii for the contact geometry,
        the initial ones (the mass) for the capacities and the exposed surface."""
        p = self.particles
        return Particles(mechanics.state.x, radius, *(self.local(mechanics, a) for a in (self.T, p.material, p.fixed,
                                                                                       p.heat)), p.materials)

    def _walls_now(self, mechanics) -> list:
        return [self.walls[k].at(mechanics.w.q[k]) for k in self.thermal_walls]

    def network(self, mechanics, bonds: tuple | None = None) -> Network:
        """A new network of the contacts of ``mechanics`` now.

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel: its contacts, positions (m), radii (m) and wall offsets (m).
        bonds : tuple or None
            Its ``(bonds, K_pairs, K_walls)`` where known already (:meth:`bonds`); None: found now.

        Returns
        -------
        dem.network.heat.Network
            The network, at the temperatures ``T``.
        """
        bonds, K_pairs, K_walls = self.bonds(mechanics) if bonds is None else bonds
        wall_T = np.array([self.walls[k].temperature for k in self.thermal_walls], dtype=float)
        return Network(self._particles_now(mechanics, self.local(mechanics, self.particles.radius)), bonds, K_pairs,
                       K_walls, wall_T, self.sources, self.box)

    def step(self, mechanics, dt: float) -> None:
        """Advance the temperatures by ``dt`` on the network of the contacts of ``mechanics`` now.

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel at the end of the interval: its contacts give the network.
        dt : float
            The step (s), > 0.
        """
        if self.spec.nodes == "necks":  # the network of the contacts now, its elements made of their halves
            self.necks = net = self.neck_heat(mechanics, update=True)
            self.assemblies += 1
            T_F = net.initial  # the free centres' temperatures now, the necks' where their rows hold
        else:
            bonds, K_pairs, K_walls = self.bonds(mechanics, update=True)
            if self.net is not None and self.net.graph.same_edges(bonds.i, bonds.j, bonds.wall_particle,
                                                                  bonds.wall_index):
                self.net.refresh(bonds, K_pairs, K_walls)
                self.refreshes += 1
            else:
                self.net = self.network(mechanics, (bonds, K_pairs, K_walls))
                self.assemblies += 1
            net, T_F = self.net, self.T[self.free]
        integrator = self.integrator
        centres = net.C > 0.0 if self.necks is not None else None  # (a neck is massless: no time constant)
        if integrator == "crank-nicolson" and surely_stiff(dt, net.matrix(net.sinks(T_F)), net.C, rows=centres):
            integrator = "implicit"  # the start-up of a step far above the stiffest time constant (module docstring)
            self.startup_steps += 1
        T_F, heat = theta_step(net, T_F, dt, integrator, self.linear)
        for k, v in heat.items():
            self.heat_in[k] = self.heat_in.get(k, 0.0) + v
        T_F = T_F[:len(self.free)]  # the free centres (then, with a node per neck, the necks)
        self.rate[self.free] = (T_F - self.T[self.free]) / dt
        self.T[self.free] = T_F

    def _neck_network(self, mechanics, update: bool = False, pair_necks: bool = False) -> NeckNetwork:
        """The network with a node per neck of the contacts of ``mechanics`` now (module docstring; the arguments
        those of :meth:`neck_heat`), assembled once per configuration (``_configuration``) and, handing over, once
        per state of the hand-overs too (an update, or every contact read as a pair neck, is assembled each time)."""
        kept = self._configuration(mechanics)
        now, walls, pairs = kept["now"], kept["walls"], mechanics.contacts()[:2]
        if pair_necks:
            spec = replace(self.spec, out_of_range="clip")
            bonds = find_bonds(now, walls, spec.contact, spec.out_of_range, pairs=pairs, box=self.box)
            return neck_network(spec, now, bonds, box=self.box, walls=walls)
        if self.handing_over(mechanics):
            return self._handed_over(kept, "necks", lambda advance: self.handover.neck_network(now, walls, pairs,
                                                                                                  self.box, advance),
                                     update)
        if "necks" not in kept:
            bonds = find_bonds(now, walls, self.spec.contact, self.spec.out_of_range, pairs=pairs, box=self.box)
            kept["necks"] = neck_network(self.spec, now, bonds, box=self.box, walls=walls)
        return kept["necks"]

    def neck_heat(self, mechanics, update: bool = False, pair_necks: bool = False) -> NeckHeat:
        r"""The network with a node per neck of the contacts of ``mechanics`` now (module docstring), at the
        temperatures ``T``: handing over (:meth:`handing_over`), as :meth:`dem.engines.handover.Handover.neck_network`
        reads them.

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel: its contacts, positions (m), radii (m) and wall offsets (m).
        update : bool
            Whether to update the hand-over weights and solid radii to this configuration first (a thermal step
            does; a snapshot reads them as they are).
        pair_necks : bool
            Whether to read every contact as a pair neck (the scene's reading, clipped to its range), as if no
            particle had been handed over.

        Returns
        -------
        dem.network.necks.NeckHeat
            The network in the terms of the :math:`\theta` step.
        """
        # the capacities from the masses (the initial radii), as the one-node network's: the heat balance's own
        massive = replace(self._neck_network(mechanics, update, pair_necks),
                          particles=self._particles_now(mechanics, self.local(mechanics, self.particles.radius)))
        return NeckHeat(massive, self.linear)

    def contact_heat(self, mechanics, i: np.ndarray, j: np.ndarray) -> tuple[dict, np.ndarray]:
        """The heat of the contacts ``(i, j)`` of ``mechanics`` now, for the snapshots: per contact its
        ``neck_radius`` (m), ``conductance`` (W/K) and ``heat_flow`` (W, from i to j), all 0 for a contact without
        a bond (``conductance.out_of_range = "drop"``); and the heat flow (W) into each particle through its
        contacts and walls. With a node per neck the flows are the necks' (:func:`dem.network.necks.neck_flows`, the
        necks where their rows hold at ``T``) and ``conductance`` the one-node law's of the bond (a neck-node bond has
        no conductance of its own: its particles' elements couple it to their other necks).

        Parameters
        ----------
        mechanics : dem.engines.verlet.mechanics.MechanicalModel
            The mechanical submodel now: its contacts give the bonds.
        i, j : numpy.ndarray
            The contacts' particle indices, shape (M,) each; the heat flow is counted from ``i`` to ``j``.

        Returns
        -------
        tuple of (dict, numpy.ndarray)
            ``{"neck_radius": m, "conductance": W/K, "heat_flow": W}``, arrays of shape (M,), and the heat flow into
            each particle (W), shape (N,).
        """
        bonds, K_pairs, K_walls = self.bonds(mechanics)
        T = self.local(mechanics, self.T)
        n = len(T)
        if self.spec.nodes == "necks":  # the flows through the necks, solved where their rows hold at T
            heat = self.neck_heat(mechanics)
            q, q_walls = neck_flows(heat.net, heat.nodes(heat.initial))[:2]
        else:
            jump = bonds.shifts @ self.box.drop if self.box is not None else 0.0
            q = K_pairs * (T[bonds.i] - T[bonds.j] + jump)
            wall_T = np.array([self.walls[k].temperature for k in self.thermal_walls], dtype=float)
            q_walls = K_walls * (T[bonds.wall_particle] - wall_T[bonds.wall_index])
        into = np.bincount(bonds.j, q, n) - np.bincount(bonds.i, q, n) - np.bincount(bonds.wall_particle, q_walls, n)
        fields = {name: np.zeros(len(i)) for name in ("neck_radius", "conductance", "heat_flow")}
        if not bonds.n_pairs:
            return fields, into
        key = np.minimum(bonds.i, bonds.j) * n + np.maximum(bonds.i, bonds.j)
        order = np.argsort(key, kind="stable")
        wanted = np.minimum(i, j) * n + np.maximum(i, j)
        at = order[np.clip(np.searchsorted(key[order], wanted), 0, len(key) - 1)]
        found = key[at] == wanted
        sign = np.where(bonds.i[at] == i, 1.0, -1.0)  # the bond's direction against the contact's
        for name, values in (("neck_radius", bonds.a[at]), ("conductance", K_pairs[at]), ("heat_flow", sign * q[at])):
            fields[name][found] = values[found]
        return fields, into

    def energy_error(self) -> float:
        """``|sum C (T - T0) - heat in| / scale`` (relative; the scale is the capacity times the temperature range
        plus the heat exchanged)."""
        C = self.particles.capacity
        change = float(C @ self.T) - self.energy0
        scale = float(C.sum()) * max(float(np.ptp(self.T)), 1e-300) + sum(abs(v) for v in self.heat_in.values())
        return abs(change - sum(self.heat_in.values())) / scale if scale > 0 else 0.0
