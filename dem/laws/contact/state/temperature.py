"""Particles that carry nothing from step to step but their temperatures, ``T0 + T_rate elapsed``, which do not change
their radii: a state sub-model of the contact laws (:mod:`dem.laws.contact.composition`)."""

from __future__ import annotations

import numpy as np
from numba import njit

from dem.laws.contact.kernel_options import JIT

PARAMS = None  # no parameters
FIELDS = {}
SCHEMA_ROWS = ()
PARTICLE_STATE = ()


def initial_state(material, T: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """No state per particle.

    Parameters
    ----------
    material : object
        The contact material (not read).
    T : numpy.ndarray
        (N,) initial temperatures (only their count is read).
    mass : numpy.ndarray
        (N,) masses (kg; not read).

    Returns
    -------
    numpy.ndarray
        An (N, 0) array.
    """
    return np.zeros((len(T), 0))


def reference_radius(material, radius: np.ndarray, T: np.ndarray) -> np.ndarray:
    """The radii do not change with temperature.

    Parameters
    ----------
    material : object
        The contact material (not read).
    radius : numpy.ndarray
        (N,) radii (m).
    T : numpy.ndarray
        (N,) temperatures (not read).

    Returns
    -------
    numpy.ndarray
        (N,) a copy of ``radius`` (m).
    """
    return np.array(radius, dtype=float)


@njit(**JIT)
def update_particles(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    """The temperatures ``T0 + T_rate elapsed`` (uniform: one value); the radii do not change (returns False)."""
    n = T.shape[0]
    for k in range(n):
        T[k] = T0[0] + T_rate[0] * elapsed if uniform else T0[k] + T_rate[k] * elapsed
    return False
