"""The ``zohdi`` conductance law (:mod:`dem.laws.conductance`) compiled on the pairs of a Verlet list, contact geometry
included: particles that move evaluate it at every fixed-point iteration of their step
(:mod:`dem.engines.staggered.heat`). Apart from :mod:`dem.laws.conductance` so that a static run loads no numba."""

from __future__ import annotations

import math

from numba import njit

from dem.geometry.neighbours import min_image

LENS_POLICY = {"error": 0, "clip": 1, "drop": 2}  # out_of_range as the compiled lens law takes it


@njit(cache=True, error_model="numpy")
def lens_conductance(l_i, l_j, area, kappa_i, kappa_j, contact_conductance):
    r""":math:`K_{ij}` of the ``zohdi`` law (Zohdi 2014, eq. 33) from the centre-to-contact-plane distances ``l_i``,
    ``l_j`` (eq. 12) and the lens area ``area`` :math:`A` (eqs. 7-11): the halves :math:`\kappa_i A / l_i` in series,
    and ``contact_conductance`` (W/K; inf: none). A half with :math:`l = 0` (a centre on the contact plane; the
    isothermal wall's side of a wall bond) adds no resistance."""
    resistance = 1.0 / contact_conductance
    if l_i > 0.0:
        resistance += l_i / (kappa_i * area)
    if l_j > 0.0:
        resistance += l_j / (kappa_j * area)
    return 1.0 / resistance


@njit(cache=True, error_model="numpy")
def lens_list_conductances(x, radius, kappa, contact_conductance, policy, pairs, walls, wall_pairs, K, K_w, box):
    r"""The ``zohdi`` law (:func:`lens_conductance`) on every listed pair of ``pairs``, the arrays ``(pi, pj)``, into
    ``K`` and every listed particle-wall pair of ``wall_pairs``, the arrays ``(wk, wm)``, into ``K_w`` (``walls`` a
    :class:`dem.geometry.walls.WallArrays`, the planes :math:`n_m \cdot x = q_m`), with the lens geometry of
    :func:`dem.geometry.bonds.find_bonds` (``contact = "lens"``) at positions ``x``; ``K = 0`` where the pair does not
    touch (:math:`|x_i - x_j| \ge R_i + R_j`, a wall at a distance :math:`\ge R_k`). Along the axes where ``box`` holds
    a period (else 0) a pair is joined by the minimum image (:func:`dem.geometry.neighbours.min_image`).

    A lens beyond its range (a centre inside the other sphere's cap, :math:`L_i < 0`) is, by ``policy``
    (``LENS_POLICY``), clipped as ``find_bonds`` clips it (the smaller sphere's centre on the contact plane) or
    dropped (``K = 0``). Returns the number of contacts that ``policy`` cannot take (``"error"``: a lens beyond its
    range; any policy but ``"drop"``: coincident centres, a centre on or behind a wall), whose ``K`` is left 0:
    ``find_bonds`` then names the first and says what to do."""
    (pi, pj), (wk, wm), wn, wq = pairs, wall_pairs, walls.normal, walls.q
    bad = 0
    periodic = box[0] > 0.0 or box[1] > 0.0 or box[2] > 0.0  # without a box the loop stays the plain one
    for c in range(pi.shape[0]):
        i, j = pi[c], pj[c]
        K[c] = 0.0
        if periodic:
            d2 = (min_image(x[j, 0] - x[i, 0], box[0]) ** 2 + min_image(x[j, 1] - x[i, 1], box[1]) ** 2
                  + min_image(x[j, 2] - x[i, 2], box[2]) ** 2)
        else:
            d2 = (x[j, 0] - x[i, 0]) ** 2 + (x[j, 1] - x[i, 1]) ** 2 + (x[j, 2] - x[i, 2]) ** 2
        ri, rj = radius[i], radius[j]
        if d2 > (ri + rj) ** 2 * (1.0 + 1e-10):  # surely apart: no square root (the exact test follows)
            continue
        d = math.sqrt(d2)
        if d >= ri + rj:
            continue
        if d <= 0.0:
            bad += policy != 2
            continue
        li = 0.5 * (d - (rj * rj - ri * ri) / d)
        lj = d - li
        if li < 0.0 or lj < 0.0:
            if policy != 1:
                bad += policy == 0
                continue
            li, lj = (0.0, d) if ri <= rj else (d, 0.0)
        small, l_small = (ri, li) if ri <= rj else (rj, lj)
        area = math.pi * max(small * small - l_small * l_small, 0.0)
        K[c] = lens_conductance(li, lj, area, kappa[i], kappa[j], contact_conductance)
    for e in range(wk.shape[0]):
        k, m = wk[e], wm[e]
        K_w[e] = 0.0
        dist = wn[m, 0] * x[k, 0] + wn[m, 1] * x[k, 1] + wn[m, 2] * x[k, 2] - wq[m]
        rk = radius[k]
        if dist >= rk:
            continue
        if dist <= 0.0:
            bad += policy != 2
            continue
        area = math.pi * (rk * rk - dist * dist)
        K_w[e] = lens_conductance(dist, 0.0, area, kappa[k], 1.0, contact_conductance)
    return bad
