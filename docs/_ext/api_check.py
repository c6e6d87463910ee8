"""Fail the build when a public function or class of a documented package is missing from the API reference.

For every module of the packages named in ``api_packages`` (conf.py), every function and class defined there whose
name has no leading underscore must have been described by autodoc (it is in the Python domain's inventory). A
missing one is a warning, which ``-W`` turns into a failed build, so a new function cannot go unlisted.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil


def public_objects(package: str) -> list[str]:
    """Dotted names of the public functions and classes defined in ``package`` and its modules (``__main__``
    modules are not imported: they run their command)."""
    root = importlib.import_module(package)
    names = [package]
    if hasattr(root, "__path__"):
        names += [m.name for m in pkgutil.walk_packages(root.__path__, package + ".")]
    found = []
    for name in names:
        if any(part.startswith("_") for part in name.split(".")):
            continue
        module = importlib.import_module(name)
        for attr, obj in vars(module).items():
            if (not attr.startswith("_") and (inspect.isfunction(obj) or inspect.isclass(obj))
                    and getattr(obj, "__module__", None) == name):
                found.append(f"{name}.{attr}")
    return found


def check(app, env):
    from sphinx.util import logging  # here, so that the tests import this module without Sphinx

    logger = logging.getLogger(__name__)
    documented = set(env.get_domain("py").objects)
    for package in app.config.api_packages:
        missing = [name for name in public_objects(package) if name not in documented]
        for name in missing:
            logger.warning("%s is public but not in the API reference (add its module to docs/reference/)", name,
                           type="api_check")


def setup(app):
    app.add_config_value("api_packages", [], "env")
    app.connect("env-check-consistency", check)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
