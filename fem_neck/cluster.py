r"""3D finite-element conduction through small clusters of sintered spheres (gmsh OCC + scikit-fem tetrahedra).

Geometry (Rojek, Kasztelan & Tharmaraj 2022, Sections 4.3, Fig. 8). Each bonded pair ``(i, j)`` with overlap
:math:`h = r_i + r_j - |c_j - c_i|` gets the volume-conserving cylindrical neck of
:func:`fem_neck.geometry.neck_geometry`: radius ``a``, spanning :math:`c_i + z_i e` to :math:`c_i + (z_i + h_n) e`
along the unit vector ``e`` from ``c_i`` to ``c_j``. The solid is the union of the full spheres and the neck
cylinders.

This *is* the truncated-sphere geometry of the paper: the cap of sphere ``i`` beyond its base plane ``z_i`` lies inside
the neck cylinder (the sphere's cross-section there is narrower than ``a``) or, where it pokes past the cylinder's far
end (unequal radii), inside the truncated sphere ``j``. So no cap has to be cut explicitly, and for necks that do not
touch one another the volume is exactly :math:`\sum \frac{4}{3} \pi r^3` (volume conservation, eq. 22). Each cylinder is
extended by :math:`\delta = z/4` into both spheres so that its side meets each sphere transversally at the neck circle
instead of along a shared edge, which keeps the OCC boolean robust without changing the union.

Boundary conditions that the pipe network represents exactly (chosen here, see :class:`Terminal`):

* ``"plane"`` -- a particle with exactly one bond is cut by the plane through its centre normal to that bond and
  the cut disk is held at a fixed temperature. That half-particle is precisely the body whose conductance defines
  the pipe's half-conductance ``K_i`` (Rojek 2022, Fig. 12, eqs. 36, 43) and the end of the FE pair/chain solves,
  so a DEM particle held at ``T`` with that bond's law is an exact model of this boundary; any difference is the
  law's error, not the boundary's.
* ``"core"`` -- a concentric ball of radius :math:`\rho r` (default :math:`\rho` = ``rho`` = 0.25) is removed and its
  surface held at ``T``: the particle's "centre temperature". Usable for particles with several bonds; it is *not*
  exactly the pipe model's boundary (the half-conductance is defined from the equatorial disk), which the comparison
  quantifies.

Everything else is insulated. The effective conductance is :math:`K = Q / (T_{hot} - T_{cold})` with ``Q`` from the
reaction at the hot Dirichlet dofs. The per-particle mean temperature is the volume average over the particle's own
share of the solid: its truncated sphere plus the part of each neck cylinder next to it whose volume equals its cap's,
so that each particle owns exactly :math:`\frac{4}{3} \pi r^3` (the DEM's mass, :math:`m = \rho \frac{4}{3} \pi r^3`)
less what a terminal cut removes. Elements are assigned by their centroids.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fem_neck.geometry import check_positive, max_overlap, neck_geometry

BC_KINDS = ("plane", "core")
_EXTEND = 0.25  # neck cylinders reach delta = _EXTEND * z into each sphere (hidden inside it)


@dataclass(frozen=True)
class Terminal:
    r"""A particle held at a fixed temperature (module docstring).

    Parameters
    ----------
    particle : int
        Index of the particle in the cluster.
    T : float
        Its temperature, K.
    kind : str
        ``"plane"`` (a one-bond particle cut at its centre plane, the cut disk held at ``T``) or ``"core"`` (a ball
        of radius :math:`\rho r` at the centre removed, its surface held at ``T``).
    rho : float
        Radius of the core ball over the particle radius (dimensionless, ``"core"`` only).
    """

    particle: int
    T: float
    kind: str = "plane"
    rho: float = 0.25


@dataclass(frozen=True)
class Cluster:
    """Spheres joined by sintered necks; ``ValueError`` on inconsistent shapes or indices.

    Parameters
    ----------
    centres : array_like
        Sphere centres ``(n, 3)``, m.
    radii : array_like
        Sphere radii ``(n,)``, m, each finite and > 0.
    bonds : array_like
        Bonded pairs ``(m, 2)`` of distinct particle indices; each pair's overlap sets its neck.
    """

    centres: np.ndarray
    radii: np.ndarray
    bonds: np.ndarray

    def __post_init__(self):
        centres = np.asarray(self.centres, dtype=float).reshape(-1, 3)
        radii = check_positive("radii", np.asarray(self.radii, dtype=float).reshape(-1))
        bonds = np.asarray(self.bonds, dtype=int).reshape(-1, 2)
        if len(radii) != len(centres):
            raise ValueError(f"radii has {len(radii)} entries: must match the {len(centres)} centres")
        if bonds.size and (bonds.min() < 0 or bonds.max() >= len(radii) or np.any(bonds[:, 0] == bonds[:, 1])):
            raise ValueError(f"bonds = {bonds.tolist()}: indices must be distinct and in 0..{len(radii) - 1}")
        object.__setattr__(self, "centres", centres)
        object.__setattr__(self, "radii", radii)
        object.__setattr__(self, "bonds", bonds)

    @property
    def n(self) -> int:
        """Number of particles."""
        return len(self.radii)

    def overlaps(self) -> np.ndarray:
        """Overlap :math:`h = r_i + r_j - d` of every bond (Rojek 2022, eq. 21/44)."""
        i, j = self.bonds.T
        return self.radii[i] + self.radii[j] - np.linalg.norm(self.centres[j] - self.centres[i], axis=1)

    def necks(self, method: str = "newton"):
        """:class:`fem_neck.geometry.NeckGeometry` of every bond (raises ``ValueError`` outside the neck model's
        range).

        Parameters
        ----------
        method : str
            Neck model: ``"newton"`` (volume-conserving, default), ``"first"`` or ``"coble"``
            (:func:`fem_neck.geometry.neck_radius`).
        """
        i, j = self.bonds.T
        return neck_geometry(self.radii[i], self.radii[j], self.overlaps(), method=method)

    def directions(self) -> np.ndarray:
        """Unit vectors ``e`` from ``c_i`` to ``c_j`` of every bond."""
        i, j = self.bonds.T
        v = self.centres[j] - self.centres[i]
        return v / np.linalg.norm(v, axis=1)[:, None]

    def corner_exponent(self, method: str = "newton") -> float:
        r"""The smallest singular exponent of the re-entrant neck edges (each neck meets two spheres, each side with
        :math:`\lambda = \pi / (\pi + \arccos(a / r_k))`, :func:`fem_neck.accuracy.corner_exponent`); 1 without bonds.

        Parameters
        ----------
        method : str
            Neck model (as in :meth:`necks`).
        """
        from fem_neck.accuracy import corner_exponent

        if not len(self.bonds):
            return 1.0
        a = self.necks(method).a
        i, j = self.bonds.T
        return float(min(np.min(corner_exponent(a / self.radii[i])), np.min(corner_exponent(a / self.radii[j]))))

    def degree(self) -> np.ndarray:
        """Coordination number (bonds per particle)."""
        return np.bincount(self.bonds.ravel(), minlength=self.n)

    def validate(self, method: str = "newton", gap: float = 0.0, angle_margin: float = 0.0) -> None:
        r"""Raise ``ValueError`` unless the cluster is a valid union of non-interfering necks.

        Bonded pairs must overlap within the neck model's range; unbonded spheres must stay more than ``gap``
        (m) apart; two neck circles on one sphere (angular radius :math:`\arcsin(a/r)` each) must stay more than
        ``angle_margin`` (radians) apart.

        Parameters
        ----------
        method : str
            Neck model (as in :meth:`necks`).
        gap : float
            Smallest distance between the surfaces of unbonded spheres, m.
        angle_margin : float
            Smallest angle between two neck circles on one sphere, rad.
        """
        h = self.overlaps()
        i, j = self.bonds.T
        for b in range(len(h)):
            if not 0.0 < h[b] <= max_overlap(self.radii[i[b]], self.radii[j[b]]):
                raise ValueError(
                    f"bond {b} ({i[b]}, {j[b]}): overlap h = {h[b]:.6g} outside the neck model's range "
                    f"0 < h <= {max_overlap(self.radii[i[b]], self.radii[j[b]]):.6g}")
        bonded = {tuple(sorted(p)) for p in self.bonds.tolist()}
        dist = np.linalg.norm(self.centres[:, None] - self.centres[None], axis=2)
        space = dist - self.radii[:, None] - self.radii[None]
        for p, q in zip(*np.nonzero(np.triu(space <= gap, 1))):
            if (int(p), int(q)) not in bonded:
                raise ValueError(f"particles {p} and {q} are not bonded but {space[p, q]:.3g} m apart "
                                 f"(must be > {gap:.3g} m)")
        if len(bonded) != len(self.bonds):
            raise ValueError("bonds contain a duplicate pair")
        a = self.necks(method).a
        e = self.directions()
        for k in range(self.n):
            ends = [(b, 1.0) for b in np.flatnonzero(i == k)] + [(b, -1.0) for b in np.flatnonzero(j == k)]
            for x in range(len(ends)):
                for y in range(x + 1, len(ends)):
                    (b1, s1), (b2, s2) = ends[x], ends[y]
                    angle = np.arccos(np.clip(s1 * s2 * e[b1] @ e[b2], -1.0, 1.0))
                    need = np.arcsin(min(a[b1] / self.radii[k], 1.0)) + np.arcsin(min(a[b2] / self.radii[k], 1.0))
                    if angle <= need + angle_margin:
                        raise ValueError(
                            f"particle {k}: necks of bonds {b1} and {b2} touch (angle {np.degrees(angle):.1f} deg "
                            f"<= {np.degrees(need):.1f} deg); the cylindrical-neck model needs separate necks")


@dataclass
class ClusterMesh:
    """A tetrahedral mesh of a cluster with boundaries ``"hot"`` and ``"cold"`` (:func:`build_cluster_mesh`).

    Parameters
    ----------
    cluster : Cluster
        The cluster meshed, m.
    terminals : tuple of Terminal
        Its terminals.
    mesh : skfem.MeshTet or skfem.MeshTet2
        The mesh, m, with boundaries ``"hot"`` and ``"cold"``.
    particle : numpy.ndarray
        The owning particle of every element (at its centroid).
    volume_exact : float
        The solid's exact volume, m^3.
    volume_cad : float
        The OCC volume of the built solid, m^3 (equal to ``volume_exact`` to the CAD kernel's tolerance).
    neck_a : numpy.ndarray
        Neck radius of every bond, m.
    cut : numpy.ndarray, optional
        Mask of the elements whose vertices belong to different particles (those that a neck's split plane or a
        cap plane passes through).
    method : str
        The neck model (:func:`fem_neck.geometry.neck_geometry`).
    """

    cluster: Cluster
    terminals: tuple
    mesh: object
    particle: np.ndarray
    volume_exact: float
    volume_cad: float
    neck_a: np.ndarray = field(repr=False)
    cut: np.ndarray = field(default=None, repr=False)
    method: str = "newton"


def add_neck_cylinders(occ, cluster: Cluster, geo) -> list:
    """One OCC cylinder per bond: the neck of radius ``a`` from ``z_i`` to ``z_i + h_n`` along the bond, extended by
    ``_EXTEND * z`` into both spheres (hidden inside them) so that its side meets each sphere transversally.

    Parameters
    ----------
    occ : object
        ``gmsh.model.occ`` of an open gmsh session.
    cluster : Cluster
        The cluster (in the session's length unit).
    geo : fem_neck.geometry.NeckGeometry
        Its necks (:meth:`Cluster.necks`).
    """
    e = cluster.directions()
    c = cluster.centres
    bi = cluster.bonds[:, 0]
    out = []
    for b in range(len(bi)):
        start = c[bi[b]] + (geo.z_i[b] - _EXTEND * geo.z_i[b]) * e[b]
        length = geo.h_n[b] + _EXTEND * (geo.z_i[b] + geo.z_j[b])
        out.append((3, occ.addCylinder(*start, *(length * e[b]), geo.a[b])))
    return out


def neck_size_fields(gmsh, cluster: Cluster, geo, surfaces, size_neck: float, size_far: float, neck_cells: float,
                     tol: float, every_bond: bool = True, grading: float | None = None) -> list:
    """gmsh size fields graded toward every neck circle found on the boundary ``surfaces`` (set as the background
    mesh): ``min(size_neck a, h_n / neck_cells)`` at the circle, growing linearly to ``size_far`` times the smaller
    radius at a distance ``2 a`` (Distance + Threshold fields), or, with ``grading``, growing by ``grading`` per unit
    distance (the same relative grading around small and large necks). The circles are the curves all of whose sample points
    lie at distance ``a`` from the bond axis and at the neck's ends (possibly split into arcs at seams or cut by
    planes); a neck without length (``h_n = 0``: the circle where two spheres of a union meet,
    :class:`fem_neck.lattice.mesh.UnionNecks`) has one circle, and ``size_neck a`` there. ``every_bond``: each bond must
    have its two circles on the boundary (else ``RuntimeError``); otherwise
    bonds without any are skipped (a neck cut away by a cell face). Returns the Threshold field tags.

    Parameters
    ----------
    gmsh : object
        The ``gmsh`` module, in an open session with the solid built.
    cluster : Cluster
        The cluster (in the session's length unit).
    geo : fem_neck.geometry.NeckGeometry
        Its necks (:meth:`Cluster.necks`).
    surfaces : sequence of int
        Tags of the boundary surfaces searched for neck circles.
    size_neck : float
        Element size at a neck circle over its neck radius ``a`` (dimensionless).
    size_far : float
        Element size at distance ``2 a`` over the bond's smaller radius (dimensionless).
    neck_cells : float
        Elements along the neck length ``h_n`` at least.
    tol : float
        Distance within which a curve's sample points count as on a neck circle, in the session's length unit.
    every_bond : bool
        Require both circles of every bond on the boundary.
    grading : float, optional
        Growth of the size per unit distance from the circle (dimensionless); default the linear ramp to
        ``size_far`` at ``2 a``.
    """
    c, r = cluster.centres, cluster.radii
    bi, bj = cluster.bonds.T
    e = cluster.directions()
    curves = [tag for _, tag in gmsh.model.getBoundary([(2, s) for s in surfaces], combined=False, oriented=False)]
    samples = {}
    for tag in sorted(set(abs(x) for x in curves)):
        lo, hi = gmsh.model.getParametrizationBounds(1, tag)
        samples[tag] = np.reshape(gmsh.model.getValue(1, tag, np.linspace(lo[0], hi[0], 5)), (-1, 3))
    thresholds = []
    for b in range(len(bi)):
        found = []
        for tag, xyz in samples.items():
            rel = xyz - c[bi[b]]
            axial = rel @ e[b]
            radial = np.linalg.norm(rel - axial[:, None] * e[b], axis=1)
            on_radius = np.all(np.abs(radial - geo.a[b]) < 10 * tol)
            for z in (geo.z_i[b], geo.z_i[b] + geo.h_n[b]) if geo.h_n[b] > 0 else (geo.z_i[b],):
                if on_radius and np.all(np.abs(axial - z) < 10 * tol):
                    found.append(tag)
        if len(found) < 2 and every_bond:
            raise RuntimeError(f"bond {b}: found {len(found)} neck-circle curves after the union, expected >= 2")
        if not found:
            continue
        dist = gmsh.model.mesh.field.add("Distance")
        gmsh.model.mesh.field.setNumbers(dist, "CurvesList", found)
        gmsh.model.mesh.field.setNumber(dist, "Sampling", 200)
        thr = gmsh.model.mesh.field.add("Threshold")
        size_min = min(size_neck * geo.a[b], geo.h_n[b] / neck_cells) if geo.h_n[b] > 0 else size_neck * geo.a[b]
        size_max = size_far * min(r[bi[b]], r[bj[b]])
        gmsh.model.mesh.field.setNumber(thr, "InField", dist)
        gmsh.model.mesh.field.setNumber(thr, "SizeMin", size_min)
        gmsh.model.mesh.field.setNumber(thr, "SizeMax", size_max)
        gmsh.model.mesh.field.setNumber(thr, "DistMin", 0.0)
        gmsh.model.mesh.field.setNumber(thr, "DistMax", 2.0 * geo.a[b] if grading is None
                                        else max(size_max - size_min, 0.0) / grading)
        thresholds.append(thr)
    fmin = gmsh.model.mesh.field.add("Min")
    gmsh.model.mesh.field.setNumbers(fmin, "FieldsList", thresholds)
    gmsh.model.mesh.field.setAsBackgroundMesh(fmin)
    return thresholds


def mesh_tetrahedra(gmsh, curvature: int, size_max: float) -> None:
    r"""Generate the 3D mesh from the background size field: ``curvature`` elements per :math:`2 \pi` of surface
    curvature, at most ``size_max``; one thread and fixed algorithms (Frontal-Delaunay surfaces, Delaunay volume), so
    the same input gives the same mesh.

    Parameters
    ----------
    gmsh : object
        The ``gmsh`` module, in an open session with the background size field set.
    curvature : int
        Elements per :math:`2 \pi` of surface curvature.
    size_max : float
        Largest element size, in the session's length unit.
    """
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", curvature)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size_max)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.Algorithm3D", 1)
    gmsh.option.setNumber("Mesh.Optimize", 1)
    gmsh.model.mesh.generate(3)


def tetrahedra(gmsh, vol_tag: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points (N, 3), tets (M, 4) indices into points, index)`` of the meshed volume ``vol_tag``; ``index`` maps
    gmsh node tags to rows of ``points``.

    Parameters
    ----------
    gmsh : object
        The ``gmsh`` module, in an open session with the volume meshed.
    vol_tag : int
        Tag of the meshed volume.
    """
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    points = np.asarray(coords).reshape(-1, 3)
    index = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
    index[node_tags.astype(np.int64)] = np.arange(len(node_tags))
    _, _, elem_nodes = gmsh.model.mesh.getElements(3, vol_tag)
    return points, index[np.asarray(elem_nodes[0], dtype=np.int64)].reshape(-1, 4), index


def _surface_of(cx, tags, centre, area, kind, tol):
    """The tag of the surface of type ``kind`` centred at ``centre`` with area ``area`` (found by position)."""
    import gmsh

    for tag in tags:
        if gmsh.model.getType(2, tag) != kind:
            continue
        com = np.array(gmsh.model.occ.getCenterOfMass(2, tag))
        if np.linalg.norm(com - centre) < tol and abs(gmsh.model.occ.getMass(2, tag) - area) < 1e-3 * area:
            return tag
    raise RuntimeError(f"{cx}: boundary surface of type {kind} at {centre.tolist()} not found after the boolean")


def _check_terminals(cluster: Cluster, terminals) -> tuple:
    terminals = tuple(terminals)
    deg = cluster.degree()
    seen = set()
    for t in terminals:
        if t.kind not in BC_KINDS:
            raise ValueError(f"terminal kind = {t.kind!r}: must be one of {', '.join(BC_KINDS)}")
        if not 0 <= t.particle < cluster.n or t.particle in seen:
            raise ValueError(f"terminal particle = {t.particle}: must be a distinct index in 0..{cluster.n - 1}")
        seen.add(t.particle)
        if t.kind == "plane" and deg[t.particle] != 1:
            raise ValueError(f"terminal particle {t.particle} has {deg[t.particle]} bonds: a 'plane' terminal "
                             "needs exactly one (use kind='core')")
        if t.kind == "core" and not 0.0 < t.rho < 0.5:
            raise ValueError(f"terminal rho = {t.rho}: valid range 0 < rho < 0.5")
    if len({t.T for t in terminals}) < 2:
        raise ValueError("terminals: need at least two different temperatures")
    return terminals


def build_cluster_mesh(cluster: Cluster, terminals, size_neck: float = 0.2, size_far: float = 0.35,
                       curvature: int = 20, method: str = "newton", curved: bool = True,
                       neck_cells: float = 2.0) -> ClusterMesh:
    r"""Mesh the cluster with first-order tetrahedra, graded toward every neck circle.

    ``size_neck`` is the element size at the neck circles as a fraction of the neck radius ``a`` (and at most the
    neck length over ``neck_cells``; the length is :math:`\approx a^2/(2r)` for small necks); it grows
    linearly to ``size_far`` times the smaller radius of the bond at a distance ``2 a`` (gmsh Distance + Threshold
    fields). ``curvature`` is gmsh's elements per :math:`2 \pi` of surface curvature. ``curved`` returns the quadratic
    :func:`curved_mesh` (exact boundary edge midpoints; use with ``order=2``). Deterministic (one thread, fixed
    algorithm). Terminals: a sequence of :class:`Terminal`; only the hottest and coldest boundaries are named
    (``"hot"``, ``"cold"``), intermediate temperatures are not supported.

    Parameters
    ----------
    cluster : Cluster
        The cluster, m (validated with ``method``).
    terminals : sequence of Terminal
        At least two, of at least two temperatures.
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless, > 0).
    size_far : float
        Element size at distance ``2 a`` over the bond's smaller radius (dimensionless, > 0).
    curvature : int
        gmsh's elements per :math:`2 \pi` of surface curvature.
    method : str
        Neck model (as in :meth:`Cluster.necks`).
    curved : bool
        Return the quadratic mesh of :func:`curved_mesh` (for ``order=2``).
    neck_cells : float
        Elements along the neck length at least (> 0).
    """
    from skfem import MeshTet

    from fem_neck.shapes import gmsh_session

    cluster.validate(method)
    terminals = _check_terminals(cluster, terminals)
    check_positive("size_neck", size_neck)
    check_positive("size_far", size_far)
    check_positive("neck_cells", neck_cells)
    # Build in units of the largest radius (OCC's tolerances are absolute), scale the mesh back at the end.
    unit = float(cluster.radii.max())
    real = cluster
    cluster = Cluster(cluster.centres / unit, cluster.radii / unit, cluster.bonds)
    geo = cluster.necks(method)
    e = cluster.directions()
    c, r = cluster.centres, cluster.radii
    bi, bj = cluster.bonds.T
    scale = float(r.max())
    tol = 1e-6 * scale
    by_particle = {t.particle: t for t in terminals}
    volume_exact = float(np.sum(4.0 / 3.0 * np.pi * r**3))
    for t in terminals:
        volume_exact -= (2.0 / 3.0 * np.pi * r[t.particle] ** 3 if t.kind == "plane"
                         else 4.0 / 3.0 * np.pi * (t.rho * r[t.particle]) ** 3)

    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        solids = []
        for k in range(cluster.n):
            t = by_particle.get(k)
            if t is not None and t.kind == "plane":
                # the half sphere z >= 0 about its own centre, turned so that +z points along the bond: its
                # flat face is the terminal disk, and no sphere pole lies in the cut plane
                s = occ.addSphere(*c[k], r[k], angle1=0.0)
                b = int(np.flatnonzero((bi == k) | (bj == k))[0])
                ek = e[b] if bi[b] == k else -e[b]
                axis = np.cross([0.0, 0.0, 1.0], ek)
                angle = float(np.arctan2(np.linalg.norm(axis), ek[2]))
                if np.linalg.norm(axis) < 1e-12:
                    axis = np.array([1.0, 0.0, 0.0])
                if angle > 0.0:
                    occ.rotate([(3, s)], *c[k], *axis, angle)
            else:
                s = occ.addSphere(*c[k], r[k])
            solids.append((3, s))
        solids += add_neck_cylinders(occ, cluster, geo)
        out, _ = occ.fuse(solids[:1], solids[1:])
        if len(out) != 1:
            raise RuntimeError(f"cluster solid has {len(out)} volumes after the union: the cluster must be connected")
        volume = out
        cores = [t for t in terminals if t.kind == "core"]
        if cores:
            balls = [(3, occ.addSphere(*c[t.particle], t.rho * r[t.particle])) for t in cores]
            volume = occ.cut(volume, balls)[0]
        occ.synchronize()
        vol_tag = volume[0][1]
        volume_cad = occ.getMass(3, vol_tag)
        surfaces = [tag for _, tag in gmsh.model.getBoundary(volume, oriented=False)]
        named = {"hot": [], "cold": []}
        t_hot = max(t.T for t in terminals)
        t_cold = min(t.T for t in terminals)
        for t in terminals:
            k = t.particle
            if t.kind == "plane":
                tag = _surface_of(f"particle {k}", surfaces, c[k], np.pi * r[k] ** 2, "Plane", tol)
            else:
                tag = _surface_of(f"particle {k}", surfaces, c[k], 4 * np.pi * (t.rho * r[k]) ** 2, "Sphere", tol)
            if t.T == t_hot:
                named["hot"].append(tag)
            elif t.T == t_cold:
                named["cold"].append(tag)
            else:
                raise ValueError(f"terminal T = {t.T}: only two temperature levels are supported")
        neck_size_fields(gmsh, cluster, geo, surfaces, size_neck, size_far, neck_cells, tol)
        mesh_tetrahedra(gmsh, curvature, size_far * float(r.max()))
        points, tets, index = tetrahedra(gmsh, vol_tag)
        facets = {}
        for name, tags in named.items():
            tris = []
            for tag in tags:
                _, _, fn = gmsh.model.mesh.getElements(2, tag)
                tris.append(index[np.asarray(fn[0], dtype=np.int64)].reshape(-1, 3))
            facets[name] = np.vstack(tris)

    used = np.unique(tets)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    points = points[used]
    tets = remap[tets]
    mesh = MeshTet(points.T.copy(), tets.T.copy())
    lookup = {tuple(f): n for n, f in enumerate(np.sort(mesh.facets.T, axis=1).tolist())}
    boundaries = {name: np.array([lookup[tuple(f)] for f in np.sort(remap[tri], axis=1).tolist()], dtype=np.int64)
                  for name, tri in facets.items()}
    particle = assign_particles(cluster, geo, points[tets].mean(axis=1))
    vertex_owner = assign_particles(cluster, geo, points)[tets]
    cut = np.any(vertex_owner != vertex_owner[:, :1], axis=1)
    if curved:
        mesh = curved_mesh(mesh, cluster, geo, terminals)
    mesh = type(mesh)(mesh.doflocs * unit, mesh.t).with_boundaries(boundaries)
    return ClusterMesh(cluster=real, terminals=terminals, mesh=mesh, particle=particle,
                       volume_exact=volume_exact * unit**3, volume_cad=volume_cad * unit**3,
                       neck_a=np.asarray(geo.a) * unit, cut=cut, method=method)


def _on_sphere(x, centre, radius, tol):
    return np.abs(np.linalg.norm(x - centre, axis=-1) - radius) < tol


def curved_mesh(mesh, cluster: Cluster, geo, terminals, tol: float | None = None):
    """Quadratic (isoparametric) version of a first-order cluster mesh: ``skfem.MeshTet2`` whose boundary edge
    midpoints are moved onto the exact surfaces -- the spheres, the neck cylinders, the core balls and the neck
    circles where sphere and cylinder meet. Straight-sided tetrahedra inscribe the spheres (volume and ``K`` too
    small); with P2 on this mesh the geometric error falls from :math:`O(h^2)` to :math:`O(h^3)` or better.

    Parameters
    ----------
    mesh : skfem.MeshTet
        The first-order mesh (in the unit of ``cluster``).
    cluster : Cluster
        The cluster it meshes.
    geo : fem_neck.geometry.NeckGeometry
        Its necks (:meth:`Cluster.necks`).
    terminals : sequence of Terminal
        Its terminals (their cut planes and core balls).
    tol : float, optional
        Distance within which a point counts as on a surface, in the mesh's length unit; default ``1e-7`` times
        the largest radius.
    """
    from skfem import MeshTet2

    c, r = cluster.centres, cluster.radii
    bi, bj = cluster.bonds.T
    e = cluster.directions()
    tol = 1e-7 * float(r.max()) if tol is None else tol
    p = mesh.p.T
    nv = len(p)
    edges = np.sort(mesh.edges.T, axis=1)
    keys = edges[:, 0] * nv + edges[:, 1]
    order = np.argsort(keys)
    facets = mesh.facets[:, mesh.boundary_facets()].T
    x = p[facets]                                  # (nf, 3 vertices, 3)
    xc = x.mean(axis=1)
    normal = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    fedges = np.sort(np.stack([facets[:, [0, 1]], facets[:, [1, 2]], facets[:, [0, 2]]], axis=1), axis=2)
    m2 = MeshTet2.from_mesh(mesh)
    doflocs = m2.doflocs.copy()

    def move(on_surface, project):
        ed = fedges[on_surface].reshape(-1, 2)
        ed = np.unique(ed[:, 0] * nv + ed[:, 1])
        idx = order[np.searchsorted(keys, ed, sorter=order)]
        mid = 0.5 * (p[edges[idx, 0]] + p[edges[idx, 1]])
        doflocs[:, nv + idx] = project(mid).T

    def sphere(centre, radius):
        on = np.all(_on_sphere(x, centre, radius, tol), axis=1)
        radial = xc - centre
        on &= np.abs(np.sum(normal * radial, axis=1)) > 0.5 * np.linalg.norm(radial, axis=1)
        move(on, lambda m: centre + radius * (m - centre) / np.linalg.norm(m - centre, axis=1)[:, None])

    def cylinder(origin, axis, radius, z0, z1, circle=False):
        def split(y):
            axial = (y - origin) @ axis
            rad = (y - origin) - axial[..., None] * axis
            return axial, rad

        axial, rad = split(x)
        dist = np.linalg.norm(rad, axis=-1)
        on = np.all(np.abs(dist - radius) < tol, axis=1) & np.all((axial > z0 - tol) & (axial < z1 + tol), axis=1)
        if circle:  # edges along the neck circle at z0 (z1 == z0): both ends on it, any facet type
            ed = np.sort(np.stack([facets[:, [0, 1]], facets[:, [1, 2]], facets[:, [0, 2]]], axis=1), axis=2)
            a0, r0 = split(p[ed[..., 0]])
            a1, r1 = split(p[ed[..., 1]])
            ok = ((np.abs(np.linalg.norm(r0, axis=-1) - radius) < tol) & (np.abs(a0 - z0) < tol)
                  & (np.abs(np.linalg.norm(r1, axis=-1) - radius) < tol) & (np.abs(a1 - z0) < tol))
            sel = np.unique(ed[ok][:, 0] * nv + ed[ok][:, 1])
            idx = order[np.searchsorted(keys, sel, sorter=order)]
            mid = 0.5 * (p[edges[idx, 0]] + p[edges[idx, 1]])
            ma, mr = split(mid)
            doflocs[:, nv + idx] = (origin + z0 * axis + radius * mr / np.linalg.norm(mr, axis=1)[:, None]).T
            return
        on &= np.abs(normal @ axis) < 0.5
        move(on, lambda m: origin + (split(m)[0])[:, None] * axis
             + radius * split(m)[1] / np.linalg.norm(split(m)[1], axis=1)[:, None])

    for k in range(cluster.n):
        sphere(c[k], r[k])
    for t in terminals:
        if t.kind == "core":
            sphere(c[t.particle], t.rho * r[t.particle])
    for b in range(len(bi)):
        cylinder(c[bi[b]], e[b], geo.a[b], geo.z_i[b], geo.z_i[b] + geo.h_n[b])
    for b in range(len(bi)):
        z0, z1 = geo.z_i[b], geo.z_i[b] + geo.h_n[b]
        cylinder(c[bi[b]], e[b], geo.a[b], z0, z0, circle=True)
        cylinder(c[bi[b]], e[b], geo.a[b], z1, z1, circle=True)
    return MeshTet2(doflocs, m2.t)


def assign_particles(cluster: Cluster, geo, x: np.ndarray) -> np.ndarray:
    r"""Owning particle of each point ``x`` (N, 3) of the solid.

    In a neck cylinder of bond ``(i, j)``, the part of length :math:`V_{cap,i} / (\pi a^2)` next to ``i`` belongs to
    ``i``, the rest to ``j``; elsewhere the point belongs to the sphere that contains it on the near side of all of that
    sphere's cap planes (its truncated sphere). Each particle thus owns the volume :math:`\frac{4}{3} \pi r^3`.

    Parameters
    ----------
    cluster : Cluster
        The cluster, m.
    geo : fem_neck.geometry.NeckGeometry
        Its necks (:meth:`Cluster.necks`).
    x : numpy.ndarray
        Points ``(N, 3)`` of the solid, m.
    """
    c, r = cluster.centres, cluster.radii
    bi, bj = cluster.bonds.T
    e = cluster.directions()
    owner = np.full(len(x), -1, dtype=np.int64)
    beyond = np.zeros((len(x), cluster.n), dtype=bool)
    for b in range(len(bi)):
        rel = x - c[bi[b]]
        axial = rel @ e[b]
        radial = np.linalg.norm(rel - axial[:, None] * e[b], axis=1)
        z0, z1 = geo.z_i[b], geo.z_i[b] + geo.h_n[b]
        cap_i = np.pi * geo.h_ci[b] ** 2 * (3.0 * r[bi[b]] - geo.h_ci[b]) / 3.0
        split = z0 + cap_i / (np.pi * geo.a[b] ** 2)
        inside = (radial <= geo.a[b] * (1 + 1e-9)) & (axial >= z0) & (axial <= z1)
        owner[inside & (axial <= split)] = bi[b]
        owner[inside & (axial > split)] = bj[b]
        beyond[:, bi[b]] |= axial > z0
        beyond[:, bj[b]] |= axial < z1
    dist = np.linalg.norm(x[:, None, :] - c[None], axis=2) / r[None]
    dist[beyond] = np.inf
    rest = owner < 0
    owner[rest] = np.argmin(dist[rest], axis=1)
    return owner


@dataclass
class ClusterSolution:
    """Steady 3D conduction result (:func:`solve_cluster`).

    Parameters
    ----------
    K : float
        Conductance ``Q / (T_hot - T_cold)``, W/K.
    Q : float
        Heat flow through the hot terminal (the reaction at its dofs), W.
    particle_T : numpy.ndarray
        Mean temperature of every particle over the volume it owns, K.
    particle_volume : numpy.ndarray
        The mesh volume each particle owns, m^3.
    dofs : int
        Unknowns of the FE space.
    u : numpy.ndarray
        Temperature at every dof, K.
    basis : skfem.Basis
        The FE basis ``u`` lives on.
    """

    K: float
    Q: float
    particle_T: np.ndarray
    particle_volume: np.ndarray
    dofs: int
    u: np.ndarray = field(repr=False)
    basis: object = field(repr=False)


def particle_means(basis, u: np.ndarray, cmesh: ClusterMesh) -> tuple[np.ndarray, np.ndarray]:
    """Volume-averaged ``u`` per particle and each particle's volume, by quadrature.

    An element whose vertices all belong to one particle lies inside it (the particles' shares are bounded by
    planes: the necks' split planes and the spheres' cap planes) and counts whole; an element that such a plane
    cuts is divided at its quadrature points (:func:`assign_particles`), so the shares are exact to quadrature
    instead of to whole elements (which would leave an O(h) error that no mesh sequence estimate follows).

    Parameters
    ----------
    basis : skfem.Basis
        The FE basis of ``u`` on ``cmesh.mesh``.
    u : numpy.ndarray
        Temperature at every dof, K.
    cmesh : ClusterMesh
        The mesh with its particle ownership.
    """
    value = np.asarray(basis.interpolate(u))
    dx = basis.dx
    owner = np.repeat(cmesh.particle[:, None], dx.shape[1], axis=1)
    cut = np.flatnonzero(cmesh.cut) if cmesh.cut is not None else np.zeros(0, dtype=np.int64)
    if cut.size:
        x = basis.mapping.F(basis.quadrature[0], tind=cut)  # (3, cut elements, points)
        owner[cut] = assign_particles(cmesh.cluster, cmesh.cluster.necks(cmesh.method),
                                      x.reshape(3, -1).T).reshape(x.shape[1:])
    n = cmesh.cluster.n
    vol = np.bincount(owner.ravel(), weights=dx.ravel(), minlength=n)
    return np.bincount(owner.ravel(), weights=(value * dx).ravel(), minlength=n) / vol, vol


def solve_cluster(cmesh: ClusterMesh, kappa: float = 1.0, order: int = 2, rtol: float = 1e-10) -> ClusterSolution:
    r"""Steady conduction :math:`\nabla \cdot (\kappa \nabla T) = 0` on the cluster, ``T`` fixed on the terminals,
    insulated elsewhere.

    P1 or P2 tetrahedra; the linear system is solved by conjugate gradients with a smoothed-aggregation AMG
    preconditioner (pyamg) to relative residual ``rtol``. ``Q`` is the reaction at the hot dofs (design notes).

    Parameters
    ----------
    cmesh : ClusterMesh
        The meshed cluster.
    kappa : float
        Thermal conductivity, W/(m K), > 0.
    order : int
        Element order, 1 or 2.
    rtol : float
        Relative residual of the AMG-preconditioned CG (dimensionless).
    """
    import pyamg
    from skfem import Basis, ElementTetP1, ElementTetP2, condense
    from skfem.models.poisson import laplace

    check_positive("kappa", kappa)
    if order not in (1, 2):
        raise ValueError(f"order = {order}: must be 1 or 2")
    elem = ElementTetP1() if order == 1 else ElementTetP2()
    basis = Basis(cmesh.mesh, elem)
    A = (kappa * laplace.assemble(basis)).tocsr()
    t_hot = max(t.T for t in cmesh.terminals)
    t_cold = min(t.T for t in cmesh.terminals)
    hot = basis.get_dofs(cmesh.mesh.boundaries["hot"]).all()
    cold = basis.get_dofs(cmesh.mesh.boundaries["cold"]).all()
    u = np.zeros(basis.N)
    u[hot] = t_hot
    u[cold] = t_cold
    D = np.concatenate([hot, cold])
    Ai, bi, _, I = condense(A, np.zeros(basis.N), x=u, D=D)
    ml = pyamg.smoothed_aggregation_solver(Ai.tocsr(), symmetry="symmetric")
    u[I] = ml.solve(bi, x0=np.full(len(I), 0.5 * (t_hot + t_cold)), tol=rtol, accel="cg", maxiter=500)
    Q = float((A @ u)[hot].sum())
    means, vols = particle_means(basis, u, cmesh)
    return ClusterSolution(K=Q / (t_hot - t_cold), Q=Q, particle_T=means, particle_volume=vols, dofs=int(basis.N),
                           u=u, basis=basis)


@dataclass
class ClusterResult:
    """A cluster solved on a mesh sequence (:func:`cluster_conductance`); the values are the finest level's.

    Parameters
    ----------
    K : float
        Conductance, W/K.
    error_estimate : float or None
        Relative error estimate of ``K`` (dimensionless, :func:`fem_neck.accuracy.mesh_sequence_estimate`; None
        with one level).
    particle_T : numpy.ndarray
        Mean temperature of every particle, K.
    T_error_estimate : float or None
        Absolute error estimate of ``particle_T``, K: the last change of the particle means times the estimate's
        amplification (None with one level).
    levels : list of dict
        Per level the ``size_factor``, ``dofs``, ``K`` (W/K) and ``seconds`` (wall time, s).
    sequence : fem_neck.accuracy.SequenceEstimate or None
        The estimate's details (None with one level).
    cmesh : ClusterMesh
        The finest level's mesh.
    solution : ClusterSolution
        The finest level's field.
    """

    K: float
    error_estimate: float | None
    particle_T: np.ndarray
    T_error_estimate: float | None
    levels: list
    sequence: object
    cmesh: ClusterMesh = field(repr=False)
    solution: ClusterSolution = field(repr=False)


def cluster_conductance(cluster: Cluster, terminals, kappa: float = 1.0, size_neck: float = 0.12,
                        size_far: float = 0.25, levels: int = 3, curvature: float | None = None,
                        neck_cells: float = 2.0, method: str = "newton") -> ClusterResult:
    r"""Steady conductance and particle mean temperatures of a cluster, with an error estimate from a mesh sequence.

    The finest level uses the given sizes (:func:`build_cluster_mesh`; ``curvature`` defaults to ``4 / size_far``);
    each coarser level multiplies every size by :data:`fem_neck.accuracy.MESH_RATIO` (``size_neck``, ``size_far``,
    the neck length per element ``1 / neck_cells`` and the curved-surface size ``1 / curvature``), so that the
    levels refine one mesh pattern and the error falls at least at the neck edges' corner rate. The estimate is
    :func:`fem_neck.accuracy.mesh_sequence_estimate` with the cluster's smallest corner exponent. Three levels cost
    about 1.5 times the finest alone (dofs fall ~3x per level).

    Parameters
    ----------
    cluster : Cluster
        The cluster, m.
    terminals : sequence of Terminal
        At least two, of at least two temperatures.
    kappa : float
        Thermal conductivity, W/(m K), > 0.
    size_neck : float
        The finest level's element size at the neck circles over the neck radius (dimensionless).
    size_far : float
        The finest level's element size at distance ``2 a`` over the bond's smaller radius (dimensionless).
    levels : int
        Meshes of the sequence: 1, 2 or 3.
    curvature : float, optional
        The finest level's elements per :math:`2 \pi` of surface curvature; default ``4 / size_far``.
    neck_cells : float
        The finest level's elements along the neck length at least.
    method : str
        Neck model (as in :meth:`Cluster.necks`).
    """
    import time

    from fem_neck import accuracy
    from sinterheat.interrupt import where

    factors = accuracy.mesh_levels(levels)
    curvature = 4.0 / size_far if curvature is None else curvature
    runs = []
    for k, f in enumerate(factors):
        where().update(step=f"mesh level {k + 1} of {levels}")
        t0 = time.perf_counter()
        cmesh = build_cluster_mesh(cluster, terminals, size_neck=size_neck * f, size_far=size_far * f,
                                   curvature=max(4, int(round(curvature / f))), method=method,
                                   neck_cells=neck_cells / f)
        sol = solve_cluster(cmesh, kappa=kappa, order=2)
        runs.append((f, cmesh, sol, time.perf_counter() - t0))
    f, cmesh, sol, _ = runs[-1]
    table = [{"size_factor": f, "dofs": s.dofs, "K": s.K, "seconds": t} for f, _, s, t in runs]
    if levels == 1:
        return ClusterResult(K=sol.K, error_estimate=None, particle_T=sol.particle_T, T_error_estimate=None,
                             levels=table, sequence=None, cmesh=cmesh, solution=sol)
    seq = accuracy.mesh_sequence_estimate([s.K for _, _, s, _ in runs], cluster.corner_exponent(method))
    T_change = float(np.max(np.abs(runs[-1][2].particle_T - runs[-2][2].particle_T)))
    return ClusterResult(K=sol.K, error_estimate=seq.relative, particle_T=sol.particle_T,
                         T_error_estimate=seq.amplification * T_change, levels=table, sequence=seq, cmesh=cmesh,
                         solution=sol)


def write_vtu(cmesh: ClusterMesh, sol: ClusterSolution, path) -> None:
    """Write the temperature (vertex values) and the owning particle per element to a VTU file for ParaView.

    Parameters
    ----------
    cmesh : ClusterMesh
        The mesh solved on.
    sol : ClusterSolution
        The solution on it.
    path : str or pathlib.Path
        The ``.vtu`` file to write.
    """
    import meshio

    mesh = cmesh.mesh
    nv = mesh.p.shape[1]
    meshio.Mesh(mesh.p.T, [("tetra", mesh.t.T)], point_data={"T": sol.u[:nv]},
                cell_data={"particle": [cmesh.particle]}).write(str(path))


def load_cluster_json(data: dict) -> tuple[Cluster, list]:
    """``{"centres": [[x, y, z], ...], "radii": [...], "bonds": [[i, j], ...], "terminals": [{"particle": k,
    "T": ..., "kind": "plane"|"core", "rho": 0.25}, ...]}`` (metres, kelvin) -> (Cluster, terminals).

    Parameters
    ----------
    data : dict
        The parsed JSON document (above).
    """
    try:
        cluster = Cluster(np.asarray(data["centres"], dtype=float), np.asarray(data["radii"], dtype=float),
                          np.asarray(data["bonds"], dtype=int))
        terminals = [Terminal(int(t["particle"]), float(t["T"]), t.get("kind", "plane"), float(t.get("rho", 0.25)))
                     for t in data["terminals"]]
    except (KeyError, TypeError) as exc:
        raise ValueError(f"cluster file: missing or malformed entry ({exc}); need centres, radii, bonds, "
                         "terminals") from exc
    return cluster, terminals
