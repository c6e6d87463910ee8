"""Ctrl-C (sinterheat.interrupt): a real SIGINT at random moments ends every CLI with one line on stderr, exit code 130,
no traceback, and partial results that can be used."""

import json
import os
import pathlib
import random
import re
import signal
import subprocess
import sys
import threading
import time

import pytest

from sinterheat import interrupt
from fem_neck.fit import read_points, reusable_points

ROOT = pathlib.Path(__file__).resolve().parents[1]
LINE = re.compile(r"^python -m (fem_neck|dem|verification) [\w-]+: interrupted at (?P<at>.+); "
                  r"(partial results in (?P<out>.+)|no results written)$")
FIT = ["fem_neck", "fit", "--points", "200", "--rtol", "1e-8", "--out", "fit", "--json"]  # ~1 min of work


@pytest.fixture(autouse=True)
def _handlers_restored():
    """Every signal a run handles (SIGINT, SIGTERM, SIGHUP) has its handler back after each test: an interrupted
    command ignores them all until it exits, and a SIGTERM left ignored in this process would be inherited by every
    process a later test starts."""
    before = {signum: signal.getsignal(signum) for signum in interrupt.SIGNALS}
    yield
    for signum, handler in before.items():
        signal.signal(signum, handler)


def _start(args, cwd):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def _interrupted(proc) -> re.Match:
    """Exit code 130, nothing on stdout, no traceback; besides progress bars stderr holds one line, the last."""
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert out == "" and "Traceback" not in err and "KeyboardInterrupt" not in err, err
    lines = err.rstrip("\n").split("\n")
    text = [line for line in lines if line and "%|" not in line]  # tqdm bars hold "NN%|"
    assert len(text) == 1 and text[0] == lines[-1], err  # a line of its own: no bar in front of it
    match = LINE.match(text[0])
    assert match, err
    return match  # before the arguments are parsed "where" is "start-up"


def _fit_usable(tmp_path, match):
    """The sweep's partial fit.csv holds at least the solves the line counts, and a rerun would reuse them all."""
    done = re.search(r"(\d+) of 200 solves done", match["at"])
    csv = tmp_path / "fit" / "fit.csv"
    if match["out"] is None:
        assert done is None or done[1] == "0"
        assert not read_points(csv)
        return 0
    assert pathlib.Path(tmp_path, match["out"]).resolve() == csv.parent.resolve()
    rows = read_points(csv)
    assert len(rows) >= int(done[1]) and len(reusable_points(csv, 1e-8)[0]) == len(rows)
    return len(rows)


def _wait_for_rows(csv, rows, timeout=90.0):
    deadline = time.perf_counter() + timeout
    while time.perf_counter() < deadline and not (csv.exists() and csv.read_text().count("\n") > rows):
        time.sleep(0.02)


@pytest.mark.slow
def test_fit_sweep_interrupted_at_random_moments(tmp_path):
    # three sweeps (pool of 2 workers each): interrupted at random in start-up and imports, and at a random moment
    # after the sweep has written its first points (a machine's load shifts the phases, so that one waits for them)
    rng = random.Random(7)
    runs = []
    for k in range(3):
        (tmp_path / str(k)).mkdir()
        runs.append(_start(FIT, tmp_path / str(k)))
    t0 = time.perf_counter()
    for k, proc in enumerate(runs[:2]):
        time.sleep(max(0.0, rng.uniform(0.3, 1.0) + k - (time.perf_counter() - t0)))
        proc.send_signal(signal.SIGINT)
    _wait_for_rows(tmp_path / "2" / "fit" / "fit.csv", 2)
    time.sleep(rng.uniform(0.0, 0.5))
    runs[2].send_signal(signal.SIGINT)
    for k, proc in enumerate(runs):
        match = _interrupted(proc)
        rows = _fit_usable(tmp_path / str(k), match)
        print(match[0], "| rows:", rows)  # shown with pytest -s
    assert rows >= 2


@pytest.mark.slow
def test_cluster_interrupted_names_the_mesh_level(tmp_path):
    (tmp_path / "c.json").write_text(json.dumps({
        "centres": [[0, 0, 0], [0, 0, 1.93e-3], [0, 0, 3.86e-3]], "radii": [1e-3] * 3, "bonds": [[0, 1], [1, 2]],
        "terminals": [{"particle": 0, "T": 1.0}, {"particle": 2, "T": 0.0}]}))
    proc = _start(["fem_neck", "cluster", "c.json", "--size-far", "0.15", "--json"], tmp_path)
    time.sleep(random.Random(3).uniform(1.0, 3.0))
    proc.send_signal(signal.SIGINT)
    match = _interrupted(proc)
    assert match["out"] is None and re.search(r"cluster(, mesh level [123] of 3)?$", match["at"]), match[0]


