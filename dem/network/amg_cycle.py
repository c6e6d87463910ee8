r"""The V-cycle that preconditions :class:`dem.network.linsolve.AMGSolver`'s conjugate gradients.

pyamg's hierarchy (``sinterheat.amg.hierarchy``: the levels' matrices and transfer operators on CSR) is cycled here
instead of by ``MultilevelSolver.aspreconditioner``, which runs its cycle through ``solve(maxiter=1)`` and so
computes the residual norm before and after it: two products with the finest matrix per cycle that nothing reads,
a quarter of the cycle's memory traffic. The cycle is pyamg's V-cycle with one symmetric Gauss-Seidel sweep
(forward, then backward: ``linsolve.AMG_SMOOTHER``) before and after each coarse correction, the coarsest level
solved by the hierarchy's own coarse solver.

Its kernels are pyamg's and scipy's (one thread), or from ``COMPILED_FROM`` unknowns of the finest level on, where
the bond search has loaded numba already, the compiled ones of :mod:`dem.network.amg_kernels` on numba's threads,
over ``BLOCKS`` fixed row blocks, with hybrid Gauss-Seidel sweeps, on every level of ``BLOCK_MIN_ROWS`` rows or
more (a smaller level keeps pyamg's and scipy's kernels: on a loaded machine every parallel loop waits for its
slowest thread, which the scheduler may have set aside for milliseconds, more than a small level's work on one). The cycle stays a symmetric positive definite operator either way; the result
does not depend on the number of threads.
"""

from __future__ import annotations

import numpy as np

BLOCKS = 8  # row blocks of a level's matrix: its smoother's hybrid blocks and the threads' shares of every product
BLOCK_MIN_ROWS = 100_000  # a level of fewer rows is swept in one block (sequential Gauss-Seidel)
COMPILED_FROM = 300_000  # unknowns of the finest level from which the compiled kernels run the cycle


class Level:
    """One level of the cycle: its CSR matrix ``A``, restriction ``R`` and prolongation ``P`` (None on the
    coarsest), the kernels that apply them and the level's work arrays.

    Parameters
    ----------
    A, R, P : scipy.sparse.csr_matrix or None
        The level's matrix and its transfer operators to and from the next coarser level.
    blocks : int or None
        Row blocks of the compiled kernels (module docstring); None: pyamg's and scipy's kernels.
    """

    def __init__(self, A, R=None, P=None, blocks: int | None = None):
        n = A.shape[0]
        self.A, self.R, self.P = A, R, P
        self.x, self.b, self.r = (np.zeros(n) for _ in range(3))
        self.kernels = None
        if blocks is not None:
            from dem.network import amg_kernels

            self.kernels = amg_kernels
            A = self.A = A if A.has_sorted_indices else A.sorted_indices()
            self.diag_at = amg_kernels.diagonal_places(A.indptr, A.indices)
            if np.any(self.diag_at < 0):
                raise ValueError(f"A: {int(np.sum(self.diag_at < 0))} rows without a diagonal entry; must be "
                                 "symmetric positive definite")
            self.lower = np.zeros(n)  # the forward sweeps' sums for the backward ones (amg_kernels.hybrid_sweep)
            self.A_blocks = amg_kernels.row_blocks(A.indptr, blocks if n >= BLOCK_MIN_ROWS else 1)
            self.mixed = amg_kernels.mixed_rows(A.indptr, A.indices, self.A_blocks)
            self.R_blocks = None if R is None else amg_kernels.row_blocks(R.indptr, blocks)
            self.P_blocks = None if P is None else amg_kernels.row_blocks(P.indptr, blocks)
            self.copies = (np.zeros(n), np.zeros(n))  # x as the last sweep or prolongation left it, and a spare

    def smooth(self, x, b, from_zero: bool = False):
        """One symmetric Gauss-Seidel sweep of ``A x = b`` (forward, then backward).

        Parameters
        ----------
        x : numpy.ndarray
            The level's unknowns, updated in place.
        b : numpy.ndarray
            The level's right-hand side.
        from_zero : bool
            Sweep from ``x = 0`` (whatever ``x`` holds: it is not read).
        """
        A, k = self.A, self.kernels
        if k is None:
            from pyamg.relaxation.relaxation import gauss_seidel

            if from_zero:
                x[:] = 0.0
            gauss_seidel(A, x, b, iterations=1, sweep="symmetric")
            return
        now, spare = self.copies  # ``now`` holds x (unless from zero)
        first = k.FROM_ZERO if from_zero else k.FORWARD
        k.hybrid_sweep(A.indptr, A.indices, A.data, self.diag_at, x, b, now, spare, self.lower, self.mixed,
                       self.A_blocks, first)
        k.hybrid_sweep(A.indptr, A.indices, A.data, self.diag_at, x, b, spare, now, self.lower, self.mixed,
                       self.A_blocks, k.BACKWARD)

    def restrict_residual(self, x, b, coarse_b):
        """The restricted residual :math:`R (b - A x)`.

        Parameters
        ----------
        x, b : numpy.ndarray
            The level's unknowns and right-hand side.
        coarse_b : numpy.ndarray
            Where the result goes: the next coarser level's right-hand side.
        """
        A, R, k = self.A, self.R, self.kernels
        if k is None:
            coarse_b[:] = R @ (b - A @ x)
            return
        k.residual(A.indptr, A.indices, A.data, x, b, self.r, self.A_blocks)
        k.matvec(R.indptr, R.indices, R.data, self.r, coarse_b, self.R_blocks)

    def prolong_add(self, coarse_x, x):
        """Adds the prolonged correction :math:`P x_c` to ``x``.

        Parameters
        ----------
        coarse_x : numpy.ndarray
            The next coarser level's correction :math:`x_c`.
        x : numpy.ndarray
            The level's unknowns, updated in place.
        """
        P, k = self.P, self.kernels
        if k is None:
            x += P @ coarse_x
            return
        k.add_matvec(P.indptr, P.indices, P.data, coarse_x, x, self.copies[0], self.P_blocks)


