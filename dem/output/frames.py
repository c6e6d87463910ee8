"""Frames of a moving-particle run rendered as pictures (pyvista, off-screen), in the style of Zohdi 2014, Fig. 8:
the spheres coloured by temperature, the two walls the powder is pressed between drawn as plates, the side walls
left out so that the powder can be seen.

:class:`FrameWriter` is an observer of a run (``[output] frames = N``): it renders ``frames/frame_KK.png`` at ``N``
evenly spaced times from start to end (at the first output time at or after each). pyvista (and VTK) are imported
only here, only when frames are asked for.
"""

from __future__ import annotations

import pathlib

import numpy as np

WINDOW = (900, 700)


def _quiet_pyvista():
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # no "bad X server connection" on a headless machine
    pv.OFF_SCREEN = True
    return pv


def render(path, x, radius, T, plates, up: int, clim, title: str, sphere_resolution: int = 12) -> None:
    """Write one PNG: spheres at ``x`` of ``radius`` coloured by ``T`` (colour range ``clim``), the ``plates``
    (``(centre, normal, (size_1, size_2))``) in grey, axis ``up`` vertical, ``title`` at the top."""
    pv = _quiet_pyvista()
    points = pv.PolyData(np.asarray(x, dtype=float))
    points["radius"] = np.asarray(radius, dtype=float)
    points["temperature (K)"] = np.asarray(T, dtype=float)
    spheres = points.glyph(scale="radius", orient=False, factor=1.0,
                           geom=pv.Sphere(radius=1.0, theta_resolution=sphere_resolution,
                                          phi_resolution=sphere_resolution))
    plotter = pv.Plotter(off_screen=True, window_size=WINDOW)
    plotter.set_background("white")
    plotter.add_mesh(spheres, scalars="temperature (K)", cmap="inferno", clim=clim, smooth_shading=True,
                     scalar_bar_args={"title": "temperature (K)", "color": "black", "vertical": False,
                                      "position_x": 0.2, "position_y": 0.04, "width": 0.6, "fmt": "%.0f"})
    for centre, normal, (a, b) in plates:
        plotter.add_mesh(pv.Plane(center=centre, direction=normal, i_size=a, j_size=b), color="grey", opacity=0.5)
    plotter.add_text(title, font_size=12, color="black")
    up_vector = np.zeros(3)
    up_vector[up] = 1.0
    side = (up + 2) % 3  # look along the third axis: the side view of Fig. 8
    centre = np.mean(np.asarray(x, dtype=float), axis=0)
    view = np.zeros(3)
    view[side] = 1.0
    view[(up + 1) % 3] = 0.6
    extent = float(np.ptp(np.asarray(x, dtype=float), axis=0).max()) + 4.0 * float(np.max(radius))
    plotter.camera.focal_point = centre
    plotter.camera.position = centre + 2.2 * extent * view / np.linalg.norm(view)
    plotter.camera.up = up_vector
    plotter.screenshot(str(path))
    plotter.close()


class FrameWriter:
    """Observer of a run: ``count`` frames at evenly spaced times (module docstring)."""

    def __init__(self, out_dir, count: int, t_end: float, up: int, T_low: float, T_high: float):
        """``up``: the vertical axis; the colours run from ``T_low`` to ``T_high`` or, where hotter, the 98th
        percentile of the particles' temperatures of the frame."""
        self.dir = pathlib.Path(out_dir) / "frames"
        self.dir.mkdir(parents=True, exist_ok=True)
        self.times = list(np.linspace(0.0, t_end, count)) if count > 1 else [t_end]
        self.up, self.T_low, self.T_high = up, T_low, T_high
        self.written: list[str] = []

    def __call__(self, sim) -> None:
        t = sim.t
        if not self.times or t < self.times[0] - 1e-12 * max(self.times[-1], 1.0):
            return
        while self.times and self.times[0] <= t + 1e-12 * max(self.times[-1], 1.0):
            self.times.pop(0)
        s = sim.mechanics.state
        row = sim.record()
        fraction = row.get("volume_fraction")
        title = f"t = {t:.3f} s" + (f"   volume fraction {fraction:.3f}" if fraction is not None else "")
        path = self.dir / f"frame_{len(self.written):02d}.png"
        clim = (self.T_low, max(self.T_high, float(np.percentile(s.T, 98))))
        render(path, s.x, s.radius, s.T, sim.plates(), self.up, clim, title)
        self.written.append(path.name)


class WithFrames:
    """A run's writer (:class:`dem.output.writer.RunWriter`) that also renders ``[output] frames`` pictures, the
    colours from the coldest to the hottest prescribed temperature (initial, walls) or hotter."""

    def __init__(self, writer, scene, out_dir):
        m = scene.motion
        temperatures = [float(np.min(scene.particles.temperature))]
        temperatures += [w.temperature for w in m.walls if w.temperature is not None]
        self.writer = writer
        self.frames = FrameWriter(out_dir, m.frames, scene.solver.t_end, m.control or 0, min(temperatures),
                                  max(temperatures))

    @property
    def last(self):
        return self.writer.last

    def observe(self) -> None:
        self.writer.observe()
        self.frames(self.writer.engine)

    def finish(self, summary: dict, plots: bool = True) -> dict:
        summary["frames"] = self.frames.written
        return self.writer.finish(summary, plots)

    def interrupted(self, summary: dict) -> None:
        self.writer.interrupted({**summary, "frames": self.frames.written})
