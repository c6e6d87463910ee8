"""The runs behind the sintering section: Luding 2005's protocol over a grid of N, p and t_s, in worker processes,
resumed where it stopped.

A :class:`Task` is one stage of :mod:`verification.luding.protocol` for one sample: ``prepare`` (N, p), ``sinter`` (heating
and sintering for t_s, from the prepared state), ``cool`` (cooling and relaxation), ``compress`` and ``vibrate``
(the tests of Sec. 4.4, from the cooled state), ``schedule`` (the whole of Fig. 7 in one scene: the three-particle
control of Sec. 4.1.3, the control without thermal expansion), and the 3D stages with heated walls (``prepare3d``,
``sinter3d``). A task's ``variant`` names a change of the protocol that isolates a cause (:data:`VARIANTS`: another
preparation, walls that sinter, a cool-down with the walls held or without thermal contraction). Each task runs in
its own folder ``runs/<kind>/<sample>/``: the engine's
``timeseries.csv``, ``summary.json`` and ``state.npz``, then ``analysis.npz`` (contacts, forces, fragments and
snapshots at the stage's end) and, last, ``result.json``. A folder holding ``result.json`` is finished: a rerun
skips it. The preparation of each (N, p) runs once and every t_s starts from its state; each cooled state is the
start of both tests.

:func:`run_tasks` runs a list of tasks (and the tasks they need) in a pool of worker processes or on a Dask cluster
(:mod:`sinterheat.pool`), each task as soon as the one it starts from has finished, the longest first.
"""

from __future__ import annotations

import json
import pathlib
import sys
import time
import traceback
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from dem.laws.contact.luding import LUDING_TABLE1, P_MU
from verification.luding.protocol import CONTROL_T_HEAT, WALL_DAMPING, Times

PREPARE, SINTER, COOL, COMPRESS, VIBRATE, SCHEDULE = "prepare", "sinter", "cool", "compress", "vibrate", "schedule"
PREPARE3D, SINTER3D = "prepare3d", "sinter3d"
PARENT = {SINTER: PREPARE, COOL: SINTER, COMPRESS: COOL, VIBRATE: COOL, SINTER3D: PREPARE3D}

COMPRESSION_RATE = 1.0      # 1/s: eps_zz = t (the times of Fig. 20 are then strains)
COMPRESSION_STRAIN = 0.06
COMPRESSION_OUTPUT = 1e-4   # s between rows: failure strains at p = 10 are a few 1e-3
FIG20_TIMES = (0.005, 0.02, 0.03, 0.035, 0.04)  # s, Fig. 20
VIBRATION = {"frequency": 100.0, "amplitude": 2.0e-4, "duration": 0.1}  # Figs. 21-22

# 3D beyond the paper (a demonstration of the coupling, not a reproduction): Table 1's material on spheres with a
# narrower spread than its disks (w0 = 0.2, as the hot-wall-sintering scene), p in Pa chosen so that the mean contact
# force 2 a0 p_2D of the paper's p = 100 N/m is about that of a sphere in the cube, p_3D = 4 a0^2 sigma; the heat
# capacity time-scaled (as t0 scales the sintering) so that the heat crosses the sample within the run.
P3D = 5.0e4
SPREAD3D = 0.2
HOT3D = (150.0, 130.0)   # bottom, top wall while sintering (°C; mean 140 °C, the paper's sintering temperature)
SINTER3D_TIME = 0.3
CONDUCTIVITY3D, SPECIFIC_HEAT3D = 20.0, 10.0


@dataclass(frozen=True)
class Variant:
    """A change of the protocol (:mod:`verification.luding.protocol`) that isolates one cause: ``prep`` keyword arguments of
    the preparation, ``material`` fields changed in every stage (``prep_material``: in the preparation only),
    ``walls_held`` in the cool-down, ``t_heat`` of the three-particle control, ``heated``: false keeps a schedule
    at the preparation's 80 °C throughout (the three-particle control without heating), ``strain`` of the
    compression test; ``stage_only``: the variant changes its own stage alone and starts from the protocol's
    state."""

    label: str
    prep: dict = field(default_factory=dict)
    material: dict = field(default_factory=dict)
    prep_material: dict = field(default_factory=dict)
    walls_held: bool = False
    t_heat: float | None = None
    heated: bool = True
    strain: float | None = None
    stage_only: bool = False


