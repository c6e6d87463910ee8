"""sinterheat.pool: the sweeps' independent jobs on local processes or a Dask cluster give the same results; Dask is
optional (without it --scheduler is one line saying how to install it); Ctrl-C on a Dask run is one line, exit 130."""

import json
import os
import pathlib
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from benchmarks.timing import worker_sweep
from fem_neck.fit import sweep, sweep_points
from sinterheat import pool as P
from verification.luding import runs as sr

ROOT = pathlib.Path(__file__).resolve().parents[1]
# a chain of stages (prepare, sinter, cool, vibrate: each starts from its parent's state) and a three-particle
# schedule: the grid in small
TASKS = [sr.Task(sr.VIBRATE, 12, 10.0, 1e-4), sr.Task(sr.SCHEDULE, 3, 10.0, 1e-4)]
TIMINGS = ("seconds", "ns_per_particle_step")  # wall time: the only fields of result.json that may differ


def _untimed(result: dict) -> dict:
    return {k: v for k, v in result.items() if k not in TIMINGS}


def _failing(x):
    if x == 3:
        raise ArithmeticError(f"job {x} fails")
    return x * x


class _Section:
    """What worker_sweep writes into: the CSV rows, in the order written."""

    def __init__(self):
        self.written = []

    def csv(self, name, rows):
        self.written.append([dict(r) for r in rows])


# ------------------------------------------------------------------------------------------------ without Dask
@pytest.mark.parametrize("workers", [1, 2])
@pytest.mark.slow
def test_local_jobs_come_back_complete_and_an_error_is_raised(workers):
    jobs = [(abs, (-k,)) for k in range(7)]
    assert sorted(P.run_jobs(jobs, workers, progress=False)) == list(range(7))
    with pytest.raises(ArithmeticError, match="job 3 fails"):
        list(P.run_jobs([(_failing, (k,)) for k in range(5)], workers, progress=False))


def _pid_of(k):
    return k, os.getpid()


@pytest.mark.slow
def test_jobs_alongside_a_pool_of_the_callers_run_there_and_here_and_it_stays_usable():
    """With a pool of the caller's alongside (one process) and two workers, the jobs run in that pool's process and
    in this one, no other process is started, every result comes back once; an error is raised; the caller's pool
    still takes jobs afterwards."""
    with P.ProcessPool(1, "fork") as helper:
        first = helper.submit(os.getpid).result()
        results = list(P.run_jobs([(_pid_of, (k,)) for k in range(40)], 2, progress=False, alongside=helper))
        assert sorted(k for k, _ in results) == list(range(40))
        assert {pid for _, pid in results} == {first, os.getpid()}
        with pytest.raises(ArithmeticError, match="job 3 fails"):
            list(P.run_jobs([(_failing, (k,)) for k in range(5)], 2, progress=False, alongside=helper))
        assert helper.submit(os.getpid).result() == first
        assert [pid for _, pid in P.run_jobs([(_pid_of, (0,))], 2, progress=False, alongside=helper)] == [os.getpid()]


@pytest.mark.parametrize("environment, progress, shown", [("", True, True), ("1", True, False), ("", False, False)])
def test_the_bar_follows_no_progress_of_the_command_line(monkeypatch, capsys, environment, progress, shown):
    """--no-progress sets TQDM_DISABLE; a sweep's own bar (progress left at its default) must then stay silent."""
    monkeypatch.setenv("TQDM_DISABLE", environment)
    assert sorted(P.run_jobs([(abs, (-k,)) for k in range(3)], 1, desc="sweep", progress=progress)) == [0, 1, 2]
    assert ("sweep" in capsys.readouterr().err) == shown


def _gone(pid: int) -> bool:
    """The process has ended (no longer listed, or a zombie waiting to be reaped)."""
    try:
        return pathlib.Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] == "Z"
    except OSError:
        return True


ORPHANS = {"pool": """
import os, sys, time
from sinterheat.pool import pool
with pool(2, start=sys.argv[1]) as jobs:
    pids = {jobs.submit(os.getpid).result() for _ in range(20)}
    waiting = [jobs.submit(time.sleep, 120) for _ in range(2)]
    print(*sorted(pids), flush=True)
    time.sleep(120)
""", "lattice": """
import os, sys, time
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context
from fem_neck.lattice import bounds
context = get_context(sys.argv[1])
queue = context.Queue()  # the lower bound's process, as fem_neck.lattice.bounds.solve_bounds starts it
with ProcessPoolExecutor(1, mp_context=context, initializer=bounds._receive_temperatures,
                         initargs=(queue, None)) as one:
    pid = one.submit(os.getpid).result()
    waiting = one.submit(time.sleep, 120)
    print(pid, flush=True)
    time.sleep(120)
"""}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("script, start", [("pool", "fork"), ("pool", "spawn"), ("lattice", "fork")])
@pytest.mark.slow
def test_workers_end_with_a_parent_killed_outright(script, start):
    # a SIGKILL (the OOM killer) gives the parent no chance to stop its pool: the workers must not wait for ever
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    parent = subprocess.Popen([sys.executable, "-c", ORPHANS[script], start], stdout=subprocess.PIPE, text=True,
                              env=env, stderr=subprocess.DEVNULL)  # a killed spawner's resource tracker reports
    try:
        pids = [int(x) for x in parent.stdout.readline().split()]
        assert pids and all(not _gone(pid) for pid in pids)
    finally:
        parent.kill()
        parent.wait()
    deadline = time.perf_counter() + 20.0
    while time.perf_counter() < deadline and not all(_gone(pid) for pid in pids):
        time.sleep(0.05)
    assert all(_gone(pid) for pid in pids), [pid for pid in pids if not _gone(pid)]


