r"""The hand-over of a moving run from a pair-neck reading to the union of spheres, where a particle's necks meet.

The pair-neck readings (``newton``, ``first``, ``coble``: Rojek 2022, eqs. 21-34) have no answer once two necks of
one particle meet (:mod:`dem.geometry.necks`); the union of the spheres (:mod:`fem_neck.geometry.union`, the
truncated spheres of Arzt 1982) has one at every density. In a heat-carrying moving run with a pair-neck reading,
a particle whose necks meet is read as a truncated sphere from then on:

* **Its solid radius** ``r_s`` grows so that its cut sphere -- its sphere of radius ``r_s`` cut by the radical planes of
  every neighbour it overlaps (with the neighbours' solid radii) and by the isothermal walls it touches -- keeps the
  particle's volume :math:`\frac{4}{3} \pi r^3` (Arzt 1982: the material of the flattened contacts goes to the free
  surface), :func:`solid_radii`. The volumes are solved together by Newton's method with the exact derivatives of the
  cut volume :math:`V_k`: growing :math:`r_k` by :math:`dr` moves the free surface out (:math:`A_{free} \, dr`) and
  every radical plane of ``k``, at :math:`l_b = (d_b^2 + r_k^2 - r_j^2) / (2 d_b)`, by :math:`(r_k / d_b) \, dr`
  (:math:`A_b (r_k / d_b) \, dr`), so :math:`\partial V_k / \partial r_k = A_{free} + \sum_b A_b r_k / d_b` and
  :math:`\partial V_k / \partial r_j = -A_b r_j / d_b` for the neighbour ``j`` across face ``b``. A wall's plane does
  not move (the particle's mirror image grows with it).
* **Its necks** are the lens circles of the grown spheres (:func:`dem.geometry.bonds.find_bonds` with ``"union"``),
  their conductances the scene's law on the union reading
  (:func:`dem.laws.conductance.bond_conductances` with ``neck = "union"``).

Design choices:

(a) The solid radius is a thermal and geometric reading only: the contact law keeps the particle's radius, whose
    plastic overlap already models the mechanics of sintering; the bonds stay the mechanical contacts (two grown
    spheres that overlap without a mechanical contact are not bonded).
(b) A bond reads the union lens as soon as either of its particles is handed over: its weight is the larger of its
    two particles' (:func:`bond_weights`); a wall bond takes its particle's. A particle not handed over keeps its
    radius in the union reading of its bonds (its volume is the pair reading's, whose neck keeps it).
(c) A particle whose necks meet (:func:`dem.geometry.necks.necks_meeting`, under the pair reading) is handed over
    over ``HANDOVER_STEPS`` thermal steps (:func:`advance`): its weight ``w`` rises by ``1 / HANDOVER_STEPS`` a step
    (:func:`weights`), and a bond's conductance is ``(1 - w) K_pair + w K_union``. A hand-over once begun goes on
    to the end whatever the necks do, and a handed-over particle (``w = 1``) stays handed over (sintering does not
    undo itself; no flicker between the readings); the steps and the solid radii are part of a run's checkpoint.
    The steps are there because the two readings of one contact differ where the necks meet: the volume-conserving
    pair neck holds the material of the flattened caps in the neck, the truncated sphere spreads it over the free
    surface, so the lens circle is the smaller (twelve equal necks meeting: a/r = 0.41 against 0.50, the ``fit``
    law's half 5 % lower on the union than on the cylinder, ``rojek``'s 17 %). Handed over at once, a compact whose
    particles meet together would see its k_eff jump by that much; over ``HANDOVER_STEPS`` steps no step changes
    a bond by more than a hundredth of it. Runs in which no necks meet are the same as without the hand-over, to the
    bit.
(d) The snapshots carry ``solid_radius`` and ``handed_over`` (the weight) per particle, the summary how many
    particles were handed over (``particles_handed_over``) and how many are on the way (``particles_handing_over``).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

from fem_neck.geometry.union import cut_spheres

HANDOVER_STEPS = 100  # thermal steps over which a particle is handed over
VOLUME_RTOL = 1e-12  # the solid radii keep every cut sphere's volume to this fraction
NEWTON_ITERATIONS = 30


def advance(steps, meeting) -> np.ndarray:
    """The thermal steps of each particle's hand-over after one more step: a particle whose necks meet starts (or
    goes on), one already started goes on whatever its necks do now, up to ``HANDOVER_STEPS``.

    Parameters
    ----------
    steps : numpy.ndarray
        Per particle, the steps of its hand-over so far (integers, 0 to ``HANDOVER_STEPS``).
    meeting : numpy.ndarray
        Per particle, whether two of its necks meet now (bool).

    Returns
    -------
    numpy.ndarray
        The steps after this one.
    """
    steps = np.asarray(steps, dtype=np.int64)
    return np.where(meeting | (steps > 0), np.minimum(steps + 1, HANDOVER_STEPS), steps)


def weights(steps) -> np.ndarray:
    """The hand-over weight of each particle: ``steps / HANDOVER_STEPS`` (0: the pair reading, 1: handed over).

    Parameters
    ----------
    steps : numpy.ndarray
        Per particle, the steps of its hand-over so far.

    Returns
    -------
    numpy.ndarray
        The weights, in [0, 1].
    """
    return np.asarray(steps, dtype=float) / HANDOVER_STEPS


def bond_weights(weight: np.ndarray, bonds) -> tuple[np.ndarray, np.ndarray]:
    """Per pair bond the larger weight of its two particles, per wall bond its particle's (design choice (b)).

    Parameters
    ----------
    weight : numpy.ndarray
        Per particle, its hand-over weight (0 to 1).
    bonds : dem.geometry.bonds.Bonds
        The bonds.

    Returns
    -------
    tuple of numpy.ndarray
        The pair bonds' and the wall bonds' weights.
    """
    return np.maximum(weight[bonds.i], weight[bonds.j]), weight[bonds.wall_particle]


def solid_radii(radius, grow, i, j, vectors, wall_particle, wall_normals, wall_distance, start=None) -> np.ndarray:
    r"""The solid radii that keep the cut spheres of the particles ``grow`` at the volumes of their spheres (module
    docstring); the other particles keep their radii.

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m: the volumes :math:`\frac{4}{3} \pi r^3` to keep, and the solid radii of the particles not
        grown.
    grow : numpy.ndarray
        Per particle, whether its solid radius is solved for (bool).
    i, j : numpy.ndarray
        The overlapping pairs (each once; ``j`` may be a periodic image, given by ``vectors``).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair (one row each), m.
    wall_particle : numpy.ndarray
        The particle of each wall that cuts a sphere (indices).
    wall_normals : numpy.ndarray
        The unit normal of each such wall (one row each), pointing into the packing.
    wall_distance : numpy.ndarray
        The distance of each such particle's centre from its wall, m (> 0).
    start : numpy.ndarray or None
        The radii to start Newton's method from, m (the last solution in a run); None: ``radius``.

    Returns
    -------
    numpy.ndarray
        Per particle its solid radius, m.

    Raises
    ------
    ValueError
        Newton's method does not keep the volumes to ``VOLUME_RTOL`` within ``NEWTON_ITERATIONS`` iterations, or a
        pair leaves the union's range (:func:`fem_neck.geometry.union.cut_spheres`).
    """
    radius = np.asarray(radius, dtype=float)
    grow = np.asarray(grow, dtype=bool)
    n, m = len(radius), len(i)
    r = radius.copy() if start is None else np.where(grow, start, radius)
    idx = np.flatnonzero(grow)
    if not len(idx):
        return r
    target = 4.0 / 3.0 * np.pi * radius[idx] ** 3
    # a wall is the radical plane of the particle and its mirror image: a ghost sphere that grows with it
    ends_i = np.concatenate([i, wall_particle]).astype(np.int64)
    ends_j = np.concatenate([j, n + np.arange(len(wall_particle))]).astype(np.int64)
    arms = np.vstack([np.reshape(vectors, (-1, 3)),
                      -2.0 * np.asarray(wall_distance, dtype=float)[:, None] * np.reshape(wall_normals, (-1, 3))])
    d = np.linalg.norm(arms[:m], axis=1)
    column = np.full(n, -1, dtype=np.int64)
    column[idx] = np.arange(len(idx))
    rows_i, rows_j = column[i], column[j]
    for _ in range(NEWTON_ITERATIONS + 1):
        cut = cut_spheres(np.concatenate([r, r[wall_particle]]), ends_i, ends_j, arms)
        residual = cut.volume[idx] - target
        if np.max(np.abs(residual) / target) <= VOLUME_RTOL:
            return r
        f_i, f_j = cut.face_i[:m], cut.face_j[:m]
        rows = np.concatenate([np.arange(len(idx)), rows_i, rows_i, rows_j, rows_j])
        cols = np.concatenate([np.arange(len(idx)), rows_i, rows_j, rows_j, rows_i])
        values = np.concatenate([cut.free_area[idx], f_i * r[i] / d, -f_i * r[j] / d, f_j * r[j] / d,
                                 -f_j * r[i] / d])
        keep = (rows >= 0) & (cols >= 0)
        jacobian = sp.csr_matrix((values[keep], (rows[keep], cols[keep])), shape=(len(idx), len(idx)))
        r[idx] -= np.atleast_1d(spsolve(jacobian.tocsc(), residual))
    worst = int(idx[np.argmax(np.abs(residual) / target)])
    raise ValueError(f"solid radii: Newton's method left particle {worst}'s cut sphere {np.max(np.abs(residual) / target):.3g} "
                     f"off its volume after {NEWTON_ITERATIONS} iterations (needs {VOLUME_RTOL:g})")