PREP_SEEDS = (2, 3)  # other random placements of the protocol's preparation: the spread of nu(t_heat) of one sample
PLACEMENTS = (1,) + PREP_SEEDS  # the placements whose mean the statements read: densification (N max, t_s max),
#                                  failure in the compression test (every N, p and t_s)
FRICTIONLESS = {"prep_mu": 0.0, "prep_mu_wall": 0.0}
VARIANTS = {v.label: v for v in (
    Variant("frictionless", FRICTIONLESS),                                   # the paper's text (Sec. 4)
    Variant("frictionless-fast", {**FRICTIONLESS, "speed": 1.0}),            # random speeds 100x ours
    Variant("frictionless-slow", {**FRICTIONLESS, "wall_damping": 10 * WALL_DAMPING}),  # walls 10x slower
    Variant("frictionless-cohesive", FRICTIONLESS, prep_material={"brittle_sliding": False}),  # Table 1's cohesion
    Variant("frictionless-wall-friction", {**FRICTIONLESS, "prep_mu_wall": LUDING_TABLE1.mu}),
    Variant("no-wall-friction", {"prep_mu_wall": 0.0}),                      # particles frictional, walls not
    Variant("slow", {"wall_damping": 10 * WALL_DAMPING}),                    # the protocol, walls 10x slower
    Variant("walls-sinter", material={"wall_sintering": True}),              # wall contacts soften like pairs
    Variant("short-prep", t_heat=0.2),                                       # the control prepared for 0.2 s only
    Variant("control-wall-friction", {"prep_mu_wall": LUDING_TABLE1.mu}),    # the control with the walls' friction
    Variant("no-heating", heated=False),                                     # the control kept at 80 °C
    Variant("no-expansion", material={"expansion": 0.0}),                    # delta a_T = 0 (Sec. 4.1.3)
    Variant("expansion-text", material={"expansion": 2.5e-4}),  # Sec. 3.2's "one per-cent" from 80 to 120 °C
    Variant("held", walls_held=True, stage_only=True),                        # cool-down, the box held
    Variant("cool-no-expansion", material={"expansion": 0.0}, stage_only=True),
    Variant("cool-expansion-x3", material={"expansion": 3e-4}, stage_only=True),
    Variant("cool-expansion-x5", material={"expansion": 5e-4}, stage_only=True),
    Variant("held-no-expansion", material={"expansion": 0.0}, walls_held=True, stage_only=True),
    Variant("long", strain=0.15, stage_only=True),                             # the compression test to 15 %
)}


@dataclass(frozen=True)
class Task:
    """One stage for one sample. ``variant``: ``""`` (the protocol) or a key of :data:`VARIANTS`."""

    kind: str
    n: int
    p: float
    t_s: float | None = None
    seed: int = 1
    variant: str = ""

    @property
    def sample(self) -> str:
        name = f"n{self.n}-p{self.p:g}"
        if self.t_s is not None:
            name += f"-ts{self.t_s:g}"
        if self.seed != 1:
            name += f"-seed{self.seed}"
        return name + (f"-{self.variant}" if self.variant else "")

    @property
    def folder(self) -> str:
        return f"runs/{self.kind}/{self.sample}"

    @property
    def parent(self) -> "Task | None":
        kind = PARENT.get(self.kind)
        if kind is None:
            return None
        t_s = None if kind in (PREPARE, PREPARE3D) else self.t_s
        variant = "" if self.variant and VARIANTS[self.variant].stage_only else self.variant
        return Task(kind, self.n, self.p, t_s, self.seed, variant)

    @property
    def times(self) -> Times:
        """The times of the protocol for this task (the three-particle control prepares for longer:
        :data:`verification.luding.protocol.CONTROL_T_HEAT`)."""
        t_heat = VARIANTS[self.variant].t_heat if self.variant else None
        if t_heat is None:
            t_heat = CONTROL_T_HEAT if (self.kind == SCHEDULE and self.n == 3) else 0.2
        return Times(t_s=1.0 if self.t_s is None else self.t_s, t_heat=t_heat)

    @property
    def cost(self) -> float:
        """Simulated time times particles: the order in which ready tasks start (longest first)."""
        strain = VARIANTS[self.variant].strain if self.variant else None
        seconds = {PREPARE: 0.2, SINTER: 0.1 + (self.t_s or 0), COOL: 0.2, COMPRESS: strain or COMPRESSION_STRAIN,
                   VIBRATE: 0.5 * VIBRATION["duration"], SCHEDULE: self.times.t_f, PREPARE3D: 0.4,
                   SINTER3D: 2.0 * SINTER3D_TIME}[self.kind]
        return seconds * self.n


