r"""The hysteretic sintering normal force of Luding, Manetsberger & Müllers 2005 (Luding 2005, eqs. 4-15, Figs. 2, 3,
5), a normal sub-model of the contact laws (:mod:`dem.laws.contact.composition`), and the time step it needs (eq. 6).

Conventions (Sec. 3.1): the unit normal :math:`n` points from particle j to particle i (eq. 3), the overlap
:math:`\delta = a_i + a_j - |r_i - r_j|` is positive in contact, :math:`\dot\delta = d\delta/dt` is positive while the
particles approach, and the force is that **on particle i**. For a wall contact the wall plays j (no radius; the
particle's k1(T, t), or with ``wall_sintering`` off the cold-limit k1).

Stiffness history is carried as the dimensionless factor ``s = k1(T, t)/k1`` (eqs. 10-12), a property of each
particle's material (:mod:`dem.laws.contact.state.sintering`): a contact uses the mean of its two particles' factors,
which for a uniform temperature is exactly the single ``k1(T, t)`` of the paper. Each contact stores ``delta_max``
(eq. 4) and the factor it saw at its previous step (Fig. 5: heating keeps ``delta_max``, cooling keeps ``delta_0``).

The fluid overlap of a contact (Sec. 3.1.3) is ``delta_fluid = fluid_overlap * 2 R_eff`` for a pair, ``R_eff = a_i
a_j/(a_i + a_j)`` (``fluid_overlap * a`` for equal radii; :func:`pair_delta_fluid`), and ``fluid_overlap * a_i`` for
a particle-wall contact. Its history limit is ``delta_max_fluid = k2 delta_fluid/(k2 - k1)`` with the constant
cold-limit k1 (eq. 7: k2 is not changed directly when k1(T) falls). Parameters: the block of
:func:`dem.laws.contact.luding.params_of` (indices ``P_*`` of :mod:`dem.laws.contact.luding`).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact import luding
from dem.laws.contact.damping import luding as damping
from dem.laws.contact.kernel_options import IN_LOOP, JIT
from dem.laws.contact.luding import P_FLUID_OVERLAP, P_GAMMA_N, P_K1, P_K2, P_KC, P_WALL_SINTERING, LudingMaterial


def time_step(k2: float, gamma_n: float, m_min: float) -> float:
    r""":math:`t_{MD} = \pi/(50 \omega)`, :math:`\omega = \sqrt{k_2/m_{12} - \eta_0^2}`, :math:`\eta_0 =
    \gamma_0/(2 m_{12})` (Luding 2005, eq. 6 and below) for the smallest reduced mass ``m_min`` :math:`= m_{12}`
    (kg) of any contact; :math:`k_2` is the largest stiffness. Overcritical damping (:math:`\omega^2 \le 0`) is
    refused.

    Parameters
    ----------
    k2 : float
        The largest stiffness (N/m).
    gamma_n : float
        Normal viscous damping :math:`\gamma_0` (kg/s).
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


