"""The sintering contact law of Luding, Manetsberger & Müllers 2005 as compiled scalar kernels.

The kernels are ``numba.njit(cache=True)`` functions of plain floats and 3-tuples and the material ``params``
(:meth:`dem.laws.contact.luding.LudingMaterial.params`, indices ``P_*``; an array, or the same numbers as a tuple), called
per contact from the engine's compiled loop (:mod:`dem.engines.verlet.loop`, which passes a tuple and gets the kernels it calls
inlined) and, unchanged, from Python (the contact-law tool ``python -m dem contact`` and the tests). Conventions and
the history each contact carries: :mod:`dem.laws.contact.luding`.
"""

from __future__ import annotations

import math

from numba import njit

from dem.laws.contact.luding import (P_BRITTLE_SLIDING, P_GAMMA_N, P_GAMMA_T, P_K1, P_K2, P_KC, P_KT_RATIO, P_MU,
                             P_MU_WALL)

JIT = {"cache": True, "error_model": "numpy"}  # fastmath stays off: the tests compare closely
IN_LOOP = {**JIT, "inline": "always"}  # the kernels of the force loop, inlined there by numba (10 % faster)


@njit(**JIT)
def pair_delta_fluid(a_i, a_j, fluid_overlap):
    """``delta_fluid = fluid_overlap * 2 a_i a_j/(a_i + a_j)`` of a pair (``fluid_overlap * a`` for equal radii)."""
    return fluid_overlap * 2.0 * a_i * a_j / (a_i + a_j)


# ------------------------------------------------------------------------------------------ temperature, time
@njit(**JIT)
def radius_at(a_melt, T, T_melt, expansion):
    """``a(T) = a(T_melt) [1 - delta a_T (T_melt - T)]`` (Luding 2005, eq. 9)."""
    return a_melt * (1.0 - expansion * (T_melt - T))


@njit(**JIT)
def k1_factor(T, T_melt, T_var):
    """``k1(T)/k1 = [1 + tanh((T_melt - T)/T_var)]/2`` (Luding 2005, eq. 10), evaluated as the equal logistic
    ``1/(1 + exp(-2 tau))``: no cancellation in ``1 + tanh`` far above T_melt, so the factor stays > 0 there."""
    return 1.0 / (1.0 + math.exp(-2.0 * (T_melt - T) / T_var))


@njit(**JIT)
def relax_k1(k1t, k1T, dt, t0, cooling):
    """New factor k1(T, t)/k1 after a step ``dt`` from ``k1t`` towards the target ``k1T = k1(T)/k1``.

    Eq. (12), ``d k/dt = (K - k)|K - k|/(K t0)``, solved exactly over the step from the previous step's value
    (footnote 3) at constant target K: with ``u = 1 - k/K``, ``u_new = u/(1 + |u| dt/t0)`` (eq. 11 is this
    solution for heating). Written as ``k_new = K - d K t0/(K t0 + |d| dt)``, ``d = K - k``: unconditionally
    stable and finite for K -> 0. Cooling with ``K > k`` freezes at once, ``k_new = K`` (end of Sec. 3.4).
    """
    d = k1T - k1t
    if cooling and d > 0.0:
        return k1T
    denominator = k1T * t0 + abs(d) * dt
    if denominator <= 0.0:
        return k1T
    return k1T - d * (k1T * t0) / denominator


# ------------------------------------------------------------------------------------------ normal history
@njit(**JIT)
def delta_max_fluid(delta_fluid, params):
    """``delta_max^fluid = k2 delta_fluid/(k2 - k1)`` (Luding 2005, text above eq. 7; k1 the cold limit)."""
    k1 = params[P_K1]
    k2 = params[P_K2]
    return k2 * delta_fluid / (k2 - k1)


@njit(**IN_LOOP)
def k2_of_delta_max(delta_max, delta_fluid, params):
    """``k2(delta_max)`` (Luding 2005, eq. 7): ``k1 + (k2 - k1) delta_max/delta_max^fluid`` below the fluid
    limit, ``k2`` at and above it."""
    k1 = params[P_K1]
    k2 = params[P_K2]
    x = (k2 - k1) * delta_max  # delta_max >= delta_max^fluid  <=>  x >= k2 delta_fluid (one division, none if k1 = k2)
    if x >= k2 * delta_fluid:
        return k2
    return k1 + (k2 - k1) * x / (k2 * delta_fluid)