@dataclass(frozen=True)
class Grid:
    """The samples of a verification run: particle numbers, pressures (N/m), sintering times (s), the seeds of the
    three-particle control, whether to run the control without thermal expansion, the 3D sample's size, and which
    isolating runs (:meth:`isolating_tasks`): none, ``"quick"`` or ``"full"``."""

    n: tuple
    p: tuple
    t_s: tuple
    three_seeds: tuple
    no_expansion: bool
    n3d: int
    isolation: str = ""

    def isolating_tasks(self) -> list[Task]:
        """The runs that isolate the causes of the differences from the paper (:data:`VARIANTS`). ``"quick"``: the cheap
        ones, each a fraction of the cost of a sintered chain: the preparations alone (N max, p = 10: the paper's
        frictionless one, frictionless particles against walls with friction, frictional particles against frictionless
        walls, the protocol's with walls 10x slower) and the three-particle control of the first placement kept at 80 °C
        and without thermal expansion (p = 10) and sintered for every t_s (both p). ``"full"`` adds the paper's
        frictionless preparation through sintering and cool-down for every N and p, every other preparation (initial
        speeds, compression rate, cohesion, wall friction) for every N at p = 10 and the densification that follows from
        each (N min, p = 10; the one with frictionless walls also at p = 100), the three-particle control with walls
        that sinter, prepared for 0.2 s only, with wall friction, kept at 80 °C or without thermal expansion (every seed
        and p), the cool-down of the longest-sintered sample with the box held, without thermal contraction and with
        three and five times it (N max, both p), and the compression test of the shortest-sintered sample at p = 100
        carried on to 15 % strain, and the longest sintering of N max at p = 100 with the thermal expansion Sec. 3.2's
        text describes ("one per-cent" from 80 to 120 °C, δa_T = 2.5e-4 /K, against Table 1's 1e-4 /K)."""
        if not self.isolation:
            return []
        n, t_max = max(self.n), max(self.t_s)
        out = [Task(PREPARE, n, 10.0, variant=v)
               for v in ("frictionless", "frictionless-wall-friction", "no-wall-friction", "slow")]
        out += [Task(SCHEDULE, 3, 10.0, t_max, 1, v) for v in ("no-heating", "no-expansion")]
        out += [Task(SCHEDULE, 3, p, t_s, 1) for p in self.p for t_s in self.t_s]
        if self.isolation == "full":
            preps = ("frictionless", "frictionless-fast", "frictionless-slow", "frictionless-cohesive",
                     "frictionless-wall-friction", "no-wall-friction", "slow")
            out += [Task(PREPARE, m, 10.0, variant=v) for m in self.n for v in preps]
            out += [Task(PREPARE, m, p, seed=seed) for m in self.n for p in self.p for seed in PREP_SEEDS]
            out += [Task(COOL, m, p, t_max, variant="frictionless") for m in self.n for p in self.p]
            out += [Task(COOL, min(self.n), 10.0, t_max, variant=v) for v in preps if v != "frictionless"]
            out.append(Task(COOL, min(self.n), 100.0, t_max, variant="no-wall-friction"))
            out += [Task(SCHEDULE, 3, p, t_max, seed, v) for p in self.p for seed in self.three_seeds
                    for v in ("walls-sinter", "short-prep", "control-wall-friction", "no-heating", "no-expansion")]
            out += [Task(COOL, n, p, t_max, variant=v) for p in self.p
                    for v in ("held", "cool-no-expansion", "held-no-expansion", "cool-expansion-x3",
                              "cool-expansion-x5")]
            out.append(Task(COOL, n, 100.0, t_max, variant="expansion-text"))
            out.append(Task(COMPRESS, n, 100.0, min(self.t_s), variant="long"))
        return list(dict.fromkeys(out))

    def tasks(self) -> list[Task]:
        out = []
        for n in self.n:
            for p in self.p:
                for t_s in self.t_s:
                    out += [Task(COMPRESS, n, p, t_s), Task(VIBRATE, n, p, t_s)]
        t_max = max(self.t_s)
        out += [Task(COOL, max(self.n), p, t_max, seed) for p in self.p for seed in PREP_SEEDS]
        out += [Task(COMPRESS, n, p, t_s, seed) for n in self.n for p in self.p for t_s in self.t_s
                for seed in PREP_SEEDS]
        out += [Task(SCHEDULE, 3, p, t_max, seed) for p in self.p for seed in self.three_seeds]
        if self.no_expansion:
            out += [Task(SCHEDULE, min(self.n), p, t_max, variant="no-expansion") for p in self.p]
        out.append(Task(SINTER3D, self.n3d, P3D))
        return list(dict.fromkeys(out + self.isolating_tasks()))


