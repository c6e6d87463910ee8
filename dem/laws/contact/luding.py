"""The sintering contact law of Luding, Manetsberger & Müllers 2005: its material, the time step it needs, its compiled
kernels, and the plug-in functions through which the engines' compiled loops use it.

:class:`LudingMaterial` holds the material (SI units); :meth:`LudingMaterial.params` packs it into the float64 array
that every kernel takes as ``params`` (indices ``P_*`` below; the loops pass the same numbers as a tuple). The kernels
are ``numba.njit(cache=True)`` functions of plain floats and 3-tuples, called per contact from the compiled loops
(which get them inlined) and, unchanged, from Python (the contact-law tool ``python -m dem contact`` and the tests).

Conventions (Luding 2005, Sec. 3.1): the unit normal ``n`` points from particle j to particle i (eq. 3), the overlap
``delta = a_i + a_j - |r_i - r_j|`` is positive in contact, ``delta_dot = d delta/dt`` is positive while the
particles approach, and every force returned is the force **on particle i** (on j it is the opposite):
``F_i = f_n n + f_t``. For a wall contact the wall plays j (no radius, no spin; ``mu_wall``; the particle's
k1(T, t), or with ``wall_sintering`` off the cold-limit k1). Temperatures only enter as differences (T - T_melt), so °C and K both work.

Stiffness history is carried as the dimensionless factor ``s = k1(T, t)/k1`` (eq. 10-12): ``k1(T, t) = s k1``, a
property of each particle's material (the healing of its defects, ``PARTICLE_STATE``): a contact uses the mean of
its two particles' factors, which for a uniform temperature is exactly the single ``k1(T, t)`` of the paper. Each
contact stores ``delta_max`` (eq. 4), the factor it saw at its previous step (Fig. 5: heating keeps ``delta_max``,
cooling keeps ``delta_0``) and the tangential spring ``xi`` (eq. 16-21): ``PAIR_HISTORY``.

The fluid overlap of a contact (Sec. 3.1.3) is ``delta_fluid = fluid_overlap * 2 R_eff`` for a pair,
``R_eff = a_i a_j/(a_i + a_j)`` (``fluid_overlap * a`` for equal radii; :func:`pair_delta_fluid`), and
``fluid_overlap * a_i`` for a particle-wall contact. Its history limit is ``delta_max_fluid = k2 delta_fluid/(k2 -
k1)`` with the constant cold-limit k1 (eq. 7: k2 is not changed directly when k1(T) falls).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

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
P_WALL_SINTERING = 15  # 1.0: particle-wall contacts take k1(T, t) of the particle, 0.0: the cold-limit k1
N_PARAMS = 16

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
    contact keeps no cohesion, f_n >= 0 (footnote 5); ``density`` of the particles; ``wall_sintering``: a
    particle-wall contact softens and sinters with the particle's k1(T, t) like a pair (true), or keeps the
    cold-limit k1 of a wall that does not melt (false; Luding 2005 gives the walls no law beyond mu_w).

    Parameters
    ----------
    k1 : float
        Plastic loading stiffness in the cold limit (N/m), > 0 and <= ``k2`` (eq. 4).
    k2 : float
        Largest un/reloading stiffness (N/m), > 0 (eq. 7).
    kc : float
        Cohesion stiffness in the cold limit (N/m), >= 0.
    kt_ratio : float
        alpha = k_t / k2(delta_max), the tangential stiffness ratio (eq. 23), >= 0.
    gamma_n : float
        Normal viscous damping gamma_0 (kg/s), >= 0 (eq. 5).
    gamma_t : float
        Tangential viscous damping (kg/s), >= 0 (eq. 19).
    mu : float
        Particle-particle friction coefficient in the cold limit, >= 0 (eq. 14).
    mu_wall : float
        Particle-wall friction coefficient in the cold limit, >= 0 (eq. 24).
    T_melt : float
        Melting temperature of k1(T) (degC or K; eq. 10).
    T_var : float
        Width of the melting transition of k1(T) (K), > 0 (eq. 10).
    expansion : float
        Thermal expansion coefficient delta a_T (1/K), >= 0 (eq. 9).
    fluid_overlap : float
        phi = delta_fluid / a, in ``(0, 1)`` (Sec. 3.1.3).
    t0 : float
        Relaxation time of k1(T, t) (s), > 0 (eqs. 11-12).
    brittle_sliding : bool
        Whether a sliding contact keeps no cohesion, f_n >= 0 (footnote 5).
    density : float
        Particle density (kg/m^3), > 0.
    wall_sintering : bool
        Whether a particle-wall contact softens and sinters with the particle's k1(T, t) like a pair.

    Raises
    ------
    ValueError
        A field is out of its range, or ``k1 > k2``; the message names it (``contact.<field>``).
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
    wall_sintering: bool = True

    law = "luding"

    def __post_init__(self):
        check_fields(self, "contact", _POSITIVE, _NONNEGATIVE, flags=("brittle_sliding", "wall_sintering"))
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
        out[P_WALL_SINTERING] = 1.0 if self.wall_sintering else 0.0
        return out

    @property
    def lowest_temperature(self) -> float:
        """Where the radius of eq. (9) reaches zero, ``T_melt - 1/expansion`` (-inf without expansion)."""
        return self.T_melt - 1.0 / self.expansion if self.expansion > 0 else -math.inf

    def check_temperatures(self, T, name: str = "T") -> None:
        """Raise ``ValueError`` if a temperature lies at or below :attr:`lowest_temperature`, where eq. (9)
        gives a radius <= 0 (the linear expansion law no longer holds).

        Parameters
        ----------
        T : array_like
            Temperatures (degC or K, the unit of ``T_melt``).
        name : str
            The temperatures' name in the message.

        Raises
        ------
        ValueError
            A temperature lies at or below :attr:`lowest_temperature`.
        """
        T = np.asarray(T, dtype=float)
        bad = np.flatnonzero(T <= self.lowest_temperature)
        if bad.size:
            k = int(bad[0])
            raise ValueError(f"{name}[{k}] = {float(T.flat[k])!r}: must be > T_melt - 1/expansion = "
                             f"{self.lowest_temperature:.6g} (below it the radius a(T) of Luding 2005, eq. 9, is <= 0)")


# Luding 2005, Table 1 (Sec. 4): k2 = 2e5 N/m, k1/k2 = kc/k2 = 0.5, k_t/k2 = 0.2, gamma_0 = 0.2 kg/s,
# gamma_t = 0.05 kg/s, mu = 0.5, mu_w = 0, T_melt = 120 °C, T_var = 10 K, delta a_T = 1e-4 /K,
# delta_fluid/a0 = 0.2, t0 = 1e3 s (default; 0.1 s during sintering), rho = 2000 kg/m^3; f_n >= 0 while sliding
# (footnote 5: "In this study we assume ... f^n >= 0, (if sliding)"). The walls of Sec. 4 get only mu_w in the
# paper; here their contacts keep the cold-limit law (wall_sintering = False): only so does the three-particle
# control of Sec. 4.1.3 come near the paper's 8 % at p = 100 (walls that sinter like pairs triple it; python -m
# verification sintering, its isolating runs).
LUDING_TABLE1 = LudingMaterial(k1=1.0e5, k2=2.0e5, kc=1.0e5, kt_ratio=0.2, gamma_n=0.2, gamma_t=0.05, mu=0.5,
                               mu_wall=0.0, T_melt=120.0, T_var=10.0, expansion=1.0e-4, fluid_overlap=0.2, t0=1.0e3,
                               brittle_sliding=True, density=2000.0, wall_sintering=False)


def time_step(k2: float, gamma_n: float, m_min: float) -> float:
    """``t_MD = pi/(50 omega)``, ``omega = sqrt(k2/m12 - eta0^2)``, ``eta0 = gamma_0/(2 m12)`` (Luding 2005,
    eq. 6 and below) for the smallest reduced mass ``m_min = m12`` (kg) of any contact; k2 is the largest
    stiffness. Overcritical damping (omega^2 <= 0) is refused.

    Parameters
    ----------
    k2 : float
        The largest stiffness (N/m).
    gamma_n : float
        Normal viscous damping gamma_0 (kg/s).
    m_min : float
        The smallest reduced mass of any contact (kg), > 0.

    Returns
    -------
    float
        ``t_MD`` (s).

    Raises
    ------
    ValueError
        ``m_min`` is not finite and > 0, or the damping is overcritical.
    """
    if not (math.isfinite(m_min) and m_min > 0):
        raise ValueError(f"m_min = {m_min!r}: must be a finite reduced mass > 0 (kg)")
    eta0 = gamma_n / (2.0 * m_min)
    omega2 = k2 / m_min - eta0 * eta0
    if not omega2 > 0:
        raise ValueError(f"contact.gamma_n = {gamma_n!r}: the normal damping is overcritical for the smallest reduced "
                         f"mass m12 = {m_min:.6g} kg (k2/m12 - (gamma_n/(2 m12))^2 = {omega2:.6g} <= 0, Luding 2005, "
                         f"eq. 6); must be < 2 sqrt(k2 m12) = {2.0 * math.sqrt(k2 * m_min):.6g} kg/s")
    return math.pi / (50.0 * math.sqrt(omega2))


JIT = {"cache": True, "error_model": "numpy"}  # fastmath stays off: the tests compare closely
IN_LOOP = {**JIT, "inline": "always"}  # the kernels of the force loop, inlined there by numba (10 % faster)


@njit(**IN_LOOP)
def pair_delta_fluid(a_i, a_j, fluid_overlap):
    """``delta_fluid = fluid_overlap * 2 a_i a_j/(a_i + a_j)`` of a pair (``fluid_overlap * a`` for equal radii)."""
    return fluid_overlap * 2.0 * a_i * a_j / (a_i + a_j)


# ------------------------------------------------------------------------------------------ temperature, time
@njit(**JIT)
def radius_at(a_melt, T, T_melt, expansion):
    """``a(T) = a(T_melt) [1 - delta a_T (T_melt - T)]`` (Luding 2005, eq. 9)."""
    return a_melt * (1.0 - expansion * (T_melt - T))


@njit(**JIT)
def k1_factor(T, T_melt, T_var):
    """``k1(T)/k1 = [1 + tanh((T_melt - T)/T_var)]/2`` (Luding 2005, eq. 10), evaluated as the equal logistic
    ``1/(1 + exp(-2 tau))``: no cancellation in ``1 + tanh`` far above T_melt, so the factor stays > 0 there."""
    return 1.0 / (1.0 + math.exp(-2.0 * (T_melt - T) / T_var))


@njit(**JIT)
def relax_k1(k1t, k1T, dt, t0, cooling):
    """New factor k1(T, t)/k1 after a step ``dt`` from ``k1t`` towards the target ``k1T = k1(T)/k1``.

    Eq. (12), ``d k/dt = (K - k)|K - k|/(K t0)``, solved exactly over the step from the previous step's value
    (footnote 3) at constant target K: with ``u = 1 - k/K``, ``u_new = u/(1 + |u| dt/t0)`` (eq. 11 is this
    solution for heating). Written as ``k_new = K - d K t0/(K t0 + |d| dt)``, ``d = K - k``: unconditionally
    stable and finite for K -> 0. Cooling with ``K > k`` freezes at once, ``k_new = K`` (end of Sec. 3.4).
    """
    d = k1T - k1t
    if cooling and d > 0.0:
        return k1T
    denominator = k1T * t0 + abs(d) * dt
    if denominator <= 0.0:
        return k1T
    return k1T - d * (k1T * t0) / denominator


# ------------------------------------------------------------------------------------------ normal history
@njit(**JIT)
def delta_max_fluid(delta_fluid, params):
    """``delta_max^fluid = k2 delta_fluid/(k2 - k1)`` (Luding 2005, text above eq. 7; k1 the cold limit)."""
    k1 = params[P_K1]
    k2 = params[P_K2]
    return k2 * delta_fluid / (k2 - k1)


@njit(**IN_LOOP)
def k2_of_delta_max(delta_max, delta_fluid, params):
    """``k2(delta_max)`` (Luding 2005, eq. 7): ``k1 + (k2 - k1) delta_max/delta_max^fluid`` below the fluid
    limit, ``k2`` at and above it."""
    k1 = params[P_K1]
    k2 = params[P_K2]
    x = (k2 - k1) * delta_max  # delta_max >= delta_max^fluid  <=>  x >= k2 delta_fluid (one division, none if k1 = k2)
    if x >= k2 * delta_fluid:
        return k2
    return k1 + (k2 - k1) * x / (k2 * delta_fluid)


@njit(**IN_LOOP)
def _plastic_overlap(delta_max, k1_factor_now, delta_fluid, params):
    """``(1 - k1(T, t)/k2(delta_max)) delta_max``: the force-free overlap before the fluid limit (eq. 4)."""
    return (1.0 - k1_factor_now * params[P_K1] / k2_of_delta_max(delta_max, delta_fluid, params)) * delta_max


@njit(**JIT)
def delta_0(delta_max, k1_factor_now, delta_fluid, params):
    """Force-free overlap ``delta_0 = (1 - k1(T, t)/k2(delta_max)) delta_max`` (Luding 2005, eq. 4 and below),
    never beyond ``delta_fluid`` (Sec. 3.1.3: there the contact is on the fluid branch)."""
    return min(_plastic_overlap(delta_max, k1_factor_now, delta_fluid, params), delta_fluid)


@njit(**IN_LOOP)
def delta_max_for_delta_0(d0, k1_factor_now, delta_fluid, params):
    """The ``delta_max`` whose force-free overlap (before the fluid cap) is ``d0``: the inverse of
    ``(1 - s k1/k2(x)) x = d0`` with k2(x) of eq. (7), ``s = k1(T, t)/k1`` (Fig. 5 right: cooling keeps delta_0;
    the tension branch: reloading starts on a new k2 line).

    At or above delta_max^fluid, ``x = d0/(1 - s k1/k2)``. Below, with ``k2(x) = k1 + c x``,
    ``c = (k2 - k1)/delta_max^fluid``: ``c x^2 + b x - k1 d0 = 0``, ``b = k1 (1 - s) - c d0``, whose positive root
    is taken in the form without cancellation (``2 k1 d0/(b + sqrt(D))`` for b >= 0).
    """
    if d0 <= 0.0:
        return 0.0
    k1 = params[P_K1]
    k2 = params[P_K2]
    dmf = k2 * delta_fluid / (k2 - k1)
    x = d0 / (1.0 - k1_factor_now * k1 / k2)
    if x >= dmf:
        return x
    c = (k2 - k1) / dmf
    b = k1 * (1.0 - k1_factor_now) - c * d0
    root = math.sqrt(b * b + 4.0 * c * k1 * d0)
    if b >= 0.0:
        return 2.0 * k1 * d0 / (b + root)
    return (root - b) / (2.0 * c)


@njit(**JIT)
def kc_of(delta_max, k1_factor_now, delta_fluid, params):
    """``kc(T, t, delta_max) = (k1(T, t)/k1) (k2(delta_max)/k2) kc`` (Luding 2005, eq. 13)."""
    return k1_factor_now * k2_of_delta_max(delta_max, delta_fluid, params) / params[P_K2] * params[P_KC]


@njit(**JIT)
def delta_min(delta_max, k1_factor_now, delta_fluid, params):
    """Overlap of the largest attraction, where the k2 line meets ``-kc delta``: ``k2 delta_0/(k2 + kc)``, i.e.
    ``(k2 - k1)/(k2 + kc) delta_max`` of Luding 2005, Sec. 3.1.1, with k2(delta_max), k1(T, t), kc(T, t,
    delta_max)."""
    k2m = k2_of_delta_max(delta_max, delta_fluid, params)
    kcm = k1_factor_now * k2m / params[P_K2] * params[P_KC]
    return k2m * delta_0(delta_max, k1_factor_now, delta_fluid, params) / (k2m + kcm)


@njit(**JIT)
def f_min(delta_max, k1_factor_now, delta_fluid, params):
    """Largest attraction ``f_min = -kc delta_min = -(k2 - k1(T, t))/(1 + k2/kc) delta_max`` (Luding 2005,
    eq. 15; with delta_0 capped at delta_fluid on the fluid branch)."""
    return -kc_of(delta_max, k1_factor_now, delta_fluid, params) * delta_min(delta_max, k1_factor_now,
                                                                            delta_fluid, params)


@njit(**IN_LOOP)
def normal_force(delta, delta_dot, k1_factor_now, delta_max, k1_factor_last, delta_fluid, params):
    """Normal force on particle i and the new history (Luding 2005, eqs. 4, 5, 7, 13, 15; Figs. 2, 3, 5):
    :func:`normal_force_of` with the contact's ``1/(k2 delta_fluid)`` computed here."""
    return normal_force_of(delta, delta_dot, k1_factor_now, delta_max, k1_factor_last, delta_fluid,
                           1.0 / (params[P_K2] * delta_fluid), params)


