"""Run outputs, written as the run goes: a CSV time series, VTU/PVD snapshots for ParaView, ``summary.json``.

* ``timeseries.csv`` -- step, t, mean/min/max temperature, and the heat flow into the particles (W) through
  each boundary: fixed particles, walls, convection, radiation, internal sources.
* ``particles.pvd`` + ``particles_NNNNN.vtu`` -- particles as points (vertex cells) with radius, temperature,
  fixed and material.
* ``bonds.pvd`` + ``bonds_NNNNN.vtu`` -- bonds as lines with conductance, heat flow and neck radius; a wall bond
  joins the particle to its foot point on the wall, a bond across a periodic face joins the particle to the image
  of its partner (outside the box).
"""

from __future__ import annotations

import io
import json
import math
import pathlib
import re

import meshio
import numpy as np

CSV_FLOWS = ("fixed", "walls", "convection", "radiation", "internal")
MAX_SNAPSHOTS = 1000  # VTU snapshots per run (each is two files): more is refused up front (fixed dt) or thinned (auto)


def resumed_csv(path: pathlib.Path, keep) -> "io.TextIOBase":
    """``path`` opened for appending after dropping the rows (dicts) ``keep`` refuses: the rows written after the
    checkpoint a run resumes from."""
    with path.open() as fh:
        lines = fh.read().splitlines()
    header = lines[0].split(",") if lines else []
    kept = lines[:1] + [line for line in lines[1:] if keep(dict(zip(header, line.split(","))))]
    path.write_text("".join(line + "\n" for line in kept))
    return path.open("a")


def resumed_snapshots(out: pathlib.Path, kinds, last_step: int) -> list[tuple[float, int]]:
    """The ``(t, step)`` of the snapshots listed in ``out/<kind>.pvd`` up to ``last_step``; the files of later ones
    (written after the checkpoint a run resumes from) are deleted."""
    listed = []
    pvd = out / f"{kinds[0]}.pvd"
    if pvd.exists():
        listed = [(float(t), int(step)) for t, step in
                  re.findall(r'timestep="([^"]+)"[^>]*file="[a-z]+_(\d+)\.vtu"', pvd.read_text())]
    for kind in kinds:
        for f in out.glob(f"{kind}_*.vtu"):
            if int(f.stem.split("_")[-1]) > last_step:
                f.unlink()
    return [(t, step) for t, step in listed if step <= last_step]


def write_vtu(path: pathlib.Path, mesh) -> None:
    """``mesh`` to ``path``, written aside and renamed: a VTU file on disk is always whole."""
    tmp = path.with_name(path.name + ".part")
    meshio.write(tmp, mesh, file_format="vtu")
    tmp.replace(path)


def settle_snapshots(out: pathlib.Path, kinds, snapshots, digits: int) -> None:
    """After an interrupt: the half-written files and the files of a snapshot left unfinished are deleted and every
    PVD collection lists exactly the snapshots on disk."""
    steps = {step for _, step in snapshots}
    for f in out.glob("*.vtu.part"):
        f.unlink()
    for kind in kinds:
        for f in out.glob(f"{kind}_*.vtu"):
            if int(f.stem.split("_")[-1]) not in steps:
                f.unlink()
        write_pvd(out / f"{kind}.pvd", [(t, f"{kind}_{step:0{digits}d}.vtu") for t, step in snapshots])


def write_pvd(path: pathlib.Path, entries: list[tuple[float, str]]) -> None:
    """A ParaView collection of ``(time, file)`` entries."""
    rows = "\n".join(f'    <DataSet timestep="{t:.17g}" group="" part="0" file="{f}"/>' for t, f in entries)
    path.write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
                    f"  <Collection>\n{rows}\n  </Collection>\n</VTKFile>\n")


