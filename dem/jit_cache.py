"""numba's on-disk cache for the compiled kernels, kept from going stale.

``numba.njit(cache=True)`` keeps a compiled function until *its own* source file changes: a kernel that calls
functions of another module (the time loop of :mod:`dem.md_loop` calls the contact law of
:mod:`dem.laws.luding_kernels` and the binning of :mod:`dem.neighbours`) keeps the old callees' machine code after
only they were edited -- a researcher who changes the contact law would run the old one. So the cache lives in a
folder named by a digest of every compiled module's source (:data:`SOURCES`): any edit to any of them starts a fresh
cache, and an unchanged installation reuses its compiled kernels across runs.

:func:`configure` sets ``NUMBA_CACHE_DIR`` before numba is first imported (``import dem`` calls it); a cache folder
the user chose (``NUMBA_CACHE_DIR`` set already) is left alone.
"""

from __future__ import annotations

import hashlib
import os
import pathlib
import sys
import tempfile

PACKAGE = pathlib.Path(__file__).resolve().parent
SOURCES = ("md_loop.py", "neighbours.py", "exposure.py", "laws/luding_kernels.py", "laws/shared_body.py")


def digest() -> str:
    """A short hash of the compiled modules' source."""
    h = hashlib.sha1()
    for name in SOURCES:
        path = PACKAGE / name
        h.update(name.encode())
        h.update(path.read_bytes() if path.exists() else b"")
    return h.hexdigest()[:12]


def configure() -> None:
    """Point numba's cache at ``__pycache__/numba-<digest>`` of this package (or of the temp folder when the
    package is read-only), unless the user set ``NUMBA_CACHE_DIR`` or numba is imported already."""
    if "NUMBA_CACHE_DIR" in os.environ or "numba" in sys.modules:
        return
    folder = PACKAGE / "__pycache__" / f"numba-{digest()}"
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".writable"
        probe.touch()
    except OSError:
        folder = pathlib.Path(tempfile.gettempdir()) / "sinterheat-numba" / digest()
        folder.mkdir(parents=True, exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