@njit(**IN_LOOP)
def _plastic_overlap(delta_max, k1_factor_now, delta_fluid, params):
    """``(1 - k1(T, t)/k2(delta_max)) delta_max``: the force-free overlap before the fluid limit (eq. 4)."""
    return (1.0 - k1_factor_now * params[P_K1] / k2_of_delta_max(delta_max, delta_fluid, params)) * delta_max


@njit(**JIT)
def delta_0(delta_max, k1_factor_now, delta_fluid, params):
    """Force-free overlap ``delta_0 = (1 - k1(T, t)/k2(delta_max)) delta_max`` (Luding 2005, eq. 4 and below),
    never beyond ``delta_fluid`` (Sec. 3.1.3: there the contact is on the fluid branch)."""
    return min(_plastic_overlap(delta_max, k1_factor_now, delta_fluid, params), delta_fluid)


@njit(**IN_LOOP)
def delta_max_for_delta_0(d0, k1_factor_now, delta_fluid, params):
    """The ``delta_max`` whose force-free overlap (before the fluid cap) is ``d0``: the inverse of
    ``(1 - s k1/k2(x)) x = d0`` with k2(x) of eq. (7), ``s = k1(T, t)/k1`` (Fig. 5 right: cooling keeps delta_0;
    the tension branch: reloading starts on a new k2 line).

    At or above delta_max^fluid, ``x = d0/(1 - s k1/k2)``. Below, with ``k2(x) = k1 + c x``,
    ``c = (k2 - k1)/delta_max^fluid``: ``c x^2 + b x - k1 d0 = 0``, ``b = k1 (1 - s) - c d0``, whose positive root
    is taken in the form without cancellation (``2 k1 d0/(b + sqrt(D))`` for b >= 0).
    """
    if d0 <= 0.0:
        return 0.0
    k1 = params[P_K1]
    k2 = params[P_K2]
    dmf = k2 * delta_fluid / (k2 - k1)
    x = d0 / (1.0 - k1_factor_now * k1 / k2)
    if x >= dmf:
        return x
    c = (k2 - k1) / dmf
    b = k1 * (1.0 - k1_factor_now) - c * d0
    root = math.sqrt(b * b + 4.0 * c * k1 * d0)
    if b >= 0.0:
        return 2.0 * k1 * d0 / (b + root)
    return (root - b) / (2.0 * c)


@njit(**JIT)
def kc_of(delta_max, k1_factor_now, delta_fluid, params):
    """``kc(T, t, delta_max) = (k1(T, t)/k1) (k2(delta_max)/k2) kc`` (Luding 2005, eq. 13)."""
    return k1_factor_now * k2_of_delta_max(delta_max, delta_fluid, params) / params[P_K2] * params[P_KC]


@njit(**JIT)
def delta_min(delta_max, k1_factor_now, delta_fluid, params):
    """Overlap of the largest attraction, where the k2 line meets ``-kc delta``: ``k2 delta_0/(k2 + kc)``, i.e.
    ``(k2 - k1)/(k2 + kc) delta_max`` of Luding 2005, Sec. 3.1.1, with k2(delta_max), k1(T, t), kc(T, t,
    delta_max)."""
    k2m = k2_of_delta_max(delta_max, delta_fluid, params)
    kcm = k1_factor_now * k2m / params[P_K2] * params[P_KC]
    return k2m * delta_0(delta_max, k1_factor_now, delta_fluid, params) / (k2m + kcm)


@njit(**JIT)
def f_min(delta_max, k1_factor_now, delta_fluid, params):
    """Largest attraction ``f_min = -kc delta_min = -(k2 - k1(T, t))/(1 + k2/kc) delta_max`` (Luding 2005,
    eq. 15; with delta_0 capped at delta_fluid on the fluid branch)."""
    return -kc_of(delta_max, k1_factor_now, delta_fluid, params) * delta_min(delta_max, k1_factor_now,
                                                                            delta_fluid, params)


