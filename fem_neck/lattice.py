"""Effective conductivity of periodic packings of sintered spheres: 3D FE of the mirror cell with two-sided bounds.

Geometry. A :class:`PeriodicCell` holds the particles of one period (centres, radii, the period box); every
overlapping pair of particle images is bonded (Rojek 2022, eq. 21) and gets the volume-conserving cylindrical neck of
:func:`fem_neck.geometry.neck_geometry` (eqs. 22-33). The solid is the union of all spheres and all neck cylinders,
exactly as in :mod:`fem_neck.cluster`; it conserves each particle's volume, so the solid volume fraction is
``phi = sum 4/3 pi r^3 / |period|`` exactly. The pair neck model has an answer only while the necks of one particle
stay apart: :func:`check_cell` refuses a cell where two neck circles on one sphere touch (for the cubic lattices from
``a/r = sin(theta/2)``, theta the smallest angle between bonds: SC 90 deg, BCC 70.5 deg, FCC 60 deg; see
:func:`max_h_over_r`).

The computational cell. A macroscopic gradient along z through a packing that is mirror-symmetric about the planes
``x = 0``, ``y = 0``, ``z = 0`` (hence also about ``x = P_x/2`` etc.) leaves the planes ``z = 0`` and ``z = P_z/2``
isothermal (the temperature fluctuation is odd under the z mirror) and the planes normal to x and y insulated (it
is even under those). The FE therefore solves the box ``[0, P/2]^3`` -- an eighth of the period -- with ``T = 1`` on
``z = 0``, ``T = 0`` on ``z = P_z/2`` and no flux elsewhere; when the packing is also symmetric under ``x <-> y``
(the cubic lattices) only the wedge ``0 <= y <= x`` of that box is solved (a sixteenth), and when also under
``(x, y) -> (P/2 - y, P/2 - x)`` (face-centred cubic) only its half with ``x + y <= P/2``. Then
``k_eff = Q (P_z / 2) / A`` with ``Q`` the heat flow and ``A`` the cell's cross-section, for ``kappa = 1``.

Two bounds (the error estimate). With ``K`` the exact heat flow of the cell for a unit temperature difference:

* **upper**: conforming P2 on curved (isoparametric quadratic) tetrahedra. By Dirichlet's principle the discrete
  energy ``u_h . A u_h`` is never below ``K`` on the same domain; the curved boundary reproduces the spheres and
  cylinders to third order, and that geometric error is far below the discretisation error (measured: the quadratic
  boundary moves ``K`` by ~1e-4 relative to straight sides at the default meshes).
* **lower**: Crouzeix-Raviart (nonconforming P1) on the *straight* tetrahedra. Every boundary facet has its three
  vertices on one sphere or one neck cylinder, and each sphere and each cylinder lies inside the solid, so the straight
  mesh is inscribed in the exact solid. The CR equations at a facet say that the elementwise-constant flux
  ``q = -grad u_h`` has the same normal component on both sides of every interior facet and none on the insulated
  facets: ``q`` is divergence-free and, extended by zero, admissible in the complementary (Thomson) principle on the
  exact solid, so ``K >= P^2 / E*`` with ``P`` the flux ``q`` carries through the hot face and ``E* = int |q|^2``
  (Cauchy-Schwarz). This bound is rigorous up to the linear solver's residual (solved to 1e-11).

``error_estimate = (upper - lower) / upper`` bounds the error of the reported value (the upper, P2, which is the
more accurate of the two). The mesh is refined (all sizes by one factor, the gap falling like size^1.65) until the
estimate meets ``rtol``.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from fem_neck.geometry import check_positive, max_overlap, neck_geometry, overlap_for_neck

KINDS = ("sc", "bcc", "fcc")
# particle sites of the cubic cell (units of the cell edge) and the cell edge in units of the neighbour distance
BASIS = {"sc": [[0.0, 0.0, 0.0]],
         "bcc": [[0.0, 0.0, 0.0], [0.5, 0.5, 0.5]],
         "fcc": [[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]]}
EDGE_OVER_SPACING = {"sc": 1.0, "bcc": 2.0 / math.sqrt(3.0), "fcc": math.sqrt(2.0)}
BOND_ANGLE = {"sc": math.pi / 2, "bcc": math.acos(1.0 / 3.0), "fcc": math.pi / 3}  # smallest angle between bonds
COORDINATION = {"sc": 6, "bcc": 8, "fcc": 12}
# smallest neck meshed: below it the neck is thinner than 1.3e-3 r and the mesh of its disk explodes; the network is
# exact in the limit of small necks (independent constrictions), which the FE shows from here up
MIN_NECK_RATIO = 0.05
# the refinement ladder: level sizes relative to the particle radius (far) and to the neck radius (at the circles)
SIZE_FAR0, SIZE_NECK0, GRADING0, LEVEL_FACTOR = 0.25, 0.06, 0.25, 0.8
MAX_ELEMENTS = 3_000_000  #: finer meshes are refused (~10 GB and ~15 min on 2 cores)
GAP_ORDER = 1.65  # the gap between the bounds falls like size^GAP_ORDER (:func:`effective_conductivity`)
LINEAR_RTOL = 1e-11
_TOL = 1e-9  # geometric tolerance in units of the largest radius


@dataclass(frozen=True)
class PeriodicCell:
    """One period of a packing: ``centres`` (n, 3) wrapped into ``[0, period)``, ``radii`` (n,), ``period`` (3,).

    Every pair of particle images closer than the sum of their radii is bonded (Rojek 2022, eq. 21).
    """

    centres: np.ndarray
    radii: np.ndarray
    period: np.ndarray
    name: str = "cell"

    def __post_init__(self):
        period = check_positive("period", np.asarray(self.period, dtype=float).reshape(-1))
        if period.shape != (3,):
            raise ValueError(f"period = {self.period!r}: must be three lengths")
        centres = np.asarray(self.centres, dtype=float).reshape(-1, 3)
        radii = check_positive("radii", np.asarray(self.radii, dtype=float).reshape(-1))
        if len(radii) != len(centres) or not len(radii):
            raise ValueError(f"radii has {len(radii)} entries: must match the {len(centres)} centres (at least one)")
        if not np.all(np.isfinite(centres)):
            raise ValueError("centres: must be finite")
        object.__setattr__(self, "period", period)
        object.__setattr__(self, "centres", np.mod(centres, period))
        object.__setattr__(self, "radii", radii)

    @property
    def n(self) -> int:
        return len(self.radii)

    @property
    def phi(self) -> float:
        """Solid volume fraction ``sum 4/3 pi r^3 / |period|`` (exact: the necks conserve each particle's volume)."""
        return float(np.sum(4.0 / 3.0 * np.pi * self.radii**3) / np.prod(self.period))

    def images(self, lo, hi) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every image ``c_k + n P`` with its centre in the box ``[lo, hi]``: ``(centres, owner k, shift n)``."""
        lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        n_lo = np.floor((lo - self.period) / self.period).astype(int)
        n_hi = np.ceil(hi / self.period).astype(int)
        grids = np.meshgrid(*(np.arange(a, b + 1) for a, b in zip(n_lo, n_hi)), indexing="ij")
        shifts = np.column_stack([g.ravel() for g in grids])
        x = self.centres[None, :, :] + (shifts * self.period)[:, None, :]
        owner = np.broadcast_to(np.arange(self.n), x.shape[:2])
        shift = np.broadcast_to(shifts[:, None, :], x.shape)
        x, owner, shift = x.reshape(-1, 3), owner.reshape(-1), shift.reshape(-1, 3)
        inside = np.all((x >= lo - _TOL * self.radii.max()) & (x <= hi + _TOL * self.radii.max()), axis=1)
        return x[inside], owner[inside], shift[inside]

    def bonds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Bonds ``(i, j, shift)``: particle ``i`` and the image ``c_j + shift P`` overlap; each bond once (``i < j``,
        or ``i == j`` with the first nonzero shift component positive)."""
        reach = 2.0 * self.radii.max()
        x, owner, shift = self.images(-reach * np.ones(3), self.period + reach)
        out = []
        for i in range(self.n):
            d = np.linalg.norm(x - self.centres[i], axis=1)
            near = (d < self.radii[i] + self.radii[owner]) & ~((owner == i) & np.all(shift == 0, axis=1))
            for j, s in zip(owner[near], shift[near]):
                first = s[np.flatnonzero(s)[0]] if np.any(s) else 0
                if j > i or (j == i and first > 0):
                    out.append((i, int(j), *s.tolist()))
        arr = np.array(out, dtype=np.int64).reshape(-1, 5)
        return arr[:, 0], arr[:, 1], arr[:, 2:]


def lattice_cell(kind: str, h_over_r: float, radius: float = 1.0) -> PeriodicCell:
    """The cubic cell of a simple cubic, body-centred or face-centred cubic lattice of equal spheres of ``radius``
    whose nearest neighbours overlap by ``h = h_over_r * radius`` (neighbour distance ``2r - h``)."""
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r}: must be one of {', '.join(KINDS)}")
    check_positive("radius", radius)
    check_h_over_r(kind, h_over_r)
    edge = EDGE_OVER_SPACING[kind] * (2.0 - h_over_r) * radius
    basis = np.asarray(BASIS[kind]) * edge
    return PeriodicCell(basis, np.full(len(basis), float(radius)), np.full(3, edge), name=kind)


