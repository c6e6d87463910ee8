r"""The half bodies of the union of spheres: how much more a cut sphere resists than the ball the pair law knows.

Under ``conductance.neck = "union"`` a particle is its sphere cut by the radical planes of all its necks
(:mod:`fem_neck.geometry.union`: Arzt's truncated sphere). The union's half-body law (``fem_neck/data/fit_union.json``,
:mod:`fem_neck.law`) is exact for a ball cut by one plane; every other neck of the particle removes a cap more, and
the heat from the centre to neck ``b`` crosses a narrower body. Along the neck's axis (``z`` from the centre,
:math:`0 \le z \le l_b`) the cut body's cross-section :math:`A_c(z)` is the disk :math:`\pi (r^2 - z^2)` of the ball
clipped by the other planes. A body of revolution of slowly varying radius :math:`\rho(z)` resists (slender-body
expansion of the Laplace equation, to second order in :math:`\rho'`)

.. math::

    R = \int \frac{1 + \rho'^2 / 2}{\kappa \pi \rho^2} \, dz,

and the difference between the cut body and the ball, with :math:`\rho = \sqrt{A / \pi}` for each, is added to the
half resistance of the law:

.. math::

    \frac{1}{K_b} = \frac{1}{K_b^{union}} + \Delta R_b, \qquad
    \Delta R_b = \frac{1}{\kappa} \int_0^{l_b} \left[\frac{1 + \rho_c'^2 / 2}{A_c}
    - \frac{1 + \rho_{ball}'^2 / 2}{A_{ball}}\right] dz,

with :math:`K_b^{union}` the half conductance of the union law, and :math:`\Delta R_b` at least zero: removing material
never lowers a body's resistance (Rayleigh's monotonicity), while the expansion's slope term, which grows without
bound where the ball's profile meets its surface, can outweigh the narrower section for a plane near the surface (a
BCC lattice's second neighbours just after they touch). Where no other plane crosses the half body the two
profiles are equal and :math:`\Delta R_b = 0`: a pair, a chain, or necks small and far apart keep the union law exactly.
Where another plane cuts the axis between the centre and the neck (:math:`A_c = 0` there: the neck's lens lies inside a
third sphere) the neck is no contact of the union at all and :math:`\Delta R_b` is infinite (its bond carries nothing).
The cross-sections are exact: the disk less a circular segment per plane where no two of the planes' lines cross inside
it, else the disk clipped by them (:mod:`fem_neck.geometry.cut_kernels`); on a uniform grid of ``SAMPLES`` intervals
with the derivative taken on the same grid for both profiles, so that they cancel exactly where they agree.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np

from fem_neck.geometry.cut_kernels import _clip, _face, ends_by_particle

SAMPLES = 32  # intervals of the grid along each half body
EMPTY = 1e-12  # a cross-section below this x pi r^2 is none: the axis has left the cut body
# A particle's work arrays: the section plane's basis u, w (3,), the other ends' lines in it (z, 3), the clipped
# polygon and the clipper's room, the areas of the cut and of the ball's sections along the half body (samples + 1)
Scratch = namedtuple("Scratch", ["u", "w", "lines", "poly", "work", "area", "ball"])


@numba.njit(cache=True)
def _basis(normal, u, w):
    """Two unit vectors ``u``, ``w`` orthogonal to the unit ``normal`` and to each other."""
    if abs(normal[0]) < 0.9:
        u[0], u[1], u[2] = 0.0, normal[2], -normal[1]
    else:
        u[0], u[1], u[2] = -normal[2], 0.0, normal[0]
    length = math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
    for c in range(3):
        u[c] /= length
    w[0] = normal[1] * u[2] - normal[2] * u[1]
    w[1] = normal[2] * u[0] - normal[0] * u[2]
    w[2] = normal[0] * u[1] - normal[1] * u[0]


@numba.njit(cache=True)
def _section(r, z, b, lo, hi, normals, planes, u, w, lines, poly, work):
    """Area of the cross-section at ``z`` along end ``b``'s normal of the sphere of radius ``r`` cut by the planes
    ``normals[e] . x <= planes[e]`` of the other ends ``lo <= e < hi``: the disk less the segment beyond each plane's
    line, exact while no two lines cross inside the disk; where two do (two necks meeting) the disk is clipped by
    every line (:mod:`fem_neck.geometry.cut_kernels`)."""
    rho2 = r * r - z * z
    if rho2 <= 0.0:
        return 0.0
    rho = math.sqrt(rho2)
    active = 0
    for e in range(lo, hi):  # the lines alpha s + beta t = gamma that cut the disk, normalised to unit (alpha, beta)
        if e == b:
            continue
        alpha = normals[e, 0] * u[0] + normals[e, 1] * u[1] + normals[e, 2] * u[2]
        beta = normals[e, 0] * w[0] + normals[e, 1] * w[1] + normals[e, 2] * w[2]
        along = normals[e, 0] * normals[b, 0] + normals[e, 1] * normals[b, 1] + normals[e, 2] * normals[b, 2]
        gamma = planes[e] - z * along
        reach = math.sqrt(alpha * alpha + beta * beta)
        if gamma >= rho * reach:
            continue  # the plane's line misses the section's disk
        if reach <= 1e-14 or gamma <= -rho * reach:
            return 0.0  # the whole section beyond the plane
        lines[active, 0], lines[active, 1], lines[active, 2] = alpha / reach, beta / reach, gamma / reach
        active += 1
    area = math.pi * rho2
    crossing = False
    for c in range(active):
        p = lines[c, 2]
        area -= rho2 * math.acos(p / rho) - p * math.sqrt(rho2 - p * p)
        for e in range(c):
            det = lines[c, 0] * lines[e, 1] - lines[c, 1] * lines[e, 0]
            if abs(det) <= 1e-14:  # parallel lines: the same side nests the segments; opposite sides leave a strip
                if lines[c, 0] * lines[e, 0] + lines[c, 1] * lines[e, 1] > 0.0:
                    crossing = True
                elif lines[c, 2] + lines[e, 2] <= 0.0:
                    return 0.0
                continue
            s = (lines[c, 2] * lines[e, 1] - lines[e, 2] * lines[c, 1]) / det
            t = (lines[c, 0] * lines[e, 2] - lines[e, 0] * lines[c, 2]) / det
            if s * s + t * t < rho2:
                crossing = True
    if not crossing:
        return max(area, 0.0)
    poly[0, 0], poly[0, 1] = -2.0 * rho, -2.0 * rho
    poly[1, 0], poly[1, 1] = 2.0 * rho, -2.0 * rho
    poly[2, 0], poly[2, 1] = 2.0 * rho, 2.0 * rho
    poly[3, 0], poly[3, 1] = -2.0 * rho, 2.0 * rho
    count = 4
    for c in range(active):
        count = _clip(poly, count, lines[c, 0], lines[c, 1], lines[c, 2], work)
        if count < 3:
            return 0.0
    return _face(poly, count, rho, 1.0)[0]


@numba.njit(cache=True)
def _half_body(r, b, lo, hi, normals, planes, scratch, samples):
    """``kappa Delta R`` of end ``b`` (module docstring), 1/m; infinite when the axis leaves the cut body.
    ``scratch``: the work arrays (:data:`Scratch`)."""
    u, w, lines, poly, work, area, ball = scratch
    length = planes[b]
    step = length / samples
    _basis(normals[b], u, w)
    for s in range(samples + 1):
        z = s * step
        area[s] = _section(r, z, b, lo, hi, normals, planes, u, w, lines, poly, work)
        ball[s] = math.pi * (r * r - z * z)
        if area[s] <= EMPTY * math.pi * r * r:
            return np.inf
    total = 0.0
    for s in range(samples + 1):
        p, q = max(s - 1, 0), min(s + 1, samples)
        span = (q - p) * step
        slope_c = (math.sqrt(area[q] / math.pi) - math.sqrt(area[p] / math.pi)) / span
        slope_b = (math.sqrt(ball[q] / math.pi) - math.sqrt(ball[p] / math.pi)) / span
        weight = 0.5 * step if s == 0 or s == samples else step
        total += weight * ((1.0 + 0.5 * slope_c * slope_c) / area[s] - (1.0 + 0.5 * slope_b * slope_b) / ball[s])
    return max(total, 0.0)


@numba.njit(cache=True, parallel=True)
def _cut_body_kernel(n, particle, normals, planes, radius, samples):
    m = len(particle)
    offsets, order = ends_by_particle(n, particle)
    z_max = int(np.max(offsets[1:] - offsets[:-1])) if m else 0
    sorted_normals = normals[order]
    sorted_planes = planes[order]
    out = np.zeros(m)
    for k in numba.prange(n):
        lo, hi = offsets[k], offsets[k + 1]
        if hi - lo < 2:
            continue
        scratch = Scratch(np.empty(3), np.empty(3), np.empty((z_max, 3)), np.empty((z_max + 4, 2)),
                          np.empty((2 * z_max + 8, 2)), np.empty(samples + 1), np.empty(samples + 1))
        for b in range(lo, hi):
            out[order[b]] = _half_body(radius[k], b, lo, hi, sorted_normals, sorted_planes, scratch, samples)
    return out


def cut_body_resistance(radius: np.ndarray, particle: np.ndarray, normals: np.ndarray, planes: np.ndarray,
                        samples: int = SAMPLES) -> np.ndarray:
    r""":math:`\kappa \Delta R` of every neck end (module docstring): how much more the particle's cut sphere resists from
    its centre to the neck than the ball does.

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    particle : numpy.ndarray
        The particle of every neck end (int).
    normals : numpy.ndarray
        The unit direction from the particle's centre toward every neck (one row each).
    planes : numpy.ndarray
        The distance from the particle's centre to every neck's plane (the radical plane, or the wall), m, in
        ``(0, r)``.
    samples : int
        Intervals of the grid along each half body.

    Returns
    -------
    numpy.ndarray
        :math:`\kappa \Delta R` per end, 1/m (0 where no other plane crosses the half body; ``inf`` where the neck lies
        inside a third sphere).
    """
    f = np.ascontiguousarray
    radius = f(radius, dtype=float)
    return _cut_body_kernel(len(radius), f(particle, dtype=np.int64), f(np.reshape(normals, (-1, 3)), dtype=float),
                            f(planes, dtype=float), radius, int(samples))
