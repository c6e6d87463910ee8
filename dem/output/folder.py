"""A run's output folder: one run per folder, checkpoints while it runs, resumed where it stopped.

* A folder that already holds a run (``RUN_FILES``) is refused unless the run is resumed (``resume``: go on
  from its last checkpoint) or cleared first (``overwrite``: the run's own files are deleted, nothing else). So two
  runs never mix their rows and snapshots.
* A run holds its folder while it writes it: ``run.lock`` names its process (pid and host), taken before any file
  is touched and removed when the run ends however it ends. A second run into the folder (``--resume`` and
  ``--overwrite`` too) is refused naming the holder; a lock whose process is gone (a run killed outright) is stale
  and taken over.
* ``--resume`` of a finished run (a ``summary.json`` not marked ``interrupted`` or ``stopped``) is refused: there
  is nothing to go on with, and the folder is left as it is.
* ``--resume`` of a run interrupted before it completed a step (a ``summary.json`` marked ``interrupted`` with no
  checkpoint to go on from, :func:`interrupted_at_start`: a batch scheduler's SIGTERM while the run still built its
  engine) starts that run again from its beginning, its files cleared: it ends where the uninterrupted run ends.
* While a transient run goes, :class:`Checkpointer` keeps the state between two steps (or intervals) and writes it
  to ``checkpoint.npz`` every ``[output] checkpoint_every`` seconds of wall time (default 5), at the end and after
  Ctrl-C, written aside and renamed, so a checkpoint on disk is always whole; an interrupted run resumes from the
  last completed step. It carries a digest of the scene: a checkpoint is resumed only by the scene that wrote it.
"""

from __future__ import annotations

import hashlib
import json
import os
import pathlib
import socket
import time

import numpy as np

from dem.output.atomic import read_npz, write_aside

CHECKPOINT = "checkpoint.npz"
LOCK = "run.lock"  # the run writing the folder: {"pid", "host"}
RUN_FILES = ("summary.json", "timeseries.csv", "profiles.csv", CHECKPOINT, "state.npz", "*.pvd", "*.vtu", "*.pvtu",
             "*.png")


def scene_digest(scene) -> str:
    """A digest of everything that decides a run's result: the particles' arrays and every specification.

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The run's scene.
    """
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


