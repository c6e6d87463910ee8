r"""The compiled kernels of the AMG V-cycle (:mod:`dem.network.amg_cycle`) on numba's threads: products with a CSR
matrix and hybrid Gauss-Seidel sweeps.

Every kernel works on a fixed partition of the rows into blocks of about equal nonzeros (:func:`row_blocks`), shared
among numba's threads; a block's work does not depend on the thread that does it, so the result is the same to the
bit on any number of threads. Column indices are read as unsigned integers (numba tests a signed index for a
negative value at every entry, which doubled the time of a product against scipy's).

The Gauss-Seidel sweep is *hybrid* (Henson & Yang 2002, BoomerAMG's default smoother): each block sweeps its own
rows in order with the newest values of its own unknowns and the values of the other blocks' unknowns from the start
of the sweep, so the blocks sweep at the same time. With :math:`A` symmetric the backward hybrid sweep is the adjoint
of the forward one (the blocks' lower and upper triangles are each other's transposes), so a forward sweep followed
by a backward one is self-adjoint, as the sequential symmetric sweep is. With one block it is pyamg's sequential
sweep (``pyamg.relaxation.relaxation.gauss_seidel``) to round-off: each row's sum is taken in two parts, its own
block's entries before the diagonal and the rest, so that a backward sweep after a forward one reads only the entries
after the diagonal (:func:`hybrid_sweep`), and a forward sweep from zero only those before it: a symmetric sweep from
zero reads the matrix once instead of twice, one from any start one and a half times.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

FORWARD, BACKWARD, FROM_ZERO = 0, 1, 2  # the kinds of sweep of :func:`hybrid_sweep`


@njit(cache=True)
def row_blocks(indptr, blocks):
    """The bounds (``blocks + 1`` row indices) of ``blocks`` consecutive row blocks of about equal nonzeros of the
    CSR matrix with row pointer ``indptr``."""
    n = indptr.shape[0] - 1
    bounds = np.empty(blocks + 1, np.int64)
    bounds[0] = 0
    bounds[blocks] = n
    nnz = indptr[n]
    row = 0
    for b in range(1, blocks):
        target = (nnz * b) // blocks
        while row < n and indptr[row] < target:
            row += 1
        bounds[b] = row
    return bounds


@njit(cache=True)
def _row_products(indptr, indices, data, x, lo, hi, y, add, mirror):
    """``y[i] = (M x)[i]``, or with ``add`` ``y[i] += (M x)[i]`` and ``mirror[i] = y[i]``, for the rows ``[lo, hi)``
    (unsigned indices: no test for negative ones per entry)."""
    for i in range(np.uint64(lo), np.uint64(hi)):
        s = 0.0
        for e in range(np.uint64(indptr[i]), np.uint64(indptr[i + 1])):
            s += data[e] * x[np.uint64(indices[e])]
        if add:
            y[i] += s
            mirror[i] = y[i]
        else:
            y[i] = s


@njit(cache=True, parallel=True)
def matvec(indptr, indices, data, x, y, bounds):
    """``y = M x`` for the CSR matrix ``M`` (``indptr``, ``indices``, ``data``) over its row blocks ``bounds``."""
    for b in prange(bounds.shape[0] - 1):
        _row_products(indptr, indices, data, x, bounds[b], bounds[b + 1], y, False, y)


@njit(cache=True, parallel=True)
def add_matvec(indptr, indices, data, x, y, mirror, bounds):
    """``y += M x``, and ``mirror = y`` (the copy a hybrid sweep reads next: :func:`hybrid_sweep`)."""
    for b in prange(bounds.shape[0] - 1):
        _row_products(indptr, indices, data, x, bounds[b], bounds[b + 1], y, True, mirror)


@njit(cache=True)
def _row_residuals(indptr, indices, data, x, rhs, lo, hi, r):
    for i in range(np.uint64(lo), np.uint64(hi)):
        s = rhs[i]
        for e in range(np.uint64(indptr[i]), np.uint64(indptr[i + 1])):
            s -= data[e] * x[np.uint64(indices[e])]
        r[i] = s


@njit(cache=True, parallel=True)
def residual(indptr, indices, data, x, rhs, r, bounds):
    r"""The residual :math:`r = \mathrm{rhs} - M x`."""
    for b in prange(bounds.shape[0] - 1):
        _row_residuals(indptr, indices, data, x, rhs, bounds[b], bounds[b + 1], r)


@njit(cache=True, parallel=True)
def mixed_rows(indptr, indices, bounds):
    """Whether each row of the CSR matrix has an entry in a column outside its own row block."""
    mixed = np.zeros(indptr.shape[0] - 1, np.bool_)
    for b in prange(bounds.shape[0] - 1):
        lo, hi = bounds[b], bounds[b + 1]
        for i in range(lo, hi):
            for e in range(indptr[i], indptr[i + 1]):
                if not lo <= indices[e] < hi:
                    mixed[i] = True
                    break
    return mixed


@njit(cache=True, parallel=True)
def diagonal_places(indptr, indices):
    """The place of each row's diagonal entry in the CSR arrays (column indices sorted in each row); -1 where a row
    has none."""
    n = indptr.shape[0] - 1
    at = np.full(n, -1, np.int64)
    for i in prange(n):
        for e in range(indptr[i], indptr[i + 1]):
            if indices[e] == i:
                at[i] = e
                break
    return at


@njit(cache=True)
def _sweep_block(indptr, indices, data, diag_at, x, read, write, rhs, lower, mixed, lo, hi, kind):
    """The Gauss-Seidel updates of the rows ``[lo, hi)`` of one block (:func:`hybrid_sweep`, whose docstring says
    what ``kind`` does): the block's own unknowns from ``x``, the others' from ``read`` (only in the ``mixed``
    rows: the test per entry would double the sweep's time); each row's new value also to ``write``."""
    lo, hi = np.uint64(lo), np.uint64(hi)
    one = np.uint64(1)
    for k in range(hi - lo):
        i = hi - one - k if kind == BACKWARD else lo + k
        begin, end, d = np.uint64(indptr[i]), np.uint64(indptr[i + 1]), np.uint64(diag_at[i])
        own = 0.0  # the row's own-block entries before the diagonal (their newest values)
        rest = 0.0  # the others
        if kind == FROM_ZERO:  # every unknown but those of the block's rows above is zero
            if mixed[i]:
                for e in range(begin, d):
                    j = np.uint64(indices[e])
                    if j >= lo:
                        own += data[e] * x[j]
            else:
                for e in range(begin, d):
                    own += data[e] * x[np.uint64(indices[e])]
            lower[i] = own
        elif kind == FORWARD:
            if mixed[i]:
                for e in range(begin, end):
                    j = np.uint64(indices[e])
                    if e < d and j >= lo:
                        own += data[e] * x[j]
                    elif e > d and j < hi:
                        rest += data[e] * x[j]
                    elif e != d:
                        rest += data[e] * read[j]
            else:
                for e in range(begin, d):
                    own += data[e] * x[np.uint64(indices[e])]
                for e in range(d + one, end):
                    rest += data[e] * x[np.uint64(indices[e])]
            lower[i] = own
        else:  # backward: the own entries before the diagonal are those the forward sweep summed in ``lower``
            own = lower[i]
            if mixed[i]:
                for e in range(begin, end):
                    j = np.uint64(indices[e])
                    if e > d and j < hi:
                        rest += data[e] * x[j]
                    elif j < lo or j >= hi:
                        rest += data[e] * read[j]
            else:
                for e in range(d + one, end):
                    rest += data[e] * x[np.uint64(indices[e])]
        x[i] = (rhs[i] - own - rest) / data[d]
        write[i] = x[i]


@njit(cache=True, parallel=True)
def hybrid_sweep(indptr, indices, data, diag_at, x, rhs, read, write, lower, mixed, bounds, kind):
    """One hybrid Gauss-Seidel sweep of ``M x = rhs`` over the row blocks (module docstring); ``mixed`` the rows of
    :func:`mixed_rows`, ``diag_at`` the places of :func:`diagonal_places` (every row has its diagonal, the column
    indices sorted). ``read`` holds ``x`` as it was before the sweep (the other blocks' unknowns are read there);
    the sweep leaves the new ``x`` in ``write`` too, for the next sweep to read, so that no copy (and no wait of the
    threads for it) comes between two sweeps.

    ``kind``: ``FORWARD``; ``FROM_ZERO``, a forward sweep from ``x = 0`` (``read`` is not read: it reads only the
    entries before the diagonal); ``BACKWARD``, right after a forward sweep, whose sums over each row's own-block
    entries before the diagonal it takes from ``lower`` (where the forward sweeps leave them) instead of summing
    them again: those unknowns have not changed since (Conrad & Wallach 1977), so it reads the entries after the
    diagonal only, but in the mixed rows."""
    for b in prange(bounds.shape[0] - 1):
        _sweep_block(indptr, indices, data, diag_at, x, read, write, rhs, lower, mixed, bounds[b], bounds[b + 1],
                     kind)
