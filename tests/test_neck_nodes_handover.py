"""Neck nodes through the hand-over from a pair-neck reading to the union (dem.engines.handover, "Neck nodes"): each
particle's element blended by its weight, against the two readings' networks assembled apart; moving runs that hand
over with neck nodes: what the summary says, k_eff continuous, resumed bit for bit."""

import pathlib
import tomllib

import numpy as np
import pytest
import scipy.sparse as sp

import dem
from dem import parse_scene
from dem.engines.handover import Handover
from dem.engines.verlet.engine import VerletEngine
from dem.geometry.bonds import find_bonds
from dem.geometry.handover import HANDOVER_STEPS
from dem.geometry.necks import necks_meeting
from dem.geometry.particles import Material, Particles
from dem.laws.conductance import ConductanceSpec
from dem.network.necks import neck_network, steady_necks
from handover_steps import record_handovers
from test_handover import fcc_cluster, squeezed

UNIT = Material(1.0, 1.0, 1.0, "unit")
SPEC = ConductanceSpec(law="shared-body", out_of_range="clip", nodes="necks")


def _cluster():
    """The FCC cluster of the hand-over's tests at h/r 0.14, past the meeting of its pair necks (from 0.131)."""
    r, i, j, v = fcc_cluster(0.14)
    x = np.zeros((len(r), 3))  # the positions from the pairs' vectors: the cluster's own
    x[:] = np.nan
    x[0] = 0.0
    for _ in range(len(r)):  # along the pairs from particle 0 (the cluster is connected)
        known = ~np.isnan(x[i, 0]) & np.isnan(x[j, 0])
        x[j[known]] = x[i[known]] + v[known]
        back = np.isnan(x[i, 0]) & ~np.isnan(x[j, 0])
        x[i[back]] = x[j[back]] - v[back]
    assert not np.isnan(x).any()
    particles = Particles.from_arrays(x, r, np.zeros(len(r)), materials=(UNIT,))
    return particles, (i, j)


def _assembled(net, weight, node_of_bond, necks=None):
    """The matrix of ``net``'s element entries each times its particle's ``weight``, on the nodes ``node_of_bond``
    gives the necks of its live bonds (``necks`` neck nodes; default one per bond)."""
    row, col, value = net.entries[:3]
    n = net.particles.n
    keep = (row >= 0) & (col >= 0)
    place = np.concatenate([np.arange(n), node_of_bond[net.live]])
    size = n + (len(node_of_bond) if necks is None else necks)
    return sp.coo_matrix((value[keep] * weight[net.owner[keep]], (place[row[keep]], place[col[keep]])),
                         shape=(size, size)).toarray()


@pytest.mark.slow
def test_each_particle_is_its_two_readings_blended_by_its_weight():
    """Weights 0, 0.37 and 1 among the particles of a cluster whose necks meet: the network's matrix is the sum over
    the particles of (1 - w) times its element on the pair reading and w times its element on the union reading of the
    grown spheres, each assembled apart by its own network; handed over altogether, the union reading's network."""
    particles, pairs = _cluster()
    n = particles.n
    handover = Handover(SPEC, particles.radius)
    pair = find_bonds(particles, (), "newton", "clip", pairs=pairs)
    assert np.any(necks_meeting(particles.radius, pair, pair.vectors(particles.position), np.zeros((0, 3))))
    rng = np.random.default_rng(5)
    for steps in (rng.choice([0, 36, HANDOVER_STEPS - 1], n), np.full(n, HANDOVER_STEPS - 1)):
        handover.steps = steps
        net = handover.neck_network(particles, (), pairs, None, update=True)  # one step on: the radii kept
        w = handover.weight
        assert len(np.unique(w)) == (4 if steps.min() == 0 else 1)  # (0 and 1/100: not meeting and meeting)
        grown = Particles.from_arrays(particles.position, handover.solid_radius, np.zeros(n), materials=(UNIT,))
        assert np.all(handover.solid_radius[w > 0] > particles.radius[w > 0])
        union = neck_network(ConductanceSpec(law="shared-body", neck="union", nodes="necks"), grown,
                             find_bonds(grown, (), "union", pairs=pairs))
        plain = neck_network(SPEC, particles, pair)
        node = n + np.arange(pair.n_pairs)
        expected = _assembled(plain, 1.0 - w, node) + _assembled(union, w, node)
        expected = 0.5 * (expected + expected.T)
        A = net.A.toarray()
        assert np.array_equal(net.live, np.arange(pair.n_pairs))
        assert np.abs(A - expected).max() < 1e-12 * np.abs(expected).max()
        assert np.abs(_assembled(union, w, node) - _assembled(plain, w, node)).max() > 1e-3 * np.abs(A).max()
    assert np.array_equal(union.live, np.arange(pair.n_pairs))  # no neck hidden: the same nodes
    assert np.abs(A - union.A.toarray()).max() < 1e-12 * np.abs(A).max()


