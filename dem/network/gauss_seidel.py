"""The Gauss-Seidel sweep of Zohdi 2014's current iteration (eq. 43), compiled: each free particle in turn takes the
contact-area-weighted mean of its neighbours' current, using the values already updated in this sweep."""

from __future__ import annotations

from numba import njit


@njit(cache=True)
def gauss_seidel(indptr, indices, weights, free, J, tol, max_sweeps):
    """Sweeps over the ``free`` particles of the weighted adjacency (CSR ``indptr``, ``indices``, ``weights``) until
    no value changes by more than ``tol`` or ``max_sweeps`` were taken; ``J`` is updated in place. Returns
    ``(sweeps, largest change of the last sweep)``."""
    change = 0.0
    for sweep in range(1, max_sweeps + 1):
        change = 0.0
        for k in range(free.shape[0]):
            i = free[k]
            num = 0.0
            den = 0.0
            for e in range(indptr[i], indptr[i + 1]):
                num += weights[e] * J[indices[e]]
                den += weights[e]
            if den > 0.0:
                new = num / den
                change = max(change, abs(new - J[i]))
                J[i] = new
        if change <= tol:
            return sweep, change
    return max_sweeps, change
