"""A system kept as its element matrices and applied element by element (:class:`ElementSystem`), and conjugate
gradients with a two-level additive Schwarz preconditioner (memory linear in the unknowns).

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
    all unknowns; the moments of one face), kept as one block sparse matrix, or the caller's own ``local`` (block
    Jacobi on the nodes of one mesh edge or face, :meth:`ElementSystem.block_jacobi`).

    Parameters
    ----------
    A : scipy.sparse matrix or ElementSystem
        The symmetric positive definite system matrix (n, n) of the free unknowns (sparse unless ``coarse`` and the
        local part are given).
    P : scipy.sparse matrix
        The coarse space (n, m): column j holds coarse function j on the unknowns.
    coarse : scipy.sparse.csr_matrix, optional
        :math:`P^T A P` (m, m) if the caller has it; computed otherwise.
    block_matrices : numpy.ndarray, optional
        The diagonal blocks (B, k, k) of ``A`` on consecutive groups of ``k`` unknowns (``B k = n``), inverted for the
        block Jacobi part; None for point Jacobi.
    local : scipy.sparse matrix, optional
        The local part :math:`D^{-1}` (n, n) itself (instead of ``block_matrices``).
    """

    def __init__(self, A, P, coarse=None, block_matrices: np.ndarray | None = None, local=None):
        import scipy.sparse as sp

        from sinterheat import amg

        self.P = P.tocsr()
        self.PT = self.P.T.tocsr()
        if coarse is None:
            coarse = (self.PT @ A @ self.P).tocsr()
        self.amg = amg.hierarchy(coarse, symmetry="symmetric", max_coarse=500, smooth=None).aspreconditioner(cycle="V")
        if local is not None:
            if block_matrices is not None:
                raise ValueError("block_matrices and local: give one of them")
            if local.shape != A.shape:
                raise ValueError(f"local: shape {local.shape} for a system of shape {A.shape}")
            self.local = local
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


class ElementSystem:
    r"""The system of the free unknowns kept as its element matrices on the global dofs ``l2g (E, n)``, the dofs marked
    ``fixed`` held at ``values``, and never assembled: ``A @ x`` is :math:`A_{ff} x = \sum_e K_e^{ff} x_e`, each
    element's matrix times its unknowns (the held ones zero) added to its free rows, in one compiled pass (as many
    bytes read as a CSR matrix of the same system, and no sparse pattern to find or place the entries in).
    :meth:`add` stores a chunk's element matrices; every element's must be added before the first product.
    The free dofs ``free`` are numbered in the order the elements first use them, so that an element's unknowns lie
    near each other in memory. The local dofs may come in ``groups``: consecutive local dofs that are consecutive
    global dofs in every element (the nodes of one mesh edge or face), all fixed or all free; :meth:`block_jacobi`
    inverts the system's diagonal block on each. :math:`A_{ff} x = b` gives the free values; :meth:`energy` is
    :math:`u^T A u` of the full vector exactly, whatever ``x``.

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
        E, n = l2g.shape
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
        index = np.full(len(fixed), -1, dtype=np.int64)
        index[self.free] = np.arange(len(self.free))
        self.l2g, self.fixed, self.values = l2g, fixed, values
        self.loc = np.ascontiguousarray(index[l2g])                            # (E, n), -1 on fixed dofs
        self.shape = (len(self.free), len(self.free))
        self.K = np.empty((E, n, n))
        self.added = 0
        self.b = np.zeros(len(self.free))
        self.constant = 0.0

    def add(self, K: np.ndarray, elements: np.ndarray) -> None:
        """Store the element matrices ``K (len(elements), n, n)`` of consecutive ``elements``.

        Parameters
        ----------
        K : numpy.ndarray
            Symmetric element matrices (len(elements), n, n), in the unit of the system (W/K for a conductance
            matrix).
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
        self.K[elements[0]:elements[-1] + 1] = K
        self.added += len(elements)

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        if self.added != len(self.K):
            raise ValueError(f"ElementSystem: {self.added} of {len(self.K)} element matrices added")
        y = np.zeros(len(self.free))
        _element_products(self.K, self.loc, np.ascontiguousarray(x, dtype=float), y)
        return y

    def groups(self) -> np.ndarray:
        """Sizes of the groups of consecutive free unknowns that are one group of local dofs (:class:`ElementSystem`),
        in order."""
        sizes = np.diff(self.offsets)
        lead = self.loc[:, self.offsets[:-1]]
        used = lead >= 0
        first, index = np.unique(lead[used], return_index=True)
        size = np.broadcast_to(sizes, lead.shape)[used][index]
        if len(first) and (first[0] != 0 or np.any(first[1:] != first[:-1] + size[:-1])
                           or first[-1] + size[-1] != len(self.free)):
            raise ValueError("groups: the free unknowns are not all in groups (an unknown no element uses)")
        return size

    def block_jacobi(self):
        """The inverse of the system's block diagonal on the groups of :meth:`groups` (the diagonal blocks summed
        from the element matrices), as CSR: the local part of :class:`TwoLevel`. ValueError if a block has a pivot
        that is not positive."""
        import scipy.sparse as sp

        groups = self.groups()
        starts = np.concatenate([[0], np.cumsum(groups)])
        indptr = np.concatenate([[0], np.cumsum(np.repeat(groups, groups))])
        inverse, columns, ok = _group_inverses(self.K, self.loc, self.offsets, starts, indptr)
        if not ok:
            raise ValueError("groups: a diagonal block of the system has a pivot that is not positive")
        return sp.csr_matrix((inverse, columns, indptr), shape=self.shape)

    def energy(self, x: np.ndarray) -> float:
        """:math:`u^T A u` of ``u`` = ``x`` on the free dofs, the fixed values elsewhere:
        :math:`x A_{ff} x - 2 x b + u_d A_{dd} u_d` (:math:`A_{fd} u_d = -b`).

        Parameters
        ----------
        x : numpy.ndarray
            Values of the free dofs, in the order of ``free``.
        """
        return float(x @ (self @ x) - 2.0 * (x @ self.b) + self.constant)