@njit(**IN_LOOP)
def normal_force(delta, delta_dot, k1_factor_now, delta_max, k1_factor_last, delta_fluid, params):
    """Normal force on particle i and the new history (Luding 2005, eqs. 4, 5, 7, 13, 15; Figs. 2, 3, 5).

    Arguments: overlap ``delta`` (m), its rate ``delta_dot`` (m/s, > 0 approaching), the factor ``k1(T, t)/k1``
    now and at the contact's previous step, the history ``delta_max`` (0 for a new contact), ``delta_fluid`` of
    the contact, ``params`` (:meth:`LudingMaterial.params`).

    Returns ``(f_n, delta_max_new, f_min, k2_now, kc_now, delta_0)``: f_n > 0 repulsive, including the viscous
    ``gamma_0 delta_dot`` (eq. 5); f_min of eq. (15), k2(delta_max) of eq. (7), kc(T, t, delta_max) of eq. (13) and
    the force-free overlap after the update (the tangential kernel takes f_min and k2_now). For ``delta <= 0`` the
    contact is open: no force, the history is returned unchanged (the engine deletes the contact).

    The elastic-plastic force lies in the cone between the k1(T, t) line and the -kc line:

    * temperature (Fig. 5): when k1(T, t) fell since the last step (heating) delta_max is kept, so delta_0 grows;
      when it rose (cooling) delta_0 is kept and delta_max grows to the root of ``(1 - k1(T, t)/k2(x)) x = delta_0``
      (:func:`delta_max_for_delta_0`);
    * loading: beyond delta_max the force follows ``k1(T, t) delta`` and delta_max = delta;
    * un/reloading: ``k2(delta_max)(delta - delta_0)``, ``delta_0 = (1 - k1(T, t)/k2(delta_max)) delta_max``;
    * fluid (Sec. 3.1.3): delta_0 never exceeds delta_fluid; from there the contact stays on
      ``k2(delta_max)(delta - delta_fluid)`` with delta_max frozen (no more plastic deformation; in the cold limit
      delta_max = delta_max^fluid and the slope is k2);
    * tension: the force never falls below ``-kc delta``; where it would, it is held there and delta_0 moves to
      ``delta (1 + kc/k2)`` (kc/k2 = k1(T, t) kc/(k1 k2) by eq. 13, whatever delta_max), delta_max to the matching
      root, so that reloading departs into the cone on that new k2 line.
    """
    # Written with two divisions per call (this runs for every contact at every step): with c = k2 delta_fluid,
    # k2(x) = k1 + (k2 - k1)^2 x / c below the fluid limit (k2 - k1) x < c, 1/k2 = delta_fluid / c, and the
    # comparisons of force-free overlaps with delta_fluid multiplied out by k2(x) > 0.
    k1 = params[P_K1]
    k2 = params[P_K2]
    kc = params[P_KC]
    s = k1_factor_now
    dm = delta_max
    dk = k2 - k1
    inv_c = 1.0 / (k2 * delta_fluid)
    kc_over_k2 = kc * delta_fluid * inv_c
    if delta > 0.0:
        if s > k1_factor_last:  # cooling: delta_0 kept
            d0_last = min(_plastic_overlap(dm, k1_factor_last, delta_fluid, params), delta_fluid)
            dm = max(dm, delta_max_for_delta_0(d0_last, s, delta_fluid, params))
        if delta > dm:
            k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
            if (k2m - s * k1) * dm < delta_fluid * k2m:  # loading: not yet on the fluid branch
                k2d = k2 if dk * delta >= k2 * delta_fluid else k1 + dk * dk * delta * inv_c
                if (k2d - s * k1) * delta <= delta_fluid * k2d:
                    dm = delta
                else:  # the fluid limit is reached within this step
                    dm = delta_max_for_delta_0(delta_fluid, s, delta_fluid, params)
        k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
        q = 1.0 + s * kc_over_k2  # kc/k2(delta_max) = s kc/k2 by eq. 13
        inv_kq = 1.0 / (k2m * q)
        d0 = min((k2m - s * k1) * dm * q * inv_kq, delta_fluid)
        kcm = s * k2m * kc_over_k2
        f = k2m * (delta - d0)
        if f < -kcm * delta:  # tension branch: a new k2 line through (delta, -kc delta)
            d0 = delta * q
            dm = delta_max_for_delta_0(d0, s, delta_fluid, params)
            k2m = k2_of_delta_max(dm, delta_fluid, params)
            kcm = s * k2m * kc_over_k2
            inv_kq = 1.0 / (k2m * q)
            f = -kcm * delta
        f += params[P_GAMMA_N] * delta_dot
    else:
        f = 0.0
        k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
        q = 1.0 + s * kc_over_k2
        inv_kq = 1.0 / (k2m * q)
        d0 = min((k2m - s * k1) * dm * q * inv_kq, delta_fluid)
        kcm = s * k2m * kc_over_k2
    attraction = kcm * k2m * d0 * inv_kq  # kc k2 d0 / (k2 + kc), the largest attraction (eq. 15)
    return f, dm, -attraction if attraction > 0.0 else 0.0, k2m, kcm, d0