@njit(**IN_LOOP)
def normal_force_of(delta, delta_dot, k1_factor_now, delta_max, k1_factor_last, delta_fluid, inv_c, params):
    """Normal force on particle i and the new history (Luding 2005, eqs. 4, 5, 7, 13, 15; Figs. 2, 3, 5).

    Arguments: overlap ``delta`` (m), its rate ``delta_dot`` (m/s, > 0 approaching), the factor ``k1(T, t)/k1``
    now and at the contact's previous step, the history ``delta_max`` (0 for a new contact), ``delta_fluid`` of
    the contact and ``inv_c = 1/(k2 delta_fluid)`` (a pair's :func:`pair_constants`), ``params``
    (:meth:`LudingMaterial.params`).

    Returns ``(f_n, delta_max_new, f_min, k2_now, kc_now, delta_0)``: f_n > 0 repulsive, including the viscous
    ``gamma_0 delta_dot`` (eq. 5); f_min of eq. (15), k2(delta_max) of eq. (7), kc(T, t, delta_max) of eq. (13) and
    the force-free overlap after the update (the tangential kernel takes f_min and k2_now). For ``delta <= 0`` the
    contact is open: no force, the history is returned unchanged (the engine deletes the contact).

    The elastic-plastic force lies in the cone between the k1(T, t) line and the -kc line:

    * temperature (Fig. 5): when k1(T, t) fell since the last step (heating) delta_max is kept, so delta_0 grows;
      when it rose (cooling) delta_0 is kept and delta_max grows to the root of ``(1 - k1(T, t)/k2(x)) x = delta_0``
      (:func:`delta_max_for_delta_0`);
    * loading: beyond delta_max the force follows ``k1(T, t) delta`` and delta_max = delta;
    * un/reloading: ``k2(delta_max)(delta - delta_0)``, ``delta_0 = (1 - k1(T, t)/k2(delta_max)) delta_max``;
    * fluid (Sec. 3.1.3): delta_0 never exceeds delta_fluid; from there the contact stays on
      ``k2(delta_max)(delta - delta_fluid)`` with delta_max frozen (no more plastic deformation; in the cold limit
      delta_max = delta_max^fluid and the slope is k2);
    * tension: the force never falls below ``-kc delta``; where it would, it is held there and delta_0 moves to
      ``delta (1 + kc/k2)`` (kc/k2 = k1(T, t) kc/(k1 k2) by eq. 13, whatever delta_max), delta_max to the matching
      root, so that reloading departs into the cone on that new k2 line.
    """
    # Written with one division per call (this runs for every contact at every step): with c = k2 delta_fluid,
    # k2(x) = k1 + (k2 - k1)^2 x / c below the fluid limit (k2 - k1) x < c, 1/k2 = delta_fluid / c, and the
    # comparisons of force-free overlaps with delta_fluid multiplied out by k2(x) > 0.
    k1 = params[P_K1]
    k2 = params[P_K2]
    kc = params[P_KC]
    s = k1_factor_now
    dm = delta_max
    dk = k2 - k1
    kc_over_k2 = kc * delta_fluid * inv_c
    if delta > 0.0:
        if s > k1_factor_last:  # cooling: delta_0 kept
            d0_last = min(_plastic_overlap(dm, k1_factor_last, delta_fluid, params), delta_fluid)
            dm = max(dm, delta_max_for_delta_0(d0_last, s, delta_fluid, params))
        if delta > dm:
            k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
            if (k2m - s * k1) * dm < delta_fluid * k2m:  # loading: not yet on the fluid branch
                k2d = k2 if dk * delta >= k2 * delta_fluid else k1 + dk * dk * delta * inv_c
                if (k2d - s * k1) * delta <= delta_fluid * k2d:
                    dm = delta
                else:  # the fluid limit is reached within this step
                    dm = delta_max_for_delta_0(delta_fluid, s, delta_fluid, params)
        k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
        q = 1.0 + s * kc_over_k2  # kc/k2(delta_max) = s kc/k2 by eq. 13
        inv_kq = 1.0 / (k2m * q)
        d0 = min((k2m - s * k1) * dm * q * inv_kq, delta_fluid)
        kcm = s * k2m * kc_over_k2
        f = k2m * (delta - d0)
        if f < -kcm * delta:  # tension branch: a new k2 line through (delta, -kc delta)
            d0 = delta * q
            dm = delta_max_for_delta_0(d0, s, delta_fluid, params)
            k2m = k2_of_delta_max(dm, delta_fluid, params)
            kcm = s * k2m * kc_over_k2
            inv_kq = 1.0 / (k2m * q)
            f = -kcm * delta
        f += params[P_GAMMA_N] * delta_dot
    else:
        f = 0.0
        k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
        q = 1.0 + s * kc_over_k2
        inv_kq = 1.0 / (k2m * q)
        d0 = min((k2m - s * k1) * dm * q * inv_kq, delta_fluid)
        kcm = s * k2m * kc_over_k2
    attraction = kcm * k2m * d0 * inv_kq  # kc k2 d0 / (k2 + kc), the largest attraction (eq. 15)
    return f, dm, -attraction if attraction > 0.0 else 0.0, k2m, kcm, d0