def max_neck_ratio(kind: str) -> float:
    """Largest ``a/r`` of a cubic lattice: the neck circles of one particle touch at ``a/r = sin(theta/2)``."""
    return math.sin(BOND_ANGLE[kind] / 2.0)


def max_h_over_r(kind: str) -> float:
    """``h/r`` at which the necks of one particle of the lattice touch (SC 0.2761, BCC 0.1774, FCC 0.1308)."""
    return overlap_for_neck(1.0, 1.0, max_neck_ratio(kind))


def check_h_over_r(kind: str, h_over_r: float) -> float:
    """``h_over_r`` if the lattice's necks exist and stay apart (and are not too small to mesh), else ValueError."""
    low = overlap_for_neck(1.0, 1.0, MIN_NECK_RATIO)
    high = max_h_over_r(kind)
    if not (isinstance(h_over_r, (int, float)) and low <= h_over_r < high):
        raise ValueError(
            f"h_over_r = {h_over_r!r}: valid range {low:.6g} <= h/r < {high:.6g} for {kind} (from h/r = {high:.6g}, "
            f"a/r = sin({math.degrees(BOND_ANGLE[kind]) / 2:.2f} deg) = {max_neck_ratio(kind):.4f}, the necks of one "
            f"particle touch and the pair neck model has no answer; below a/r = {MIN_NECK_RATIO} the neck is too "
            f"thin to mesh)")
    return float(h_over_r)


