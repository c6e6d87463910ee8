"""The current through the network with a node per neck (dem.network.necks.neck_current, conductance.nodes = "necks"
with "electrical" physics): the elements scale with the conductivity, a chain is today's current network (potentials,
currents, each particle's Joule heat), on a random packing the Joule heat of the elements is the power the electrodes
deliver and the current is sigma / kappa times the heat the same network conducts, and the static engine runs it."""

import tomllib
from dataclasses import replace

import numpy as np
import pytest

from dem.geometry.bonds import find_bonds
from dem.geometry.particles import Material, Particles
from dem.geometry.walls import Wall
from dem.laws.ambient import Convection, Sources
from dem.network.current import Electrodes, electrode_bonds, kirchhoff
from dem.network.necks import neck_current, neck_network, steady_necks
from dem.scene import parse_scene
from dem.scene.parse import SCENE_DIR
from test_neck_nodes import NECKS, PARTICLES

SIGMA_OVER_KAPPA = 5.96e7 / 394.0
METALS = (Material(394.0, 8960.0, 385.0, "copper", electrical_conductivity=5.96e7),
          Material(80.0, 7870.0, 450.0, "iron", electrical_conductivity=1.0e7))


def _random_packing(n=40, seed=3, third_wall=True):
    """Overlapping spheres of copper and iron between two plates, and a side wall that carries heat but no current."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(0.3e-3, 3.7e-3, (n, 3))  # in front of every wall
    r = rng.uniform(0.85e-3, 1.15e-3, n)
    particles = Particles.from_arrays(x, r, np.full(n, 0.5), materials=METALS, material=rng.integers(0, 2, n))
    walls = (Wall("bottom", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),
             Wall("top", point=[0.0, 0.0, 3.8e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    if third_wall:
        walls += (Wall("side", point=[0.2e-3, 0.0, 0.0], normal=[1.0, 0.0, 0.0], temperature=0.5),)
    bonds = find_bonds(particles, walls, "union", out_of_range="drop")
    return particles, walls, bonds


def _electrodes(potential=(0.0, 1e-3), current=(np.nan, np.nan)):
    return Electrodes(("bottom", "top"), (0, 1), np.array(potential, dtype=float), np.array(current, dtype=float))


def test_the_element_is_proportional_to_the_conductivity():
    """The premise of the scaling: every particle's element (halves, faces' interaction, trace cap) is its material's
    conductivity times one of the geometry, so sigma / kappa turns the thermal element into the electrical one."""
    particles, walls, bonds = _random_packing()
    net = neck_network(NECKS, particles, bonds, walls=walls)
    tripled = (Material(3 * 394.0, 1.0, 1.0, "a"), Material(3 * 80.0, 1.0, 1.0, "b"))
    other = Particles.from_arrays(particles.position, particles.radius, particles.temperature, materials=tripled,
                                  material=particles.material)
    value = net.entries[2]
    again = neck_network(NECKS, other, bonds, walls=walls).entries[2]
    assert np.max(np.abs(again - 3 * value)) < 1e-13 * np.max(np.abs(again)) and net.plain < particles.n


def test_a_chain_is_todays_current_network():
    """Four union spheres of copper between two electrodes: the neck-node current is Kirchhoff's on today's bonds,
    and each particle's element dissipates what today's shares of I^2 / G give it."""
    r, d = 1e-3, 1.6e-3
    x = np.arange(4)[:, None] * [0.0, 0.0, d]
    particles = Particles.from_arrays(x, np.full(4, r), np.zeros(4), materials=METALS[:1])
    walls = (Wall("bottom", point=[0.0, 0.0, -0.8e-3], normal=[0.0, 0.0, 1.0], temperature=0.0),
             Wall("top", point=[0.0, 0.0, 3 * d + 0.9e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    bonds = find_bonds(particles, walls, "union")
    electrodes = _electrodes()
    net = electrode_bonds(particles, bonds, walls, PARTICLES, electrodes)
    today = kirchhoff(4, bonds.i, bonds.j, net.G, net.share, net.plane_node, net.plane_index, net.G_plane, electrodes)
    flow, _ = neck_current(neck_network(NECKS, particles, bonds, walls=walls), walls, electrodes)
    assert flow.potential == pytest.approx(today.potential, rel=1e-12, abs=1e-18)
    assert flow.electrode_current == pytest.approx(today.electrode_current, rel=1e-12)
    assert flow.joule_particles == pytest.approx(today.joule_particles, rel=1e-10)
    assert flow.joule_heat == pytest.approx(today.joule_heat, rel=1e-12) and today.joule_heat > 0
    assert np.ptp(flow.joule_particles) > 0.05 * flow.joule_particles.max()  # the top wall's narrower neck heats its particle more


@pytest.mark.parametrize("linear", ["direct", "amg"])
def test_joule_heat_is_the_electrodes_power_and_the_current_the_heats_analogue(linear):
    """A random packing of two metals between two electrodes, a side wall that takes no current: the elements'
    dissipations sum to sum V I (Tellegen) and the current is conserved (what enters leaves, none through the side
    wall); of one metal between the plates alone, the conductance is sigma / kappa times the heat's, by the heat's own
    solve."""
    particles, walls, bonds = _random_packing()
    flow, _ = neck_current(neck_network(NECKS, particles, bonds, walls=walls), walls, _electrodes(), linear)
    assert flow.joule_heat == pytest.approx(flow.electrode_power, rel=1e-10) and flow.joule_heat > 0
    assert np.all(flow.joule_particles >= -1e-12 * flow.joule_heat)
    assert abs(flow.electrode_current.sum()) < 1e-10 * np.abs(flow.electrode_current).max()
    assert flow.residual < 1e-8
    particles, walls, bonds = _random_packing(third_wall=False)  # the heat's analogue: no wall but the electrodes
    copper = Particles.from_arrays(particles.position, particles.radius, particles.temperature, materials=METALS[:1])
    heat_net = neck_network(NECKS, copper, bonds, walls=walls)
    heat = steady_necks(heat_net, linear=linear)
    Q = -float(heat.wall_flow[bonds.wall_index == 0].sum())  # into the packing from the bottom wall at 1 K
    current, _ = neck_current(heat_net, walls, _electrodes(potential=(1.0, 0.0)), linear)
    assert current.electrode_current[0] == pytest.approx(SIGMA_OVER_KAPPA * Q, rel=1e-8)


def test_a_fixed_current_electrode_drives_the_potential_it_needs():
    particles, walls, bonds = _random_packing()
    net = neck_network(NECKS, particles, bonds, walls=walls)
    at_potential, _ = neck_current(net, walls, _electrodes())
    driven, _ = neck_current(net, walls, _electrodes(potential=(0.0, np.nan), current=(np.nan, 2.0)))
    R = 1e-3 / at_potential.electrode_current[1]
    assert driven.electrode_current[1] == pytest.approx(2.0, rel=1e-10)
    assert driven.electrode_potential[1] == pytest.approx(2.0 * R, rel=1e-9)
    assert driven.joule_heat == pytest.approx(driven.electrode_power, rel=1e-10)


def test_a_particle_on_two_electrodes_is_refused():
    x = np.array([[0.0, 0.0, 0.0]])
    particles = Particles.from_arrays(x, [1e-3], [0.0], materials=METALS[:1])
    walls = (Wall("bottom", point=[0.0, 0.0, -0.9e-3], normal=[0.0, 0.0, 1.0], temperature=0.0),
             Wall("top", point=[0.0, 0.0, 0.9e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    net = neck_network(NECKS, particles, find_bonds(particles, walls, "union"), walls=walls)
    with pytest.raises(ValueError, match="particle 0 touches two electrodes"):
        neck_current(net, walls, _electrodes())


def _joule_chain(nodes, mode="steady", **extra):
    doc = tomllib.loads((SCENE_DIR / "joule-chain.toml").read_text())
    doc["conductance"] = {"law": "shared-body", "neck": "union", "nodes": nodes}
    doc["solver"] = {"mode": mode, **extra}
    return parse_scene(doc)


@pytest.mark.parametrize("mode, extra", [("steady", {}),
                                         ("transient", {"integrator": "implicit", "dt": 0.05, "t_end": 1.0})])
def test_the_joule_chain_with_neck_nodes_is_todays(mode, extra):
    """The static engine: the built-in copper chain between electrodes with neck nodes runs the same circuit, the
    same Joule heat and the same temperatures as with a node per particle."""
    from dem.driver import run

    a = run(_joule_chain("necks", mode, **extra))
    b = run(_joule_chain("particles", mode, **extra))
    ea, eb = a.summary["electrical"], b.summary["electrical"]
    assert ea["resistance"] == pytest.approx(eb["resistance"], rel=1e-12)
    assert ea["joule_heat"] == pytest.approx(ea["electrode_power"], rel=1e-12)
    assert ea["joule_heat"] == pytest.approx(eb["joule_heat"], rel=1e-12)
    assert np.max(np.abs(a.T - b.T)) < 1e-10 * np.ptp(b.T) and np.ptp(b.T) > 0.01
    assert a.summary["nodes"] == "necks" and a.summary["energy_error"] < 1e-10
    assert np.max(np.abs(a.engine.potential - b.engine.potential)) < 1e-12 * 0.01


def test_a_scene_with_current_and_convection_on_neck_nodes_balances_its_heat():
    """Current, convection and walls together on a random packing with neck nodes: the absorbed Joule heat
    (the circuit's, halved by the absorption) is a source, and the walls and the ambient take all of it."""
    from dem import make_scene
    from dem.driver import run
    from dem.scene.electrical import ElectricalSpec
    from dem.scene.parse import Scene

    particles, walls, _ = _random_packing(third_wall=False)
    scene = make_scene(particles.position, particles.radius, np.full(particles.n, 0.0), materials=METALS,
                       material=particles.material, walls=walls, mode="steady",
                       conductance=replace(NECKS, out_of_range="drop"),
                       sources=Sources(convection=Convection(50.0, 0.0)))
    scene = Scene(**{**scene.__dict__, "physics": ("thermal", "electrical"),
                     "electrical": ElectricalSpec("kirchhoff", 0.5, _electrodes(potential=(0.0, 0.05)))})
    s = run(scene).summary
    e, flows = s["electrical"], s["heat_flow"]
    assert flows["internal"] == pytest.approx(0.5 * e["joule_heat"], rel=1e-12) and e["joule_heat"] > 0
    assert flows["walls"] + flows["convection"] == pytest.approx(-flows["internal"], rel=1e-10)
    assert s["energy_error"] < 1e-10


def test_mpi_refuses_a_current_through_neck_nodes_in_one_line():
    from dem.engines.distributed.static import unsupported

    assert unsupported(_joule_chain("necks")) == (
        "conductance.nodes = \"necks\" with \"electrical\" physics does not run under MPI yet (the current through "
        "the neck nodes is solved on one process); run it without mpiexec")
