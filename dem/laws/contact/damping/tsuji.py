r"""The viscoelastic damping of Tsuji, Tanaka & Ishida 1992 (Powder Technol. 71, 239): :math:`\eta_n = \alpha
\sqrt{m^* k_n}` with the contact's stiffness :math:`k_n`, which for Hertz's :math:`k_n = \frac{4}{3} E^* a` grows as
:math:`\delta^{1/4}`, so that the coefficient of restitution of a head-on collision does not depend on the impact
speed. Antypov & Elliott 2011 (EPL 94, 50004) solved that collision exactly: :math:`e = \exp(-\pi b/\sqrt{1 -
b^2})`, :math:`b = \alpha/\sqrt{5}` (:func:`damping_coefficient`, :func:`restitution_of`). A damping sub-model of the
contact laws (:mod:`dem.laws.contact.composition`): :math:`m^*` is read from the particles' masses
(:mod:`dem.laws.contact.state.mass`), a wall a partner of infinite mass (:math:`m^* = m_k`)."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.kernel_options import IN_LOOP


def damping_coefficient(restitution: float) -> float:
    r""":math:`\alpha = \sqrt{5}\,(-\ln e)/\sqrt{\pi^2 + \ln^2 e}`: the damping :math:`\eta_n = \alpha
    \sqrt{m^* k_n}` whose head-on Hertz collision has the coefficient of restitution e, at every impact speed (Antypov
    & Elliott 2011, EPL 94, 50004: :math:`e = \exp(-\pi b/\sqrt{1 - b^2})`, :math:`b = \alpha/\sqrt{5}`).

    Parameters
    ----------
    restitution : float
        The coefficient of restitution e, in ``(0, 1]``.

    Returns
    -------
    float
        :math:`\alpha` (dimensionless), 0 for e = 1.
    """
    log_e = math.log(restitution)
    return math.sqrt(5.0) * -log_e / math.sqrt(math.pi**2 + log_e**2)


def restitution_of(alpha: float) -> float:
    r"""The coefficient of restitution of a head-on collision with the damping ``alpha`` (:math:`< \sqrt{5}`):
    :math:`\exp(-\pi b/\sqrt{1 - b^2})`, :math:`b = \alpha/\sqrt{5}` (Antypov & Elliott 2011), the inverse of
    :func:`damping_coefficient`.

    Parameters
    ----------
    alpha : float
        The damping coefficient, in :math:`[0, \sqrt{5})` (dimensionless).

    Returns
    -------
    float
        The coefficient of restitution e.
    """
    b = alpha / math.sqrt(5.0)
    return math.exp(-math.pi * b / math.sqrt(1.0 - b * b))


@njit(**IN_LOOP)
def viscosity(alpha, m_eff, k_n):
    r""":math:`\eta_n = \alpha \sqrt{m^* k_n}` (kg/s): ``alpha`` of :func:`damping_coefficient`, the effective mass
    ``m_eff`` (kg) and the contact's stiffness ``k_n`` (N/m)."""
    return alpha * math.sqrt(m_eff * k_n)


SIZE = 1  # the block's length


def params_of(material) -> np.ndarray:
    r"""The block of this sub-model: :math:`(\alpha,)` of the material's ``restitution`` (:func:`damping_coefficient`).

    Parameters
    ----------
    material : object
        A material with the field ``restitution``.

    Returns
    -------
    numpy.ndarray
        (1,) the block.
    """
    return np.array([damping_coefficient(material.restitution)])


PARAMS = (params_of, SIZE)
FIELDS = {"restitution": ("positive", "")}
SCHEMA_ROWS = ((("restitution",), "0 < e ≤ 1, required", "the coefficient of restitution of a head-on collision, "
                "at every impact speed: Tsuji's damping η_n = α √(m* k_n) with α from e (Antypov & Elliott 2011)"),)
PAIR_HISTORY = WALL_HISTORY = ()
STATE = "mass"  # the particles' masses

check = hm.check_restitution  # the range the field kinds do not say


@njit(**IN_LOOP)
def pair(state, i, j, f_el, delta_dot, k_n, params):
    r""":math:`(f_{el} + \eta_n \dot\delta, \eta_n)` of a pair, :math:`\eta_n = \alpha \sqrt{m^* k_n}`, :math:`m^* =
    m_i m_j/(m_i + m_j)` (:mod:`dem.laws.contact.composition`)."""
    mi, mj = state[i, 0], state[j, 0]
    eta = viscosity(params[0], mi * mj / (mi + mj), k_n)
    return f_el + eta * delta_dot, eta


@njit(**IN_LOOP)
def wall(state, k, f_el, delta_dot, k_n, params):
    """As :func:`pair` with the wall as a partner of infinite mass, :math:`m^* = m_k`."""
    eta = viscosity(params[0], state[k, 0], k_n)
    return f_el + eta * delta_dot, eta
