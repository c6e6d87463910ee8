"""The mechanical submodel of Zohdi 2014: particles that move under the forces of eqs. (2)-(21), stepped by the
trapezoidal rule (eqs. 22-24) whose implicit equations are solved by fixed-point iteration (eqs. 25-27).

A step from ``t`` to ``t + dt`` is a sequence of iterations (:meth:`StaggeredMechanics.iterate`), each evaluating the
forces at the previous iterate with the temperatures frozen at theirs; the staggered scheme
(:mod:`dem.engines.staggered.engine`) decides when the iterates have converged and then :meth:`~StaggeredMechanics.accept`\\ s
the last one, or :meth:`~StaggeredMechanics.restart`\\ s the step with a smaller ``dt``. Walls move by prescribed
kinematics (fixed, strain at a constant speed, vibrating; :mod:`dem.geometry.walls`), so where they are at the end of the
step is known before it is solved.

Neighbours (Zohdi 2014, Sec. 8): a Verlet list with a skin built by cell binning (:mod:`dem.geometry.neighbours`); an
iterate that takes a particle (plus the farthest-moved wall) more than half the skin from where the list was built
rebuilds it there, carrying each pair's bond flag. In a periodic box (:class:`dem.geometry.periodic.PeriodicBox`)
pairs touch across its faces by the minimum image, and a rebuild moves the particles that left the box back into it
-- at a rebuild within a step both the iterate and the step's start, by the same period, so the step goes on as it
was. A bond (eq. 19) becomes part of the pair's history when a step
that reached ``E*`` is accepted (it acts from the next step on); it is forgotten when the pair separates.
"""

from __future__ import annotations

import math

import numpy as np

from dem.engines import compiled, records
from dem.engines.records import Constants, PairList, Trial, WallList
from dem.engines.state import MotionState
from dem.geometry.neighbours import carry_history, max_displacement, restore_lists, verlet_pairs, wall_pairs
from dem.geometry.periodic import PeriodicBox
from dem.geometry.walls import MOTIONS, WallArrays
from dem.laws.contact import law_module

NO_PAIR_CONSTANTS = np.empty((0, 0))  # the pairs' numbers of the radii are computed at every force evaluation