def test_a_neck_the_union_hides_takes_nothing_from_it_and_has_no_node_once_handed_over():
    """Two spheres whose lens neck lies inside a third, larger sphere: the union reading has no neck there. Its
    particles on the way, the neck keeps its node through their pair elements (the blend as above); both handed
    over, it has no node, and the network is the union reading's, which then holds a fixed temperature to
    round-off."""
    x = np.array([[0.0, 0.0, 0.0], [1.9e-3, 0.0, 0.0], [0.95e-3, 0.6e-3, 0.0]])
    r = np.array([1e-3, 1e-3, 1.2e-3])
    fixed = np.array([True, False, False])
    particles = Particles.from_arrays(x, r, np.where(fixed, 1.0, 0.0), materials=(UNIT,), fixed=fixed)
    pair = find_bonds(particles, (), "newton", "clip")
    pairs = (pair.i, pair.j)
    for steps, nodes in (([HANDOVER_STEPS - 1, 30, 0], 3), ([0, HANDOVER_STEPS - 1, HANDOVER_STEPS - 1], 3),
                         ([HANDOVER_STEPS - 1] * 3, 2)):
        handover = Handover(SPEC, r)
        handover.steps = np.array(steps)
        net = handover.neck_network(particles, (), pairs, None, update=True)
        w = handover.weight
        grown = Particles.from_arrays(x, handover.solid_radius, particles.temperature, materials=(UNIT,),
                                      fixed=fixed)
        union = neck_network(ConductanceSpec(law="shared-body", neck="union", nodes="necks"), grown,
                             find_bonds(grown, (), "union", pairs=pairs))
        assert np.array_equal(union.live, [1, 2]) and len(net.live) == nodes  # bond (0, 1) hidden by sphere 2
        node = 3 + np.arange(pair.n_pairs)
        node[net.live] = 3 + np.arange(len(net.live))
        expected = _assembled(neck_network(SPEC, particles, pair), 1.0 - w, node)[:3 + nodes, :3 + nodes]
        expected += _assembled(union, w, node)[:3 + nodes, :3 + nodes]
        expected = 0.5 * (expected + expected.T)
        assert np.abs(net.A.toarray() - expected).max() < 1e-12 * np.abs(expected).max()
    assert np.abs(net.A.toarray() - union.A.toarray()).max() < 1e-12 * np.abs(expected).max()
    assert steady_necks(net).T == pytest.approx(np.ones(3), rel=1e-12)


def test_out_of_range_error_decides_on_what_each_reading_holds():
    """``out_of_range = "error"``, a pair neck past its range (h = 0.75 r > 2r/3) between a particle handed over and
    one not on its way: with neck nodes the latter's element is its pair element, which has the neck, so the read
    stops with the range error (it read the clipped neck: the check took the bond's weight, the larger, 1); the
    one-node law's bond has that weight and reads the union alone; both handed over, neither reads the pair neck."""
    r = 1e-3
    particles = Particles.from_arrays(np.array([[0.0, 0.0, 0.0], [1.25e-3, 0.0, 0.0]]), np.full(2, r), np.zeros(2),
                                      materials=(UNIT,))
    pairs = (np.array([0]), np.array([1]))
    for steps in ([HANDOVER_STEPS, 0], [0, HANDOVER_STEPS], [HANDOVER_STEPS, HANDOVER_STEPS]):
        one, necks = (Handover(ConductanceSpec(law="shared-body", nodes=nodes), particles.radius)
                      for nodes in ("particles", "necks"))
        one.steps = necks.steps = np.array(steps)
        K = one.bonds(particles, (), pairs, None)[1]
        assert np.all(np.isfinite(K)) and np.all(K > 0.0)
        if min(steps) == HANDOVER_STEPS:
            assert np.array_equal(necks.neck_network(particles, (), pairs, None).live, [0])
        else:
            with pytest.raises(ValueError, match="beyond the contact model's range"):
                necks.neck_network(particles, (), pairs, None)


