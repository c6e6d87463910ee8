"""Runs that stop and go on: one run per folder, Ctrl-C at a random moment, --resume ends bit for bit where the
uninterrupted run ends (a thermal run with a fixed step; moving particles; Zohdi 2014's staggered scheme)."""

import json
import os
import pathlib
import random
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from dem import load_scene, run

ROOT = pathlib.Path(__file__).resolve().parents[1]
THERMAL = """
[material]
conductivity = 394.0
density = 8960.0
specific_heat = 385.0
[generator]
kind = "random"
n = 3000
radius = 5e-5
overlap = 0.1
seed = 1
boundary = "plates"
hot = 100.0
cold = 0.0
[conductance]
law = "fit"
[solver]
mode = "transient"
integrator = "crank-nicolson"
linear = "cg"
dt = 2e-5
t_end = 0.01
[output]
vtu_every = 50
checkpoint_every = 0.2
"""
MOVING = """
[scene]
physics = ["mechanical"]
dimension = 2
height = 6e-3
[material]
density = 2000.0
[generator]
kind = "box"
n = 60
radius = 1e-3
radius_spread = 0.5
box = [[0.0, 0.0, 0.0], [0.03, 0.0, 0.03]]
speed = 0.01
seed = 2
temperature = 80.0
[contact]
law = "luding"
k1 = 1e5
k2 = 2e5
kc = 1e5
kt_ratio = 0.2
gamma_n = 0.2
gamma_t = 0.05
mu = 0.5
mu_wall = 0.0
T_melt = 120.0
T_var = 10.0
expansion = 1e-4
fluid_overlap = 0.2
t0 = 1e3
brittle_sliding = true
[temperature]
time = [0.0, 0.1, 0.2]
value = [80.0, 140.0, 80.0]
relaxation_time = [0.1, 0.1]
[[walls]]
name = "left"
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[walls]]
name = "bottom"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[walls]]
name = "right"
point = [0.03, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
motion = "stress"
pressure = 100.0
mass = 0.01
damping = 0.2
[[walls]]
name = "top"
point = [0.0, 0.0, 0.03]
normal = [0.0, 0.0, -1.0]
motion = "stress"
pressure = 100.0
mass = 0.01
damping = 0.2
[solver]
mode = "transient"
t_end = 0.2
[output]
interval = 5e-3
vtu_interval = 0.04
checkpoint_every = 0.2
"""


def _zohdi(text: str) -> str:
    """The built-in Zohdi 2014 compaction, smaller (200 spheres) and shorter (the pour and the press with current),
    without frames."""
    for old, new in (("n = 1000 ", "n = 200 "), ("t_end = 1.0 ", "t_end = 0.75 "), ("frames = 6 ", "frames = 0 "),
                     ("vtu_interval = 0.05 ", "vtu_interval = 0.1 "),
                     ("[output]\n", "[output]\ncheckpoint_every = 0.2\n")):
        assert old in text
        text = text.replace(old, new, 1)
    return text


ZOHDI = _zohdi((ROOT / "dem" / "scene" / "builtin" / "zohdi-compaction.toml").read_text())


