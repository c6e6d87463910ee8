"""One DEM run, whatever the engine: build the engine the scene names (:mod:`dem.engines`), run it, and own
everything around it -- the run folder, the progress bar, Ctrl-C, checkpoints and ``--resume``, the outputs (one
writer, :mod:`dem.output.writer`), ``state.npz`` and the summary.

Under MPI (:func:`dem.parallel.comm.launched`) the registry gives the engine that shares the sample out among the
ranks, and the run takes the same path: rank 0 prepares and holds the folder, shows the bar and writes the summary;
on several ranks (or with an engine whose ranks hold only their pieces of the sample) every rank writes its piece
of each snapshot (:class:`dem.output.pieces.PieceWriter`).
"""

from __future__ import annotations

import math
import pathlib
import sys
import time
from dataclasses import dataclass

import numpy as np

from dem.engines import engine_class
from dem.memory import announcing
from dem.parallel.comm import launched, maximum, on_root, world
from dem.output import folder as run_folder
from dem.output.writer import RunWriter, write_summary
from dem.scene import Scene
from dem.scene import state_file
from sinterheat.interrupt import Where, where

T_LIST_MAX = 1000  # the summary lists the final temperatures for scenes up to this many particles


@dataclass
class RunResult:
    """What :func:`run` returns.

    Parameters
    ----------
    summary : dict
        The run's summary (JSON-ready; what ``summary.json`` holds).
    T : numpy.ndarray
        Final particle temperatures, in the scene's temperature unit (``[scene] temperature_unit``), in input order;
        with an engine whose ranks hold only their pieces (``engine.pieces_only``), those of the particles this rank
        owns (``engine.owned``: their indices).
    engine : object
        The engine that ran (its ``name`` is the scene's engine).
    """

    summary: dict
    T: np.ndarray
    engine: object

    @property
    def thermal(self):
        """The thermal network (bonds, conductances) -- the static engine itself, or the moving engines' network."""
        return self.engine if self.engine.name == "static" else self.engine.thermal


def _progress_bar(scene: Scene, engine, enabled: bool):
    """A tqdm bar on stderr that appears only after 2 s: simulated time (transient) or the build/solve stages.

    The time left is estimated only where steps are of one size (fixed ``dt``, and moving particles): adaptive steps
    start small and grow by orders of magnitude, so a linear extrapolation of their early pace means nothing."""
    if not enabled:
        return None
    from tqdm import tqdm

    if scene.solver.mode != "transient":
        return tqdm(total=1, desc=f"dem {scene.name}: bonds, solve", file=sys.stderr, delay=2.0)
    uniform = scene.motion is not None or scene.solver.dt != "auto"
    tail = " [{elapsed}<{remaining}]" if uniform else " [{elapsed}]"
    return tqdm(total=scene.solver.t_end - engine.t_start, unit="s", desc=f"dem {scene.name}", file=sys.stderr,
                delay=2.0, bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s simulated" + tail)


def _announce(scene: Scene, enabled: bool) -> None:
    """A run of many particles says on stderr what it will take (:func:`dem.memory.estimate`), once its up-front
    checks have passed; only where it reports its progress (the CLI's)."""
    from dem.memory import estimate

    spec = scene.conductance
    line = estimate(scene.particle_count, spec.neck, spec.nodes, scene.motion is not None) if enabled else None
    if line is not None:
        _say(line)


def _say(line: str) -> None:
    """One line of what the run will take, on stderr (:func:`dem.memory.announce` while the engine is built)."""
    print(f"python -m dem run: {line}", file=sys.stderr, flush=True)


def _position(scene: Scene, out, progress: bool) -> Where:
    """The run's position for the line an interrupt prints (:func:`sinterheat.interrupt.where`) -- only for a run
    that reports its progress (the CLI's): a run inside another command (a verification section) leaves that
    command's position alone."""
    if not progress:
        return Where()  # a throw-away position
    here = where()
    here.update(stage=f"dem run {scene.name}", out=str(out) if out is not None else None)
    return here


def _finite(summary: dict) -> dict:
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in summary.items()}


def run(scene: Scene, out=None, progress: bool = False, resume: bool = False, overwrite: bool = False) -> RunResult:
    """Run ``scene``; with ``out`` write summary.json, timeseries.csv, VTU/PVD snapshots, state.npz and plots into
    that folder (refused if it holds a run, unless ``resume``: go on from its last checkpoint, or ``overwrite``: clear
    it first; :mod:`dem.output.folder`). Ctrl-C leaves the folder usable and resumable: the rows and snapshots written
    so far, the checkpoint of the last completed step, and ``summary.json`` marked ``"interrupted": true``.
    ``progress``: a bar on stderr, and the run's position in the line an interrupt prints.

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene (:func:`dem.scene.parse.load_scene` reads one).
    out : str or pathlib.Path, optional
        The output folder; None writes nothing.
    progress : bool
        Draw a progress bar on stderr.
    resume : bool
        Go on from the last checkpoint of the run in ``out``.
    overwrite : bool
        Clear the run in ``out`` first.
    """
    if out is None and (resume or overwrite):
        raise ValueError("--resume and --overwrite need --out (the folder of the run)")
    ranks = launched()  # under MPI the scene's engine shares its sample out among the ranks (dem.engines)
    cls = engine_class(scene.engine, ranks)
    cls.refuse(scene, resume)  # before MPI or the folder is touched: a refused run costs nothing
    comm = world() if ranks else None
    root = comm is None or comm.Get_rank() == 0
    if out is not None:
        out, resume = on_root(comm, lambda: run_folder.prepare(out, resume, overwrite))
    try:
        return _run_held(scene, out, progress, resume, comm, cls, root)
    finally:  # the folder is free again however the run ended
        if out is not None and root:
            run_folder.unlock(out)


