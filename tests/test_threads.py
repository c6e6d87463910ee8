"""Threads: the velocity-Verlet loop gives the same bits on 1, 2 and 3 threads (its threaded copy sums each
particle's pair forces in the order of the list, as the one-thread loop does: the pairs in its own block directly, the
others from their rows), ``--threads`` is checked, the
environment variable ``SINTERHEAT_THREADS`` is honoured, ``--quiet`` draws no progress bar."""

import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from sinterheat import threads

ROOT = pathlib.Path(__file__).resolve().parents[1]

# In a fresh process (numba's thread pool is sized when it starts): each scene's first steps on 1, 2 and 3 threads
# (3 beyond this machine's 2 cores: the pool is made larger), the threaded copy bound for any size. The state after
# the steps, as lists of the bytes' hex digests. A compiled loop that numba cannot cache (it would be compiled again
# in every process: a minute for the threaded copies) fails the run.
SAME_BITS = """
import hashlib, json, sys, warnings
warnings.filterwarnings("error", message="Cannot cache compiled function")
import numpy as np
from sinterheat import threads
import dem.engines.verlet.mechanics as mechanics
from dem.engines.verlet.engine import VerletEngine
from dem.scene import load_scene

threads.cores = lambda: 3
mechanics.THREADED_MIN_PARTICLES = 0
out = {}
for name, steps in (("hot-wall-sintering", 3000), ("luding-table1", 3000)):
    for number in (1, 2, 3):
        threads.use(number)
        mech = VerletEngine(load_scene(name)).mechanics
        s = mech.state
        T0 = 80.0 + 90.0 * (s.x[:, 2] - s.x[:, 2].min()) / np.ptp(s.x[:, 2])  # 80-170 C: every branch of the law
        mech.advance(steps, T0, np.full(s.n, 200.0))
        arrays = (s.x, s.v, s.w, s.f, s.tau, s.radius, mech.particle_state, mech.p_hist, mech.p_fn, mech.p_ft,
                  mech.w_hist, mech.w_fn, mech.w.q, mech.w.dq)
        out[f"{name} {number}"] = {"threaded": mech.threaded, "rebuilds": mech.rebuilds,
                                   "bits": [hashlib.sha1(np.ascontiguousarray(a).tobytes()).hexdigest()
                                            for a in arrays]}
print(json.dumps(out))
"""


def _env(**extra):
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path, **extra}


@pytest.mark.slow  # three whole runs in a fresh process (~1.5 min); the blocks' tests below are the quick check
def test_one_two_and_three_threads_give_the_same_bits():
    proc = subprocess.run([sys.executable, "-c", SAME_BITS], env=_env(NUMBA_NUM_THREADS="3"), capture_output=True,
                          text=True, timeout=1800)
    assert proc.returncode == 0, proc.stderr[-2000:]
    runs = json.loads(proc.stdout.strip().splitlines()[-1])
    for name in ("hot-wall-sintering", "luding-table1"):
        one, two, three = (runs[f"{name} {k}"] for k in (1, 2, 3))
        assert not one["threaded"] and two["threaded"] and three["threaded"]  # the two loops are compared
        assert one["rebuilds"] > 0  # the pairs by particle were made again along the way
        assert one == {**two, "threaded": False} == {**three, "threaded": False}, name


