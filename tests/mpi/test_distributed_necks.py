"""The network with a node per neck on several MPI ranks (dem.network.distributed_necks) against the serial run of the
same scene in the same process: random union packings whose necks meet, periodic and between two walls, each some
blocks long so that the ranks' halos end inside it. Every owned row is the serial matrix's; k_eff, the heat flows
and the temperatures are the serial run's to the solver's tolerance, steady and in implicit and Crank-Nicolson steps."""

import dataclasses

import numpy as np
import pytest

from dem.driver import run
from dem.engines.distributed.static import DistributedStaticEngine
from dem.engines.static import StaticEngine
from dem.geometry.periodic import PeriodicBox
from dem.laws.ambient import Convection, Sources
from dem.network.distributed_necks import node_keys
from dem.network.heat import stable_limit
from dem.network.necks import NeckHeat
from dem.parallel import comm as mpi
from dem.scene.parse import parse_scene

COMM = mpi.world()

MATERIAL = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0}
NECKS = {"law": "shared-body", "neck": "union", "nodes": "necks"}


def serial(scene):
    engine = StaticEngine(scene)
    engine.run()
    return engine


def _blocks(boundary: str, solver: dict | None = None, blocks: int = 2, n: int = 200, element: str = "law"):
    """A random union packing of ``n`` spheres (radii +-15 %, mean overlap 0.15 of the smaller radius: necks meet)
    repeated ``blocks`` times along x, the longest axis the ranks cut across (periodic: three, as a rank's halo
    reaches across the period on both sides), with the particles' ``element``."""
    doc = {"material": MATERIAL, "conductance": {**NECKS, "element": element},
           "generator": {"kind": "random", "n": n, "radius": 5e-5, "radius_spread": 0.15, "overlap": 0.15,
                         "seed": 3, "boundary": boundary, "hot": 1.0, "cold": 0.0}}
    if solver is not None:
        doc["solver"] = solver
    scene = parse_scene(doc)
    p = scene.particles
    if scene.box is not None:
        step = scene.box.lengths[0]
    else:
        step = float(np.ptp(p.position[:, 0]) + 2.0 * p.radius.max())  # clear of the first block
    many = dataclasses.replace(
        p, position=np.vstack([p.position + [k * step, 0.0, 0.0] for k in range(blocks)]),
        radius=np.tile(p.radius, blocks), temperature=np.tile(p.temperature, blocks),
        material=np.tile(p.material, blocks), fixed=np.tile(p.fixed, blocks), heat=np.tile(p.heat, blocks),
        id=np.arange(blocks * p.n))
    if scene.box is not None:
        b = scene.box
        box = PeriodicBox(b.lengths * [blocks, 1.0, 1.0], b.mask, b.origin, b.drop)
        return dataclasses.replace(scene, particles=many, box=box)
    return dataclasses.replace(scene, particles=many,
                               specimen=dataclasses.replace(scene.specimen, area=blocks * scene.specimen.area))


def _compare_steady(scene):
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert s["ranks"] == COMM.Get_size() and s["nodes"] == r["nodes"] == "necks"
    for key in ("neck_nodes", "bonds", "wall_bonds", "particles_necks_meeting", "particles_without_interactions"):
        assert s[key] == r[key], key
    assert r["particles_necks_meeting"] > 0.2 * scene.particles.n  # the union's regime: necks meet
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-8  # hot - cold = 1 K
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-8)
    assert s["energy_error"] < 1e-9
    part = result.engine.part  # the halo ends inside the packing: some held nodes are neither owned nor reached
    assert len(part.held) > len(part.used) and len(result.engine.held) < scene.particles.n
    return s, r


def test_a_periodic_union_packing_equals_the_serial_run():
    s, r = _compare_steady(_blocks("periodic", blocks=3))
    q, q_ref = np.array(s["periodic_heat_flow"]), np.array(r["periodic_heat_flow"])
    assert np.max(np.abs(q - q_ref)) < 1e-8 * np.max(np.abs(q_ref))
    assert s["T_mean"] == pytest.approx(r["T_mean"], abs=1e-10)


def test_a_union_packing_between_walls_equals_the_serial_run():
    s, r = _compare_steady(_blocks("plates"))
    walls, walls_ref = s["boundary_heat_flow"]["walls"], r["boundary_heat_flow"]["walls"]
    for name in ("hot", "cold"):
        assert walls[name] == pytest.approx(walls_ref[name], rel=1e-8)
    assert s["heat_flow"]["walls"] == pytest.approx(0.0, abs=1e-8 * abs(walls_ref["hot"]))