def _run_held(scene: Scene, out, progress: bool, resume: bool, comm, cls, root: bool) -> RunResult:
    """:func:`run` once its folder (if any) is prepared and held."""
    start = time.perf_counter()
    here = _position(scene, out, progress and root)
    restart = run_folder.load(out, scene, scene.engine) if resume else None
    try:
        with announcing(_say if progress and root else None):  # an estimate of what building it takes, where large
            engine = cls(scene, restart)  # the memory and the work checked and refused up front
    except KeyboardInterrupt:  # nothing written yet: a --resume starts the run again (run_folder.interrupted_at_start)
        if out is not None and root and restart is None:
            write_summary(out / "summary.json", {"scene": scene.name, "mode": scene.solver.mode, "interrupted": True,
                                                 "physics": list(scene.physics), "resume_from": None})
        raise
    _announce(scene, progress and root)
    writer = None
    resume_step = engine.steps if resume else None
    if out is not None and comm is not None and (comm.Get_size() > 1 or engine.pieces_only):  # a piece per rank
        from dem.output.pieces import PieceWriter

        writer = PieceWriter(out, scene, engine, comm.Get_rank(), comm.Get_size(), resume_step)
    elif out is not None and root:
        writer = RunWriter(out, scene, engine, resume_step=resume_step)
        if scene.motion is not None and scene.motion.staggered and scene.motion.staggered.frames:
            from dem.output.frames import WithFrames

            writer = WithFrames(writer, scene, out)
    checkpointer = run_folder.Checkpointer(out, scene, scene.engine, scene.output.checkpoint_every) \
        if writer is not None and root and (scene.solver.mode == "transient") else None
    bar = _progress_bar(scene, engine, progress and root)

    def advanced(t):
        if writer is None:  # with a folder the position is that of its last row (observed below)
            here.update(step=engine.steps, t=t)
        if bar is not None:
            bar.update(min(t - engine.t_start, bar.total) - bar.n)

    def observed():
        writer.observe()
        here.update(step=writer.last["step"], t=writer.last["t"])

    try:
        _advance(engine, scene, bar, observed if writer is not None else (_nothing if out is not None else None),
                 advanced, checkpointer)
        summary = _summary(scene, engine, restart)
        seconds = time.perf_counter() - start
        summary["seconds"] = seconds if comm is None else maximum(comm, seconds)
        if writer is not None and not engine.pieces_only:  # no process holds a piece-only sample's state
            summary["state"] = "state.npz"
            writer.finish(_with_state(summary, engine, out) if root else summary)
        elif writer is not None:
            writer.finish(summary)
    except KeyboardInterrupt:  # also while the run's last files are written: the folder says it was interrupted
        if writer is not None and root:
            if checkpointer is not None:
                checkpointer.last()  # the last completed step, to resume from whatever the periodic ones were
            writer.interrupted({"scene": scene.name, "mode": scene.solver.mode, "interrupted": True,
                                "physics": list(scene.physics), **_safe_summary(engine)})
        raise
    except ValueError as exc:  # the run stopped (a particle through a wall, a neck beyond its model): keep what exists
        if writer is not None:
            writer.finish({"scene": scene.name, "stopped": " ".join(str(exc).split()), **_safe_summary(engine)},
                          plots=False)
        raise
    return RunResult(summary, engine.temperatures(), engine)


def _advance(engine, scene: Scene, bar, observe, advanced, checkpointer) -> None:
    """``engine.run``, ``advanced(t)`` told the simulated time of a transient run; the bar closed however it ends (a
    steady run's bar filled first)."""
    transient = scene.solver.mode == "transient"
    try:
        engine.run(observe, advanced if transient else None, checkpointer)
    finally:
        if bar is not None:
            if not transient:
                bar.update(1)
            bar.close()


def _nothing():
    """The observer of a rank that writes nothing (rank 0 writes the run's folder)."""


def _summary(scene: Scene, engine, restart) -> dict:
    """The summary: the scene, the engine's findings, where the run resumed from, the final temperatures."""
    summary = {"scene": scene.name, "physics": list(scene.physics), "engine": engine.name, **engine.summary()}
    if restart is not None:
        summary["resumed_from"] = {"t": float(restart["t"]), "steps": int(restart["steps"])}
    if scene.start is not None:
        summary["started_from"] = {"t": scene.start["t"], "steps": scene.start["steps"]}
    T = _listed_temperatures(scene, engine)
    if T is not None:
        summary["T"] = T.tolist()
    return _finite(summary)


def _listed_temperatures(scene: Scene, engine):
    """The final temperatures the summary lists (up to ``T_LIST_MAX`` particles), or None: those of the whole
    sample, gathered from the ranks where each holds its piece (``engine.pieces_only``)."""
    if engine.pieces_only:
        return engine.gathered_temperatures() if scene.particle_count <= T_LIST_MAX else None
    T = engine.temperatures()
    return T if len(T) <= T_LIST_MAX else None


def _safe_summary(engine) -> dict:
    """What an engine can say of itself after an interrupt or a stop (its summary, or nothing if even that fails);
    nothing from an engine whose summary is a reduction over ranks (``pieces_only``), which a rank interrupted alone
    would wait for."""
    if engine.pieces_only:
        return {}
    try:
        return _finite(engine.summary())
    except (ValueError, ArithmeticError, IndexError, KeyError):
        return {}


def _with_state(summary: dict, engine, out) -> dict:
    """``state.npz`` written beside the summary; a failure to write it is named in the summary, not raised."""
    try:
        state_file.save(engine.state(), pathlib.Path(out) / "state.npz")
    except OSError as exc:
        summary.pop("state", None)
        summary.setdefault("output_errors", {})["state.npz"] = " ".join(str(exc).split())
    return summary

