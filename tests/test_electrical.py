"""Current between particles: Kirchhoff's solve against series and parallel resistances, Tellegen's theorem and
charge conservation; Zohdi 2014's area-weighted iteration (eq. 43) against Remark 4 and against the same network
solve with contact areas as weights; floating groups and electrodes without a path."""

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.network.current import Electrodes, area_weighted_current, kirchhoff
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.network.laplacian import BoundedLaplacian, solve_anchored
from dem.geometry.particles import Material, Particles
from dem.geometry.walls import Wall

SIGMA = 0.1  # S/m (Zohdi 2014, Sec. 7)
LENS = ConductanceSpec("zohdi")


def electrodes(potential=(1.0, 0.0), current=(np.nan, np.nan)):
    return Electrodes(("top", "bottom"), (0, 1), np.array(potential, dtype=float), np.array(current, dtype=float))


def chain_packing(n=5, r=0.075, overlaps=None, columns=((0.0, 0.0),)):
    """Chains of spheres along x between a bottom plane (x = 0) and a top plane, each sphere overlapping the next
    (and the planes) by ``overlaps`` (one per contact, bottom plane first)."""
    overlaps = np.full(n + 1, 0.1 * r) if overlaps is None else np.asarray(overlaps, dtype=float)
    x = [r - overlaps[0]]
    for k in range(1, n):
        x.append(x[-1] + 2 * r - overlaps[k])
    top = x[-1] + r - overlaps[n]
    pos = np.array([[xx, y, z] for (y, z) in columns for xx in x])
    particles = Particles.from_arrays(pos, np.full(len(pos), r), np.zeros(len(pos)),
                                      (Material(SIGMA, 2000.0, 100.0),))
    walls = [Wall("top", [top, 0, 0], [-1, 0, 0], 0.0), Wall("bottom", [0, 0, 0], [1, 0, 0], 0.0)]
    return particles, walls


def solve(particles, walls, el, spec=LENS):
    bonds = find_bonds(particles, walls, spec.contact)
    G, G_w, share = bond_conductances(spec, particles, bonds, np.full(particles.n, SIGMA), shares=True)
    flow = kirchhoff(particles.n, bonds.i, bonds.j, G, share, bonds.wall_particle, bonds.wall_index, G_w, el)
    return bonds, G, G_w, flow


def test_series_chain_is_the_sum_of_its_resistances():
    overlaps = np.array([0.05, 0.1, 0.2, 0.15, 0.3, 0.08]) * 0.075
    particles, walls = chain_packing(5, overlaps=overlaps)
    bonds, G, G_w, flow = solve(particles, walls, electrodes((2.0, 0.0)))
    resistance = np.sum(1.0 / G) + np.sum(1.0 / G_w)
    current = flow.electrode_current[0]
    assert current == pytest.approx(2.0 / resistance, rel=1e-13)
    assert flow.electrode_current[1] == pytest.approx(-current, rel=1e-13)
    assert np.allclose(-flow.pair_current, current, rtol=1e-13)  # the same current (downwards, j to i) in every contact
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-13)
    assert flow.electrode_power == pytest.approx(2.0 * current, rel=1e-13)
    assert flow.residual < 1e-13
    # each contact's heat I^2/G shared by its particles; all of it is in the particles
    assert flow.joule_particles.sum() == pytest.approx(current**2 * resistance, rel=1e-13)


def test_parallel_chains_add_their_conductances():
    overlaps = [np.array([0.05, 0.1, 0.2, 0.15]) * 0.075, np.array([0.2, 0.2, 0.2, 0.2]) * 0.075]
    systems = [chain_packing(3, overlaps=o) for o in overlaps]
    # the same chains side by side (far apart laterally) between the same planes: place them by hand
    pos = np.vstack([systems[0][0].position, systems[1][0].position + [0.0, 1.0, 0.0]])
    top_a, top_b = systems[0][1][0].point[0], systems[1][1][0].point[0]
    assert top_a != top_b  # different heights: one top plane cannot touch both, so give each its own electrode
    particles = Particles.from_arrays(pos, np.full(len(pos), 0.075), np.zeros(len(pos)),
                                      (Material(SIGMA, 2000.0, 100.0),))
    walls = [Wall("top_a", [top_a, 0, 0], [-1, 0, 0], 0.0), Wall("bottom", [0, 0, 0], [1, 0, 0], 0.0),
             Wall("top_b", [top_b, 0, 0], [-1, 0, 0], 0.0)]
    bonds = find_bonds(particles, walls, "lens")
    keep = ~((bonds.wall_index == 0) & (bonds.wall_particle >= 3)) & ~((bonds.wall_index == 2)
                                                                         & (bonds.wall_particle < 3))
    G, G_w, share = bond_conductances(LENS, particles, bonds, np.full(particles.n, SIGMA), shares=True)
    el = Electrodes(("top_a", "bottom", "top_b"), (0, 1, 2), np.array([1.5, 0.0, 1.5]), np.full(3, np.nan))
    flow = kirchhoff(particles.n, bonds.i, bonds.j, G, share, bonds.wall_particle[keep], bonds.wall_index[keep],
                     G_w[keep], el)
    resistances = []
    for chain in (0, 1):
        inside = (bonds.i >= 3) == bool(chain)
        walls_of = (bonds.wall_particle[keep] >= 3) == bool(chain)
        resistances.append(np.sum(1.0 / G[inside]) + np.sum(1.0 / G_w[keep][walls_of]))
    total = 1.5 * (1.0 / resistances[0] + 1.0 / resistances[1])
    assert -flow.electrode_current[1] == pytest.approx(total, rel=1e-13)
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-13)


