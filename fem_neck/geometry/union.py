r"""The union of spheres: a geometry of sintered particles defined at every density.

The pair-neck models of :mod:`fem_neck.geometry` (Rojek 2022, eqs. 21-34) describe one neck between two spheres;
once two necks of one particle meet they have no answer. The *union of the spheres* has one at every density: it is
the truncated-sphere model of Arzt (1982), each sphere cut by its radical planes. For any radii the union of the cut
spheres is the union of the spheres, because the radical planes are the faces of the power (Laguerre) diagram of
the spheres, which partitions space, and the union of the balls meets the power cell of ball ``k`` in ball ``k``
alone. It is also how a packing fitted to X-ray tomography (centres and radii of overlapping spheres) reads.

**A neck** of the union is the circle where two spheres meet (:func:`lens`): with the centre distance ``d``, the
radical plane lies at :math:`l_i = (d^2 + r_i^2 - r_j^2) / (2 d)` from centre ``i`` (:math:`l_j = d - l_i`) and the
circle has the radius :math:`a = \sqrt{r_i^2 - l_i^2}` (Zohdi 2014, eqs. 7-12 use the same lens). Second neighbours
that overlap are necks too. A neck is seen from its particle's centre as a cone of half-angle
:math:`\arctan(a / l)` (:func:`angular_radius`); two necks of one particle *meet* when their cones overlap
(:func:`necks_meet`), which is where the pair-neck models end.

**Volumes and areas** (:func:`cut_spheres`). The cut sphere ``k`` (ball ``k`` and the half-spaces
:math:`n_b \cdot (x - x_k) \le l_b` of its necks) is convex, and by the divergence theorem with the origin at its
centre its volume is :math:`V = (r A_{free} + \sum_b l_b A_b) / 3`, where :math:`A_{free}` is the area of its
spherical surface left and :math:`A_b` the area of its flat face ``b`` (the disk of neck ``b`` less what other faces
cut off). With the centre inside the cut sphere (every :math:`l_b > 0`), the faces and the free surface are seen from
the centre in disjoint solid angles :math:`\Omega_b` that fill the sphere, so
:math:`A_{free} = r^2 (4 \pi - \sum_b \Omega_b)`. Each face is a convex polygon (the
half-planes the other faces leave in its plane) intersected with its disk; its area and its solid angle are integrals
over the face of functions of the distance :math:`\rho` from the foot of the centre's perpendicular, so they are
sums over the polygon's edges of signed sectors around that foot, each integrated in closed form (the edge
:math:`\rho = p / \cos\varphi`: :math:`\int p^2 / (2 \cos^2\varphi) \, d\varphi = p^2 \tan(\varphi) / 2` for the
area and :math:`\int \left(1 - h \cos\varphi / \sqrt{h^2 \cos^2\varphi + p^2}\right) d\varphi = \varphi -
\arcsin\left(h \sin\varphi / \sqrt{h^2 + p^2}\right)` for the solid angle, the circle :math:`\rho = a` linear
in :math:`\varphi`). The volumes are exact to round-off, and their sum is the volume of the union.
These areas also give the derivatives that keep volumes under growth: moving face ``b`` outward by :math:`dl` adds
:math:`A_b \, dl`, and growing the radius by :math:`dr` adds :math:`A_{free} \, dr`.

Where necks do not meet, the cut sphere is the sphere less its caps,
:math:`V = \frac{4}{3} \pi r^3 - \sum_b \pi (r - l_b)^2 (2 r + l_b) / 3`, and this is what the kernel computes for
such particles.

The range: two spheres have a neck for :math:`|r_i - r_j| < d < r_i + r_j`; the cut sphere needs its centre on its own
side of every radical plane, :math:`l_b > 0` (:math:`d^2 > r_j^2 - r_i^2`: the centre of the smaller sphere outside the
larger), as the lens of :mod:`dem.geometry.bonds` does.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from fem_neck.geometry import check_positive

PAIRS_PER_BLOCK = 1 << 20  # necks_meet compares at most this many pairs of necks at once (a few tens of MB)


@dataclass(frozen=True)
class Lens:
    """The neck of two overlapping spheres in the union (:func:`lens`).

    Parameters
    ----------
    a : numpy.ndarray or float
        Radius of the circle where the two spheres meet, m.
    l_i, l_j : numpy.ndarray or float
        Distances from centre ``i`` and from centre ``j`` to the radical plane that holds the circle, m
        (:math:`l_i + l_j = d`).
    """

    a: np.ndarray
    l_i: np.ndarray
    l_j: np.ndarray


def lens(r_i, r_j, d) -> Lens:
    """The neck circle of two overlapping spheres (module docstring); arrays broadcast.

    Parameters
    ----------
    r_i, r_j : float or array_like
        Radii of the two spheres, m.
    d : float or array_like
        Distance between their centres, m.

    Returns
    -------
    Lens
        The circle's radius and the centres' distances from its plane.

    Raises
    ------
    ValueError
        Unless ``|r_i - r_j| < d < r_i + r_j`` (the spheres overlap and neither holds the other).
    """
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
    r"""Half-angle of the cone in which a neck is seen from its particle's centre: :math:`\arctan(a / l)`. For a pair
    neck (:mod:`fem_neck.geometry`) the circle on the sphere lies at :math:`l = \sqrt{r^2 - a^2}`, so the angle is
    :math:`\arcsin(a / r)`.

    Parameters
    ----------
    a : float or array_like
        Neck (circle) radius, m.
    l : float or array_like
        Distance from the centre to the circle's plane, m.

    Returns
    -------
    float or numpy.ndarray
        The half-angle, rad.
    """
    return np.arctan2(a, l)


@dataclass(frozen=True)
class CutSpheres:
    """The cut spheres of a packing (:func:`cut_spheres`).

    Parameters
    ----------
    volume : numpy.ndarray
        Per particle, the volume of its sphere cut by the radical planes of its necks, m^3.
    free_area : numpy.ndarray
        Per particle, the area of its spherical surface left, m^2.
    meeting : numpy.ndarray
        Per particle, whether two of its necks meet (bool).
    face_i, face_j : numpy.ndarray
        Per bond, the area of the flat face the neck leaves on particle ``i`` and on ``j``, m^2 (equal: the face is
        one piece of the radical plane).
    """

    volume: np.ndarray
    free_area: np.ndarray
    meeting: np.ndarray
    face_i: np.ndarray
    face_j: np.ndarray


def cut_spheres(radius, i, j, vectors) -> CutSpheres:
    r"""Cut every sphere by the radical planes of its necks (module docstring).

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    i, j : numpy.ndarray
        The overlapping pairs, integer indices (each pair once; ``j`` may be a periodic image of a particle, given by
        ``vectors``).
    vectors : numpy.ndarray
        :math:`x_j - x_i` of every pair (one row each), m: the image's in a periodic packing.

    Returns
    -------
    CutSpheres
        Volumes, free areas, whether necks meet, per particle; face areas per bond. ``ValueError`` for a pair that
        does not overlap, one sphere holding the other, or a centre beyond a radical plane
        (:math:`d^2 \le r_j^2 - r_i^2`), naming the first.
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
        neck = lens(radius[i], radius[j], d)  # the range of every pair, with its message
        beyond = (neck.l_i <= 0.0) | (neck.l_j <= 0.0)
        if np.any(beyond):
            b = int(np.flatnonzero(beyond)[0])
            raise ValueError(f"pair ({i[b]}, {j[b]}): d = {d[b]:.6g} with radii {radius[i[b]]:.6g} and "
                             f"{radius[j[b]]:.6g} puts a centre beyond their radical plane (the union reading needs "
                             f"d^2 > |r_j^2 - r_i^2|)")
    from fem_neck.geometry.cut_kernels import cut_spheres_kernel as kernel  # compiled: loaded only where spheres are cut

    out = kernel(n, radius, i, j, np.ascontiguousarray(vectors), d)
    m = len(i)
    return CutSpheres(out[0], out[1], out[2].astype(bool), out[3][:m], out[3][m:])


