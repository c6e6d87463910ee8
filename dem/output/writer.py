"""Run outputs, written as the run goes, by one writer for every engine (:class:`RunWriter`):

* ``timeseries.csv`` -- one row of the engine's observables (``engine.record()``: step, t, temperatures, the heat flow
  through each boundary, for moving particles the solid fraction, coordination, wall stresses, ...);
* ``particles.pvd`` + ``particles_NNNNNNNNN.vtu`` -- the particles as points (vertex cells) with their ids and the
  fields the engine offers (``engine.particle_fields()``);
* ``bonds.pvd`` + ``bonds_NNNNNNNNN.vtu`` (a static packing) or ``contacts.pvd`` + ``contacts_NNNNNNNNN.vtu`` (particles
  that move) -- the links between particles as lines with their fields (``engine.links()``);
* ``particles_NNNNNNNNN.dump`` (with ``[output] lammps_dump``) -- the same snapshots as LAMMPS text dumps
  (:mod:`dem.output.lammps_dump`), for OVITO and LAMMPS's tools;
* ``profiles.csv`` -- profiles against the distance from a heated wall, where the engine offers them;
* ``summary.json`` at the end (and after Ctrl-C, marked ``"interrupted": true``), and the engine's plots.

When rows and snapshots are written follows the scene's ``[output]`` table: a static run every ``every`` steps and
snapshots every ``vtu_every`` steps; particles that move at every output time (the engine reports at those) and
snapshots every ``vtu_interval`` seconds; both at the start and at the end. Every file is written aside and renamed,
or appended and flushed row by row, so what is on disk is whole at any moment. The steps after the run each keep what
the run produced: one that fails (a plot, a snapshot) is named in ``summary.json`` under ``output_errors`` and the
others still happen.
"""

from __future__ import annotations

import io
import json
import math
import pathlib
import re

import meshio
import numpy as np

from dem.output.atomic import read_npz, write_aside

MAX_SNAPSHOTS = 1000  # VTU snapshots per run (each is two files): more is refused up front (fixed dt) or thinned (auto)
DIGITS = 9  # of the step in a snapshot's file name


def resumed_csv(path: pathlib.Path, keep) -> "io.TextIOBase":
    """``path`` opened for appending after dropping the rows (dicts) ``keep`` refuses: the rows written after the
    checkpoint a run resumes from.

    Parameters
    ----------
    path : pathlib.Path
        The CSV file (with a header row).
    keep : callable
        ``row (dict of column to text) -> bool``: whether a row stays.
    """
    with path.open() as fh:
        lines = fh.read().splitlines()
    header = lines[0].split(",") if lines else []
    kept = lines[:1] + [line for line in lines[1:] if keep(dict(zip(header, line.split(","))))]
    write_aside(path, lambda fh: fh.write("".join(line + "\n" for line in kept)))
    return path.open("a")


def resumed_profiles(path: pathlib.Path, t_last: float) -> None:
    """``profiles.csv`` cut after the block of the snapshot at ``t_last`` (the last one a resumed run keeps). A block's
    time is written rounded (``_cell``: 12 digits), so it is compared with ``t_last`` rounded the same way: the block at
    exactly ``t_last`` stays even where its rounded time lies above ``t_last``, and every later one goes.

    Parameters
    ----------
    path : pathlib.Path
        The ``profiles.csv`` file.
    t_last : float
        Time of the last snapshot kept, s.
    """
    limit = float(_cell(t_last))
    resumed_csv(path, lambda row: float(row["t"]) <= limit).close()


def snapshot_files(out: pathlib.Path, kind: str):
    """``(step, path)`` of every snapshot file of ``kind`` in ``out``: ``kind_STEP.vtu``, and in parallel the
    pieces ``kind_STEP_RANK.vtu`` and ``kind_STEP.pvtu`` (:mod:`dem.output.pieces`).

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    kind : str
        The snapshot kind: ``"particles"``, ``"bonds"`` or ``"contacts"``.
    """
    for f in (*out.glob(f"{kind}_*vtu"), *out.glob(f"{kind}_*.dump")):
        yield int(f.name.split("_")[1].split(".")[0]), f


def listed_snapshots(out: pathlib.Path, kind: str) -> list[tuple[float, int]]:
    """The ``(t, step)`` of the snapshots ``out/<kind>.pvd`` lists (VTU or PVTU files).

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    kind : str
        The snapshot kind: ``"particles"``, ``"bonds"`` or ``"contacts"``.
    """
    pvd = out / f"{kind}.pvd"
    if not pvd.exists():
        return []
    return [(float(t), int(step)) for t, step in
            re.findall(r'timestep="([^"]+)"[^>]*file="[a-z]+_(\d+)\.p?vtu"', pvd.read_text())]


