"""Neighbour search for particles that move: cell binning and a Verlet list with a skin (Zohdi 2014, Sec. 8;
Allen & Tildesley 1987, the "Verlet table" of Luding 2005, Sec. 3).

The list holds every pair ``i < j`` whose surfaces are closer than ``skin``: ``|x_i - x_j| < r_i + r_j + skin``.
It stays valid as long as no particle has moved more than ``skin / 2`` since it was built (two particles then
approach by less than ``skin``), so it is rebuilt only when some particle has (:func:`max_displacement`). A
rebuild bins the particles into cubic cells of edge ``2 r_max + skin`` (larger where that would make more than
``MAX_CELLS_PER_PARTICLE`` cells per particle, as a particle far from the others would) and compares each particle
with those in its own and the neighbouring cells: O(N) per rebuild. Periodic axes (``box[k] > 0``) wrap the cells and use the
minimum image.

The same binning places particles at random without overlaps (:func:`sequential_addition`, random sequential
addition for the box generator).

Per-pair history (the contact state that a contact law carries from step to step) lives in rows aligned with the
list; :func:`carry_history` moves it to the rows of a rebuilt list, matching the pairs of the two sorted lists.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

PAIR_BLOCK = 4096  # particles per block of the pair search (verlet_pairs): the blocks are shared among numba's threads


@njit(cache=True)
def min_image(d, length):
    """``d`` wrapped into ``[-length/2, length/2]`` on a periodic axis (``length > 0``); unchanged otherwise.

    A listed pair's separation is far below a quarter of the box: there ``floor(d/length + 0.5) = 0`` and the
    result is ``d`` to the bit, so the division and the floor are skipped."""
    if length > 0.0:
        if abs(d) < 0.25 * length:
            return d
        return d - length * math.floor(d / length + 0.5)
    return d


MAX_CELLS_PER_PARTICLE = 64  # the cell grid's memory bound: a particle far from the rest cannot make it huge


@njit(cache=True)
def _cell_of(x, lo, size, n):
    c = int((x - lo) / size)
    if c < 0:
        return 0
    if c >= n:
        return n - 1
    return c


@njit(cache=True)
def _cells(x, radius, skin, box):
    """The particles binned into cubic cells of edge ``2 r_max + skin`` (wrapped on periodic axes): ``(cell, head,
    nxt, ncell, wrap)``, each particle's cell indices (n, 3), the first particle of every cell and the next of every
    particle (-1 ends a cell), the cells per axis and whether an axis wraps."""
    n = x.shape[0]
    r_max = 0.0
    for k in range(n):
        r_max = max(r_max, radius[k])
    size = 2.0 * r_max + skin
    lo = np.empty(3)
    span = np.empty(3)
    for a in range(3):
        if box[a] > 0.0:
            lo[a], span[a] = 0.0, box[a]
        else:
            xmin, xmax = x[0, a], x[0, a]
            for k in range(n):
                xmin = min(xmin, x[k, a])
                xmax = max(xmax, x[k, a])
            lo[a], span[a] = xmin, xmax - xmin
    ncell = np.empty(3, dtype=np.int64)
    wrap = np.zeros(3, dtype=np.bool_)
    while True:  # cells no smaller than the cutoff, and at most MAX_CELLS_PER_PARTICLE n + 4096 of them
        for a in range(3):
            if box[a] > 0.0:
                ncell[a] = max(1, int(box[a] / size))
                wrap[a] = ncell[a] >= 3
                if not wrap[a]:  # fewer than 3 cells across a periodic axis: one cell, every pair compared
                    ncell[a] = 1
            else:
                ncell[a] = max(1, min(int(span[a] / size) + 1, 1 << 20))
        if ncell[0] * ncell[1] * ncell[2] <= MAX_CELLS_PER_PARTICLE * n + 4096:
            break
        size *= 1.25  # a sparse or scattered sample (a particle far away): fewer, larger cells
    csize = np.empty(3)
    for a in range(3):
        if box[a] > 0.0:
            csize[a] = box[a] / ncell[a]
        else:
            csize[a] = size
    total = ncell[0] * ncell[1] * ncell[2]
    head = -np.ones(total, dtype=np.int64)
    nxt = -np.ones(n, dtype=np.int64)
    cell = np.empty((n, 3), dtype=np.int64)
    for k in range(n):
        for a in range(3):
            xa = x[k, a]
            if box[a] > 0.0:
                xa = xa - box[a] * math.floor(xa / box[a])
            cell[k, a] = _cell_of(xa, lo[a], csize[a], ncell[a])
        c = (cell[k, 0] * ncell[1] + cell[k, 1]) * ncell[2] + cell[k, 2]
        nxt[k] = head[c]
        head[c] = k
    return cell, head, nxt, ncell, wrap


@njit(cache=True)
def _partners(k, x, radius, skin, box, grid, out, found, room):
    """The partners ``m > k`` of particle ``k`` within ``r_k + r_m + skin`` (``grid``: the cells of :func:`_cells`),
    written in order of ``m`` into ``out = (out_i, out_j, out_d)`` from ``found`` on while below ``room``, with their
    centre distances in ``out_d`` unless it is empty; returns ``found`` plus their number."""
    cell, head, nxt, ncell, wrap = grid
    out_i, out_j, out_d = out
    distances = out_d.shape[0] > 0
    first = found
    for d0 in range(-1, 2):
        c0 = cell[k, 0] + d0
        if c0 < 0 or c0 >= ncell[0]:
            if not wrap[0]:
                continue
            c0 %= ncell[0]
        if ncell[0] == 1 and d0 != 0:
            continue
        for d1 in range(-1, 2):
            c1 = cell[k, 1] + d1
            if c1 < 0 or c1 >= ncell[1]:
                if not wrap[1]:
                    continue
                c1 %= ncell[1]
            if ncell[1] == 1 and d1 != 0:
                continue
            for d2 in range(-1, 2):
                c2 = cell[k, 2] + d2
                if c2 < 0 or c2 >= ncell[2]:
                    if not wrap[2]:
                        continue
                    c2 %= ncell[2]
                if ncell[2] == 1 and d2 != 0:
                    continue
                m = head[(c0 * ncell[1] + c1) * ncell[2] + c2]
                while m >= 0:
                    if m > k:
                        dx = min_image(x[k, 0] - x[m, 0], box[0])
                        dy = min_image(x[k, 1] - x[m, 1], box[1])
                        dz = min_image(x[k, 2] - x[m, 2], box[2])
                        cut = radius[k] + radius[m] + skin
                        square = dx * dx + dy * dy + dz * dz
                        if square < cut * cut:
                            if found < room:
                                out_i[found] = k
                                out_j[found] = m
                                if distances:
                                    out_d[found] = math.sqrt(square)
                            found += 1
                    m = nxt[m]
    for a in range(first + 1, min(found, room)):  # k's partners in order (a handful: insertion sort)
        partner = out_j[a]
        length = out_d[a] if distances else 0.0
        b = a - 1
        while b >= first and out_j[b] > partner:
            out_j[b + 1] = out_j[b]
            if distances:
                out_d[b + 1] = out_d[b]
            b -= 1
        out_j[b + 1] = partner
        if distances:
            out_d[b + 1] = length
    return found


@njit(cache=True, parallel=True)
def _pairs_in_blocks(x, radius, skin, box, block, slot, out_i, out_j, out_d):
    """The pairs within ``r_i + r_j + skin`` by cell binning, sorted by ``(i, j)``: the particles ``b block ...
    (b + 1) block - 1`` (block ``b``, one block per thread at a time) write theirs into ``out_i``, ``out_j`` (and
    their centre distances into ``out_d`` unless it is empty) from ``slot[b]`` on while below ``slot[b + 1]``; returns
    every block's number of pairs (a block whose slot is that large holds them all)."""
    n = x.shape[0]
    grid = _cells(x, radius, skin, box)
    blocks = slot.shape[0] - 1
    counts = np.zeros(blocks, dtype=np.int64)
    for b in prange(blocks):
        found = slot[b]
        for k in range(b * block, min(n, (b + 1) * block)):
            found = _partners(k, x, radius, skin, box, grid, (out_i, out_j, out_d), found, slot[b + 1])
        counts[b] = found - slot[b]
    return counts


