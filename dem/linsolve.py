"""Sparse symmetric positive definite solves behind one small interface.

``make_solver(A, backend)`` returns an object with ``solve(b, x0=None) -> x`` for a fixed matrix, so a
factorisation or a multigrid hierarchy is built once and reused for every right-hand side (every time step).
Backends (:data:`BACKENDS`; a PETSc/MPI backend is one more entry with the same two methods):

* ``"direct"`` -- sparse LU (SuperLU, symmetric mode with a minimum-degree ordering of ``A + A^T``); exact to
  round-off. Fill-in grows fast on 3D networks, so ``"auto"`` uses it for small systems only.
* ``"cg"`` -- conjugate gradients with a Jacobi (diagonal) preconditioner. Converges in a handful of iterations
  when the capacity term ``C/dt`` dominates the diagonal (implicit steps of large packings).
* ``"amg"`` -- conjugate gradients preconditioned by a smoothed-aggregation algebraic multigrid V-cycle (pyamg),
  for large steady networks.

``"auto"`` picks direct below :data:`DIRECT_MAX` unknowns; above it, Jacobi-CG when the diagonal-dominance bound
on the condition number of the Jacobi-scaled matrix (``1 + 2/rho`` with ``rho = min_i m_i / L_ii``, ``m_i`` the
part of the diagonal beyond the Laplacian) is at most :data:`JACOBI_MAX_CONDITION`, else AMG.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

DIRECT_MAX = 20_000
JACOBI_MAX_CONDITION = 200.0


class SolverError(ValueError):
    """The linear solve failed (no convergence); a ValueError so that the CLI reports it in one line."""


class DirectSolver:
    """Sparse LU, factorised once."""

    name = "direct"

    def __init__(self, A: sp.spmatrix, rtol: float = 0.0):
        self.lu = spl.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
        self.iterations = 0

    def solve(self, b: np.ndarray, x0=None) -> np.ndarray:
        return self.lu.solve(b)


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """Inner product without BLAS: BLAS threads that spin between calls slow the CG loop on a busy machine."""
    return float(np.einsum("i,i->", a, b))


class PCGSolver:
    """Preconditioned conjugate gradients to ``|r| <= rtol |b|``, warm-started from ``x0``."""

    name = "cg"

    def __init__(self, A: sp.spmatrix, rtol: float = 1e-12, max_iterations: int | None = None):
        self.A = sp.csr_matrix(A)
        self.rtol = rtol
        self.max_iterations = max_iterations or max(1000, 10 * int(np.sqrt(self.A.shape[0])))
        self.iterations = 0
        self.precondition = self._preconditioner()

    def _preconditioner(self):
        inv_diag = 1.0 / self.A.diagonal()
        return lambda r: inv_diag * r

    def solve(self, b: np.ndarray, x0=None) -> np.ndarray:
        A, M = self.A, self.precondition
        x = np.zeros_like(b) if x0 is None else np.array(x0, dtype=float)
        r = b - A @ x
        target2 = self.rtol**2 * _dot(b, b)
        rr = _dot(r, r)
        if rr <= target2:
            return x
        z = M(r)
        p = z.copy()
        rz = _dot(r, z)
        for k in range(1, self.max_iterations + 1):
            q = A @ p
            alpha = rz / _dot(p, q)
            x += alpha * p
            q *= alpha
            r -= q
            rr = _dot(r, r)
            if rr <= target2:
                self.iterations += k
                return x
            z = M(r)
            rz_new = _dot(r, z)
            p *= rz_new / rz
            p += z
            rz = rz_new
        raise SolverError(f"{self.name} did not reach rtol = {self.rtol:g} in {self.max_iterations} iterations "
                          f"(relative residual {np.sqrt(rr / _dot(b, b)):.3g}); try solver.linear = "
                          f"\"direct\" or \"amg\"")


class AMGSolver(PCGSolver):
    """CG preconditioned by one smoothed-aggregation V-cycle (pyamg), hierarchy built once."""

    name = "amg"

    def _preconditioner(self):
        import pyamg

        self.hierarchy = pyamg.smoothed_aggregation_solver(self.A, symmetry="hermitian", max_coarse=500)
        return self.hierarchy.aspreconditioner(cycle="V")


BACKENDS = {"direct": DirectSolver, "cg": PCGSolver, "amg": AMGSolver}


def choose_backend(A: sp.spmatrix, laplacian_diagonal: np.ndarray) -> str:
    """The ``"auto"`` rule of the module docstring."""
    n = A.shape[0]
    if n <= DIRECT_MAX:
        return "direct"
    extra = A.diagonal() - laplacian_diagonal
    with np.errstate(divide="ignore"):
        rho = np.min(np.where(laplacian_diagonal > 0, extra / laplacian_diagonal, np.inf))
    return "cg" if rho > 0 and 1.0 + 2.0 / rho <= JACOBI_MAX_CONDITION else "amg"


def make_solver(A: sp.spmatrix, backend: str = "auto", laplacian_diagonal: np.ndarray | None = None,
                rtol: float = 1e-12):
    """A solver for the SPD matrix ``A`` (module docstring)."""
    if backend == "auto":
        backend = choose_backend(A, A.diagonal() if laplacian_diagonal is None else laplacian_diagonal)
    if backend not in BACKENDS:
        raise ValueError(f"solver.linear = {backend!r}: must be one of auto, {', '.join(BACKENDS)}")
    return BACKENDS[backend](A, rtol=rtol)
