"""``[conductance] element = "trefftz"``: the Trefftz element of each cut sphere as a scene option
(dem.network.elements): its refusals, a static run equal to neck_network with trefftz_elements, the summary's account
of the element and of its FE evidence (dem.laws.verified_range), and the up-front estimate of its time (dem.memory)."""

import time
from dataclasses import replace

import numpy as np
import pytest

from dem import make_scene, memory, run
from dem.geometry.bonds import find_bonds
from dem.geometry.periodic import PeriodicBox
from dem.geometry.walls import Wall
from dem.laws.conductance import ConductanceSpec
from dem.network import trefftz_element as te
from dem.network.necks import neck_network, steady_necks
from dem.scene.parse import parse_scene

# The Trefftz element's kernels take numba 25 s to compile in a fresh clone: with the slow tests.
pytestmark = pytest.mark.slow

TREFFTZ = ConductanceSpec(law="shared-body", neck="union", nodes="necks", element="trefftz")
_TREFFTZ = te.trefftz_elements


def _packing(seed: int = 5, conductance: ConductanceSpec = TREFFTZ, **options):
    """A simple cubic 2 x 2 x 2 block of copper spheres of 1 mm (radii +-10 %) 1.6 mm apart, each centre moved by up
    to 0.15 mm at random, in its periodic box, read as the union of its spheres, 1 K drop per period along z: six necks
    per particle, of different widths, meeting on some particles."""
    rng = np.random.default_rng(seed)
    x = (np.indices((2, 2, 2)).reshape(3, -1).T + 0.5) * 1.6e-3 + rng.uniform(-0.15e-3, 0.15e-3, (8, 3))
    r = rng.uniform(0.9e-3, 1.1e-3, 8)
    box = PeriodicBox(np.full(3, 3.2e-3), drop=[0.0, 0.0, 1.0])
    return make_scene(x, r, np.zeros(8), box=box, mode="steady", floating="mean", conductance=conductance, **options)


def _toml(**conductance) -> dict:
    table = {"law": "shared-body", "neck": "union", "nodes": "necks", "element": "trefftz", **conductance}
    return {"scene": {"name": "t"}, "material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},
            "generator": {"kind": "random", "n": 8, "radius": 5e-5, "radius_spread": 0.15, "overlap": 0.15,
                          "seed": 3, "boundary": "periodic", "hot": 1.0, "cold": 0.0},
            "conductance": {k: v for k, v in table.items() if v is not None}, "solver": {"floating": "mean"}}


@pytest.mark.parametrize("options, match", [
    ({"element": "exact"}, r"conductance.element = 'exact': must be one of law, trefftz"),
    ({"law": "fit", "nodes": "particles"},
     r"conductance.element = \"trefftz\": only with law = \"shared-body\", nodes = \"necks\" and neck = \"union\" "
     r".*here law = 'fit'"),
    ({"nodes": "particles"}, r"element = \"trefftz\": only with .*nodes = 'particles'"),
    ({"neck": "newton"}, r"element = \"trefftz\": only with .*neck = 'newton'"),
])
def test_the_option_is_refused_outside_the_cut_spheres_with_a_neck_node_network(options, match):
    base = {"law": "shared-body", "neck": "union", "nodes": "necks", "element": "trefftz"}
    with pytest.raises(ValueError, match=match):
        ConductanceSpec(**{**base, **options})
    assert ConductanceSpec().element == "law"


def test_a_scene_names_the_table_and_the_key():
    with pytest.raises(ValueError, match=r"^\[conductance\] element = \"trefftz\": only with law = \"shared-body\""):
        parse_scene(_toml(nodes="particles"))
    with pytest.raises(ValueError, match=r"^\[conductance\] element = 'none': must be one of law, trefftz$"):
        parse_scene(_toml(element="none"))


def test_moving_particles_are_refused_with_the_reason_and_mpi_is_not():
    from dem.engines.distributed.static import unsupported

    law = _packing(conductance=ConductanceSpec(law="shared-body", neck="union", nodes="necks"))
    with pytest.raises(ValueError, match=r"^\[conductance\] element = \"trefftz\": not with moving particles \(engine "
                                         r"'verlet': every thermal step would rebuild"):
        replace(law, engine="verlet", conductance=TREFFTZ)
    assert unsupported(_packing()) is None  # (tests/mpi/test_distributed_trefftz.py runs it on two ranks)
    assert unsupported(law) is None


