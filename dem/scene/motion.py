r"""The part of a scene that makes particles move (``[scene] physics`` with ``"mechanical"``): TOML into a
:class:`MotionSpec`.

Tables and keys (SI units; the README's scene schema lists them with their defaults):

* ``[scene] dimension`` (3: spheres; 2: disks in the x-z plane) and ``height`` (m, the disks' height);
* ``[particles] velocity``, ``angular_velocity`` (lists of 3-vectors; or the generator's random ``speed``);
* ``[contact]`` -- the contact law and its parameters (``law = "luding"``, Luding 2005; ``law = "zohdi"``,
  Zohdi 2014);
* ``[[walls]]`` -- planes that move: ``motion`` fixed | stress | strain | vibrate with ``pressure``, ``mass``,
  ``damping``, ``velocity``, ``amplitude``, ``frequency`` (:mod:`dem.geometry.walls`); ``temperature`` optional;
* ``[gravity] acceleration`` (m/s^2, a 3-vector);
* ``[[phases]]`` -- from time ``start`` on, other friction or damping (``mu``, ``mu_wall``, ``gamma_n``,
  ``gamma_t``): Luding 2005 prepares frictionless and switches the friction at t_heat; and other wall speeds
  (``wall_velocity = {name = v}``, m/s inward, for strain walls): a wall pushed, held and pulled away (Zohdi 2014,
  Sec. 7);
* ``[start] state`` -- begin from a saved state (:mod:`dem.scene.state_file`) instead of ``[particles]``;
* ``[solver]`` -- ``t_end``; ``skin`` (m, the neighbour list's; its default is the engine's);
* ``[output]`` -- ``interval`` (s between rows of ``timeseries.csv``), ``vtu_interval`` (s between snapshots).

Each engine that moves particles reads keys of its own, parsed into its own spec (``MotionSpec.verlet`` or
``MotionSpec.staggered``): :mod:`dem.scene.verlet` (the step, a coupled thermal network's interval, a prescribed
temperature schedule) and :mod:`dem.scene.staggered` (Zohdi 2014's implicit stepping, the powder bed's axis).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from dem.geometry.particles import finite_array
from dem.scene.schema import number
from dem.scene.staggered import STAGGERED_SKIN, StaggeredSpec, parse_staggered
from dem.scene.verlet import VERLET_SKIN, VerletSpec, parse_verlet, verlet_step

DEFAULT_OUTPUT_ROWS = 100     # rows of timeseries.csv when [output] interval is not given
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
    dt : float
        The mechanical time step (s; the staggered engine's first step).
    skin : float
        The neighbour list's skin (m).
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
    verlet : dem.scene.verlet.VerletSpec or None
        The verlet engine's own keys; None on the staggered engine.
    staggered : dem.scene.staggered.StaggeredSpec or None
        The staggered engine's own keys; None on the verlet engine.
    """

    dimension: int
    height: float | None
    velocity: np.ndarray | None
    angular_velocity: np.ndarray | None
    walls: tuple
    gravity: tuple
    dt: float
    skin: float
    output_interval: float
    vtu_interval: float
    phases: tuple = ()        # (start time, {material field: value}), sorted by start
    start: dict | None = None  # a saved state (dem.scene.state_file.load) the run begins from
    wall_phases: tuple = ()   # (start time, {wall name: inward velocity}), sorted by start
    verlet: VerletSpec | None = None  # the verlet engine's own keys
    staggered: StaggeredSpec | None = None  # the staggered engine's own keys


def parse_motion(doc: dict, particles, solver, physics, contact, velocity=None, start=None, walls=(),
                 engine: str = "verlet") -> MotionSpec:
    """The moving part of a scene (module docstring); ``particles``, ``solver``, the ``contact`` material and the
    ``walls`` are already parsed (the schema has checked every key); ``velocity`` comes from a generator (its random
    ``speed``); ``start`` is a saved state; the keys of the ``engine`` go into its own spec.

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
    engine : str
        The engine that moves the particles: ``"verlet"`` or ``"staggered"`` (:mod:`dem.engines`).

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
    height = number(meta, "scene", "height", positive=True)
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
    solver_table, out = doc.get("solver", {}), doc.get("output", {})
    staggered = parse_staggered(doc, walls, dimension) if engine == "staggered" else None
    dt = staggered.stepping.dt if staggered else verlet_step(particles, solver, contact, dimension, height)
    skin = number(solver_table, "solver", "skin", (STAGGERED_SKIN if staggered else VERLET_SKIN)
                  * float(np.mean(particles.radius)), positive=True)
    output_interval = number(out, "output", "interval", solver.t_end / DEFAULT_OUTPUT_ROWS, positive=True)
    vtu_interval = number(out, "output", "vtu_interval", 0.0, nonnegative=True)
    if staggered:  # Zohdi 2014 starts from the scene's particles and changes no material over the run
        return MotionSpec(dimension, None, velocity, None, walls, gravity, dt, skin, output_interval, vtu_interval,
                          wall_phases=wall_phases, staggered=staggered)
    return MotionSpec(dimension, height, velocity, angular, walls, gravity, dt, skin, output_interval, vtu_interval,
                      phases=tuple(p[:2] for p in phases if p[1]), start=start, wall_phases=wall_phases,
                      verlet=parse_verlet(doc, physics, contact, solver, dt, output_interval))


def _phase(k: int, table: dict, contact) -> tuple:
    """``(start, {material field: value}, {wall: velocity})`` of ``[[phases]]`` entry ``k`` (the schema has checked
    its keys); the material it makes is checked now, not when the phase starts."""
    start = number(table, f"phases][{k}", "start", nonnegative=True)
    if start is None:
        raise ValueError(f"[phases][{k}] start: required (s)")
    walls = table.get("wall_velocity", {})
    if not isinstance(walls, dict):
        raise ValueError(f"[phases][{k}] wall_velocity: must be a table {{wall name = velocity (m/s, inward)}}")
    values = {key: v if isinstance(v, bool) else number(table, f"phases][{k}", key) for key, v in table.items()
              if key not in ("start", "wall_velocity")}
    try:
        replace(contact, **values)
    except ValueError as exc:
        raise ValueError(f"[phases][{k}] {str(exc).removeprefix('contact.')}") from None
    return start, values, {str(name): number(walls, f"phases][{k}] wall_velocity", name) for name in walls}


def _check_wall_phases(wall_phases, walls) -> None:
    """Every wall a phase changes the speed of exists and moves at a constant speed (``motion = "strain"``)."""
    motions = {w.name: w.motion for w in walls}
    for start, speeds in wall_phases:
        for name in speeds:
            if motions.get(name) != "strain":
                raise ValueError(f"[phases] wall_velocity.{name}: " + (
                    f"no wall named {name!r} (walls: {', '.join(motions) or 'none'})" if name not in motions else
                    f"the wall's motion is {motions[name]!r}; only strain walls (constant speed) change speed"))
