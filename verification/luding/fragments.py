"""Fragments of a sintered sample: connected clusters of particles joined by cohesive contacts.

A contact of the Luding 2005 law can carry tension only down to ``f_min`` (eq. 15), which grows with the contact's
largest overlap ``delta_max`` and with the stiffness factor k1(T, t): a contact that was pressed hard or sintered
holds its particles together, one that only touches does not. A **bond** is a closed contact (overlap > 0) whose
tension capacity ``-f_min`` is at least ``min_tension`` (N); a **fragment** is a connected cluster of particles
joined by bonds, and a particle without a bond is a fragment of its own.

Why a threshold: every contact that has been loaded has ``f_min < 0``, however little, because k2(delta_max) > k1
for any delta_max > 0 (eq. 7); two disks resting on each other under their weight ``m g`` reach ``delta_max ~ m
g/k1`` and a tension capacity of order ``(m g)^2/(k1 delta_max^fluid)``, some 1e-9 of their weight with Table 1.
A sintered contact holds about 1 N, 10^3 - 10^4 weights. The verification uses the weight of the lighter particle
of the pair as ``min_tension``: a bond can at least hold a particle hanging from it.
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from dem.laws.contact.luding import P_FLUID_OVERLAP
from dem.laws.contact.normal.luding import f_min, pair_delta_fluid


def clusters(n: int, i: np.ndarray, j: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Connected components of the graph on ``n`` particles with edges ``(i, j)``: ``(labels, sizes)``, labels
    numbered by decreasing size (0 the largest), sizes sorted decreasing."""
    i, j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
    graph = coo_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    count, labels = connected_components(graph, directed=False)
    sizes = np.bincount(labels, minlength=count)
    order = np.argsort(-sizes, kind="stable")
    rank = np.empty(count, dtype=np.int64)
    rank[order] = np.arange(count)
    return rank[labels], sizes[order]


def tension_capacity(mech) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(i, j, -f_min)`` of the closed pair contacts of a :class:`dem.engines.verlet.mechanics.MechanicalModel`: the largest
    attraction each can carry now (eq. 15 with its delta_max and the mean stiffness factor of its particles), N."""
    s = mech.state
    d = s.x[mech.pi] - s.x[mech.pj]
    for a in range(3):
        if mech.box[a] > 0:
            d[:, a] -= mech.box[a] * np.floor(d[:, a] / mech.box[a] + 0.5)
    closed = s.radius[mech.pi] + s.radius[mech.pj] - np.linalg.norm(d, axis=1) > 0
    i, j, dmax = mech.pi[closed], mech.pj[closed], mech.pair_column("delta_max")[closed]
    phi = mech.params[P_FLUID_OVERLAP]
    k1f = mech.particle_column("k1_factor")
    cap = np.array([-f_min(dm, 0.5 * (k1f[a] + k1f[b]), pair_delta_fluid(s.radius[a], s.radius[b], phi), mech.params)
                    for a, b, dm in zip(i, j, dmax)])
    return i, j, cap.reshape(-1)


def fragments(mech, min_tension=None) -> tuple[np.ndarray, np.ndarray]:
    """``(labels, sizes)`` of the fragments (module docstring) of a mechanical model. ``min_tension``: N, a number
    or None for the weight of the lighter particle of each pair under standard gravity (9.81 m/s^2)."""
    i, j, cap = tension_capacity(mech)
    if min_tension is None:
        threshold = 9.81 * np.minimum(mech.state.mass[i], mech.state.mass[j])
    else:
        threshold = float(min_tension)
        if not np.isfinite(threshold) or threshold < 0:
            raise ValueError(f"min_tension = {min_tension!r}: must be a finite force >= 0 (N)")
    bond = cap >= threshold
    if min_tension is not None and threshold == 0:
        bond &= cap > 0
    return clusters(mech.state.n, i[bond], j[bond])
