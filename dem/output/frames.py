"""Frames of a moving-particle run rendered as pictures (pyvista, off-screen), in the style of Zohdi 2014, Fig. 8:
the spheres coloured by temperature, the two walls the powder is pressed between drawn as plates, the side walls
left out so that the powder can be seen.

:class:`FrameWriter` is an observer of a run (``[output] frames = N``): it renders ``frames/frame_KK.png`` at ``N``
evenly spaced times from start to end (at the first output time at or after each), all in one colour range: the
particles of each frame are saved when it is taken (``frame_KK.npz``) and drawn at the end of the run, also of an
interrupted one. pyvista (and VTK) are imported only here, only when frames are asked for.
"""

from __future__ import annotations

import pathlib

import numpy as np

from dem.output.atomic import read_npz, write_aside

WINDOW = (900, 700)


def _quiet_pyvista():
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # no "bad X server connection" on a headless machine
    pv.OFF_SCREEN = True
    return pv


def render(path, x, radius, T, plates, up: int, clim, title: str, unit: str = "K", sphere_resolution: int = 12) -> None:
    """Write one PNG: spheres at ``x`` of ``radius`` coloured by ``T`` (colour range ``clim``, temperatures in
    ``unit``: "K" or "C"), the ``plates`` (``(centre, normal, (size_1, size_2))``) in grey, axis ``up`` vertical,
    ``title`` at the top, clear of the picture's edges.

    Parameters
    ----------
    path : str or pathlib.Path
        The PNG file to write.
    x : array_like
        (N, 3) particle centres (m).
    radius : array_like
        (N,) radii (m).
    T : array_like
        (N,) temperatures (in ``unit``).
    plates : sequence of tuple
        The walls to draw, each ``(centre (m), normal, (size_1, size_2) (m))``.
    up : int
        The axis drawn vertical: 0, 1 or 2.
    clim : tuple of float
        The colour range (in ``unit``).
    title : str
        The text at the top.
    unit : str
        The temperatures' unit, ``"K"`` or ``"C"``.
    sphere_resolution : int
        Facets around each sphere.
    """
    from dem.output.plots import TEMPERATURE_UNITS

    pv = _quiet_pyvista()
    points = pv.PolyData(np.asarray(x, dtype=float))
    points["radius"] = np.asarray(radius, dtype=float)
    label = f"temperature ({TEMPERATURE_UNITS[unit]})"
    points[label] = np.asarray(T, dtype=float)
    spheres = points.glyph(scale="radius", orient=False, factor=1.0,
                           geom=pv.Sphere(radius=1.0, theta_resolution=sphere_resolution,
                                          phi_resolution=sphere_resolution))
    plotter = pv.Plotter(off_screen=True, window_size=WINDOW)
    plotter.set_background("white")
    plotter.add_mesh(spheres, scalars=label, cmap="inferno", clim=clim, smooth_shading=True,
                     scalar_bar_args={"title": label, "color": "black", "vertical": False,
                                      "position_x": 0.2, "position_y": 0.04, "width": 0.6, "fmt": "%.0f"})
    for centre, normal, (a, b) in plates:
        plotter.add_mesh(pv.Plane(center=centre, direction=normal, i_size=a, j_size=b), color="grey", opacity=0.5)
    plotter.add_text(title, position=(16, WINDOW[1] - 40), font_size=12, color="black")  # pixels from lower left
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
    """Observer of a run: ``count`` frames at evenly spaced times (module docstring). Each frame's particles are
    saved as it is taken (``frames/frame_KK.npz``: a resumed run keeps those taken before); :meth:`render` draws them
    all with one colour range for the whole run, from ``T_low`` to the hottest of ``T_high`` and every frame's
    particles, so that colours compare across frames."""

    def __init__(self, out_dir, count: int, t_end: float, up: int, T_low: float, T_high: float, unit: str = "K"):
        """``up``: the vertical axis; ``unit``: the temperatures' ("K" or "C").

        Parameters
        ----------
        out_dir : str or pathlib.Path
            The run folder (frames go to its ``frames/``).
        count : int
            Number of frames, evenly spaced from 0 to ``t_end``.
        t_end : float
            The run's end (s).
        up : int
            The axis drawn vertical: 0, 1 or 2.
        T_low : float
            The bottom of the colour range (in ``unit``).
        T_high : float
            The top of the colour range at least (in ``unit``).
        unit : str
            ``"K"`` or ``"C"``.
        """
        self.dir = pathlib.Path(out_dir) / "frames"
        self.dir.mkdir(parents=True, exist_ok=True)
        self.times = list(np.linspace(0.0, t_end, count)) if count > 1 else [t_end]
        self.up, self.T_low, self.T_high, self.unit = up, T_low, T_high, unit
        self.next = 0  # the next frame to take: past those a run before this one (resumed) took
        while self.next < len(self.times) and self._data(self.next).exists():
            self.next += 1
        self.written: list[str] = []

    def _data(self, k: int) -> pathlib.Path:
        return self.dir / f"frame_{k:02d}.npz"

    def __call__(self, sim) -> None:
        t, tol = sim.t, 1e-12 * max(self.times[-1], 1.0)
        if self.next >= len(self.times) or t < self.times[self.next] - tol:
            return
        while self.next + 1 < len(self.times) and self.times[self.next + 1] <= t + tol:
            self.next += 1  # several frame times passed since the last output: one frame, of the latest
        s = sim.mechanics.state
        fraction = sim.record().get("volume_fraction")
        title = f"t = {t:.3f} s" + (f",  volume fraction {fraction:.3f}" if fraction is not None else "")
        plates = sim.plates()
        arrays = dict(x=s.x, radius=s.radius, T=s.T, title=np.array(title),
                      plates=np.array([np.concatenate([c, n, size]) for c, n, size in plates]).reshape(-1, 8))
        write_aside(self._data(self.next), lambda fh: np.savez(fh, **arrays), "wb")  # whole, for a resumed run
        self.next += 1

    def render(self) -> list[str]:
        """Draw every saved frame as ``frame_KK.png`` with one colour range (class docstring); returns the names."""
        frames = [(k, read_npz(self._data(k), "frame")) for k in range(len(self.times)) if self._data(k).exists()]
        hottest = max((float(np.max(f["T"])) for _, f in frames), default=self.T_high)
        clim = (self.T_low, max(self.T_high, hottest))
        self.written = []
        for k, f in frames:
            plates = [(p[0:3], p[3:6], (p[6], p[7])) for p in f["plates"]]
            render(self.dir / f"frame_{k:02d}.png", f["x"], f["radius"], f["T"], plates, self.up, clim,
                   str(f["title"]), self.unit)
            self.written.append(f"frame_{k:02d}.png")
        return self.written


