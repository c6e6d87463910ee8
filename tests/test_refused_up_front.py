"""Inputs refused before they cost: the ``box`` generator asked for more particles than fit, a run larger than the
machine's memory, a particle that starts behind a wall -- one line, exit code 2, no traceback, no large allocation."""

import math
import pathlib
import re
import tracemalloc

import numpy as np
import pytest

import dem
from dem import memory
from dem.cli import main
from dem.geometry import generators
from dem.geometry.generators import RSA_CANDIDATES, box_capacity, random_box

HOT_WALL = (pathlib.Path(dem.__file__).parent / "scene" / "builtin" / "hot-wall-sintering.toml").read_text()
BOX = [[0.0, 0.0, 0.0], [6.0e-3, 6.0e-3, 22.0e-3]]  # the hot-wall box: 433 spheres of 0.5 mm +- 20 % fit


def peak_bytes(call):
    """``call()``'s exception and the peak of the memory Python and numpy allocated meanwhile."""
    tracemalloc.start()
    try:
        with pytest.raises(ValueError) as info:
            call()
        return info.value, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def run_cli(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code, err):
    assert code == 2, err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err


@pytest.mark.parametrize("n", [50_000, 2_000_000])
def test_box_generator_refuses_more_particles_than_fit_before_allocating(n):
    """Random sequential addition jams at a solid fraction of 0.384: 558 spheres at most in the hot-wall box. The
    former generator drew 3000 candidates per requested particle first (72 kB each: 3.6 GB for n = 50 000)."""
    error, peak = peak_bytes(lambda: random_box(n, 0.5e-3, BOX, radius_spread=0.2, seed=3))
    assert peak < 1e6
    capacity = box_capacity(0.5e-3, 0.2, np.array(BOX))
    assert capacity == int(0.384130 * 6 * 6 * 22e-9 / (4 / 3 * np.pi * 0.5e-3**3 * (1 + 0.2**2)))
    assert f"n = {n}: about {capacity} spheres" in str(error) and f"use n <= {capacity}" in str(error)


def test_box_that_jams_below_the_estimate_reports_how_many_fit_in_bounded_memory():
    """Below the estimate but above what fits: the candidates come in blocks (the former 3000 n rows at once were
    36 MB for n = 500), and the message says how many were placed."""
    random_box(5, 0.5e-3, BOX)  # compiled (or loaded from numba's cache) before the memory is traced
    error, peak = peak_bytes(lambda: random_box(500, 0.5e-3, BOX, radius_spread=0.2, seed=3))
    placed = int(re.search(r"only (\d+) spheres fit", str(error)).group(1))
    assert 350 < placed < 500 and f"use n <= {placed}" in str(error)
    assert peak < 8e6


def _addition_by_hand(n, radius, box, spread, seed, speed):
    """Random sequential addition as the generator defines it, in plain Python with every candidate drawn at once."""
    rng = np.random.default_rng(seed)
    lo, hi = np.array(box[0]), np.array(box[1])
    r = rng.uniform(radius * (1 - spread), radius * (1 + spread), n)
    u = rng.random((RSA_CANDIDATES * n, 3))
    pos, trial = [], 0
    for k in range(n):
        while True:
            p = lo + r[k] + u[trial] * (hi - lo - 2 * r[k])
            trial += 1
            if all(np.sum((q - p) ** 2) >= (r[j] + r[k]) ** 2 for j, q in enumerate(pos)):
                pos.append(p)
                break
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    return np.array(pos), r, speed * direction


def test_candidates_in_blocks_place_the_particles_of_one_draw(monkeypatch):
    """Blocks of 64 candidates give the positions, radii and velocities of one draw of all 3000 n candidates, bit for bit: seeded scenes keep their packings."""
    monkeypatch.setattr(generators, "RSA_BLOCK", 64)
    box = [[0.0, 0.0, 0.0], [4e-3, 4e-3, 4e-3]]  # solid fraction 0.17
    layout = random_box(40, 0.4e-3, box, radius_spread=0.2, seed=5, speed=0.1)
    pos, r, v = _addition_by_hand(40, 0.4e-3, box, 0.2, 5, 0.1)
    assert np.array_equal(layout.position, pos) and np.array_equal(layout.radius, r)
    assert np.array_equal(layout.velocity, v)


