"""The scene schema: every table and key of a scene, its type and default, its unit, and which engine reads it -- the
one table the parser checks a scene against (:func:`check`) and the documentation's schema page is made from
(:func:`display_rows`, rendered by ``docs/_ext/scene_schema.py``).

Engines (:mod:`dem.engines`): ``static`` (a packing that does not move), ``verlet`` (particles that move, velocity
Verlet) and ``staggered`` (Zohdi 2014's implicit scheme). A key the scene's engine does not read is refused, naming the
engine and those that read it. The ``[contact]`` keys are those of the contact law's material
(:data:`dem.laws.contact.CONTACT_LAWS`), and a ``[[phases]]`` entry may change any of them but the density. A
number a key holds is read by :func:`number`, which names the key when it is not one or out of its range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

ENGINE_NAMES = ("static", "verlet", "staggered")
ALL = ENGINE_NAMES
MOVING = ("verlet", "staggered")
STATIC = ("static",)
VERLET = ("verlet",)
STAGGERED = ("staggered",)
STATIC_VERLET = ("static", "verlet")
STATIC_STAGGERED = ("static", "staggered")
ENGINE_WORDS = {ALL: "all", MOVING: "moving", STATIC: "static", VERLET: "verlet", STAGGERED: "staggered",
                STATIC_VERLET: "static, verlet", STATIC_STAGGERED: "static, staggered"}
ARRAYS = ("materials", "walls", "phases", "groups")  # tables given as arrays of tables ([[walls]])
LAW_TABLES = ("contact", "phases")  # tables whose keys (beyond those listed) are the contact law's material fields


@dataclass(frozen=True)
class Row:
    """Keys of one table that share a type, a default and a meaning (one row of the scene schema page).

    Parameters
    ----------
    table : str
        The TOML table (``"scene"``, ``"material"``, ...).
    keys : tuple of str
        The keys the row documents.
    engines : tuple of str
        The engines that read them (``ENGINE_NAMES``).
    type : str
        Their type, unit and default, as the schema page shows it (Markdown).
    meaning : str
        What they mean (Markdown).
    """

    table: str
    keys: tuple
    engines: tuple
    type: str
    meaning: str


ROWS = (
    Row("scene", ("name",), ALL, "string, the file's name", "shown in the summary"),
    Row("scene", ("description",), ALL, "string", "listed by `python -m dem scenes`"),
    Row("scene", ("physics",), ALL, 'list, `["thermal"]`',
        'submodels: `"thermal"`, `"mechanical"` (particles that move), `"electrical"` (the current and its Joule heat, '
        'with `"thermal"`: on a static packing, or on moving ones with `[contact] law = "zohdi"`)'),
    Row("scene", ("temperature_unit",), ALL, '`"C"`; `"K"` with `[contact] law = "zohdi"`; radiation.unit where given',
        'the unit of the scene\'s temperatures, `"C"` or `"K"`: the plots\' axes say it (the laws take the '
        'temperatures as given)'),
    Row("scene", ("dimension",), MOVING, "3", "3: spheres; 2: disks in the x-z plane (velocity Verlet only)"),
    Row("scene", ("height",), VERLET, "m, required with dimension = 2", "the disks' height (Luding 2005's cylinders)"),
    Row("material", ("conductivity", "density", "specific_heat"), ALL, "numbers > 0",
        "κ W/(m K), ρ kg/m³, c J/(kg K); capacity C_i = ρ(4/3)πr_i³ c (Rojek 2022, eq. 1); thermal physics needs κ "
        "and c, moving particles ρ"),
    Row("material", ("electrical_conductivity",), STATIC_STAGGERED, 'number > 0, required with "electrical"',
        "σ S/m: a contact's electrical conductance is the conductance law with σ for κ"),
    Row("material", ("name",), ALL, "string", "what particles call it by"),
    Row("materials", ("name", "conductivity", "density", "specific_heat", "electrical_conductivity"), ALL,
        "as `[material]`", "several materials instead of one `[material]`; particles pick one by `material`"),
    Row("particles", ("position",), ALL, "list of [x, y, z] m, required", "particle centres"),
    Row("particles", ("radius",), ALL, "list, m, > 0, required", ""),
    Row("particles", ("temperature",), ALL, "list, required", "initial temperature (K or °C)"),
    Row("particles", ("fixed",), ALL, "list of bool, all false",
        "held at the initial temperature (a boundary); a steady run with two ends at different temperatures (held "
        "groups or walls with a temperature) reports `effective_conductivity` = Q L / (A ΔT) and its `specimen`"),
    Row("particles", ("material",), ALL, "name, index or list of them, 0", "index/name into `[[materials]]`"),
    Row("particles", ("heat",), ALL, "list, W, 0", "internal heat generation Q_i^int (Rojek 2022, eq. 3)"),
    Row("particles", ("file",), ALL, "path, instead of `position` and `radius`",
        "a packing file (CSV, LAMMPS data or dump, VTK; relative to the scene); `temperature` may then be one "
        "number"),
    Row("particles", ("format", "length_unit", "timestep"), ALL, "from the name, 1, the last",
        "the file's format, metres per length unit, a dump's snapshot"),
    Row("particles", ("velocity",), MOVING, "list of [vx, vy, vz] m/s, 0", "initial velocities"),
    Row("particles", ("angular_velocity",), VERLET, "list of 3-vectors, 1/s, 0", "initial angular velocities"),
    Row("groups", ("name",), ALL, "string, required, unique",
        "a named group of particles (`dem.scene.groups`), as LAMMPS's `region` and `group`; its selectors "
        "(`region`, `ids`, `types`, `layer`) all choose its particles, which must be at least one"),
    Row("groups", ("region",), ALL, '`"slab"`, `"box"`, `"sphere"`, `"cylinder"`',
        "the particles whose centres lie in it: slab `axis`, `lo` and/or `hi` (m along it); box `lo`, `hi` (corners "
        "[x, y, z] m); sphere `center`, `radius`; cylinder `axis`, `center` (a point of its axis), `radius`, "
        "optional `lo`, `hi` along the axis"),
    Row("groups", ("axis", "lo", "hi", "center", "radius"), ALL, '`"x"`/`"y"`/`"z"`, m or [x, y, z] m, m',
        "the region's (and the layer's `axis`, default z)"),
    Row("groups", ("ids",), ALL, "list of ids and [first, last] ranges", "by particle id (LAMMPS `group id 1:100`)"),
    Row("groups", ("types",), ALL, "list of LAMMPS types (from 1) or material names",
        "by type: type k is material k − 1"),
    Row("groups", ("layer", "thickness"), ALL, '`"top"` or `"bottom"`, m',
        "the particles whose centres lie within `thickness` of the highest (lowest) centre along `axis`"),
    Row("groups", ("temperature", "fixed", "material", "heat"), ALL, "K or °C, bool, name or index, W",
        "given to the group's particles over `[particles]`' lists (groups in order, a later one over an earlier "
        "one): the initial temperature, held at it (a held group is an end of `effective_conductivity` and has its "
        "total in `boundary_heat_flow`), the material, the internal heat per particle"),
    Row("generator", ("kind",), ALL, '`"chain"`, `"lattice"`, `"random"`, `"box"`',
        'instead of `[particles]`; `"box"`: random sequential addition in a box (moving particles)'),
    Row("generator", ("structure",), ALL, '`"sc"`', 'lattice: `"sc"`, `"bcc"` or `"fcc"` (1, 2 or 4 spheres per '
        'cubic cell; nearest neighbours 2r - h apart)'),
    Row("generator", ("n",), ALL, "int", "chain: particles; random: approximate count (complete FCC layers); box: "
        "particles"),
    Row("generator", ("shape",), ALL, "[nx, ny, nz]", "lattice: cubic cells per axis"),
    Row("generator", ("radius",), ALL, "m (chain: or list)", "random, box: mean radius"),
    Row("generator", ("overlap",), ALL, "number (chain: or list per bond)",
        "h / min(r_i, r_j); random: the target mean over bonded pairs"),
    Row("generator", ("radius_spread", "distribution"), ALL, '0.1, `"uniform"`',
        'random, box: relative spread; `"constant"`, `"uniform"` (±spread) or `"lognormal"` (relative std)'),
    Row("generator", ("jitter",), ALL, "0.02", "random: position noise (fraction of the neighbour distance)"),
    Row("generator", ("seed",), ALL, "int, 0", "random, box: seed (runs are reproducible)"),
    Row("generator", ("temperature",), ALL, "0.0", "initial temperature of every particle"),
    Row("generator", ("boundary",), ALL, '`"none"`, `"plates"`, `"fixed"`, `"periodic"`',
        "plates: walls named `hot` (below) and `cold` (above) touching the end layers with overlap `overlap·r/2`; "
        "fixed: bottom/top layer (chain: end particles) held at `hot`/`cold`; periodic (lattice, random): the block "
        "repeats along every axis (random: whole FCC cells, n ≥ 32) with the temperature dropping by `hot - cold` "
        "per period along z -- the infinite packing, no wall or side effect; without `temperature` the particles "
        "start on that gradient"),
    Row("generator", ("hot", "cold"), ALL, "numbers, required with a boundary",
        "plate or end temperatures; a steady run reports `effective_conductivity` = Q L / (A ΔT)"),
    Row("generator", ("heat",), ALL, "W, 0", "internal heat per particle"),
    Row("generator", ("box",), MOVING, "[[lo], [hi]] m, box: required", "the box particles are placed in"),
    Row("generator", ("speed",), MOVING, "m/s, 0", "box: random velocity directions of this speed"),
    Row("walls", ("name", "point", "normal"), ALL, "string, [x, y, z] m, [nx, ny, nz]; required",
        "a plane; `normal` points into the packing"),
    Row("walls", ("temperature",), ALL, "number (static: required)", "an isothermal plane: particles closer than "
        "their radius are bonded to it"),
    Row("walls", ("motion",), MOVING, '`"fixed"`', '`"stress"` (Luding 2005, eq. 1; velocity Verlet), `"strain"` '
        '(constant `velocity`), `"vibrate"` (`amplitude`, `frequency`)'),
    Row("walls", ("pressure", "mass", "damping"), VERLET, "N/m (2D) or Pa (3D), kg, kg/s",
        "of a stress wall: the pressure times the box's extent pushes it in (eq. 1); the extent is between the walls "
        "facing each other, or the period of a box periodic along that axis"),
    Row("walls", ("velocity",), MOVING, "m/s, inward", "of a strain wall"),
    Row("walls", ("amplitude", "frequency"), MOVING, "m, Hz", "of a vibrating wall, q(t) = q0 + A sin(2πf(t - t_0)) "
        "from the run's start t_0"),
    Row("walls", ("potential", "current"), STATIC_STAGGERED, "V or A", 'an electrode ("electrical" physics): a fixed '
        "potential, or a current into the packing"),
    Row("periodic", ("lengths",), ALL,
        "[Lx, Ly, Lz] m, required (default: the box of a `[particles] file` or a `[start] state`)",
        "a periodic box (`dem.geometry.periodic.PeriodicBox`): bonds cross its faces to the neighbours' images (the "
        "same bonds as an explicit larger block, also in boxes shorter than a bond); moving particles touch (forces, "
        "bonds, heat, current) across them by the minimum image and are wrapped back into the box at the rebuilds "
        "of their neighbour list, walls (and electrodes) must be parallel to its periodic axes; a run's state "
        "keeps the box"),
    Row("periodic", ("axes", "origin"), ALL, "all, [0, 0, 0]",
        "the periodic axes and the box's lower corner"),
    Row("periodic", ("drop",), STATIC_VERLET, "[0, 0, 0]",
        "temperature drop per period, T(x + L_k e_k) = T(x) - drop_k: a "
        "bond to an image sees T_j - drop·shift. A group of particles with no fixed temperature, wall or ambient is "
        "then solved up to a constant, kept at its capacity-weighted mean initial temperature; with one axis "
        "dropping, a steady run reports `effective_conductivity` = Q L / (A drop) from the heat flow Q across the "
        "period"),
    Row("start", ("state",), ALL, "path", "begin from a saved `state.npz` (any engine's): its particles, for moving "
        "particles their velocities and contact histories; the clock and counters go on from the state's"),
    Row("conductance", ("law",), ALL, '`"rojek"`', '`"rojek"` (1.064 κπa per half, eqs. 40/43, halves in series '
        'eq. 9 → eq. 45), `"argento-bouvard"` (1.112, eq. 42), `"fit"` (κπr_i f(a/r_i) from a fit.json, each half at '
        'its own a/r_i), `"shared-body"` (the fit law with every half scaled for the necks that share its particle\'s '
        'body), `"zohdi"` (κπa²/‖x_i - x_j‖ with the lens contact circle, Zohdi 2014 eqs. 11-12, 33); `python -m dem '
        'laws` lists them'),
    Row("conductance", ("slope",), ALL, "number", "overrides c of the linear laws"),
    Row("conductance", ("fit_file",), ALL, "path", "fit and shared-body laws; default `fem_neck/data/fit.json`"),
    Row("conductance", ("unequal",), ALL, "true", "fit and shared-body laws: multiply the series of halves by the FE "
        "correction for unequal radii (`fem_neck.law.unequal_factor`)"),
    Row("conductance", ("neck",), ALL, '`"newton"`', '`"newton"` (Rojek 2022, eqs. 27-33), `"first"` (eq. 34), '
        '`"coble"` (eqs. 11-12): pair necks, no answer once two necks of a particle meet; `"union"`: the circle '
        'where two spheres meet, the packing read as the union of its spheres (`fem_neck.geometry.union`), defined '
        'at every density'),
    Row("conductance", ("nodes",), STATIC_VERLET, '`"particles"`', '`"particles"`: a node per particle, each bond a '
        'conductance; `"necks"`: a node per neck as well, each particle an element joining its centre to its necks '
        '(`dem.network.necks`: the `shared-body` particle solved exactly, its interaction taken between the necks\' '
        'faces), for `law = "shared-body"` with `neck = "union"`; steady heat, or transient with implicit or '
        'crank-nicolson steps, with convection, radiation and current on a static packing (the ambient on each '
        'particle\'s centre, the electrical element the thermal one times sigma / kappa); moving particles (the verlet '
        'engine, each thermal step on the network of its contacts) without them so far; not under MPI so far'),
    Row("conductance", ("element",), STATIC_VERLET, '`"law"`', '`"law"`: each particle\'s element with a node per '
        'neck is the `shared-body` law\'s; `"trefftz"`: the Trefftz element of its cut sphere with three flux modes '
        'per neck (`dem.network.trefftz_element`: within 0.6 % of the union\'s FE on 39 cells, where the law is '
        '−4.05 to +1.81 %; about 1.6 ms of CPU per neck and 1.9 ms per pair of a particle\'s necks that meet), for '
        '`law = "shared-body"` with `nodes = "necks"` and `neck = "union"`; the static engine on one process '
        '(a wall\'s face cut like a neck\'s)'),
    Row("conductance", ("contact_conductance",), ALL, "W/K, none", "K_c of the interface in series (eq. 8)"),
    Row("conductance", ("out_of_range",), ALL, '`"error"`', 'bonds beyond the contact model\'s range (h > '
        'max_overlap; wall overlap > r/3): `"error"` reports their count and the first pair, `"clip"` sets a to the '
        'smaller radius, `"drop"` removes them'),
    Row("convection", ("h", "T_inf", "area_fraction"), STATIC_VERLET, 'W/(m² K), K or °C, `"exposed"`',
        "Q = h A (T_inf - T), A = fraction · 4πr²; `\"exposed\"`: the fraction of each particle's surface whose "
        "outward normal ray leaves the packing (`dem.geometry.exposure`: 1 for an isolated particle, 0 inside a "
        "block, 0.29/0.5/0.66 on a face/edge/corner of a simple cubic block at h/r = 0.1); a number or list: that "
        "fraction (`1`: the whole surface, opted in)"),
    Row("radiation", ("emissivity", "T_inf", "area_fraction", "unit"), STATIC_VERLET,
        '-, K or °C, `"exposed"`, `"K"` or `"C"` (required)', "Q = εσA (T_inf⁴ - T⁴) in kelvin; `unit`: the unit "
        "of the scene's temperatures (a scene with radiation must say which)"),
    Row("solver", ("engine",), ALL, "from the physics and the contact law",
        '`"static"`, `"verlet"` or `"staggered"` (`python -m dem` chooses; a scene may name it)'),
    Row("solver", ("mode",), ALL, '`"steady"` (moving: `"transient"`)', '`"steady"` or `"transient"`'),
    Row("solver", ("t_end",), ALL, "s, required in transient mode", "the time the run ends at"),
    Row("solver", ("dt",), ALL, '`"auto"` (staggered: required)',
        "step in s. Static: `\"auto\"`: error-controlled steps (each step estimates its local error -- explicit "
        "against Heun's step, implicit and Crank-Nicolson by step doubling -- and is redone with a smaller step when "
        "it exceeds the per-step tolerance); implicit steps are t_end/2ᵏ so their factorisations are reused; explicit "
        "never above 0.9 × the stable limit, and an explicit `dt` above 2/λ_max(C⁻¹A) is refused with the limit in "
        "the message. Verlet: `\"auto\"` is t_MD = π/(50ω) (Luding 2005, eq. 6); a `dt` above the stable step of the "
        "stiffest, lightest contact is refused. Staggered: the first step"),
    Row("solver", ("integrator",), STATIC_VERLET, '`"crank-nicolson"`',
        '`"explicit"`, `"implicit"`, `"crank-nicolson"` (verlet: of the thermal network)'),
    Row("solver", ("rtol",), STATIC, "1e-3", 'tolerance of `dt = "auto"`: the global error of the temperatures '
        "relative to the temperature range (initial, fixed, wall and ambient temperatures); measured on decaying "
        "pairs, chains and a 2048-particle packing: 0.06-1 × `rtol` for rtol 1e-2 … 1e-4"),
    Row("solver", ("linear",), ALL, '`"auto"`', '`"direct"` (sparse LU), `"cg"` (Jacobi-CG), `"amg"` '
        "(pyamg-preconditioned CG; its multigrid hierarchy reused while the matrix changes a little: radiation's "
        "Newton and time steps, Kirchhoff refreshes); auto: Jacobi-CG above 1 000 unknowns when the time step's capacity term C/dt "
        "makes the matrix diagonally dominant enough (Jacobi condition bound ≤ 4000), otherwise direct up to 5 000 "
        'unknowns and AMG above (`python -m benchmarks dem`, "DEM linear solvers")'),
    Row("solver", ("floating",), STATIC, '`"error"`', 'steady: groups of particles with no fixed temperature, wall '
        'or ambient make the system singular: `"error"` explains, `"mean"` keeps them at their capacity-weighted '
        'mean initial temperature'),
    Row("solver", ("max_steps",), STATIC, "100 000", "runs needing more steps are refused: up front for fixed steps "
        "and explicit auto, after at most ~100 steps when an implicit auto run projects beyond it; a fixed-step run "
        "above 3000 × `max_steps` particle-steps is refused before the bond search, with a time estimate"),
    Row("solver", ("skin",), MOVING, "m, 0.1 (staggered: 0.5) × mean radius", "of the Verlet list"),
    Row("solver", ("thermal_interval",), VERLET, "s, the output interval or 1000 steps",
        "between the thermal network's steps"),
    Row("solver", ("dt_max", "phi", "iterations", "tolerance", "order", "growth", "shrink", "dt_min"), STAGGERED,
        "dt, 0.5, 10, 5e-4, 2, 1.25, 0.5, 1e-9",
        "Zohdi 2014's stepping: Δt_lim, φ, K_d, TOL, p (eqs. 22-30, 45-49) and bounds on the step factor"),
    Row("output", ("every",), STATIC, "1", "a CSV row every `every` steps"),
    Row("output", ("vtu_every",), STATIC, "0", "a VTU snapshot every `vtu_every` steps (0: first and last only); "
        "at most 1000 snapshots (refused up front for a fixed `dt`, thinned for `dt = \"auto\"`)"),
    Row("output", ("interval",), MOVING, "s, t_end / 100", "between rows of `timeseries.csv`"),
    Row("output", ("vtu_interval",), MOVING, "s, 0", "between VTU snapshots (0: first and last)"),
    Row("output", ("vtu",), ALL, "true", "write VTU/PVD snapshots"),
    Row("output", ("lammps_dump",), ALL, "false", "beside every snapshot a LAMMPS `dump custom` text file "
        "`particles_STEP.dump` (id type radius x y z, vx vy vz fx fy fz and T where the engine has them; OVITO and "
        "LAMMPS's tools read it); not under MPI"),
    Row("output", ("checkpoint_every",), ALL, "5", "seconds of wall time between checkpoints (`--resume`)"),
    Row("output", ("fraction_axis",), STAGGERED, '`"x"`, `"y"` or `"z"`',
        "the axis the powder stands and is pressed along (Zohdi 2014, Sec. 7, Remark 1)"),
    Row("output", ("frames",), STAGGERED, "0", "rendered pictures over the run (Fig. 8)"),
    Row("contact", ("law",), MOVING, "required", "the contact law (`dem.laws.contact.CONTACT_LAWS`); the other keys "
        "are its material's fields"),
    Row("gravity", ("acceleration",), MOVING, "[gx, gy, gz] m/s²", ""),
    Row("temperature", ("time", "value", "relaxation_time"), VERLET, "s, K or °C, s",
        "a prescribed temperature schedule (Luding 2005, Fig. 7) and its t0 per segment"),
    Row("phases", ("start",), MOVING, "s, required", "from this time on"),
    Row("phases", ("wall_velocity",), MOVING, "{name = m/s}", "strain walls' new speeds"),
    Row("electrical", ("scheme", "absorption", "floating"), STATIC_STAGGERED, '`"kirchhoff"`, 1, `"allow"`',
        "the current (Zohdi 2014, eqs. 35, 38-44): Kirchhoff or the paper's iteration (moving particles only), the "
        "fraction of the Joule heat the particles take, whether groups touching no electrode stop the run"),
    Row("electrical", ("tolerance", "sweeps"), STAGGERED, "1e-8, 10 000", "the paper's iteration: its tolerance "
        "(the largest change per sweep relative to the largest wall value) and its sweeps at most"),
)
TABLES = tuple(dict.fromkeys(row.table for row in ROWS))


def number(table: dict, section: str, key: str, default=None, positive: bool = False,
           nonnegative: bool = False, required: bool = False) -> float | None:
    """The number ``table[key]`` as a float, ``default`` where the key is not given.

    Parameters
    ----------
    table : dict
        The table (``[solver]``, say).
    section : str
        The table's name in errors (``"solver"``, ``"phases][0"``).
    key : str
        The key.
    default : float or None
        What a missing key reads as.
    positive : bool
        Whether the number must be > 0.
    nonnegative : bool
        Whether the number must be >= 0.
    required : bool
        Whether a missing key is an error (else it reads as ``default``).

    Returns
    -------
    float or None
        The number, or ``default``.

    Raises
    ------
    ValueError
        The value is not a finite number, out of its range, or missing where required (one line naming
        ``[section] key``).
    """
    if key not in table:
        if required:
            raise ValueError(f"[{section}] {key}: required")
        return default
    v = table[key]
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
        raise ValueError(f"[{section}] {key} = {v!r}: must be a finite number")
    if positive and v <= 0:
        raise ValueError(f"[{section}] {key} = {v!r}: must be > 0")
    if nonnegative and v < 0:
        raise ValueError(f"[{section}] {key} = {v!r}: must be >= 0")
    return float(v)


def keys(table: str, engine: str | None = None) -> set[str]:
    """The keys of ``table`` (those ``engine`` reads, when given).

    Parameters
    ----------
    table : str
        The TOML table.
    engine : str, optional
        An engine (``ENGINE_NAMES``); None: the keys any engine reads.
    """
    return {k for row in ROWS if row.table == table and (engine is None or engine in row.engines) for k in row.keys}


def _engines_reading(table: str, key: str) -> tuple:
    return tuple(e for e in ENGINE_NAMES if any(key in row.keys and e in row.engines
                                                for row in ROWS if row.table == table))


def law_keys(table: str, engine: str, law) -> set[str]:
    """The contact law's material fields a table takes (``law``: the law's module): ``[contact]`` all of them,
    ``[[phases]]`` all but the density on velocity Verlet (the staggered scheme changes wall speeds only).

    Parameters
    ----------
    table : str
        The TOML table.
    engine : str
        The scene's engine.
    law : object or None
        The contact law's module (its ``Material`` dataclass lists the fields); None: no law.
    """
    if law is None or table not in LAW_TABLES or (table == "phases" and engine != "verlet"):
        return set()
    names = {f.name for f in fields(law.Material)}
    return names if table == "contact" else names - {"density"}


def check(doc: dict, engine: str, law=None) -> None:
    """Every table and key of the TOML document ``doc`` is one the scene's ``engine`` reads (``law``: the module of
    its contact law, for the ``[contact]`` and ``[[phases]]`` keys); ``ValueError`` naming the first that is not.

    Parameters
    ----------
    doc : dict
        The parsed TOML document.
    engine : str
        The scene's engine.
    law : object, optional
        The module of its contact law.
    """
    for table, value in doc.items():
        if table not in TABLES:
            raise ValueError(f"[{table}]: unknown table (allowed: {', '.join(sorted(TABLES))})")
        readers = tuple(e for e in ENGINE_NAMES if keys(table, e))
        if engine not in readers:
            raise ValueError(f"[{table}]: not read by the {engine} engine (read by {', '.join(readers)})")
        entries = value if table in ARRAYS else [value]
        if table in ARRAYS and not isinstance(value, list):
            raise ValueError(f"[[{table}]]: must be an array of tables")
        for k, entry in enumerate(entries):
            where = f"{table}][{k}" if table in ARRAYS else table
            if not isinstance(entry, dict):
                raise ValueError(f"[{where}]: must be a table")
            allowed = keys(table, engine) | law_keys(table, engine, law)
            for key in entry:
                if key in allowed:
                    continue
                readers = _engines_reading(table, key)
                if readers:
                    raise ValueError(f"[{where}] {key}: not read by the {engine} engine (read by "
                                     f"{', '.join(readers)}; this scene's keys there: {', '.join(sorted(allowed))})")
                if table in LAW_TABLES and law is not None and key not in law_keys("contact", engine, law):
                    listed = (f"its parameters: {', '.join(sorted(allowed - {'law'}))}" if table == "contact" else
                              f"this scene's keys there: {', '.join(sorted(allowed))}")
                    others = ", ".join(f'"{name}"' for name in _laws_taking(key))
                    raise ValueError(f"[{where}] {key}: not a parameter of law = \"{law.NAME}\" ({listed}"
                                     f"{f'; {key} is one of law = {others}' if others else ''})")
                raise ValueError(f"[{where}] {key}: unknown key (allowed: {', '.join(sorted(allowed))})")


def _laws_taking(key: str) -> list[str]:
    """The registered contact laws whose material has the field ``key``."""
    from dem.laws.contact import CONTACT_LAWS, law_module

    return [name for name in CONTACT_LAWS if key in {f.name for f in fields(law_module(name).Material)}]


def law_rows() -> tuple:
    """The ``[contact]`` rows of every registered contact law (its ``SCHEMA_ROWS``: keys, type and unit, meaning; the
    law's module imported), each headed by the law's name."""
    from dem.laws.contact import CONTACT_LAWS, law_module

    out = []
    for name in CONTACT_LAWS:
        law = law_module(name)
        engines = VERLET if law.SPINS else STAGGERED
        out += [Row("contact", keys, engines, f'`law = "{name}"`: {unit}', meaning)
                for keys, unit, meaning in law.SCHEMA_ROWS]
    return tuple(out)


def display_rows() -> list[tuple[str, str, str, str, str]]:
    """Every row as the key tables show it, cells in Markdown: ``(table, keys, engines, type / default and unit,
    meaning)``, the contact laws' materials after the ``[contact]`` table's own row and the fields a phase may change
    after the ``[[phases]]`` keys."""
    rows = []
    for row in ROWS:
        rows.append(row)
        if row.table == "contact":
            rows.extend(law_rows())
    out = []
    for row in rows:
        engines = ENGINE_WORDS.get(row.engines, ", ".join(row.engines))
        out.append((row.table, ", ".join(f"`{k}`" for k in row.keys), engines, row.type, row.meaning))
        if row.table == "phases" and row.keys == ("wall_velocity",):
            out.append(("phases", "a field of the contact law's material but `density`", "verlet", "as in `[contact]`",
                        "its value from `start` on (Luding 2005: the friction `mu` switched on at t_heat)"))
    return out
