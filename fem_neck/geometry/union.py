"""The union of spheres: a geometry of sintered particles defined at every density.

The pair-neck models of :mod:`fem_neck.geometry` (Rojek 2022, eqs. 21-34) describe one neck between two spheres;
once two necks of one particle meet they have no answer. The *union of the spheres* has one at every density: it is
the truncated-sphere model of Arzt (1982), each sphere cut by its radical planes. For any radii the union of the cut
spheres is the union of the spheres, because the radical planes are the faces of the power (Laguerre) diagram of
the spheres, which partitions space, and the union of the balls meets the power cell of ball ``k`` in ball ``k``
alone. It is also how a packing fitted to X-ray tomography (centres and radii of overlapping spheres) reads.

**A neck** of the union is the circle where two spheres meet (:func:`lens`): with the centre distance ``d``, the
radical plane lies at ``l_i = (d^2 + r_i^2 - r_j^2) / (2 d)`` from centre ``i`` (``l_j = d - l_i``) and the circle
has the radius ``a = sqrt(r_i^2 - l_i^2)`` (Zohdi 2014, eqs. 7-12 use the same lens). Second neighbours that
overlap are necks too. A neck is seen from its particle's centre as a cone of half-angle
``atan2(a, l)`` (:func:`angular_radius`); two necks of one particle *meet* when their cones overlap
(:func:`necks_meet`), which is where the pair-neck models end.

**Volumes and areas** (:func:`cut_spheres`). The cut sphere ``k`` (ball ``k`` and the half-spaces
``n_b . (x - x_k) <= l_b`` of its necks) is convex, and by the divergence theorem with the origin at its centre
its volume is ``V = (r A_free + sum_b l_b A_b) / 3``, where ``A_free`` is the area of its spherical surface left
and ``A_b`` the area of its flat face ``b`` (the disk of neck ``b`` less what other faces cut off). With the centre
inside the cut sphere (every ``l_b > 0``), the faces and the free surface are seen from the centre in disjoint solid
angles that fill the sphere, so ``A_free = r^2 (4 pi - sum_b Omega_b)``. Each face is a convex polygon (the
half-planes the other faces leave in its plane) intersected with its disk; its area and its solid angle are integrals
over the face of functions of the distance ``rho`` from the foot of the centre's perpendicular, so they are sums over
the polygon's edges of signed sectors around that foot, each integrated in closed form (the edge ``rho = p / cos
phi``: ``int p^2 / (2 cos^2 phi) d phi = p^2 tan(phi) / 2`` for the area and ``int (1 - h cos(phi) / sqrt(h^2
cos^2 phi + p^2)) d phi = phi - arcsin(h sin(phi) / sqrt(h^2 + p^2))`` for the solid angle, the circle ``rho = a``
linear in ``phi``). The volumes are exact to round-off, and their sum is the volume of the union.
These areas also give the derivatives that keep volumes under growth: moving face ``b`` outward by ``dl`` adds
``A_b dl``, and growing the radius by ``dr`` adds ``A_free dr``.

Where necks do not meet, the cut sphere is the sphere less its caps, ``V = 4/3 pi r^3 - sum_b pi (r - l_b)^2 (2 r +
l_b) / 3``, and this is what the kernel computes for such particles.

The range: two spheres have a neck for ``|r_i - r_j| < d < r_i + r_j``; the cut sphere needs its centre on its own
side of every radical plane, ``l_b > 0`` (``d^2 > r_j^2 - r_i^2``: the centre of the smaller sphere outside the
larger), as the lens of :mod:`dem.geometry.bonds` does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from fem_neck.geometry import check_positive


@dataclass(frozen=True)
class Lens:
    """The neck of two overlapping spheres in the union: circle radius ``a`` and the distances ``l_i``, ``l_j`` (m)
    from each centre to the radical plane that holds the circle (``l_i + l_j = d``)."""

    a: np.ndarray
    l_i: np.ndarray
    l_j: np.ndarray


def lens(r_i, r_j, d) -> Lens:
    """The neck circle of two spheres of radii ``r_i``, ``r_j`` (m) whose centres are ``d`` (m) apart (module
    docstring); arrays broadcast. ``ValueError`` unless ``|r_i - r_j| < d < r_i + r_j`` (the spheres overlap and
    neither holds the other)."""
    r_i = check_positive("r_i", r_i)
    r_j = check_positive("r_j", r_j)
    d = check_positive("d", d)
    r_i, r_j, d = np.broadcast_arrays(r_i, r_j, d)
    bad = ~((d > np.abs(r_i - r_j)) & (d < r_i + r_j))
    if np.any(bad):
        k = np.unravel_index(int(np.flatnonzero(bad)[0]), bad.shape)
        raise ValueError(f"d = {d[k]!r}: two spheres of radii {r_i[k]!r} and {r_j[k]!r} meet in a circle only for "
                         f"|r_i - r_j| < d < r_i + r_j")
    l_i = 0.5 * (d + (r_i - r_j) * (r_i + r_j) / d)
    l_j = d - l_i
    a = np.sqrt(np.maximum((r_i - l_i) * (r_i + l_i), 0.0))
    return Lens(a[()], l_i[()], l_j[()])


def angular_radius(a, l):
    """Half-angle (rad) of the cone in which a neck of radius ``a`` whose plane lies ``l`` from the centre is seen
    from the centre: ``atan2(a, l)``. For a pair neck (:mod:`fem_neck.geometry`) the circle on the sphere lies at
    ``l = sqrt(r^2 - a^2)``, so the angle is ``arcsin(a / r)``."""
    return np.arctan2(a, l)


@dataclass(frozen=True)
class CutSpheres:
    """The cut spheres of a packing (:func:`cut_spheres`): per particle its ``volume`` (m^3), the area
    ``free_area`` (m^2) of its spherical surface left and ``meeting`` (whether two of its necks meet); per bond the
    areas ``face_i``, ``face_j`` (m^2) of the flat faces the neck leaves on particle ``i`` and on ``j`` (equal: the
    face is one piece of the radical plane)."""

    volume: np.ndarray
    free_area: np.ndarray
    meeting: np.ndarray
    face_i: np.ndarray
    face_j: np.ndarray


def cut_spheres(radius, i, j, vectors) -> CutSpheres:
    """Cut every sphere by the radical planes of its necks (module docstring).

    Parameters
    ----------
    radius : array (n,)
        Particle radii, m.
    i, j : int arrays (m,)
        The overlapping pairs (each once; ``j`` may be a periodic image of a particle, given by ``vectors``).
    vectors : array (m, 3)
        ``x_j - x_i`` of every pair (m), the image's in a periodic packing.

    Returns
    -------
    CutSpheres
        Volumes, free areas, whether necks meet, per particle; face areas per bond. ``ValueError`` for a pair that
        does not overlap, one sphere holding the other, or a centre beyond a radical plane (``d^2 <= r_j^2 -
        r_i^2``), naming the first.
    """
    radius = check_positive("radius", np.asarray(radius, dtype=float).reshape(-1))
    i = np.asarray(i, dtype=np.int64).reshape(-1)
    j = np.asarray(j, dtype=np.int64).reshape(-1)
    vectors = np.asarray(vectors, dtype=float).reshape(-1, 3)
    n = len(radius)
    if not (len(i) == len(j) == len(vectors)):
        raise ValueError(f"i, j and vectors: {len(i)}, {len(j)} and {len(vectors)} entries, must be as many")
    if len(i) and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n):
        raise ValueError(f"i, j: particle indices must lie in 0..{n - 1}")
    d = np.linalg.norm(vectors, axis=1)
    if len(i):
        lens(radius[i], radius[j], d)  # the range of every pair, with its message
        l_i = 0.5 * (d + (radius[i] - radius[j]) * (radius[i] + radius[j]) / d)
        beyond = (l_i <= 0.0) | (d - l_i <= 0.0)
        if np.any(beyond):
            b = int(np.flatnonzero(beyond)[0])
            raise ValueError(f"pair ({i[b]}, {j[b]}): d = {d[b]:.6g} with radii {radius[i[b]]:.6g} and "
                             f"{radius[j[b]]:.6g} puts a centre beyond their radical plane (the union reading needs "
                             f"d^2 > |r_j^2 - r_i^2|)")
    out = _cut_spheres(n, radius, i, j, np.ascontiguousarray(vectors), d)
    m = len(i)
    return CutSpheres(out[0], out[1], out[2].astype(bool), out[3][:m], out[3][m:])


def necks_meet(n: int, particle, direction, angle) -> np.ndarray:
    """Whether two necks of each of ``n`` particles meet (bool per particle), for any neck reading.

    Parameters
    ----------
    n : int
        Number of particles.
    particle : int array (e,)
        The particle of each neck end (a pair bond has two ends, a wall bond one).
    direction : array (e, 3)
        The direction from that particle's centre toward the neck (any length but zero).
    angle : array (e,)
        Half-angle (rad) of the cone in which the neck is seen from the centre (:func:`angular_radius`).

    Two necks of one particle meet when the angle between their directions is at most the sum of their half-angles.
    """
    particle = np.ascontiguousarray(particle, dtype=np.int64).reshape(-1)
    direction = np.ascontiguousarray(direction, dtype=float).reshape(-1, 3)
    angle = np.ascontiguousarray(angle, dtype=float).reshape(-1)
    if not (len(particle) == len(direction) == len(angle)):
        raise ValueError(f"particle, direction and angle: {len(particle)}, {len(direction)} and {len(angle)} "
                         f"entries, must be as many")
    if len(particle) and (particle.min() < 0 or particle.max() >= n):
        raise ValueError(f"particle: indices must lie in 0..{n - 1}")
    return _necks_meet(int(n), particle, direction, angle).astype(bool)


@njit(cache=True)
def _group_ends(n, i, j):
    """The bond ends grouped by particle (a counting sort): end ``e < m`` is bond ``e`` on ``i``, ``e >= m`` bond
    ``e - m`` on ``j``; particle ``k``'s ends are ``ends[offsets[k]:offsets[k + 1]]``."""
    m = len(i)
    counts = np.zeros(n + 1, dtype=np.int64)
    for e in range(2 * m):
        counts[(i[e] if e < m else j[e - m]) + 1] += 1
    offsets = np.cumsum(counts)
    fill = offsets[:-1].copy()
    ends = np.empty(2 * m, dtype=np.int64)
    for e in range(2 * m):
        k = i[e] if e < m else j[e - m]
        ends[fill[k]] = e
        fill[k] += 1
    return offsets, ends


