"""SIGTERM (a batch scheduler's time limit) and SIGHUP (a closed terminal) are handled as Ctrl-C is: one line, exit
code 128 + the signal, the last completed step checkpointed (also before the first periodic checkpoint, which the run
had not written: 8 s of work were lost), and ``--resume`` ends where the uninterrupted run ends. Before, SIGTERM
killed the run with exit 143, no message and nothing to resume."""

from __future__ import annotations

import json
import os
import pathlib
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from dem import load_scene, run
from test_dem_resume import THERMAL

ROOT = pathlib.Path(__file__).resolve().parents[1]
NO_PERIODIC = THERMAL.replace("checkpoint_every = 0.2", "checkpoint_every = 3600.0")  # only the signal's checkpoint


def start(args, cwd):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    return subprocess.Popen([sys.executable, "-m", *args], cwd=cwd, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def loaded(pid: int, name: str) -> bool:
    """Whether process ``pid`` has a shared object ``name`` mapped (Linux: /proc/PID/maps); True once it is gone."""
    try:
        return name in pathlib.Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return True


def one_line(err: str) -> str:
    lines = [line for line in err.split("\n") if line.strip() and "%|" not in line]  # besides progress bars
    assert "Traceback" not in err and len(lines) == 1, err
    return lines[0]


@pytest.mark.parametrize("signum", [signal.SIGTERM, pytest.param(signal.SIGHUP, marks=pytest.mark.slow)],
                         ids=["SIGTERM", "SIGHUP"])
def test_signal_before_the_first_checkpoint_then_resume(tmp_path, signum):
    scene = tmp_path / "scene.toml"
    scene.write_text(NO_PERIODIC)
    part = tmp_path / "part"
    proc = start(["dem", "run", str(scene), "--out", str(part), "--quiet"], tmp_path)
    rows = part / "timeseries.csv"
    deadline = time.monotonic() + 120
    while proc.poll() is None and time.monotonic() < deadline and not (rows.exists() and
                                                                      rows.read_text().count("\n") > 20):
        time.sleep(0.02)
    proc.send_signal(signum)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the run finished before the signal reached it")
    name = signal.Signals(signum).name
    assert proc.returncode == 128 + signum, err
    assert re.match(rf"python -m dem run: interrupted by {name} at dem run scene, step \d+, t = .*; partial results "
                    rf"in .*part$", one_line(err)), err
    summary = json.loads((part / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["resume_from"]["steps"] > 0
    resumed = run(load_scene(scene), out=part, resume=True)
    whole = run(load_scene(scene), out=tmp_path / "whole")
    assert resumed.summary["resumed_from"]["steps"] == summary["resume_from"]["steps"]
    assert np.array_equal(resumed.T, whole.T)
    assert (part / "timeseries.csv").read_text() == (tmp_path / "whole" / "timeseries.csv").read_text()


@pytest.mark.parametrize("when", ["building", "stepping"])
@pytest.mark.slow
def test_a_signal_before_the_first_step_then_resume_starts_the_run(tmp_path, monkeypatch, when):
    """A signal while the run builds its engine (SIGTERM 3 s into hot-wall-sintering: numba's kernels loading) left
    an empty folder, or, once its first files were written, one whose summary said interrupted with no checkpoint;
    either way --resume refused it ("holds no checkpoint"), and a scheduler's requeue with --resume failed. Now
    --resume of such a folder runs the scene from its beginning and ends where the uninterrupted run ends."""
    import dem.driver

    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(NO_PERIODIC.replace("t_end = 0.01", "t_end = 0.001"))
    scene = load_scene(scene_file)
    part = tmp_path / "part"
    built = dem.driver.engine_class(scene.engine)

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    if when == "building":
        monkeypatch.setattr(built, "__init__", interrupted)
    else:
        monkeypatch.setattr(built, "run", interrupted)
    with pytest.raises(KeyboardInterrupt):
        run(scene, out=part)
    monkeypatch.undo()
    summary = json.loads((part / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["resume_from"] is None
    assert not (part / "run.lock").exists() and not (part / "checkpoint.npz").exists()
    resumed = run(load_scene(scene_file), out=part, resume=True)
    whole = run(load_scene(scene_file), out=tmp_path / "whole")
    assert "resumed_from" not in resumed.summary and np.array_equal(resumed.T, whole.T)
    for name in ("timeseries.csv", "particles.pvd"):
        assert (part / name).read_text() == (tmp_path / "whole" / name).read_text(), name
    with pytest.raises(ValueError, match="holds a finished run"):
        run(load_scene(scene_file), out=part, resume=True)

@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_signal_while_the_package_imports_is_one_line(tmp_path, signum):
    """``python -m dem`` imports the package ``dem`` (numpy, scipy, ...) before its ``__main__`` runs: a Ctrl-C
    there was a KeyboardInterrupt traceback from an import, a SIGTERM a silent kill. Now the package's first
    statement holds both: one line, exit 128 + the signal. The signal is sent once numpy's core is loaded, in the
    middle of the package's imports."""
    proc = start(["dem", "run", "pair", "--quiet"], tmp_path)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and not loaded(proc.pid, "_multiarray_umath"):
        time.sleep(0.001)
    proc.send_signal(signum)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signum and out == "", err
    by = "" if signum == signal.SIGINT else " by SIGTERM"
    assert re.match(rf"python -m dem run: interrupted{by} at .*; no results written$", one_line(err)), err


def test_nohup_keeps_sighup_ignored():
    """A run started under nohup (SIGHUP ignored) is not interrupted by a hang-up."""
    from sinterheat import interrupt

    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        here = interrupt.Where("test")
        with interrupt.interruptible(here):
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            assert signal.getsignal(signal.SIGTERM) is interrupt._raise_once
        assert signal.getsignal(signal.SIGTERM) is not interrupt._raise_once  # restored
    finally:
        signal.signal(signal.SIGHUP, previous)
