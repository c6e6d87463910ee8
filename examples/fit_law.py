"""
The conductance fit and the full-range law
==========================================

Rojek 2022, Fig. 16 and eq. 40 from 40 hp solves of the semisphere with a neck (what ``python -m fem_neck fit``
runs, here in this process): the linear fit on a/r <= 0.7, the paper's slope and Argento & Bouvard's (eq. 42), and
the full-range law that honours the constriction limit K -> 4 kappa a of small necks and K/K_cyl = 3/2 at a = r.
"""

import matplotlib.pyplot as plt
import numpy as np

from fem_neck.fit import fit_law, linear_slope, sweep, sweep_points
from fem_neck.law import ARGENTO_BOUVARD, ROJEK

# 5 log-spaced small necks, 35 uniform in a/r on (0, 0.97] as Fig. 16
a_over_r, on_grid = sweep_points(40)
# each K/K_cyl to 1e-4
points = sweep(a_over_r, on_grid, rtol=1e-4, workers=1, progress=False)
x = np.array([p.a_over_r for p in points])
f = np.array([p.K_over_Kcyl for p in points])
uniform = np.array([p.uniform for p in points])

# least squares through the origin on a/r <= 0.7 (eq. 40)
slope = linear_slope(x[uniform], f[uniform])
law = fit_law(x, f)  # B, C, E fitted; A = 5/(4 pi) derived
low, high = law.fit_range
print(f"slope {slope:.4f} (Rojek 2022: {ROJEK.slope}, "
      f"Argento & Bouvard: {ARGENTO_BOUVARD.slope:.3f}); "
      f"full-range law B = {law.B:.5f}, C = {law.C:.5f}, E = {law.E:.5f}, "
      f"within {law.max_rel_residual:.1e} of the FE over "
      f"{low} <= a/r <= {high}")

# %%
# The Fig. 16 analogue: the FE points and the laws; below, each law against the FE.
xs = np.linspace(0.0, 1.0, 401)
fig, (ax, ax_dev) = plt.subplots(2, 1, figsize=(6.4, 7), height_ratios=(3, 2),
                                 layout="constrained")
ax.plot(x, f, "o", ms=4, mfc="none", color="k",
        label="FE, semisphere with a neck")
ax.plot(xs, law.k_over_kcyl(xs), "-", label="full-range law")
ax.plot(xs, slope * xs, "--", label=f"linear fit, c = {slope:.4f}")
ax.plot(xs, ROJEK.slope * xs, ":",
        label=f"Rojek 2022 eq. 40, c = {ROJEK.slope}")
ax.plot(xs, ARGENTO_BOUVARD.slope * xs, "-.",
        label=f"Argento & Bouvard eq. 42, c = {ARGENTO_BOUVARD.slope:.3f}")
ax.plot(xs[:120], 4 / np.pi * xs[:120], lw=0.8, color="grey",
        label="constriction limit (4/π) a/r")
ax.set(xlabel="neck radius over particle radius a/r (–)",
       ylabel="conductance K/K_cyl (–)", xlim=(0, 1), ylim=(0, 1.6))
ax.legend(fontsize=8)
ax_dev.plot(x, 100 * (law.k_over_kcyl(x) / f - 1), "o-", ms=3,
            label="full-range law")
ax_dev.plot(x, 100 * (ROJEK.slope * x / f - 1), "s:", ms=3,
            label="Rojek 2022 eq. 40")
ax_dev.axhline(0.0, color="k", lw=0.5)
ax_dev.set(xscale="log", xlabel="neck radius over particle radius a/r (–)",
           ylabel="model / FE − 1 (%)")
ax_dev.legend(fontsize=8)
plt.show()