def check_cell(cell: PeriodicCell, method: str = "newton") -> None:
    """Raise ``ValueError`` unless every bond's overlap lies in the neck model's range and no two necks of one
    particle touch (their circles, of angular radius ``arcsin(a/r)``, must stay apart on the sphere)."""
    i, j, s = cell.bonds()
    if not len(i):
        raise ValueError(f"{cell.name}: no two particles overlap, so nothing conducts")
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    d = np.linalg.norm(e, axis=1)
    e = e / d[:, None]
    r_i, r_j = cell.radii[i], cell.radii[j]
    h = r_i + r_j - d
    limit = max_overlap(r_i, r_j)
    bad = np.flatnonzero(h > limit)
    if bad.size:
        b = int(bad[0])
        raise ValueError(f"{cell.name}: bond ({i[b]}, {j[b]}) overlaps by h = {h[b]:.6g}, beyond the neck model's "
                         f"range h <= {limit[b]:.6g} (there the neck reaches the smaller radius)")
    a = neck_geometry(r_i, r_j, h, method=method).a
    for k in range(cell.n):
        ends = [(b, e[b]) for b in np.flatnonzero(i == k)] + [(b, -e[b]) for b in np.flatnonzero(j == k)]
        for x in range(len(ends)):
            for y in range(x + 1, len(ends)):
                (b1, e1), (b2, e2) = ends[x], ends[y]
                angle = math.acos(float(np.clip(e1 @ e2, -1.0, 1.0)))
                need = math.asin(min(a[b1] / cell.radii[k], 1.0)) + math.asin(min(a[b2] / cell.radii[k], 1.0))
                if angle <= need:
                    raise ValueError(
                        f"{cell.name}: the necks of particle {k} (bonds {b1} and {b2}, a/r = "
                        f"{a[b1] / cell.radii[k]:.4f} and {a[b2] / cell.radii[k]:.4f}) touch: the bonds are "
                        f"{math.degrees(angle):.2f} deg apart, the neck circles need more than "
                        f"{math.degrees(need):.2f} deg; the pair neck model has no answer there")


