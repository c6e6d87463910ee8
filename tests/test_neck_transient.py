"""The transient heat of the network with a node per neck (dem.network.necks.NeckHeat, conductance.nodes = "necks"):
a chain is today's particle network at every output time, the long-time limit is the steady neck solve, the heat
stored is the heat that came in, a resumed run is the uninterrupted one, and an explicit step is refused."""

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Particles
from dem.geometry.periodic import PeriodicBox
from dem.geometry.walls import Wall
from dem.network.heat import Checkpoint, build_network, integrate, stable_limit
from dem.network.necks import NeckHeat, neck_network, steady_necks
from fem_neck import lattice
from test_neck_nodes import NECKS, PARTICLES, UNIT, _chain

T_END = 1e-4  # s: some 25 time constants C/K of the chain's particles (C 4.2e-9 J/K, K 2.5e-3 W/K)


def _histories(net, integrator, dt, t_end=T_END):
    """Every output (t, particles' temperatures) and the result of ``integrate`` on ``net``."""
    seen = []
    res = integrate(net, integrator, dt, t_end, observer=lambda step, t, T, flows: seen.append((t, net.full(T))))
    return seen, res


@pytest.mark.parametrize("integrator, dt", [("implicit", 2e-6), ("crank-nicolson", 2e-6),
                                            ("crank-nicolson", "auto"), ("implicit", "auto")])
def test_a_chain_is_todays_transient_at_every_output_time(integrator, dt):
    """Collinear necks: each neck node joins two halves in series with no capacity, today's bond. Fixed Crank-Nicolson
    steps above the stable limit start with implicit Euler steps in both (the limit of the condensed matrix)."""
    particles, walls = _chain()
    today = build_network(particles, walls, PARTICLES)
    heat = NeckHeat(neck_network(NECKS, particles, find_bonds(particles, walls, "union"), walls=walls))
    assert stable_limit(heat) == pytest.approx(stable_limit(today), rel=1e-10)
    a, res_a = _histories(today, integrator, dt)
    b, res_b = _histories(heat, integrator, dt)
    assert len(a) == len(b) == res_a.steps + 1 > 20 and res_a.startup_steps == res_b.startup_steps
    for (t_a, T_a), (t_b, T_b) in zip(a, b):
        assert t_b == t_a and np.max(np.abs(T_b - T_a)) < 1e-13
    assert a[0][1][-1] == 0.0 and a[-1][1][-1] > 0.05  # the chain did warm up: the comparison is not of constants
    for key in ("fixed", "walls"):
        assert res_b.heat_in[key] == pytest.approx(res_a.heat_in[key], rel=1e-12)
    assert res_b.energy_error < 1e-13


