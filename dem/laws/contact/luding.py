"""The sintering contact material of Luding, Manetsberger & Müllers 2005 and the time step it needs.

:class:`LudingMaterial` holds the material (SI units); :meth:`LudingMaterial.params` packs it into the float64 array
that every kernel of :mod:`dem.laws.contact.luding_kernels` takes as ``params`` (indices ``P_*`` below). This module needs
no compiler: a scene that only reads the material (or runs no mechanics) never loads numba.

Conventions (Luding 2005, Sec. 3.1): the unit normal ``n`` points from particle j to particle i (eq. 3), the overlap
``delta = a_i + a_j - |r_i - r_j|`` is positive in contact, ``delta_dot = d delta/dt`` is positive while the
particles approach, and every force returned is the force **on particle i** (on j it is the opposite):
``F_i = f_n n + f_t``. For a wall contact the wall plays j (no radius, no spin; ``mu_wall``; the particle's
k1(T, t)). Temperatures only enter as differences (T - T_melt), so °C and K both work.

Stiffness history is carried as the dimensionless factor ``s = k1(T, t)/k1`` (eq. 10-12): ``k1(T, t) = s k1``.
Each contact stores ``delta_max`` (eq. 4), the factor it saw at its previous step (Fig. 5: heating keeps
``delta_max``, cooling keeps ``delta_0``) and the tangential spring ``xi`` (eq. 16-21).

The fluid overlap of a contact (Sec. 3.1.3) is ``delta_fluid = fluid_overlap * 2 R_eff`` for a pair,
``R_eff = a_i a_j/(a_i + a_j)`` (``fluid_overlap * a`` for equal radii; :func:`pair_delta_fluid`), and
``fluid_overlap * a_i`` for a particle-wall contact. Its history limit is ``delta_max_fluid = k2 delta_fluid/(k2 -
k1)`` with the constant cold-limit k1 (eq. 7: k2 is not changed directly when k1(T) falls).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from dem.laws.fields import check_fields

# Indices into LudingMaterial.params()
P_K1 = 0               # k1, loading stiffness, cold limit (N/m)
P_K2 = 1               # k2, maximal un/reloading stiffness (N/m)
P_KC = 2               # kc, cohesion stiffness, cold limit (N/m)
P_KT_RATIO = 3         # alpha = k_t / k2(delta_max) (eq. 23)
P_GAMMA_N = 4          # gamma_0, normal viscous damping (kg/s, eq. 5)
P_GAMMA_T = 5          # gamma_t, tangential viscous damping (kg/s, eq. 19)
P_MU = 6               # particle-particle friction, cold limit (eq. 14, 24)
P_MU_WALL = 7          # particle-wall friction, cold limit
P_T_MELT = 8           # melting temperature (eq. 10)
P_T_VAR = 9            # width of the melting range (eq. 10)
P_EXPANSION = 10       # delta a_T, relative radius change per unit temperature (1/K, eq. 9)
P_FLUID_OVERLAP = 11   # delta_fluid / a (Sec. 3.1.3)
P_T0 = 12              # relaxation time of k1(T, t) (s, eq. 11-12)
P_BRITTLE_SLIDING = 13  # 1.0: no cohesion while sliding (footnote 5), 0.0: cohesion kept
P_DENSITY = 14         # particle density (kg/m^3)
N_PARAMS = 15

_NONNEGATIVE = {"kc": "N/m", "kt_ratio": "", "gamma_n": "kg/s", "gamma_t": "kg/s", "mu": "", "mu_wall": "",
                "expansion": "1/K"}
_POSITIVE = {"k1": "N/m", "k2": "N/m", "T_var": "K", "t0": "s", "density": "kg/m^3"}


@dataclass(frozen=True)
class LudingMaterial:
    """Material of the Luding 2005 contact law (SI units; temperatures in °C or K, only differences matter).

    ``k1`` loading stiffness and ``kc`` cohesion stiffness in the cold limit, ``k2`` the largest un/reloading
    stiffness (eq. 4, 7); ``kt_ratio`` alpha = k_t/k2(delta_max) (eq. 23); ``gamma_n`` gamma_0 (eq. 5) and
    ``gamma_t`` (eq. 19) viscous damping; ``mu``, ``mu_wall`` friction coefficients in the cold limit (eq. 14, 24);
    ``T_melt``, ``T_var`` of k1(T) (eq. 10); ``expansion`` delta a_T (eq. 9); ``fluid_overlap`` phi =
    delta_fluid/a (Sec. 3.1.3); ``t0`` the relaxation time of k1(T, t) (eq. 11-12); ``brittle_sliding``: a sliding
    contact keeps no cohesion, f_n >= 0 (footnote 5); ``density`` of the particles.
    """

    k1: float
    k2: float
    kc: float
    kt_ratio: float
    gamma_n: float
    gamma_t: float
    mu: float
    mu_wall: float
    T_melt: float
    T_var: float
    expansion: float
    fluid_overlap: float
    t0: float
    brittle_sliding: bool
    density: float

    law = "luding"

    def __post_init__(self):
        check_fields(self, "contact", _POSITIVE, _NONNEGATIVE, flags=("brittle_sliding",))
        if self.k1 > self.k2:
            raise ValueError(f"contact.k1 = {self.k1!r}: must be <= k2 = {self.k2!r} N/m (Luding 2005, eq. 4: "
                             f"plastic loading is no stiffer than un/reloading)")
        if not 0.0 < self.fluid_overlap < 1.0:
            raise ValueError(f"contact.fluid_overlap = {self.fluid_overlap!r}: must be in (0, 1) "
                             f"(delta_fluid / radius; Luding 2005 uses 0.2)")

    def params(self) -> np.ndarray:
        """The material as the float64 array the kernels take (indices ``P_*`` of this module)."""
        out = np.empty(N_PARAMS)
        out[P_K1], out[P_K2], out[P_KC], out[P_KT_RATIO] = self.k1, self.k2, self.kc, self.kt_ratio
        out[P_GAMMA_N], out[P_GAMMA_T], out[P_MU], out[P_MU_WALL] = self.gamma_n, self.gamma_t, self.mu, self.mu_wall
        out[P_T_MELT], out[P_T_VAR], out[P_EXPANSION] = self.T_melt, self.T_var, self.expansion
        out[P_FLUID_OVERLAP], out[P_T0], out[P_DENSITY] = self.fluid_overlap, self.t0, self.density
        out[P_BRITTLE_SLIDING] = 1.0 if self.brittle_sliding else 0.0
        return out

    @property
    def lowest_temperature(self) -> float:
        """Where the radius of eq. (9) reaches zero, ``T_melt - 1/expansion`` (-inf without expansion)."""
        return self.T_melt - 1.0 / self.expansion if self.expansion > 0 else -math.inf

    def check_temperatures(self, T, name: str = "T") -> None:
        """Raise ``ValueError`` if a temperature lies at or below :attr:`lowest_temperature`, where eq. (9)
        gives a radius <= 0 (the linear expansion law no longer holds)."""
        T = np.asarray(T, dtype=float)
        bad = np.flatnonzero(T <= self.lowest_temperature)
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"{name}[{k}] = {float(T.flat[k])!r}: must be > T_melt - 1/expansion = "
                             f"{self.lowest_temperature:.6g} (below it the radius a(T) of Luding 2005, eq. 9, is <= 0)")


# Luding 2005, Table 1 (Sec. 4): k2 = 2e5 N/m, k1/k2 = kc/k2 = 0.5, k_t/k2 = 0.2, gamma_0 = 0.2 kg/s,
# gamma_t = 0.05 kg/s, mu = 0.5, mu_w = 0, T_melt = 120 °C, T_var = 10 K, delta a_T = 1e-4 /K,
# delta_fluid/a0 = 0.2, t0 = 1e3 s (default; 0.1 s during sintering), rho = 2000 kg/m^3; f_n >= 0 while sliding
# (footnote 5: "In this study we assume ... f^n >= 0, (if sliding)").
LUDING_TABLE1 = LudingMaterial(k1=1.0e5, k2=2.0e5, kc=1.0e5, kt_ratio=0.2, gamma_n=0.2, gamma_t=0.05, mu=0.5,
                               mu_wall=0.0, T_melt=120.0, T_var=10.0, expansion=1.0e-4, fluid_overlap=0.2, t0=1.0e3,
                               brittle_sliding=True, density=2000.0)


def time_step(k2: float, gamma_n: float, m_min: float) -> float:
    """``t_MD = pi/(50 omega)``, ``omega = sqrt(k2/m12 - eta0^2)``, ``eta0 = gamma_0/(2 m12)`` (Luding 2005,
    eq. 6 and below) for the smallest reduced mass ``m_min = m12`` (kg) of any contact; k2 is the largest
    stiffness. Overcritical damping (omega^2 <= 0) is refused."""
    if not (math.isfinite(m_min) and m_min > 0):
        raise ValueError(f"m_min = {m_min!r}: must be a finite reduced mass > 0 (kg)")
    eta0 = gamma_n / (2.0 * m_min)
    omega2 = k2 / m_min - eta0 * eta0
    if not omega2 > 0:
        raise ValueError(f"contact.gamma_n = {gamma_n!r}: the normal damping is overcritical for the smallest reduced "
                         f"mass m12 = {m_min:.6g} kg (k2/m12 - (gamma_n/(2 m12))^2 = {omega2:.6g} <= 0, Luding 2005, "
                         f"eq. 6); must be < 2 sqrt(k2 m12) = {2.0 * math.sqrt(k2 * m_min):.6g} kg/s")
    return math.pi / (50.0 * math.sqrt(omega2))