FULL = Grid(n=(100, 300), p=(10.0, 100.0), t_s=(1e-4, 1e-3, 0.01, 0.02, 0.05, 0.1, 0.5, 1.0),
            three_seeds=(1, 2, 3, 4), no_expansion=True, n3d=250, isolation="full")
QUICK = Grid(n=(100,), p=(10.0, 100.0), t_s=(1e-4, 0.01, 1.0), three_seeds=(1, 2), no_expansion=False, n3d=40,
             isolation="quick")


def with_parents(tasks) -> list[Task]:
    """``tasks`` and every task they start from, each once, parents first."""
    out, seen = [], set()

    def add(task):
        if task in seen:
            return
        if task.parent is not None:
            add(task.parent)
        seen.add(task)
        out.append(task)

    for task in tasks:
        add(task)
    return out


# ------------------------------------------------------------------------------------------------ one stage
def _material(task: Task, kind: str | None = None):
    """The material of ``task`` (of its stage ``kind``, default its own): the protocol's, changed by the variant."""
    if not task.variant:
        return LUDING_TABLE1
    v = VARIANTS[task.variant]
    changes = {**v.material, **(v.prep_material if (kind or task.kind) in (PREPARE, SCHEDULE) else {})}
    return replace(LUDING_TABLE1, **changes)


def _frozen_radii(state: pathlib.Path, out: pathlib.Path, material) -> str:
    """``state`` with the reference radii a(T_melt) of eq. 9 recomputed for ``material``'s delta a_T from the radii
    and temperatures it holds, written to ``out``: a run with another delta a_T from a state saved with Table 1's
    keeps each particle's size at the start (eq. 9 would otherwise jump it)."""
    with np.load(state) as f:
        data = {k: f[k] for k in f.files}
    data["radius_ref"] = data["radius"] / (1.0 - material.expansion * (material.T_melt - data["T"]))
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez(out, **data)
    return str(out)


