"""The compiled time loop of the mechanics: velocity-Verlet steps with the Luding 2005 contact law.

One call advances the particles (and the walls) by up to ``n_steps`` steps of ``dt``, entirely in compiled code
(numba), and returns early only when the caller must act: the Verlet lists are about to become invalid (a
particle, plus the farthest-moved wall, has moved more than half the skin since they were built), a position became
non-finite, or a particle left through a wall. Besides the pair list there is a particle-wall list: the particles
within ``radius + skin`` of each wall (the only ones that can touch it or cross it before the next rebuild). Each
step:

1. half kick and drift: ``v += dt/2 f/m``, ``x += dt v`` (and ``omega += dt/2 tau/I``); walls move by their law
   (:mod:`dem.geometry.walls`);
2. material state: the temperature ``T_i(t) = T0_i + rate_i (t - t_first)``, the radius ``a(T)`` (Luding 2005,
   eq. 9), the stiffness factor ``k1(T, t)/k1`` relaxed towards ``k1(T)/k1`` (eqs. 10-12);
3. forces: gravity, every listed pair (normal law eqs. 3-13, tangential eqs. 14-24) and every particle-wall
   contact, summed into forces and torques;
4. second half kick (velocities at the end of the step); stress-controlled walls from eq. 1.

Contact geometry (Luding 2005, eqs. 3, 17-18): ``n`` points from j to i, the overlap is ``delta = a_i + a_j -
|x_i - x_j|``, the relative surface velocity ``v_ij = v_i - v_j + l_i n x omega_i + l_j n x omega_j``; the force on
i is ``f_n n + f_t`` and the torque ``-l_i n x f_t``. The lever arms reach the middle of the overlap, ``l = a -
delta/2`` (as LAMMPS does), rather than the paper's ``a``: then ``l_i + l_j = |x_i - x_j|`` and a contact conserves
angular momentum exactly (with ``a`` it would create ``-delta n x f_t``; the difference is of order delta/a). A
wall is the partner j with an infinite radius, moving along its normal.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from numba.np.unsafe.ndarray import to_fixed_tuple

from dem.laws.contact.luding import N_PARAMS, P_EXPANSION, P_FLUID_OVERLAP, P_T_MELT, P_T_VAR
from dem.laws.contact.luding_kernels import k1_factor, normal_force, radius_at, relax_k1, tangential_force
from dem.geometry.neighbours import min_image

DONE, REBUILD, NONFINITE, ESCAPED = 0, 1, 2, 3
# The force loop's floating-point flags: no NaN, no infinity (positions are checked finite before forces are
# computed), no signed zeros. They let the compiler drop products with a zero it knows (the y terms of 2D disks),
# and change no result: without reassociation, contraction or approximate reciprocals every operation on finite
# numbers stays the IEEE one.
FINITE_MATH = {"nnan", "ninf", "nsz"}
STATUS = {DONE: "done", REBUILD: "rebuild", NONFINITE: "non-finite", ESCAPED: "escaped"}


@njit(cache=True, error_model="numpy", fastmath=FINITE_MATH)
def _forces(x, v, w, f, tau, spin_axes, mass, radius, k1f, gravity, box, pi, pj, p_dmax, p_k1last, p_xi, p_fn, p_ft,
            wn, wq, wdq, wforce, wk, wm, w_dmax, w_k1last, w_xi, w_fn, w_ft, params, dt, record=True):
    """Forces and torques of the current state (gravity, pairs, the listed particle-wall pairs ``(wk, wm)``); the
    normal forces on the walls go into ``wforce``. Returns the index into the wall list of the first particle whose
    centre lies behind its wall, else -1. With ``record`` the contact forces are kept (``p_fn``, ``p_ft``, ``w_fn``,
    ``w_ft``: outputs only, so the time loop records them on the last step of a call). ``spin_axes``
    (:attr:`dem.geometry.motion.MotionState.spin_axes`): ``(1,)`` for 2D disks in the x-z plane, whose pair terms along y
    vanish.

    The contact kernels are inlined right here, scalars and 3-tuples in and out, with the material as a tuple: an
    array argument costs an atomic reference count per call (a quarter of the loop), and wrapping the kernels in a
    helper returning their eight results 30 % more. The length of ``spin_axes`` is part of its type, so 2D and 3D
    get code of their own, the 2D one without the terms that vanish (a fifth faster)."""
    planar = len(spin_axes) == 1
    escaped = -1
    n = x.shape[0]
    phi = params[P_FLUID_OVERLAP]
    params = to_fixed_tuple(params, N_PARAMS)
    for k in range(n):
        f[k, 0] = mass[k] * gravity[0]
        f[k, 1] = mass[k] * gravity[1]
        f[k, 2] = mass[k] * gravity[2]
        tau[k, 0] = 0.0
        tau[k, 1] = 0.0
        tau[k, 2] = 0.0
    for c in range(pi.shape[0]):
        i, j = pi[c], pj[c]
        dx = min_image(x[i, 0] - x[j, 0], box[0])
        dy = 0.0 if planar else min_image(x[i, 1] - x[j, 1], box[1])
        dz = min_image(x[i, 2] - x[j, 2], box[2])
        ri, rj = radius[i], radius[j]
        d2 = dx * dx + dy * dy + dz * dz
        if d2 >= (ri + rj) * (ri + rj) or d2 == 0.0:
            if p_dmax[c] != 0.0:  # the contact opened: it forgets its history
                p_dmax[c] = 0.0
                p_xi[c, 0], p_xi[c, 1], p_xi[c, 2] = 0.0, 0.0, 0.0
            if record:
                p_fn[c] = 0.0
                p_ft[c, 0], p_ft[c, 1], p_ft[c, 2] = 0.0, 0.0, 0.0
            continue
        d = math.sqrt(d2)
        n0, n1, n2 = dx / d, dy / d, dz / d
        delta = ri + rj - d
        li, lj = ri - 0.5 * delta, rj - 0.5 * delta  # lever arms to the middle of the overlap: li + lj = d
        # v_ij = v_i - v_j + l_i n x w_i + l_j n x w_j  (Luding 2005, eq. 18)
        c0 = 0.0 if planar else li * w[i, 0] + lj * w[j, 0]
        c1 = li * w[i, 1] + lj * w[j, 1]
        c2 = 0.0 if planar else li * w[i, 2] + lj * w[j, 2]
        vr0 = v[i, 0] - v[j, 0] + n1 * c2 - n2 * c1
        vr1 = 0.0 if planar else v[i, 1] - v[j, 1] + n2 * c0 - n0 * c2
        vr2 = v[i, 2] - v[j, 2] + n0 * c1 - n1 * c0
        k1c = 0.5 * (k1f[i] + k1f[j])
        vn = vr0 * n0 + vr1 * n1 + vr2 * n2
        f_n, dmax, f_min, k2_now, kc_now, d0 = normal_force(delta, -vn, k1c, p_dmax[c], p_k1last[c],
                                                            phi * 2.0 * ri * rj / (ri + rj), params)
        xi_y = 0.0 if planar else p_xi[c, 1]
        ft, xi, sliding, f_n = tangential_force((p_xi[c, 0], xi_y, p_xi[c, 2]), (n0, n1, n2),
                                                (vr0 - vn * n0, vr1 - vn * n1, vr2 - vn * n2), f_n, f_min, k2_now,
                                                k1c, dt, params, False)
        ft0, ft1, ft2 = ft
        p_dmax[c] = dmax
        p_k1last[c] = k1c
        p_xi[c, 0], p_xi[c, 1], p_xi[c, 2] = xi
        if record:
            p_fn[c] = f_n
            p_ft[c, 0], p_ft[c, 1], p_ft[c, 2] = ft0, ft1, ft2
        g0, g1, g2 = f_n * n0 + ft0, f_n * n1 + ft1, f_n * n2 + ft2
        f[i, 0] += g0
        f[i, 1] += g1
        f[i, 2] += g2
        f[j, 0] -= g0
        f[j, 1] -= g1
        f[j, 2] -= g2
        # torques -l n x f_t on both (the lever arms -l_i n and +l_j n, the forces f_t and -f_t)
        m0, m1, m2 = n1 * ft2 - n2 * ft1, n2 * ft0 - n0 * ft2, n0 * ft1 - n1 * ft0
        tau[i, 1] -= li * m1
        tau[j, 1] -= lj * m1
        if not planar:
            tau[i, 0] -= li * m0
            tau[i, 2] -= li * m2
            tau[j, 0] -= lj * m0
            tau[j, 2] -= lj * m2
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
        if delta <= 0.0:
            if w_dmax[k, m] != 0.0:
                w_dmax[k, m] = 0.0
                w_xi[k, m, 0], w_xi[k, m, 1], w_xi[k, m, 2] = 0.0, 0.0, 0.0
                w_fn[k, m] = 0.0  # (rare: a wall contact opening; kept unconditionally)
                w_ft[k, m, 0], w_ft[k, m, 1], w_ft[k, m, 2] = 0.0, 0.0, 0.0
            continue
        lk = rk - 0.5 * delta
        vr0 = v[k, 0] - wdq[m] * n0 + lk * (n1 * w[k, 2] - n2 * w[k, 1])
        vr1 = v[k, 1] - wdq[m] * n1 + lk * (n2 * w[k, 0] - n0 * w[k, 2])
        vr2 = v[k, 2] - wdq[m] * n2 + lk * (n0 * w[k, 1] - n1 * w[k, 0])
        vn = vr0 * n0 + vr1 * n1 + vr2 * n2
        f_n, dmax, f_min, k2_now, kc_now, d0 = normal_force(delta, -vn, k1f[k], w_dmax[k, m], w_k1last[k, m],
                                                            phi * rk, params)
        ft, xi, sliding, f_n = tangential_force((w_xi[k, m, 0], w_xi[k, m, 1], w_xi[k, m, 2]), (n0, n1, n2),
                                                (vr0 - vn * n0, vr1 - vn * n1, vr2 - vn * n2), f_n, f_min, k2_now,
                                                k1f[k], dt, params, True)
        ft0, ft1, ft2 = ft
        w_dmax[k, m] = dmax
        w_k1last[k, m] = k1f[k]
        w_xi[k, m, 0], w_xi[k, m, 1], w_xi[k, m, 2] = xi
        w_fn[k, m] = f_n
        w_ft[k, m, 0], w_ft[k, m, 1], w_ft[k, m, 2] = ft0, ft1, ft2
        f[k, 0] += f_n * n0 + ft0
        f[k, 1] += f_n * n1 + ft1
        f[k, 2] += f_n * n2 + ft2
        tau[k, 0] -= lk * (n1 * ft2 - n2 * ft1)
        tau[k, 1] -= lk * (n2 * ft0 - n0 * ft2)
        tau[k, 2] -= lk * (n0 * ft1 - n1 * ft0)
        wforce[m] += f_n
    return escaped


@njit(cache=True, error_model="numpy")
def _wall_acceleration(m, wq, wdq, wmode, wpress, wmass, wdamp, wspan, wforce):
    """Eq. (1) of Luding 2005 for stress wall ``m``: ``(p L - F_w - gamma_w dq/dt) / m_w``."""
    if wmode[m] != 1:
        return 0.0
    extent = 1.0
    for a in range(2):
        lo, hi = wspan[m, 2 * a], wspan[m, 2 * a + 1]
        if lo >= 0:
            extent *= -(wq[lo] + wq[hi])
    return (wpress[m] * extent - wforce[m] - wdamp[m] * wdq[m]) / wmass[m]


@njit(cache=True, error_model="numpy")
def _material_state(elapsed, T0, T_rate, T, radius, radius_ref, k1f, uniform, params, t0, dt):
    """Temperatures at ``t``, radii (eq. 9) and stiffness factors relaxed over one step (eqs. 10-12)."""
    T_melt, T_var, expansion = params[P_T_MELT], params[P_T_VAR], params[P_EXPANSION]
    n = T.shape[0]
    if uniform:
        Tu = T0[0] + T_rate[0] * elapsed
        target = k1_factor(Tu, T_melt, T_var)
        scale = radius_at(1.0, Tu, T_melt, expansion)
        cooling = T_rate[0] < 0.0
        old = k1f[0]
        new = relax_k1(old, target, dt, t0, cooling)  # the factors of a uniform temperature are all equal
        for k in range(n):
            T[k] = Tu
            radius[k] = radius_ref[k] * scale
            k1f[k] = new if k1f[k] == old else relax_k1(k1f[k], target, dt, t0, cooling)
    else:
        for k in range(n):
            T[k] = T0[k] + T_rate[k] * elapsed
            radius[k] = radius_at(radius_ref[k], T[k], T_melt, expansion)
            k1f[k] = relax_k1(k1f[k], k1_factor(T[k], T_melt, T_var), dt, t0, T_rate[k] < 0.0)


@njit(cache=True, error_model="numpy")
def advance(n_steps, dt, step0, first, x, v, w, f, tau, mass, inertia, axes, spin_axes, radius, radius_ref, T0, T_rate,
            T, k1f,
            uniform_T, t0, gravity, box, pi, pj, p_dmax, p_k1last, p_xi, p_fn, p_ft,
            wn, wq, wdq, wacc, wmode, wpress, wmass, wdamp, wq0, wamp, wfreq, wspan, wforce, wk, wm, wq_ref,
            w_dmax, w_k1last, w_xi, w_fn, w_ft, params, x_ref, skin, info):
    """Up to ``n_steps`` velocity-Verlet steps (module docstring) from global step ``step0`` (t = step0 dt) of an
    interval that began at step ``first`` with temperatures ``T0`` (``T0 + T_rate (t - first dt)`` after it): times
    come from step counts, so where a run is split into calls (rebuilds, a resume) never changes its arithmetic.
    ``f``/``tau``/``wacc`` must hold the forces of the current state on entry. Returns ``(steps done, status)``;
    ``info`` receives the particle (and wall) index of a non-finite or escaped particle."""
    n = x.shape[0]
    n_w = wn.shape[0]
    h = 0.5 * dt
    for s in range(n_steps):
        t = (step0 + s) * dt
        for k in range(n):
            im, ii = 1.0 / mass[k], 1.0 / inertia[k]
            moved = 0.0
            for a in axes:
                v[k, a] += h * f[k, a] * im
                x[k, a] += dt * v[k, a]
                moved += abs(x[k, a])
            for a in spin_axes:
                w[k, a] += h * tau[k, a] * ii
                moved += abs(w[k, a])
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
        _material_state((step0 + s + 1 - first) * dt, T0, T_rate, T, radius, radius_ref, k1f, uniform_T, params, t0,
                        dt)
        escaped = _forces(x, v, w, f, tau, spin_axes, mass, radius, k1f, gravity, box, pi, pj, p_dmax, p_k1last,
                          p_xi, p_fn, p_ft, wn, wq, wdq, wforce, wk, wm, w_dmax, w_k1last, w_xi, w_fn, w_ft, params, dt,
                          s == n_steps - 1)
        worst = 0.0
        for k in range(n):
            im, ii = 1.0 / mass[k], 1.0 / inertia[k]
            d2 = 0.0
            for a in axes:
                v[k, a] += h * f[k, a] * im
                d = min_image(x[k, a] + dt * v[k, a] - x_ref[k, a], box[a])
                d2 += d * d
            for a in spin_axes:
                w[k, a] += h * tau[k, a] * ii
            if not (d2 < math.inf):  # NaN or inf
                info[0] = k
                return s + 1, 2
            worst = max(worst, d2)
        wall_moved = 0.0
        for m in range(n_w):
            if wmode[m] == 1:
                wacc[m] = _wall_acceleration(m, wq, wdq, wmode, wpress, wmass, wdamp, wspan, wforce)
                wdq[m] += h * wacc[m]
            wall_moved = max(wall_moved, abs(wq[m] + dt * wdq[m] - wq_ref[m]))
        if escaped >= 0:
            info[0] = wk[escaped]
            info[1] = wm[escaped]
            return s + 1, 3
        if math.sqrt(worst) + wall_moved > 0.5 * skin:
            return s + 1, 1
    return n_steps, 0