# ------------------------------------------------------------------------------------------ tangential
@njit(**JIT)
def relative_velocity(v_i, v_j, w_i, w_j, a_i, a_j, n):
    """Tangential relative velocity ``v_t`` (eq. 17) and ``delta_dot`` at a contact.

    ``v_ij = v_i - v_j + a_i n x w_i + a_j n x w_j`` (Luding 2005, eq. 18) with ``n`` from j to i (eq. 3): the
    velocity of i's surface relative to j's at the contact point. ``delta_dot = -n . v_ij`` (> 0 approaching). For
    a wall, pass its velocity as ``v_j``, ``w_j = (0, 0, 0)`` and ``a_j = 0``. 3-vectors are 3-tuples.
    Returns ``(v_t, delta_dot)``.
    """
    n0, n1, n2 = n
    u0 = v_i[0] - v_j[0] + a_i * (n1 * w_i[2] - n2 * w_i[1]) + a_j * (n1 * w_j[2] - n2 * w_j[1])
    u1 = v_i[1] - v_j[1] + a_i * (n2 * w_i[0] - n0 * w_i[2]) + a_j * (n2 * w_j[0] - n0 * w_j[2])
    u2 = v_i[2] - v_j[2] + a_i * (n0 * w_i[1] - n1 * w_i[0]) + a_j * (n0 * w_j[1] - n1 * w_j[0])
    vn = n0 * u0 + n1 * u1 + n2 * u2
    return (u0 - vn * n0, u1 - vn * n1, u2 - vn * n2), -vn


