r"""The tangential contact of Luding, Manetsberger & Müllers 2005 (Luding 2005, eqs. 14, 16-24, footnote 5): a
spring :math:`\xi` of stiffness :math:`k_t = \alpha k_2(\delta_{max})` (eq. 23) with viscous damping
:math:`\gamma_t` (eq. 19), sticking below the Coulomb limit :math:`f_C = \mu(T, t) (f_n - f_{min})` (eqs. 14, 24)
and sliding at it (eqs. 20-22); a sliding contact keeps no cohesion where ``brittle_sliding`` (footnote 5). A
tangential sub-model of the contact laws (:mod:`dem.laws.contact.composition`): the stiffness is the normal
sub-model's :math:`k_n` (:math:`k_2(\delta_{max})` for Luding's; the secant stiffness for another),
:math:`\mu(T, t)` its softening factor times :math:`\mu`. Parameters: the block of
:func:`dem.laws.contact.luding.params_of`.
"""

from __future__ import annotations

import math

from numba import njit

from dem.laws.contact import luding
from dem.laws.contact.kernel_options import IN_LOOP, JIT
from dem.laws.contact.luding import P_BRITTLE_SLIDING, P_GAMMA_T, P_KT_RATIO, P_MU, P_MU_WALL


@njit(**JIT)
def relative_velocity(v_i, v_j, w_i, w_j, a_i, a_j, n):
    r"""Tangential relative velocity :math:`v_t` (eq. 17) and :math:`\dot\delta` at a contact.

    :math:`v_{ij} = v_i - v_j + a_i\, n \times \omega_i + a_j\, n \times \omega_j` (Luding 2005, eq. 18) with
    :math:`n` from j to i (eq. 3): the velocity of i's surface relative to j's at the contact point.
    :math:`\dot\delta = -n \cdot v_{ij}` (> 0 approaching). For
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
    r"""Tangential force on particle i and the new spring (Luding 2005, eqs. 14, 16, 19-24, footnote 5).

    ``xi`` the spring of the previous step, ``n`` the unit normal (j to i), ``vt`` the tangential relative
    velocity (eq. 17, :func:`relative_velocity`), all 3-tuples; ``f_n`` the normal force (with its viscous part),
    ``f_min_now`` and ``k2_now`` from :func:`dem.laws.contact.normal.luding.normal_force`, ``dt`` the time step,
    ``is_wall`` selects ``mu_wall``.

    :math:`f_C = \mu(T, t) (f_n - f_{min})`, :math:`\mu(T, t) = (k_1(T, t)/k_1) \mu` (eqs. 14, 24); :math:`\xi` is
    projected into the tangent plane (eq. 16); test force :math:`f_{t0} = -k_t \xi - \gamma_t v_t`, :math:`k_t =
    \alpha k_2(\delta_{max})` (eqs. 19, 23). Sticking, :math:`|f_{t0}| \le f_C`: :math:`f_t = f_{t0}`, :math:`\xi'
    = \xi + v_t\, dt` (eq. 20). Sliding: :math:`f_t = f_C t`, :math:`t = f_{t0}/|f_{t0}|` (eq. 22), :math:`\xi' =
    -(f_C t + \gamma_t v_t)/k_t` (eq. 21), and with ``brittle_sliding`` the normal force loses its attraction,
    :math:`f_n \ge 0` (footnote 5). :math:`f_n - f_{min} \le 0`: no tangential force and
    :math:`\xi' = 0`.

    Returns ``(f_t, xi_new, sliding, f_n)``: two 3-tuples, a bool, the (possibly raised) normal force.
    """
    return friction(xi, n, vt, f_n, f_n - f_min_now, k2_now, k1_factor_now, dt, params, is_wall)


@njit(**IN_LOOP)
def friction(xi, n, vt, f_n, excess, k2_now, k1_factor_now, dt, params, is_wall):
    """:func:`tangential_force` with the load friction resists, ``excess = f_n - f_min`` (N), given."""
    mu = params[P_MU_WALL] if is_wall else params[P_MU]
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


# ------------------------------------------------------------------------------------------ the sub-model
PARAMS = (luding.params_of, luding.N_PARAMS)
FIELDS = {"kt_ratio": ("nonnegative", ""), "gamma_t": ("nonnegative", "kg/s"), "mu": ("nonnegative", ""),
          "mu_wall": ("nonnegative", ""), "brittle_sliding": ("flag", "")}
SCHEMA_ROWS = ((("kt_ratio",), "≥ 0, required", "α = k_t/k_n, the tangential over the normal stiffness "
                "(Luding 2005, eq. 23)"),
               (("gamma_t",), "kg/s, ≥ 0, required", "tangential viscous damping (eq. 19)"),
               (("mu", "mu_wall"), "≥ 0, required", "particle-particle and particle-wall friction (eqs. 14, 24)"),
               (("brittle_sliding",), "bool, required", "a sliding contact keeps no cohesion, f_n ≥ 0 (footnote 5)"))
PAIR_HISTORY = ("xi_x", "xi_y", "xi_z")
WALL_HISTORY = PAIR_HISTORY
SPINS = True  # the tangential forces act at the contact point: torques


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, contact, planar, f_n, load, k_n, a, eta, soft, dt, params):
    """The tangential force of a pair, ``(f_n, f_t0, f_t1, f_t2)`` with the normal force raised where a brittle
    contact slides (:func:`friction`); the spring in columns ``col`` to ``col + 2`` of row ``at``. ``planar``: 2D
    disks in the x-z plane (no y terms)."""
    delta, d, n, vr, vn = contact
    n0, n1, n2 = n
    xi_y = 0.0 if planar else hist_in[at + (col + 1,)]
    ft, xi, sliding, f_n = friction((hist_in[at + (col,)], xi_y, hist_in[at + (col + 2,)]), n,
                                    (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), f_n, load, k_n, soft, dt,
                                    params, False)
    hist[at + (col,)], hist[at + (col + 1,)], hist[at + (col + 2,)] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, contact, f_n, load, k_n, a, eta, soft, dt, params):
    """As :func:`pair`, on a wall (``mu_wall``)."""
    delta, d, n, vr, vn = contact
    n0, n1, n2 = n
    ft, xi, sliding, f_n = friction((hist_in[at + (col,)], hist_in[at + (col + 1,)], hist_in[at + (col + 2,)]), n,
                                    (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), f_n, load, k_n, soft, dt,
                                    params, True)
    hist[at + (col,)], hist[at + (col + 1,)], hist[at + (col + 2,)] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def forget(at, col, hist_in, hist):
    """A contact that opened forgets its spring; whether it had one (written only then: most listed pairs are open,
    and their rows stay untouched)."""
    had = hist_in[at + (col,)] != 0.0 or hist_in[at + (col + 1,)] != 0.0 or hist_in[at + (col + 2,)] != 0.0
    if had:
        hist[at + (col,)], hist[at + (col + 1,)], hist[at + (col + 2,)] = 0.0, 0.0, 0.0
    return had
