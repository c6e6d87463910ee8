"""The steady network's fast assembly against the general one: the Laplacian of canonical edges written row by row
against scipy's summed COO entries, the connected groups from the free block against the edge list, and the heat
flow through a packing (what k_eff is made of) by the cell search, the row-by-row Laplacian and AMG-CG against the
k-d trees, the summed assembly and a direct solve; and a small static solve without numba."""

import subprocess
import sys

import numpy as np
import pytest
import scipy.sparse as sp

from dem.geometry import bonds as bond_search
from dem.geometry.bonds import sorted_pairs
from dem.network.laplacian import BoundedLaplacian, laplacian


def summed_laplacian(n, i, j, K):
    """The Laplacian as scipy sums its COO entries (the general route)."""
    diag = np.bincount(i, K, n) + np.bincount(j, K, n)
    return sp.csr_matrix((np.concatenate([-K, -K, diag]), (np.concatenate([i, j, np.arange(n)]),
                                                            np.concatenate([j, i, np.arange(n)]))), shape=(n, n))


@pytest.mark.parametrize("n, m", [(1, 0), (7, 0), (60, 300), (3000, 12000)])
def test_canonical_edges_give_the_summed_laplacian_to_the_bit(n, m):
    rng = np.random.default_rng(n)
    i, j = sorted_pairs(rng.integers(0, n, m), rng.integers(0, n, m), n)
    i, j = i[i != j], j[i != j]
    K = rng.uniform(0.0, 2.0, len(i))
    K[::5] = 0.0  # open contacts stay explicit entries
    L, ref = laplacian(n, i, j, K), summed_laplacian(n, i, j, K)
    assert np.array_equal(L.indptr, ref.indptr) and np.array_equal(L.indices, ref.indices)
    assert np.array_equal(L.data, ref.data)
    if len(i) > 2:  # the same edges out of order and reversed take the summed route: the same matrix
        order = rng.permutation(len(i))
        shuffled = laplacian(n, j[order], i[order], K[order])
        assert abs(shuffled - L).max() <= 1e-15 * np.abs(L.data).max()


@pytest.mark.parametrize("n, m, n_fixed, canonical", [(1, 0, 0, True), (7, 0, 2, True), (60, 300, 0, True),
                                                      (60, 300, 60, True), (3000, 12000, 150, True),
                                                      (3000, 12000, 150, False)])
def test_compiled_laplacian_and_blocks_are_scipys_selection_to_the_bit(n, m, n_fixed, canonical, monkeypatch):
    """L, L_FF and L_FD written row by row (compiled) are, entry for entry, dtype for dtype and to the bit (the sign
    of an open contact's zero too), the Laplacian and scipy's row and column selection of its blocks; edges out of
    order take the general route, whose matrices they are then."""
    from dem.network import laplacian as assembly

    rng = np.random.default_rng(m + n_fixed)
    i, j = sorted_pairs(rng.integers(0, n, m), rng.integers(0, n, m), n)
    i, j = i[i != j], j[i != j]
    K = rng.uniform(0.0, 2.0, len(i))
    K[::5] = 0.0
    if not canonical:
        i, j = i[::-1], j[::-1]
    fixed = np.zeros(n, dtype=bool)
    fixed[rng.permutation(n)[:n_fixed]] = True
    built = []
    for compiled_from in (10**9, 0):
        monkeypatch.setattr(assembly, "COMPILED_ASSEMBLY_FROM", compiled_from)
        g = BoundedLaplacian(n, i, j, K, fixed, np.zeros(0, int), np.zeros(0, int), np.zeros(0), 0)
        built.append((g.L, g.L_FF, g.L_FD))
    for general, compiled in zip(*built):
        assert general.shape == compiled.shape
        for a, b in ((general.indptr, compiled.indptr), (general.indices, compiled.indices)):
            assert a.dtype == b.dtype and np.array_equal(a, b)
        assert general.data.tobytes() == compiled.data.tobytes()
    if n_fixed == 0:
        assert built[1][1] is built[1][0]
    # new conductances on the compiled matrices (the blocks first, L written later): rewritten in place as a fresh
    # general assembly writes them
    K2 = rng.uniform(0.5, 1.0, len(i))
    g.L_FF, g.refresh(i, j, K2, np.zeros(0, int), np.zeros(0, int), np.zeros(0))
    monkeypatch.setattr(assembly, "COMPILED_ASSEMBLY_FROM", 10**9)
    ref = BoundedLaplacian(n, i, j, K2, fixed, np.zeros(0, int), np.zeros(0, int), np.zeros(0), 0)
    for a, b in ((g.L, ref.L), (g.L_FF, ref.L_FF), (g.L_FD, ref.L_FD)):
        assert a.shape == b.shape and np.abs((a - b).toarray()).max(initial=0.0) <= 1e-15 * (1.0 + abs(b).sum())