@pytest.mark.slow
def test_verification_interrupted_keeps_the_finished_sections(tmp_path):
    proc = _start(["verification", "all", "--quick", "--out", "v", "--no-progress"], tmp_path)
    run_json = tmp_path / "v" / "run.json"
    deadline = time.perf_counter() + 90
    while time.perf_counter() < deadline:  # until the paper section has finished, then up to 1 s later
        sections = json.loads(run_json.read_text())["sections"] if run_json.exists() else {}
        if sections.get("paper", {}).get("status") == "ok":  # written as "running" when it starts
            break
        time.sleep(0.05)
    time.sleep(random.Random(5).uniform(0.0, 1.0))
    proc.send_signal(signal.SIGINT)
    match = _interrupted(proc)
    assert re.match(r"section (chains|clusters), 1 of 5 sections done", match["at"]) and match["out"] == "v"
    sections = json.loads(run_json.read_text())["sections"]
    assert sections["paper"]["status"] == "ok" and list(sections.values())[-1]["status"] == "interrupted"
    summary = json.loads((tmp_path / "v" / "summary.json").read_text())
    assert any(key.startswith("paper.") for key in summary)
    report = (tmp_path / "v" / "report.md").read_text()
    assert "Paper reproduction" in report and "interrupted (Ctrl-C)" in report


@pytest.mark.slow
def test_gmsh_is_finalized_and_the_handler_restored_in_process(tmp_path, capsys):
    # main() called in this process: an interrupt during the cluster's meshing leaves no gmsh session open
    gmsh = pytest.importorskip("gmsh")
    from fem_neck.cli import main

    (tmp_path / "c.json").write_text(json.dumps({
        "centres": [[0, 0, 0], [0, 0, 1.93e-3]], "radii": [1e-3] * 2, "bonds": [[0, 1]],
        "terminals": [{"particle": 0, "T": 1.0}, {"particle": 1, "T": 0.0}]}))
    before = signal.getsignal(signal.SIGINT)
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        code = main(["cluster", str(tmp_path / "c.json"), "--size-far", "0.12", "--levels", "1"])
    finally:
        timer.join()
        signal.signal(signal.SIGINT, before)  # after an interrupt the CLI ignores further ones until exit
    assert code == 130 and not gmsh.isInitialized()
    err = capsys.readouterr().err
    assert err.startswith("python -m fem_neck cluster: interrupted at cluster") and err.count("\n") == 1
    # without an interrupt the previous handler is back after main()
    assert main(["neck", "--ri", "1e-3", "--rj", "1e-3", "--h", "1e-4", "--json"]) == 0
    assert signal.getsignal(signal.SIGINT) is before


def test_an_interrupt_swallowed_in_a_destructor_ends_the_run_at_the_next_update(capsys):
    # Python only reports a KeyboardInterrupt raised in a destructor as "ignored": the run still stops, in one line
    class Collected:
        def __del__(self):
            signal.raise_signal(signal.SIGINT)  # the Ctrl-C lands here

    after = []

    def body():
        Collected()
        after.append("update reached")
        interrupt.where().update(stage="after the destructor")
        after.append("went on")
        return 0

    before = signal.getsignal(signal.SIGINT)
    try:
        code = interrupt.run_command(interrupt.Where("python -m dem run"), body)
    finally:
        signal.signal(signal.SIGINT, before)
    assert code == interrupt.EXIT_CODE and after == ["update reached"]
    assert capsys.readouterr().err == ("python -m dem run: interrupted at after the destructor; "
                                       "no results written\n")


def test_shielded_holds_back_a_ctrl_c_that_another_thread_receives():
    # the kernel gives a SIGINT sent to the process to a thread that does not block it (here a waiting thread, in a
    # CLI tqdm's monitor or BLAS threads), and the main thread then runs the Python handler: inside the block that
    # would interrupt a pool between forking a worker and recording it, and the worker would outlive the run
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    here, reached = interrupt.Where("python -m fem_neck fit"), []
    before = signal.getsignal(signal.SIGINT)
    try:
        with pytest.raises(KeyboardInterrupt):
            with interrupt.interruptible(here):
                with interrupt.shielded():
                    os.kill(os.getpid(), signal.SIGINT)
                    for _ in range(50):
                        time.sleep(0.002)  # a call: where the handler would raise
                    reached.append("end of the block")
                reached.append("after the block")
    finally:
        stop.set()
        other.join()
        signal.signal(signal.SIGINT, before)
    assert reached == ["end of the block"] and here.signalled


def test_where_message():
    here = interrupt.Where("python -m dem run")
    assert here.message() == "python -m dem run: interrupted at start-up; no results written"
    here.update(stage="transient", step=1200, t=0.0125, out=pathlib.Path("out"))
    assert here.message() == ("python -m dem run: interrupted at transient, step 1200, t = 0.0125 s; "
                              "partial results in out")
    with pytest.raises(TypeError, match="unknown field"):
        here.update(time=1.0)
    assert interrupt.where() is not interrupt.where()  # outside a run: throw-away objects