def test_a_run_between_walls_is_the_neck_network_of_trefftz_elements_and_keeps_its_heat():
    """A cluster of 40 overlapping spheres between a hot and a cold wall (their faces cut like necks'): the run's wall
    flows are those of neck_network(elements=trefftz_elements) solved directly, what enters leaves, and they differ
    from the law's element's (the element is used, not the law's)."""
    rng = np.random.default_rng(11)
    x = rng.uniform([0.0, 0.0, 0.3e-3], [4e-3, 4e-3, 3.7e-3], (40, 3))
    r = rng.uniform(0.85e-3, 1.15e-3, 40)
    walls = (Wall("hot", point=[0.0, 0.0, 0.2e-3], normal=[0.0, 0.0, 1.0], temperature=1.0),
             Wall("cold", point=[0.0, 0.0, 3.8e-3], normal=[0.0, 0.0, -1.0], temperature=0.0))
    spec = replace(TREFFTZ, out_of_range="drop")
    scene = make_scene(x, r, np.full(40, 0.5), walls=walls, mode="steady", conductance=spec)
    flows = run(scene).summary["boundary_heat_flow"]["walls"]
    bonds = find_bonds(scene.particles, walls, "union", out_of_range="drop")
    assert bonds.n_walls > 4
    net = neck_network(spec, scene.particles, bonds, walls=walls, elements=_TREFFTZ)
    into = np.bincount(bonds.wall_index[net.live_walls], steady_necks(net).wall_flow, minlength=2)
    assert [flows["hot"], flows["cold"]] == pytest.approx(list(into), rel=1e-9)
    assert abs(flows["hot"] + flows["cold"]) < 1e-9 * abs(flows["hot"])
    law = run(replace(scene, conductance=replace(spec, element="law"))).summary["boundary_heat_flow"]["walls"]
    assert abs(law["hot"] / flows["hot"] - 1.0) > 1e-3


@pytest.mark.parametrize("seed", [1, 3])
def test_a_static_run_is_the_neck_network_of_trefftz_elements_and_says_so(seed):
    """The run's k_eff is neck_network(elements=trefftz_elements)'s, solved here directly; it is not the law's
    element's; the summary names the element, counts the particles that carry it and those that kept the law's
    monopoles and those whose quadrature was refined
    (as the elements built directly say), and the evidence is the element's: +-0.7 % where
    necks meet, where the law's element is outside its verified range."""
    scene = _packing(seed)
    s = run(scene).summary
    p, box = scene.particles, scene.box
    bonds = find_bonds(p, contact="union", box=box)
    built = []
    direct = steady_necks(neck_network(scene.conductance, p, bonds, box=box,
                                       elements=_recording(te.trefftz_elements, built)))
    k = direct.periodic_heat_flow[2] * box.lengths[2] / (box.cross_section(2) * box.drop[2])
    assert s["effective_conductivity"] == pytest.approx(k, rel=1e-12)
    law = run(_packing(seed, conductance=ConductanceSpec(law="shared-body", neck="union", nodes="necks"))).summary
    assert abs(s["effective_conductivity"] / law["effective_conductivity"] - 1.0) > 3e-3
    assert s["particles_necks_meeting"] > 0
    plain = int(np.count_nonzero(built[0].plain))
    refined = int(np.count_nonzero(built[0].refine > 1.0))
    assert (s["element"], s["element_particles"], s["element_plain"], s["element_refined"]) == ("trefftz",
                                                                                               p.n - plain, plain,
                                                                                               refined)
    assert s["element_seconds"] > 0.0
    assert s["law_in_verified_range"] is True and s["law_error_range"] == [-0.007, 0.007] and "warnings" not in s
    assert "particles_without_interactions" not in s and law["element"] == "law"
    assert "element_particles" not in law and law["law_in_verified_range"] is False


def test_the_evidence_of_the_element_holds_where_necks_meet_and_the_laws_does_not():
    from dem.laws.verified_range import neck_account

    element = neck_account(3, 10, "union", 40, "shared-body", wide=2, nodes="necks", element="trefftz")
    law = neck_account(3, 10, "union", 40, "shared-body", wide=2, nodes="necks")
    assert element["law_in_verified_range"] is True and element["law_error_range"] == [-0.007, 0.007]
    assert "warnings" not in element and element["particles_necks_wide"] == 2
    assert law["law_in_verified_range"] is False and len(law["warnings"]) == 2
    assert neck_account(0, 10, "union", 40, "shared-body", nodes="necks", element="trefftz")["law_error_range"] == \
        [-0.007, 0.007]


def test_the_estimate_is_per_neck_and_per_pair_of_necks_meeting_said_only_where_large():
    a, b = memory.TREFFTZ_SECONDS["neck"], memory.TREFFTZ_SECONDS["meeting pair"]
    assert memory.element_seconds([4, 6, 0], [0, 3, 0]) == pytest.approx(10 * a + 3 * b, rel=1e-15)
    assert memory.element_estimate([100], [600], [200], [1]) is None  # 100 particles: about 1.4 s
    n = int(np.ceil(memory.ANNOUNCE_SECONDS / (12 * a + 24 * b)))
    line = memory.element_estimate([n], [12 * n], [24 * n], [1])
    assert line == (f"the Trefftz elements of {n} particles (12 necks each on average, {24 * n} pairs of necks "
                    f"meeting): about {(12 * a + 24 * b) * n:.3g} s on one core, before the solve")
    assert memory.element_estimate([n], [12 * n], [24 * n], [4]) == line.replace("one core,",
                                                                                "one core, shared by 4 threads,")


