"""A node per neck under the pair-neck readings (dem.network.necks, "Pair necks"): a chain of unequal spheres is the
one-node shared-body network to round-off, a turning chain its particles' two-terminal resistances in series, the
simple cubic lattice today's law, and a packing whose necks do not meet close to the one-node law."""

import math

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Material, Particles
from dem.geometry.walls import Wall
from dem.laws.conductance import ConductanceSpec, half_conductance, unequal_factor
from dem.laws.shared_body import face_interaction
from dem.network.heat import build_network, steady
from dem.network.necks import neck_network, steady_necks
from fem_neck import lattice
from verification.lattices import dem_periodic

UNIT = Material(1.0, 1.0, 1.0, "unit")


def _chain(radii, h=0.15, turn=False):
    """Spheres of ``radii`` (mm) in a chain along x, neighbours overlapping by ``h`` times the smaller radius, the
    first fixed at 1, a wall at 0 cutting the last by ``h`` of its radius; with ``turn`` (four spheres) the chain goes
    x, y, x (the two middle spheres have necks at right angles)."""
    r = np.asarray(radii, dtype=float) * 1e-3
    d = r[:-1] + r[1:] - h * np.minimum(r[:-1], r[1:])
    if turn:
        x = np.array([[0, 0, 0], [d[0], 0, 0], [d[0], d[1], 0], [d[0] + d[2], d[1], 0]])
        end = x[-1] + [r[-1] * (1 - h / 2), 0.0, 0.0]
    else:
        x = np.zeros((len(r), 3))
        x[1:, 0] = np.cumsum(d)
        end = x[-1] + [r[-1] * (1 - h / 2), 0.0, 0.0]
    fixed = np.zeros(len(r), dtype=bool)
    fixed[0] = True
    particles = Particles.from_arrays(np.asarray(x, dtype=float), r, fixed * 1.0, materials=(UNIT,), fixed=fixed)
    return particles, (Wall("end", point=end.tolist(), normal=[-1.0, 0.0, 0.0], temperature=0.0),)


@pytest.mark.parametrize("neck", ["newton", "first", "coble"])
def test_a_chain_of_unequal_spheres_is_the_one_node_network(neck):
    """Collinear necks: each particle's element is its halves in series (the fit's unequal-radii correction on both
    halves of a bond multiplies their series as the one-node law multiplies it), so temperatures and flows are the
    one-node shared-body network's to round-off."""
    particles, walls = _chain([1.0, 1.4, 0.8, 1.1])
    spec = ConductanceSpec(law="shared-body", neck=neck)
    net = build_network(particles, walls, spec)
    today = steady(net)
    res = steady_necks(neck_network(ConductanceSpec(law="shared-body", neck=neck, nodes="necks"), particles,
                                    find_bonds(particles, walls, neck), walls=walls))
    assert res.T == pytest.approx(today.T, rel=1e-12, abs=1e-13)
    q = net.K_pairs * (today.T[net.bonds.i] - today.T[net.bonds.j])
    assert res.bond_flow == pytest.approx(q, rel=1e-12)
    assert res.wall_flow == pytest.approx(net.K_walls * today.T[net.bonds.wall_particle], rel=1e-12)
    # the correction is there to be carried: without it the flows would differ by 1e-3, far above the tolerance
    assert np.all(unequal_factor(spec, particles.radius, net.bonds) < 1.0 - 5e-4)


def test_a_turning_chain_is_its_particles_two_terminal_resistances_in_series():
    """The two middle spheres pass the heat between two pair necks at right angles: R_bb + R_cc - 2 R_bc, R_bc the
    interaction of the necks' faces (the discs of the newton neck radius at the contact planes' distances) over
    4 pi kappa r; the chain's flow is 1 K over the sum of the resistances."""
    particles, walls = _chain([1.0, 1.0, 1.0, 1.0], h=0.1, turn=True)
    spec = ConductanceSpec(law="shared-body", nodes="necks")
    bonds = find_bonds(particles, walls, "newton")
    res = steady_necks(neck_network(spec, particles, bonds, walls=walls))
    kappa, r = particles.conductivity, particles.radius
    k_i = half_conductance(spec, kappa[bonds.i], r[bonds.i], bonds.a, bonds.l_i)
    k_j = half_conductance(spec, kappa[bonds.j], r[bonds.j], bonds.a, bonds.l_j)
    k_w = half_conductance(spec, kappa[0], r[3], bonds.wall_a, bonds.wall_l)
    q, arm = bonds.a[0] / r[0], bonds.l_i[0] / r[0]
    assert arm > math.sqrt(1.0 - q * q) + 1e-3  # the pair neck's face is not the cap base: the reading's arm counts
    g = face_interaction([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [arm, arm], [q, q])[0, 1] / (4 * math.pi * r[0])
    R_plain = np.sum(1.0 / k_i) + np.sum(1.0 / k_j) + 1.0 / k_w[0]
    assert res.wall_flow[0] == pytest.approx(1.0 / (R_plain - 4 * g), rel=1e-10)
    assert 4 * g / R_plain > 1e-3  # the interaction matters
    assert res.energy_error < 1e-12


@pytest.mark.parametrize("h", [0.05, 0.2])
def test_simple_cubic_lattice_is_todays_law(h):
    """Six necks in opposite pairs: the interactions cancel in every uniform field, as in the one-node law."""
    cell = lattice.lattice_cell("sc", h)
    assert dem_periodic(cell, "shared-body", "newton", nodes="necks") == pytest.approx(
        dem_periodic(cell, "shared-body", "newton"), rel=1e-12)


def test_a_packing_whose_necks_do_not_meet_is_close_to_the_one_node_law():
    """A periodic BCC cell at h/r 0.1 (newton necks a/r 0.45, apart): the neck-node solve of the particle the one-node
    law reduces to one factor per neck, within 0.1 % of it (the factors are exact for a cubic lattice's isotropic
    tensors; what remains is the faces' interaction against the cap bases' centres)."""
    cell = lattice.lattice_cell("bcc", 0.1)
    k_necks = dem_periodic(cell, "shared-body", "newton", nodes="necks")
    k_one = dem_periodic(cell, "shared-body", "newton")
    assert 1e-6 < abs(k_necks / k_one - 1.0) < 1e-3
