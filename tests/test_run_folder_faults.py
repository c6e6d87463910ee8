"""Nothing on disk is lost: a finished run is not rewritten by --resume, a folder is held by one run at a time (a
stale lock of a killed run is taken over), a resumed run cuts profiles.csv after the exact snapshot it keeps, and a
write that fails names its path and leaves no ``.part``. Each case failed before the fix it guards."""

from __future__ import annotations

import errno
import json
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest

from dem import make_scene, run
from dem.cli import main as dem_main
from dem.output import folder
from dem.output.atomic import write_aside
from dem.output.writer import resumed_profiles
from test_cli_stress import run_cli

X = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]
R = [1.0e-3, 3.0e-3]
PAIR_TOML = ("[material]\nconductivity = 394.0\ndensity = 8960.0\nspecific_heat = 385.0\n"
             "[particles]\nposition = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]\nradius = [1.0e-3, 3.0e-3]\n"
             'temperature = [100.0, 0.0]\n[solver]\nmode = "transient"\nintegrator = "implicit"\ndt = 1.0e-3\n'
             "t_end = 0.01\n")


def pair_scene():
    return make_scene(X, R, [100.0, 0.0], mode="transient", integrator="implicit", dt=1e-3, t_end=0.01)


def test_resume_of_a_finished_run_is_refused_and_leaves_the_summary(tmp_path, capsys):
    """It rewrote summary.json (effective_conductivity null, the wall forces 0) and exited 0."""
    scene = tmp_path / "pair.toml"
    scene.write_text(PAIR_TOML)
    out = tmp_path / "run"
    assert run_cli(dem_main, ["run", str(scene), "--out", str(out), "--quiet"], capsys)[0] == 0
    before = (out / "summary.json").read_bytes()
    code, stdout, err = run_cli(dem_main, ["run", str(scene), "--out", str(out), "--resume", "--quiet"], capsys)
    assert code == 2 and stdout == "" and len(err) == 1 and "finished run" in err[0] and str(out) in err[0], err
    assert (out / "summary.json").read_bytes() == before
    assert not (out / folder.LOCK).exists()


def sleeper():
    """A live process that is not this one (it holds the folder in the test)."""
    return subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])


def test_second_run_into_a_held_folder_is_refused_naming_the_holder(tmp_path):
    """Two runs into one --out both exited 0: duplicated blocks, NUL bytes in timeseries.csv, plots lost."""
    out = tmp_path / "run"
    out.mkdir()
    other = sleeper()
    try:
        (out / folder.LOCK).write_text(json.dumps({"pid": other.pid, "host": os.uname().nodename}))
        for options in ({}, {"overwrite": True}, {"resume": True}):
            with pytest.raises(ValueError, match=rf"another run is writing it \(pid {other.pid} on "):
                run(pair_scene(), out=out, **options)
        assert folder.run_files(out) == []  # --overwrite deleted nothing of the holder's
    finally:
        other.kill()
        other.wait()
    # the holder was killed outright: its lock is stale, the next run takes it over and releases it at its end
    res = run(pair_scene(), out=out)
    assert res.summary["steps"] == 10 and not (out / folder.LOCK).exists()


def test_resumed_profiles_keep_the_block_at_the_exact_snapshot_time(tmp_path):
    """The CSV keeps t rounded to 12 digits: 0.04249999999999999 is written 0.0425, above the exact time, and the
    resumed run dropped that block (33 lines instead of 41 in a hot-wall-sintering run)."""
    t_kept, t_later = 0.04249999999999999, 0.0625
    assert float(f"{t_kept:.12g}") > t_kept
    path = tmp_path / "profiles.csv"
    rows = ["t,distance,solid_fraction,neck_over_radius"]
    for t in (0.0225, t_kept, t_later):
        rows += [f"{t:.12g},{d:.12g},0.6,0.1" for d in (1e-3, 2e-3)]
    path.write_text("\n".join(rows) + "\n")
    resumed_profiles(path, t_kept)
    times = [line.split(",")[0] for line in path.read_text().splitlines()[1:]]
    assert times == ["0.0225", "0.0225", "0.0425", "0.0425"]