class RunWriter:
    """Observer for the integrators: CSV row every ``every`` steps, snapshots every ``vtu_every`` steps."""

    def __init__(self, out_dir, scene, model, resume_step: int | None = None):
        """``resume_step``: go on with the files of a run resumed from the checkpoint at that step."""
        o, s = scene.output, scene.solver
        if o.vtu and o.vtu_every and s.mode == "transient" and s.dt != "auto":
            snapshots = math.ceil(s.t_end / s.dt * (1 - 1e-12)) // o.vtu_every
            if snapshots > MAX_SNAPSHOTS:
                raise ValueError(f"[output] vtu_every = {o.vtu_every}: {snapshots} snapshots of t_end / dt = "
                                 f"{s.t_end / s.dt:.6g} steps exceed the limit of {MAX_SNAPSHOTS}; valid: vtu_every >= "
                                 f"{math.ceil(s.t_end / s.dt / MAX_SNAPSHOTS)}, 0 (first and last) or vtu = false")
        self.out = pathlib.Path(out_dir)
        self.out.mkdir(parents=True, exist_ok=True)
        self.scene, self.model = scene, model
        self.snapshots: list[tuple[float, int]] = []
        self.last = None
        if resume_step is None:
            self.csv = (self.out / "timeseries.csv").open("w")
            self.csv.write("step,t,T_mean,T_min,T_max," + ",".join(f"Q_{k}" for k in CSV_FLOWS) + "\n")
        else:
            self.csv = resumed_csv(self.out / "timeseries.csv", lambda row: int(row["step"]) <= resume_step)
            self.snapshots = resumed_snapshots(self.out, ("particles", "bonds"), resume_step)

    def __call__(self, step, t, T_free, flows):
        net = self.model.network
        T = net.full(T_free)
        self.last = (step, t, T, flows)
        if step % self.scene.output.every == 0:
            self._row(step, t, T, flows)
        every = self.scene.output.vtu_every
        if every and len(self.snapshots) >= MAX_SNAPSHOTS:  # dt = "auto": the step count was not known up front
            every *= 2 ** (len(self.snapshots) // MAX_SNAPSHOTS)  # thin the snapshots, keep their number bounded
        if self.scene.output.vtu and (step == 0 or (every and step % every == 0)):
            self._snapshot(step, t, T)

    def _row(self, step, t, T, flows):
        q = ",".join(f"{flows.get(k, 0.0):.12g}" for k in CSV_FLOWS)
        self.csv.write(f"{step},{t:.12g},{T.mean():.12g},{T.min():.12g},{T.max():.12g},{q}\n")
        self.csv.flush()

    def _snapshot(self, step, t, T):
        if self.snapshots and self.snapshots[-1][1] == step:
            return
        p, b = self.scene.particles, self.model.bonds
        write_vtu(self.out / f"particles_{step:05d}.vtu", meshio.Mesh(
            p.position, [("vertex", np.arange(p.n).reshape(-1, 1))],
            point_data={"radius": p.radius, "temperature": T, "fixed": p.fixed.astype(np.int8),
                        "material": p.material.astype(np.int32)}))
        self.model.T = T
        q_pairs, q_walls = self.model.bond_heat_flow()
        walls = self.scene.walls
        foot = np.array([walls[w].point for w in b.wall_index]).reshape(-1, 3)
        normal = np.array([walls[w].normal for w in b.wall_index]).reshape(-1, 3)
        x = p.position[b.wall_particle]
        foot = x - np.sum((x - foot) * normal, axis=1, keepdims=True) * normal
        crossing = np.flatnonzero(np.any(b.shifts != 0, axis=1))
        image = b.vectors(p.position, self.scene.box)[crossing] + p.position[b.i[crossing]]
        points = np.vstack([p.position, foot, image])
        partner = b.j.copy()
        partner[crossing] = p.n + b.n_walls + np.arange(len(crossing))
        lines = np.vstack([np.column_stack([b.i, partner]),
                           np.column_stack([b.wall_particle, p.n + np.arange(b.n_walls)])]).astype(np.int64)
        write_vtu(self.out / f"bonds_{step:05d}.vtu", meshio.Mesh(
            points, [("line", lines.reshape(-1, 2))],
            cell_data={"conductance": [np.concatenate([self.model.K_pairs, self.model.K_walls])],
                       "heat_flow": [np.concatenate([q_pairs, q_walls])],
                       "neck_radius": [np.concatenate([b.a, b.wall_a])]}))
        self.snapshots.append((t, step))
        self._write_pvd()  # every snapshot listed at once: an interrupted run's collection holds all it wrote

    def _write_pvd(self):
        for kind in ("particles", "bonds"):
            write_pvd(self.out / f"{kind}.pvd", [(tt, f"{kind}_{s:05d}.vtu") for tt, s in self.snapshots])

    def interrupted(self, summary: dict) -> None:
        """Close the files of a run stopped by Ctrl-C: ``summary.json`` marked ``"interrupted": true`` with the state
        reached (the last step's time, step and temperatures) and where a resume starts (the last checkpoint)."""
        if self.last is not None:
            step, t, T, _ = self.last
            summary.update(t=t, steps=step, T_mean=float(T.mean()), T_min=float(T.min()), T_max=float(T.max()))
        summary["resume_from"] = checkpoint_reached(self.out)
        self.csv.close()
        settle_snapshots(self.out, ("particles", "bonds"), self.snapshots, 5)
        write_summary(self.out / "summary.json", summary)

    def finish(self, summary: dict, plots: bool = True):
        if self.last is not None:
            step, t, T, flows = self.last
            if step % self.scene.output.every:
                self._row(step, t, T, flows)
            if self.scene.output.vtu:
                self._snapshot(step, t, T)
        if self.snapshots:
            self._write_pvd()
        self.csv.close()
        write_summary(self.out / "summary.json", summary)  # first: the profile plot reads k_eff from it
        if plots:
            from dem.output.plots import thermal_plots

            summary["plots"] = thermal_plots(self.out, self.scene, self.model.T)
            write_summary(self.out / "summary.json", summary)


def checkpoint_reached(out: pathlib.Path) -> dict | None:
    """``{"t", "steps"}`` of the checkpoint in ``out`` (where ``--resume`` goes on from), or None."""
    path = out / "checkpoint.npz"
    if not path.exists():
        return None
    import numpy as np

    with np.load(path, allow_pickle=False) as f:
        return {"t": float(f["t"]), "steps": int(f["steps"])}


def write_summary(path, summary: dict) -> None:
    pathlib.Path(path).write_text(json.dumps(summary, indent=2) + "\n")


class MotionWriter:
    """Observer of the engine for moving particles: a ``timeseries.csv`` row per output time and snapshots every
    ``[output] vtu_interval`` (and at the start and end): ``particles_NNNNN.vtu`` (points with the fields the
    submodels offer) and ``contacts_NNNNN.vtu`` (lines with normal and tangential force and overlap), each listed in
    its PVD collection as soon as it is written."""

    def __init__(self, out_dir, scene, resume_step: int | None = None):
        """``resume_step``: go on with the files of a run resumed from the checkpoint at that step."""
        self.out = pathlib.Path(out_dir)
        self.out.mkdir(parents=True, exist_ok=True)
        self.scene = scene
        self.csv = None
        self.columns: list[str] = []
        self.snapshots: list[tuple[float, int]] = []
        self.next_vtu = 0.0
        if resume_step is not None:
            with (self.out / "timeseries.csv").open() as fh:
                self.columns = fh.readline().strip().split(",")
            self.csv = resumed_csv(self.out / "timeseries.csv", lambda row: int(row["step"]) <= resume_step)
            self.snapshots = resumed_snapshots(self.out, ("particles", "contacts"), resume_step)
            t_last = max((t for t, _ in self.snapshots), default=0.0)
            if (self.out / "profiles.csv").exists():
                resumed_csv(self.out / "profiles.csv", lambda row: float(row["t"]) <= t_last).close()
            interval = scene.motion.vtu_interval
            while interval > 0 and self.next_vtu <= t_last + 1e-12 * scene.solver.t_end:
                self.next_vtu += interval  # as the run advanced it: the same sums, the same snapshot times

    def __call__(self, sim):
        row = sim.record()
        if self.csv is None:
            self.columns = list(row)
            self.csv = (self.out / "timeseries.csv").open("w")
            self.csv.write(",".join(self.columns) + "\n")
        self.csv.write(",".join("" if row.get(k) is None else f"{row[k]:.12g}" for k in self.columns) + "\n")
        self.csv.flush()
        m = self.scene.motion
        t_end = self.scene.solver.t_end
        if m.vtu_interval > 0 and row["t"] >= self.next_vtu - 1e-12 * t_end or row["t"] == 0.0 \
                or row["t"] >= t_end * (1 - 1e-12):
            self.snapshot(sim, row["t"], row["step"])
            if m.vtu_interval > 0:
                while self.next_vtu <= row["t"] + 1e-12 * t_end:
                    self.next_vtu += m.vtu_interval

    def snapshot(self, sim, t: float, step: int):
        if self.snapshots and self.snapshots[-1][1] == step:
            return
        profile = sim.profile()
        if profile is not None:
            new = not (self.out / "profiles.csv").exists()
            with (self.out / "profiles.csv").open("a") as fh:
                if new:
                    fh.write("t,distance,solid_fraction,neck_over_radius\n")
                for d, phi, a in zip(profile["distance"], profile["solid_fraction"], profile["neck_over_radius"]):
                    fh.write(f"{t:.12g},{d:.12g},{phi:.12g},{'' if a is None else f'{a:.12g}'}\n")
        if not self.scene.output.vtu:
            self.snapshots.append((t, step))
            return
        s = sim.mechanics.state
        fields = sim.particle_fields()
        write_vtu(self.out / f"particles_{step:09d}.vtu", meshio.Mesh(
            s.x, [("vertex", np.arange(s.n).reshape(-1, 1))], point_data=fields))
        i, j, cfields = sim.contact_fields()
        write_vtu(self.out / f"contacts_{step:09d}.vtu", meshio.Mesh(
            s.x, [("line", np.column_stack([i, j]).astype(np.int64).reshape(-1, 2))],
            cell_data={k: [v] for k, v in cfields.items()}))
        self.snapshots.append((t, step))
        for kind in ("particles", "contacts"):
            write_pvd(self.out / f"{kind}.pvd", [(tt, f"{kind}_{k:09d}.vtu") for tt, k in self.snapshots])

    def interrupted(self, summary: dict) -> None:
        """Close the files of a run stopped by Ctrl-C (:meth:`RunWriter.interrupted`)."""
        summary["resume_from"] = checkpoint_reached(self.out)
        if self.scene.output.vtu:
            settle_snapshots(self.out, ("particles", "contacts"), self.snapshots, 9)
        self.finish(summary, plots=False)

    def finish(self, summary: dict, plots: bool = True):
        if self.csv is not None:
            self.csv.close()
        if plots:
            from dem.output.plots import motion_plots

            summary["plots"] = motion_plots(self.out)
        write_summary(self.out / "summary.json", summary)
