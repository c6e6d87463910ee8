r"""Mindlin's tangential contact with Coulomb sliding (Mindlin 1949; Mindlin & Deresiewicz 1953, J. Appl. Mech. 20, 327;
the "no-slip" form of Di Renzo & Di Maio 2004): a spring :math:`\xi` (the tangential displacement of the contact),
turned into the current tangent plane keeping its length and advanced by the tangential surface velocity :math:`v_t\,
dt`; the force :math:`F_t = -k_t \xi - \eta_t v_t`; where :math:`|F_t|` exceeds the friction limit the contact
slides, :math:`F_t` is scaled to the limit and the spring set to what gives that force, :math:`\xi = -(F_t + \eta_t
v_t)/k_t` (as LAMMPS's ``tangential mindlin``). The law that uses it gives the stiffness (Mindlin's :math:`k_t = 8 G^*
a` on its contact radius), the damping and the limit (Coulomb's :math:`\mu` times the load the contact carries).

As a tangential sub-model of the contact laws (:mod:`dem.laws.contact.composition`): :math:`k_t = 8 G^* a` on the
normal sub-model's contact radius a, :math:`G^* = G/(2 (2 - \nu))`, :math:`\eta_t` the ``tangential_damping`` times
:math:`\eta_n` of the damping sub-model, and the limit :math:`\mu\, s \max(L, 0)` of the load L the contact carries
(:math:`F_n` of a cohesionless contact; :math:`F_{el} + 2 P_c` with JKR's adhesion) and the normal sub-model's
softening factor s (1 for Hertz); ``mu_wall`` at a wall.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.kernel_options import IN_LOOP


@njit(**IN_LOOP)
def mindlin_force(xi, n, vt, k_t, eta_t, f_limit, dt):
    r"""Mindlin's tangential force with Coulomb sliding: ``(F_t, xi_new)``, two 3-tuples (module docstring).

    ``xi`` the spring of the previous step, ``n`` the unit normal, ``vt`` the tangential surface velocity of i
    relative to j; ``k_t`` the stiffness, ``eta_t`` the damping, ``f_limit`` the largest tangential force
    (:math:`\mu F_n`); ``dt`` the step. The spring is turned into the tangent plane keeping its length, advanced by
    :math:`v_t\, dt`; :math:`F_t = -k_t \xi - \eta_t v_t`; beyond ``f_limit`` it slides: :math:`F_t` scaled to
    ``f_limit``, :math:`\xi = -(F_t + \eta_t v_t)/k_t`."""
    n0, n1, n2 = n
    length2 = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]
    xn = xi[0] * n0 + xi[1] * n1 + xi[2] * n2
    x0, x1, x2 = xi[0] - xn * n0, xi[1] - xn * n1, xi[2] - xn * n2
    if xn != 0.0:  # turned into the tangent plane: the same length
        plane2 = x0 * x0 + x1 * x1 + x2 * x2
        scale = math.sqrt(length2 / plane2) if plane2 > 0.0 else 0.0
        x0, x1, x2 = x0 * scale, x1 * scale, x2 * scale
    x0 += vt[0] * dt
    x1 += vt[1] * dt
    x2 += vt[2] * dt
    f0 = -k_t * x0 - eta_t * vt[0]
    f1 = -k_t * x1 - eta_t * vt[1]
    f2 = -k_t * x2 - eta_t * vt[2]
    size2 = f0 * f0 + f1 * f1 + f2 * f2
    if size2 > f_limit * f_limit:
        scale = f_limit / math.sqrt(size2)
        f0, f1, f2 = f0 * scale, f1 * scale, f2 * scale
        inv_k = 1.0 / k_t
        x0 = -(f0 + eta_t * vt[0]) * inv_k
        x1 = -(f1 + eta_t * vt[1]) * inv_k
        x2 = -(f2 + eta_t * vt[2]) * inv_k
    return (f0, f1, f2), (x0, x1, x2)


SIZE = 4  # the block's length


def params_of(material) -> np.ndarray:
    r"""The block of this sub-model: :math:`(8 G^*, \eta_t/\eta_n, \mu, \mu_{wall})` (Pa, -, -, -).

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa), ``poisson_ratio``, ``tangential_damping``, ``mu`` and
        ``mu_wall``.

    Returns
    -------
    numpy.ndarray
        (4,) the block.
    """
    g_star = hm.effective_shear_modulus(material)
    return np.array([8.0 * g_star, material.tangential_damping, material.mu, material.mu_wall])


PARAMS = (params_of, SIZE)
FIELDS = {"youngs_modulus": ("positive", "Pa"), "poisson_ratio": ("number", ""),
          "tangential_damping": ("nonnegative", ""), "mu": ("nonnegative", ""), "mu_wall": ("nonnegative", "")}
SCHEMA_ROWS = ((("tangential_damping",), "≥ 0, required", "η_t/η_n, the damping of the tangential spring"),
               (("mu", "mu_wall"), "≥ 0, required", "particle-particle and particle-wall Coulomb friction, ‖F_t‖ ≤ μ "
                "F_n"))
PAIR_HISTORY = ("xi_x", "xi_y", "xi_z")  # the tangential spring
WALL_HISTORY = PAIR_HISTORY
SPINS = True
_KT, _XT, _MU, _MU_WALL = 0, 1, 2, 3  # the block's entries


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, contact, planar, f_n, load, k_n, a, eta, soft, dt, params):
    """Mindlin's force of a pair (:func:`mindlin_force`; module docstring), ``(f_n, f_t0, f_t1, f_t2)``; the spring
    in columns ``col`` to ``col + 2`` of row ``at``. ``planar``: 2D disks in the x-z plane."""
    delta, d, n, vr, vn = contact
    n0, n1, n2 = n
    ft, xi = mindlin_force((hist_in[at + (col,)], 0.0 if planar else hist_in[at + (col + 1,)],
                            hist_in[at + (col + 2,)]), n, (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2),
                           params[_KT] * a, params[_XT] * eta, soft * params[_MU] * max(load, 0.0), dt)
    hist[at + (col,)], hist[at + (col + 1,)], hist[at + (col + 2,)] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, contact, f_n, load, k_n, a, eta, soft, dt, params):
    """As :func:`pair`, on a wall (``mu_wall``)."""
    delta, d, n, vr, vn = contact
    n0, n1, n2 = n
    ft, xi = mindlin_force((hist_in[at + (col,)], hist_in[at + (col + 1,)], hist_in[at + (col + 2,)]), n,
                           (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), params[_KT] * a, params[_XT] * eta,
                           soft * params[_MU_WALL] * max(load, 0.0), dt)
    hist[at + (col,)], hist[at + (col + 1,)], hist[at + (col + 2,)] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def forget(at, col, hist_in, hist):
    """A contact that opened forgets its spring; whether it had one."""
    had = hist_in[at + (col,)] != 0.0 or hist_in[at + (col + 1,)] != 0.0 or hist_in[at + (col + 2,)] != 0.0
    hist[at + (col,)], hist[at + (col + 1,)], hist[at + (col + 2,)] = 0.0, 0.0, 0.0
    return had
