"""Sparse assembly of element matrices (:class:`Assembly`), and conjugate gradients with a two-level additive
Schwarz preconditioner (memory linear in the unknowns).

``M^-1 r = P (P^T A P)^-1 P^T r + D^-1 r``: a coarse space ``P`` (for high-order elements the piecewise-linear hats,
for the hybridised fluxes the face means), whose Galerkin matrix gets one smoothed-aggregation AMG V-cycle (pyamg),
plus Jacobi: point Jacobi, or block Jacobi on small groups of unknowns (the moments of one face). The coarse space
removes the low-frequency error, the local part the high-order one (Toselli & Widlund 2005, Ch. 2; Pavarino 1994
for the p-version).
"""

from __future__ import annotations

import numpy as np

ENERGY_WINDOW = 10  # steps whose energy drops bound the error left (:func:`solve`)


class TwoLevel:
    """The preconditioner of the module docstring, as a callable ``r -> M^-1 r``: the local part ``D^-1`` is point
    Jacobi, or block Jacobi on the groups of unknowns ``blocks (B, n)`` (one row of dof indices per group; the
    moments of one face) whose diagonal blocks of ``A`` are ``block_matrices (B, n, n)`` (point Jacobi on the
    unknowns of no group), kept as one sparse matrix."""

    def __init__(self, A, P, blocks: np.ndarray | None = None, block_matrices: np.ndarray | None = None):
        import pyamg
        import scipy.sparse as sp

        self.P = P.tocsr()
        self.PT = self.P.T.tocsr()
        coarse = (self.PT @ A @ self.P).tocsr()
        self.amg = pyamg.smoothed_aggregation_solver(coarse, symmetry="symmetric", max_coarse=500).aspreconditioner(
            cycle="V")
        rest = np.ones(A.shape[0], dtype=bool)
        rows, cols, values = [], [], []
        if blocks is not None:
            if len(np.unique(blocks)) != blocks.size:
                raise ValueError("blocks: a dof belongs to two blocks")
            rest[blocks] = False
            rows.append(np.broadcast_to(blocks[:, :, None], block_matrices.shape).ravel())
            cols.append(np.broadcast_to(blocks[:, None, :], block_matrices.shape).ravel())
            values.append(np.linalg.inv(block_matrices).ravel())
        rest = np.flatnonzero(rest)
        rows.append(rest)
        cols.append(rest)
        values.append(1.0 / A.diagonal()[rest])
        self.local = sp.csr_matrix((np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))),
                                   shape=A.shape)

    def __call__(self, r: np.ndarray) -> np.ndarray:
        return self.P @ self.amg(self.PT @ r) + self.local @ r


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


def two_level(A, P, blocks: np.ndarray | None = None, block_matrices: np.ndarray | None = None) -> TwoLevel:
    return TwoLevel(A, P, blocks, block_matrices)


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
