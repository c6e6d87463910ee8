"""Slabs of space, one per MPI rank: which rank owns a particle and which other ranks need it as a ghost.

The domain is cut along one axis into ``P`` slabs ``[cut_r, cut_{r+1})``; rank ``r`` owns the particles whose centre
lies in its slab (on a periodic axis the coordinate wrapped into the box, ``cut_0`` the box's origin and ``cut_P``
its far face; on an open axis the outer slabs reach to infinity). A particle is a *ghost* on every other rank whose
slab lies closer than the *halo* to its centre (on a periodic axis by the nearer of the two ways round): a ghost
holds a copy of the owner's particle so that every pair a rank lists has both partners at hand. With the halo ``2
r_max + skin`` every pair of the Verlet list (``|x_i - x_j| < r_i + r_j + skin``, :mod:`dem.geometry.neighbours`)
with one partner owned is complete on that rank.

The cuts are chosen once, at equal particle counts (:meth:`Slabs.balanced`); a particle that crosses one changes
owner at the next rebuild of the Verlet list (migration, :mod:`dem.engines.distributed.verlet`). Everything here is
arithmetic on coordinates, the same on every rank: the owner computed from a ghost's copy is the owner's own answer.
A packing that does not move is shared out by recursive coordinate bisection instead (:mod:`dem.geometry.bisection`:
compact cells, cut once); why two: there.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Slabs:
    """``cuts`` (P + 1,) along ``axis``; ``period`` the box length along it (0: open axis, the outer cuts are
    -inf and inf) and ``origin`` the box's lower face.

    Parameters
    ----------
    axis : int
        The axis the slabs are cut along: 0, 1 or 2 (x, y, z).
    cuts : numpy.ndarray
        (P + 1,) the slabs' faces along the axis (m), ascending.
    period : float
        The periodic box's length along the axis (m); 0: an open axis.
    origin : float
        The box's lower face along the axis (m).
    """

    axis: int
    cuts: np.ndarray
    period: float = 0.0
    origin: float = 0.0

    @classmethod
    def balanced(cls, coordinate: np.ndarray, ranks: int, axis: int, period: float = 0.0, origin: float = 0.0):
        """Slabs holding nearly equal numbers of the particles at ``coordinate`` (their positions along ``axis``).

        Parameters
        ----------
        coordinate : numpy.ndarray
            (N,) the particles' coordinates along ``axis`` (m).
        ranks : int
            Number of slabs, >= 1.
        axis : int
            The axis: 0, 1 or 2.
        period : float
            The periodic box's length along the axis (m); 0: an open axis.
        origin : float
            The box's lower face along the axis (m).

        Returns
        -------
        Slabs
            The slabs.

        Raises
        ------
        ValueError
            ``ranks < 1``.
        """
        if ranks < 1:
            raise ValueError(f"ranks = {ranks!r}: must be at least 1")
        u = np.sort(cls(axis, np.zeros(2), period, origin).wrapped(np.asarray(coordinate, dtype=float)))
        inner = [0.5 * (u[k * len(u) // ranks - 1] + u[k * len(u) // ranks]) if len(u) > 1 else 0.0
                 for k in range(1, ranks)]
        ends = (origin, origin + period) if period > 0 else (-np.inf, np.inf)
        return cls(axis, np.array([ends[0], *inner, ends[1]]), float(period), float(origin))

    @property
    def ranks(self) -> int:
        """Number of slabs (ranks)."""
        return len(self.cuts) - 1

    def wrapped(self, u: np.ndarray) -> np.ndarray:
        """Coordinates along the axis, wrapped into ``[origin, origin + period)`` on a periodic axis.

        Parameters
        ----------
        u : numpy.ndarray
            Coordinates along the axis (m).

        Returns
        -------
        numpy.ndarray
            The wrapped coordinates (m); unchanged on an open axis.
        """
        if self.period > 0:
            return self.origin + np.mod(u - self.origin, self.period)
        return u

    def owner(self, x: np.ndarray) -> np.ndarray:
        """The rank owning each particle at positions ``x`` (N, 3).

        Parameters
        ----------
        x : numpy.ndarray
            (N, 3) particle centres (m).

        Returns
        -------
        numpy.ndarray
            (N,) int, the ranks.
        """
        u = self.wrapped(x[:, self.axis])
        return np.clip(np.searchsorted(self.cuts, u, side="right") - 1, 0, self.ranks - 1)

    def distance(self, x: np.ndarray, rank: int) -> np.ndarray:
        """How far each centre lies from the slab of ``rank`` along the axis (0 inside it).

        Parameters
        ----------
        x : numpy.ndarray
            (N, 3) particle centres (m).
        rank : int
            The rank, ``0 <= rank < ranks``.

        Returns
        -------
        numpy.ndarray
            (N,) the distances (m), the nearer image on a periodic axis.
        """
        u = self.wrapped(x[:, self.axis])
        lo, hi = self.cuts[rank], self.cuts[rank + 1]
        images = (u - self.period, u, u + self.period) if self.period > 0 else (u,)  # both ways round the box
        return np.min([np.maximum(np.maximum(lo - v, v - hi), 0.0) for v in images], axis=0)

    def within_halo(self, x: np.ndarray, rank: int, halo: float) -> np.ndarray:
        """Indices of the particles at ``x`` closer than ``halo`` to the slab of ``rank`` (those of another rank's
        slab are the ghosts ``rank`` needs).

        Parameters
        ----------
        x : numpy.ndarray
            (N, 3) particle centres (m).
        rank : int
            The rank, ``0 <= rank < ranks``.
        halo : float
            The halo's width (m).

        Returns
        -------
        numpy.ndarray
            Indices of those particles.
        """
        return np.flatnonzero(self.distance(x, rank) < halo)
