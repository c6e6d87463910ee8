"""PLACEHOLDER (engine development only; replaced by the real Luding 2005 kernels at merge)."""

import math

import numpy as np
from numba import njit

P_K1, P_K2, P_KC, P_KT_RATIO, P_GAMMA_N, P_GAMMA_T, P_MU, P_MU_WALL, P_T_MELT, P_T_VAR, P_EXPANSION, P_PHI, \
    P_T0, P_BRITTLE = range(14)
N_PARAMS = 14


@njit(cache=True)
def k1_factor(T, T_melt, T_var):
    return 0.5 * (1.0 + math.tanh((T_melt - T) / T_var))


@njit(cache=True)
def relax_k1(k1t, k1T, dt, t0, cooling):
    if cooling and k1T > k1t:
        return k1T
    u = 1.0 - k1t / k1T
    return k1T * (1.0 - u / (1.0 + abs(u) * dt / t0))


@njit(cache=True)
def radius_at(a_melt, T, T_melt, expansion):
    return a_melt * (1.0 - expansion * (T_melt - T))


@njit(cache=True, inline="always")
def normal_force(delta, delta_dot, k1f, delta_max, k1f_last, delta_fluid, p):
    k1 = p[P_K1] * k1f
    k2 = p[P_K2]
    kc = p[P_KC] * k1f
    if delta > delta_max:
        delta_max = delta
    d0 = (1.0 - k1 / k2) * delta_max
    f = k2 * (delta - d0)
    if f > k1 * delta:
        f = k1 * delta
    if f < -kc * delta:
        f = -kc * delta
    f_min = -(k2 - k1) / (1.0 + k2 / kc) * delta_max if kc > 0 else 0.0
    return f + p[P_GAMMA_N] * delta_dot, delta_max, f_min, k2, kc


@njit(cache=True, inline="always")
def tangential_force(xi0, xi1, xi2, n0, n1, n2, vt0, vt1, vt2, f_n, f_min, k2_now, k1f, dt, p, is_wall):
    dot = xi0 * n0 + xi1 * n1 + xi2 * n2
    xi0 -= dot * n0
    xi1 -= dot * n1
    xi2 -= dot * n2
    mu = (p[P_MU_WALL] if is_wall else p[P_MU]) * k1f
    fc = mu * (f_n - f_min)
    if fc <= 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, False, f_n
    kt = p[P_KT_RATIO] * k2_now
    gt = p[P_GAMMA_T]
    f0 = -kt * xi0 - gt * vt0
    f1 = -kt * xi1 - gt * vt1
    f2 = -kt * xi2 - gt * vt2
    fm = math.sqrt(f0 * f0 + f1 * f1 + f2 * f2)
    if fm <= fc:
        return f0, f1, f2, xi0 + vt0 * dt, xi1 + vt1 * dt, xi2 + vt2 * dt, False, f_n
    s = fc / fm
    f0 *= s
    f1 *= s
    f2 *= s
    if kt > 0:
        xi0, xi1, xi2 = -(f0 + gt * vt0) / kt, -(f1 + gt * vt1) / kt, -(f2 + gt * vt2) / kt
    return f0, f1, f2, xi0, xi1, xi2, True, f_n
