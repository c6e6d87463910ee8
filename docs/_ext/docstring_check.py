"""Public parameters without a description: how far the API is from numpy-style docstrings throughout.

Every parameter of a public function, of a public class (its constructor) and of a public method a class defines
(``self`` and ``cls`` aside) should be described in its docstring, numpy style, which napoleon renders::

    Parameters
    ----------
    r_i : float or array_like
        Radius of particle i (m).

A class describes its constructor's parameters in its own docstring (or its ``__init__``'s); a dataclass may list
its fields under ``Attributes`` instead. :func:`undescribed` lists what lacks a description; the tests hold its
count per package as a ratchet (it may fall, never rise).
"""

from __future__ import annotations

import dataclasses
import inspect
import re

import api_check

SECTIONS = ("Parameters", "Other Parameters", "Attributes")  # the sections whose entries describe parameters


def described(docstring: str | None) -> set[str]:
    """The names that ``docstring`` (cleaned, as ``inspect.getdoc`` gives it) describes in one of :data:`SECTIONS`:
    an entry line ``name : type`` (or ``name``, or ``a, b : type``) followed by at least one indented, non-empty
    line."""
    lines = (docstring or "").splitlines()
    names: set[str] = set()
    section = None
    for k, line in enumerate(lines):
        underline = lines[k + 1] if k + 1 < len(lines) else ""
        if line.strip() and re.fullmatch(r"\s*-{3,}\s*", underline):
            section = line.strip() if line.strip() in SECTIONS else None
            continue
        if section is None or not line.strip() or line[0].isspace() or re.fullmatch(r"-{3,}", line.strip()):
            continue
        following = lines[k + 1] if k + 1 < len(lines) else ""
        if following.strip() and following[0].isspace():
            entry = line.split(" : ", 1)[0].strip()
            names.update(name.strip().lstrip("*") for name in entry.split(","))
    return names


def _parameters(function, drop_first: bool) -> list[str]:
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):  # a builtin without a signature
        return []
    names = list(signature.parameters)
    return names[1:] if drop_first and names else names


def _class_docstrings(cls) -> str:
    own = inspect.getdoc(cls) if "__doc__" in vars(cls) else None
    init = vars(cls).get("__init__")
    return "\n".join(filter(None, [own, inspect.getdoc(init) if inspect.isfunction(init) else None]))


def undescribed(package: str) -> list[str]:
    """``object(parameter)`` for every parameter of the public API of ``package`` that no docstring describes: the
    functions and classes of :func:`api_check.public_objects` and the public methods each class defines."""
    import importlib

    missing = []
    for dotted in api_check.public_objects(package):
        module, _, name = dotted.rpartition(".")
        obj = getattr(importlib.import_module(module), name)
        if inspect.isfunction(obj):
            documented = described(inspect.getdoc(obj))
            missing += [f"{dotted}({p})" for p in _parameters(obj, False) if p not in documented]
            continue
        if dataclasses.is_dataclass(obj) or "__init__" in vars(obj):
            documented = described(_class_docstrings(obj))
            missing += [f"{dotted}({p})" for p in _parameters(obj, False) if p not in documented]
        for attr, member in vars(obj).items():
            if attr.startswith("_"):
                continue
            function = member.__func__ if isinstance(member, (classmethod, staticmethod)) else member
            if inspect.isfunction(function):
                documented = described(inspect.getdoc(function))
                missing += [f"{dotted}.{attr}({p})" for p in _parameters(function, not isinstance(member, staticmethod))
                            if p not in documented]
    return missing


def undocumented(package: str) -> list[str]:
    """The public functions and classes of ``package`` (:func:`api_check.public_objects`), and the public methods and
    properties each class defines, that have no docstring: of their own, or (a method, a property) inherited from the
    one they override, as autodoc shows it. A dataclass's generated signature is none."""
    import importlib

    missing = []
    for dotted in api_check.public_objects(package):
        module, _, name = dotted.rpartition(".")
        obj = getattr(importlib.import_module(module), name)
        own = vars(obj).get("__doc__") if inspect.isclass(obj) else obj.__doc__
        if dataclasses.is_dataclass(obj) and (own or "").startswith(f"{obj.__name__}("):
            own = None
        if not (own or "").strip():
            missing.append(dotted)
        for attr, member in (vars(obj).items() if inspect.isclass(obj) else ()):
            function = member.fget if isinstance(member, property) else getattr(member, "__func__", member)
            function = getattr(function, "func", function)  # functools.cached_property
            documented = inspect.getdoc(member if isinstance(member, property) else function)
            if not attr.startswith("_") and inspect.isfunction(function) and not (documented or "").strip():
                missing.append(f"{dotted}.{attr}")
    return missing

