"""A run's output folder: one run per folder, checkpoints while it runs, resumed where it stopped.

* A folder that already holds a run (``RUN_FILES``) is refused unless the run is resumed (``resume``: go on
  from its last checkpoint) or cleared first (``overwrite``: the run's own files are deleted, nothing else). So two
  runs never mix their rows and snapshots.
* While a transient run goes, :class:`Checkpointer` keeps the state between two steps (or intervals) and writes it
  to ``checkpoint.npz`` every ``[output] checkpoint_every`` seconds of wall time (default 5), at the end and after
  Ctrl-C, written aside and renamed, so a checkpoint on disk is always whole; an interrupted run resumes from the
  last completed step. It carries a digest of the scene: a checkpoint is resumed only by the scene that wrote it.
"""

from __future__ import annotations

import hashlib
import pathlib
import time

import numpy as np

CHECKPOINT = "checkpoint.npz"
RUN_FILES = ("summary.json", "timeseries.csv", "profiles.csv", CHECKPOINT, "state.npz", "*.pvd", "*.vtu", "*.pvtu",
             "*.png")


def scene_digest(scene) -> str:
    """A digest of everything that decides a run's result: the particles' arrays and every specification."""
    h = hashlib.sha1()
    p = scene.particles
    for arr in (p.position, p.radius, p.temperature, p.material, p.fixed, p.heat):
        h.update(np.ascontiguousarray(arr).tobytes())
    motion = scene.motion
    h.update(repr((p.materials, scene.walls, scene.conductance, scene.sources, scene.solver, scene.output,
                   scene.physics, scene.contact,
                   None if motion is None else {k: v for k, v in vars(motion).items() if k != "start"})).encode())
    if motion is not None and motion.start is not None:
        h.update(np.ascontiguousarray(motion.start["x"]).tobytes())
    return h.hexdigest()


def run_files(out: pathlib.Path) -> list[pathlib.Path]:
    return sorted({f for pattern in RUN_FILES for f in out.glob(pattern)})


def prepare(out, resume: bool = False, overwrite: bool = False) -> pathlib.Path:
    """The output folder, checked: refused when it holds a run and neither ``resume`` nor ``overwrite`` is given;
    with ``overwrite`` the old run's files are deleted first."""
    out = pathlib.Path(out)
    if resume and overwrite:
        raise ValueError("--resume and --overwrite: give one of them")
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out}: exists and is not a folder")
    found = run_files(out) if out.exists() else []
    if resume:
        if not (out / CHECKPOINT).exists():
            raise ValueError(f"--resume: {out} holds no checkpoint ({CHECKPOINT}) to go on from")
        return out
    if found and not overwrite:
        raise ValueError(f"--out {out}: holds a run already ({found[0].name}, ...); --resume goes on from its last "
                         f"checkpoint, --overwrite clears it first")
    for f in found:
        f.unlink()
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"--out {out}: cannot be created ({exc.strerror})") from None
    return out


def load(out, scene, kind: str) -> dict:
    """The checkpoint of the run in ``out`` as a dict of arrays, refused if another scene (or kind) wrote it."""
    path = pathlib.Path(out) / CHECKPOINT
    with np.load(path, allow_pickle=False) as f:
        data = {k: f[k] for k in f.files}
    if str(data.get("kind")) != kind or str(data.get("scene_digest")) != scene_digest(scene):
        raise ValueError(f"--resume: {path} was written by another scene (or another kind of run); resume it with "
                         f"the scene that started it, or use --overwrite")
    return data


class Checkpointer:
    """Keeps the checkpoint of the last completed step and writes it to ``out/checkpoint.npz`` once ``every`` seconds
    have passed since the last write, at the end (``final``) and after Ctrl-C (:meth:`last`): a run interrupted at any
    moment -- in its first seconds too -- resumes from the step it had completed."""

    def __init__(self, out, scene, kind: str, every: float):
        self.path = pathlib.Path(out) / CHECKPOINT
        self.header = {"kind": np.array(kind), "scene_digest": np.array(scene_digest(scene))}
        self.every = every
        self.written_at = time.monotonic()
        self.latest = None  # the arrays of the last completed step (copies: the run goes on changing its own)
        self.written = True

    def __call__(self, make, final: bool = False) -> None:
        """After a completed step: ``make()`` builds its checkpoint (an object with ``arrays()`` or a dict)."""
        state = make()
        arrays = state.arrays() if hasattr(state, "arrays") else state
        self.latest = {k: np.array(v, copy=True) for k, v in arrays.items()}
        self.written = False
        if final or time.monotonic() - self.written_at >= self.every:
            self._write()

    def last(self) -> None:
        """Write the checkpoint of the last completed step, unless it is on disk already."""
        if self.latest is not None and not self.written:
            self._write()

    def _write(self) -> None:
        tmp = self.path.with_name(self.path.name + ".part")
        with tmp.open("wb") as fh:
            np.savez(fh, **self.header, **self.latest)
        tmp.replace(self.path)
        self.written_at = time.monotonic()
        self.written = True
