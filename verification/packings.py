"""Random sintered packings that both the periodic-cell FE and the periodic DEM solve exactly.

The FE of :mod:`fem_neck.lattice` solves the mirror cell ``[0, P/2]^3`` of a packing that is mirror-symmetric about
``x = 0``, ``y = 0`` and ``z = 0``. :func:`mirror_packing` builds such a packing from ``n`` random spheres in the
mirror cell: their images under the three mirrors fill the period ``P`` (8 n spheres), and a sphere near a mirror
plane is bonded to its own image across it. The spheres are placed by minimising soft pair energies over the base
positions (the energy of the whole period, its gradient gathered from the 8 images of each sphere):

1. *jamming*: overlapping spheres repel; the packing fraction is bisected (positions and period scaled together)
   for the densest state in which the repulsion relaxes to zero: the jamming point, a disordered packing whose
   contacts touch;
2. *sintering*: positions and period shrink by one factor until the mean relative overlap of the touching pairs
   is ``overlap``;
3. *clean-up*: the overlapping pairs are pulled into the overlap range whose necks lie between ``min_neck`` and
   ``max_neck`` (a/r) and all other pairs pushed apart, until the set of overlapping pairs no longer changes.

The result is checked (:func:`fem_neck.lattice.cells.check_cell`, the neck sizes and the angular margin between neck
circles on one sphere) and redrawn from the next attempt until it passes. In a period only a few diameters wide
the mirror planes act like walls, so these packings jam loose (packing fraction ~0.4, coordination ~4-5).

:func:`union_packing` reads the packing as the union of its spheres (``neck = "union"``, defined at every density):
step 2 shrinks the jammed packing until the union is as dense as asked, step 3 keeps every neck at least
``min_neck`` wide, and the necks of one particle may meet.
"""

from __future__ import annotations

import numpy as np
from scipy.optimize import minimize
from scipy.spatial import cKDTree

from fem_neck.geometry import neck_radius
from fem_neck.lattice import PeriodicCell, check_cell

SIGNS = np.array([(sx, sy, sz) for sx in (1, -1) for sy in (1, -1) for sz in (1, -1)], dtype=float)


def _images(x, period):
    """The 8 mirror images of the base positions (n, 3) in the period: (8 n, 3), image c of sphere k at c n + k."""
    return np.mod((SIGNS[:, None, :] * x[None, :, :]).reshape(-1, 3), period)


def _pairs(points, radius, period, cutoff_scale=1.15):
    """Image pairs closer than ``cutoff_scale (r_p + r_q)`` (nearest image in the period): (p, q, vector, d)."""
    tree = cKDTree(np.where(points >= period, 0.0, points), boxsize=period)
    pairs = tree.query_pairs(cutoff_scale * 2.0 * radius.max(), output_type="ndarray")
    p, q = pairs[:, 0], pairs[:, 1]
    v = points[q] - points[p]
    v -= period * np.round(v / period)
    d = np.linalg.norm(v, axis=1)
    near = d < cutoff_scale * (radius[p] + radius[q])
    return p[near], q[near], v[near], d[near]


def _energy(flat, radius8, period, bonds, overlap, gap):
    """The pair energy (module docstring) and its gradient wrt the base positions and, the last variable, the log of
    a common scale of positions and period. ``bonds = (p, q, m)``: bonded image pairs, ``q`` taken ``m`` periods
    away, pulled into ``overlap = (lo, hi)`` (``h / min(r_p, r_q)``); every other pair closer than
    ``(1 + gap)(r_p + r_q)`` is pushed there (``bonds`` empty and ``gap = 0``: repulsion of overlapping spheres)."""
    n = (len(flat) - 1) // 3
    scale = np.exp(flat[-1])
    period = period * scale
    pts = _images(flat[:3 * n].reshape(n, 3) * scale, period)
    p, q, v, d = _pairs(pts, radius8, period)
    rest = (1.0 + gap) * (radius8[p] + radius8[q])
    keep = d < rest
    bp, bq, bm = bonds
    if len(bp):
        bonded = np.isin(np.minimum(p, q) * len(pts) + np.maximum(p, q),
                         np.minimum(bp, bq) * len(pts) + np.maximum(bp, bq))
        keep &= ~bonded
    p, q, v, d, rest = p[keep], q[keep], v[keep], d[keep], rest[keep]
    bv = pts[bq] + bm * period - pts[bp]
    p, q, v = np.concatenate([p, bp]), np.concatenate([q, bq]), np.concatenate([v, bv])
    d = np.concatenate([d, np.linalg.norm(bv, axis=1)])
    r_sum, r_min = radius8[bp] + radius8[bq], np.minimum(radius8[bp], radius8[bq])
    bd = d[len(rest):]
    target = np.concatenate([rest, np.clip(bd, r_sum - overlap[1] * r_min, r_sum - overlap[0] * r_min)])
    diff = d - target
    coef = 2.0 * diff / np.maximum(d, 1e-12)
    force = coef[:, None] * v                          # dE/dX_q = coef v, dE/dX_p = -coef v
    g_img = np.zeros_like(pts)
    np.add.at(g_img, q, force)
    np.add.at(g_img, p, -force)
    grad = np.einsum("cka,ca->ka", g_img.reshape(8, n, 3), SIGNS).ravel() * scale
    return float(np.sum(diff**2)), np.append(grad, float(np.sum(coef * d * d)))


