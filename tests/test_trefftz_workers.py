"""The Trefftz elements built on several threads (dem.network.trefftz_element, "On every core"): the same elements,
bit for bit, as the serial loop's, on a periodic cell and on a packing between walls, with a mask of Trefftz particles
and with particles the quadrature's check refines or sends back to the law; the threads did build them; a worker's
error is the serial loop's; a bad worker count is refused in one line."""

import threading

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.periodic import PeriodicBox
from dem.geometry.particles import Particles
from dem.geometry.walls import Wall
from dem.network import trefftz_element as te
from dem.network.necks import neck_network
from test_mixed_modes import HALF, _cell
from test_neck_nodes import NECKS, UNIT

# The Trefftz element's kernels take numba 25 s to compile in a fresh clone: with the slow tests.
pytestmark = pytest.mark.slow


class _Captured(Exception):
    """Raised by the hook once it has the elements' arguments: the network itself is not needed."""


def _arguments(particles, bonds, **network):
    """The arguments :func:`dem.network.necks.neck_network` gives its ``elements`` hook."""
    seen = {}

    def hook(*args, **kwargs):
        seen.update(args=args, kwargs=kwargs)
        raise _Captured

    with pytest.raises(_Captured):
        neck_network(NECKS, particles, bonds, elements=hook, **network)
    return seen["args"], seen["kwargs"]


def _periodic_cell():
    particles, bonds, box = _cell()
    return _arguments(particles, bonds, box=box)


def _between_walls():
    """Twelve spheres (radii 0.9-1.1 mm) jittered about a simple cubic lattice of 1.75 mm, two by two across x and y
    (periodic) and three high, between a hot wall cutting the lowest layer and a cold one cutting the highest."""
    rng = np.random.default_rng(4)
    d = 1.75e-3
    x = (np.stack(np.meshgrid(np.arange(2), np.arange(2), np.arange(3), indexing="ij"), -1).reshape(-1, 3) + 0.5) * d
    x += rng.uniform(-0.1e-3, 0.1e-3, x.shape)
    walls = (Wall("hot", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),
             Wall("cold", point=[0.0, 0.0, 3 * d - 0.2e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    box = PeriodicBox([2 * d, 2 * d, 3 * d], periodic=(True, True, False))
    particles = Particles.from_arrays(x, rng.uniform(0.9e-3, 1.1e-3, len(x)), np.full(len(x), 0.5),
                                      materials=(UNIT,))
    bonds = find_bonds(particles, walls, "union", box=box)
    assert bonds.n_walls == 8
    return _arguments(particles, bonds, box=box, walls=walls)


def _threads_used(monkeypatch):
    """Record the name of the thread that computes each particle's element."""
    names = []
    element = te.particle_element

    def recorded(k, cut):
        names.append(threading.current_thread().name)
        return element(k, cut)

    monkeypatch.setattr(te, "particle_element", recorded)
    return names


def _same(a, b):
    return all(np.array_equal(x, y) for x, y in zip(a, b)) and len(a) == len(b)


@pytest.mark.parametrize("packing, where", [(_periodic_cell, HALF), (_between_walls, None),
                                            (_between_walls, np.arange(12) % 3 != 1)])
def test_two_threads_build_the_serial_loops_elements_bit_for_bit(monkeypatch, packing, where):
    args, kwargs = packing()
    serial = te.trefftz_elements(*args, **kwargs, where=where, workers=1)
    names = _threads_used(monkeypatch)
    threaded = te.trefftz_elements(*args, **kwargs, where=where, workers=2)
    assert len(set(names)) == 2 and all(name.startswith("trefftz") for name in names)
    assert len(names) == (args[0] if where is None else where.sum())
    assert _same(serial, threaded)


def test_refined_and_fallback_particles_are_the_serial_loops_bit_for_bit(monkeypatch):
    """A stricter check (DEFECT 1e-5) on the packing between walls: particles computed at each of the rule's
    factors and some sent back to the law's monopoles, on two threads as in the serial loop."""
    monkeypatch.setattr(te, "DEFECT", 1e-5)
    args, kwargs = _between_walls()
    serial = te.trefftz_elements(*args, **kwargs, workers=1)
    assert set(serial.refine) == set(te.REFINE) and 0 < serial.plain.sum() < args[0]
    assert _same(serial, te.trefftz_elements(*args, **kwargs, workers=2))


def test_a_workers_error_is_the_serial_loops(monkeypatch):
    """Two particles failing: the first of them in particle order is named, as by the serial loop."""
    element = te.particle_element

    def failing(k, cut):
        if k in (9, 5):
            raise ValueError(f"the Trefftz element: particle {k} has a neck with no face (inside another's cap)")
        return element(k, cut)

    monkeypatch.setattr(te, "particle_element", failing)
    args, kwargs = _between_walls()
    for workers in (1, 2):
        with pytest.raises(ValueError, match="particle 5 has"):
            te.trefftz_elements(*args, **kwargs, workers=workers)


@pytest.mark.parametrize("workers", [0, -1, 1.5, True, "2"])
def test_a_bad_worker_count_is_refused_in_one_line(workers):
    args, kwargs = _between_walls()
    with pytest.raises(ValueError, match=r"workers = .*: must be an integer >= 1") as err:
        te.trefftz_elements(*args, **kwargs, workers=workers)
    assert "\n" not in str(err.value)
