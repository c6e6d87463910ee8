"""The transient heat of the network with a node per neck (dem.network.necks, conductance.nodes = "necks"), and the
steady neck solve of a group that floats."""

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.network.necks import neck_network, steady_necks
from fem_neck import lattice
from test_neck_nodes import NECKS, UNIT


def _tiled_bcc(drop=0.2):
    """The BCC union cell at h/r 0.25 (radius 1 mm) tiled 2 x 2 x 2 in a periodic box with a temperature drop per
    period along z, the particles at random initial temperatures."""
    cell = lattice.lattice_cell("bcc", 0.25, neck="union")
    tiles = np.array([(a, b, c) for a in range(2) for b in range(2) for c in range(2)])
    x = 1e-3 * (cell.centres[None] + (tiles * cell.period)[:, None]).reshape(-1, 3)
    r = np.tile(cell.radii * 1e-3, len(tiles))
    box = PeriodicBox(2e-3 * cell.period, drop=[0.0, 0.0, drop])
    particles = Particles.from_arrays(x, r, np.random.default_rng(5).uniform(0.0, 1.0, len(r)), materials=(UNIT,))
    return neck_network(NECKS, particles, find_bonds(particles, contact="union", box=box), box=box)


def test_the_steady_neck_solve_of_a_floating_periodic_group_holds_at_every_node():
    """No anchor and warm particles: the node held while solving is held at the 0 it was solved with (every node's
    row holds), then the group keeps its capacity-weighted mean."""
    net = _tiled_bcc()
    res = steady_necks(net)
    T = np.concatenate([res.T, res.T_necks])
    assert np.max(np.abs(net.A @ T - net.rhs)) < 1e-12 * np.abs(net.A).max()
    C = net.particles.capacity
    assert float(C @ res.T) == pytest.approx(float(C @ net.particles.temperature), rel=1e-12)
    assert np.max(np.abs(res.periodic_heat_flow[:2])) < 1e-12 * abs(res.periodic_heat_flow[2])
