r"""The forces and torques on particles that touch each other and plane walls, for any contact law: the one force
loop of every engine that moves particles.

The loop does the geometry and the bookkeeping; the contact law (:mod:`dem.laws.contact`) does the physics through its
kernels, bound at compile time: the loop takes the law as its first argument, whose numba type names the law
(:mod:`dem.laws.contact.binding`), so that numba inlines each law's kernels into a loop of its own (no dispatch at run
time) and caches it under the law's signature.

Contact geometry (Luding 2005, eqs. 3, 17-18): :math:`\mathbf{n}` points from :math:`j` to :math:`i`, the overlap is
:math:`\delta = a_i + a_j - |\mathbf{x}_i - \mathbf{x}_j|`, the relative surface velocity
:math:`\mathbf{v}_{ij} = \mathbf{v}_i - \mathbf{v}_j + l_i \mathbf{n} \times \boldsymbol{\omega}_i
+ l_j \mathbf{n} \times \boldsymbol{\omega}_j`; the force on :math:`i` is :math:`f_n \mathbf{n} + \mathbf{f}_t` and the
torque :math:`-l_i \mathbf{n} \times \mathbf{f}_t`. The lever arms reach the middle of the overlap,
:math:`l = a - \delta/2` (as LAMMPS does), rather than the paper's :math:`a`: then
:math:`l_i + l_j = |\mathbf{x}_i - \mathbf{x}_j|` and a contact conserves angular momentum exactly (with :math:`a` it
would create :math:`-\delta \, \mathbf{n} \times \mathbf{f}_t`; the difference is of order :math:`\delta/a`). A wall is
the partner :math:`j` with an infinite radius, moving along its normal. A pair acts while its surfaces are closer than
the law's ``reach``, a particle-wall pair while closer than its ``wall_reach`` (0: while they overlap; an adhesive law
holds a contact beyond touching until it breaks); the laws whose particles do not rotate (its ``SPINS`` false) get no
torques.

Latency: a pair's geometry (a square root, then divisions) and its law form one long chain of dependent
operations, and the processor overlaps two pairs only as far as its window of instructions reaches. So the
loop begins the next pair's geometry (:func:`pair_geometry`) before the law of this one: the same
operations on the same numbers (the results do not change), but the next square root and divisions run while this
pair's law is computed. (For an open pair that geometry is not needed: a few operations spent to keep the chain
short for the closed ones, most of a dense packing's list.)

Threads: in the copies of this module for more than one thread (:mod:`dem.engines.compiled`) ``THREADED`` is true and
the pairs are cut into one block of consecutive pairs per thread. A particle belongs to the block of its first pair in
the list (:func:`split_incidences`): that block's thread adds the particle's pairs in it straight into its force and
torque, as the one-thread loop does, and no other thread writes them. A pair whose particle belongs to an earlier block
writes its force and torque arms into a row of its own (``load``) instead, and after the blocks every particle adds
those rows, in the order of the list (on one thread: they are few, and a parallel loop costs more to start than they
take). Each particle's sum thus runs in the order of the list, the order in which the one-thread loop adds its pairs, so
the results are the same to the bit on any number of threads; only the pairs at the blocks' seams are written twice. The
flag is a compile-time constant: the one-thread loop carries nothing of the threaded one.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from dem.geometry.neighbours import min_image
from dem.laws.contact import binding

# The force loop's floating-point flags: no NaN, no infinity (positions are checked finite before forces are
# computed), no signed zeros. They let the compiler drop products with a zero it knows (the y terms of 2D disks),
# and change no result: without reassociation, contraction or approximate reciprocals every operation on finite
# numbers stays the IEEE one.
FINITE_MATH = {"nnan", "ninf", "nsz"}
THREADED = False  # True in the copies for more than one thread (dem.engines.compiled)
LOAD_COLUMNS = 9  # a pair's row of the threaded loop's buffer: g = f_n n + f_t (3), n x f_t (3), l_i, l_j, closed


@njit(cache=True)
def pair_blocks(n_pairs, n_blocks):
    """How many blocks of consecutive pairs the threaded loop cuts ``n_pairs`` into for ``n_blocks`` threads: block
    ``b`` holds the pairs ``b n_pairs // blocks`` up to ``(b + 1) n_pairs // blocks``."""
    return max(1, min(n_blocks, n_pairs))


