r"""The dynamic state of particles that move, what the engines advance, as arrays: positions, velocities, angular
velocities, forces, torques, masses, moments of inertia (:mod:`dem.geometry.inertia`), radii and temperatures.

Two kinds of particle:

* ``dimension = 3`` -- spheres, :math:`m = \rho \frac{4}{3} \pi a^3`, :math:`I = \frac{2}{5} m a^2`;
* ``dimension = 2`` -- disks (cylinders) of height ``height`` lying in the x-z plane, as in Luding 2005
  (Sec. 2): :math:`m = \rho \pi a^2 h`, :math:`I = m a^2 / 2` about the y axis. Their centres keep :math:`y = 0`; they
  translate
  in x and z and rotate about y only (:attr:`MotionState.axes`, :attr:`MotionState.spin_axes`).

The radius follows the temperature by thermal expansion (Luding 2005, eq. 9) while the mass stays constant, so the
radius at the reference (melting) temperature ``radius_ref`` is kept beside the current ``radius``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dem.geometry.inertia import moment_of_inertia, particle_mass

DIMENSIONS = (2, 3)


def _mask(axes: tuple[int, ...]) -> np.ndarray:
    mask = np.zeros(3)
    mask[list(axes)] = 1.0
    return mask


@dataclass
class MotionState:
    """Arrays of N particles (C-contiguous float64, ``(N, 3)`` vectors); mutated in place by the integrator.

    Parameters
    ----------
    dimension : int
        3 (spheres) or 2 (disks in the x-z plane).
    height : float or None
        Height of the 2D disks (m); None in 3D.
    x : numpy.ndarray
        (N, 3) positions (m).
    v : numpy.ndarray
        (N, 3) velocities (m/s).
    w : numpy.ndarray
        (N, 3) angular velocities (rad/s).
    f : numpy.ndarray
        (N, 3) forces (N).
    tau : numpy.ndarray
        (N, 3) torques (N m).
    mass : numpy.ndarray
        (N,) masses (kg), constant.
    inertia : numpy.ndarray
        (N,) moments of inertia (kg m^2).
    radius : numpy.ndarray
        (N,) current radii (m), which follow the temperature by thermal expansion.
    radius_ref : numpy.ndarray
        (N,) radii at the reference (melting) temperature (m).
    T : numpy.ndarray
        (N,) temperatures (the scene's unit, K or degC).
    """

    dimension: int
    height: float | None
    x: np.ndarray
    v: np.ndarray
    w: np.ndarray
    f: np.ndarray
    tau: np.ndarray
    mass: np.ndarray
    inertia: np.ndarray
    radius: np.ndarray
    radius_ref: np.ndarray
    T: np.ndarray

    @classmethod
    def create(cls, dimension, position, radius, density, temperature, velocity=None, angular_velocity=None,
               height=None, radius_ref=None) -> "MotionState":
        """A state at rest unless ``velocity``/``angular_velocity`` are given; ``density`` kg/m^3 (scalar or per
        particle); 2D disks need ``height`` (m) and positions with ``y = 0``.

        Parameters
        ----------
        dimension : int
            3 (spheres) or 2 (disks in the x-z plane).
        position : array_like
            (N, 3) positions (m); ``y = 0`` in 2D.
        radius : array_like
            (N,) radii (m).
        density : float or array_like
            Density (kg/m^3), scalar or one per particle.
        temperature : array_like
            (N,) temperatures (the scene's unit, K or degC).
        velocity : array_like or None
            (N, 3) velocities (m/s); None: at rest.
        angular_velocity : array_like or None
            (N, 3) angular velocities (rad/s); None: at rest.
        height : float or None
            Height of the 2D disks (m, > 0); read in 2D only.
        radius_ref : array_like or None
            (N,) radii at the reference temperature (m); None: ``radius``.

        Returns
        -------
        MotionState
            The state, with velocities restricted to the particles' degrees of freedom.

        Raises
        ------
        ValueError
            A bad ``dimension``, or in 2D a missing or bad ``height`` or a position off the x-z plane.
        """
        if dimension not in DIMENSIONS:
            raise ValueError(f"[scene] dimension = {dimension!r}: must be 2 (disks) or 3 (spheres)")
        x = np.ascontiguousarray(position, dtype=float).copy()
        n = len(x)
        r = np.ascontiguousarray(radius, dtype=float).copy()
        if dimension == 2:
            if height is None or not np.isfinite(height) or height <= 0:
                raise ValueError(f"[scene] height = {height!r}: 2D disks need a height > 0 (m)")
            off = np.flatnonzero(x[:, 1] != 0.0)
            if off.size:
                k = int(off[0])
                raise ValueError(f"particles.position[{k}] = {x[k].tolist()}: 2D disks lie in the x-z plane "
                                 f"(y = 0)")
        mass = particle_mass(dimension, np.broadcast_to(np.asarray(density, dtype=float), (n,)), r, height)
        v = np.zeros((n, 3)) if velocity is None else np.ascontiguousarray(velocity, dtype=float).copy()
        w = np.zeros((n, 3)) if angular_velocity is None else np.ascontiguousarray(angular_velocity,
                                                                                      dtype=float).copy()
        state = cls(dimension, height if dimension == 2 else None, x, v, w, np.zeros((n, 3)), np.zeros((n, 3)),
                    mass, moment_of_inertia(dimension, mass, r), r,
                    r.copy() if radius_ref is None else np.asarray(radius_ref, dtype=float).copy(),
                    np.asarray(temperature, dtype=float).copy())
        state.v *= state.linear_dof
        state.w *= state.angular_dof
        return state

    @property
    def n(self) -> int:
        """Number of particles."""
        return len(self.mass)

    @property
    def axes(self) -> tuple[int, ...]:
        """The axes a particle translates along (x and z in 2D)."""
        return (0, 2) if self.dimension == 2 else (0, 1, 2)

    @property
    def spin_axes(self) -> tuple[int, ...]:
        """The axes a particle rotates about (y in 2D)."""
        return (1,) if self.dimension == 2 else (0, 1, 2)

    @property
    def linear_dof(self) -> np.ndarray:
        """1 for the :attr:`axes`, 0 for the others."""
        return _mask(self.axes)

    @property
    def angular_dof(self) -> np.ndarray:
        """1 for the :attr:`spin_axes`, 0 for the others."""
        return _mask(self.spin_axes)

    def kinetic_energy(self) -> float:
        """Translational plus rotational kinetic energy, J."""
        return float(0.5 * self.mass @ np.einsum("ij,ij->i", self.v, self.v)
                     + 0.5 * self.inertia @ np.einsum("ij,ij->i", self.w, self.w))

    def momentum(self) -> np.ndarray:
        """Total momentum (dimension,), kg m/s."""
        return self.mass @ self.v

    def solid_volume(self) -> float:
        """Sum of the particle volumes (2D: disk areas times the height), m^3."""
        if self.dimension == 3:
            return float(np.sum(4.0 / 3.0 * np.pi * self.radius**3))
        return float(np.sum(np.pi * self.radius**2) * self.height)
