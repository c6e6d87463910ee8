"""The semisphere with a neck (Rojek 2022, Fig. 12): FE conductance against the 12-digit reference.

A sphere of radius r sintered to its mirror image with overlap h: by symmetry, half of the pair is a semisphere with
a half neck, T fixed on its equatorial disk and on the neck's mid-plane. K/K_cyl (K_cyl = kappa pi r) depends on
a/r only.
"""

from fem_neck.conduction import semisphere_conductance
from fem_neck.geometry import equal_neck_radius
from verification.cases import SEMISPHERE_BY_H

h_over_r = 0.08
a_over_r = float(equal_neck_radius(1.0, h_over_r))  # volume-conserving neck, eqs. 19-20
result = semisphere_conductance(a_over_r, rtol=1e-6)  # hp elements, order raised until two orders agree to rtol
K_over_Kcyl = result.K_over_Kcyl

reference = SEMISPHERE_BY_H[h_over_r].K_over_Kcyl
print(f"a/r = {a_over_r:.9f}: K/K_cyl = {K_over_Kcyl:.10f} (estimate {result.error_estimate:.1e}), "
      f"reference {reference:.12f}, error {abs(K_over_Kcyl / reference - 1):.1e}")