@njit(cache=True)
def split_incidences(pi, pj, n, n_blocks):
    """The threaded loop's view of the list for ``n_blocks`` threads (module docstring): ``(owner, start, pairs)``,
    the block of each particle's first pair (-1 for a particle in none), and each particle's pairs outside that
    block in the order of the list: particle k's are ``pairs[start[k]:start[k + 1]]``, ``c`` where k is the pair's
    i, ``~c`` (= -1 - c) where it is its j."""
    m = pi.shape[0]
    blocks = pair_blocks(m, n_blocks)
    owner = np.full(n, -1, dtype=np.int64)
    block = np.empty(m, dtype=np.int64)
    for b in range(blocks):
        for c in range(b * m // blocks, (b + 1) * m // blocks):
            block[c] = b
    start = np.zeros(n + 1, dtype=np.int64)
    for c in range(m):
        for k in (pi[c], pj[c]):
            if owner[k] < 0:
                owner[k] = block[c]
            elif block[c] != owner[k]:
                start[k + 1] += 1
    for k in range(n):
        start[k + 1] += start[k]
    fill = start[:-1].copy()
    pairs = np.empty(start[n], dtype=np.int64)
    for c in range(m):
        if block[c] != owner[pi[c]]:
            pairs[fill[pi[c]]] = c
            fill[pi[c]] += 1
        if block[c] != owner[pj[c]]:
            pairs[fill[pj[c]]] = ~c
            fill[pj[c]] += 1
    return owner, start, pairs


@njit(cache=True, error_model="numpy", fastmath=FINITE_MATH, inline="always")
def add_pair_share(law, f, tau, k, sign, g, arm, m, planar):
    """Particle ``k``'s share of a pair's force and torque: ``sign g`` into its force (``sign`` +1 for the pair's i,
    -1 for its j; ``g = f_n n + f_t``, a 3-tuple) and ``-arm m`` into its torque, ``m = n x f_t`` (a 3-tuple) and
    ``arm`` its lever ``l_i`` or ``l_j`` (module docstring). (``x - g`` and ``x + (-1) g`` are the same number.)"""
    g0, g1, g2 = g
    m0, m1, m2 = m
    f[k, 0] += sign * g0
    f[k, 1] += sign * g1
    f[k, 2] += sign * g2
    if binding.spins(law):
        tau[k, 1] -= arm * m1
        if not planar:
            tau[k, 0] -= arm * m0
            tau[k, 2] -= arm * m2


@njit(cache=True, error_model="numpy", fastmath=FINITE_MATH, inline="always")
def pair_geometry(c, x, pi, pj, box, planar):
    """The listed pair ``c`` = (i, j): ``(d2, d, n0, n1, n2)``, the squared distance of the centres (minimum image),
    the distance and the unit normal from j to i (0 where the centres coincide)."""
    i, j = np.uint64(pi[c]), np.uint64(pj[c])
    dx = min_image(x[i, 0] - x[j, 0], box[0])
    dy = 0.0 if planar else min_image(x[i, 1] - x[j, 1], box[1])
    dz = min_image(x[i, 2] - x[j, 2], box[2])
    d2 = dx * dx + dy * dy + dz * dz
    d = math.sqrt(d2)
    q = d if d2 > 0.0 else 1.0
    return d2, d, dx / q, dy / q, dz / q


@njit(cache=True, error_model="numpy", fastmath=FINITE_MATH, inline="never" if THREADED else "always")
def contact_tuple(delta, d, n0, n1, n2, vr0, vr1, vr2, vn):
    r"""The contact as the laws' kernels read it: the tuple :math:`(\delta, d, n, v_{ij}, v_n)` of the overlap (m),
    the distance of the centres (m), the unit normal (a 3-tuple), the relative velocity (m/s, a 3-tuple) and its
    normal part (m/s). In the threaded copies numba does not inline it: the parallel loop's array analysis reads a
    tuple built in place as array dimensions and fails on the nested ones."""
    return delta, d, (n0, n1, n2), (vr0, vr1, vr2), vn


@njit(cache=True, error_model="numpy", fastmath=FINITE_MATH, parallel=THREADED)
def forces(law, particles, pairs, walls, wall_list, constants, dt, fresh, record):
    """Forces and torques of the current state under the contact law ``law`` (a
    :class:`~dem.laws.contact.binding.ContactLaw`): gravity, the law's drag, the listed pairs, the listed
    particle-wall pairs; the normal forces on the walls go into ``walls.force``. Returns the index into the wall list
    of the first particle whose centre lies behind its wall, else -1.

    Parameters
    ----------
    law : dem.laws.contact.binding.ContactLaw
        The contact law, bound at compile time.
    particles : dem.engines.records.Particles
        The particles; their forces ``f`` and torques ``tau`` are written.
    pairs : dem.engines.records.PairList
        The Verlet list of pairs.
    walls : dem.geometry.walls.WallArrays
        The walls.
    wall_list : dem.engines.records.WallList
        The particle-wall list.
    constants : dem.engines.records.Constants
        Gravity, the periodic box and the law's material.
    dt : float
        The step the contacts' histories advance by (s; 0: none).
    fresh : bool
        Whether the pairs' numbers of the radii alone are computed (below), not read.
    record : bool
        Whether the contact forces are kept (``pairs.fn``, ``pairs.ft``).

    Notes
    -----
    Each contact's history is read from ``hist_in`` and written to ``hist`` of its list: the same arrays for a step
    that is taken (velocity Verlet), others for an iterate that may be discarded (the implicit scheme). With
    ``record`` the pair forces are kept (outputs only, so a time loop records them on the last step of a call).
    ``pairs.const`` (M, 2) holds the listed pairs' numbers that depend on their radii alone (the law's
    ``pair_constants``, where it keeps any): ``fresh`` computes them (and keeps them there when it has rows), else
    they are read from there; a time loop passes ``fresh`` where the radii or the list changed. ``spin_axes``
    (:attr:`dem.engines.state.MotionState.spin_axes`): ``(1,)`` for 2D disks in the x-z plane, whose pair terms
    along y vanish.

    The law's kernels are inlined right here, scalars and 3-tuples in and out, with the material as a tuple: an
    array argument costs an atomic reference count per call (a quarter of the loop). The length of ``spin_axes`` is
    part of its type, so 2D and 3D get code of their own, the 2D one without the terms that vanish (a fifth
    faster).

    Where ``THREADED`` (module docstring), the list's ``owner``, ``start`` and ``order`` are
    :func:`split_incidences` of the list for ``n_blocks`` threads and ``load`` a ``(M, LOAD_COLUMNS)`` buffer; the
    walls stay on one thread (a few particles: the surface's).
    """
    x, v, w, f, tau, spin_axes = particles.x, particles.v, particles.w, particles.f, particles.tau, particles.spin_axes
    mass, radius, state, T = particles.mass, particles.radius, particles.state, particles.T
    pi, pj, p_hist_in, p_hist, p_fn, p_ft = pairs.i, pairs.j, pairs.hist_in, pairs.hist, pairs.fn, pairs.ft
    p_const, owner, start, order, load, n_blocks = pairs.const, pairs.owner, pairs.start, pairs.order, pairs.load, \
        pairs.n_blocks
    wn, wq, wdq, wforce = walls.normal, walls.q, walls.dq, walls.force
    wk, wm, w_hist_in, w_hist, w_fn, w_ft = wall_list.k, wall_list.m, wall_list.hist_in, wall_list.hist, \
        wall_list.fn, wall_list.ft
    gravity, box, param_array = constants.gravity, constants.box, constants.params
    planar = len(spin_axes) == 1
    escaped = -1
    n = x.shape[0]
    params = binding.params_tuple(law, param_array)
    for k in range(n):
        if binding.has_drag(law):
            drag = binding.drag(law, k, radius, params)
            f[k, 0] = mass[k] * gravity[0] - drag * v[k, 0]
            f[k, 1] = mass[k] * gravity[1] - drag * v[k, 1]
            f[k, 2] = mass[k] * gravity[2] - drag * v[k, 2]
        else:
            f[k, 0] = mass[k] * gravity[0]
            f[k, 1] = mass[k] * gravity[1]
            f[k, 2] = mass[k] * gravity[2]
        tau[k, 0] = 0.0
        tau[k, 1] = 0.0
        tau[k, 2] = 0.0
    n_pairs = pi.shape[0]
    blocks = pair_blocks(n_pairs, n_blocks) if THREADED else 1
    for b in prange(blocks):  # one block on one thread; on more, a block of consecutive pairs per thread
        first, stop = b * n_pairs // blocks, (b + 1) * n_pairs // blocks
        block_params = binding.params_tuple(law, param_array)  # the block's own: a parallel loop takes no nested tuple
        ahead = (0.0, 0.0, 0.0, 0.0, 0.0)  # the next pair's geometry, begun before this pair's law (module docstring)
        if first < stop:
            ahead = pair_geometry(first, x, pi, pj, box, planar)
        for c in range(first, stop):
            i, j = np.uint64(pi[c]), np.uint64(pj[c])  # unsigned: no wrap-around of negative indices
            d2, d, n0, n1, n2 = ahead
            if c + 1 < stop:
                ahead = pair_geometry(c + 1, x, pi, pj, box, planar)
            ri, rj = radius[i], radius[j]
            if binding.keeps_pair_constants(law) and not fresh:  # (read here: an array passed to a kernel costs)
                const = (p_const[c, 0], p_const[c, 1])
            else:  # every listed pair's: it may close later
                const = binding.pair_constants(law, ri, rj, block_params)
                if binding.keeps_pair_constants(law) and p_const.shape[0]:
                    p_const[c, 0], p_const[c, 1] = const
            cut = ri + rj + binding.reach(law, c, p_hist_in, ri, rj, block_params)
            if d2 >= cut * cut or d2 == 0.0:
                binding.forget_pair(law, c, p_hist_in, p_hist)  # the contact opened: it forgets its history
                if record:
                    p_fn[c] = 0.0
                    p_ft[c, 0], p_ft[c, 1], p_ft[c, 2] = 0.0, 0.0, 0.0
                if THREADED:
                    load[c, 8] = 0.0  # open: no load
                continue
            delta = ri + rj - d
            li, lj = ri - 0.5 * delta, rj - 0.5 * delta  # lever arms to the middle of the overlap: li + lj = d
            # v_ij = v_i - v_j + l_i n x w_i + l_j n x w_j  (Luding 2005, eq. 18)
            c0 = 0.0 if planar else li * w[i, 0] + lj * w[j, 0]
            c1 = li * w[i, 1] + lj * w[j, 1]
            c2 = 0.0 if planar else li * w[i, 2] + lj * w[j, 2]
            vr0 = v[i, 0] - v[j, 0] + n1 * c2 - n2 * c1
            vr1 = 0.0 if planar else v[i, 1] - v[j, 1] + n2 * c0 - n0 * c2
            vr2 = v[i, 2] - v[j, 2] + n0 * c1 - n1 * c0
            vn = vr0 * n0 + vr1 * n1 + vr2 * n2
            f_n, ft0, ft1, ft2 = binding.pair_force(law, c, i, j, p_hist_in, p_hist, state, T,
                                                    contact_tuple(delta, d, n0, n1, n2, vr0, vr1, vr2, vn), ri, rj,
                                                    planar, dt, block_params, const)
            if record:  # (2D disks: the y force recorded as +0 on any number of threads; under the flag nsz the
                # compiler may give a zero either sign, and it compiles the threaded loop's body on its own)
                p_fn[c] = f_n
                p_ft[c, 0], p_ft[c, 1], p_ft[c, 2] = ft0, 0.0 if planar else ft1, ft2
            g0, g1, g2 = f_n * n0 + ft0, f_n * n1 + ft1, f_n * n2 + ft2
            # torques -l n x f_t on both (the lever arms -l_i n and +l_j n, the forces f_t and -f_t)
            m0, m1, m2 = n1 * ft2 - n2 * ft1, n2 * ft0 - n0 * ft2, n0 * ft1 - n1 * ft0
            add_i, add_j = True, True
            if THREADED:  # this block's particles here; for a particle of an earlier block, into the pair's row
                add_i, add_j = owner[i] == b, owner[j] == b
                if not (add_i and add_j):
                    load[c, 0], load[c, 1], load[c, 2], load[c, 3], load[c, 4], load[c, 5] = g0, g1, g2, m0, m1, m2
                    load[c, 6], load[c, 7], load[c, 8] = li, lj, 1.0
            if add_i:
                add_pair_share(law, f, tau, i, 1.0, (g0, g1, g2), li, (m0, m1, m2), planar)
            if add_j:
                add_pair_share(law, f, tau, j, -1.0, (g0, g1, g2), lj, (m0, m1, m2), planar)
    if THREADED:
        for k in range(n):  # each particle the rows of its pairs in later blocks, in the order of the list
            for e in range(start[k], start[k + 1]):
                c = order[e]
                sign, arm = (1.0, 6) if c >= 0 else (-1.0, 7)
                c = c if c >= 0 else ~c
                if load[c, 8] == 0.0:
                    continue
                add_pair_share(law, f, tau, k, sign, (load[c, 0], load[c, 1], load[c, 2]), load[c, arm],
                               (load[c, 3], load[c, 4], load[c, 5]), planar)
    n_w = wn.shape[0]
    for m in range(n_w):
        wforce[m] = 0.0
    for e in range(wk.shape[0]):
        k, m = wk[e], wm[e]
        rk = radius[k]
        n0, n1, n2 = wn[m, 0], wn[m, 1], wn[m, 2]
        dist = n0 * x[k, 0] + n1 * x[k, 1] + n2 * x[k, 2] - wq[m]
        if dist < 0.0 and escaped < 0:
            escaped = e
        delta = rk - dist
        if delta <= -binding.wall_reach(law, k, m, w_hist_in, rk, params):
            if binding.forget_wall(law, k, m, w_hist_in, w_hist):  # (rare: a wall contact opening)
                w_fn[k, m] = 0.0
                w_ft[k, m, 0], w_ft[k, m, 1], w_ft[k, m, 2] = 0.0, 0.0, 0.0
            continue
        lk = rk - 0.5 * delta
        vr0 = v[k, 0] - wdq[m] * n0 + lk * (n1 * w[k, 2] - n2 * w[k, 1])
        vr1 = v[k, 1] - wdq[m] * n1 + lk * (n2 * w[k, 0] - n0 * w[k, 2])
        vr2 = v[k, 2] - wdq[m] * n2 + lk * (n0 * w[k, 1] - n1 * w[k, 0])
        vn = vr0 * n0 + vr1 * n1 + vr2 * n2
        f_n, ft0, ft1, ft2 = binding.wall_force(law, k, m, w_hist_in, w_hist, state, T,
                                                contact_tuple(delta, dist, n0, n1, n2, vr0, vr1, vr2, vn), rk, dt,
                                                params)
        w_fn[k, m] = f_n
        w_ft[k, m, 0], w_ft[k, m, 1], w_ft[k, m, 2] = ft0, ft1, ft2
        f[k, 0] += f_n * n0 + ft0
        f[k, 1] += f_n * n1 + ft1
        f[k, 2] += f_n * n2 + ft2
        if binding.spins(law):
            tau[k, 0] -= lk * (n1 * ft2 - n2 * ft1)
            tau[k, 1] -= lk * (n2 * ft0 - n0 * ft2)
            tau[k, 2] -= lk * (n0 * ft1 - n1 * ft0)
        wforce[m] += f_n
    return escaped
