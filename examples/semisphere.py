"""
The semisphere with a neck
==========================

Rojek 2022, Fig. 12: FE conductance against the 12-digit reference, and the temperature and heat-flux fields of
Figs. 13 and 14.

A sphere of radius r sintered to its mirror image with overlap h: by symmetry, half of the pair is a semisphere with
a half neck, T fixed on its equatorial disk and on the neck's mid-plane. K/K_cyl (K_cyl = kappa pi r) depends on
a/r only. The pictures put in the paper's case: r = 10 mm, copper (kappa = 394 W/(m K)), 10 °C across.
"""

import matplotlib.pyplot as plt
from matplotlib.colors import LogNorm

from fem_neck.conduction import semisphere_conductance
from fem_neck.geometry import equal_neck_radius
from fem_neck.render import sampled_fields
from verification.cases import SEMISPHERE_BY_H

h_over_r = 0.08
# the volume-conserving neck, eqs. 19-20
a_over_r = float(equal_neck_radius(1.0, h_over_r))
# hp elements, the order raised until two orders agree to rtol
result = semisphere_conductance(a_over_r, rtol=1e-6)
K_over_Kcyl = result.K_over_Kcyl

reference = SEMISPHERE_BY_H[h_over_r].K_over_Kcyl
print(f"a/r = {a_over_r:.9f}: K/K_cyl = {K_over_Kcyl:.10f} "
      f"(estimate {result.error_estimate:.1e}), reference {reference:.12f}, "
      f"error {abs(K_over_Kcyl / reference - 1):.1e}")

# %%
# The fields in the meridian half-plane (x radial, y axial; the solve has r = 1 and kappa = 1).
r, kappa, delta_T = 10e-3, 394.0, 10.0  # m, W/(m K), °C: Rojek 2022, Sec. 5
points, triangles, T, q = sampled_fields(result, delta_t=delta_T)
x_mm, y_mm = points[:, 0] * r * 1e3, points[:, 1] * r * 1e3
q = q * kappa / r  # |q| = kappa |grad T| in W/m^2 for the physical sphere

fig, (ax_T, ax_q) = plt.subplots(1, 2, figsize=(9, 4.6), sharey=True,
                                 layout="constrained")
shown_T = ax_T.tripcolor(x_mm, y_mm, triangles, T, shading="gouraud",
                         cmap="turbo")
fig.colorbar(shown_T, ax=ax_T, label="temperature T (°C)")
shown_q = ax_q.tripcolor(x_mm, y_mm, triangles, q, shading="gouraud",
                         cmap="turbo",
                         norm=LogNorm(vmin=q.max() * 1e-3, vmax=q.max()))
fig.colorbar(shown_q, ax=ax_q, label="heat flux |q| (W/m$^2$)")
for ax in (ax_T, ax_q):
    ax.set_aspect("equal")
    ax.set_xlabel("radial position x (mm)")
ax_T.set_ylabel("axial position y (mm)")
fig.suptitle(f"h/r = {h_over_r}, a/r = {a_over_r:.4f}: "
             f"K/K_cyl = {K_over_Kcyl:.7f}")
plt.show()
