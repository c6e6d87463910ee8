r"""Particle arrangements for scenes: a chain, a cubic lattice block (simple, body- or face-centred cubic), a
random sintered packing, and particles scattered in a box (for scenes that move).

Every generator returns a :class:`Layout`: positions, radii, the indices of the bottom and top layers and the
specimen's cross-section, so that a scene can hold the two ends at different temperatures (hot and cold plates,
or fixed end particles) and read off an effective conductivity ``k_eff = Q L / (A dT)``. The lattice block and the
random packing also give the ``period`` of the block: repeated with it along every axis they tile space (a
periodic scene, :mod:`dem.geometry.periodic`).

Overlaps are relative to the smaller radius of a pair: :math:`h = o \min(r_i, r_j)` with ``o`` the ``overlap``.

The random sintered packing is a jittered face-centred cubic lattice with random radii: the sites of an FCC lattice
block of m x m cells and complete (001) layers (N is rounded up to fill the top layer), each moved by a uniform random jitter, radii drawn from a distribution of the given
mean and relative spread, then all radii scaled by one factor (bisection) so that the mean relative overlap of the
bonded pairs hits the target. Everything is vectorised and costs O(N log N) (one k-d tree): 10^6 particles take
seconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from dem import memory
from fem_neck.geometry import max_overlap

DISTRIBUTIONS = ("constant", "uniform", "lognormal")
MAX_PARTICLES = 20_000_000  # larger packings need a distributed backend; below, dem.memory refuses what does not fit
RSA_CANDIDATES = 3000  # random points tried per particle by random_box (jamming near a solid fraction of 0.3 in 3D)
RSA_BLOCK = 1 << 16    # random_box draws its candidates in blocks of this many points
# the fractions of space that random sequential addition of equal spheres (3) and disks (2) fills when it jams, the
# saturation limit of infinitely many attempts (Zhang & Torquato 2013, Phys. Rev. E 88, 053312)
RSA_JAMMING = {3: 0.384130, 2: 0.547070}


def _check_count(n: int, name: str):
    """Refuse ``n`` particles beyond :data:`MAX_PARTICLES` or the machine's memory, before they are generated."""
    if n > MAX_PARTICLES:
        raise ValueError(f"[generator] {name}: {n} particles exceeds the limit of {MAX_PARTICLES} for one machine")
    memory.check(n, f"[generator] {name}")


@dataclass(frozen=True)
class Layout:
    """Generated geometry: ``position`` (N,3), ``radius`` (N,), ``bottom``/``top`` layer indices, the z of the
    lowest/highest particle surfaces, the cross-section ``area`` (m^2) normal to z; ``period`` (3,) and ``origin``
    (3,) of the box that tiles space with the block (None where it does not), initial ``velocity`` (N,3) or None.

    Parameters
    ----------
    position : numpy.ndarray
        (N, 3) centres (m).
    radius : numpy.ndarray
        (N,) radii (m).
    bottom : numpy.ndarray
        Indices of the bottom layer (lowest along z).
    top : numpy.ndarray
        Indices of the top layer.
    z_low : float
        z of the lowest particle surface (m).
    z_high : float
        z of the highest particle surface (m).
    area : float
        The cross-section normal to z (m^2).
    period : numpy.ndarray or None
        (3,) the box that tiles space with the block (m); None where it does not.
    origin : numpy.ndarray or None
        (3,) that box's lower corner (m); None with no period.
    velocity : numpy.ndarray or None
        (N, 3) initial velocities (m/s); None: at rest.
    """

    position: np.ndarray
    radius: np.ndarray
    bottom: np.ndarray
    top: np.ndarray
    z_low: float
    z_high: float
    area: float
    period: np.ndarray | None = None
    origin: np.ndarray | None = None
    velocity: np.ndarray | None = None


def _positive(name, value):
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not np.isfinite(value) or value <= 0:
        raise ValueError(f"[generator] {name} = {value!r}: must be a finite number > 0")
    return float(value)


