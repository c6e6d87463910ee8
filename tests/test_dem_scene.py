"""TOML scenes and the ``python -m dem`` CLI: the pair example, built-ins, generators, bad input -> exit 2."""

import json
import subprocess
import sys

import numpy as np
import pytest

from dem import load_scene, run
from dem.scene import builtin_scenes

EXAMPLE = """
[material]
conductivity = 394.0    # W/(m K)
density = 8960.0        # kg/m^3
specific_heat = 385.0   # J/(kg K)
[particles]
position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]
radius = [1.0e-3, 3.0e-3]
temperature = [100.0, 0.0]
fixed = [false, false]          # optional: held at their initial temperature
[conductance]
law = "rojek"
[solver]
mode = "transient"              # "transient" | "steady"
integrator = "crank-nicolson"   # "explicit" | "implicit" | "crank-nicolson"
dt = 1.0e-3                     # or "auto"
t_end = 0.1
"""


def dem_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "dem", *args], capture_output=True, text=True, cwd=cwd, timeout=120)


@pytest.mark.slow
def test_pair_example_runs_from_cli(tmp_path):
    path = tmp_path / "pair.toml"
    path.write_text(EXAMPLE)
    proc = dem_cli("run", str(path), "--json", "--out", str(tmp_path / "out"))
    assert proc.returncode == 0, proc.stderr
    s = json.loads(proc.stdout)
    assert s["steps"] == 100 and s["particles"] == 2 and s["bonds"] == 1 and s["physics"] == ["thermal"]
    assert s["energy_error"] < 1e-10 and len(s["T"]) == 2
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["steps"] == 100


BAD = {
    "malformed": (lambda t: t.replace("radius = [", "radius = [[", 1), "line"),
    "unknown key": (lambda t: t.replace("[conductance]", "[conductance]\nfoo = 1"), "foo"),
    "unknown table": (lambda t: t + "\n[bogus]\nx = 1\n", "bogus"),
    "missing property": (lambda t: t.replace("conductivity = 394.0    # W/(m K)\n", ""), "conductivity"),
    "negative radius": (lambda t: t.replace("radius = [1.0e-3", "radius = [-1.0e-3"), "radius"),
    "length mismatch": (lambda t: t.replace("radius = [1.0e-3, 3.0e-3]", "radius = [1.0e-3]"), "radius"),
    "unstable dt": (lambda t: t.replace('"crank-nicolson"   #', '"explicit" #').replace("dt = 1.0e-3", "dt = 1.0"),
                    "stability limit"),
    "unknown law": (lambda t: t.replace('law = "rojek"', 'law = "magic"'), "law"),
    "nan temperature": (lambda t: t.replace("temperature = [100.0", "temperature = [nan"), "temperature"),
    "steady no fixed": (lambda t: t.replace('mode = "transient"', 'mode = "steady"'), "singular"),
    "coincident": (lambda t: t.replace("3.94e-3]]", "0.0]]"), "beyond"),
    "too many steps": (lambda t: t.replace("t_end = 0.1", "t_end = 1.0e9"), "max_steps"),
    "below absolute zero": (lambda t: t.replace("temperature = [100.0", "temperature = [-400.0")
                            + '\n[radiation]\nemissivity = 0.5\nT_inf = 20.0\nunit = "C"\n', "absolute zero"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, case):
    """In-process (``dem.cli.main``, what ``python -m dem`` calls); the subprocess path is tested below."""
    from dem.cli import main

    edit, word = BAD[case]
    path = tmp_path / "bad.toml"
    path.write_text(edit(EXAMPLE))
    assert main(["run", str(path), "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and word in lines[0], err


@pytest.mark.slow
def test_missing_file_and_no_args():
    proc = dem_cli("run", "no/such/scene.toml")
    assert proc.returncode == 2 and len(proc.stderr.strip().splitlines()) == 1 and "Traceback" not in proc.stderr
    assert dem_cli().returncode == 2


@pytest.mark.slow
def test_builtin_scenes_listed_and_all_load():
    proc = dem_cli("scenes", "--json")
    names = json.loads(proc.stdout)
    assert {"pair", "chain", "lattice", "packing", "packing-transient", "cooling"} <= set(names)
    for name in builtin_scenes():
        load_scene(name)


def test_lattice_plates_effective_conductivity():
    """Simple cubic block between plates: columns of identical bonds, k_eff = K_col L / (s^2 dT) exactly."""
    res = run(load_scene("lattice"))
    s = res.summary
    th = res.thermal
    r, h = 1e-3, 0.1e-3
    s_lat = 2 * r - h
    k_bond = th.K_pairs[0]
    k_wall = th.K_walls[0]
    column = 1.0 / (9 / k_bond + 2 / k_wall)
    spec = load_scene("lattice").specimen
    assert s["effective_conductivity"] == pytest.approx(column * spec.length / (s_lat * s_lat), rel=1e-10)
    assert np.allclose(th.K_pairs, k_bond)


def test_random_packing_hits_target_overlap_and_is_seeded():
    from dem.geometry.generators import random_packing

    a = random_packing(2000, 1e-4, 0.1, seed=5, radius_spread=0.1)
    b = random_packing(2000, 1e-4, 0.1, seed=5, radius_spread=0.1)
    assert np.array_equal(a.position, b.position)
    from dem.geometry.bonds import candidate_pairs

    i, j = candidate_pairs(a.position, a.radius)
    h = a.radius[i] + a.radius[j] - np.linalg.norm(a.position[i] - a.position[j], axis=1)
    assert np.mean(h / np.minimum(a.radius[i], a.radius[j])) == pytest.approx(0.1, rel=1e-9)
    assert a.radius.mean() == pytest.approx(1e-4, rel=1e-12)


def test_several_materials_walls_and_sources_from_toml(tmp_path):
    text = """
[scene]
name = "two materials"
[[materials]]
name = "copper"
conductivity = 394.0
density = 8960.0
specific_heat = 385.0
[[materials]]
name = "steel"
conductivity = 16.0
density = 7900.0
specific_heat = 500.0
[particles]
position = [[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-3]]
radius = [1.0e-3, 1.0e-3]
temperature = [0.0, 0.0]
material = ["copper", "steel"]
heat = [0.01, 0.0]
[[walls]]
name = "sink"
point = [0.0, 0.0, 2.88e-3]
normal = [0.0, 0.0, -1.0]
temperature = 0.0
[convection]
h = 10.0
T_inf = 0.0
[solver]
mode = "steady"
"""
    path = tmp_path / "two.toml"
    path.write_text(text)
    s = run(load_scene(path)).summary
    # all heat generated leaves through the wall and the ambient
    assert s["boundary_heat_flow"]["walls"]["sink"] + (-s["heat_flow"]["convection"]) == pytest.approx(0.01, rel=1e-10)
    assert s["T"][0] > s["T"][1] > 0
