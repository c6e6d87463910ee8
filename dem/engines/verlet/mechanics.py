"""The mechanical submodel: particles that move under a contact law (:mod:`dem.laws.contact`), walls and gravity.

It owns the Verlet list and the per-contact history and advances the state with the compiled loop of
:mod:`dem.engines.verlet.loop` (compiled for the law, :mod:`dem.engines.compiled`), returning to Python only to rebuild
the list (when some particle has moved more than half the skin), at the times the engine asks for (output, a thermal
update, a change of schedule), or to stop a run that went wrong (a non-finite position, a particle through a wall)
with a one-line message naming the step and the particle.

Threads: with more than one (:func:`sinterheat.threads.count`) and at least ``THREADED_MIN_PARTICLES`` particles the
model binds the threaded copy of the loop (:mod:`dem.engines.compiled`), which needs each particle's pairs outside the
block of its first one (:func:`dem.engines.contact_forces.split_incidences`, made at every rebuild); its results are
those of one thread to the bit. Below that size a step is too short to share: the threads would cost more than they
save.

History: per pair in the list the numbers the law carries (``law.PAIR_HISTORY``; Luding 2005: the largest overlap,
the stiffness factor the contact saw at its last step and the tangential spring), the same per particle-wall pair
(``law.WALL_HISTORY``), and per particle the law's state (``law.PARTICLE_STATE``; Luding 2005: the stiffness factor
``k1(T, t)/k1``). A rebuild carries the history of every pair that stays listed
(:func:`dem.geometry.neighbours.carry_history`); a contact that opens forgets it.
"""

from __future__ import annotations

import numpy as np

from sinterheat import threads

from dem.engines import compiled, records
from dem.engines.contact_forces import LOAD_COLUMNS, split_incidences
from dem.engines.records import Constants, PairList, Steps, WallList
from dem.engines.verlet.loop import ESCAPED, NONFINITE, REBUILD, wall_acceleration
from dem.engines.state import MotionState
from dem.geometry.neighbours import carry_history, restore_lists, verlet_pairs, wall_pairs
from dem.geometry.periodic import PeriodicBox
from dem.geometry.walls import WallArrays
from dem.laws.contact import law_module


THREADED_MIN_PARTICLES = 2000


class MechanicsError(ValueError):
    """A run that cannot go on (non-finite state, a particle through a wall); the message names step and particle."""