def scene_doc(task: Task, root: pathlib.Path) -> dict:
    """The scene of ``task`` (its parent's state under ``root``)."""
    from verification.luding import protocol as sp
    from dem.scene import state_file

    material = _material(task)
    variant = VARIANTS.get(task.variant)
    prep = dict(variant.prep) if variant else {}
    parent = None if task.parent is None else str(root / task.parent.folder / "state.npz")
    if task.kind == COOL and variant and variant.stage_only and "expansion" in variant.material:
        parent = _frozen_radii(pathlib.Path(parent), root / task.folder / "start.npz", material)
    if task.kind == PREPARE:
        damping = prep.pop("wall_damping", WALL_DAMPING)
        doc = sp.preparation_doc(task.n, task.p, seed=task.seed, material=material, **prep)
        for wall in doc["walls"]:
            if wall.get("motion") == "stress":
                wall["damping"] = damping
        return doc
    if task.kind == SINTER:
        return sp.sintering_doc(parent, task.p, task.t_s, material=material)
    if task.kind == COOL:
        return sp.cooling_doc(parent, task.p, material=material, walls_held=bool(variant and variant.walls_held))
    if task.kind == COMPRESS:
        z0 = -sp.wall_offset(state_file.load(parent), "top")
        strain = variant.strain if variant and variant.strain else COMPRESSION_STRAIN
        return sp.compression_doc(parent, task.p, strain_rate=COMPRESSION_RATE, strain=strain, z0=z0,
                                  material=material, output_interval=COMPRESSION_OUTPUT)
    if task.kind == VIBRATE:
        return sp.vibration_doc(parent, sp.floor_height(state_file.load(parent)), material=material, **VIBRATION)
    if task.kind == SCHEDULE:
        if variant and variant.prep_material:
            raise ValueError(f"variant {task.variant!r}: a preparation-only material needs separate stages")
        if task.n == 3:
            doc = sp.control_doc(task.p, task.t_s, seed=task.seed, t_heat=task.times.t_heat,
                                 material=_material(task, SINTER), **prep)
            if variant and not variant.heated:
                doc["temperature"]["value"] = [sp.T_PREPARE for _ in doc["temperature"]["value"]]
            return doc
        return sp.schedule_doc(task.n, task.p, task.t_s, seed=task.seed, material=_material(task, SINTER), **prep)
    if task.kind == PREPARE3D:
        return sp.preparation_doc(task.n, task.p, seed=task.seed, material=material, dimension=3, spread=SPREAD3D)
    return sp.heated_walls_doc(parent, task.p, hot=HOT3D[0], cold=HOT3D[1], duration=SINTER3D_TIME,
                               t0=sp.T0_SINTER, conductivity=CONDUCTIVITY3D, specific_heat=SPECIFIC_HEAT3D,
                               material=material)


def snapshot(sim) -> dict:
    """Particles, contacts and walls of the current state, for drawings in the style of Figs. 20-22."""
    mech = sim.mechanics
    s = mech.state
    fields = sim.particle_fields()
    _, pairs, cf = sim.links()
    return {"t": np.array(mech.t), "x": s.x.copy(), "radius": s.radius.copy(), "mean_stress": fields["mean_stress"],
            "i": pairs[:, 0], "j": pairs[:, 1], "fn": cf["normal_force"], "ft": cf["tangential_force"],
            "wall_normal": mech.w.normal.copy(), "wall_q": mech.w.q.copy()}


def contact_statistics(sim) -> dict:
    """Per closed contact: overlap over a_i + a_j (Figs. 12-13), normal force (Figs. 14-15), tangential force,
    f_min (eq. 15), the activated friction ``mu_t = f_t/(f_n - f_min)`` and ``mu(T, t)`` (eq. 24, Sec. 4.3.3)."""
    from verification.luding.fragments import tension_capacity

    mech = sim.mechanics
    s = mech.state
    i, j, overlap, fn, ft = mech.contacts()
    _, _, capacity = tension_capacity(mech)
    k1f = mech.particle_column("k1_factor")
    ft = np.linalg.norm(ft, axis=1)
    excess = fn + capacity
    with np.errstate(divide="ignore", invalid="ignore"):
        mu_t = np.where(excess > 0, ft / excess, np.nan)
    return {"overlap_rel": overlap / (s.radius[i] + s.radius[j]), "fn": fn, "ft": ft, "fmin": -capacity,
            "mu_t": mu_t, "mu_T": 0.5 * (k1f[i] + k1f[j]) * mech.params[P_MU]}


