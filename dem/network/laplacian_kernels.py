r"""The Laplacian of canonical edges and its free and fixed blocks, compiled: one pass to count the rows, one to write
them, no temporary of the edges' length.

For edges :math:`(i, j)` with :math:`i < j`, sorted by :math:`(i, j)` and each once (what
:func:`dem.geometry.bonds.find_bonds` gives), row :math:`r` of the Laplacian :math:`L` is its lower entries (the edges
:math:`(i, r)`, by :math:`i`), the diagonal, its upper entries (the edges :math:`(r, j)`, by :math:`j`). Walking the
rows in order with the edges in order, every edge :math:`(r, c)` appends its upper entry to row :math:`r` and its
lower entry to row :math:`c`; the lower entries of a row all come from earlier rows, so when the walk reaches a row
they are written, in order, and its diagonal goes right after them. The free-free block :math:`L_{FF}` and the
free-fixed block :math:`L_{FD}` are written by the same walk (without :math:`L`): the free (fixed) nodes
keep their order, so their positions are sorted column indices as well. The result is, entry for entry and to the
bit, :func:`dem.network.laplacian.laplacian` and scipy's row and column selection of it: the diagonal, :math:`\sum K`
over the edges to earlier nodes in order plus that over the edges to later nodes in order, is numpy's
``bincount(j, K) + bincount(i, K)``.

Apart so that a smaller network loads no numba (:data:`dem.network.laplacian.COMPILED_ASSEMBLY_FROM`).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def count_rows(n, i, j, position, fixed, whole, indptr, indptr_ff, indptr_fd):
    """Whether the edges are canonical (``0 <= i < j < n``, sorted by ``(i, j)``, each once) and, if they are, the
    number of entries of every row of :math:`L` (``whole``) or of :math:`L_{FF}` and :math:`L_{FD}` (not ``whole``),
    written at ``indptr[r + 1]`` (``indptr_ff``, ``indptr_fd``: at the free row's position plus one).

    Parameters
    ----------
    n : int
        Number of nodes.
    i, j : numpy.ndarray
        (M,) int, the edges' nodes.
    position : numpy.ndarray
        (n,) int, each node's position among the free nodes, or among the fixed ones for a fixed node.
    fixed : numpy.ndarray
        (n,) bool, the fixed nodes.
    whole : bool
        True: :math:`L` is wanted; False: its blocks.
    indptr, indptr_ff, indptr_fd : numpy.ndarray
        Zeroed row pointers of :math:`L` (n + 1) and of :math:`L_{FF}` and :math:`L_{FD}` (free nodes + 1), each
        read only where wanted.

    Returns
    -------
    bool
        Whether the edges are canonical (the counts are complete only then).
    """
    blocks = not whole
    m = i.shape[0]
    for e in range(m):
        a, b = i[e], j[e]
        if a < 0 or a >= b or b >= n or (e > 0 and (a < i[e - 1] or (a == i[e - 1] and b <= j[e - 1]))):
            return False
        if whole:
            indptr[a + 1] += 1
            indptr[b + 1] += 1
        if blocks:
            if not fixed[a]:
                if fixed[b]:
                    indptr_fd[position[a] + 1] += 1
                else:
                    indptr_ff[position[a] + 1] += 1
            if not fixed[b]:
                if fixed[a]:
                    indptr_fd[position[b] + 1] += 1
                else:
                    indptr_ff[position[b] + 1] += 1
    for r in range(n):
        if whole:
            indptr[r + 1] += 1  # the diagonal
        if blocks and not fixed[r]:
            indptr_ff[position[r] + 1] += 1
    return True


@njit(cache=True)
def _append(indices, data, cursor, row, col, value):
    at = cursor[row]
    indices[at] = col
    data[at] = value
    cursor[row] = at + 1


@njit(cache=True)
def write_rows(n, i, j, K, position, fixed, whole, indptr, indices, data, indptr_ff, indices_ff, data_ff, indptr_fd,
               indices_fd, data_fd):
    """The entries of :math:`L` (``whole``) or of :math:`L_{FF}` and :math:`L_{FD}` (not ``whole``), into arrays
    sized by :func:`count_rows` (row pointers summed up), for canonical edges (module docstring).

    Parameters
    ----------
    n : int
        Number of nodes.
    i, j : numpy.ndarray
        (M,) int, the canonical edges' nodes.
    K : numpy.ndarray
        (M,) the edge conductances (W/K for heat, S for current).
    position : numpy.ndarray
        (n,) int, each node's position among the free nodes, or among the fixed ones for a fixed node.
    fixed : numpy.ndarray
        (n,) bool, the fixed nodes.
    whole : bool
        True: :math:`L` is written; False: its blocks.
    indptr, indices, data : numpy.ndarray
        :math:`L`'s row pointers (filled) and its column indices and values (written).
    indptr_ff, indices_ff, data_ff, indptr_fd, indices_fd, data_fd : numpy.ndarray
        The same of :math:`L_{FF}` and :math:`L_{FD}`.
    """
    blocks = not whole
    cursor = indptr[:-1].copy()
    cursor_ff = indptr_ff[:-1].copy()
    cursor_fd = indptr_fd[:-1].copy()
    lower = np.zeros(n)  # per node, the sum of K over its edges to earlier nodes, in the edges' order
    m = i.shape[0]
    e = 0
    diagonal = 0
    for r in range(n):
        if whole:  # the lower entries of row r are written
            diagonal = cursor[r]
            cursor[r] = diagonal + 1
        free_r = blocks and not fixed[r]
        p = 0
        if free_r:
            p = position[r]
            diagonal_ff = cursor_ff[p]
            cursor_ff[p] = diagonal_ff + 1
        upper = 0.0
        while e < m and i[e] == r:
            c, k = j[e], K[e]
            lower[c] += k
            if whole:
                _append(indices, data, cursor, r, c, -k)
                _append(indices, data, cursor, c, r, -k)
            if blocks:
                if free_r:
                    if fixed[c]:
                        _append(indices_fd, data_fd, cursor_fd, p, position[c], -k)
                    else:
                        _append(indices_ff, data_ff, cursor_ff, p, position[c], -k)
                if not fixed[c]:
                    if fixed[r]:
                        _append(indices_fd, data_fd, cursor_fd, position[c], position[r], -k)
                    else:
                        _append(indices_ff, data_ff, cursor_ff, position[c], position[r], -k)
            upper += k
            e += 1
        if whole:
            indices[diagonal] = r
            data[diagonal] = lower[r] + upper
        if free_r:
            indices_ff[diagonal_ff] = p
            data_ff[diagonal_ff] = lower[r] + upper
