"""sinterheat.amg: the hierarchies both packages build are seeded (the same to the bit on every run, whatever the
caller's random state) and on CSR."""

import numpy as np
import scipy.sparse as sp

from sinterheat import amg


def _laplacian(n=40):
    one = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    return (sp.kron(one, sp.identity(n)) + sp.kron(sp.identity(n), one)).tocsr()


def test_hierarchy_is_seeded_and_leaves_the_callers_random_state():
    A = _laplacian()
    b = np.ones(A.shape[0])
    np.random.seed(1)
    first = amg.hierarchy(A, max_coarse=50).aspreconditioner(cycle="V")(b)
    after = np.random.random()
    np.random.seed(2)
    second = amg.hierarchy(A, max_coarse=50).aspreconditioner(cycle="V")(b)
    np.random.seed(1)
    assert np.random.random() == after                     # the caller's stream goes on as if nothing was drawn
    assert np.array_equal(first, second)


def test_every_level_is_csr():
    ml = amg.hierarchy(_laplacian(), max_coarse=50)
    assert len(ml.levels) >= 2
    assert all(level.A.format == "csr" for level in ml.levels)
    assert all(level.P.format == "csr" and level.R.format == "csr" for level in ml.levels[:-1])