def neck_statistics(sim) -> dict:
    """3D: Rojek's volume-conserving neck radius of each closed contact over the smaller radius."""
    from fem_neck.geometry import neck_radius

    mech = sim.mechanics
    s = mech.state
    i, j, overlap = mech.contacts()[:3]
    r_min = np.minimum(s.radius[i], s.radius[j])
    h = np.minimum(overlap, 0.999 * (2.0 / 3.0) * r_min)
    a = np.asarray(neck_radius(s.radius[i], s.radius[j], h)) if len(i) else np.zeros(0)
    return {"neck_over_radius": a / r_min}


def run_task(task: Task, root) -> dict:
    """Run ``task`` into ``root/task.folder`` (module docstring); returns what ``result.json`` holds."""
    from dem.scene import state_file
    from dem.engines.verlet.engine import VerletEngine
    from verification.luding.fragments import fragments
    from dem.output.writer import RunWriter
    from dem.scene import parse_scene

    root = pathlib.Path(root)
    out = root / task.folder
    out.mkdir(parents=True, exist_ok=True)
    (out / "result.json").unlink(missing_ok=True)
    scene = parse_scene(scene_doc(task, root), task.kind)
    t_start = time.perf_counter()
    sim = VerletEngine(scene)
    writer = RunWriter(out, scene, sim)
    interval = scene.motion.output_interval
    captures = list(FIG20_TIMES) if task.kind == COMPRESS else []
    snaps = []

    def observe():
        writer.observe()
        elapsed = sim.mechanics.t - sim.mechanics.t_start  # the stage's time (the clock goes on from the state)
        if captures and elapsed >= captures[0] - 0.5 * interval:  # the first row at (or just before) it
            captures.pop(0)
            snaps.append(snapshot(sim))

    sim.run(observe)
    summary = sim.summary()
    seconds = time.perf_counter() - t_start
    state_file.save(sim.state(), out / "state.npz")
    writer.finish({"scene": scene.name, **summary, "seconds": seconds}, plots=False)
    snaps.append(snapshot(sim))
    arrays = {f"snap{k}_{key}": v for k, snap in enumerate(snaps) for key, v in snap.items()}
    arrays.update(contact_statistics(sim))
    if sim.mechanics.state.dimension == 3:
        arrays.update(neck_statistics(sim))
    labels, sizes = fragments(sim.mechanics)
    arrays["fragment_sizes"] = sizes
    np.savez_compressed(out / "analysis.npz", **arrays)
    s = sim.mechanics.state
    volume = sim.box_volume()
    result = {
        "task": asdict(task), "seconds": seconds, "steps": sim.mechanics.steps, "particles": s.n,
        "ns_per_particle_step": 1e9 * seconds / max(1, sim.mechanics.steps * s.n), "t": sim.mechanics.t,
        "volume_fraction": sim.volume_fraction(),
        "mass_fraction": None if volume is None else float(np.sum(s.mass) / (scene.contact.density * volume)),
        "coordination": sim.mechanics.coordination(),
        "k1_factor": float(np.mean(sim.mechanics.particle_column("k1_factor"))),
        "kinetic_energy": s.kinetic_energy(), "wall_stress": sim.wall_stress(), "snapshots": len(snaps),
        "fragments": int(len(sizes)), "largest_fragment": int(sizes[0]), "single_particles": int(np.sum(sizes == 1)),
        "effective_conductivity": summary.get("effective_conductivity"),
    }
    (out / "result.json").write_text(json.dumps(result, indent=1) + "\n")
    return result


def _run_in_worker(task: Task, root: str) -> dict:
    try:
        return run_task(task, root)
    except Exception as exc:  # reported, not raised: the other tasks go on (the traceback in the task's folder)
        folder = pathlib.Path(root) / task.folder
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "error.txt").write_text(traceback.format_exc())
        return {"task": asdict(task), "error": f"{type(exc).__name__}: {exc}".splitlines()[0]}


