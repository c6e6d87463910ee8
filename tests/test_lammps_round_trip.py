"""Round trips that keep the box: a saved state or a packing written as a LAMMPS data file keeps its periodic box,
ids and types; a centre outside the box is wrapped along a periodic axis (its image flag counting the periods) and
refused along any other; `dem convert` says so in one line."""

import subprocess
import sys

import numpy as np
import pytest

from dem import read_packing, run
from dem.scene import parse_scene, state_file
from dem.scene.packing_files import Packing, packing_from_state, wrapped, write_lammps_data

L = 1e-3  # m, the box's period along x and y


def packing(periodic=(True, True, False)) -> Packing:
    """Three spheres in the box [0, L) x [0, L) x [0, 2L): the second 0.3 L beyond the +x face, the third 1.2 L
    before the -y face (two periods back along y)."""
    x = np.array([[0.5, 0.5, 0.5], [1.3, 0.5, 0.5], [0.5, -1.2, 1.0]]) * L
    return Packing(np.array([4, 9, 11]), x, np.full(3, 0.05 * L), material=np.array([0, 1, 0]),
                   density=np.full(3, 8960.0), box_lo=np.zeros(3), box_hi=np.array([L, L, 2 * L]),
                   periodic=periodic)


def test_centres_outside_a_periodic_box_are_wrapped_with_their_image_flags(tmp_path):
    p = packing()
    x, image = wrapped(p)
    assert np.all((x >= p.box_lo) & (x < p.box_hi))
    assert image.tolist() == [[0, 0, 0], [1, 0, 0], [0, -2, 0]]
    np.testing.assert_allclose(x + image * (p.box_hi - p.box_lo), p.position, rtol=0, atol=1e-18)
    back = read_packing(write_lammps_data(tmp_path / "p.data", p))
    np.testing.assert_array_equal(back.id, p.id)
    np.testing.assert_array_equal(back.material, p.material)  # LAMMPS types 1, 2, 1
    np.testing.assert_array_equal(back.box_hi, p.box_hi)
    np.testing.assert_array_equal(back.image, image)
    np.testing.assert_allclose(back.position + back.image * (p.box_hi - p.box_lo), p.position, rtol=0, atol=1e-18)


@pytest.mark.parametrize("periodic, message", [
    ((True, False, False), r"particle id 11 has y = -0\.0012 m, outside the box \[0\.0, 0\.001\) along y, which is "
                           r"not periodic; 1 particle\(s\)"),
    (None, r"particle id 9 has x = 0\.0013\d* m, outside .* along x, which is not periodic \(which axes are periodic is "
           r"not known: give them, e\.g\. --periodic xy\); 1 particle"),
])
def test_centres_outside_a_closed_box_are_refused(tmp_path, periodic, message):
    with pytest.raises(ValueError, match=message):
        write_lammps_data(tmp_path / "p.data", packing(periodic))
    assert not (tmp_path / "p.data").exists()


def periodic_state(tmp_path):
    """The state of a steady run on a 2 x 2 x 2 simple cubic lattice periodic along every axis."""
    doc = {"material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},
           "generator": {"kind": "lattice", "shape": [2, 2, 2], "radius": 1e-4, "overlap": 0.1,
                         "boundary": "periodic", "hot": 1.0, "cold": 0.0}, "solver": {"mode": "steady"}}
    scene = parse_scene(doc)
    run(scene, out=tmp_path / "run")
    return scene, tmp_path / "run" / "state.npz"


@pytest.mark.slow
def test_dem_convert_keeps_a_states_periodic_box(tmp_path):
    scene, state = periodic_state(tmp_path)
    p = packing_from_state(state_file.load(state))
    np.testing.assert_array_equal(p.box_lo, scene.box.origin)
    np.testing.assert_array_equal(p.box_hi - p.box_lo, scene.box.lengths)
    assert p.periodic == (True, True, True)
    out = tmp_path / "bed.data"
    proc = subprocess.run([sys.executable, "-m", "dem", "convert", str(state), str(out), "--density", "8960"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    back = read_packing(out)
    np.testing.assert_allclose(back.box_hi - back.box_lo, scene.box.lengths, rtol=1e-15)
    np.testing.assert_array_equal(back.id, scene.particles.id + 1)
    np.testing.assert_allclose(back.position + back.image * scene.box.lengths, scene.particles.position, rtol=0,
                               atol=1e-18)
    proc = subprocess.run([sys.executable, "-m", "dem", "convert", str(state), str(out), "--periodic", "xy"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stderr.count("\n") == 1
    assert "--periodic = 'xy': only for a packing file" in proc.stderr


@pytest.mark.slow
def test_a_moving_run_writes_lammps_dumps_that_read_back(tmp_path):
    """[output] lammps_dump: beside every snapshot a LAMMPS text dump; the last one reads back (read_packing) to the
    run's final state bit for bit: ids, centres, radii, velocities, temperatures, and its forces are there."""
    import pathlib
    import tomllib

    builtin = pathlib.Path(__file__).resolve().parents[1] / "dem" / "scene" / "builtin"
    text = (builtin / "hot-wall-sintering.toml").read_text().replace("t_end = 0.15\n", "t_end = 0.004\n")
    doc = tomllib.loads(text)
    doc.setdefault("output", {})["lammps_dump"] = True
    result = run(parse_scene(doc), tmp_path / "run")
    dumps = sorted((tmp_path / "run").glob("particles_*.dump"))
    vtus = sorted((tmp_path / "run").glob("particles_*.vtu"))
    assert len(dumps) == len(vtus) >= 2
    last = read_packing(dumps[-1])
    state = state_file.load(tmp_path / "run" / "state.npz")
    assert last.timestep == result.summary["steps"]
    assert np.array_equal(last.position, state["x"]) and np.array_equal(last.radius, state["radius"])
    assert np.array_equal(last.temperature, state["T"]) and np.array_equal(last.velocity, state["v"])
    assert last.id.tolist() == (np.asarray(state["id"]) + 1).tolist()  # LAMMPS numbers atoms from 1
    header = dumps[-1].read_text().splitlines()
    assert header[:2] == ["ITEM: UNITS", "si"]
    assert header[10] == "ITEM: ATOMS id type radius x y z vx vy vz fx fy fz T"


def test_lammps_dump_must_be_true_or_false():
    with pytest.raises(ValueError, match=r"\[output\] lammps_dump = 'yes': must be true or false"):
        parse_scene({"material": {"conductivity": 1.0, "density": 1.0, "specific_heat": 1.0},
                     "particles": {"position": [[0, 0, 0]], "radius": [1e-3], "temperature": [0.0]},
                     "output": {"lammps_dump": "yes"}})
