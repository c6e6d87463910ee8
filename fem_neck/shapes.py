r"""Axisymmetric meshes of sintered spheres with cylindrical necks: gmsh (OCC kernel) -> scikit-fem.

Every body here is a solid of revolution about the z axis, so it is meshed in its meridian half-plane
``x = radial coordinate >= 0``, ``y = axial coordinate z``:

* :func:`semisphere_mesh` -- the semisphere with a cylindrical neck of Rojek 2022, Section 5, Fig. 12: the sphere of
  radius ``r`` from its equatorial plane :math:`z = 0` to the cap base :math:`z_i = \sqrt{r^2 - a^2}`, then the half
  neck, a cylinder of radius ``a`` and height ``h_n / 2`` (eqs. 19-20); with ``neck = "union"`` the half body of the
  union of spheres, the sphere up to the cap base alone (no neck cylinder);
* :func:`chain_mesh` -- a collinear chain of spheres with arbitrary radii and overlaps, the end particles cut at
  their outer equatorial planes (the unequal pair of Section 6, Figs. 8 and 17, is the chain of two).

Named boundaries of the returned :class:`ProfileMesh`: ``bottom`` and ``top`` (the two end disks, where the
temperature is fixed), ``axis`` (the symmetry axis ``x = 0``), ``sphere{k}`` (the spherical surface of particle k),
``neck{k}`` (the cylindrical surface of neck k) and ``insulated`` (all sphere and neck surfaces).

Meshing. The temperature is singular at every re-entrant corner circle where a neck meets a sphere (corner exponent
:math:`\lambda = \pi / (\pi + \arccos(a/r))`). The element size grows linearly with the distance ``d`` to the nearest
corner, ``size = min(h_max, h_min + grading * d)``: a geometric grading whose innermost layer is ``h_min`` (far below
any tolerance) and whose accuracy is set by ``grading``. Inside a neck thinner than ``grading * a`` (small
``a/r``: the half neck is :math:`\approx a^2/(4r)` high) the size is at most 4 neck heights. The triangles in that thin,
nearly isothermal disk get flat (largest angle up to ~170 degrees at a/r = 0.001), which is harmless there: at
a/r = 0.001 K changes by < 1e-8 between 1 and 0.1 cells per height, while 1-2 cells per height took 1-2 s to mesh.
gmsh runs single-threaded with its Frontal-Delaunay mesher, so the same input gives the same mesh; it is initialised and
finalised inside one context manager (:func:`gmsh_session`) and never left running.
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import dataclass

import numpy as np

from fem_neck import signal_guard
from fem_neck.geometry import cap_height, check_positive, neck_geometry
from fem_neck.law import check_neck

# Defaults of the size field (lengths relative to the corner or neck scale, see module docstring).
DEFAULT_GRADING = 0.3
# Smallest neck radius over sphere radius that is meshed: the half neck is a^2/(4r) high, ~2.5e-9 r at the limit
# (meshing takes ~10 s there, ~2 s at 3e-4, 0.3 s at 1e-3). Below it K is the constriction limit 4 kappa a to O(a/r).
MIN_NECK_RATIO = 1e-4
#: Largest radius ratio of neighbouring spheres; beyond it the graded mesh of the larger sphere spans too many decades
#: (1e6 converges; 1e9 returned an unconverged K 700x too large).
MAX_RADIUS_RATIO = 1e6


@dataclass(frozen=True)
class SizeField:
    """Element-size law: ``min(h_max, h_min + grading * d)`` with ``d`` the distance to the nearest re-entrant
    corner and ``h_min = h_min_fraction * a``; ``uniform`` replaces it by one constant size (for convergence studies
    only: it leaves the corner singularity unresolved). Inside a neck thinner than ``grading * a`` the size is at most
    the neck height over ``neck_cells_per_height`` (0.25: four heights).

    Parameters
    ----------
    grading : float
        Growth of the element size per distance to the nearest corner, ``0 < grading <= 1`` (dimensionless).
    h_min_fraction : float
        The innermost size ``h_min`` over the neck radius ``a`` (dimensionless).
    neck_cells_per_height : float
        Cells per neck height inside a thin neck: the size there is at most the height over this (0.25: four
        heights).
    uniform : float or None
        One constant element size (the body's length unit, e.g. the sphere radius 1) instead of the graded law;
        None: graded.

    Raises
    ------
    ValueError
        ``grading`` outside ``(0, 1]`` or ``uniform`` not finite and > 0.
    """

    grading: float = DEFAULT_GRADING
    h_min_fraction: float = 1e-6
    neck_cells_per_height: float = 0.25
    uniform: float | None = None

    def __post_init__(self):
        if not (np.isfinite(self.grading) and 0.0 < self.grading <= 1.0):
            raise ValueError(f"grading = {self.grading!r}: valid range 0 < grading <= 1")
        if self.uniform is not None and not (np.isfinite(self.uniform) and self.uniform > 0.0):
            raise ValueError(f"uniform = {self.uniform!r}: must be finite and > 0")


@contextlib.contextmanager
def gmsh_session():
    """Initialise gmsh quietly and single-threaded, yield the module, always finalise it.

    gmsh is one global, thread-unsafe state per process; this refuses to nest, so a session never inherits another
    caller's model. Run parallel meshing in separate processes.
    """
    import gmsh

    if gmsh.isInitialized():
        raise RuntimeError("gmsh is already initialised in this process; meshes must be built one at a time")
    with signal_guard.kept():  # gmsh resets the process's signal handlers (faulthandler's among them)
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.option.setNumber("General.NumThreads", 1)
        gmsh.option.setNumber("Mesh.MaxNumThreads2D", 1)
        yield gmsh
    finally:
        with signal_guard.kept():
            gmsh.finalize()


@dataclass(frozen=True)
class ProfileMesh:
    """A meridian-plane mesh of an axisymmetric body.

    mesh: ``skfem.MeshTri1`` with the named boundaries listed in the module docstring.
    arcs: ``{boundary name: (z_centre, radius)}`` for every spherical surface, so that higher-order geometry can
    place boundary nodes exactly on the circle.
    corners: ``(m, 2)`` array of the re-entrant corner points ``(a, z)``.
    volume: exact volume of the body of revolution (for conservation checks).
    h_min: shortest mesh edge; z_top: axial position of the ``top`` disk.

    Parameters
    ----------
    mesh : skfem.MeshTri1
        The triangle mesh of the meridian half-plane, ``(x, z)``, with the named boundaries of the module docstring.
    arcs : dict
        ``{boundary name: (z_centre, radius)}`` of every spherical surface (the body's length unit).
    corners : numpy.ndarray
        ``(m, 2)`` the re-entrant corner points ``(a, z)``.
    volume : float
        Exact volume of the body of revolution (length unit cubed).
    h_min : float
        Shortest mesh edge (length unit).
    z_top : float
        Axial position of the ``top`` disk (length unit).
    """

    mesh: object
    arcs: dict
    corners: np.ndarray
    volume: float
    h_min: float
    z_top: float


# ---------------------------------------------------------------------------------------------------------------
# Profiles: the outer boundary as a list of segments from the bottom disk's rim to the top disk's rim.
# A segment is ("arc", end_point, z_centre, radius, name) or ("line", end_point, name).
# ---------------------------------------------------------------------------------------------------------------


def _segment_volume(p, q, seg) -> float:
    """Volume of revolution swept between the axis and one outer segment from ``p`` to ``q`` (``q`` above ``p``)."""
    if seg[0] == "line":
        return math.pi * p[0] ** 2 * (q[1] - p[1])
    zc, rad = seg[2], seg[3]
    z0, z1 = p[1] - zc, q[1] - zc
    return math.pi * (rad**2 * (z1 - z0) - (z1**3 - z0**3) / 3.0)


def _sphere_segments(k, r, zc, z_lo, z_hi, x_hi):
    """Arc(s) of sphere k from height ``z_lo`` to ``z_hi`` (radius ``x_hi`` there); split at the equator if crossed."""
    name = f"sphere{k}"
    segs = []
    if z_lo < zc < z_hi:
        segs.append(("arc", (r, zc), zc, r, name))
    segs.append(("arc", (x_hi, z_hi), zc, r, name))
    return segs


def _check_arc(k, r, z_lo, z_hi):
    if not z_hi - z_lo > 1e-9 * r:
        raise ValueError(f"sphere {k} (radius {r:.6g}) is consumed by its necks: nothing of its surface remains")


def semisphere_profile(a_over_r: float, r: float = 1.0, neck: str = "cylinder"):
    """Outer boundary, corners and neck height of the semisphere with a neck (Rojek 2022, Fig. 12, eqs. 19-20).

    ``neck = "cylinder"`` (default): ``h_n / 2 = h_c - h/2`` with ``h = 2 phi(h_c)`` (volume conservation)
    simplifies to ``h_c (3r - h_c) / (3 (2r - h_c))``, free of cancellation for small necks. ``neck = "union"``: the
    half body of the union of spheres, the sphere up to its cap base, whose disk of radius ``a`` is the end disk
    (no neck cylinder; the corner is where that disk meets the sphere).

    Parameters
    ----------
    a_over_r : float
        Neck radius over sphere radius, ``MIN_NECK_RATIO <= a_over_r < 1``.
    r : float
        Sphere radius (any length unit, e.g. m; > 0).
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (with Rojek's half neck) or ``"union"`` (the
        sphere up to its cap base).

    Returns
    -------
    tuple
        ``(start, segments, corners, necks)``: the bottom rim ``(r, 0)``, the outer segments (a segment is
        ``("arc", end, z_centre, radius, name)`` or ``("line", end, name)``), the ``(1, 2)`` corner array and the
        necks as ``(a, z_low, z_high)`` (none for the union); lengths in the unit of ``r``.

    Raises
    ------
    ValueError
        ``a_over_r`` or ``r`` out of range, or ``neck`` not one of :data:`fem_neck.law.NECKS`.
    """
    check_neck(neck)
    r = float(check_positive("r", r))
    a = float(check_positive("a_over_r", a_over_r, upper=1.0, upper_name="the neck reaches the sphere radius")) * r
    if not MIN_NECK_RATIO * r <= a < r * (1.0 - 1e-9):
        raise ValueError(f"a_over_r = {a / r:.9g}: valid range {MIN_NECK_RATIO:g} <= a_over_r < 1 (a thinner neck "
                         "cannot be meshed; at 1 the sphere surface vanishes)")
    h_c = float(cap_height(r, a))
    z_i = math.sqrt((r - a) * (r + a))
    if neck == "union":
        return (r, 0.0), [("arc", (a, z_i), 0.0, r, "sphere0")], np.array([[a, z_i]]), []
    half_neck = h_c * (3.0 * r - h_c) / (3.0 * (2.0 * r - h_c))
    segments = [
        ("arc", (a, z_i), 0.0, r, "sphere0"),
        ("line", (a, z_i + half_neck), "neck0"),
    ]
    return (r, 0.0), segments, np.array([[a, z_i]]), [(a, z_i, z_i + half_neck)]


def chain_profile(radii, overlaps):
    """Outer boundary of a collinear chain of spheres (centres on the z axis, the first at ``z = 0``).

    Neck k joins spheres k and k+1: radius ``a_k`` and length ``h_n`` from the volume-conserving model (Rojek 2022,
    eqs. 21-33). The end spheres are cut at their outer equatorial planes.

    Parameters
    ----------
    radii : array_like
        The spheres' radii (any length unit, e.g. m; > 0), at least 2, neighbours within :data:`MAX_RADIUS_RATIO`.
    overlaps : array_like
        The overlap ``h`` of each neighbouring pair (same unit), one per bond.

    Returns
    -------
    tuple
        ``(start, segments, corners, necks)``: the bottom rim, the outer segments, the ``(m, 2)`` corner points
        and the necks as ``(a, z_low, z_high)``; lengths in the unit of the radii.

    Raises
    ------
    ValueError
        Bad radii or overlaps: fewer than 2 spheres, a radius ratio out of range, a neck too thin to mesh or
        without length, a sphere consumed by its necks.
    """
    radii = np.atleast_1d(check_positive("radii", radii)).astype(float)
    overlaps = np.atleast_1d(np.asarray(overlaps, dtype=float))
    if radii.ndim != 1 or radii.size < 2:
        raise ValueError(f"radii: need at least 2 spheres, got {radii.size}")
    check_radius_ratio(radii)
    if overlaps.shape != (radii.size - 1,):
        raise ValueError(f"overlaps: need {radii.size - 1} values (one per bond), got {overlaps.size}")
    geos = [_bond_geometry(radii, overlaps, k) for k in range(overlaps.size)]
    centres = np.concatenate(([0.0], np.cumsum([float(g.d) for g in geos])))
    segments, corners, necks = [], [], []
    z_lo = 0.0
    for k, r in enumerate(radii):
        zc = centres[k]
        if k < len(geos):
            a = float(geos[k].a)
            if a < MIN_NECK_RATIO * min(r, radii[k + 1]):
                raise ValueError(f"overlaps[{k}] = {overlaps[k]:.9g}: neck radius {a:.6g} is below {MIN_NECK_RATIO:g} "
                                 "of the smaller radius, too thin to mesh (K is the constriction limit there)")
            z_hi, x_hi = zc + float(geos[k].z_i), a
        else:
            z_hi, x_hi = zc, r
        _check_arc(k, r, z_lo, z_hi)
        segments += _sphere_segments(k, r, zc, z_lo, z_hi, x_hi)
        if k < len(geos):
            z_top_neck = centres[k + 1] - float(geos[k].z_j)
            if not z_top_neck > z_hi:
                raise ValueError(f"overlaps[{k}] = {overlaps[k]:.9g}: the neck has no length")
            segments.append(("line", (a, z_top_neck), f"neck{k}"))
            corners += [(a, z_hi), (a, z_top_neck)]
            necks.append((a, z_hi, z_top_neck))
            z_lo = z_top_neck
    return (radii[0], 0.0), segments, np.array(corners), necks


def check_radius_ratio(radii, names=None) -> None:
    """Neighbouring radii at most :data:`MAX_RADIUS_RATIO` apart (``ValueError`` naming the pair otherwise).

    Parameters
    ----------
    radii : sequence of float
        The radii in chain order (any length unit).
    names : tuple of (str, str) or None
        The names the message gives the pair (a two-sphere call); None: ``radii[k]`` and ``radii[k + 1]``.

    Raises
    ------
    ValueError
        A neighbouring ratio lies outside ``[1/MAX_RADIUS_RATIO, MAX_RADIUS_RATIO]``.
    """
    for k in range(len(radii) - 1):
        r_i, r_j = float(radii[k]), float(radii[k + 1])
        if not (1.0 / MAX_RADIUS_RATIO <= r_j / r_i <= MAX_RADIUS_RATIO):
            name_i, name_j = names or (f"radii[{k}]", f"radii[{k + 1}]")
            raise ValueError(f"{name_j} / {name_i} = {r_j / r_i:.3g}: valid range {1 / MAX_RADIUS_RATIO:g} to "
                             f"{MAX_RADIUS_RATIO:g} for the FE mesh")


def _bond_geometry(radii, overlaps, k):
    """The neck of bond ``k``; a bad overlap is reported as ``overlaps[k]`` with the bond's valid range."""
    try:
        return neck_geometry(radii[k], radii[k + 1], overlaps[k])
    except ValueError as exc:
        reason = str(exc).split(": ", 1)[-1]
        raise ValueError(f"overlaps[{k}] = {overlaps[k]:.9g} (radii {radii[k]:.6g}, {radii[k + 1]:.6g}): "
                         f"{reason.replace('0 < h', '0 < overlap')}") from None


# ---------------------------------------------------------------------------------------------------------------
# gmsh
# ---------------------------------------------------------------------------------------------------------------


def _is_corner(point, corners) -> bool:
    return bool(np.any(np.all(np.isclose(corners, point, rtol=0.0, atol=1e-12 * max(1.0, abs(point[1]))), axis=1)))


def _build_mesh(start, segments, corners, necks, sizes: SizeField):
    """Mesh the profile in gmsh and return (skfem MeshTri1 with boundaries, volume, z_top)."""
    import skfem

    grading = sizes.grading
    points = [start] + [seg[1] for seg in segments]
    z_top = points[-1][1]
    volume = sum(_segment_volume(points[i], points[i + 1], segments[i]) for i in range(len(segments)))
    scale = max(p[0] for p in points)
    a_min = float(np.min(corners[:, 0]))
    h_min = sizes.h_min_fraction * a_min if sizes.uniform is None else sizes.uniform
    h_max = 0.5 * scale
    # gmsh works in units of the smallest neck radius: OpenCASCADE cannot make edges shorter than ~1e-7 units, and
    # the half neck of a/r = 1e-4 is 2.5e-9 r high but 2.5e-5 a.
    unit = a_min
    try:
        with gmsh_session() as gmsh:
            gmsh.model.add("profile")
            occ = gmsh.model.occ
            axis_bottom = occ.addPoint(0.0, 0.0, 0.0)
            p_tags = [occ.addPoint(x / unit, z / unit, 0.0) for x, z in points]
            axis_top = occ.addPoint(0.0, z_top / unit, 0.0)
            centre_tags = {}
            curves = {"bottom": [occ.addLine(axis_bottom, p_tags[0])]}
            for i, seg in enumerate(segments):
                if seg[0] == "arc":
                    zc = seg[2]
                    if zc not in centre_tags:
                        centre_tags[zc] = axis_bottom if zc == 0.0 else occ.addPoint(0.0, zc / unit, 0.0)
                    tag = occ.addCircleArc(p_tags[i], centre_tags[zc], p_tags[i + 1])
                else:
                    tag = occ.addLine(p_tags[i], p_tags[i + 1])
                curves.setdefault(seg[-1], []).append(tag)
            curves["top"] = [occ.addLine(p_tags[-1], axis_top)]
            curves["axis"] = [occ.addLine(axis_top, axis_bottom)]
            loop_tags = curves["bottom"] + [t for seg_tags in _in_order(curves, segments) for t in seg_tags]
            loop_tags += curves["top"] + curves["axis"]
            loop = occ.addCurveLoop(loop_tags)
            surface = occ.addPlaneSurface([loop])
            occ.synchronize()

            # Distance + MathEval + Box combined by a Min field (a MathEval that references another MathEval
            # deadlocks gmsh 4.15, and numbers are formatted explicitly: numpy reprs are not gmsh syntax).
            field = gmsh.model.mesh.field
            corner_tags = [tag for tag, pt in zip(p_tags, points) if _is_corner(pt, corners)]
            if len(corner_tags) != len(corners):
                raise ValueError("corners: every corner must be an end point of the profile's segments")
            dist = field.add("Distance")
            field.setNumbers(dist, "PointsList", corner_tags)
            graded = field.add("MathEval")
            law = f"min({h_max / unit:.17g}, {h_min / unit:.17g} + {float(grading):.17g}*F{dist})"
            field.setString(graded, "F", law if sizes.uniform is None else f"{h_min / unit:.17g} + 0*F{dist}")
            fields = [graded]
            for a, z0, z1 in necks:
                cell = (z1 - z0) / sizes.neck_cells_per_height
                if cell < grading * a:
                    box = field.add("Box")
                    for key, val in (("VIn", cell), ("VOut", 1e22), ("XMin", -a), ("XMax", a * (1 + 1e-9)),
                                     ("YMin", z0 - 1e-9 * a), ("YMax", z1 + 1e-9 * a)):
                        field.setNumber(box, key, float(val) / (1.0 if key == "VOut" else unit))
                    fields.append(box)
            size = field.add("Min")
            field.setNumbers(size, "FieldsList", fields)
            field.setAsBackgroundMesh(size)
            for opt, val in (("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeFromPoints", 0),
                             ("Mesh.MeshSizeFromCurvature", 0), ("Mesh.Algorithm", 6),
                             ("Mesh.MeshSizeMin", h_min / unit), ("Mesh.MeshSizeMax", h_max / unit)):
                gmsh.option.setNumber(opt, val)
            gmsh.model.mesh.generate(2)

            node_tags, coords, _ = gmsh.model.mesh.getNodes()
            _, tri_nodes = gmsh.model.mesh.getElementsByType(2, surface)
            line_nodes = {name: np.concatenate([gmsh.model.mesh.getElementsByType(1, t)[1] for t in tags])
                          for name, tags in curves.items()}
    except ValueError:
        raise
    except Exception as exc:  # gmsh raises a bare Exception with its own message
        raise RuntimeError(f"gmsh failed to mesh the profile: {exc}") from exc

    # gmsh node tags -> contiguous indices over the nodes used by triangles
    xy = coords.reshape(-1, 3)[:, :2] * unit
    tag_to_row = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
    tag_to_row[node_tags.astype(np.int64)] = np.arange(node_tags.size)
    tri = tag_to_row[tri_nodes.astype(np.int64)].reshape(-1, 3)
    used, tri = np.unique(tri, return_inverse=True)
    tri = tri.reshape(-1, 3)
    p = xy[used].T.copy()
    row_to_new = np.full(node_tags.size, -1, dtype=np.int64)
    row_to_new[used] = np.arange(used.size)
    # orient counter-clockwise
    e1 = p[:, tri[:, 1]] - p[:, tri[:, 0]]
    e2 = p[:, tri[:, 2]] - p[:, tri[:, 0]]
    flip = e1[0] * e2[1] - e1[1] * e2[0] < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    mesh = skfem.MeshTri1(np.ascontiguousarray(p), np.ascontiguousarray(tri.T, dtype=np.int32))

    nv = p.shape[1]
    facets = mesh.facets.astype(np.int64)
    facet_key = np.minimum(facets[0], facets[1]) * nv + np.maximum(facets[0], facets[1])
    order = np.argsort(facet_key)
    boundaries = {}
    for name, nodes in line_nodes.items():
        ends = row_to_new[tag_to_row[nodes.astype(np.int64)]].reshape(-1, 2)
        key = np.minimum(ends[:, 0], ends[:, 1]) * nv + np.maximum(ends[:, 0], ends[:, 1])
        pos = np.searchsorted(facet_key, key, sorter=order)
        boundaries[name] = np.sort(order[pos]).astype(np.int32)
    boundaries["insulated"] = np.sort(np.concatenate(
        [np.empty(0, np.int32)] + [v for k, v in boundaries.items() if k.startswith(("sphere", "neck"))]
    )).astype(np.int32)
    mesh = mesh.with_boundaries(boundaries)
    return mesh, volume, z_top


def _in_order(curves, segments):
    seen = []
    for seg in segments:
        if seg[-1] not in seen:
            seen.append(seg[-1])
    return [curves[name] for name in seen]


def profile_mesh(start, segments, corners, necks=(), sizes: SizeField | None = None) -> ProfileMesh:
    """Mesh any axisymmetric profile: the ``bottom`` line from the axis to ``start``, then ``segments`` (each
    ``("line", end, name)`` or ``("arc", end, z_centre, radius, name)``, counter-clockwise, ending at the top rim),
    then the ``top`` line back to the axis and the ``axis``. ``corners`` ((m, 2), each a segment end point) are
    where the size is graded; ``necks`` are ``(a, z_low, z_high)`` cylinders kept isotropic when thin.

    Parameters
    ----------
    start : tuple of float
        The bottom rim ``(x, z)``, where the first segment starts.
    segments : list of tuple
        The outer boundary, counter-clockwise from ``start`` to the top rim.
    corners : array_like
        ``(m, 2)`` the re-entrant corner points.
    necks : sequence of tuple
        The neck cylinders ``(a, z_low, z_high)``.
    sizes : SizeField or None
        The element-size law; None: ``SizeField()``.

    Returns
    -------
    ProfileMesh
        The mesh with its arcs, corners, exact volume, shortest edge and top height.
    """
    sizes = sizes or SizeField()
    corners = np.atleast_2d(np.asarray(corners, dtype=float))
    mesh, volume, z_top = _build_mesh(start, segments, corners, necks, sizes)
    arcs = {seg[-1]: (seg[2], seg[3]) for seg in segments if seg[0] == "arc"}
    edges = mesh.p[:, mesh.facets]
    h_min = float(np.min(np.hypot(*(edges[:, 1] - edges[:, 0]))))
    return ProfileMesh(mesh=mesh, arcs=arcs, corners=corners, volume=volume, h_min=h_min, z_top=z_top)


def curved_mesh(profile: ProfileMesh):
    """The quadratic (isoparametric) version of ``profile.mesh``: a ``skfem.MeshTri2`` whose edge midpoints on the
    spherical surfaces lie exactly on their circles, so the elements follow the curved boundary.

    Straight-sided triangles inscribe the sphere and lose an :math:`O(h^2)` sliver of volume per edge; the quadratic
    boundary cuts that to :math:`O(h^4)`. Named boundaries carry over (same facets).

    Parameters
    ----------
    profile : ProfileMesh
        The linear mesh and its arcs.

    Returns
    -------
    skfem.MeshTri2
        The quadratic mesh.
    """
    import skfem

    base = profile.mesh
    quadratic = skfem.MeshTri2.from_mesh(base)
    doflocs = quadratic.doflocs.copy()
    for name, (z_centre, radius) in profile.arcs.items():
        dofs = quadratic.dofs.get_facet_dofs(base.boundaries[name]).flatten()
        rel = doflocs[:, dofs] - np.array([[0.0], [z_centre]])
        doflocs[:, dofs] = rel * (radius / np.hypot(rel[0], rel[1])) + np.array([[0.0], [z_centre]])
    return skfem.MeshTri2(doflocs, base.t, _boundaries=base.boundaries)


def semisphere_mesh(a_over_r: float, r: float = 1.0, grading: float = DEFAULT_GRADING,
                    sizes: SizeField | None = None, neck: str = "cylinder") -> ProfileMesh:
    """Graded mesh of the semisphere with a neck (Rojek 2022, Fig. 12); see :func:`semisphere_profile`.

    ``bottom`` is the equatorial disk (``z = 0``), ``top`` the neck's end disk (:math:`z = z_i + h_n/2`; ``z_i`` for
    ``neck = "union"``).

    Parameters
    ----------
    a_over_r : float
        Neck radius over sphere radius, ``MIN_NECK_RATIO <= a_over_r < 1``.
    r : float
        Sphere radius (any length unit, e.g. m; > 0).
    grading : float
        The size field's grading (:class:`SizeField`), read where ``sizes`` is None.
    sizes : SizeField or None
        The element-size law; None: ``SizeField(grading=grading)``.
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"`` (with Rojek's half neck) or ``"union"`` (the
        sphere up to its cap base).

    Returns
    -------
    ProfileMesh
        The graded mesh.
    """
    start, segments, corners, necks = semisphere_profile(a_over_r, r, neck)
    return profile_mesh(start, segments, corners, necks, sizes or SizeField(grading=grading))


def chain_mesh(radii, overlaps, grading: float = DEFAULT_GRADING, sizes: SizeField | None = None) -> ProfileMesh:
    """Graded mesh of a collinear chain (``bottom``: equator of the first sphere, ``top``: of the last).

    Parameters
    ----------
    radii : array_like
        The spheres' radii (any length unit; > 0), at least 2 (:func:`chain_profile`).
    overlaps : array_like
        The overlap of each neighbouring pair (same unit).
    grading : float
        The size field's grading (:class:`SizeField`), read where ``sizes`` is None.
    sizes : SizeField or None
        The element-size law; None: ``SizeField(grading=grading)``.

    Returns
    -------
    ProfileMesh
        The graded mesh.
    """
    start, segments, corners, necks = chain_profile(radii, overlaps)
    return profile_mesh(start, segments, corners, necks, sizes or SizeField(grading=grading))
