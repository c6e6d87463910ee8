r"""Where a packing stands: which particles carry necks that meet, under the scene's neck reading.

A neck is seen from its particle's centre as a cone (:func:`fem_neck.geometry.union.angular_radius`); two necks of one
particle *meet* when their cones overlap. The pair-neck readings (``newton``, ``first``, ``coble``: Rojek 2022, eqs.
10-34) put the neck's circle on the sphere where the neck cylinder of radius ``a`` meets it, at the angle
:math:`\arcsin(a / r)`; the lens readings (``lens``, ``union``) put it on the radical plane, at :math:`\arctan(a / l)`
with ``l`` the centre's distance from that plane. Once necks meet, the pair-neck readings have no answer (the necks
would overlap inside the particle); the union of the spheres (:mod:`fem_neck.geometry.union`) has one at every density.
A wall bond's neck counts as one of its particle's necks.
"""

from __future__ import annotations

import numpy as np

from fem_neck.geometry.union import angular_radius, meeting_pairs, necks_meet

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
    return necks_meet(len(radius), *_cones(radius, bonds, vectors, wall_normals))


def pairs_meeting(radius: np.ndarray, bonds: Bonds, vectors: np.ndarray, wall_normals: np.ndarray) -> np.ndarray:
    """How many pairs of necks of each particle meet (int per particle; :func:`necks_meeting` on every pair).

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
    return meeting_pairs(len(radius), *_cones(radius, bonds, vectors, wall_normals))


def _cones(radius, bonds: Bonds, vectors, wall_normals) -> tuple:
    """``(particle, direction, angle)`` of every neck end: its particle, the direction toward it from that particle's
    centre and the half-angle of the cone it is seen in from there (module docstring)."""
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
    return particle, direction, np.concatenate(angles)


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


def widest_necks(radius: np.ndarray, bonds: Bonds) -> np.ndarray:
    """Per particle, its widest neck over its radius, ``max a / r`` (0 without a neck).

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    bonds : Bonds
        The pair and wall bonds with their neck radii, m.

    Returns
    -------
    numpy.ndarray
        ``max a / r`` per particle (dimensionless).
    """
    radius = np.asarray(radius, dtype=float)
    widest = np.zeros(len(radius))
    for particle, a in ((bonds.i, bonds.a), (bonds.j, bonds.a), (bonds.wall_particle, bonds.wall_a)):
        np.maximum.at(widest, particle, np.asarray(a, dtype=float) / radius[particle])
    return widest