def _bond_list(x, radius8, period, within):
    """Image pairs closer than ``within (r_p + r_q)``, with the period offset of their nearest image."""
    pts = _images(x, period)
    p, q, v, d = _pairs(pts, radius8, period)
    near = d < within * (radius8[p] + radius8[q])
    p, q, v = p[near], q[near], v[near]
    return p, q, np.round((v - (pts[q] - pts[p])) / period).astype(int)


def _relax(x, radius8, period, bonds, overlap, gap):
    """Minimise :func:`_energy` from the base positions ``x``; returns ``(x, period, energy)``."""
    n = len(x)
    bounds = [(None, None)] * (3 * n) + [(0.0, 0.0)]  # the period as given
    res = minimize(_energy, np.append(x.ravel(), 0.0), jac=True, method="L-BFGS-B", bounds=bounds,
                   args=(radius8, period, bonds, overlap, gap),
                   options={"maxiter": 20000, "gtol": 1e-14, "ftol": 1e-16})
    scale = np.exp(res.x[-1])
    return res.x[:-1].reshape(n, 3) * scale, period * scale, float(res.fun)


_NONE = (np.zeros(0, int), np.zeros(0, int), np.zeros((0, 3), int))  # no bonds


def _jammed(n: int, spread: float, rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 1 (module docstring): ``n`` base spheres of mean radius 1, radii uniform within ``+-spread``, jammed in
    the mirror cell; ``(base positions, radii of the 8 n images, period)``."""
    r = 1.0 + spread * rng.uniform(-1.0, 1.0, n)
    r8 = np.tile(r, 8)
    volume = 8.0 * np.sum(4.0 / 3.0 * np.pi * r**3)
    side = (volume / 0.3) ** (1.0 / 3.0)
    x = rng.uniform(0.05, 0.45, (n, 3)) * side
    lo, hi = 0.3, 0.7  # bisection on the packing fraction
    for _ in range(16):
        phi = 0.5 * (lo + hi)
        new_side = (volume / phi) ** (1.0 / 3.0)
        y, _, energy = _relax(x * new_side / side, r8, np.full(3, new_side), _NONE, (0.0, 0.0), 0.0)
        if energy > 1e-12 * n:
            hi = phi
        else:
            lo, x, side = phi, y, new_side
    return x, r8, np.full(3, side)


def mirror_packing(n: int, overlap: float = 0.07, spread: float = 0.15, seed: int = 0, min_neck: float = 0.15,
                   max_neck: float = 0.6, min_margin_deg: float = 5.0, max_tries: int = 20) -> PeriodicCell:
    """A random sintered packing of ``8 n`` spheres (mean radius 1, radii uniform within ``+-spread``) in a cubic
    period, mirror-symmetric about the planes through the origin, with mean relative overlap about ``overlap``
    (module docstring)."""
    from scipy.optimize import brentq

    from fem_neck.geometry import overlap_for_neck

    for attempt in range(max_tries):
        x, r8, period = _jammed(n, spread, np.random.default_rng([seed, attempt]))
        p, q, _, d = _pairs(_images(x, period), r8, period)
        r_min = np.minimum(r8[p], r8[q])

        def mean_overlap(lam):  # 2. sintering: one factor on positions and period
            h = r8[p] + r8[q] - lam * d
            return float(np.mean(h[h > 0] / r_min[h > 0])) if np.any(h > 0) else 0.0

        lam = brentq(lambda lam: mean_overlap(lam) - overlap, 0.7, 1.0)
        x, period = x * lam, period * lam
        bounds_h = (overlap_for_neck(1.0, 1.0, min_neck), overlap_for_neck(1.0, 1.0, max_neck))
        bonds = _bond_list(x, r8, period, 1.0)
        for _ in range(20):  # 3. clean-up
            x, period, energy = _relax(x, r8, period, bonds, bounds_h, 1e-3)
            new = _bond_list(x, r8, period, 1.0)
            if energy < 1e-20 and len(new[0]) == len(bonds[0]):
                break
            bonds = new
        cell = PeriodicCell(_images(x, period), r8, period, name=f"mirror packing n={8 * n} seed={seed}")
        if _acceptable(cell, min_neck, np.radians(min_margin_deg)):
            return cell
    raise RuntimeError(f"mirror packing n={n} seed={seed}: no acceptable packing in {max_tries} tries")


def union_packing(n: int, phi: float, spread: float = 0.15, seed: int = 0, min_neck: float = 0.2,
                  max_tries: int = 20) -> PeriodicCell:
    """A random packing of ``8 n`` overlapping spheres (mean radius 1, radii uniform within ``+-spread``) in a cubic
    period, mirror-symmetric about the planes through the origin, read as the union of its spheres
    (``neck = "union"``) and about ``phi`` dense.

    ``phi`` (0 < phi < 1): the union's solid fraction aimed at (exact volumes of the cut spheres,
    :func:`fem_neck.geometry.union.cut_spheres`); ``min_neck``: the smallest ``a / r`` of a neck (``r`` the smaller
    radius), below which the gap between two spheres at their circle is too thin to mesh. After jamming (step 1 of
    the module docstring) positions and period shrink by one factor until the union is ``phi`` dense, then the
    overlapping pairs are pulled to necks of at least ``min_neck`` and every other pair pushed apart (step 3), twice,
    each time from the factor that gives ``phi``: the cell's ``phi`` lies within a few per cent of the one asked for.
    """
    from scipy.optimize import brentq

    if not 0.0 < phi < 1.0:
        raise ValueError(f"phi = {phi!r}: valid range 0 < phi < 1")
    overlap = (2.0 - 2.0 * np.sqrt(1.0 - min_neck**2), 1.0)  # h / r_min: the neck of equal spheres, at most r_min
    name = f"union packing n={8 * n} seed={seed}"
    for attempt in range(max_tries):
        x, r8, period = _jammed(n, spread, np.random.default_rng([seed, attempt]))

        def fraction(lam):
            return PeriodicCell(_images(x * lam, period * lam), r8, period * lam, neck="union").phi - phi

        try:
            for _ in range(2):
                lam = brentq(fraction, 0.5, 1.0, xtol=1e-6)
                x, period = x * lam, period * lam
                bonds = _bond_list(x, r8, period, 1.0)
                for _ in range(20):
                    x, period, energy = _relax(x, r8, period, bonds, overlap, 1e-3)
                    new = _bond_list(x, r8, period, 1.0)
                    if energy < 1e-20 and len(new[0]) == len(bonds[0]):
                        break
                    bonds = new
            cell = PeriodicCell(_images(x, period), r8, period, name=name, neck="union")
        except ValueError:  # a sphere inside another, or a centre beyond a radical plane, on the way
            continue
        if _acceptable_union(cell, min_neck):
            return cell
    raise RuntimeError(f"{name}: no acceptable packing in {max_tries} tries")


def _acceptable_union(cell: PeriodicCell, min_neck: float) -> bool:
    """The cell is a valid union (no sphere inside another, every centre inside its cut sphere), every sphere
    bonded, every neck at least ``min_neck`` of the smaller radius."""
    from fem_neck.geometry.union import lens

    try:
        check_cell(cell)
        cell.phi
    except ValueError:
        return False
    i, j, s = cell.bonds()
    if np.bincount(np.concatenate([i, j]), minlength=cell.n).min() < 1:
        return False
    d = np.linalg.norm(cell.centres[j] + s * cell.period - cell.centres[i], axis=1)
    return bool(np.all(lens(cell.radii[i], cell.radii[j], d).a >= 0.99 * min_neck * np.minimum(cell.radii[i],
                                                                                              cell.radii[j])))


def _acceptable(cell: PeriodicCell, min_neck: float, margin: float) -> bool:
    """The cell is a valid union of pair necks, every sphere bonded, the necks big enough and apart enough to
    mesh."""
    try:
        check_cell(cell)
    except ValueError:
        return False
    i, j, s = cell.bonds()
    if np.bincount(np.concatenate([i, j]), minlength=cell.n).min() < 1:
        return False
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    d = np.linalg.norm(e, axis=1)
    a = neck_radius(cell.radii[i], cell.radii[j], cell.radii[i] + cell.radii[j] - d)
    if np.any(a < 0.99 * min_neck * np.minimum(cell.radii[i], cell.radii[j])):
        return False
    e /= d[:, None]
    for k in range(cell.n):  # neck circles on one sphere at least `margin` apart
        ends = [(e[b], a[b]) for b in np.flatnonzero(i == k)] + [(-e[b], a[b]) for b in np.flatnonzero(j == k)]
        for u in range(len(ends)):
            for v in range(u + 1, len(ends)):
                angle = np.arccos(np.clip(ends[u][0] @ ends[v][0], -1.0, 1.0))
                need = sum(np.arcsin(min(end[1] / cell.radii[k], 1.0)) for end in (ends[u], ends[v]))
                if angle < need + margin:
                    return False
    return True
