"""
The FE-fitted law inside a DEM scene
====================================

A steady chain of four copper particles between 100 °C and 0 °C.

``law="fit"`` gives every pipe half kappa pi r_i f(a/r_i) from the fit shipped in ``fem_neck/data/fit.json`` (or the
one ``python -m fem_neck fit`` wrote: ``conductance=ConductanceSpec(law="fit", fit_file=...)``).
"""

import matplotlib.pyplot as plt
import numpy as np

from dem import make_scene, run

radius = np.array([1.0e-3, 1.5e-3, 1.0e-3, 2.0e-3])  # m
overlap = 0.1 * np.minimum(radius[:-1], radius[1:])  # h = 0.1 r_min per bond
z = np.concatenate([[0.0], np.cumsum(radius[:-1] + radius[1:] - overlap)])
position = np.column_stack([np.zeros(4), np.zeros(4), z])

result = run(make_scene(position, radius, [100.0, 0.0, 0.0, 0.0],
                        fixed=[True, False, False, True], law="fit",
                        mode="steady"))
# W leaving the hot end particle into the chain
Q = -result.summary["boundary_heat_flow"]["particles"]["0"]
K_chain = Q / 100.0  # W/K
print(f"T = {np.round(result.T, 3)} C; heat flow {Q:.4f} W; "
      f"chain conductance {K_chain:.6f} W/K "
      f"(pipes {np.round(result.thermal.K_pairs, 5)} W/K)")

# %%
# Each particle is one temperature (lumped), drawn over its extent along the chain; the drops are at the necks.
fig, ax = plt.subplots(figsize=(6.4, 4), layout="constrained")
for k, (z_k, r_k, T_k) in enumerate(zip(z, radius, result.T)):
    ax.plot([(z_k - r_k) * 1e3, (z_k + r_k) * 1e3], [T_k, T_k], lw=3,
            label=f"particle {k}, r = {r_k * 1e3:g} mm")
ax.set_xlabel("position along the chain z (mm)")
ax.set_ylabel("particle temperature T (°C)")
ax.set_title(f"steady chain, fit law: K = {K_chain:.6f} W/K")
ax.legend()
plt.show()