def interrupted_run(scene, out, seed):
    """``python -m dem run SCENE --out OUT`` stopped by SIGINT at a random moment after its first checkpoint."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    proc = subprocess.Popen([sys.executable, "-m", "dem", "run", str(scene), "--out", str(out)], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while not (out / "checkpoint.npz").exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    time.sleep(random.Random(seed).uniform(0.0, 0.6))
    proc.send_signal(signal.SIGINT)
    _, stderr = proc.communicate(timeout=300)
    return proc.returncode, stderr


def listed(pvd: pathlib.Path) -> list[str]:
    return re.findall(r'file="([^"]+)"', pvd.read_text())


@pytest.mark.parametrize("text, seed", [(THERMAL, 3), pytest.param(MOVING, 4, marks=pytest.mark.slow),
                                        pytest.param(ZOHDI, 5, marks=pytest.mark.slow)],
                         ids=["thermal", "moving", "zohdi"])  # the thermal run is the quick check
def test_interrupted_then_resumed_ends_as_the_uninterrupted_run(tmp_path, text, seed):
    scene = tmp_path / "scene.toml"
    scene.write_text(text)
    whole = run(load_scene(scene), out=tmp_path / "whole")
    part = tmp_path / "part"
    code, err = interrupted_run(scene, part, seed)
    if code == 0:
        pytest.skip("the run finished before the interrupt reached it")
    lines = [line for line in err.split("\n") if line.strip() and "%|" not in line]  # besides progress bars
    assert code == 130 and "Traceback" not in err and len(lines) == 1, err
    assert re.match(r"python -m dem run: interrupted at .*; partial results in .*part", lines[0]), err
    summary = json.loads((part / "summary.json").read_text())
    assert summary["interrupted"] is True and summary["resume_from"]["steps"] > 0
    for pvd in part.glob("*.pvd"):
        kind = pvd.stem
        assert listed(pvd) == sorted(p.name for p in part.glob(f"{kind}_*.vtu"))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    refused = subprocess.run([sys.executable, "-m", "dem", "run", str(scene), "--out", str(part)], env=env,
                             capture_output=True, text=True, timeout=300)
    assert refused.returncode == 2 and "holds a run already" in refused.stderr and "Traceback" not in refused.stderr
    resumed = run(load_scene(scene), out=part, resume=True)
    assert resumed.summary["resumed_from"]["steps"] == summary["resume_from"]["steps"]
    assert np.array_equal(resumed.T, whole.T)
    if text is not THERMAL:
        assert resumed.summary["volume_fraction"] == whole.summary["volume_fraction"]
        for key in ("steps", "t", "neighbour_rebuilds", "energy_error", "joule_energy", "restarts", "iterations"):
            assert resumed.summary.get(key) == whole.summary.get(key), key
    assert (part / "timeseries.csv").read_text() == (tmp_path / "whole" / "timeseries.csv").read_text()
    for pvd in (tmp_path / "whole").glob("*.pvd"):
        assert listed(part / pvd.name) == listed(pvd)


@pytest.mark.slow
def test_overwrite_clears_and_resume_needs_a_checkpoint(tmp_path):
    scene = tmp_path / "scene.toml"
    scene.write_text(THERMAL.replace("t_end = 0.01", "t_end = 0.001"))
    first = run(load_scene(scene), out=tmp_path / "out")
    (tmp_path / "out" / "notes.txt").write_text("mine")
    again = run(load_scene(scene), out=tmp_path / "out", overwrite=True)
    assert np.array_equal(first.T, again.T) and (tmp_path / "out" / "notes.txt").exists()
    with pytest.raises(ValueError, match="no checkpoint"):
        run(load_scene(scene), out=tmp_path / "empty", resume=True)
    other = tmp_path / "other.toml"
    other.write_text(THERMAL.replace("t_end = 0.01", "t_end = 0.002"))
    with pytest.raises(ValueError, match="another scene"):
        run(load_scene(other), out=tmp_path / "out", resume=True)


@pytest.mark.slow  # 2D disks: Luding's force loop for them (35-40 s for numba to compile in a fresh clone)
def test_a_restored_list_brings_the_arrays_sized_by_it(tmp_path):
    """A checkpoint's Verlet list is rarely as long as the one the resumed model built at its start; the arrays the
    loop indexes by pair (the pairs' constants, the threads' rows) must follow it. They did not: the loop wrote past
    their end (the segmentation faults of the resume test in CI)."""
    from dem.engines.verlet.engine import VerletEngine
    from dem.geometry.neighbours import list_arrays, verlet_pairs

    scene = tmp_path / "scene.toml"
    scene.write_text(MOVING)
    mech = VerletEngine(load_scene(scene)).mechanics
    s = mech.state
    longer = verlet_pairs(s.x, s.radius, 4.0 * mech.skin, mech.box)
    assert len(longer[0]) > len(mech.pi)
    saved = {**list_arrays(mech), "x": s.x.copy(), "pi": longer[0], "pj": longer[1],
             "p_hist": np.zeros((len(longer[0]), mech.p_hist.shape[1]))}
    mech.restore_lists(saved)
    assert len(mech.pi) == len(longer[0])
    assert mech.p_const.shape[0] == len(mech.pi) and mech.p_const.shape[1] == 2  # Luding keeps two per pair
    if mech.threaded:  # the rows by pair, the owning block by particle, the pairs outside it indexing the list
        assert mech.pair_load.shape[0] == len(mech.pi) and mech.pair_owner.shape == (s.n,)
        assert mech.pair_start[-1] == len(mech.pair_order) and np.all(np.where(
            mech.pair_order >= 0, mech.pair_order, ~mech.pair_order) < len(mech.pi))
