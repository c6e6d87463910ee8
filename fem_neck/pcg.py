"""Sparse assembly of element matrices, and preconditioned conjugate gradients with a two-level additive Schwarz preconditioner (memory linear in the
unknowns).

``M^-1 r = P (P^T A P)^-1 P^T r + D^-1 r``: a coarse space ``P`` (for high-order elements the piecewise-linear hats,
for the hybridised fluxes the face means), whose Galerkin matrix is solved by one smoothed-aggregation AMG V-cycle
(pyamg), plus block Jacobi on small groups of unknowns (``blocks``: one row of dof indices per group, -1 padded).
The coarse space removes the low-frequency error, the blocks the high-order one within an edge, face or element
(Toselli & Widlund 2005, Ch. 2; Pavarino 1994 for the p-version).
"""

from __future__ import annotations

import numpy as np


class TwoLevel:
    """The preconditioner of the module docstring, as a callable ``r -> M^-1 r``."""

    def __init__(self, A, P, blocks: np.ndarray | None = None):
        import pyamg

        self.P = P.tocsr()
        self.PT = self.P.T.tocsr()
        coarse = (self.PT @ A @ self.P).tocsr()
        self.amg = pyamg.smoothed_aggregation_solver(coarse, symmetry="symmetric", max_coarse=500).aspreconditioner(
            cycle="V")
        if blocks is None:
            self.blocks = None
            self.inv_diag = 1.0 / A.diagonal()
        else:
            self.blocks = blocks
            mask = blocks >= 0
            idx = np.where(mask, blocks, 0)
            sub = np.where(mask[:, :, None] & mask[:, None, :], entries(A, idx[:, :, None], idx[:, None, :]), 0.0)
            n = blocks.shape[1]
            sub[:, np.arange(n), np.arange(n)] += ~mask                # identity on padding
            self.inverses = np.linalg.inv(sub)
            self.mask = mask
            self.idx = idx
            self.covered = blocks[mask]
            if len(np.unique(self.covered)) != len(self.covered):
                raise ValueError("blocks: a dof belongs to two blocks")
            covered = np.zeros(A.shape[0], dtype=bool)
            covered[self.covered] = True
            self.rest = np.flatnonzero(~covered)
            self.inv_diag_rest = 1.0 / A.diagonal()[self.rest]

    def __call__(self, r: np.ndarray) -> np.ndarray:
        z = self.P @ self.amg(self.PT @ r)
        if self.blocks is None:
            return z + self.inv_diag * r
        local = np.where(self.mask, r[self.idx], 0.0)
        corr = np.matmul(self.inverses, local[:, :, None])[:, :, 0]
        z[self.covered] += corr[self.mask]  # the blocks do not overlap
        z[self.rest] += self.inv_diag_rest * r[self.rest]
        return z


def entries(A, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """``A[rows, cols]`` elementwise for broadcast index arrays (zeros where ``A`` has no entry)."""
    A = A.tocsr()
    A.sort_indices()
    n = A.shape[1]
    keys = np.repeat(np.arange(A.shape[0], dtype=np.int64), np.diff(A.indptr)) * n + A.indices
    rows, cols = np.broadcast_arrays(rows, cols)
    want = rows.astype(np.int64) * n + cols
    pos = np.minimum(np.searchsorted(keys, want), len(keys) - 1)
    return np.where(keys[pos] == want, A.data[pos], 0.0)


def assemble(K: np.ndarray, l2g: np.ndarray, fixed: np.ndarray, values: np.ndarray):
    """The system of the free unknowns from element matrices ``K (E, n, n)`` on the global dofs ``l2g (E, n)``,
    with the dofs marked ``fixed`` held at ``values``: ``(A_ff (CSR), b, free)`` so that ``A_ff x = b`` gives the
    free values ``x`` (``free``: their global indices). Only the free block is ever built."""
    import scipy.sparse as sp

    free = np.flatnonzero(~fixed)
    index = np.full(len(fixed), -1, dtype=np.int32)
    index[free] = np.arange(len(free), dtype=np.int32)
    loc = index[l2g]                                                           # (E, n), -1 on fixed dofs
    known = np.where(fixed[l2g], values[l2g], 0.0)
    load = -np.einsum("eij,ej->ei", K, known)
    on = loc >= 0
    b = np.bincount(loc[on], load[on], minlength=len(free))
    pair = on[:, :, None] & on[:, None, :]
    rows = np.broadcast_to(loc[:, :, None], K.shape)[pair]
    cols = np.broadcast_to(loc[:, None, :], K.shape)[pair]
    A = sp.csr_matrix((K[pair], (rows, cols)), shape=(len(free), len(free)))
    return A, b, free


def element_energy(K: np.ndarray, l2g: np.ndarray, u: np.ndarray) -> float:
    """``sum_K u_K^T K u_K``: the energy of the global vector ``u``."""
    uK = u[l2g]
    return float(np.einsum("ei,eij,ej->", uK, K, uK))


def two_level(A, P, blocks: np.ndarray | None = None) -> TwoLevel:
    return TwoLevel(A, P, blocks)


def solve(A, b: np.ndarray, precondition, rtol: float = 1e-10, maxiter: int = 5000,
          x0: np.ndarray | None = None) -> tuple[np.ndarray, int, float]:
    """Conjugate gradients on the SPD ``A x = b`` to ``|r| <= rtol |b|``: ``(x, iterations, |r| / |b|)``;
    ``RuntimeError`` if ``maxiter`` iterations do not reach it."""
    x = np.zeros_like(b) if x0 is None else x0.copy()
    r = b - A @ x
    norm_b = float(np.linalg.norm(b)) or 1.0
    z = precondition(r)
    p = z.copy()
    rz = float(r @ z)
    for it in range(1, maxiter + 1):
        Ap = A @ p
        alpha = rz / float(p @ Ap)
        x += alpha * p
        r -= alpha * Ap
        res = float(np.linalg.norm(r)) / norm_b
        if res <= rtol:
            return x, it, res
        z = precondition(r)
        rz_new = float(r @ z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    raise RuntimeError(f"conjugate gradients did not converge: relative residual {res:.1e} after {maxiter} "
                       "iterations")
