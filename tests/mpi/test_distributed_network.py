"""The static network on several MPI ranks against the serial run of the same scene in the same process: the same
temperatures to the solver's tolerance, the same matrix rows to the bit, the same groups, one data set on disk."""

import dataclasses
import pathlib
import tempfile

import numpy as np
import pytest
import scipy.sparse as sp

from dem.driver import run
from dem.engines.distributed.static import DistributedStaticEngine
from dem.engines.static import StaticEngine
from dem.parallel import comm as mpi
from dem.scene import load_scene
from dem.scene.parse import parse_scene

COMM = mpi.world()

MATERIAL = {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0}


def serial(scene):
    engine = StaticEngine(scene)
    engine.run()
    return engine


def shared_folder() -> pathlib.Path:
    """One temporary folder for all ranks (rank 0's)."""
    return pathlib.Path(COMM.bcast(tempfile.mkdtemp(prefix="dem-mpi-") if COMM.Get_rank() == 0 else None))


def union_parts_scene(n: int, conductance: str):
    """A packing of about `n` spheres in parts (16 plates) with the `shared-body` law and union necks, the extra
    `conductance` lines added to its table: this rank's part and the packing read whole."""
    from benchmarks.distributed import parts_scene

    folder = shared_folder()
    if COMM.Get_rank() == 0:
        path = parts_scene(n, folder, 16, "plates")
        path.write_text(path.read_text().replace('law = "rojek"',
                                                 'law = "shared-body"\nneck = "union"\n' + conductance))
    path = COMM.bcast(folder / "packing.toml")
    return load_scene(path, part=(COMM.Get_size(), COMM.Get_rank())), load_scene(path)


def test_packing_equals_the_serial_run():
    """The built-in packing (2e4 particles, rattlers kept at their initial temperature as floating groups)."""
    scene = load_scene("packing")
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert s["ranks"] == COMM.Get_size()
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-8  # hot - cold = 1 K
    assert s["bonds"] == r["bonds"] and s["wall_bonds"] == r["wall_bonds"]
    assert s["floating_groups"] == r["floating_groups"] > 0
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-8)
    assert s["energy_error"] < 1e-9


def test_rows_are_those_of_the_serial_matrix_to_the_bit():
    scene = load_scene("packing")
    engine = DistributedStaticEngine(scene)
    net, part = engine.network, engine.part
    gid = part.held[net.free]
    local = net.matrix(net.sinks(net.particles.temperature[net.free]))[np.flatnonzero(part.own_free)].tocoo()
    ref = serial(scene).network
    full = ref.matrix(ref.sinks(ref.particles.temperature[ref.free])).tocsr()
    rows = np.searchsorted(ref.free, gid[part.own_free])
    expected = full[rows].tocoo()
    ours = sp.coo_matrix((local.data, (local.row, gid[local.col])), shape=(len(rows), scene.particles.n)).tocsr()
    theirs = sp.coo_matrix((expected.data, (expected.row, ref.free[expected.col])),
                           shape=(len(rows), scene.particles.n)).tocsr()
    ours.sort_indices()
    theirs.sort_indices()
    assert np.array_equal(ours.indptr, theirs.indptr) and np.array_equal(ours.indices, theirs.indices)
    assert np.array_equal(ours.data, theirs.data)
    assert mpi.total(COMM, len(rows)) == len(ref.free)


def _isolated_pairs_scene(floating: str):
    """A lattice bar between plates along x and, beside it, pairs of touching particles that touch nothing else,
    one of them straddling the middle of the bar (where two ranks part): floating groups across ranks."""
    doc = {"material": MATERIAL,
           "generator": {"kind": "lattice", "shape": [12, 2, 2], "radius": 1e-3, "overlap": 0.1,
                         "boundary": "plates", "hot": 1.0, "cold": 0.0},
           "solver": {"mode": "steady", "floating": floating}}
    scene = parse_scene(doc)
    p = scene.particles
    x = p.position
    centre = 0.5 * (x[:, 0].min() + x[:, 0].max())
    y, z = x[:, 1].max() + 10e-3, 0.5 * (x[:, 2].min() + x[:, 2].max())  # clear of the bar and the plates
    d = 1.9e-3
    extra = np.array([[centre - d / 2, y, z], [centre + d / 2, y, z],
                      [x[:, 0].min() + 2e-3, y, z], [x[:, 0].min() + 2e-3 + d, y, z]])
    T0 = np.array([0.2, 0.6, 0.0, 1.0])
    particles = dataclasses.replace(
        p, position=np.vstack([x, extra]), radius=np.r_[p.radius, np.full(4, 1e-3)],
        temperature=np.r_[p.temperature, T0], material=np.r_[p.material, np.zeros(4, p.material.dtype)],
        fixed=np.r_[p.fixed, np.zeros(4, bool)], heat=np.r_[p.heat, np.zeros(4)],
        id=np.arange(p.n + 4))
    return dataclasses.replace(scene, particles=particles)


