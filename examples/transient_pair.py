"""
Two particles equalising their temperatures
===========================================

The copper pair of Rojek 2022, Sec. 6 (r = 1 and 3 mm, h = 0.06 mm), 100 °C and 0 °C at t = 0, against the closed
form.

The lumped pair obeys d(T_i - T_j)/dt = -K (1/C_i + 1/C_j) (T_i - T_j), so the difference decays as
exp(-lambda t). Crank-Nicolson with error-controlled steps (``dt="auto"``, ``rtol``) follows it; the run's
``timeseries.csv`` holds every step.
"""

import pathlib
import tempfile

import matplotlib.pyplot as plt
import numpy as np

from dem import make_scene, run

# m: r = 1 and 3 mm, overlap 0.06 mm
position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]
radius = [1.0e-3, 3.0e-3]
# the run's folder: summary.json, timeseries.csv, VTU, plots
out = pathlib.Path(tempfile.mkdtemp()) / "transient_pair"
result = run(make_scene(position, radius, [100.0, 0.0], law="rojek",
                        mode="transient", integrator="crank-nicolson",
                        dt="auto", rtol=1e-4, t_end=0.1), out=out)
T_i, T_j = result.T

K = result.thermal.K_pairs[0]  # W/K
C = result.thermal.network.particles.capacity  # J/K, rho 4/3 pi r^3 c
rate = K * (1.0 / C[0] + 1.0 / C[1])
exact = 100.0 * np.exp(-rate * 0.1)
difference_error = abs((T_i - T_j) - exact) / 100.0
print(f"t = 0.1 s: T = {T_i:.5f}, {T_j:.5f} C; "
      f"T_i - T_j = {T_i - T_j:.5f} (closed form {exact:.5f}), "
      f"{result.summary['steps']} steps, "
      f"energy error {result.summary['energy_error']:.0e}")

# %%
# Every step of the run against the closed form (the small particle is the hotter one: T_max).
steps = np.genfromtxt(out / "timeseries.csv", delimiter=",", names=True)
t = np.linspace(0.0, 0.1, 400)
# the capacity-weighted mean temperature, conserved
mean = (C[0] * 100.0) / (C[0] + C[1])
decay = 100.0 * np.exp(-rate * t) / (C[0] + C[1])
fig, ax = plt.subplots(figsize=(6.4, 4.2), layout="constrained")
ax.plot(t * 1e3, mean + C[1] * decay, "k-", lw=1, label="closed form")
ax.plot(t * 1e3, mean - C[0] * decay, "k-", lw=1)
ax.plot(steps["t"] * 1e3, steps["T_max"], "o", ms=4,
        label="r = 1 mm (Crank-Nicolson steps)")
ax.plot(steps["t"] * 1e3, steps["T_min"], "s", ms=4,
        label="r = 3 mm (Crank-Nicolson steps)")
ax.set_xlabel("time t (ms)")
ax.set_ylabel("particle temperature T (°C)")
ax.set_title(f"{result.summary['steps']} error-controlled steps, rtol = 1e-4")
ax.legend()
plt.show()