@njit(cache=True, fastmath=True)
def _element_products(K, loc, x, y):
    """``y += sum_e K_e x_e`` on the free rows: ``x_e`` the element's unknowns ``x[loc[e]]``, zero where ``loc`` is -1
    (a held dof), whose rows are skipped."""
    E, n = loc.shape
    xe = np.empty(n)
    for e in range(E):
        for a in range(n):
            c = loc[e, a]
            xe[a] = x[c] if c >= 0 else 0.0
        for i in range(n):
            c = loc[e, i]
            if c >= 0:
                s = 0.0
                for j in range(n):
                    s += K[e, i, j] * xe[j]
                y[c] += s


@njit(cache=True)
def _group_inverses(K, loc, offsets, starts, out_indptr):
    """The inverses of the diagonal blocks, on the groups of free rows ``starts[g]`` to ``starts[g + 1] - 1``, of the
    system of the element matrices ``K (E, n, n)`` on the free dofs ``loc`` (-1 where held) whose local dofs come in
    the groups ``offsets``: the blocks summed from the elements, then inverted (Gauss-Jordan without pivoting:
    symmetric positive definite blocks); as the data and column indices of a CSR matrix whose rows start at
    ``out_indptr`` (each row holds its group's columns), and False if a pivot is not positive."""
    out = np.zeros(out_indptr[-1])
    columns = np.empty(out_indptr[-1], dtype=np.int64)
    for e in range(K.shape[0]):                                  # the blocks: row i of a group from its first dof
        for g in range(len(offsets) - 1):
            first = loc[e, offsets[g]]
            if first >= 0:
                h = offsets[g + 1] - offsets[g]
                for i in range(h):
                    for j in range(h):
                        out[out_indptr[first + i] + j] += K[e, offsets[g] + i, offsets[g] + j]
    for g in range(len(starts) - 1):
        s, h = starts[g], starts[g + 1] - starts[g]
        block = np.empty((h, 2 * h))
        for i in range(h):
            for j in range(h):
                block[i, j] = out[out_indptr[s + i] + j]
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


def two_level(A, P, coarse=None, block_matrices: np.ndarray | None = None, local=None) -> TwoLevel:
    """The preconditioner :class:`TwoLevel` of ``A`` on the coarse space ``P``.

    Parameters
    ----------
    A : scipy.sparse matrix or ElementSystem
        The symmetric positive definite system matrix (n, n).
    P : scipy.sparse matrix
        The coarse space (n, m).
    coarse : scipy.sparse.csr_matrix, optional
        :math:`P^T A P` if the caller has it.
    block_matrices : numpy.ndarray, optional
        Diagonal blocks (B, k, k) of ``A`` for block Jacobi; None for point Jacobi.
    local : scipy.sparse matrix, optional
        The local part itself (:meth:`ElementSystem.block_jacobi`).
    """
    return TwoLevel(A, P, coarse, block_matrices, local)


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
    A : scipy.sparse matrix, ElementSystem or scipy.sparse.linalg.LinearOperator
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
