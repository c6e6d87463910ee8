"""Scenes: everything one DEM run needs, read from TOML (``tomllib``) or built from arrays in Python.

:func:`load_scene` reads a file path or a built-in name (``dem/scene/builtin/*.toml``); :func:`parse_scene` validates a
TOML document (a dict) into a :class:`Scene`; :func:`make_scene` builds one from explicit arrays. The schema is
documented in the README (section "Scene schema"). Every problem raises ``ValueError`` naming the table and key (and, for malformed
TOML, the line).
"""

from __future__ import annotations

import math
import pathlib
import tomllib
from dataclasses import dataclass, field, fields

import numpy as np

from dem.scene import packing_files, state_file
from dem.geometry import generators
from dem.geometry.bisection import NECK_HALO
from dem.laws.conductance import ConductanceSpec
from dem.laws.fields import material_from_table
from dem.laws.contact import CONTACT_LAWS, law_module
from dem.scene.electrical import ElectricalSpec, parse_electrical
from dem.geometry.particles import COPPER, Material, Particles, material_indices
from dem.geometry.periodic import AXES, PeriodicBox
from dem.laws.ambient import RADIATION_T_MAX, Convection, Radiation, Sources
from dem.geometry.walls import Wall, check_inside
from dem.network.heat import INTEGRATORS
from dem.network.linsolve import BACKENDS
from dem.output.plots import TEMPERATURE_UNITS
from dem.scene.motion import MotionSpec, parse_motion
from dem.scene.schema import ENGINE_NAMES, TABLES, check, number
from dem.scene.groups import apply_groups
from dem.scene.specimen import Specimen, find_specimen, held_name

SCENE_DIR = pathlib.Path(__file__).with_name("builtin")
MODES = ("transient", "steady")
BOUNDARIES = ("plates", "fixed", "periodic", "none")
RTOL_MIN = 1e-9  # [solver] rtol of dt = "auto"

GENERATOR_KEYS = {
    "chain": {"n", "radius", "overlap"},
    "lattice": {"shape", "radius", "overlap", "structure"},
    "random": {"n", "radius", "overlap", "seed", "radius_spread", "distribution", "jitter"},
    "box": {"n", "radius", "box", "seed", "radius_spread", "speed"},
}


@dataclass(frozen=True)
class SolverSpec:
    """``mode`` steady|transient; transient: ``integrator``, ``dt`` (s or "auto"), ``t_end``, ``rtol`` (auto dt);
    ``linear`` backend (:mod:`dem.network.linsolve`); ``floating`` steady policy; ``max_steps`` guard.

    Parameters
    ----------
    mode : str
        ``"steady"`` (the steady temperatures) or ``"transient"`` (integrate in time to ``t_end``).
    integrator : str
        The transient time stepper, one of ``dem.network.heat.INTEGRATORS``.
    dt : float or str
        The time step (s, > 0), or ``"auto"`` (adaptive, to ``rtol``).
    t_end : float or None
        The time a transient run ends at (s, finite and > 0; required in transient mode).
    rtol : float
        Relative tolerance of the adaptive step ``dt = "auto"``, in ``[RTOL_MIN, 1)``.
    linear : str
        The linear solver: ``"auto"`` or one of ``dem.network.linsolve.BACKENDS``.
    floating : str
        What a steady solve does with a group of particles without a fixed temperature: ``"error"`` (refuse) or
        ``"mean"`` (keep its capacity-weighted mean initial temperature), :func:`dem.network.heat.steady`.
    max_steps : int
        The most time steps a transient run may take (>= 1).

    Raises
    ------
    ValueError
        A field is out of its range; the message names it (``[solver] <key>``).
    """

    mode: str = "steady"
    integrator: str = "crank-nicolson"
    dt: object = "auto"
    t_end: float | None = None
    rtol: float = 1e-3
    linear: str = "auto"
    floating: str = "error"
    max_steps: int = 100_000

    def __post_init__(self):
        if self.mode not in MODES:
            raise ValueError(f"[solver] mode = {self.mode!r}: must be one of {', '.join(MODES)}")
        if self.integrator not in INTEGRATORS:
            raise ValueError(f"[solver] integrator = {self.integrator!r}: must be one of {', '.join(INTEGRATORS)}")
        if self.linear not in ("auto", *BACKENDS):
            raise ValueError(f"[solver] linear = {self.linear!r}: must be one of auto, {', '.join(BACKENDS)}")
        if self.floating not in ("error", "mean"):
            raise ValueError(f"[solver] floating = {self.floating!r}: must be error or mean")
        if isinstance(self.dt, str):
            if self.dt != "auto":
                raise ValueError(f"[solver] dt = {self.dt!r}: must be a number > 0 (s) or \"auto\"")
        elif not _is_number(self.dt) or not math.isfinite(self.dt) or self.dt <= 0:
            raise ValueError(f"[solver] dt = {self.dt!r}: must be a number > 0 (s) or \"auto\"")
        if self.mode == "transient":
            if self.t_end is None:
                raise ValueError("[solver] t_end: required in transient mode (s)")
            if not _is_number(self.t_end) or not math.isfinite(self.t_end) or self.t_end <= 0:
                raise ValueError(f"[solver] t_end = {self.t_end!r}: must be a finite number > 0 (s)")
        if not _is_number(self.rtol) or not (RTOL_MIN <= self.rtol < 1):
            raise ValueError(f"[solver] rtol = {self.rtol!r}: must be in [{RTOL_MIN:g}, 1) (a tighter tolerance "
                             f"only shrinks dt = \"auto\" to round-off)")
        if not isinstance(self.max_steps, int) or isinstance(self.max_steps, bool) or self.max_steps < 1:
            raise ValueError(f"[solver] max_steps = {self.max_steps!r}: must be an integer >= 1")


