"""The checks every contact-law material makes of its fields: booleans where a flag is meant, finite numbers
elsewhere, and the sign each number must have -- one ``ValueError`` naming the field, the value and the rule."""

from __future__ import annotations

import math
from dataclasses import MISSING, fields

import numpy as np


def check_fields(material, section: str, positive: dict, nonnegative: dict, flags=()) -> None:
    """Raise for the first field of the dataclass ``material`` that is not a finite number (or a bool, for the names
    in ``flags``), or breaks its sign: ``positive``/``nonnegative`` map field names to their units.

    Parameters
    ----------
    material : object
        A contact-law material (a dataclass instance).
    section : str
        The table its fields are named under in the message (``"contact"``).
    positive : dict
        ``{field name: unit}`` of the fields that must be > 0 (the unit, or ``""``, follows the rule in the message).
    nonnegative : dict
        ``{field name: unit}`` of the fields that must be >= 0.
    flags : sequence of str
        The fields that must be booleans.

    Raises
    ------
    ValueError
        The first field that breaks its rule, named as ``<section>.<field>``.
    """
    for f in fields(material):
        value = getattr(material, f.name)
        if f.name in flags:
            if not isinstance(value, (bool, np.bool_)):
                raise ValueError(f"{section}.{f.name} = {value!r}: must be true or false")
        elif (not isinstance(value, (int, float, np.floating, np.integer)) or isinstance(value, bool)
              or not math.isfinite(value)):
            raise ValueError(f"{section}.{f.name} = {value!r}: must be a finite number")
    for limits, bound in ((positive, "> 0"), (nonnegative, ">= 0")):
        for name, unit in limits.items():
            value = getattr(material, name)
            if value < 0 or (value == 0 and bound == "> 0"):
                raise ValueError(f"{section}.{name} = {value!r}: must be {bound}{f' ({unit})' if unit else ''}")


def material_from_table(cls, law: str, values: dict):
    """The material ``cls`` of the contact law ``law`` from a scene's ``[contact]`` values (without ``law``): every
    field without a default required, no other; a bad value is reported as ``[contact] name = value: rule``.

    Parameters
    ----------
    cls : type
        The law's material dataclass.
    law : str
        The law's name, in messages.
    values : dict
        The ``[contact]`` table without ``law`` (SI units).

    Returns
    -------
    object
        The material.

    Raises
    ------
    ValueError
        An unknown or missing key, or a bad value.
    """
    names = [f.name for f in fields(cls)]
    extra = sorted(set(values) - set(names))
    if extra:
        raise ValueError(f"[contact] {extra[0]}: not a parameter of law = \"{law}\" (its parameters: "
                         f"{', '.join(names)})")
    required = [f.name for f in fields(cls) if f.default is MISSING]
    missing = [name for name in required if name not in values]
    if missing:
        raise ValueError(f"[contact] {missing[0]}: required (law = \"{law}\" needs {', '.join(required)})")
    try:
        return cls(**values)
    except ValueError as exc:
        msg = str(exc)
        raise ValueError(f"[contact] {msg[len('contact.'):]}" if msg.startswith("contact.") else msg) from None
