"""One DEM run: build the physics a scene names, run it, write the outputs, return the summary."""

from __future__ import annotations

import math
import pathlib
import sys
import time
from dataclasses import dataclass

import numpy as np

from dem.engines import static as physics
from dem.output import folder as run_folder
from dem.output.writer import RunWriter
from dem.scene import Scene
from dem.network.heat import Checkpoint
from sinterheat.interrupt import where

T_LIST_MAX = 1000  # the summary lists the final temperatures for scenes up to this many particles


@dataclass
class RunResult:
    """``summary`` (JSON-ready), final temperatures ``T`` (input order) and the built submodels."""

    summary: dict
    T: np.ndarray
    models: list

    @property
    def thermal(self):
        return next(m for m in self.models if m.name == "thermal")


def _progress_bar(scene: Scene, enabled: bool):
    """A tqdm bar on stderr that appears only after 2 s: simulated time (transient) or the build/solve stages.

    The time left is estimated only where steps are of one size (fixed ``dt``, and moving particles): adaptive steps
    start small and grow by orders of magnitude, so a linear extrapolation of their early pace means nothing."""
    if not enabled:
        return None, None
    from tqdm import tqdm

    if scene.solver.mode != "transient":
        bar = tqdm(total=2, desc=f"dem {scene.name}: bonds, solve", file=sys.stderr, delay=2.0)
        return bar, (lambda stage: bar.update(1))
    uniform = scene.motion is not None or scene.solver.dt != "auto"
    tail = " [{elapsed}<{remaining}]" if uniform else " [{elapsed}]"
    bar = tqdm(total=scene.solver.t_end, unit="s", desc=f"dem {scene.name}", file=sys.stderr, delay=2.0,
               bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s simulated" + tail)
    return bar, (lambda t: bar.update(min(t, bar.total) - bar.n))


def _position(scene: Scene, out, progress: bool):
    """The run's position for the line an interrupt prints (:func:`sinterheat.interrupt.where`) -- only for a run
    that reports its progress (the CLI's): a run inside another command (a verification section) leaves that
    command's position alone."""
    if not progress:
        from sinterheat.interrupt import Where

        return Where()  # a throw-away position
    here = where()
    here.update(stage=f"dem run {scene.name}", out=str(out) if out is not None else None)
    return here


def effective_conductivity(scene: Scene, summary: dict) -> float | None:
    """``k_eff = Q L / (A dT)`` (steady): of a generated specimen between hot and cold ends, or along the one axis
    of a periodic box with a temperature drop per period (``Q`` the heat flow across the period)."""
    box, sp = scene.box, scene.specimen
    if box is not None and "periodic_heat_flow" in summary:
        axes = np.flatnonzero(box.drop)
        if len(axes) != 1:
            return None
        k = int(axes[0])
        return summary["periodic_heat_flow"][k] * box.lengths[k] / (box.cross_section(k) * box.drop[k])
    if sp is None or sp.hot == sp.cold or "boundary_heat_flow" not in summary:
        return None
    boundary = summary["boundary_heat_flow"]
    if sp.hot_particles:
        q = -sum(boundary.get("particles", {}).get(str(k), 0.0) for k in sp.hot_particles)
    else:
        q = -boundary["walls"]["hot"]
    return q * sp.length / (sp.area * (sp.hot - sp.cold))


def run(scene: Scene, out=None, progress: bool = False, resume: bool = False, overwrite: bool = False) -> RunResult:
    """Run ``scene``; with ``out`` write summary.json, timeseries.csv, VTU/PVD snapshots and plots into that folder
    (refused if it holds a run, unless ``resume``: go on from its last checkpoint, or ``overwrite``: clear it first;
    :mod:`dem.output.folder`). Ctrl-C leaves the folder usable: the rows and snapshots written so far, the last
    checkpoint, and ``summary.json`` marked ``"interrupted": true``. ``progress``: a bar on stderr, and the run's
    position in the line an interrupt prints."""
    if out is not None:
        out = run_folder.prepare(out, resume, overwrite)
    elif resume or overwrite:
        raise ValueError("--resume and --overwrite need --out (the folder of the run)")
    if scene.motion is not None:
        return run_moving(scene, out, progress, resume)
    start = time.perf_counter()
    here = _position(scene, out, progress)
    bar, report = _progress_bar(scene, progress)
    transient = scene.solver.mode == "transient"
    writer = None
    try:
        models = physics.build(scene)
        thermal = next(m for m in models if m.name == "thermal")
        checkpoint = restart = None
        if out is not None and transient:
            checkpoint = run_folder.Checkpointer(out, scene, "thermal", scene.output.checkpoint_every)
            if resume:
                restart = Checkpoint.from_arrays(run_folder.load(out, scene, "thermal"))
        if out is not None:
            writer = RunWriter(out, scene, thermal, resume_step=restart.steps if restart is not None else None)

        def observe(step, t, T_free, flows):
            here.update(step=step, t=t)
            if writer is not None:
                writer(step, t, T_free, flows)

        if not transient and report is not None:
            report("bonds")
        try:
            details = thermal.run(observe, report if transient else None, restart, checkpoint)
            if not transient and report is not None:
                report("solve")
        finally:
            if bar is not None:
                bar.close()
        summary = _thermal_summary(scene, models, thermal, details, restart)
        summary["seconds"] = time.perf_counter() - start
        if writer is not None:
            writer.finish(summary)
    except KeyboardInterrupt:  # also while the run's last files are written: the folder says it was interrupted
        if writer is not None:
            writer.interrupted({"scene": scene.name, "mode": scene.solver.mode, "interrupted": True,
                                "physics": list(scene.physics)})
        raise
    finally:
        if bar is not None:
            bar.close()
    return RunResult(summary, thermal.T, models)


def _thermal_summary(scene: Scene, models, thermal, details: dict, restart) -> dict:
    """The summary of a thermal run (static packing) from what its model returned."""
    p = scene.particles
    summary = {"scene": scene.name, "mode": scene.solver.mode, "t": details.pop("t"), "steps": details.pop("steps"),
               "particles": p.n, "bonds": thermal.bonds.n_pairs, "energy_error": details.pop("energy_error"),
               "seconds": None, "physics": [m.name for m in models], "static": True}
    if p.n <= T_LIST_MAX:
        summary["T"] = thermal.T.tolist()
    for key in ("boundary_heat_flow", "periodic_heat_flow"):
        if key in details:
            summary[key] = details.pop(key)
    k_eff = effective_conductivity(scene, summary)
    if k_eff is not None:
        summary["effective_conductivity"] = k_eff
    summary.update(T_mean=float(thermal.T.mean()), T_min=float(thermal.T.min()), T_max=float(thermal.T.max()))
    summary.update(details)
    if restart is not None:
        summary["resumed_from"] = {"t": restart.t, "steps": restart.steps}
    return {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in summary.items()}


def run_moving(scene: Scene, out=None, progress: bool = False, resume: bool = False) -> RunResult:
    """A scene with moving particles (``"mechanical"`` physics): the engine of :mod:`dem.engines.verlet.engine`, or with
    ``[contact] law = "zohdi"`` the staggered scheme of :mod:`dem.engines.staggered.engine` (``out`` prepared by
    :func:`run`)."""
    from dem.scene import state_file
    from dem.output.writer import MotionWriter

    zohdi = scene.contact.law == "zohdi"
    if zohdi:
        from dem.engines.staggered.engine import ZohdiSimulation as Simulation

        if resume:
            raise ValueError("--resume: runs of the zohdi contact law write no checkpoints; run again with --overwrite")
    else:
        from dem.engines.verlet.engine import Simulation

    start = time.perf_counter()
    here = _position(scene, out, progress)
    saved = state_file.normalised(run_folder.load(out, scene, "moving")) if resume else None
    sim = Simulation(scene) if zohdi else Simulation(scene, resume=saved)
    writer = MotionWriter(out, scene, resume_step=sim.mechanics.steps if resume else None) if out is not None \
        else None
    if writer is not None and scene.motion.frames:
        from dem.output.frames import WithFrames

        writer = WithFrames(writer, scene, out)
    checkpoint = run_folder.Checkpointer(out, scene, "moving", scene.output.checkpoint_every) \
        if out is not None and not zohdi else None
    bar, report = _progress_bar(scene, progress)
    try:
        try:
            details = sim.run(writer, report) if zohdi else sim.run(writer, report, checkpoint, here)
        finally:
            if bar is not None:
                bar.close()
        summary = {"scene": scene.name, "mode": "transient", "physics": list(scene.physics), "static": False,
                   **details}
        if resume:
            summary["resumed_from"] = {"t": float(saved["t"]), "steps": int(saved["steps"])}
        if out is not None and not zohdi:
            summary["state"] = state_file.save(sim, pathlib.Path(out) / "state.npz").name
        if scene.particles.n <= T_LIST_MAX:
            summary["T"] = sim.mechanics.state.T.tolist()
        summary = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in summary.items()}
        summary["seconds"] = time.perf_counter() - start
        if writer is not None:
            writer.finish(summary)
    except KeyboardInterrupt:  # also while the run's last files are written: the folder says it was interrupted
        if writer is not None:
            writer.interrupted({"scene": scene.name, "interrupted": True, **sim.summary()})
        raise
    except ValueError as exc:  # the run stopped (a particle through a wall, a neck beyond its model): keep what exists
        if writer is not None:
            writer.finish({"scene": scene.name, "stopped": " ".join(str(exc).split()), **sim.summary()})
        raise
    return RunResult(summary, sim.mechanics.state.T.copy(), sim.models)
