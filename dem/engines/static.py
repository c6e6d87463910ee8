r"""The engine of a static packing: the pipe network of Rojek 2022 (eqs. 1-9) on bonds found once from the scene's
geometry, solved steady or integrated in time (:mod:`dem.network.heat`). It never moves a particle and allocates
no mechanical state; a scene whose physics is ``"thermal"``, or ``"thermal"`` and ``"electrical"``, runs here.

With ``"electrical"`` physics a current flows between the electrodes (walls with a potential or a current) through the
same bonds (Kirchhoff's laws, :func:`dem.network.current.kirchhoff`: each contact's conductance the scene's law with the
electrical conductivity for :math:`\kappa`; with a node per neck the particles' elements scaled by
:math:`\sigma / \kappa`, :func:`dem.network.necks.neck_current`, each particle's Joule heat its element's
dissipation). Nothing moves and the conductivities do not depend on the temperature, so it is solved once, before the
heat: the absorbed part of its Joule heat is a constant source in every particle.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from dem import memory
from dem.engines import Engine
from dem.geometry.bonds import find_bonds
from dem.geometry.necks import meeting_in
from dem.laws.conductance import bond_conductances
from dem.laws.verified_range import neck_account, wide_necks
from dem.network.current import circuit, electrode_bonds, kirchhoff, refuse_floating, require_paths
from dem.network.elements import scene_elements
from dem.network.heat import (Checkpoint, Network, bonds_and_conductances, boundary_heat_flow, integrate,
                              periodic_heat_flow, steady)
from dem.network.necks import NeckHeat, neck_current, neck_flows, neck_network, steady_necks
from dem.scene.specimen import group_flows, held_groups
from dem.scene.state_file import box_arrays

WORK_PER_STEP_LIMIT = 3000  # particle-steps allowed per unit of solver.max_steps (default 1e5: 3e8, ~1 min)
SECONDS_PER_PARTICLE_STEP = 2e-7  # implicit, 2 cores: 1e-7 (10^6-particle lattice) to 6e-7 (random packing, bench)
# an implicit step with a node per neck (AMG on the centres and necks) costs as many one-node particle-steps, by the
# neck reading: 1.4e-6 s of CPU per particle-step (7 x the figure above) on a random union packing tiled to 6912
# particles, and 4.6e-6 s (23 x) on a pair-neck reading (the benchmarks' random sintered packing of 6050 particles,
# 5.2 bonds each, where one node per particle took 1.0e-7 s), dt = 0.1 r^2 rho c / kappa, 30 steps
NECK_STEP_COST = {"union": 7.0, "pair": 23.0}
CSV_FLOWS = ("fixed", "walls", "convection", "radiation", "internal")  # the heat-flow columns of timeseries.csv


def effective_conductivity(scene, summary: dict) -> float | None:
    """``k_eff = Q L / (A dT)`` (steady): between the two ends of the scene's specimen (:mod:`dem.scene.specimen`:
    walls or held groups, ``Q`` the heat leaving the hot end), or along the one axis of a periodic box with a
    temperature drop per period (``Q`` the heat flow across the period).

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene: its specimen (:mod:`dem.scene.specimen`) and periodic box.
    summary : dict
        The run's summary: its ``boundary_heat_flow`` (W) or ``periodic_heat_flow`` (W per axis).

    Returns
    -------
    float or None
        ``k_eff`` (W/(m K)), or None where the scene has no specimen, its ends are at one temperature or the
        summary lacks the heat flow.
    """
    box, sp = scene.box, scene.specimen
    if box is not None and "periodic_heat_flow" in summary:
        axes = np.flatnonzero(box.drop)
        if len(axes) == 1:
            k = int(axes[0])
            return summary["periodic_heat_flow"][k] * box.lengths[k] / (box.cross_section(k) * box.drop[k])
    if sp is None or sp.periodic or sp.hot == sp.cold or "boundary_heat_flow" not in summary:
        return None
    kind, name = sp.hot_end
    q = -summary["boundary_heat_flow"]["walls" if kind == "wall" else "groups"][name]
    return q * sp.length / (sp.area * (sp.hot - sp.cold))


def refuse_neck_nodes(scene, moving: bool = False) -> None:
    """``[conductance] nodes = "necks"`` (:mod:`dem.network.necks`) solves steady heat and integrates it with implicit
    or Crank-Nicolson steps, on a static packing with convection, radiation and a current: an explicit integrator
    (which cannot carry the massless necks), and on moving particles an ambient exchange or a current, are refused in
    one line.

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene.
    moving : bool
        Whether the particles move (the velocity-Verlet engine's thermal steps on the network of their contacts,
        :mod:`dem.engines.contact_heat`, which carries no ambient or current with neck nodes so far).

    Raises
    ------
    ValueError
        The scene asks for what the network with a node per neck does not solve.
    """
    if scene.conductance.nodes != "necks":
        return
    if scene.solver.mode == "transient" and scene.solver.integrator == "explicit":
        raise ValueError("solver.integrator = \"explicit\": an explicit step cannot carry the massless neck nodes of "
                         "[conductance] nodes = \"necks\"; use \"implicit\" or \"crank-nicolson\"")
    what = ("convection" if scene.sources.convection is not None else
            "radiation" if scene.sources.radiation is not None else
            "electrical physics" if scene.electrical is not None else None)
    if moving and what is not None:
        raise ValueError(f"[conductance] nodes = \"necks\": moving particles exchange heat without convection, "
                         f"radiation or current so far (this scene has {what}); use nodes = \"particles\"")


def boundary_summary(scene, walls, into: dict) -> dict:
    """The summary's ``boundary_heat_flow``: W into each wall (``walls``, in the scene's order) by name, into each
    held group (:func:`dem.scene.specimen.held_groups`) by name, into all held particles, and (up to 1000 of them)
    into each held particle by id (``into``: ``{index: W}``).

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene: its walls, particles and named groups.
    walls : sequence of float
        The heat flow into each wall of ``scene.walls``, in its order (W).
    into : dict
        The heat flow into each held particle, ``{index: W}``.

    Returns
    -------
    dict
        ``{"walls": {name: W}, "groups": {name: W}, "fixed_total": W}``, and ``"particles": {id: W}`` for up to
        1000 held particles.
    """
    part = scene.part
    if part is None or part.fixed is None:
        groups, ids = held_groups(scene.particles, scene.groups), scene.particles.id
    else:  # a rank's part of a packing in parts: the groups of all its fixed particles, by their places in it
        groups = {name: part.fixed_places[k] for name, k in held_groups(part.fixed).items()}
        ids = dict(zip(part.fixed_places.tolist(), part.fixed.id.tolist()))
    out = {"walls": {w.name: float(q) for w, q in zip(scene.walls, walls)}, "groups": group_flows(groups, into),
           "fixed_total": float(sum(into[k] for k in sorted(into)))}
    if len(into) <= 1000:  # by particle id (the index unless a packing file gave ids)
        out["particles"] = {str(ids[k]): into[k] for k in sorted(into)}
    return out


class StaticEngine(Engine):
    """The thermal network of a static packing (module docstring), as the driver asks of an engine
    (:mod:`dem.engines`).

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene to solve (steady) or integrate (transient).
    restart : dict or None
        The checkpoint of this scene's transient run (:func:`dem.output.folder.load`) to go on from; None: start
        at the scene's start.

    Raises
    ------
    ValueError
        The scene needs more memory than is available, or a fixed-step transient run exceeds the work limit.
    """

    name = "static"
    link_kind = "bonds"
    necks_heat = None  # a transient run with a node per neck: its network (dem.network.necks.NeckHeat)
    T_nodes = None  # with a node per neck: all its nodes' temperatures as the run stands (K or degC)
    elements = None  # with a node per neck: the particles' elements as built (dem.network.elements.SceneElements)

    def __init__(self, scene, restart: dict | None = None):
        """``restart``: the checkpoint of this scene's transient run (:func:`dem.output.folder.load`)."""
        self.scene = scene
        spec = scene.conductance
        memory.check(scene.particles.n, "particles", spec.neck, spec.nodes)  # before the bond search: costs nothing
        refuse_neck_nodes(scene)
        if scene.solver.mode == "transient":
            self._check_work()
        particles, walls = scene.particles, scene.walls
        if spec.nodes == "necks":  # a node per neck (dem.network.necks): the solves, the current and the bonds' flows
            # are its own, the one-node law's conductances (the links' field) from the halves its elements are of
            bonds = find_bonds(particles, tuple(walls), spec.contact, spec.out_of_range, box=scene.box)
            self.elements = scene_elements(spec)
            self.necks = neck_network(spec, particles, bonds, box=scene.box, walls=walls, elements=self.elements)
            K_pairs, K_walls = bond_conductances(spec, particles, bonds, box=scene.box, walls=tuple(walls),
                                                 union=self.necks.union)
        else:
            self.necks = None
            bonds, K_pairs, K_walls = bonds_and_conductances(particles, walls, spec, box=scene.box)
        self.potential, self.circuit = None, None
        if scene.electrical is not None:
            particles = self._joule_heated(particles, bonds)
        wall_temperature = np.array([w.temperature for w in walls], dtype=float)
        self.network = Network(particles, bonds, K_pairs, K_walls, wall_temperature, scene.sources, scene.box)
        self.bonds, self.K_pairs, self.K_walls = bonds, K_pairs, K_walls
        self.meeting = meeting_in(particles, walls, bonds, scene.box)
        self.restart = Checkpoint.from_arrays(restart) if restart is not None else None
        self.t_start = float(scene.start_time)
        self.T = scene.particles.temperature.astype(float)
        self.t, self.steps = (self.restart.t, self.restart.steps) if self.restart is not None else (self.t_start, 0)
        self.flows: dict = {}
        self.details: dict = {}

    def _joule_heated(self, particles, bonds):
        """The particles with the absorbed Joule heat of the current (module docstring) added to their heat sources;
        keeps the potentials and what the summary says of the circuit."""
        e = self.scene.electrical
        if self.necks is not None:  # the current through the neck nodes, each particle's Joule heat its element's
            flow, plane_index = neck_current(self.necks, self.scene.walls, e.electrodes, self.scene.solver.linear)
        else:
            net = electrode_bonds(particles, bonds, self.scene.walls, self.scene.conductance, e.electrodes,
                                  self.scene.box)
            flow = kirchhoff(particles.n, bonds.i, bonds.j, net.G, net.share, net.plane_node, net.plane_index,
                             net.G_plane, e.electrodes, self.scene.solver.linear)
            plane_index = net.plane_index
        require_paths(flow, e.electrodes, plane_index)
        if e.floating == "error":
            refuse_floating(flow.floating)
        self.potential = flow.potential
        self.circuit = circuit(e.electrodes, flow.electrode_potential, flow.electrode_current, flow.joule_heat,
                               flow.electrode_power)
        heated = replace(particles, heat=particles.heat + e.absorption * flow.joule_particles)
        if self.necks is not None:
            self.necks = replace(self.necks, particles=heated)
        return heated

    def run(self, observe=None, progress=None, checkpoint=None) -> None:
        """Solve (steady) or integrate (transient) to ``[solver] t_end``; ``observe()`` after every step (and at the
        start), ``progress(t)`` with the simulated time, ``checkpoint(make, final)`` after every step and at the end
        (:func:`dem.network.heat.integrate`).

        Parameters
        ----------
        observe : callable or None
            Called without arguments after every step and at the start (the snapshots); None: not called.
        progress : callable or None
            Called with the simulated time (s) as the run advances; None: not called.
        checkpoint : callable or None
            Called as ``checkpoint(make, final)`` after every step and at the end; None: not called.

        Raises
        ------
        ValueError
            A factorisation failed (exactly singular); the message says why from the scene's capacities and
            conductances.
        """
        try:
            self._run(observe, progress, checkpoint)
        except RuntimeError as exc:  # e.g. SuperLU "Factor is exactly singular": explain it as a property of the scene
            raise ValueError(self._singular_message(exc)) from None

    def _check_work(self) -> None:
        """Refuse a fixed-step run whose particle-steps (a node per neck: :data:`NECK_STEP_COST` each, by the neck
        reading) exceed ``WORK_PER_STEP_LIMIT * max_steps`` up front, with a time estimate
        (:data:`SECONDS_PER_PARTICLE_STEP`)."""
        s, n, spec = self.scene.solver, self.scene.particle_count, self.scene.conductance
        if s.dt == "auto":
            return  # the step count is not known in advance; max_steps bounds it while running
        necks = spec.nodes == "necks"
        each = NECK_STEP_COST["union" if spec.neck == "union" else "pair"] if necks else 1.0
        work = s.t_end / s.dt * n * each
        if work > WORK_PER_STEP_LIMIT * s.max_steps:
            cost = f" x {each:g} (a node per neck)" if necks else ""
            raise ValueError(f"solver: t_end / dt = {s.t_end / s.dt:.3g} steps x {n} particles{cost} = {work:.3g} "
                             f"particle-steps (about {SECONDS_PER_PARTICLE_STEP * work:.3g} s) exceeds "
                             f"{WORK_PER_STEP_LIMIT} x solver.max_steps = {WORK_PER_STEP_LIMIT * s.max_steps:.3g}; "
                             f"raise max_steps to run it anyway, or use a larger dt, a shorter t_end or fewer "
                             f"particles")

    def _singular_message(self, exc: Exception) -> str:
        """Why a factorisation failed: the capacities vanish next to the conductances in ``C/dt + theta A``."""
        s, p = self.scene.solver, self.scene.particles
        diag = np.bincount(self.bonds.i, self.K_pairs, p.n) + np.bincount(self.bonds.j, self.K_pairs, p.n)
        diag += np.bincount(self.bonds.wall_particle, self.K_walls, p.n)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            tau = float(np.min(p.capacity / diag, initial=np.inf))
        step = s.t_end if s.dt == "auto" else s.dt
        what = "solver.t_end (the largest step dt = \"auto\" can take)" if s.dt == "auto" else "solver.dt"
        return (f"the linear system became numerically singular ({' '.join(str(exc).split())}): {what} = "
                f"{step:.6g} s against a smallest particle time constant C/K = {tau:.6g} s, so the capacities are "
                f"lost to round-off; use a step (or t_end) below about 1e12 times that time constant, or "
                f"mode = \"steady\"" if s.mode == "transient" else
                f"the steady linear system is numerically singular ({' '.join(str(exc).split())}); check that "
                f"conductances, ambient coefficients and fixed temperatures are within a few orders of magnitude "
                f"of each other")

    def _observed(self, observe):
        """The integrator's observer: keeps the step's state for :meth:`record` and passes it on."""
        def observer(step, t, T_free, flows):
            self.steps, self.t, self.flows = step, self.t_start + t, flows
            if self.necks_heat is None:
                self.T = self.network.full(T_free)
            else:
                self.T, self.T_nodes = self.necks_heat.full(T_free), self.necks_heat.nodes(T_free)
            if observe is not None:
                observe()
        return observer

    def _run(self, observe, progress, checkpoint) -> None:
        s = self.scene.solver
        spec = self.scene.conductance
        law, nodes, element = spec.law, spec.nodes, spec.element
        out = {"law": law, "contact": self.bonds.contact,
               "bonds_clipped": self.bonds.clipped, "bonds_dropped": self.bonds.dropped,
               "wall_bonds": self.bonds.n_walls,
               **neck_account(np.count_nonzero(self.meeting), self.scene.particles.n, self.bonds.contact,
                              self.bonds.n_pairs + self.bonds.n_walls, law,
                              np.count_nonzero(wide_necks(self.scene.particles.radius, self.bonds, self.meeting, law,
                                                          nodes, element)), nodes=nodes, element=element)}
        if self.necks is not None:  # (a Trefftz element's plain particles keep the law's monopoles: element_plain)
            out.update(nodes="necks", neck_nodes=len(self.necks.live), **self.elements.account())
            if element == "law":
                out["particles_without_interactions"] = self.necks.plain
        observer = self._observed(observe)
        t0 = self.t_start
        if s.mode == "steady" and self.necks is not None:
            self._steady_necks(observer, out)
        elif s.mode == "steady":
            res = steady(self.network, s.floating, s.linear)
            observer(0, 0.0, res.T[self.network.free], res.flows)
            out.update(energy_error=res.energy_error, heat_flow=res.flows, linear_solver=res.solver,
                       newton_iterations=res.iterations, floating_groups=res.floating)
            if len(self.network.fixed) or len(self.scene.walls):
                out["boundary_heat_flow"] = self._boundary(res.T)
            if self.scene.box is not None:
                out["periodic_heat_flow"] = periodic_heat_flow(self.network, res.T).tolist()
        else:
            if self.necks is not None:
                self.necks_heat = NeckHeat(self.necks, s.linear, sources=self.network.sources)
            net = self.network if self.necks_heat is None else self.necks_heat
            res = integrate(net, s.integrator, s.dt, s.t_end - t0, s.rtol, s.linear, s.max_steps, observer,
                            None if progress is None else (lambda t: progress(t0 + t)), resume=self.restart,
                            checkpoint=checkpoint)
            self.T, self.t, self.steps = res.T, t0 + res.t, res.steps
            out.update(energy_error=res.energy_error, heat_in=res.heat_in,
                       integrator=s.integrator, dt=s.dt, dt_min=res.dt_min, dt_max=res.dt_max,
                       rejected_steps=res.rejected, stable_limit=res.stable_limit, linear_solver=res.solver,
                       factorizations=res.factorizations, max_principle_violation=res.max_principle_violation)
            if res.startup_steps:  # a stiff Crank-Nicolson run: say that its first steps were implicit Euler
                out["startup_steps"] = res.startup_steps
        self.details = out

    def _steady_necks(self, observer, out: dict) -> None:
        """The steady solve with a node per neck (:func:`dem.network.necks.steady_necks`) and what the summary says of
        it, in the keys of the one-node solve."""
        res = steady_necks(self.necks, self.scene.solver.floating, self.scene.solver.linear,
                           sources=self.network.sources)
        b = self.bonds
        self.T_nodes = np.concatenate([res.T, res.T_necks])
        observer(0, 0.0, res.T[self.network.free], res.flows)
        out.update(energy_error=res.energy_error, heat_flow=res.flows, linear_solver=res.solver,
                   newton_iterations=res.iterations)
        if len(self.network.fixed) or len(self.scene.walls):
            walls = np.bincount(b.wall_index, res.wall_flow, len(self.scene.walls))
            out["boundary_heat_flow"] = boundary_summary(self.scene, walls,
                                                         {int(k): float(-res.fixed_flow[k]) for k in self.network.fixed})
        if self.scene.box is not None:
            out["periodic_heat_flow"] = res.periodic_heat_flow.tolist()

    def _boundary(self, T: np.ndarray) -> dict:
        flows = boundary_heat_flow(self.network, T)
        return boundary_summary(self.scene, flows["walls"], flows["particles"])

    # -------------------------------------------------------------------------------------------- outputs
    def record(self) -> dict:
        """One row of ``timeseries.csv``: step, time, temperatures and the heat flow (W) into the particles through
        each boundary."""
        T = self.T
        return {"step": self.steps, "t": self.t, "T_mean": float(T.mean()), "T_min": float(T.min()),
                "T_max": float(T.max()), **{f"Q_{k}": float(self.flows.get(k, 0.0)) for k in CSV_FLOWS}}

    def positions(self) -> np.ndarray:
        """Particle centres (n, 3), m."""
        return self.scene.particles.position

    def temperatures(self) -> np.ndarray:
        """Particle temperatures (n,), in the scene's temperature unit."""
        return self.T

    def particle_fields(self) -> dict:
        """The snapshot's point data by name: id, radius, temperature, fixed, material, necks_meeting."""
        p = self.scene.particles
        fields = {"id": p.id, "radius": p.radius, "temperature": self.T, "fixed": p.fixed.astype(np.int8),
                  "material": p.material.astype(np.int32), "necks_meeting": self.meeting.astype(np.int8)}
        if self.potential is not None:
            fields["potential"] = self.potential
        return fields

    def links(self):
        """The bonds as lines: a pair bond joins its particles, a wall bond joins the particle to its foot point on
        the wall, a bond across a periodic face joins the particle to the image of its partner (outside the box);
        with their conductance, heat flow and neck radius."""
        p, b = self.scene.particles, self.bonds
        q_pairs, q_walls = self.bond_heat_flow()
        walls = self.scene.walls
        x = p.position[b.wall_particle]
        foot = np.array([walls[w].point for w in b.wall_index]).reshape(-1, 3)
        normal = np.array([walls[w].normal for w in b.wall_index]).reshape(-1, 3)
        foot = x - np.sum((x - foot) * normal, axis=1, keepdims=True) * normal
        crossing = np.flatnonzero(np.any(b.shifts != 0, axis=1))
        image = b.vectors(p.position, self.scene.box)[crossing] + p.position[b.i[crossing]]
        points = np.vstack([p.position, foot, image])
        partner = b.j.copy()
        partner[crossing] = p.n + b.n_walls + np.arange(len(crossing))
        lines = np.vstack([np.column_stack([b.i, partner]),
                           np.column_stack([b.wall_particle, p.n + np.arange(b.n_walls)])]).astype(np.int64)
        return points, lines, {"conductance": np.concatenate([self.K_pairs, self.K_walls]),
                               "heat_flow": np.concatenate([q_pairs, q_walls]),
                               "neck_radius": np.concatenate([b.a, b.wall_a])}

    def profile(self):
        """None: this engine offers no profiles."""
        return None

    def plots(self, out, summary: dict) -> list[str]:
        """Write the run folder's plots (:func:`dem.output.plots.thermal_plots`).

        Parameters
        ----------
        out : str or pathlib.Path
            The run folder.
        summary : dict
            The run's summary (unused here: the plots read the folder and the engine's temperatures).

        Returns
        -------
        list of str
            The names of the files written.
        """
        from dem.output.plots import thermal_plots

        return thermal_plots(out, self.scene, self.T)

    def _over_the_packing(self) -> tuple:
        """``(scene, pair bonds, (T_mean, T_min, T_max))`` of the whole packing, for the summary (the distributed
        engine sums and reduces its ranks' parts)."""
        return self.scene, self.bonds.n_pairs, (float(self.T.mean()), float(self.T.min()), float(self.T.max()))

    def summary(self) -> dict:
        """What the run found (the driver adds the scene's name, times and the state file)."""
        scene, bonds, (T_mean, T_min, T_max) = self._over_the_packing()
        d = dict(self.details)
        out = {"mode": self.scene.solver.mode, "t": self.t, "steps": self.steps, "particles": scene.particle_count,
               "bonds": bonds, "energy_error": d.pop("energy_error", None), "static": True}
        for key in ("boundary_heat_flow", "periodic_heat_flow"):
            if key in d:
                out[key] = d.pop(key)
        k_eff = effective_conductivity(scene, out)
        if k_eff is not None:
            out["effective_conductivity"] = k_eff
            if scene.specimen is not None and not scene.specimen.periodic:
                out["specimen"] = scene.specimen.describe()
        out.update(T_mean=T_mean, T_min=T_min, T_max=T_max)
        out.update(d)
        if self.circuit is not None:
            out["electrical"] = self.circuit
        return out

    def state(self) -> dict:
        """The particles as they end (:mod:`dem.scene.state_file`): positions, radii, temperatures, ids, the time,
        the periodic box."""
        p = self.scene.particles
        return {"engine": np.array(self.name), "t": np.array(self.t), "steps": np.array(self.steps),
                "x": p.position, "radius": p.radius, "T": self.T, "id": p.id, "material": p.material,
                **box_arrays(self.scene.box)}

    def bond_heat_flow(self) -> tuple[np.ndarray, np.ndarray]:
        """Heat flow (W) along each pair bond from i to j, and from each wall-bonded particle into its wall (with a
        node per neck: through the neck, :func:`dem.network.necks.neck_flows`)."""
        if self.T_nodes is not None:
            return neck_flows(self.necks, self.T_nodes)[:2]
        b, T = self.bonds, self.T
        wall_T = self.network.wall_temperature[b.wall_index]
        return self.K_pairs * (T[b.i] - T[b.j] + self.network.jump), self.K_walls * (T[b.wall_particle] - wall_T)