def test_on_ranks_the_estimate_is_one_line_for_all_of_them_with_the_busiest_ranks_wall_time():
    """Three ranks building 100, 300 and 200 particles' elements (necks and meeting pairs in proportion, on 2, 4 and 1
    threads: wall times in the ratio 0.5 : 0.75 : 2): the total over the ranks, and the third rank's wall time."""
    a, b = memory.TREFFTZ_SECONDS["neck"], memory.TREFFTZ_SECONDS["meeting pair"]
    each = 10 * a + 3 * b  # one particle's
    n = int(np.ceil(memory.ANNOUNCE_SECONDS / (600 * each)))
    particles = [100 * n, 300 * n, 200 * n]
    line = memory.element_estimate(particles, [10 * k for k in particles], [3 * k for k in particles], [2, 4, 1])
    assert line == (f"the Trefftz elements of {600 * n} particles on 3 ranks (10 necks each on average, {1800 * n} "
                    f"pairs of necks meeting): about {600 * n * each:.3g} s on one core in all, about "
                    f"{200 * n * each:.3g} s on the busiest rank, before the solve")
    threads = memory.element_estimate(particles, [10 * k for k in particles], [3 * k for k in particles], [2, 4, 4])
    assert threads == line.replace(f"{200 * n * each:.3g} s on the busiest rank,",  # now the second: 300 n on 4
                                   f"{75 * n * each:.3g} s on the busiest rank (its {300 * n * each:.3g} s shared "
                                   f"by 4 threads),")
    assert memory.element_estimate([100, 100], [600, 600], [200, 200], [1, 1]) is None  # 2.8 s in all


@pytest.mark.parametrize("kind, h, pairs", [("sc", 0.6, 36), ("fcc", 0.2, 0), ("fcc", 0.3, 24)])
def test_the_pairs_of_necks_that_meet_are_counted_per_particle(kind, h, pairs):
    """Union lattices, each neck seen in a cone of half-angle arctan(a / l): SC at h/r 0.6 (six face necks of 45.6
    degrees, 90 degrees apart: 12 pairs; the twelve second neighbours, 1.98 r away, overlap too, necks of 8.1 degrees
    45 degrees from two face necks each: 24 pairs), FCC at 0.2 (25.8 degrees, 60 apart: none) and 0.3 (31.8 degrees:
    each neck meets its four neighbours 60 degrees away, 24 pairs); the particles whose necks meet are those with a
    pair."""
    from dem.geometry.necks import meeting_in, pairs_meeting
    from dem.geometry.particles import Particles
    from fem_neck.lattice import lattice_cell

    cell = lattice_cell(kind, h, neck="union")
    p = Particles.from_arrays(cell.centres, cell.radii, np.zeros(cell.n))
    box = PeriodicBox(cell.period)
    bonds = find_bonds(p, contact="union", box=box)
    count = pairs_meeting(p.radius, bonds, bonds.vectors(p.position, box), np.zeros((0, 3)))
    assert count.tolist() == [pairs] * cell.n
    assert meeting_in(p, (), bonds, box).tolist() == [pairs > 0] * cell.n


def test_the_estimate_is_said_from_the_live_necks_before_the_elements_are_built(monkeypatch):
    """With a large figure per neck the hook says, before it builds them, what the elements of the live necks it is
    given will take (their count and the pairs of them that meet, per particle); nothing without a listener, nothing
    for a small estimate."""
    from dem.engines.static import StaticEngine
    from dem.geometry.necks import pairs_meeting
    from sinterheat import threads

    scene = _packing(1)
    heard = []
    with memory.announcing(heard.append):
        StaticEngine(scene)
    assert heard == []  # 8 particles: far below ANNOUNCE_SECONDS
    monkeypatch.setitem(memory.TREFFTZ_SECONDS, "neck", 10.0)
    given, built = [], []

    def build(*args):
        given.append(args)
        built.append(_TREFFTZ(*args))
        return built[-1]

    monkeypatch.setattr(te, "trefftz_elements", build)
    monkeypatch.setattr(threads, "count", lambda: 2)  # the threads that will build them, named in the line
    with memory.announcing(lambda line: heard.append((line, len(built)))):
        StaticEngine(scene)
    n, radius, live, vectors = given[0][:4]
    z = np.bincount(np.concatenate([live.i, live.j]), minlength=n)
    m = pairs_meeting(radius, live, vectors, given[0][8])
    seconds = 10.0 * z.sum() + memory.TREFFTZ_SECONDS["meeting pair"] * m.sum()
    assert heard == [(f"the Trefftz elements of 8 particles ({z.mean():.3g} necks each on average, {m.sum()} pairs "
                      f"of necks meeting): about {seconds:.3g} s on one core, shared by 2 threads, before the solve",
                      0)]
    assert len(built) == 1 and m.sum() > 0


