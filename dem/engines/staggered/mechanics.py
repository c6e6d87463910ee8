"""The mechanical submodel of Zohdi 2014: particles that move under the forces of eqs. (2)-(21), stepped by the
trapezoidal rule (eqs. 22-24) whose implicit equations are solved by fixed-point iteration (eqs. 25-27).

A step from ``t`` to ``t + dt`` is a sequence of iterations (:meth:`ZohdiMechanics.iterate`), each evaluating the
forces at the previous iterate with the temperatures frozen at theirs; the staggered scheme
(:mod:`dem.engines.staggered.engine`) decides when the iterates have converged and then :meth:`~ZohdiMechanics.accept`\\ s
the last one, or :meth:`~ZohdiMechanics.restart`\\ s the step with a smaller ``dt``. Walls move by prescribed
kinematics (fixed, strain at a constant speed, vibrating; :mod:`dem.geometry.walls`), so where they are at the end of the
step is known before it is solved.

Neighbours (Zohdi 2014, Sec. 8): a Verlet list with a skin built by cell binning (:mod:`dem.geometry.neighbours`); an
iterate that takes a particle (plus the farthest-moved wall) more than half the skin from where the list was built
rebuilds it there, carrying each pair's bond flag. A bond (eq. 19) becomes part of the pair's history when a step
that reached ``E*`` is accepted (it acts from the next step on); it is forgotten when the pair separates.
"""

from __future__ import annotations

import math

import numpy as np

from dem.geometry.motion import MotionState
from dem.geometry.neighbours import carry_history, max_displacement, verlet_pairs, wall_pairs
from dem.geometry.walls import MOTIONS, WallArrays
from dem.engines.staggered import kernels


