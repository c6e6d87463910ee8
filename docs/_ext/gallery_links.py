""""Examples using this" under every API entry that a gallery example uses: a rubric and the examples' thumbnails
(sphinx-gallery's ``minigallery``) added to the entry's docstring.

sphinx-gallery records, before any page is read, which functions and classes of the packages in its ``doc_module``
each example uses (``backreferences_dir``), keyed by the shortest public path of each (``fem_neck.neck_radius`` for
:func:`fem_neck.geometry.neck_radius`, which the package re-exports). The API reference documents every object where
it is defined, so the keys are resolved to their objects and an entry is matched by identity, whatever path the
example took to it.
"""

from __future__ import annotations

import importlib
import inspect
import json
import pathlib

RUBRIC = "Examples using this"


def _plain(obj):
    """A bound (class) method's function: what autodoc documents for it."""
    return getattr(obj, "__func__", obj)


def resolve(name: str):
    """The function or class that the dotted ``name`` denotes (the longest importable module, then attributes; a
    method as its function), or None."""
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:k]))
        except ImportError:
            continue
        for attr in parts[k:]:
            obj = getattr(obj, attr, None)
        obj = _plain(obj)
        return obj if inspect.isfunction(obj) or inspect.isclass(obj) else None
    return None


def index(backreferences: dict) -> dict[int, list[str]]:
    """``id(object) -> keys`` of the functions and classes that some example uses, from sphinx-gallery's
    ``backreferences_all.json`` (key: dotted name, value: the examples using it)."""
    found: dict[int, list[str]] = {}
    for key, examples in backreferences.items():
        obj = resolve(key) if examples else None
        if obj is not None:
            found.setdefault(id(obj), []).append(key)
    return found


def lines(keys) -> list[str]:
    """The reST appended to a docstring: the rubric and a mini-gallery of the examples using any of ``keys``."""
    return ["", f".. rubric:: {RUBRIC}", "", ".. minigallery:: " + " ".join(sorted(keys)), ""]


def _index(app) -> dict[int, list[str]]:
    if not hasattr(app.env, "_gallery_links"):
        path = pathlib.Path(app.srcdir, app.config.sphinx_gallery_conf["backreferences_dir"],
                            "backreferences_all.json")
        app.env._gallery_links = index(json.loads(path.read_text())) if path.is_file() else {}
    return app.env._gallery_links


def add_examples(app, what, name, obj, options, docstring):
    if what in ("function", "class", "method"):
        keys = _index(app).get(id(_plain(obj)))
        if keys:
            docstring.extend(lines(keys))


def setup(app):
    app.connect("autodoc-process-docstring", add_examples)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
