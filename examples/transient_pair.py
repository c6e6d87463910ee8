"""Two copper particles equalising their temperatures (Rojek 2022, Sec. 6 pair), against the closed form.

The lumped pair obeys d(T_i - T_j)/dt = -K (1/C_i + 1/C_j) (T_i - T_j), so the difference decays as
exp(-lambda t). Crank-Nicolson with error-controlled steps (``dt="auto"``, ``rtol``) follows it.
"""

import numpy as np

from dem import make_scene, run

position = [[0.0, 0.0, 0.0], [0.0, 0.0, 3.94e-3]]  # m: r = 1 and 3 mm, overlap 0.06 mm
radius = [1.0e-3, 3.0e-3]
result = run(make_scene(position, radius, [100.0, 0.0], law="rojek", mode="transient", integrator="crank-nicolson",
                        dt="auto", rtol=1e-4, t_end=0.1))
T_i, T_j = result.T

K = result.thermal.K_pairs[0]  # W/K
C = result.thermal.network.particles.capacity  # J/K, rho 4/3 pi r^3 c
rate = K * (1.0 / C[0] + 1.0 / C[1])
exact = 100.0 * np.exp(-rate * 0.1)
difference_error = abs((T_i - T_j) - exact) / 100.0
print(f"t = 0.1 s: T = {T_i:.5f}, {T_j:.5f} C; T_i - T_j = {T_i - T_j:.5f} (closed form {exact:.5f}), "
      f"{result.summary['steps']} steps, energy error {result.summary['energy_error']:.0e}")