@pytest.mark.slow
def test_a_process_whose_numba_threads_are_openmp_spawns_its_workers(monkeypatch):
    # a child forked from a process that ran GNU OpenMP threads is terminated at its own first parallel loop
    monkeypatch.setattr(P, "openmp_started", lambda: True)
    with P.pool(2) as spawned:
        assert spawned._executor._mp_context.get_start_method() == "spawn"
        assert [f.result() for f in [spawned.submit(_failing, 2)]] == [4]
    monkeypatch.setattr(P, "openmp_started", lambda: False)
    with P.pool(2) as forked:
        assert forked._executor._mp_context.get_start_method() == "fork"


OPENMP_STARTED = """
import numba, numpy as np
from sinterheat import threads
threads.use(2)
before = threads.openmp_started()
threads.bind_numba()
@numba.njit(parallel=True)
def twice(a):
    for k in numba.prange(len(a)):
        a[k] *= 2.0
twice(np.ones(8))
print(before, threads.openmp_started(), numba.threading_layer())
"""


@pytest.mark.skipif(os.cpu_count() < 2, reason="needs two cores")
@pytest.mark.slow
def test_openmp_is_seen_once_numba_has_started_its_threads():
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_THREADING_LAYER"}
    proc = subprocess.run([sys.executable, "-c", OPENMP_STARTED], capture_output=True, text=True, timeout=300,
                          env={**env, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stderr[-2000:]
    before, after, layer = proc.stdout.split()
    assert before == "False" and after == str(layer == "omp") and layer in ("omp", "workqueue")


def test_one_worker_runs_each_job_when_its_result_is_taken():
    ran = []
    jobs = [(ran.append, (k,)) for k in range(3)]
    results = P.run_jobs(jobs, 1, progress=False)
    next(results)
    assert ran == [0]  # in this process, one at a time: results are written as they come
    results.close()
    assert ran == [0]


def _exit_code(main, argv) -> int:
    try:
        return main(argv)
    except SystemExit as stop:  # argparse's refusal
        return stop.code


def test_scheduler_without_dask_says_how_to_install_it(monkeypatch, capsys):
    from fem_neck.cli import main

    monkeypatch.setattr(P, "dask_available", lambda: False)
    assert _exit_code(main, ["fit", "--scheduler", "local", "--out", "nowhere"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Dask is not installed" in err and "pip install '.[dask]'" in err, err
    with pytest.raises(ValueError, match="Dask is not installed"):
        P.check_scheduler("tcp://host:8786")


def test_without_scheduler_dask_is_not_imported():
    code = ("import sys; from fem_neck.fit import run_fit; run_fit(8, 1e-4, workers=2, progress=False); "
            "print('distributed' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         env={**os.environ, "PYTHONPATH": str(ROOT)}).stdout
    assert out.strip() == "False"


# ------------------------------------------------------------------------------------------------ through Dask
SIZES_WORKER = """import json
def work(n):
    if n > 2000:
        raise SystemExit('too big')
    print(json.dumps({'particles': n, 'square': n * n}))
"""


@pytest.fixture(scope="module")
def sizes_worker(tmp_path_factory):
    """``PYTHONPATH`` for the module's tests (and the processes they start) finds the module ``sizes_worker``."""
    folder = tmp_path_factory.mktemp("modules")
    (folder / "sizes_worker.py").write_text(SIZES_WORKER)
    with pytest.MonkeyPatch.context() as env:
        env.setenv("PYTHONPATH", os.pathsep.join([str(folder), str(ROOT)]))
        yield


@pytest.fixture(scope="module")
def dask_client(sizes_worker):
    """A LocalCluster of two one-thread workers (which find ``sizes_worker``)."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=":0",
                                  scheduler_kwargs={"dashboard": False}) as cluster, \
            distributed.Client(cluster) as client:
        yield client


@pytest.mark.slow
def test_fit_sweep_on_dask_equals_the_local_pool(dask_client):
    x, uniform = sweep_points(16)
    with P.use_dask(dask_client):
        on_dask = sweep(x, uniform, 1e-4, progress=False)
    local = sweep(x, uniform, 1e-4, workers=2, progress=False)
    assert [p.a_over_r for p in on_dask] == [p.a_over_r for p in local] == sorted(x)
    assert [p.K_over_Kcyl for p in on_dask] == [p.K_over_Kcyl for p in local]
    assert [p.error_estimate for p in on_dask] == [p.error_estimate for p in local]


@pytest.mark.slow  # sintering runs on a local Dask cluster, one of them resumed
def test_sintering_runs_on_dask_equal_the_local_pool_and_resume(dask_client, tmp_path):
    with P.use_dask(dask_client):
        on_dask = sr.run_tasks(TASKS, tmp_path / "dask", progress=False)
    local = sr.run_tasks(TASKS, tmp_path / "local", workers=2, progress=False)
    assert set(on_dask) == set(local) and len(local) == 5  # the two tasks and the chain they start from
    for task in local:
        a = json.loads((tmp_path / "dask" / task.folder / "result.json").read_text())
        b = json.loads((tmp_path / "local" / task.folder / "result.json").read_text())
        assert "error" not in a and _untimed(a) == _untimed(b), task.folder
        with np.load(tmp_path / "dask" / task.folder / "analysis.npz") as fa, \
                np.load(tmp_path / "local" / task.folder / "analysis.npz") as fb:
            assert sorted(fa.files) == sorted(fb.files)
            for name in fa.files:
                np.testing.assert_array_equal(fa[name], fb[name], err_msg=f"{task.folder}: {name}")
    # resumed where it stopped: a finished run is not run again, a run without result.json is
    stamps = {t: (tmp_path / "dask" / t.folder / "result.json").stat().st_mtime_ns for t in local}
    redo = sr.Task(sr.VIBRATE, 12, 10.0, 1e-4)
    (tmp_path / "dask" / redo.folder / "result.json").unlink()
    with P.use_dask(dask_client):
        again = sr.run_tasks(TASKS, tmp_path / "dask", progress=False)
    assert _untimed(again[redo]) == _untimed(on_dask[redo]) and again.keys() == on_dask.keys()
    for task, stamp in stamps.items():
        changed = (tmp_path / "dask" / task.folder / "result.json").stat().st_mtime_ns != stamp
        assert changed == (task == redo), task.folder


@pytest.mark.parametrize("prog", ["verification", "fem_neck", "benchmarks"])
@pytest.mark.slow
def test_a_scheduler_out_of_reach_is_one_line_and_exit_2(prog, monkeypatch, capsys, tmp_path):
    pytest.importorskip("distributed")
    from benchmarks.cli import main as benchmarks_main
    from fem_neck.cli import main as fem_main
    from verification.cli import main as verification_main

    monkeypatch.setattr(P, "CONNECT_TIMEOUT", 1.0)
    main, command = {"verification": (verification_main, "sintering"), "fem_neck": (fem_main, "fit"),
                     "benchmarks": (benchmarks_main, "neck")}[prog]
    assert _exit_code(main, [command, "--scheduler", "tcp://127.0.0.1:9", "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    prefix = f"python -m {prog}" + ("" if prog == "benchmarks" else f" {command}")
    assert err.count("\n") == 1 and err.startswith(f"{prefix}: error: scheduler tcp://127.0.0.1:9: cannot connect"), err


@pytest.mark.parametrize("on_dask", [False, True])
@pytest.mark.slow
def test_size_sweep_keeps_the_sizes_up_to_the_first_failure(sizes_worker, request, on_dask):
    section = _Section()
    with P.use_dask(request.getfixturevalue("dask_client") if on_dask else None):
        rows = worker_sweep(section, "sizes", "sizes_worker", "work", (1000, 2000, 3000, 4000), 60,
                            stop_at_error=True)
    assert [r["particles"] for r in rows] == [1000, 2000, 3000] and "too big" in rows[-1]["error"]
    assert rows[:2] == [{"particles": 1000, "square": 10**6}, {"particles": 2000, "square": 4 * 10**6}]
    assert section.written[-1] == rows  # the CSV holds the rows in order of size
    if not on_dask:  # one after another here: each row written as it comes, nothing run after the failure
        assert [len(w) for w in section.written] == [1, 2, 3]


@pytest.mark.slow  # a Dask cluster started and interrupted in a fresh process
def test_interrupted_dask_run_is_one_line_and_exit_130(tmp_path):
    pytest.importorskip("distributed")
    args = ["fem_neck", "fit", "--points", "200", "--rtol", "1e-8", "--scheduler", "local", "--workers", "2",
            "--out", "fit", "--json"]
    proc = subprocess.Popen([sys.executable, "-m", *args], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)},
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    csv = tmp_path / "fit" / "fit.csv"
    deadline = time.perf_counter() + 120
    while time.perf_counter() < deadline and not (csv.exists() and csv.read_text().count("\n") > 3):
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    lines = [line for line in err.rstrip("\n").split("\n") if line and "%|" not in line]
    assert proc.returncode == 130 and out == "" and "Traceback" not in err, err
    assert len(lines) == 1 and lines[0].startswith("python -m fem_neck fit: interrupted at fit, fit sweep: "), err
    assert lines[0].endswith(f"solves done; partial results in {pathlib.Path('fit')}"), err