def _floats(name, value) -> np.ndarray:
    try:
        return np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"[generator] {name} = {value!r}: must be a number or a list of numbers") from None


def _overlap(value, count, name="overlap"):
    arr = _floats(name, value)
    arr = np.broadcast_to(arr, (count,)) if arr.ndim == 0 else arr
    if arr.shape != (count,) or not np.all(np.isfinite(arr)) or np.any(arr <= 0):
        raise ValueError(f"[generator] {name} = {value!r}: must be a number > 0 or a list of {count} such numbers "
                         f"(relative to the smaller radius of each pair)")
    return arr


def chain(n: int, radius, overlap) -> Layout:
    """``n`` collinear particles along z; ``radius`` scalar or per particle, ``overlap`` scalar or per bond.

    Parameters
    ----------
    n : int
        Number of particles, >= 1.
    radius : float or sequence of float
        Radius (m), one for all or one per particle, > 0.
    overlap : float or sequence of float
        Relative overlap ``h / min(r_i, r_j)``, one for all or one per bond, within the neck model's range.

    Returns
    -------
    Layout
        The chain, the first particle's centre at the origin.

    Raises
    ------
    ValueError
        A bad ``n``, radius or overlap (the message names it).
    """
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ValueError(f"[generator] n = {n!r}: must be an integer >= 1")
    _check_count(n, "n")
    r = _floats("radius", radius)
    r = np.broadcast_to(r, (n,)).copy() if r.ndim == 0 else r
    if r.shape != (n,) or not np.all(np.isfinite(r)) or np.any(r <= 0):
        raise ValueError(f"[generator] radius = {radius!r}: must be a number > 0 or a list of {n} such numbers")
    rel = _overlap(overlap, n - 1)
    h = rel * np.minimum(r[:-1], r[1:])
    h_max = max_overlap(r[:-1], r[1:])
    beyond = np.flatnonzero(h > h_max * (1.0 + 1e-12))
    if beyond.size:
        k = int(beyond[0])
        raise ValueError(f"[generator] overlap[{k}] = {rel[k]:.9g}: valid range 0 < overlap <= "
                         f"{h_max[k] / min(r[k], r[k + 1]):.9g} for radii {r[k]:.6g} and {r[k + 1]:.6g} m (relative to "
                         f"the smaller radius; there the neck reaches it)")
    z = np.concatenate([[0.0], np.cumsum(r[:-1] + r[1:] - h)])
    pos = np.column_stack([np.zeros(n), np.zeros(n), z])
    return Layout(pos, r, np.array([0]), np.array([n - 1]), float(z[0] - r[0]), float(z[-1] + r[-1]),
                  float(np.pi * r.max() ** 2))


STRUCTURES = ("sc", "bcc", "fcc")
# sites of the cubic cell (units of its edge), and the edge over the nearest-neighbour distance
CELL_SITES = {"sc": [[0.0, 0.0, 0.0]],
              "bcc": [[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]],
              "fcc": [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]]}
CELL_EDGE = {"sc": 1.0, "bcc": 2.0 / np.sqrt(3.0), "fcc": np.sqrt(2.0)}


