"""A packing in parts (:mod:`dem.scene.packing_files.parts`) read in part on each rank: no rank holds the whole packing
or opens every block, and the run gives the effective conductivity, the temperatures, the bond count, the specimen
and the held layers' heat flows of the serial run of the same scene read whole, in the same process."""

import numpy as np
import pytest

from benchmarks.distributed import parts_scene
from dem.driver import run
from dem.scene import load_scene
from test_distributed_network import COMM, serial, shared_folder


@pytest.mark.parametrize("boundary", ["plates", "fixed"])  # the ends: two walls, or two held layers
def test_a_packing_read_in_parts_gives_the_serial_run(boundary):
    folder = shared_folder()
    path = parts_scene(20000, folder, 20, boundary) if COMM.Get_rank() == 0 else None
    path = COMM.bcast(path)
    scene = load_scene(path, part=(COMM.Get_size(), COMM.Get_rank()))
    whole = load_scene(path)
    assert scene.part is not None and scene.particles.n < whole.particles.n == scene.particle_count
    assert scene.part.blocks_read < 20
    result = run(scene)
    ref = serial(whole)
    s, r = result.summary, ref.summary()
    assert s["ranks"] == COMM.Get_size() and s["particles"] == r["particles"] == whole.particles.n
    assert s["bonds"] == r["bonds"] and s["wall_bonds"] == r["wall_bonds"]
    assert s["specimen"] == r["specimen"]
    assert s["effective_conductivity"] == pytest.approx(r["effective_conductivity"], rel=1e-8)
    for name, q in r["boundary_heat_flow"]["groups"].items():  # the held layers' heat, summed over the ranks
        assert s["boundary_heat_flow"]["groups"][name] == pytest.approx(q, rel=1e-8)
    assert np.max(np.abs(result.engine.gathered_temperatures() - ref.T)) < 1e-8  # hot - cold = 1 K