def test_resistor_network_and_fixed_current_electrode():
    """A Wheatstone bridge of given conductances between two electrodes, one at 0 V, one driving 3 A: the potentials
    match a dense solve of Kirchhoff's laws, the delivered power equals the Joule heat, every node balances."""
    # nodes 0..3; edges with conductances (S); electrode A (driven) on node 0, ground on node 3
    i, j = np.array([0, 0, 1, 2, 1]), np.array([1, 2, 3, 3, 2])
    G = np.array([1.0, 2.0, 3.0, 4.0, 0.5])
    G_w = np.array([10.0, 20.0])
    el = Electrodes(("A", "ground"), (0, 1), np.array([np.nan, 0.0]), np.array([3.0, np.nan]))
    flow = kirchhoff(4, i, j, G, np.full(5, 0.5), np.array([0, 3]), np.array([0, 1]), G_w, el)
    # dense: unknowns phi_0..phi_3 and V_A; KCL at every node and the 3 A into node 0 from A
    M = np.zeros((5, 5))
    for a, b, g in zip(i, j, G):
        M[a, a] += g; M[b, b] += g; M[a, b] -= g; M[b, a] -= g  # noqa: E702
    M[0, 0] += G_w[0]; M[0, 4] -= G_w[0]; M[3, 3] += G_w[1]  # noqa: E702
    M[4, 0], M[4, 4] = -G_w[0], G_w[0]  # the current leaving electrode A is 3 A
    x = np.linalg.solve(M, np.array([0, 0, 0, 0, 3.0]))
    assert np.allclose(flow.potential, x[:4], rtol=1e-13)
    assert flow.electrode_potential[0] == pytest.approx(x[4], rel=1e-13)
    assert flow.electrode_current == pytest.approx([3.0, -3.0], rel=1e-13)
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-13) and flow.electrode_power == \
        pytest.approx(3.0 * x[4], rel=1e-13)
    assert flow.residual < 1e-13


def random_box_packing(n=150, seed=2):
    """Particles on a jittered cubic lattice with overlaps, between a bottom and a top plane (x axis)."""
    rng = np.random.default_rng(seed)
    r = 0.075
    side = int(round(n ** (1 / 3)))
    g = np.arange(side) * 1.8 * r + r
    X, Y, Z = np.meshgrid(g, g, g, indexing="ij")
    pos = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()]) + rng.uniform(-0.1, 0.1, (side**3, 3)) * r
    particles = Particles.from_arrays(pos, np.full(len(pos), r), np.zeros(len(pos)),
                                      (Material(SIGMA, 2000.0, 100.0),))
    walls = [Wall("top", [pos[:, 0].max() + 0.9 * r, 0, 0], [-1, 0, 0], 0.0),
             Wall("bottom", [pos[:, 0].min() - 0.9 * r, 0, 0], [1, 0, 0], 0.0)]
    return particles, walls


def test_current_conserved_and_joule_equals_power_in_a_packing():
    particles, walls = random_box_packing()
    bonds, G, G_w, flow = solve(particles, walls, electrodes((5.0, 0.0)))
    assert bonds.n_walls > 10 and bonds.n_pairs > 200
    assert flow.residual < 1e-12
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-12)
    assert flow.electrode_current[0] == pytest.approx(-flow.electrode_current[1], rel=1e-12)
    assert len(flow.floating) == 0 or np.all(np.isnan(flow.potential[flow.floating]))