@dataclass(frozen=True)
class OutputSpec:
    """CSV row every ``every`` steps; VTU snapshot every ``vtu_every`` steps (0: first and last only); a checkpoint
    of a transient run every ``checkpoint_every`` seconds of wall time (:mod:`dem.output.folder`).

    Parameters
    ----------
    every : int
        Steps between rows of the time-series CSV (>= 1).
    vtu_every : int
        Steps between VTU snapshots (>= 0; 0: the first and last only).
    vtu : bool
        Whether to write VTU snapshots at all.
    checkpoint_every : float
        Wall-clock time between checkpoints of a transient run (s, > 0).
    lammps_dump : bool
        Whether to write, at every snapshot, a LAMMPS ``dump custom`` text file of the particles
        (``particles_STEP.dump``: id type radius x y z, velocities, forces and T where the engine has them).

    Raises
    ------
    ValueError
        A field is out of its range; the message names it (``[output] <key>``).
    """

    every: int = 1
    vtu_every: int = 0
    vtu: bool = True
    checkpoint_every: float = 5.0
    lammps_dump: bool = False

    def __post_init__(self):
        for key in ("every", "vtu_every"):
            v = getattr(self, key)
            if not isinstance(v, int) or isinstance(v, bool) or v < (1 if key == "every" else 0):
                raise ValueError(f"[output] {key} = {v!r}: must be an integer >= {1 if key == 'every' else 0}")
        for key in ("vtu", "lammps_dump"):
            if not isinstance(getattr(self, key), bool):
                raise ValueError(f"[output] {key} = {getattr(self, key)!r}: must be true or false")
        if not (isinstance(self.checkpoint_every, (int, float)) and not isinstance(self.checkpoint_every, bool)
                and self.checkpoint_every > 0 and math.isfinite(self.checkpoint_every)):
            raise ValueError(f"[output] checkpoint_every = {self.checkpoint_every!r}: must be a number of seconds > 0")


@dataclass(frozen=True)
class Scene:
    """One DEM run: particles (+ walls), conductance law, ambient sources, solver, outputs, the physics to run;
    ``contact`` the Luding 2005 material of a ``[contact]`` table, or None.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles at the start.
    walls : tuple of dem.geometry.walls.Wall
        The walls of a static packing (the moving walls of particles that move are ``motion.walls``).
    conductance : dem.laws.conductance.ConductanceSpec
        The contact geometry and conductance law.
    sources : dem.laws.ambient.Sources
        The exchanges with the surroundings (convection, radiation).
    solver : SolverSpec
        The thermal solver: steady or transient, and its options.
    output : OutputSpec
        What the run folder gets, and how often.
    physics : tuple of str
        The submodels to run, from ``PHYSICS``.
    name : str
        The scene's name (the file's stem, or a built-in's name).
    description : str
        One line saying what the scene is.
    specimen : dem.scene.specimen.Specimen or None
        The specimen of the effective conductivity ``k_eff = Q L / (A dT)``; None: the scene has none.
    contact : object
        The material of the contact law (:mod:`dem.laws.contact`), or None.
    motion : dem.scene.motion.MotionSpec or None
        The particles' motion (physics with ``"mechanical"``), or None for a static packing.
    electrical : dem.scene.electrical.ElectricalSpec or None
        The current's scheme and electrodes (``"electrical"`` physics), or None.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box, or None.
    engine : str
        The engine that runs the scene (:mod:`dem.engines`), ``"static"`` by default.
    start : dict or None
        The saved state the run starts from (:func:`dem.scene.state_file.load`), or None.
    temperature_unit : str
        The unit of the scene's temperatures, ``"C"`` or ``"K"`` (:func:`temperature_unit`).
    groups : dict
        The ``[[groups]]`` that hold their particles, ``{name: indices}`` (:func:`dem.scene.groups.apply_groups`).
    part : dem.scene.packing_files.parts.Part or None
        Where ``particles`` are in the packing when they are one rank's part of a packing in parts
        (:func:`dem.scene.packing_files.parts.read_part`); None: they are the whole packing.

    Raises
    ------
    ValueError
        A particle's centre starts behind a wall (:func:`dem.geometry.walls.check_inside`).
    """

    particles: Particles
    walls: tuple = ()
    conductance: ConductanceSpec = field(default_factory=ConductanceSpec)
    sources: Sources = field(default_factory=Sources)
    solver: SolverSpec = field(default_factory=SolverSpec)
    output: OutputSpec = field(default_factory=OutputSpec)
    physics: tuple = ("thermal",)
    name: str = "scene"
    description: str = ""
    specimen: Specimen | None = None
    contact: object = None  # the material of the contact law (dem.laws.contact), or None
    motion: MotionSpec | None = None  # particles that move ([scene] physics with "mechanical"), else None
    electrical: ElectricalSpec | None = None  # the current's scheme and electrodes ("electrical" physics)
    box: PeriodicBox | None = None  # a periodic box (dem.geometry.periodic), else None
    engine: str = "static"  # the engine that runs it (dem.engines)
    start: dict | None = None  # the saved state it starts from (dem.scene.state_file.load), else None
    temperature_unit: str = "C"  # the unit of its temperatures, "C" or "K" (:func:`temperature_unit`)
    groups: dict = field(default_factory=dict)  # the [[groups]] that hold their particles, {name: indices}
    part: object = None  # a rank's part of a packing in parts (dem.scene.packing_files.parts.Part), else None

    def __post_init__(self):
        walls = self.motion.walls if self.motion is not None else self.walls
        check_inside(walls, self.particles.position, self.particles.id)
        if self.conductance.nodes != "particles" and self.engine not in ("static", "verlet"):
            raise ValueError(f"[conductance] nodes = {self.conductance.nodes!r}: the static and verlet engines only "
                             f"(this scene runs on {self.engine}, whose step is Zohdi's fixed-point iteration, "
                             f"explicit in each particle's lumped heat, which a massless neck node does not have: not "
                             f"the network's theta step, which solves for the necks); use nodes = \"particles\"")
        if self.conductance.element == "trefftz" and self.engine != "static":
            raise ValueError(f"[conductance] element = \"trefftz\": not with moving particles (engine {self.engine!r}: "
                             f"every thermal step would rebuild every particle's element, about 10 to 70 ms each); "
                             f"use element = \"law\"")

    @property
    def particle_count(self) -> int:
        """The number of particles in the whole packing (more than ``particles`` holds where it is a rank's part)."""
        return self.particles.n if self.part is None else self.part.n

    @property
    def start_time(self) -> float:
        """The time the run starts at -- the saved state's, or 0."""
        return 0.0 if self.start is None else self.start["t"]


