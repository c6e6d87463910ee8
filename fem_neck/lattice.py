"""Effective conductivity of periodic packings of sintered spheres: 3D FE of the mirror cell with two-sided bounds.

Geometry. A :class:`PeriodicCell` holds the particles of one period (centres, radii, the period box); every
overlapping pair of particle images is bonded (Rojek 2022, eq. 21) and gets the volume-conserving cylindrical neck of
:func:`fem_neck.geometry.neck_geometry` (eqs. 22-33). The solid is the union of all spheres and all neck cylinders, exactly as
in :mod:`fem_neck.cluster`; it conserves each particle's volume, so the solid volume fraction is
``phi = sum 4/3 pi r^3 / |period|`` exactly. The pair neck model has an answer only while the necks of one particle
stay apart: :func:`check_cell` refuses a cell where two neck circles on one sphere touch (for the cubic lattices from
``a/r = sin(theta/2)``, theta the smallest angle between bonds: SC 90 deg, BCC 70.5 deg, FCC 60 deg; see
:func:`max_h_over_r`).

The union reading (``neck = "union"``). The solid is the union of the spheres: Arzt's (1982) truncated spheres, each
cut by its radical planes (:mod:`fem_neck.geometry.union`), no cylinders. A neck is the circle where two spheres meet
(:class:`UnionNecks`), second neighbours that overlap are necks too, and the necks of one particle may meet; the
model holds up to the overlap at which the spheres fill space (:func:`union_max_h_over_r`), and ``phi`` is the exact
volume of the cut spheres over the period. Its circles are re-entrant edges of interior angle ``pi + 2 arccos(a/r)``
(equal spheres), sharper than a pair neck's, so its first mesh, gap order and mesh prediction are measured on its own
cells (``UNION_*``). Below ``UNION_MIN_H_OVER_R`` the gap between two spheres at their circle is too thin a wedge to
mesh.

The computational cell. A macroscopic gradient along z through a packing that is mirror-symmetric about the planes
``x = 0``, ``y = 0``, ``z = 0`` (hence also about ``x = P_x/2`` etc.) leaves the planes ``z = 0`` and ``z = P_z/2``
isothermal (the temperature fluctuation is odd under the z mirror) and the planes normal to x and y insulated (it
is even under those). The FE therefore solves the box ``[0, P/2]^3`` -- an eighth of the period -- with ``T = 1`` on
``z = 0``, ``T = 0`` on ``z = P_z/2`` and no flux elsewhere; when the packing is also symmetric under ``x <-> y``
(the cubic lattices) only the wedge ``0 <= y <= x`` of that box is solved (a sixteenth), and when also under
``(x, y) -> (P/2 - y, P/2 - x)`` (face-centred cubic) only its half with ``x + y <= P/2``. Then
``k_eff = Q (P_z / 2) / A`` with ``Q`` the heat flow and ``A`` the cell's cross-section, for ``kappa = 1``.

Two bounds (the error estimate). With ``K`` the exact heat flow of the cell for a unit temperature difference, both
are computed on one mesh whose tetrahedra fill the exact solid (:mod:`fem_neck.curved`: every boundary edge and
face mapped onto its sphere, cylinder, plane or their intersection curve), so there is no geometric error:

* **upper**: conforming ``P_p`` elements (:mod:`fem_neck.primal`). By Dirichlet's principle the energy of any
  admissible temperature is at least ``K``.
* **lower**: the hybridised Raviart-Thomas flux of degree ``p - 1`` (:mod:`fem_neck.dual`): divergence-free in every
  element, normal-continuous across faces and zero on the insulated ones, hence admissible in the complementary
  (Thomson) principle: ``K >= P^2 / E*`` with ``P`` the heat it carries through the hot face and ``E* = int |q|^2``.

Both converge at one rate, so ``error_estimate = (upper - lower) / upper`` bounds the error of the reported value
(the upper) and is 2-3 times it (the two errors are about equal, measured on the lattice cells). The bounds hold up
to the quadrature of the curved elements (degree ``2 p``: 2-3e-9 relative at p = 4, measured against ``2 p + 4``)
and round-off, whatever the solvers' residuals: both CGs stop when their energy has settled to ``ALGEBRAIC_SHARE
rtol`` (1e-7 at the default ``rtol``); the energy of any iterate is an upper bound, and the flux of any iterate is
made exactly admissible (:func:`fem_neck.dual.equilibrate`). The mesh is graded toward every neck circle, where the
temperature is singular (``size_neck a`` at the circles, growing by ``GRADING`` per unit distance); it is refined
until the estimate meets ``rtol``, and the memory of each solve is estimated before its mesh is made
(:func:`effective_conductivity`).
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from fem_neck.curved import FoldedMesh
from fem_neck.geometry import check_positive, max_overlap, neck_geometry, overlap_for_neck
from fem_neck.geometry.union import cut_spheres, lens
from sinterheat.threads import one_blas_thread

KINDS = ("sc", "bcc", "fcc")
# the readings of a bond: "newton", the volume-conserving pair neck (Rojek 2022, eqs. 21-33); "union", the union of the
# spheres (module docstring)
NECKS = ("newton", "union")
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
# the smallest overlap of nearest neighbours whose union the mesher takes (module docstring)
UNION_MIN_H_OVER_R = 0.02
# the meshes: element size at the neck circles over the neck radius (the range of first meshes), far size over the
# particle radius, growth of the size per unit distance from the circles
FIRST_SIZES, SIZE_FAR, GRADING = (0.005, 0.3), 0.5, 0.8
# measured on the lattice cells: the gap falls like size_neck^GAP_ORDER; a refined mesh aims at REFINE_MARGIN rtol
# (:func:`effective_conductivity`)
GAP_ORDER, REFINE_MARGIN = 1.25, 0.7
# the solvers' energy tolerance over the requested rtol: the bounds' algebraic error stays ~1e-3 of the gap asked for
# (at rtol 1e-4 the bounds of BCC h/r = 0.02 move by 1.4e-9 and 4e-9 against CGs settled to 1e-9)
ALGEBRAIC_SHARE = 1e-3
# the first mesh (:func:`first_neck_size`), by order p: (size0, rtol0, neck_order, margin): at neck size size0 the
# bounds of a cell whose necks have the mean a/r = NECK0 are about rtol0 apart; larger necks need a coarser mesh, the
# gap falling like (a/r)^-neck_order, used only over NECK_RANGE (not extrapolated to necks smaller than measured);
# the first mesh aims at margin rtol. p = 4: the cubic lattices at h/r = 0.02 (a/r = 0.2) are 0.9-1.1e-4 apart at
# size 0.01, at h/r = 0.08 (a/r = 0.39) 3.3-4.4e-5. p = 3: the cubic lattices at a/r = 0.2 are 1.47-1.68e-3 apart
# at size 0.05 and 4.7-5.7e-4 at 0.0191, at a/r = 0.39 0.70-0.79e-3 and 2.2-2.4e-4; two random packings (mean a/r
# 0.32 and 0.37) were 2.5e-3 and 2.2e-3 apart at 0.087, 1.08 and 1.13 times this rule's gap (inside the margin).
FIRST_MESH = {3: (0.05, 1.9e-3, 1.1, 0.75), 4: (0.01, 1e-4, 1.3, 0.75)}
NECK0, NECK_RANGE = 0.2, (0.2, 0.5)
P3_FROM = 3e-4  # the rtol from which the upper bound is P_3 by default (below, P_4)
# the union reading's first mesh, gap order, neck range and first sizes (as FIRST_MESH, GAP_ORDER, NECK0, NECK_RANGE,
# FIRST_SIZES): its circles are sharper edges (interior angle pi + 2 arccos(a/r)), so its gap falls more slowly with
# the neck size, and it falls with the pore fraction 1 - phi as well (a cell near closure is nearly uniform), like
# ((1 - phi) / UNION_PORE0)^UNION_PORE_ORDER over UNION_PORE_RANGE. Measured on its own cells (SC, BCC, FCC at h/r
# 0.02, 0.2-0.3, 0.3-0.6 and near closure; a/r the mean over all bonds, second neighbours included): per cell the
# gap falls like size^0.83-1.06 (p = 3, BCC h/r = 0.02: 1.49e-2, 6.45e-3, 1.71e-3, 8.25e-4 at 0.1, 0.04, 0.01,
# 0.0042); fitted at gap order 0.94 to the 37 solves at neck sizes 0.0015-0.04, like (a/r)^-0.747 and
# (1 - phi)^0.692. The cells scatter about the fit by 0.2-2.7 (SC 0.2-0.9, FCC 0.7-1.9, BCC 1.1-2.7; random
# packings of phi 0.6 0.3-0.35), so rtol0 is the fit, not the largest: a cell inside 1 / margin of it meets rtol on
# its first mesh, a BCC cell may need a second, and the first mesh's memory is not predicted for the worst cell.
UNION_FIRST_MESH = {3: (0.01, 1.52e-3, 0.747, 0.75), 4: (0.01, 7.03e-4, 0.747, 0.75)}
UNION_GAP_ORDER = 0.94
UNION_NECK0, UNION_NECK_RANGE = 0.141, (0.141, 0.70)
UNION_PORE0, UNION_PORE_ORDER, UNION_PORE_RANGE = 0.3, 0.692, (2e-5, 0.46)
UNION_FIRST_SIZES = (0.001, 0.3)
# the tetrahedra of a mesh predicted before meshing (:func:`predicted_tetrahedra`): the constants fitted to 42 meshes
# (the six cubic cells and two chains at neck sizes 0.005-0.3, a random packing at 0.087 and 0.03), and the margin
# that puts every measured mesh on the safe side: 64 of them (also the other random packings and the first meshes
# of the dense-packing study) were predicted 1.04-1.77 times their tetrahedra
TETRAHEDRA_PER_CIRCLE, TETRAHEDRA_PER_VOLUME, PREDICTION_MARGIN = 315.0, 27.3, 1.3
# the union's, fitted to 27 meshes of the three cubic cells (h/r 0.02-0.6, neck sizes 0.01-0.1): with
# PREDICTION_MARGIN 1.05-2.62 times their tetrahedra (random union packings of 32-80 spheres: 1.9-3.3 times); their
# memory (p = 3 at most 18 kB per tetrahedron beyond the base, also on random packings of up to 109 127 tetrahedra;
# p = 4 at most 52 kB, FCC h/r = 0.02 at 0.01, 17 995 tetrahedra) lies within BYTES_PER_ELEMENT
UNION_TETRAHEDRA_PER_CIRCLE, UNION_TETRAHEDRA_PER_VOLUME = 353.0, 57.7
# peak memory of solve_bounds (both processes): BASE_BYTES + BYTES_PER_ELEMENT[order] * tetrahedra (measured by
# peak_memory, whole runs: p = 4 at most 41 kB per tetrahedron beyond the base on the six cells of SC, BCC, FCC at
# h/r = 0.02 and 0.08; p = 3 at most 18 kB, on the largest random packing of the dense-packing study, 106 027
# tetrahedra; about 1.4 times that here)
BASE_BYTES, BYTES_PER_ELEMENT = 0.5e9, {2: 20e3, 3: 25e3, 4: 60e3}
_TOL = 1e-9  # geometric tolerance in units of the largest radius


@dataclass(frozen=True)
class PeriodicCell:
    """One period of a packing. Every pair of particle images closer than the sum of their radii is bonded (Rojek
    2022, eq. 21).

    Parameters
    ----------
    centres : numpy.ndarray
        Particle centres (n, 3), m, wrapped into ``[0, period)``.
    radii : numpy.ndarray
        Particle radii (n,), m.
    period : numpy.ndarray
        Edges of the period box (3,), m.
    name : str
        Name of the cell in messages.
    neck : str
        How bonds are read (``NECKS``): ``"newton"``, the volume-conserving pair necks (Rojek 2022, eqs. 21-33);
        ``"union"``, the union of the spheres (module docstring).
    """

    centres: np.ndarray
    radii: np.ndarray
    period: np.ndarray
    name: str = "cell"
    neck: str = "newton"

    def __post_init__(self):
        if self.neck not in NECKS:
            raise ValueError(f"neck = {self.neck!r}: must be one of {', '.join(NECKS)}")
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
        """Number of particles in the period."""
        return len(self.radii)

    @property
    def phi(self) -> float:
        """Solid volume fraction ``sum 4/3 pi r^3 / |period|`` (exact: the necks conserve each particle's volume);
        read as the union of the spheres, the sum of the volumes of the spheres cut by their radical planes over
        ``|period|`` (:func:`fem_neck.geometry.union.cut_spheres`, exact)."""
        if self.neck == "union":
            i, j, s = self.bonds()
            vectors = self.centres[j] + s * self.period - self.centres[i]
            return float(np.sum(cut_spheres(self.radii, i, j, vectors).volume) / np.prod(self.period))
        return float(np.sum(4.0 / 3.0 * np.pi * self.radii**3) / np.prod(self.period))

    def images(self, lo, hi) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every image ``c_k + n P`` with its centre in the box ``[lo, hi]``: ``(centres, owner k, shift n)``.

        Parameters
        ----------
        lo, hi : array_like
            Corners ``(3,)`` of the box, m.
        """
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


def lattice_cell(kind: str, h_over_r: float, radius: float = 1.0, neck: str = "newton") -> PeriodicCell:
    """The cubic cell of a simple cubic, body-centred or face-centred cubic lattice of equal spheres.

    Parameters
    ----------
    kind : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.
    h_over_r : float
        Overlap of nearest neighbours over the radius (neighbour distance ``2r - h``); the valid range of each
        reading: :func:`check_h_over_r`.
    radius : float
        Particle radius, m.
    neck : str
        How bonds are read (``NECKS``, :class:`PeriodicCell`).
    """
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r}: must be one of {', '.join(KINDS)}")
    if neck not in NECKS:
        raise ValueError(f"neck = {neck!r}: must be one of {', '.join(NECKS)}")
    check_positive("radius", radius)
    check_h_over_r(kind, h_over_r, neck)
    edge = EDGE_OVER_SPACING[kind] * (2.0 - h_over_r) * radius
    basis = np.asarray(BASIS[kind]) * edge
    return PeriodicCell(basis, np.full(len(basis), float(radius)), np.full(3, edge), name=kind, neck=neck)


