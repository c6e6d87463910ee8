"""Effective conductivity of a random sintered packing between a hot and a cold plate (steady DEM).

The scene is the dict form of a TOML scene file (``python -m dem run FILE.toml`` reads the same keys).
"""

from dem import parse_scene, run

scene = parse_scene({
    "material": {"conductivity": 394.0, "density": 8960.0, "specific_heat": 385.0},  # copper, SI
    "generator": {"kind": "random", "n": 2000, "radius": 5.0e-5, "radius_spread": 0.1, "overlap": 0.1,
                  "seed": 1, "boundary": "plates", "hot": 1.0, "cold": 0.0},
    "conductance": {"law": "fit"},
    "solver": {"mode": "steady", "floating": "mean"},  # particles without bonds keep their initial temperature
})
result = run(scene)
k_eff = result.summary["effective_conductivity"]  # Q L / (A dT), W/(m K)
print(f"{result.summary['particles']} particles, {result.summary['bonds']} bonds: k_eff = {k_eff:.3f} W/(m K), "
      f"{k_eff / 394.0:.4f} of solid copper")
