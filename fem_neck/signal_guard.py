"""The process's signal handlers, kept across a C library that resets them.

``gmsh.initialize()`` sets every signal it does not use itself back to the system default (gmsh 4.15 on Linux:
SIGSEGV, SIGFPE, SIGBUS, SIGILL, SIGPIPE, SIGTERM, SIGHUP, ...). After a mesh, Python's ``faulthandler`` then no
longer prints where a crash happened (a segmentation fault kills the process without a word), and a write to a closed
pipe (``python -m fem_neck ... | head``) kills it instead of raising ``BrokenPipeError``. :func:`kept` saves the
handlers of all standard signals (``sigaction``, read and written through the C library) and puts them back on
leaving. On systems other than Linux, whose ``struct sigaction`` this module does not describe, it does nothing.
"""

from __future__ import annotations

import contextlib
import ctypes
import signal
import sys

STANDARD = tuple(s for s in range(1, 32) if s not in (signal.SIGKILL, signal.SIGSTOP))


class SigAction(ctypes.Structure):
    """glibc's ``struct sigaction`` (x86-64 and aarch64): handler, 1024-bit mask, flags, restorer."""
    _fields_ = [("handler", ctypes.c_void_p), ("mask", ctypes.c_ulong * 16), ("flags", ctypes.c_int),
                ("restorer", ctypes.c_void_p)]


def _libc():
    return ctypes.CDLL(None, use_errno=True) if sys.platform == "linux" else None


def handlers() -> dict[int, SigAction]:
    """The handler of every standard signal, as the C library holds it (empty where not on Linux)."""
    libc = _libc()
    if libc is None:
        return {}
    saved = {}
    for number in STANDARD:
        action = SigAction()
        if libc.sigaction(number, None, ctypes.byref(action)) == 0:
            saved[number] = action
    return saved


def restore(saved: dict[int, SigAction]) -> None:
    """Put back the handlers :func:`handlers` returned.

    Parameters
    ----------
    saved : dict
        Signal number to the C library's handler record, as :func:`handlers` returned it.
    """
    libc = _libc()
    for number, action in saved.items():
        libc.sigaction(number, ctypes.byref(action), None)


@contextlib.contextmanager
def kept():
    """The signal handlers as they are on entering, put back after the block (and if it raises)."""
    saved = handlers()
    try:
        yield
    finally:
        restore(saved)
