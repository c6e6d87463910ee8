"""``[conductance] element = "trefftz"`` on several MPI ranks (dem.network.distributed_necks: three flux modes per
neck, each rank building the Trefftz elements of its own particles and receiving those of their necks' partners)
against the serial run of the same scene in the same process: random union packings, periodic and between two walls,
some blocks long. Every owned row is the serial matrix's; k_eff, the wall flows and the temperatures are the serial
run's, steady and in implicit and Crank-Nicolson steps."""

import numpy as np
import pytest

from dem.driver import run
from dem.engines.distributed.static import DistributedStaticEngine
from dem.parallel import comm as mpi
from test_distributed_necks import COMM, _blocks, owned_rows_against_serial, serial

ELEMENT = ("element_particles", "element_plain", "element_refined")
GUARD = 300  # s: a test still running after it is taken for a rank left waiting, ended (exit status 1)


def _trefftz(boundary: str, solver: dict | None = None):
    """Three blocks of 48 spheres (some with necks that meet) with the Trefftz element (in a periodic box the
    ranks' halos then reach every particle, a fringe of them still unused and on the law's element)."""
    return _blocks(boundary, solver, blocks=3, n=40, element="trefftz")


def _compare(scene):
    """The run on the ranks and the serial one: the same necks, elements and temperatures; returns both summaries."""
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert s["ranks"] == COMM.Get_size() and s["element"] == r["element"] == "trefftz"
    assert ref.necks.modes == 3 and r["element_particles"] > 0.9 * scene.particles.n
    for key in ("neck_nodes", "bonds", "wall_bonds", "particles_necks_meeting", *ELEMENT):
        assert s[key] == r[key], key
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-9  # hot - cold = 1 K
    assert s["energy_error"] < 1e-9
    engine = result.engine  # a fringe of held nodes neither owned nor reached, its particles on the law's element
    assert len(engine.part.held) > len(engine.part.used)
    assert scene.box is not None or len(engine.held) < scene.particles.n  # between walls the halo ends inside
    assert np.any(np.asarray(engine.necks.modes) == 1) and np.any(np.asarray(engine.necks.modes) == 3)
    built = np.asarray(engine.elements.built.modes) == 3  # each rank built the Trefftz elements of its own only
    assert np.array_equal(built, engine.mine) and mpi.total(COMM, int(built.sum())) == scene.particles.n
    return s, r


def test_a_periodic_union_packing_equals_the_serial_run():
    s, r = _compare(_trefftz("periodic"))
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-10)
    q, q_ref = np.array(s["periodic_heat_flow"]), np.array(r["periodic_heat_flow"])
    assert np.max(np.abs(q - q_ref)) < 1e-10 * np.max(np.abs(q_ref))


def test_a_union_packing_between_walls_equals_the_serial_run():
    s, r = _compare(_trefftz("plates"))
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-10)
    walls, walls_ref = s["boundary_heat_flow"]["walls"], r["boundary_heat_flow"]["walls"]
    for name in ("hot", "cold"):
        assert walls[name] == pytest.approx(walls_ref[name], rel=1e-10)


def test_owned_rows_are_those_of_the_serial_matrix():
    """Each rank's rows over the free nodes, centres and the necks' three modes each, by the nodes' global keys: the
    serial network's to round-off."""
    scene = _trefftz("periodic")
    ours, theirs, _, _, owned, free, ref = owned_rows_against_serial(scene)
    assert abs(ours - theirs).max() < 1e-12 * np.abs(theirs).max() and ours.nnz == theirs.nnz
    assert owned == free == scene.particles.n + 3 * len(ref.necks.live)


@pytest.mark.parametrize("integrator", ["implicit", "crank-nicolson"])
def test_fixed_steps_equal_the_serial_steps(integrator):
    """Between the walls from 0 C, five steps of 2e-4 s (above the stable limit: Crank-Nicolson starts with implicit
    Euler steps on both, decided on the condensed matrix of the centres over the ranks)."""
    scene = _trefftz("plates", {"mode": "transient", "integrator": integrator, "dt": 2e-4, "t_end": 1e-3})
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert s["steps"] == r["steps"] == 5
    assert s.get("startup_steps") == r.get("startup_steps")
    assert (r.get("startup_steps") or 0) > 0 or integrator == "implicit"
    T, T_ref = result.engine.gathered_temperatures(), ref.T
    assert 0.01 < np.ptp(T_ref) < 1.0  # heat on its way through
    assert np.max(np.abs(T - T_ref)) < 1e-9
    assert s["heat_in"]["walls"] == pytest.approx(r["heat_in"]["walls"], rel=1e-9)
    assert s["energy_error"] < 1e-9


def test_a_packing_read_in_parts_equals_the_serial_run():
    """A packing in parts (16 blocks, 320 particles) read with the Trefftz element: each rank reads the particles
    within three bond lengths of its own (all of them here; test_distributed_necks' larger one is cut) and builds the
    elements of its own only; the run is the serial run of the packing read whole."""
    from test_distributed_network import union_parts_scene

    scene, whole = union_parts_scene(300, 'nodes = "necks"\nelement = "trefftz"')
    assert scene.conductance.element == "trefftz"
    assert scene.part is not None and whole.particles.n == scene.particle_count
    result = run(scene)
    ref = serial(whole)
    s, r = result.summary, ref.summary()
    assert np.array_equal(np.asarray(result.engine.elements.built.modes) == 3, result.engine.mine)
    for key in ("neck_nodes", "particles_necks_meeting", *ELEMENT):
        assert s[key] == r[key], key
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-10)
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-9


