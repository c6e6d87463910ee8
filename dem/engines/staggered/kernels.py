"""The compiled kernels of the staggered implicit scheme (Zohdi 2014): one fixed-point iteration of the trapezoidal
step (eqs. 22-27) with the forces of the contact law (:func:`dem.engines.contact_forces.forces`), and the touching
pairs of the Verlet list.

Like :mod:`dem.engines.contact_forces`, the iteration takes the contact law as its first argument, bound at compile
time (:mod:`dem.laws.contact.binding`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.engines.contact_forces import forces
from dem.geometry.neighbours import min_image



@njit(cache=True, error_model="numpy")
def iterate(law, particles, trial, pairs, walls, wall_list, constants, dt, phi):
    r"""One fixed-point iteration K of the trapezoidal step (Zohdi 2014, eqs. 22-27) under the contact law ``law``:
    the forces at the previous iterate (with the walls where they are at the end of the step; the contacts' histories
    read from the lists' ``hist_in``, those of the step's start, and written to their ``hist``), then

    .. math::

        v^K = v^L + \frac{\Delta t}{m} \big(\phi F^{K-1} + (1 - \phi) F^L\big) \tag{22}

    .. math::

        r^K = r^L + \Delta t \big(\phi v^K + (1 - \phi) v^L\big) \tag{23}

    (together eq. 26).

    Parameters
    ----------
    law : dem.laws.contact.binding.ContactLaw
        The contact law, bound at compile time.
    particles : dem.engines.records.Particles
        The previous iterate, its positions :math:`r^{K-1}` and velocities :math:`v^{K-1}` as ``x`` and ``v``; its
        forces :math:`F^{K-1}` are written into ``f``.
    trial : dem.engines.records.Trial
        The step's start and where the new iterate goes; its ``stats`` receive :math:`\sum |r^K - r^{K-1}|`,
        :math:`\sum |r^K - r^L|` (Algorithm 1, step 4a), the largest distance of any particle from where the Verlet
        list was built and a NaN flag.
    pairs : dem.engines.records.PairList
        The Verlet list of pairs.
    walls : dem.geometry.walls.WallArrays
        The walls.
    wall_list : dem.engines.records.WallList
        The particle-wall list.
    constants : dem.engines.records.Constants
        Gravity, the periodic box and the law's material.
    dt : float
        The step (s).
    phi : float
        The trapezoidal weight, in ``[0, 1]`` (eqs. 22-24).

    Returns
    -------
    int
        The escaped wall pair index of :func:`~dem.engines.contact_forces.forces` (-1 if none).
    """
    escaped = forces(law, particles, pairs, walls, wall_list, constants, dt, True, True)
    x_L, v_L, f_L, x_new, v_new, stats = trial.x_start, trial.v_start, trial.f_start, trial.x_new, trial.v_new, \
        trial.stats
    x_prev, f, mass, x_ref = particles.x, particles.f, particles.mass, pairs.x_ref
    change, motion, reach, finite = 0.0, 0.0, 0.0, 1.0
    for k in range(x_L.shape[0]):
        h = dt / mass[k]
        c2, m2, r2 = 0.0, 0.0, 0.0
        for a in range(3):
            vk = v_L[k, a] + h * (phi * f[k, a] + (1.0 - phi) * f_L[k, a])
            xk = x_L[k, a] + dt * (phi * vk + (1.0 - phi) * v_L[k, a])
            c2 += (xk - x_prev[k, a]) ** 2
            m2 += (xk - x_L[k, a]) ** 2
            r2 += (xk - x_ref[k, a]) ** 2
            v_new[k, a] = vk
            x_new[k, a] = xk
        if not (c2 + m2 < math.inf):
            finite = 0.0
        change += math.sqrt(c2)
        motion += math.sqrt(m2)
        reach = max(reach, r2)
    stats[0], stats[1], stats[2], stats[3] = change, motion, math.sqrt(reach), finite
    return escaped


@njit(cache=True)
def closed_pairs(x, radius, pi, pj, box):
    """Mask of the listed pairs that touch (``|x_i - x_j| < R_i + R_j``; the minimum image along the axes where
    ``box`` holds a period, :func:`dem.geometry.neighbours.min_image`)."""
    out = np.zeros(pi.shape[0], dtype=np.bool_)
    for c in range(pi.shape[0]):
        i, j = pi[c], pj[c]
        d2 = (min_image(x[i, 0] - x[j, 0], box[0]) ** 2 + min_image(x[i, 1] - x[j, 1], box[1]) ** 2
              + min_image(x[i, 2] - x[j, 2], box[2]) ** 2)
        s = radius[i] + radius[j]
        out[c] = d2 < s * s
    return out