class WithFrames:
    """A run's writer (:class:`dem.output.writer.RunWriter`) that also renders ``[output] frames`` pictures, the
    colours from the coldest prescribed temperature (initial, walls) to the hottest prescribed or reached.

    Parameters
    ----------
    writer : dem.output.writer.RunWriter
        The run's writer.
    scene : dem.scene.parse.Scene
        The scene (its ``[output] frames``, walls and temperatures).
    out_dir : str or pathlib.Path
        The run folder.
    """

    def __init__(self, writer, scene, out_dir):
        m = scene.motion
        temperatures = [float(np.min(scene.particles.temperature))]
        temperatures += [w.temperature for w in m.walls if w.temperature is not None]
        self.writer = writer
        self.frames = FrameWriter(out_dir, m.staggered.frames, scene.solver.t_end, m.staggered.control or 0, min(temperatures),
                                  max(temperatures), scene.temperature_unit)

    @property
    def last(self):
        """The last row the writer observed."""
        return self.writer.last

    def observe(self) -> None:
        """Observe the row (:meth:`dem.output.writer.RunWriter.observe`), then draw the frames due."""
        self.writer.observe()
        self.frames(self.writer.engine)

    def finish(self, summary: dict, plots: bool = True) -> dict:
        """Render the frames, then close the run's files (:meth:`dem.output.writer.RunWriter.finish`).

        Parameters
        ----------
        summary : dict
            The run's summary; gets ``frames``, the files rendered.
        plots : bool
            Whether to draw the run's plots.

        Returns
        -------
        dict
            The summary as written.
        """
        summary["frames"] = self.frames.render()
        return self.writer.finish(summary, plots)

    def interrupted(self, summary: dict) -> None:
        """Render the frames taken, then close the files of a stopped run
        (:meth:`dem.output.writer.RunWriter.interrupted`).

        Parameters
        ----------
        summary : dict
            The run's summary so far.
        """
        self.writer.interrupted({**summary, "frames": self.frames.render()})
