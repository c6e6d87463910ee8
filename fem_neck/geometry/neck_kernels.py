"""The compiled Newton of :func:`fem_neck.geometry.neck_radius` for many bonds: the blocks of ``_CHUNK`` bonds of the
numpy route, each block on one of numba's threads, with that route's own functions compiled (``_validated``'s
arithmetic, :func:`~fem_neck.geometry.newton_start`, ``_z_and_slope``), one bond after another in registers instead
of a temporary array per operation. Every bond of a block takes as many iterations as the block's slowest, as in numpy,
and every operation is the same IEEE operation in the same order, so the radii are the numpy route's to the bit, on
any number of threads. Apart from :mod:`fem_neck.geometry` so that a smaller call loads no numba."""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from fem_neck import geometry as _g

# numpy's error model: a division is the processor's, without the test for a zero divisor that Python's needs at
# every one (which keeps the loops from being vectorised; the results are the same IEEE quotients)
_compiled = njit(error_model="numpy")
_cap_height = _compiled(_g.cap_height)
_phi = _compiled(_g._phi)
_newton_start = _compiled(_g.newton_start)
_z_and_slope = _compiled(_g._z_and_slope)

OUT_OF_RANGE, NOT_CONVERGED = 1, 2  # a block's flag: an input outside the model's range, a Newton that did not end


@njit(cache=True, parallel=True, error_model="numpy")
def newton_blocks(r_i, r_j, h, out):
    """The volume-conserving neck radius (Rojek 2022, eqs. 27-33) of every bond, ``_CHUNK`` bonds per block.

    Parameters
    ----------
    r_i, r_j : numpy.ndarray
        (M,) float, the radii of the bonds' two spheres, m.
    h : numpy.ndarray
        (M,) float, the bonds' overlaps, m.
    out : numpy.ndarray
        (M,) float, written with the neck radii (m) of every block whose flag is 0.

    Returns
    -------
    numpy.ndarray
        A flag per block (uint8): 0, ``OUT_OF_RANGE`` (an input outside the model's range, as ``_validated`` refuses
        it) or ``NOT_CONVERGED``.
    """
    m = h.shape[0]
    chunk = _g._CHUNK
    blocks = (m + chunk - 1) // chunk
    flags = np.zeros(blocks, dtype=np.uint8)
    for b in prange(blocks):
        lo = b * chunk
        k = min(m, lo + chunk) - lo
        ri, rj, hs = np.empty(k), np.empty(k), np.empty(k)
        scale, h_max, a, steps = np.empty(k), np.empty(k), np.empty(k), np.empty(k)
        for e in range(k):  # _validated, then _solve's cap on the ratio and newton_start
            x_i, x_j, x_h = r_i[lo + e], r_j[lo + e], h[lo + e]
            if not (x_i > 0.0 and x_i < np.inf and x_j > 0.0 and x_j < np.inf):
                flags[b] = OUT_OF_RANGE
            s = np.minimum(x_i, x_j)
            u_i, u_j = x_i / s, x_j / s
            u_h = x_h / s
            u_max = np.maximum(u_i, u_j)
            top = 1.0 / 3.0 + _phi(_cap_height(u_max, 1.0), u_max)
            if not (u_h > 0.0 and u_h <= top * (1.0 + _g._LIMIT_SLACK)):
                flags[b] = OUT_OF_RANGE
            ri[e], rj[e] = np.minimum(u_i, _g._RATIO_CAP), np.minimum(u_j, _g._RATIO_CAP)
            hs[e], scale[e], h_max[e] = np.minimum(u_h, top), s, top
        if flags[b]:
            continue
        for e in range(k):
            a[e] = _newton_start(ri[e], rj[e], hs[e], h_max[e])
        for e in range(k):  # the first iteration, from the bracket's right end where the start's slope is not > 0
            z, slope = _z_and_slope(a[e], ri[e], rj[e], hs[e])
            if not slope > 0.0:
                a[e] = 1.0
                z, slope = _z_and_slope(a[e], ri[e], rj[e], hs[e])
            steps[e] = z / np.maximum(slope, _g._TINY)
        flags[b] = NOT_CONVERGED
        for iterations in range(1, _g._MAX_ITERATIONS + 1):
            if iterations > 1:
                for e in range(k):
                    z, slope = _z_and_slope(a[e], ri[e], rj[e], hs[e])
                    steps[e] = z / np.maximum(slope, _g._TINY)
            late = 0
            for e in range(k):
                a[e] = np.minimum(a[e] - steps[e], 1.0)
                late += not np.abs(steps[e]) <= _g._STEP_TOL * a[e]
            if late == 0:
                flags[b] = 0
                break
        if not flags[b]:
            for e in range(k):
                out[lo + e] = a[e] * scale[e]
    return flags
