"""A packing that does not move shared out in space among the ranks of a distributed run (the static engine's, and a
packing in parts), and the halo each rank needs.

:func:`bisection` is recursive coordinate bisection (Berger & Bokhari 1987): the particles are split across their
longest extent at the count that gives each side its share of the parts, and each side again, until there are
``parts`` cells of (almost) equal counts. On two ranks it is one cut across the longest axis (two slabs); on many
ranks the cells stay compact, so the bonds that cross a cell face (the off-rank matrix entries) grow as the faces,
not as the slabs' ever larger share.

:func:`halo` lists the particles within ``reach`` of a cell's particles that another rank owns: with ``reach`` one
bond length (twice the largest radius: two spheres bond only when ``d < r_i + r_j``), every bond of an owned particle
has its partner among the owned and the halo particles, so a bond search over those finds all of them. On periodic
axes the distance is taken to the nearest image. The network with a node per neck needs ``NECK_HALO`` bond lengths
(:mod:`dem.network.distributed_necks`).

A packing stored in parts (:mod:`dem.scene.packing_files.parts`) is shared out by its blocks, not its particles: the
same bisection over the blocks' centres, each weighted by its particle count, so that a rank reads only its blocks and
those within ``reach`` of them.

Particles that move are shared out otherwise, in slabs along one axis (:mod:`dem.geometry.slabs`): they cross
the cuts all the time, so their cuts are planes fixed for the run, the owner of a particle is computed from one
coordinate alone (the same answer on every rank, from a ghost's copy too), and the halo includes the Verlet skin. A
packing that does not move is cut once, into compact cells whose faces -- the off-rank matrix entries -- stay small on
many ranks; the two jobs want different cuts, hence two modules.
"""

from __future__ import annotations

import numpy as np

HALO_MARGIN = 1.0 + 1e-9  # the halo's reach: this x one bond length (two largest radii), against round-off
NECK_HALO = 3  # the halo of a network with a node per neck, in bond lengths (dem.network.distributed_necks)


def bisection(position: np.ndarray, parts: int, lengths: np.ndarray | None = None,
              weights: np.ndarray | None = None) -> np.ndarray:
    """The rank (0 ... ``parts - 1``) of every particle: recursive coordinate bisection (module docstring).
    ``lengths``: the extent of each axis where it is known (a periodic box), else the particles' span; ``weights``:
    what each point counts for (a block's particles), each cut at the weight that gives each side its share.

    Parameters
    ----------
    position : numpy.ndarray
        (N, 3) particle centres (m).
    parts : int
        Number of ranks, >= 1.
    lengths : numpy.ndarray or None
        (3,) the box's lengths (m); None: the particles' span.
    weights : numpy.ndarray or None
        (N,) what each point counts for, >= 0 (the particle count of a block); None: one each.

    Returns
    -------
    numpy.ndarray
        (N,) int, the rank of each particle.
    """
    if parts < 1:
        raise ValueError(f"parts = {parts}: must be >= 1")
    owner = np.zeros(len(position), dtype=np.int64)
    _split(position, np.arange(len(position)), 0, parts, owner, lengths, weights)
    return owner


def _split(position, members, first, parts, owner, lengths, weights):
    if parts == 1 or len(members) == 0:
        owner[members] = first
        return
    x = position[members]
    span = np.ptp(x, axis=0) if lengths is None else np.minimum(np.ptp(x, axis=0), lengths)
    axis = int(np.argmax(span))
    low_parts = parts // 2
    order = members[np.argsort(x[:, axis], kind="stable")]
    if weights is None:
        cut = len(members) * low_parts // parts
    else:  # the first points up to the low side's share of the weight, each side at least one point per part
        w = np.cumsum(weights[order])
        cut = int(np.searchsorted(w, w[-1] * low_parts / parts, side="right"))
        if len(members) >= parts:
            cut = min(max(cut, low_parts), len(members) - (parts - low_parts))
    _split(position, order[:cut], first, low_parts, owner, lengths, weights)
    _split(position, order[cut:], first + low_parts, parts - low_parts, owner, lengths, weights)


def halo(position: np.ndarray, owner: np.ndarray, rank: int, reach: float, lengths=None, periodic=None) -> np.ndarray:
    """Indices of the particles that ``rank`` does not own within ``reach`` (per axis) of the bounding box of those it
    owns (module docstring); ``lengths`` and ``periodic`` (3,): the box, whose periodic axes wrap.

    Parameters
    ----------
    position : numpy.ndarray
        (N, 3) particle centres (m).
    owner : numpy.ndarray
        (N,) int, the rank of each particle (:func:`bisection`).
    rank : int
        The rank whose halo is wanted.
    reach : float
        How far beyond its particles' bounding box the halo reaches (m).
    lengths : array_like or None
        (3,) the box's lengths (m), read along periodic axes; None without a box.
    periodic : array_like or None
        (3,) bool, the box's periodic axes; None: none.

    Returns
    -------
    numpy.ndarray
        Indices of the halo particles.
    """
    mine = owner == rank
    if not np.any(mine):
        return np.zeros(0, dtype=np.int64)
    lo, hi = position[mine].min(axis=0) - reach, position[mine].max(axis=0) + reach
    near = np.ones(len(position), dtype=bool)
    for axis in range(position.shape[1]):
        x = position[:, axis]
        inside = (x >= lo[axis]) & (x <= hi[axis])
        if periodic is not None and periodic[axis]:
            L = lengths[axis]
            inside |= ((x + L >= lo[axis]) & (x + L <= hi[axis])) | ((x - L >= lo[axis]) & (x - L <= hi[axis]))
        near &= inside
    return np.flatnonzero(near & ~mine)