class StaggeredMechanics:
    """The particles, their Verlet list and the walls, advanced by fixed-point iterations (module docstring)."""

    name = "mechanical"

    def __init__(self, state: MotionState, walls, material, gravity, skin: float, history: dict | None = None,
                 box: PeriodicBox | None = None):
        """``material``: the contact law's material (``material.law`` names the law: one whose particles do not
        rotate); ``history``: a saved state (:mod:`dem.scene.state_file`) whose walls (by name: offset and speed)
        and, for the same contact law, contact histories the model starts from; ``box``: a periodic box (module
        docstring).

        Parameters
        ----------
        state : dem.engines.state.MotionState
            The particles' state (SI units), advanced in place.
        walls : sequence of dem.geometry.walls.Wall
            The walls (fixed, strain or vibrating; no stress walls).
        material : object
            The contact law's material (:mod:`dem.laws.contact`).
        gravity : array_like
            The gravitational acceleration [x, y, z] (m/s^2).
        skin : float
            The Verlet list's skin (m).
        history : dict or None
            A saved state to start the walls and contact histories from; None: none.
        box : dem.geometry.periodic.PeriodicBox or None
            The periodic box; None: none.

        Raises
        ------
        ValueError
            A stress-controlled wall, or an unknown contact law.
        """
        self.state = state
        self.walls = tuple(walls)
        for wall in self.walls:
            if wall.motion == "stress":
                raise ValueError(f"walls.{wall.name}.motion = \"stress\": the Zohdi 2014 scheme moves walls by "
                                 f"prescribed kinematics only (fixed, strain, vibrate)")
        self.law = law_module(material.law)
        self._forces = compiled.loop(material.law, "dem.engines.contact_forces", "forces")
        self._iterate = compiled.loop(material.law, "dem.engines.staggered.kernels", "iterate")
        self.params = np.ascontiguousarray(material.params(), dtype=float)
        self.gravity = np.asarray(gravity, dtype=float)
        self.skin = float(skin)
        self.periodic_box = box
        self.box = box.kernel_lengths if box is not None else np.zeros(3)  # 0: not periodic
        self.w = WallArrays.build(self.walls, 3, self.box)
        n = state.n
        self.f = np.zeros((n, 3))          # forces at the start of the step, F^L
        self._f_iter = np.zeros((n, 3))    # forces of the current iteration, F^(K-1)
        self.x_new, self.v_new = state.x.copy(), state.v.copy()
        self.x_prev, self.v_prev = state.x.copy(), state.v.copy()
        self.q_start = self.w.q.copy()
        self.wforce = self.w.force  # the particles' normal forces on the walls, of the latest evaluation
        self.stats = np.zeros(4)
        self.rebuilds = 0
        # the particles do not rotate: no spin, no torque (the force loop's arrays for them stay zero)
        self._spin, self._torque = np.zeros((n, 3)), np.zeros((n, 3))
        self.particle_state = self.law.initial_state(material, state.T, state.mass)
        self._bodies = records.particles(state, self.particle_state, w=self._spin, tau=self._torque,
                                         spin_axes=(0, 1, 2))  # the positions, velocities, forces, T: per call
        n_w = len(self.walls)
        self.w_hist = np.zeros((n, n_w, len(self.law.WALL_HISTORY)))  # committed at each accepted step
        self._w_hist_iter = self.w_hist.copy()
        self.w_fn, self.w_ft = np.zeros((n, n_w)), np.zeros((n, n_w, 3))
        self.p_hist = np.zeros((0, len(self.law.PAIR_HISTORY)))
        self.pi = self.pj = np.zeros(0, dtype=np.int64)
        if history is not None:
            self._restore_walls(history)
        self._build_list(state.x)
        if history is not None and history["contact_law"] == self.law.NAME:
            (self.p_hist,) = carry_history(history["pi"], history["pj"], self.pi, self.pj, history["p_hist"])
            self.w_hist[:] = history["w_hist"]
        self._evaluate(state.x, state.v, state.T, self.f)

    def _restore_walls(self, saved: dict) -> None:
        """Walls named like walls of the saved state take their offsets and speeds."""
        names = list(saved["wall_names"])
        for k, wall in enumerate(self.walls):
            if wall.name in names:
                m = names.index(wall.name)
                self.w.q[k], self.w.dq[k] = saved["wall_q"][m], saved["wall_dq"][m]
        self.q_start = self.w.q.copy()

    # ------------------------------------------------------------------------------------------------ list
    def _build_list(self, x):
        """The lists at positions ``x`` (the state's, or the latest iterate's: then the state moves with it when
        the box wraps it)."""
        s = self.state
        if self.periodic_box is not None:
            moved = self.periodic_box.wrap_outside(x)
            if x is not s.x:
                s.x += moved
        i, j = verlet_pairs(x, s.radius, self.skin, self.box)
        if len(self.pi):
            (self.p_hist,) = carry_history(self.pi, self.pj, i, j, self.p_hist)
            self.rebuilds += 1
        else:
            self.p_hist = np.zeros((len(i), len(self.law.PAIR_HISTORY)))
        self.pi, self.pj = i, j
        self.p_fn, self.p_ft = np.zeros(len(i)), np.zeros((len(i), 3))
        self._p_hist_iter = np.zeros_like(self.p_hist)  # the histories an iterate would leave
        self.x_ref = x.copy()
        self.wk, self.wm = wall_pairs(x, s.radius, self.w.normal, self.w.q, self.skin)
        self.wq_ref = self.w.q.copy()

    def resume_lists(self, saved: dict) -> None:
        """The Verlet lists of a checkpoint (a resumed run rebuilds them at the uninterrupted run's steps), with the
        forces of the start of the step on them.

        Parameters
        ----------
        saved : dict
            The checkpoint's arrays (:func:`dem.geometry.neighbours.list_arrays`, with ``x`` and ``p_hist``).
        """
        restore_lists(self, saved)
        self._p_hist_iter = np.zeros_like(self.p_hist)
        s = self.state
        self._evaluate(s.x, s.v, s.T, self.f)

    def _wall_reach(self) -> float:
        return float(np.max(np.abs(self.w.q - self.wq_ref), initial=0.0))

    def records(self, x, v, T, f) -> tuple:
        """What the compiled loops take (:mod:`dem.engines.records`) for the particles at ``(x, v, T)`` whose forces
        go into ``f``, made of the model's arrays as they are now: the histories read from those of the step's start
        and written to the iterate's, the pairs' numbers of the radii computed at every force evaluation (no room
        kept for them).

        Parameters
        ----------
        x, v : numpy.ndarray
            (N, 3) positions (m) and velocities (m/s).
        T : numpy.ndarray
            (N,) temperatures (K).
        f : numpy.ndarray
            (N, 3) where the forces go (N).

        Returns
        -------
        tuple
            ``(particles, pairs, walls, wall_list, constants)``: :class:`~dem.engines.records.Particles`,
            :class:`~dem.engines.records.PairList`, :class:`~dem.geometry.walls.WallArrays`,
            :class:`~dem.engines.records.WallList`, :class:`~dem.engines.records.Constants`.
        """
        particles = self._bodies._replace(x=x, v=v, f=f, T=T)
        pairs = PairList(self.pi, self.pj, self.p_hist, self._p_hist_iter, self.p_fn, self.p_ft, NO_PAIR_CONSTANTS,
                         self.x_ref, *records.ONE_THREAD, 1)
        wall_list = WallList(self.wk, self.wm, self.w_hist, self._w_hist_iter, self.w_fn, self.w_ft, self.wq_ref)
        return particles, pairs, self.w, wall_list, Constants(self.gravity, self.box, self.params, self.skin)

    def _evaluate(self, x, v, T, out):
        """Forces at ``(x, v, T)`` with the walls where they are now; checks that no particle left the box."""
        escaped = self._forces(*self.records(x, v, T, out), 0.0, True, True)
        self._check_escape(escaped, x)

    def _check_escape(self, escaped, x):
        if escaped >= 0:
            k, m = int(self.wk[escaped]), int(self.wm[escaped])
            raise ValueError(f"particle {k} (centre {x[k].tolist()}) left the box through wall "
                             f"{self.walls[m].name!r}; reduce solver.dt_max or the wall speed")

    # --------------------------------------------------------------------------------------------- walls
    def wall_offsets(self, t: float, dt: float) -> np.ndarray:
        """Where the walls are at ``t + dt`` when the step starts at ``t`` with them at ``q_start``.

        Parameters
        ----------
        t : float
            The step's start (s).
        dt : float
            The step (s).

        Returns
        -------
        numpy.ndarray
            (W,) the walls' offsets (m).
        """
        w = self.w
        q = self.q_start.copy()
        strain = w.mode == MOTIONS["strain"]
        q[strain] += dt * w.dq[strain]
        vib = np.flatnonzero(w.mode == MOTIONS["vibrate"])
        q[vib] = w.q0[vib] + w.amplitude[vib] * np.sin(2.0 * math.pi * w.frequency[vib] * (t + dt))
        return q

    def set_wall_velocity(self, name: str, velocity: float) -> None:
        """A strain wall's inward speed from now on (a ``[[phases]]`` entry).

        Parameters
        ----------
        name : str
            The wall's name.
        velocity : float
            Its inward speed (m/s).
        """
        m = [w.name for w in self.walls].index(name)
        self.w.dq[m] = velocity

    # ----------------------------------------------------------------------------------------------- step
    def begin(self, t: float, dt: float) -> None:
        """Start a step of ``dt`` from the state now: walls to their end-of-step place, iterate 0 = the state.

        Parameters
        ----------
        t : float
            The step's start (s).
        dt : float
            The step (s).
        """
        self.q_start = self.w.q.copy()
        self.w.q[:] = self.wall_offsets(t, dt)
        if max_displacement(self.state.x, self.x_ref, self.box) + self._wall_reach() > 0.5 * self.skin:
            self._build_list(self.state.x)
        self.x_prev[:] = self.state.x
        self.v_prev[:] = self.state.v

    def iterate(self, dt: float, phi: float, T: np.ndarray) -> tuple[float, float]:
        r"""One fixed-point iteration at the temperatures ``T`` (those of the previous iterate): the new iterate is
        ``x_new``, ``v_new``. Returns :math:`(\sum |r^K - r^{K-1}|, \sum |r^K - r^L|)`.

        Parameters
        ----------
        dt : float
            The step (s).
        phi : float
            The trapezoidal weight, in ``[0, 1]`` (eqs. 22-24).
        T : numpy.ndarray
            (N,) temperatures (K).

        Returns
        -------
        tuple of (float, float)
            The change since the last iterate and the motion since the step's start (m, summed over particles).

        Raises
        ------
        ValueError
            A particle left the box through a wall, or a position became non-finite.
        """
        s = self.state
        particles, pairs, walls, wall_list, constants = self.records(self.x_prev, self.v_prev, T, self._f_iter)
        trial = Trial(s.x, s.v, self.f, self.x_new, self.v_new, self.stats)
        escaped = self._iterate(particles, trial, pairs, walls, wall_list, constants, dt, phi)
        self._check_escape(escaped, self.x_prev)
        change, motion, reach, finite = self.stats
        if not finite:
            k = int(np.flatnonzero(~np.all(np.isfinite(self.x_new), axis=1))[0])
            raise ValueError(f"particle {k} has a non-finite position; a parameter is extreme")
        self.x_prev, self.x_new = self.x_new, self.x_prev
        self.v_prev, self.v_new = self.v_new, self.v_prev
        if reach + self._wall_reach() > 0.5 * self.skin:
            self._build_list(self.x_prev)  # valid for the new iterate, from which the next forces are taken
        return float(change), float(motion)

    @property
    def x_iterate(self) -> np.ndarray:
        """Positions of the latest iterate."""
        return self.x_prev

    def accept(self, T: np.ndarray) -> None:
        """The latest iterate becomes the state (with the temperatures ``T`` of the step's end); its forces become
        :math:`F^L` of the next step and the histories it made are kept (Zohdi 2014: the bonds it activated).

        Parameters
        ----------
        T : numpy.ndarray
            (N,) temperatures (K).
        """
        s = self.state
        s.x[:] = self.x_prev
        s.v[:] = self.v_prev
        self._evaluate(s.x, s.v, T, self.f)
        changed = not (np.array_equal(self._p_hist_iter, self.p_hist) and np.array_equal(self._w_hist_iter, self.w_hist))
        if changed:  # histories changed by this step (bonds activated or broken) act from the next one on
            self.p_hist[:] = self._p_hist_iter
            self.w_hist[:] = self._w_hist_iter
            self._evaluate(s.x, s.v, T, self.f)
        self.q_start = self.w.q.copy()

    def restart(self) -> None:
        """Undo the iterations of a step that did not converge: the walls go back to where the step started."""
        self.w.q[:] = self.q_start
        if max_displacement(self.state.x, self.x_ref, self.box) + self._wall_reach() > 0.5 * self.skin:
            self._build_list(self.state.x)

    # -------------------------------------------------------------------------------------------- outputs
    def pair_column(self, name: str) -> np.ndarray:
        """The column ``name`` of the listed pairs' committed history (``law.PAIR_HISTORY``; e.g. ``"bonded"``).

        Parameters
        ----------
        name : str
            A name of the law's ``PAIR_HISTORY``.

        Returns
        -------
        numpy.ndarray
            One value per listed pair.
        """
        return self.p_hist[:, self.law.PAIR_HISTORY.index(name)]

    def contacts(self):
        """The touching pairs of the state: ``(i, j, normal force (N, > 0 repulsive), contact area (m^2), bonded)``
        (as the forces of the last accepted step saw them)."""
        s = self.state
        ri, rj = s.radius[self.pi], s.radius[self.pj]
        dx = s.x[self.pi] - s.x[self.pj]
        if self.periodic_box is not None:
            dx = self.periodic_box.minimum_image(dx)
        d = np.sqrt(np.sum(dx ** 2, axis=1))
        closed = (d < ri + rj) & (d > 0.0)
        d, ri, rj = d[closed], ri[closed], rj[closed]
        li = 0.5 * (d - (rj * rj - ri * ri) / d)
        area = np.pi * np.maximum(ri * ri - li * li, 0.0)  # the lens of Zohdi 2014, eqs. 7-12
        bonded = self._p_hist_iter[closed, 0] != 0.0
        return self.pi[closed], self.pj[closed], self.p_fn[closed], area, bonded

    def wall_contacts(self):
        """``(particle, wall)`` of the particle-wall contacts of the state."""
        s, w = self.state, self.w
        dist = s.x @ w.normal.T - w.q[None, :]
        return np.nonzero(dist < s.radius[:, None])

