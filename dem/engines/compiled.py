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
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import pathlib
import sys
import tempfile

from dem import jit_cache
from dem.laws.contact import law_module_name

TEMPLATES = ("dem.engines.contact_forces", "dem.engines.verlet.loop", "dem.engines.staggered.kernels")
TEMPLATE_LAW = "dem.laws.contact.luding"
LAW_IMPORT = "from dem.laws.contact import luding as law"


def _copy_name(law: str, template: str) -> str:
    return f"_dem_compiled_{law}_{template.replace('.', '_')}"


def _folder(law: str) -> pathlib.Path:
    base = pathlib.Path(os.environ.get("NUMBA_CACHE_DIR") or pathlib.Path(tempfile.gettempdir()) / "sinterheat-numba")
    return base / f"specialised-{jit_cache.remembered_digest()}" / law


def module(law: str, template: str):
    """The module ``template`` (one of ``TEMPLATES``) compiled for the contact law named ``law``."""
    law_path = law_module_name(law)
    if law_path == TEMPLATE_LAW:
        return importlib.import_module(template)
    name = _copy_name(law, template)
    if name in sys.modules:
        return sys.modules[name]
    source = pathlib.Path(importlib.util.find_spec(template).origin).read_text()
    if source.count(LAW_IMPORT) > 1:
        raise RuntimeError(f"{template}: imports its contact law more than once as {LAW_IMPORT!r}")
    source = source.replace(LAW_IMPORT, f"import {law_path} as law")
    for other in TEMPLATES:
        if f"from {other} import" in source:
            module(law, other)  # loaded first: the copy imports it by name
            source = source.replace(f"from {other} import", f"from {_copy_name(law, other)} import")
    path = _folder(law) / f"{template.rsplit('.', 1)[1]}.py"
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