class ZohdiMechanics:
    """The particles, their Verlet list and the walls, advanced by fixed-point iterations (module docstring)."""

    name = "mechanical"

    def __init__(self, state: MotionState, walls, params: np.ndarray, gravity, skin: float):
        self.state = state
        self.walls = tuple(walls)
        for wall in self.walls:
            if wall.motion == "stress":
                raise ValueError(f"walls.{wall.name}.motion = \"stress\": the Zohdi 2014 scheme moves walls by "
                                 f"prescribed kinematics only (fixed, strain, vibrate)")
        self.params = np.ascontiguousarray(params, dtype=float)
        self.gravity = np.asarray(gravity, dtype=float)
        self.skin = float(skin)
        self.w = WallArrays.build(self.walls, 3)
        n = state.n
        self.f = np.zeros((n, 3))          # forces at the start of the step, F^L
        self._f_iter = np.zeros((n, 3))    # forces of the current iteration, F^(K-1)
        self.x_new, self.v_new = state.x.copy(), state.v.copy()
        self.x_prev, self.v_prev = state.x.copy(), state.v.copy()
        self.q_start = self.w.q.copy()
        self.wforce = np.zeros(len(self.walls))
        self.stats = np.zeros(4)
        self.rebuilds = 0
        self.bonded = np.zeros(0, dtype=np.int8)
        self.pi = self.pj = np.zeros(0, dtype=np.int64)
        self._build_list(state.x)
        self._evaluate(state.x, state.v, state.T, self.f)

    # ------------------------------------------------------------------------------------------------ list
    def _build_list(self, x):
        s = self.state
        i, j = verlet_pairs(x, s.radius, self.skin, np.zeros(3))
        if len(self.pi):
            (self.bonded,) = carry_history(self.pi, self.pj, i, j, self.bonded)
            self.rebuilds += 1
        else:
            self.bonded = np.zeros(len(i), dtype=np.int8)
        self.pi, self.pj = i, j
        self.p_fn, self.p_area = np.zeros(len(i)), np.zeros(len(i))
        self.p_bond = np.zeros(len(i), dtype=np.int8)
        self.x_ref = x.copy()
        self.wk, self.wm = wall_pairs(x, s.radius, self.w.normal, self.w.q, self.skin)
        self.wq_ref = self.w.q.copy()

    def _wall_reach(self) -> float:
        return float(np.max(np.abs(self.w.q - self.wq_ref), initial=0.0))

    def _evaluate(self, x, v, T, out):
        """Forces at ``(x, v, T)`` with the walls where they are now; checks that no particle left the box."""
        w = self.w
        escaped = kernels.forces(x, v, T, self.state.mass, self.state.radius, self.gravity, self.pi, self.pj,
                                 self.bonded, w.normal, w.q, self.wk, self.wm, self.params, out, self.p_fn,
                                 self.p_area, self.p_bond, self.wforce)
        self._check_escape(escaped, x)

    def _check_escape(self, escaped, x):
        if escaped >= 0:
            k, m = int(self.wk[escaped]), int(self.wm[escaped])
            raise ValueError(f"particle {k} (centre {x[k].tolist()}) left the box through wall "
                             f"{self.walls[m].name!r}; reduce solver.dt_max or the wall speed")

    # --------------------------------------------------------------------------------------------- walls
    def wall_offsets(self, t: float, dt: float) -> np.ndarray:
        """Where the walls are at ``t + dt`` when the step starts at ``t`` with them at :attr:`q_start`."""
        w = self.w
        q = self.q_start.copy()
        strain = w.mode == MOTIONS["strain"]
        q[strain] += dt * w.dq[strain]
        vib = np.flatnonzero(w.mode == MOTIONS["vibrate"])
        q[vib] = w.q0[vib] + w.amplitude[vib] * np.sin(2.0 * math.pi * w.frequency[vib] * (t + dt))
        return q

    def set_wall_velocity(self, name: str, velocity: float) -> None:
        """A strain wall's inward speed from now on (a ``[[phases]]`` entry)."""
        m = [w.name for w in self.walls].index(name)
        self.w.dq[m] = velocity

    # ----------------------------------------------------------------------------------------------- step
    def begin(self, t: float, dt: float) -> None:
        """Start a step of ``dt`` from the state now: walls to their end-of-step place, iterate 0 = the state."""
        self.q_start = self.w.q.copy()
        self.w.q[:] = self.wall_offsets(t, dt)
        self.x_prev[:] = self.state.x
        self.v_prev[:] = self.state.v
        if max_displacement(self.state.x, self.x_ref, np.zeros(3)) + self._wall_reach() > 0.5 * self.skin:
            self._build_list(self.state.x)

    def iterate(self, dt: float, phi: float, T: np.ndarray) -> tuple[float, float]:
        """One fixed-point iteration at the temperatures ``T`` (those of the previous iterate): the new iterate is
        :attr:`x_new`, :attr:`v_new`. Returns ``(sum |r^K - r^(K-1)|, sum |r^K - r^L|)``."""
        s, w = self.state, self.w
        escaped = kernels.iterate(dt, phi, s.x, s.v, self.f, self.x_prev, self.v_prev, T, s.mass, s.radius,
                                  self.gravity, self.pi, self.pj, self.bonded, w.normal, w.q, self.wk, self.wm,
                                  self.params, self._f_iter, self.p_fn, self.p_area, self.p_bond, self.wforce,
                                  self.x_new, self.v_new, self.x_ref, self.stats)
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
        F^L of the next step and the bonds it activated are kept."""
        s = self.state
        s.x[:] = self.x_prev
        s.v[:] = self.v_prev
        self._evaluate(s.x, s.v, T, self.f)
        if np.any(self.p_bond != self.bonded):  # bonds activated (or broken) by this step act from the next one on
            self.bonded[:] = self.p_bond
            self._evaluate(s.x, s.v, T, self.f)
        self.q_start = self.w.q.copy()

    def restart(self) -> None:
        """Undo the iterations of a step that did not converge: the walls go back to where the step started."""
        self.w.q[:] = self.q_start
        if max_displacement(self.state.x, self.x_ref, np.zeros(3)) + self._wall_reach() > 0.5 * self.skin:
            self._build_list(self.state.x)

    # -------------------------------------------------------------------------------------------- outputs
    def contacts(self):
        """The touching pairs of the state: ``(i, j, normal force (N, > 0 repulsive), contact area (m^2), bonded)``
        (as the forces of the last accepted step saw them)."""
        closed = self.p_area > 0.0
        return self.pi[closed], self.pj[closed], self.p_fn[closed], self.p_area[closed], self.p_bond[closed]

    def wall_contacts(self):
        """``(particle, wall)`` of the particle-wall contacts of the state."""
        s, w = self.state, self.w
        dist = s.x @ w.normal.T - w.q[None, :]
        return np.nonzero(dist < s.radius[:, None])

