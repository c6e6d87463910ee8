"""What each particle of a sintering powder carries (Luding, Manetsberger & Müllers 2005, Luding 2005, eqs. 9-12): its
radius grows with temperature (eq. 9), and its stiffness factor ``k1(T, t)/k1`` (eq. 10) relaxes towards that of its
temperature with the time t0 (eqs. 11-12). A state sub-model of the contact laws
(:mod:`dem.laws.contact.composition`); the normal sub-model :mod:`dem.laws.contact.normal.luding` reads the factors.
Parameters: the block of :func:`dem.laws.contact.luding.params_of`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from dem.laws.contact import luding
from dem.laws.contact.kernel_options import JIT
from dem.laws.contact.luding import P_EXPANSION, P_T_MELT, P_T_VAR, LudingMaterial

PARAMS = (luding.params_of, luding.N_PARAMS)
FIELDS = {"T_melt": ("number", "K"), "T_var": ("positive", "K"), "expansion": ("nonnegative", "1/K"),
          "t0": ("positive", "s")}
SCHEMA_ROWS = tuple(row for row in luding.SCHEMA_ROWS if set(row[0]) & set(FIELDS))
PARTICLE_STATE = ("k1_factor",)  # k1(T, t)/k1 of each particle's material (eqs. 10-12)


@njit(**JIT)
def radius_at(a_melt, T, T_melt, expansion):
    r""":math:`a(T) = a(T_{melt}) [1 - \delta a_T (T_{melt} - T)]` (Luding 2005, eq. 9)."""
    return a_melt * (1.0 - expansion * (T_melt - T))


@njit(**JIT)
def k1_factor(T, T_melt, T_var):
    r""":math:`k_1(T)/k_1 = [1 + \tanh((T_{melt} - T)/T_{var})]/2` (Luding 2005, eq. 10), evaluated as the equal
    logistic :math:`1/(1 + e^{-2 \tau})`: no cancellation in :math:`1 + \tanh` far above :math:`T_{melt}`, so the
    factor stays > 0 there."""
    return 1.0 / (1.0 + math.exp(-2.0 * (T_melt - T) / T_var))


@njit(**JIT)
def relax_k1(k1t, k1T, dt, t0, cooling):
    r"""New factor :math:`k_1(T, t)/k_1` after a step ``dt`` from ``k1t`` towards the target ``k1T``,
    :math:`k_1(T)/k_1`.

    Eq. (12), :math:`dk/dt = (K - k)|K - k|/(K t_0)`, solved exactly over the step from the previous step's value
    (footnote 3) at constant target K: with :math:`u = 1 - k/K`, :math:`u_{new} = u/(1 + |u|\, dt/t_0)` (eq. 11 is
    this solution for heating). Written as :math:`k_{new} = K - d K t_0/(K t_0 + |d|\, dt)`, :math:`d = K - k`:
    unconditionally stable and finite for :math:`K \to 0`. Cooling with :math:`K > k` freezes at once,
    :math:`k_{new} = K` (end of Sec. 3.4).
    """
    d = k1T - k1t
    if cooling and d > 0.0:
        return k1T
    denominator = k1T * t0 + abs(d) * dt
    if denominator <= 0.0:
        return k1T
    return k1T - d * (k1T * t0) / denominator


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
