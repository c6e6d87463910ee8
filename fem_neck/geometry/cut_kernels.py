"""The compiled kernels of :func:`fem_neck.geometry.union.cut_spheres`: every sphere cut by the radical planes of its
necks, its faces clipped by one another and integrated in closed form (the module docstring of
:mod:`fem_neck.geometry.union` derives them). Apart from it so that reading necks loads no numba."""

from __future__ import annotations

import math

import numpy as np
from numba import njit


@njit(cache=True)
def ends_by_particle(n, particle):
    """Bond ends grouped by particle (a counting sort): ``(offsets, order)``, the ends of particle ``k`` being
    ``order[offsets[k]:offsets[k + 1]]`` in their original order; ``particle`` holds the particle (int, < ``n``) of
    every end."""
    m = len(particle)
    counts = np.zeros(n + 1, dtype=np.int64)
    for e in range(m):
        counts[particle[e] + 1] += 1
    offsets = np.cumsum(counts)
    fill = offsets[:-1].copy()
    order = np.empty(m, dtype=np.int64)
    for e in range(m):
        order[fill[particle[e]]] = e
        fill[particle[e]] += 1
    return offsets, order


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
def cut_spheres_kernel(n, radius, i, j, vectors, d):
    """Volumes, free areas, meeting flags (per particle) and face areas (per bond end) of the cut spheres
    (:func:`fem_neck.geometry.union.cut_spheres`, which checks the input)."""
    m = len(i)
    offsets, ends = ends_by_particle(n, np.concatenate((i, j)))  # end e < m: bond e on i, else e - m on j
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
