r"""Bonds from geometry: overlapping particle pairs and particle-wall contacts, with their neck radii.

Two spheres are bonded when they overlap, :math:`h = r_i + r_j - d > 0` (Rojek 2022, eq. 21/44). Candidate pairs come
from cubic cells of the largest diameter searched on numba's threads when no radius is twice the smallest in a large
packing (the
neighbour list's binning, :func:`dem.geometry.neighbours.verlet_pairs`), else from k-d trees
(``scipy.spatial.cKDTree``), the particles grouped in radius classes (a factor 2 apart) so that a polydisperse
packing never searches with twice the largest radius among its small particles. From ``CELL_SEARCH_MIN`` particles
on, the pairs' radii, overlaps and radical planes come from one compiled pass (:mod:`dem.geometry.bond_kernels`),
numpy's values to the bit.

The contact radius ``a`` of a bond is given by the *contact geometry* that the conductance law asks for:

* ``"newton"``, ``"first"``, ``"coble"`` -- the neck of :func:`fem_neck.geometry.neck_radius` (volume-conserving neck,
  Rojek 2022 eqs. 27-33, its first iterate eq. 34, or Coble's eqs. 11-12). Its range is
  ``0 < h <= max_overlap(r_i, r_j)``.
* ``"lens"`` -- the intersection circle of the two spheres (Zohdi 2014, eqs. 7-12): :math:`a^2 = r_i^2 - L_i^2` with
  :math:`L_i = (d - (r_j^2 - r_i^2)/d)/2`. Its range is :math:`L_i, L_j \ge 0`.
* ``"union"`` -- the same circle read as a neck of the union of the spheres (:mod:`fem_neck.geometry.union`: each
  sphere cut by its radical planes, Arzt 1982), defined at every density; the range is the lens'.

A particle touching a wall (plane) is bonded to the wall. With a neck model the contact is the mirror image: a
sphere sintered to its mirror image across the plane, whose symmetry plane is the isothermal wall, so the wall bond
is one half of a pair of equal spheres with overlap :math:`2 \delta` (range :math:`\delta \le r/3`). With the lens,
:math:`a^2 = r^2 - L^2` with ``L`` the distance of the centre from the wall.

Bonds beyond the model's range are never clipped silently: ``out_of_range = "error"`` (default) raises a
``ValueError`` with their count and the first offending pair; ``"clip"`` sets them to the range's end (``a`` =
the smaller radius) and ``"drop"`` removes them; the counts go into the summary.

Every bond also stores ``l_i``, ``l_j``: the distances from the centres to the plane of the contact circle (the
lens' radical plane), which Zohdi's law uses as the pipe length.

Periodic boxes (:class:`dem.geometry.periodic.PeriodicBox`): a bond may join a particle to an image of another (or of itself,
in a box shorter than a bond) across the boundary; it stores that image's integer ``shift``, and its centre distance
is that of the image. The search adds the images of the particles near each periodic face, so a periodic block has
exactly the bonds of an explicit larger block.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.spatial import cKDTree

from fem_neck.geometry import max_overlap, neck_radius

from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox, canonical_bonds

CONTACT_MODELS = ("newton", "first", "coble", "lens", "union")
LENS_GEOMETRY = ("lens", "union")  # the contact models whose circle is where the two spheres meet
OUT_OF_RANGE = ("error", "clip", "drop")
PAIRS_EXPECTED = 8  # room for pairs per particle in a one-class search (a dense random packing has 5.5)
# from this many particles on, the cells (numba) search one radius class: importing numba and loading the compiled
# search (about 0.7 s of CPU in a fresh process) costs what the k-d trees take for 2-3 * 10^5 particles, and below it
# a static run loads no numba
CELL_SEARCH_MIN = 300_000


@dataclass(frozen=True)
class Bonds:
    r"""Pair bonds ``(i, j)`` with ``i < j`` and wall bonds ``(wall_particle, wall_index)`` as index arrays
    (:func:`find_bonds`). Per-bond arrays have one entry per pair bond (``m``) or per wall bond.

    Parameters
    ----------
    i, j : numpy.ndarray
        The two particles of every pair bond, ``i < j``.
    h : numpy.ndarray
        Overlap ``r_i + r_j - d`` of every pair bond, m.
    d : numpy.ndarray
        Centre distance of every pair bond (to the image of ``j`` in a periodic box), m.
    a : numpy.ndarray
        Contact (neck) radius of every pair bond, m, from the contact geometry ``contact``.
    l_i, l_j : numpy.ndarray
        Distances from the centres of ``i`` and ``j`` to the plane of the contact circle, m.
    wall_particle : numpy.ndarray
        The particle of every wall bond.
    wall_index : numpy.ndarray
        The wall of every wall bond (index into the scene's walls).
    wall_h : numpy.ndarray
        Overlap :math:`\delta = r - L` of every wall bond, m.
    wall_a : numpy.ndarray
        Contact radius of every wall bond, m.
    wall_l : numpy.ndarray
        Distance ``L`` of the particle's centre from the wall, m.
    contact : str
        The contact geometry (``CONTACT_MODELS``, module docstring).
    clipped, dropped : int
        Bonds the out-of-range policy clipped to the range's end, and dropped.
    shift : numpy.ndarray, optional
        In a periodic box, the integer image shift ``(m, 3)`` of ``j``; None without one (all zero).
    """

    i: np.ndarray
    j: np.ndarray
    h: np.ndarray
    d: np.ndarray
    a: np.ndarray
    l_i: np.ndarray
    l_j: np.ndarray
    wall_particle: np.ndarray
    wall_index: np.ndarray
    wall_h: np.ndarray
    wall_a: np.ndarray
    wall_l: np.ndarray
    contact: str = "newton"
    clipped: int = 0
    dropped: int = 0
    shift: np.ndarray | None = None

    @property
    def shifts(self) -> np.ndarray:
        """The image shift of every pair bond, (m, 3) integers (zeros without a periodic box)."""
        return np.zeros((len(self.i), 3), dtype=np.int64) if self.shift is None else self.shift

    def vectors(self, position: np.ndarray, box: PeriodicBox | None = None) -> np.ndarray:
        """``x_j (+ shift L) - x_i`` of every pair bond (m, 3).

        Parameters
        ----------
        position : numpy.ndarray
            Particle centres ``(n, 3)``, m.
        box : dem.geometry.periodic.PeriodicBox, optional
            The periodic box the bonds were found in; None without one.
        """
        if box is None or self.shift is None:
            return position[self.j] - position[self.i]
        return box.bond_vectors(position, self.i, self.j, self.shift)

    @property
    def n_pairs(self) -> int:
        """Number of pair bonds."""
        return len(self.i)

    @property
    def n_walls(self) -> int:
        """Number of wall bonds."""
        return len(self.wall_particle)

    def necks_per_particle(self, n: int) -> np.ndarray:
        """Per particle of ``n``, its bonds' ends: its pair bonds (as ``i`` or ``j``) and its wall bonds (int).

        Parameters
        ----------
        n : int
            Number of particles.
        """
        return np.bincount(np.concatenate([self.i, self.j, self.wall_particle]), minlength=n)

    def subset(self, pairs: np.ndarray, walls: np.ndarray) -> "Bonds":
        """The pair bonds at ``pairs`` and the wall bonds at ``walls`` (masks or indices), in their order.

        Parameters
        ----------
        pairs : numpy.ndarray
            Mask or indices of the pair bonds to keep.
        walls : numpy.ndarray
            Mask or indices of the wall bonds to keep.
        """
        return replace(self, i=self.i[pairs], j=self.j[pairs], h=self.h[pairs], d=self.d[pairs], a=self.a[pairs],
                       l_i=self.l_i[pairs], l_j=self.l_j[pairs],
                       shift=None if self.shift is None else self.shift[pairs],
                       wall_particle=self.wall_particle[walls], wall_index=self.wall_index[walls],
                       wall_h=self.wall_h[walls], wall_a=self.wall_a[walls], wall_l=self.wall_l[walls])


def candidate_pairs(position: np.ndarray, radius: np.ndarray, distances: bool = False) -> tuple:
    """All pairs ``i < j`` with ``|x_i - x_j| < r_i + r_j``, sorted by ``(i, j)``: a packing of ``CELL_SEARCH_MIN``
    particles or more in one radius class (no radius twice the smallest) by cell binning on numba's threads
    (:func:`dem.geometry.neighbours.verlet_pairs` with no skin), others by k-d trees per radius class.

    Parameters
    ----------
    position : numpy.ndarray
        Particle centres ``(n, 3)``, m.
    radius : numpy.ndarray
        Particle radii ``(n,)``, m, > 0.
    distances : bool
        Also return the pairs' centre distances ``|x_j - x_i|`` (m; :func:`lengths` of the differences, to the bit),
        which the cell search computes as it goes.

    Returns
    -------
    tuple of numpy.ndarray
        ``(i, j)``, or with ``distances`` ``(i, j, d)``.
    """
    n = len(radius)
    if n < 2:
        return (np.zeros(0, np.int64), np.zeros(0, np.int64)) + ((np.zeros(0),) if distances else ())
    level = np.floor(np.log2(radius / radius.min())).astype(np.int64)
    if n >= CELL_SEARCH_MIN and not level.any():
        from dem.geometry.neighbours import verlet_pairs  # compiled: a static run of fewer particles loads no numba

        return verlet_pairs(position, radius, 0.0, np.zeros(3), PAIRS_EXPECTED * n, distances)
    classes = [np.flatnonzero(level == k) for k in np.unique(level)]
    trees = [cKDTree(position[idx]) for idx in classes]
    r_max = [radius[idx].max() for idx in classes]
    found_i, found_j = [], []
    for a, (idx_a, tree_a) in enumerate(zip(classes, trees)):
        for b in range(a, len(classes)):
            cutoff = r_max[a] + r_max[b]
            if b == a:
                pairs = tree_a.query_pairs(cutoff, output_type="ndarray")
                pi, pj = idx_a[pairs[:, 0]], idx_a[pairs[:, 1]]
            else:
                sdm = tree_a.sparse_distance_matrix(trees[b], cutoff, output_type="ndarray")
                pi, pj = idx_a[sdm["i"]], classes[b][sdm["j"]]
            found_i.append(pi)
            found_j.append(pj)
    i = np.concatenate(found_i).astype(np.int64)
    j = np.concatenate(found_j).astype(np.int64)
    diff = position[i] - position[j]
    keep = np.einsum("ij,ij->i", diff, diff) < (radius[i] + radius[j]) ** 2
    i, j = sorted_pairs(i[keep], j[keep], n)
    return (i, j, lengths(position[j] - position[i])) if distances else (i, j)


def lengths(vec: np.ndarray) -> np.ndarray:
    r"""The length of every row of ``vec`` (m, 3): :math:`\sqrt{x x + y y + z z}`, summed in that order into one fresh
    array: ``np.linalg.norm(vec, axis=1)`` to the bit, in a tenth of its time.

    Parameters
    ----------
    vec : numpy.ndarray
        ``(m, 3)`` vectors, e.g. bond vectors in m.
    """
    x, y, z = vec[:, 0], vec[:, 1], vec[:, 2]
    d, square = x * x, y * y
    d += square
    d += np.multiply(z, z, out=square)
    return np.sqrt(d, out=d)


def periodic_pairs(position: np.ndarray, radius: np.ndarray, box: PeriodicBox) -> tuple:
    """All bonds ``(i, j, shift)`` with ``|x_j + shift L - x_i| < r_i + r_j`` in a periodic box: the overlaps among
    the particles and their images near the faces (:meth:`~dem.geometry.periodic.PeriodicBox.images`), each bond
    once (:func:`dem.geometry.periodic.canonical_bonds`).

    Parameters
    ----------
    position : numpy.ndarray
        Particle centres ``(n, 3)``, m.
    radius : numpy.ndarray
        Particle radii ``(n,)``, m, > 0.
    box : dem.geometry.periodic.PeriodicBox
        The periodic box.
    """
    n = len(radius)
    points, owner, shift = box.images(position, 2.0 * float(radius.max()))
    p, q = candidate_pairs(points, radius[owner])
    keep = (p < n) | (q < n)  # pairs of two images repeat a pair with an original
    p, q = p[keep], q[keep]
    # shifts between the wrapped positions, made shifts between the positions as given
    wrapped = np.round((points[:n] - position) / box.lengths).astype(np.int64)
    shift = shift + wrapped[owner]
    return canonical_bonds(owner[p], owner[q], shift[q] - shift[p])


def sorted_pairs(i: np.ndarray, j: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Pairs as ``i < j``, sorted by ``(i, j)`` (one int64 key), without duplicates.

    Parameters
    ----------
    i, j : numpy.ndarray
        Particle indices of the pairs (either order), int64.
    n : int
        Number of particles (the indices are below it).
    """
    key = np.sort(np.minimum(i, j) * n + np.maximum(i, j))
    # sort + neighbour mask rather than np.unique: same keys, 0.05 s instead of 6.5 s at 5e6 pairs (numpy 2.4)
    key = key[np.r_[True, key[1:] != key[:-1]]] if len(key) else key
    return key // n, key % n


def unique_pairs(i, j, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Canonical (``i < j``), duplicate-free pairs; self-pairs and indices outside ``[0, n)`` raise ValueError.

    Parameters
    ----------
    i, j : array_like
        Particle indices of the pairs (either order).
    n : int
        Number of particles.
    """
    i = np.asarray(i, dtype=np.int64).ravel()
    j = np.asarray(j, dtype=np.int64).ravel()
    if len(i) != len(j):
        raise ValueError(f"bonds: {len(i)} first indices but {len(j)} second indices")
    bad = (i < 0) | (i >= n) | (j < 0) | (j >= n) | (i == j)
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"bonds[{k}] = ({i[k]}, {j[k]}): must join two different particles among 0..{n - 1}")
    return sorted_pairs(i, j, n)


def _lens_planes(r_i, r_j, d):
    """``L_i, L_j``: centre-to-radical-plane distances (Zohdi 2014, eq. 12), safe for ``d = 0``."""
    d_safe = np.where(d > 0, d, 1.0)
    l_i, l_j = r_j**2, r_i**2  # in place from here: 0.5 (d - (r_j^2 - r_i^2) / d_safe), three fresh arrays in all
    l_i -= l_j
    l_i /= d_safe
    np.subtract(d, l_i, out=l_i)
    l_i *= 0.5
    np.copyto(l_i, -np.inf, where=~(d > 0))
    return l_i, np.subtract(d, l_i, out=l_j)


def _apply_policy(bad, what: str, first: str, policy: str, total: int):
    if not np.any(bad):
        return 0
    if policy == "error":
        raise ValueError(f"{int(bad.sum())} of {total} {what} lie beyond the contact model's range ({first}); "
                         f"set conductance.out_of_range = \"clip\" or \"drop\" to proceed")
    return int(bad.sum())


def _pair_contacts(p: Particles, i, j, d, contact, policy):
    lens = contact in LENS_GEOMETRY
    if p.n >= CELL_SEARCH_MIN:  # numba is loaded (the cell search, the solve): one compiled pass, the same bits
        from dem.geometry.bond_kernels import pair_geometry

        r_i, r_j, h, l_i, l_j, bad = pair_geometry(p.radius, i, j, d, lens)
    else:
        r_i, r_j = p.radius[i], p.radius[j]
        h = r_i + r_j
        h -= d
        l_i, l_j = _lens_planes(r_i, r_j, d)
        if lens:
            bad = (l_i < 0) | (l_j < 0)
        else:  # max_overlap is the smaller radius / 3 plus a cap's share >= 0: only the bonds beyond it need it
            third = np.minimum(r_i, r_j)
            third /= 3.0
            bad = h > third
    if lens:
        limit = "the lens needs both centres outside the other sphere's cap: d^2 >= |r_j^2 - r_i^2|"
    else:
        near = np.flatnonzero(bad)
        bad[near] = h[near] > max_overlap(r_i[near], r_j[near])
        limit = "overlap h <= max_overlap(r_i, r_j), where the neck reaches the smaller radius"
    first = ""
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        first = (f"first: particles {i[k]} and {j[k]}, r = {r_i[k]:.6g} and {r_j[k]:.6g} m, d = {d[k]:.6g} m, "
                 f"h = {h[k]:.6g} m; valid: {limit}")
    count = _apply_policy(bad, "particle pairs", first, policy, len(i))
    clipped = dropped = 0
    keep = np.ones(len(i), dtype=bool)
    if count and policy == "drop":
        keep = ~bad
        i, j, r_i, r_j, d, h, l_i, l_j = (x[keep] for x in (i, j, r_i, r_j, d, h, l_i, l_j))
        dropped = count
    elif count:
        clipped = count
    if contact in LENS_GEOMETRY:
        small_i = r_i <= r_j
        if clipped:  # the smaller sphere's centre on the radical plane: a is its radius, the larger's pipe is d
            coincident = np.flatnonzero(bad & (d == 0.0))
            if coincident.size:
                k = int(coincident[0])
                raise ValueError(f"particles {i[k]} and {j[k]} coincide (d = 0): the lens law's conductance "
                                 f"kappa pi a^2 / d is infinite; remove the duplicate particle or set "
                                 f"conductance.out_of_range = \"drop\"")
            l_i = np.where(bad, np.where(small_i, 0.0, d), l_i)
            l_j = np.where(bad, np.where(small_i, d, 0.0), l_j)
        # a from the smaller sphere (the same circle for a valid lens; the clipped one is that sphere's equator)
        r_small, l_small = np.where(small_i, r_i, r_j), np.where(small_i, l_i, l_j)
        a = np.sqrt(np.maximum(r_small**2 - np.maximum(l_small, 0.0) ** 2, 0.0))
    else:
        h_model = np.minimum(h, max_overlap(r_i, r_j)) if clipped else h
        a = np.asarray(neck_radius(r_i, r_j, h_model, method=contact)) if len(h) else np.zeros(0)
    return i, j, h, d, a, np.maximum(l_i, 0.0, out=l_i), np.maximum(l_j, 0.0, out=l_j), clipped, dropped, keep


def _wall_contacts(p: Particles, walls, contact, policy):
    parts, index, hs, dists = [], [], [], []
    for w, wall in enumerate(walls):
        dist = wall.distance(p.position)
        touching = np.flatnonzero(dist < p.radius)
        parts.append(touching)
        index.append(np.full(len(touching), w, dtype=np.int64))
        hs.append(p.radius[touching] - dist[touching])
        dists.append(dist[touching])
    k_p = np.concatenate(parts) if parts else np.zeros(0, np.int64)
    k_w = np.concatenate(index) if index else np.zeros(0, np.int64)
    delta = np.concatenate(hs) if hs else np.zeros(0)
    dist = np.concatenate(dists) if dists else np.zeros(0)
    r = p.radius[k_p]
    if contact in LENS_GEOMETRY:
        bad = dist < 0
        limit = "the centre must stay on the packing's side of the wall"
    else:
        bad = delta > r / 3.0
        limit = "overlap delta <= r/3 (the mirror pair's neck reaches the radius)"
    first = ""
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        first = (f"first: particle {k_p[k]} on wall {walls[k_w[k]].name!r}, r = {r[k]:.6g} m, "
                 f"overlap = {delta[k]:.6g} m; valid: {limit}")
    count = _apply_policy(bad, "wall contacts", first, policy, len(k_p))
    clipped = dropped = 0
    if count and policy == "drop":
        keep = ~bad
        k_p, k_w, delta, dist, r = (x[keep] for x in (k_p, k_w, delta, dist, r))
        dropped = count
    elif count:
        clipped = count
        if contact in LENS_GEOMETRY:  # centre on or behind the plane: the pipe has no length, the conductance no bound
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"particle {k_p[k]} has its centre on or behind wall {walls[k_w[k]].name!r} (distance "
                             f"{dist[k]:.6g} m): the lens law's conductance kappa pi a^2 / L is infinite at L = 0; "
                             f"move the wall or set conductance.out_of_range = \"drop\"")
        delta = np.minimum(delta, r / 3.0)
    if contact in LENS_GEOMETRY:
        a = np.sqrt(np.maximum(r**2 - dist**2, 0.0))
    else:
        a = np.asarray(neck_radius(r, r, 2.0 * delta, method=contact)) if len(r) else np.zeros(0)
    return k_p, k_w, delta, a, dist, clipped, dropped


def find_bonds(particles: Particles, walls=(), contact: str = "newton", out_of_range: str = "error",
               pairs=None, box: PeriodicBox | None = None) -> Bonds:
    """Bonds of ``particles`` (and ``walls``) with contact radii from ``contact`` (module docstring).

    ``pairs = (i, j)`` gives the pair bonds explicitly instead of searching for overlaps (duplicates and reversed
    duplicates are removed; every listed pair must overlap; in a periodic ``box``, through its nearest image).
    With a periodic ``box`` bonds cross its faces (:func:`periodic_pairs`).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (positions and radii in m).
    walls : sequence of dem.geometry.walls.Wall
        The planes particles may touch.
    contact : str
        Contact geometry, one of ``CONTACT_MODELS`` (module docstring).
    out_of_range : str
        What to do with bonds beyond the model's range: ``"error"``, ``"clip"`` or ``"drop"``.
    pairs : tuple of array_like, optional
        ``(i, j)``: the pair bonds given explicitly; None searches for overlaps.
    box : dem.geometry.periodic.PeriodicBox, optional
        A periodic box whose faces bonds may cross.
    """
    if contact not in CONTACT_MODELS:
        raise ValueError(f"contact = {contact!r}: must be one of {', '.join(CONTACT_MODELS)}")
    if out_of_range not in OUT_OF_RANGE:
        raise ValueError(f"out_of_range = {out_of_range!r}: must be one of {', '.join(OUT_OF_RANGE)}")
    periodic = box is not None and box.any_periodic
    x = particles.position
    if pairs is None and not periodic:
        i, j, d = candidate_pairs(x, particles.radius, distances=True)
    else:
        if pairs is None:
            i, j, shift = periodic_pairs(x, particles.radius, box)
        else:
            i, j = unique_pairs(*pairs, particles.n)
            if periodic:
                shift = np.where(box.mask, -np.round((x[j] - x[i]) / box.lengths), 0).astype(np.int64)
        if periodic:
            vec = box.bond_vectors(x, i, j, shift)
        else:
            vec = x[j]
            vec -= x[i]
        d = lengths(vec)
        if pairs is not None:
            apart = d >= particles.radius[i] + particles.radius[j]
            if np.any(apart):
                k = int(np.flatnonzero(apart)[0])
                raise ValueError(f"bonds: particles {i[k]} and {j[k]} do not overlap (d = {d[k]:.6g} m >= "
                                 f"r_i + r_j = {particles.radius[i[k]] + particles.radius[j[k]]:.6g} m)")
    i, j, h, d, a, l_i, l_j, c1, d1, keep = _pair_contacts(particles, i, j, d, contact, out_of_range)
    wp, wi, wh, wa, wl, c2, d2 = _wall_contacts(particles, tuple(walls), contact, out_of_range)
    return Bonds(i, j, h, d, a, l_i, l_j, wp, wi, wh, wa, wl, contact, c1 + c2, d1 + d2,
                 shift[keep] if periodic else None)