def max_neck_ratio(kind: str) -> float:
    """Largest ``a/r`` of a cubic lattice: the neck circles of one particle touch at ``a/r = sin(theta/2)``.

    Parameters
    ----------
    kind : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.
    """
    return math.sin(BOND_ANGLE[kind] / 2.0)


def max_h_over_r(kind: str) -> float:
    """``h/r`` at which the necks of one particle of the lattice touch (SC 0.2761, BCC 0.1774, FCC 0.1308).

    Parameters
    ----------
    kind : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.
    """
    return overlap_for_neck(1.0, 1.0, max_neck_ratio(kind))


def union_max_h_over_r(kind: str) -> float:
    """``h/r`` at which the union of the lattice's spheres fills space: the neighbour distance at which the radius
    is the lattice's covering radius (SC: the cube's half diagonal, ``d = 2r / sqrt(3)``, h/r = 0.8453; BCC: ``sqrt(5)
    / 4`` of the cube edge, ``d = 2 sqrt(3 / 5) r``, 0.4508; FCC: half the cube edge, ``d = sqrt(2) r``, 0.5858).

    Parameters
    ----------
    kind : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.
    """
    covering = {"sc": math.sqrt(3.0) / 2.0, "bcc": math.sqrt(5.0) / 4.0, "fcc": 0.5}[kind]  # over the cube edge
    return 2.0 - 1.0 / (covering * EDGE_OVER_SPACING[kind])