def test_a_floating_group_across_ranks_is_held_at_its_mean():
    scene = _isolated_pairs_scene("mean")
    result = run(scene)
    ref = serial(scene)
    T = result.engine.gathered_temperatures()
    assert result.summary["floating_groups"] == ref.summary()["floating_groups"] == 2
    assert T[-4] == pytest.approx(0.4, abs=1e-15) and T[-3] == pytest.approx(0.4, abs=1e-15)  # equal capacities
    assert T[-2] == pytest.approx(0.5, abs=1e-15) and T[-1] == pytest.approx(0.5, abs=1e-15)
    assert np.max(np.abs(T - ref.T)) < 1e-10


def test_a_floating_group_is_refused_as_in_the_serial_run():
    scene = _isolated_pairs_scene("error")
    with pytest.raises(ValueError) as serial_error:
        serial(scene)
    with pytest.raises(ValueError) as ours:
        run(scene)
    assert "2 of 3 connected group(s)" in str(ours.value) and "4 particles" in str(ours.value)
    assert "2 of 3 connected group(s)" in str(serial_error.value)


def test_a_periodic_lattice_is_gauged_across_ranks():
    """A periodic block (no wall: one group fixed up to a constant by its mean) with a drop of 1 K per period."""
    doc = {"material": MATERIAL,
           "generator": {"kind": "lattice", "shape": [8, 6, 6], "radius": 1e-3, "overlap": 0.1, "structure": "bcc",
                         "boundary": "periodic", "hot": 3.0, "cold": 1.0}}
    scene = parse_scene(doc)
    result = run(scene)
    ref = serial(scene)
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-9
    assert result.summary["effective_conductivity"] == pytest.approx(ref.summary()["effective_conductivity"],
                                                                     rel=1e-9)
    assert result.summary["T_mean"] == pytest.approx(2.0, abs=1e-10)


@pytest.mark.parametrize("integrator", ["implicit", "crank-nicolson"])
def test_fixed_steps_equal_the_serial_steps(integrator):
    doc = {"material": MATERIAL,
           "generator": {"kind": "random", "n": 2000, "radius": 5e-5, "radius_spread": 0.1, "overlap": 0.1,
                         "seed": 2, "boundary": "plates", "hot": 100.0, "cold": 0.0, "temperature": 0.0},
           "solver": {"mode": "transient", "integrator": integrator, "dt": 2e-3, "t_end": 0.01}}
    scene = parse_scene(doc)
    result = run(scene)
    ref = serial(scene)
    s, r = result.summary, ref.summary()
    assert s["steps"] == r["steps"] == 5
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-6  # of 100 K: 1e-8
    assert s["heat_in"]["walls"] == pytest.approx(r["heat_in"]["walls"], rel=1e-8)
    assert s["energy_error"] < 1e-12


def test_explicit_and_adaptive_steps_are_refused_by_the_ranks_loop():
    """The ranks take the serial loop (dem.network.heat.integrate) for fixed implicit and Crank-Nicolson steps only:
    its explicit limit and its error control are reductions of one process, refused up front on every rank alike."""
    doc = {"material": MATERIAL, "particles": {"position": [[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-3]],
                                               "radius": [1e-3, 1e-3], "temperature": [100.0, 0.0]},
           "solver": {"mode": "transient", "integrator": "implicit", "dt": 1e-3, "t_end": 1e-2}}
    part = run(parse_scene(doc)).engine.part
    for integrator, dt in (("explicit", 1e-3), ("implicit", "auto")):
        with pytest.raises(ValueError, match="on MPI ranks only fixed steps"):
            part.integrate(integrator, dt, 1e-2)
    COMM.Barrier()  # every rank got here


