"""The mesh of a periodic cell's computational cell (:mod:`fem_neck.lattice`): the particle images and necks that
reach it, the mirror planes that bound it, and its curved tetrahedra graded toward every neck circle."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fem_neck.geometry.union import lens
from fem_neck.lattice.cells import PeriodicCell, mirror_symmetry

LC_INTEGRATION_PRECISION = 1e-6  # relative precision of gmsh's integral of 1 / size along a curve (build_cell_mesh)


@dataclass
class CellMesh:
    r"""The meshed computational cell (:func:`build_cell_mesh`). Lengths in units of the largest radius ``unit``.

    Parameters
    ----------
    curved : fem_neck.curved.CurvedMesh
        The mesh, exact geometry.
    hot, cold : numpy.ndarray
        Indices into ``curved.faces`` of its faces on ``z = 0`` and on ``z = height``.
    height : float
        Height of the cell, the half period along z (in units of ``unit``).
    area : float
        Cross-section of the cell normal to z (in units of ``unit`` squared).
    wedge : float
        The fraction of the half-period box meshed: 1, 1/2 (the wedge :math:`y \le x`) or 1/4 (with also
        :math:`x + y \le P/2`).
    volume_exact : float
        The exact volume of the solid in the cell (in units of ``unit`` cubed).
    volume_cad : float
        The OCC volume of the built solid (in units of ``unit`` cubed).
    unit : float
        The largest particle radius, m: the length unit of the mesh.
    neck_a : numpy.ndarray
        Neck radius of every bond of the local cluster (in units of ``unit``).
    """

    curved: object
    hot: np.ndarray
    cold: np.ndarray
    height: float
    area: float
    wedge: float
    volume_exact: float
    volume_cad: float
    unit: float
    neck_a: np.ndarray = field(repr=False)


def local_cluster(cell: PeriodicCell, box: np.ndarray):
    r"""The particle images whose spheres or necks can reach the box ``[0, box]``, with their bonds, as a
    :class:`fem_neck.cluster.Cluster` (a neck point lies within :math:`\sqrt{2} \, r_{max}` of its nearer centre).

    Parameters
    ----------
    cell : PeriodicCell
        The cell.
    box : numpy.ndarray
        The far corner ``(3,)`` of the box, in the cell's length unit.
    """
    from fem_neck.cluster import Cluster

    r_max = float(cell.radii.max())
    reach = 1.5 * r_max
    x, owner, _ = cell.images(-(reach + 2 * r_max) * np.ones(3), box + reach + 2 * r_max)
    r = cell.radii[owner]
    gap = np.linalg.norm(np.maximum(np.maximum(-x, x - box), 0.0), axis=1)
    near = gap < reach
    d = np.linalg.norm(x[:, None] - x[None], axis=2)
    bonded = (d < r[:, None] + r[None]) & ~np.eye(len(x), dtype=bool)
    keep = near | bonded[:, near].any(axis=1)
    x, r, bonded = x[keep], r[keep], bonded[np.ix_(keep, keep)]
    near = near[keep]
    p, q = np.nonzero(np.triu(bonded, 1))
    use = near[p] | near[q]
    return Cluster(x, r, np.column_stack([p[use], q[use]]))


def _domain(box: np.ndarray, diagonal: bool, anti: bool) -> list:
    """The half-spaces ``n . x <= d`` of the computational cell (the box, or its wedge ``y <= x``, and ``x + y <=
    box_x`` too for face-centred cubic), as ``(n, d)``."""
    planes = [((0, 0, -1.0), 0.0), ((0, 0, 1.0), box[2]), ((0, -1.0, 0), 0.0)]
    if diagonal:
        planes.append(((-1.0, 1.0, 0), 0.0))
        planes.append(((1.0, 1.0, 0), box[0]) if anti else ((1.0, 0, 0), box[0]))
    else:
        planes += [((-1.0, 0, 0), 0.0), ((1.0, 0, 0), box[0]), ((0, 1.0, 0), box[1])]
    return [(np.asarray(n) / np.linalg.norm(n), d / np.linalg.norm(n)) for n, d in planes]


def _inside(halfspaces: list, points: np.ndarray, tol: float) -> np.ndarray:
    """Whether the ``points`` lie in the cell (to ``tol``)."""
    keep = np.ones(len(points), dtype=bool)
    for n, d in halfspaces:
        keep &= points @ n - d <= tol
    return keep


def _reaches(halfspaces: list, points: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """Whether the balls (or, with ``points (k, 2, 3)``, capsules) of ``radius`` can meet the cell: no half-space
    leaves them wholly outside (a necessary condition; enough to leave out the far images)."""
    keep = np.ones(len(radius), dtype=bool)
    for n, d in halfspaces:
        near = points @ n
        if near.ndim > 1:
            near = near.min(axis=1)
        keep &= near - d < radius
    return keep


@dataclass(frozen=True)
class CellFrame:
    r"""What the mesh of a cell is built from, before any meshing. Lengths in units of ``unit``.

    Parameters
    ----------
    scaled : PeriodicCell
        The cell scaled to its largest radius.
    unit : float
        The largest particle radius, m.
    box : numpy.ndarray
        The half period ``(3,)``.
    local : fem_neck.cluster.Cluster
        The particle images that reach the computational cell, with their bonds (:func:`local_cluster`).
    geo : fem_neck.geometry.NeckGeometry
        The necks of those bonds.
    e : numpy.ndarray
        Unit directions ``(bonds, 3)`` of the bonds.
    halfspaces : list of tuple
        ``(n, d)`` of every half-space ``n . x <= d`` bounding the computational cell.
    diagonal : bool
        Whether the cell is the wedge ``y <= x`` of the box (symmetry under ``x <-> y``).
    anti : bool
        Whether it is also cut by :math:`x + y \le P/2` (the face-centred cubic symmetry).
    fraction : float
        The fraction of the box the cell is (1, 1/2 or 1/4).
    solid_volume : float
        The exact volume of the solid in the cell.
    """

    scaled: PeriodicCell
    unit: float
    box: np.ndarray
    local: object
    geo: object
    e: np.ndarray
    halfspaces: list
    diagonal: bool
    anti: bool
    fraction: float
    solid_volume: float


def cell_frame(cell: PeriodicCell, method: str = "newton") -> CellFrame:
    """The :class:`CellFrame` of ``cell``; ``ValueError`` unless it is mirror-symmetric (:mod:`fem_neck.lattice`).

    Parameters
    ----------
    cell : PeriodicCell
        The cell, lengths in m.
    method : str
        Neck model of the pair reading (:func:`fem_neck.geometry.neck_radius`).
    """
    mirror, diagonal, anti = mirror_symmetry(cell)
    if not mirror:
        raise ValueError(f"{cell.name}: the packing is not mirror-symmetric about x = 0, y = 0 and z = 0 (modulo the "
                         "period); this FE solves the mirror cell [0, P/2]^3 and needs those mirror planes")
    unit = float(cell.radii.max())
    scaled = PeriodicCell(cell.centres / unit, cell.radii / unit, cell.period / unit, cell.name, cell.neck)
    box = scaled.period / 2.0
    local = local_cluster(scaled, box)
    fraction = 0.25 if anti else 0.5 if diagonal else 1.0
    geo = union_necks(local) if cell.neck == "union" else local.necks(method)
    return CellFrame(scaled, unit, box, local, geo, local.directions(), _domain(box, diagonal, anti),
                     diagonal, anti, fraction, float(scaled.phi * np.prod(box) * fraction))


@dataclass(frozen=True)
class UnionNecks:
    """The necks of the union reading, per bond of a :class:`fem_neck.cluster.Cluster` (the fields the meshing
    reads of a pair neck's :class:`fem_neck.geometry.NeckGeometry`).

    Parameters
    ----------
    a : numpy.ndarray
        Radius of the circle where the two spheres meet (:func:`fem_neck.geometry.union.lens`), in the cluster's
        length unit.
    z_i : numpy.ndarray
        Distance from centre ``i`` along the bond to the bond's radical plane, which holds the circle.
    h_n : numpy.ndarray
        Zeros: a neck without length.
    """

    a: np.ndarray
    z_i: np.ndarray
    h_n: np.ndarray


def union_necks(local) -> UnionNecks:
    """The :class:`UnionNecks` of the bonds of a cluster.

    Parameters
    ----------
    local : fem_neck.cluster.Cluster
        Spheres and their bonds (overlapping pairs).
    """
    i, j = local.bonds.T
    neck = lens(local.radii[i], local.radii[j], np.linalg.norm(local.centres[j] - local.centres[i], axis=1))
    return UnionNecks(neck.a, neck.l_i, np.zeros_like(neck.a))


def build_cell_mesh(cell: PeriodicCell, size_neck: float, size_far: float, grading: float,
                    curvature: int = 12, neck_cells: float = 1.0, method: str = "newton") -> CellMesh:
    r"""Mesh the computational cell (:mod:`fem_neck.lattice`): the union of the spheres and necks that reach it, cut to
    the cell, graded toward every neck circle (``size_neck a`` at the circles, growing by ``grading`` per unit distance
    up to ``size_far r``; :func:`fem_neck.cluster.neck_size_fields`), its boundary classified onto the exact spheres,
    cylinders and planes (:mod:`fem_neck.curved`). Lengths are scaled to the largest radius.

    Parameters
    ----------
    cell : PeriodicCell
        The cell (validated by :func:`~fem_neck.lattice.cells.check_cell`).
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless).
    size_far : float
        Largest element size over the particle radius (dimensionless).
    grading : float
        Growth of the element size per unit distance from a neck circle (dimensionless).
    curvature : int
        gmsh's elements per :math:`2 \pi` of surface curvature.
    neck_cells : float
        Elements along a neck's length at least.
    method : str
        Neck model of the pair reading (:func:`fem_neck.geometry.neck_radius`).
    """
    from fem_neck import curved
    from fem_neck.cluster import mesh_tetrahedra, neck_size_fields, tetrahedra
    from fem_neck.shapes import gmsh_session

    frame = cell_frame(cell, method)
    scaled, unit, box, local, geo, e, halfspaces = (frame.scaled, frame.unit, frame.box, frame.local, frame.geo,
                                                    frame.e, frame.halfspaces)
    diagonal, anti = frame.diagonal, frame.anti
    bi, bj = local.bonds.T
    tol = 1e-6
    if scaled.neck == "union":
        # the spheres centred in the cell: every other one is covered there by its mirror image (the cell is bounded
        # by mirror planes of the packing, and a ball reflected across one of them covers the ball's part on the
        # cell's side), so no sphere meets a cell face in a circle of its own
        use_sphere = _inside(halfspaces, local.centres, tol)
        use_neck = np.zeros(len(bi), dtype=bool)
        surfaces = [curved.sphere(c, r) for c, r in zip(local.centres[use_sphere], local.radii[use_sphere])]
    else:
        start = local.centres[bi] + (0.75 * geo.z_i)[:, None] * e
        end = start + (geo.h_n + 0.25 * (geo.z_i + geo.z_j))[:, None] * e
        use_sphere = _reaches(halfspaces, local.centres, local.radii)
        use_neck = _reaches(halfspaces, np.stack([start, end], axis=1), geo.a)
        surfaces = [curved.sphere(c, r) for c, r in zip(local.centres, local.radii)]
        surfaces += [curved.cylinder(c, d, a) for c, d, a in zip(local.centres[bi], e, geo.a)]
    surfaces += [curved.plane(n, d) for n, d in halfspaces]
    surfaces = curved.distinct(surfaces, tol)
    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        solids = [(3, occ.addSphere(*local.centres[k], local.radii[k])) for k in np.flatnonzero(use_sphere)]
        solids += [(3, occ.addCylinder(*start[b], *(end[b] - start[b]), geo.a[b])) for b in np.flatnonzero(use_neck)]
        union, _ = occ.fuse(solids[:1], solids[1:]) if len(solids) > 1 else (solids, None)
        if diagonal:  # the prism 0 <= y <= x <= P_x/2 (and x + y <= P_x/2), 0 <= z <= P_z/2
            apex = (0.5 * box[0], 0.5 * box[1]) if anti else (box[0], box[1])
            corners = [occ.addPoint(0, 0, 0), occ.addPoint(box[0], 0, 0), occ.addPoint(*apex, 0)]
            lines = [occ.addLine(corners[k], corners[(k + 1) % 3]) for k in range(3)]
            face = occ.addPlaneSurface([occ.addCurveLoop(lines)])
            domain = [d for d in occ.extrude([(2, face)], 0, 0, box[2]) if d[0] == 3]
        else:
            domain = [(3, occ.addBox(0, 0, 0, *box))]
        volume, _ = occ.intersect(union, domain)
        occ.synchronize()
        volume_cad = sum(occ.getMass(3, tag) for _, tag in volume)
        boundary = [tag for _, tag in gmsh.model.getBoundary(volume, combined=False, oriented=False)]
        neck_size_fields(gmsh, local, geo, boundary, size_neck, size_far, neck_cells, tol, every_bond=False,
                         grading=grading)
        # the size integrated along each curve to 1e-6 rather than gmsh's 1e-9: the curves' nodes move by ~1e-6 of
        # an element, and their meshing takes a tenth of the time (it was half of gmsh's on BCC h/r = 0.02)
        gmsh.option.setNumber("Mesh.LcIntegrationPrecision", LC_INTEGRATION_PRECISION)
        mesh_tetrahedra(gmsh, curvature, size_far)
        pieces = [tetrahedra(gmsh, tag) for _, tag in volume]
        points, index = pieces[0][0], pieces[0][2]
        tets = np.vstack([piece[1] for piece in pieces])
        triangles, owner = [], []
        for tag in sorted(set(abs(t) for t in boundary)):
            _, _, nodes = gmsh.model.mesh.getElements(2, tag)
            tri = index[np.asarray(nodes[0], dtype=np.int64)].reshape(-1, 3)
            xyz = points[np.unique(tri)]
            dist = np.array([s.distance(xyz).max() for s in surfaces])
            best = int(np.argmin(dist))
            if dist[best] > 10 * tol:
                raise RuntimeError(f"{cell.name}: boundary surface {tag} lies on none of the spheres, necks and cell "
                                   f"planes (closest {dist[best]:.1e} away)")
            triangles.append(tri)
            owner.append(np.full(len(tri), best))
    triangles, owner = np.vstack(triangles), np.concatenate(owner)
    tets = _conducting(points, tets, box[2], tol)
    used = np.unique(tets)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    inside = np.all(remap[triangles] >= 0, axis=1)
    mesh = curved.build(points[used], remap[tets], remap[triangles[inside]], owner[inside], surfaces, 10 * tol)
    fz = mesh.points[mesh.faces[mesh.boundary_faces], 2]
    hot = mesh.boundary_faces[np.all(np.abs(fz) < tol, axis=1)]
    cold = mesh.boundary_faces[np.all(np.abs(fz - box[2]) < tol, axis=1)]
    area = box[0] * box[1] * frame.fraction
    return CellMesh(mesh, hot, cold, float(box[2]), float(area), frame.fraction, frame.solid_volume,
                    float(volume_cad), unit, np.asarray(geo.a))


def _conducting(points: np.ndarray, tets: np.ndarray, height: float, tol: float) -> np.ndarray:
    """The tetrahedra of the pieces of the solid that touch an isothermal face (``z = 0`` or ``z = height``): a
    piece joined to the rest only outside the cell and touching neither carries no heat (its temperature is
    undetermined, its energy zero), so it is left out."""
    import scipy.sparse as sparse
    from scipy.sparse.csgraph import connected_components

    n = len(points)
    rows = np.repeat(tets[:, :1], 3, axis=1).ravel()
    graph = sparse.coo_matrix((np.ones(len(rows)), (rows, tets[:, 1:].ravel())), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    z = points[:, 2]
    touching = np.unique(label[(np.abs(z) < tol) | (np.abs(z - height) < tol)])
    return tets[np.isin(label[tets[:, 0]], touching)]