def test_generated_run_beyond_the_machines_memory_is_refused(monkeypatch):
    monkeypatch.setattr(memory, "available_bytes", lambda: 1.0e9)
    big = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]  # room for them: only the memory refuses
    error, peak = peak_bytes(lambda: random_box(2_000_000, 0.5e-3, big))
    limit = int((1.0e9 - memory.BASE_BYTES) / memory.BYTES_PER_PARTICLE)
    assert "[generator] n: a run of 2000000 particles needs about 2.73 GiB" in str(error)
    assert f"0.931 GiB are available on this machine: use at most about {limit} particles" in str(error)
    assert peak < 1e6


def test_a_small_run_does_not_ask_the_machine(monkeypatch):
    def asked():
        raise AssertionError("available_bytes read")
    monkeypatch.setattr(memory, "available_bytes", asked)
    first_asked = math.ceil(memory.SMALL_BYTES / memory.BYTES_PER_PARTICLE)
    memory.check(first_asked - 1, "particles")  # not refused, /proc/meminfo not read
    with pytest.raises(AssertionError, match="available_bytes read"):
        memory.check(first_asked, "particles")


@pytest.mark.parametrize("n", [50_000, 2_000_000])
def test_cli_box_too_full_one_line(capsys, tmp_path, n):
    path = tmp_path / "scene.toml"
    path.write_text(HOT_WALL.replace("n = 400", f"n = {n}"))
    code, out, err = run_cli(capsys, "run", str(path))
    one_line_error(code, err)
    assert f"[generator] n = {n}: about 558 spheres" in err and "6 x 6 x 22 mm box" in err


def particles_table(centres, radius, temperature) -> str:
    return (f"[particles]\nposition = {centres!r}\nradius = {[radius] * len(centres)!r}\n"
            f"temperature = {[temperature] * len(centres)!r}\n")


def moving_scene(centres) -> str:
    """The hot-wall scene (hot wall at z = 0) with these particles and 1 ms to run."""
    table = particles_table(centres, 0.5e-3, 80.0)
    return re.sub(r"\[generator\].*?temperature = 80.0\n", table, HOT_WALL, flags=re.S).replace("t_end = 0.15",
                                                                                               "t_end = 1e-3")


def static_scene(centres) -> str:
    """A steady column between a hot wall at z = 0 and a cold one at 3.6 mm, out-of-range overlaps clipped."""
    return particles_table(centres, 1.0e-3, 20.0) + """
[material]
conductivity = 394.0
density = 8960.0
specific_heat = 385.0

[[walls]]
name = "hot"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
temperature = 100.0

[[walls]]
name = "cold"
point = [0.0, 0.0, 3.6e-3]
normal = [0.0, 0.0, -1.0]
temperature = 20.0

[conductance]
law = "rojek"
out_of_range = "clip"

[solver]
mode = "steady"
"""


@pytest.mark.parametrize("kind", ["moving", "static"])
def test_particle_behind_a_wall_is_named(capsys, tmp_path, kind):
    """Formerly the moving run said the particle "left the box" (and advised a smaller dt), the static run with
    out_of_range = "clip" bonded it to the hot wall and reported 100 C for it."""
    scene, x = (moving_scene, 3.0e-3) if kind == "moving" else (static_scene, 0.0)
    inside = [[x, x, 0.9e-3], [x, x, 2.7e-3]]
    path = tmp_path / "scene.toml"
    path.write_text(scene(inside + [[x, x, -5.0e-3]]))
    code, out, err = run_cli(capsys, "run", str(path))
    one_line_error(code, err)
    assert "particle 2: its centre [" in err and "-0.005] m lies 0.005 m behind wall 'hot'" in err
    path.write_text(scene(inside))
    code, out, err = run_cli(capsys, "run", str(path))
    assert code == 0, err