# ------------------------------------------------------------------------------------------ tangential
@njit(**JIT)
def relative_velocity(v_i, v_j, w_i, w_j, a_i, a_j, n):
    """Tangential relative velocity ``v_t`` (eq. 17) and ``delta_dot`` at a contact.

    ``v_ij = v_i - v_j + a_i n x w_i + a_j n x w_j`` (Luding 2005, eq. 18) with ``n`` from j to i (eq. 3): the
    velocity of i's surface relative to j's at the contact point. ``delta_dot = -n . v_ij`` (> 0 approaching). For
    a wall, pass its velocity as ``v_j``, ``w_j = (0, 0, 0)`` and ``a_j = 0``. 3-vectors are 3-tuples.
    Returns ``(v_t, delta_dot)``.
    """
    n0, n1, n2 = n
    u0 = v_i[0] - v_j[0] + a_i * (n1 * w_i[2] - n2 * w_i[1]) + a_j * (n1 * w_j[2] - n2 * w_j[1])
    u1 = v_i[1] - v_j[1] + a_i * (n2 * w_i[0] - n0 * w_i[2]) + a_j * (n2 * w_j[0] - n0 * w_j[2])
    u2 = v_i[2] - v_j[2] + a_i * (n0 * w_i[1] - n1 * w_i[0]) + a_j * (n0 * w_j[1] - n1 * w_j[0])
    vn = n0 * u0 + n1 * u1 + n2 * u2
    return (u0 - vn * n0, u1 - vn * n1, u2 - vn * n2), -vn


@njit(**IN_LOOP)
def tangential_force(xi, n, vt, f_n, f_min_now, k2_now, k1_factor_now, dt, params, is_wall):
    """Tangential force on particle i and the new spring (Luding 2005, eqs. 14, 16, 19-24, footnote 5).

    ``xi`` the spring of the previous step, ``n`` the unit normal (j to i), ``vt`` the tangential relative
    velocity (eq. 17, :func:`relative_velocity`), all 3-tuples; ``f_n`` the normal force (with its viscous part),
    ``f_min_now`` and ``k2_now`` from :func:`normal_force`, ``dt`` the time step, ``is_wall`` selects mu_wall.

    ``f_C = mu(T, t) (f_n - f_min)``, ``mu(T, t) = (k1(T, t)/k1) mu`` (eqs. 14, 24); ``xi`` is projected into the
    tangent plane (eq. 16); test force ``f_t0 = -k_t xi - gamma_t v_t``, ``k_t = alpha k2(delta_max)`` (eqs. 19,
    23). Sticking, ``|f_t0| <= f_C``: ``f_t = f_t0``, ``xi' = xi + v_t dt`` (eq. 20). Sliding: ``f_t = f_C t``,
    ``t = f_t0/|f_t0|`` (eq. 22), ``xi' = -(f_C t + gamma_t v_t)/k_t`` (eq. 21), and with ``brittle_sliding`` the
    normal force loses its attraction, ``f_n >= 0`` (footnote 5). ``f_n - f_min <= 0``: no tangential force and
    ``xi' = 0``.

    Returns ``(f_t, xi_new, sliding, f_n)``: two 3-tuples, a bool, the (possibly raised) normal force.
    """
    mu = params[P_MU_WALL] if is_wall else params[P_MU]
    excess = f_n - f_min_now
    if excess <= 0.0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), False, f_n
    f_c = k1_factor_now * mu * excess
    n0, n1, n2 = n
    xn = xi[0] * n0 + xi[1] * n1 + xi[2] * n2
    x0 = xi[0] - xn * n0
    x1 = xi[1] - xn * n1
    x2 = xi[2] - xn * n2
    kt = params[P_KT_RATIO] * k2_now
    gt = params[P_GAMMA_T]
    f0 = -kt * x0 - gt * vt[0]
    f1 = -kt * x1 - gt * vt[1]
    f2 = -kt * x2 - gt * vt[2]
    size = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
    if size <= f_c:
        return (f0, f1, f2), (x0 + vt[0] * dt, x1 + vt[1] * dt, x2 + vt[2] * dt), False, f_n
    scale = f_c / size
    f0 *= scale
    f1 *= scale
    f2 *= scale
    if kt > 0.0:
        inv_kt = 1.0 / kt
        xi_new = (-(f0 + gt * vt[0]) * inv_kt, -(f1 + gt * vt[1]) * inv_kt, -(f2 + gt * vt[2]) * inv_kt)
    else:
        xi_new = (0.0, 0.0, 0.0)
    if params[P_BRITTLE_SLIDING] != 0.0 and f_n < 0.0:
        f_n = 0.0
    return (f0, f1, f2), xi_new, True, f_n
