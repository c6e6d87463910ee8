"""Steady pipe networks against closed forms: series chains, walls, mixed materials, ambient exchange, singular
systems."""

import numpy as np
import pytest
from scipy.optimize import brentq

from dem import Material, make_scene, run
from dem.laws.conductance import ConductanceSpec
from dem.laws.ambient import STEFAN_BOLTZMANN, Convection, Radiation, Sources
from dem.geometry.walls import Wall
from fem_neck import law as fem_law
from fem_neck.geometry import neck_radius


def chain_arrays(radii, rel_overlap):
    r = np.asarray(radii, float)
    h = np.asarray(rel_overlap) * np.minimum(r[:-1], r[1:])
    z = np.concatenate([[0.0], np.cumsum(r[:-1] + r[1:] - h)])
    return np.column_stack([np.zeros_like(z), np.zeros_like(z), z]), r, h


@pytest.mark.parametrize("law", ["rojek", "argento-bouvard", "zohdi", "fit"])
def test_chain_is_series_conductance(law):
    radii = [1e-3, 3e-3, 2e-3, 1e-3, 5e-3, 1.5e-3]
    x, r, h = chain_arrays(radii, [0.06, 0.2, 0.1, 0.3, 0.02])
    T = np.zeros(len(r))
    T[0] = 10.0
    fixed = np.zeros(len(r), bool)
    fixed[[0, -1]] = True
    res = run(make_scene(x, r, T, fixed=fixed, law=law, mode="steady"))
    if law == "zohdi":  # kappa pi a^2 / d with the lens circle (Zohdi 2014, eqs. 11-12, 33)
        d = r[:-1] + r[1:] - h
        l_i = 0.5 * (d - (r[1:] ** 2 - r[:-1] ** 2) / d)
        K = 394.0 * np.pi * (r[:-1] ** 2 - l_i**2) / d
    else:
        chosen = {"rojek": fem_law.ROJEK, "argento-bouvard": fem_law.ARGENTO_BOUVARD, "fit": None}[law]
        K = fem_law.pair_conductance(394.0, r[:-1], r[1:], neck_radius(r[:-1], r[1:], h), chosen)
    Q = 10.0 / np.sum(1.0 / K)
    flows = res.summary["boundary_heat_flow"]["particles"]
    assert -flows["0"] == pytest.approx(Q, rel=1e-12)
    assert flows[str(len(r) - 1)] == pytest.approx(Q, rel=1e-12)
    # temperatures drop by Q/K_k across each bond
    assert np.allclose(-np.diff(res.T), Q / K, rtol=1e-11, atol=1e-12)
    assert res.summary["energy_error"] < 1e-12


def test_walls_are_mirror_halves_and_mixed_materials_in_series():
    steel = Material(16.0, 7900.0, 500.0, "steel")
    copper = Material(394.0, 8960.0, 385.0, "copper")
    r = 1e-3
    x = [[0, 0, 0], [0, 0, 1.9e-3]]  # h = 0.1 mm
    walls = [Wall("hot", [0, 0, -0.98e-3], [0, 0, 1], 1.0), Wall("cold", [0, 0, 1.9e-3 + 0.98e-3], [0, 0, -1], 0.0)]
    res = run(make_scene(x, [r, r], [0, 0], materials=(copper, steel), material=[0, 1], walls=walls,
                         mode="steady"))
    c = 1.064
    a_pair = neck_radius(r, r, 0.1e-3)
    a_wall = neck_radius(r, r, 2 * 0.02e-3)
    halves = [c * 394 * np.pi * a_wall, c * 394 * np.pi * a_pair, c * 16 * np.pi * a_pair, c * 16 * np.pi * a_wall]
    Q = 1.0 / np.sum(1.0 / np.array(halves))
    walls_q = res.summary["boundary_heat_flow"]["walls"]
    assert -walls_q["hot"] == pytest.approx(Q, rel=1e-12)
    assert walls_q["cold"] == pytest.approx(Q, rel=1e-12)


def test_contact_conductance_adds_in_series():
    x, r, h = chain_arrays([1e-3, 3e-3], [0.06])
    base = run(make_scene(x, r, [1.0, 0.0], fixed=[True, True], mode="steady"))
    kc = 0.1
    with_kc = run(make_scene(x, r, [1.0, 0.0], fixed=[True, True], mode="steady",
                             conductance=ConductanceSpec(contact_conductance=kc)))
    k0 = base.summary["boundary_heat_flow"]["particles"]["1"]
    k1 = with_kc.summary["boundary_heat_flow"]["particles"]["1"]
    assert 1 / k1 == pytest.approx(1 / k0 + 1 / kc, rel=1e-12)  # Rojek 2022, eq. (8)


def test_convection_and_radiation_steady():
    x, r, h = chain_arrays([1e-3, 1e-3], [0.1])
    K = fem_law.pair_conductance(394.0, 1e-3, 1e-3, neck_radius(1e-3, 1e-3, h[0]), fem_law.ROJEK)
    A = 4 * np.pi * 1e-6
    conv = Sources(convection=Convection(1e4, 20.0, area_fraction=1.0))  # the whole surface, opted in
    res = run(make_scene(x, r, [500.0, 0.0], fixed=[True, False], sources=conv, mode="steady"))
    assert res.T[1] == pytest.approx((K * 500 + 1e4 * A * 20) / (K + 1e4 * A), rel=1e-12)
    rad = Sources(radiation=Radiation(0.8, 300.0, area_fraction=1.0, unit="K"))
    res = run(make_scene(x, r, [1500.0, 0.0], fixed=[True, False], sources=rad, mode="steady"))
    f = lambda T: K * (1500 - T) - 0.8 * STEFAN_BOLTZMANN * A * (T**4 - 300.0**4)
    assert res.T[1] == pytest.approx(brentq(f, 300, 1500, xtol=1e-13), rel=1e-12)
    assert res.summary["energy_error"] < 1e-10


