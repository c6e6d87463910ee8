"""The engine for particles that move: the simulation owns the time loop, the submodels plug into it.

A run is a sequence of *intervals* on the mechanical step grid ``t = k dt``. An interval ends at the next output
time, the next thermal update and the next knot of the temperature schedule, whichever comes first; in each the
submodels act in order:

1. ``mechanical`` (:class:`dem.engines.verlet.mechanics.MechanicalModel`) -- contact forces, walls, gravity and velocity-Verlet
   steps, in compiled code, with the temperatures of the interval: prescribed by the schedule (linear in time,
   uniform), computed by the thermal network (its latest temperatures extrapolated with the rate of its last step),
   or the initial ones;
2. ``thermal`` (:class:`dem.engines.contact_heat.ContactThermalModel`) -- one implicit step of the pipe network over the
   interval, on the contacts as they are at its end;
3. observers -- the output writer and the progress bar.

The thermal interval is many mechanical steps long (``[solver] thermal_interval``), so neither physics forces the
other's step down. A scene whose physics is only ``thermal`` never comes here: it runs on the static path of
:mod:`dem.engines.static`, exactly as before.
"""

from __future__ import annotations

import math

import numpy as np

from dataclasses import replace

from dem import memory
from dem.engines import Engine
from dem.engines.contact_heat import ContactThermalModel
from dem.engines.static import refuse_neck_nodes
from dem.engines.verlet.mechanics import MechanicalModel
from dem.geometry.bonds import find_bonds
from dem.engines.state import MotionState
from dem.geometry.necks import meeting_in
from dem.geometry.neighbours import list_arrays
from dem.geometry.periodic import pair_lines
from dem.geometry.walls import box_axes
from dem.laws.contact import law_module
from dem.laws.verified_range import neck_account, wide_necks
from dem.scene.state_file import moving_arrays, normalised
from dem.network.heat import Network, boundary_heat_flow, bonds_and_conductances, steady
from dem.network.necks import steady_necks
from fem_neck.geometry import max_overlap, neck_radius