@njit(**IN_LOOP)
def tangential_force(xi, n, vt, f_n, f_min_now, k2_now, k1_factor_now, dt, params, is_wall):
    """Tangential force on particle i and the new spring (Luding 2005, eqs. 14, 16, 19-24, footnote 5).

    ``xi`` the spring of the previous step, ``n`` the unit normal (j to i), ``vt`` the tangential relative
    velocity (eq. 17, :func:`relative_velocity`), all 3-tuples; ``f_n`` the normal force (with its viscous part),
    ``f_min_now`` and ``k2_now`` from :func:`normal_force`, ``dt`` the time step, ``is_wall`` selects mu_wall.

    ``f_C = mu(T, t) (f_n - f_min)``, ``mu(T, t) = (k1(T, t)/k1) mu`` (eqs. 14, 24); ``xi`` is projected into the
    tangent plane (eq. 16); test force ``f_t0 = -k_t xi - gamma_t v_t``, ``k_t = alpha k2(delta_max)`` (eqs. 19,
    23). Sticking, ``|f_t0| <= f_C``: ``f_t = f_t0``, ``xi' = xi + v_t dt`` (eq. 20). Sliding: ``f_t = f_C t``,
    ``t = f_t0/|f_t0|`` (eq. 22), ``xi' = -(f_C t + gamma_t v_t)/k_t`` (eq. 21), and with ``brittle_sliding`` the
    normal force loses its attraction, ``f_n >= 0`` (footnote 5). ``f_n - f_min <= 0``: no tangential force and
    ``xi' = 0``.

    Returns ``(f_t, xi_new, sliding, f_n)``: two 3-tuples, a bool, the (possibly raised) normal force.
    """
    mu = params[P_MU_WALL] if is_wall else params[P_MU]
    excess = f_n - f_min_now
    if excess <= 0.0:
        return (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), False, f_n
    f_c = k1_factor_now * mu * excess
    n0, n1, n2 = n
    xn = xi[0] * n0 + xi[1] * n1 + xi[2] * n2
    x0 = xi[0] - xn * n0
    x1 = xi[1] - xn * n1
    x2 = xi[2] - xn * n2
    kt = params[P_KT_RATIO] * k2_now
    gt = params[P_GAMMA_T]
    f0 = -kt * x0 - gt * vt[0]
    f1 = -kt * x1 - gt * vt[1]
    f2 = -kt * x2 - gt * vt[2]
    size = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
    if size <= f_c:
        return (f0, f1, f2), (x0 + vt[0] * dt, x1 + vt[1] * dt, x2 + vt[2] * dt), False, f_n
    scale = f_c / size
    f0 *= scale
    f1 *= scale
    f2 *= scale
    if kt > 0.0:
        inv_kt = 1.0 / kt
        xi_new = (-(f0 + gt * vt[0]) * inv_kt, -(f1 + gt * vt[1]) * inv_kt, -(f2 + gt * vt[2]) * inv_kt)
    else:
        xi_new = (0.0, 0.0, 0.0)
    if params[P_BRITTLE_SLIDING] != 0.0 and f_n < 0.0:
        f_n = 0.0
    return (f0, f1, f2), xi_new, True, f_n


