"""Every file of a run is written aside and renamed: ``PATH.part`` first, then ``os.replace`` onto ``PATH``, so a
file on disk is whole at any moment (an interrupted or killed write leaves the previous version). A write that
fails (a full disk, a folder gone) removes its ``.part`` and is one ``OSError`` naming the path."""

from __future__ import annotations

import os
import pathlib


def write_aside(path, write, mode: str | None = "w") -> pathlib.Path:
    """Write ``path`` through ``write(fh)``, ``fh`` the open ``PATH.part`` (text for ``mode = "w"``, bytes for
    ``"wb"``; with ``mode = None`` its path, for a writer that opens the file itself), then rename it onto ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write.
    write : callable
        Called once with the open temporary file (or its path).
    mode : str or None
        ``"w"`` (text, UTF-8), ``"wb"`` (bytes) or None (the path).

    Raises
    ------
    OSError
        The write or the rename failed: ``cannot write PATH: REASON``; no ``.part`` is left.
    """
    path = pathlib.Path(path)
    tmp = path.with_name(path.name + ".part")
    try:
        if mode is None:
            write(tmp)
        else:
            with tmp.open(mode, **({"encoding": "utf-8"} if "b" not in mode else {})) as fh:
                write(fh)
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise OSError(exc.errno, f"cannot write {path}: {exc.strerror or exc}") from None
    except BaseException:  # an interrupt in the middle: no half-written .part is left either
        tmp.unlink(missing_ok=True)
        raise
    return path
