r"""The pair bonds' geometry of :func:`dem.geometry.bonds.find_bonds` in one compiled pass on numba's threads: both
radii, the overlap, the distances from the centres to the radical plane and whether the bond may lie beyond the
contact model's range, where numpy's route makes a fresh array for nearly every operation (about a dozen passes over
the bonds and five temporaries of a bond each). Every value is the same IEEE operation in the same order as numpy's
(the lens planes of :mod:`dem.geometry.bonds`), so the results are that route's to the bit, on any number of threads.
Apart from :mod:`dem.geometry.bonds` so that a smaller packing loads no numba."""

from __future__ import annotations

import numpy as np
from numba import njit, prange


def pair_geometry(radius, i, j, d, lens: bool):
    r"""Per bond :math:`(i, j)` at centre distance :math:`d`: :math:`r_i`, :math:`r_j`, :math:`h = r_i + r_j - d`,
    the radical plane's distances :math:`L_i = (d - (r_j^2 - r_i^2) / d) / 2` (Zohdi 2014, eq. 12;
    :math:`-\infty` at :math:`d = 0`) and :math:`L_j = d - L_i`, and a flag: with ``lens``, :math:`L_i < 0` or
    :math:`L_j < 0` (beyond the lens' range); otherwise :math:`h > \min(r_i, r_j) / 3`, where a neck's range
    (``fem_neck.geometry.max_overlap``, at least a third of the smaller radius) may end.

    Parameters
    ----------
    radius : numpy.ndarray
        (N,) particle radii (m).
    i, j : numpy.ndarray
        (M,) the bonds' particles.
    d : numpy.ndarray
        (M,) the bonds' centre distances (m).
    lens : bool
        Flag the bonds beyond the lens' range instead of those a neck's range may not reach.

    Returns
    -------
    tuple of numpy.ndarray
        ``(r_i, r_j, h, l_i, l_j, flag)``: five (M,) float arrays (m) and a bool one.
    """
    m = len(d)  # numpy's arrays (huge pages asked for), not numba's (4 kB pages: three times the kernel's faults)
    out = tuple(np.empty(m) for _ in range(5)) + (np.empty(m, dtype=bool),)
    _pair_geometry(radius, i, j, d, lens, *out)
    return out


@njit(cache=True, parallel=True, error_model="numpy")
def _pair_geometry(radius, i, j, d, lens, r_i, r_j, h, l_i, l_j, flag):
    """:func:`pair_geometry` into its arrays."""
    for k in prange(d.shape[0]):
        a, b, dist = radius[i[k]], radius[j[k]], d[k]
        r_i[k], r_j[k] = a, b
        overlap = a + b
        overlap -= dist
        h[k] = overlap
        if dist > 0:
            plane = 0.5 * (dist - (b * b - a * a) / dist)
        else:
            plane = -np.inf
        l_i[k] = plane
        l_j[k] = dist - plane
        if lens:
            flag[k] = plane < 0 or dist - plane < 0
        else:
            flag[k] = overlap > min(a, b) / 3.0