def test_a_failed_write_names_the_path_and_leaves_no_part(tmp_path):
    """ENOSPC was printed without the path and left checkpoint.npz.part behind."""
    target = tmp_path / "checkpoint.npz"
    target.write_bytes(b"the last whole checkpoint")

    def full_disk(fh):
        fh.write(b"half a checkpoint")
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError, match=rf"cannot write {target}: No space left on device") as caught:
        write_aside(target, full_disk, "wb")
    assert caught.value.errno == errno.ENOSPC
    assert sorted(p.name for p in tmp_path.iterdir()) == ["checkpoint.npz"]
    assert target.read_bytes() == b"the last whole checkpoint"


def test_a_checkpoint_that_cannot_be_written_is_one_line(tmp_path, capsys, monkeypatch):
    """Through the CLI: a full disk at the checkpoint is one line naming the file, exit 2, no .part left."""
    scene = tmp_path / "pair.toml"
    scene.write_text(PAIR_TOML)
    out = tmp_path / "run"

    def no_space(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(folder.np, "savez", no_space)
    code, stdout, err = run_cli(dem_main, ["run", str(scene), "--out", str(out), "--quiet"], capsys)
    assert code == 2 and len(err) == 1, err
    assert str(out / "checkpoint.npz") in err[0] and "No space left" in err[0]
    assert not list(out.glob("*.part")) and not (out / folder.LOCK).exists()


@pytest.mark.slow
def test_two_runs_into_one_folder_one_refused_the_folder_whole(tmp_path):
    """The issue's case end to end: a run writing its folder, a second started into it (a process of its own)."""
    from test_dem_resume import THERMAL
    from test_signals import start

    scene = tmp_path / "scene.toml"
    scene.write_text(THERMAL)
    out = tmp_path / "run"
    first = start(["dem", "run", str(scene), "--out", str(out), "--quiet", "--json"], tmp_path)
    rows = out / "timeseries.csv"
    while first.poll() is None and not (rows.exists() and rows.read_text().count("\n") > 5):
        pass
    second = start(["dem", "run", str(scene), "--out", str(out), "--overwrite", "--quiet"], tmp_path)
    _, err = second.communicate(timeout=120)
    stdout, first_err = first.communicate(timeout=300)
    assert first.returncode == 0, first_err
    assert second.returncode == 2 and err.count("\n") == 1, err
    assert f"another run is writing it (pid {first.pid} " in err, err
    summary = json.loads((out / "summary.json").read_text())
    text = rows.read_text()
    assert "\x00" not in text and len(text.splitlines()) == summary["steps"] + 2  # header, steps 0 ... n
    assert summary == {**json.loads(stdout), **{k: summary[k] for k in ("seconds", "plots", "state")
                                                 if k in summary}}


@pytest.mark.slow
def test_interrupted_sintering_run_resumed_keeps_every_profile_block(tmp_path):
    """The issue's case end to end: hot-wall-sintering (t_end 0.08 s, a snapshot every 0.02 s) interrupted after
    its block at t = 0.0425 (written 0.0424999633209, the exact time rounded up) and resumed: profiles.csv is the
    uninterrupted run's, all 41 lines (it had 33)."""
    import signal
    import time

    from dem import load_scene
    from test_signals import start

    text = (pathlib.Path(__file__).resolve().parents[1] / "dem" / "scene" / "builtin" / "hot-wall-sintering.toml")
    text = text.read_text().replace("\nt_end = 0.15", "\nt_end = 0.08").replace("vtu_interval = 0.025",
                                                                               "vtu_interval = 0.02")
    scene = tmp_path / "scene.toml"
    scene.write_text(text + "checkpoint_every = 0.5\n")  # the [output] table is the file's last
    whole = run(load_scene(scene), out=tmp_path / "whole")
    part = tmp_path / "part"
    proc = start(["dem", "run", str(scene), "--out", str(part), "--quiet"], tmp_path)
    profiles = part / "profiles.csv"
    while proc.poll() is None and not (profiles.exists() and profiles.read_text().count("\n") >= 25):
        time.sleep(0.05)
    time.sleep(1.0)  # a checkpoint after the block
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the run finished before the interrupt reached it")
    assert proc.returncode == 130
    resumed = run(load_scene(scene), out=part, resume=True)
    assert resumed.summary["resumed_from"]["t"] > 0.0425
    assert np.array_equal(resumed.T, whole.T)
    assert profiles.read_text() == (tmp_path / "whole" / "profiles.csv").read_text()
    assert len(profiles.read_text().splitlines()) == 41
