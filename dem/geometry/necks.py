"""Where a packing stands: which particles carry necks that meet, under the scene's neck reading.

A neck is seen from its particle's centre as a cone (:func:`fem_neck.geometry.union.angular_radius`); two necks of
one particle *meet* when their cones overlap. The pair-neck readings (``newton``, ``first``, ``coble``: Rojek 2022,
eqs. 10-34) put the neck's circle on the sphere where the neck cylinder of radius ``a`` meets it, at the angle
``arcsin(a / r)``; the lens readings (``lens``, ``union``) put it on the radical plane, at ``atan2(a, l)`` with
``l`` the centre's distance from that plane. Once necks meet, the pair-neck readings have no answer (the necks
would overlap inside the particle); the union of the spheres (:mod:`fem_neck.geometry.union`) has one at every
density. A wall bond's neck counts as one of its particle's necks.
"""

from __future__ import annotations

import numpy as np

from fem_neck.geometry.union import angular_radius, necks_meet

from dem.geometry.bonds import LENS_GEOMETRY, Bonds

PAIR_READINGS = ("newton", "first", "coble")  # the readings that end where necks meet


def necks_meeting(radius: np.ndarray, bonds: Bonds, vectors: np.ndarray, wall_normals: np.ndarray) -> np.ndarray:
    """Whether two necks of each particle meet (bool per particle).

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    bonds : Bonds
        The pair and wall bonds with their neck radii and reading (``bonds.contact``).
    vectors : numpy.ndarray
        ``x_j - x_i`` of every pair bond (one row each), m (the image's across a periodic face).
    wall_normals : numpy.ndarray
        The unit normal of each wall bond's wall (one row each), pointing into the packing.
    """
    radius = np.asarray(radius, dtype=float)
    i, j, p = bonds.i, bonds.j, bonds.wall_particle
    if bonds.contact in LENS_GEOMETRY:
        angles = [angular_radius(bonds.a, bonds.l_i), angular_radius(bonds.a, bonds.l_j),
                  angular_radius(bonds.wall_a, bonds.wall_l)]
    else:
        angles = [np.arcsin(np.minimum(bonds.a / radius[i], 1.0)), np.arcsin(np.minimum(bonds.a / radius[j], 1.0)),
                  np.arcsin(np.minimum(bonds.wall_a / radius[p], 1.0))]
    particle = np.concatenate([i, j, p])
    direction = np.vstack([np.reshape(vectors, (-1, 3)), -np.reshape(vectors, (-1, 3)),
                           -np.reshape(wall_normals, (-1, 3))])
    return necks_meet(len(radius), particle, direction, np.concatenate(angles))


def meeting_in(particles, walls, bonds: Bonds, box=None) -> np.ndarray:
    """:func:`necks_meeting` of bonds found among particles and walls.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles (positions and radii, m) the bonds join.
    walls : sequence of dem.geometry.walls.Wall
        The walls ``bonds.wall_index`` indexes (their normals point into the packing).
    bonds : Bonds
        The pair and wall bonds, with their neck radii and reading.
    box : dem.geometry.periodic.PeriodicBox, optional
        The periodic box the bonds' image shifts refer to.

    Returns
    -------
    numpy.ndarray
        Per particle, whether two of its necks meet (bool).
    """
    normals = np.array([walls[k].normal for k in bonds.wall_index], dtype=float).reshape(-1, 3)
    return necks_meeting(particles.radius, bonds, bonds.vectors(particles.position, box), normals)


def neck_account(count: int, n: int, reading: str, bonds: int, law: str, readings: dict | None = None,
                 handed_over: int | None = None) -> dict:
    """The summary's account of the necks: the reading every bond used (``neck_readings``: bonds per reading), how
    many particles carry necks that meet (``particles_necks_meeting``), and, for the laws verified against FE (all but
    ``zohdi``), whether the run stayed where the law is verified (``law_in_verified_range``: the necks of every
    particle apart) with a one-line ``warnings`` entry where not. A run that hands particles over to the union
    (:mod:`dem.geometry.handover`) also says how many it handed over (``particles_handed_over``); its particles whose
    necks meet are read by the union.

    Parameters
    ----------
    count : int
        Particles that carry necks that meet.
    n : int
        Particles in the run.
    reading : str
        The neck reading of the scene (``dem.geometry.bonds.CONTACT_MODELS``).
    bonds : int
        Pair and wall bonds.
    law : str
        The conductance law (``dem.laws.conductance.LAWS``).
    readings : dict or None
        Bonds per reading where they differ (a hand-over); None: all ``bonds`` read ``reading``.
    handed_over : int or None
        Particles handed over to the union; None: the run hands none over.

    Returns
    -------
    dict
        The summary's entries.
    """
    count = int(count)
    out = {"neck_readings": {reading: int(bonds)} if readings is None else {k: int(v) for k, v in readings.items()},
           "particles_necks_meeting": count}
    if handed_over is not None:
        out["particles_handed_over"] = int(handed_over)
    if reading not in PAIR_READINGS and reading != "union":
        return out
    out["law_in_verified_range"] = count == 0
    if count:
        where = f"{count} of {n} particles ({100.0 * count / n:.1f} %) carry necks that meet"
        if reading in PAIR_READINGS and handed_over is None:
            why = (f"the pair-neck reading {reading!r} has no answer there, so law {law!r} is outside the "
                   f"range where it is verified; conductance.neck = \"union\" reads the packing as the union of its "
                   f"spheres, defined at every density")
        else:
            why = f"law {law!r} is not verified against FE on union necks that meet"
        out["warnings"] = [f"{where}: {why}"]
    return out
