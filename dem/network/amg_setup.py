r"""The finest level of :class:`dem.network.linsolve.AMGSolver`'s hierarchy on a large network, built compiled on
numba's threads; the coarser levels are pyamg's (``sinterheat.amg.hierarchy``), the coarsest solved exactly
(:class:`CoarseCholesky`).

pyamg's smoothed aggregation (Vaněk, Mandel & Brezina 1996) builds the finest level's prolongator
:math:`P = (I - \omega D^{-1} A) T` (``jacobi_prolongation_smoother`` with ``weighting="local"``: :math:`D_{ii} =
\sum_j |A_{ij}|`) through a copy of :math:`|A|`, a scaled copy of :math:`A` and a sparse product on 1 x 1 blocks, and
the Galerkin product :math:`A_c = P^T A P` through two more such products, all on one thread: most of the setup's
time at :math:`10^6` unknowns, much of it the kernel's first touch of the copies. Here :math:`P` comes in one pass
over the rows of :math:`A` (the tentative prolongator :math:`T` has one entry per row: :math:`T_{i, a(i)} = t_i`,
``a`` the aggregate), and :math:`A_c` from :math:`AP` and :math:`P^T (AP)`, each a row-by-row product (Gustavson)
over fixed blocks of rows on the threads, in one pass with no count of the entries first (into arrays as long as a
bound, of which only the part written is touched), :math:`AP` never copied into CSR. The aggregates are pyamg's
(``standard_aggregation``), :math:`T` and the coarse candidates those of its ``fit_candidates`` for the constant
vector (:math:`t_i = |a(i)|^{-1/2}`, written without its sparse matrices), and so are :math:`P`'s entries, to the
bit (the same sums in the same order); :math:`A_c` is scipy's :math:`P^T (AP)` to the bit and pyamg's to round-off
(summed in another order), its column indices sorted.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit, prange

from dem.network.amg_kernels import row_blocks

BLOCKS = 8  # row blocks of the products (any number gives the same result)
# the coarsest level of the hierarchy: at most this many unknowns (pyamg's ``max_coarse``), solved exactly by a dense
# Cholesky factorisation (:class:`CoarseCholesky`: 0.01 s of CPU for 10^3 unknowns, 0.08 s at the bound)
COARSEST_MAX = 2_000


@njit(cache=True, parallel=True)
def _prolongator(indptr, indices, data, agg, t, n_coarse, omega, bounds):
    r"""The CSR arrays of :math:`P = T - (\omega D^{-1} A) T` (module docstring), with pyamg's operations in its
    order: :math:`D_i = \sum_j |A_{ij}|`, :math:`w_{ij} = \omega (A_{ij} / D_i)`, :math:`P_{iJ} = T_{iJ} - \sum_{j:
    a(j) = J} w_{ij} t_j`. ``agg`` is -1 for a row that no aggregate holds (no entry in ``T``)."""
    n = indptr.shape[0] - 1
    count = np.zeros(n + 1, np.int64)
    blocks = bounds.shape[0] - 1
    for b in prange(blocks):  # the entries of each row: the distinct aggregates of its columns and its own
        seen = np.full(n_coarse, -1, np.int64)
        for i in range(bounds[b], bounds[b + 1]):
            c = 0
            if agg[i] >= 0:
                seen[agg[i]] = i
                c = 1
            for e in range(indptr[i], indptr[i + 1]):
                J = agg[np.uint64(indices[e])]
                if J >= 0 and seen[J] != i:
                    seen[J] = i
                    c += 1
            count[i + 1] = c
    P_indptr = np.cumsum(count)
    P_indices = np.empty(P_indptr[n], np.int32)
    P_data = np.empty(P_indptr[n])
    for b in prange(blocks):
        slot = np.full(n_coarse, -1, np.int64)
        for i in range(bounds[b], bounds[b + 1]):
            start = P_indptr[i]
            d = 0.0
            for e in range(indptr[i], indptr[i + 1]):
                d += abs(data[e]) * 1.0
            d_inv = 1.0 / abs(d) if d != 0.0 else 0.0
            k = start
            for e in range(indptr[i], indptr[i + 1]):
                j = np.uint64(indices[e])
                J = agg[j]
                if J < 0:
                    continue
                if slot[J] < start:
                    slot[J] = k
                    P_indices[k] = J
                    P_data[k] = 0.0
                    k += 1
                P_data[slot[J]] += (omega * (data[e] * d_inv)) * t[j]
            own = agg[i]
            if own >= 0 and slot[own] < start:
                slot[own] = k
                P_indices[k] = own
                P_data[k] = 0.0
                k += 1
            for q in range(start, k):
                P_data[q] = (t[i] if P_indices[q] == own else 0.0) - P_data[q]
    return P_indptr, P_indices, P_data


@njit(cache=True, parallel=True)
def _product(a_indptr, a_indices, a_data, b_start, b_stop, b_indices, b_data, n_cols, bounds):
    """The product of two sparse matrices in one pass (Gustavson: row by row, each row's entries summed in the
    order of the left row's entries), over the row blocks ``bounds`` of the left one, a CSR matrix. The right one's
    row ``j`` is ``b_indices[b_start[j]:b_stop[j]]`` (and ``b_data``): CSR, or the rows this function returns.

    No pass counts the entries first: each block writes its rows one after the other into its own part of arrays as
    long as the rows' bound (the sum of the lengths of the right rows a left row reads), of which only what is
    written is ever touched. Returns ``(start, stop, indices, values)``, row ``i`` at ``start[i]:stop[i]``."""
    n = a_indptr.shape[0] - 1
    blocks = bounds.shape[0] - 1
    room = np.zeros(blocks + 1, np.int64)  # where each block's part begins
    for b in prange(blocks):
        c = 0
        for e in range(a_indptr[bounds[b]], a_indptr[bounds[b + 1]]):
            j = np.uint64(a_indices[e])
            c += b_stop[j] - b_start[j]
        room[b + 1] = c
    room = np.cumsum(room)
    indices = np.empty(room[blocks], np.int32)
    values = np.empty(room[blocks])
    start = np.empty(n, np.int64)
    stop = np.empty(n, np.int64)
    one = np.uint64(1)
    for b in prange(blocks):  # indices and places unsigned (module docstring of dem.network.amg_kernels)
        slot = np.zeros(n_cols, np.uint64)  # 1 + the place of each column's entry (none in this row if <= first)
        k = np.uint64(room[b])
        for i in range(bounds[b], bounds[b + 1]):
            first = k
            for e in range(np.uint64(a_indptr[i]), np.uint64(a_indptr[i + 1])):
                j = np.uint64(a_indices[e])
                v = a_data[e]
                for f in range(np.uint64(b_start[j]), np.uint64(b_stop[j])):
                    J = np.uint64(b_indices[f])
                    if slot[J] <= first:
                        k += one
                        slot[J] = k
                        indices[k - one] = b_indices[f]
                        values[k - one] = 0.0
                    values[slot[J] - one] += v * b_data[f]
            start[i], stop[i] = first, k
    return start, stop, indices, values


@njit(cache=True, parallel=True)
def _compact(start, stop, indices, values, bounds):
    """The CSR arrays of the rows ``start[i]:stop[i]`` of :func:`_product`, copied over the row blocks ``bounds``,
    each row's entries sorted by column as they are copied (insertion: a coarse row has a few dozen)."""
    n = start.shape[0]
    indptr = np.zeros(n + 1, np.int64)
    indptr[1:] = np.cumsum(stop - start)
    out_indices = np.empty(indptr[n], np.int32)
    out_values = np.empty(indptr[n])
    for b in prange(bounds.shape[0] - 1):
        for i in range(bounds[b], bounds[b + 1]):
            first = indptr[i]
            k = first
            for e in range(start[i], stop[i]):
                column, value = indices[e], values[e]
                m = k
                while m > first and out_indices[m - 1] > column:
                    out_indices[m] = out_indices[m - 1]
                    out_values[m] = out_values[m - 1]
                    m -= 1
                out_indices[m] = column
                out_values[m] = value
                k += 1
    return indptr, out_indices, out_values


def galerkin(A, P, R) -> sp.csr_matrix:
    """:math:`R (A P)` for CSR matrices, on numba's threads: the rows of :math:`A P` as ``_product`` leaves
    them, never copied into CSR.

    Parameters
    ----------
    A, P, R : scipy.sparse.csr_matrix
        The fine matrix (n, n), the prolongator (n, n_c) and the restriction (n_c, n).

    Returns
    -------
    scipy.sparse.csr_matrix
        The coarse matrix (n_c, n_c), its column indices sorted.
    """
    p_rows = P.indptr.astype(np.int64)  # where P's rows begin and end, as A P's: one compiled product, not two
    AP = _product(A.indptr, A.indices, A.data, p_rows[:-1], p_rows[1:], P.indices, P.data, P.shape[1],
                  row_blocks(A.indptr, BLOCKS))
    bounds = row_blocks(R.indptr, BLOCKS)
    rows = _product(R.indptr, R.indices, R.data, *AP, P.shape[1], bounds)
    del AP  # freed before the compaction's arrays are
    A_c = sp.csr_matrix(_compact(*rows, bounds)[::-1], shape=(R.shape[0], P.shape[1]))
    A_c.has_sorted_indices = True  # sorted by the compaction
    return A_c


def finest_level(A, omega: float):
    """The finest level's transfer operators, the next level's matrix and its near-null-space candidates.

    Parameters
    ----------
    A : scipy.sparse.csr_matrix
        The symmetric positive definite matrix (n, n), every connection strong (pyamg's ``strength=None``).
    omega : float
        The weight of the prolongation smoother (``weighting="local"``).

    Returns
    -------
    tuple
        ``(P, R, A_c, B_c)``: CSR prolongator (n, n_c) and restriction :math:`R = P^T`, the Galerkin matrix
        :math:`A_c = R A P` (n_c, n_c; sorted indices) and the coarse candidates (n_c, 1) of pyamg's
        ``fit_candidates`` for the constant vector.
    """
    from pyamg import amg_core

    n = A.shape[0]
    agg = np.empty(n, dtype=A.indptr.dtype)
    roots = np.empty(n, dtype=A.indptr.dtype)
    n_coarse = amg_core.standard_aggregation(n, A.indptr, A.indices, agg, roots)
    # fit_candidates for the constant vector, to the bit: each aggregate's column of ones normalised,
    # t_i = 1 / |a|^(1/2) on the rows it holds, and the coarse candidate its norm |a|^(1/2)
    held = agg >= 0
    norm = np.sqrt(np.bincount(agg[held], minlength=n_coarse).astype(float))
    t = np.zeros(n)
    t[held] = 1.0 / norm[agg[held]]
    B_c = norm.reshape(-1, 1)
    P = sp.csr_matrix(_prolongator(A.indptr, A.indices, A.data, agg, t, n_coarse, omega,
                                   row_blocks(A.indptr, BLOCKS))[::-1], shape=(n, n_coarse))
    R = P.T.tocsr()
    A_c = galerkin(A, P, R)
    return P, R, A_c, B_c


class CoarseCholesky:
    r"""The exact solve of the coarsest level, a pyamg coarse solver (called as ``solve(A, b)``): the dense Cholesky
    factors of :math:`A`, computed at the first call and kept. A Galerkin matrix :math:`P^T A P` of a symmetric
    positive definite :math:`A` is one too; should the factorisation still fail (positive definite only to less
    than round-off), the pseudo-inverse (pyamg's default coarse solver) is taken instead."""

    def __init__(self):
        self.factors = None
        self.pseudo_inverse = None

    def __call__(self, A, b: np.ndarray) -> np.ndarray:
        """The solution of ``A x = b``.

        Parameters
        ----------
        A : scipy.sparse.spmatrix
            The coarsest level's matrix (n, n); the same at every call.
        b : numpy.ndarray
            The right-hand side (n,).

        Returns
        -------
        numpy.ndarray
            ``x`` (n,).
        """
        import scipy.linalg as la

        if self.factors is None and self.pseudo_inverse is None:
            dense = A.toarray()
            try:
                self.factors = la.cho_factor(dense)
            except la.LinAlgError:
                self.pseudo_inverse = la.pinv(dense)
        if self.factors is None:
            return self.pseudo_inverse @ b
        return la.cho_solve(self.factors, b)


def hierarchy(A, seed: int, options: dict):
    """The hierarchy of ``pyamg.smoothed_aggregation_solver(A, **options)``: the finest level by
    :func:`finest_level`, the coarser ones by ``sinterheat.amg.hierarchy`` (seeded with ``seed``: the finest level
    draws no random number, its weighting being local, so the coarser ones see the generator as pyamg's own setup
    does), every level on CSR, down to a coarsest level of at most ``COARSEST_MAX`` unknowns solved exactly
    (:class:`CoarseCholesky`) instead of ``options``' ``max_coarse`` and coarse solver.

    A V-cycle through a coarsest level of a few unknowns is a rough solve of the level above it, whose aggregates
    are large (on the bench packing of :math:`10^6` particles the levels have 984 312, 60 865, 951 and 15 unknowns):
    solving the third level exactly instead takes the conjugate gradients from 13 iterations to 10 at no cost in the
    setup.

    Parameters
    ----------
    A : scipy.sparse.csr_matrix
        The symmetric positive definite matrix (n, n).
    seed : int
        Seed of numpy's global generator during the coarser levels' setup (restored after).
    options : dict
        pyamg's keywords (``dem.network.linsolve.AMG_OPTIONS``): ``strength=None``, ``improve_candidates=None``,
        ``symmetry="hermitian"`` and a first ``smooth`` entry ``("jacobi", {"omega": w, "weighting": "local"})``.

    Returns
    -------
    pyamg.multilevel.MultilevelSolver
        The hierarchy (its levels' ``A``, ``P``, ``R``; the coarser levels' smoothers are pyamg's).

    Raises
    ------
    ValueError
        ``options`` ask for another finest level than :func:`finest_level` builds.
    """
    from pyamg.multilevel import MultilevelSolver

    from sinterheat import amg

    first, *rest = options["smooth"]
    fixed = {"strength": None, "improve_candidates": None, "symmetry": "hermitian"}
    if (any(options.get(key) != value for key, value in fixed.items()) or first[0] != "jacobi"
            or first[1].get("weighting") != "local"):
        raise ValueError(f"options = {options!r}: the compiled finest level needs {fixed} and a first smooth "
                         f"entry ('jacobi', {{'omega': w, 'weighting': 'local'}})")
    P, R, A_c, B_c = finest_level(A, first[1]["omega"])
    ml = amg.hierarchy(A_c, seed, **{**options, "smooth": rest, "B": B_c, "max_coarse": COARSEST_MAX,
                                     "coarse_solver": CoarseCholesky()})
    level = MultilevelSolver.Level()
    level.A, level.P, level.R, level.B = A, P, R, np.ones((A.shape[0], 1))
    ml.levels.insert(0, level)
    return ml
