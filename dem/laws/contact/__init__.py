"""Contact laws of particles that move, as plug-ins: each law is one module, registered by one line of
:data:`CONTACT_LAWS`, and the engines' compiled loops take its kernels in at compile time
(:mod:`dem.laws.contact.binding`).

A contact law module defines (SI units; forces on particle i, the unit normal ``n`` from j to i, 3-vectors as
3-tuples; the compiled kernels ``numba.njit`` with ``inline="always"``):

* ``NAME``; ``Material``, a frozen dataclass of its parameters with ``params()`` (a float64 array; ``N_PARAMS``
  entries) and a ``density``; ``PAIR_HISTORY``, ``WALL_HISTORY`` (the names of the numbers each pair and each
  particle-wall contact carries from step to step) and ``PARTICLE_STATE`` (those each particle carries); ``SPINS``
  (its tangential forces make torques) and ``DRAG`` (it has a drag on every particle); ``SCHEMA_ROWS``, its
  material's fields documented for the scene schema (:mod:`dem.scene.schema`: keys, type and unit, meaning);
* ``initial_state(material, T, mass)`` -- the particles' state columns from their initial temperatures and masses,
  (N, S); ``reference_radius(material, radius, T)`` -- the radii the law's thermal expansion starts from;
  ``time_steps(material, mass, inertia, radius, m_mean)`` -- ``(dt, stable)``: the step ``dt = "auto"`` takes and the
  largest a velocity-Verlet step may take; ``largest_reach(material, radius)`` -- the farthest beyond touching any
  contact of these particles acts (the neighbour lists' skin must exceed it; 0 for a law without forces at a
  distance);
* ``pair_constants(ri, rj, params)`` -- two numbers of a pair that depend on its radii alone, which the loops keep
  per pair and compute again only when the radii or the list changed, where ``PAIR_CONSTANTS`` names them (a law
  that keeps none has ``PAIR_CONSTANTS = ()`` and returns two zeros);
* ``pair_force(c, i, j, hist_in, hist, state, T, delta, d, n, vr, vn, ri, rj, planar, dt, params, const) -> (f_n,
  f_t0, f_t1, f_t2)`` -- the force on i of pair ``c`` at overlap ``delta`` (centre distance ``d``) with relative
  surface velocity ``vr`` (normal part ``vn``) and the pair's ``pair_constants`` ``const``, reading the pair's
  history from row ``c`` of ``hist_in`` and writing it to row ``c`` of ``hist``;
  ``forget_pair(c, hist_in, hist)`` -- the pair opened (returns whether it had a history); ``reach(c, hist, ri, rj,
  params)`` -- how far beyond touching the pair still acts (0 for a law without forces at a distance);
* ``wall_force(k, m, hist_in, hist, state, T, delta, dist, n, vr, vn, rk, dt, params)``, ``forget_wall(k, m, hist_in,
  hist)`` and ``wall_reach(k, m, hist, rk, params)`` -- the same for particle k on wall m (histories indexed
  ``[k, m]``);
* ``update_particles(elapsed, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt)`` -- before the
  forces of every step: the temperatures ``T0 + T_rate elapsed`` and what the law makes of them (radii, state);
  returns whether a radius changed;
  ``drag(k, radius, params)`` -- the drag coefficient of particle k (kg/s) where ``DRAG``.
"""

from __future__ import annotations

import importlib

#: The contact laws by the name ``[contact] law`` gives, each as the module that implements it.
CONTACT_LAWS = {
    "luding": "dem.laws.contact.luding",  # Luding, Manetsberger & Mueller 2005: sintering, hysteretic normal law
    "zohdi": "dem.laws.contact.zohdi",  # Zohdi 2014: power law on the contact area, bonds, thermal softening
    "hertz_mindlin": "dem.laws.contact.hertz_mindlin",  # Hertz, Tsuji's damping (restitution e), Mindlin, Coulomb
    "jkr": "dem.laws.contact.jkr",  # Johnson-Kendall-Roberts 1971 adhesion, with Hertz-Mindlin's damping and friction
}


#: One line on each contact law, for ``python -m dem laws``.
DESCRIPTIONS = {
    "luding": "sintering: hysteretic normal law with cohesion, temperature-dependent stiffness, friction "
              "(Luding, Manetsberger & Mueller 2005)",
    "zohdi": "power law on the contact area, bonds, thermal softening; staggered engine (Zohdi 2014)",
    "hertz_mindlin": "elastic spheres: Hertz normal force with Tsuji's damping (restitution e), Mindlin tangential "
                     "stiffness, Coulomb friction",
    "jkr": "Johnson-Kendall-Roberts 1971 adhesion, with Hertz-Mindlin's damping and friction",
}


def law_module_name(name) -> str:
    """The module of the contact law ``name``; ``ValueError`` naming the laws for an unknown one.

    Parameters
    ----------
    name : str
        A law of :data:`CONTACT_LAWS` (``"luding"``, say).

    Returns
    -------
    str
        The law's dotted module name.

    Raises
    ------
    ValueError
        ``name`` is not a known law.
    """
    if not isinstance(name, str) or name not in CONTACT_LAWS:
        raise ValueError(f"[contact] law = {name!r}: must be one of {', '.join(CONTACT_LAWS)}")
    return CONTACT_LAWS[name]


def law_module(name):
    """The contact law ``name`` (:data:`CONTACT_LAWS`), imported.

    Parameters
    ----------
    name : str
        A law of :data:`CONTACT_LAWS`.

    Returns
    -------
    object
        The law's module.

    Raises
    ------
    ValueError
        ``name`` is not a known law.
    """
    return importlib.import_module(law_module_name(name))
