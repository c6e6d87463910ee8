"""Files whole or not at all.

* :func:`write_aside`: every file of a run is written aside and renamed: ``PATH.part`` first, then ``os.replace``
  onto ``PATH``, so a file on disk is whole at any moment (an interrupted or killed write leaves the previous
  version). A write that fails (a full disk, a folder gone) removes its ``.part`` and is one ``OSError`` naming the
  path.
* :func:`read_npz`: a ``.npz`` file read whole into memory, or one ``ValueError`` naming it (empty, truncated, not a
  zip of arrays, holding pickled objects), never numpy's or zipfile's own exception.
"""

from __future__ import annotations

import os
import pathlib
import zipfile
import zlib

import numpy as np


def write_aside(path, write, mode: str | None = "w") -> pathlib.Path:
    """Write ``path`` through ``write(fh)``, ``fh`` the open ``PATH.part`` (text for ``mode = "w"``, bytes for
    ``"wb"``; with ``mode = None`` its path, for a writer that opens the file itself), then rename it onto ``path``.

    Parameters
    ----------
    path : str or pathlib.Path
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


def read_npz(path, what: str) -> dict:
    """The arrays of the ``.npz`` file ``path`` as a dict.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    what : str
        How the message names the file, e.g. ``"[start] state"`` or ``"--resume"``.

    Raises
    ------
    ValueError
        ``WHAT = 'PATH': cannot be read (REASON)``: missing, unreadable, empty, truncated or not a ``.npz``.
    """
    try:
        loaded = np.load(path, allow_pickle=False)
        if not isinstance(loaded, np.lib.npyio.NpzFile):  # a .npy file: one array, no archive
            raise zipfile.BadZipFile("one array (.npy)")
        with loaded as f:
            return {k: f[k] for k in f.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, KeyError) as exc:
        reason = {EOFError: "empty", zipfile.BadZipFile: "truncated or not a .npz archive"}.get(type(exc))
        reason = reason or " ".join(str(exc).split()).split(". ")[0] or type(exc).__name__
        raise ValueError(f"{what} = {str(path)!r}: cannot be read as a .npz file ({reason})") from None