def union_neck_ratio(h_over_r: float) -> float:
    """``a/r`` of the circle where two equal spheres meet: ``a^2 = r h - h^2 / 4`` (:func:`fem_neck.geometry.union.lens`
    at ``d = 2r - h``).

    Parameters
    ----------
    h_over_r : float
        Their overlap over the radius, ``0 < h/r < 2``.
    """
    return float(lens(1.0, 1.0, 2.0 - h_over_r).a)


def check_h_over_r(kind: str, h_over_r: float, neck: str = "newton") -> float:
    """``h_over_r`` if the lattice's necks exist (and are not too small to mesh) and, read as pair necks, stay apart,
    or, read as the union of the spheres, leave pores open (:func:`union_max_h_over_r`); else ValueError.

    Parameters
    ----------
    kind : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.
    h_over_r : float
        Overlap of nearest neighbours over the radius.
    neck : str
        How bonds are read (``NECKS``).
    """
    if neck == "union":
        low, high = UNION_MIN_H_OVER_R, union_max_h_over_r(kind)
        if not (isinstance(h_over_r, (int, float)) and low <= h_over_r < high):
            raise ValueError(f"h_over_r = {h_over_r!r}: valid range {low:.6g} <= h/r < {high:.6g} for the union "
                             f"of the {kind} lattice's spheres (from h/r = {high:.6g} they fill space; below "
                             f"{low:.6g} the gap between the spheres at their circles is too thin to mesh)")
        return float(h_over_r)
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
    """Raise ``ValueError`` unless some particles overlap and, read as pair necks, every bond's overlap lies in the
    neck model's range and no two necks of one particle touch (their circles, of angular radius ``arcsin(a/r)``,
    must stay apart on the sphere), or, read as the union of the spheres, no sphere lies inside another.

    Parameters
    ----------
    cell : PeriodicCell
        The cell.
    method : str
        Neck model of the pair reading (:func:`fem_neck.geometry.neck_radius`).
    """
    i, j, s = cell.bonds()
    if not len(i):
        raise ValueError(f"{cell.name}: no two particles overlap, so nothing conducts")
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    d = np.linalg.norm(e, axis=1)
    e = e / d[:, None]
    r_i, r_j = cell.radii[i], cell.radii[j]
    if cell.neck == "union":
        inside = np.flatnonzero(d <= np.abs(r_i - r_j))
        if inside.size:
            b = int(inside[0])
            raise ValueError(f"{cell.name}: particle {i[b] if r_i[b] < r_j[b] else j[b]} lies inside particle "
                             f"{j[b] if r_i[b] < r_j[b] else i[b]} (centres {d[b]:.6g} apart, radii {r_i[b]:.6g} and "
                             f"{r_j[b]:.6g}): it is no particle of the union")
        return
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
    ``(x, y) -> (P/2 - y, P/2 - x)`` (the face-centred cubic lattice).

    Parameters
    ----------
    cell : PeriodicCell
        The cell.
    """

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
    """The meshed computational cell (:func:`build_cell_mesh`). Lengths in units of the largest radius ``unit``.

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
        The fraction of the half-period box meshed: 1, 1/2 (the wedge ``y <= x``) or 1/4 (with also
        ``x + y <= P/2``).
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
    """The particle images whose spheres or necks can reach the box ``[0, box]``, with their bonds, as a
    :class:`fem_neck.cluster.Cluster` (a neck point lies within ``sqrt(2) r_max`` of its nearer centre).

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
    """What the mesh of a cell is built from, before any meshing. Lengths in units of ``unit``.

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
        Whether it is also cut by ``x + y <= P/2`` (the face-centred cubic symmetry).
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


