r"""Electrically aided sintering (Zohdi 2014) on the engine: the staggered, adaptive multiphysics step of
Algorithm 1 (eqs. 45-49) over the mechanical, thermal and electrical submodels.

Each step from :math:`t` to :math:`t + \Delta t` iterates, :math:`K = 1, 2, \ldots`:

1. positions :math:`r^K` with the temperatures frozen at :math:`\theta^{K-1}`
   (:class:`dem.engines.staggered.mechanics.StaggeredMechanics`, eqs. 22-27, 45);
2. temperatures :math:`\theta^K` with the positions frozen at :math:`r^K`
   (:class:`dem.engines.staggered.heat.LumpedHeat`, eqs. 36-37, 46), with the Joule heating of the current refreshed
   at the last accepted step;
3. the normalised changes :math:`D_r = \sum |r^K - r^{K-1}| / \sum |r^K - r^L|` and :math:`D_\theta` alike
   (Algorithm 1, step 4a; eq. 47), the violation ratio :math:`Z_K = \max(D_r, D_\theta) / \mathrm{TOL}` (eq. 48) and
   the step factor :math:`\Phi_K = \min(\Phi_r, \Phi_\theta)`,
   :math:`\Phi = (\mathrm{TOL}/D_0)^{1/(p K_d)} / (D_K/D_0)^{1/(p K)}` (eqs. 30, 49; :math:`D_0 = 1`, the first
   iterate's relative change).

:math:`Z_K \le 1`: the step is accepted, the current refreshed at the new configuration (step 6d), and the next step
is :math:`\min(\Phi_K \Delta t, \Delta t_\mathrm{lim})` (steps 6a-c). :math:`Z_K > 1` after :math:`K_d` iterations:
the step restarts from :math:`t` with :math:`\Phi_K \Delta t` (step 7). Beyond the paper: an accepted step grows by
at most ``growth``, a restart shrinks it by at least ``shrink`` (:class:`dem.scene.staggered.ZohdiStepping`), a
displacement below 1e-12 of the mean radius (a temperature change below 1e-12 of the temperatures) counts as none, and
a step below ``dt_min`` that still cannot converge stops the run. Steps end exactly on the start of every
``[[phases]]`` entry (a wall changing speed) and on ``t_end``.

The simulation offers what the outputs ask of an engine (:class:`dem.output.writer.RunWriter`): ``record()``,
``particle_fields()``, ``contact_fields()``, ``profile()``, ``summary()`` and ``mechanics.state``.
"""

from __future__ import annotations

import math

import numpy as np

from dem.engines.state import MotionState
from dem.geometry.neighbours import list_arrays
from dem.geometry.periodic import pair_lines
from dem.geometry.walls import box_axes
from dem.engines import Engine
from dem.engines.contact_current import ContactCurrent
from dem.engines.handover import Handover
from dem.engines.staggered.heat import LumpedHeat, contact_bonds
from dem.geometry.necks import meeting_in
from dem.laws.verified_range import neck_account, wide_necks
from dem.engines.staggered.mechanics import StaggeredMechanics
from dem.scene.state_file import moving_arrays, normalised

NO_MOTION = 1e-12  # displacements below this x the mean radius (temperature changes below this x |theta|) are none


class ConvergenceError(ValueError):
    """A step that cannot converge even at ``dt_min``."""


