"""
A 3D cluster: FE against the pipe network
=========================================

A cluster JSON for ``python -m fem_neck cluster``: three copper spheres in an L, heat in through the first and out
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

import matplotlib.pyplot as plt
from matplotlib.collections import PatchCollection
from matplotlib.patches import Circle

from dem import make_scene, run
from fem_neck.cluster import (build_cluster_mesh, load_cluster_json,
                              solve_cluster)

data = {
    "centres": [[0.0, 0.0, 0.0], [0.0, 0.0, 1.9e-3],
                [1.9e-3, 0.0, 1.9e-3]],  # m
    "radii": [1.0e-3, 1.0e-3, 1.0e-3],  # m
    "bonds": [[0, 1], [1, 2]],  # particle indices of each sintered neck
    # cut at the centre plane, T fixed there
    "terminals": [{"particle": 0, "T": 1.0}, {"particle": 2, "T": 0.0}],
}
path = pathlib.Path(tempfile.mkdtemp()) / "cluster.json"
path.write_text(json.dumps(data, indent=1))

cluster, terminals = load_cluster_json(json.loads(path.read_text()))
# coarse: ~0.1 % from a finer mesh
mesh = build_cluster_mesh(cluster, terminals, size_neck=0.4, size_far=0.7)
solution = solve_cluster(mesh, kappa=394.0, order=2)
K_cluster = solution.K  # W/K between the two terminals
# the L is symmetric: the middle particle's mean temperature is 1/2
middle_T = solution.particle_T[1]

dem = run(make_scene(data["centres"], data["radii"], [1.0, 0.0, 0.0],
                     fixed=[True, False, True], law="fit", mode="steady"))
# W/K: the heat out of the hot terminal over the 1 K difference
K_dem = -dem.summary["boundary_heat_flow"]["particles"]["0"] / 1.0
print(f"{path.name}: 3D FE K = {K_cluster:.5f} W/K ({solution.dofs} dofs, "
      f"middle particle at {middle_T:.4f}); DEM pipe network (fit law) "
      f"{K_dem:.5f} W/K ({K_dem / K_cluster - 1:+.2%})")

# %%
# Each particle's mean temperature, FE (colour) and DEM (label), in the plane of the L (y = 0). The DEM holds the
# terminals at 1 and 0; the FE holds their centre planes there, so its means are those of the halves beyond them.
centres_mm = [(x * 1e3, z * 1e3) for x, _, z in data["centres"]]
circles = PatchCollection(
    [Circle(c, r * 1e3) for c, r in zip(centres_mm, data["radii"])],
    cmap="turbo")
circles.set_array(solution.particle_T)
circles.set_clim(0.0, 1.0)
fig, ax = plt.subplots(figsize=(5.6, 4.6), layout="constrained")
ax.add_collection(circles)
for (x, z), T_fe, T_dem in zip(centres_mm, solution.particle_T, dem.T):
    ax.annotate(f"FE {T_fe:.4f}\nDEM {T_dem:.4f}", (x, z), ha="center",
                va="center")
fig.colorbar(circles, ax=ax,
             label="mean temperature (K above the cold terminal)")
ax.set_xlim(-1.2, 3.1)
ax.set_ylim(-1.2, 3.1)
ax.set_aspect("equal")
ax.set_xlabel("x (mm)")
ax.set_ylabel("z (mm)")
ax.set_title(f"K: 3D FE {K_cluster:.5f} W/K, DEM {K_dem:.5f} W/K")
plt.show()
