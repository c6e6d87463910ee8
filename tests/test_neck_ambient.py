"""Convection and radiation with a node per neck (dem.network.necks, conductance.nodes = "necks"): the ambient acts
on each particle's centre, so a chain (collinear necks) is today's particle network, steady and transient; a small
packing cooled by convection is an independent dense solve of the same equations, with radiation its nonlinear
balance holds at the solution; the heat stored is the heat that came in, through the ambient too."""

import math
from dataclasses import replace

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.exposure import exposed_fraction
from dem.geometry.particles import Particles
from dem.geometry.walls import Wall
from dem.laws.ambient import STEFAN_BOLTZMANN, Convection, Radiation, Sources
from dem.laws.conductance import bond_halves, union_halves, wall_normals
from dem.laws.shared_body import particle_elements
from dem.network.heat import build_network, integrate, steady
from dem.network.necks import NeckHeat, neck_network, steady_necks
from test_neck_nodes import NECKS, PARTICLES, UNIT, _chain

CONVECTION = Sources(convection=Convection(100.0, 0.25))  # h A ~ 1.3e-3 W/K on a 1 mm sphere, as a half's K
# in kelvin about 1000 K, where 4 eps sigma A T^3 is of the halves' size too
RADIATION = Sources(convection=Convection(50.0, 300.0), radiation=Radiation(0.8, 300.0, unit="K"))


def _hot_chain(turn=False):
    """The chain of test_neck_nodes in kelvin: the first particle held at 1200 K, the wall at 800 K."""
    particles, (wall,) = _chain(turn)
    T = np.where(particles.fixed, 1200.0, 1000.0)
    particles = Particles.from_arrays(particles.position, particles.radius, T, materials=(UNIT,),
                                      fixed=particles.fixed)
    return particles, (Wall(wall.name, point=wall.point, normal=wall.normal, temperature=800.0),)


@pytest.mark.parametrize("sources, hot", [(CONVECTION, False), (RADIATION, True)])
def test_a_chain_with_an_ambient_is_todays_steady_network(sources, hot):
    """The ambient on the centres and the necks' halves in series: the condensed matrix is today's, so are the
    temperatures, the bonds' flows and the ambient's (the exposed areas computed once per network)."""
    particles, walls = _hot_chain() if hot else _chain()
    today = steady(build_network(particles, walls, PARTICLES, sources))
    res = steady_necks(neck_network(NECKS, particles, find_bonds(particles, walls, "union"), walls=walls),
                       sources=sources)
    scale = np.max(np.abs(today.T))
    assert np.max(np.abs(res.T - today.T)) < 1e-12 * scale
    for name in sources.names:
        assert res.flows[name] == pytest.approx(today.flows[name], rel=1e-10) and abs(res.flows[name]) > 1e-4
    assert res.flows["walls"] == pytest.approx(today.flows["walls"], rel=1e-10)
    assert res.energy_error < 1e-12 and (res.iterations > 3) == hot
    assert np.ptp(res.T[1:]) > 1e-3 * scale  # the chain is not at one temperature


@pytest.mark.parametrize("integrator, dt", [("implicit", 2e-6), ("crank-nicolson", 2e-6), ("crank-nicolson", "auto")])
@pytest.mark.parametrize("sources, hot", [(CONVECTION, False), (RADIATION, True)])
def test_a_chain_with_an_ambient_is_todays_transient_at_every_output_time(sources, hot, integrator, dt):
    particles, walls = _hot_chain() if hot else _chain()
    today = build_network(particles, walls, PARTICLES, sources)
    heat = NeckHeat(neck_network(NECKS, particles, find_bonds(particles, walls, "union"), walls=walls),
                    sources=sources)
    seen = {}
    for key, net in (("today", today), ("necks", heat)):
        out = []
        res = integrate(net, integrator, dt, 1e-4, observer=lambda step, t, T, flows: out.append((t, net.full(T))))
        seen[key] = (out, res)
    (a, res_a), (b, res_b) = seen["today"], seen["necks"]
    scale = np.max(np.abs(a[0][1]))
    assert len(a) == len(b) > 20
    for (t_a, T_a), (t_b, T_b) in zip(a, b):
        assert t_b == t_a and np.max(np.abs(T_b - T_a)) < 1e-12 * scale
    assert abs(a[-1][1][-1] - a[0][1][-1]) > 1e-3 * scale  # it changed: the comparison is not of constants
    for key in ("fixed", "walls", *sources.names):
        assert res_b.heat_in[key] == pytest.approx(res_a.heat_in[key], rel=1e-9)
    assert res_b.energy_error < 1e-12