class MechanicalModel:
    """Velocity-Verlet dynamics with a contact law (module docstring)."""

    name = "mechanical"

    def __init__(self, state: MotionState, walls, material, dt: float, skin: float, gravity=(0.0, 0.0, 0.0),
                 box: PeriodicBox | None = None, relaxation_time: float = 1e3, history=None):
        """``material``: the contact law's material (``material.law`` names the law); ``box``: a periodic box
        (:class:`dem.geometry.periodic.PeriodicBox`): contacts across its faces by the minimum image, the particles
        wrapped into it at every rebuild of the Verlet list; ``history``: a saved state
        (:func:`dem.scene.state_file.load`) whose particle state and contact histories (pairs, and particle-wall
        pairs matched by wall name) the model starts from.

        Parameters
        ----------
        state : dem.engines.state.MotionState
            The particles' state (SI units), advanced in place.
        walls : sequence of dem.geometry.walls.Wall
            The walls.
        material : object
            The contact law's material (:mod:`dem.laws.contact`).
        dt : float
            The velocity-Verlet step (s).
        skin : float
            The Verlet list's skin (m), larger than the law's largest reach.
        gravity : array_like
            The gravitational acceleration [x, y, z] (m/s^2).
        box : dem.geometry.periodic.PeriodicBox or None
            The periodic box; None: none.
        relaxation_time : float
            The material's relaxation time (s; Luding 2005's ``t0``).
        history : dict or None
            A saved state to start the particle state and contact histories from; None: none.

        Raises
        ------
        ValueError
            The skin does not exceed the law's largest reach, a stress wall lacks its box, or an unknown law.
        """
        self.state = state
        self.walls = tuple(walls)
        self.law = law_module(material.law)
        self._forces = compiled.loop(material.law, "dem.engines.contact_forces", "forces")
        self.n_threads = threads.bind_numba()
        self.threaded = self.n_threads > 1 and state.n >= THREADED_MIN_PARTICLES
        self._advance = compiled.loop(material.law, "dem.engines.verlet.loop", "advance", self.threaded)
        self.params = np.ascontiguousarray(material.params(), dtype=float)
        self.dt = float(dt)
        self.skin = float(skin)
        reach = self.law.largest_reach(material, state.radius)
        if not self.skin > reach:  # a listed pair must stay listed for as long as it acts
            raise ValueError(f"[solver] skin = {self.skin:.6g} m: must exceed {reach:.6g} m, the farthest a contact "
                             f"of law = \"{self.law.NAME}\" acts beyond touching (its pull-off distance)")
        self.gravity = np.asarray(gravity, dtype=float) * state.linear_dof
        self.periodic_box = box
        self.box = box.kernel_lengths if box is not None else np.zeros(3)  # 0: not periodic
        self.relaxation_time = float(relaxation_time)
        self.w = WallArrays.build(self.walls, state.dimension, self.box)
        n, n_w = state.n, len(self.walls)
        self.particle_state = self.law.initial_state(material, state.T, state.mass)  # each particle's state at the start
        self.w_hist = np.zeros((n, n_w, len(self.law.WALL_HISTORY)))
        self.w_fn = np.zeros((n, n_w))
        self.w_ft = np.zeros((n, n_w, 3))
        self.steps = 0  # of this run
        self.t_start = 0.0  # the time the run started at (a saved state's, when it goes on from one)
        self.rebuilds = 0
        self._info = np.zeros(2, dtype=np.int64)
        self._build_list(first=True)
        if history is not None:
            self._restore(history)  # with the forces of its last step: the run goes on as if it had not stopped
        else:
            self._initial_forces()

    def _restore(self, saved: dict):
        """Particle state and contact histories from a saved state (the list is rebuilt here, so the pairs'
        histories are carried by key; walls by name). A state saved with another contact law gives its particles
        only: the contacts start afresh."""
        if saved["contact_law"] != self.law.NAME:
            self._initial_forces()
            return
        self.particle_state = np.array(saved["particle_state"], dtype=float)
        self.p_hist, self.p_fn, self.p_ft = carry_history(saved["pi"], saved["pj"], self.pi, self.pj,
                                                          saved["p_hist"], np.zeros(len(saved["pi"])),
                                                          np.zeros((len(saved["pi"]), 3)))
        names = [w.name for w in self.walls]
        for m_old, name in enumerate(saved["wall_names"]):
            if name in names:
                m = names.index(name)
                self.w_hist[:, m] = saved["w_hist"][:, m_old]
                if self.walls[m].motion == "stress":
                    self.w.dq[m] = saved["wall_dq"][m_old]
                    self.w.acc[m] = saved["wall_acc"][m_old]

    # ------------------------------------------------------------------------------------------------ list
    def _build_list(self, first: bool = False):
        s = self.state
        box = self.periodic_box
        if box is not None:  # those that left it back into the box
            box.wrap_outside(s.x)
        expected = 0 if first else len(self.pi) + len(self.pi) // 8 + 16  # the last list, with room to grow
        i, j = verlet_pairs(s.x, s.radius, self.skin, self.box, expected)
        if first:
            m = len(i)
            self.p_hist, self.p_fn, self.p_ft = np.zeros((m, len(self.law.PAIR_HISTORY))), np.zeros(m), np.zeros((m, 3))
        else:
            self.p_hist, self.p_fn, self.p_ft = carry_history(self.pi, self.pj, i, j, self.p_hist, self.p_fn, self.p_ft)
            self.rebuilds += 1
        self._listed(i, j)

    def _listed(self, i: np.ndarray, j: np.ndarray):
        """The pairs ``(i, j)`` as the list (with the threads' view of it), built at the positions of now."""
        self.pi, self.pj = i, j
        self._pair_arrays()
        self.x_ref = self.state.x.copy()
        self.walls_moved()

    def _pair_arrays(self):
        """The arrays the loop indexes by listed pair: the pairs' constants and the threads' view of the list."""
        i, j = self.pi, self.pj
        self.p_const = np.empty((len(i), 2 if self.law.PAIR_CONSTANTS else 0))  # filled at each call's first step
        if self.threaded:
            self.pair_owner, self.pair_start, self.pair_order = split_incidences(i, j, self.state.n, self.n_threads)
            self.pair_load = np.empty((len(i), LOAD_COLUMNS))
        else:  # the one-thread loop reads none of them
            self.pair_owner, self.pair_start, self.pair_order, self.pair_load = records.ONE_THREAD

    def restore_lists(self, saved: dict) -> None:
        """The Verlet lists of a checkpoint (:func:`dem.geometry.neighbours.restore_lists`), with the arrays the loop
        indexes by pair (``_pair_arrays``) sized by them.

        Parameters
        ----------
        saved : dict
            The checkpoint's arrays.
        """
        restore_lists(self, saved)
        self._pair_arrays()

    def walls_moved(self):
        """The walls were set elsewhere (a resumed run): their Verlet list follows."""
        self.wk, self.wm = wall_pairs(self.state.x, self.state.radius, self.w.normal, self.w.q, self.skin)
        self.wq_ref = self.w.q.copy()

    def records(self) -> tuple:
        """What the compiled loops take (:mod:`dem.engines.records`), made of the model's arrays as they are now.

        Returns
        -------
        tuple
            ``(particles, pairs, walls, wall_list, constants)``: :class:`~dem.engines.records.Particles`,
            :class:`~dem.engines.records.PairList`, :class:`~dem.geometry.walls.WallArrays`,
            :class:`~dem.engines.records.WallList`, :class:`~dem.engines.records.Constants`.
        """
        pairs = PairList(self.pi, self.pj, self.p_hist, self.p_hist, self.p_fn, self.p_ft, self.p_const, self.x_ref,
                         self.pair_owner, self.pair_start, self.pair_order, self.pair_load, self.n_threads)
        wall_list = WallList(self.wk, self.wm, self.w_hist, self.w_hist, self.w_fn, self.w_ft, self.wq_ref)
        return (records.particles(self.state, self.particle_state), pairs, self.w, wall_list,
                Constants(self.gravity, self.box, self.params, self.skin))

    def _initial_forces(self):
        """Forces of the initial state (dt = 0: no history increment)."""
        self._forces(*self.records(), 0.0, True, True)
        for m in range(len(self.walls)):
            self.w.acc[m] = wall_acceleration(m, self.w)

    # --------------------------------------------------------------------------------------------- advance
    @property
    def t(self) -> float:
        """Simulated time ``t_start + steps dt``, s."""
        return self.t_start + self.steps * self.dt

    def _temperature_arguments(self, T0, T_rate, relaxation_time: float | None):
        """The compiled loop's temperature arguments: ``T0`` and ``T_rate`` as contiguous arrays, whether they are
        uniform (one entry), and the relaxation time (the model's unless given)."""
        T0 = np.ascontiguousarray(T0, dtype=float)
        return (T0, np.ascontiguousarray(T_rate, dtype=float), len(T0) == 1,
                self.relaxation_time if relaxation_time is None else relaxation_time)

    def advance(self, n_steps: int, T0: np.ndarray, T_rate: np.ndarray, relaxation_time: float | None = None):
        """``n_steps`` steps with temperatures ``T0 + T_rate (t - t_now)`` (uniform when both have one entry).

        Parameters
        ----------
        n_steps : int
            Number of steps.
        T0 : numpy.ndarray
            Temperatures now (K or degC): one per particle, or one for all.
        T_rate : numpy.ndarray
            Their rates (K/s), shaped as ``T0``.
        relaxation_time : float or None
            The relaxation time (s); None: the model's.

        Raises
        ------
        MechanicsError
            A particle's position or velocity became non-finite, or a particle left the box (a ValueError).
        """
        s = self.state
        heating = self._temperature_arguments(T0, T_rate, relaxation_time)
        first = self.steps
        done = 0
        kernel_records = self.records()
        while done < n_steps:
            steps, status = self._advance(*kernel_records, Steps(n_steps - done, self.dt, self.steps, first, *heating),
                                          self._info)
            done += steps
            self.steps += steps
            if status == REBUILD:
                self._build_list()
                kernel_records = self.records()
            elif status == NONFINITE:
                k = int(self._info[0])
                raise MechanicsError(f"the run stopped at step {self.steps} (t = {self.t:.6g} s): particle {k} has a "
                                     f"non-finite position or velocity; the step dt = {self.dt:.6g} s is too large "
                                     f"or a parameter is extreme")
            elif status == ESCAPED:
                k, m = int(self._info[0]), int(self._info[1])
                raise MechanicsError(f"the run stopped at step {self.steps} (t = {self.t:.6g} s): particle {k} "
                                     f"(centre {s.x[k].tolist()}) left the box through wall "
                                     f"{self.walls[m].name!r}; reduce dt or the wall speed, or enlarge the box")

    # --------------------------------------------------------------------------------------------- outputs
    def contacts(self):
        """The closed pair contacts: ``(i, j, overlap, f_n, f_t)`` with f_t the (M, 3) tangential forces on i."""
        s = self.state
        d = s.x[self.pi] - s.x[self.pj]
        if self.periodic_box is not None:
            d = self.periodic_box.minimum_image(d)
        overlap = s.radius[self.pi] + s.radius[self.pj] - np.linalg.norm(d, axis=1)
        closed = overlap > 0
        return self.pi[closed], self.pj[closed], overlap[closed], self.p_fn[closed], self.p_ft[closed]

    def wall_contacts(self):
        """The closed particle-wall contacts: ``(particle, wall, overlap, f_n)``."""
        s, w = self.state, self.w
        dist = s.x @ w.normal.T - w.q[None, :]
        overlap = s.radius[:, None] - dist
        k, m = np.nonzero(overlap > 0)
        return k, m, overlap[k, m], self.w_fn[k, m]

    def particle_column(self, name: str) -> np.ndarray:
        """The column ``name`` of the contact law's particle state (``law.PARTICLE_STATE``; e.g. the stiffness factor
        ``"k1_factor"`` of Luding 2005), a view.

        Parameters
        ----------
        name : str
            A name of the law's ``PARTICLE_STATE``.

        Returns
        -------
        numpy.ndarray
            One value per particle.
        """
        return self.particle_state[:, self.law.PARTICLE_STATE.index(name)]

    def pair_column(self, name: str) -> np.ndarray:
        """The column ``name`` of the listed pairs' history (``law.PAIR_HISTORY``; e.g. ``"delta_max"``), a view.

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

    def coordination(self) -> float:
        """Mean number of particle contacts per particle, ``2 M / N``."""
        return 2.0 * len(self.contacts()[0]) / self.state.n