def owned_rows_against_serial(scene) -> tuple:
    """This rank's owned rows of ``scene``'s neck-node matrix and right-hand side against the serial network's rows
    of the same nodes (matched by their global keys), and the serial network: ``(ours, theirs, r_ours, r_theirs,
    owned rows summed over the ranks, serial free nodes, serial engine)``."""
    engine = DistributedStaticEngine(scene)
    ref = serial(scene)
    part, net, ref_heat = engine.part, engine.necks_heat, NeckHeat(ref.necks)
    ref_keys, _ = node_keys(ref.necks, np.arange(scene.particles.n), np.zeros(scene.particles.n, dtype=np.int64),
                            COMM)
    ref_free = ref_keys[ref_heat.free]
    order = np.argsort(ref_free)
    place = lambda keys: order[np.searchsorted(ref_free, keys, sorter=order)]  # noqa: E731
    keys = part.held[net.free]
    own = np.flatnonzero(part.own_free)
    assert np.array_equal(ref_free[place(keys[own])], keys[own])
    ours = net.A[own].tocoo()
    theirs = ref_heat.A[place(keys[own])].tocsr()
    ours = type(theirs)((ours.data, (ours.row, place(keys[ours.col]))), shape=theirs.shape).tocsr()
    return (ours, theirs, net.r_const[own], ref_heat.r_const[place(keys[own])], mpi.total(COMM, len(own)),
            len(ref_free), ref)


def test_owned_rows_are_those_of_the_serial_matrix():
    """Each rank's rows over the free nodes, centres and necks, by the nodes' global keys: the serial network's to
    round-off (the halo of three bond lengths holds every element they are summed from)."""
    ours, theirs, r_ours, r_ref, owned, free, _ = owned_rows_against_serial(_blocks("periodic", blocks=3))
    assert abs(ours - theirs).max() < 1e-12 * np.abs(theirs).max() and ours.nnz == theirs.nnz
    assert np.max(np.abs(r_ours - r_ref)) <= 1e-12 * max(np.max(np.abs(r_ref)), 1e-300)
    assert owned == free


@pytest.mark.parametrize("integrator, dt", [("implicit", 2e-4), ("crank-nicolson", 2e-4),
                                          ("crank-nicolson", 1e-5)])
def test_fixed_steps_equal_the_serial_steps(integrator, dt):
    """Between the walls from 0 C, five steps: of 2e-4 s (twelve times the stable limit, 1.6e-5 s: Crank-Nicolson
    starts with two implicit Euler steps on both) and of 1e-5 s (below it: no start-up on either)."""
    scene = _blocks("plates", {"mode": "transient", "integrator": integrator, "dt": dt, "t_end": 5 * dt})
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert s["steps"] == r["steps"] == 5
    assert s.get("startup_steps") == r.get("startup_steps") == (2 if integrator == "crank-nicolson" and dt > 1e-4
                                                                else None)
    T, T_ref = result.engine.gathered_temperatures(), ref.T
    assert 0.01 < np.ptp(T_ref) < 1.0  # heat on its way through
    assert np.max(np.abs(T - T_ref)) < 1e-8
    for name in ("walls", "fixed", "internal"):
        assert s["heat_in"][name] == pytest.approx(r["heat_in"][name], rel=1e-8, abs=1e-14)
    assert s["energy_error"] < 1e-9


def test_the_ranks_find_the_serial_stable_limit():
    """Crank-Nicolson's start-up is decided on the condensed matrix's largest eigenvalue, estimated over the ranks
    in 100 Lanczos steps: the serial limit (dem.network.heat.stable_limit, ARPACK's to 1e-8 here) to 1e-4 (3e-5
    measured)."""
    scene = _blocks("plates", {"mode": "transient", "integrator": "crank-nicolson", "dt": 2e-4, "t_end": 1e-3})
    limit = stable_limit(NeckHeat(serial(scene).necks))
    part = DistributedStaticEngine(scene).part
    T = part.initial()
    assert part.stable_limit(T) == pytest.approx(limit, rel=1e-4)
    assert not part.above_stable_limit(0.999 * limit, T) and part.above_stable_limit(1.001 * limit, T)


