"""Pipe-network thermal DEM of sintered particles (Rojek, Kasztelan & Tharmaraj 2022, Section 2), TOML scenes.

Python use::

    from dem import make_scene, load_scene, run
    result = run(make_scene(positions, radii, temperatures, fixed=mask, law="rojek", mode="steady"))
    result.T, result.summary["boundary_heat_flow"], result.thermal.bonds, result.thermal.K_pairs
    packing = read_packing("packing.dump")      # CSV, LAMMPS data file or dump, VTK point set

``dem`` needs no gmsh or FE code: it imports only :mod:`fem_neck.geometry` and :mod:`fem_neck.law`.
"""

import sys

if sys.argv[:1] == ["-m"]:  # imported by `python -m dem`, before its __main__: Ctrl-C held to one line from here on
    from sinterheat.startup import hold

    hold("python -m dem")

from sinterheat import jit_cache  # noqa: E402

jit_cache.configure()  # before numba is imported: compiled kernels cached per version of their source

from dem.scene.packing_files import Packing, read_packing, write_lammps_data  # noqa: E402
from dem.geometry.particles import COPPER, Material, Particles  # noqa: E402
from dem.scene import Scene, SolverSpec, load_scene, make_scene, parse_scene  # noqa: E402
from dem.driver import RunResult, run  # noqa: E402

__all__ = ["COPPER", "Material", "Packing", "Particles", "RunResult", "Scene", "SolverSpec", "load_scene", "make_scene",
           "parse_scene", "read_packing", "run", "write_lammps_data"]