def time_steps(material: LudingMaterial, mass: np.ndarray, inertia: np.ndarray, radius: np.ndarray,
               m_mean: float) -> tuple[float, float]:
    r"""``(t_MD, stable)``.

    :math:`t_{MD} = \pi/(50 \omega)` is the "typical time-step" of Luding 2005 (eq. 6 and below, :func:`time_step`)
    for a contact of two particles of the mean mass ``m_mean``. The lightest pair of a polydisperse sample vibrates
    faster: with Table 1's radii (a0 +- 50 %) its contact still takes 25 steps per half period. ``stable`` is the
    largest velocity-Verlet step that stays stable for the stiffest contact, :math:`2/(\omega_{max} + \eta)`: the
    lightest pair, with the normal stiffness :math:`k_2` or the tangential spring acting with rotation (:math:`\alpha
    k_2 (1 + m a^2/I)`), whichever is stiffer, and the viscous rate :math:`\eta = \gamma_n/(2 m_{12})`.

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
def pair_delta_fluid(a_i, a_j, fluid_overlap):
    """``delta_fluid = fluid_overlap * 2 a_i a_j/(a_i + a_j)`` of a pair (``fluid_overlap * a`` for equal radii)."""
    return fluid_overlap * 2.0 * a_i * a_j / (a_i + a_j)


# ------------------------------------------------------------------------------------------ normal history
@njit(**JIT)
def delta_max_fluid(delta_fluid, params):
    r""":math:`\delta_{max}^{fluid} = k_2 \delta_{fluid}/(k_2 - k_1)` (Luding 2005, text above eq. 7; :math:`k_1` the
    cold limit)."""
    k1 = params[P_K1]
    k2 = params[P_K2]
    return k2 * delta_fluid / (k2 - k1)


@njit(**IN_LOOP)
def k2_of_delta_max(delta_max, delta_fluid, params):
    r""":math:`k_2(\delta_{max})` (Luding 2005, eq. 7): :math:`k_1 + (k_2 - k_1) \delta_{max}/\delta_{max}^{fluid}`
    below the fluid limit, :math:`k_2` at and above it."""
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
    r"""Force-free overlap :math:`\delta_0 = (1 - k_1(T, t)/k_2(\delta_{max})) \delta_{max}` (Luding 2005, eq. 4 and
    below), never beyond :math:`\delta_{fluid}` (Sec. 3.1.3: there the contact is on the fluid branch)."""
    return min(_plastic_overlap(delta_max, k1_factor_now, delta_fluid, params), delta_fluid)


@njit(**IN_LOOP)
def delta_max_for_delta_0(d0, k1_factor_now, delta_fluid, params):
    r"""The :math:`\delta_{max}` whose force-free overlap (before the fluid cap) is :math:`d_0`: the inverse of
    :math:`(1 - s k_1/k_2(x))\, x = d_0` with :math:`k_2(x)` of eq. (7), :math:`s = k_1(T, t)/k_1` (Fig. 5 right:
    cooling keeps :math:`\delta_0`; the tension branch: reloading starts on a new :math:`k_2` line).

    At or above :math:`\delta_{max}^{fluid}`, :math:`x = d_0/(1 - s k_1/k_2)`. Below, with :math:`k_2(x) = k_1 + c
    x`, :math:`c = (k_2 - k_1)/\delta_{max}^{fluid}`: :math:`c x^2 + b x - k_1 d_0 = 0`, :math:`b = k_1 (1 - s) - c
    d_0`, whose positive root is taken in the form without cancellation (:math:`2 k_1 d_0/(b + \sqrt{D})` for
    :math:`b \ge 0`).
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
    r""":math:`k_c(T, t, \delta_{max}) = (k_1(T, t)/k_1) (k_2(\delta_{max})/k_2)\, k_c` (Luding 2005, eq. 13)."""
    return k1_factor_now * k2_of_delta_max(delta_max, delta_fluid, params) / params[P_K2] * params[P_KC]


@njit(**JIT)
def delta_min(delta_max, k1_factor_now, delta_fluid, params):
    r"""Overlap of the largest attraction, where the :math:`k_2` line meets :math:`-k_c \delta`: :math:`k_2
    \delta_0/(k_2 + k_c)`, i.e. :math:`(k_2 - k_1)/(k_2 + k_c)\, \delta_{max}` of Luding 2005, Sec. 3.1.1, with
    :math:`k_2(\delta_{max})`, :math:`k_1(T, t)`, :math:`k_c(T, t, \delta_{max})`."""
    k2m = k2_of_delta_max(delta_max, delta_fluid, params)
    kcm = k1_factor_now * k2m / params[P_K2] * params[P_KC]
    return k2m * delta_0(delta_max, k1_factor_now, delta_fluid, params) / (k2m + kcm)


@njit(**JIT)
def f_min(delta_max, k1_factor_now, delta_fluid, params):
    r"""Largest attraction :math:`f_{min} = -k_c \delta_{min} = -(k_2 - k_1(T, t))/(1 + k_2/k_c)\, \delta_{max}`
    (Luding 2005, eq. 15; with :math:`\delta_0` capped at :math:`\delta_{fluid}` on the fluid branch)."""
    return -kc_of(delta_max, k1_factor_now, delta_fluid, params) * delta_min(delta_max, k1_factor_now,
                                                                            delta_fluid, params)


