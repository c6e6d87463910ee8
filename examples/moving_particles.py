"""
Particles that move: a packing poured and settled
=================================================

40 spheres dropped into a 4 mm × 4 mm box fall under gravity, collide and come to rest on the floor (velocity Verlet
with the Luding 2005 contact law: elastic-plastic normal force with viscous damping, Coulomb friction between the
particles, frictionless walls). At rest the floor carries the packing's whole weight (with wall friction the side
walls would take a part of it, as in Janssen's silo), and the particles have stopped moving (a few keep a slow spin in
place); the run's folder (here a temporary one) holds the time series ``timeseries.csv`` that shows the way there, VTU
snapshots for ParaView and ``state.npz``.

The scene is the dict form of a TOML scene file (``python -m dem run FILE.toml`` reads the same keys).
"""

import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from dem import parse_scene, run

L = 4.0e-3  # m, the box's width
scene = parse_scene({
    "scene": {"name": "pour", "physics": ["mechanical"]},
    "material": {"density": 1000.0},  # kg/m^3
    # N/m, kg/s, degC, s
    "contact": {"law": "luding", "k1": 1.0e3, "k2": 2.0e3, "kc": 0.0,
                "kt_ratio": 0.2, "gamma_n": 0.02, "gamma_t": 0.005,
                "mu": 0.5, "mu_wall": 0.0, "T_melt": 1000.0, "T_var": 10.0,
                "expansion": 0.0, "fluid_overlap": 0.2, "t0": 1.0,
                "brittle_sliding": True},
    "generator": {"kind": "box", "n": 40, "radius": 0.5e-3,
                  "radius_spread": 0.2, "seed": 1, "temperature": 20.0,
                  "box": [[0.0, 0.0, 2.0e-3], [L, L, 12.0e-3]]},
    "walls": [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]},
              {"name": "x-", "point": [0, 0, 0], "normal": [1, 0, 0]},
              {"name": "x+", "point": [L, 0, 0], "normal": [-1, 0, 0]},
              {"name": "y-", "point": [0, 0, 0], "normal": [0, 1, 0]},
              {"name": "y+", "point": [0, L, 0], "normal": [0, -1, 0]}],
    "gravity": {"acceleration": [0.0, 0.0, -9.81]},  # m/s^2
    "solver": {"mode": "transient", "t_end": 0.3},
})
folder = Path(tempfile.mkdtemp(prefix="moving_particles_"))
result = run(scene, folder)
mechanics = result.engine.mechanics
weight = float(np.sum(mechanics.state.mass)) * 9.81  # N
names = [w.name for w in mechanics.walls]
floor = mechanics.w.force[names.index("floor")]  # N, on the floor
speed2 = np.sum(mechanics.state.v ** 2, axis=1)  # m^2/s^2
kinetic = 0.5 * float(np.sum(mechanics.state.mass * speed2))  # J, translation
print(f"{result.summary['particles']} particles at rest after "
      f"{result.summary['t']:.2f} s: the floor carries {floor * 1e3:.4f} mN "
      f"of their {weight * 1e3:.4f} mN weight, "
      f"translational kinetic energy {kinetic:.2e} J")

# %%
# The kinetic energy of the particles, translational and rotational, as they
# fall, collide and settle. What stays after 0.15 s is rotational: a few
# spheres keep spinning in place (the walls are frictionless).
series = np.genfromtxt(folder / "timeseries.csv", delimiter=",", names=True)
fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
ax.semilogy(series["t"], np.maximum(series["kinetic_energy"], 1e-30))
ax.set_xlabel("time t (s)")
ax.set_ylabel("kinetic energy, with rotation (J)")
ax.set_title("40 spheres poured into a box")
plt.show()
