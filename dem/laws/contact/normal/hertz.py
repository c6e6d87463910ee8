r"""Hertz's normal contact of elastic spheres (Hertz 1882; Johnson, Contact Mechanics, 1985, Sec. 4.2): at the overlap
:math:`\delta` of two spheres of effective radius :math:`R^*` the contact radius is :math:`a = \sqrt{R^* \delta}`
and the force :math:`F_{el} = \frac{4}{3} E^* a \delta`, i.e. a spring of stiffness :math:`k_n = \frac{4}{3} E^* a`
that grows with the overlap. A normal sub-model of the contact laws (:mod:`dem.laws.contact.composition`): a wall is
a partner of infinite radius (:math:`R^* = a_k`); the material's ``youngs_modulus`` E and ``poisson_ratio``
:math:`\nu` give :math:`E^* = E/(2 (1 - \nu^2))`
(:func:`dem.laws.contact.hertz_mindlin.effective_modulus`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.damping import tsuji
from dem.laws.contact.kernel_options import IN_LOOP

RAYLEIGH_FRACTION = 0.1  # dt = "auto": this fraction of the Rayleigh time
STABLE_OVERLAP = 0.1     # the stable step is that of an overlap of this fraction of R* (time_steps)


SIZE = 1  # the block's length


def params_of(material) -> np.ndarray:
    """The block of this sub-model: ``(4/3 E*,)`` (Pa).

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa) and ``poisson_ratio``.

    Returns
    -------
    numpy.ndarray
        (1,) the block.
    """
    return np.array([4.0 / 3.0 * hm.effective_modulus(material)])


PARAMS = (params_of, SIZE)
FIELDS = {"youngs_modulus": ("positive", "Pa"), "poisson_ratio": ("number", "")}
SCHEMA_ROWS = ((("youngs_modulus", "poisson_ratio"), "Pa, -; required, E > 0, -1 < ν < 0.5",
                "E and ν of the particles and the walls: Hertz's F = 4/3 E* √R* δ^(3/2), E* = E/(2(1 - ν²)) "
                "(Johnson 1985, Sec. 4.2)"),)
PAIR_HISTORY = WALL_HISTORY = ()
PAIR_CONSTANTS = ()
check = hm.check_poisson_ratio  # the range the field kinds do not say
STATE = None


def time_steps(material, mass: np.ndarray, inertia: np.ndarray, radius: np.ndarray,
               m_mean: float) -> tuple[float, float]:
    r"""``(dt, stable)``: ``dt = "auto"`` is ``RAYLEIGH_FRACTION`` of the Rayleigh time of the smallest particle
    (:mod:`dem.laws.contact.hertz_mindlin`). Hertz's stiffness :math:`k = dF/d\delta = 2 E^* a` grows with the
    overlap, so no step is stable at every overlap: ``stable`` is the largest velocity-Verlet step, :math:`2/(\omega +
    \eta_n/(2 m^*))`, for the lightest pair at an overlap of ``STABLE_OVERLAP`` :math:`R^*` (beyond the small strains
    Hertz's law is for), with its stiffest mode: normal, :math:`2 E^* a`, or tangential with rotation, :math:`8 G^* a
    (1 + m a^2/I)` (Mindlin's, also where another tangential sub-model is taken), with Tsuji's damping of the
    ``restitution``.

    Parameters
    ----------
    material : object
        The contact material: its ``youngs_modulus``, ``poisson_ratio``, ``restitution`` and ``density``.
    mass : numpy.ndarray
        (N,) masses (kg).
    inertia : numpy.ndarray
        (N,) moments of inertia (kg m^2).
    radius : numpy.ndarray
        (N,) radii (m).
    m_mean : float
        The mass of a particle of the mean radius (kg; not read by this law).

    Returns
    -------
    tuple of (float, float)
        The step ``dt = "auto"`` takes (at most ``stable``) and ``stable`` (s).
    """
    order = np.argsort(mass)
    lo, hi = order[0], order[1] if len(mass) > 1 else order[0]
    m_eff = mass[lo] * mass[hi] / (mass[lo] + mass[hi]) if len(mass) > 1 else float(mass[lo])
    r_eff = radius[lo] * radius[hi] / (radius[lo] + radius[hi]) if len(mass) > 1 else float(radius[lo])
    a = r_eff * math.sqrt(STABLE_OVERLAP)
    rotational = 1.0 + float(np.max(mass * radius**2 / inertia))
    e_star = hm.effective_modulus(material)
    g_star = hm.effective_shear_modulus(material)
    k_max = max(2.0 * e_star * a, 8.0 * g_star * a * rotational)
    eta = tsuji.damping_coefficient(material.restitution) * math.sqrt(m_eff * 4.0 / 3.0 * e_star * a)
    stable = 2.0 / (math.sqrt(k_max / m_eff) + eta / (2.0 * m_eff))
    return min(RAYLEIGH_FRACTION * hm.rayleigh_time(material, float(np.min(radius))), stable), stable


@njit(**IN_LOOP)
def stiffness(delta, r_eff, four_thirds_e_star):
    r"""``(k_n, a)``: the secant stiffness :math:`k_n = F_{el}/\delta = \frac{4}{3} E^* a` (N/m) and the contact
    radius :math:`a = \sqrt{R^* \delta}` (m) at the overlap ``delta`` > 0 (m) of a contact of effective radius
    ``r_eff`` (m); ``four_thirds_e_star`` is :math:`\frac{4}{3} E^*` (Pa)."""
    a = math.sqrt(r_eff * delta)
    return four_thirds_e_star * a, a


@njit(**IN_LOOP)
def pair_constants(ri, rj, params):
    """No numbers of the radii alone are kept per pair (``PAIR_CONSTANTS`` is empty): two zeros."""
    return 0.0, 0.0


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, state, T, i, j, contact, ri, rj, params, const):
    """Hertz's force of a pair, ``(F_el, k_n, a, 0, 1, R*)`` (:mod:`dem.laws.contact.composition`), ``R* = a_i
    a_j/(a_i + a_j)``."""
    r_eff = ri * rj / (ri + rj)
    k_n, a = stiffness(contact[0], r_eff, params[0])
    return k_n * contact[0], k_n, a, 0.0, 1.0, r_eff


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, state, T, k, contact, rk, params):
    """As :func:`pair` with the wall as a partner of infinite radius, ``R* = a_k``."""
    k_n, a = stiffness(contact[0], rk, params[0])
    return k_n * contact[0], k_n, a, 0.0, 1.0, rk