def _run(scene: dict, restart=None) -> VerletEngine:
    engine = VerletEngine(parse_scene(scene), restart=restart)
    engine.run()
    return engine


def _squeezed(t_end: float, nodes: str = "necks") -> dict:
    scene = squeezed(t_end, rate=30.0)
    scene["conductance"] = {"law": "shared-body", "out_of_range": "clip", "nodes": nodes}
    return scene


def _conductance(engine, steps) -> float:
    """The steady heat flow (W) from the hot layer to the cold one per kelvin through the neck-node network of the
    contacts now with the hand-over steps ``steps``."""
    th, mech = engine.thermal, engine.mechanics
    kept, th.handover.steps = th.handover.steps, steps
    try:
        net = th.neck_heat(mech).net
    finally:
        th.handover.steps = kept
    hot = th.particles.temperature == 100.0
    return float(steady_necks(net).fixed_flow[hot].sum()) / 100.0


@pytest.mark.slow
def test_a_run_that_hands_over_says_what_the_one_node_run_says():
    """The squeezed cluster with neck nodes: its necks meet and its particles are handed over as in the one-node
    run of the same contacts (the hand-over reads the pair necks, not the network), and the summary says so; the
    heat balance holds through the blended elements."""
    necks, plain = _run(_squeezed(0.0012)), _run(_squeezed(0.0012, "particles"))
    assert np.array_equal(necks.mechanics.state.x, plain.mechanics.state.x)
    s, p = necks.summary(), plain.summary()
    assert s["particles_handing_over"] > 0 and s["particles_necks_meeting"] > 0
    for key in ("particles_necks_meeting", "particles_handed_over", "particles_handing_over", "neck_readings"):
        assert s[key] == p[key], key
    assert s["nodes"] == "necks" and s["law_error_range"] == [-0.043, 0.016]
    assert s["energy_error"] < 1e-12
    assert np.array_equal(necks.thermal.handover.solid_radius, plain.thermal.handover.solid_radius)
    # the snapshots read the neck-node network through the hand-over as the last step left it
    links, fields = necks.links()[2], necks.particle_fields()
    assert np.array_equal(fields["handed_over"], necks.thermal.handover.weight)
    assert np.all(np.isfinite(links["heat_flow"])) and np.any(links["heat_flow"] != 0.0)


@pytest.mark.slow
def test_a_resumed_run_goes_on_handing_over_bit_for_bit():
    """Stopped while particles are on the way, the neck-node run resumes from its checkpoint and ends as the run
    that did not stop."""
    whole = _run(_squeezed(0.0025))
    first = _run(_squeezed(0.0018))
    on_the_way = (first.thermal.handover.steps > 0) & (first.thermal.handover.steps < HANDOVER_STEPS)
    assert np.any(on_the_way)
    resumed = _run(_squeezed(0.0025), restart=first.checkpoint())
    assert np.array_equal(resumed.thermal.T, whole.thermal.T)
    for name in ("steps", "solid_radius"):
        assert np.array_equal(getattr(resumed.thermal.handover, name), getattr(whole.thermal.handover, name)), name
    assert resumed.summary()["energy_error"] == whole.summary()["energy_error"]


@pytest.mark.slow
def test_k_eff_is_continuous_through_the_handover():
    """Squeezed harder, most of the cluster's particles begin their hand-over together: across every thermal step
    that hands particles over the conductance between the hot and the cold layer (the same contacts, the steps
    before and after) changes by at most 0.5 %, as the one-node law's; handed over at once it would jump."""
    engine = VerletEngine(parse_scene(_squeezed(0.005)))
    th = engine.thermal
    jumps, at_once = record_handovers(
        engine, _conductance,
        lambda old: _conductance(engine, np.where(th.handover.steps > 0, HANDOVER_STEPS, 0)) / old - 1.0)
    engine.run()
    assert np.count_nonzero(th.handover.steps) >= 40 and len(jumps) >= 60
    assert np.max(np.abs(jumps)) < 5e-3
    assert np.max(np.abs(at_once)) > 10 * np.max(np.abs(jumps))  # the steps are what keeps it continuous


