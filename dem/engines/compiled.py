"""The compiled loops of the engines, specialised for a contact law.

The force loop (:mod:`dem.engines.contact_forces`), the velocity-Verlet loop (:mod:`dem.engines.verlet.loop`) and the
implicit iteration (:mod:`dem.engines.staggered.kernels`) are written against one contact law, imported in each as
``from dem.laws.contact import luding as law`` (or importing a template that does). For that law they are used as
they are. For every other law
(:data:`dem.laws.contact.CONTACT_LAWS`) :func:`module` writes a copy of each with only that import changed (and their
imports of each other pointed at the copies) and loads it: numba then compiles the law's kernels inlined into a loop
of its own -- the law is bound at compile time, nothing is dispatched at run time -- and caches it on disk like any
module, which it cannot do for a loop made by a Python closure (a closure's compiled code is never found in the cache
by another process). The copies live in the cache folder of :mod:`dem.jit_cache`, named by the digest of the sources
they come from, so an edit to a template or a law makes new ones; a law is copied and compiled only when a scene
uses it.

For more than one thread, ``module(law, template, threaded=True)`` is a copy (for every law, the template's own
too) with the template's ``THREADED = False`` made true: a compile-time constant that turns its loops over particles
and pairs into numba's parallel loops (numba drops the branches it rules out, so the one-thread loop carries nothing
of the threaded one). Which of the two a run gets is decided when the engine is built
(:func:`sinterheat.threads.count`), never inside the loop.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import pathlib
import sys

from dem.laws.contact import law_module_name

TEMPLATES = ("dem.engines.contact_forces", "dem.engines.verlet.loop", "dem.engines.staggered.kernels")
TEMPLATE_LAW = "dem.laws.contact.luding"
LAW_IMPORT = "from dem.laws.contact import luding as law"
SERIAL_FLAG, THREADED_FLAG = "\nTHREADED = False", "\nTHREADED = True"


def _copy_name(law: str, template: str, threaded: bool) -> str:
    return f"_dem_compiled_{law}{'_threaded' if threaded else ''}_{template.replace('.', '_')}"


def _folder(law: str, threaded: bool) -> pathlib.Path:
    """Where the copies for ``law`` live: in numba's cache folder, which :func:`dem.jit_cache.configure` named by
    the digest of the sources."""
    from numba.core import config

    return pathlib.Path(config.CACHE_DIR) / "specialised" / (f"{law}-threaded" if threaded else law)


def module(law: str, template: str, threaded: bool = False):
    """The module ``template`` (one of ``TEMPLATES``) compiled for the contact law named ``law``; ``threaded``:
    its copy for more than one thread (module docstring).

    Parameters
    ----------
    law : str
        The contact law (:data:`dem.laws.contact.CONTACT_LAWS`).
    template : str
        The dotted name of the template module, one of ``TEMPLATES``.
    threaded : bool
        Whether the copy for more than one thread is wanted.

    Returns
    -------
    object
        The compiled module.

    Raises
    ------
    ValueError
        ``law`` is not a known contact law.
    RuntimeError
        The template imports its contact law more than once.
    """
    law_path = law_module_name(law)
    if law_path == TEMPLATE_LAW and not threaded:
        return importlib.import_module(template)
    name = _copy_name(law, template, threaded)
    if name in sys.modules:
        return sys.modules[name]
    source = pathlib.Path(importlib.util.find_spec(template).origin).read_text()
    if source.count(LAW_IMPORT) > 1:
        raise RuntimeError(f"{template}: imports its contact law more than once as {LAW_IMPORT!r}")
    source = source.replace(LAW_IMPORT, f"import {law_path} as law")
    if threaded:
        source = source.replace(SERIAL_FLAG, THREADED_FLAG)
    for other in TEMPLATES:
        if f"from {other} import" in source:
            module(law, other, threaded)  # loaded first: the copy imports it by name
            source = source.replace(f"from {other} import", f"from {_copy_name(law, other, threaded)} import")
    path = _folder(law, threaded) / f"{template.rsplit('.', 1)[1]}.py"
    if not path.exists() or path.read_text() != source:
        path.parent.mkdir(parents=True, exist_ok=True)
        part = path.with_name(f"{path.name}.{os.getpid()}.part")
        part.write_text(source)
        part.replace(path)
    spec = importlib.util.spec_from_file_location(name, path)
    loaded = importlib.util.module_from_spec(spec)
    sys.modules[name] = loaded
    try:
        spec.loader.exec_module(loaded)
    except BaseException:
        del sys.modules[name]
        raise
    return loaded