def _random_packing(seed=3, n=40, heat=False):
    """Overlapping spheres (unit material) between a hot and a cold wall, one fixed particle in the middle, all else at
    0.5; with ``heat`` two particles hold sources."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.0, 4e-3, (n, 3))
    r = rng.uniform(0.85e-3, 1.15e-3, n)
    fixed = np.zeros(n, dtype=bool)
    fixed[np.argmin(np.linalg.norm(x - 2e-3, axis=1))] = True
    q = np.zeros(n)
    if heat:
        q[np.flatnonzero(~fixed)[:2]] = [2e-4, 1e-4]
    particles = Particles.from_arrays(x, r, np.where(fixed, 0.3, 0.5), materials=(UNIT,), fixed=fixed, heat=q)
    walls = (Wall("hot", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),
             Wall("cold", point=[0.0, 0.0, 3.8e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    net = neck_network(NECKS, particles, find_bonds(particles, walls, "union", out_of_range="drop"), walls=walls)
    assert net.bonds.n_walls > 4 and len(net.live) > 40
    return net


@pytest.mark.parametrize("integrator", ["implicit", "crank-nicolson"])
def test_heat_stored_is_heat_in_on_a_random_packing(integrator):
    """The change of sum C T equals the heat that came in through the walls, the fixed particle and the sources over
    the run, and the necks' interactions matter (the run is not today's network)."""
    net = _random_packing(heat=True)
    heat = NeckHeat(net)
    res = integrate(heat, integrator, 1e-6, 2e-5)
    C = net.particles.capacity
    stored = float(C @ (res.T - net.particles.temperature))
    came_in = sum(res.heat_in.values())
    assert abs(stored - came_in) < 1e-12 * sum(abs(v) for v in res.heat_in.values())
    assert res.heat_in["walls"] != 0.0 and res.heat_in["fixed"] != 0.0 and res.heat_in["internal"] == pytest.approx(
        3e-4 * 2e-5, rel=1e-12)
    assert res.energy_error < 1e-12 and net.plain < net.particles.n


def test_the_long_time_limit_is_the_steady_neck_solve():
    """Walls and a fixed particle: the transient ends at steady_necks, the centres and the necks."""
    net = _random_packing()
    heat = NeckHeat(net)
    seen = []
    res = integrate(heat, "implicit", 2e-4, 2e-2, observer=lambda step, t, T, flows: seen.append(T))
    steady = steady_necks(net)
    assert np.max(np.abs(res.T - steady.T)) < 1e-10
    assert np.max(np.abs(heat.nodes(seen[-1])[net.particles.n:] - steady.T_necks)) < 1e-10
    assert np.max(np.abs(heat.full(seen[1]) - steady.T)) > 1e-3  # it started elsewhere


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


@pytest.mark.parametrize("linear", ["direct", "amg"])
@pytest.mark.slow
def test_a_periodic_box_ends_at_its_steady_state_and_keeps_its_heat(linear):
    """A tiled BCC union cell with a temperature drop per period and no anchor: the heat stays (sum C T is the
    initial one) and the transient ends at the steady neck solve (which keeps that mean)."""
    net = _tiled_bcc()
    particles, T0 = net.particles, net.particles.temperature
    res = integrate(NeckHeat(net), "crank-nicolson", "auto", 2e-2, rtol=1e-6, linear=linear)
    C = particles.capacity
    assert float(C @ res.T) == pytest.approx(float(C @ T0), rel=1e-10)
    assert np.max(np.abs(res.T - steady_necks(net).T)) < 1e-6


def test_an_explicit_step_is_refused():
    particles, walls = _chain()
    heat = NeckHeat(neck_network(NECKS, particles, find_bonds(particles, walls, "union"), walls=walls))
    with pytest.raises(ValueError, match="solver.integrator = \"explicit\""):
        integrate(heat, "explicit", 1e-7, 1e-6)


def test_a_transient_scene_with_neck_nodes_runs_reports_and_resumes():
    """The static engine: a transient run with neck nodes is today's on a chain, says so in its summary, gives the
    necks' flows, refuses an explicit integrator, and goes on from a checkpoint to the end of the uninterrupted
    run bit for bit."""
    from dem import make_scene, run
    from dem.engines.static import StaticEngine

    particles, walls = _chain()

    def scene(conductance, integrator="crank-nicolson"):
        return make_scene(particles.position, particles.radius, particles.temperature, materials=(UNIT,),
                          fixed=particles.fixed, walls=walls, mode="transient", integrator=integrator, dt=2e-6,
                          t_end=T_END, conductance=conductance)

    whole = run(scene(NECKS))
    today = run(scene(PARTICLES))
    assert np.max(np.abs(whole.T - today.T)) < 1e-13
    s = whole.summary
    assert s["nodes"] == "necks" and s["neck_nodes"] == 3 and s["steps"] == 50 and s["energy_error"] < 1e-13
    q_pairs, q_walls = whole.engine.bond_heat_flow()
    q_today = today.engine.bond_heat_flow()
    assert q_pairs == pytest.approx(q_today[0], rel=1e-9) and q_walls == pytest.approx(q_today[1], rel=1e-9)
    with pytest.raises(ValueError, match="solver.integrator = \"explicit\": an explicit step cannot carry"):
        run(scene(NECKS, "explicit"))
    saved = []

    def keep(make, final=False):
        if not final and len(saved) < 20:
            saved.append(make().arrays())

    first = StaticEngine(scene(NECKS))
    first.run(checkpoint=keep)
    again = StaticEngine(scene(NECKS), restart=saved[-1])
    assert again.steps == 20 and Checkpoint.from_arrays(saved[-1]).T.size == 3 + 3  # free centres and necks
    again.run()
    assert np.array_equal(again.T, whole.T) and np.array_equal(again.T_nodes, first.T_nodes)


@pytest.mark.parametrize("mode", ["steady", "transient"])
@pytest.mark.slow
def test_the_links_of_the_snapshots_carry_the_necks_flows(tmp_path, mode):
    """Every snapshot's bonds carry the flows through the necks at that step (the steady one was written before
    the neck solve's flows were kept, with the one-node law's K dT): on the turning chain the two differ."""
    import meshio

    from dem import make_scene, run
    from dem.network.necks import neck_flows

    particles, walls = _chain(turn=True)
    result = run(make_scene(particles.position, particles.radius, particles.temperature, materials=(UNIT,),
                            fixed=particles.fixed, walls=walls, mode=mode, integrator="implicit", dt=2e-6,
                            t_end=2e-5, conductance=NECKS), out=tmp_path)
    last = sorted(tmp_path.glob("bonds_*.vtu"))[-1]
    written = np.concatenate(meshio.read(last).cell_data["heat_flow"])
    e = result.engine
    assert np.array_equal(written, np.concatenate(neck_flows(e.necks, e.T_nodes)[:2]))
    b, T = e.bonds, e.T
    one_node = e.K_pairs * (T[b.i] - T[b.j])
    assert np.max(np.abs(written[:b.n_pairs] - one_node)) > 1e-3 * np.max(np.abs(one_node))