class VerletEngine(Engine):
    """A moving-particle run built from a scene with ``"mechanical"`` physics, as the driver asks of an engine
    (:mod:`dem.engines`)."""

    name = "verlet"
    link_kind = "contacts"
    mechanics_class = MechanicalModel  # the particles of one process (the ranks engine sets its own)
    thermal_class = ContactThermalModel  # their heat (the ranks engine's on several ranks: its own)

    def __init__(self, scene, restart: dict | None = None):
        """``restart``: a checkpoint of this scene's run (:meth:`checkpoint` as loaded by
        :func:`dem.output.folder.load`): the run goes on from its step as if it had not stopped. A scene that starts
        from a saved state (``[start] state``) goes on from that state's time and counters.

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene.
        restart : dict or None
            A checkpoint of this scene's run to go on from; None: start at the scene's start.
        """
        self.scene = scene
        m = scene.motion
        p = scene.particles
        if "thermal" in scene.physics and scene.conductance.nodes == "necks":  # before anything large: costs nothing
            memory.check(p.n, "particles", scene.conductance.neck, "necks", moving=True)
        material = scene.contact
        T_init = p.temperature.astype(float)
        law = law_module(material.law)
        state = MotionState.create(m.dimension, p.position, p.radius, material.density, T_init, m.velocity,
                                   m.angular_velocity, m.height, radius_ref=law.reference_radius(material, p.radius,
                                                                                                   T_init))
        if restart is not None:
            restart = normalised(dict(restart))
        saved = restart if restart is not None else m.start
        if saved is not None:
            for key in ("x", "v", "w", "f", "tau", "mass", "inertia", "radius", "radius_ref", "T"):
                setattr(state, key, np.ascontiguousarray(saved[key], dtype=float).copy())
        self.material = material
        self.mechanics = self.mechanics_class(state, m.walls, material, m.dt, m.skin, m.gravity, scene.box,
                                              relaxation_time=m.verlet.relaxation_time, history=saved)
        self.thermal = None
        refuse_neck_nodes(scene, moving=True)
        if "thermal" in scene.physics:
            self.thermal = self.thermal_class(p, m.walls, scene.conductance, scene.sources, m.verlet.thermal_integrator,
                                               scene.solver.linear, scene.box)
        self.schedule = m.verlet.schedule
        self.steps_start = 0
        if restart is not None:
            self._resume(restart)
        elif m.start is not None:
            self._go_on_from(m.start)

    @property
    def t(self) -> float:
        """Simulated time, s."""
        return self.mechanics.t

    @property
    def t_start(self) -> float:
        """The time the run started at, s (0, or a saved state's)."""
        return self.mechanics.t_start

    @property
    def steps(self) -> int:
        """Steps since the first run of the sample (a run from a saved state goes on counting from its steps)."""
        return self.steps_start + self.mechanics.steps

    def _go_on_from(self, saved: dict) -> None:
        """A saved state's clock and counters: the run starts at its time and goes on counting."""
        mech = self.mechanics
        mech.t_start, self.steps_start = float(saved["t"]), int(saved["steps"])
        mech.rebuilds = int(saved.get("neighbour_rebuilds", 0))
        if self.thermal is not None:
            self.thermal.assemblies = int(saved.get("network_assemblies", 0))
            self.thermal.refreshes = int(saved.get("network_refreshes", 0))

    def _resume(self, saved: dict) -> None:
        """The clock, the walls' motion and the heat balance of a checkpoint (the particles came in above)."""
        mech = self.mechanics
        mech.steps, mech.t_start = int(saved["run_steps"]), float(saved["t_start"])
        self.steps_start = int(saved["steps_start"])
        mech.rebuilds = int(saved["neighbour_rebuilds"])
        names = list(saved["wall_names"])
        for k, wall in enumerate(mech.walls):
            m = names.index(wall.name)
            mech.w.q[k], mech.w.dq[k], mech.w.acc[k] = saved["wall_q"][m], saved["wall_dq"][m], saved["wall_acc"][m]
        mech.restore_lists(saved)
        if self.thermal is not None:
            th = self.thermal
            th.T = np.array(saved["thermal_T"], dtype=float)
            th.rate = np.array(saved["thermal_rate"], dtype=float)
            th.energy0 = float(saved["thermal_energy0"])
            th.heat_in = {str(k): float(v) for k, v in zip(saved["heat_keys"], saved["heat_values"])}
            th.assemblies, th.refreshes = int(saved["network_assemblies"]), int(saved["network_refreshes"])
            th.startup_steps = int(saved.get("thermal_startup_steps", 0))  # 0: a checkpoint from before the count
            th.handover.restore(saved)

    @property
    def temperature_source(self) -> str:
        """The source of the particles' temperatures (``schedule``, ``network`` or ``initial``)."""
        if self.schedule is not None:
            return "schedule"
        return "network" if self.thermal is not None else "initial"

    # ------------------------------------------------------------------------------------------------ loop
    def _interval_temperatures(self, t: float, t_end: float):
        """``(T0, rate, relaxation_time)`` over the interval ``[t, t_end]`` (length-1 arrays: uniform). The
        schedule's segment is the one holding the interval's middle: an interval ends at every knot, but its start
        ``k dt`` may fall a little before the knot it begins at (the knot rounded to the step grid)."""
        mech = self.mechanics
        if self.schedule is not None:
            middle = 0.5 * (t + t_end)
            return (np.array([self.schedule.at(t)]), np.array([self.schedule.rate(middle)]),
                    self.schedule.relaxation(middle))
        if self.thermal is not None:  # the network's temperatures, extrapolated with its last rate (cooling is
            th = self.thermal            # then seen as cooling: k1(T, t) freezes, Sec. 3.4)
            T, rate = th.local(mech, th.T), th.local(mech, th.rate)
        else:
            T, rate = mech.state.T, np.zeros(len(mech.state.T))
        if np.all(T == T[0]) and np.all(rate == rate[0]):
            return np.array([T[0]]), np.array([rate[0]]), mech.relaxation_time
        return T.copy(), rate.copy(), mech.relaxation_time

    def _params_at(self, t: float) -> np.ndarray:
        """The material at time ``t``: the scene's, with the overrides of every ``[[phases]]`` entry started."""
        values = {}
        for start, overrides in self.scene.motion.phases:
            if start <= t * (1 + 1e-12) + 1e-300:
                values.update(overrides)
        return replace(self.material, **values).params()

    def _interval_ends(self, n_end: int) -> list[int]:
        """Step indices (of this run) at which an interval ends: output times, thermal updates, schedule knots, phase
        starts, the end."""
        m, dt, t0 = self.scene.motion, self.mechanics.dt, self.mechanics.t_start
        ends = {n_end}
        every = max(1, round(m.output_interval / dt))
        ends.update(range(every, n_end, every))
        if self.thermal is not None:
            every = max(1, round(m.verlet.thermal_interval / dt))
            ends.update(range(every, n_end, every))
        if self.schedule is not None:
            ends.update(k for k in (round((t - t0) / dt) for t in self.schedule.time) if 0 < k < n_end)
        ends.update(k for k in (round((start - t0) / dt) for start, _ in m.phases + m.wall_phases) if 0 < k < n_end)
        return sorted(ends)

    def _wall_speeds_at(self, t: float) -> None:
        """Strain walls at the speeds of every ``[[phases]]`` ``wall_velocity`` entry started by time ``t``."""
        mech = self.mechanics
        names = [w.name for w in mech.walls]
        for start, speeds in self.scene.motion.wall_phases:
            if start <= t * (1 + 1e-12) + 1e-300:
                for name, velocity in speeds.items():
                    mech.w.dq[names.index(name)] = velocity

    def run(self, observe=None, progress=None, checkpoint=None) -> None:
        """Advance to ``[solver] t_end``; ``observe()`` after each interval that ends on an output time (and at the
        start), ``progress(t)`` after every interval, ``checkpoint(make, final)`` after every interval and at the end
        (:class:`dem.output.folder.Checkpointer`).

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
            The mechanics stopped (a non-finite state, a particle leaving the box).
        """
        m, mech = self.scene.motion, self.mechanics
        n_end = max(1, math.ceil((self.scene.solver.t_end - mech.t_start) / mech.dt - 1e-9))
        out_every = max(1, round(m.output_interval / mech.dt))
        if observe is not None and mech.steps == 0:
            observe()
        for end in self._interval_ends(n_end):
            steps = end - mech.steps
            if steps <= 0:
                continue
            T0, rate, t0 = self._interval_temperatures(mech.t, mech.t_start + end * mech.dt)
            mech.params = self._params_at(mech.t)
            self._wall_speeds_at(mech.t)
            mech.advance(steps, T0, rate, t0)
            if self.thermal is not None:
                self.thermal.step(mech, steps * mech.dt)
                mech.state.T[:] = self.thermal.local(mech, self.thermal.T)  # the next interval starts from these
            if observe is not None and (end % out_every == 0 or end == n_end):
                observe()
            if progress is not None:
                progress(mech.t)
            if checkpoint is not None:
                checkpoint(self.checkpoint, final=end == n_end)

    # -------------------------------------------------------------------------------------------- outputs
    def box_volume(self) -> float | None:
        """Volume of the box the walls (or the periodic lengths) enclose (2D: area times height), m^3; None when
        the walls do not close an axis-aligned box."""
        mech = self.mechanics
        s, w = mech.state, mech.w
        axes = (0, 2) if s.dimension == 2 else (0, 1, 2)
        volume = s.height if s.dimension == 2 else 1.0
        box = box_axes(mech.walls)
        for a in axes:
            if mech.box[a] > 0:
                volume *= mech.box[a]
                continue
            if a not in box:
                return None
            volume *= w.extent(*box[a])
        return volume

    def volume_fraction(self) -> float | None:
        r"""Solid volume over box volume (Luding 2005's density :math:`\nu`)."""
        volume = self.box_volume()
        return None if volume is None else self.mechanics.state.solid_volume() / volume

    def wall_stress(self) -> dict:
        """Normal load the particles exert on each wall, in one unit for every wall (:meth:`wall_load_unit`): the
        force per unit length (2D, N/m, the paper's pressure unit) or per unit area (3D, Pa) when every wall spans the
        same number of box axes, else the bare force (N) on every wall."""
        mech = self.mechanics
        extents, _ = self._wall_extents()
        return {wall.name: float(mech.w.force[k] / extents[k]) for k, wall in enumerate(mech.walls)}

    def wall_load_unit(self) -> str:
        """The unit of :meth:`wall_stress`: "Pa", "N/m" or "N"."""
        return ("N", "N/m", "Pa")[self._wall_extents()[1]]

    def _wall_extents(self) -> tuple[list, int]:
        """Per wall the length (one box axis along it) or area (two) its load is divided by -- between the walls
        facing each other along an axis, or the periodic box's period --, and that number of axes; all 1 and 0 axes when the walls span different numbers of axes (N/m beside Pa would share no axis)."""
        mech = self.mechanics
        extents, spanned = [], set()
        for k, wall in enumerate(mech.walls):
            extent, axes = mech.w.periodic_extent(wall, mech.state.dimension, mech.box)  # the box's periods
            lo_hi = mech.w.span[k]
            for a in range(2):
                if lo_hi[2 * a] >= 0:
                    extent *= mech.w.extent(lo_hi[2 * a], lo_hi[2 * a + 1])
                    axes += 1
            extents.append(extent)
            spanned.add(axes)
        if len(spanned) > 1:
            return [1.0] * len(extents), 0
        return extents, spanned.pop() if spanned else 0

    def heated_walls(self):
        """``(hot, cold)`` wall indices when exactly two walls carry different temperatures and face each other
        (the specimen of an effective conductivity), else None."""
        mech = self.mechanics
        walls = [k for k, w in enumerate(mech.walls) if w.temperature is not None]
        if len(walls) != 2:
            return None
        a, b = (mech.walls[k] for k in walls)
        if a.temperature == b.temperature or not np.allclose(a.normal, -b.normal, atol=1e-12):
            return None
        return tuple(walls) if a.temperature > b.temperature else tuple(reversed(walls))

    def effective_conductivity(self, pair_necks: bool = False) -> float | None:
        """``k_eff = Q L / (A (T_hot - T_cold))`` of the contact network as it is now, from a steady solve between
        the hot and the cold wall (W/(m K)); None without two such walls, a closed box or a network (or with
        ambient sources, which are not conduction). Groups of particles touching neither wall carry no heat. With a
        node per neck (``[conductance] nodes = "necks"``) the solve is the neck-node network's
        (:func:`dem.network.necks.steady_necks`) of the contacts of the last thermal step (with ``pair_necks``, of the
        contacts now read as pair necks).

        Parameters
        ----------
        pair_necks : bool
            Whether to read every contact as a pair neck (the scene's reading, clipped to its range), as if no
            particle had been handed over to the union (:mod:`dem.engines.handover`), on the nodes of the scene's
            ``conductance.nodes``; False: the network as the run conducts.

        Returns
        -------
        float or None
            k_eff (W/(m K)), or None.
        """
        th, pair = self.thermal, self.heated_walls()
        volume = self.box_volume()
        if (th is None or (th.net is None and th.necks is None) or pair is None or volume is None
                or self.scene.sources.names):
            return None
        mech = self.mechanics
        hot, cold = pair
        length = -(mech.w.q[hot] + mech.w.q[cold])
        delta_T = mech.walls[hot].temperature - mech.walls[cold].temperature
        if th.necks is not None and th.spec.nodes == "necks":  # a node per neck: the last step's network solved
            net = th.neck_heat(mech, pair_necks=True).net if pair_necks else th.necks.net
            res = steady_necks(net, floating="mean", linear=self.scene.solver.linear)
            into = np.bincount(net.bonds.wall_index, res.wall_flow, len(th.thermal_walls))
            return float(-into[th.thermal_walls.index(hot)] * length / (volume / length * delta_T))
        net = th.net
        if pair_necks:
            i, j = mech.contacts()[:2]
            bonds, K_pairs, K_walls = bonds_and_conductances(
                th._particles_now(mech, mech.state.radius), th._walls_now(mech),
                replace(th.spec, out_of_range="clip"), pairs=(i, j), box=th.box)
            wall_T = np.array([th.walls[k].temperature for k in th.thermal_walls], dtype=float)
            net = Network(th._particles_now(mech, th.particles.radius), bonds, K_pairs, K_walls, wall_T, th.sources,
                          th.box)
        res = steady(net, floating="mean", linear=self.scene.solver.linear)
        into = boundary_heat_flow(net, res.T)["walls"]
        q = -into[th.thermal_walls.index(hot)]  # heat leaving the hot wall
        return float(q * length / (volume / length * delta_T))

    def profile(self, bins: int = 8) -> dict | None:
        """Solid fraction and mean neck radius (Rojek's volume-conserving neck of each contact's overlap, a/r of
        the smaller particle) in slabs parallel to the hot wall, against the distance from it; None without a hot
        wall and a closed box.

        Parameters
        ----------
        bins : int
            Number of slabs.

        Returns
        -------
        dict or None
            ``distance`` (m, the slabs' middles from the hot wall), ``solid_fraction`` and ``neck_over_radius`` (mean
            a/r, None for a slab without contacts); None without a hot wall and a closed box.
        """
        pair = self.heated_walls()
        volume = self.box_volume()
        if pair is None or volume is None:
            return None
        mech = self.mechanics
        s = mech.state
        hot, cold = pair
        normal = mech.walls[hot].normal
        length = -(mech.w.q[hot] + mech.w.q[cold])
        area = volume / length
        edges = np.linspace(0.0, length, bins + 1)
        dist = s.x @ normal - mech.w.q[hot]
        v = 4.0 / 3.0 * np.pi * s.radius**3
        slab = np.clip(np.searchsorted(edges, dist) - 1, 0, bins - 1)
        density = np.bincount(slab, v, bins) / (area * np.diff(edges))
        i, j, overlap = mech.contacts()[:3]
        neck = self._necks(s.radius[i], s.radius[j], overlap) / np.minimum(s.radius[i], s.radius[j])
        mid = np.clip(np.searchsorted(edges, 0.5 * (dist[i] + dist[j])) - 1, 0, bins - 1)
        count = np.bincount(mid, minlength=bins)
        with np.errstate(invalid="ignore"):
            neck_mean = np.bincount(mid, neck, bins) / count
        return {"distance": (0.5 * (edges[1:] + edges[:-1])).tolist(), "solid_fraction": density.tolist(),
                "neck_over_radius": [None if c == 0 else float(x) for c, x in zip(count, neck_mean)]}

    def record(self) -> dict:
        """The scalar observables of the current state (one row of ``timeseries.csv``)."""
        mech = self.mechanics
        s = mech.state
        i = mech.contacts()[0]
        row = {"t": mech.t, "step": self.steps, "kinetic_energy": s.kinetic_energy(),
               "volume_fraction": self.volume_fraction(), "coordination": 2.0 * len(i) / s.n,
               **{name: float(np.mean(mech.particle_column(name))) for name in mech.law.PARTICLE_STATE},
               "T_mean": float(np.mean(s.T)),
               "T_min": float(np.min(s.T)), "T_max": float(np.max(s.T))}
        if self.thermal is not None and self.heated_walls() is not None:
            row["effective_conductivity"] = self.effective_conductivity()
            if self.thermal.handing_over(mech):  # beside it, the contacts all read as pair necks
                row["effective_conductivity_pair_necks"] = self.effective_conductivity(pair_necks=True)
        for name, value in self.wall_stress().items():
            row[f"wall_{name}"] = value
        for k, wall in enumerate(mech.walls):
            row[f"q_{wall.name}"] = float(mech.w.q[k])
        return row

    def summary(self) -> dict:
        """What the run found (JSON-ready): the last row, the steps, contacts, momentum and thermal totals."""
        mech = self.mechanics
        s = mech.state
        out = {"mode": "transient", "static": False,
               **{k: v for k, v in self.record().items() if k not in ("step",)}}
        profile = self.profile()
        if profile is not None:
            out["profile"] = profile
        out.update(steps=self.steps, dt=mech.dt, particles=s.n, contacts=len(mech.contacts()[0]),
                   wall_contacts=len(mech.wall_contacts()[0]), dimension=s.dimension,
                   momentum=s.momentum().tolist(), neighbour_rebuilds=mech.rebuilds, skin=mech.skin,
                   temperature_source=self.temperature_source)
        if self.thermal is not None:
            th = self.thermal
            out.update(energy_error=th.energy_error(), heat_in={k: float(v) for k, v in th.heat_in.items()},
                       network_assemblies=th.assemblies, network_refreshes=th.refreshes, law=self.scene.conductance.law)
            if th.startup_steps:  # stiff Crank-Nicolson thermal steps taken as implicit Euler
                out["startup_steps"] = th.startup_steps
            meeting, bonds = self.necks()
            law, nodes = self.scene.conductance.law, self.scene.conductance.nodes
            if th.necks is not None:
                out.update(nodes="necks", neck_nodes=len(th.necks.net.live),
                           particles_without_interactions=th.necks.net.plain)
            readings = handed_over = None
            if th.handing_over(mech):
                account = th.handover.account(bonds)
                readings, handed_over = account["readings"], account["handed_over"]
                out["particles_handing_over"] = account["handing_over"]
            out.update(neck_account(np.count_nonzero(meeting), s.n, bonds.contact, bonds.n_pairs + bonds.n_walls, law,
                                    np.count_nonzero(wide_necks(s.radius, bonds, meeting, law, nodes)), readings,
                                    handed_over, nodes=nodes))
        return out

    def necks(self):
        """``(meeting, bonds)``: the thermal bonds of the contacts now, under the scene's neck reading, and whether
        two necks of each particle meet (:mod:`dem.geometry.necks`); from the whole sample (on several ranks, the
        one gathered on rank 0)."""
        mech, th = self.mechanics, self.thermal
        s = mech.state
        particles = replace(self.scene.particles, position=s.x, radius=s.radius)
        walls = [mech.walls[k].at(mech.w.q[k]) for k in th.thermal_walls]
        i, j = mech.contacts()[:2]
        bonds = find_bonds(particles, walls, self.scene.conductance.contact, "clip", pairs=(i, j), box=th.box)
        return meeting_in(particles, walls, bonds, th.box), bonds

    def particle_fields(self) -> dict:
        r"""Per-particle fields for snapshots: velocity, angular velocity, force, temperature, stiffness factor, with
        thermal physics the heat flow (W) into the particle through its contacts and walls, and the particle stress
        :math:`\sigma_i = \frac{1}{V_i} \sum_c \mathbf{l}_c \otimes \mathbf{f}_c` (:math:`\mathbf{l}_c` from the
        centre to contact :math:`c`, :math:`\mathbf{f}_c` the force on :math:`i` there) with its mean
        :math:`\mathrm{tr}(\sigma_i)/\mathrm{dim}` (positive in compression)."""
        mech = self.mechanics
        s = mech.state
        i, j, overlap, fn, ft = mech.contacts()
        d = s.x[i] - s.x[j]
        if mech.periodic_box is not None:
            d = mech.periodic_box.minimum_image(d)
        n = d / np.linalg.norm(d, axis=1)[:, None]
        f_i = fn[:, None] * n + ft
        sigma = np.zeros((s.n, 3, 3))
        np.add.at(sigma, i, -s.radius[i, None, None] * n[:, :, None] * f_i[:, None, :])
        np.add.at(sigma, j, -s.radius[j, None, None] * n[:, :, None] * f_i[:, None, :])  # l_j = a_j n, f_j = -f_i
        k, m, _, wfn = mech.wall_contacts()
        wn = mech.w.normal[m]
        np.add.at(sigma, k, -s.radius[k, None, None] * wn[:, :, None] * (wfn[:, None] * wn)[:, None, :])
        volume = (4.0 / 3.0 * np.pi * s.radius**3) if s.dimension == 3 else np.pi * s.radius**2 * s.height
        sigma /= volume[:, None, None]
        # sign: compression positive (the lever arm points against the compressive force)
        sigma = -sigma
        mean = np.trace(sigma, axis1=1, axis2=2) / s.dimension
        fields = {"id": self.scene.particles.id, "radius": s.radius, "velocity": s.v, "angular_velocity": s.w,
                  "force": s.f, "temperature": s.T,
                  **{name: mech.particle_column(name) for name in mech.law.PARTICLE_STATE},
                  "stress": sigma.reshape(-1, 9), "mean_stress": mean}
        if self.thermal is not None:
            fields["heat_flow"] = self.thermal.contact_heat(mech, i, j)[1]
            fields["necks_meeting"] = self.necks()[0].astype(np.int8)
            if self.thermal.handing_over(mech):
                fields["solid_radius"] = self.thermal.handover.solid_radii(s.radius)
                fields["handed_over"] = self.thermal.handover.weight
        return fields

    def positions(self) -> np.ndarray:
        """Particle centres (n, 3), m."""
        return self.mechanics.state.x

    def temperatures(self) -> np.ndarray:
        """Particle temperatures (n,), a copy, in the scene's temperature unit."""
        return self.mechanics.state.T.copy()

    def links(self):
        """The closed pair contacts as lines between the particles (to the partner's image across a periodic face):
        normal force (> 0 repulsive), tangential force magnitude, overlap, neck radius (m); with thermal physics
        each contact's conductance (W/K) and heat flow (W, from the first particle to the second), its neck that of
        its bond (:meth:`dem.engines.contact_heat.ContactThermalModel.contact_heat`), else the volume-conserving
        neck of its overlap (Rojek 2022, eqs. 27-33)."""
        i, j, overlap, fn, ft = self.mechanics.contacts()
        points, lines = pair_lines(self.mechanics.state.x, i, j, self.mechanics.periodic_box)
        fields = {"normal_force": fn, "tangential_force": np.linalg.norm(ft, axis=1), "overlap": overlap}
        if self.thermal is not None:
            fields.update(self.thermal.contact_heat(self.mechanics, i, j)[0])
        else:
            r = self.mechanics.state.radius
            fields["neck_radius"] = self._necks(r[i], r[j], overlap)
        return points, lines, fields

    @staticmethod
    def _necks(ri: np.ndarray, rj: np.ndarray, overlap: np.ndarray) -> np.ndarray:
        """The volume-conserving neck radius (m) of each contact, its overlap within the neck model's range (the
        neck reaches the smaller radius)."""
        if not len(ri):
            return np.zeros(0)
        return np.asarray(neck_radius(ri, rj, np.minimum(overlap, 0.999 * max_overlap(ri, rj))), dtype=float)

    def plots(self, out, summary: dict) -> list[str]:
        """Write the run folder's plots (:func:`dem.output.plots.motion_plots`).

        Parameters
        ----------
        out : str or pathlib.Path
            The run folder.
        summary : dict
            The run's summary (not read).

        Returns
        -------
        list of str
            The names of the files written.
        """
        from dem.output.plots import motion_plots

        return motion_plots(out, self.scene.temperature_unit, self.wall_load_unit())

    @property
    def dt(self) -> float:
        """The time step, s."""
        return self.mechanics.dt

    def state(self) -> dict:
        """The sample as it is (:mod:`dem.scene.state_file`): another run starts from it."""
        return moving_arrays(self)

    def checkpoint(self) -> dict:
        """Everything the run carries, to go on bit for bit: the state, the run's own clock and the thermal
        network's heat balance."""
        data = self.state()
        mech = self.mechanics
        data.update(run_steps=np.array(mech.steps), t_start=np.array(mech.t_start),
                    steps_start=np.array(self.steps_start), **list_arrays(mech))
        if self.thermal is not None:
            th = self.thermal
            data.update(thermal_T=th.T, thermal_rate=th.rate, thermal_energy0=np.array(th.energy0),
                        heat_keys=np.array(list(th.heat_in), dtype=str),
                        heat_values=np.array(list(th.heat_in.values()), dtype=float),
                        thermal_startup_steps=np.array(th.startup_steps), **th.handover.state())
        return data
