r"""The bonds of Zohdi 2014 (eqs. 18-19): a pair whose strain reaches :math:`E^*` is bonded from the next step on (the
flag is the pair's history, committed when a step is accepted) and stays bonded while it touches; a bond pulls with
:math:`K_b |E|^{p_b} A` on the pair's contact area. Within a step the flags are fixed: a bond switched on between two
iterates makes the force jump by :math:`K_b {E^*}^{p_b} A`, and the fixed-point iteration then stalls at the size of
that jump instead of converging. An adhesion sub-model of the contact laws (:mod:`dem.laws.contact.composition`) on
Zohdi's normal force (:mod:`dem.laws.contact.normal.zohdi`); friction resists the contact force without the bond's pull;
walls do not bond. Parameters: the block of :func:`dem.laws.contact.zohdi.params_of`.
"""

from __future__ import annotations

from numba import njit

from dem.laws.contact import zohdi
from dem.laws.contact.kernel_options import IN_LOOP
from dem.laws.contact.zohdi import Z_E_STAR, Z_KB, Z_PB

PARAMS = (zohdi.params_of, zohdi.N_PARAMS)
FIELDS = {"K_b": ("nonnegative", "N/m^2"), "p_b": ("positive", ""), "E_star": ("nonnegative", "")}
SCHEMA_ROWS = tuple(row for row in zohdi.SCHEMA_ROWS if set(row[0]) & set(FIELDS))
NORMALS = ("zohdi",)
PAIR_HISTORY = ("bonded",)  # 1: the bond of eq. 19 acts (activated by an accepted step that reached E*)
WALL_HISTORY = ()


def largest_reach(material, radius) -> float:
    """A bond acts while its particles touch.

    Parameters
    ----------
    material : object
        The contact material (not read).
    radius : numpy.ndarray
        (N,) radii (m; not read).

    Returns
    -------
    float
        0.0: the largest gap (m) across which the law acts.
    """
    return 0.0


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, contact, f_el, k_n, a, r_eff, ri, rj, params):
    """The contact force less the bond's pull where the pair is bonded (eq. 19), ``(F_n, k_n, A, F_con)``; the flag
    in column ``col`` of row ``at`` is set once the strain reaches ``E*`` (eq. 18), cleared where the lens
    vanishes."""
    if a == 0.0:
        hist[at + (col,)] = 0.0
        return f_el, k_n, a, f_el
    strain = contact[0] / (ri + rj)  # |E_ij| (eq. 3)
    bond = hist_in[at + (col,)] != 0.0  # eq. 19, activated by an earlier accepted step (eq. 18)
    f_n = f_el - (params[Z_KB] * strain ** params[Z_PB] * a if bond else 0.0)
    hist[at + (col,)] = 1.0 if bond or strain >= params[Z_E_STAR] else 0.0
    return f_n, k_n, a, f_el


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, contact, f_el, k_n, a, rk, params):
    """Walls do not bond: ``(F_con, k_n, A, F_con)``."""
    return f_el, k_n, a, f_el


@njit(**IN_LOOP)
def forget(at, col, hist_in, hist):
    """A pair that separated forgets its bond; whether it had one."""
    had = hist_in[at + (col,)] != 0.0
    hist[at + (col,)] = 0.0
    return had


@njit(**IN_LOOP)
def reach(at, col, hist):
    """A bond acts while its particles touch."""
    return 0.0