PHYSICS = ("thermal", "mechanical", "electrical")  # the submodels a scene can name ([scene] physics)


def check_physics(names) -> None:
    """Every name a submodel that exists (``PHYSICS``); ``electrical`` runs with moving particles, or with
    ``thermal`` on a static packing (its Joule heat is all it does there).

    Parameters
    ----------
    names : sequence of str
        The ``[scene] physics`` names.

    Raises
    ------
    ValueError
        A name is unknown, there is none, or ``electrical`` is named without ``thermal`` or ``mechanical``.
    """
    for name in names:
        if name not in PHYSICS:
            raise ValueError(f"[scene] physics = {name!r}: unknown (available: {', '.join(PHYSICS)})")
    if not names:
        raise ValueError(f"[scene] physics: names no submodel (available: {', '.join(PHYSICS)})")
    if "electrical" in names and "mechanical" not in names and "thermal" not in names:
        raise ValueError("[scene] physics: \"electrical\" on a static packing heats it and runs with \"thermal\": "
                         "[\"thermal\", \"electrical\"] (or [\"mechanical\", \"thermal\", \"electrical\"] "
                         "with [contact] law = \"zohdi\" for particles that move)")


def _is_number(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def make_scene(position, radius, temperature, *, materials=(COPPER,), material=None, fixed=None, heat=None,
               walls=(), law="rojek", conductance: ConductanceSpec | None = None, sources: Sources | None = None,
               solver: SolverSpec | None = None, output: OutputSpec | None = None, name="scene",
               box: PeriodicBox | None = None, **solver_options) -> Scene:
    """A :class:`Scene` from explicit arrays, e.g. for a chain or cluster to compare with FE::

        make_scene(x, r, T, fixed=mask, law="fit", mode="steady")
        make_scene(x, r, T, mode="transient", integrator="implicit", dt=1e-3, t_end=0.1)
        make_scene(x, r, T, box=PeriodicBox(L, drop=[0, 0, 1.0]), law="fit")      # periodic, 1 K drop along z

    Keyword ``solver_options`` are :class:`SolverSpec` fields (``mode``, ``integrator``, ``dt``, ...).

    Parameters
    ----------
    position : array_like
        (N, 3) particle centres (m).
    radius : float or array_like
        Particle radii (m), one per particle.
    temperature : float or array_like
        Initial temperatures (K or degC), one per particle; the held ones keep theirs.
    materials : sequence of dem.geometry.particles.Material
        The materials (copper by default).
    material : array_like or None
        (N,) int, each particle's index into ``materials``; None: all the first.
    fixed : array_like or None
        (N,) bool, True for a particle held at its temperature; None: none held.
    heat : array_like or None
        (N,) internal heat source of each particle (W); None: none.
    walls : sequence of dem.geometry.walls.Wall
        The walls.
    law : str
        The conductance law (``dem.laws.conductance.LAWS``), read only where ``conductance`` is None.
    conductance : dem.laws.conductance.ConductanceSpec or None
        The law and its options; None: ``ConductanceSpec(law=law)``.
    sources : dem.laws.ambient.Sources or None
        Convection and radiation; None: neither.
    solver : SolverSpec or None
        The solver; None: ``SolverSpec(**solver_options)``.
    output : OutputSpec or None
        The outputs; None: the defaults.
    name : str
        The scene's name.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: none.
    **solver_options
        :class:`SolverSpec` fields, read only where ``solver`` is None.

    Returns
    -------
    Scene
        The scene, with the specimen found between its ends (:func:`dem.scene.specimen.find_specimen`).

    Raises
    ------
    ValueError
        A bad array or option; the message names it.
    """
    particles = Particles.from_arrays(position, radius, temperature, materials, material, fixed, heat)
    walls = tuple(walls)
    return Scene(particles, walls, conductance or ConductanceSpec(law=law), sources or Sources(),
                 solver or SolverSpec(**solver_options), output or OutputSpec(), name=name,
                 specimen=find_specimen(particles, walls, box), box=box)


# --------------------------------------------------------------------------------------------------- TOML
def _materials(doc, thermal: bool = True, electrical: bool = False) -> tuple:
    if "material" in doc and "materials" in doc:
        raise ValueError("[material] and [[materials]]: give one or the other")
    tables = doc.get("materials", [doc["material"]] if "material" in doc else None)
    if tables is None:
        raise ValueError("[material]: required (density; conductivity and specific_heat for thermal physics)")
    if not isinstance(tables, list) or not tables:
        raise ValueError("[[materials]]: must be a non-empty array of tables")
    out = []
    for k, t in enumerate(tables):
        section = "material" if "material" in doc else f"materials[{k}]"
        props = {key: number(t, section, key, required=thermal or key == "density")
                 for key in ("conductivity", "density", "specific_heat")}
        props["electrical_conductivity"] = number(t, section, "electrical_conductivity", required=electrical)
        for key, v in props.items():
            if v is not None and v <= 0:
                raise ValueError(f"[{section}] {key} = {v!r}: must be > 0")
        out.append(Material(**props, name=str(t.get("name", f"material{k}"))))
    return tuple(out)


def _explicit_particles(t: dict, materials, base_dir=None, part=None):
    if "file" in t:  # a packing file (dem.scene.packing_files); its box, periodic or not, is returned as the box
        particles, box, held = packing_files.scene_particles(t, materials, base_dir, part)
        return particles, (), None, None, box, held
    extra = sorted(set(t) & set(packing_files.SCENE_KEYS))
    if extra:
        raise ValueError(f"[particles] {extra[0]}: only with file = \"...\" (a packing file)")
    for key in ("position", "radius", "temperature"):
        if key not in t:
            raise ValueError(f"[particles] {key}: required")
    n = len(t["position"]) if isinstance(t["position"], list) else 0
    material = material_indices("[particles] material", t.get("material"), materials, n)
    return Particles.from_arrays(t["position"], t["radius"], t["temperature"], materials, material, t.get("fixed"),
                                 t.get("heat"), prefix="[particles]"), (), None, None, None, None


def _generated_particles(t: dict, materials, dimension: int = 3):
    kind = t.get("kind")
    if not isinstance(kind, str) or kind not in GENERATOR_KEYS:
        raise ValueError(f"[generator] kind = {kind!r}: must be one of {', '.join(GENERATOR_KEYS)}")
    geometry_keys = {"n", "shape", "radius", "overlap", "seed", "radius_spread", "distribution", "jitter", "box", "speed"}
    extra = sorted((set(t) & geometry_keys) - GENERATOR_KEYS[kind])
    if extra:
        raise ValueError(f"[generator] {extra[0]}: not a parameter of kind = {kind!r} "
                         f"(its parameters: {', '.join(sorted(GENERATOR_KEYS[kind]))})")
    args = {k: t[k] for k in GENERATOR_KEYS[kind] if k in t}
    required = {"n", "radius", "box"} if kind == "box" else {"radius", "overlap", "shape" if kind == "lattice" else "n"}
    missing = sorted(required - set(args))
    if missing:
        raise ValueError(f"[generator] {missing[0]}: required for kind = {kind!r}")
    boundary = t.get("boundary", "none")
    if boundary not in BOUNDARIES:
        raise ValueError(f"[generator] boundary = {boundary!r}: must be one of {', '.join(BOUNDARIES)}")
    if boundary == "periodic" and kind not in ("lattice", "random"):
        raise ValueError(f"[generator] boundary = 'periodic': only for kind = 'lattice' or 'random' (a {kind} has no "
                         "period)")
    if boundary == "periodic" and kind == "random":
        args["periodic"] = True
    try:
        if kind == "box":
            args["dimension"] = dimension
        layout = {"chain": generators.chain, "lattice": generators.lattice, "random": generators.random_packing,
                  "box": generators.random_box}[kind](**args)
    except (TypeError, ValueError) as exc:
        msg = str(exc)
        raise ValueError(msg if msg.startswith("[") else f"[generator] kind = {kind!r}: bad parameter ({msg})") from None
    n = len(layout.radius)
    T0 = number(t, "generator", "temperature", 0.0)
    hot = number(t, "generator", "hot", required=boundary != "none")
    cold = number(t, "generator", "cold", required=boundary != "none")
    heat = number(t, "generator", "heat", 0.0)
    temperature = np.full(n, T0)
    fixed = np.zeros(n, dtype=bool)
    walls, specimen, box = (), None, None
    if boundary != "none" and kind == "box":
        raise ValueError("[generator] boundary: not for kind = \"box\" (give [[walls]] instead)")
    if boundary == "periodic":
        # the block repeats along every axis; the temperature drops by hot - cold per period along z. Without a
        # given temperature the particles start on that gradient about (hot + cold) / 2 (the mean a steady run
        # keeps, for equal capacities)
        box = PeriodicBox(layout.period, (True, True, True), layout.origin, [0.0, 0.0, hot - cold])
        if "temperature" not in t:
            z = layout.position[:, 2]
            temperature = 0.5 * (hot + cold) - (hot - cold) * (z - z.mean()) / layout.period[2]
        specimen = Specimen(float(layout.period[2]), box.cross_section(2), hot, cold, periodic=True)
    elif boundary == "fixed":
        fixed[layout.bottom] = fixed[layout.top] = True
        temperature[layout.bottom], temperature[layout.top] = hot, cold
        length = float(np.mean(layout.position[layout.top, 2]) - np.mean(layout.position[layout.bottom, 2]))
        specimen = Specimen(length, layout.area, hot, cold, ("group", held_name(hot)), ("group", held_name(cold)))
    elif boundary == "plates":
        # plane walls touching the end layers with overlap delta = overlap * r / 2: the mirror pair's neck equals
        # that of a pair with the generator's relative overlap
        mean_overlap = float(np.mean(np.atleast_1d(t["overlap"])))
        r_b, r_t = layout.radius[layout.bottom], layout.radius[layout.top]
        z_b = float(np.mean(layout.position[layout.bottom, 2] - r_b * (1.0 - 0.5 * mean_overlap)))
        z_t = float(np.mean(layout.position[layout.top, 2] + r_t * (1.0 - 0.5 * mean_overlap)))
        walls = (Wall("hot", [0.0, 0.0, z_b], [0.0, 0.0, 1.0], hot), Wall("cold", [0.0, 0.0, z_t], [0.0, 0.0, -1.0],
                                                                          cold))
        specimen = Specimen(z_t - z_b, layout.area, hot, cold)
    particles = Particles.from_arrays(layout.position, layout.radius, temperature, materials, None, fixed,
                                      np.full(n, heat), prefix="[generator]")
    return particles, walls, specimen, layout.velocity, box


def _periodic_box(t: dict, file_box: PeriodicBox | None = None) -> PeriodicBox:
    """``[periodic]``: ``lengths`` (m), ``axes`` (the periodic ones, default all), ``origin``, ``drop`` (the
    temperature drop per period along each axis). With a packing file's box ``file_box``, ``lengths`` and
    ``origin`` default to its box and ``axes`` to its periodic axes (all where it has none)."""
    if "lengths" not in t and file_box is None:
        raise ValueError("[periodic] lengths: required (the period along x, y and z, m)")
    default_axes = [a for a, p in zip(AXES, file_box.periodic) if p] if file_box is not None else []
    axes = t.get("axes", default_axes or list(AXES))
    if not isinstance(axes, list) or not all(isinstance(a, str) and a in AXES for a in axes) or not axes:
        raise ValueError(f"[periodic] axes = {axes!r}: must be a non-empty list of \"x\", \"y\", \"z\"")
    values = {}
    for key in ("lengths", "origin", "drop"):
        if key in t:
            v = t[key]
            if (not isinstance(v, list) or len(v) != 3
                    or not all(_is_number(x) and math.isfinite(x) for x in v)):
                raise ValueError(f"[periodic] {key} = {v!r}: must be a list of three finite numbers")
            values[key] = v
    if file_box is not None:
        values.setdefault("lengths", file_box.lengths)
        values.setdefault("origin", file_box.origin)
    try:
        return PeriodicBox(values["lengths"], tuple(a in axes for a in AXES), values.get("origin"), values.get("drop"))
    except ValueError as exc:
        raise ValueError(f"[periodic] {exc}") from None


WALL_NUMBERS = ("pressure", "mass", "damping", "velocity", "amplitude", "frequency")


def _walls(doc, start: dict | None, static: bool) -> tuple:
    """The ``[[walls]]`` of any scene (:class:`dem.geometry.walls.Wall`; a static scene's carry a temperature); a
    wall named like a wall of the saved state ``start`` stands where that one stood."""
    tables = doc.get("walls", [])
    out = []
    for k, w in enumerate(tables):
        for key in ("point", "normal") + (("temperature",) if static else ()):
            if key not in w:
                raise ValueError(f"[walls][{k}] {key}: required")
        numbers = {key: number(w, f"walls][{k}", key) for key in WALL_NUMBERS if key in w}
        out.append(Wall(str(w.get("name", f"wall{k}")), w["point"], w["normal"],
                        number(w, f"walls][{k}", "temperature"), str(w.get("motion", "fixed")), **numbers))
    names = [w.name for w in out]
    if len(set(names)) != len(names):
        raise ValueError(f"[[walls]] name: names must be unique, got {names}")
    if start is not None and start["moving"]:
        saved = dict(zip(start["wall_names"], start["wall_q"]))
        out = [w.at(float(saved[w.name])) if w.name in saved else w for w in out]
    return tuple(out)


def _saved_walls(start: dict | None) -> list:
    """The walls of a saved moving state, where they stood (they bound a static scene's cross-section)."""
    if start is None or not start["moving"] or not np.any(start["wall_normal"]):
        return []
    return [Wall(name, normal * q, normal) for name, normal, q in
            zip(start["wall_names"], start["wall_normal"], start["wall_q"])]


def _spec(cls, table, section, numeric=(), integer=(), words=()):
    """``cls(**table)`` with the keys of ``table`` that are fields of ``cls`` (the schema has checked them all);
    keys in ``numeric`` must be finite numbers (or, if also in ``words``, a string that the class checks, e.g.
    ``dt = "auto"``), keys in ``integer`` integers."""
    names = {f.name for f in fields(cls)}
    kwargs = {}
    for key, v in table.items():
        if key not in names:
            continue
        if key in numeric and not (key in words and isinstance(v, str)):
            v = number(table, section, key)
        if key in integer and (not isinstance(v, int) or isinstance(v, bool)):
            raise ValueError(f"[{section}] {key} = {v!r}: must be an integer")
        kwargs[key] = v
    try:
        return cls(**kwargs)
    except ValueError as exc:
        msg = str(exc)
        if msg.startswith(f"{section}."):
            msg = f"[{section}] {msg[len(section) + 1:]}"
        raise ValueError(msg if msg.startswith("[") else f"[{section}] {msg}") from None


def _engine(doc: dict, physics, law) -> str:
    """The engine a scene runs on (:mod:`dem.engines`): ``[solver] engine`` if it names one, else the one its physics
    and contact law call for; the combination checked."""
    moving = "mechanical" in physics
    solver = doc.get("solver", {})
    named = solver.get("engine") if isinstance(solver, dict) else None
    if named is None:
        return "static" if not moving else ("verlet" if law.SPINS else "staggered")
    if named not in ENGINE_NAMES:
        raise ValueError(f"[solver] engine = {named!r}: must be one of {', '.join(ENGINE_NAMES)}")
    if (named == "static") == moving:
        raise ValueError(f"[solver] engine = {named!r}: " + ("a packing that does not move runs on the static engine"
                         if not moving else "particles that move (\"mechanical\" physics) run on \"verlet\" or "
                                            "\"staggered\""))
    if named == "staggered" and law.SPINS:
        raise ValueError(f"[solver] engine = \"staggered\": steps particles that do not rotate; [contact] law = "
                         f"{law.NAME!r} makes torques (use engine = \"verlet\")")
    return named


def parse_scene(doc: dict, source: str = "scene", base_dir: pathlib.Path | None = None, part=None) -> Scene:
    """Validate a parsed TOML document into a :class:`Scene`: every table and key against the schema of the engine
    the scene runs on (:mod:`dem.scene.schema`), then each table into its part of the scene.

    Parameters
    ----------
    doc : dict
        The parsed TOML document (SI units).
    source : str
        The scene's name where ``[scene] name`` gives none (a file's stem).
    base_dir : pathlib.Path or None
        The scene file's folder, against which relative paths (a packing file, a saved state) are read; None:
        the working directory.
    part : tuple or None
        ``(ranks, rank)``: a static scene whose ``[particles] file`` is a packing in parts
        (:mod:`dem.scene.packing_files.parts`) gets only the particles rank ``rank`` of ``ranks`` holds
        (``Scene.part`` says which); None, or another scene: every particle.

    Returns
    -------
    Scene
        The scene.

    Raises
    ------
    ValueError
        A table or key is unknown, missing or bad; the message names the table and the key.
    """
    if not isinstance(doc, dict):
        raise ValueError("scene: must be a table of tables")
    unknown = sorted(set(doc) - set(TABLES))
    if unknown:
        raise ValueError(f"[{unknown[0]}]: unknown table (allowed: {', '.join(sorted(TABLES))})")
    meta = doc.get("scene", {})
    if not isinstance(meta, dict):
        raise ValueError("[scene]: must be a table")
    physics = meta.get("physics", ["thermal"])
    if isinstance(physics, str):
        physics = [physics]
    if not isinstance(physics, list) or not all(isinstance(x, str) for x in physics):
        raise ValueError(f"[scene] physics = {physics!r}: must be a list of names (available: "
                         f"{', '.join(PHYSICS)})")
    check_physics(physics)
    moving = "mechanical" in physics
    if moving and not isinstance(doc.get("contact"), dict):
        raise ValueError(f"[contact]: required for mechanical physics (law = one of {', '.join(CONTACT_LAWS)}, and its "
                         f"parameters)")
    law = law_module(doc["contact"].get("law")) if moving else None
    engine = _engine(doc, physics, law)
    check(doc, engine, law)
    materials = _materials(doc, thermal="thermal" in physics, electrical="electrical" in physics)
    start = held = None  # held: the part of a packing in parts that this rank holds, if it holds a part
    if "start" in doc:
        if "particles" in doc or "generator" in doc:
            raise ValueError("[start] state: the particles come from the saved state; remove [particles] or "
                             "[generator]")
        name = doc["start"].get("state")
        if not isinstance(name, str):
            raise ValueError("[start] state: required, the path of a saved state (.npz)")
        start = state_file.load(base_dir / name if base_dir is not None else name)
        material = start.get("material")
        if material is not None and int(np.max(material, initial=0)) >= len(materials):
            material = None  # the state's materials are not this scene's: the scene's first, as for [particles]
        particles = Particles.from_arrays(start["x"], start["radius"], start["T"], materials, material,
                                          prefix="[start] state", id=start.get("id"))
        walls, specimen, velocity, box = (), None, None, state_file.saved_box(start)
    elif ("particles" in doc) == ("generator" in doc):
        raise ValueError("[particles] or [generator]: give exactly one of them")
    elif "particles" in doc:
        necks = isinstance(doc.get("conductance"), dict) and doc["conductance"].get("nodes") == "necks"
        in_part = None if part is None or engine != "static" else (*part, lambda file_box: _scene_box(doc, file_box),
                                                                      NECK_HALO if necks else 1)
        particles, walls, specimen, velocity, box, held = _explicit_particles(doc["particles"], materials, base_dir,
                                                                              in_part)
    else:
        particles, walls, specimen, velocity, box = _generated_particles(doc["generator"], materials,
                                                                         meta.get("dimension", 3))
    box = _scene_box(doc, box)
    groups = {}
    if "groups" in doc:
        if held is not None:
            raise ValueError("[[groups]]: not on a packing read in parts on several ranks (a group is chosen over the "
                             "whole packing); run on one process")
        particles, groups = apply_groups(doc["groups"], particles)
    walls = walls + _walls(doc, start, static=not moving)
    if box is not None and moving:
        _check_walls_across(walls, box)
    if not moving and specimen is None:
        ends = particles if held is None or held.fixed is None else held.fixed  # the fixed ones of all, in parts
        span = None if held is None else (held.extent_lo, held.extent_hi)
        specimen = find_specimen(ends, walls, box, groups, bounds=_saved_walls(start), span=span)
    cond = dict(doc.get("conductance", {}))
    if "fit_file" in cond and not isinstance(cond["fit_file"], str):
        raise ValueError(f"[conductance] fit_file = {cond['fit_file']!r}: must be a path (string)")
    if "fit_file" in cond and base_dir is not None:
        cond["fit_file"] = str((base_dir / cond["fit_file"]).resolve())
    conductance = _spec(ConductanceSpec, cond, "conductance", numeric=("slope", "contact_conductance"))
    conv = _spec(Convection, doc["convection"], "convection", numeric=("h", "T_inf")) if "convection" in doc else None
    rad = (_spec(Radiation, doc["radiation"], "radiation", numeric=("emissivity", "T_inf"))
           if "radiation" in doc else None)
    if rad is not None:
        _check_radiation_temperatures(rad, particles.temperature, walls)
    solver = _spec(SolverSpec, doc.get("solver", {}), "solver", numeric=("dt", "t_end", "rtol"),
                   integer=("max_steps",), words=("dt",))
    output = _spec(OutputSpec, doc.get("output", {}), "output", numeric=("checkpoint_every",),
                   integer=("every", "vtu_every"))
    contact = contact_material_from_scene(doc) if moving else None
    motion = parse_motion(doc, particles, solver, physics, contact, velocity, start, walls, engine) if moving else None
    electrical = parse_electrical(doc, walls, physics)
    if start is not None and solver.mode == "transient" and solver.t_end <= start["t"]:
        raise ValueError(f"[solver] t_end = {solver.t_end:g} s: must be beyond the saved state's time "
                         f"{start['t']:.6g} s (the run's clock goes on from the state's)")
    return Scene(particles, () if moving else walls, conductance, Sources(conv, rad), solver, output,
                 tuple(physics), str(meta.get("name", source)), str(meta.get("description", "")), specimen, contact,
                 motion, electrical, box, engine, start,
                 temperature_unit(meta, rad, zohdi=law is not None and law.NAME == "zohdi"), groups, held)


def _scene_box(doc: dict, box: PeriodicBox | None) -> PeriodicBox | None:
    """The scene's periodic box: ``[periodic]`` over the box of its packing file or generator (``box``), else that
    box where it is periodic along some axis."""
    if "periodic" in doc:
        if box is not None and "generator" in doc:
            raise ValueError("[periodic]: the generator's boundary = \"periodic\" already makes the block periodic; "
                             "give one or the other")
        return _periodic_box(doc["periodic"], box)
    if box is not None and not box.any_periodic:
        return None  # a packing file's box that is not periodic (or that cannot say): only [periodic] uses it
    return box




def temperature_unit(meta: dict, rad: Radiation | None, zohdi: bool) -> str:
    """``[scene] temperature_unit``: "C" or "K"; by default ``radiation.unit`` where the scene has radiation, "K"
    for scenes with Zohdi 2014's contact law (``zohdi``: its thermal softening and Joule heating work in kelvin),
    else "C". Only labels the outputs: every law takes the scene's temperatures as they are.

    Parameters
    ----------
    meta : dict
        The ``[scene]`` table.
    rad : dem.laws.ambient.Radiation or None
        The scene's radiation, whose ``unit`` is the default; None without radiation.
    zohdi : bool
        Whether the scene uses Zohdi 2014's contact law (default unit ``"K"``).

    Returns
    -------
    str
        ``"C"`` or ``"K"``.

    Raises
    ------
    ValueError
        The unit is neither, or differs from the radiation's.
    """
    default = rad.unit if rad is not None else "K" if zohdi else "C"
    unit = meta.get("temperature_unit", default)
    if unit not in TEMPERATURE_UNITS:
        raise ValueError(f"[scene] temperature_unit = {unit!r}: must be \"C\" or \"K\"")
    if rad is not None and unit != rad.unit:
        raise ValueError(f"[scene] temperature_unit = {unit!r}: differs from radiation.unit = {rad.unit!r} (the unit "
                         f"of the same temperatures)")
    return unit


def _check_walls_across(walls, box: PeriodicBox) -> None:
    """A wall of particles that move must lie along the periodic axes (a wall across one would face its own
    images)."""
    for wall in walls:
        across = [AXES[a] for a in range(3) if box.periodic[a] and abs(wall.normal[a]) > 1e-12]
        if across:
            raise ValueError(f"walls.{wall.name}: its normal {list(map(float, wall.normal))} has a component along the "
                             f"periodic axis {across[0]}; a wall must be parallel to every periodic axis")


def contact_material_from_scene(doc: dict):
    """The contact material of a TOML document's ``[contact]`` table: ``law`` names the contact law
    (:data:`dem.laws.contact.CONTACT_LAWS`), the other keys are its material's fields in SI units (``density``
    defaults to that of a single ``[material]``).

    Parameters
    ----------
    doc : dict
        The parsed TOML document.

    Returns
    -------
    object
        The contact law's material (its ``Material`` class, :mod:`dem.laws.contact`).

    Raises
    ------
    ValueError
        There is no ``[contact]`` table, its law is unknown, or a value is bad.
    """
    table = doc.get("contact")
    if not isinstance(table, dict):
        raise ValueError(f"[contact]: must be a table with law = one of {', '.join(CONTACT_LAWS)}, and the material")
    law = law_module(table.get("law"))
    values = {key: v for key, v in table.items() if key != "law"}
    material = doc.get("material")
    if "density" not in values and isinstance(material, dict) and "density" in material:
        values["density"] = material["density"]
    return material_from_table(law.Material, law.NAME, values)


def luding_material_from_scene(doc_or_scene):
    """The Luding 2005 contact material of a :class:`Scene` (its ``contact``) or of a TOML document (its
    ``[contact]`` table, :func:`contact_material_from_scene`). Raises ``ValueError`` when there is none or a value
    is bad.

    Parameters
    ----------
    doc_or_scene : Scene or dict
        A scene, or a parsed TOML document.

    Returns
    -------
    object
        The Luding 2005 material (:mod:`dem.laws.contact`).

    Raises
    ------
    ValueError
        There is no Luding contact material, or a value is bad.
    """
    if isinstance(doc_or_scene, Scene):
        material = doc_or_scene.contact
        if material is None or material.law != "luding":
            raise ValueError(f"scene {doc_or_scene.name!r}: has no [contact] table with law = \"luding\" (the Luding "
                             f"2005 sintering contact material)")
        return material
    if not isinstance(doc_or_scene, dict) or doc_or_scene.get("contact") is None:
        raise ValueError("[contact]: required, with law = \"luding\" and the material (k1, k2, kc, ...)")
    law = doc_or_scene["contact"].get("law") if isinstance(doc_or_scene["contact"], dict) else None
    if law != "luding":
        law_module(law)  # an unknown law is named as such
        raise ValueError(f"[contact] law = {law!r}: not the Luding 2005 sintering contact (law = \"luding\")")
    return contact_material_from_scene(doc_or_scene)


def _check_radiation_temperatures(rad: Radiation, temperature: np.ndarray, walls) -> None:
    """Radiation works in absolute temperature: every prescribed temperature must lie between 0 K and
    :data:`dem.laws.ambient.RADIATION_T_MAX`."""
    named = [("particles.temperature", np.asarray(temperature, dtype=float))]
    named += [(f"walls.{w.name}.temperature", np.asarray([w.temperature], dtype=float)) for w in walls]
    for name, values in named:
        kelvin = rad.kelvin(values)
        bad = np.flatnonzero((kelvin < 0.0) | (kelvin > RADIATION_T_MAX))
        if bad.size:
            k = int(bad[0])
            where = f"[{k}]" if name == "particles.temperature" else ""
            raise ValueError(f"{name}{where} = {values[k]:g} {rad.unit}: outside the range of the radiation model "
                             f"(radiation.unit = {rad.unit!r}); valid range {0.0 - rad.kelvin(0.0):g} to "
                             f"{RADIATION_T_MAX - rad.kelvin(0.0):g} {rad.unit} (absolute zero to "
                             f"{RADIATION_T_MAX:g} K)")


def builtin_scenes() -> dict:
    """``{name: description}`` of the scenes shipped in ``dem/scene/builtin``."""
    out = {}
    for path in sorted(SCENE_DIR.glob("*.toml")):
        with path.open("rb") as fh:
            out[path.stem] = tomllib.load(fh).get("scene", {}).get("description", "")
    return out


def load_scene(name_or_path, part=None) -> Scene:
    """Read a scene from a TOML file path or a built-in name (``python -m dem scenes`` lists them).

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A scene TOML file, or the name of a built-in scene.
    part : tuple or None
        ``(ranks, rank)``: of a packing in parts, only what this rank holds (:func:`parse_scene`); None: all.

    Returns
    -------
    Scene
        The scene.

    Raises
    ------
    ValueError
        No such file or built-in, a file that cannot be read or is malformed TOML, or a bad scene (the message
        starts with the file's name).
    """
    path = pathlib.Path(name_or_path)
    if not path.exists() and (SCENE_DIR / f"{name_or_path}.toml").exists():
        path = SCENE_DIR / f"{name_or_path}.toml"
    if not path.exists():
        raise ValueError(f"scene = {str(name_or_path)!r}: no such file or built-in scene "
                         f"(built-ins: {', '.join(builtin_scenes())})")
    if not path.is_file():
        raise ValueError(f"scene = {str(name_or_path)!r}: not a file")
    try:
        with path.open("rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path.name}: malformed TOML: {exc}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path.name}: cannot be read ({exc})") from None
    try:
        return parse_scene(doc, path.stem, path.parent, part)
    except ValueError as exc:
        raise ValueError(f"{path.name}: {exc}") from None