# ------------------------------------------------------------------------------------------ the plug-in
# What the engines' compiled loops call (:mod:`dem.laws.contact` lists the names every contact law defines).
NAME = "luding"
Material = LudingMaterial
PAIR_HISTORY = ("delta_max", "k1_last", "xi_x", "xi_y", "xi_z")
WALL_HISTORY = PAIR_HISTORY
PARTICLE_STATE = ("k1_factor",)  # k1(T, t)/k1 of each particle's material (eqs. 10-12)
PAIR_CONSTANTS = ("delta_fluid", "inv_k2_delta_fluid")  # of the radii only (pair_constants)
SPINS = True  # the tangential forces act at the contact point: torques
SCHEMA_ROWS = (  # the scene keys of the material (dem.scene.schema): keys, type and unit, meaning
    (("k1", "k2", "kc"), "N/m, required", "loading, largest un/reloading and cohesion stiffness (cold limit), "
     "0 < k1 ≤ k2 (k1 = k2: elastic), kc ≥ 0 (eqs. 4, 7, 13)"),
    (("kt_ratio",), "≥ 0, required", "α = k_t/k2(δmax) (eq. 23)"),
    (("gamma_n", "gamma_t"), "kg/s, ≥ 0, required", "normal (eq. 5) and tangential (eq. 19) viscous damping"),
    (("mu", "mu_wall"), "≥ 0, required", "particle-particle and particle-wall friction, cold limit (eqs. 14, 24)"),
    (("T_melt", "T_var"), "required, T_var > 0", "k1(T) = k1[1 + tanh((T_melt - T)/T_var)]/2 (eq. 10); the scene's "
     "temperature unit"),
    (("expansion",), "1/K, ≥ 0, required", "δa_T of a(T) = a(T_melt)[1 - δa_T(T_melt - T)] (eq. 9)"),
    (("fluid_overlap",), "0 < φ < 1, required", "δ_fluid = φ·2R_eff for a pair (φa for equal radii), φa_i for a wall "
     "contact (Sec. 3.1.3)"),
    (("t0",), "s, > 0, required", "relaxation time of k1(T, t) (eqs. 11-12)"),
    (("brittle_sliding",), "bool, required", "a sliding contact keeps no cohesion, f_n ≥ 0 (footnote 5)"),
    (("density",), "kg/m³, the `[material]` density", "particle density"),
    (("wall_sintering",), "bool, default true", "a particle-wall contact softens and sinters with the particle's "
     "k1(T, t) like a pair (true), or keeps the cold-limit k1 of a wall that does not melt (false)"),
)
DRAG = False