def resumed_snapshots(out: pathlib.Path, kinds, last_step: int) -> list[tuple[float, int]]:
    """The ``(t, step)`` of the snapshots listed in ``out/<kind>.pvd`` up to ``last_step``; the files of later ones
    (written after the checkpoint a run resumes from) are deleted.

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    kinds : sequence of str
        The snapshot kinds of the run, the first one's collection giving the list.
    last_step : int
        The step of the checkpoint the run resumes from.
    """
    for kind in kinds:
        for step, f in snapshot_files(out, kind):
            if step > last_step:
                f.unlink()
    return [(t, step) for t, step in listed_snapshots(out, kinds[0]) if step <= last_step]


def write_vtu(path: pathlib.Path, mesh) -> None:
    """``mesh`` to ``path``, written aside and renamed: a VTU file on disk is always whole.

    Parameters
    ----------
    path : pathlib.Path
        The ``.vtu`` file to write.
    mesh : meshio.Mesh
        What to write.
    """
    write_aside(path, lambda tmp: meshio.write(tmp, mesh, file_format="vtu"), None)


def write_pvd(path: pathlib.Path, entries: list[tuple[float, str]]) -> None:
    """A ParaView collection of ``(time, file)`` entries.

    Parameters
    ----------
    path : pathlib.Path
        The ``.pvd`` file to write.
    entries : list of tuple
        ``(time in s, file name relative to the collection)`` of every snapshot.
    """
    rows = "\n".join(f'    <DataSet timestep="{t:.17g}" group="" part="0" file="{f}"/>' for t, f in entries)
    write_aside(path, lambda fh: fh.write('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" '
                                          f'byte_order="LittleEndian">\n  <Collection>\n{rows}\n  </Collection>\n'
                                          "</VTKFile>\n"))


def checkpoint_reached(out: pathlib.Path) -> dict | None:
    """``{"t", "steps"}`` of the checkpoint in ``out`` (where ``--resume`` goes on from), or None.

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    """
    path = out / "checkpoint.npz"
    if not path.exists():
        return None
    try:
        data = read_npz(path, "checkpoint")
        return {"t": float(data["t"]), "steps": int(data["steps"])}
    except (ValueError, KeyError):  # not one of ours: nothing to resume from
        return None


def write_summary(path, summary: dict) -> None:
    """``summary`` as JSON, written aside and renamed.

    Parameters
    ----------
    path : str or pathlib.Path
        The JSON file to write.
    summary : dict
        The JSON-ready summary.
    """
    write_aside(path, lambda fh: fh.write(json.dumps(summary, indent=2) + "\n"))


def _cell(value) -> str:
    return "" if value is None else f"{value:.12g}"


