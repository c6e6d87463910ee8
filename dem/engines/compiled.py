"""The compiled loops of the engines, bound to a contact law and to one or more threads.

The force loop (:mod:`dem.engines.contact_forces`), the velocity-Verlet loop (:mod:`dem.engines.verlet.loop`) and the
implicit iteration (:mod:`dem.engines.staggered.kernels`) take the contact law as their first argument, a
:class:`dem.laws.contact.binding.ContactLaw`: each law is a numba type of its own, so numba compiles (and caches on
disk) a loop for each law with the law's kernels inlined -- the law is bound at compile time, nothing is dispatched at
run time. :func:`loop` hands an engine a template's loop with its law bound.

For more than one thread, :func:`module` with ``threaded=True`` is a copy of the template with its ``THREADED =
False`` made true: a compile-time constant that turns its loops over particles and pairs into numba's parallel loops
(numba drops the branches it rules out, so the one-thread loop carries nothing of the threaded one), and its imports
of the other templates pointed at their threaded copies. The copies live in the cache folder of
:mod:`sinterheat.jit_cache`, named by the digest of the sources they come from, so an edit to a template makes new
ones.
Which of the two a run gets is decided when the engine is built (:func:`sinterheat.threads.count`), never inside the
loop.
"""


from __future__ import annotations

import functools
import importlib
import importlib.util
import os
import pathlib
import sys

from dem.laws.contact.binding import ContactLaw

TEMPLATES = ("dem.engines.contact_forces", "dem.engines.verlet.loop", "dem.engines.staggered.kernels")
SERIAL_FLAG, THREADED_FLAG = "\nTHREADED = False", "\nTHREADED = True"


def _copy_name(template: str) -> str:
    return f"_dem_compiled_threaded_{template.replace('.', '_')}"


def _folder() -> pathlib.Path:
    """Where the threaded copies live: in numba's cache folder, which :func:`sinterheat.jit_cache.configure` named by
    the digest of the sources."""
    from numba.core import config

    return pathlib.Path(config.CACHE_DIR) / "threaded"


def module(template: str, threaded: bool = False):
    """The module ``template`` (one of ``TEMPLATES``), or its copy for more than one thread (module docstring).

    Parameters
    ----------
    template : str
        The dotted name of the template module, one of ``TEMPLATES``.
    threaded : bool
        Whether the copy for more than one thread is wanted.

    Returns
    -------
    object
        The module.
    """
    if not threaded:
        return importlib.import_module(template)
    name = _copy_name(template)
    if name in sys.modules:
        return sys.modules[name]
    source = pathlib.Path(importlib.util.find_spec(template).origin).read_text().replace(SERIAL_FLAG, THREADED_FLAG)
    for other in TEMPLATES:
        if f"from {other} import" in source:
            module(other, threaded)  # loaded first: the copy imports it by name
            source = source.replace(f"from {other} import", f"from {_copy_name(other)} import")
    path = _folder() / f"{template.rsplit('.', 1)[1]}.py"
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


def loop(law: str, template: str, function: str, threaded: bool = False):
    """The compiled loop ``function`` of ``template`` with the contact law ``law`` bound as its first argument.

    Parameters
    ----------
    law : str
        The contact law (:data:`dem.laws.contact.CONTACT_LAWS`).
    template : str
        The dotted name of the template module, one of ``TEMPLATES``.
    function : str
        The loop's name in the template (``"forces"``, ``"advance"``, ``"iterate"``).
    threaded : bool
        Whether the copy for more than one thread is wanted.

    Returns
    -------
    callable
        The loop with the law bound first (a ``functools.partial``), to be called with its other arguments.

    Raises
    ------
    ValueError
        ``law`` is not a known contact law.
    """
    return functools.partial(getattr(module(template, threaded), function), ContactLaw(law))
