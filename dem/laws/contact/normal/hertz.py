"""Hertz's normal contact of elastic spheres (Hertz 1882; Johnson, Contact Mechanics, 1985, Sec. 4.2): at the overlap
``delta`` of two spheres of effective radius ``R*`` the contact radius is ``a = sqrt(R* delta)`` and the force ``F_el
= 4/3 E* a delta``, i.e. a spring of stiffness ``k_n = 4/3 E* a`` that grows with the overlap."""

from __future__ import annotations

import math

from numba import njit

IN_LOOP = {"cache": True, "error_model": "numpy", "inline": "always"}  # inlined into the engines' force loop


@njit(**IN_LOOP)
def stiffness(delta, r_eff, four_thirds_e_star):
    """``(k_n, a)``: the secant stiffness ``k_n = F_el/delta = 4/3 E* a`` (N/m) and the contact radius ``a = sqrt(R*
    delta)`` (m) at the overlap ``delta`` > 0 (m) of a contact of effective radius ``r_eff`` (m);
    ``four_thirds_e_star`` is 4/3 E* (Pa)."""
    a = math.sqrt(r_eff * delta)
    return four_thirds_e_star * a, a