def necks_meet(n: int, particle, direction, angle) -> np.ndarray:
    """Whether two necks of each of ``n`` particles meet (bool per particle), for any neck reading: two necks of one
    particle meet when the angle between their directions is at most the sum of their half-angles.

    Parameters
    ----------
    n : int
        Number of particles.
    particle : numpy.ndarray
        The particle of each neck end, integer indices (a pair bond has two ends, a wall bond one).
    direction : numpy.ndarray
        The direction from that particle's centre toward the neck (one row each, any length but zero).
    angle : numpy.ndarray
        Half-angle (rad) of the cone in which the neck is seen from the centre (:func:`angular_radius`).

    Returns
    -------
    numpy.ndarray
        Per particle, whether two of its necks meet (bool).
    """
    return meeting_pairs(n, particle, direction, angle) > 0


def meeting_pairs(n: int, particle, direction, angle) -> np.ndarray:
    """How many pairs of necks of each of ``n`` particles meet (:func:`necks_meet`'s test on every pair).

    Parameters
    ----------
    n : int
        Number of particles.
    particle : numpy.ndarray
        The particle of each neck end, integer indices (a pair bond has two ends, a wall bond one).
    direction : numpy.ndarray
        The direction from that particle's centre toward the neck (one row each, any length but zero).
    angle : numpy.ndarray
        Half-angle (rad) of the cone in which the neck is seen from the centre (:func:`angular_radius`).

    Returns
    -------
    numpy.ndarray
        Per particle, the pairs of its necks that meet (int).
    """
    particle = np.ascontiguousarray(particle, dtype=np.int64).reshape(-1)
    direction = np.ascontiguousarray(direction, dtype=float).reshape(-1, 3)
    angle = np.ascontiguousarray(angle, dtype=float).reshape(-1)
    if not (len(particle) == len(direction) == len(angle)):
        raise ValueError(f"particle, direction and angle: {len(particle)}, {len(direction)} and {len(angle)} "
                         f"entries, must be as many")
    if len(particle) and (particle.min() < 0 or particle.max() >= n):
        raise ValueError(f"particle: indices must lie in 0..{n - 1}")
    unit = direction / np.sqrt(np.einsum("ij,ij->i", direction, direction))[:, None]
    order = np.argsort(particle, kind="stable")
    counts = np.bincount(particle, minlength=int(n))
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])  # a particle's ends are order[first : first + count]
    out = np.zeros(int(n), dtype=np.int64)
    for z in np.unique(counts[counts >= 2]):  # the particles of one neck count at once: every pair of their necks
        b, c = np.triu_indices(int(z), 1)
        group = np.flatnonzero(counts == z)
        for block in np.array_split(group, -(-len(group) * len(b) // PAIRS_PER_BLOCK)):
            ends = order[first[block][:, None] + np.arange(z)]  # (particles, z)
            u, half = unit[ends], angle[ends]
            cos_g = np.matmul(u, u.transpose(0, 2, 1))[:, b, c]
            out[block] = np.count_nonzero(np.arccos(np.clip(cos_g, -1.0, 1.0)) <= half[:, b] + half[:, c], axis=1)
    return out