@njit(**IN_LOOP)
def normal_force(delta, delta_dot, k1_factor_now, delta_max, k1_factor_last, delta_fluid, params):
    r"""Normal force on particle i and the new history (Luding 2005, eqs. 4, 5, 7, 13, 15; Figs. 2, 3, 5): the
    elastic-plastic force of :func:`elastic_plastic` (the contact's :math:`1/(k_2 \delta_{fluid})` computed here) with
    the viscous :math:`\gamma_0 \dot\delta` of eq. (5) (:func:`dem.laws.contact.damping.luding.force`) in contact;
    ``delta_dot`` (m/s) is > 0 approaching. Returns what :func:`elastic_plastic` returns, with that force."""
    f, dm, f_min_now, k2m, kcm, d0 = elastic_plastic(delta, k1_factor_now, delta_max, k1_factor_last, delta_fluid,
                                                     1.0 / (params[P_K2] * delta_fluid), params)
    if delta > 0.0:
        f = damping.force(f, delta_dot, params[P_GAMMA_N])
    return f, dm, f_min_now, k2m, kcm, d0


@njit(**IN_LOOP)
def elastic_plastic(delta, k1_factor_now, delta_max, k1_factor_last, delta_fluid, inv_c, params):
    r"""Elastic-plastic normal force on particle i and the new history (Luding 2005, eqs. 4, 7, 13, 15; Figs. 2, 3,
    5).

    Arguments: overlap ``delta`` (m), the factor :math:`k_1(T, t)/k_1` now and at the contact's previous step, the
    history ``delta_max`` (0 for a new contact), ``delta_fluid`` of the contact and ``inv_c``, :math:`1/(k_2
    \delta_{fluid})` (a pair's :func:`pair_constants`), ``params`` (:func:`dem.laws.contact.luding.params_of`).

    Returns ``(f_n, delta_max_new, f_min, k2_now, kc_now, delta_0)``: :math:`f_n > 0` repulsive, without the viscous
    part (eq. 5, the damping sub-model's); :math:`f_{min}` of eq. (15), :math:`k_2(\delta_{max})` of eq. (7),
    :math:`k_c(T, t, \delta_{max})` of eq. (13) and the force-free overlap after the update (the tangential kernel
    takes ``f_min`` and ``k2_now``). For :math:`\delta \le 0` the contact is open: no force, the history is returned
    unchanged (the engine deletes the contact).

    The elastic-plastic force lies in the cone between the :math:`k_1(T, t)` line and the :math:`-k_c` line:

    * temperature (Fig. 5): when :math:`k_1(T, t)` fell since the last step (heating) :math:`\delta_{max}` is kept,
      so :math:`\delta_0` grows; when it rose (cooling) :math:`\delta_0` is kept and :math:`\delta_{max}` grows to
      the root of :math:`(1 - k_1(T, t)/k_2(x))\, x = \delta_0` (:func:`delta_max_for_delta_0`);
    * loading: beyond :math:`\delta_{max}` the force follows :math:`k_1(T, t)\, \delta` and :math:`\delta_{max} =
      \delta`;
    * un/reloading: :math:`k_2(\delta_{max}) (\delta - \delta_0)`, :math:`\delta_0 = (1 - k_1(T,
      t)/k_2(\delta_{max}))\, \delta_{max}`;
    * fluid (Sec. 3.1.3): :math:`\delta_0` never exceeds :math:`\delta_{fluid}`; from there the contact stays on
      :math:`k_2(\delta_{max}) (\delta - \delta_{fluid})` with :math:`\delta_{max}` frozen (no more plastic
      deformation; in the cold limit :math:`\delta_{max} = \delta_{max}^{fluid}` and the slope is :math:`k_2`);
    * tension: the force never falls below :math:`-k_c \delta`; where it would, it is held there and
      :math:`\delta_0` moves to :math:`\delta (1 + k_c/k_2)` (:math:`k_c/k_2 = k_1(T, t)\, k_c/(k_1 k_2)` by eq. 13,
      whatever :math:`\delta_{max}`), :math:`\delta_{max}` to the matching root, so that reloading departs into the
      cone on that new :math:`k_2` line.
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
    else:
        f = 0.0
        k2m = k2 if dk * dm >= k2 * delta_fluid else k1 + dk * dk * dm * inv_c
        q = 1.0 + s * kc_over_k2
        inv_kq = 1.0 / (k2m * q)
        d0 = min((k2m - s * k1) * dm * q * inv_kq, delta_fluid)
        kcm = s * k2m * kc_over_k2
    attraction = kcm * k2m * d0 * inv_kq  # kc k2 d0 / (k2 + kc), the largest attraction (eq. 15)
    return f, dm, -attraction if attraction > 0.0 else 0.0, k2m, kcm, d0


# ------------------------------------------------------------------------------------------ the sub-model
PARAMS = (luding.params_of, luding.N_PARAMS)
FIELDS = {"k1": ("positive", "N/m"), "k2": ("positive", "N/m"), "kc": ("nonnegative", "N/m"),
          "fluid_overlap": ("positive", ""), "wall_sintering": ("flag", "")}
SCHEMA_ROWS = tuple(row for row in luding.SCHEMA_ROWS if set(row[0]) & set(FIELDS))
PAIR_HISTORY = ("delta_max", "k1_last")
WALL_HISTORY = PAIR_HISTORY
PAIR_CONSTANTS = ("delta_fluid", "inv_k2_delta_fluid")  # of the radii only (pair_constants)
STATE = "sintering"  # the particles' k1(T, t)/k1
GUARDS = True  # a closed contact has delta_max > 0: one without it has no other history (binding's forget)


@njit(**IN_LOOP)
def pair_constants(ri, rj, params):
    """The pair's ``delta_fluid`` (Sec. 3.1.3, :func:`pair_delta_fluid`) and ``1/(k2 delta_fluid)``
    (``PAIR_CONSTANTS``): numbers of the radii alone, which the loops keep per pair while the radii stay (two
    divisions fewer per contact and step)."""
    delta_fluid = pair_delta_fluid(ri, rj, params[P_FLUID_OVERLAP])
    return delta_fluid, 1.0 / (params[P_K2] * delta_fluid)


@njit(**IN_LOOP)
def pair(at, col, hist_in, hist, state, T, i, j, contact, ri, rj, params, const):
    r"""The elastic-plastic force of the closed pair (i, j) (:func:`elastic_plastic`) at the mean factor of its
    particles, :math:`(f_{el}, k_2(\delta_{max}), 0, f_{min}, k_1(T, t)/k_1, 0)` (:mod:`dem.laws.contact.composition`);
    the
    history ``(delta_max, k1_last)`` in columns ``col``, ``col + 1`` of row ``at``."""
    k1c = 0.5 * (state[i, 0] + state[j, 0])
    delta_fluid, inv_c = const
    f, dm, f_min_now, k2_now, kc_now, d0 = elastic_plastic(contact[0], k1c, hist_in[at + (col,)],
                                                            hist_in[at + (col + 1,)], delta_fluid, inv_c, params)
    hist[at + (col,)] = dm
    hist[at + (col + 1,)] = k1c
    return f, k2_now, 0.0, f_min_now, k1c, 0.0


@njit(**IN_LOOP)
def wall(at, col, hist_in, hist, state, T, k, contact, rk, params):
    """The pair force with the wall as j: the particle's own factor, or the cold-limit 1 without
    ``wall_sintering`` (a wall that does not melt keeps the cold k1), and ``delta_fluid = fluid_overlap a_k``."""
    s = state[k, 0] if params[P_WALL_SINTERING] != 0.0 else 1.0
    delta_fluid = params[P_FLUID_OVERLAP] * rk
    f, dm, f_min_now, k2_now, kc_now, d0 = elastic_plastic(contact[0], s, hist_in[at + (col,)],
                                                            hist_in[at + (col + 1,)], delta_fluid,
                                                            1.0 / (params[P_K2] * delta_fluid), params)
    hist[at + (col,)] = dm
    hist[at + (col + 1,)] = s
    return f, k2_now, 0.0, f_min_now, s, 0.0


@njit(**IN_LOOP)
def forget(at, col, hist_in, hist):
    """A contact that opened forgets its plastic history (the factor it saw is kept); whether it had one."""
    if hist_in[at + (col,)] != 0.0:
        hist[at + (col,)] = 0.0
        return True
    return False