def load_result(root, task: Task) -> dict | None:
    """The finished result of ``task`` under ``root``, or None."""
    path = pathlib.Path(root) / task.folder / "result.json"
    if not path.exists():
        return None
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError:
        return None


def run_tasks(tasks, root, workers: int = 2, progress: bool = True) -> dict:
    """Run ``tasks`` (and their parents) under ``root`` in ``workers`` processes, or on the Dask cluster of
    :func:`sinterheat.pool.use_dask` (its workers must share ``root``); finished ones are skipped. Returns ``{task:
    result}``; a failed task's result holds ``error`` and its dependents are not run."""
    from tqdm import tqdm

    from sinterheat.pool import bar_switch, pool

    root = pathlib.Path(root).resolve()  # the same path on every worker
    everything = with_parents(tasks)
    results = {t: r for t in everything if (r := load_result(root, t)) is not None}
    pending = [t for t in everything if t not in results]
    bar = tqdm(total=len(everything), initial=len(results), desc="sintering runs", unit="run", file=sys.stderr,
               **bar_switch(progress))
    running = {}
    with pool(workers, start="spawn") as runs:
        while pending or running:
            finished = {t for t, r in results.items() if "error" not in r}
            ready = sorted((t for t in pending if t.parent is None or t.parent in finished), key=lambda t: -t.cost)
            blocked = [t for t in pending if t.parent is not None and "error" in results.get(t.parent, {})]
            for t in blocked:
                results[t] = {"task": asdict(t), "error": f"not run: {t.parent.folder} failed"}
                pending.remove(t)
                bar.update(1)
            free = len(ready) if runs.slots is None else max(0, runs.slots - len(running))
            for t in ready[:free]:
                running[runs.submit(_run_in_worker, t, str(root), priority=t.cost)] = t
                pending.remove(t)
            if not running:
                continue
            for future in runs.wait(running):
                task = running.pop(future)
                results[task] = future.result()
                bar.update(1)
                bar.set_postfix_str(task.folder.split("/", 1)[1])
                if "error" in results[task]:
                    bar.write(f"sintering: {task.folder}: {results[task]['error']}", file=sys.stderr)
    bar.close()
    return results


def schedule_seconds(n: int = 300, p: float = 100.0, t_s: float = 1.0, seed: int = 1) -> dict:
    """The whole schedule of Fig. 7 (:func:`verification.luding.protocol.schedule_doc`) in this process, without output:
    ``seconds`` of the run (building the simulation, loading the compiled kernels and the time loop),
    ``loop_seconds`` (the time loop alone), ``steps``, ``ns_per_particle_step`` (of the loop) and the final solid
    fraction and coordination number. For the bench row of "the whole schedule, t_s = 1, N = 300"."""
    from dem.engines.verlet.engine import VerletEngine
    from dem.scene import parse_scene
    from verification.luding.protocol import schedule_doc

    t0 = time.perf_counter()
    sim = VerletEngine(parse_scene(schedule_doc(n, p, t_s, seed=seed), "schedule"))
    t1 = time.perf_counter()
    sim.run()
    t2 = time.perf_counter()
    summary = sim.summary()
    steps = sim.mechanics.steps
    return {"n": n, "p": p, "t_s": t_s, "seconds": t2 - t0, "loop_seconds": t2 - t1, "steps": steps,
            "ns_per_particle_step": 1e9 * (t2 - t1) / (steps * n), "volume_fraction": summary["volume_fraction"],
            "coordination": summary["coordination"], "neighbour_rebuilds": summary["neighbour_rebuilds"]}


def _main(argv=None) -> int:
    """``python -m verification.luding.runs [N P T_S]``: time the whole schedule (one JSON line)."""
    args = sys.argv[1:] if argv is None else argv
    n, p, t_s = (int(args[0]), float(args[1]), float(args[2])) if args else (300, 100.0, 1.0)
    print(json.dumps(schedule_seconds(n, p, t_s)))
    return 0


if __name__ == "__main__":
    sys.exit(_main())
