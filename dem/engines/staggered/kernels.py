"""The compiled kernels of the staggered implicit scheme (Zohdi 2014): one fixed-point iteration of the trapezoidal
step (eqs. 22-27) with the forces of the contact law (:func:`dem.engines.contact_forces.forces`), and the paper's
conduction law on the Verlet list.

Like :mod:`dem.engines.contact_forces`, this module is compiled for each contact law (:mod:`dem.engines.compiled`):
its import of the force loop is pointed at the law's copy.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.engines.contact_forces import forces
from dem.laws.contact.zohdi import lens_area


@njit(cache=True, error_model="numpy")
def iterate(dt, phi, x_L, v_L, f_L, x_prev, v_prev, T, mass, radius, gravity, pi, pj, p_hist_in, p_hist, p_fn,
            p_ft, wn, wq, wdq, wk, wm, w_hist_in, w_hist, w_fn, w_ft, params, f, w, tau, spin_axes, state, box, wforce,
            x_new, v_new, x_ref, stats):
    """One fixed-point iteration K of the trapezoidal step (Zohdi 2014, eqs. 22-27): the forces at the previous
    iterate ``(x_prev, v_prev)`` (with the walls where they are at the end of the step; the contacts' histories read
    from ``p_hist_in``/``w_hist_in``, those of the step's start, and written to ``p_hist``/``w_hist``), then::

        v^K = v^L + dt/m (phi F^(K-1) + (1 - phi) F^L)          (eq. 22)
        r^K = r^L + dt (phi v^K + (1 - phi) v^L)                 (eq. 23; together eq. 26)

    ``stats`` receives ``sum |r^K - r^(K-1)|``, ``sum |r^K - r^L|`` (Algorithm 1, step 4a), the largest distance of
    any particle from ``x_ref`` (where the Verlet list was built) and a NaN flag. Returns the escaped wall pair index
    of :func:`forces` (-1 if none)."""
    escaped = forces(x_prev, v_prev, w, f, tau, spin_axes, mass, radius, state, T, gravity, box, pi, pj, p_hist_in,
                     p_hist, p_fn, p_ft, wn, wq, wdq, wforce, wk, wm, w_hist_in, w_hist, w_fn, w_ft, params, dt)
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
def closed_pairs(x, radius, pi, pj):
    """Mask of the listed pairs that touch (``|x_i - x_j| < R_i + R_j``)."""
    out = np.zeros(pi.shape[0], dtype=np.bool_)
    for c in range(pi.shape[0]):
        i, j = pi[c], pj[c]
        d2 = (x[i, 0] - x[j, 0]) ** 2 + (x[i, 1] - x[j, 1]) ** 2 + (x[i, 2] - x[j, 2]) ** 2
        s = radius[i] + radius[j]
        out[c] = d2 < s * s
    return out


@njit(cache=True, error_model="numpy")
def lens_conduction(x, T, radius, kappa, contact_conductance, pi, pj, wn, wq, wall_T, wk, wm, Q):
    """``Q_i`` (W) of Zohdi 2014, eq. (33): ``K A_ij (theta_j - theta_i) / |r_i - r_j|`` over the touching listed
    pairs, written as the halves ``kappa_i A_ij / L_i`` in series (``L_i`` the centre-to-contact-plane distance of
    eq. 12; one material: exactly eq. 33) and a contact conductance ``contact_conductance`` in series (W/K; inf:
    none), and ``kappa_k A_k (theta_w - theta_k) / dist`` from every listed wall with a temperature (``wall_T``
    finite). The same law as :func:`dem.laws.conductance.half_conductance` with ``law = "zohdi"``, evaluated where
    the mechanics is, without building bonds. Returns the number of conducting pairs and wall contacts."""
    n = x.shape[0]
    for k in range(n):
        Q[k] = 0.0
    count = 0
    for c in range(pi.shape[0]):
        i, j = pi[c], pj[c]
        d = math.sqrt((x[j, 0] - x[i, 0]) ** 2 + (x[j, 1] - x[i, 1]) ** 2 + (x[j, 2] - x[i, 2]) ** 2)
        ri, rj = radius[i], radius[j]
        if d >= ri + rj or d <= 0.0:
            continue
        li = max(0.5 * (d - (rj * rj - ri * ri) / d), 0.0)
        lj = max(d - li, 0.0)
        small, l_small = (ri, li) if ri <= rj else (rj, lj)
        area = math.pi * max(small * small - l_small * l_small, 0.0)
        resistance = 1.0 / contact_conductance
        if li > 0.0:
            resistance += li / (kappa[i] * area)
        if lj > 0.0:
            resistance += lj / (kappa[j] * area)
        g = 1.0 / resistance
        flow = g * (T[j] - T[i])
        Q[i] += flow
        Q[j] -= flow
        count += 1
    for e in range(wk.shape[0]):
        k, m = wk[e], wm[e]
        if not math.isfinite(wall_T[m]):
            continue
        dist = wn[m, 0] * x[k, 0] + wn[m, 1] * x[k, 1] + wn[m, 2] * x[k, 2] - wq[m]
        rk = radius[k]
        if dist >= rk or dist <= 0.0:
            continue
        area = math.pi * (rk * rk - dist * dist)
        g = 1.0 / (dist / (kappa[k] * area) + 1.0 / contact_conductance)
        Q[k] += g * (wall_T[m] - T[k])
        count += 1
    return count
