"""The spatial partition of a distributed run (:mod:`dem.geometry.bisection`), without MPI: balanced cells, and a
halo that holds the partner of every bond of the cell's particles (so that a bond search over the cell and its
halo finds all of them), across periodic faces too."""

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.generators import random_packing
from dem.geometry.particles import Particles
from dem.geometry.bisection import bisection, halo
from dem.geometry.periodic import PeriodicBox
from dem.parallel.comm import launched


@pytest.mark.parametrize("parts", [1, 2, 3, 4, 7])
def test_cells_share_the_particles_evenly(parts):
    x = np.random.default_rng(0).random((1001, 3)) * [3.0, 1.0, 2.0]
    owner = bisection(x, parts)
    counts = np.bincount(owner, minlength=parts)
    assert len(counts) == parts and counts.sum() == len(x)
    assert counts.max() - counts.min() <= parts  # each cut within one particle of its share
    if parts == 2:  # two slabs across the longest axis
        assert x[owner == 0, 0].max() <= x[owner == 1, 0].min()


@pytest.mark.parametrize("periodic", [False, True])
@pytest.mark.parametrize("parts", [2, 4])
def test_the_halo_holds_every_bond_partner(periodic, parts):
    lay = random_packing(600, 1.0, 0.1, seed=4, periodic=periodic)
    box = PeriodicBox(lay.period) if periodic else None
    particles = Particles.from_arrays(lay.position, lay.radius, np.zeros(len(lay.radius)))
    bonds = find_bonds(particles, box=box)
    lengths = None if box is None else box.lengths
    owner = bisection(lay.position, parts, lengths)
    reach = 2.0 * lay.radius.max() * (1 + 1e-9)
    crossing = 0
    for rank in range(parts):
        held = np.zeros(len(owner), dtype=bool)
        held[halo(lay.position, owner, rank, reach, lengths, None if box is None else box.mask)] = True
        assert not np.any(held & (owner == rank))
        mine_i, mine_j = owner[bonds.i] == rank, owner[bonds.j] == rank
        assert np.all(held[bonds.j[mine_i & ~mine_j]]) and np.all(held[bonds.i[mine_j & ~mine_i]])
        crossing += int(np.sum(mine_i & ~mine_j))
    assert crossing > 0  # the cells do share bonds: the test looks at some


def test_launched_reads_the_launcher(monkeypatch):
    for name in ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS", "DEM_MPI"):
        monkeypatch.delenv(name, raising=False)
    assert not launched()
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "1")
    assert not launched()
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "2")
    assert launched()
    monkeypatch.setenv("OMPI_COMM_WORLD_SIZE", "1")
    monkeypatch.setenv("DEM_MPI", "1")
    assert launched()
