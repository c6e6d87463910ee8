r"""The viscous normal damping of Luding, Manetsberger & Müllers 2005 (Luding 2005, eq. 5): :math:`f_n = f_{el} +
\gamma_0 \dot\delta` with a constant :math:`\gamma_0` (kg/s), a damping sub-model of the contact laws
(:mod:`dem.laws.contact.composition`). Parameters: the block of :func:`dem.laws.contact.luding.params_of`."""

from __future__ import annotations

from numba import njit

from dem.laws.contact import luding
from dem.laws.contact.kernel_options import IN_LOOP
from dem.laws.contact.luding import P_GAMMA_N

PARAMS = (luding.params_of, luding.N_PARAMS)
FIELDS = {"gamma_n": ("nonnegative", "kg/s")}
SCHEMA_ROWS = ((("gamma_n",), "kg/s, ≥ 0, required", "normal viscous damping γ0 (Luding 2005, eq. 5)"),)
PAIR_HISTORY = WALL_HISTORY = ()
STATE = None


@njit(**IN_LOOP)
def force(f_el, delta_dot, gamma_0):
    r""":math:`f_{el} + \gamma_0 \dot\delta` (eq. 5): the force ``f_el`` (N) with the viscous part of the overlap's rate
    ``delta_dot`` (m/s, > 0 approaching) and ``gamma_0`` (kg/s)."""
    return f_el + gamma_0 * delta_dot


@njit(**IN_LOOP)
def pair(state, i, j, f_el, delta_dot, k_n, params):
    r""":math:`(f_{el} + \gamma_0 \dot\delta, \gamma_0)` of a pair (:mod:`dem.laws.contact.composition`)."""
    return force(f_el, delta_dot, params[P_GAMMA_N]), params[P_GAMMA_N]


@njit(**IN_LOOP)
def wall(state, k, f_el, delta_dot, k_n, params):
    """As :func:`pair`, on a wall."""
    return force(f_el, delta_dot, params[P_GAMMA_N]), params[P_GAMMA_N]