def mirror_symmetry(cell: PeriodicCell) -> tuple[bool, bool, bool]:
    """``(mirror, diagonal, antidiagonal)``: whether the packing is symmetric under ``x -> -x``, ``y -> -y`` and
    ``z -> -z`` (each modulo the period); whether it is also symmetric under ``x <-> y``; and whether also under
    ``(x, y) -> (P/2 - y, P/2 - x)`` (the face-centred cubic lattice)."""

    def same(mapped) -> bool:
        mapped = np.mod(mapped, cell.period)
        diff = mapped[:, None, :] - cell.centres[None, :, :]
        diff -= np.round(diff / cell.period) * cell.period
        close = np.all(np.abs(diff) < _TOL * cell.radii.max() * 10, axis=2)
        close &= np.abs(cell.radii[:, None] - cell.radii[None, :]) < _TOL * cell.radii.max()
        return bool(np.all(close.any(axis=1)))

    mirror = all(same(cell.centres * np.where(np.arange(3) == ax, -1.0, 1.0)) for ax in range(3))
    square = bool(abs(cell.period[0] - cell.period[1]) < _TOL * cell.period[0])
    diagonal = square and same(cell.centres[:, [1, 0, 2]])
    half = 0.5 * cell.period[0]
    anti = diagonal and same(np.column_stack([half - cell.centres[:, 1], half - cell.centres[:, 0], cell.centres[:, 2]]))
    return mirror, diagonal, anti


@dataclass
class CellMesh:
    """The meshed computational cell: ``mesh`` straight P1 tetrahedra (inscribed), ``curved`` the isoparametric
    quadratic mesh, ``hot``/``cold`` boundary facet indices (``z = 0`` and ``z = height``), the cross-section
    ``area``, ``wedge`` (the fraction of the box meshed: 1, the half ``y <= x``, or the quarter with also
    ``x + y <= P/2``), the exact and the CAD volume of the solid in the cell."""

    mesh: object
    curved: object
    hot: np.ndarray
    cold: np.ndarray
    height: float
    area: float
    wedge: float
    volume_exact: float
    volume_cad: float
    neck_a: np.ndarray = field(repr=False)


def _local_cluster(cell: PeriodicCell, box: np.ndarray):
    """The particle images whose spheres or necks can reach the box ``[0, box]``, with their bonds, as a
    :class:`fem_neck.cluster.Cluster` (a neck point lies within ``sqrt(2) r_max`` of its nearer centre)."""
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