def _cell_frame(cell: PeriodicCell, method: str = "newton") -> CellFrame:
    """The :class:`CellFrame` of ``cell``; ``ValueError`` unless it is mirror-symmetric (module docstring)."""
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


@dataclass(frozen=True)
class NeckCircles:
    """The neck circles on the boundary of a cell's solid, for predicting its mesh before meshing
    (:func:`predicted_tetrahedra`). Lengths in units of the largest radius.

    Parameters
    ----------
    a : numpy.ndarray
        Radius of each circle.
    h_n : numpy.ndarray
        Length of its neck (``inf`` for the union's circles, which no neck length limits).
    r_min : numpy.ndarray
        The smaller radius of its pair.
    fraction : numpy.ndarray
        The fraction of the circle inside the computational cell and on the solid's boundary.
    solid_volume : float
        Volume of the solid in the computational cell.
    neck : str
        The cell's reading (``NECKS``): which constants predict its mesh.
    """

    a: np.ndarray
    h_n: np.ndarray
    r_min: np.ndarray
    fraction: np.ndarray
    solid_volume: float
    neck: str = "newton"


def neck_circles(cell: PeriodicCell, samples: int = 360) -> NeckCircles:
    """The :class:`NeckCircles` of ``cell``: each bond's two circles sampled at ``samples`` points, the fraction
    of them inside the computational cell and inside no other particle (there the circle is not on the boundary).

    Parameters
    ----------
    cell : PeriodicCell
        The cell.
    samples : int
        Points per circle.
    """
    frame = _cell_frame(cell)
    local, geo, e = frame.local, frame.geo, frame.e
    c, r = local.centres, local.radii
    bi, bj = local.bonds.T
    union = cell.neck == "union"
    slack = _TOL if union else 0.0  # a union's circle may lie on a mirror plane, a face of the cell
    helper = np.where(np.abs(e[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(e, helper)
    u /= np.linalg.norm(u, axis=1)[:, None]
    v = np.cross(e, u)
    angle = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    ring = np.cos(angle)[None, :, None] * u[:, None, :] + np.sin(angle)[None, :, None] * v[:, None, :]
    fractions = []
    ends = (geo.z_i,) if union else (geo.z_i, geo.z_i + geo.h_n)
    for z in ends:
        points = (c[bi] + z[:, None] * e)[:, None, :] + geo.a[:, None, None] * ring  # (bonds, samples, 3)
        inside = np.ones(points.shape[:2], dtype=bool)
        for n, d in frame.halfspaces:
            inside &= points @ n <= d + slack
        for k in range(len(r)):
            covered = np.linalg.norm(points - c[k], axis=2) < r[k] * (1.0 - 1e-9)
            inside &= ~(covered & ((bi != k) & (bj != k))[:, None])
        fractions.append(inside.mean(axis=1))
    h_n = np.full(len(bi), np.inf) if union else geo.h_n  # a union's circle: no neck length limits its size
    a, h_n, r_min = (np.tile(np.asarray(x, dtype=float), len(ends)) for x in (geo.a, h_n, np.minimum(r[bi], r[bj])))
    return NeckCircles(a, h_n, r_min, np.concatenate(fractions), frame.solid_volume, cell.neck)


def predicted_tetrahedra(circles: NeckCircles, size_neck: float) -> float:
    """Tetrahedra of the mesh of neck size ``size_neck`` (:func:`mesh_sizes`), predicted before meshing, on the
    safe side. A mesh of local size ``h(x)`` has about ``int dV / h^3`` tetrahedra up to a constant. Around a neck
    circle of radius ``a`` the size is ``s + GRADING rho`` at the distance ``rho`` (``s = min(size_neck a, h_n)``,
    :func:`fem_neck.cluster.neck_size_fields`) up to ``U = SIZE_FAR r_min``, so the circle adds
    ``a (1 / (2 s) - 1 / U + s / (2 U^2))`` times a constant (the solid's angle around it over ``GRADING^2``);
    the rest of the solid adds its volume over ``SIZE_FAR^3``. The two constants are measured
    (``TETRAHEDRA_PER_CIRCLE``, ``TETRAHEDRA_PER_VOLUME``), times ``PREDICTION_MARGIN``.

    Parameters
    ----------
    circles : NeckCircles
        The cell's neck circles (:func:`neck_circles`).
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless).
    """
    s = np.minimum(size_neck * circles.a, circles.h_n)
    far = SIZE_FAR * circles.r_min
    near = np.where(s < far, circles.a * (0.5 / s - 1.0 / far + 0.5 * s / far**2), 0.0)
    per_circle, per_volume = ((UNION_TETRAHEDRA_PER_CIRCLE, UNION_TETRAHEDRA_PER_VOLUME) if circles.neck == "union"
                              else (TETRAHEDRA_PER_CIRCLE, TETRAHEDRA_PER_VOLUME))
    return PREDICTION_MARGIN * (per_circle * float(np.sum(circles.fraction * near))
                                + per_volume * circles.solid_volume / SIZE_FAR**3)


def build_cell_mesh(cell: PeriodicCell, size_neck: float, size_far: float, grading: float,
                    curvature: int = 12, neck_cells: float = 1.0, method: str = "newton") -> CellMesh:
    """Mesh the computational cell (module docstring): the union of the spheres and necks that reach it, cut to the
    cell, graded toward every neck circle (``size_neck a`` at the circles, growing by ``grading`` per unit
    distance up to ``size_far r``; :func:`fem_neck.cluster.neck_size_fields`), its boundary classified onto the
    exact spheres, cylinders and planes (:mod:`fem_neck.curved`). Lengths are scaled to the largest radius.

    Parameters
    ----------
    cell : PeriodicCell
        The cell (validated by :func:`check_cell`).
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless).
    size_far : float
        Largest element size over the particle radius (dimensionless).
    grading : float
        Growth of the element size per unit distance from a neck circle (dimensionless).
    curvature : int
        gmsh's elements per 2 pi of surface curvature.
    neck_cells : float
        Elements along a neck's length at least.
    method : str
        Neck model of the pair reading (:func:`fem_neck.geometry.neck_radius`).
    """
    from fem_neck import curved
    from fem_neck.cluster import mesh_tetrahedra, neck_size_fields, tetrahedra
    from fem_neck.shapes import gmsh_session

    frame = _cell_frame(cell, method)
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


@dataclass(frozen=True)
class Bounds:
    """Both bounds of one mesh (:func:`solve_bounds`), as ``k / kappa`` of the cell (dimensionless).

    Parameters
    ----------
    upper : float
        Upper bound (``P_p`` energy, :mod:`fem_neck.primal`).
    lower : float
        Lower bound (``RT_(p-1)`` flux, :mod:`fem_neck.dual`).
    flux_defect : float
        The flux's largest normal-flux jump relative to its mean flux per hot face (admissibility; round-off).
    dofs_upper, dofs_lower : int
        Unknowns of the two solves.
    elements : int
        Tetrahedra of the mesh.
    volume_error : float
        The mapped mesh's volume over the exact one, minus 1 (dimensionless).
    seconds : float
        Wall time of both solves, s.
    """

    upper: float
    lower: float
    flux_defect: float
    dofs_upper: int
    dofs_lower: int
    elements: int
    volume_error: float
    seconds: float

    @property
    def gap(self) -> float:
        """``(upper - lower) / upper``: the relative error bound (dimensionless)."""
        return (self.upper - self.lower) / self.upper


def _dual(mesh, order: int, hot, cold, etol: float, temperature):
    """The lower bound, its CG started from the trace of the upper bound's temperature (``temperature()``, called
    once the face system is assembled)."""
    from fem_neck import dual

    def start():
        return dual.trace_multipliers(mesh, order, temperature(), order - 1)

    with one_blas_thread():  # the dense work is many small products (see fem_neck.spectral.conductance)
        return dual.solve(mesh, order - 1, hot, cold, etol, start=start)


_TEMPERATURES = None  # in the lower bound's process: the queue on which the upper bound's temperature arrives


def _receive_temperatures(queue) -> None:
    """Initializer of the lower bound's process: the queue of the upper bound's temperature; the process ends with
    its parent (:func:`sinterheat.pool.end_with_parent`: killed outright, the parent would leave it waiting on the
    queue for ever, holding the mesh)."""
    from sinterheat.pool import end_with_parent

    global _TEMPERATURES
    _TEMPERATURES = queue
    end_with_parent()


def _dual_receiving(mesh, order: int, hot, cold, etol: float):
    return _dual(mesh, order, hot, cold, etol, _TEMPERATURES.get)


def solve_bounds(cm: CellMesh, order: int = 4, workers: int = 2, etol: float | None = None) -> Bounds:
    """Upper and lower bound of the cell's ``k / kappa`` on the mesh ``cm`` (module docstring), the two solves in
    parallel processes when ``workers >= 2`` (the lower bound assembles its system while the upper bound solves,
    then starts its CG from the upper bound's temperature). Both integrate the curved elements at the same points,
    where the elements are mapped once. Both CGs stop when their energy has settled to ``etol`` (default
    ``fem_neck.primal.ENERGY_RTOL``).

    Parameters
    ----------
    cm : CellMesh
        The meshed cell.
    order : int
        Order ``p`` of the upper bound (the lower bound's flux has degree ``p - 1``).
    workers : int
        Processes: 2 or more runs the two bounds side by side, 1 one after the other.
    etol : float, optional
        Relative energy tolerance of both CGs (dimensionless).
    """
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    from fem_neck import primal
    from fem_neck.simplex import tet_quadrature

    t0 = time.perf_counter()
    etol = primal.ENERGY_RTOL if etol is None else etol
    mesh = cm.curved
    mesh.keep_jacobians(tet_quadrature(primal.quadrature_degree(order))[0])   # = dual's quadrature_degree(order)
    try:
        if workers >= 2:
            context = get_context("fork")
            queue = context.Queue()      # put does not wait for the reader (which may have failed before reading)
            queue.cancel_join_thread()   # nor does the exit, if it never read
            pool = ProcessPoolExecutor(1, mp_context=context, initializer=_receive_temperatures, initargs=(queue,))
        else:
            pool = contextlib.nullcontext()
        with pool:
            future = pool.submit(_dual_receiving, mesh, order, cm.hot, cm.cold, etol) if workers >= 2 else None
            with one_blas_thread():
                up = primal.solve(mesh, order, cm.hot, cm.cold, etol)
                if future is not None:
                    queue.put(up.u)
                volume = primal.volume(mesh)  # (while the lower bound finishes in its process)
            low = future.result() if future is not None else _dual(mesh, order, cm.hot, cm.cold, etol, lambda: up.u)
    finally:  # the kept Jacobians (a few hundred MB on a fine mesh) go with the solves, also when one fails
        mesh.keep_jacobians(None)
    scale = cm.height / cm.area
    return Bounds(float(up.energy * scale), float(low.lower * scale), float(low.flux_defect), int(up.dofs),
                  int(low.dofs), len(mesh.tets), float(volume / cm.volume_exact - 1.0), time.perf_counter() - t0)


@dataclass
class CellResult:
    """Effective conductivity of a periodic cell (module docstring, :func:`effective_conductivity`); the values are
    the last mesh's. Conductivities are over the particles' ``kappa`` (dimensionless).

    Parameters
    ----------
    k_eff_over_kappa : float
        The best value: the ``P_p`` upper bound.
    k_lower_over_kappa, k_upper_over_kappa : float
        The two bounds.
    error_estimate : float
        ``(upper - lower) / upper`` (dimensionless).
    converged : bool
        Whether ``error_estimate`` met the tolerance asked for.
    phi : float
        Solid volume fraction (also the Wiener bound of ``k_eff / kappa``).
    order : int
        Order ``p`` of the upper bound's elements.
    dofs : int
        Unknowns of the upper bound's solve.
    elements : int
        Tetrahedra of the mesh.
    levels : list of dict
        Every mesh solved: ``size_neck``, ``elements``, ``k_upper``, ``k_lower``, ``gap`` and ``seconds`` (wall time
        since the start, s).
    seconds : float
        Wall time of the whole computation, s.
    volume_error : float
        The mapped mesh's volume over the exact one, minus 1.
    flux_defect : float
        The lower bound's flux defect (:class:`Bounds`).
    memory_estimate : float
        Estimated peak memory of the last solve, bytes (:func:`memory_estimate`).
    mesh : CellMesh, optional
        The last mesh.
    """

    k_eff_over_kappa: float
    k_lower_over_kappa: float
    k_upper_over_kappa: float
    error_estimate: float
    converged: bool
    phi: float
    order: int
    dofs: int
    elements: int
    levels: list
    seconds: float
    volume_error: float
    flux_defect: float
    memory_estimate: float
    mesh: CellMesh | None = field(default=None, repr=False)


def mesh_sizes(size_neck: float) -> dict:
    """The mesh of neck size ``size_neck`` (element size at the neck circles over the neck radius): far size and
    grading fixed (``SIZE_FAR``, ``GRADING``).

    Parameters
    ----------
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless).
    """
    return {"size_neck": size_neck, "size_far": SIZE_FAR, "grading": GRADING}


def memory_estimate(elements: float, order: int) -> float:
    """Peak bytes of one :func:`solve_bounds` on ``elements`` tetrahedra (both processes; measured, see
    ``BYTES_PER_ELEMENT``).

    Parameters
    ----------
    elements : float
        Tetrahedra of the mesh.
    order : int
        Order of the upper bound: 2, 3 or 4.
    """
    return BASE_BYTES + BYTES_PER_ELEMENT[order] * elements


def peak_memory() -> float:
    """Peak resident bytes of this process plus the largest of its finished children (the lower-bound solves): at
    least what the run held at any one time."""
    import resource

    kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss + resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return kib * 1024.0


def available_memory() -> float:
    """Bytes the machine can still give (``MemAvailable``), or all of its memory where that is unknown."""
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def mean_neck_ratio(cell: PeriodicCell) -> float:
    """The mean ``a / r`` of the cell's bonds (``r`` the smaller radius of the pair; ``a`` the neck's radius, or the
    radius of the circle where the spheres meet, read as their union).

    Parameters
    ----------
    cell : PeriodicCell
        The packing.
    """
    i, j, s = cell.bonds()
    d = np.linalg.norm(cell.centres[j] + s * cell.period - cell.centres[i], axis=1)
    r_i, r_j = cell.radii[i], cell.radii[j]
    a = lens(r_i, r_j, d).a if cell.neck == "union" else neck_geometry(r_i, r_j, r_i + r_j - d).a
    return float(np.mean(a / np.minimum(r_i, r_j)))


def _rule(neck: str) -> tuple:
    """``(FIRST_MESH, GAP_ORDER, NECK0, NECK_RANGE, FIRST_SIZES)`` of the reading ``neck`` (the union's:
    ``UNION_*``)."""
    if neck == "union":
        return UNION_FIRST_MESH, UNION_GAP_ORDER, UNION_NECK0, UNION_NECK_RANGE, UNION_FIRST_SIZES
    return FIRST_MESH, GAP_ORDER, NECK0, NECK_RANGE, FIRST_SIZES


def _neck_factor(neck_ratio: float, order: int, neck: str = "newton", pore: float = UNION_PORE0) -> float:
    """How much coarser than at ``NECK0`` a mesh may be for the same gap when the mean neck is ``neck_ratio`` (and,
    read as the union, the pore fraction ``pore`` rather than ``UNION_PORE0``)."""
    first_mesh, gap_order, neck0, neck_range, _ = _rule(neck)
    neck_order = first_mesh[order][2]
    factor = (float(np.clip(neck_ratio, *neck_range)) / neck0) ** (neck_order / gap_order)
    if neck == "union":
        factor *= (float(np.clip(pore, *UNION_PORE_RANGE)) / UNION_PORE0) ** (-UNION_PORE_ORDER / gap_order)
    return factor


def first_neck_size(rtol: float, neck_ratio: float, order: int, neck: str = "newton",
                    pore: float = UNION_PORE0) -> float:
    """Neck size of the first mesh of a cell: the size whose gap is predicted at ``margin rtol`` (``FIRST_MESH``:
    ``rtol0`` at ``size0`` for ``a / r = NECK0``, the gap falling like ``size^GAP_ORDER`` and like ``(a /
    r)^-neck_order``; the union's ``UNION_*``, its gap also falling with the pore fraction), within ``FIRST_SIZES``.

    Parameters
    ----------
    rtol : float
        Relative gap of the bounds asked for.
    neck_ratio : float
        The cell's mean ``a / r`` (:func:`mean_neck_ratio`).
    order : int
        Order of the upper bound (3 or 4).
    neck : str
        The cell's reading (``NECKS``).
    pore : float
        The cell's pore fraction ``1 - phi`` (read as the union only).
    """
    first_mesh, gap_order, _, _, first_sizes = _rule(neck)
    size0, rtol0, _, margin = first_mesh[order]
    size = size0 * (margin * rtol / rtol0) ** (1.0 / gap_order) * _neck_factor(neck_ratio, order, neck, pore)
    return float(np.clip(size, *first_sizes))


def first_rtol(size: float, neck_ratio: float, order: int, neck: str = "newton", pore: float = UNION_PORE0) -> float:
    """The ``rtol`` whose first mesh (:func:`first_neck_size`) has the neck size ``size``.

    Parameters
    ----------
    size : float
        Element size at the neck circles over their radius.
    neck_ratio, order, neck, pore
        As for :func:`first_neck_size`.
    """
    first_mesh, gap_order, _, _, _ = _rule(neck)
    size0, rtol0, _, margin = first_mesh[order]
    return rtol0 * (size / (size0 * _neck_factor(neck_ratio, order, neck, pore))) ** gap_order / margin


def _size_that_fits(circles: NeckCircles, calibration: float, order: int, budget: float) -> float | None:
    """The finest neck size (down to a fiftieth of the reading's ``FIRST_SIZES``' finest) whose solve fits in
    ``budget`` bytes (``calibration`` times its :func:`predicted_tetrahedra`), or ``None`` if not even the coarsest
    does."""
    def fits(size):
        return memory_estimate(calibration * predicted_tetrahedra(circles, size), order) <= budget

    first_sizes = _rule(circles.neck)[4]
    lo, hi = first_sizes[0] / 50.0, first_sizes[1]
    if not fits(hi):
        return None
    if fits(lo):
        return lo
    for _ in range(60):  # bisection in log size: the predicted tetrahedra fall as the size grows
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return hi


def _check_fits(cell: PeriodicCell, circles: NeckCircles, size: float, calibration: float, order: int,
                budget: float, what: str, rtol_at) -> None:
    """``ValueError`` unless the solve on the mesh of neck size ``size`` (``calibration`` times its
    :func:`predicted_tetrahedra`) fits in ``budget`` bytes, naming ``what`` it is, the estimate and the rtol that
    would fit (``rtol_at(size)`` of the finest size that fits)."""
    elements = calibration * predicted_tetrahedra(circles, size)
    need = memory_estimate(elements, order)
    if need <= budget:
        return
    fit = _size_that_fits(circles, calibration, order, budget)
    if fit is None:
        coarsest = _rule(circles.neck)[4][1]
        need = memory_estimate(calibration * predicted_tetrahedra(circles, coarsest), order)
        tail = f"no rtol fits: even neck size {coarsest:g} a needs ~{need / 1e9:.1f} GB"
    else:
        tail = f"rtol = {rtol_at(fit):.1e} would fit"
    raise ValueError(f"{cell.name}: {what} (neck size {size:.3g} a, ~{elements:.0f} tetrahedra) needs "
                     f"~{need / 1e9:.1f} GB, more than the {budget / 1e9:.1f} GB available; {tail}")


def default_order(rtol: float) -> int:
    """The order of the upper bound for ``rtol`` unless one is given: 3 from ``P3_FROM`` up, else 4.

    Parameters
    ----------
    rtol : float
        The relative error asked for (dimensionless).
    """
    return 3 if rtol >= P3_FROM else 4


def _refined_rtol(gap: float, size: float, new: float, neck: str = "newton") -> float:
    """The ``rtol`` whose refinement from a mesh of neck size ``size`` with the bounds ``gap`` apart goes to the
    neck size ``new`` (the inverse of the refinement rule of :func:`effective_conductivity`)."""
    return gap * (new / size) ** _rule(neck)[1] / REFINE_MARGIN


def effective_conductivity(cell: PeriodicCell, rtol: float = 1e-4, order: int | None = None,
                           max_memory: float | None = None, max_meshes: int = 4, workers: int = 2,
                           progress=None) -> CellResult:
    """``k_eff / kappa`` along z of the periodic ``cell`` with two-sided bounds (module docstring).

    The first mesh has the neck size :func:`first_neck_size` (from ``rtol`` and the cell's mean neck); while
    the bounds are more than ``rtol`` apart it predicts the neck size that meets ``rtol`` (the gap falls like
    ``size_neck^GAP_ORDER``) and solves there, at most ``max_meshes`` meshes. Before each mesh is made, its
    tetrahedra are predicted (:func:`predicted_tetrahedra`, on the safe side; from the second mesh on scaled up
    if a mesh had more) and the memory of its solve estimated (:func:`memory_estimate`): one that would not fit in
    ``max_memory`` bytes (default: what the machine has available) is refused with a ``ValueError`` naming the
    estimate and the ``rtol`` that would fit. A mesh too coarse for the curvature of its surfaces (a curved element
    folds, :class:`fem_neck.curved.FoldedMesh`) is followed by one twice as fine.

    Parameters
    ----------
    cell : PeriodicCell
        The packing, mirror-symmetric about x = 0, y = 0 and z = 0; its bonds read as ``cell.neck``.
    rtol : float
        Relative gap ``(upper - lower) / upper`` of the bounds to reach.
    order : int, optional
        Order of the upper bound, 3 or 4 (default :func:`default_order`).
    max_memory : float, optional
        Bytes the solves may use (default: what the machine has available).
    max_meshes : int
        Most meshes solved.
    workers : int
        2: the two bounds in parallel processes; 1: one after the other.
    progress : callable, optional
        ``progress(text)`` reports each mesh.
    """
    check_positive("rtol", rtol)
    check_cell(cell)
    explicit = order is not None
    order = order or default_order(rtol)
    if order not in FIRST_MESH:  # (solve_bounds takes p = 2 too; its first mesh is not measured)
        raise ValueError(f"order = {order!r}: must be one of {', '.join(map(str, FIRST_MESH))} (the orders whose "
                         f"first mesh is sized from measurements)")
    budget = available_memory() if max_memory is None else float(max_memory)
    t0 = time.perf_counter()
    neck = mean_neck_ratio(cell)
    circles = neck_circles(cell)
    pore = 1.0 - cell.phi
    size = first_neck_size(rtol, neck, order, cell.neck, pore)
    gap_order = _rule(cell.neck)[1]
    calibration = 1.0  # tetrahedra meshed over predicted, where a mesh had more than predicted

    def first_fit(fit: float) -> float:
        """The rtol whose first mesh is the finest that fits, at the order that rtol gets (unless one was given)."""
        reach = first_rtol(fit, neck, order, cell.neck, pore)
        if not explicit and default_order(reach) != order:  # p = 4 does not fit, p = 3 from P3_FROM does
            reach = max(first_rtol(_size_that_fits(circles, calibration, 3, budget), neck, 3, cell.neck, pore),
                        P3_FROM)
        return reach

    what, rtol_at = "the first mesh", first_fit
    history = []
    for level in range(max_meshes):
        _check_fits(cell, circles, size, calibration, order, budget, what, rtol_at)
        if progress is not None:
            progress(f"neck size {size:.3g} a")
        cm = build_cell_mesh(cell, **mesh_sizes(size))
        calibration = max(calibration, len(cm.curved.tets) / predicted_tetrahedra(circles, size))
        _check_fits(cell, circles, size, calibration, order, budget, what, rtol_at)
        try:
            b = solve_bounds(cm, order, workers, ALGEBRAIC_SHARE * rtol)
        except FoldedMesh:  # too coarse for the curvature of its surfaces (seen on random union packings)
            if level == max_meshes - 1:
                raise
            what = f"the mesh of neck size {size:.3g} a folds a curved element; the mesh twice as fine"
            size /= 2.0
            continue
        history.append({"size_neck": size, "elements": b.elements, "k_upper": b.upper, "k_lower": b.lower,
                        "gap": b.gap, "seconds": time.perf_counter() - t0})
        if b.gap <= rtol:
            break
        # the neck size that meets REFINE_MARGIN rtol, at least 1.5x finer, at most 8x
        new = size * min(max((REFINE_MARGIN * rtol / b.gap) ** (1.0 / gap_order), 1.0 / 8.0), 1.0 / 1.5)
        what = (f"rtol = {rtol:g} needs a finer mesh than the {b.elements} tetrahedra whose bounds are {b.gap:.2e} "
                f"apart; that mesh")
        rtol_at = functools.partial(_refined_rtol, b.gap, size, neck=cell.neck)
        size = new
    return CellResult(k_eff_over_kappa=b.upper, k_lower_over_kappa=b.lower, k_upper_over_kappa=b.upper,
                      error_estimate=b.gap, converged=bool(b.gap <= rtol), phi=cell.phi, order=order, dofs=b.dofs_upper,
                      elements=b.elements, levels=history, seconds=time.perf_counter() - t0,
                      volume_error=b.volume_error, flux_defect=b.flux_defect,
                      memory_estimate=memory_estimate(b.elements, order), mesh=cm)


def network_conductivity(cell: PeriodicCell, pair_conductance) -> float:
    """``k_zz / kappa`` of the pipe network on the cell's bonds when every particle's temperature follows the
    uniform gradient (exact for lattices, whose bond stars are centrosymmetric): ``sum_b K_b dz_b^2 / |period|``.
    ``pair_conductance(r_i, r_j, a)`` gives the bond conductances for kappa = 1.

    Parameters
    ----------
    cell : PeriodicCell
        The cell (pair reading).
    pair_conductance : callable
        ``(r_i, r_j, a) -> K`` in W/K for ``kappa`` = 1 W/(m K), vectorised (e.g. a partial of
        :func:`fem_neck.law.pair_conductance`).
    """
    i, j, s = cell.bonds()
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    d = np.linalg.norm(e, axis=1)
    h = cell.radii[i] + cell.radii[j] - d
    a = neck_geometry(cell.radii[i], cell.radii[j], h).a
    K = np.asarray(pair_conductance(cell.radii[i], cell.radii[j], a), dtype=float)
    return float(np.sum(K * e[:, 2] ** 2) / np.prod(cell.period))


def write_vtu(result: CellResult, path) -> None:
    """The cell's mesh (straight tetrahedra, vertices on the exact surfaces) for ParaView (VTU).

    Parameters
    ----------
    result : CellResult
        A result that kept its ``mesh``.
    path : str or pathlib.Path
        The ``.vtu`` file to write.
    """
    import meshio

    mesh = result.mesh.curved
    unit = result.mesh.unit
    meshio.Mesh(mesh.points * unit, [("tetra", mesh.tets)]).write(str(path))