class VCycle:
    """The V-cycle of the module docstring on the levels of a pyamg ``MultilevelSolver`` whose matrices and transfer
    operators are CSR.

    Parameters
    ----------
    ml : pyamg.multilevel.MultilevelSolver
        The hierarchy, every level on CSR (one level: the cycle is its coarse solve).
    blocks : int or None
        Row blocks of the compiled kernels on every level (one on a level of fewer than ``BLOCK_MIN_ROWS`` rows; 1:
        sequential sweeps, pyamg's cycle to round-off); None: ``BLOCKS`` on the levels of ``BLOCK_MIN_ROWS`` rows or
        more from ``COMPILED_FROM`` unknowns of the finest level on, pyamg's and scipy's kernels elsewhere.
    """

    def __init__(self, ml, blocks: int | None = None):
        if blocks is not None and blocks < 1:
            raise ValueError(f"blocks = {blocks}: must be at least 1")
        compiled = ml.levels[0].A.shape[0] >= COMPILED_FROM

        def level_blocks(n):
            if blocks is None:  # the default: a small level's sweeps are pyamg's (no thread is woken for them)
                return BLOCKS if compiled and n >= BLOCK_MIN_ROWS else None
            return blocks if n >= BLOCK_MIN_ROWS else 1

        last = len(ml.levels) - 1
        self.levels = [Level(lv.A, lv.R, lv.P, level_blocks(lv.A.shape[0])) if k < last else Level(lv.A)
                       for k, lv in enumerate(ml.levels)]
        self.coarse_solver = ml.coarse_solver

    def __call__(self, b: np.ndarray) -> np.ndarray:
        """One V-cycle from zero on ``A x = b`` (``A`` the finest matrix).

        Parameters
        ----------
        b : numpy.ndarray
            The right-hand side.

        Returns
        -------
        numpy.ndarray
            The cycle's ``x`` (a new array).
        """
        b = np.asarray(b, dtype=float)
        if len(self.levels) == 1:
            return self.coarse_solver(self.levels[0].A, b)
        x = np.empty(len(b))
        self._cycle(0, x, b)
        return x

    def _cycle(self, k, x, b):
        """The cycle from level ``k`` on, from ``x = 0`` (whatever ``x`` holds)."""
        level, coarse = self.levels[k], self.levels[k + 1]
        level.smooth(x, b, from_zero=True)
        level.restrict_residual(x, b, coarse.b)
        if k + 2 == len(self.levels):
            coarse.x[:] = self.coarse_solver(coarse.A, coarse.b)
        else:
            self._cycle(k + 1, coarse.x, coarse.b)
        level.prolong_add(coarse.x, x)
        level.smooth(x, b)
