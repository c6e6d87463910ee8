"""A cluster JSON for ``python -m fem_neck cluster``: three copper spheres in an L, heat in through the first and out
through the last (each cut at its centre plane), solved by 3D FE and by the DEM's pipe network.

The same file runs from the shell: ``python -m fem_neck cluster cluster.json --kappa 394 --out results/cluster``.
A pipe's half-conductance is the body between a particle's centre and its neck, so the DEM with the two terminal
particles held at their temperatures describes the FE body cut at the terminals' centre planes; what remains is the
network model's own error: the middle particle's two necks, at a right angle, share its volume (a few per cent
here; ``python -m verification dem-vs-fe`` maps it over many clusters).
"""

import json
import pathlib
import tempfile

from dem import make_scene, run
from fem_neck.cluster import build_cluster_mesh, load_cluster_json, solve_cluster

data = {
    "centres": [[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-3], [1.9e-3, 0.0, 1.9e-3]],  # m
    "radii": [1.0e-3, 1.0e-3, 1.0e-3],  # m
    "bonds": [[0, 1], [1, 2]],  # particle indices of each sintered neck
    "terminals": [{"particle": 0, "T": 1.0}, {"particle": 2, "T": 0.0}],  # cut at the centre plane, T fixed
}
path = pathlib.Path(tempfile.mkdtemp()) / "cluster.json"
path.write_text(json.dumps(data, indent=1))

cluster, terminals = load_cluster_json(json.loads(path.read_text()))
mesh = build_cluster_mesh(cluster, terminals, size_neck=0.4, size_far=0.7)  # coarse: ~0.1 % from a finer mesh
solution = solve_cluster(mesh, kappa=394.0, order=2)
K_cluster = solution.K  # W/K between the two terminals
middle_T = solution.particle_T[1]  # the L is symmetric: the middle particle's mean temperature is 1/2

dem = run(make_scene(data["centres"], data["radii"], [1.0, 0.0, 0.0], fixed=[True, False, True], law="fit",
                     mode="steady"))
K_dem = -dem.summary["boundary_heat_flow"]["particles"]["0"] / 1.0  # W/K: heat out of the hot terminal / dT
print(f"{path}: 3D FE K = {K_cluster:.5f} W/K ({solution.dofs} dofs, middle particle at {middle_T:.4f}); "
      f"DEM pipe network (fit law) {K_dem:.5f} W/K ({K_dem / K_cluster - 1:+.2%})")
