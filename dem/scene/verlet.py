r"""The keys only the verlet engine reads (:mod:`dem.engines.verlet`, velocity-Verlet steps with any contact law that
spins), as its own spec (:class:`VerletSpec`): the step, the coupled thermal network's interval and step, a prescribed
temperature schedule.

* ``[solver]`` -- ``dt`` (s, or "auto": :math:`t_{MD} = \pi/(50 \omega)`, Luding 2005 eq. 6; a given step at most the stable one);
  ``skin`` (m, default ``VERLET_SKIN`` x the mean radius); ``thermal_interval`` (s) and ``integrator`` (implicit |
  crank-nicolson) of a coupled thermal network;
* ``[temperature]`` -- a prescribed schedule ``time``, ``value``, ``relaxation_time`` (:mod:`dem.scene.events`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dem.geometry.inertia import moment_of_inertia, particle_mass
from dem.laws.contact import law_module
from dem.scene.events import TemperatureSchedule
from dem.scene.schema import number

VERLET_SKIN = 0.1             # x the mean radius
DEFAULT_THERMAL_STEPS = 1000  # mechanical steps per thermal step when [solver] thermal_interval is not given


@dataclass(frozen=True)
class VerletSpec:
    """What the verlet engine reads of a scene beyond the moving part every engine reads
    (:class:`dem.scene.motion.MotionSpec`).

    Parameters
    ----------
    schedule : dem.scene.events.TemperatureSchedule or None
        A prescribed temperature history; None: none.
    thermal_interval : float
        Time between the steps of a coupled thermal network (s).
    thermal_integrator : str
        That network's step: ``"implicit"`` or ``"crank-nicolson"``.
    relaxation_time : float
        The relaxation time of a relaxing material (s; Luding 2005, ``t0`` of eqs. 11-12), 0 without one.
    """

    schedule: TemperatureSchedule | None
    thermal_interval: float
    thermal_integrator: str
    relaxation_time: float = 0.0


def time_steps(contact, mass: np.ndarray, inertia: np.ndarray, radius: np.ndarray, dimension: int,
               height: float | None) -> tuple[float, float]:
    """``(dt, stable)`` of the contact law ``contact.law`` (its ``time_steps``): the step ``dt = "auto"`` takes, and
    the largest velocity-Verlet step that stays stable for the stiffest contact; a two-particle contact of the mean
    radius sets the typical mass.

    Parameters
    ----------
    contact : object
        The contact law's material (:mod:`dem.laws.contact`), with its ``law`` and ``density`` (kg/m^3).
    mass : numpy.ndarray
        (N,) particle masses (kg).
    inertia : numpy.ndarray
        (N,) moments of inertia (kg m^2).
    radius : numpy.ndarray
        (N,) radii (m).
    dimension : int
        3 (spheres) or 2 (disks).
    height : float or None
        Height of the 2D disks (m); None in 3D.

    Returns
    -------
    tuple of (float, float)
        ``(dt, stable)`` (s).
    """
    m_mean = float(particle_mass(dimension, contact.density, np.mean(radius), height))
    return law_module(contact.law).time_steps(contact, mass, inertia, radius, m_mean)


def verlet_step(particles, solver, contact, dimension: int, height: float | None) -> float:
    """The mechanical step (s) of ``[solver] dt``: ``"auto"`` takes t_MD of the contact law, a number must not exceed
    the stable step of the stiffest contact (:func:`time_steps`).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles (their radii and materials' densities).
    solver : dem.scene.parse.SolverSpec
        The scene's solver (its ``dt`` and ``t_end``, s).
    contact : object
        The contact law's material (:mod:`dem.laws.contact`).
    dimension : int
        3 (spheres) or 2 (disks).
    height : float or None
        Height of the 2D disks (m); None in 3D.

    Returns
    -------
    float
        The step (s).

    Raises
    ------
    ValueError
        A step above the stable one, or more steps than one run can take.
    """
    density = np.array([m.density for m in particles.materials])[particles.material]
    mass = particle_mass(dimension, density, particles.radius, height)
    t_md, stable = time_steps(contact, mass, moment_of_inertia(dimension, mass, particles.radius), particles.radius,
                              dimension, height)
    if solver.dt == "auto":
        dt = t_md
    else:
        dt = float(solver.dt)
        if dt > stable:
            raise ValueError(f"[solver] dt = {dt:.6g} s: above the stable step {stable:.6g} s of the stiffest contact "
                             f"(2/omega of law = \"{contact.law}\" for the lightest pair); use dt <= {stable:.6g} s or "
                             f"dt = \"auto\" ({t_md:.6g} s)")
    stable_steps = solver.t_end / dt
    if stable_steps > 1e10:
        raise ValueError(f"[solver] t_end / dt = {stable_steps:.3g} steps: beyond what one run can take; shorten t_end")
    return dt


def parse_verlet(doc: dict, physics, contact, solver, dt: float, output_interval: float) -> VerletSpec:
    """The verlet engine's own keys of a scene (module docstring) but the step (:func:`verlet_step`).

    Parameters
    ----------
    doc : dict
        The parsed TOML document (its ``[temperature]`` and ``[solver]`` tables).
    physics : sequence of str
        The scene's ``[scene] physics``.
    contact : object
        The contact law's material (:mod:`dem.laws.contact`); its ``t0`` (s), where it has one, is the schedule's
        default relaxation time.
    solver : dem.scene.parse.SolverSpec
        The scene's solver (its ``integrator``).
    dt : float
        The mechanical step (s).
    output_interval : float
        Time between rows of ``timeseries.csv`` (s): the thermal interval at most, by default.

    Returns
    -------
    VerletSpec
        The spec.

    Raises
    ------
    ValueError
        A schedule with a thermal network, a schedule without its ``time`` or ``value``, or a bad
        ``thermal_interval``.
    """
    relaxation_time = float(getattr(contact, "t0", 0.0))  # the material's relaxation time, where its law has one
    schedule = None
    if "temperature" in doc:
        t = doc["temperature"]
        if "thermal" in physics:
            raise ValueError("[temperature]: a prescribed schedule and a thermal network both set the temperature; "
                             "give one (heat the walls or fix particles instead)")
        for key in ("time", "value"):
            if key not in t:
                raise ValueError(f"[temperature] {key}: required")
        schedule = TemperatureSchedule.build(t["time"], t["value"], t.get("relaxation_time", relaxation_time))
    thermal_interval = number(doc.get("solver", {}), "solver", "thermal_interval",
                              min(output_interval, DEFAULT_THERMAL_STEPS * dt), positive=True)
    return VerletSpec(schedule, thermal_interval, solver.integrator, relaxation_time)
