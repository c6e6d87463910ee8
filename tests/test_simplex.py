"""fem_neck.simplex: the quadrature rules on the reference tetrahedron integrate every monomial of their degree
exactly (closed form a! b! c! / (a + b + c + 3)!), with all points inside and all weights positive; the Gauss-Jacobi
rules they and the triangle's are built from are exact to degree 2 n - 1 (closed form: the Beta function)."""

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


@pytest.mark.parametrize("alpha", [0, 1, 2])
@pytest.mark.parametrize("n", [1, 2, 5, 9])
def test_gauss_jacobi_is_gaussian_for_its_weight(alpha, n):
    t, w = simplex._gauss_jacobi(n, float(alpha))
    assert np.all((t > 0.0) & (t < 1.0)) and np.all(w > 0.0) and np.all(np.diff(t) > 0.0)
    for j in range(2 * n + 1):  # int_0^1 (1 - t)^alpha t^j dt = j! alpha! / (j + alpha + 1)!
        exact = math.factorial(j) * math.factorial(alpha) / math.factorial(j + alpha + 1)
        error = abs(np.sum(w * t**j) / exact - 1.0)
        assert error < 1e-13 if j < 2 * n else error > 1e-11  # exact to degree 2 n - 1, not beyond
