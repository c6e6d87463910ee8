"""numba's on-disk cache for the compiled kernels, kept from going stale.

``numba.njit(cache=True)`` keeps a compiled function until *its own* source file changes: a kernel that calls
functions of another module (the time loop calls the contact law's kernels and the binning of the neighbour list), or
reads another module's constants (the parameter indices of a contact law are compile-time constants of every kernel
that uses them), keeps the old code after only those were edited -- a researcher who changes the contact law would
run the old one. So the cache lives in a folder named by a digest of the source of every module whose code or
constants can reach compiled code: the modules of the project's packages (``dem``, ``fem_neck``, ``sinterheat``)
that import numba and, transitively, every module of the project they import (:func:`compiled_sources`, found by
reading the import statements, not listed by hand). Any edit to any of them starts a fresh cache; an unchanged
installation reuses its compiled kernels across runs. One folder serves both packages: ``dem`` compiles kernels of
``fem_neck.geometry``, so a key of its own modules alone would miss an edit there.

:func:`configure` points numba there, whether or not numba is imported already (numba reads the folder when a
function is decorated; without it, a script that imports numba first would run kernels compiled from older sources).
``import dem`` and ``import fem_neck`` call it before any of their modules is imported, so every kernel of either is
decorated after the call, however a script reaches it. A folder the user chose with ``NUMBA_CACHE_DIR`` stays the
root: the digest's folder is made inside it.

Processes share the folder (``pytest -n``'s workers, a sweep's pool, MPI ranks), and numba adds a signature to a
kernel's index by reading the index, adding the entry and writing the index back, unguarded: two processes that
save two signatures of one kernel at once each write the index they read plus their own entry, and the one written
last drops the other's, which every later run then compiles again (and both may take the same data file's number, so
that an entry names the other signature's code). :func:`configure` makes that update hold a lock on a file of the
kernel's cache folder (``fcntl``; where Python has no ``fcntl`` numba's own update stays). The index's key is
numba's, unchanged: the signature, the machine, and the hashes of the function's byte code and closure.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import importlib.abc
import importlib.util
import json
import os
import pathlib
import sys
import tempfile
import warnings

try:
    import fcntl
except ImportError:  # not on a POSIX system
    fcntl = None

PACKAGE = pathlib.Path(__file__).resolve().parent  # sinterheat/: the cache and the remembered key live here
ROOT = PACKAGE.parent  #: the folder that holds the project's packages
PROJECT_PACKAGES = ("dem", "fem_neck", "sinterheat")  # the project's top-level packages, side by side in ROOT


def _module_file(root: pathlib.Path, dotted: str) -> pathlib.Path | None:
    """The source file of the project module ``dotted`` under ``root`` (a module or a package's ``__init__``)."""
    parts = dotted.split(".")
    if parts[0] not in PROJECT_PACKAGES:
        return None
    base = root.joinpath(*parts)
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _dotted(root: pathlib.Path, path: pathlib.Path) -> str:
    parts = list(path.relative_to(root).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _statements(body):
    """Every statement in ``body`` and the blocks nested in it (imports are statements: no expression is visited)."""
    for node in body:
        yield node
        for block in ("body", "orelse", "finalbody", "handlers", "cases"):
            inner = getattr(node, block, None)
            if isinstance(inner, list):
                yield from _statements(inner)


def _imports(root: pathlib.Path, path: pathlib.Path) -> tuple[set[pathlib.Path], bool]:
    """The project modules ``path`` imports (anywhere in it, also inside functions: an over-approximation is safe),
    and whether it imports numba."""
    tree = ast.parse(path.read_bytes(), str(path))
    package = _dotted(root, path) if path.name == "__init__.py" else _dotted(root, path).rpartition(".")[0]
    found, compiled = set(), False
    for node in _statements(tree.body):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from the module's own package upwards
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            # ``from a.b import c``: c is a submodule when it has a file, else a name defined in a.b
            names = [f"{base}.{alias.name}" if _module_file(root, f"{base}.{alias.name}") else base
                     for alias in node.names]
        else:
            continue
        for name in names:
            compiled |= name == "numba" or name.startswith("numba.")
            target = _module_file(root, name)
            if target is not None:
                found.add(target)
    return found, compiled


def _sources(package: pathlib.Path) -> list[pathlib.Path]:
    """The package's source files, without ``__pycache__`` (where the cache itself lives, and with it the loops
    :mod:`dem.engines.compiled` copies for more than one thread: were they sources, writing them would change the
    key)."""
    return sorted(p for p in package.rglob("*.py") if "__pycache__" not in p.relative_to(package).parts)


def compiled_sources(root: pathlib.Path = ROOT) -> list[pathlib.Path]:
    """Every module whose code or constants can reach compiled code: the modules of the project's packages that
    import numba, and every project module they import, transitively (module docstring).

    Parameters
    ----------
    root : pathlib.Path
        The folder that holds the project's packages (:data:`ROOT` by default).

    Returns
    -------
    list of pathlib.Path
        The source files, sorted.
    """
    seeds = []
    for name in PROJECT_PACKAGES:
        for path in _sources(root / name):
            if b"numba" in path.read_bytes() and _imports(root, path)[1]:
                seeds.append(path)
    closure, todo = set(seeds), list(seeds)
    while todo:
        for target in _imports(root, todo.pop())[0]:
            if target not in closure:
                closure.add(target)
                todo.append(target)
    return sorted(closure)


def digest(root: pathlib.Path = ROOT) -> str:
    """A short hash of the source of :func:`compiled_sources`.

    Parameters
    ----------
    root : pathlib.Path
        The folder that holds the project's packages (:data:`ROOT` by default).

    Returns
    -------
    str
        The hash, hexadecimal.
    """
    h = hashlib.sha1()
    for path in compiled_sources(root):
        h.update(str(path.relative_to(root)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:12]


def _stamp(root: pathlib.Path) -> str:
    """A hash of the name, size and modification time of every source file of the project's packages."""
    h = hashlib.sha1()
    for name in PROJECT_PACKAGES:
        for path in _sources(root / name):
            st = path.stat()
            h.update(f"{path.relative_to(root)}:{st.st_size}:{st.st_mtime_ns};".encode())
    return h.hexdigest()


def remembered_digest(root: pathlib.Path = ROOT) -> str:
    """:func:`digest`, remembered in ``sinterheat/__pycache__/jit_digest.json`` for as long as no source file of the
    project changed its size or modification time (as Python's own ``.pyc`` files are): reading the imports of the
    compiled modules takes a tenth of a second, a look at the files' times a millisecond.

    Parameters
    ----------
    root : pathlib.Path
        The folder that holds the project's packages (:data:`ROOT` by default).

    Returns
    -------
    str
        The hash of :func:`digest`.
    """
    memo = root / PACKAGE.name / "__pycache__" / "jit_digest.json"
    stamp = _stamp(root)
    try:
        saved = json.loads(memo.read_text())
        if saved.get("stamp") == stamp:
            return saved["digest"]
    except (OSError, ValueError, KeyError, AttributeError):
        pass
    key = digest(root)
    try:
        memo.parent.mkdir(parents=True, exist_ok=True)
        part = memo.with_name(f"{memo.name}.{os.getpid()}.part")
        part.write_text(json.dumps({"stamp": stamp, "digest": key}))
        part.replace(memo)
    except OSError:
        pass  # a read-only installation computes it each time
    return key


def _writable(folder: pathlib.Path) -> bool:
    """Whether ``folder`` exists or can be made, and a file can be written in it."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / ".writable").touch()
    except OSError:
        return False
    return True


def configure() -> None:
    """Point numba's cache at ``numba-<digest>``: in ``sinterheat/__pycache__``, or inside the folder the user set in
    ``NUMBA_CACHE_DIR`` (module docstring); where that cannot be written, in the temp folder (a user's folder that
    cannot be written is named in a warning). ``import dem`` and ``import fem_neck`` call it first."""
    key = remembered_digest()
    name = f"numba-{key}"
    chosen = os.environ.get("NUMBA_CACHE_DIR")
    if chosen and pathlib.Path(chosen).name == name:  # set by this function already (a parent process)
        folder = pathlib.Path(chosen)
    elif chosen:
        folder = pathlib.Path(chosen) / name
    else:
        folder = PACKAGE / "__pycache__" / name
    if not _writable(folder):
        fallback = pathlib.Path(tempfile.gettempdir()) / "sinterheat-numba" / name  # a child process finds it by name
        if chosen:
            warnings.warn(f"NUMBA_CACHE_DIR = {chosen!r}: cannot write {folder}; the compiled kernels are cached in "
                          f"{fallback} instead", stacklevel=2)
        folder = fallback
        folder.mkdir(parents=True, exist_ok=True)
    os.environ["NUMBA_CACHE_DIR"] = str(folder)
    if "numba" in sys.modules:  # numba imported first: its configuration has read the environment already
        from numba.core import config
        config.CACHE_DIR = str(folder)
    _lock_index_updates()


def _locked(save):
    """numba's ``IndexDataCacheFile.save`` (read the index, add the entry, write the index and the data) under an
    exclusive lock on ``index.lock`` in the kernel's cache folder (module docstring)."""
    @functools.wraps(save)
    def locked(self, key, data):
        with open(os.path.join(self._cache_path, "index.lock"), "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file is closed
            save(self, key, data)
    locked.locked = True
    return locked


def _lock_caching(caching) -> None:
    """Put numba's index update (module ``numba.core.caching``) under the lock of ``_locked``, once."""
    if not getattr(caching.IndexDataCacheFile.save, "locked", False):
        caching.IndexDataCacheFile.save = _locked(caching.IndexDataCacheFile.save)


class _AfterImport(importlib.abc.MetaPathFinder):
    """Calls ``_lock_caching`` on ``numba.core.caching`` as soon as it is imported, for a process that has not
    imported numba yet (as :func:`configure` wants it: importing numba for the lock would cost a run without compiled
    kernels its import)."""

    name = "numba.core.caching"

    def find_spec(self, fullname, path, target=None):
        if fullname != self.name:
            return None
        sys.meta_path.remove(self)  # the search below is the ordinary one
        spec = importlib.util.find_spec(fullname)
        run = spec.loader.exec_module

        def exec_module(module):
            run(module)
            _lock_caching(module)

        spec.loader.exec_module = exec_module
        return spec


def _lock_index_updates() -> None:
    """numba's index updates under a lock in this process (module docstring): now if numba is imported, else when it
    is."""
    if fcntl is None:
        return
    if _AfterImport.name in sys.modules:
        _lock_caching(sys.modules[_AfterImport.name])
    elif not any(isinstance(finder, _AfterImport) for finder in sys.meta_path):
        sys.meta_path.insert(0, _AfterImport())
