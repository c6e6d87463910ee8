"""How much of each particle's surface sees the ambient: the exposed fraction for convection and radiation.

A particle buried in a packing neither convects to the surrounding gas nor radiates to the surroundings; one on a
face of the block does so through the part of its surface that faces outwards. The model: the exposed fraction of
particle i is the fraction of its surface points whose outward normal ray leaves the packing without meeting
another particle. The points are ``n`` directions spread evenly over the sphere (a Fibonacci lattice); a point
inside a neck (within a neighbour) is covered at once, so the necks' caps are subtracted too. An isolated particle
has fraction 1, a particle on a flat face of a dense block about 1/2 (the normals pointing out of the face), an
interior particle 0. For radiation this is the view factor to the surroundings with each surface element's view
taken along its normal; for convection it is the area the outer flow reaches.

The rays are traced through a uniform grid of cells (the particles binned by centre, cell edge the largest
diameter), visiting cells in the order the ray crosses them (Amanatides & Woo's 3D-DDA): O(N n) rays, each testing
only the particles near it. Compiled with numba (``cache=True``), loaded only by scenes with an ambient.
"""

from __future__ import annotations

import numpy as np
from numba import njit

DIRECTIONS = 96  # surface points per particle: the fraction is resolved to about 1 % (1/96)


def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere (equal-area Fibonacci lattice).

    Parameters
    ----------
    n : int
        Number of directions.

    Returns
    -------
    numpy.ndarray
        (n, 3) unit vectors.
    """
    k = np.arange(n) + 0.5
    z = 1.0 - 2.0 * k / n
    phi = np.pi * (1.0 + 5.0**0.5) * k
    s = np.sqrt(1.0 - z * z)
    return np.column_stack([s * np.cos(phi), s * np.sin(phi), z])


@njit(cache=True)
def _hits(x, radius, k, origin, direction, bins, cell):
    """Does the ray ``o + s d`` (s > 0; ``origin`` o and ``direction`` d as 3-tuples) meet a particle of cell ``cell``
    other than ``k``? ``bins``: ``(members, start, count)``, the particles of each cell."""
    ox, oy, oz = origin
    dx, dy, dz = direction
    members, start, count = bins
    for e in range(start[cell], start[cell] + count[cell]):
        m = members[e]
        if m == k:
            continue
        px, py, pz = ox - x[m, 0], oy - x[m, 1], oz - x[m, 2]
        b = px * dx + py * dy + pz * dz
        c = px * px + py * py + pz * pz - radius[m] * radius[m]
        if c <= 0.0:  # the origin lies inside particle m (a neck): covered
            return True
        if b < 0.0 and b * b > c:  # the particle is ahead and the ray passes through it
            return True
    return False


@njit(cache=True)
def _exposed(x, radius, directions, lo, size, ncell, members, start, count):
    n = x.shape[0]
    out = np.zeros(n)
    for k in range(n):
        free = 0
        for q in range(directions.shape[0]):
            dx, dy, dz = directions[q, 0], directions[q, 1], directions[q, 2]
            ox, oy, oz = x[k, 0] + radius[k] * dx, x[k, 1] + radius[k] * dy, x[k, 2] + radius[k] * dz
            c0 = min(max(int((ox - lo[0]) / size), 0), ncell[0] - 1)
            c1 = min(max(int((oy - lo[1]) / size), 0), ncell[1] - 1)
            c2 = min(max(int((oz - lo[2]) / size), 0), ncell[2] - 1)
            step0 = 1 if dx > 0 else -1
            step1 = 1 if dy > 0 else -1
            step2 = 1 if dz > 0 else -1
            inf = 1e300
            t0 = ((lo[0] + (c0 + (1 if dx > 0 else 0)) * size) - ox) / dx if dx != 0.0 else inf
            t1 = ((lo[1] + (c1 + (1 if dy > 0 else 0)) * size) - oy) / dy if dy != 0.0 else inf
            t2 = ((lo[2] + (c2 + (1 if dz > 0 else 0)) * size) - oz) / dz if dz != 0.0 else inf
            d0 = size / abs(dx) if dx != 0.0 else inf
            d1 = size / abs(dy) if dy != 0.0 else inf
            d2 = size / abs(dz) if dz != 0.0 else inf
            hit = False
            # the ray is tested against the particles of every cell it crosses and of the cells around them
            # (a particle binned by its centre reaches up to one cell into its neighbours)
            while True:
                for a in range(max(c0 - 1, 0), min(c0 + 2, ncell[0])):
                    for b in range(max(c1 - 1, 0), min(c1 + 2, ncell[1])):
                        for c in range(max(c2 - 1, 0), min(c2 + 2, ncell[2])):
                            if _hits(x, radius, k, (ox, oy, oz), (dx, dy, dz), (members, start, count),
                                     (a * ncell[1] + b) * ncell[2] + c):
                                hit = True
                                break
                        if hit:
                            break
                    if hit:
                        break
                if hit:
                    break
                if t0 <= t1 and t0 <= t2:
                    c0 += step0
                    t0 += d0
                    if c0 < 0 or c0 >= ncell[0]:
                        break
                elif t1 <= t2:
                    c1 += step1
                    t1 += d1
                    if c1 < 0 or c1 >= ncell[1]:
                        break
                else:
                    c2 += step2
                    t2 += d2
                    if c2 < 0 or c2 >= ncell[2]:
                        break
            if not hit:
                free += 1
        out[k] = free / directions.shape[0]
    return out


def exposed_fraction(position: np.ndarray, radius: np.ndarray, directions: int = DIRECTIONS) -> np.ndarray:
    """The exposed fraction of every particle's surface (module docstring), in [0, 1].

    Parameters
    ----------
    position : numpy.ndarray
        (N, 3) particle centres (m).
    radius : numpy.ndarray
        (N,) radii (m).
    directions : int
        Number of directions sampled over each surface (:func:`fibonacci_directions`).

    Returns
    -------
    numpy.ndarray
        (N,) the exposed fractions.
    """
    x = np.ascontiguousarray(position, dtype=float)
    r = np.ascontiguousarray(radius, dtype=float)
    if len(r) == 0:
        return np.zeros(0)
    size = 2.0 * float(r.max())
    lo = x.min(axis=0) - size
    ncell = np.maximum(1, np.ceil((x.max(axis=0) + size - lo) / size).astype(np.int64))
    if np.prod(ncell.astype(float)) > 5e7:  # a sparse cloud spread over a huge box: coarser cells, same answer
        size *= (np.prod(ncell.astype(float)) / 5e7) ** (1.0 / 3.0)
        ncell = np.maximum(1, np.ceil((x.max(axis=0) + size - lo) / size).astype(np.int64))
    cell = np.minimum(((x - lo) / size).astype(np.int64), ncell - 1)
    flat = (cell[:, 0] * ncell[1] + cell[:, 1]) * ncell[2] + cell[:, 2]
    members = np.argsort(flat, kind="stable").astype(np.int64)
    total = int(np.prod(ncell))
    count = np.bincount(flat, minlength=total).astype(np.int64)
    start = np.concatenate([[0], np.cumsum(count)[:-1]]).astype(np.int64)
    return _exposed(x, r, fibonacci_directions(directions), lo, size, ncell, members, start, count)
