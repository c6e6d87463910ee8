"""
Three neck models
=================

Rojek 2022, Figs. 10 and 11: the volume-conserving cylindrical neck of two spheres (Newton on eq. 27) against
Coble's neck (eqs. 11-12) and the first Newton iterate (eq. 34), for radius ratios r_j/r_i from 1 to 10, each up to
the model's largest overlap (where the neck reaches the smaller radius).
"""

import matplotlib.pyplot as plt
import numpy as np

from fem_neck import max_overlap, neck_radius

# Section 4.3, Fig. 9: r_i = 1 mm, r_j = 3 mm, h = 0.2 mm
# (the paper: a = 0.741466 mm, Coble 0.774597 mm, first iterate 0.745039 mm)
a = neck_radius(1e-3, 3e-3, 0.2e-3)
a_coble = neck_radius(1e-3, 3e-3, 0.2e-3, method="coble")
a_first = neck_radius(1e-3, 3e-3, 0.2e-3, method="first")
coble_error = a_coble / a - 1
print(f"a = {a * 1e3:.6f} mm, "
      f"Coble {a_coble * 1e3:.6f} mm ({coble_error:+.2%}), "
      f"first iterate {a_first * 1e3:.6f} mm ({a_first / a - 1:+.2%})")

# %%
# Figs. 10 and 11: the neck against the overlap, and how far Coble's neck and the first iterate are from it.
r_i = 1e-3  # m
fig, (ax_a, ax_err) = plt.subplots(1, 2, figsize=(10, 4.2),
                                   layout="constrained")
for ratio in (1, 2, 3, 5, 10):
    r_j = ratio * r_i
    h = np.linspace(1e-3, 1.0, 300) * max_overlap(r_i, r_j)  # m, to the limit
    a_newton = neck_radius(r_i, r_j, h)
    coble = neck_radius(r_i, r_j, h, method="coble")
    first = neck_radius(r_i, r_j, h, method="first")
    line, = ax_a.plot(h * 1e3, a_newton * 1e3, label=f"r_j/r_i = {ratio}")
    colour = line.get_color()
    ax_a.plot(h * 1e3, coble * 1e3, ":", color=colour)
    ax_err.plot(a_newton / r_i, 100 * (coble / a_newton - 1), color=colour,
                label=f"r_j/r_i = {ratio}")
    ax_err.plot(a_newton / r_i, 100 * (first / a_newton - 1), "--",
                color=colour)
ax_a.set(xlabel="overlap h (mm)", ylabel="neck radius a (mm)",
         title="volume-conserving (solid) and Coble (dotted), r_i = 1 mm")
ax_a.legend(fontsize=8)
ax_err.set(xlabel="neck radius over the smaller radius a/r_i (–)",
           ylabel="model / volume-conserving − 1 (%)",
           title="Coble (solid) and the first Newton iterate (dashed)")
ax_err.legend(fontsize=8)
plt.show()