@njit(cache=True)
def _end_normal(e, m, vectors, normal):
    """The unit direction of bond end ``e`` from its particle toward the partner, into ``normal``; returns ``d``."""
    b = e if e < m else e - m
    sign = 1.0 if e < m else -1.0
    d = math.sqrt(vectors[b, 0] ** 2 + vectors[b, 1] ** 2 + vectors[b, 2] ** 2)
    for c in range(3):
        normal[c] = sign * vectors[b, c] / d
    return d


@njit(cache=True)
def _necks_meet(n, particle, direction, angle):
    e = len(particle)
    counts = np.zeros(n + 1, dtype=np.int64)
    for x in range(e):
        counts[particle[x] + 1] += 1
    offsets = np.cumsum(counts)
    fill = offsets[:-1].copy()
    ends = np.empty(e, dtype=np.int64)
    for x in range(e):
        ends[fill[particle[x]]] = x
        fill[particle[x]] += 1
    out = np.zeros(n, dtype=np.uint8)
    for k in range(n):
        lo, hi = offsets[k], offsets[k + 1]
        for x in range(lo, hi):
            b = ends[x]
            nb = math.sqrt(direction[b, 0] ** 2 + direction[b, 1] ** 2 + direction[b, 2] ** 2)
            for y in range(x + 1, hi):
                c = ends[y]
                nc = math.sqrt(direction[c, 0] ** 2 + direction[c, 1] ** 2 + direction[c, 2] ** 2)
                cos_g = (direction[b, 0] * direction[c, 0] + direction[b, 1] * direction[c, 1]
                         + direction[b, 2] * direction[c, 2]) / (nb * nc)
                if math.acos(min(max(cos_g, -1.0), 1.0)) <= angle[b] + angle[c]:
                    out[k] = 1
                    break
            if out[k]:
                break
    return out


