"""The compiled geometry of the pair bonds (dem.geometry.pair_geometry) is the numpy route's to the bit."""

import dataclasses

import numpy as np
import pytest

from dem.geometry import bonds as bond_search
from dem.geometry.bonds import _pair_geometry, find_bonds
from dem.geometry.particles import Particles


def test_compiled_geometry_is_the_numpy_one_to_the_bit():
    """Random bonds of unequal spheres, two with coinciding centres (L_i = -inf, L_j = inf): every array equal."""
    rng = np.random.default_rng(7)
    x = rng.uniform(0.0, 1e-3, (500, 3))
    x[11] = x[10]
    r = rng.uniform(20e-6, 90e-6, 500)
    i = np.sort(rng.integers(0, 250, 4000))
    j = rng.integers(250, 500, 4000)
    i[0], j[0] = 10, 11
    compiled = _pair_geometry(x, r, i, j, None)
    plain = _pair_geometry(x, r, i, j, x[j] - x[i])
    assert compiled[4][0] == -np.inf and compiled[5][0] == np.inf
    for name, a, b in zip(("r_i", "r_j", "d", "h", "L_i", "L_j"), compiled, plain):
        assert np.array_equal(a, b), name


@pytest.mark.parametrize("contact", ["newton", "lens"])
def test_bonds_of_a_packing_the_same_on_both_routes(monkeypatch, contact):
    """find_bonds on a packing searched by cells (compiled geometry) and by k-d trees (numpy): the same bonds."""
    from dem.geometry.generators import random_packing

    lay = random_packing(3000, 50e-6, 0.15, seed=2)
    particles = Particles.from_arrays(lay.position, lay.radius, np.zeros(len(lay.radius)))
    found = []
    for cells_from in (1000, 10**9):
        monkeypatch.setattr(bond_search, "CELL_SEARCH_MIN", cells_from)
        found.append(find_bonds(particles, contact=contact))
    assert found[0].n_pairs > 3000
    for field in dataclasses.fields(found[0]):
        a, b = getattr(found[0], field.name), getattr(found[1], field.name)
        assert (a == b) if a is None or np.isscalar(a) or isinstance(a, str) else np.array_equal(a, b), field.name
