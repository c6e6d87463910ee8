"""The static engine on several MPI ranks: the pipe network of a packing that does not move (Rojek 2022, eqs. 1-9),
steady or in implicit steps of a fixed size, its particles shared out in space and its matrix solved on PETSc.

Every rank reads the scene, keeps the particles of its cell of a recursive coordinate bisection
(:func:`dem.geometry.bisection.bisection`) and a halo of one bond length around them
(:func:`dem.geometry.bisection.halo`) -- or, from a packing in parts, reads only those
(:func:`dem.scene.packing_files.parts.read_part`: the scene's ``part``) --, finds their bonds and conductances as the
serial engine does, and keeps those with an owned particle (:mod:`dem.network.distributed`: its rows are the serial
matrix's to the bit). The summary and the effective conductivity are reduced over the ranks; the snapshots are one
piece per rank (:class:`dem.output.pieces.PieceWriter`).

A current between electrodes (``"electrical"`` physics, :mod:`dem.engines.static`) is solved before the heat on the
same ranks and the same code path: its network is a :class:`dem.network.heat.Network` of the same bonds with the
electrical conductances, the electrodes as its walls at their potentials and nothing fixed, solved by
:meth:`dem.network.distributed.DistributedNetwork.steady` (groups touching no electrode float at potential 0, as the
serial solve leaves them: they carry nothing). Each rank then has the potentials of its particles and their halo,
hence the current and Joule heat of every contact of its own particles (:func:`dem.network.current.contact_currents`);
the electrodes' currents and the Joule heat are summed over the ranks.

With a node per neck (``[conductance] nodes = "necks"``, :mod:`dem.network.necks`) each rank holds the particles
within three bond lengths of its own (a packing in parts is read so), assembles their network with the serial code
and solves the rows of its centres and necks (:mod:`dem.network.distributed_necks`); the heat flows into the walls,
the fixed particles and across the period are summed from the necks' flows (:func:`dem.network.necks.neck_flows`) of
each rank's own particles.

What it does not do, refused up front with the reason: moving particles (another engine's), radiation (a Newton
iteration), explicit steps and ``dt = "auto"`` (fixed implicit or Crank-Nicolson steps only), the ``clip`` and
``drop`` bond policies, an electrode driving a fixed current (a superposition of solves), ``--resume``; with a node
per neck, a current.

The Trefftz element (``[conductance] element = "trefftz"``, :mod:`dem.network.elements`) runs on the ranks with its
three flux modes per neck (:func:`dem.network.distributed_necks.node_keys`): each rank builds it for its own particles
only, the expensive part of such a run shared out (what it will take said once, by rank 0, for all the ranks:
:class:`dem.network.elements.SceneElements`' ``comm``), receives those of their necks' partners from their owners
(:func:`dem.network.distributed_necks.shared_elements`) and then assembles its network, once; the summary's
``element_*`` entries are summed over the ranks (``element_seconds``: the CPU time of all the ranks' elements,
``element_compile_seconds`` that of all their compiling).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dem import memory
from dem.engines.static import CSV_FLOWS, StaticEngine, boundary_summary
from dem.geometry.bonds import find_bonds
from dem.geometry.necks import meeting_in
from dem.geometry.bisection import HALO_MARGIN, NECK_HALO, bisection, halo
from dem.laws.conductance import bond_conductances
from dem.laws.verified_range import neck_account, wide_necks
from dem.parallel import comm as mpi
from dem.network.current import circuit, contact_currents, electrode_bonds, refuse_floating
from dem.network.distributed import DistributedNetwork
from dem.network.distributed_necks import DistributedNecks, RankNeckHeat, node_keys, shared_elements
from dem.network.elements import scene_elements
from dem.network.heat import Network, bonds_and_conductances
from dem.network.necks import assembled, live_necks, neck_flows
from dem.output.pieces import refuse_lammps_dump
from sinterheat import threads


def unsupported(scene, resume: bool = False) -> str | None:
    """Why ``scene`` cannot run on several ranks (module docstring), or None.

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene.
    resume : bool
        Whether the run would resume from a checkpoint.

    Returns
    -------
    str or None
        The one-line reason, or None where it can run.
    """
    s = scene.solver
    if scene.sources.radiation is not None:
        return f"scene {scene.name!r}: radiation (a Newton iteration) does not run under MPI; run it without mpiexec"
    if scene.conductance.out_of_range != "error":
        return (f"conductance.out_of_range = {scene.conductance.out_of_range!r} does not run under MPI (valid there: "
                f"\"error\"); run it without mpiexec")
    if s.mode == "transient" and (s.integrator == "explicit" or s.dt == "auto"):
        return (f"[solver] integrator = {s.integrator!r}, dt = {s.dt!r}: under MPI transient runs take fixed "
                f"implicit or crank-nicolson steps (a number for dt); run it without mpiexec")
    if scene.electrical is not None and not np.all(scene.electrical.electrodes.fixed_potential):
        e = scene.electrical.electrodes
        name = e.names[int(np.flatnonzero(~e.fixed_potential)[0])]
        return (f"walls.{name}.current: an electrode driving a fixed current does not run under MPI (its potential "
                f"needs a superposition of solves); give it a potential, or run without mpiexec")
    if scene.conductance.nodes == "necks" and scene.electrical is not None:
        return ("conductance.nodes = \"necks\" with \"electrical\" physics does not run under MPI yet (the current "
                "through the neck nodes is solved on one process); run it without mpiexec")
    if resume:
        return "--resume does not run under MPI; run the scene again"
    return None


class DistributedStaticEngine(StaticEngine):
    """The static engine's protocol (:mod:`dem.engines`) on this rank's particles (module docstring);
    ``positions()``, ``particle_fields()`` and ``temperatures()`` are those of the particles it owns
    (``owned``: their indices in the scene)."""

    name = "static"
    pieces_only = True

    @classmethod
    def refuse(cls, scene, resume: bool) -> None:
        """What a static scene cannot do on several ranks (:func:`unsupported`, and a LAMMPS dump:
        :func:`dem.output.pieces.refuse_lammps_dump`), refused before the run's folder is touched.

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene.
        resume : bool
            Whether the run would go on from a checkpoint.

        Raises
        ------
        ValueError
            The one-line reason.
        """
        refuse_lammps_dump(scene)
        why = unsupported(scene, resume)
        if why is not None:
            raise ValueError(why)

    def __init__(self, scene, restart: dict | None = None):
        """This rank's particles of ``scene`` and their network.

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene.
        restart : dict or None
            A checkpoint (refused: a distributed run does not resume); None.

        Raises
        ------
        ValueError
            The scene cannot run on several ranks (:func:`unsupported`).
        """
        why = unsupported(scene, restart is not None)
        if why is not None:
            raise ValueError(why)
        self.comm = mpi.world()
        self.ranks, rank = self.comm.Get_size(), self.comm.Get_rank()
        threads.share_among_ranks(self.ranks)  # (the Trefftz elements are built on threads)
        self.full_scene = self.scene = scene  # self.scene: the local particles once built
        self.t_start = float(scene.start_time)
        self.t, self.steps = self.t_start, 0
        self.flows, self.details, self.restart = {}, {}, None
        self.necks = None  # with a node per neck: the network of the held particles (dem.network.necks)
        owner, live = mpi.agree(self.comm, lambda: self._build(scene, rank))  # no collective call inside: a bond out
        particles = self.scene.particles                                        # of range stops every rank alike
        if live is not None:
            self.necks, self.plain = self._neck_network(live, owner)
        self.potential, self.circuit = None, None
        if scene.electrical is not None:
            particles = mpi.agree(self.comm, lambda: self._joule_heated(particles, owner))
        wall_temperature = np.array([w.temperature for w in scene.walls], dtype=float)
        self.network = Network(particles, self.bonds, self.K_pairs, self.K_walls, wall_temperature, scene.sources,
                               scene.box)
        if self.necks is None:
            self.part = DistributedNetwork(self.comm, self.network, self.held, owner)
        else:  # a node per neck (dem.network.distributed_necks)
            self.necks_heat = RankNeckHeat(self.necks, scene.solver.linear, sources=self.network.sources,
                                           own=self.mine)
            keys, node_owner = node_keys(self.necks, self.held, owner, self.comm)
            self.part = DistributedNecks(self.comm, self.necks_heat, keys, node_owner)

    def _build(self, scene, rank: int) -> tuple:
        """This rank's particles, bonds and conductances (no communication); returns the owner of each held particle
        and, with a node per neck, the held particles' live necks (:func:`dem.network.necks.live_necks`; None:
        without)."""
        p, box, spec = scene.particles, scene.box, scene.conductance
        nodes = spec.nodes
        if p.n < self.ranks:
            raise ValueError(f"{p.n} particles on {self.ranks} ranks: use at most {p.n} ranks")
        if scene.solver.mode == "transient":
            self._check_work()
        if scene.part is not None:  # read in part: the held particles and their owners
            if scene.part.ranks != self.ranks:
                raise ValueError(f"the packing in parts was read for {scene.part.ranks} ranks, not these "
                                 f"{self.ranks}")
            held, owner_held = scene.part.held, scene.part.owner
            self.owned = held[owner_held == rank]
            local = p
        else:
            lengths = None if box is None else np.where(box.mask, box.lengths, np.inf)
            owner = bisection(p.position, self.ranks, lengths)
            reach = 2.0 * float(p.radius.max()) * HALO_MARGIN * (NECK_HALO if nodes == "necks" else 1)
            self.owned = np.flatnonzero(owner == rank)
            held = np.union1d(self.owned, halo(p.position, owner, rank, reach, None if box is None else box.lengths,
                                              None if box is None else box.mask))
            owner_held = owner[held]
            local = p.permuted(held)
        memory.check(len(held), "particles", scene.conductance.neck, scene.conductance.nodes)
        self.scene = replace(scene, particles=local)
        mine = owner_held == rank
        try:
            if nodes == "necks":  # all the bonds of the held particles (module docstring of distributed_necks)
                bonds = find_bonds(local, tuple(scene.walls), spec.contact, spec.out_of_range, box=box)
                live = live_necks(spec, local, bonds, box=box, walls=scene.walls)
                K_pairs, K_walls = bond_conductances(spec, local, bonds, box=box, walls=tuple(scene.walls),
                                                     union=live.union)
            else:
                live = None
                bonds, K_pairs, K_walls = bonds_and_conductances(local, scene.walls, spec, box=box)
        except ValueError as exc:  # its counts and indices are of this rank's particles
            raise ValueError(f"rank {rank} of {self.ranks}, its {len(held)} particles numbered from 0 in the "
                             f"scene's order: {exc}") from None
        pairs, walls = mine[bonds.i] | mine[bonds.j], mine[bonds.wall_particle]
        self.kept = (pairs, walls)  # the bonds of this rank's particles among those found
        self.bonds, self.K_pairs, self.K_walls = bonds.subset(pairs, walls), K_pairs[pairs], K_walls[walls]
        self.held, self.mine = held, mine
        self.meeting = meeting_in(local, scene.walls, self.bonds, box)  # right for the owned: all their bonds are here
        self.wide = wide_necks(local.radius, self.bonds, self.meeting, spec.law, nodes, spec.element)
        self.T = local.temperature.astype(float)
        return owner_held, live

    def _neck_network(self, live, owner: np.ndarray) -> tuple:
        """The network with a node per neck of the held particles from their live necks ``live``
        (:func:`dem.network.necks.live_necks`), assembled once (:func:`dem.network.necks.assembled`) from the elements
        of ``[conductance] element`` (:func:`dem.network.elements.scene_elements`: a Trefftz element on the own
        particles only, what it takes said once for all the ranks) and, with the Trefftz element, those of the own
        particles' partners from their owners (:func:`dem.network.distributed_necks.shared_elements`); and, per held
        particle, whether its element dropped its interactions (``plain``)."""
        spec = self.scene.conductance
        self.elements = scene_elements(spec, self.mine, self.comm)
        el = mpi.agree(self.comm, lambda: self.elements(*live.arguments))
        if spec.element != "law":
            el = shared_elements(self.comm, el, live, self.held, owner, self.mine)
        return mpi.agree(self.comm, lambda: assembled(live, el)), np.asarray(self.elements.built.plain, dtype=bool)

    def _joule_heated(self, particles, owner: np.ndarray):
        """The held particles with the absorbed Joule heat of the current added to their heat sources (module
        docstring: valid for the owned ones, whose contacts are all here); keeps the potentials of the held particles
        and the circuit's summary, reduced over the ranks."""
        e, b = self.full_scene.electrical, self.bonds
        wires = electrode_bonds(particles, b, self.scene.walls, self.scene.conductance, e.electrodes, self.scene.box)
        neutral = replace(particles, temperature=np.zeros(particles.n), fixed=np.zeros(particles.n, dtype=bool),
                          heat=np.zeros(particles.n))
        through = replace(b.subset(slice(None), wires.on_electrode), wall_index=wires.plane_index)
        network = Network(neutral, through, wires.G, wires.G_plane, e.electrodes.potential)
        part = DistributedNetwork(self.comm, network, self.held, owner)
        x, _, _, n_float, _ = part.steady("mean")
        if e.floating == "error" and n_float:
            G = part.groups(network.fixed_diag + network.wall_diag)
            lost = G.member(G.floating) & part.own_free
            refuse_floating(np.sort(np.concatenate(self.comm.allgather(self.held[lost]))))
        V = e.electrodes.potential
        pair_current, wall_current, heat_pairs, heat_walls, self.joule = contact_currents(
            particles.n, b.i, b.j, wires.G, wires.share, wires.plane_node, wires.plane_index, wires.G_plane, x, V,
            np.ones(len(wires.plane_node), dtype=bool))
        current = part.total(np.bincount(wires.plane_index, wall_current, len(V)))
        heat = part.total(float(heat_pairs[self.mine[b.i]].sum() + heat_walls.sum()))
        self.potential = x
        self.circuit = circuit(e.electrodes, V, current, heat, float(V @ current))
        return replace(particles, heat=particles.heat + e.absorption * self.joule)

    # ------------------------------------------------------------------------------------------------ run
    def run(self, observe=None, progress=None, checkpoint=None) -> None:
        """Solve (steady) or step (transient) to ``[solver] t_end`` on all ranks together (``checkpoint`` unused:
        a distributed run does not resume).

        Parameters
        ----------
        observe : callable or None
            Called without arguments at the output times; None: not called.
        progress : callable or None
            Called with the simulated time (s); None: not called.
        checkpoint : callable or None
            Called as ``checkpoint(make, final)``; None: not called.

        Raises
        ------
        ValueError
            The network has no solution (a floating group) or the solve failed.
        """
        s = self.scene.solver
        nodes, element = self.scene.conductance.nodes, self.scene.conductance.element
        out = {"law": self.scene.conductance.law, "contact": self.bonds.contact, "bonds_clipped": 0,
               "bonds_dropped": 0, "wall_bonds": self.part.total(int(self.bonds.n_walls)), "ranks": self.ranks}
        b = self.bonds
        out.update(neck_account(self.part.total(int(np.count_nonzero(self.meeting[self.mine]))),
                                self.full_scene.particle_count, b.contact,
                                self.part.total(int(np.count_nonzero(self.mine[b.i]) + b.n_walls)),
                                self.full_scene.conductance.law,
                                self.part.total(int(np.count_nonzero(self.wide[self.mine]))), nodes=nodes,
                                element=element))
        if self.necks is not None:
            live = self.mine[self.necks.bonds.i[self.necks.live]]
            out.update(nodes="necks", neck_nodes=self.part.total(int(np.count_nonzero(live))))
            if element == "law":
                out["particles_without_interactions"] = self.part.total(int(np.count_nonzero(self.plain[self.mine])))
            else:  # the counts of the own particles and the time of every rank's elements, summed
                out.update({key: self.part.total(value) if key != "element" else value
                            for key, value in self.elements.account().items()})
        observer = self._observed(observe)
        if s.mode == "steady" and self.necks is not None:
            T_F, flows, err, solver = mpi.agree(self.comm, lambda: self.part.steady(s.floating))
            observer(0, 0.0, T_F, flows)
            out.update(energy_error=err, heat_flow=flows, linear_solver=solver, newton_iterations=1)
            self._neck_boundary(out)
        elif s.mode == "steady":
            T_F, flows, err, n_float, solver = mpi.agree(
                self.comm, lambda: self.part.steady(s.floating))
            observer(0, 0.0, T_F, flows)
            out.update(energy_error=err, heat_flow=flows, linear_solver=solver, newton_iterations=1,
                       floating_groups=n_float)
            if self.part.total(len(self.network.fixed)) or len(self.scene.walls):
                out["boundary_heat_flow"] = self._boundary(self.T)
            if self.scene.box is not None:
                out["periodic_heat_flow"] = self._periodic(self.T).tolist()
        else:
            t0 = self.t_start
            res = mpi.agree(self.comm, lambda: self.part.integrate(
                s.integrator, float(s.dt), s.t_end - t0, observer=observer,
                progress=None if progress is None else (lambda t: progress(t0 + t))))
            out.update(energy_error=res.energy_error, heat_in=res.heat_in, integrator=s.integrator, dt=s.dt,
                       dt_min=res.dt_min, dt_max=res.dt_max, rejected_steps=0, stable_limit=None,
                       linear_solver=res.solver, factorizations=res.factorizations,
                       max_principle_violation=res.max_principle_violation)
            if res.startup_steps:  # a stiff Crank-Nicolson run: its first steps were implicit Euler
                out["startup_steps"] = res.startup_steps
        out["linear_iterations"] = self.part.linear_iterations
        self.details = out

    def _neck_boundary(self, out: dict) -> None:
        """With a node per neck: the heat flow into each wall and each fixed particle and across the period
        (:func:`dem.network.necks.neck_flows`), each wall bond and fixed particle counted by the rank owning its
        particle, each neck across the period by the rank owning its bond's first particle; into ``out`` under the
        serial run's keys."""
        net, own = self.necks, self.mine
        bond_flow, wall_flow, fixed_flow = neck_flows(net, self.T_nodes)
        b = net.bonds
        if self.part.total(int(np.count_nonzero(self.scene.particles.fixed[own]))) or len(self.scene.walls):
            mine = own[b.wall_particle]
            walls = self.part.total(np.bincount(b.wall_index[mine], wall_flow[mine], len(self.scene.walls)))
            fixed = np.flatnonzero(self.scene.particles.fixed & own)
            into = {int(k): float(v) for part in self.comm.allgather(
                dict(zip(self.held[fixed].tolist(), (-fixed_flow[fixed]).tolist()))) for k, v in part.items()}
            out["boundary_heat_flow"] = boundary_summary(self.full_scene, walls, into)
        if self.scene.box is not None:
            first = own[b.i]
            out["periodic_heat_flow"] = self.part.total(bond_flow[first] @ b.shifts[first]).tolist()

    def bond_heat_flow(self) -> tuple[np.ndarray, np.ndarray]:
        """Heat flow (W) along each pair bond of this rank's particles from i to j, and from each of its
        wall-bonded particles into its wall (with a node per neck: through the neck)."""
        if self.T_nodes is None:
            return super().bond_heat_flow()
        q_pairs, q_walls = neck_flows(self.necks, self.T_nodes)[:2]
        pairs, walls = self.kept
        return q_pairs[pairs], q_walls[walls]

    def _boundary(self, T: np.ndarray) -> dict:
        """Heat flow into each wall and each fixed particle (:func:`dem.network.heat.boundary_heat_flow`), summed
        over the ranks."""
        net, b = self.network, self.bonds
        into = -(net.L @ T) + net.jump_rhs
        to_wall = net.K_walls * (T[b.wall_particle] - net.wall_temperature[b.wall_index])
        into -= np.bincount(b.wall_particle, to_wall, len(T))
        n_walls = len(net.wall_temperature)
        walls = self.part.total(np.bincount(b.wall_index, to_wall, n_walls)) if n_walls else np.zeros(0)
        mine = net.fixed[self.mine[net.fixed]]
        fixed = {int(k): float(v) for part in self.comm.allgather(
            dict(zip(self.part.held[mine].tolist(), into[mine].tolist()))) for k, v in part.items()}
        return boundary_summary(self.full_scene, walls, fixed)

    def _periodic(self, T: np.ndarray) -> np.ndarray:
        """Heat flow across the period along x, y, z (:func:`dem.network.heat.periodic_heat_flow`) over the
        ranks: each bond counted by the rank owning its first particle."""
        b, net = self.bonds, self.network
        first = self.mine[b.i]
        q = net.K_pairs[first] * (T[b.i[first]] - T[b.j[first]] + net.jump[first])
        return self.part.total(q @ b.shifts[first])

    # -------------------------------------------------------------------------------------------- outputs
    def record(self) -> dict:
        T = self.T[self.mine]
        n = self.part.total(len(T))
        return {"step": self.steps, "t": self.t, "T_mean": float(self.part.total(float(T.sum())) / n),
                "T_min": mpi.minimum(self.comm, float(T.min(initial=np.inf))),
                "T_max": mpi.maximum(self.comm, float(T.max(initial=-np.inf))),
                **{f"Q_{k}": float(self.flows.get(k, 0.0)) for k in CSV_FLOWS}}

    def positions(self) -> np.ndarray:
        return self.scene.particles.position[self.mine]

    def temperatures(self) -> np.ndarray:
        return self.T[self.mine]

    def particle_fields(self) -> dict:
        return {k: v[self.mine] for k, v in super().particle_fields().items()}

    def links(self):
        """The bonds of
        :meth:`~dem.engines.static.StaticEngine.links` this rank writes: pair bonds whose first particle it owns, the
        wall bonds of its particles."""
        points, lines, fields = super().links()
        keep = np.concatenate([self.mine[self.bonds.i], np.ones(self.bonds.n_walls, dtype=bool)])
        return points, lines[keep], {k: v[keep] for k, v in fields.items()}

    def plots(self, out, summary: dict) -> list[str]:
        return []  # the plots need every particle on one rank

    def _over_the_packing(self) -> tuple:
        """The whole scene, the pair bonds of the owned particles summed over the ranks, the temperatures' mean,
        smallest and largest over every rank's owned particles."""
        own = self.T[self.mine]
        bonds = self.part.total(int(np.sum(self.mine[self.bonds.i])))
        T_mean = float(self.part.total(float(own.sum())) / self.full_scene.particle_count)
        return self.full_scene, bonds, (T_mean, mpi.minimum(self.comm, float(own.min(initial=np.inf))),
                                        mpi.maximum(self.comm, float(own.max(initial=-np.inf))))

    def gathered_temperatures(self) -> np.ndarray:
        """The final temperatures of all particles in the scene's order, on every rank (for small scenes: the
        summary's list, tests)."""
        T = np.empty(self.full_scene.particle_count)
        for index, values in self.comm.allgather((self.owned, self.T[self.mine])):
            T[index] = values
        return T