def build_cell_mesh(cell: PeriodicCell, size_neck: float, size_far: float, curvature: int, grading: float,
                    neck_cells: float = 2.0, method: str = "newton") -> CellMesh:
    """Mesh the computational cell (module docstring): the union of the spheres and necks near it, intersected with
    the box ``[0, P/2]^3`` (or its wedge ``y <= x``), graded toward every neck circle (sizes as in
    :func:`fem_neck.cluster.neck_size_fields`: ``size_neck a`` at the circles, growing by ``grading`` per unit
    distance up to ``size_far r``). Lengths are scaled to the largest radius while meshing."""
    from skfem import MeshTet

    from fem_neck.cluster import add_neck_cylinders, curved_mesh, mesh_tetrahedra, neck_size_fields, tetrahedra
    from fem_neck.shapes import gmsh_session

    mirror, diagonal, anti = mirror_symmetry(cell)
    if not mirror:
        raise ValueError(f"{cell.name}: the packing is not mirror-symmetric about x = 0, y = 0 and z = 0 (modulo the "
                         "period); this FE solves the mirror cell [0, P/2]^3 and needs those mirror planes")
    unit = float(cell.radii.max())
    scaled = PeriodicCell(cell.centres / unit, cell.radii / unit, cell.period / unit, cell.name)
    box = scaled.period / 2.0
    local = _local_cluster(scaled, box)
    geo = local.necks(method)
    tol = 1e-6
    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        solids = [(3, occ.addSphere(*local.centres[k], local.radii[k])) for k in range(local.n)]
        solids += add_neck_cylinders(occ, local, geo)
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
        # the solid may reach the cell in several pieces, joined outside it (see _conducting)
        volume_cad = sum(occ.getMass(3, tag) for _, tag in volume)
        surfaces = [tag for _, tag in gmsh.model.getBoundary(volume, combined=False, oriented=False)]
        neck_size_fields(gmsh, local, geo, surfaces, size_neck, size_far, neck_cells, tol, every_bond=False,
                         grading=grading)
        mesh_tetrahedra(gmsh, curvature, size_far)
        pieces = [tetrahedra(gmsh, tag) for _, tag in volume]
        points, tets = pieces[0][0], np.vstack([piece[1] for piece in pieces])
    tets = _conducting(points, tets, box[2], tol)
    used = np.unique(tets)
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    mesh = MeshTet(points[used].T.copy(), remap[tets].T.copy())
    curved = _untangled(curved_mesh(mesh, local, geo, ()), mesh)
    bf = mesh.boundary_facets()
    fz = mesh.p[2, mesh.facets[:, bf]]
    hot = bf[np.all(np.abs(fz) < tol, axis=0)]
    cold = bf[np.all(np.abs(fz - box[2]) < tol, axis=0)]
    fraction = 0.25 if anti else 0.5 if diagonal else 1.0
    area = box[0] * box[1] * fraction
    volume_exact = cell.phi * area * box[2]
    mesh = MeshTet(mesh.p * unit, mesh.t)
    curved = type(curved)(curved.doflocs * unit, curved.t)
    return CellMesh(mesh, curved, hot, cold, float(box[2] * unit), float(area * unit**2), fraction,
                    float(volume_exact * unit**3), float(volume_cad * unit**3), np.asarray(geo.a) * unit)


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


def _untangled(curved, straight):
    """The curved mesh with the edges of any element whose curved map folds (Jacobian <= 0 at a quadrature point)
    put back straight: on a coarse mesh a thin element next to a curved face can turn inside out, which would make
    the stiffness matrix indefinite."""
    from skfem import Basis, ElementTetP1, MeshTet2

    doflocs = curved.doflocs.copy()
    nv = straight.p.shape[1]
    for _ in range(5):
        mesh = MeshTet2(doflocs, curved.t)
        detj = Basis(mesh, ElementTetP1(), intorder=4).mapping.detDF(Basis(mesh, ElementTetP1(), intorder=4).X)
        bad = np.flatnonzero(np.min(detj, axis=1) <= 0.0)
        if not len(bad):
            return mesh
        edges = np.unique(straight.t2e[:, bad])
        ends = straight.edges[:, edges]
        doflocs[:, nv + edges] = 0.5 * (straight.p[:, ends[0]] + straight.p[:, ends[1]])
    return MeshTet2(doflocs, curved.t)


def _solve_dirichlet(basis, hot_dofs, cold_dofs, rtol: float):
    """``(u, A)``: the Laplace solution with u = 1 on the hot dofs and 0 on the cold ones (AMG-preconditioned CG)."""
    import pyamg
    from skfem import condense
    from skfem.models.poisson import laplace

    A = laplace.assemble(basis).tocsr()
    u = np.zeros(basis.N)
    u[hot_dofs] = 1.0
    Ai, b, _, interior = condense(A, np.zeros(basis.N), x=u, D=np.concatenate([hot_dofs, cold_dofs]))
    ml = pyamg.smoothed_aggregation_solver(Ai.tocsr(), symmetry="symmetric")
    residuals = []
    u[interior] = ml.solve(b, x0=np.full(len(interior), 0.5), tol=rtol, accel="cg", maxiter=2000,
                           residuals=residuals)
    if residuals and residuals[-1] > 100.0 * rtol * max(residuals[0], 1e-300):
        raise RuntimeError(f"the FE system ({len(interior)} unknowns) did not converge: relative residual "
                           f"{residuals[-1] / residuals[0]:.1e} after {len(residuals) - 1} AMG-CG iterations")
    return u, A


@dataclass(frozen=True)
class Bounds:
    """Heat flow bounds of one mesh for a unit temperature difference and kappa = 1 (W/K per W/(m K)): ``upper``
    (P2, curved), ``lower`` (CR flux, straight), the CR flux's largest normal-flux defect relative to its mean flux
    density (admissibility, ~solver tolerance), dofs of both solves, the mesh volume of the curved mesh and the P2
    temperature at the mesh vertices."""

    upper: float
    lower: float
    flux_defect: float
    dofs_p2: int
    dofs_cr: int
    elements: int
    volume_curved: float
    temperature: np.ndarray = field(repr=False)


