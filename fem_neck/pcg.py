"""Sparse assembly of element matrices (:class:`Assembly`), and conjugate gradients with a two-level additive
Schwarz preconditioner (memory linear in the unknowns).

:math:`M^{-1} r = P (P^T A P)^{-1} P^T r + D^{-1} r`: a coarse space ``P`` (for high-order elements the piecewise-linear
hats, for the hybridised fluxes the face means), whose Galerkin matrix gets one V-cycle of plain (unsmoothed)
aggregation AMG (pyamg; on the lattice cells as many CG steps as smoothed aggregation, at a fraction of its setup),
plus Jacobi: point Jacobi, or block Jacobi on small groups of unknowns (the moments of one face, the nodes of one mesh
edge or face). The coarse space removes the low-frequency error, the local part the high-order one (Toselli &
Widlund 2005, Ch. 2; Pavarino 1994 for the p-version).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numba import njit

ENERGY_WINDOW = 10  # steps whose energy drops bound the error left (:func:`solve`)


class TwoLevel:
    r"""The preconditioner of the module docstring, as a callable :math:`r \to M^{-1} r`. The coarse matrix
    :math:`P^T A P` is computed unless given (``coarse``, CSR); the local part :math:`D^{-1}` is point Jacobi, or block
    Jacobi on consecutive groups of unknowns whose diagonal blocks of ``A`` are ``block_matrices (B, n, n)`` (``B n`` =
    all unknowns; the moments of one face), kept as one block sparse matrix, or block Jacobi on consecutive ``groups``
    of unknowns of any sizes, the blocks read from ``A`` (CSR; the nodes of one mesh edge or face,
    :meth:`Assembly.groups`).

    Parameters
    ----------
    A : scipy.sparse matrix
        The symmetric positive definite system matrix (n, n) of the free unknowns.
    P : scipy.sparse matrix
        The coarse space (n, m): column j holds coarse function j on the unknowns.
    coarse : scipy.sparse.csr_matrix, optional
        :math:`P^T A P` (m, m) if the caller has it; computed otherwise.
    block_matrices : numpy.ndarray, optional
        The diagonal blocks (B, k, k) of ``A`` on consecutive groups of ``k`` unknowns (``B k = n``), inverted for the
        block Jacobi part; None for point Jacobi.
    groups : numpy.ndarray, optional
        Sizes of consecutive groups of unknowns (summing to n) whose diagonal blocks of ``A`` are inverted for the
        block Jacobi part (instead of ``block_matrices``).
    """

    def __init__(self, A, P, coarse=None, block_matrices: np.ndarray | None = None,
                 groups: np.ndarray | None = None):
        import scipy.sparse as sp

        from sinterheat import amg

        self.P = P.tocsr()
        self.PT = self.P.T.tocsr()
        if coarse is None:
            coarse = (self.PT @ A @ self.P).tocsr()
        self.amg = amg.hierarchy(coarse, symmetry="symmetric", max_coarse=500, smooth=None).aspreconditioner(cycle="V")
        if groups is not None:
            if block_matrices is not None:
                raise ValueError("block_matrices and groups: give one of them")
            if np.sum(groups) != A.shape[0] or np.any(np.asarray(groups) < 1):
                raise ValueError(f"groups: positive sizes summing to the {A.shape[0]} unknowns")
            starts = np.concatenate([[0], np.cumsum(groups)]).astype(A.indptr.dtype)
            indptr = np.concatenate([[0], np.cumsum(np.repeat(groups, groups))]).astype(A.indptr.dtype)
            inverse, indices, ok = _group_inverses(A.data, A.indices, A.indptr, starts, indptr)
            if not ok:
                raise ValueError("groups: a diagonal block of A is not stored whole or has a pivot that is not "
                                 "positive")
            self.local = sp.csr_matrix((inverse, indices, indptr), shape=A.shape)
        elif block_matrices is None:
            self.local = sp.diags(1.0 / A.diagonal(), format="csr")
        else:
            count, n = len(block_matrices), block_matrices.shape[1]
            if count * n != A.shape[0]:
                raise ValueError(f"block_matrices: {count} blocks of {n} unknowns for {A.shape[0]} unknowns")
            inverse, ok = _block_inverses(np.ascontiguousarray(block_matrices, dtype=float))
            if not ok:
                raise ValueError("block_matrices: a block has a pivot that is not positive (not positive definite)")
            self.local = sp.bsr_matrix((inverse, np.arange(count), np.arange(count + 1)), shape=A.shape)

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self.P @ self.amg(self.PT @ r) + self.local @ r


@njit(cache=True)
def _block_inverses(blocks):
    """The inverses of the symmetric positive definite ``blocks (B, n, n)`` by their Cholesky factors
    (:math:`A^{-1} = L^{-T} L^{-1}`; about a third of the flops of LAPACK's solve with the identity that
    ``numpy.linalg.inv`` does, without its per-matrix calls), and False if a pivot is not positive."""
    B, n = blocks.shape[0], blocks.shape[1]
    out = np.empty_like(blocks)
    L = np.empty((n, n))
    for b in range(B):
        for j in range(n):                                       # Cholesky, L lower
            d = blocks[b, j, j]
            for k in range(j):
                d -= L[j, k] * L[j, k]
            if not d > 0.0:
                return out, False
            L[j, j] = np.sqrt(d)
            for i in range(j + 1, n):
                s = blocks[b, i, j]
                for k in range(j):
                    s -= L[i, k] * L[j, k]
                L[i, j] = s / L[j, j]
        for j in range(n):                                       # L^-1 in place, column by column
            L[j, j] = 1.0 / L[j, j]
            for i in range(j + 1, n):
                s = 0.0
                for k in range(j, i):
                    s -= L[i, k] * L[k, j]
                L[i, j] = s / L[i, i]
        for i in range(n):                                       # L^-T L^-1, symmetric
            for j in range(i + 1):
                s = 0.0
                for k in range(i, n):
                    s += L[k, i] * L[k, j]
                out[b, i, j] = out[b, j, i] = s
    return out, True


@njit(cache=True)
def _group_inverses(data, indices, indptr, starts, out_indptr):
    """The inverses of the diagonal blocks of the CSR matrix ``(data, indices, indptr)`` (sorted columns) on the
    groups of rows ``starts[g]`` to ``starts[g + 1] - 1``, as the data and column indices of a CSR matrix whose rows
    start at ``out_indptr`` (each row holds its group's columns), and False if a block is not stored whole or a pivot
    is not positive; Gauss-Jordan without pivoting (symmetric positive definite blocks)."""
    out = np.empty(out_indptr[-1])
    columns = np.empty(out_indptr[-1], dtype=indices.dtype)
    for g in range(len(starts) - 1):
        s, h = starts[g], starts[g + 1] - starts[g]
        block = np.empty((h, 2 * h))
        for i in range(h):
            row = s + i
            k = indptr[row]
            while k < indptr[row + 1] and indices[k] != s:       # the group's columns s .. s + h - 1, in a run
                k += 1
            if k + h > indptr[row + 1] or indices[k + h - 1] != s + h - 1:
                return out, columns, False
            for j in range(h):
                block[i, j] = data[k + j]
                block[i, h + j] = 1.0 if i == j else 0.0
        for p in range(h):                                       # [B | I] -> [I | B^-1]
            if not block[p, p] > 0.0:
                return out, columns, False
            f = 1.0 / block[p, p]
            for j in range(2 * h):
                block[p, j] *= f
            for i in range(h):
                if i != p:
                    f = block[i, p]
                    for j in range(2 * h):
                        block[i, j] -= f * block[p, j]
        for i in range(h):
            for j in range(h):
                out[out_indptr[s + i] + j] = block[i, h + j]
                columns[out_indptr[s + i] + j] = s + j
    return out, columns, True


class Assembly:
    """The system of the free unknowns, assembled chunk by chunk from element matrices on the global dofs ``l2g (E,
    n)``, the dofs marked ``fixed`` held at ``values``. Only the free block is stored, as CSR whose pattern (sorted
    column indices, no duplicates) and every element block's place in it are computed once from ``l2g``
    (``_pattern``); :meth:`add` adds a chunk's element matrices into those places, which can then be dropped.
    The free dofs ``free`` are numbered in the order the elements first use them, so that an element's rows lie
    near each other in memory (the pattern and the additions take half the time of the global dofs' order).
    The local dofs may come in ``groups``: consecutive local dofs that are consecutive global dofs in every element
    (the nodes of one mesh edge or face), all fixed or all free. The rows of one group then have one pattern, found
    once, and an element keeps one place per pair of its groups instead of one per entry.
    :math:`A_{ff} x = b` gives the free values; :meth:`energy` is :math:`u^T A u` of the full vector exactly, whatever
    ``x``.

    Parameters
    ----------
    l2g : numpy.ndarray
        Global dof of each element's local dofs, integers (E, n).
    fixed : numpy.ndarray
        Boolean mask over the global dofs: True where the value is prescribed (Dirichlet).
    values : numpy.ndarray
        Value of every global dof (only those marked ``fixed`` are read), in the unit of the unknown (K for a
        temperature).
    groups : sequence of int, optional
        Sizes of the groups of consecutive local dofs (summing to ``n``); default every dof its own group.
        ValueError if ``l2g`` or ``fixed`` breaks a group.
    """

    def __init__(self, l2g: np.ndarray, fixed: np.ndarray, values: np.ndarray, groups=None):
        n = l2g.shape[1]
        sizes = np.ones(n, dtype=np.int64) if groups is None else np.asarray(groups, dtype=np.int64)
        if np.any(sizes < 1) or sizes.sum() != n:
            raise ValueError(f"groups = {sizes.tolist()}: positive sizes summing to the {n} local dofs")
        self.offsets = np.concatenate([[0], np.cumsum(sizes)])
        within = np.arange(n) - np.repeat(self.offsets[:-1], sizes)          # each local dof's place in its group
        lead = np.repeat(self.offsets[:-1], sizes)
        if np.any(l2g != l2g[:, lead] + within) or np.any(fixed[l2g] != fixed[l2g[:, lead]]):
            raise ValueError("groups: a group's local dofs must be consecutive global dofs, all fixed or all free, "
                             "in every element")
        start, extent = np.full(len(fixed), -1), np.zeros(len(fixed), dtype=np.int64)
        start[l2g], extent[l2g] = l2g[:, lead], np.repeat(sizes, sizes)         # (the last element's, if they differ)
        if np.any(start[l2g] != l2g[:, lead]) or np.any(extent[l2g] != np.repeat(sizes, sizes)):
            raise ValueError("groups: every global dof must lie in one group in every element (the same first dof "
                             "and size)")
        dofs, first = np.unique(l2g, return_index=True)
        first_use = np.full(len(fixed), l2g.size)
        first_use[dofs] = first
        free = np.flatnonzero(~fixed)
        self.free = free[np.argsort(first_use[free], kind="stable")]            # in the order the elements use them
        index_type = np.int32 if len(l2g) * n * n < 2**31 else np.int64
        index = np.full(len(fixed), -1, dtype=index_type)
        index[self.free] = np.arange(len(self.free), dtype=index_type)
        self.l2g, self.fixed, self.values = l2g, fixed, values
        loc = np.ascontiguousarray(index[l2g])                                 # (E, n), -1 on fixed dofs
        self.indptr = np.zeros(len(self.free) + 1, dtype=index_type)
        self.place = np.empty((len(l2g), len(sizes), len(sizes)), dtype=index_type)
        self.indices = _pattern(loc, self.offsets, self.indptr, self.place)
        self.loc = loc
        self.data = np.zeros(len(self.indices))
        self.b = np.zeros(len(self.free))
        self.constant = 0.0

    def add(self, K: np.ndarray, elements: np.ndarray) -> None:
        """Add the element matrices ``K (len(elements), n, n)`` of consecutive ``elements``.

        Parameters
        ----------
        K : numpy.ndarray
            Element matrices (len(elements), n, n), in the unit of the system (W/K for a conductance matrix).
        elements : numpy.ndarray
            Indices of consecutive elements (rows of ``l2g``), ascending without gaps.
        """
        held = self.fixed[self.l2g[elements]]
        near = np.flatnonzero(held.any(axis=1))                                # the elements with a fixed dof
        known = np.where(held[near], self.values[self.l2g[elements[near]]], 0.0)
        load = -np.matmul(K[near], known[:, :, None])[:, :, 0]
        loc = self.loc[elements[near]]
        on = loc >= 0
        self.b += np.bincount(loc[on], load[on], minlength=len(self.free))
        self.constant -= float(np.sum(known * load))
        chunk = slice(elements[0], elements[-1] + 1)
        _scatter(self.data, self.indptr, self.loc[chunk], self.offsets, self.place[chunk], np.ascontiguousarray(K))

    def groups(self) -> np.ndarray:
        """Sizes of the groups of consecutive free unknowns that are one group of local dofs (:class:`Assembly`), in
        order (``TwoLevel``'s ``groups``)."""
        sizes = np.diff(self.offsets)
        lead = self.loc[:, self.offsets[:-1]]
        used = lead >= 0
        first, index = np.unique(lead[used], return_index=True)
        size = np.broadcast_to(sizes, lead.shape)[used][index]
        if len(first) and (first[0] != 0 or np.any(first[1:] != first[:-1] + size[:-1])
                           or first[-1] + size[-1] != len(self.free)):
            raise ValueError("groups: the free unknowns are not all in groups (an unknown no element uses)")
        return size

    def matrix(self):
        """``A_ff`` (CSR); frees the element places."""
        import scipy.sparse as sp

        A = sp.csr_matrix((self.data, self.indices, self.indptr), shape=(len(self.free), len(self.free)))
        A.has_sorted_indices = True
        del self.place
        return A

    def energy(self, A, x: np.ndarray) -> float:
        """:math:`u^T A u` of ``u`` = ``x`` on the free dofs, the fixed values elsewhere:
        :math:`x A_{ff} x - 2 x b + u_d A_{dd} u_d` (:math:`A_{fd} u_d = -b`).

        Parameters
        ----------
        A : scipy.sparse.csr_matrix
            ``A_ff``, as :meth:`matrix` returned it.
        x : numpy.ndarray
            Values of the free dofs, in the order of ``free``.
        """
        return float(x @ (A @ x) - 2.0 * (x @ self.b) + self.constant)


@njit(cache=True)
def _pattern(loc, offsets, indptr, place):
    """The CSR pattern of the free block of an assembly on the element dofs ``loc (E, n)`` (-1 on fixed dofs) whose
    local dofs come in the groups ``offsets`` (:class:`Assembly`): fills ``indptr`` (free dofs + 1) and ``place (E,
    G, G)`` (where the columns of group ``j`` start within the rows of group ``i``, -1 where either is fixed) and
    returns the column indices, sorted within each row. Group by group, through the elements of each group's first
    dof: O(the element matrices' group pairs), plus the indices written."""
    E, n = loc.shape
    G = len(offsets) - 1
    rows = len(indptr) - 1
    first = np.zeros(rows + 1, dtype=np.int64)                   # the group's (element, local group) incidences
    for e in range(E):
        for g in range(G):
            if loc[e, offsets[g]] >= 0:
                first[loc[e, offsets[g]] + 1] += 1
    for r in range(rows):
        first[r + 1] += first[r]
    incidence = np.empty(first[rows], dtype=np.int64)
    filled = first[:-1].copy()
    for e in range(E):
        for g in range(G):
            r = loc[e, offsets[g]]
            if r >= 0:
                incidence[filled[r]] = e * G + g
                filled[r] += 1
    seen = np.full(rows, -1, dtype=np.int64)
    size = np.zeros(rows, dtype=np.int64)                        # the size of the group a column group starts
    leads = np.empty(rows, dtype=np.int64)                       # the current rows' column groups (their first dof)
    column = np.empty(rows, dtype=loc.dtype)                     # a column group's place within the current rows
    indices = np.empty(0, dtype=loc.dtype)
    for sweep in range(2):                                       # the rows' lengths, then their columns and places
        if sweep == 1:
            indices = np.empty(indptr[rows], dtype=loc.dtype)
            seen[:] = -1
        r = 0
        while r < rows:
            if first[r] == first[r + 1]:                         # a dof no element uses
                if sweep == 0:
                    indptr[r + 1] = indptr[r]
                r += 1
                continue
            g = incidence[first[r]] % G
            height = offsets[g + 1] - offsets[g]                 # the rows of this group: r to r + height - 1
            count = 0
            for s in range(first[r], first[r + 1]):              # the distinct column groups of the group's rows
                e = incidence[s] // G
                for h in range(G):
                    c = loc[e, offsets[h]]
                    if c >= 0 and seen[c] != r:
                        seen[c] = r
                        size[c] = offsets[h + 1] - offsets[h]
                        leads[count] = c
                        count += 1
            if sweep == 0:
                width = 0
                for j in range(count):
                    width += size[leads[j]]
                for d in range(height):
                    indptr[r + d + 1] = indptr[r + d] + width
            else:
                ordered = np.sort(leads[:count])
                width = 0
                for j in range(count):
                    column[ordered[j]] = width
                    width += size[ordered[j]]
                k = indptr[r]
                for d in range(height):
                    for j in range(count):
                        for i in range(size[ordered[j]]):
                            indices[k] = ordered[j] + i
                            k += 1
                for s in range(first[r], first[r + 1]):
                    e, g = incidence[s] // G, incidence[s] % G
                    for h in range(G):
                        c = loc[e, offsets[h]]
                        place[e, g, h] = column[c] if c >= 0 else -1
            r += height
    for e in range(E):                                           # the rows of fixed groups
        for g in range(G):
            if loc[e, offsets[g]] < 0:
                place[e, g, :] = -1
    return indices


@njit(cache=True)
def _scatter(data, indptr, loc, offsets, place, K):
    """``data += K`` element after element: entry ``(a, b)`` of element ``e``, ``a`` in group ``i`` and ``b`` in
    group ``j``, goes to ``indptr[loc[e, a]] + place[e, i, j] + (b - offsets[j])`` where that place is not -1."""
    E, G = K.shape[0], len(offsets) - 1
    for e in range(E):
        for i in range(G):
            for j in range(G):
                base = place[e, i, j]
                if base >= 0:
                    for a in range(offsets[i], offsets[i + 1]):
                        start = indptr[loc[e, a]] + base - offsets[j]
                        for b in range(offsets[j], offsets[j + 1]):
                            data[start + b] += K[e, a, b]


def two_level(A, P, coarse=None, block_matrices: np.ndarray | None = None,
              groups: np.ndarray | None = None) -> TwoLevel:
    """The preconditioner :class:`TwoLevel` of ``A`` on the coarse space ``P``.

    Parameters
    ----------
    A : scipy.sparse matrix
        The symmetric positive definite system matrix (n, n).
    P : scipy.sparse matrix
        The coarse space (n, m).
    coarse : scipy.sparse.csr_matrix, optional
        :math:`P^T A P` if the caller has it.
    block_matrices : numpy.ndarray, optional
        Diagonal blocks (B, k, k) of ``A`` for block Jacobi; None for point Jacobi.
    groups : numpy.ndarray, optional
        Sizes of consecutive groups of unknowns for block Jacobi on ``A``'s own blocks (CSR ``A``).
    """
    return TwoLevel(A, P, coarse, block_matrices, groups)


def solve(A, b: np.ndarray, precondition, rtol: float = 1e-10, maxiter: int = 5000,
          x0: np.ndarray | None = None, energy: tuple[float, float] | None = None,
          settled: tuple[float, Callable[[np.ndarray], None]] | None = None) -> tuple[np.ndarray, int, float]:
    r"""Conjugate gradients on the SPD :math:`A x = b` to :math:`|r| \le \mathrm{rtol} \, |b|`:
    ``(x, iterations, |r| / |b|)``; ``RuntimeError`` if ``maxiter`` iterations do not reach it.

    ``energy = (E0, etol)`` stops instead on the energy :math:`E(x) = x A x - 2 b x + \mathrm{const}` (``E0`` at
    ``x0``), which CG lowers by :math:`\alpha_k r_k \cdot z_k` in step k: when the last ``ENERGY_WINDOW`` steps together
    lowered it by less than ``etol E(x)``. The error left is then ~``etol E`` (the steps shrink geometrically), about
    half the iterations of a residual of ``etol`` -- enough for a Dirichlet energy, which bounds the exact one from
    above whatever ``x`` (the energy error after step k is the sum of the later drops; Strakos & Tichy 2002).

    Parameters
    ----------
    A : scipy.sparse matrix or scipy.sparse.linalg.LinearOperator
        The symmetric positive definite matrix (n, n).
    b : numpy.ndarray
        Right-hand side (n,).
    precondition : callable
        :math:`r \to M^{-1} r` for a symmetric positive definite ``M`` (a :class:`TwoLevel`).
    rtol : float
        Relative residual ``|r| / |b|`` to reach (dimensionless; ignored when ``energy`` is given).
    maxiter : int
        Iterations allowed before ``RuntimeError``.
    x0 : numpy.ndarray, optional
        Start vector (n,); zero by default.
    energy : tuple of float, optional
        ``(E0, etol)``: the energy at ``x0`` (in the unit of ``b x``) and the relative energy tolerance
        (dimensionless) of the energy stop above.
    settled : tuple, optional
        ``(tol, report)``: ``report(x)`` is called once with a copy of the first iterate whose energy has settled to
        ``tol`` (relative, looser than ``etol``; by the stop above), or with the result if none did before it (with
        ``energy`` only).
    """
    x = np.zeros_like(b) if x0 is None else x0.copy()
    r = b - A @ x
    norm_b = float(np.linalg.norm(b)) or 1.0
    z = precondition(r)
    p = z.copy()
    rz = float(r @ z)
    drops = []
    for it in range(1, maxiter + 1):
        Ap = A @ p
        alpha = rz / float(p @ Ap)
        x += alpha * p
        r -= alpha * Ap
        res = float(np.linalg.norm(r)) / norm_b
        if energy is None and res <= rtol:
            return x, it, res
        if energy is not None:
            drops.append(alpha * rz)
            left = energy[0] - sum(drops)
            window = sum(drops[-ENERGY_WINDOW:]) if len(drops) >= ENERGY_WINDOW else np.inf
            if settled is not None and (window <= settled[0] * abs(left) or window <= energy[1] * abs(left)):
                settled[1](x.copy())
                settled = None
            if window <= energy[1] * abs(left):
                return x, it, res
        z = precondition(r)
        rz_new = float(r @ z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    raise RuntimeError(f"conjugate gradients did not converge: relative residual {res:.1e} after {maxiter} "
                       "iterations")