def test_singular_steady_detected_and_floating_mean():
    x, r, h = chain_arrays([1e-3, 1e-3, 1e-3], [0.1, 0.1])
    x = np.vstack([x, [[1.0, 0, 0], [1.0, 0, 1.9e-3]]])  # a floating pair far away
    r = np.concatenate([r, [1e-3, 1e-3]])
    T = [1.0, 0.5, 0.0, 3.0, 1.0]
    fixed = [True, False, True, False, False]
    with pytest.raises(ValueError, match="singular.*1 of 2 connected group"):
        run(make_scene(x, r, T, fixed=fixed, mode="steady"))
    res = run(make_scene(x, r, T, fixed=fixed, mode="steady", floating="mean"))
    assert res.T[3] == pytest.approx(2.0) and res.T[4] == pytest.approx(2.0)
    assert res.T[1] == pytest.approx(0.5)


def test_out_of_range_reported_or_by_policy():
    x = [[0, 0, 0], [0, 0, 1.2e-3], [0, 0, 3.1e-3]]  # first pair h = 0.8 mm > 2r/3
    with pytest.raises(ValueError, match=r"1 of 2 particle pairs .* particles 0 and 1"):
        run(make_scene(x, [1e-3] * 3, [1, 0, 0], fixed=[True, False, True], mode="steady"))
    res = run(make_scene(x, [1e-3] * 3, [1, 0, 0], fixed=[True, False, True], mode="steady",
                         conductance=ConductanceSpec(out_of_range="clip")))
    assert res.summary["bonds_clipped"] == 1
    res = run(make_scene(x, [1e-3] * 3, [1, 0, 0], fixed=[True, False, True], mode="steady",
                         conductance=ConductanceSpec(out_of_range="drop")))
    assert res.summary["bonds"] == 1 and res.T[1] == pytest.approx(0.0)


def test_large_network_iterative_matches_direct():
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles
    from dem.network.heat import build_network, steady

    lay = random_packing(3000, 1e-4, 0.12, seed=3)
    T = np.zeros(len(lay.radius))
    fixed = np.zeros(len(T), bool)
    fixed[lay.bottom] = fixed[lay.top] = True
    T[lay.bottom] = 1.0
    net = build_network(Particles.from_arrays(lay.position, lay.radius, T, fixed=fixed), spec=ConductanceSpec())
    ref = steady(net, floating="mean", linear="direct").T
    for backend in ("amg", "cg"):
        assert np.max(np.abs(steady(net, floating="mean", linear=backend, rtol=1e-12).T - ref)) < 1e-9


def test_amg_solves_are_the_same_on_every_run_and_leave_numpy_random_alone():
    """pyamg starts its spectral-radius estimates from a random vector: seeded inside the solver, a steady AMG solve
    is the same to the bit however often it is repeated, and the caller's random stream goes on undisturbed."""
    from dem.geometry.generators import random_packing
    from dem.geometry.particles import Particles
    from dem.network.heat import build_network, steady

    lay = random_packing(3000, 1e-4, 0.12, seed=3)
    T = np.zeros(len(lay.radius))
    fixed = np.zeros(len(T), bool)
    fixed[lay.bottom] = fixed[lay.top] = True
    T[lay.bottom] = 1.0
    net = build_network(Particles.from_arrays(lay.position, lay.radius, T, fixed=fixed), spec=ConductanceSpec())
    np.random.seed(7)
    expected = np.random.rand(3)
    np.random.seed(7)
    first = steady(net, floating="mean", linear="amg").T
    assert np.array_equal(np.random.rand(3), expected)
    for _ in range(2):
        np.random.rand(5)  # another state of the global generator
        assert np.array_equal(steady(net, floating="mean", linear="amg").T, first)


def test_zohdi_wall_contact_is_lens_area_over_distance():
    r, L = 1e-3, 0.9e-3
    walls = [Wall("hot", [0, 0, -L], [0, 0, 1], 1.0), Wall("cold", [0, 0, L], [0, 0, -1], 0.0)]
    res = run(make_scene([[0, 0, 0]], [r], [0.0], walls=walls, law="zohdi", mode="steady"))
    k_half = 394.0 * np.pi * (r * r - L * L) / L  # Zohdi 2014, eq. (33) with the wall's lens circle
    assert res.summary["boundary_heat_flow"]["walls"]["cold"] == pytest.approx(k_half / 2, rel=1e-12)
    assert res.T[0] == pytest.approx(0.5, rel=1e-12)


def test_explicit_pairs_deduplicated():
    from dem.geometry.bonds import find_bonds
    from dem.geometry.particles import Particles

    x, r, h = chain_arrays([1e-3, 1e-3, 1e-3], [0.1, 0.1])
    p = Particles.from_arrays(x, r, [0, 0, 0])
    b = find_bonds(p, pairs=([0, 1, 1, 2, 0], [1, 0, 2, 1, 1]))
    assert b.n_pairs == 2 and b.i.tolist() == [0, 1] and b.j.tolist() == [1, 2]
    with pytest.raises(ValueError, match="do not overlap"):
        find_bonds(p, pairs=([0], [2]))