def solve_bounds(cm: CellMesh, rtol: float = LINEAR_RTOL) -> Bounds:
    """Upper (P2 energy) and lower (CR complementary energy) bounds of the cell's heat flow (module docstring).

    Pieces of the solid that touch neither isothermal face make the systems singular but consistent: conjugate
    gradients keep them at their constant initial value, which carries no heat."""
    from skfem import Basis, ElementTetCR, ElementTetP2, Functional

    p2 = Basis(cm.curved, ElementTetP2())
    u, A = _solve_dirichlet(p2, p2.get_dofs(cm.hot).all(), p2.get_dofs(cm.cold).all(), rtol)
    upper = float(u @ (A @ u))
    volume_curved = float(Functional(lambda w: 1.0 + 0.0 * w.x[0]).assemble(p2))

    cr = Basis(cm.mesh, ElementTetCR())
    v, _ = _solve_dirichlet(cr, cr.get_dofs(cm.hot).all(), cr.get_dofs(cm.cold).all(), rtol)
    mesh = cm.mesh
    q = -cr.interpolate(v).grad[:, :, 0].T                          # (nel, 3): the CR flux, constant per element
    vol = _tet_volumes(mesh)
    energy = float(np.sum(vol * np.sum(q**2, axis=1)))
    # outward flux through each facet of each element, q . n_out |F|; summed per facet it cancels inside
    area, normal, centre = _facet_geometry(mesh)
    t2f = mesh.t2f                                                  # (4, nel)
    inward = mesh.p[:, mesh.t].mean(axis=1)                         # element centroids (3, nel)
    side = np.sign(np.einsum("ife,ife->fe", centre[:, t2f] - inward[:, None, :], normal[:, t2f]))
    out = side * np.einsum("ei,ife->fe", q, normal[:, t2f]) * area[t2f]
    net = np.bincount(t2f.ravel(), out.ravel(), mesh.facets.shape[1])
    boundary = mesh.boundary_facets()
    free = np.setdiff1d(np.arange(mesh.facets.shape[1]), np.concatenate([cm.hot, cm.cold]))
    through = -float(net[cm.hot].sum())                             # heat flow entering at the hot face
    defect = float(np.max(np.abs(net[free])) / (abs(through) / area[cm.hot].sum() * np.median(area[boundary])))
    lower = through**2 / energy
    return Bounds(upper, lower, defect, int(p2.N), int(cr.N), int(mesh.t.shape[1]), volume_curved,
                  u[:mesh.p.shape[1]])


def _tet_volumes(mesh) -> np.ndarray:
    x = mesh.p[:, mesh.t]                                           # (3, 4, nel)
    return np.abs(np.einsum("ie,ie->e", x[:, 1] - x[:, 0], np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 0], axis=0))) / 6