class StaggeredEngine(Engine):
    """A scene with ``[contact] law = "zohdi"`` (module docstring), as the driver asks of an engine
    (:mod:`dem.engines`)."""

    name = "staggered"
    link_kind = "contacts"

    def __init__(self, scene, restart: dict | None = None):
        """``restart``: a checkpoint of this scene's run (:meth:`checkpoint`): the run goes on from its step, bit for
        bit. A scene that starts from a saved state goes on from its positions, velocities, temperatures, time and
        counters.

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene, with ``[contact] law = "zohdi"``.
        restart : dict or None
            A checkpoint of this scene's run to go on from; None: start at the scene's start.
        """
        self.scene = scene
        m, p = scene.motion, scene.particles
        self.stepping = m.staggered.stepping
        material = scene.contact
        saved = normalised(dict(restart)) if restart is not None else m.start
        state = MotionState.create(3, p.position, p.radius, material.density, p.temperature, m.velocity)
        if saved is not None and saved["moving"]:
            state.x[:], state.v[:], state.T[:] = saved["x"], saved["v"], saved["T"]
        self.mechanics = StaggeredMechanics(state, m.walls, material, m.gravity, m.skin,
                                            history=saved if saved is not None and saved["moving"] else None,
                                            box=scene.box)
        self.thermal = LumpedHeat(p, m.walls, scene.conductance) if "thermal" in scene.physics else None
        if self.thermal is not None and restart is not None:
            self.thermal.T, self.thermal.T0 = saved["T"].copy(), saved["thermal_T0"].copy()
            self.thermal.heat_in = {str(k): float(v) for k, v in zip(saved["heat_keys"], saved["heat_values"])}
            self.thermal.handover.restore(saved)
        self.current = None
        if "electrical" in scene.physics:
            e = scene.electrical
            self.current = ContactCurrent(p, m.walls, e.electrodes, scene.conductance, e.scheme, e.absorption,
                                          e.tolerance, e.sweeps, scene.solver.linear, e.floating)
        self.t = self.t_start = scene.start_time
        self.steps, self.restarts, self.iterations = 0 if saved is None else saved["steps"], 0, 0
        self.steps_start = self.steps
        self.last_iterations, self.max_iterations = 0, 0
        self.dt = self.stepping.dt
        self.dt_taken: list[float] = []
        self._phase = 0
        if saved is not None:
            self.mechanics.rebuilds = saved.get("neighbour_rebuilds", 0)
        if restart is not None:
            self._resume(saved)
        self._apply_phases()
        axis = m.staggered.control
        if axis is not None:  # the walls facing +axis (bottom) and -axis (top) of the bed's fractions
            normals = self.mechanics.w.normal[:, axis]
            self._bottom = int(np.flatnonzero(np.abs(normals - 1.0) < 1e-12)[0])
            self._top = int(np.flatnonzero(np.abs(normals + 1.0) < 1e-12)[0])
            self._lowest = -self.mechanics.w.q[self._top] if restart is None else float(saved["lowest"])
        if self.thermal is not None:
            self.thermal.start(self.mechanics)
        if self.current is not None:
            if restart is not None:
                self.current.J = saved["current_J"].copy()  # the warm start of Zohdi's iteration
            self.current.refresh(self.mechanics, self.t)
            if restart is not None:
                self._resume_current(saved)
        self._floor_r = NO_MOTION * float(np.mean(state.radius)) * state.n

    def _resume(self, saved: dict) -> None:
        """The scheme's clock and counters of a checkpoint (the particles and walls came in above)."""
        self.t, self.t_start, self.steps = float(saved["t"]), float(saved["t_start"]), int(saved["steps"])
        self.steps_start = int(saved["steps_start"])
        self.restarts, self.iterations = int(saved["restarts"]), int(saved["iterations"])
        self.last_iterations, self.max_iterations = int(saved["last_iterations"]), int(saved["max_iterations"])
        self.dt = float(saved["next_dt"])
        self.dt_taken = [float(x) for x in saved["dt_taken"]]
        self._phase = int(saved["phase"])
        self.mechanics.resume_lists(saved)

    def _resume_current(self, saved: dict) -> None:
        """The current's energies and counters of a checkpoint (its refresh at the restored state counted once)."""
        c = self.current
        for key in ("refreshes", "total_sweeps", "open_refreshes"):
            setattr(c, key, int(saved[f"current_{key}"]))
        for key in ("joule_energy", "electrode_energy", "peak_power"):
            setattr(c, key, float(saved[f"current_{key}"]))
    # ------------------------------------------------------------------------------------------------ loop
    def _apply_phases(self) -> None:
        """Wall speeds of every ``[[phases]]`` entry that has started."""
        phases = self.scene.motion.wall_phases
        while self._phase < len(phases) and phases[self._phase][0] <= self.t * (1 + 1e-12) + 1e-300:
            for name, velocity in phases[self._phase][1].items():
                self.mechanics.set_wall_velocity(name, velocity)
            self._phase += 1

    def _next_event(self) -> float:
        phases = self.scene.motion.wall_phases
        t_end = self.scene.solver.t_end
        return min(t_end, phases[self._phase][0]) if self._phase < len(phases) else t_end

    def _attempt(self, dt: float):
        """Iterate one step of ``dt`` (module docstring): ``(converged, K, Phi, theta)``."""
        mech, th, st = self.mechanics, self.thermal, self.stepping
        mech.begin(self.t, dt)
        T_L = mech.state.T if th is None else th.T
        T_prev = T_L.copy()
        H = self.current.heating if self.current is not None else np.zeros(mech.state.n)
        floor_T = NO_MOTION * max(float(np.max(np.abs(T_L), initial=0.0)), 1e-300) * len(T_L)
        phi_K = 1.0
        for K in range(1, st.iterations + 1):
            change, motion = mech.iterate(dt, st.phi, T_prev)
            d_r = change / max(motion, self._floor_r)
            factor = st.factor(d_r, K)
            z = d_r / st.tolerance
            T_new = T_prev
            if th is not None:
                T_new = th.iterate(dt, st.phi, mech, T_prev, H)
                d_T = float(np.abs(T_new - T_prev).sum()) / max(float(np.abs(T_new - T_L).sum()), floor_T)
                z = max(z, d_T / st.tolerance)
                factor = min(factor, st.factor(d_T, K))
            T_prev, phi_K = T_new, factor
            if z <= 1.0:
                return True, K, phi_K, T_new
        return False, st.iterations, phi_K, T_prev

    def step(self) -> None:
        """One accepted step (restarting with smaller steps as Algorithm 1 says)."""
        st, mech = self.stepping, self.mechanics
        while True:
            event = self._next_event()
            dt = min(self.dt, st.dt_max, event - self.t)
            last = dt >= event - self.t
            ok, K, factor, T = self._attempt(dt)
            self.iterations += K
            if ok:
                break
            self.restarts += 1
            mech.restart()
            self.dt = dt * st.restart_factor(factor)
            if self.dt < st.dt_min:
                raise ConvergenceError(f"the run stopped at t = {self.t:.6g} s: a step of {dt:.3g} s did not converge "
                                       f"in {st.iterations} iterations and the next, {self.dt:.3g} s, would be below "
                                       f"solver.dt_min = {st.dt_min:g} s; raise solver.tolerance or iterations, or "
                                       f"soften the contacts")
        mech.accept(T)
        if self.thermal is not None:
            self.thermal.accept(dt, st.phi, T, mech, self.current.heating if self.current is not None
                                else np.zeros(mech.state.n))
            mech.state.T[:] = self.thermal.T
        self.t = event if last else self.t + dt
        self.steps += 1
        self.last_iterations = K
        self.max_iterations = max(self.max_iterations, K)
        self.dt_taken.append(dt)
        # a step cut short to land on an event does not hold the next one back
        self.dt = min(st.dt_max, max(factor * dt, self.dt) if last else factor * dt)
        self._apply_phases()
        if self.scene.motion.staggered.control is not None:
            self._lowest = min(self._lowest, -mech.w.q[self._top])
        if self.current is not None:
            self.current.book(dt)
            self.current.refresh(mech, self.t)

    def run(self, observe=None, progress=None, checkpoint=None) -> None:
        """Advance to ``[solver] t_end``; ``observe()`` at the start, whenever an output time is passed, and at the
        end; ``progress(t)`` and ``checkpoint(make, final)`` after every step.

        Parameters
        ----------
        observe : callable or None
            Called without arguments at the output times; None: not called.
        progress : callable or None
            Called with the simulated time (s) after every step; None: not called.
        checkpoint : callable or None
            Called as ``checkpoint(make, final)`` after every step; None: not called.

        Raises
        ------
        ConvergenceError
            A step cannot converge even at ``dt_min`` (a ValueError, as is a particle leaving the box).
        """
        t_end = self.scene.solver.t_end
        every = self.scene.motion.output_interval
        next_out = self.t_start + every
        while next_out <= self.t * (1 + 1e-12):  # a resumed run: the output times as the run advanced them
            next_out += every
        if observe is not None and self.t == self.t_start:
            observe()
        while self.t < t_end * (1 - 1e-12):
            self.step()
            if observe is not None and (self.t >= next_out * (1 - 1e-12) or self.t >= t_end * (1 - 1e-12)):
                observe()
                while next_out <= self.t * (1 + 1e-12):
                    next_out += every
            if progress is not None:
                progress(self.t)
            if checkpoint is not None:
                checkpoint(self.checkpoint, final=self.t >= t_end * (1 - 1e-12))

    def state(self) -> dict:
        """The sample as it is (:mod:`dem.scene.state_file`): another run starts from it."""
        return moving_arrays(self)

    def checkpoint(self) -> dict:
        """Everything the scheme carries, to go on bit for bit: the state, the clock and counters, the heat balance
        and the current's warm start and energies."""
        data = self.state()
        data.update(t_start=np.array(self.t_start), steps_start=np.array(self.steps_start),
                    restarts=np.array(self.restarts),
                    iterations=np.array(self.iterations), last_iterations=np.array(self.last_iterations),
                    max_iterations=np.array(self.max_iterations), next_dt=np.array(self.dt),
                    dt_taken=np.array(self.dt_taken, dtype=float), phase=np.array(self._phase),
                    lowest=np.array(getattr(self, "_lowest", np.nan)), **list_arrays(self.mechanics))
        if self.thermal is not None:
            th = self.thermal
            data.update(thermal_T0=th.T0, heat_keys=np.array(list(th.heat_in), dtype=str),
                        heat_values=np.array(list(th.heat_in.values()), dtype=float), **th.handover.state())
        if self.current is not None:
            c = self.current
            data.update(current_J=c.J, **{f"current_{k}": np.array(getattr(c, k)) for k in (
                "refreshes", "total_sweeps", "open_refreshes", "joule_energy", "electrode_energy", "peak_power")})
        return data

    # -------------------------------------------------------------------------------------------- outputs
    def _cross_section(self, axis):
        """``(area, (lo, hi) per lateral axis)`` of the box the walls (or the periods of a periodic box)
        perpendicular to ``axis`` enclose, or None."""
        mech = self.mechanics
        area, spans = 1.0, []
        box = box_axes(mech.walls)
        periodic = mech.periodic_box
        for a in range(3):
            if a == axis:
                continue
            if mech.box[a] > 0:
                spans.append((a, periodic.origin[a], periodic.origin[a] + periodic.lengths[a]))
                area *= periodic.lengths[a]
                continue
            if a not in box:
                return None
            lo, hi = box[a]
            spans.append((a, mech.w.q[lo], -mech.w.q[hi]))
            area *= mech.w.extent(lo, hi)
        return area, spans

    def bed(self) -> dict:
        """Solid fractions along ``[output] fraction_axis`` (the bed stands on the wall facing +axis and is pressed
        by the one facing -axis):

        * ``volume_fraction`` -- Zohdi 2014, Sec. 7, Remark 1: "calculated based on the volume contained within the
          lowest compression point": the solid inside the box between the bottom wall and the lowest point the top
          wall has reached so far (each sphere's part in it: spherical caps cut by the two planes) over the box's
          volume. While the wall descends towards the bed it is the bed's fraction at that height; under the wall it
          is the compaction; after the release particles that spring back above the lowest point leave the box;
        * ``bed_fraction`` -- the bulk fraction of the bed: solid volume over the volume up to its surface (the mean,
          over columns of width 2 R across the bed, of the highest particle top in each), or to the top wall where
          that is lower.

        Without ``fraction_axis``: ``volume_fraction`` is the solid volume over the volume of the walls' box."""
        s, mech = self.mechanics.state, self.mechanics
        axis = self.scene.motion.staggered.control
        section = self._cross_section(axis)
        if section is None:
            return {"volume_fraction": None}
        area, spans = section
        if axis is None:
            return {"volume_fraction": float(s.solid_volume() / area)}
        floor = mech.w.q[self._bottom]
        ceiling = -mech.w.q[self._top]
        inside = cap_volume(s.x[:, axis], s.radius, self._lowest) - cap_volume(s.x[:, axis], s.radius, floor)
        width = 2.0 * float(np.mean(s.radius))
        x = s.x if mech.periodic_box is None else mech.periodic_box.wrap(s.x)  # columns over the periods
        column = np.zeros(len(s.x), dtype=np.int64)
        for (a, lo, hi) in spans:
            count = max(1, int((hi - lo) / width))
            column = column * count + np.clip(((x[:, a] - lo) / (hi - lo) * count).astype(np.int64), 0, count - 1)
        tops = np.full(column.max() + 1, -np.inf)
        np.maximum.at(tops, column, s.x[:, axis] + s.radius)
        surface = min(float(np.mean(tops[np.isfinite(tops)])), ceiling)
        return {"volume_fraction": float(np.sum(inside) / (area * (self._lowest - floor))),
                "bed_fraction": float(s.solid_volume() / (area * (surface - floor))), "bed_surface": surface,
                "lowest_compression": self._lowest}

    def record(self) -> dict:
        """The scalar observables of the current state (one row of ``timeseries.csv``)."""
        mech = self.mechanics
        s = mech.state
        i, j, fn, area, bond = mech.contacts()
        row = {"t": self.t, "step": self.steps, "dt": self.dt_taken[-1] if self.dt_taken else 0.0,
               "iterations": self.last_iterations, "restarts": self.restarts, "kinetic_energy": s.kinetic_energy(),
               **self.bed(), "coordination": 2.0 * len(i) / s.n,
               "bonds": int(np.sum(bond)), "T_mean": float(np.mean(s.T)), "T_min": float(np.min(s.T)),
               "T_max": float(np.max(s.T))}
        if self.current is not None:
            c = self.current
            row.update(heating=float(c.heating.sum()), joule_heat=c.joule_heat, electrode_power=c.electrode_power)
            row.update(c.electrode_currents())
        for k, wall in enumerate(mech.walls):
            row[f"q_{wall.name}"] = float(mech.w.q[k])
            row[f"wall_{wall.name}"] = float(mech.wforce[k])
        return row

    def profile(self):
        """None: this engine offers no profiles."""
        return None

    def plates(self) -> list:
        """The bottom and top walls of ``[output] fraction_axis`` as ``(centre, normal, sizes)`` for pictures
        (:mod:`dem.output.frames`); none without that axis."""
        axis = self.scene.motion.staggered.control
        section = self._cross_section(axis) if axis is not None else None
        if section is None:
            return []
        _, spans = section
        out = []
        for k in (self._bottom, self._top):
            centre = np.zeros(3)
            for a, lo, hi in spans:
                centre[a] = 0.5 * (lo + hi)
            normal = self.mechanics.w.normal[k]
            centre[axis] = self.mechanics.w.q[k] * normal[axis]
            out.append((centre, normal, tuple(hi - lo for _, lo, hi in spans)))
        return out

    def summary(self) -> dict:
        """What the run found (JSON-ready): the last row, the step counts and sizes, the contacts."""
        mech = self.mechanics
        out = {k: v for k, v in self.record().items() if k not in ("step", "dt", "iterations")}
        dts = np.array(self.dt_taken) if self.dt_taken else np.zeros(1)
        out.update(mode="transient", static=False, contact_law="zohdi", steps=self.steps, restarts=self.restarts,
                   iterations=self.iterations,
                   iterations_per_step=self.iterations / max(self.steps - self.steps_start, 1),
                   iterations_max=self.max_iterations,
                   dt_min=float(dts.min()), dt_max=float(dts.max()), dt_mean=float(dts.mean()),
                   particles=mech.state.n, contacts=len(mech.contacts()[0]), neighbour_rebuilds=mech.rebuilds,
                   skin=mech.skin, phi=self.stepping.phi, tolerance=self.stepping.tolerance,
                   target_iterations=self.stepping.iterations)
        if self.thermal is not None:
            out.update(energy_error=self.thermal.energy_error(),
                       heat_in={k: float(v) for k, v in self.thermal.heat_in.items()}, law=self.scene.conductance.law)
            meeting, bonds = self.necks()
            law = self.scene.conductance.law
            readings = handed_over = None
            if self._handing_over():
                account = self.thermal.handover.account(self._pair_bonds())
                readings, handed_over = account["readings"], account["handed_over"]
                out["particles_handing_over"] = account["handing_over"]
            out.update(neck_account(np.count_nonzero(meeting), mech.state.n, bonds.contact,
                                    bonds.n_pairs + bonds.n_walls, law,
                                    np.count_nonzero(wide_necks(mech.state.radius, bonds, meeting, law)), readings,
                                    handed_over))
        if self.current is not None:
            c = self.current
            out.update(scheme=c.scheme, current_refreshes=c.refreshes, joule_energy=c.joule_energy,
                       peak_joule_heat=c.peak_power)
            if c.scheme == "zohdi":
                out.update(current_sweeps=c.total_sweeps)
            else:
                out.update(electrode_energy=c.electrode_energy, open_circuit_refreshes=c.open_refreshes,
                           floating_particles=int(len(c.flow.floating)) if c.flow is not None else 0)
        return out

    def positions(self) -> np.ndarray:
        """Particle centres (n, 3), m."""
        return self.mechanics.state.x

    def temperatures(self) -> np.ndarray:
        """Particle temperatures (n,), a copy, in the scene's temperature unit."""
        return self.mechanics.state.T.copy()

    def plots(self, out, summary: dict) -> list[str]:
        """Write the run folder's plots (:func:`dem.output.plots.motion_plots`, wall loads as forces).

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

        return motion_plots(out, self.scene.temperature_unit, "N")  # the walls' loads: forces

    def links(self):
        """The touching pairs as lines between the particles: normal force (N, > 0 repulsive), contact area (m^2),
        bonded."""
        i, j, fn, area, bond = self.mechanics.contacts()
        points, lines = pair_lines(self.mechanics.state.x, i, j, self.mechanics.periodic_box)
        return points, lines, {"normal_force": fn, "area": area, "bonded": bond.astype(np.int8)}

    def necks(self):
        """``(meeting, bonds)``: the lens bonds of the touching pairs now (those out of the lens' range left out) and
        whether two necks of each particle meet (:mod:`dem.geometry.necks`)."""
        mech, th = self.mechanics, self.thermal
        s = mech.state
        now, bonds = contact_bonds(self.scene.particles, mech, s.x, s.T, th.thermal_walls, "lens", "drop")
        walls = [mech.walls[k].at(float(mech.w.q[k])) for k in th.thermal_walls]
        return meeting_in(now, walls, bonds, mech.periodic_box), bonds

    def _handing_over(self) -> bool:
        """Whether the thermal submodel hands particles over to the union (:mod:`dem.engines.handover`)."""
        return self.thermal is not None and Handover.applies(self.scene.conductance, self.mechanics.state.dimension)

    def _pair_bonds(self):
        """The bonds of the touching pairs now under the scene's pair-neck reading (clipped to its range)."""
        mech, th = self.mechanics, self.thermal
        return contact_bonds(self.scene.particles, mech, mech.state.x, mech.state.T, th.thermal_walls,
                             self.scene.conductance.contact, "clip")[1]

    def particle_fields(self) -> dict:
        """The snapshot's point data by name: id, radius, velocity, force, temperature, and the current's."""
        s = self.mechanics.state
        out = {"id": self.scene.particles.id, "radius": s.radius, "velocity": s.v, "force": self.mechanics.f,
               "temperature": s.T}
        if self.thermal is not None:
            out["necks_meeting"] = self.necks()[0].astype(np.int8)
            if self._handing_over():
                out["solid_radius"] = self.thermal.handover.solid_radii(s.radius)
                out["handed_over"] = self.thermal.handover.weight
        if self.current is not None:
            out["heating"] = self.current.heating
            out["current" if self.current.scheme == "zohdi" else "potential"] = np.nan_to_num(self.current.J)
        return out



def cap_volume(centre, radius, level):
    """Volume of each sphere below the plane ``x = level`` along its axis (a spherical cap), m^3.

    Parameters
    ----------
    centre : array_like
        The spheres' centres' coordinates along the axis (m).
    radius : array_like
        Their radii (m).
    level : float
        The plane's coordinate along the axis (m).

    Returns
    -------
    numpy.ndarray
        The volumes below the plane (m^3).
    """
    h = np.clip(level - (np.asarray(centre) - radius), 0.0, 2.0 * radius)
    return math.pi * h * h * (3.0 * radius - h) / 3.0