def _packing(n=24, seed=7, T0=0.0, wall_T=1.0):
    """Overlapping spheres (unit material, radii 0.85-1.15 mm) on a hot wall, none held: the ambient anchors them."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 3.5e-3, (n, 3))
    x[:, 2] = rng.uniform(0.4e-3, 3.5e-3, n)  # in front of the wall
    r = rng.uniform(0.85e-3, 1.15e-3, n)
    particles = Particles.from_arrays(x, r, np.full(n, T0), materials=(UNIT,))
    walls = (Wall("hot", point=[0.0, 0.0, 0.3e-3], normal=[0.0, 0.0, 1.0], temperature=wall_T),)
    bonds = find_bonds(particles, walls, "union", out_of_range="drop")
    return particles, walls, bonds


def _dense(particles, walls, bonds):
    """The equations of the network with a node per neck written densely, particle by particle, from the law's
    elements (:func:`dem.laws.shared_body.particle_elements`): ``(M, r, nodes)`` with ``M T = r`` over the centres
    and the live pair bonds' necks (walls' necks known), no ambient yet."""
    n, kappa = particles.n, particles.conductivity
    k_i, k_j, k_w = bond_halves(NECKS, particles, bonds, kappa)
    normals = wall_normals(bonds, walls)
    vectors = bonds.vectors(particles.position)
    k_i, k_j, k_w, pairs, live_walls, volume = union_halves(particles, bonds, vectors, normals, kappa, k_i, k_j,
                                                            k_w, None, None, walls)
    live, live_walls = np.flatnonzero(pairs), np.flatnonzero(live_walls)
    sub = bonds.subset(live, live_walls)
    el = particle_elements(n, particles.radius, sub, vectors[live], k_i[live], k_j[live], k_w[live_walls], kappa,
                           np.reshape(normals, (-1, 3))[live_walls], volume)
    m = len(live)
    size = n + m
    M, r = np.zeros((size, size)), np.zeros(size)
    wall_T = [walls[w].temperature for w in sub.wall_index]

    def node(end):  # (node, known temperature) of an end; the centre is end -1
        return (end % m + n, None) if end < 2 * m else (None, wall_T[end - 2 * m])

    for k in range(n):
        ends = list(el.ends[el.offsets[k]:el.offsets[k + 1]])
        z = len(ends)
        block = np.reshape(el.values[el.start[k]:el.start[k + 1]], (z + 1, z + 1))
        places = [node(e) for e in ends] + [(k, None)]
        for p, (row, _) in enumerate(places):
            if row is None:
                continue  # a wall's neck has no equation
            for q, (col, known) in enumerate(places):
                if col is None:
                    r[row] -= block[p, q] * known
                else:
                    M[row, col] += block[p, q]
    return M, r, m


def test_steady_convective_cooling_of_a_packing_is_the_dense_solve():
    """A hot wall under a packing in a cool gas: the neck solve is the dense solve of M T = r with h f 4 pi r^2 on
    the centres' diagonal (f the exposed fraction), to round-off; the necks' interactions matter (the one-node law's
    answer is farther off) and every watt the wall gives leaves by convection."""
    particles, walls, bonds = _packing()
    h, T_inf = 200.0, 0.25
    sources = Sources(convection=Convection(h, T_inf))
    res = steady_necks(neck_network(NECKS, particles, bonds, walls=walls), sources=sources)
    M, r, m = _dense(particles, walls, bonds)
    n = particles.n
    g = h * exposed_fraction(particles.position, particles.radius) * 4 * math.pi * particles.radius**2
    M[np.arange(n), np.arange(n)] += g
    r[:n] += g * T_inf
    T = np.linalg.solve(M, r)
    assert np.max(np.abs(res.T - T[:n])) < 1e-10 and np.max(np.abs(res.T_necks - T[n:])) < 1e-10
    assert np.ptp(res.T) > 0.05 and m > 20 and np.count_nonzero(g) > n // 2
    one_node = steady(build_network(particles, walls, PARTICLES, sources, bonds=bonds)).T
    assert np.max(np.abs(one_node - T[:n])) > 1e3 * np.max(np.abs(res.T - T[:n]))
    assert res.flows["walls"] == pytest.approx(-res.flows["convection"], rel=1e-10) and res.flows["walls"] > 0
    assert res.flows["convection"] == pytest.approx(float(g @ (T_inf - res.T)), rel=1e-10)


def test_steady_radiation_of_a_packing_holds_its_fourth_power_balance():
    """Radiation by Newton's iteration on the neck-node matrix: at the solution the dense equations with the exact
    eps sigma A (T_inf^4 - T^4) on the centres hold to round-off of the flows."""
    particles, walls, bonds = _packing(T0=900.0, wall_T=1300.0)
    eps, T_inf = 0.7, 400.0
    sources = Sources(radiation=Radiation(eps, T_inf, unit="K"))
    res = steady_necks(neck_network(NECKS, particles, bonds, walls=walls), sources=sources)
    M, r, m = _dense(particles, walls, bonds)
    n = particles.n
    coef = eps * STEFAN_BOLTZMANN * exposed_fraction(particles.position, particles.radius) * 4 * math.pi \
        * particles.radius**2
    T = np.concatenate([res.T, res.T_necks])
    residual = M @ T - r
    residual[:n] -= coef * (T_inf**4 - res.T**4)
    assert np.max(np.abs(residual)) < 1e-10 * res.flows["walls"]
    assert res.iterations > 3 and res.flows["walls"] == pytest.approx(-res.flows["radiation"], rel=1e-10)
    assert res.T.min() > T_inf and res.T.max() < 1300.0


@pytest.mark.parametrize("integrator", ["implicit", "crank-nicolson"])
def test_heat_stored_is_heat_in_through_the_wall_and_the_ambient(integrator):
    """A packing warmed by a wall, losing heat by convection and radiation, with a source in one particle: the change
    of sum C T is the heat that came in through the wall, the ambient and the source, to round-off."""
    particles, walls, bonds = _packing(T0=900.0, wall_T=1300.0)
    q = np.zeros(particles.n)
    q[3] = 5e-3
    particles = Particles.from_arrays(particles.position, particles.radius, particles.temperature,
                                      materials=(UNIT,), heat=q)
    net = neck_network(NECKS, particles, bonds, walls=walls)
    res = integrate(NeckHeat(net, sources=RADIATION), integrator, 1e-6, 2e-5)
    stored = float(particles.capacity @ (res.T - particles.temperature))
    came_in = sum(res.heat_in.values())
    assert abs(stored - came_in) < 1e-12 * sum(abs(v) for v in res.heat_in.values())
    assert res.heat_in["walls"] > 0 and res.heat_in["convection"] < 0 and res.heat_in["radiation"] < 0
    assert res.energy_error < 1e-12


def test_a_scene_with_neck_nodes_and_an_ambient_runs_the_neck_solve():
    """The static engine passes the scene's ambient to the neck solve (its exposed areas resolved once) and says
    what left through it."""
    from dem import make_scene, run

    particles, walls, bonds = _packing()
    sources = Sources(convection=Convection(200.0, 0.25))
    s = run(make_scene(particles.position, particles.radius, particles.temperature, materials=(UNIT,),
                       walls=walls, mode="steady", conductance=replace(NECKS, out_of_range="drop"),
                       sources=sources)).summary
    res = steady_necks(neck_network(NECKS, particles, bonds, walls=walls), sources=sources)
    assert s["nodes"] == "necks" and s["heat_flow"] == pytest.approx(res.flows, rel=1e-12)
    assert s["T_max"] == pytest.approx(res.T.max(), rel=1e-12) and s["energy_error"] < 1e-12


def test_mpi_takes_neck_nodes_with_an_ambient():
    """Neck nodes with convection run on MPI ranks (dem.network.distributed_necks; tests/mpi compares them with the
    serial run)."""
    from dem import make_scene
    from dem.engines.distributed.static import unsupported

    particles, walls, _ = _packing()
    scene = make_scene(particles.position, particles.radius, particles.temperature, materials=(UNIT,), walls=walls,
                       mode="steady", conductance=NECKS, sources=CONVECTION)
    assert unsupported(scene) is None


def test_a_transient_chain_scene_with_an_ambient_on_neck_nodes_is_todays():
    """The static engine hands the scene's ambient to the transient neck network: on the chain the run ends where
    the one-node run ends, with the same heat through the ambient."""
    from dem import make_scene, run

    particles, walls = _hot_chain()

    def scene(conductance):
        return make_scene(particles.position, particles.radius, particles.temperature, materials=(UNIT,),
                          fixed=particles.fixed, walls=walls, mode="transient", integrator="crank-nicolson", dt=2e-6,
                          t_end=1e-4, conductance=conductance, sources=RADIATION)

    a, b = run(scene(NECKS)), run(scene(PARTICLES))
    assert np.max(np.abs(a.T - b.T)) < 1e-12 * np.max(np.abs(b.T)) and np.ptp(b.T) > 10.0
    for key in ("convection", "radiation"):
        assert a.summary["heat_in"][key] == pytest.approx(b.summary["heat_in"][key], rel=1e-9)
    assert a.summary["nodes"] == "necks" and a.summary["energy_error"] < 1e-12
