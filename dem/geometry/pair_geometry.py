"""The geometry of the pair bonds of a large packing, compiled: one pass over the bonds on numba's threads.

For every bond ``(i, j)`` (no periodic image) it gives the radii, the centre distance ``d = |x_j - x_i|``, the overlap
``h = r_i + r_j - d`` (Rojek 2022, eq. 21) and the distances ``L_i = (d - (r_j^2 - r_i^2)/d)/2``, ``L_j = d - L_i``
of the centres from the radical plane (Zohdi 2014, eq. 12), each the same to the bit as the numpy expressions of
:mod:`dem.geometry.bonds`, which make a fresh array over the bonds per operation, on one thread.
:func:`dem.geometry.bonds.find_bonds` takes it for packings of ``dem.geometry.bonds.CELL_SEARCH_MIN`` particles or
more (where the cells search one radius class, numba is loaded already); a static run of fewer particles loads no
numba.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange


@njit(cache=True, parallel=True)
def pair_geometry(x, radius, i, j):
    """``(r_i, r_j, d, h, L_i, L_j)`` of the bonds ``(i[k], j[k])``, each an array of one entry per bond (module
    docstring); ``L_i = -inf`` and ``L_j = +inf`` where the centres coincide (``d = 0``), as
    the numpy route of :mod:`dem.geometry.bonds` gives them.

    Parameters
    ----------
    x : numpy.ndarray
        (N, 3) particle centres, m.
    radius : numpy.ndarray
        (N,) particle radii, m.
    i, j : numpy.ndarray
        (M,) int, the two particles of every bond.

    Returns
    -------
    tuple of numpy.ndarray
        ``(r_i, r_j, d, h, L_i, L_j)``, (M,) each, m.
    """
    m = i.shape[0]
    r_i, r_j, d, h = np.empty(m), np.empty(m), np.empty(m), np.empty(m)
    l_i, l_j = np.empty(m), np.empty(m)
    for k in prange(m):
        a, b = i[k], j[k]
        vx, vy, vz = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        dk = math.sqrt(vx * vx + vy * vy + vz * vz)
        ra, rb = radius[a], radius[b]
        r_i[k], r_j[k], d[k] = ra, rb, dk
        h[k] = ra + rb - dk
        if dk > 0.0:
            la = 0.5 * (dk - (rb * rb - ra * ra) / dk)
        else:
            la = -np.inf
        l_i[k], l_j[k] = la, dk - la
    return r_i, r_j, d, h, l_i, l_j