def lattice(shape, radius, overlap, structure: str = "sc") -> Layout:
    r"""A block of ``shape = [nx, ny, nz]`` cubic cells of equal spheres: simple cubic (one sphere per cell, so the
    block is nx x ny x nz spheres), body-centred (two) or face-centred cubic (four), nearest neighbours ``2r - h``
    apart (:math:`h = o r` with ``o`` the ``overlap``). Its ``period`` is the block's size: shape times the cell edge.

    Parameters
    ----------
    shape : sequence of int
        ``[nx, ny, nz]``, the number of cubic cells along each axis (>= 1).
    radius : float
        The spheres' radius (m), > 0.
    overlap : float
        Relative overlap ``h / r`` of nearest neighbours.
    structure : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.

    Returns
    -------
    Layout
        The block, with its ``period`` and ``origin``.

    Raises
    ------
    ValueError
        A bad shape, radius, overlap or structure (the message names it).
    """
    if structure not in STRUCTURES:
        raise ValueError(f"[generator] structure = {structure!r}: must be one of {', '.join(STRUCTURES)}")
    if (not isinstance(shape, (list, tuple)) or len(shape) != 3
            or not all(isinstance(k, int) and not isinstance(k, bool) and k >= 1 for k in shape)):
        raise ValueError(f"[generator] shape = {shape!r}: must be three integers >= 1")
    sites = np.asarray(CELL_SITES[structure])
    _check_count(shape[0] * shape[1] * shape[2] * len(sites), "shape")  # Python integers: no overflow
    r = _positive("radius", radius)
    rel = float(_overlap(overlap, 1)[0])
    if rel > 2.0 / 3.0:
        raise ValueError(f"[generator] overlap = {overlap!r}: valid range 0 < overlap <= 2/3 (relative to the radius; "
                         f"at 2/3 the neck reaches the radius)")
    s = 2.0 * r - rel * r
    edge = CELL_EDGE[structure] * s
    nx, ny, nz = shape
    ix, iy, iz = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    cells = np.column_stack([ix.ravel(), iy.ravel(), iz.ravel()]).astype(float)
    pos = edge * (cells[:, None, :] + sites[None, :, :]).reshape(-1, 3)
    z = np.round(pos[:, 2] / (0.5 * edge)).astype(np.int64)  # layer index: every site is on a half-edge plane
    period = edge * np.array(shape, dtype=float)
    return Layout(pos, np.full(len(pos), r), np.flatnonzero(z == z.min()), np.flatnonzero(z == z.max()), -r,
                  float(pos[:, 2].max()) + r, nx * ny * edge * edge, period, np.full(3, -0.25 * edge))


def _shape_radii(rng, n, distribution, spread):
    if distribution not in DISTRIBUTIONS:
        raise ValueError(f"[generator] distribution = {distribution!r}: must be one of {', '.join(DISTRIBUTIONS)}")
    if not (np.isfinite(spread) and 0 <= spread < 1):
        raise ValueError(f"[generator] radius_spread = {spread!r}: must be in [0, 1) (relative)")
    if distribution == "constant" or spread == 0:
        return np.ones(n)
    if distribution == "uniform":
        return rng.uniform(1.0 - spread, 1.0 + spread, n)
    sigma = np.sqrt(np.log1p(spread**2))  # lognormal with mean 1 and relative standard deviation ``spread``
    return rng.lognormal(-0.5 * sigma**2, sigma, n)


