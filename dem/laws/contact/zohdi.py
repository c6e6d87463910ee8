"""The contact material of Zohdi 2014 (eqs. 2-21 and Sec. 7) and the parameters of its implicit stepping (eqs.
22-30, 45-49).

:class:`ZohdiMaterial` holds the material in SI units, named by the paper's symbols; :meth:`ZohdiMaterial.params`
packs it into the float64 array the compiled kernels take (indices ``Z_*``). :class:`ZohdiStepping` holds the
parameters of the adaptive trapezoidal fixed-point scheme. No compiler is needed here.

Units (Sec. 7 states them: "K_po = 10^7 N/m^2"): the contact force ``K_p |E|^p_p A_c`` is in newtons with the
contact area ``A_c`` in m^2 and the strain ``E`` dimensionless, so ``K_p``, ``K_w`` and ``K_b`` are in N/m^2 (Pa).
Temperatures are absolute (K): the softening ``K = max(K_0 (1 - theta/theta*), K_lim)`` of Sec. 7 needs theta = 0
to mean absolute zero.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from dem.laws.fields import check_fields

# Indices into ZohdiMaterial.params()
Z_KP = 0           # K_p0, particle-particle contact stiffness, cold (N/m^2, eq. 2)
Z_PP = 1           # p_p, exponent of the particle contact law (eq. 2)
Z_KP_LIM = 2       # K_p^lim, the softened floor (N/m^2, Sec. 7)
Z_KW = 3           # K_w0, particle-wall stiffness, cold (N/m^2, eq. 13)
Z_PW = 4           # p_w (eq. 13)
Z_KW_LIM = 5       # K_w^lim (N/m^2, Sec. 7)
Z_THETA_STAR = 6   # theta*, the softening temperature (K, Sec. 7)
Z_KB = 7           # K_b, bond stiffness (N/m^2, eq. 19)
Z_PB = 8           # p_b (eq. 19)
Z_E_STAR = 9       # E*, the critical interpenetration that activates a bond (eqs. 18-19)
Z_MU = 10          # mu_d, dynamic friction, particles and walls (eqs. 5, 16)
Z_C_ENV = 11       # c_env^o: drag c_env = c_env^o 6 pi R (kg/(m s), eq. 20 and Sec. 7)
Z_V_SLIP = 12      # regularisation speed of the friction direction (m/s)
Z_DENSITY = 13     # particle density (kg/m^3)
N_ZPARAMS = 14
LEAST_FACTOR = 0.05  # the step factor Phi never goes below this (one restart shrinks the step at most 20 x)

_POSITIVE = {"K_p": "N/m^2", "p_p": "", "K_w": "N/m^2", "p_w": "", "theta_star": "K", "p_b": "", "v_slip": "m/s",
             "density": "kg/m^3"}
_NONNEGATIVE = {"K_p_lim": "N/m^2", "K_w_lim": "N/m^2", "K_b": "N/m^2", "E_star": "", "mu_d": "", "c_env": "kg/(m s)"}


@dataclass(frozen=True)
class ZohdiMaterial:
    """The contact material of Zohdi 2014 (paper's symbols; SI units; module docstring).

    Normal contact ``K_p |E_ij|^p_p A_ij`` (eqs. 2-12, ``E_ij = (|r_i - r_j| - (R_i + R_j)) / (R_i + R_j)``, the lens
    area ``A_ij = pi (R_i^2 - L_i^2)``); wall contact ``K_w |E_iw|^p_w A_i`` (eqs. 13-15, ``E_iw`` the overlap over
    the radius, ``A_i`` the circle the wall cuts from the sphere); thermal softening ``K = max(K_0 (1 -
    theta/theta*), K_lim)`` (Sec. 7; for a pair, theta is the mean of the two); an adhesive bond ``K_b |E_ij|^p_b
    A_ij`` (eq. 19), activated once ``|E_ij| >= E_star`` and kept while the particles touch; sliding friction
    ``mu_d |F_con|`` against the relative velocity (eqs. 5-6; against the tangential one at a wall, eqs. 16-17),
    its direction regularised below ``v_slip``; drag ``-c_env 6 pi R v`` (eq. 20, Sec. 7); ``density``.
    """

    K_p: float
    p_p: float
    K_p_lim: float
    K_w: float
    p_w: float
    K_w_lim: float
    theta_star: float
    K_b: float
    p_b: float
    E_star: float
    mu_d: float
    c_env: float
    v_slip: float
    density: float

    law = "zohdi"

    def __post_init__(self):
        check_fields(self, "contact", _POSITIVE, _NONNEGATIVE)
        for cold, floor in (("K_p", "K_p_lim"), ("K_w", "K_w_lim")):
            if getattr(self, floor) > getattr(self, cold):
                raise ValueError(f"contact.{floor} = {getattr(self, floor)!r}: must be <= {cold} = "
                                 f"{getattr(self, cold)!r} N/m^2 (the softened stiffness never exceeds the cold one)")

    def params(self) -> np.ndarray:
        """The material as the float64 array the kernels take (indices ``Z_*`` of this module)."""
        out = np.empty(N_ZPARAMS)
        out[Z_KP], out[Z_PP], out[Z_KP_LIM] = self.K_p, self.p_p, self.K_p_lim
        out[Z_KW], out[Z_PW], out[Z_KW_LIM] = self.K_w, self.p_w, self.K_w_lim
        out[Z_THETA_STAR], out[Z_KB], out[Z_PB], out[Z_E_STAR] = self.theta_star, self.K_b, self.p_b, self.E_star
        out[Z_MU], out[Z_C_ENV], out[Z_V_SLIP], out[Z_DENSITY] = self.mu_d, self.c_env, self.v_slip, self.density
        return out

    def stiffness(self, theta, wall: bool = False):
        """``max(K_0 (1 - theta/theta*), K_lim)`` (Sec. 7), N/m^2."""
        k0, floor = (self.K_w, self.K_w_lim) if wall else (self.K_p, self.K_p_lim)
        return np.maximum(k0 * (1.0 - np.asarray(theta, dtype=float) / self.theta_star), floor)


@dataclass(frozen=True)
class ZohdiStepping:
    """The implicit scheme of Zohdi 2014: trapezoidal weight ``phi`` (eqs. 22-24; 0 explicit, 1/2 the trapezoid, 1
    backward), the fixed-point iteration within a step to ``tolerance`` (TOL of eqs. 47-48, for positions and
    temperatures) in a target of ``iterations`` (K_d) iterations, the exponent ``order`` (p of eq. 30, 2 for this
    second-order system), the first step ``dt`` and its upper bound ``dt_max`` (Delta t_lim) and, beyond the paper,
    bounds on the step factor Phi: an accepted step grows by at most ``growth`` (>= 1), a restart shrinks it by at
    least ``shrink`` (in [LEAST_FACTOR, 1)) and at most :data:`LEAST_FACTOR` -- eq. (30) assumes the error falls as
    ``(S dt^p)^K``; where an iteration stalls instead (a force that is steep in the velocity, such as friction below
    ``v_slip``), Phi of a failed step is close to 1 and the restarts would creep -- and a floor ``dt_min`` below
    which a step that cannot converge stops the run."""

    dt: float
    dt_max: float
    phi: float = 0.5
    iterations: int = 10
    tolerance: float = 5e-4
    order: float = 2.0
    growth: float = 1.25
    shrink: float = 0.5
    dt_min: float = 1e-9

    def __post_init__(self):
        def bad(name, rule):
            raise ValueError(f"[solver] {name} = {getattr(self, name)!r}: {rule}")

        for f in fields(self):
            value = getattr(self, f.name)
            if (not isinstance(value, (int, float, np.floating, np.integer)) or isinstance(value, bool)
                    or not math.isfinite(value)):
                bad(f.name, "must be a finite number")
        if not 0.0 <= self.phi <= 1.0:
            bad("phi", "must be in [0, 1] (the trapezoidal weight of Zohdi 2014, eq. 22)")
        if not isinstance(self.iterations, (int, np.integer)) or self.iterations < 2:
            bad("iterations", "must be an integer >= 2 (K_d, the target number of fixed-point iterations, eq. 30: "
                "the first iterate's relative change is 1 by construction, so one iteration never meets a tolerance)")
        if self.tolerance <= 0.0:
            bad("tolerance", "must be > 0 (TOL of the fixed-point iteration, eqs. 47-48)")
        if self.order <= 0.0:
            bad("order", "must be > 0 (p of eq. 30; 2 for a second-order system)")
        if self.dt <= 0.0:
            bad("dt", "must be > 0 (s, the first step)")
        if self.dt_max < self.dt:
            bad("dt_max", f"must be >= dt = {self.dt!r} s (the upper bound Delta t_lim of the step)")
        if self.growth < 1.0:
            bad("growth", "must be >= 1 (the largest factor by which a step may grow)")
        if not LEAST_FACTOR <= self.shrink < 1.0:
            bad("shrink", f"must be in [{LEAST_FACTOR}, 1) (a restarted step shrinks at least by this factor)")
        if not 0.0 < self.dt_min <= self.dt:
            bad("dt_min", f"must be in (0, dt = {self.dt!r}] s")

    def factor(self, error: float, K: int) -> float:
        """The step factor Phi_K of eq. (30) / Algorithm 1 (4c) for the relative iteration error ``error`` after
        ``K`` iterations: ``(TOL/D0)^(1/(p K_d)) / (D_K/D0)^(1/(p K))`` with ``D0 = 1`` (the first iterate's relative
        change is 1 by construction), clipped to ``[LEAST_FACTOR, growth]``."""
        if error <= 0.0:
            return self.growth
        p = self.order
        phi = self.tolerance ** (1.0 / (p * self.iterations)) / error ** (1.0 / (p * K))
        return min(self.growth, max(LEAST_FACTOR, phi))

    def restart_factor(self, phi: float) -> float:
        """The factor of a restarted step: Phi_K, but at least ``shrink`` and at most :data:`LEAST_FACTOR`."""
        return max(LEAST_FACTOR, min(phi, self.shrink))
