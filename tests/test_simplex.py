"""fem_neck.simplex: the quadrature rules on the reference tetrahedron integrate every monomial of their degree
exactly (closed form a! b! c! / (a + b + c + 3)!), with all points inside and all weights positive."""

import itertools
import math

import numpy as np
import pytest

from fem_neck import simplex


def _monomial_errors(degree: int, up_to: int) -> np.ndarray:
    x, w = simplex.tet_quadrature(degree)
    errors = []
    for a, b, c in itertools.product(range(up_to + 1), repeat=3):
        if a + b + c == up_to:
            exact = math.factorial(a) * math.factorial(b) * math.factorial(c) / math.factorial(up_to + 3)
            errors.append(np.sum(w * x[:, 0] ** a * x[:, 1] ** b * x[:, 2] ** c) / exact - 1.0)
    return np.abs(errors)


@pytest.mark.parametrize("degree", [1, 4, 6, 8, 10])
def test_tet_quadrature_is_exact_to_its_degree_and_not_beyond(degree):
    for up_to in range(degree + 1):
        assert _monomial_errors(degree, up_to).max() < 1e-13
    assert _monomial_errors(degree, degree + 2).max() > 1e-8      # (odd degrees vanish on the symmetric rules)


@pytest.mark.parametrize("degree, points", [(6, 24), (8, 46)])
def test_symmetric_rules_are_inside_positive_and_smaller_than_the_conical_product(degree, points):
    x, w = simplex.tet_quadrature(degree)
    assert len(w) == points < ((degree + 2) // 2) ** 3
    assert np.all(w > 0.0) and np.all(x > 0.0) and np.all(x.sum(axis=1) < 1.0)
    assert len(np.unique(x.round(12), axis=0)) == points