def _holder(path: pathlib.Path) -> dict | None:
    """``{"pid", "host"}`` of the run named by the lock file at ``path`` while that process lives (on this host:
    on another one it cannot be checked, so it counts as alive), None for a missing, unreadable or stale lock."""
    try:
        held = json.loads(path.read_text())
        pid, host = int(held["pid"]), str(held["host"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if host != socket.gethostname():
        return held
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return None
    except PermissionError:  # alive, another user's
        pass
    return held


def lock(out: pathlib.Path) -> None:
    """Take the folder ``out`` for this process (module docstring): ``ValueError`` naming the holder when another
    live run has it; a stale lock is replaced.

    Parameters
    ----------
    out : pathlib.Path
        The output folder (existing).
    """
    path = out / LOCK
    me = json.dumps({"pid": os.getpid(), "host": socket.gethostname()})
    for _ in range(2):
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            held = _holder(path)
            if held is not None and held.get("pid") != os.getpid():
                raise ValueError(f"--out {out}: another run is writing it (pid {held['pid']} on {held['host']}, "
                                 f"{LOCK}); wait for it to end, or use another folder (no such run: delete "
                                 f"{path})") from None
            path.unlink(missing_ok=True)  # stale: its run was killed (or it is this process's own)
            continue
        with os.fdopen(fd, "w") as fh:
            fh.write(me)
        return
    raise ValueError(f"--out {out}: {LOCK} could not be taken (another run took it at the same moment)")


def unlock(out) -> None:
    """Release the folder ``out`` if this process holds it.

    Parameters
    ----------
    out : str or pathlib.Path
        The output folder.
    """
    path = pathlib.Path(out) / LOCK
    try:
        held = json.loads(path.read_text())
    except (OSError, ValueError):
        return
    if held.get("pid") == os.getpid() and held.get("host") == socket.gethostname():
        path.unlink(missing_ok=True)


def finished(out: pathlib.Path) -> dict | None:
    """The summary of the finished run in ``out`` (not marked ``interrupted`` or ``stopped``), or None.

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    """
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(summary, dict) or summary.get("interrupted") or "stopped" in summary:
        return None
    return summary


def interrupted_at_start(out: pathlib.Path) -> bool:
    """Whether the run in ``out`` was interrupted before it completed a step: its ``summary.json`` marked
    ``interrupted``, with no checkpoint to resume from (module docstring).

    Parameters
    ----------
    out : pathlib.Path
        The run's folder.

    Returns
    -------
    bool
        A ``--resume`` of it starts the run from its beginning.
    """
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return False
    return (isinstance(summary, dict) and summary.get("interrupted") is True and summary.get("resume_from") is None
            and not (out / CHECKPOINT).exists())


def run_files(out: pathlib.Path) -> list[pathlib.Path]:
    """The files of a run in ``out`` (those matching ``RUN_FILES``), sorted.

    Parameters
    ----------
    out : pathlib.Path
        The output folder.
    """
    return sorted({f for pattern in RUN_FILES for f in out.glob(pattern)})


def prepare(out, resume: bool = False, overwrite: bool = False) -> tuple[pathlib.Path, bool]:
    """The output folder, checked: refused when it holds a run and neither ``resume`` nor ``overwrite`` is given;
    with ``overwrite`` the old run's files are deleted first, and so are those of a run interrupted before it
    completed a step when it is resumed (:func:`interrupted_at_start`).

    Parameters
    ----------
    out : str or pathlib.Path
        The output folder (created if missing).
    resume : bool
        Go on from the checkpoint of the run in ``out``.
    overwrite : bool
        Delete the run's files in ``out`` first.

    Returns
    -------
    tuple
        The folder (pathlib.Path) and whether the run goes on from a checkpoint (bool).
    """
    out = pathlib.Path(out)
    if resume and overwrite:
        raise ValueError("--resume and --overwrite: give one of them")
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {out}: exists and is not a folder")
    held = out.exists()
    if held:  # first of all: a folder another run is writing is refused whatever was asked
        lock(out)
    try:
        found = run_files(out) if out.exists() else []
        if resume:
            if not (out / CHECKPOINT).exists():
                if not interrupted_at_start(out):
                    raise ValueError(f"--resume: {out} holds no checkpoint ({CHECKPOINT}) to go on from")
                resume = False  # interrupted before its first step: it starts again
        elif found and not overwrite:
            raise ValueError(f"--out {out}: holds a run already ({found[0].name}, ...); --resume goes on from its "
                             f"last checkpoint, --overwrite clears it first")
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"--out {out}: cannot be created ({exc.strerror})") from None
        if not held:
            lock(out)
        if not resume:
            for f in run_files(out):
                f.unlink()
    except BaseException:
        unlock(out)
        raise
    return out, resume


def load(out, scene, kind: str) -> dict:
    """The checkpoint of the run in ``out`` as a dict of arrays, refused if another scene (or kind) wrote it or the
    run is finished (:func:`finished`).

    Parameters
    ----------
    out : str or pathlib.Path
        The output folder.
    scene : dem.scene.parse.Scene
        The scene resuming the run (it must be the one that wrote the checkpoint).
    kind : str
        The kind of run (the scene's engine), which must match the checkpoint's.
    """
    path = pathlib.Path(out) / CHECKPOINT
    data = read_npz(path, "--resume: the checkpoint")
    if str(data.get("kind")) != kind or str(data.get("scene_digest")) != scene_digest(scene):
        raise ValueError(f"--resume: {path} was written by another scene (or another kind of run); resume it with "
                         f"the scene that started it, or use --overwrite")
    done = finished(pathlib.Path(out))
    if done is not None:
        raise ValueError(f"--resume: {out} holds a finished run (summary.json, t = {done.get('t')}, steps = "
                         f"{done.get('steps')}); nothing to go on with; --overwrite runs it again")
    return data


class Checkpointer:
    """Keeps the checkpoint of the last completed step and writes it to ``out/checkpoint.npz`` once ``every`` seconds
    have passed since the last write, at the end (``final``) and after Ctrl-C (:meth:`last`): a run interrupted at any
    moment -- in its first seconds too -- resumes from the step it had completed.

    Parameters
    ----------
    out : str or pathlib.Path
        The output folder.
    scene : dem.scene.parse.Scene
        The run's scene (its digest goes into the checkpoint).
    kind : str
        The kind of run (the scene's engine).
    every : float
        Wall time between two writes, s.
    """

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
        write_aside(self.path, lambda fh: np.savez(fh, **self.header, **self.latest), "wb")
        self.written_at = time.monotonic()
        self.written = True
