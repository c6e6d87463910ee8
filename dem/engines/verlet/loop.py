r"""The compiled time loop of particles that move: velocity-Verlet steps with any contact law.

One call advances the particles (and the walls) by up to ``n_steps`` steps of ``dt``, entirely in compiled code
(numba), and returns early only when the caller must act: the Verlet lists are about to become invalid (a
particle, plus the farthest-moved wall, has moved more than half the skin since they were built), a position became
non-finite, or a particle left through a wall. Besides the pair list there is a particle-wall list: the particles
within ``radius + skin`` of each wall (the only ones that can touch it or cross it before the next rebuild). Each
step:

1. half kick and drift: :math:`v \mathrel{+}= \frac{\Delta t}{2} f/m`, :math:`x \mathrel{+}= \Delta t \, v` (and
   :math:`\omega \mathrel{+}= \frac{\Delta t}{2} \tau/I`); walls move by their law (:mod:`dem.geometry.walls`);
2. material state: the temperature :math:`T_i(t) = T_{0,i} + \dot T_i \, (t - t_\mathrm{first})` (:math:`T_{0,i}` and
   :math:`\dot T_i` the ``T0`` and ``T_rate`` of the call) and what the contact law makes of it (the law's
   ``update_particles``; Luding 2005: the radius :math:`a(T)`, eq. 9, the stiffness factor :math:`k_1(T, t)/k_1` relaxed
   towards :math:`k_1(T)/k_1`, eqs. 10-12);
3. forces: gravity, every listed pair and every particle-wall contact by the contact law, summed into forces and
   torques (:func:`dem.engines.contact_forces.forces`);
4. second half kick (velocities at the end of the step); stress-controlled walls from eq. 1.

Like :mod:`dem.engines.contact_forces`, the loop takes the contact law as its first argument, bound at compile time
(:mod:`dem.laws.contact.binding`); its copy for more than one thread (:mod:`dem.engines.compiled`) calls the threaded
force pass, which runs on all of numba's threads with the same results to the bit (:mod:`dem.engines.contact_forces`).
The kicks and the drift stay on one thread: they take a few ns per particle, less than numba's threads may take to
start a parallel loop (about 1 us on GNU OpenMP, 0.1 ms on numba's ``workqueue``: :mod:`sinterheat.threads`), so a
step starts one parallel loop only.
"""

from __future__ import annotations

import math

from numba import njit

from dem.engines.contact_forces import forces
from dem.geometry.neighbours import min_image
from dem.laws.contact import binding

DONE, REBUILD, NONFINITE, ESCAPED = 0, 1, 2, 3  # how a call of advance() ended


@njit(cache=True, error_model="numpy")
def wall_acceleration(m, walls):
    r"""Eq. (1) of Luding 2005 for stress wall ``m`` of ``walls`` (:class:`dem.geometry.walls.WallArrays`):
    :math:`(p L - F_w - \gamma_w \, dq/dt) / m_w`."""
    if walls.mode[m] != 1:
        return 0.0
    wq, span = walls.q, walls.span
    extent = 1.0
    for a in range(2):
        lo, hi = span[m, 2 * a], span[m, 2 * a + 1]
        if lo >= 0:
            extent *= -(wq[lo] + wq[hi])
    return (walls.pressure[m] * extent - walls.force[m] - walls.damping[m] * walls.dq[m]) / walls.mass[m]