def test_each_rank_assembles_its_network_once(monkeypatch):
    """Each rank computes its necks' halves (the cut bodies, the closing pores) once and assembles its network with a
    node per neck once, from its own particles' Trefftz elements and their partners' received from their owners: the
    network assembled from scratch with those elements, to the bit."""
    import dem.engines.distributed.static as engine_module
    import dem.laws.conductance as conductance
    import dem.network.necks as necks

    counts = {"halves": 0, "networks": 0}
    halves, share, given = conductance.union_halves, engine_module.shared_elements, []

    def counted(*args, **kwargs):
        counts["halves"] += 1
        return halves(*args, **kwargs)

    class Counted(necks.NeckNetwork):
        def __init__(self, *args, **kwargs):
            counts["networks"] += 1
            super().__init__(*args, **kwargs)

    def shared(*args):
        given.append(share(*args))
        return given[-1]

    for module in (conductance, necks):
        monkeypatch.setattr(module, "union_halves", counted)
    monkeypatch.setattr(necks, "NeckNetwork", Counted)
    monkeypatch.setattr(engine_module, "shared_elements", shared)
    scene = _trefftz("periodic")
    engine = DistributedStaticEngine(scene)
    assert COMM.allgather(counts) == [{"halves": 1, "networks": 1}] * COMM.Get_size()
    assert np.any(np.asarray(given[0].modes) == 3) and not np.array_equal(given[0].values, engine.elements.built.values)
    local = engine.scene
    again = necks.neck_network(local.conductance, local.particles, engine.necks.bonds, box=local.box,
                               walls=local.walls, elements=lambda *args: given[0])
    net = engine.necks
    for ours, theirs in ((net.A.data, again.A.data), (net.A.indices, again.A.indices), (net.rhs, again.rhs),
                         *zip(net.entries, again.entries)):
        assert np.array_equal(ours, theirs)


def test_what_the_elements_take_is_said_once_by_rank_0_for_all_the_ranks(monkeypatch, capsys):
    """With a large figure per neck (so that it is said), a run on the ranks that reports its progress says on
    stderr one line of what the elements take, on rank 0 only: for the particles, necks and pairs of them meeting of
    the serial run's live necks, and the busiest rank's share of them (the elements are the law's here: only what is
    said is looked at)."""
    from dem import memory
    from dem.engines.static import StaticEngine
    from dem.geometry.necks import pairs_meeting
    from dem.laws.shared_body import particle_elements
    from dem.network import trefftz_element as te
    from sinterheat import threads

    given = []

    def law(*args, where=None):
        given.append(args)
        return te.TrefftzElements(*particle_elements(*args), refine=np.ones(args[0]))

    monkeypatch.setitem(memory.TREFFTZ_SECONDS, "neck", 10.0)
    monkeypatch.setattr(te, "trefftz_elements", law)
    scene = _trefftz("periodic")
    StaticEngine(scene)  # the serial run's live necks (nothing said: no listener)
    n, radius, live, vectors = given[0][:4]
    necks, meeting = live.necks_per_particle(n), pairs_meeting(radius, live, vectors, given[0][8])
    capsys.readouterr()
    result = run(scene, progress=True)
    said = [line for line in capsys.readouterr().err.splitlines() if "Trefftz elements" in line]
    shares = [(len(own), int(necks[own].sum()), int(meeting[own].sum()), workers)
              for own, workers in COMM.allgather((result.engine.owned, threads.count()))]
    line = memory.element_estimate(*zip(*shares))
    assert f"of {scene.particles.n} particles on {COMM.Get_size()} ranks" in line and meeting.sum() > 0
    assert COMM.allgather(said) == [[f"python -m dem run: {line}"]] + [[]] * (COMM.Get_size() - 1)


def test_counting_the_necks_raising_on_one_rank_stops_every_rank(monkeypatch):
    """The count of what the elements take (the necks and the pairs of them meeting, gathered to rank 0 to be said)
    raising a ValueError on the last rank only: every rank raises it, none is left waiting in the gather (were one,
    the run would end, failed, after ``GUARD`` seconds; no elements are built: quick)."""
    import faulthandler

    from dem.network import elements
    from dem.network import trefftz_element as te

    message = "the necks of the last rank could not be counted"

    def uncounted(*args):
        raise ValueError(message)

    if COMM.Get_rank() == COMM.Get_size() - 1:  # not rank 0, which waits in the gather for the others
        monkeypatch.setattr(elements, "pairs_meeting", uncounted)
    monkeypatch.setattr(te, "trefftz_elements", lambda *args, where=None: None)  # (the run stops before using them)
    scene = _trefftz("periodic")
    faulthandler.dump_traceback_later(GUARD, exit=True)
    try:
        with pytest.raises(ValueError) as error:
            DistributedStaticEngine(scene)
    finally:
        faulthandler.cancel_dump_traceback_later()
    assert COMM.allgather(str(error.value)) == [message] * COMM.Get_size()
