"""
Electric current through a static packing
=========================================

Kirchhoff's laws on the contact network of a sintered copper packing between two electrodes 1 mV apart, without a
scene: the functions the staggered engine (Zohdi 2014) calls at every accepted step. The contact conductances are the
FE-verified neck law with the electrical conductivity in place of the thermal one (the neck is the same Laplace
problem); ``share`` is the part of each contact's resistance on the side of its first particle, where that part of
its Joule heat is made. The current in equals the current out, and the Joule heat in the contacts equals the power the
electrodes deliver.
"""

import matplotlib.pyplot as plt
import numpy as np

from dem import Material, Particles
from dem.geometry.bonds import find_bonds
from dem.geometry.generators import random_packing
from dem.geometry.walls import Wall
from dem.laws.conductance import ConductanceSpec, bond_conductances
from dem.network.current import Electrodes, kirchhoff

layout = random_packing(1000, 1e-3, 0.1, seed=1)  # sintered, h/r = 0.1
copper = Material(394.0, 8960.0, 385.0, "copper",
                  electrical_conductivity=5.96e7)  # SI
p = Particles.from_arrays(layout.position, layout.radius,
                          np.zeros(len(layout.radius)), copper)
walls = [Wall("top", [0, 0, layout.z_high - 5e-5], [0, 0, -1], 0.0),
         Wall("bottom", [0, 0, layout.z_low + 5e-5], [0, 0, 1], 0.0)]
spec = ConductanceSpec("fit")  # the FE-verified neck law, sigma for kappa
bonds = find_bonds(p, walls, spec.contact, "clip")
G, G_w, share = bond_conductances(spec, p, bonds, p.electrical_conductivity,
                                  shares=True)
# the top electrode at 1 mV, the bottom one at 0 V (no fixed currents)
electrodes = Electrodes(("top", "bottom"), (0, 1), np.array([1e-3, 0.0]),
                        np.full(2, np.nan))
flow = kirchhoff(p.n, bonds.i, bonds.j, G, share, bonds.wall_particle,
                 bonds.wall_index, G_w, electrodes)
print(f"current into the electrodes {flow.electrode_current} A, "
      f"Joule heat {flow.joule_heat:.4f} W, "
      f"electrode power {flow.electrode_power:.4f} W")

# %%
# Each particle's potential against its height, and the current through horizontal planes at every height between
# the particles that touch the electrodes: the contacts that cross a plane carry the whole electrode current down
# through it (Kirchhoff's current law summed over the particles above the plane), whatever the packing's disorder.
z = p.position[:, 2]
# the heights of the particles that touch each electrode
touching = {e: z[bonds.wall_particle[bonds.wall_index == e]] for e in (0, 1)}
# m: planes crossed by particle contacts alone
planes = np.linspace(touching[1].max(), touching[0].min(), 41)[1:-1]
z_i, z_j = z[bonds.i][:, None], z[bonds.j][:, None]
downward = (np.where((z_i > planes) & (z_j < planes), 1.0, 0.0)
            - np.where((z_i < planes) & (z_j > planes), 1.0, 0.0))
plane_current = flow.pair_current @ downward  # A down through each plane
fig, (left, right) = plt.subplots(1, 2, figsize=(7.2, 4.0), sharey=True,
                                  layout="constrained")
left.plot(flow.potential * 1e3, z * 1e3, ".", ms=2, alpha=0.5)
left.set_xlabel("particle potential (mV)")
left.set_ylabel("height z (mm)")
right.plot(plane_current, planes * 1e3, "o-", ms=3)
right.axvline(flow.electrode_current[0], color="k", lw=1, ls="--",
              label="into the top electrode")
right.set_xlabel("current down through the plane (A)")
right.set_xlim(0.0, 1.2 * flow.electrode_current[0])
right.legend(loc="lower left")
fig.suptitle(f"{p.n} copper particles, 1 mV between the electrodes")
plt.show()
