"""The periodic box: lengths per axis, which axes are periodic, and the displacements between particle images.

A packing periodic along axis k repeats itself every ``lengths[k]``: particle ``j`` has images at ``x_j + s L`` for
every integer vector ``s`` that is zero on the non-periodic axes. A bond joins particle ``i`` to one image of
``j``, stored as the integer *shift* ``s``; its vector is ``x_j + s L - x_i`` (:meth:`PeriodicBox.bond_vectors`).
The bond search (:func:`dem.geometry.bonds.find_bonds`) finds bonds across the boundary by adding the images of the particles
near each periodic face (:meth:`PeriodicBox.images`), so that a periodic block gives the same bonds as an explicit
larger block, for boxes of any size (a box shorter than a bond has a particle bonded to its own image). The
neighbour list of moving particles can use the same :meth:`PeriodicBox.images` and :meth:`PeriodicBox.minimum_image`.

A macroscopic temperature gradient through a periodic packing is a temperature *drop* per period:
``T(x + L_k e_k) = T(x) - drop_k``, so the image ``x_j + s L`` of particle ``j`` is at ``T_j - drop . s``
(:mod:`dem.network.heat`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

AXES = "xyz"


@dataclass(frozen=True)
class PeriodicBox:
    """``lengths`` (3,) m of the box from ``origin`` (3,); ``periodic`` (3,) bool; ``drop`` (3,) the temperature
    drop per period along each periodic axis (K or degC), zero by default.

    Parameters
    ----------
    lengths : array_like
        (3,) the box's lengths along x, y, z (m), finite and > 0.
    periodic : tuple of bool
        Which of x, y, z are periodic.
    origin : array_like or None
        (3,) the box's lower corner (m); None: the origin.
    drop : array_like or None
        (3,) the temperature drop per period along each axis (K or degC), nonzero only along periodic axes;
        None: zero.

    Raises
    ------
    ValueError
        A field has a bad shape or value, or a drop is given along a non-periodic axis.
    """

    lengths: np.ndarray
    periodic: tuple = (True, True, True)
    origin: np.ndarray = None
    drop: np.ndarray = None

    def __post_init__(self):
        lengths = np.asarray(self.lengths, dtype=float).reshape(-1)
        if lengths.shape != (3,) or not np.all(np.isfinite(lengths)) or np.any(lengths <= 0):
            raise ValueError(f"box lengths = {self.lengths!r}: must be three finite lengths > 0 (m)")
        periodic = tuple(self.periodic)
        if len(periodic) != 3 or not all(isinstance(p, (bool, np.bool_)) for p in periodic):
            raise ValueError(f"box periodic = {self.periodic!r}: must be three true/false values (x, y, z)")
        origin = np.zeros(3) if self.origin is None else np.asarray(self.origin, dtype=float).reshape(-1)
        if origin.shape != (3,) or not np.all(np.isfinite(origin)):
            raise ValueError(f"box origin = {self.origin!r}: must be three finite coordinates (m)")
        drop = np.zeros(3) if self.drop is None else np.asarray(self.drop, dtype=float).reshape(-1)
        if drop.shape != (3,) or not np.all(np.isfinite(drop)):
            raise ValueError(f"box drop = {self.drop!r}: must be three finite temperature differences")
        for k in range(3):
            if drop[k] != 0.0 and not periodic[k]:
                raise ValueError(f"box drop[{k}] = {drop[k]!r}: a temperature drop needs a periodic {AXES[k]} axis")
        object.__setattr__(self, "lengths", lengths)
        object.__setattr__(self, "periodic", tuple(bool(p) for p in periodic))
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "drop", drop)

    @property
    def mask(self) -> np.ndarray:
        """Which axes are periodic (3,) bool."""
        return np.array(self.periodic)

    @property
    def any_periodic(self) -> bool:
        """Whether any axis is periodic."""
        return any(self.periodic)

    @property
    def kernel_lengths(self) -> np.ndarray:
        """The lengths with 0 on the non-periodic axes -- the form the compiled kernels of moving particles take
        (``dem.geometry.neighbours.min_image``)."""
        return np.where(self.mask, self.lengths, 0.0)

    def wrap(self, x: np.ndarray) -> np.ndarray:
        """Positions moved into ``[origin, origin + lengths)`` along the periodic axes.

        Parameters
        ----------
        x : array_like
            (N, 3) or (3,) positions (m).

        Returns
        -------
        numpy.ndarray
            The wrapped positions (m), same shape; the non-periodic components unchanged.
        """
        x = np.asarray(x, dtype=float)
        offset = np.mod(x - self.origin, self.lengths)
        offset = np.where(offset >= self.lengths, 0.0, offset)  # mod of a tiny negative number rounds up to L
        return np.where(self.mask, self.origin + offset, x)

    def wrap_outside(self, x: np.ndarray) -> np.ndarray:
        """Moves the positions ``x`` (N, 3) that have left the box along a periodic axis back into it, in place (the
        others keep their bits, so a resumed run wraps as the uninterrupted one did); returns the displacement each
        got (a multiple of the lengths; zero for the others).

        Parameters
        ----------
        x : numpy.ndarray
            (N, 3) positions (m), changed in place.

        Returns
        -------
        numpy.ndarray
            (N, 3) the displacement each position got (m).
        """
        outside = self.mask & ((x < self.origin) | (x >= self.origin + self.lengths))
        if not outside.any():
            return np.zeros_like(x)
        wrapped = np.where(outside, self.wrap(x), x)
        moved = wrapped - x
        x[:] = wrapped
        return moved

    def minimum_image(self, dx: np.ndarray) -> np.ndarray:
        """The shortest image of each displacement ``dx`` (N, 3) along the periodic axes.

        Parameters
        ----------
        dx : array_like
            (N, 3) displacements (m).

        Returns
        -------
        numpy.ndarray
            (N, 3) the shortest images (m).
        """
        dx = np.asarray(dx, dtype=float)
        return np.where(self.mask, dx - self.lengths * np.round(dx / self.lengths), dx)

    def bond_vectors(self, position: np.ndarray, i: np.ndarray, j: np.ndarray, shift: np.ndarray) -> np.ndarray:
        """``x_j + shift L - x_i`` for bonds from ``i`` to the image ``shift`` of ``j``.

        Parameters
        ----------
        position : numpy.ndarray
            (N, 3) particle centres (m).
        i, j : numpy.ndarray
            (B,) int, the bonds' particle indices.
        shift : numpy.ndarray
            (B, 3) int, the image of ``j`` each bond joins (periods along x, y, z).

        Returns
        -------
        numpy.ndarray
            (B, 3) the bond vectors (m).
        """
        return position[j] + shift * self.lengths - position[i]

    def images(self, position: np.ndarray, cutoff: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The wrapped particles and their images within ``cutoff`` of the box: ``(points, owner, shift)``.

        ``points = wrap(x_owner) + shift L``; the originals come first (shift 0). Along each periodic axis, images
        are added axis by axis (so edges and corners get theirs), ``ceil(cutoff / L)`` periods deep.

        Parameters
        ----------
        position : numpy.ndarray
            (N, 3) particle centres (m).
        cutoff : float
            How far beyond the box's periodic faces images are kept (m).

        Returns
        -------
        tuple of numpy.ndarray
            ``points`` (M, 3) m, ``owner`` (M,) the particle each point is an image of, ``shift`` (M, 3) int.
        """
        x = self.wrap(position)
        owner = np.arange(len(x))
        shift = np.zeros((len(x), 3), dtype=np.int64)
        for k in np.flatnonzero(self.mask):
            L, lo = self.lengths[k], self.origin[k]
            depth = math.ceil(cutoff / L)
            add_x, add_o, add_s = [x], [owner], [shift]
            for m in range(1, depth + 1):
                for sign in (-1, 1):
                    y = x[:, k] + sign * m * L
                    near = (y >= lo - cutoff) & (y < lo + L + cutoff)
                    moved = x[near].copy()
                    moved[:, k] = y[near]
                    s = shift[near].copy()
                    s[:, k] += sign * m
                    add_x.append(moved)
                    add_o.append(owner[near])
                    add_s.append(s)
            x, owner, shift = np.concatenate(add_x), np.concatenate(add_o), np.concatenate(add_s)
        return x, owner, shift

    def cross_section(self, axis: int = 2) -> float:
        """Area of the box normal to ``axis`` (m^2).

        Parameters
        ----------
        axis : int
            0, 1 or 2 (x, y, z).

        Returns
        -------
        float
            The product of the two other lengths (m^2).
        """
        others = [k for k in range(3) if k != axis]
        return float(self.lengths[others[0]] * self.lengths[others[1]])