def test_the_pieces_open_as_one_data_set():
    pyvista = pytest.importorskip("pyvista")
    out = shared_folder()
    scene = load_scene("lattice")
    result = run(scene, out, overwrite=True)
    T = result.engine.gathered_temperatures()
    COMM.Barrier()
    if COMM.Get_rank() == 0:
        pvd = (out / "particles.pvd").read_text()
        assert 'file="particles_000000000.pvtu"' in pvd
        mesh = pyvista.read(out / "particles_000000000.pvtu")
        assert mesh.n_points == scene.particles.n
        assert np.array_equal(np.sort(mesh.point_data["id"]), np.arange(scene.particles.n))
        order = np.argsort(mesh.point_data["id"])
        assert np.array_equal(mesh.point_data["temperature"][order], T)
        bonds = pyvista.read(out / "bonds_000000000.pvtu")
        assert bonds.n_cells == result.summary["bonds"] + result.summary["wall_bonds"]
        assert (out / "summary.json").exists() and (out / "timeseries.csv").exists()


def test_a_bond_out_of_range_on_one_rank_stops_every_rank():
    """The overlap of one pair (in the first rank's cell) beyond the neck model's range: refused on all ranks with
    the serial run's message, none left waiting."""
    scene = _isolated_pairs_scene("mean")
    p = scene.particles
    x = p.position.copy()
    x[-1] = x[-2] + [0.2e-3, 0.0, 0.0]  # h = 1.8 mm of r = 1 mm: beyond the range
    scene = dataclasses.replace(scene, particles=dataclasses.replace(p, position=x))
    with pytest.raises(ValueError) as serial_error:
        serial(scene)
    with pytest.raises(ValueError) as ours:
        run(scene)
    beyond = "particle pairs lie beyond the contact model's range"
    assert beyond in str(serial_error.value) and beyond in str(ours.value) and " of " in str(ours.value).split(":")[0]


# a copper pair, r = 1 mm at 0 C and r = 10 mm at 100 C (overlap 0.06 mm), equalising at 99.9 C
UNEQUAL_PAIR = {"material": MATERIAL,
                "particles": {"position": [[0.0, 0.0, 0.0], [0.0, 0.0, 1.094e-2]], "radius": [1e-3, 1e-2],
                              "temperature": [0.0, 100.0]},
                "solver": {"mode": "transient", "integrator": "crank-nicolson", "dt": 0.2, "t_end": 2.0}}


def test_temperatures_out_of_range_stop_every_rank_as_the_serial_run():
    """Crank-Nicolson steps of 0.2 s, z = lambda dt = 4.19: the two implicit Euler steps of the start-up leave
    1/(1 + z)^2 = 3.7 % of the stiff mode, and the next step (factor (1 - z/2)/(1 + z/2) = -0.35) throws the small
    particle 1.21 K above 100 C. The serial run refuses it at t = 0.6 s; the ranks reported
    max_principle_violation = 1.21 and ended as if nothing were wrong. Now every rank stops at the same step with
    the serial run's message (one process refusing alone would leave the other waiting in its next reduction)."""
    scene = parse_scene(UNEQUAL_PAIR)
    with pytest.raises(ValueError) as serial_error:
        serial(scene)
    with pytest.raises(ValueError) as ours:
        run(scene)
    assert str(ours.value) == str(serial_error.value)
    assert "at t = 0.6 s" in str(ours.value) and "by 1.212 (max_principle_violation" in str(ours.value)
    COMM.Barrier()  # every rank got here: none waits in the integrator


def test_crank_nicolson_steps_far_above_the_stiffest_time_constant_end_as_in_the_serial_run():
    """The issue's pair (r = 1 and 3 mm at 100 and 0 C) in steps of 1e6 s, ~1e8 time constants: the serial run
    ends at the capacity-weighted mean 100/28 C. On the ranks CG stopped at its first iteration (PETSc's divergence
    test: the warm start's residual, ~K |delta T|, is far above |b| ~ C/dt |T|), and the run was refused."""
    doc = {"material": MATERIAL,
           "particles": {"position": [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]], "radius": [1e-3, 3e-3],
                         "temperature": [100.0, 0.0]},
           "solver": {"mode": "transient", "integrator": "crank-nicolson", "dt": 1e6, "t_end": 1e7}}
    scene = parse_scene(doc)
    result = run(scene)
    ref = serial(scene)
    assert np.allclose(result.engine.gathered_temperatures(), 100.0 / 28.0, rtol=0, atol=1e-6)
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-6
    assert result.summary["startup_steps"] == ref.summary()["startup_steps"] == 2
