"""
A chain of three sintered spheres
=================================

A collinear chain of copper spheres of 1, 5 and 2 mm: FE of the whole chain against its pipes in series (the
fit law per bond, as the DEM's network sees them), and the temperature along the chain.
"""

import matplotlib.pyplot as plt
import numpy as np

from fem_neck import law, neck_radius
from fem_neck.conduction import chain_conductance
from fem_neck.render import sampled_fields

radii = [1e-3, 5e-3, 2e-3]  # m
overlaps = [0.02e-3, 0.3e-3]  # m, one per bond
kappa = 394.0  # W/(m K)

# the end particles cut at their outer equatorial planes, T fixed there
fe = chain_conductance(radii, overlaps, kappa)
K_fe = fe.K

pairs = list(zip(radii, radii[1:]))
necks = [neck_radius(r_i, r_j, h) for (r_i, r_j), h in zip(pairs, overlaps)]
pipes = [law.pair_conductance(kappa, r_i, r_j, a)
         for (r_i, r_j), a in zip(pairs, necks)]
# the bonds in series, as the DEM's network sees them
K_pipes = 1.0 / np.sum(1.0 / np.array(pipes))
print(f"K_fe = {K_fe:.6f} W/K (estimate {fe.error_estimate:.0e}), "
      f"pipes in series (fit law) {K_pipes:.6f} W/K "
      f"({K_pipes / K_fe - 1:+.2%})")

# %%
# The temperature in the meridian half-plane (x radial, y along the chain, in m), 1 K across the chain.
points, triangles, T, _ = sampled_fields(fe, delta_t=1.0)
fig, ax = plt.subplots(figsize=(4.8, 7), layout="constrained")
shown = ax.tripcolor(points[:, 0] * 1e3, points[:, 1] * 1e3, triangles, T,
                     shading="gouraud", cmap="turbo")
fig.colorbar(shown, ax=ax, label="temperature T (K above the cold end)")
ax.set_aspect("equal")
ax.set_xlabel("radial position x (mm)")
ax.set_ylabel("position along the chain y (mm)")
ax.set_title(f"K_fe = {K_fe:.6f} W/K, pipes {K_pipes:.6f} W/K")
plt.show()