@njit(cache=True)
def _sector(phi_a, phi_b, p, a, h):
    """Area and solid angle (seen from the point ``h`` above the foot) of the sector between the polar angles
    ``phi_a < phi_b`` (measured from the perpendicular onto the edge line, at distance ``p`` from the foot) bounded
    by the edge line or the circle of radius ``a``, whichever is nearer."""
    area = 0.0
    solid = 0.0
    circle_solid = 1.0 - h / math.sqrt(h * h + a * a)
    inner = math.acos(p / a) if p < a else 0.0  # |phi| < inner: the edge lies inside the circle
    lo, hi = max(phi_a, -inner), min(phi_b, inner)
    if hi > lo:  # the edge part
        q = math.sqrt(h * h + p * p)
        area += 0.5 * p * p * (math.tan(hi) - math.tan(lo))
        solid += (hi - lo) - (math.asin(h * math.sin(hi) / q) - math.asin(h * math.sin(lo) / q))
        arc = max(lo - phi_a, 0.0) + max(phi_b - hi, 0.0)
    else:
        arc = phi_b - phi_a
    area += 0.5 * a * a * arc
    solid += circle_solid * arc
    return area, solid


@njit(cache=True)
def _face(poly, count, a, h):
    """Area and solid angle of the polygon ``poly[:count]`` (counter-clockwise, in the face's plane, origin at the
    foot of the centre's perpendicular, ``h`` below) intersected with the disk of radius ``a`` about the origin:
    signed sectors over the edges (module docstring)."""
    area = 0.0
    solid = 0.0
    for v in range(count):
        x1, y1 = poly[v, 0], poly[v, 1]
        x2, y2 = poly[(v + 1) % count, 0], poly[(v + 1) % count, 1]
        cross = x1 * y2 - y1 * x2
        dx, dy = x2 - x1, y2 - y1
        length2 = dx * dx + dy * dy
        if length2 <= 0.0 or abs(cross) <= 1e-15 * length2:
            continue  # an edge on a line through the foot spans no sector
        t = -(x1 * dx + y1 * dy) / length2
        fx, fy = x1 + t * dx, y1 + t * dy  # the foot of the perpendicular onto the edge's line
        p = math.sqrt(fx * fx + fy * fy)
        normal = math.atan2(fy, fx)
        phi1 = math.atan2(y1, x1) - normal
        phi1 = (phi1 + math.pi) % (2.0 * math.pi) - math.pi
        span = math.atan2(cross, x1 * x2 + y1 * y2)  # signed angle from vertex 1 to vertex 2, in (-pi, pi)
        phi2 = phi1 + span
        sa, ss = _sector(min(phi1, phi2), max(phi1, phi2), p, a, h)
        sign = 1.0 if span > 0.0 else -1.0
        area += sign * sa
        solid += sign * ss
    return area, solid


