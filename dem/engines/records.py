"""The records the compiled loops take: the particles, the Verlet list of pairs, the particle-wall list, the run's
constants and the time loop's steps, each a named tuple of arrays and numbers.

numba passes a named tuple to a compiled function as one argument (a structure of its fields, each array unboxed as
it would be on its own) and reads a field as it reads a local variable, so a loop that takes records runs the same
machine code as one that takes the arrays one by one; the records only name what belongs together, once, for every
call site. The walls' record is :class:`dem.geometry.walls.WallArrays`.

A record holds references to the arrays, not copies: the loops write into them in place. A model makes its records
in one method (its ``records()``) from its arrays as they are: at each call of a loop from Python, and again after
a rebuild of the Verlet list (which makes new arrays) -- never per step within a call. At a call from Python numba
types a named tuple in Python, not in its dispatcher's compiled fast path for arrays: a few microseconds more per
call, once per call of the time loop (which runs up to a rebuild's worth of steps), nothing within it.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from dem.engines.contact_forces import LOAD_COLUMNS

Particles = namedtuple("Particles", ["x", "v", "w", "f", "tau", "mass", "inv_mass", "inv_inertia", "radius",
                                     "radius_ref", "T", "state", "spin_axes"])
Particles.__doc__ = """The particles as the compiled loops take them (N particles; the loops write into the arrays).

Parameters
----------
x, v, w : numpy.ndarray
    (N, 3) positions (m), velocities (m/s) and angular velocities (rad/s).
f, tau : numpy.ndarray
    (N, 3) forces (N) and torques (N m), written by the force loop.
mass : numpy.ndarray
    (N,) masses (kg).
inv_mass, inv_inertia : numpy.ndarray
    (N,) ``1/mass`` (1/kg) and ``1/inertia`` (1/(kg m^2)).
radius, radius_ref : numpy.ndarray
    (N,) current radii and radii at the reference temperature (m).
T : numpy.ndarray
    (N,) temperatures (the scene's unit, K or degC).
state : numpy.ndarray
    (N, S) the contact law's particle state (its ``PARTICLE_STATE``).
spin_axes : tuple of int
    The axes the particles rotate about (:attr:`dem.engines.state.MotionState.spin_axes`): ``(1,)`` for 2D disks in
    the x-z plane, ``(0, 1, 2)`` in 3D.
"""

PairList = namedtuple("PairList", ["i", "j", "hist_in", "hist", "fn", "ft", "const", "x_ref", "owner", "start",
                                   "order", "load", "n_blocks"])
PairList.__doc__ = """The Verlet list of particle pairs and what the loops keep per listed pair (M pairs).

Parameters
----------
i, j : numpy.ndarray
    (M,) int, the pairs' particles.
hist_in, hist : numpy.ndarray
    (M, H) the contacts' history (the law's ``PAIR_HISTORY``) read and written: the same array where a step is taken,
    two where an iterate may be discarded.
fn, ft : numpy.ndarray
    (M,) normal forces (N) and (M, 3) tangential forces on i (N), written where forces are recorded.
const : numpy.ndarray
    (M, 2) room for the pairs' numbers of the radii alone (the law's ``pair_constants``), (0, 0) for none.
x_ref : numpy.ndarray
    (N, 3) the positions the list was built at (m).
owner, start, order, load : numpy.ndarray
    The threaded force loop's view of the list (:func:`dem.engines.contact_forces.split_incidences`) and its buffer
    (M, ``LOAD_COLUMNS``); empty where one thread runs the loop.
n_blocks : int
    The threads the force loop shares the pairs among.
"""

WallList = namedtuple("WallList", ["k", "m", "hist_in", "hist", "fn", "ft", "q_ref"])
WallList.__doc__ = """The particle-wall list: the particles within reach of each wall (E entries), and what the loops
keep per particle and wall (N particles, W walls).

Parameters
----------
k, m : numpy.ndarray
    (E,) int, the particle and the wall of each entry.
hist_in, hist : numpy.ndarray
    (N, W, H) the contacts' history (the law's ``WALL_HISTORY``) read and written (as :class:`PairList`'s).
fn, ft : numpy.ndarray
    (N, W) normal forces (N) and (N, W, 3) tangential forces (N) of the contacts.
q_ref : numpy.ndarray
    (W,) the walls' offsets when the list was built (m).
"""

Constants = namedtuple("Constants", ["gravity", "box", "params", "skin"])
Constants.__doc__ = """What stays fixed over a run.

Parameters
----------
gravity : numpy.ndarray
    (3,) the gravitational acceleration (m/s^2).
box : numpy.ndarray
    (3,) the periodic box's lengths (m), 0 along the axes that are not periodic.
params : numpy.ndarray
    The contact law's material parameters (its ``params()``).
skin : float
    The Verlet list's skin (m).
"""

Steps = namedtuple("Steps", ["count", "dt", "step0", "first", "T0", "T_rate", "uniform_T", "t0"])
Steps.__doc__ = """A call of the time loop: which steps, and the temperatures along them.

Parameters
----------
count : int
    The most steps to take.
dt : float
    The step (s).
step0 : int
    The global step the call starts at (t = step0 dt).
first : int
    The step at which the temperatures ``T0`` hold.
T0, T_rate : numpy.ndarray
    The temperatures at step ``first`` (K or degC) and their rates (K/s): one per particle, or one for all.
uniform_T : bool
    Whether ``T0`` and ``T_rate`` hold one entry for all particles.
t0 : float
    The relaxation time of the material state (s; Luding 2005's ``t0``).
"""


Trial = namedtuple("Trial", ["x_start", "v_start", "f_start", "x_new", "v_new", "stats"])
Trial.__doc__ = """A fixed-point iteration of the implicit trapezoidal step
(:func:`dem.engines.staggered.kernels.iterate`).

Parameters
----------
x_start, v_start, f_start : numpy.ndarray
    (N, 3) the positions (m), velocities (m/s) and forces (N) at the step's start.
x_new, v_new : numpy.ndarray
    (N, 3) where the new iterate's positions and velocities are written.
stats : numpy.ndarray
    (4,) where the iteration's measures are written.
"""

def particles(state, particle_state: np.ndarray, **replaced) -> Particles:
    """The record of a :class:`dem.engines.state.MotionState` with the contact law's particle state.

    Parameters
    ----------
    state : dem.engines.state.MotionState
        The particles.
    particle_state : numpy.ndarray
        (N, S) the contact law's particle state.
    **replaced : numpy.ndarray or tuple
        Fields of :class:`dem.engines.records.Particles` taken from elsewhere than ``state`` (e.g. an iterate's positions).

    Returns
    -------
    dem.engines.records.Particles
        The record (references to the arrays, ``inv_mass`` and ``inv_inertia`` computed here).
    """
    return Particles(state.x, state.v, state.w, state.f, state.tau, state.mass, 1.0 / state.mass, 1.0 / state.inertia,
                     state.radius, state.radius_ref, state.T, particle_state, state.spin_axes)._replace(**replaced)


# The threaded force loop's view of a list (PairList's owner, start, order, load) where one thread runs the loop:
# empty arrays of the right types, which that loop does not read
ONE_THREAD = (np.zeros(0, np.int64), np.zeros(1, np.int64), np.zeros(0, np.int64), np.zeros((0, LOAD_COLUMNS)))