# all contacts closed (the free block's graph: scipy's search, or compiled as for a large network), some open (edges)
@pytest.mark.parametrize("open_every, compiled", [(0, False), (0, True), (3, False)])
def test_groups_are_those_of_the_closed_edges(open_every, compiled, monkeypatch):
    from dem.network import laplacian as assembly

    monkeypatch.setattr(assembly, "COMPILED_GROUPS_FROM", 0 if compiled else 10**9)
    rng = np.random.default_rng(2)
    n = 400
    i, j = sorted_pairs(rng.integers(0, n, 300), rng.integers(0, n, 300), n)
    i, j = i[i != j], j[i != j]
    K = rng.uniform(0.5, 1.0, len(i))
    if open_every:
        K[::open_every] = 0.0
    fixed = np.zeros(n, dtype=bool)
    fixed[:20] = True
    g = BoundedLaplacian(n, i, j, K, fixed, np.zeros(0, int), np.zeros(0, int), np.zeros(0), 0)
    count, label, anchored = g.components()
    # reference: union-find over the closed edges between free nodes
    parent = np.arange(n)

    def root(a):
        while parent[a] != a:
            a = parent[a]
        return a

    for a, b, k in zip(i, j, K):
        if k > 0 and not fixed[a] and not fixed[b]:
            parent[root(a)] = root(b)
    roots = np.array([root(a) for a in g.free])
    assert count == len(np.unique(roots))
    same = roots[:, None] == roots[None, :]
    assert np.array_equal(same, label[:, None] == label[None, :])
    touches = np.zeros(n, dtype=bool)
    for a, b, k in zip(i, j, K):
        if k > 0 and fixed[a] != fixed[b]:
            touches[b if fixed[a] else a] = True
    assert np.array_equal(anchored[label], np.isin(roots, roots[touches[g.free]]))


def test_shared_matrix_is_the_free_block_only_where_the_sum_would_copy_it():
    """``matrix(shared=True)`` is ``L_FF`` itself where nothing is added to its diagonal; with a diagonal added or a
    zero entry (an open contact, which the sum drops) it is the sum, as without sharing, to the bit."""
    rng = np.random.default_rng(3)
    n = 300
    chain = np.arange(n)  # every node bonded: no zero diagonal (an isolated node's, which the sum would drop too)
    i, j = sorted_pairs(np.r_[rng.integers(0, n, 900), chain[:-1]], np.r_[rng.integers(0, n, 900), chain[1:]], n)
    i, j = i[i != j], j[i != j]
    fixed = np.zeros(n, dtype=bool)
    fixed[:10] = True
    for K, extra, alike in ((rng.uniform(0.5, 1.0, len(i)), None, True),
                            (rng.uniform(0.5, 1.0, len(i)), rng.uniform(0.0, 1.0, n - 10), False),
                            (np.where(np.arange(len(i)) % 4 == 0, 0.0, 1.0), None, False)):
        g = BoundedLaplacian(n, i, j, K, fixed, np.zeros(0, int), np.zeros(0, int), np.zeros(0), 0)
        A, summed = g.matrix(extra, shared=True), g.matrix(extra)
        assert (A is g.L_FF) == alike and summed is not g.L_FF
        assert np.array_equal(A.indptr, summed.indptr) and np.array_equal(A.indices, summed.indices)
        assert np.array_equal(A.data, summed.data)