def random_packing(n: int, radius, overlap, seed: int = 0, radius_spread: float = 0.1,
                   distribution: str = "uniform", jitter: float = 0.02, periodic: bool = False) -> Layout:
    """Random sintered packing (module docstring); ``radius`` is the mean radius, ``overlap`` the target mean of
    ``h / min(r_i, r_j)`` over bonded pairs, ``jitter`` the half-width of the position noise over the neighbour
    distance. ``periodic``: the block tiles space with its ``period`` (complete FCC cells along z as well, so the
    layer count is even; at least 2 x 2 x 2 cells, n >= 32), the overlaps across its faces count in the mean, and
    the positions are wrapped into the period box.

    Parameters
    ----------
    n : int
        Number of particles asked for, >= 1 (rounded up to complete layers).
    radius : float
        Mean radius (m), > 0, before the common scaling that meets ``overlap``.
    overlap : float
        Target mean relative overlap ``h / min(r_i, r_j)`` of the bonded pairs, < 2/3.
    seed : int
        Seed of the random generator, >= 0.
    radius_spread : float
        Relative spread of the radii, in ``[0, 1)``: half-width for ``"uniform"``, standard deviation over the
        mean for ``"lognormal"``.
    distribution : str
        The radius distribution, one of ``DISTRIBUTIONS``.
    jitter : float
        Half-width of the uniform position noise over the neighbour distance, in ``[0, 0.25)``.
    periodic : bool
        Whether the block tiles space with its ``period``.

    Returns
    -------
    Layout
        The packing.

    Raises
    ------
    ValueError
        A parameter out of its range, or more particles than one machine holds.
    """
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ValueError(f"[generator] n = {n!r}: must be an integer >= 1")
    _check_count(n, "n")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ValueError(f"[generator] seed = {seed!r}: must be an integer >= 0")
    for name, value in (("radius_spread", radius_spread), ("jitter", jitter)):
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ValueError(f"[generator] {name} = {value!r}: must be a number")
    r_mean = _positive("radius", radius)
    target = float(_overlap(overlap, 1)[0])
    if target >= 2.0 / 3.0:
        raise ValueError(f"[generator] overlap = {overlap!r}: the mean relative overlap must be < 2/3 (the neck "
                         f"model's range)")
    if not (np.isfinite(jitter) and 0 <= jitter < 0.25):
        raise ValueError(f"[generator] jitter = {jitter!r}: must be in [0, 0.25) (fraction of the neighbour "
                         f"distance)")
    rng = np.random.default_rng(seed)
    m = max(1, int(round((n / 4.0) ** (1.0 / 3.0))))
    layers = int(np.ceil(n / (2.0 * m * m)))  # FCC: 2 m^2 sites per (001) layer; complete layers only
    if periodic:
        m, layers = max(m, 2), max(layers + layers % 2, 4)  # whole cells, and the period at least two cells wide
    cell = np.sqrt(2.0)  # FCC cell edge for a neighbour distance of 1
    basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]])
    g, gz = np.arange(m), np.arange((layers + 1) // 2)
    cz, cy, cx = np.meshgrid(gz, g, g, indexing="ij")
    corners = np.column_stack([cx.ravel(), cy.ravel(), cz.ravel()]).astype(float)
    sites = (corners[:, None, :] + basis[None, :, :]).reshape(-1, 3) * cell
    sites = sites[np.round(sites[:, 2] / (0.5 * cell)) < layers]
    sites = sites[np.lexsort((sites[:, 0], sites[:, 1], sites[:, 2]))]
    n = len(sites)
    pos = sites + rng.uniform(-jitter, jitter, sites.shape)
    shape = _shape_radii(rng, n, distribution, radius_spread)
    # candidate neighbours: every pair that could overlap for radii up to the 2/3-overlap scale
    cutoff = (1.0 + 2.0 * np.sqrt(3.0) * jitter) * 1.05
    period = np.array([m, m, layers // 2], dtype=float) * cell
    if periodic:  # the nearest image of each pair (the period is wider than twice the cutoff)
        pos = np.mod(pos, period)
        pos = np.where(pos >= period, 0.0, pos)
        pairs = cKDTree(pos, boxsize=period).query_pairs(cutoff, output_type="ndarray")
        diff = pos[pairs[:, 0]] - pos[pairs[:, 1]]
        d = np.linalg.norm(diff - period * np.round(diff / period), axis=1)
    else:
        pairs = cKDTree(pos).query_pairs(cutoff, output_type="ndarray")
        d = np.linalg.norm(pos[pairs[:, 0]] - pos[pairs[:, 1]], axis=1)
    i, j = pairs[:, 0], pairs[:, 1]
    ssum, smin = shape[i] + shape[j], np.minimum(shape[i], shape[j])

    def mean_overlap(sigma):
        h = sigma * ssum - d
        bonded = h > 0
        return float(np.mean(h[bonded] / (sigma * smin[bonded]))) if np.any(bonded) else 0.0

    if len(d) == 0:
        sigma = 0.5
    else:
        lo, hi = 0.5 * d.min() / ssum.max(), cutoff / ssum.min()
        if mean_overlap(hi) < target:
            raise ValueError(f"[generator] overlap = {overlap!r}: not reachable with this jitter and spread")
        from scipy.optimize import brentq  # here: scipy.optimize is most of what `import dem` would load

        sigma = brentq(lambda s: mean_overlap(s) - target, lo, hi, xtol=1e-14, rtol=1e-12)
    scale = r_mean / (sigma * shape.mean())  # metres per neighbour distance
    r = sigma * shape * scale
    pos = pos * scale
    layer = np.round(sites[:, 2] / (0.5 * cell)).astype(np.int64)
    bottom, top = np.flatnonzero(layer == layer.min()), np.flatnonzero(layer == layer.max())
    side = m * cell * scale
    return Layout(pos, r, bottom, top, float(np.min(pos[:, 2] - r)), float(np.max(pos[:, 2] + r)), side * side,
                  period * scale, np.zeros(3))


def _mean_size(radius: float, spread: float, dimension: int) -> float:
    """The mean volume (3D) or area (2D) of a particle with a radius uniform in ``radius (1 +- spread)``:
    ``E[r^3] = radius^3 (1 + spread^2)``, ``E[r^2] = radius^2 (1 + spread^2 / 3)``."""
    if dimension == 2:
        return math.pi * radius**2 * (1.0 + spread**2 / 3.0)
    return 4.0 / 3.0 * math.pi * radius**3 * (1.0 + spread**2)


def box_capacity(radius: float, spread: float, box, dimension: int = 3) -> int:
    """About how many particles :func:`random_box` can place at most in ``box``: the box's volume (area of the x-z
    face for 2D disks) filled to the jamming fraction of random sequential addition (``RSA_JAMMING``), over
    the particles' mean volume (area). An upper estimate: the box's faces and a finite number of attempts leave
    it emptier (about 0.30 for the spheres of ``hot-wall-sintering``).

    Parameters
    ----------
    radius : float
        Mean radius (m).
    spread : float
        Relative half-width of the uniform radius distribution, in ``[0, 1)``.
    box : sequence
        ``[[x, y, z]_lo, [x, y, z]_hi]``, the box's corners (m).
    dimension : int
        3 (spheres) or 2 (disks in the x-z plane).

    Returns
    -------
    int
        The estimated largest number of particles.
    """
    b = np.asarray(box, dtype=float)
    span = (b[1] - b[0])[[0, 2] if dimension == 2 else [0, 1, 2]]
    return int(RSA_JAMMING[dimension] * float(np.prod(span)) / _mean_size(radius, spread, dimension))


def random_box(n: int, radius, box, radius_spread: float = 0.0, seed: int = 0, speed: float = 0.0,
               dimension: int = 3) -> Layout:
    """``n`` particles placed one after the other at uniformly random positions inside the box ``[[x, y, z]_lo,
    [x, y, z]_hi]`` without overlapping each other or the box faces (random sequential addition, Zohdi 2014,
    Sec. 7; Luding 2005, Sec. 4: "randomly placed in a box with random initial velocity"). Radii uniform in
    ``radius (1 +- radius_spread)`` (Luding's w0); velocities of magnitude ``speed`` in random directions (in the
    x-z plane for 2D disks, which keep ``y = 0``). Refused when the box is too full for the particles to fit.

    Parameters
    ----------
    n : int
        Number of particles, >= 1.
    radius : float
        Mean radius (m), > 0.
    box : sequence
        ``[[x, y, z]_lo, [x, y, z]_hi]``, the box's corners (m).
    radius_spread : float
        Relative half-width of the uniform radius distribution, in ``[0, 1)``.
    seed : int
        Seed of the random generator, >= 0.
    speed : float
        Magnitude of each particle's initial velocity (m/s), >= 0.
    dimension : int
        3 (spheres) or 2 (disks in the x-z plane).

    Returns
    -------
    Layout
        The particles with their velocities.

    Raises
    ------
    ValueError
        A parameter out of its range, or a box too full for the particles.
    """
    if not isinstance(n, int) or isinstance(n, bool) or n < 1:
        raise ValueError(f"[generator] n = {n!r}: must be an integer >= 1")
    _check_count(n, "n")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ValueError(f"[generator] seed = {seed!r}: must be an integer >= 0")
    r_mean = _positive("radius", radius)
    spread = float(_floats("radius_spread", radius_spread))
    if not (np.isfinite(spread) and 0 <= spread < 1):
        raise ValueError(f"[generator] radius_spread = {radius_spread!r}: must be in [0, 1) (relative)")
    v = float(_floats("speed", speed))
    if not (np.isfinite(v) and v >= 0):
        raise ValueError(f"[generator] speed = {speed!r}: must be a finite number >= 0 (m/s)")
    b = _floats("box", box)
    axes = [0, 2] if dimension == 2 else [0, 1, 2]
    if b.shape != (2, 3) or not np.all(np.isfinite(b)) or np.any(b[1][axes] <= b[0][axes]):
        raise ValueError(f"[generator] box = {box!r}: must be [[x, y, z]_low, [x, y, z]_high] with low < high"
                         f"{' in x and z (2D disks: y is ignored)' if dimension == 2 else ''}")
    lo, hi = b[0].copy(), b[1].copy()
    if dimension == 2:
        lo[1] = hi[1] = 0.0
    capacity = box_capacity(r_mean, spread, b, dimension)
    if n > capacity:
        shape = "disks" if dimension == 2 else "spheres"
        size = " x ".join(f"{1e3 * s:.4g}" for s in (b[1] - b[0])[axes])
        need = n * _mean_size(r_mean, spread, dimension) / np.prod((b[1] - b[0])[axes])
        raise ValueError(f"[generator] n = {n}: about {capacity} {shape} of radius {r_mean:.4g} m "
                         f"(+-{100 * spread:.3g} %) at most fit in the {size} mm box{' (x-z)' if dimension == 2 else ''}"
                         f" by random sequential addition, which jams at {'an area' if dimension == 2 else 'a solid'}"
                         f" fraction of {RSA_JAMMING[dimension]:.3f}; n = {n} would need a fraction of {need:.3g}: "
                         f"use n <= {capacity} or a larger box")
    rng = np.random.default_rng(seed)
    r = rng.uniform(r_mean * (1.0 - spread), r_mean * (1.0 + spread), n)
    if np.any(2.0 * r.max() > (b[1] - b[0])[axes]):
        raise ValueError(f"[generator] box = {box!r}: narrower than the largest particle ({2 * r.max():.6g} m)")
    from dem.geometry.neighbours import addition_grid, sequential_addition  # compiled: loaded only when placing

    pos, grid = np.zeros((n, 3)), addition_grid(r, lo, hi)
    placed, drawn, budget = 0, 0, RSA_CANDIDATES * n
    while placed < n and drawn < budget:  # the candidates in blocks: memory O(block), not O(RSA_CANDIDATES n)
        block = min(RSA_BLOCK, budget - drawn)
        placed = sequential_addition(r, lo, hi, rng.random((block, 3)), pos, placed, *grid)
        drawn += block
    if placed < n:
        filled = np.sum(np.pi * r[:placed] ** 2) / np.prod((b[1] - b[0])[axes]) if dimension == 2 else \
            np.sum(4 / 3 * np.pi * r[:placed] ** 3) / np.prod(b[1] - b[0])
        raise ValueError(f"[generator] n = {n}: only {placed} {'disks' if dimension == 2 else 'spheres'} fit by "
                         f"random sequential addition ({RSA_CANDIDATES} attempts per particle; "
                         f"{'area' if dimension == 2 else 'solid'} fraction {filled:.3f}): use n <= {placed} or a "
                         f"larger box")
    rng.bit_generator.advance(3 * (budget - drawn))  # the velocities: as if every candidate had been drawn
    direction = rng.normal(size=(n, 3))
    if dimension == 2:
        direction[:, 1] = 0.0
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    span = b[1] - b[0]
    area = span[0] * span[1] if dimension == 3 else span[0]  # normal to z (2D: a length)
    empty = np.zeros(0, dtype=np.int64)
    return Layout(pos, r, empty, empty, float(b[0][2]), float(b[1][2]), float(area),
                  velocity=v * direction if v > 0 else None)