def canonical_bonds(i: np.ndarray, j: np.ndarray, shift: np.ndarray) -> tuple:
    """Each bond once, sorted: ``(i, j, shift)`` and ``(j, i, -shift)`` are the same bond; keep ``i < j``, or
    ``i == j`` with the first nonzero shift component positive. A bond with ``i == j`` and zero shift is dropped.

    Parameters
    ----------
    i, j : array_like
        (B,) int, the bonds' particle indices.
    shift : array_like
        (B, 3) int, the image of ``j`` each bond joins.

    Returns
    -------
    tuple of numpy.ndarray
        ``(i, j, shift)`` of the distinct bonds, sorted by ``i``, ``j``, then shift.
    """
    i, j, shift = np.asarray(i, np.int64), np.asarray(j, np.int64), np.asarray(shift, np.int64).reshape(-1, 3)
    first = np.zeros(len(i), dtype=np.int64)
    for k in (2, 1, 0):  # the first nonzero component, found last to first
        first = np.where(shift[:, k] != 0, shift[:, k], first)
    flip = (i > j) | ((i == j) & (first < 0))
    i, j = np.where(flip, j, i), np.where(flip, i, j)
    shift = np.where(flip[:, None], -shift, shift)
    keep = ~((i == j) & np.all(shift == 0, axis=1))
    i, j, shift = i[keep], j[keep], shift[keep]
    if not len(i):
        return i, j, shift
    order = np.lexsort((shift[:, 2], shift[:, 1], shift[:, 0], j, i))
    i, j, shift = i[order], j[order], shift[order]
    same = (i[1:] == i[:-1]) & (j[1:] == j[:-1]) & np.all(shift[1:] == shift[:-1], axis=1)
    keep = np.r_[True, ~same]
    return i[keep], j[keep], shift[keep]


def pair_lines(position: np.ndarray, i: np.ndarray, j: np.ndarray, box: PeriodicBox | None) -> tuple:
    """Lines for drawing the pairs ``(i, j)`` of ``position`` (N, 3): ``(points, lines)``. In a periodic ``box`` a
    pair whose minimum image crosses a face joins ``i`` to the image of ``j`` beside it, appended to the points (a
    line between the two originals would cross the box).

    Parameters
    ----------
    position : numpy.ndarray
        (N, 3) particle centres (m).
    i, j : numpy.ndarray
        (P,) int, the pairs' particle indices.
    box : PeriodicBox or None
        The periodic box; None: lines between the originals.

    Returns
    -------
    tuple of numpy.ndarray
        ``points`` (N + C, 3) m (the centres, then the C images appended) and ``lines`` (P, 2) int indices into
        them.
    """
    lines = np.column_stack([i, j]).astype(np.int64)
    if box is None:
        return position, lines
    raw = position[j] - position[i]
    near = box.minimum_image(raw)
    crossing = np.flatnonzero(np.any(near != raw, axis=1))
    lines[crossing, 1] = len(position) + np.arange(len(crossing))
    return np.vstack([position, position[i[crossing]] + near[crossing]]), lines
