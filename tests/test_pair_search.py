"""The pair search behind the bonds and the neighbour lists: cells searched in blocks on numba's threads against
brute force, with the pairs' distances, and the bond search's two routes (cells for one radius class, k-d trees for
wider ones; the bonds' geometry compiled or by numpy)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from dem.geometry import bonds, neighbours
from dem.geometry.bonds import candidate_pairs
from dem.geometry.neighbours import verlet_pairs
from dem.geometry.particles import Particles


def brute_pairs(x, r, skin=0.0, box=(0.0, 0.0, 0.0)):
    """Every pair ``i < j`` within ``r_i + r_j + skin`` (minimum image on periodic axes), sorted by (i, j)."""
    box = np.asarray(box, dtype=float)
    d = x[:, None, :] - x[None, :, :]
    d -= np.where(box > 0, box, 1.0) * np.round(d / np.where(box > 0, box, np.inf))
    close = np.einsum("ijk,ijk->ij", d, d) < (r[:, None] + r[None, :] + skin) ** 2
    return np.nonzero(np.triu(close, k=1))


@pytest.mark.parametrize("box", [(0.0, 0.0, 0.0), (6e-3, 0.0, 6e-3)])
def test_blocks_give_every_pair_in_order_whatever_room_they_are_given(monkeypatch, box):
    """Blocks of 7 particles (many blocks, slots overflowing or not, one block emptier than the rest) find exactly
    the brute-force pairs, sorted by (i, j)."""
    monkeypatch.setattr(neighbours, "PAIR_BLOCK", 7)
    rng = np.random.default_rng(3)
    x = rng.uniform(0.0, 6e-3, (400, 3))
    x[:7] += 0.01  # the first block away from the rest: no pairs but its own
    r = rng.uniform(0.2e-3, 0.4e-3, 400)
    i_ref, j_ref = brute_pairs(x, r, 1e-4, box)
    assert len(i_ref) > 400
    vec = x[j_ref] - x[i_ref]
    vec -= np.where(np.array(box) > 0, box, 1.0) * np.round(vec / np.where(np.array(box) > 0, box, np.inf))
    d_ref = np.linalg.norm(vec, axis=1)  # the minimum image's lengths
    for capacity in (0, len(i_ref) // 2, len(i_ref), 3 * len(i_ref)):
        i, j = verlet_pairs(x, r, 1e-4, np.array(box), capacity)
        assert np.array_equal(i, i_ref) and np.array_equal(j, j_ref), capacity
        i, j, d = verlet_pairs(x, r, 1e-4, np.array(box), capacity, distances=True)
        assert np.array_equal(i, i_ref) and np.array_equal(j, j_ref) and np.array_equal(d, d_ref), capacity


@pytest.mark.parametrize("cells_from", [10**9, 1000])  # k-d trees always; cells for one class of 1000 or more
@pytest.mark.parametrize("spread", [1.5, 3.0])  # one radius class, two or more (k-d trees)
def test_bond_candidates_are_the_overlapping_pairs(monkeypatch, spread, cells_from):
    monkeypatch.setattr(bonds, "CELL_SEARCH_MIN", cells_from)
    rng = np.random.default_rng(5)
    n = 3000
    r = 1e-4 * rng.uniform(1.0, spread, n)
    x = rng.uniform(0.0, 3e-3 * spread ** (1 / 3) * 1.3, (n, 3))
    tree = cKDTree(x)
    pairs = tree.query_pairs(2.0 * r.max(), output_type="ndarray")
    d = x[pairs[:, 0]] - x[pairs[:, 1]]
    touching = np.einsum("ij,ij->i", d, d) < (r[pairs[:, 0]] + r[pairs[:, 1]]) ** 2
    key = np.sort(pairs[touching, 0] * n + pairs[touching, 1])
    i, j = candidate_pairs(x, r)
    assert len(key) > n
    assert np.array_equal(i, key // n) and np.array_equal(j, key % n)
    # the distances the search computes as it goes: numpy's norms of the bond vectors to the bit
    i, j, d = candidate_pairs(x, r, distances=True)
    assert np.array_equal(i, key // n) and np.array_equal(j, key % n)
    assert np.array_equal(d, np.linalg.norm(x[j] - x[i], axis=1))



@pytest.mark.parametrize("policy", ["error", "clip", "drop"])
@pytest.mark.parametrize("contact", ["newton", "coble", "lens"])
def test_the_compiled_bond_geometry_is_numpys_to_the_bit(monkeypatch, contact, policy):
    """From CELL_SEARCH_MIN particles on the bonds' radii, overlaps, radical planes and range flags come from one
    compiled pass (dem.geometry.bond_kernels): the same bonds as numpy's route to the bit, bonds beyond the range and
    two coincident particles (d = 0: the planes at -inf) included, and the same refusal where the policy refuses."""
    rng = np.random.default_rng(7)
    n = 3000
    r = 1e-4 * rng.uniform(1.0, 1.5, n)
    x = rng.uniform(0.0, 3.2e-3, (n, 3))
    x[1] = x[0]

    def bonds_or_refusal(cells_from):
        monkeypatch.setattr(bonds, "CELL_SEARCH_MIN", cells_from)
        try:
            return bonds.find_bonds(Particles.from_arrays(x, r, np.zeros(n)), contact=contact, out_of_range=policy)
        except ValueError as refusal:
            return str(refusal)

    compiled, by_numpy = bonds_or_refusal(1000), bonds_or_refusal(10**9)
    if policy == "error" or (policy == "clip" and contact == "lens"):  # d = 0: the lens' conductance is infinite
        assert isinstance(by_numpy, str) and compiled == by_numpy
        return
    assert (compiled.clipped or compiled.dropped) > 10
    for field in ("i", "j", "h", "d", "a", "l_i", "l_j"):
        assert np.array_equal(getattr(compiled, field), getattr(by_numpy, field)), field
    assert (compiled.clipped, compiled.dropped) == (by_numpy.clipped, by_numpy.dropped)

def test_a_particle_far_away_does_not_make_the_cell_grid_huge():
    """400 particles in a 6 mm box and one 1 m away along every axis: cells of the cutoff (1 mm) would number
    ~1e9 (8 GB of heads); the grid stays within MAX_CELLS_PER_PARTICLE cells per particle and finds the same pairs."""
    rng = np.random.default_rng(5)
    x = rng.uniform(0.0, 6e-3, (401, 3))
    x[400] = 1.0
    r = rng.uniform(0.2e-3, 0.4e-3, 401)
    cell, head, nxt, ncell, wrap = neighbours._cells(x, r, 1e-4, np.zeros(3))
    assert len(head) == np.prod(ncell) <= neighbours.MAX_CELLS_PER_PARTICLE * 401 + 4096
    i_ref, j_ref = brute_pairs(x, r, 1e-4)
    i, j = verlet_pairs(x, r, 1e-4, np.zeros(3), 0)
    assert np.array_equal(i, i_ref) and np.array_equal(j, j_ref)
