"""dem.network.laplacian.BoundedLaplacian: its flux is -L x plus the planes' terms, and edges with K = 0 (the open
pairs of a Verlet list) change neither the flux, nor the solve, nor which groups float."""

import numpy as np
import pytest

from dem.network.laplacian import BoundedLaplacian, solve_anchored


def random_graph(rng, n=40, m=90, planes=3):
    a = rng.integers(0, n, m)
    b = (a + rng.integers(1, n, m)) % n
    key = np.unique(np.minimum(a, b) * n + np.maximum(a, b))  # each edge once
    i, j = key // n, key % n
    K = rng.uniform(0.1, 2.0, len(i))
    plane_node = rng.choice(n, 6, replace=False)
    plane_index = rng.integers(0, planes, 6)
    return n, i, j, K, plane_node, plane_index, rng.uniform(0.5, 1.5, 6)


def test_flux_is_minus_laplacian_plus_plane_terms_and_sums_to_the_planes_inflow():
    rng = np.random.default_rng(3)
    n, i, j, K, pn, pw, Kp = random_graph(rng)
    fixed = np.zeros(n, dtype=bool)
    fixed[[0, 5]] = True
    g = BoundedLaplacian(n, i, j, K, fixed, pn, pw, Kp, 3)
    x, xw = rng.uniform(-1.0, 1.0, n), np.array([2.0, -1.0, 0.5])
    expected = -(g.L @ x) + np.bincount(pn, Kp * (xw[pw] - x[pn]), n)
    flux = g.flux(x, xw)
    assert np.allclose(flux, expected, rtol=0.0, atol=1e-13)
    assert flux.sum() == pytest.approx(np.sum(Kp * (xw[pw] - x[pn])), abs=1e-12)  # edges carry heat, planes supply it
    # after a refresh it is the flux of the new conductances
    K2 = K * rng.uniform(0.5, 2.0, len(K))
    g.refresh(i, j, K2, pn, pw, 2 * Kp)
    fresh = BoundedLaplacian(n, i, j, K2, fixed, pn, pw, 2 * Kp, 3)
    assert np.array_equal(g.flux(x, xw), fresh.flux(x, xw))


def test_zero_conductance_edges_change_no_result_and_join_no_groups():
    """Edges with K = 0 give the flux bit for bit, the solve to round-off, and the same floating groups (an edge
    with K = 0 joins nothing: two chains joined only by it float and anchor on their own)."""
    rng = np.random.default_rng(4)
    # two chains 0-1-2-3 (plane at node 0) and 4-5-6 (no plane): joined by a K = 0 edge (3, 4)
    i, j, K = np.array([0, 1, 2]), np.array([1, 2, 3]), np.array([1.0, 2.0, 3.0])
    i2, j2, K2 = np.array([4, 5]), np.array([5, 6]), np.array([1.5, 0.5])
    pn, pw, Kp = np.array([0]), np.array([0]), np.array([1.0])
    live = BoundedLaplacian(7, np.r_[i, i2], np.r_[j, j2], np.r_[K, K2], None, pn, pw, Kp, 1)
    with_zero = BoundedLaplacian(7, np.r_[i, 3, i2], np.r_[j, 4, j2], np.r_[K, 0.0, K2], None, pn, pw, Kp, 1)
    x = rng.uniform(0.0, 1.0, 7)
    assert np.array_equal(live.flux(x, [2.0]), with_zero.flux(x, [2.0]))
    n_live, label_live, anchored_live = live.components()
    n_zero, label_zero, anchored_zero = with_zero.components()
    assert n_live == n_zero == 2 and np.array_equal(label_live, label_zero)
    assert np.array_equal(anchored_live, anchored_zero) and anchored_zero.tolist() == [True, False]
    anchored = np.flatnonzero(anchored_zero[label_zero])
    rhs = live.boundary_rhs(np.zeros(0), [2.0])
    a, _ = solve_anchored(live, rhs, anchored)
    b, _ = solve_anchored(with_zero, rhs, anchored)
    assert np.allclose(a, 2.0, rtol=1e-12) and np.allclose(b, a, rtol=1e-14, atol=0.0)


def test_components_ignore_zero_edges_on_random_graphs():
    """The groups from the edges with K > 0 are those of the Laplacian without the K = 0 edges, labels included."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        n, i, j, K, pn, pw, Kp = random_graph(rng, n=30, m=25)
        K[rng.random(len(K)) < 0.3] = 0.0
        fixed = rng.random(n) < 0.1
        g = BoundedLaplacian(n, i, j, K, fixed, pn, pw, Kp, 3)
        live = K > 0
        h = BoundedLaplacian(n, i[live], j[live], K[live], fixed, pn, pw, Kp, 3)
        for a, b in zip(g.components(), h.components()):
            assert np.array_equal(a, b)


@pytest.mark.parametrize("with_fixed", [False, True])
def test_refreshed_matrices_are_those_assembled_afresh_also_with_an_edge_listed_twice(with_fixed):
    """The matrices rewritten in place after :meth:`refresh` equal a fresh assembly: on distinct edges to the bit,
    and where an edge is listed twice or a node has a loop (two entries in one place of the Laplacian)."""
    rng = np.random.default_rng(11)
    fixed = np.array([False, False, False, False, True]) if with_fixed else None
    none = np.zeros(0, dtype=np.int64)
    for i, j in ((np.array([0, 1, 2, 3]), np.array([1, 2, 3, 4])),          # a chain: distinct edges
                 (np.array([0, 0, 1, 2, 3]), np.array([1, 1, 2, 2, 4]))):   # 0-1 twice, a loop at 2
        g = BoundedLaplacian(5, i, j, rng.uniform(1.0, 2.0, len(i)), fixed, none, none, np.zeros(0), 0)
        g.L  # assembled once; refreshed from then on
        for _ in range(2):
            K = rng.uniform(1.0, 2.0, len(i))
            g.refresh(i, j, K, none, none, np.zeros(0))
            fresh = BoundedLaplacian(5, i, j, K, fixed, none, none, np.zeros(0), 0)
            for name in ("L", "L_FF", "L_FD"):
                assert np.array_equal(getattr(g, name).toarray(), getattr(fresh, name).toarray()), name
