"""Sparse assembly of element matrices (:class:`Assembly`), and conjugate gradients with a two-level additive
Schwarz preconditioner (memory linear in the unknowns).

``M^-1 r = P (P^T A P)^-1 P^T r + D^-1 r``: a coarse space ``P`` (for high-order elements the piecewise-linear hats,
for the hybridised fluxes the face means), whose Galerkin matrix gets one smoothed-aggregation AMG V-cycle (pyamg),
plus Jacobi: point Jacobi, or block Jacobi on small groups of unknowns (``blocks``: one row of dof indices per
group, -1 padded; the moments of one face). The coarse space removes the low-frequency error, the local part the
high-order one (Toselli & Widlund 2005, Ch. 2; Pavarino 1994 for the p-version).
"""

from __future__ import annotations

import numpy as np

ENERGY_WINDOW = 10  # steps whose energy drops bound the error left (:func:`solve`)


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


class Assembly:
    """The system of the free unknowns, assembled chunk by chunk from element matrices on the global dofs ``l2g (E,
    n)``, the dofs marked ``fixed`` held at ``values``. Only the free block is stored (COO with 32-bit indices,
    allocated once, then CSR); the element matrices of a chunk can be dropped after :meth:`add`. ``A_ff x = b`` gives
    the free values; :meth:`energy` is ``u^T A u`` of the full vector exactly, whatever ``x``."""

    def __init__(self, l2g: np.ndarray, fixed: np.ndarray, values: np.ndarray):
        self.free = np.flatnonzero(~fixed)
        index = np.full(len(fixed), -1, dtype=np.int32)
        index[self.free] = np.arange(len(self.free), dtype=np.int32)
        self.l2g, self.fixed, self.values = l2g, fixed, values
        self.loc = index[l2g]                                                  # (E, n), -1 on fixed dofs
        count = np.sum(self.loc >= 0, axis=1) ** 2
        self.offset = np.concatenate([[0], np.cumsum(count)])
        self.rows = np.empty(self.offset[-1], dtype=np.int32)
        self.cols = np.empty(self.offset[-1], dtype=np.int32)
        self.data = np.empty(self.offset[-1])
        self.b = np.zeros(len(self.free))
        self.constant = 0.0

    def add(self, K: np.ndarray, elements: np.ndarray) -> None:
        loc = self.loc[elements]
        known = np.where(self.fixed[self.l2g[elements]], self.values[self.l2g[elements]], 0.0)
        load = -np.matmul(K, known[:, :, None])[:, :, 0]
        on = loc >= 0
        self.b += np.bincount(loc[on], load[on], minlength=len(self.free))
        self.constant -= float(np.sum(known * load))
        pair = on[:, :, None] & on[:, None, :]
        span = slice(self.offset[elements[0]], self.offset[elements[-1] + 1])
        self.rows[span] = np.broadcast_to(loc[:, :, None], K.shape)[pair]
        self.cols[span] = np.broadcast_to(loc[:, None, :], K.shape)[pair]
        self.data[span] = K[pair]

    def matrix(self):
        """``A_ff`` (CSR); frees the COO arrays."""
        import scipy.sparse as sp

        A = sp.csr_matrix((self.data, (self.rows, self.cols)), shape=(len(self.free), len(self.free)))
        del self.rows, self.cols, self.data
        return A

    def energy(self, A, x: np.ndarray) -> float:
        """``u^T A u`` of ``u`` = ``x`` on the free dofs, the fixed values elsewhere: ``x A_ff x - 2 x b + u_d A_dd
        u_d`` (``A_fd u_d = -b``)."""
        return float(x @ (A @ x) - 2.0 * (x @ self.b) + self.constant)


def two_level(A, P, blocks: np.ndarray | None = None) -> TwoLevel:
    return TwoLevel(A, P, blocks)


def solve(A, b: np.ndarray, precondition, rtol: float = 1e-10, maxiter: int = 5000,
          x0: np.ndarray | None = None, energy: tuple[float, float] | None = None) -> tuple[np.ndarray, int, float]:
    """Conjugate gradients on the SPD ``A x = b`` to ``|r| <= rtol |b|``: ``(x, iterations, |r| / |b|)``;
    ``RuntimeError`` if ``maxiter`` iterations do not reach it.

    ``energy = (E0, etol)`` stops instead on the energy ``E(x) = x A x - 2 b x + const`` (``E0`` at ``x0``), which
    CG lowers by ``alpha_k r_k . z_k`` in step k: when the last ``ENERGY_WINDOW`` steps together lowered it by less
    than ``etol E(x)``. The error left is then ~``etol E`` (the steps shrink geometrically), about half the
    iterations of a residual of ``etol`` -- enough for a Dirichlet energy, which bounds the exact one from above
    whatever ``x`` (the energy error after step k is the sum of the later drops; Strakos & Tichy 2002)."""
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
            if len(drops) >= ENERGY_WINDOW and sum(drops[-ENERGY_WINDOW:]) <= energy[1] * abs(left):
                return x, it, res
        z = precondition(r)
        rz_new = float(r @ z)
        p = z + (rz_new / rz) * p
        rz = rz_new
    raise RuntimeError(f"conjugate gradients did not converge: relative residual {res:.1e} after {maxiter} "
                       "iterations")