def test_a_large_run_says_what_it_will_take_before_it_starts():
    """From a million particles a run states its memory and time up front (the benchmarks' steady solve: 1.35 kB
    and about 7.8e-6 s per particle above 0.23 GB); smaller runs say nothing."""
    from dem import memory

    assert memory.estimate(memory.ANNOUNCE_FROM - 1) is None
    line = memory.estimate(4_096_000)
    assert line == ("4096000 particles: about 5.36 GiB at the peak of a steady solve and about 31.9 s for it on 2 "
                    "cores (a transient or moving run takes longer)")


def test_a_union_run_says_so_from_far_fewer_particles():
    """The union law's cut bodies and cells, and a node per neck, cost tens to hundreds of times the pair-neck
    network per particle: such a run announces itself once its steady solve is estimated at ten seconds."""
    from dem import memory

    small = int(memory.ANNOUNCE_SECONDS / memory.UNION_SECONDS_PER_PARTICLE["necks"]) - 1
    assert memory.estimate(small, "union", "necks") is None and memory.estimate(small, "newton") is None
    assert memory.estimate(small, "union", "particles") is None
    line = memory.estimate(100_000, "union", "necks")
    assert line.endswith("about 90 s for it on 2 cores (a transient or moving run takes longer)")
    assert "about 45 s" in memory.estimate(100_000, "union")


def test_a_neck_node_run_beyond_the_memory_is_refused_with_its_own_figure(monkeypatch):
    """Under the union of spheres a particle takes about 7 kB at the peak (a node per neck a little more), five times
    the pair necks' 1.35 kB: 30 000 particles with a node per neck are refused where 0.4 GB are left, before the bond
    search, with the neck nodes' figure; the same count on pair necks passes."""
    from dem import make_scene
    from dem.engines.static import StaticEngine
    from dem.laws.conductance import ConductanceSpec

    monkeypatch.setattr(memory, "available_bytes", lambda: 0.4e9)
    memory.check(30_000, "particles")  # 0.27 GB on pair necks
    n = 30_000
    x = np.column_stack([np.arange(n) * 3e-3, np.zeros(n), np.zeros(n)])  # apart: no bond, were they searched
    spec = ConductanceSpec(law="shared-body", neck="union", nodes="necks")
    scene = make_scene(x, np.full(n, 1e-3), np.zeros(n), mode="steady", conductance=spec)
    need = memory.BASE_BYTES + memory.UNION_BYTES_PER_PARTICLE["necks"] * n
    with pytest.raises(ValueError, match=rf"particles: a run of 30000 particles needs about {need / 2**30:.3g} GiB "
                                         r"\(about 7.3 kB per particle"):
        StaticEngine(scene)
    assert memory.bytes_per_particle("union") == memory.UNION_BYTES_PER_PARTICLE["particles"]
    assert f"about {need / 2**30:.3g} GiB" in memory.estimate(n, "union", "necks")


def test_neck_node_steps_are_weighed_up_front():
    """An implicit step with a node per neck costs NECK_STEP_COST one-node particle-steps: 2e5 steps of 10 particles
    (2e6 particle-steps, under the 3e6 that max_steps = 1000 allows one node per particle) are refused with neck
    nodes, with the estimate."""
    from dem import make_scene
    from dem.engines import static
    from dem.laws.conductance import ConductanceSpec

    x = np.column_stack([np.arange(10) * 1.9e-3, np.zeros(10), np.zeros(10)])
    spec = ConductanceSpec(law="shared-body", neck="union", nodes="necks")
    scene = make_scene(x, np.full(10, 1e-3), np.zeros(10), mode="transient", integrator="implicit", dt=1e-3,
                       t_end=200.0, max_steps=1000, conductance=spec)
    work = 2e5 * 10 * static.NECK_STEP_COST["union"]
    assert 2e6 < static.WORK_PER_STEP_LIMIT * 1000 < work
    cost = static.NECK_STEP_COST["union"]
    with pytest.raises(ValueError, match=re.escape(f"10 particles x {cost:g} (a node per neck) = {work:.3g} "
                                                   f"particle-steps (about ")):
        static.StaticEngine(scene)


