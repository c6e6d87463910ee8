r"""The sliding friction of Zohdi 2014 (eqs. 5-6, 16-17): :math:`\mu_d |F_{con}|\, t` with :math:`t = (v_j - v_i)/|v_j -
v_i|` the whole relative velocity between particles, as the paper writes it (so friction also opposes the approach of
two particles, which is what makes their collisions inelastic: the law has no normal damping), only the tangential one
at a wall (eq. 17). The direction is regularised, :math:`t = \Delta v/\sqrt{|\Delta v|^2 + v_{slip}^2}`: a unit vector
while sliding faster than ``v_slip``, proportional to the slip below it, so that the fixed-point map stays continuous
where the relative velocity passes through zero. The particles do not rotate (Sec. 2). A tangential sub-model of the
contact laws (:mod:`dem.laws.contact.composition`): ``|F_con|`` is the load it is given. Parameters: the block of
:func:`dem.laws.contact.zohdi.params_of`.
"""

from __future__ import annotations

import math

from numba import njit

from dem.laws.contact import zohdi
from dem.laws.contact.kernel_options import IN_LOOP
from dem.laws.contact.zohdi import Z_MU, Z_V_SLIP

PARAMS = (zohdi.params_of, zohdi.N_PARAMS)
FIELDS = {"mu_d": ("nonnegative", ""), "v_slip": ("positive", "m/s")}
SCHEMA_ROWS = ()  # in the row of c_env (drag.zohdi)
PAIR_HISTORY = WALL_HISTORY = ()
SPINS = False  # the particles do not rotate (Sec. 2)


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, contact, planar, f_n, load, k_n, a, eta, soft, dt, params):
    r""":math:`(F_n, \mu_d L u/\sqrt{|u|^2 + v_{slip}^2})` with :math:`u = -v_r = v_j - v_i` (eqs. 5-6,
    regularised) and the load L; no force where the contact's area ``a`` vanishes."""
    if a == 0.0:
        return f_n, 0.0, 0.0, 0.0
    vr = contact[3]
    u0, u1, u2 = -vr[0], -vr[1], -vr[2]  # v_j - v_i (eq. 6)
    scale = params[Z_MU] * load / math.sqrt(u0 * u0 + u1 * u1 + u2 * u2 + params[Z_V_SLIP] ** 2)
    return f_n, scale * u0, scale * u1, scale * u2


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, contact, f_n, load, k_n, a, eta, soft, dt, params):
    """Against the tangential velocity on a wall (eqs. 16-17)."""
    delta, d, n, vr, vn = contact
    n0, n1, n2 = n
    t0, t1, t2 = vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2  # the wall slides along none of these
    scale = params[Z_MU] * load / math.sqrt(t0 * t0 + t1 * t1 + t2 * t2 + params[Z_V_SLIP] ** 2)  # eqs. 16-17
    return f_n, -scale * t0, -scale * t1, -scale * t2
