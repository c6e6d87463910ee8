"""The compiled kernels of the Zohdi 2014 mechanics: forces (eqs. 2-21) and one fixed-point iteration of the
trapezoidal step (eqs. 22-27).

Conventions (Zohdi 2014, eqs. 3-4): ``n_ij = (r_j - r_i)/|r_j - r_i|`` points from i to j; the strain ``E_ij =
(|r_i - r_j| - (R_i + R_j))/(R_i + R_j)`` is negative in contact; the contact force on i is ``-K_p |E|^p_p A_ij
n_ij`` (it pushes i away from j), the bond force ``+K_b |E|^p_b A_ij n_ij`` pulls it back. The particles do not
rotate (Sec. 2: "the effects of their rotation ... unimportant").

A wall is the plane ``n_w . x = q_w`` (normal into the packing) moving along its normal with the inward speed
``dq_w``; its contact force on particle k is ``K_w E^p_w A_k n_w`` with ``E = (R_k - dist)/R_k`` (eq. 14: the
overlap over the radius, as a pair's strain is its overlap over R_i + R_j) and ``A_k = pi (R_k^2 - dist^2)`` the
circle the plane cuts from the sphere (the lens of eqs. 7-12 with the plane for the second particle).

Friction (eqs. 5-6): ``mu_d |F_con| t`` with ``t = (v_j - v_i)/|v_j - v_i|`` the whole relative velocity, as the
paper writes it (so friction also opposes the approach of two particles, which is what makes their collisions
inelastic: the law has no normal damping). At a wall only the tangential velocity counts (eq. 17). The direction is
regularised, ``t = dv / sqrt(|dv|^2 + v_slip^2)``: a unit vector while sliding faster than ``v_slip``, proportional
to the slip below it, so that the fixed-point map stays continuous where the relative velocity passes through zero.

Bonds (eqs. 18-19): a pair whose strain reaches ``E*`` is bonded from the next step on (the flag is part of the
pair's history, committed when a step is accepted) and stays bonded while it touches. Within a step the flags are
fixed: a bond switched on between two iterates makes the force jump by ``K_b E*^p_b A``, and the fixed-point
iteration then stalls at the size of that jump instead of converging.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact.zohdi import (Z_C_ENV, Z_E_STAR, Z_KB, Z_KP, Z_KP_LIM, Z_KW, Z_KW_LIM, Z_MU, Z_PB, Z_PP, Z_PW,
                                Z_THETA_STAR, Z_V_SLIP)


@njit(cache=True)
def softened(k0, k_lim, theta, theta_star):
    """``max(K_0 (1 - theta/theta*), K_lim)`` (Zohdi 2014, Sec. 7)."""
    return max(k0 * (1.0 - theta / theta_star), k_lim)


@njit(cache=True)
def lens_area(ri, rj, d):
    """``pi a^2 = pi (R_i^2 - L_i^2)``, ``L_i = (d - (R_j^2 - R_i^2)/d)/2`` (Zohdi 2014, eqs. 7-12); 0 apart."""
    if d >= ri + rj or d <= 0.0:
        return 0.0
    li = 0.5 * (d - (rj * rj - ri * ri) / d)
    return math.pi * max(ri * ri - li * li, 0.0)


@njit(cache=True, error_model="numpy")
def forces(x, v, T, mass, radius, gravity, pi, pj, bonded, wn, wq, wk, wm, params, f, p_fn, p_area, p_bond, wforce):
    """Total forces ``f`` (eq. 21 plus gravity) at positions ``x``, velocities ``v``, temperatures ``T`` and wall
    offsets ``wq``: listed pairs ``(pi, pj)`` (``bonded``: the pair's bond is active), listed particle-wall pairs
    ``(wk, wm)``. Per pair it writes the net normal force (``p_fn``, > 0 repulsive), the contact area (``p_area``, 0
    when apart) and whether the pair is bonded at this state (``p_bond``: bonded, or ``|E| >= E*`` now); per wall the
    normal load (``wforce``, N).
    Returns the index into the wall list of a particle whose centre lies behind its wall, else -1."""
    n = x.shape[0]
    kp0, pp, kp_lim = params[Z_KP], params[Z_PP], params[Z_KP_LIM]
    kw0, pw, kw_lim = params[Z_KW], params[Z_PW], params[Z_KW_LIM]
    theta_star, kb, pb, e_star = params[Z_THETA_STAR], params[Z_KB], params[Z_PB], params[Z_E_STAR]
    mu, c_env, v_slip2 = params[Z_MU], params[Z_C_ENV], params[Z_V_SLIP] ** 2
    for k in range(n):
        drag = c_env * 6.0 * math.pi * radius[k]  # eq. 20 with c_env = c_env^o 6 pi R (Sec. 7), v_env = 0
        for a in range(3):
            f[k, a] = mass[k] * gravity[a] - drag * v[k, a]
    for c in range(pi.shape[0]):
        i, j = pi[c], pj[c]
        d0, d1, d2 = x[j, 0] - x[i, 0], x[j, 1] - x[i, 1], x[j, 2] - x[i, 2]
        d = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        ri, rj = radius[i], radius[j]
        area = lens_area(ri, rj, d)
        if area == 0.0:
            p_fn[c], p_area[c], p_bond[c] = 0.0, 0.0, 0
            continue
        strain = (ri + rj - d) / (ri + rj)  # |E_ij| (eq. 3)
        stiffness = softened(kp0, kp_lim, 0.5 * (T[i] + T[j]), theta_star)
        f_con = stiffness * strain**pp * area  # eq. 2
        bond = bonded[c] != 0  # eq. 19, activated by an earlier accepted step (eq. 18)
        f_n = f_con - (kb * strain**pb * area if bond else 0.0)
        n0, n1, n2 = d0 / d, d1 / d, d2 / d
        u0, u1, u2 = v[j, 0] - v[i, 0], v[j, 1] - v[i, 1], v[j, 2] - v[i, 2]  # eq. 6
        scale = mu * f_con / math.sqrt(u0 * u0 + u1 * u1 + u2 * u2 + v_slip2)
        g0, g1, g2 = -f_n * n0 + scale * u0, -f_n * n1 + scale * u1, -f_n * n2 + scale * u2
        f[i, 0] += g0
        f[i, 1] += g1
        f[i, 2] += g2
        f[j, 0] -= g0
        f[j, 1] -= g1
        f[j, 2] -= g2
        p_fn[c], p_area[c], p_bond[c] = f_n, area, 1 if bond or strain >= e_star else 0
    for m in range(wn.shape[0]):
        wforce[m] = 0.0
    escaped = -1
    for e in range(wk.shape[0]):
        k, m = wk[e], wm[e]
        rk = radius[k]
        n0, n1, n2 = wn[m, 0], wn[m, 1], wn[m, 2]
        dist = n0 * x[k, 0] + n1 * x[k, 1] + n2 * x[k, 2] - wq[m]
        if dist < 0.0 and escaped < 0:
            escaped = e
        if dist >= rk:
            continue
        strain = (rk - dist) / rk  # eq. 14
        stiffness = softened(kw0, kw_lim, T[k], theta_star)
        f_con = stiffness * strain**pw * math.pi * max(rk * rk - dist * dist, 0.0)  # eq. 13
        vn = v[k, 0] * n0 + v[k, 1] * n1 + v[k, 2] * n2
        t0, t1, t2 = v[k, 0] - vn * n0, v[k, 1] - vn * n1, v[k, 2] - vn * n2  # the wall slides along none of these
        scale = mu * f_con / math.sqrt(t0 * t0 + t1 * t1 + t2 * t2 + v_slip2)  # eqs. 16-17
        f[k, 0] += f_con * n0 - scale * t0
        f[k, 1] += f_con * n1 - scale * t1
        f[k, 2] += f_con * n2 - scale * t2
        wforce[m] += f_con
    return escaped


@njit(cache=True, error_model="numpy")
def iterate(dt, phi, x_L, v_L, f_L, x_prev, v_prev, T, mass, radius, gravity, pi, pj, bonded, wn, wq, wk, wm, params,
            f, p_fn, p_area, p_bond, wforce, x_new, v_new, x_ref, stats):
    """One fixed-point iteration K of the trapezoidal step (Zohdi 2014, eqs. 22-27): the forces at the previous
    iterate ``(x_prev, v_prev)`` (with the walls where they are at the end of the step), then::

        v^K = v^L + dt/m (phi F^(K-1) + (1 - phi) F^L)          (eq. 22)
        r^K = r^L + dt (phi v^K + (1 - phi) v^L)                 (eq. 23; together eq. 26)

    ``stats`` receives ``sum |r^K - r^(K-1)|``, ``sum |r^K - r^L|`` (Algorithm 1, step 4a), the largest distance of
    any particle from ``x_ref`` (where the Verlet list was built) and a NaN flag. Returns the escaped wall pair index
    of :func:`forces` (-1 if none)."""
    escaped = forces(x_prev, v_prev, T, mass, radius, gravity, pi, pj, bonded, wn, wq, wk, wm, params, f, p_fn, p_area,
                     p_bond, wforce)
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