def _apart(n: int):
    """``n`` spheres of 1 mm in a row, apart: no bond, were they searched."""
    return np.column_stack([np.arange(n) * 3e-3, np.zeros(n), np.zeros(n)]), np.full(n, 1e-3)


def test_a_neck_node_run_on_pair_necks_is_refused_with_its_own_figure(monkeypatch):
    """With a node per neck on a pair-neck reading a particle takes about 22 kB at the peak of a static run (the
    elements over the necks' faces), and more through the hand-over of a moving run: 30 000 such particles are
    refused where 0.8 GB are left, before the bond search, static and moving, each with its figure; one node per
    particle on the same necks passes (0.27 GB)."""
    from dem import make_scene, parse_scene
    from dem.engines.static import StaticEngine
    from dem.engines.verlet.engine import VerletEngine
    from dem.laws.conductance import ConductanceSpec
    from test_handover import LUDING

    monkeypatch.setattr(memory, "available_bytes", lambda: 0.8e9)
    n = 30_000
    memory.check(n, "particles", "newton", "particles")
    x, r = _apart(n)
    spec = ConductanceSpec(law="shared-body", nodes="necks")
    need = memory.BASE_BYTES + memory.PAIR_NECK_NODES_BYTES_PER_PARTICLE["static"] * n
    assert need > 0.8e9
    with pytest.raises(ValueError, match=rf"particles: a run of 30000 particles needs about {need / 2**30:.3g} GiB "
                                         r"\(about 21.8 kB per particle at the peak of a steady solve\)"):
        StaticEngine(make_scene(x, r, np.zeros(n), mode="steady", conductance=spec))
    each = memory.PAIR_NECK_NODES_BYTES_PER_PARTICLE["moving"]
    scene = parse_scene({"scene": {"physics": ["mechanical", "thermal"]},
                         "material": {"density": 7800.0, "conductivity": 50.0, "specific_heat": 500.0},
                         "contact": LUDING, "particles": {"position": x.tolist(), "radius": r.tolist(), "temperature": [0.0] * n},
                         "conductance": {"law": "shared-body", "nodes": "necks"},
                         "solver": {"mode": "transient", "t_end": 1e-3}})
    with pytest.raises(ValueError, match=rf"about {each / 1e3:.3g} kB per particle at the peak of a moving run\)"):
        VerletEngine(scene)
    line = memory.estimate(n, "first", "necks", moving=True)
    assert f"about {(memory.BASE_BYTES + each * n) / 2**30:.3g} GiB at the peak of a moving run" in line


def test_neck_node_steps_on_pair_necks_weigh_more_up_front():
    """An implicit step with a node per neck on a pair-neck reading costs NECK_STEP_COST["pair"] (23) one-node
    particle-steps, where the union's 7 would let 2e4 steps of 10 particles (1.4e6) pass under the 3e6 that
    max_steps = 1000 allows: refused, with the estimate."""
    from dem import make_scene
    from dem.engines import static
    from dem.laws.conductance import ConductanceSpec

    x = np.column_stack([np.arange(10) * 1.9e-3, np.zeros(10), np.zeros(10)])
    scene = make_scene(x, np.full(10, 1e-3), np.zeros(10), mode="transient", integrator="implicit", dt=1e-3,
                       t_end=20.0, max_steps=1000, conductance=ConductanceSpec(law="shared-body", nodes="necks"))
    work = 2e4 * 10 * static.NECK_STEP_COST["pair"]
    assert 2e4 * 10 * static.NECK_STEP_COST["union"] < static.WORK_PER_STEP_LIMIT * 1000 < work
    with pytest.raises(ValueError, match=re.escape(f"10 particles x 23 (a node per neck) = {work:.3g} particle-steps")):
        static.StaticEngine(scene)
    assert "about 21 s" in memory.estimate(10_000, "coble", "necks")  # 2.1 ms per particle; one node says nothing
    assert memory.estimate(10_000, "coble") is None