@njit(cache=True, error_model="numpy")
def advance(law, particles, pairs, walls, wall_list, constants, steps, info):
    """Up to ``steps.count`` velocity-Verlet steps (module docstring) under the contact law ``law``.

    Parameters
    ----------
    law : dem.laws.contact.binding.ContactLaw
        The contact law, bound at compile time.
    particles : dem.engines.records.Particles
        The particles, advanced in place; ``f``/``tau`` must hold the forces of the current state on entry.
    pairs : dem.engines.records.PairList
        The Verlet list of pairs (``const``: computed at the first step and at any step whose radii changed, read at
        the others; the threaded view read by the threaded copies: :func:`dem.engines.contact_forces.forces`).
    walls : dem.geometry.walls.WallArrays
        The walls, moved in place; ``acc`` must hold the stress walls' accelerations of the current state on entry.
    wall_list : dem.engines.records.WallList
        The particle-wall list.
    constants : dem.engines.records.Constants
        Gravity, the periodic box, the law's material and the Verlet list's skin.
    steps : dem.engines.records.Steps
        Which steps: from global step ``step0`` (t = step0 dt) of an interval that began at step ``first`` with
        temperatures ``T0`` (``T0 + T_rate (t - first dt)`` after it). Times come from step counts, so where a run
        is split into calls (rebuilds, a resume) never changes its arithmetic.
    info : numpy.ndarray
        (2,) int, receives the particle (and wall) index of a non-finite or escaped particle (the first such).

    Returns
    -------
    tuple of (int, int)
        The steps done and how the call ended (``DONE``, ``REBUILD``, ``NONFINITE``, ``ESCAPED``).
    """
    n_steps, dt, step0, first = steps.count, steps.dt, steps.step0, steps.first
    x, v, w, f, tau, spin_axes = particles.x, particles.v, particles.w, particles.f, particles.tau, particles.spin_axes
    inv_mass, inv_inertia = particles.inv_mass, particles.inv_inertia
    wn, wq, wdq, wacc, wmode = walls.normal, walls.q, walls.dq, walls.acc, walls.mode
    wq0, wamp, wfreq = walls.q0, walls.amplitude, walls.frequency
    wk, wm, wq_ref = wall_list.k, wall_list.m, wall_list.q_ref
    box, x_ref, skin = constants.box, pairs.x_ref, constants.skin
    n = x.shape[0]
    n_w = wn.shape[0]
    h = 0.5 * dt
    planar = len(spin_axes) == 1  # 2D disks in the x-z plane: axes (0, 2), spin about y
    for s in range(n_steps):
        t = (step0 + s) * dt
        for k in range(n):
            im, ii = inv_mass[k], inv_inertia[k]
            v[k, 0] += h * f[k, 0] * im
            x[k, 0] += dt * v[k, 0]
            moved = abs(x[k, 0])
            if not planar:
                v[k, 1] += h * f[k, 1] * im
                x[k, 1] += dt * v[k, 1]
                moved += abs(x[k, 1])
            v[k, 2] += h * f[k, 2] * im
            x[k, 2] += dt * v[k, 2]
            moved += abs(x[k, 2])
            if not planar:
                w[k, 0] += h * tau[k, 0] * ii
                moved += abs(w[k, 0])
            w[k, 1] += h * tau[k, 1] * ii
            moved += abs(w[k, 1])
            if not planar:
                w[k, 2] += h * tau[k, 2] * ii
                moved += abs(w[k, 2])
            if not moved < math.inf:  # NaN or inf: name the particle before its neighbours are contaminated
                info[0] = k
                return s + 1, 2
        for m in range(n_w):
            if wmode[m] == 1:
                wdq[m] += h * wacc[m]
                wq[m] += dt * wdq[m]
            elif wmode[m] == 2:
                wq[m] += dt * wdq[m]
            elif wmode[m] == 3:
                phase = 2.0 * math.pi * wfreq[m] * (t + dt)
                wq[m] = wq0[m] + wamp[m] * math.sin(phase)
                wdq[m] = 2.0 * math.pi * wfreq[m] * wamp[m] * math.cos(phase)
        resized = binding.update_particles(law, (step0 + s + 1 - first) * dt, steps.T0, steps.T_rate, particles.T,
                                           particles.radius, particles.radius_ref, particles.state, steps.uniform_T,
                                           constants.params, steps.t0, dt)
        fresh = s == 0 or resized
        escaped = forces(law, particles, pairs, walls, wall_list, constants, dt, fresh, s == n_steps - 1)
        worst = 0.0
        for k in range(n):
            im, ii = inv_mass[k], inv_inertia[k]
            v[k, 0] += h * f[k, 0] * im
            d = min_image(x[k, 0] + dt * v[k, 0] - x_ref[k, 0], box[0])
            d2 = d * d
            if not planar:
                v[k, 1] += h * f[k, 1] * im
                d = min_image(x[k, 1] + dt * v[k, 1] - x_ref[k, 1], box[1])
                d2 += d * d
            v[k, 2] += h * f[k, 2] * im
            d = min_image(x[k, 2] + dt * v[k, 2] - x_ref[k, 2], box[2])
            d2 += d * d
            if not planar:
                w[k, 0] += h * tau[k, 0] * ii
            w[k, 1] += h * tau[k, 1] * ii
            if not planar:
                w[k, 2] += h * tau[k, 2] * ii
            if not (d2 < math.inf):  # NaN or inf
                info[0] = k
                return s + 1, 2
            worst = max(worst, d2)
        wall_moved = 0.0
        for m in range(n_w):
            if wmode[m] == 1:
                wacc[m] = wall_acceleration(m, walls)
                wdq[m] += h * wacc[m]
            wall_moved = max(wall_moved, abs(wq[m] + dt * wdq[m] - wq_ref[m]))
        if escaped >= 0:
            info[0] = wk[escaped]
            info[1] = wm[escaped]
            return s + 1, 3
        if math.sqrt(worst) + wall_moved > 0.5 * skin:
            return s + 1, 1
    return n_steps, 0