def verlet_pairs(x: np.ndarray, radius: np.ndarray, skin: float, box: np.ndarray, capacity: int = 0,
                 distances: bool = False) -> tuple:
    r"""Pairs ``i < j`` with ``|x_i - x_j| < r_i + r_j + skin`` (minimum image on periodic axes), sorted by
    ``(i, j)``. The particles are searched in blocks of ``PAIR_BLOCK`` on numba's threads, each block's pairs
    written into a slot of its own of ``capacity`` pairs shared out evenly; ``capacity``: the number of pairs
    expected (a rebuild passes its last list's length with some room): one pass over the cells when every block's
    pairs fit in its slot, else a second one into slots of the sizes counted.

    Parameters
    ----------
    x : numpy.ndarray
        (N, 3) particle centres (m).
    radius : numpy.ndarray
        (N,) radii (m).
    skin : float
        The list's skin (m), >= 0.
    box : numpy.ndarray
        (3,) the periodic box's lengths, 0 along non-periodic axes (m).
    capacity : int
        The number of pairs expected.
    distances : bool
        Also return the pairs' centre distances, as the search computed them:
        :math:`\sqrt{d_x d_x + d_y d_y + d_z d_z}` of the (minimum-image) differences, summed in that order
        (``np.linalg.norm`` of ``x_j - x_i`` to the bit).

    Returns
    -------
    tuple of numpy.ndarray
        ``(i, j)``, int, sorted by ``(i, j)``; with ``distances``, ``(i, j, d)``, ``d`` in m.
    """
    n = len(radius)
    if n < 2:
        empty = np.zeros(0, dtype=np.int64)
        return (empty, empty, np.zeros(0)) if distances else (empty, empty)
    blocks = -(-n // PAIR_BLOCK)
    per = -(-max(int(capacity), 0) // blocks)
    slot = np.arange(blocks + 1, dtype=np.int64) * per

    def search(slot):
        out = (np.empty(slot[-1], dtype=np.int64), np.empty(slot[-1], dtype=np.int64),
               np.empty(slot[-1] if distances else 0))
        return out, _pairs_in_blocks(x, radius, skin, box, PAIR_BLOCK, slot, *out)

    out, counts = search(slot)
    if np.any(counts > per):
        out, _ = search(np.concatenate(([0], np.cumsum(counts))))
    else:
        filled = [slice(start, start + count) for start, count in zip(slot[:-1].tolist(), counts.tolist())]
        out = [np.concatenate([a[f] for f in filled]) for a in out]
    return tuple(out) if distances else tuple(out[:2])


@njit(cache=True)
def max_displacement(x, x_ref, box):
    """The largest distance any particle has moved since ``x_ref`` (minimum image on periodic axes)."""
    worst = 0.0
    for k in range(x.shape[0]):
        s = 0.0
        for a in range(3):
            d = min_image(x[k, a] - x_ref[k, a], box[a])
            s += d * d
        worst = max(worst, s)
    return math.sqrt(worst)


@njit(cache=True)
def _rows_in(old_i, old_j, new_i, new_j):
    """The row of each pair ``(new_i, new_j)`` in ``(old_i, old_j)``, -1 where it is new (both sorted by
    ``(i, j)``: one merge)."""
    rows = np.empty(new_i.shape[0], dtype=np.int64)
    p, m = 0, old_i.shape[0]
    for q in range(new_i.shape[0]):
        while p < m and (old_i[p] < new_i[q] or (old_i[p] == new_i[q] and old_j[p] < new_j[q])):
            p += 1
        rows[q] = p if p < m and old_i[p] == new_i[q] and old_j[p] == new_j[q] else -1
    return rows


def carry_history(old_i, old_j, new_i, new_j, *columns):
    """History rows of the pairs ``(new_i, new_j)`` taken from the rows of the same pairs in ``(old_i, old_j)``
    (both sorted by ``(i, j)``); pairs new to the list start from zeros. Returns the new columns.

    Parameters
    ----------
    old_i, old_j : numpy.ndarray
        The old list's pairs, sorted by ``(i, j)``.
    new_i, new_j : numpy.ndarray
        The new list's pairs, sorted by ``(i, j)``.
    *columns : numpy.ndarray
        History arrays with one row per old pair (any unit and trailing shape).

    Returns
    -------
    list of numpy.ndarray
        The same columns with one row per new pair.
    """
    rows = _rows_in(old_i, old_j, new_i, new_j)
    found = rows >= 0
    out = []
    for col in columns:
        new = np.zeros((len(new_i),) + col.shape[1:], dtype=col.dtype)
        new[found] = col[rows[found]]
        out.append(new)
    return out


def wall_pairs(x: np.ndarray, radius: np.ndarray, normal: np.ndarray, offset: np.ndarray,
               skin: float) -> tuple[np.ndarray, np.ndarray]:
    """Particle-wall pairs ``(k, m)`` with particle k closer than ``r_k + skin`` to the plane ``n_m . x = q_m`` (or
    behind it): the Verlet list of the walls.

    Parameters
    ----------
    x : numpy.ndarray
        (N, 3) particle centres (m).
    radius : numpy.ndarray
        (N,) radii (m).
    normal : numpy.ndarray
        (W, 3) the walls' unit normals, into the packing.
    offset : numpy.ndarray
        (W,) the walls' offsets ``q`` (m).
    skin : float
        The list's skin (m).

    Returns
    -------
    tuple of numpy.ndarray
        ``(k, m)``, int: the particle and the wall of each pair.
    """
    if len(offset) == 0:
        empty = np.zeros(0, dtype=np.int64)
        return empty, empty
    dist = x @ normal.T - offset[None, :]
    k, m = np.nonzero(dist < radius[:, None] + skin)
    return k.astype(np.int64), m.astype(np.int64)


def list_arrays(mech) -> dict:
    """The Verlet lists of ``mech`` (its pairs ``pi, pj``, particle-wall pairs ``wk, wm`` and the positions
    ``x_ref`` and wall offsets ``wq_ref`` they were built at), for a checkpoint: a resumed run rebuilds its lists at
    the steps the uninterrupted run does.

    Parameters
    ----------
    mech : dem.engines.verlet.mechanics.MechanicalModel
        The mechanical model of particles that move.

    Returns
    -------
    dict
        The lists' arrays, named as a checkpoint holds them.
    """
    return {"pi": mech.pi, "pj": mech.pj, "list_x_ref": mech.x_ref, "wall_list_k": mech.wk, "wall_list_m": mech.wm,
            "wall_list_q_ref": mech.wq_ref}


def restore_lists(mech, saved: dict) -> None:
    """The Verlet lists of a checkpoint (:func:`list_arrays`) back into ``mech``, with the saved pair histories and
    the positions they go with (in a periodic box the list built before may have wrapped particles the uninterrupted
    run wraps only at its next rebuild).

    Parameters
    ----------
    mech : dem.engines.verlet.mechanics.MechanicalModel
        The mechanical model of particles that move.
    saved : dict
        The checkpoint's arrays (:func:`list_arrays`, with ``x`` and ``p_hist``).
    """
    mech.state.x[:] = saved["x"]
    mech.pi, mech.pj = (np.array(saved[k], dtype=np.int64) for k in ("pi", "pj"))
    mech.p_hist = np.array(saved["p_hist"], dtype=float)
    mech.p_fn, mech.p_ft = np.zeros(len(mech.pi)), np.zeros((len(mech.pi), 3))
    mech.x_ref = np.array(saved["list_x_ref"], dtype=float)
    mech.wk, mech.wm = (np.array(saved[k], dtype=np.int64) for k in ("wall_list_k", "wall_list_m"))
    mech.wq_ref = np.array(saved["wall_list_q_ref"], dtype=float)


@njit(cache=True)
def addition_grid(r, lo, hi):
    """The cells of :func:`sequential_addition` for particles of radii ``r`` in the box ``[lo, hi]``: ``(size,
    ncell, head, nxt)``, cubic cells of edge at least the largest diameter (a candidate then meets only particles in
    its own and the neighbouring cells), and no more cells than particles (a sparse box allocates O(N))."""
    n = r.shape[0]
    volume = 1.0
    for a in range(3):
        volume *= max(hi[a] - lo[a], 2.0 * r.max())
    size = max(2.0 * r.max(), (volume / n) ** (1.0 / 3.0))
    ncell = np.empty(3, dtype=np.int64)
    for a in range(3):
        ncell[a] = max(1, int((hi[a] - lo[a]) / size) + 1)
    return size, ncell, -np.ones(ncell[0] * ncell[1] * ncell[2], dtype=np.int64), -np.ones(n, dtype=np.int64)


@njit(cache=True)
def sequential_addition(r, lo, hi, uniform, pos, placed, size, ncell, head, nxt):
    """Place particles ``placed, placed + 1, ...`` of radii ``r`` one by one at the next candidate points ``lo + u
    (hi - lo)`` (``u`` rows of ``uniform``, kept inside the box by each radius) that overlap no particle placed
    before; the cells of :func:`addition_grid` make each test O(1). Writes ``pos`` and the cells in place and returns
    the number placed when the candidates ran out (or all were): called again with more candidates, it goes on as if
    it had been given them all at once."""
    n = r.shape[0]
    c = np.empty(3, dtype=np.int64)
    p = np.empty(3)
    trial = 0
    k = placed
    while k < n and trial < uniform.shape[0]:
        for a in range(3):
            span = hi[a] - lo[a] - 2.0 * r[k]
            p[a] = lo[a] + r[k] + uniform[trial, a] * span if span > 0 else lo[a]
            c[a] = min(ncell[a] - 1, int((p[a] - lo[a]) / size))
        trial += 1
        free = True
        for d0 in range(max(0, c[0] - 1), min(ncell[0], c[0] + 2)):
            for d1 in range(max(0, c[1] - 1), min(ncell[1], c[1] + 2)):
                for d2 in range(max(0, c[2] - 1), min(ncell[2], c[2] + 2)):
                    m = head[(d0 * ncell[1] + d1) * ncell[2] + d2]
                    while m >= 0 and free:
                        s = 0.0
                        for a in range(3):
                            s += (pos[m, a] - p[a]) ** 2
                        if s < (r[m] + r[k]) ** 2:
                            free = False
                        m = nxt[m]
        if free:
            pos[k] = p
            cell = (c[0] * ncell[1] + c[1]) * ncell[2] + c[2]
            nxt[k] = head[cell]
            head[cell] = k
            k += 1
    return k
