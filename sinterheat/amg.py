"""Smoothed-aggregation algebraic multigrid hierarchies (pyamg) as both packages build them: seeded, and on CSR.

pyamg estimates the spectral radius behind its prolongation smoother by Arnoldi from a random vector of numpy's
global generator; :func:`hierarchy` seeds it (and restores the caller's state), so a solve is the same on every
run, to the bit. pyamg keeps the coarse levels as 1 x 1 block sparse (BSR) matrices, whose Gauss-Seidel sweeps are
several times slower than on CSR; :func:`hierarchy` converts every level's matrix and transfer operators to CSR
(the smoothers dispatch on the format at each call).
"""

from __future__ import annotations

import numpy as np

SEED = 0  # the random start vector of pyamg's spectral-radius estimates


def hierarchy(A, seed: int = SEED, **options):
    """``pyamg.smoothed_aggregation_solver(A, **options)`` seeded with ``seed``, every level on CSR.

    Parameters
    ----------
    A : scipy.sparse matrix
        The symmetric positive definite matrix (n, n).
    seed : int
        Seed of numpy's global generator during the setup (restored after).
    options : object
        Keywords of ``pyamg.smoothed_aggregation_solver`` (``symmetry``, ``max_coarse``, ...).
    """
    import pyamg

    state = np.random.get_state()
    np.random.seed(seed)
    try:
        ml = pyamg.smoothed_aggregation_solver(A, **options)
    finally:
        np.random.set_state(state)
    for level in ml.levels:
        level.A = level.A.tocsr()
        if hasattr(level, "P"):
            level.P, level.R = level.P.tocsr(), level.R.tocsr()
    return ml
