"""Mass and moment of inertia of a particle: spheres (``dimension = 3``) and disks of height ``h`` lying in the x-z plane
(``dimension = 2``, Luding 2005, Sec. 2), what the scene's time step and the engines' states are computed from."""

from __future__ import annotations

import numpy as np


def particle_mass(dimension: int, density, radius, height: float | None = None) -> np.ndarray:
    r""":math:`\rho \frac{4}{3} \pi a^3` (spheres) or :math:`\rho \pi a^2 h` (disks of height h), kg.

    Parameters
    ----------
    dimension : int
        3 (spheres) or 2 (disks in the x-z plane).
    density : float or array_like
        Density :math:`\rho` (kg/m^3), scalar or one per particle.
    radius : float or array_like
        Radii a (m).
    height : float or None
        Height h of the disks (m), read in 2D only.

    Returns
    -------
    numpy.ndarray
        The masses (kg).
    """
    radius = np.asarray(radius, dtype=float)
    if dimension == 3:
        return density * 4.0 / 3.0 * np.pi * radius**3
    return density * np.pi * radius**2 * height


def moment_of_inertia(dimension: int, mass, radius) -> np.ndarray:
    r""":math:`\frac{2}{5} m a^2` (sphere) or :math:`m a^2 / 2` (disk about its axis), kg m^2.

    Parameters
    ----------
    dimension : int
        3 (spheres) or 2 (disks in the x-z plane).
    mass : float or array_like
        Masses m (kg).
    radius : float or array_like
        Radii a (m).

    Returns
    -------
    numpy.ndarray
        The moments of inertia (kg m^2).
    """
    return (0.4 if dimension == 3 else 0.5) * np.asarray(mass) * np.asarray(radius) ** 2
