r"""Geometric quadrilateral meshes of the semisphere with a neck (Rojek 2022, Sec. 5, Fig. 12), for hp elements.

The body (sphere radius 1, neck radius ``a``, meridian half-plane, ``x`` radial) is the sphere cut at its equator
:math:`z = 0` and at the cap base :math:`z_i = \sqrt{1 - a^2}`, plus the half neck :math:`[0, a] \times [z_i, z_i + t]`
with :math:`t = h_n / 2` (eqs. 19-20) -- or, for the *union* of spheres, no neck cylinder at all (:math:`t = 0`: the end
disk is the cap base itself, the circle where two spheres meet). The temperature is singular at the corner
``C = (a, z_i)`` (re-entrant with the cylinder; with the union, where the isothermal disk meets the insulated sphere);
an hp method converges exponentially when the elements shrink geometrically toward ``C`` while the order is raised
(Babuska-Guo). The mesh is built from three families of quadrilaterals, all from closed-form points (no mesher):

* **corner cells** -- three cells meet at ``C``: the neck square ``[a - R, a] x [z_i, z_i + R]``, the square below
  it, and the wedge between the line ``x = a`` and the sphere (the union has no neck square: two cells). Each is
  refined ``levels`` times by the pattern "corner cell -> corner cell scaled by ``sigma`` + two trapezoids" (far
  edges untouched, so the mesh stays conforming);
* **rings** around ``C`` (geometric radii from ``R`` to ``a``) and, for small necks, rings around the axis point
  ``P = (0, z_i)`` (from ``3.5 a`` to ``0.6 z_i``), so every scale from the neck height :math:`t \approx a^2 / 4` to the
  sphere radius is covered by elements of its own size;
* a few **far cells** that reach the equator.

The neck above the cap base is a tensor grid whose columns end at :math:`x = a - \rho` for the ring radii :math:`\rho`.
Two layouts of the body below share the corner cells: *small neck* (``a <= 0.6``, ``R = t``: square and wedge rings to
the axis, then rings around ``P`` and spokes to the equator) and *large neck* (``a > 0.6``, ``R = min(t, z_i / 2)``: two
rows of the neck's columns, then the wedge down to the equator); the union takes :math:`R = \min(a / 4, z_i / 2)`. A
pair (:func:`pair_quad_mesh`) is two such half bodies, each in its own sphere radius, glued at the neck's mid-plane.

Coordinates are ``(x, z - z_i)``: relative to the corner's height, so elements of size 1e-15 next to ``C`` keep full
precision even at ``a = 1e-4`` (where ``t = 2.5e-9``); points on the sphere are given by their angle offset
``delta`` from ``C`` and evaluated without cancellation.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fem_neck.geometry import cap_height, neck_geometry
from fem_neck.law import check_neck
from fem_neck.spectral import QuadMesh

SIGMA = 0.17            # geometric factor of the corner refinement (hp optimum ~0.15-0.2)
RING_RATIO = 4.0        # largest radius ratio between consecutive rings
SMALL_NECK_MAX = 0.6    # a / r up to which the small-neck layout is used
P_RINGS_START = 3.5     # first ring around P, in units of a
P_RINGS_END = 0.6       # last ring around P, in units of z_i
LONGEST_ARC = 0.6       # radians of sphere in one far cell before it is split


@dataclass(frozen=True)
class SemisphereShape:
    r"""Dimensions of the body (sphere radius 1): neck radius ``a``, cap base ``z_i``, half-neck height ``t`` (0 for
    the union), the corner's polar angle ``phi_c``. Exact volume for checks: :meth:`volume`.

    Parameters
    ----------
    a : float
        Neck radius, in units of the sphere radius.
    z_i : float
        Height of the cap base above the equator, :math:`\sqrt{1 - a^2}`, in units of the sphere radius.
    t : float
        Height of the half neck above the cap base, ``h_n / 2`` (eqs. 19-20), in units of the sphere radius; 0 for
        the union.
    phi_c : float
        Polar angle of the corner ``C`` from the equatorial plane, :math:`\arctan(z_i / a)` (rad).
    """

    a: float
    z_i: float
    t: float
    phi_c: float

    @classmethod
    def from_neck(cls, a: float, neck: str = "cylinder") -> "SemisphereShape":
        """The body of neck radius ``a``: ``neck = "cylinder"`` (the volume-conserving half neck, eqs. 19-20) or
        ``"union"`` (no neck cylinder).

        Parameters
        ----------
        a : float
            Neck radius, in units of the sphere radius, in ``[0, 1)``.
        neck : str
            The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (with the volume-conserving half neck) or
            ``"union"`` (no neck cylinder).

        Returns
        -------
        SemisphereShape
            The body's dimensions.

        Raises
        ------
        ValueError
            ``neck`` is not one of :data:`fem_neck.law.NECKS`.
        """
        h_c = float(cap_height(1.0, a))
        t = h_c * (3.0 - h_c) / (3.0 * (2.0 - h_c)) if check_neck(neck) == "cylinder" else 0.0
        z_i = math.sqrt((1.0 - a) * (1.0 + a))
        return cls(a=a, z_i=z_i, t=t, phi_c=math.atan2(z_i, a))

    def volume(self) -> float:
        """Volume of revolution: the sphere between ``z = 0`` and ``z_i`` plus the neck cylinder."""
        return math.pi * (self.z_i - self.z_i**3 / 3.0) + math.pi * self.a**2 * self.t

    def sphere_point(self, delta):
        r"""Points on the sphere at angle offset ``delta`` (toward the equator) from ``C``, in ``(x, z - z_i)``, and
        their ``delta``-derivatives;
        :math:`S - C = 2 \sin(\delta/2) \left(\sin(\varphi_c - \delta/2), -\cos(\varphi_c - \delta/2)\right)` with
        :math:`\delta` the ``delta`` and :math:`\varphi_c` the ``phi_c``.

        Parameters
        ----------
        delta : float or array_like
            Angle offsets from ``C`` along the sphere toward the equator (rad), any shape.

        Returns
        -------
        tuple of (numpy.ndarray, numpy.ndarray)
            The points ``(x, z - z_i)`` and their derivatives with respect to ``delta``, of the shape of ``delta`` with
            a last axis of 2 each (units of the sphere radius).
        """
        delta = np.asarray(delta, dtype=float)
        half = np.sin(0.5 * delta)
        mid = self.phi_c - 0.5 * delta
        points = np.stack([self.a + 2.0 * half * np.sin(mid), -2.0 * half * np.cos(mid)], axis=-1)
        tangent = np.stack([np.sin(self.phi_c - delta), -np.cos(self.phi_c - delta)], axis=-1)
        return points, tangent


class _Builder:
    """Collects vertices (deduplicated by exact coordinates) and counter-clockwise quads; an edge joining two
    sphere points is a boundary arc."""

    def __init__(self, shape: SemisphereShape):
        self.shape = shape
        self.points: list[tuple[float, float]] = []
        self.delta: list[float] = []
        self.index: dict[tuple[float, float], int] = {}
        self.quads: list[list[int]] = []

    def vertex(self, x: float, z: float, delta: float = math.nan) -> int:
        key = (float(x), float(z))
        if key not in self.index:
            self.index[key] = len(self.points)
            self.points.append(key)
            self.delta.append(delta)
        return self.index[key]

    def sphere(self, delta: float) -> int:
        if delta == self.shape.phi_c:  # the equator's rim, exactly on the bottom plane
            return self.vertex(1.0, -self.shape.z_i, delta)
        half, mid = math.sin(0.5 * delta), self.shape.phi_c - 0.5 * delta
        return self.vertex(self.shape.a + 2.0 * half * math.sin(mid), -2.0 * half * math.cos(mid), delta)

    def quad(self, *ids: int) -> None:
        pts = [self.points[i] for i in ids]
        twice_area = sum(pts[k - 1][0] * pts[k][1] - pts[k][0] * pts[k - 1][1] for k in range(4))
        self.quads.append(list(ids) if twice_area > 0.0 else list(ids[::-1]))

    def ray_point(self, corner: int, far: int, fraction: float) -> int:
        """The point at ``fraction`` of the way from ``corner`` to ``far``: along the sphere if both are on it."""
        if not (math.isnan(self.delta[corner]) or math.isnan(self.delta[far])):
            return self.sphere(self.delta[corner] + fraction * (self.delta[far] - self.delta[corner]))
        (xc, zc), (xf, zf) = self.points[corner], self.points[far]
        return self.vertex(xc + fraction * (xf - xc), zc + fraction * (zf - zc))

    def corner_cell(self, corner: int, ray1: int, opposite: int, ray2: int, levels: int, sigma: float) -> None:
        """Refine the cell ``(corner, ray1, opposite, ray2)`` geometrically toward ``corner``."""
        for _ in range(levels):
            r1, r2 = self.ray_point(corner, ray1, sigma), self.ray_point(corner, ray2, sigma)
            (xc, zc), (xo, zo) = self.points[corner], self.points[opposite]
            o = self.vertex(xc + sigma * (xo - xc), zc + sigma * (zo - zc))
            self.quad(r1, ray1, opposite, o)
            self.quad(o, opposite, ray2, r2)
            ray1, opposite, ray2 = r1, o, r2
        self.quad(corner, ray1, opposite, ray2)

    def grid(self, xs, zs, skip_row: int) -> None:
        """The tensor grid of cells ``[xs[i], xs[i+1]] x [zs[j], zs[j+1]]``, without the last column's row
        ``skip_row`` (a corner cell, built by :meth:`corner_cell`)."""
        for i in range(len(xs) - 1):
            for j in range(len(zs) - 1):
                if i == len(xs) - 2 and j == skip_row:
                    continue
                self.quad(self.vertex(xs[i], zs[j]), self.vertex(xs[i + 1], zs[j]),
                          self.vertex(xs[i + 1], zs[j + 1]), self.vertex(xs[i], zs[j + 1]))

    def mesh(self) -> QuadMesh:
        points = np.array(self.points)
        quads = np.array(self.quads, dtype=np.int64)
        delta = np.array(self.delta)
        ends = np.stack([delta[quads], delta[np.roll(quads, -1, axis=1)]], axis=-1)
        straight = np.isnan(ends).any(axis=-1)
        ends[straight] = np.nan
        return QuadMesh(points=points, quads=quads, arc_angles=ends, arc_circle=np.where(straight, -1, 0),
                        circles=(self.shape.sphere_point,), origin=(0.0, self.shape.z_i))


def _radii(start: float, end: float, ratio: float = RING_RATIO) -> np.ndarray:
    """Geometric radii from ``start`` to ``end`` (both included) with ratio at most ``ratio``."""
    n = max(1, math.ceil(math.log(end / start) / math.log(ratio) - 1e-9))
    radii = start * (end / start) ** (np.arange(n + 1) / n)
    radii[0], radii[-1] = start, end
    return radii


def _graded_breaks(start: float, end: float, first: float, ratio: float = 3.0) -> list[float]:
    """Breaks from ``start`` toward ``end`` with widths ``first, first*ratio, ...``; the last piece is merged when
    it would be thinner than half the previous one. Includes both ends."""
    sign = 1.0 if end > start else -1.0
    breaks, width = [start], first
    while abs(end - breaks[-1]) > 1.5 * width:
        breaks.append(breaks[-1] + sign * width)
        width *= ratio
    breaks.append(end)
    return breaks


def _bulge_mid(builder: _Builder, shape: SemisphereShape, rho: float, sphere_delta: float) -> int:
    """The vertex between the line ``x = a`` (down from ``C``) and the chord to the sphere point at ``rho``: on the
    bisector, at ``rho / cos(alpha / 2)`` (so the corner cell is a kite with right angles at its ray ends)."""
    point, _ = shape.sphere_point(sphere_delta)
    chord = math.atan2(point[1], point[0] - shape.a)
    alpha = chord + 0.5 * math.pi
    angle = -0.5 * math.pi + 0.5 * alpha
    dist = rho / math.cos(0.5 * alpha)
    return builder.vertex(shape.a + dist * math.cos(angle), dist * math.sin(angle))


def _chord_delta(rho: float) -> float:
    """Angle offset of the sphere point at chord length ``rho`` from ``C`` (unit sphere)."""
    return 2.0 * math.asin(0.5 * rho)


def semisphere_quad_mesh(a: float, levels: int, sigma: float = SIGMA,
                         neck: str = "cylinder") -> tuple[QuadMesh, SemisphereShape]:
    """The geometric quadrilateral mesh of the semisphere with neck radius ``a`` (``1e-4 <= a < 1``, sphere radius
    1) refined ``levels`` times toward the corner; ``neck``: ``"cylinder"`` or ``"union"`` (module docstring).

    Parameters
    ----------
    a : float
        Neck radius over sphere radius, ``1e-4 <= a < 1``.
    levels : int
        Number of geometric refinements of the corner cells toward the corner ``C`` (>= 0).
    sigma : float
        The geometric factor of each refinement, in ``(0, 1)`` (``SIGMA`` by default).
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (with the volume-conserving half neck) or
        ``"union"`` (no neck cylinder).

    Returns
    -------
    tuple of (fem_neck.spectral.QuadMesh, SemisphereShape)
        The mesh (coordinates ``(x, z - z_i)``, units of the sphere radius) and the body's dimensions.
    """
    shape = SemisphereShape.from_neck(a, neck)
    return half_body(shape, corner_radius(shape), levels, sigma), shape


def end_disks(mesh: QuadMesh, shape: SemisphereShape) -> dict:
    """The fixed temperatures of the semisphere, as :func:`fem_neck.spectral.conductance` takes them: ``T = 0`` on
    the equatorial disk, ``1`` on the neck's end disk (vertex masks; both planes are built exactly).

    Parameters
    ----------
    mesh : fem_neck.spectral.QuadMesh
        A mesh of :func:`half_body` or :func:`semisphere_quad_mesh`.
    shape : SemisphereShape
        The body it meshes.

    Returns
    -------
    dict
        ``{0.0: mask, 1.0: mask}``: bool vertex masks of the equatorial disk and the end disk.
    """
    z = mesh.points[:, 1]
    return {0.0: z == -shape.z_i, 1.0: z == shape.t}


def corner_radius(shape: SemisphereShape) -> float:
    """Radius ``R`` of the corner cells: the neck height ``t`` for small necks, at most half of ``z_i`` otherwise;
    without a neck cylinder (``t = 0``) a quarter of the neck radius, at most half of ``z_i`` (one ring to ``a``).

    Parameters
    ----------
    shape : SemisphereShape
        The body.

    Returns
    -------
    float
        ``R``, in units of the sphere radius.
    """
    if shape.t == 0.0:
        return min(shape.a / RING_RATIO, 0.5 * shape.z_i)
    return shape.t if shape.a <= SMALL_NECK_MAX else min(shape.t, 0.5 * shape.z_i)


def half_body(shape: SemisphereShape, R: float, levels: int, sigma: float = SIGMA) -> QuadMesh:
    r"""One sphere from its equator to the plane ``t`` above its cap base (the neck's end disk), corner cells of
    radius ``R <= t``. The neck cylinder is a tensor grid whose columns end at :math:`x = a - \rho` for the ring radii
    :math:`\rho` from ``R`` to ``a`` -- so two halves with the same ``a``, ``t`` and ``R`` share their end disk's nodes
    (:func:`pair_quad_mesh`). With ``t = 0`` (the union) the end disk is the cap base and ``0 < R < a``.

    Parameters
    ----------
    shape : SemisphereShape
        The body (units of its sphere radius).
    R : float
        Radius of the corner cells (units of the sphere radius), ``<= t`` (``< a`` for the union).
    levels : int
        Number of geometric refinements of the corner cells toward the corner ``C`` (>= 0).
    sigma : float
        The geometric factor of each refinement, in ``(0, 1)`` (``SIGMA`` by default).

    Returns
    -------
    fem_neck.spectral.QuadMesh
        The mesh, in coordinates ``(x, z - z_i)``.
    """
    if shape.t > 0.0 and R >= shape.t * (1.0 - 1e-9):  # a corner radius in another sphere's units may miss t
        R = shape.t
    b = _Builder(shape)
    corner = b.sphere(0.0)
    down, mid, on_sphere = _corner_cells(b, shape, corner, R, levels, sigma)
    radii = _radii(R, shape.a)
    if shape.t > 0.0:
        _neck_block(b, shape, R, radii)
    if shape.a <= SMALL_NECK_MAX:
        _small_neck_body(b, shape, radii)
    else:
        _large_neck_body(b, shape, R, radii, down, mid, on_sphere)
    return b.mesh()


def _corner_cells(b: _Builder, shape: SemisphereShape, corner: int, R: float, levels: int, sigma: float):
    """The refined corner cells of radius ``R`` (three; two without a neck cylinder); returns the ids of their
    outer vertices."""
    a = shape.a
    up = (b.vertex(a, R), b.vertex(a - R, R)) if shape.t > 0.0 else None
    left, low_left, down = b.vertex(a - R, 0.0), b.vertex(a - R, -R), b.vertex(a, -R)
    s_delta = _chord_delta(R)
    on_sphere = b.sphere(s_delta)
    mid = _bulge_mid(b, shape, R, s_delta)
    if up is not None:
        b.corner_cell(corner, *up, left, levels, sigma)
    b.corner_cell(corner, left, low_left, down, levels, sigma)
    b.corner_cell(corner, down, mid, on_sphere, levels, sigma)
    return down, mid, on_sphere


def _neck_block(b: _Builder, shape: SemisphereShape, R: float, radii) -> None:
    """The neck cylinder ``[0, a] x [0, t]`` (above the cap base) as a tensor grid, without the corner cell."""
    a, t = shape.a, shape.t
    b.grid([a - rho for rho in radii[::-1]] + [a], [0.0] + (_graded_breaks(R, t, 3.0 * R) if R < t else [t]),
           skip_row=0)


def _small_neck_body(b: _Builder, shape: SemisphereShape, radii) -> None:
    """Below the cap base of a small neck: square rings and wedge rings around the corner out to ``a``, rings
    around the axis point ``P`` out to ``0.6 z_i``, then spokes to the equator."""
    a, z_i = shape.a, shape.z_i
    for rho, nxt in zip(radii[:-1], radii[1:]):
        b.quad(b.vertex(a - rho, 0.0), b.vertex(a - nxt, 0.0), b.vertex(a - nxt, -nxt), b.vertex(a - rho, -rho))
        b.quad(b.vertex(a - rho, -rho), b.vertex(a - nxt, -nxt), b.vertex(a, -nxt), b.vertex(a, -rho))
        d0, d1 = _chord_delta(rho), _chord_delta(nxt)
        m0, m1 = _bulge_mid(b, shape, rho, d0), _bulge_mid(b, shape, nxt, d1)
        b.quad(b.vertex(a, -rho), b.vertex(a, -nxt), m1, m0)
        b.quad(m0, m1, b.sphere(d1), b.sphere(d0))
    layer = [b.vertex(0.0, -a), b.vertex(a, -a), _bulge_mid(b, shape, a, _chord_delta(a)), b.sphere(_chord_delta(a))]
    start, end = P_RINGS_START * a, P_RINGS_END * z_i
    for rho in (_radii(start, end) if start <= end else []):
        # ring around P = (0, z_i): axis, two interior rays, the sphere point at distance rho from P
        z_rel = (a - rho) * (a + rho) / (2.0 * z_i)
        x = math.sqrt((rho - z_rel) * (rho + z_rel))
        delta = shape.phi_c - math.atan2(z_i + z_rel, x)
        theta = math.atan2(x, -z_rel)
        nxt = [b.vertex(0.0, -rho)]
        nxt += [b.vertex(rho * math.sin(k * theta / 3.0), -rho * math.cos(k * theta / 3.0)) for k in (1, 2)]
        nxt.append(b.sphere(delta))
        for k in range(3):
            b.quad(layer[k], nxt[k], nxt[k + 1], layer[k + 1])
        layer = nxt
    origin = b.vertex(0.0, -z_i)
    f1 = b.vertex(0.5 * b.points[layer[1]][0] + 1.0 / 6.0, -z_i)
    f2 = b.vertex(0.5 * b.points[layer[2]][0] + 1.0 / 3.0, -z_i)
    b.quad(origin, f1, layer[1], layer[0])
    b.quad(f1, f2, layer[2], layer[1])
    _far_wedge(b, shape, f2, layer[3], layer[2])


def _large_neck_body(b: _Builder, shape: SemisphereShape, R: float, radii, down: int, mid: int,
                     on_sphere: int) -> None:
    """Below the cap base of a large neck: the cylinder ``x <= a`` as two rows of the neck's columns, then the
    wedge between ``x = a`` and the sphere down to the equator."""
    a, z_i = shape.a, shape.z_i
    b.grid([a - rho for rho in radii[::-1]] + [a], [-z_i, -R, 0.0], skip_row=1)
    foot = b.vertex(a, -z_i)
    f = b.vertex(0.5 * (a + 1.0), -z_i)
    b.quad(down, foot, f, mid)
    _far_wedge(b, shape, f, on_sphere, mid)


def _far_wedge(b: _Builder, shape: SemisphereShape, foot: int, on_sphere: int, inner: int) -> None:
    """The cell ``(foot, equator rim, on_sphere, inner)`` whose outer edge is the sphere from the equator up to
    ``on_sphere``. An arc of more than ~35 degrees in one cell slows the p-convergence (measured: 3e-5 -> 2e-6 at
    p = 5, a/r = 0.2), so a long arc is split at its middle into three cells around an interior point."""
    equator = b.sphere(shape.phi_c)
    delta = b.delta[on_sphere]
    if shape.phi_c - delta <= LONGEST_ARC:
        b.quad(foot, equator, on_sphere, inner)
        return
    middle = b.sphere(0.5 * (delta + shape.phi_c))
    x_foot, z_bottom = b.points[foot]
    half = b.vertex(0.5 * (x_foot + 1.0), z_bottom)
    pts = np.array([b.points[i] for i in (foot, half, middle, inner)])
    centre = b.vertex(*pts.mean(axis=0))
    b.quad(foot, half, centre, inner)
    b.quad(half, equator, middle, centre)
    b.quad(centre, middle, on_sphere, inner)


def pair_quad_mesh(r_i: float, r_j: float, h: float, levels: int, sigma: float = SIGMA):
    """The hp mesh of two sintered spheres (Rojek 2022, Sec. 6): sphere ``i`` below, ``j`` above, each built by
    :func:`half_body` in its own radius and glued at the neck's mid-plane (both halves have the same neck radius,
    half-neck height and corner radius, hence the same nodes there). Lengths in units of ``s = min(r_i, r_j)``, ``z``
    from the mid-plane. The corner radius is the smaller of the two halves' own (:func:`corner_radius`), so the
    neck's columns, which depend on ``a``, ``t`` and ``R`` alone, are the same in both; ``mesh.origin`` puts absolute
    ``z`` at sphere ``i``'s centre, as on the gmsh path. Returns ``(mesh, s, bottom vertex mask, top vertex mask,
    a)``.

    Parameters
    ----------
    r_i : float
        Radius of the lower sphere (any length unit, e.g. m).
    r_j : float
        Radius of the upper sphere (same unit).
    h : float
        Overlap of the two spheres (same unit), which gives the volume-conserving neck
        (:func:`fem_neck.geometry.neck_geometry`).
    levels : int
        Number of geometric refinements of the corner cells toward the corner ``C`` (>= 0).
    sigma : float
        The geometric factor of each refinement, in ``(0, 1)`` (``SIGMA`` by default).

    Returns
    -------
    tuple
        ``(mesh, s, bottom, top, a)``: the mesh in units of ``s = min(r_i, r_j)``, ``s``, the bool vertex masks
        of sphere i's and sphere j's equatorial disks, and the neck radius (unit of the radii).

    Raises
    ------
    RuntimeError
        The two halves do not share the neck's mid-plane nodes.
    """
    geo = neck_geometry(r_i, r_j, h)
    a, t = float(geo.a), 0.5 * float(geo.h_n)
    s = min(r_i, r_j)
    shapes = [SemisphereShape(a=a / r, z_i=z / r, t=t / r, phi_c=math.atan2(z, a))
              for r, z in ((r_i, float(geo.z_i)), (r_j, float(geo.z_j)))]
    R = min(corner_radius(shape) * r for shape, r in zip(shapes, (r_i, r_j)))  # common: same end-disk nodes
    halves = []
    for r, shape, mirror in ((r_i, shapes[0], False), (r_j, shapes[1], True)):
        halves.append((half_body(shape, R / r, levels, sigma), shape, r / s, mirror))
    points, quads, angles, circles, index = [], [], [], [], []
    masks, offset, interface = [], 0, None
    for number, (mesh, shape, k, mirror) in enumerate(halves):
        sign = -1.0 if mirror else 1.0
        p = np.column_stack([mesh.points[:, 0] * k, sign * (mesh.points[:, 1] - shape.t) * k])
        ids = np.arange(len(p)) + offset
        on_disk = np.flatnonzero(mesh.points[:, 1] == shape.t)
        on_disk = on_disk[np.argsort(p[on_disk, 0])]
        if interface is None:
            interface = (ids[on_disk], p[on_disk, 0])
        else:
            lower_ids, lower_x = interface
            if lower_x.size != on_disk.size or not np.allclose(p[on_disk, 0], lower_x, rtol=0, atol=1e-12 * a / s):
                raise RuntimeError("hp pair mesh: the two halves do not share the neck's mid-plane nodes")
            ids[on_disk] = lower_ids
            keep = np.ones(len(p), dtype=bool)
            keep[on_disk] = False
            ids[keep] = offset + np.arange(int(keep.sum()))
            p = p[keep]
        q, ang = ids[mesh.quads], mesh.arc_angles
        if mirror:  # reversed vertex order keeps the quads counter-clockwise; edge m was edge (2 - m) mod 4
            q, ang = q[:, ::-1], ang[:, [2, 1, 0, 3], ::-1]
        points.append(p)
        quads.append(q)
        angles.append(ang)
        index.append(np.where(np.isnan(ang[..., 0]), -1, number))
        circles.append(_scaled_circle(shape.sphere_point, k, shape.t, sign))
        masks.append((ids, mesh.points[:, 1] == -shape.z_i))
        offset += len(p)
    n = offset
    fixed = []
    for ids, mask in masks:
        full = np.zeros(n, dtype=bool)
        full[ids[mask]] = True
        fixed.append(full)
    mesh = QuadMesh(points=np.vstack(points), quads=np.vstack(quads), arc_angles=np.concatenate(angles),
                    arc_circle=np.concatenate(index), circles=tuple(circles), origin=(0.0, (float(geo.z_i) + t) / s))
    return mesh, s, fixed[0], fixed[1], a


def _scaled_circle(circle, k: float, t: float, sign: float):
    """``circle`` in pair coordinates: ``x k``, ``sign (z - t) k``."""
    def point(delta):
        p, d = circle(delta)
        return (np.stack([p[..., 0] * k, sign * (p[..., 1] - t) * k], axis=-1),
                np.stack([d[..., 0] * k, sign * d[..., 1] * k], axis=-1))
    return point
