"""The viscoelastic damping of Tsuji, Tanaka & Ishida 1992 (Powder Technol. 71, 239): ``eta_n = alpha sqrt(m* k_n)``
with the contact's stiffness ``k_n``, which for Hertz's ``k_n = 4/3 E* a`` grows as ``delta^(1/4)``, so that the
coefficient of restitution of a head-on collision does not depend on the impact speed. Antypov & Elliott 2011 (EPL
94, 50004) solved that collision exactly: ``e = exp(-pi b / sqrt(1 - b^2))``, ``b = alpha/sqrt(5)``
(:func:`damping_coefficient`, :func:`restitution_of`)."""

from __future__ import annotations

import math

from numba import njit

IN_LOOP = {"cache": True, "error_model": "numpy", "inline": "always"}  # inlined into the engines' force loop


def damping_coefficient(restitution: float) -> float:
    """``alpha = sqrt(5) (-ln e)/sqrt(pi^2 + ln^2 e)``: the damping ``eta_n = alpha sqrt(m* k_n)`` whose head-on
    Hertz collision has the coefficient of restitution e, at every impact speed (Antypov & Elliott 2011, EPL 94,
    50004: ``e = exp(-pi b/sqrt(1 - b^2))``, ``b = alpha/sqrt(5)``).

    Parameters
    ----------
    restitution : float
        The coefficient of restitution e, in ``(0, 1]``.

    Returns
    -------
    float
        alpha (dimensionless), 0 for e = 1.
    """
    log_e = math.log(restitution)
    return math.sqrt(5.0) * -log_e / math.sqrt(math.pi**2 + log_e**2)


def restitution_of(alpha: float) -> float:
    """The coefficient of restitution of a head-on collision with the damping ``alpha`` (< sqrt(5)): ``exp(-pi b /
    sqrt(1 - b^2))``, ``b = alpha/sqrt(5)`` (Antypov & Elliott 2011), the inverse of :func:`damping_coefficient`.

    Parameters
    ----------
    alpha : float
        The damping coefficient, in ``[0, sqrt(5))`` (dimensionless).

    Returns
    -------
    float
        The coefficient of restitution e.
    """
    b = alpha / math.sqrt(5.0)
    return math.exp(-math.pi * b / math.sqrt(1.0 - b * b))


@njit(**IN_LOOP)
def viscosity(alpha, m_eff, k_n):
    """``eta_n = alpha sqrt(m* k_n)`` (kg/s): ``alpha`` of :func:`damping_coefficient`, the effective mass ``m_eff``
    (kg) and the contact's stiffness ``k_n`` (N/m)."""
    return alpha * math.sqrt(m_eff * k_n)
