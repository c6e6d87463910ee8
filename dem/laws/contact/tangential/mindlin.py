"""Mindlin's tangential contact with Coulomb sliding (Mindlin 1949; Mindlin & Deresiewicz 1953, J. Appl. Mech. 20, 327;
the "no-slip" form of Di Renzo & Di Maio 2004): a spring ``xi`` (the tangential displacement of the contact), turned
into the current tangent plane keeping its length and advanced by the tangential surface velocity ``v_t dt``; the force
``F_t = -k_t xi - eta_t v_t``; where ``|F_t|`` exceeds the friction limit the contact slides, ``F_t`` is scaled to the
limit and the spring set to what gives that force, ``xi = -(F_t + eta_t v_t)/k_t`` (as LAMMPS's ``tangential
mindlin``). The law that uses it gives the stiffness (Mindlin's ``k_t = 8 G* a`` on its contact radius), the damping
and the limit (Coulomb's ``mu`` times the load the contact carries)."""

from __future__ import annotations

import math

from numba import njit

IN_LOOP = {"cache": True, "error_model": "numpy", "inline": "always"}  # inlined into the engines' force loop


@njit(**IN_LOOP)
def mindlin_force(xi, n, vt, k_t, eta_t, f_limit, dt):
    """Mindlin's tangential force with Coulomb sliding: ``(F_t, xi_new)``, two 3-tuples (module docstring).

    ``xi`` the spring of the previous step, ``n`` the unit normal, ``vt`` the tangential surface velocity of i
    relative to j; ``k_t`` the stiffness, ``eta_t`` the damping, ``f_limit`` the largest tangential force (``mu
    F_n``); ``dt`` the step. The spring is turned into the tangent plane keeping its length, advanced by ``vt dt``;
    ``F_t = -k_t xi - eta_t vt``; beyond ``f_limit`` it slides: ``F_t`` scaled to ``f_limit``, ``xi = -(F_t + eta_t
    vt)/k_t``."""
    n0, n1, n2 = n
    length2 = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2]
    xn = xi[0] * n0 + xi[1] * n1 + xi[2] * n2
    x0, x1, x2 = xi[0] - xn * n0, xi[1] - xn * n1, xi[2] - xn * n2
    if xn != 0.0:  # turned into the tangent plane: the same length
        plane2 = x0 * x0 + x1 * x1 + x2 * x2
        scale = math.sqrt(length2 / plane2) if plane2 > 0.0 else 0.0
        x0, x1, x2 = x0 * scale, x1 * scale, x2 * scale
    x0 += vt[0] * dt
    x1 += vt[1] * dt
    x2 += vt[2] * dt
    f0 = -k_t * x0 - eta_t * vt[0]
    f1 = -k_t * x1 - eta_t * vt[1]
    f2 = -k_t * x2 - eta_t * vt[2]
    size2 = f0 * f0 + f1 * f1 + f2 * f2
    if size2 > f_limit * f_limit:
        scale = f_limit / math.sqrt(size2)
        f0, f1, f2 = f0 * scale, f1 * scale, f2 * scale
        inv_k = 1.0 / k_t
        x0 = -(f0 + eta_t * vt[0]) * inv_k
        x1 = -(f1 + eta_t * vt[1]) * inv_k
        x2 = -(f2 + eta_t * vt[2]) * inv_k
    return (f0, f1, f2), (x0, x1, x2)