class RunWriter:
    """The files of one run (module docstring), fed by the engine: :meth:`observe` after every step or output time,
    :meth:`finish` at the end, :meth:`interrupted` after Ctrl-C."""

    rank = 0  # a run shared out among MPI ranks (dem.output.pieces): the summary and the plots are rank 0's

    def __init__(self, out_dir, scene, engine, resume_step: int | None = None):
        """Open the run's files in ``out_dir``.

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The output folder (created if missing).
        scene : dem.scene.parse.Scene
            The run's scene (its ``[output]`` table says when rows and snapshots are written).
        engine : object
            The run's engine: ``record()``, ``particle_fields()``, ``links()``, ``link_kind``, ``t_start`` and
            ``plots()``.
        resume_step : int, optional
            Go on with the files of a run resumed from the checkpoint at that step (the rows and snapshots
            written after it are dropped); None starts afresh.
        """
        self.out = pathlib.Path(out_dir)
        self.out.mkdir(parents=True, exist_ok=True)
        self.scene, self.engine = scene, engine
        self.kinds = ("particles", engine.link_kind)
        self.by_time = scene.motion is not None  # particles that move: rows and snapshots by simulated time
        o, s = scene.output, scene.solver
        if not self.by_time and o.vtu and o.vtu_every and s.mode == "transient" and s.dt != "auto":
            snapshots = math.ceil(s.t_end / s.dt * (1 - 1e-12)) // o.vtu_every
            if snapshots > MAX_SNAPSHOTS:
                raise ValueError(f"[output] vtu_every = {o.vtu_every}: {snapshots} snapshots of t_end / dt = "
                                 f"{s.t_end / s.dt:.6g} steps exceed the limit of {MAX_SNAPSHOTS}; valid: vtu_every >= "
                                 f"{math.ceil(s.t_end / s.dt / MAX_SNAPSHOTS)}, 0 (first and last) or vtu = false")
        self.csv = None
        self.columns: list[str] = []
        self.snapshots: list[tuple[float, int]] = []
        self.last = None  # the last row observed
        self.next_vtu = engine.t_start
        self.errors: dict = {}
        if resume_step is not None:
            path = self.out / "timeseries.csv"
            with path.open() as fh:
                self.columns = fh.readline().strip().split(",")
            self.csv = resumed_csv(path, lambda row: int(row["step"]) <= resume_step)
            self.snapshots = resumed_snapshots(self.out, self.kinds, resume_step)
            t_last = self._resumed_clock()
            if (self.out / "profiles.csv").exists():
                resumed_profiles(self.out / "profiles.csv", t_last)

    def _resumed_clock(self) -> float:
        """The time of the last snapshot kept on resuming; the next snapshot's time advanced past it, as the
        interrupted run advanced it (the same sums, the same snapshot times)."""
        t_last = max((t for t, _ in self.snapshots), default=self.engine.t)
        interval = getattr(self.scene.motion, "vtu_interval", 0.0)
        self.next_vtu = self.engine.t_start
        while interval > 0 and self.next_vtu <= t_last + 1e-12 * self.scene.solver.t_end:
            self.next_vtu += interval
        return t_last

    # ------------------------------------------------------------------------------------------------ rows
    def observe(self) -> None:
        """The engine has reached a step or an output time: a row, and a snapshot where one is due."""
        row = self.engine.record()
        self.last = row
        step, t = row["step"], row["t"]
        if self.by_time or step % self.scene.output.every == 0:
            self._row(row)
        if self._snapshot_due(step, t):
            self.snapshot()

    def _row(self, row: dict) -> None:
        if self.csv is None:
            self.columns = list(row)
            self.csv = (self.out / "timeseries.csv").open("w")
            self.csv.write(",".join(self.columns) + "\n")
        self.csv.write(",".join(_cell(row.get(k)) for k in self.columns) + "\n")
        self.csv.flush()

    def _snapshot_due(self, step: int, t: float) -> bool:
        if self.by_time:
            t_end = self.scene.solver.t_end
            m = self.scene.motion
            due = (m.vtu_interval > 0 and t >= self.next_vtu - 1e-12 * t_end) or t == self.engine.t_start \
                or t >= t_end * (1 - 1e-12)
            if due and m.vtu_interval > 0:
                while self.next_vtu <= t + 1e-12 * t_end:
                    self.next_vtu += m.vtu_interval
            return due
        o = self.scene.output
        every = o.vtu_every
        if every and len(self.snapshots) >= MAX_SNAPSHOTS:  # dt = "auto": the step count was not known up front
            every *= 2 ** (len(self.snapshots) // MAX_SNAPSHOTS)  # thin the snapshots, keep their number bounded
        return step == 0 or bool(every and step % every == 0)

    # ------------------------------------------------------------------------------------------- snapshots
    def snapshot(self) -> None:
        """The particles and their links now (and the engine's profiles), listed in the PVD collections at once: an
        interrupted run's collections hold all it wrote."""
        e = self.engine
        step, t = e.steps, e.t
        if self.snapshots and self.snapshots[-1][1] == step:
            return
        self._profile(t)
        if not (self.scene.output.vtu or self.scene.output.lammps_dump):
            self.snapshots.append((t, step))
            return
        x, particles = e.positions(), e.particle_fields()  # once for the VTU and the dump
        if self.scene.output.lammps_dump:
            self._dump(step, x, particles)
        if not self.scene.output.vtu:
            self.snapshots.append((t, step))
            return
        write_vtu(self.out / f"particles_{step:0{DIGITS}d}.vtu", meshio.Mesh(
            x, [("vertex", np.arange(len(x)).reshape(-1, 1))], point_data=particles))
        points, lines, fields = e.links()
        write_vtu(self.out / f"{e.link_kind}_{step:0{DIGITS}d}.vtu", meshio.Mesh(
            points, [("line", np.asarray(lines, dtype=np.int64).reshape(-1, 2))],
            cell_data={k: [v] for k, v in fields.items()}))
        self.snapshots.append((t, step))
        self._write_pvd()

    def _dump(self, step: int, x: np.ndarray, fields: dict) -> None:
        """The particles at positions ``x`` with their ``fields`` (the engine's) as a LAMMPS text dump,
        ``particles_STEP.dump`` (:func:`dem.output.lammps_dump.write_dump`): types from the materials (index + 1),
        the box the periodic one or the particles' extent."""
        from dem.output.lammps_dump import write_dump

        r = np.asarray(fields["radius"], dtype=float)
        box = self.scene.box
        if box is not None:
            lo, hi, periodic = box.origin, box.origin + box.lengths, tuple(box.periodic)
        else:
            lo, hi, periodic = (x - r[:, None]).min(axis=0), (x + r[:, None]).max(axis=0), (False, False, False)
        write_dump(self.out / f"particles_{step:0{DIGITS}d}.dump", step, fields["id"],
                   np.asarray(self.scene.particles.material) + 1, r, x, lo, hi, periodic, fields.get("velocity"),
                   fields.get("force"), self.engine.temperatures())

    def _profile(self, t: float) -> None:
        """The engine's profiles now, a block of rows of ``profiles.csv``."""
        profile = self.engine.profile()
        if profile is not None:
            new = not (self.out / "profiles.csv").exists()
            with (self.out / "profiles.csv").open("a") as fh:
                if new:
                    fh.write("t,distance,solid_fraction,neck_over_radius\n")
                for d, phi, a in zip(profile["distance"], profile["solid_fraction"], profile["neck_over_radius"]):
                    fh.write(f"{_cell(t)},{_cell(d)},{_cell(phi)},{_cell(a)}\n")

    def _write_pvd(self) -> None:
        for kind in self.kinds:
            write_pvd(self.out / f"{kind}.pvd", [(tt, f"{kind}_{s:0{DIGITS}d}.vtu") for tt, s in self.snapshots])

    # --------------------------------------------------------------------------------------------- the end
    def _guarded(self, what: str, action):
        """Run one output step; its failure is recorded (``output_errors``), not raised: the others still happen."""
        try:
            return action()
        except (OSError, ValueError, RuntimeError, ArithmeticError) as exc:
            self.errors[what] = " ".join(str(exc).split())
            return None

    def finish(self, summary: dict, plots: bool = True) -> dict:
        """Close the run's files: the last row and snapshot where they are not written yet, ``summary.json``, then
        the plots; returns the summary as written.

        Parameters
        ----------
        summary : dict
            The run's summary (JSON-ready).
        plots : bool
            Draw the engine's plots after writing the summary.
        """
        if self.last is not None and not self.by_time and self.last["step"] % self.scene.output.every:
            self._guarded("timeseries.csv", lambda: self._row(self.last))
        if self.csv is not None:
            self.csv.close()
        if self.last is not None or self.by_time:
            self._guarded("snapshot", self.snapshot)
        if self.snapshots:
            self._guarded("pvd", self._write_pvd)
        if self.rank != 0:
            return summary
        write_summary(self.out / "summary.json", self._with_errors(summary))  # first: a plot may read it
        if plots:
            written = self._guarded("plots", lambda: self.engine.plots(self.out, summary))
            if written is not None:
                summary["plots"] = written
            write_summary(self.out / "summary.json", self._with_errors(summary))
        return summary

    def _with_errors(self, summary: dict) -> dict:
        if self.errors:
            summary["output_errors"] = dict(self.errors)
        return summary

    def interrupted(self, summary: dict) -> None:
        """Close the files of a run stopped by Ctrl-C: ``summary.json`` marked ``"interrupted": true`` with the state
        the last row reached and where a resume starts (the last checkpoint); half-written files and the files of an
        unfinished snapshot are deleted and every PVD collection lists exactly the snapshots on disk.

        Parameters
        ----------
        summary : dict
            The run's summary so far (JSON-ready); completed here with the time and steps reached and ``resume_from``.
        """
        if self.last is not None:
            summary.update(t=self.last["t"], steps=self.last["step"])
        summary["resume_from"] = checkpoint_reached(self.out)
        if self.csv is not None:
            self.csv.close()
        steps = {step for _, step in self.snapshots}
        for f in self.out.glob("*.vtu.part"):
            f.unlink()
        for kind in self.kinds:
            for step, f in snapshot_files(self.out, kind):
                if step not in steps:
                    f.unlink()
        if self.scene.output.vtu:
            self._write_pvd()
        write_summary(self.out / "summary.json", self._with_errors(summary))
