r"""The adhesive contact of Johnson, Kendall & Roberts 1971 (Proc. R. Soc. Lond. A 324, 301; Johnson, Contact
Mechanics, 1985, Sec. 5.5): elastic spheres whose surfaces stick with the work of adhesion w (J/m^2). At the contact
radius a, the overlap is :math:`\delta = a^2/R^* - \sqrt{2 \pi w a/E^*}` and the elastic force :math:`F_{el} = 4 E^*
a^3/(3 R^*) - \sqrt{8 \pi w E^* a^3}`; pulled apart, the contact breaks :math:`-\delta_c = \frac{3}{4} (\pi^2 w^2
R^*/{E^*}^2)^{1/3}` beyond touching (Thornton & Ning 1998, Powder Technol. 99, 154). With :math:`c = \sqrt{2 \pi
w/E^*}` (:math:`\mathrm{m}^{1/2}`).

An adhesion sub-model of the contact laws (:mod:`dem.laws.contact.composition`) on Hertz's normal force
(:mod:`dem.laws.contact.normal.hertz`), whose contact radius and force it replaces by JKR's (Johnson 1985, Sec. 5.5:
:math:`\delta = a^2/R^* - \sqrt{2 \pi w a/E^*}`, :math:`F_{el}` above). A contact that touched stays closed,
beyond touching, down to the break :math:`\delta_c` (the pull-off distance :math:`-\delta_c` in its history, 0 before
it touched: its ``reach``); the load friction resists is :math:`F_{el} + 2 P_c`, :math:`P_c = \frac{3}{2} \pi w R^*`
(Thornton & Yin 1991, Powder Technol. 65, 153).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact import hertz_mindlin as hm
from dem.laws.contact.kernel_options import IN_LOOP


@njit(**IN_LOOP)
def contact_radius(delta, r_eff, c):
    r"""The JKR contact radius a at the overlap ``delta`` (above the break, module docstring): the root of :math:`s^4
    - c R^* s - \delta R^* = 0`, :math:`s = \sqrt{a}`, :math:`c = \sqrt{2 \pi w/E^*}` on the stable branch.

    Ferrari: :math:`(s^2 + y)^2 = 2 y (s + c R^*/(4 y))^2` for the root y of :math:`y^3 + P y - 2 q = 0`, :math:`P =
    \delta R^*`, :math:`q = c^2 {R^*}^2/16`. Cardano, :math:`u^3 = q + \sqrt{q^2 + (P/3)^3}` (the discriminant is
    :math:`\ge 0` down to the break, where it vanishes), :math:`y = u - P/(3 u)` written as :math:`2 q/(u^2 + P/3 +
    (P/3)^2/u^2)` (no cancellation when :math:`P > 0`); then :math:`s = (\sqrt{2 y} + \sqrt{2 c R^*/\sqrt{2 y} - 2
    y})/2`."""
    p3 = delta * r_eff / 3.0
    q = c * c * r_eff * r_eff / 16.0
    u2 = (q + math.sqrt(max(q * q + p3 * p3 * p3, 0.0))) ** (2.0 / 3.0)  # u^2 (a power: quicker than cbrt)
    y2 = 4.0 * q / (u2 + p3 + p3 * p3 / u2)  # 2 y
    root = math.sqrt(y2)
    s = 0.5 * (root + math.sqrt(max(2.0 * c * r_eff / root - y2, 0.0)))
    return s * s


@njit(**IN_LOOP)
def elastic_force(a, k_n, r_eff, e_star, c):
    r""":math:`F_{el} = 4 E^* a^3/(3 R^*) - \sqrt{8 \pi w E^* a^3}` (N) at the contact radius ``a`` (m), written with
    Hertz's :math:`k_n = \frac{4}{3} E^* a` (N/m), the effective radius ``r_eff`` (m), ``e_star`` :math:`E^*` (Pa) and
    ``c`` (:math:`\sqrt{8 \pi w E^*} = 2 E^* c`)."""
    return k_n * a * a / r_eff - 2.0 * e_star * c * a * math.sqrt(a)


@njit(**IN_LOOP)
def pulloff_distance(r_eff, w, e_star):
    r""":math:`-\delta_c = \frac{3}{4} (\pi^2 w^2 R^*/{E^*}^2)^{1/3}` (m): how far beyond touching a contact of
    effective radius ``r_eff`` (m) breaks, for the work of adhesion ``w`` (J/m^2) and ``e_star`` :math:`E^*` (Pa)."""
    w_over_e = w / e_star
    return 0.75 * np.cbrt(math.pi * math.pi * w_over_e * w_over_e * r_eff)


SIZE = 4  # the block's length


def params_of(material) -> np.ndarray:
    r"""The block of this sub-model: :math:`(\frac{4}{3} E^*, E^*, w, c)` (Pa, Pa, J/m^2, :math:`\mathrm{m}^{1/2}`).

    Parameters
    ----------
    material : object
        A material with the fields ``youngs_modulus`` (Pa), ``poisson_ratio`` and ``work_of_adhesion`` (J/m^2).

    Returns
    -------
    numpy.ndarray
        (4,) the block.
    """
    e_star = hm.effective_modulus(material)
    w = material.work_of_adhesion
    return np.array([4.0 / 3.0 * e_star, e_star, w, math.sqrt(2.0 * math.pi * w / e_star)])


PARAMS = (params_of, SIZE)
FIELDS = {"youngs_modulus": ("positive", "Pa"), "poisson_ratio": ("number", ""),
          "work_of_adhesion": ("positive", "J/m^2")}
SCHEMA_ROWS = ((("work_of_adhesion",), "J/m², > 0, required", "w, the energy per area that parts the surfaces: "
                "pull-off force 3/2 πwR*, the contact breaks 3/4 (π²w²R*/E*²)^(1/3) beyond touching (Johnson, "
                "Kendall & Roberts 1971)"),)
NORMALS = ("hertz",)
PAIR_HISTORY = ("pulloff",)  # the pull-off distance, 0 before contact
WALL_HISTORY = PAIR_HISTORY
_KN, _E_STAR, _W, _C = 0, 1, 2, 3  # the block's entries


def largest_reach(material, radius: np.ndarray) -> float:
    """The pull-off distance of the largest particle on a wall (R* = its radius), the farthest any contact acts.

    Parameters
    ----------
    material : object
        The contact material (its ``youngs_modulus``, ``poisson_ratio`` and ``work_of_adhesion``).
    radius : numpy.ndarray
        (N,) radii (m).

    Returns
    -------
    float
        The largest gap across which a contact acts (m).
    """
    return float(pulloff_distance(float(np.max(radius)), material.work_of_adhesion, hm.effective_modulus(material)))


@njit(**IN_LOOP)
def _contact(at, col, hist_in, hist, delta, r_eff, params):
    """JKR's ``(F_el, k_n, a, F_el + 2 P_c)`` at the overlap ``delta`` of a contact of effective radius ``r_eff``,
    its pull-off distance kept in column ``col`` of row ``at``."""
    c = params[_C]
    a = contact_radius(delta, r_eff, c)
    k_n = params[_KN] * a
    f_el = elastic_force(a, k_n, r_eff, params[_E_STAR], c)
    pulloff = hist_in[at + (col,)]
    hist[at + (col,)] = pulloff if pulloff > 0.0 else pulloff_distance(r_eff, params[_W], params[_E_STAR])
    return f_el, k_n, a, f_el + 3.0 * math.pi * params[_W] * r_eff


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, contact, f_el, k_n, a, r_eff, ri, rj, params):
    """JKR's force of a pair in place of Hertz's (module docstring), ``(F_el, k_n, a, F_el + 2 P_c)``."""
    return _contact(at, col, hist_in, hist, contact[0], r_eff, params)


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, contact, f_el, k_n, a, rk, params):
    """As :func:`pair`, on a wall (``R* = a_k``)."""
    return _contact(at, col, hist_in, hist, contact[0], rk, params)


@njit(**IN_LOOP)
def forget(at, col, hist_in, hist):
    """A contact that broke forgets it touched; whether it had."""
    had = hist_in[at + (col,)] != 0.0
    hist[at + (col,)] = 0.0
    return had


@njit(**IN_LOOP)
def reach(at, col, hist):
    """Beyond touching, a contact that has touched acts down to its pull-off distance (0 before it touched)."""
    return hist[at + (col,)]
