"""One DEM run: build the physics a scene names, run it, write the outputs, return the summary."""

from __future__ import annotations

import math
import pathlib
import sys
import time
from dataclasses import dataclass

import numpy as np

from dem import physics
from dem.io import RunWriter
from dem.scene import Scene

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
    """A tqdm bar on stderr that appears only after 2 s: simulated time (transient) or the build/solve stages."""
    if not enabled:
        return None, None
    from tqdm import tqdm

    if scene.solver.mode != "transient":
        bar = tqdm(total=2, desc=f"dem {scene.name}: bonds, solve", file=sys.stderr, delay=2.0)
        return bar, (lambda stage: bar.update(1))
    bar = tqdm(total=scene.solver.t_end, unit="s", desc=f"dem {scene.name}", file=sys.stderr, delay=2.0,
               bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s simulated [{elapsed}<{remaining}]")
    return bar, (lambda t: bar.update(t - bar.n))


def effective_conductivity(scene: Scene, boundary: dict) -> float | None:
    """``k_eff = Q L / (A (T_hot - T_cold))`` of a generated specimen with hot and cold ends (steady)."""
    sp = scene.specimen
    if sp is None or sp.hot == sp.cold:
        return None
    if sp.hot_particles:
        q = -sum(boundary.get("particles", {}).get(str(k), 0.0) for k in sp.hot_particles)
    else:
        q = -boundary["walls"]["hot"]
    return q * sp.length / (sp.area * (sp.hot - sp.cold))


def run(scene: Scene, out=None, progress: bool = False) -> RunResult:
    """Run ``scene``; with ``out`` write summary.json, timeseries.csv and VTU/PVD snapshots into that folder."""
    if scene.motion is not None:
        return run_moving(scene, out, progress)
    start = time.perf_counter()
    bar, report = _progress_bar(scene, progress)
    try:
        models = physics.build(scene)
        thermal = next(m for m in models if m.name == "thermal")
        writer = RunWriter(out, scene, thermal) if out is not None else None
        if scene.solver.mode != "transient" and report is not None:
            report("bonds")
        details = thermal.run(writer, report if scene.solver.mode == "transient" else None)
        if scene.solver.mode != "transient" and report is not None:
            report("solve")
    finally:
        if bar is not None:
            bar.close()
    p = scene.particles
    summary = {"scene": scene.name, "mode": scene.solver.mode, "t": details.pop("t"), "steps": details.pop("steps"),
               "particles": p.n, "bonds": thermal.bonds.n_pairs, "energy_error": details.pop("energy_error"),
               "seconds": None, "physics": [m.name for m in models], "static": True}
    if p.n <= T_LIST_MAX:
        summary["T"] = thermal.T.tolist()
    if "boundary_heat_flow" in details:
        summary["boundary_heat_flow"] = details.pop("boundary_heat_flow")
        k_eff = effective_conductivity(scene, summary["boundary_heat_flow"])
        if k_eff is not None:
            summary["effective_conductivity"] = k_eff
    summary.update(T_mean=float(thermal.T.mean()), T_min=float(thermal.T.min()), T_max=float(thermal.T.max()))
    summary.update(details)
    summary = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in summary.items()}
    summary["seconds"] = time.perf_counter() - start
    if writer is not None:
        writer.finish(summary)
    return RunResult(summary, thermal.T, models)


def run_moving(scene: Scene, out=None, progress: bool = False) -> RunResult:
    """A scene with moving particles (``"mechanical"`` physics): the engine of :mod:`dem.engine`, or with
    ``[contact] law = "zohdi"`` the staggered scheme of :mod:`dem.zohdi.simulation`."""
    from dem.io import MotionWriter

    if scene.contact.law == "zohdi":
        from dem.zohdi.simulation import ZohdiSimulation as Simulation
    else:
        from dem.engine import Simulation

    start = time.perf_counter()
    sim = Simulation(scene)
    writer = MotionWriter(out, scene) if out is not None else None
    if writer is not None and scene.motion.frames:
        from dem.frames import WithFrames

        writer = WithFrames(writer, scene, out)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=scene.solver.t_end, unit="s", desc=f"dem {scene.name}", file=sys.stderr, delay=2.0,
                   bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s simulated [{elapsed}<{remaining}]")
    try:
        details = sim.run(writer, (lambda t: bar.update(min(t, bar.total) - bar.n)) if bar is not None else None)
    except ValueError as exc:  # the run stopped (a particle through a wall, a neck beyond its model): keep what exists
        if writer is not None:
            writer.finish({"scene": scene.name, "stopped": " ".join(str(exc).split()), **sim.summary()})
        raise
    finally:
        if bar is not None:
            bar.close()
    summary = {"scene": scene.name, "mode": "transient", "physics": list(scene.physics), "static": False, **details}
    if out is not None and scene.contact.law == "luding":
        from dem import state_file

        summary["state"] = state_file.save(sim, pathlib.Path(out) / "state.npz").name
    if scene.particles.n <= T_LIST_MAX:
        summary["T"] = sim.mechanics.state.T.tolist()
    summary = {k: (None if isinstance(v, float) and not math.isfinite(v) else v) for k, v in summary.items()}
    summary["seconds"] = time.perf_counter() - start
    if writer is not None:
        writer.finish(summary)
    return RunResult(summary, sim.mechanics.state.T.copy(), sim.models)