def test_fixed_current_drives_the_potential_it_needs():
    particles, walls = random_box_packing()
    _, _, _, by_potential = solve(particles, walls, electrodes((1.0, 0.0)))
    resistance = 1.0 / by_potential.electrode_current[0]
    _, _, _, by_current = solve(particles, walls, electrodes((np.nan, 0.0), (4.0, np.nan)))
    assert by_current.electrode_potential[0] == pytest.approx(4.0 * resistance, rel=1e-12)
    assert by_current.electrode_current[0] == pytest.approx(4.0, rel=1e-12)
    assert np.allclose(by_current.potential, 4.0 * resistance * by_potential.potential, rtol=1e-11)


def test_floating_group_and_electrode_without_path():
    particles, walls = chain_packing(4)
    pos = np.vstack([particles.position, [[0.2, 2.0, 0.0], [0.34, 2.0, 0.0]]])  # a pair touching nothing else
    particles = Particles.from_arrays(pos, np.full(6, 0.075), np.zeros(6), (Material(SIGMA, 2000.0, 100.0),))
    _, _, _, flow = solve(particles, walls, electrodes((1.0, 0.0)))
    assert flow.floating.tolist() == [4, 5] and np.all(np.isnan(flow.potential[4:]))
    assert flow.joule_particles[4:].tolist() == [0.0, 0.0]
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-13)
    # the top plane lifted off the chain: the driven electrode reaches no ground
    lifted = [Wall("top", walls[0].point + [1.0, 0, 0], [-1, 0, 0], 0.0), walls[1]]
    _, _, _, flow = solve(particles, lifted, electrodes((np.nan, 0.0), (2.0, np.nan)))
    assert flow.no_path == ("top",)
    assert flow.electrode_current.tolist() == [0.0, 0.0] and flow.joule_heat == 0.0


def test_no_reference_potential_is_refused():
    particles, walls = chain_packing(3)
    with pytest.raises(ValueError, match="no electrode at a fixed potential"):
        solve(particles, walls, electrodes((np.nan, np.nan), (1.0, -1.0)))


def zohdi_inputs(particles, walls):
    bonds = find_bonds(particles, walls, "lens")
    return bonds, np.pi * bonds.a**2


def test_remark_4_chain_with_equal_areas_interpolates_linearly():
    particles, walls = chain_packing(7)
    bonds, area = zohdi_inputs(particles, walls)
    res = area_weighted_current(particles.n, bonds.i, bonds.j, area, bonds.wall_particle, bonds.wall_index,
                                np.array([100.0, -20.0]), tol=1e-14)
    J = res.J
    assert res.converged and J[6] == 100.0 and J[0] == -20.0  # the end particles take their wall's value
    assert np.allclose(J[1:-1], 0.5 * (J[:-2] + J[2:]), rtol=0, atol=1e-11)  # each interior value: the mean
    assert np.allclose(J, np.linspace(-20.0, 100.0, 7), atol=1e-11)


def test_area_weighted_iteration_is_the_network_solve_with_areas_as_conductances():
    """Zohdi's converged J is Kirchhoff's potential with conductances A_ij and the wall particles fixed: the same
    generic network solve gives it to round-off (where the two schemes agree)."""
    particles, walls = random_box_packing()
    bonds, area = zohdi_inputs(particles, walls)
    J_ext = np.array([3.0, 1.0])
    res = area_weighted_current(particles.n, bonds.i, bonds.j, area, bonds.wall_particle, bonds.wall_index, J_ext,
                                tol=1e-13, max_sweeps=100_000)
    assert res.converged and res.sweeps > 20
    touching = np.zeros(particles.n, dtype=bool)
    touching[bonds.wall_particle] = True
    value = np.zeros(particles.n)
    value[bonds.wall_particle] = J_ext[bonds.wall_index]
    system = BoundedLaplacian(particles.n, bonds.i, bonds.j, area, touching, [], [], [], 0)
    _, label, anchored = system.components()
    subset = np.flatnonzero(anchored[label])
    x, _ = solve_anchored(system, system.boundary_rhs(value[system.fixed], []), subset)
    assert np.allclose(res.J[system.free[subset]], x, rtol=0, atol=1e-10)


def test_equal_walls_heat_everything_in_zohdi_scheme_but_drive_no_current():
    particles, walls = chain_packing(5)
    bonds, area = zohdi_inputs(particles, walls)
    res = area_weighted_current(particles.n, bonds.i, bonds.j, area, bonds.wall_particle, bonds.wall_index,
                                np.array([1e5, 1e5]))
    assert np.allclose(res.J, 1e5)
    _, _, _, flow = solve(particles, walls, electrodes((7.0, 7.0)))
    assert flow.joule_heat < 1e-30 and np.all(np.abs(flow.pair_current) < 1e-16) and flow.residual < 1e-2
