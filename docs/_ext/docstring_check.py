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

Formulas are TeX in a ``:math:`` role or a ``.. math::`` block, which MathJax draws on the site; :func:`ascii_formulas`
lists the docstring lines that still write one in ASCII (``sqrt(r^2 - a^2)``, ``kappa pi r``, ``h = r_i + r_j - d``).
"""

from __future__ import annotations

import dataclasses
import inspect
import pkgutil
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


# Greek letters spelled out: alone or with a short subscript (``kappa_i``, ``lambda_1``), a formula's symbols
GREEK = ("alpha|beta|gamma|Gamma|delta|Delta|epsilon|eps|zeta|eta|theta|Theta|kappa|lambda|Lambda|mu|nu|xi|pi|rho|"
         "sigma|Sigma|tau|phi|Phi|chi|psi|Psi|omega|Omega")
FORMULA_SIGNS = {  # what makes a line (outside maths) an ASCII formula
    "function": re.compile(r"(?<![\w.])(?:sqrt|ln|exp|log|atan2|sin|cos|tan|tanh|atanh|arccos|arcsin|arctan|acos|"
                           r"asin|atan)\("),
    "power": re.compile(r"[\w)\]*]\^[-+(\w]|[\w)]\*\*[\w(]"),
    "Greek name": re.compile(rf"(?<![\w.\"'-])(?:{GREEK})(?:_\w{{1,3}})?(?![\w(\"'-])"),
    "equation": re.compile(r"(?<![\w.])[A-Za-z][\w*']{0,3}(?:\([\w, ]*\))?\s*(?:=|<=|>=)\s*[^=\s\"']*[\w)]\s*[-+*/]\s*"
                           r"[\w(]"),
}
_MATH_ROLE = re.compile(r":math:`[^`]*`")
_OTHER_ROLE = re.compile(r":[\w:.-]+:`[^`]*`")
_LITERAL = re.compile(r"``([^`]+?)``")
_NOT_POWERS = re.compile(r"(?<![\w)])(?:k?g|m|mm|um|s|K)\^-?\d\b|\b10\^-?\d+\b")  # units (m^3, K^4) and 10^6
_NUMBER = re.compile(r"(?<![\w.])\d+(?:\.\d*)?[eE][-+]?\d+\b")
_PARAMETER_ENTRY = re.compile(r"\s*\*{0,2}[\w, *]+ : .*")  # "kappa : float" under Parameters names, not maths


def formula_lines(docstring: str | None) -> list[str]:
    """The lines of ``docstring`` (as written: ``__doc__``) that write a formula in ASCII: outside ``:math:`` roles and
    ``.. math::`` blocks, a mathematical function called (``sqrt(``, ``ln(`` ...), a power (``a^2``, ``x**2``; not a
    unit's ``m^3`` nor ``10^6``), a Greek letter spelled out as a symbol (``kappa``, ``lambda_1``; not a parameter's
    name alone in a literal, nor the name of a ``Parameters`` entry), or an equation whose side is arithmetic
    (``h = r_i + r_j - d``). A literal counts as text: a formula in one is still ASCII. First, if the docstring holds
    a control character (what TeX's ``\\frac``, ``\\theta`` or ``\\rho`` become in a docstring that is not raw), a
    line saying so."""
    escaped = ["a backslash read as an escape: write the docstring r\"\"\"...\"\"\""] if re.search(
        r"[\a\b\f\r\t\v]", docstring or "") else []
    docstring = inspect.cleandoc(docstring or "")

    def blank(match):  # a role or literal may run over lines: keep its line breaks
        return re.sub(r"[^\n]", " ", match.group(0))

    def literal(match):  # a literal naming a parameter (``kappa``) is code; one holding an expression, a formula
        return blank(match) if re.fullmatch(r"\(?[\w.*]+(, [\w.*]+)*\)?", match.group(1)) else " " + match.group(1) + " "

    text = _LITERAL.sub(literal, _OTHER_ROLE.sub(blank, _MATH_ROLE.sub(blank, docstring)))
    found = escaped
    math_indent = None
    for line, original in zip(text.splitlines(), docstring.splitlines()):
        indent = len(line) - len(line.lstrip())
        if math_indent is not None:
            if not line.strip() or indent > math_indent:
                continue  # inside a .. math:: block
            math_indent = None
        if line.strip().startswith(".. math::"):
            math_indent = indent
            continue
        if line.strip().startswith(">>>") or _PARAMETER_ENTRY.fullmatch(original):
            continue
        line = re.sub(r"\*\*[^*]+\*\*", " ", _NOT_POWERS.sub(" ", line))  # units, powers of ten, bold text
        line = _NUMBER.sub("1", line)  # 3e-4 is a number, not 3e minus 4
        if any(sign.search(line) for sign in FORMULA_SIGNS.values()):
            found.append(original.strip())
    return found


def ascii_formulas(package: str) -> list[str]:
    """``object: line`` for every line of a public docstring of ``package`` (its public modules', their compiled
    (numba) functions', and those of the objects :func:`undocumented` reads: functions, classes, their public methods
    and properties) that :func:`formula_lines`
    finds an ASCII formula in, each docstring once."""
    import importlib

    seen, found = set(), []

    def read(name, obj):
        doc = obj.__doc__ if isinstance(obj, property) else getattr(obj, "__doc__", None)
        if doc and id(doc) not in seen:
            seen.add(id(doc))
            found.extend(f"{name}: {line}" for line in formula_lines(doc))

    root = importlib.import_module(package)
    modules = [package] + [m.name for m in pkgutil.walk_packages(getattr(root, "__path__", []), package + ".")]
    for module in modules:
        if not any(part.startswith("_") for part in module.split(".")):  # __main__ too: importing it would run it
            read(module, importlib.import_module(module))
            for attr, obj in vars(importlib.import_module(module)).items():  # compiled functions, which autodoc shows
                if not attr.startswith("_") and hasattr(obj, "py_func") and obj.py_func.__module__ == module:
                    read(f"{module}.{attr}", obj.py_func)
    objects = api_check.public_objects(package)
    for dotted in objects:
        module, _, name = dotted.rpartition(".")
        obj = getattr(importlib.import_module(module), name)
        read(dotted, obj)
        for attr, member in (vars(obj).items() if inspect.isclass(obj) else ()):
            function = member if isinstance(member, property) else getattr(member, "__func__", member)
            function = getattr(function, "func", function)  # functools.cached_property
            if (not attr.startswith("_") or attr == "__init__") and (
                    inspect.isfunction(function) or isinstance(function, property)):
                read(f"{dotted}.{attr}", function)
    return found


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