def test_the_timeseries_gives_k_eff_on_pair_necks_beside_it():
    """With neck nodes too, k_eff of the contacts all read as pair necks is k_eff itself while no particle is handed
    over (the first milliseconds of hot-wall-sintering), the neck-node network's both."""
    text = (pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "hot-wall-sintering.toml").read_text()
    doc = tomllib.loads(text.replace("t_end = 0.15\n", "t_end = 0.004\n"))
    doc["conductance"]["nodes"] = "necks"
    engine = _run(doc)
    row = engine.record()
    assert not np.any(engine.thermal.handover.steps) and engine.summary()["nodes"] == "necks"
    assert row["effective_conductivity_pair_necks"] == row["effective_conductivity"] is not None


@pytest.mark.parametrize("policy", ["drop", "clip"])
@pytest.mark.slow
def test_a_pair_neck_past_its_range_on_the_way_blends_the_policys_pair_reading_with_the_union(policy):
    """Squeezed hard, pair necks pass their range (h > 2r/3 for equal spheres) while their particles are on the way
    to the union. As the one-node law's pair conductance of such a bond is the scene's ``out_of_range`` reading's and
    its union one weighed in, each particle's pair element is that reading's and its union element has those necks:
    under ``"drop"`` the pair element is without them (the run stopped with an error), under ``"clip"`` it has them
    at their clipped radius. The network is that blend, each reading assembled apart; the run goes on, heat in is
    heat out, and its snapshot's one-node conductances are finite."""
    from dataclasses import replace

    from fem_neck.geometry import max_overlap

    scene = squeezed(0.00105, rate=300.0)
    scene["conductance"] = {"law": "shared-body", "out_of_range": policy, "nodes": "necks"}
    engine = _run(scene)
    assert engine.summary()["energy_error"] < 1e-12
    assert all(np.all(np.isfinite(v)) for v in engine.links()[2].values())
    th, mech = engine.thermal, engine.mechanics
    now = th._particles_now(mech, th.particles.radius)
    n, pairs = now.n, mech.contacts()[:2]
    spec = ConductanceSpec(law="shared-body", out_of_range=policy, nodes="necks")
    handover = Handover(spec, th.particles.radius)
    handover.steps, handover.solid_radius = th.handover.steps.copy(), th.handover.solid_radius.copy()
    net = handover.neck_network(now, (), pairs, None)
    w = handover.weight
    clipped = find_bonds(now, (), "newton", "clip", pairs=pairs)
    past = clipped.h > max_overlap(now.radius[clipped.i], now.radius[clipped.j])
    assert np.count_nonzero(past) >= 5 and np.all((w > 0.0) & (w < 1.0))
    read = find_bonds(now, (), "newton", policy, pairs=pairs)
    assert read.n_pairs == clipped.n_pairs - (np.count_nonzero(past) if policy == "drop" else 0)
    grown = replace(now, radius=handover.solid_radii(now.radius))
    union = neck_network(ConductanceSpec(law="shared-body", neck="union", nodes="necks"), grown,
                         find_bonds(grown, (), "union", pairs=pairs))
    plain = neck_network(spec, now, read)
    assert np.array_equal(net.live, np.arange(clipped.n_pairs))  # every neck is the union's: each keeps its node
    key = clipped.i.astype(np.int64) * n + clipped.j
    node = n + np.arange(clipped.n_pairs)
    node_read = node[np.searchsorted(key, read.i.astype(np.int64) * n + read.j)]
    assert np.all(np.diff(key) > 0)
    expected = _assembled(plain, 1.0 - w, node_read, clipped.n_pairs) + _assembled(union, w, node)
    expected = 0.5 * (expected + expected.T)
    A = net.A.toarray()
    assert np.abs(A - expected).max() < 1e-12 * np.abs(expected).max()
    # a pair neck past its range still joins its particles' centres (through the union part at least)
    at_past = n + np.flatnonzero(past)
    assert np.all(np.abs(A[at_past][:, :n]).sum(axis=1) > 0.0)