def _facet_geometry(mesh) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Area, (arbitrarily oriented) unit normal and centroid of every facet."""
    x = mesh.p[:, mesh.facets]                                      # (3, 3, nf)
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0], axis=0)
    area = 0.5 * np.linalg.norm(n, axis=0)
    return area, n / (2.0 * area), x.mean(axis=1)


@dataclass
class CellResult:
    """Effective conductivity of a periodic cell (module docstring): the best value ``k_eff_over_kappa`` (P2, the
    upper bound), its bounds, ``error_estimate = (upper - lower) / upper``, the solid fraction ``phi`` (also the
    Wiener bound of ``k_eff / kappa``), and what the last mesh cost."""

    k_eff_over_kappa: float
    k_lower_over_kappa: float
    k_upper_over_kappa: float
    error_estimate: float
    converged: bool
    phi: float
    dofs: int
    elements: int
    levels: list
    seconds: float
    volume_error: float
    flux_defect: float
    mesh: CellMesh | None = field(default=None, repr=False)
    temperature: np.ndarray | None = field(default=None, repr=False)


def level_sizes(level: float) -> dict:
    """Mesh sizes of refinement ``level`` (0 is the coarsest): all lengths shrink by ``LEVEL_FACTOR`` per level."""
    f = LEVEL_FACTOR**level
    size_far = SIZE_FAR0 * f
    return {"size_neck": SIZE_NECK0 * f, "size_far": size_far, "curvature": int(round(2 * math.pi / size_far)),
            "grading": GRADING0 * f}


def effective_conductivity(cell: PeriodicCell, rtol: float = 1e-3, start_level: float = 2.0, max_levels: int = 4,
                           progress=None) -> CellResult:
    """``k_eff / kappa`` along z of the periodic ``cell`` with two-sided bounds (module docstring).

    Starts on the mesh of ``start_level``; while the gap between the bounds exceeds ``rtol`` it predicts the level
    that meets ``rtol`` and solves there, at most ``max_levels`` meshes; meshes above :data:`MAX_ELEMENTS`
    tetrahedra are refused. The prediction takes the gap to fall like size^GAP_ORDER (the CR flux is first order,
    its energy second; measured from the coarse levels: size^1.65 to size^1.8). ``progress(text)`` reports each mesh.
    """
    check_positive("rtol", rtol)
    check_cell(cell)
    t0 = time.perf_counter()
    phi = cell.phi
    level = float(start_level)
    history = []
    for _ in range(max_levels):
        if progress is not None:
            progress(f"level {level:.2f}")
        cm = build_cell_mesh(cell, **level_sizes(level))
        if cm.mesh.t.shape[1] > MAX_ELEMENTS:
            raise ValueError(f"{cell.name}: rtol = {rtol:g} needs more than {MAX_ELEMENTS} tetrahedra "
                             f"(level {level:.2f}); use a larger rtol")
        b = solve_bounds(cm)
        scale = cm.height / cm.area
        upper, lower = b.upper * scale, b.lower * scale
        gap = (upper - lower) / upper
        history.append({"level": level, "elements": b.elements, "k_upper": upper, "k_lower": lower, "gap": gap,
                        "seconds": time.perf_counter() - t0})
        if gap <= rtol:
            break
        # the level that meets rtol, with a 20 % margin
        step = math.log((0.8 * rtol / gap) ** (1.0 / GAP_ORDER)) / math.log(LEVEL_FACTOR)
        grow = LEVEL_FACTOR ** (-3 * step)
        if b.elements * grow > MAX_ELEMENTS:
            raise ValueError(f"{cell.name}: rtol = {rtol:g} needs ~{b.elements * grow:.3g} tetrahedra (the bounds are "
                             f"{gap:.2e} apart on {b.elements}), above the limit of {MAX_ELEMENTS}; use a larger rtol")
        level += max(step, 0.5)
    return CellResult(k_eff_over_kappa=upper, k_lower_over_kappa=lower, k_upper_over_kappa=upper,
                      error_estimate=gap, converged=gap <= rtol, phi=phi, dofs=b.dofs_p2, elements=b.elements,
                      levels=history, seconds=time.perf_counter() - t0,
                      volume_error=b.volume_curved / cm.volume_exact - 1.0, flux_defect=b.flux_defect, mesh=cm,
                      temperature=b.temperature)


def network_conductivity(cell: PeriodicCell, pair_conductance) -> float:
    """``k_zz / kappa`` of the pipe network on the cell's bonds when every particle's temperature follows the
    uniform gradient (exact for lattices, whose bond stars are centrosymmetric): ``sum_b K_b dz_b^2 / |period|``.
    ``pair_conductance(r_i, r_j, a)`` gives the bond conductances for kappa = 1."""
    i, j, s = cell.bonds()
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    d = np.linalg.norm(e, axis=1)
    h = cell.radii[i] + cell.radii[j] - d
    a = neck_geometry(cell.radii[i], cell.radii[j], h).a
    K = np.asarray(pair_conductance(cell.radii[i], cell.radii[j], a), dtype=float)
    return float(np.sum(K * e[:, 2] ** 2) / np.prod(cell.period))


def write_vtu(result: CellResult, path) -> None:
    """The cell's straight mesh with the P2 temperature at its vertices (VTU for ParaView)."""
    import meshio

    mesh = result.mesh.mesh
    meshio.Mesh(mesh.p.T, [("tetra", mesh.t.T)], point_data={"T": result.temperature}).write(str(path))
