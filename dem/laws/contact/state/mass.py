"""Particles that carry their masses, for a damping that needs the contact's effective mass m*
(:mod:`dem.laws.contact.damping.tsuji`), and their temperatures, which do not change their radii
(:mod:`dem.laws.contact.state.temperature`): a state sub-model of the contact laws
(:mod:`dem.laws.contact.composition`)."""

from __future__ import annotations

import numpy as np

from dem.laws.contact.state import temperature

PARAMS = None  # no parameters
FIELDS = {}
SCHEMA_ROWS = ()
PARTICLE_STATE = ("mass",)  # each particle's mass (kg)
reference_radius = temperature.reference_radius
update_particles = temperature.update_particles


def initial_state(material, T: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """Each particle's mass, the state the damping reads m* from.

    Parameters
    ----------
    material : object
        The contact material (not read).
    T : numpy.ndarray
        (N,) initial temperatures (only their count is read).
    mass : numpy.ndarray
        (N,) masses (kg).

    Returns
    -------
    numpy.ndarray
        (N, 1) the masses (kg).
    """
    return np.array(mass, dtype=float).reshape(len(T), 1)