def initial_state(material: LudingMaterial, T: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Each particle's stiffness factor relaxed at its initial temperature, ``k1(T)/k1`` (eq. 10).

    Parameters
    ----------
    material : LudingMaterial
        The contact material.
    T : numpy.ndarray
        (N,) initial temperatures (the unit of ``T_melt``).
    mass : numpy.ndarray
        (N,) masses (kg; not read by this law).

    Returns
    -------
    numpy.ndarray
        (N, 1) the factors (dimensionless).
    """
    return np.array([[k1_factor(float(t), material.T_melt, material.T_var)] for t in T]).reshape(len(T), 1)


def reference_radius(material: LudingMaterial, radius: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The radii at the melting temperature that give ``radius`` at ``T`` (eq. 9): thermal expansion changes the
    radius, not the mass.

    Parameters
    ----------
    material : LudingMaterial
        The contact material.
    radius : numpy.ndarray
        (N,) radii at ``T`` (m).
    T : numpy.ndarray
        (N,) temperatures (the unit of ``T_melt``).

    Returns
    -------
    numpy.ndarray
        (N,) radii at ``T_melt`` (m).
    """
    return radius / np.array([radius_at(1.0, float(t), material.T_melt, material.expansion) for t in T])


def largest_reach(material: LudingMaterial, radius: np.ndarray) -> float:
    """The law acts on overlapping particles only.

    Parameters
    ----------
    material : LudingMaterial
        The contact material.
    radius : numpy.ndarray
        (N,) radii (m).

    Returns
    -------
    float
        0.0: the largest gap (m) across which the law acts.
    """
    return 0.0


def time_steps(material: LudingMaterial, mass: np.ndarray, inertia: np.ndarray, radius: np.ndarray,
               m_mean: float) -> tuple[float, float]:
    """``(t_MD, stable)``.

    ``t_MD = pi/(50 omega)`` is the "typical time-step" of Luding 2005 (eq. 6 and below, :func:`time_step`) for a
    contact of two particles of the mean mass ``m_mean``. The lightest pair of a polydisperse sample vibrates faster:
    with Table 1's radii (a0 +- 50 %) its contact still takes 25 steps per half period. ``stable`` is the largest
    velocity-Verlet step that stays stable for the stiffest contact, ``2/(omega_max + eta)``: the lightest pair, with
    the normal stiffness k2 or the tangential spring acting with rotation (``alpha k2 (1 + m a^2/I)``), whichever is
    stiffer, and the viscous rate ``eta = gamma_n/(2 m12)``.

    Parameters
    ----------
    material : LudingMaterial
        The contact material.
    mass : numpy.ndarray
        (N,) masses (kg).
    inertia : numpy.ndarray
        (N,) moments of inertia (kg m^2).
    radius : numpy.ndarray
        (N,) radii (m).
    m_mean : float
        The mass of a particle of the mean radius (kg).

    Returns
    -------
    tuple of (float, float)
        The step ``dt = "auto"`` takes, ``min(t_MD, stable)``, and ``stable`` (s).

    Raises
    ------
    ValueError
        The normal damping is overcritical.
    """
    order = np.argsort(mass)
    t_md = time_step(material.k2, material.gamma_n, 0.5 * m_mean)
    m12 = mass[order[0]] * mass[order[1]] / (mass[order[0]] + mass[order[1]]) if len(mass) > 1 else mass[0]
    rotational = 1.0 + float(np.max(mass * radius**2 / inertia))
    k_max = material.k2 * max(1.0, material.kt_ratio * rotational)
    stable = 2.0 / (math.sqrt(k_max / m12) + material.gamma_n / (2.0 * m12))
    return min(t_md, stable), stable


@njit(**IN_LOOP)
def pair_force(c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const):
    """Force on particle i of the closed pair ``c`` = (i, j): ``(f_n, f_t0, f_t1, f_t2)`` (normal eqs. 3-13,
    tangential eqs. 14-24) from the overlap ``delta`` (centre distance ``d``), the unit normal ``n`` (j to i), the
    relative surface velocity ``vr`` and its normal part ``vn``; the pair's history is read from row ``c`` of
    ``hist_in`` and written to row ``c`` of ``hist`` (``PAIR_HISTORY``); ``const``, its :func:`pair_constants`.
    ``planar``: 2D disks in the x-z plane (no y terms)."""
    k1c = 0.5 * (state[i, 0] + state[j, 0])
    delta_fluid, inv_c = const
    f_n, dmax, f_min_now, k2_now, kc_now, d0 = normal_force_of(delta, -vn, k1c, hist_in[c, 0], hist_in[c, 1],
                                                             delta_fluid, inv_c, params)
    n0, n1, n2 = n
    xi_y = 0.0 if planar else hist_in[c, 3]
    ft, xi, sliding, f_n = tangential_force((hist_in[c, 2], xi_y, hist_in[c, 4]), n,
                                            (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), f_n, f_min_now,
                                            k2_now, k1c, dt, params, False)
    hist[c, 0] = dmax
    hist[c, 1] = k1c
    hist[c, 2], hist[c, 3], hist[c, 4] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def pair_constants(ri, rj, params):
    """The pair's ``delta_fluid`` (Sec. 3.1.3, :func:`pair_delta_fluid`) and ``1/(k2 delta_fluid)``
    (``PAIR_CONSTANTS``): numbers of the radii alone, which the loops keep per pair while the radii stay (two
    divisions fewer per contact and step)."""
    delta_fluid = pair_delta_fluid(ri, rj, params[P_FLUID_OVERLAP])
    return delta_fluid, 1.0 / (params[P_K2] * delta_fluid)


@njit(**IN_LOOP)
def forget_pair(c, hist_in, hist):
    """A pair that opened forgets its plastic history and its spring (the factor it saw is kept); whether it had
    one."""
    if hist_in[c, 0] != 0.0:
        hist[c, 0] = 0.0
        hist[c, 2], hist[c, 3], hist[c, 4] = 0.0, 0.0, 0.0
        return True
    return False


@njit(**IN_LOOP)
def wall_force(k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params):
    """Force on particle k from wall m: the pair law with the wall as j (no radius, no spin, ``mu_wall``, the
    particle's own factor, or the cold-limit 1 without ``wall_sintering``; ``delta_fluid = fluid_overlap a_k``);
    history in ``[k, m]`` of the (N, W, 5) arrays."""
    s = state[k, 0] if params[P_WALL_SINTERING] != 0.0 else 1.0  # a wall that does not melt keeps the cold k1
    f_n, dmax, f_min_now, k2_now, kc_now, d0 = normal_force(delta, -vn, s, hist_in[k, m, 0], hist_in[k, m, 1],
                                                          params[P_FLUID_OVERLAP] * rk, params)
    n0, n1, n2 = n
    ft, xi, sliding, f_n = tangential_force((hist_in[k, m, 2], hist_in[k, m, 3], hist_in[k, m, 4]), n,
                                            (vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2), f_n, f_min_now,
                                            k2_now, s, dt, params, True)
    hist[k, m, 0] = dmax
    hist[k, m, 1] = s
    hist[k, m, 2], hist[k, m, 3], hist[k, m, 4] = xi
    return f_n, ft[0], ft[1], ft[2]


@njit(**IN_LOOP)
def forget_wall(k, m, hist_in, hist):
    """A wall contact that opened forgets its plastic history and its spring; whether it had one."""
    if hist_in[k, m, 0] != 0.0:
        hist[k, m, 0] = 0.0
        hist[k, m, 2], hist[k, m, 3], hist[k, m, 4] = 0.0, 0.0, 0.0
        return True
    return False


@njit(**IN_LOOP)
def reach(c, hist, ri, rj, params):
    """How far beyond touching the pair still acts: the law has no force at a distance."""
    return 0.0


@njit(**IN_LOOP)
def wall_reach(k, m, hist, rk, params):
    """A wall contact acts while it overlaps."""
    return 0.0


@njit(**JIT)
def update_particles(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    """Before the forces of a step: the temperatures ``T0 + T_rate elapsed`` (uniform: one value), the radii (eq. 9)
    and the stiffness factors relaxed over the step (eqs. 10-12). Returns whether a radius changed."""
    T_melt, T_var, expansion = params[P_T_MELT], params[P_T_VAR], params[P_EXPANSION]
    n = T.shape[0]
    changed = False
    if uniform:
        Tu = T0[0] + T_rate[0] * elapsed
        target = k1_factor(Tu, T_melt, T_var)
        scale = radius_at(1.0, Tu, T_melt, expansion)
        cooling = T_rate[0] < 0.0
        old = state[0, 0]
        new = relax_k1(old, target, dt, t0, cooling)  # the factors of a uniform temperature are all equal
        for k in range(n):
            T[k] = Tu
            a = radius_ref[k] * scale
            changed |= a != radius[k]
            radius[k] = a
            state[k, 0] = new if state[k, 0] == old else relax_k1(state[k, 0], target, dt, t0, cooling)
    else:
        for k in range(n):
            T[k] = T0[k] + T_rate[k] * elapsed
            a = radius_at(radius_ref[k], T[k], T_melt, expansion)
            changed |= a != radius[k]
            radius[k] = a
            state[k, 0] = relax_k1(state[k, 0], k1_factor(T[k], T_melt, T_var), dt, t0, T_rate[k] < 0.0)
    return changed


@njit(**IN_LOOP)
def drag(k, radius, params):
    """No drag."""
    return 0.0