def _fixed_ends(scene, floating: str = "mean", sources=None):
    """``scene`` with its end layers held at 1 and 0 C in place of its walls and, clear of the packing, a touching
    pair at 0.2 and 0.6 C across the middle where the two ranks part: a group that floats."""
    p = scene.particles
    x = p.position
    middle, d = 0.5 * (x[:, 0].min() + x[:, 0].max()), 1.7 * float(p.radius.mean())
    y, z = x[:, 1].max() + 10.0 * float(p.radius.max()), float(np.mean(x[:, 2]))
    z_lo, z_hi = x[:, 2].min(), x[:, 2].max()
    ends = (x[:, 2] < z_lo + 0.5 * d) | (x[:, 2] > z_hi - 0.5 * d)
    T = np.where(x[:, 2] > z_hi - 0.5 * d, 0.0, np.where(ends, 1.0, 0.5))
    pair = dataclasses.replace(
        p, position=np.vstack([x, [[middle - d / 2, y, z], [middle + d / 2, y, z]]]),
        radius=np.r_[p.radius, np.full(2, p.radius.mean())], temperature=np.r_[T, 0.2, 0.6],
        material=np.r_[p.material, p.material[:2]], fixed=np.r_[ends, False, False], heat=np.r_[p.heat, 0.0, 0.0],
        id=np.arange(p.n + 2))
    return dataclasses.replace(scene, particles=pair, walls=(), specimen=None,
                               sources=scene.sources if sources is None else sources,
                               solver=dataclasses.replace(scene.solver, floating=floating))


def test_fixed_layers_and_a_floating_pair_across_the_ranks():
    scene = _fixed_ends(_blocks("plates"))
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    T = result.engine.gathered_temperatures()
    assert np.max(np.abs(T - ref.T)) < 1e-8
    assert T[-2] == pytest.approx(0.4, abs=1e-10) and T[-1] == pytest.approx(0.4, abs=1e-10)  # equal capacities
    flows, flows_ref = s["boundary_heat_flow"], r["boundary_heat_flow"]
    hot = max(abs(q) for q in flows_ref["groups"].values())
    assert len(flows_ref["groups"]) == 2 and hot > 0.0
    for name, q in flows_ref["groups"].items():
        assert flows["groups"][name] == pytest.approx(q, rel=1e-8)
    assert flows["fixed_total"] == pytest.approx(flows_ref["fixed_total"], abs=1e-8 * hot)
    assert s["energy_error"] < 1e-9


def test_convection_on_the_exposed_surfaces_across_the_ranks():
    """The ambient (at the cold end's temperature) acts on each particle's exposed surface (computed from the
    packing around it) through its centre: a good part of the heat from the hot end leaves through it."""
    sources = Sources(convection=Convection(h=2e4, T_inf=0.0))
    scene = _fixed_ends(_blocks("plates"), sources=sources)
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-8
    hot = max(abs(q) for q in r["boundary_heat_flow"]["groups"].values())
    assert 0.02 < -r["heat_flow"]["convection"] / hot < 1.0
    for name in ("fixed", "convection"):
        assert s["heat_flow"][name] == pytest.approx(r["heat_flow"][name], rel=1e-8)
    assert s["energy_error"] < 1e-9


def test_a_floating_pair_is_refused_as_in_the_serial_run():
    scene = _fixed_ends(_blocks("plates"), "error")
    with pytest.raises(ValueError) as serial_error:
        serial(scene)
    with pytest.raises(ValueError) as ours:
        run(scene)
    n = scene.particles.n
    assert f"1 connected group(s) of particles (e.g. [{n - 2}, {n - 1}])" in str(ours.value)
    assert str(ours.value) == str(serial_error.value)


def test_a_union_packing_read_in_parts_equals_the_serial_run():
    """A packing in parts read with neck nodes: each rank reads the particles within three bond lengths of its own
    (not all of them; with one, as for one node per particle, its rows would be wrong), and the run is the serial run
    of the packing read whole."""
    from test_distributed_network import union_parts_scene

    scene, whole = union_parts_scene(2000, 'nodes = "necks"')
    assert scene.conductance.nodes == "necks"
    assert scene.particles.n < whole.particles.n == scene.particle_count
    result = run(scene)
    ref = serial(whole)
    s, r = result.summary, ref.summary()
    assert s["neck_nodes"] == r["neck_nodes"] and s["particles_necks_meeting"] == r["particles_necks_meeting"]
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-8)
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-8