def test_the_elements_time_leaves_numbas_compiling_out(monkeypatch):
    """``seconds`` is the build's CPU time and ``compile_seconds`` numba's: the hook called again with its kernels
    loaded compiles nothing; called with a copy of a kernel compiled inside the build (as on a cold cache), its
    ``compile_seconds`` is the copy's compile as timed outside it and its ``seconds`` those of the build alone."""
    import numba

    from dem.network.elements import SceneElements

    scene = _packing(2)
    p, box = scene.particles, scene.box
    bonds = find_bonds(p, contact="union", box=box)
    hook = SceneElements("trefftz")

    def built() -> tuple:
        neck_network(scene.conductance, p, bonds, box=box, elements=hook)
        return hook.seconds, hook.compile_seconds

    built()  # the kernels compiled or loaded
    seconds, compiled = built()
    assert compiled == 0.0 and seconds > 0.0
    kernel = te._face_points  # compiling a copy takes seconds (numba's cache is the original's)

    def compile_copy() -> float:
        copy = numba.jit(**kernel.targetoptions)(kernel.py_func)
        start = time.process_time()
        for signature in kernel.signatures:
            copy.compile(signature)
        return time.process_time() - start

    compile_copy()  # (the first copy compiles more: what the kernel calls, the originals being loaded from a cache)
    alone = compile_copy()
    monkeypatch.setattr(te, "trefftz_elements", lambda *args: (compile_copy(), _TREFFTZ(*args))[1])
    seconds_with, compiled_with = built()
    assert alone > 0.5 and 0.5 < compiled_with / alone < 2.0
    assert abs(seconds_with - seconds) < 0.25 * compiled_with
    assert hook.account()["element_compile_seconds"] == compiled_with


def _recording(build, built: list):
    def recorded(*args, **kwargs):
        built.append(build(*args, **kwargs))
        return built[-1]
    return recorded


def test_the_cli_run_says_the_estimate_on_stderr_where_it_reports_its_progress(monkeypatch, capsys):
    monkeypatch.setitem(memory.TREFFTZ_SECONDS, "neck", 10.0)
    run(_packing(), progress=True)
    assert "python -m dem run: the Trefftz elements of 8 particles (6.25 necks each" in capsys.readouterr().err
    run(_packing())
    assert "Trefftz" not in capsys.readouterr().err


def test_a_transient_run_on_trefftz_elements_keeps_its_heat_and_ends_at_the_steady_solve():
    """Implicit steps on the three-mode network (the dipoles' nodes massless, as the necks'): the heat stored is the
    heat that came in (none: a periodic box) to round-off, and after many time constants the temperatures are the
    steady solve's (floating groups at their capacity-weighted mean)."""
    scene = _packing(1)
    T0 = np.random.default_rng(2).uniform(0.0, 1.0, scene.particles.n)
    start = replace(scene, particles=replace(scene.particles, temperature=T0))
    transient = replace(start, solver=replace(start.solver, mode="transient", integrator="implicit", dt=1e-2,
                                              t_end=2.0))
    moved = run(transient)
    assert moved.summary["element"] == "trefftz" and abs(moved.summary["energy_error"]) < 1e-12
    assert np.abs(moved.T - run(start).T).max() < 1e-9


def test_the_cli_reports_the_element_in_json_and_refuses_a_wrong_scene_with_exit_2(tmp_path, capsys):
    """python -m dem run --json: the element's entries in the summary; the option with nodes = "particles": one line
    naming [conductance] element, exit 2."""
    import json
    import tomllib

    from dem.cli import main as dem_main

    def write(name, doc):
        lines = []
        for table, values in doc.items():
            lines.append(f"[{table}]")
            lines += [f"{k} = {json.dumps(v)}" for k, v in values.items()]
        (tmp_path / name).write_text("\n".join(lines) + "\n")
        assert tomllib.loads((tmp_path / name).read_text()) == doc
        return str(tmp_path / name)

    assert dem_main(["run", write("t.toml", _toml()), "--json", "--quiet"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["element"] == "trefftz" and s["element_particles"] + s["element_plain"] == s["particles"]
    assert s["element_seconds"] > 0.0 and s["law_error_range"] == [-0.007, 0.007]
    assert dem_main(["run", write("p.toml", _toml(nodes="particles")), "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "[conductance] element = \"trefftz\": only with" in err
