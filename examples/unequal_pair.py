"""
Two sintered spheres of unequal radii
=====================================

Rojek 2022, Sec. 6: copper spheres of 1 and 3 mm overlapping by 0.06 mm. FE against the pipe model of eqs. 43-45
and against the FE-fitted full-range law the DEM's ``fit`` law uses; the temperature field is the analogue of the
paper's Fig. 17 (10 °C across).
"""

import math

import matplotlib.pyplot as plt
import numpy as np

from fem_neck import law, neck_radius
from fem_neck.conduction import pair_conductance
from fem_neck.render import sampled_fields

r_i, r_j, h, kappa = 1e-3, 3e-3, 0.06e-3, 394.0  # m, m, m, W/(m K)
a = neck_radius(r_i, r_j, h)  # volume-conserving neck, eqs. 27-33
# T fixed on both equatorial disks
fe = pair_conductance(r_i, r_j, h, kappa, rtol=1e-6)
K_fe = fe.K  # W/K

# eq. 43 per half, the halves in series (eq. 45)
K_model = 1.064 * kappa * math.pi * a / 2
# the full-range law, each half at its own a/r, corrected for unequal radii
K_law = law.pair_conductance(kappa, r_i, r_j, a)
print(f"a = {a * 1e3:.6f} mm; "
      f"K_fe = {K_fe:.7f} W/K (estimate {fe.error_estimate:.0e}); "
      f"eq. 45: {K_model:.6f} W/K ({K_model / K_fe - 1:+.2%}); "
      f"fit law: {K_law:.6f} W/K ({K_law / K_fe - 1:+.2%})")

# %%
# The axial section: the meridian half-plane (x radial, y axial, in m) mirrored across the axis.
# T in °C above the cold disk
points, triangles, T, _ = sampled_fields(fe, delta_t=10.0)
x_mm = np.concatenate([points[:, 0], -points[:, 0]]) * 1e3
y_mm = np.concatenate([points[:, 1], points[:, 1]]) * 1e3
fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
mirrored = np.vstack([triangles, triangles + len(points)])
shown = ax.tripcolor(x_mm, y_mm, mirrored, np.concatenate([T, T]),
                     shading="gouraud", cmap="turbo")
fig.colorbar(shown, ax=ax, label="temperature T (°C)")
ax.set_aspect("equal")
ax.set_xlabel("radial position x (mm)")
ax.set_ylabel("axial position y (mm)")
ax.set_title(f"K_fe = {K_fe:.6f} W/K, eq. 45 {K_model:.6f} W/K")
plt.show()
