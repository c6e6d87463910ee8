"""
Effective conductivity of a random packing
==========================================

A random sintered copper packing between a hot and a cold plate (steady DEM): its effective conductivity and every
particle's temperature against its height.

The scene is the dict form of a TOML scene file (``python -m dem run FILE.toml`` reads the same keys).
"""

import matplotlib.pyplot as plt

from dem import parse_scene, run

scene = parse_scene({
    "material": {"conductivity": 394.0, "density": 8960.0,
                 "specific_heat": 385.0},  # copper, SI
    "generator": {"kind": "random", "n": 2000, "radius": 5.0e-5,
                  "radius_spread": 0.1, "overlap": 0.1, "seed": 1,
                  "boundary": "plates", "hot": 1.0, "cold": 0.0},
    "conductance": {"law": "fit"},
    # particles without bonds keep their initial temperature
    "solver": {"mode": "steady", "floating": "mean"},
})
result = run(scene)
k_eff = result.summary["effective_conductivity"]  # Q L / (A dT), W/(m K)
n = result.summary["particles"]
print(f"{n} particles, {result.summary['bonds']} bonds: "
      f"k_eff = {k_eff:.3f} W/(m K), {k_eff / 394.0:.4f} of solid copper")

# %%
# Every particle's temperature against its height between the plates (hot below, cold above).
height_mm = result.thermal.network.particles.position[:, 2] * 1e3
fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
ax.plot(height_mm, result.T, ".", ms=3, alpha=0.5)
ax.set_xlabel("height z (mm)")
ax.set_ylabel("particle temperature T (K above the cold plate)")
ax.set_title(f"{n} particles: k_eff = {k_eff:.1f} W/(m K)")
plt.show()