def test_compiled_groups_are_scipys_numbered_alike():
    """The compiled union-find's groups of a symmetric pattern (many groups, single nodes, the diagonal present or
    not) are scipy's undirected search's, numbered alike (by their smallest nodes)."""
    from scipy.sparse.csgraph import connected_components

    from dem.network.groups import groups

    rng = np.random.default_rng(7)
    n = 5000
    i, j = sorted_pairs(rng.integers(0, n, 3000), rng.integers(0, n, 3000), n)
    keep = i != j
    for diagonal in (True, False):
        L = laplacian(n, i[keep], j[keep], rng.uniform(0.5, 1.0, int(keep.sum())))
        if not diagonal:
            L.setdiag(0.0)
            L.eliminate_zeros()
        count, label = groups(L.indptr, L.indices)
        ref_count, ref_label = connected_components(L, directed=False)
        assert count == ref_count > 1000 and np.array_equal(label, ref_label)


def test_heat_flow_through_a_packing_is_that_of_the_general_route(monkeypatch):
    """The cold layer's heat flow (k_eff's numerator) and the temperatures: cells, row-by-row Laplacian and AMG-CG
    (rtol 1e-10) against k-d trees, the summed Laplacian and a direct solve, to 1e-8 relative."""
    from dem.geometry.bonds import find_bonds
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles
    from dem.network import laplacian as assembly
    from dem.network.heat import boundary_heat_flow, build_network, steady

    lay = random_packing(8000, 50e-6, 0.15, seed=3)
    n = len(lay.radius)
    fixed = np.zeros(n, dtype=bool)
    fixed[lay.bottom] = fixed[lay.top] = True
    temp = np.zeros(n)
    temp[lay.bottom] = 1.0
    particles = Particles.from_arrays(lay.position, lay.radius, temp, fixed=fixed)

    def cold_flow(cells_from, assemble, linear):
        monkeypatch.setattr(bond_search, "CELL_SEARCH_MIN", cells_from)
        monkeypatch.setattr(assembly, "laplacian", assemble)
        net = build_network(particles, bonds=find_bonds(particles))
        res = steady(net, floating="mean", linear=linear)
        flows = boundary_heat_flow(net, res.T)["particles"]
        return sum(flows[int(k)] for k in lay.top), res.T, res.solver

    fast, T_fast, solver = cold_flow(1000, laplacian, "amg")
    ref, T_ref, _ = cold_flow(10**9, summed_laplacian, "direct")
    assert solver == "amg" and ref > 0
    assert fast == pytest.approx(ref, rel=1e-8)
    assert np.max(np.abs(T_fast - T_ref)) < 1e-8


@pytest.mark.parametrize("law", ["rojek", "argento-bouvard"])
def test_linear_halves_and_series_take_numbers_as_the_arrays_do(law):
    """The linear laws' halves (Rojek 2022 eq. 43, Argento & Bouvard eq. 42), computed in place for arrays, give a
    number for numbers (the docstring's ``float or array_like``) equal to the array's entry, and so does ``series``."""
    from dem.laws.conductance import LINEAR_SLOPES, ConductanceSpec, half_conductance, series

    spec = ConductanceSpec(law=law)
    kappa, r, a, length = 394.0, 1e-3, 1e-4, 9e-4
    one = half_conductance(spec, kappa, r, a, length)
    many = half_conductance(spec, np.full(3, kappa), np.full(3, r), np.full(3, a), np.full(3, length))
    assert np.ndim(one) == 0 and float(one) == LINEAR_SLOPES[law] * kappa * np.pi * a
    assert np.array_equal(many, np.full(3, float(one)))
    assert half_conductance(spec, kappa, r, np.array([a, 2 * a]), length).tolist() == [
        LINEAR_SLOPES[law] * kappa * np.pi * x for x in (a, 2 * a)]  # a number's conductivity, an array of necks
    assert float(series(one, one)) == float(series(many, many)[0]) == 1.0 / (1.0 / float(one) + 1.0 / float(one))


SMALL_STATIC = """
import sys
import dem.engines.static
from benchmarks.dem import packing_network
from dem.network.heat import steady
steady(packing_network(2000)[0], floating="mean")
print("numba" in sys.modules)
"""


@pytest.mark.slow  # a fresh process: 2-3 s
def test_a_small_static_solve_loads_no_numba():
    """Below the compiled sizes (the cell search's and the compiled cycle's) the static engine's modules, the bonds,
    the network and the steady solve of the bench packing (``benchmarks.dem.packing_network``) import no numba, whose import and first kernel load cost a fresh process about
    0.7 s of CPU."""
    out = subprocess.run([sys.executable, "-c", SMALL_STATIC], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False"]
