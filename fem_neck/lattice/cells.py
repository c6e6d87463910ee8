"""Periodic cells of sintered spheres and their bonds: the packing of one period (:class:`PeriodicCell`), the cubic
lattices (:func:`lattice_cell`), the overlaps each reading of a bond allows and the checks that refuse a cell the
model has no answer for (:mod:`fem_neck.lattice`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fem_neck.geometry import check_positive, max_overlap, neck_geometry, overlap_for_neck
from fem_neck.geometry.union import cut_spheres, lens

KINDS = ("sc", "bcc", "fcc")
# the readings of a bond: "newton", the volume-conserving pair neck (Rojek 2022, eqs. 21-33); "union", the union of the
# spheres (:mod:`fem_neck.lattice`)
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
# the smallest overlap of nearest neighbours whose union the mesher takes (:mod:`fem_neck.lattice`)
UNION_MIN_H_OVER_R = 0.02
TOL = 1e-9  # geometric tolerance in units of the largest radius


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
        ``"union"``, the union of the spheres (:mod:`fem_neck.lattice`).
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
        r"""Solid volume fraction :math:`\sum \frac{4}{3} \pi r^3 / |P|` over the period's volume :math:`|P|` (exact:
        the necks conserve each particle's volume); read as the union of the spheres, the sum of the volumes of the
        spheres cut by their radical planes over ``|period|`` (:func:`fem_neck.geometry.union.cut_spheres`, exact)."""
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
        inside = np.all((x >= lo - TOL * self.radii.max()) & (x <= hi + TOL * self.radii.max()), axis=1)
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
    r"""Largest ``a/r`` of a cubic lattice: the neck circles of one particle touch at :math:`a/r = \sin(\theta/2)`.

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
    r""":math:`h/r` at which the union of the lattice's spheres fills space: the neighbour distance at which the radius
    is the lattice's covering radius (SC: the cube's half diagonal, :math:`d = 2r / \sqrt{3}`, :math:`h/r` = 0.8453;
    BCC: :math:`\sqrt{5} / 4` of the cube edge, :math:`d = 2 \sqrt{3 / 5} \, r`, 0.4508; FCC: half the cube edge,
    :math:`d = \sqrt{2} \, r`, 0.5858).

    Parameters
    ----------
    kind : str
        ``"sc"``, ``"bcc"`` or ``"fcc"``.
    """
    covering = {"sc": math.sqrt(3.0) / 2.0, "bcc": math.sqrt(5.0) / 4.0, "fcc": 0.5}[kind]  # over the cube edge
    return 2.0 - 1.0 / (covering * EDGE_OVER_SPACING[kind])


def union_neck_ratio(h_over_r: float) -> float:
    """:math:`a/r` of the circle where two equal spheres meet: :math:`a^2 = r h - h^2 / 4`
    (:func:`fem_neck.geometry.union.lens` at :math:`d = 2r - h`).

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
    r"""Raise ``ValueError`` unless some particles overlap and, read as pair necks, every bond's overlap lies in the
    neck model's range and no two necks of one particle touch (their circles, of angular radius :math:`\arcsin(a/r)`,
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
        close = np.all(np.abs(diff) < TOL * cell.radii.max() * 10, axis=2)
        close &= np.abs(cell.radii[:, None] - cell.radii[None, :]) < TOL * cell.radii.max()
        return bool(np.all(close.any(axis=1)))

    mirror = all(same(cell.centres * np.where(np.arange(3) == ax, -1.0, 1.0)) for ax in range(3))
    square = bool(abs(cell.period[0] - cell.period[1]) < TOL * cell.period[0])
    diagonal = square and same(cell.centres[:, [1, 0, 2]])
    half = 0.5 * cell.period[0]
    anti = diagonal and same(np.column_stack([half - cell.centres[:, 1], half - cell.centres[:, 0], cell.centres[:, 2]]))
    return mirror, diagonal, anti


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