@pytest.mark.parametrize("n_blocks", [1, 2, 3, 7, 1000])
def test_each_particle_belongs_to_the_block_of_its_first_pair_and_lists_the_others_in_order(n_blocks):
    from dem.engines.contact_forces import pair_blocks, split_incidences

    rng = np.random.default_rng(1)
    n, m = 50, 400
    i = rng.integers(0, n - 1, m)  # particle n - 1 in no pair
    j = (i + rng.integers(1, n - 1, m)) % (n - 1)
    owner, start, pairs = split_incidences(i, j, n, n_blocks)
    blocks = pair_blocks(m, n_blocks)
    block = np.repeat(np.arange(blocks), np.diff([b * m // blocks for b in range(blocks + 1)]))
    assert owner[n - 1] == -1 and start[n] - start[n - 1] == 0
    for k in range(n - 1):
        mine = np.flatnonzero((i == k) | (j == k))  # k's pairs in the order of the list
        assert owner[k] == block[mine[0]]
        listed = pairs[start[k]:start[k + 1]]
        later = mine[block[mine] != owner[k]]
        assert np.array_equal(np.where(listed >= 0, listed, ~listed), later)  # the others, in order
        assert np.array_equal(listed >= 0, i[later] == k)  # c where k is the pair's i, ~c where its j
        assert np.all(block[later] > owner[k])  # a particle's own block comes first in the list
    if blocks == 1:
        assert len(pairs) == 0


@pytest.mark.parametrize("value", ["0", str(threads.cores() + 1), "two", "-1"])
@pytest.mark.slow
def test_a_thread_count_outside_the_cores_is_one_line_and_exit_2(value):
    proc = subprocess.run([sys.executable, "-m", "dem", "run", "lattice", "--threads", value], env=_env(),
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    shown = repr(value) if value == "two" else value
    assert f"--threads: threads = {shown}: must be" in proc.stderr and f"from 1 to {threads.cores()}" in proc.stderr


@pytest.mark.slow
def test_a_bad_environment_variable_is_refused_naming_it():
    proc = subprocess.run([sys.executable, "-m", "dem", "run", "lattice"], env=_env(SINTERHEAT_THREADS="0"),
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "SINTERHEAT_THREADS = 0: must be from 1 to" in proc.stderr


def test_the_environment_variable_sets_the_count_and_the_option_wins(monkeypatch):
    monkeypatch.setattr(threads, "_chosen", None)
    monkeypatch.setenv(threads.ENVIRONMENT, "1")
    assert threads.count() == 1
    monkeypatch.delenv(threads.ENVIRONMENT)
    assert threads.count() == threads.cores()
    monkeypatch.setenv(threads.ENVIRONMENT, str(threads.cores() + 1))
    with pytest.raises(ValueError, match="SINTERHEAT_THREADS"):
        threads.count()
    monkeypatch.setenv(threads.ENVIRONMENT, "1")
    for variable in threads.BLAS_VARIABLES:
        monkeypatch.delenv(variable, raising=False)  # restored after the test
    threads.use(threads.cores())  # the option wins over the environment, which child processes then inherit
    assert threads.count() == threads.cores()
    assert os.environ[threads.ENVIRONMENT] == os.environ["OPENBLAS_NUM_THREADS"] == str(threads.cores())


# A command run by sinterheat.startup.run_main: its BLAS thread counts, and the threads of its process, after numpy
PROBE = """
import json, os, sys
import numpy, threadpoolctl

def main():
    tasks = len(os.listdir("/proc/self/task")) if os.path.isdir("/proc/self/task") else None
    counts = [i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"]
    print(json.dumps({"blas": counts, "tasks": tasks}))
    return 0
"""


@pytest.mark.parametrize("command, user, blas", [("fit", None, 1), ("solve", None, threads.cores()),
                                                 ("fit", "2", 2)])
def test_a_one_blas_thread_command_never_starts_the_blas_thread_pools(tmp_path, command, user, blas):
    (tmp_path / "probe_cli.py").write_text(PROBE)
    code = ("import sys; from sinterheat.startup import run_main; "
            "run_main('python -m probe', 'probe_cli', one_blas_thread=('fit',))")
    env = {k: v for k, v in _env().items() if k not in threads.BLAS_VARIABLES}
    env["PYTHONPATH"] += os.pathsep + str(tmp_path)
    if user is not None:  # the user's own setting is kept
        env["OPENBLAS_NUM_THREADS"] = user
    proc = subprocess.run([sys.executable, "-c", code, command, "--json"], env=env, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    seen = json.loads(proc.stdout)
    assert seen["blas"] and set(seen["blas"]) == {blas}
    if seen["tasks"] is not None and blas == 1:
        assert seen["tasks"] == 1  # no BLAS thread was started, not merely limited afterwards


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
@pytest.mark.skipif(threads.cores() < 2, reason="needs two cores")
def test_the_engine_binds_its_loop_by_the_thread_count(monkeypatch):
    import dem.engines.verlet.mechanics as mechanics
    from dem.engines.verlet.engine import VerletEngine
    from dem.scene import load_scene

    monkeypatch.setattr(threads, "_chosen", None)
    monkeypatch.setattr(mechanics, "THREADED_MIN_PARTICLES", 0)
    scene = load_scene("luding-three-particles")
    for value, threaded in (("1", False), ("2", True)):
        monkeypatch.setenv(threads.ENVIRONMENT, value)
        assert VerletEngine(scene).mechanics.threaded is threaded
    monkeypatch.setattr(mechanics, "THREADED_MIN_PARTICLES", 10)  # three particles: too few to share
    assert VerletEngine(scene).mechanics.threaded is False


def quick_moving_scene() -> str:
    """The built-in hot-wall-sintering scene (a moving run with its thermal network) cut to 0.04 s: about 6 s of
    steps on a quiet machine, so that the progress bar (drawn after 2 s) shows (at 0.02 s the run ended in 1.7 s)."""
    text = (ROOT / "dem" / "scene" / "builtin" / "hot-wall-sintering.toml").read_text()
    assert "t_end = 0.15\n" in text
    return text.replace("t_end = 0.15\n", "t_end = 0.04\n")


@pytest.mark.slow  # two moving runs of over 2 s each (the bar waits 2 s)
def test_quiet_prints_the_result_and_no_progress_bar(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(quick_moving_scene())
    runs = {}
    for quiet in (False, True):
        argv = [sys.executable, "-m", "dem", "run", str(scene), "--json"] + (["--quiet"] if quiet else [])
        runs[quiet] = subprocess.run(argv, env=_env(), capture_output=True, text=True, timeout=600)
        assert runs[quiet].returncode == 0, runs[quiet].stderr[-2000:]
    loud, quiet = runs[False], runs[True]
    assert "s simulated" in loud.stderr  # the bar, drawn after 2 s
    assert quiet.stderr == ""
    timeless = [{k: v for k, v in json.loads(r.stdout).items() if k != "seconds"} for r in (quiet, loud)]
    assert timeless[0] == timeless[1]


def test_a_user_cap_on_numbas_threads_is_the_default_and_the_bound():
    """With ``NUMBA_NUM_THREADS=1`` (numba's pool made with one thread) an engine's binding asks for one thread
    instead of every core (numba raised at its bind before), and ``--threads 2`` is refused naming the cap."""
    code = ("from sinterheat import threads\nprint(threads.bind_numba())\n"
            "try:\n    threads.check(2)\nexcept ValueError as error:\n    print(error)")
    env = {key: value for key, value in os.environ.items() if key != threads.ENVIRONMENT}  # set by an earlier use()
    out = subprocess.run([sys.executable, "-c", code], env={**env, "NUMBA_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)},
                         capture_output=True, text=True, check=True).stdout.splitlines()
    assert out == ["1", "threads = 2: must be from 1 to 1 (the cores this process may use)"]
