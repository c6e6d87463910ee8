"""The adhesive contact of Johnson, Kendall & Roberts 1971 (Proc. R. Soc. Lond. A 324, 301; Johnson, Contact
Mechanics, 1985, Sec. 5.5): elastic spheres whose surfaces stick with the work of adhesion w (J/m^2). At the contact
radius a, the overlap is ``delta = a^2/R* - sqrt(2 pi w a/E*)`` and the elastic force ``F_el = 4 E* a^3/(3 R*) -
sqrt(8 pi w E* a^3)``; pulled apart, the contact breaks ``-delta_c = 3/4 (pi^2 w^2 R*/E*^2)^(1/3)`` beyond touching
(Thornton & Ning 1998, Powder Technol. 99, 154). With ``c = sqrt(2 pi w/E*)`` (m^(1/2))."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

IN_LOOP = {"cache": True, "error_model": "numpy", "inline": "always"}  # inlined into the engines' force loop


@njit(**IN_LOOP)
def contact_radius(delta, r_eff, c):
    """The JKR contact radius a at the overlap ``delta`` (above the break, module docstring): the root of ``s^4 - c
    R* s - delta R* = 0``, ``s = sqrt(a)``, ``c = sqrt(2 pi w/E*)`` on the stable branch.

    Ferrari: ``(s^2 + y)^2 = 2 y (s + c R*/(4 y))^2`` for the root y of ``y^3 + P y - 2 q = 0``, ``P = delta R*``,
    ``q = c^2 R*^2/16``. Cardano, ``u^3 = q + sqrt(q^2 + (P/3)^3)`` (the discriminant is >= 0 down to the break,
    where it vanishes), ``y = u - P/(3 u)`` written as ``2 q/(u^2 + P/3 + (P/3)^2/u^2)`` (no cancellation when P >
    0); then ``s = (sqrt(2 y) + sqrt(2 c R*/sqrt(2 y) - 2 y))/2``."""
    p3 = delta * r_eff / 3.0
    q = c * c * r_eff * r_eff / 16.0
    u2 = (q + math.sqrt(max(q * q + p3 * p3 * p3, 0.0))) ** (2.0 / 3.0)  # u^2 (a power: quicker than cbrt)
    y2 = 4.0 * q / (u2 + p3 + p3 * p3 / u2)  # 2 y
    root = math.sqrt(y2)
    s = 0.5 * (root + math.sqrt(max(2.0 * c * r_eff / root - y2, 0.0)))
    return s * s


@njit(**IN_LOOP)
def elastic_force(a, k_n, r_eff, e_star, c):
    """``F_el = 4 E* a^3/(3 R*) - sqrt(8 pi w E* a^3)`` (N) at the contact radius ``a`` (m), written with Hertz's
    ``k_n = 4/3 E* a`` (N/m), the effective radius ``r_eff`` (m), ``e_star`` E* (Pa) and ``c`` (``sqrt(8 pi w E*) =
    2 E* c``)."""
    return k_n * a * a / r_eff - 2.0 * e_star * c * a * math.sqrt(a)


@njit(**IN_LOOP)
def pulloff_distance(r_eff, w, e_star):
    """``-delta_c = 3/4 (pi^2 w^2 R*/E*^2)^(1/3)`` (m): how far beyond touching a contact of effective radius
    ``r_eff`` (m) breaks, for the work of adhesion ``w`` (J/m^2) and ``e_star`` E* (Pa)."""
    w_over_e = w / e_star
    return 0.75 * np.cbrt(math.pi * math.pi * w_over_e * w_over_e * r_eff)