@njit(cache=True)
def _clip(poly, count, alpha, beta, gamma, work):
    """Clip the convex polygon ``poly[:count]`` by the half-plane ``alpha x + beta y <= gamma`` (Sutherland-Hodgman)
    into ``work``; returns the new count (the result is copied back into ``poly``)."""
    out = 0
    for v in range(count):
        x1, y1 = poly[v, 0], poly[v, 1]
        x2, y2 = poly[(v + 1) % count, 0], poly[(v + 1) % count, 1]
        s1 = alpha * x1 + beta * y1 - gamma
        s2 = alpha * x2 + beta * y2 - gamma
        if s1 <= 0.0:
            work[out, 0], work[out, 1] = x1, y1
            out += 1
        if (s1 < 0.0 < s2) or (s2 < 0.0 < s1):
            t = s1 / (s1 - s2)
            work[out, 0], work[out, 1] = x1 + t * (x2 - x1), y1 + t * (y2 - y1)
            out += 1
    for v in range(out):
        poly[v, 0], poly[v, 1] = work[v, 0], work[v, 1]
    return out


@njit(cache=True)
def _cut_spheres(n, radius, i, j, vectors, d):
    m = len(i)
    offsets, ends = _group_ends(n, i, j)
    volume = np.empty(n)
    free = np.empty(n)
    meeting = np.zeros(n, dtype=np.uint8)
    face = np.zeros(2 * m)
    z_max = 0
    for k in range(n):
        z_max = max(z_max, offsets[k + 1] - offsets[k])
    normal = np.empty((max(z_max, 1), 3))
    offset = np.empty(max(z_max, 1))
    half = np.empty(max(z_max, 1))
    poly = np.empty((z_max + 5, 2))
    work = np.empty((z_max + 5, 2))
    u = np.empty(3)
    w = np.empty(3)
    for k in range(n):
        r = radius[k]
        lo, hi = offsets[k], offsets[k + 1]
        z = hi - lo
        for b in range(z):
            e = ends[lo + b]
            dist = _end_normal(e, m, vectors, normal[b])
            partner = j[e] if e < m else i[e - m]
            offset[b] = 0.5 * (dist + (r - radius[partner]) * (r + radius[partner]) / dist)
            half[b] = math.atan2(math.sqrt(max((r - offset[b]) * (r + offset[b]), 0.0)), offset[b])
        met = False
        for b in range(z):
            for c in range(b + 1, z):
                cos_g = min(max(normal[b, 0] * normal[c, 0] + normal[b, 1] * normal[c, 1]
                                + normal[b, 2] * normal[c, 2], -1.0), 1.0)
                if math.acos(cos_g) <= half[b] + half[c]:
                    met = True
        meeting[k] = met
        if not met:  # the sphere less its caps
            vol = 4.0 / 3.0 * math.pi * r ** 3
            area = 4.0 * math.pi * r * r
            for b in range(z):
                cap = r - offset[b]
                vol -= math.pi * cap * cap * (2.0 * r + offset[b]) / 3.0
                area -= 2.0 * math.pi * r * cap
                face[ends[lo + b]] = math.pi * (r - offset[b]) * (r + offset[b])
            volume[k], free[k] = vol, area
            continue
        solid_total = 0.0
        flat = 0.0
        for b in range(z):
            nb = normal[b]
            # an orthonormal basis (u, w) of face b's plane
            if abs(nb[0]) < 0.9:
                u[0], u[1], u[2] = 0.0, nb[2], -nb[1]
            else:
                u[0], u[1], u[2] = -nb[2], 0.0, nb[0]
            s = math.sqrt(u[0] ** 2 + u[1] ** 2 + u[2] ** 2)
            for c in range(3):
                u[c] /= s
            w[0] = nb[1] * u[2] - nb[2] * u[1]
            w[1] = nb[2] * u[0] - nb[0] * u[2]
            w[2] = nb[0] * u[1] - nb[1] * u[0]
            a = math.sqrt(max((r - offset[b]) * (r + offset[b]), 0.0))
            box = 2.0 * a
            poly[0, 0], poly[0, 1] = -box, -box
            poly[1, 0], poly[1, 1] = box, -box
            poly[2, 0], poly[2, 1] = box, box
            poly[3, 0], poly[3, 1] = -box, box
            count = 4
            for c in range(z):
                if c == b:
                    continue
                nc = normal[c]
                cos_g = nb[0] * nc[0] + nb[1] * nc[1] + nb[2] * nc[2]
                if math.acos(min(max(cos_g, -1.0), 1.0)) >= half[b] + half[c]:
                    continue  # face c's cap misses face b's disk: it cuts nothing off it
                # x = offset_b nb + s u + t w lies in face c's half-space: alpha s + beta t <= gamma
                alpha = nc[0] * u[0] + nc[1] * u[1] + nc[2] * u[2]
                beta = nc[0] * w[0] + nc[1] * w[1] + nc[2] * w[2]
                gamma = offset[c] - offset[b] * cos_g
                count = _clip(poly, count, alpha, beta, gamma, work)
                if count == 0:
                    break
            fa, fs = _face(poly, count, a, offset[b]) if count >= 3 else (0.0, 0.0)
            face[ends[lo + b]] = fa
            flat += offset[b] * fa
            solid_total += fs
        area = r * r * (4.0 * math.pi - solid_total)
        volume[k] = (r * area + flat) / 3.0
        free[k] = area
    return volume, free, meeting, face
