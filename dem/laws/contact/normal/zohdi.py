r"""The normal contact of Zohdi 2014 (eqs. 2-15, Sec. 7): a power law of the strain on the contact area, softened by
temperature -- :math:`K_p |E|^{p_p} A` between particles (the strain :math:`E = \delta/(R_i + R_j)`, eq. 3, on the lens
area :math:`A = \pi (R_i^2 - L_i^2)`, eqs. 7-12) and :math:`K_w E^{p_w} A` on a wall (:math:`E = \delta/R_k`, eq. 14, on
the circle the plane cuts from the sphere), with :math:`K = \max(K_0 (1 - \theta/\theta^*), K_{lim})` (Sec. 7; for a
pair :math:`\theta` is the mean of the two). A normal sub-model of the contact laws
(:mod:`dem.laws.contact.composition`) whose contact's size ``a`` is its area (m^2); the law is stepped by the paper's
implicit scheme (:func:`time_steps`). Parameters: the block of :func:`dem.laws.contact.zohdi.params_of`.
"""

from __future__ import annotations

import math

from numba import njit

from dem.laws.contact import zohdi
from dem.laws.contact.kernel_options import IN_LOOP, JIT
from dem.laws.contact.zohdi import Z_KP, Z_KP_LIM, Z_KW, Z_KW_LIM, Z_PP, Z_PW, Z_THETA_STAR

PARAMS = (zohdi.params_of, zohdi.N_PARAMS)
FIELDS = {"K_p": ("positive", "N/m^2"), "p_p": ("positive", ""), "K_p_lim": ("nonnegative", "N/m^2"),
          "K_w": ("positive", "N/m^2"), "p_w": ("positive", ""), "K_w_lim": ("nonnegative", "N/m^2"),
          "theta_star": ("positive", "K")}
SCHEMA_ROWS = tuple(row for row in zohdi.SCHEMA_ROWS if set(row[0]) & set(FIELDS))
PAIR_HISTORY = WALL_HISTORY = ()
PAIR_CONSTANTS = ()
STATE = None


def time_steps(material, mass, inertia, radius, m_mean: float):
    """The law is stepped by the implicit scheme of the paper (:mod:`dem.engines.staggered`), not by velocity
    Verlet.

    Parameters
    ----------
    material : object
        The contact material (not read).
    mass, inertia, radius : numpy.ndarray
        (N,) masses (kg), moments of inertia (kg m^2) and radii (m), as every law's ``time_steps`` takes them.
    m_mean : float
        The mass of a particle of the mean radius (kg).

    Raises
    ------
    ValueError
        Always: this law has no velocity-Verlet step.
    """
    raise ValueError("[contact] law = \"zohdi\": runs on the staggered implicit scheme of Zohdi 2014 (its [solver] "
                     "keys dt, dt_max, phi, iterations, tolerance), not on velocity-Verlet steps")


@njit(**JIT)
def softened(k0, k_lim, theta, theta_star):
    r""":math:`\max(K_0 (1 - \theta/\theta^*), K_{lim})` (Zohdi 2014, Sec. 7)."""
    return max(k0 * (1.0 - theta / theta_star), k_lim)


@njit(**JIT)
def lens_area(ri, rj, d):
    r""":math:`\pi a^2 = \pi (R_i^2 - L_i^2)`, :math:`L_i = (d - (R_j^2 - R_i^2)/d)/2` (Zohdi 2014, eqs. 7-12); 0
    apart."""
    if d >= ri + rj or d <= 0.0:
        return 0.0
    li = 0.5 * (d - (rj * rj - ri * ri) / d)
    return math.pi * max(ri * ri - li * li, 0.0)


@njit(**IN_LOOP)
def pair_constants(ri, rj, params):
    """No numbers of the radii alone are kept per pair (``PAIR_CONSTANTS`` is empty): two zeros."""
    return 0.0, 0.0


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, state, T, i, j, contact, ri, rj, params, const):
    """The contact force of a pair on its lens area (eqs. 2-12) softened by the pair's mean temperature (Sec. 7):
    ``(F_con, 0, A, 0, 1, 0)`` (:mod:`dem.laws.contact.composition`), all zero where the lens vanishes."""
    area = lens_area(ri, rj, contact[1])
    if area == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 1.0, 0.0
    strain = contact[0] / (ri + rj)  # |E_ij| (eq. 3)
    stiffness = softened(params[Z_KP], params[Z_KP_LIM], 0.5 * (T[i] + T[j]), params[Z_THETA_STAR])
    return stiffness * strain ** params[Z_PP] * area, 0.0, area, 0.0, 1.0, 0.0  # eq. 2


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, state, T, k, contact, rk, params):
    """The wall's contact force on particle k at the distance ``dist`` of its centre: on the circle the plane cuts
    from the sphere (eqs. 13-15), softened by the particle's temperature."""
    delta, dist = contact[0], contact[1]
    strain = delta / rk  # eq. 14
    stiffness = softened(params[Z_KW], params[Z_KW_LIM], T[k], params[Z_THETA_STAR])
    cut = max(rk * rk - dist * dist, 0.0)
    return stiffness * strain ** params[Z_PW] * math.pi * cut, 0.0, math.pi * cut, 0.0, 1.0, rk  # eq. 13
