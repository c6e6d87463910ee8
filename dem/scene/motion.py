r"""The part of a scene that makes particles move (``[scene] physics`` with ``"mechanical"``): TOML into a
:class:`MotionSpec`.

Tables and keys (SI units; the README's scene schema lists them with their defaults):

* ``[scene] dimension`` (3: spheres; 2: disks in the x-z plane) and ``height`` (m, the disks' height);
* ``[particles] velocity``, ``angular_velocity`` (lists of 3-vectors; or the generator's random ``speed``);
* ``[contact]`` -- the contact law and its parameters (``law = "luding"``, Luding 2005; ``law = "zohdi"``,
  Zohdi 2014: its stepping, current and electrode keys are those of :mod:`dem.scene.zohdi`);
* ``[[walls]]`` -- planes that move: ``motion`` fixed | stress | strain | vibrate with ``pressure``, ``mass``,
  ``damping``, ``velocity``, ``amplitude``, ``frequency`` (:mod:`dem.geometry.walls`); ``temperature`` optional;
* ``[gravity] acceleration`` (m/s^2, a 3-vector);
* ``[temperature]`` -- a prescribed schedule ``time``, ``value``, ``relaxation_time`` (:mod:`dem.scene.events`);
* ``[[phases]]`` -- from time ``start`` on, other friction or damping (``mu``, ``mu_wall``, ``gamma_n``,
  ``gamma_t``): Luding 2005 prepares frictionless and switches the friction at t_heat; and other wall speeds
  (``wall_velocity = {name = v}``, m/s inward, for strain walls): a wall pushed, held and pulled away (Zohdi 2014,
  Sec. 7);
* ``[start] state`` -- begin from a saved state (:mod:`dem.scene.state_file`) instead of ``[particles]``;
* ``[solver]`` -- ``t_end``; ``dt`` (s, or "auto": :math:`t_{MD} = \pi/(50 \omega)`, Luding 2005 eq. 6); ``skin`` (m);
  ``thermal_interval`` (s) and ``integrator`` (implicit | crank-nicolson) of a coupled thermal network;
* ``[output]`` -- ``interval`` (s between rows of ``timeseries.csv``), ``vtu_interval`` (s between snapshots).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from dem.laws.contact import law_module
from dem.geometry.motion import particle_mass, moment_of_inertia
from dem.geometry.particles import finite_array
from dem.scene.events import TemperatureSchedule
from dem.scene import zohdi as zscene

DEFAULT_SKIN = 0.1            # x the mean radius
DEFAULT_OUTPUT_ROWS = 100     # rows of timeseries.csv when [output] interval is not given
DEFAULT_THERMAL_STEPS = 1000  # mechanical steps per thermal step when [solver] thermal_interval is not given
@dataclass(frozen=True)
class MotionSpec:
    """The moving part of a scene (module docstring), as :func:`parse_motion` reads it.

    Parameters
    ----------
    dimension : int
        3 (spheres) or 2 (disks in the x-z plane).
    height : float or None
        Height of the 2D disks (m); None in 3D.
    velocity : numpy.ndarray or None
        (N, 3) initial velocities (m/s); None: at rest.
    angular_velocity : numpy.ndarray or None
        (N, 3) initial angular velocities (rad/s); None: at rest.
    walls : tuple of dem.geometry.walls.Wall
        The walls, fixed or moving.
    gravity : tuple of float
        The gravitational acceleration [x, y, z] (m/s^2).
    schedule : dem.scene.events.TemperatureSchedule or None
        A prescribed temperature history; None: none.
    dt : float
        The mechanical time step (s).
    stable_dt : float
        The largest stable velocity-Verlet step for the stiffest contact (s).
    skin : float
        The neighbour list's skin (m).
    thermal_interval : float
        Time between the steps of a coupled thermal network (s).
    thermal_integrator : str
        That network's step: ``"implicit"`` or ``"crank-nicolson"``.
    output_interval : float
        Time between rows of ``timeseries.csv`` (s).
    vtu_interval : float
        Time between VTU snapshots (s).
    phases : tuple
        ``(start time (s), {material field: value})``, sorted by start.
    start : dict or None
        The saved state (:func:`dem.scene.state_file.load`) the run begins from; None: the scene's particles.
    wall_phases : tuple
        ``(start time (s), {wall name: inward velocity (m/s)})``, sorted by start.
    stepping : dem.scene.zohdi.ZohdiStepping or None
        The implicit stepping of ``law = "zohdi"``; None for other laws.
    control : int or None
        With ``law = "zohdi"``: the axis (0, 1, 2) the powder bed stands and is pressed along; None otherwise.
    frames : int
        With ``law = "zohdi"``: the number of rendered frames (PNG) over the run.
    relaxation_time : float
        The relaxation time of a relaxing material (s; Luding 2005, ``t0`` of eqs. 11-12), 0 without one.
    """

    dimension: int
    height: float | None
    velocity: np.ndarray | None
    angular_velocity: np.ndarray | None
    walls: tuple
    gravity: tuple
    schedule: TemperatureSchedule | None
    dt: float
    stable_dt: float
    skin: float
    thermal_interval: float
    thermal_integrator: str
    output_interval: float
    vtu_interval: float
    phases: tuple = ()        # (start time, {material field: value}), sorted by start
    start: dict | None = None  # a saved state (dem.scene.state_file.load) the run begins from
    wall_phases: tuple = ()   # (start time, {wall name: inward velocity}), sorted by start
    stepping: object = None   # law = "zohdi": its implicit stepping (dem.scene.zohdi.ZohdiStepping)
    control: int | None = None  # law = "zohdi": the axis the powder bed stands and is pressed along
    frames: int = 0           # law = "zohdi": rendered frames (PNG) over the run
    relaxation_time: float = 0.0  # a law with a relaxing material (Luding 2005: t0 of k1(T, t), eqs. 11-12)


def _num(table, section, key, default=None, positive=False, nonnegative=False):
    if key not in table:
        return default
    v = table[key]
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        raise ValueError(f"[{section}] {key} = {v!r}: must be a finite number")
    if positive and v <= 0:
        raise ValueError(f"[{section}] {key} = {v!r}: must be > 0")
    if nonnegative and v < 0:
        raise ValueError(f"[{section}] {key} = {v!r}: must be >= 0")
    return float(v)


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


def parse_motion(doc: dict, particles, solver, physics, contact, velocity=None, start=None, walls=()) -> MotionSpec:
    """The moving part of a scene (module docstring); ``particles``, ``solver``, the ``contact`` material and the
    ``walls`` are already parsed (the schema has checked every key); ``velocity`` comes from a generator (its random
    ``speed``); ``start`` is a saved state.

    Parameters
    ----------
    doc : dict
        The parsed TOML document.
    particles : dem.geometry.particles.Particles
        The scene's particles.
    solver : dem.scene.parse.SolverSpec
        The scene's solver (transient, with ``t_end``).
    physics : sequence of str
        The scene's ``[scene] physics``.
    contact : object
        The contact law's material (:mod:`dem.laws.contact`).
    velocity : numpy.ndarray or None
        (N, 3) velocities from a generator (m/s); None: none.
    start : dict or None
        A saved state to begin from; None: none.
    walls : tuple of dem.geometry.walls.Wall
        The scene's walls.

    Returns
    -------
    MotionSpec
        The moving part of the scene.

    Raises
    ------
    ValueError
        A bad table or key (the message names it).
    """
    meta = doc.get("scene", {})
    dimension = meta.get("dimension", 3)
    if dimension not in (2, 3) or isinstance(dimension, bool):
        raise ValueError(f"[scene] dimension = {dimension!r}: must be 2 (disks) or 3 (spheres)")
    height = _num(meta, "scene", "height", positive=True)
    if dimension == 2 and height is None:
        raise ValueError("[scene] height: required for 2D disks (m)")
    if dimension == 3 and height is not None:
        raise ValueError("[scene] height: only for 2D disks (dimension = 2)")
    if dimension == 2 and "thermal" in physics:
        raise ValueError("[scene] physics: thermal coupling needs 3D spheres (dimension = 3): the neck conductance "
                         "laws are for spheres, and 2D disks joined by a neck have no such law here")
    if solver.mode != "transient" or solver.t_end is None:
        raise ValueError("[solver] mode = \"transient\" and t_end are required for moving particles")
    ptable = doc.get("particles", {})
    n = particles.n
    angular = None
    if "velocity" in ptable:
        velocity = finite_array("[particles] velocity", ptable["velocity"], (3,))
    if "angular_velocity" in ptable:
        angular = finite_array("[particles] angular_velocity", ptable["angular_velocity"], (3,))
    for name, arr in (("velocity", velocity), ("angular_velocity", angular)):
        if arr is not None and len(arr) != n:
            raise ValueError(f"[particles] {name} has {len(arr)} entries but position has {n}")
    densities = {m.density for m in particles.materials}
    if densities != {contact.density}:
        raise ValueError(f"[contact] density = {contact.density:g}: differs from [material] density "
                         f"{', '.join(f'{d:g}' for d in sorted(densities))} kg/m^3; give it once, in [material]")
    if start is not None:
        saved_dimension, saved_height = (start["dimension"], start["height"]) if start["moving"] else (3, None)
        if saved_dimension != dimension or (dimension == 2 and saved_height != height):
            raise ValueError(f"[start] state: saved for dimension {saved_dimension} (height {saved_height}), "
                             f"the scene has dimension {dimension} (height {height})")
        if start["moving"]:
            velocity, angular = start["v"], start["w"]
    gravity = (0.0, 0.0, 0.0)
    if "gravity" in doc:
        g = finite_array("[gravity] acceleration", doc["gravity"].get("acceleration", [0.0, 0.0, 0.0]), ())
        if g.shape != (3,):
            raise ValueError("[gravity] acceleration: must be a 3-vector (m/s^2)")
        gravity = tuple(float(x) for x in g)
    phases = tuple(sorted((_phase(k, t, contact) for k, t in enumerate(doc.get("phases", []))), key=lambda p: p[0]))
    wall_phases = tuple((start, walls_v) for start, _, walls_v in phases if walls_v)
    _check_wall_phases(wall_phases, walls)
    if contact.law == "zohdi":
        return zscene.zohdi_motion(doc, particles, solver, physics, start, walls, gravity, velocity,
                                   tuple(p[:2] for p in phases), wall_phases, dimension)
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
    solver_table = doc.get("solver", {})
    skin = _num(solver_table, "solver", "skin", DEFAULT_SKIN * float(np.mean(particles.radius)), positive=True)
    out = doc.get("output", {})
    output_interval = _num(out, "output", "interval", solver.t_end / DEFAULT_OUTPUT_ROWS, positive=True)
    vtu_interval = _num(out, "output", "vtu_interval", 0.0, nonnegative=True)
    thermal_interval = _num(solver_table, "solver", "thermal_interval",
                            min(output_interval, DEFAULT_THERMAL_STEPS * dt), positive=True)
    return MotionSpec(dimension, height, velocity, angular, walls, gravity, schedule, dt, stable, skin,
                      thermal_interval, solver.integrator, output_interval, vtu_interval,
                      phases=tuple(p[:2] for p in phases if p[1]), start=start, wall_phases=wall_phases,
                      relaxation_time=relaxation_time)


def _phase(k: int, table: dict, contact) -> tuple:
    """``(start, {material field: value}, {wall: velocity})`` of ``[[phases]]`` entry ``k`` (the schema has checked
    its keys); the material it makes is checked now, not when the phase starts."""
    start = _num(table, f"phases][{k}", "start", nonnegative=True)
    if start is None:
        raise ValueError(f"[phases][{k}] start: required (s)")
    walls = table.get("wall_velocity", {})
    if not isinstance(walls, dict):
        raise ValueError(f"[phases][{k}] wall_velocity: must be a table {{wall name = velocity (m/s, inward)}}")
    values = {key: v if isinstance(v, bool) else _num(table, f"phases][{k}", key) for key, v in table.items()
              if key not in ("start", "wall_velocity")}
    try:
        replace(contact, **values)
    except ValueError as exc:
        raise ValueError(f"[phases][{k}] {str(exc).removeprefix('contact.')}") from None
    return start, values, {str(name): _num(walls, f"phases][{k}] wall_velocity", name) for name in walls}


def _check_wall_phases(wall_phases, walls) -> None:
    """Every wall a phase changes the speed of exists and moves at a constant speed (``motion = "strain"``)."""
    motions = {w.name: w.motion for w in walls}
    for start, speeds in wall_phases:
        for name in speeds:
            if motions.get(name) != "strain":
                raise ValueError(f"[phases] wall_velocity.{name}: " + (
                    f"no wall named {name!r} (walls: {', '.join(motions) or 'none'})" if name not in motions else
                    f"the wall's motion is {motions[name]!r}; only strain walls (constant speed) change speed"))
