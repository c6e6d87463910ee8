"""Named groups of particles (``[[groups]]``), as LAMMPS users make them with ``region`` and ``group``: particles
chosen by where their centres lie, by id, by type or as the top or bottom layer, and what the scene gives them.

A group's particles are those its selectors all choose (several selectors: the particles every one chooses, as
LAMMPS's ``group ... intersect``):

* ``region``: the particles whose centres lie in it (LAMMPS's rule): ``"slab"`` (``axis``, ``lo`` and/or ``hi``,
  m, along it), ``"box"`` (``lo``, ``hi``: corners [x, y, z], m), ``"sphere"`` (``center``, ``radius``),
  ``"cylinder"`` (``axis``, ``center`` a point of its axis, ``radius``; optional ``lo``, ``hi`` along the axis);
* ``ids``: particle ids and inclusive ranges ``[first, last]`` (LAMMPS's ``group id 1:100``);
* ``types``: LAMMPS atom types (material index + 1, integers) or material names;
* ``layer``: ``"top"`` or ``"bottom"`` along ``axis`` (default z): the particles whose centres lie within
  ``thickness`` (m) of the highest (lowest) centre.

What it gives them, over the per-particle lists of ``[particles]`` (groups apply in order, a later one over an
earlier one): ``temperature`` (the initial one), ``fixed`` (held at it: a group that holds its particles is an end
of the effective conductivity's specimen, :mod:`dem.scene.specimen`, and has its total in ``boundary_heat_flow``),
``material`` (a name or index) and ``heat`` (W per particle). Every problem raises a one-line ``ValueError`` naming
the group and the key.
"""

from __future__ import annotations

import math

import numpy as np

from dem.geometry.particles import Particles, material_indices

REGIONS = ("slab", "box", "sphere", "cylinder")
LAYERS = ("top", "bottom")
AXES = "xyz"
SELECTORS = ("region", "ids", "types", "layer")
ACTIONS = ("temperature", "fixed", "material", "heat")


def apply_groups(tables, particles: Particles) -> tuple[Particles, dict]:
    """The particles with what the ``[[groups]]`` ``tables`` give them (module docstring), and the groups that
    hold their particles (``fixed = true``), ``{name: indices}``.

    Parameters
    ----------
    tables : list of dict
        The scene's ``[[groups]]`` tables, applied in order (a later group over an earlier one).
    particles : dem.geometry.particles.Particles
        The particles of ``[particles]``, before the groups.

    Returns
    -------
    tuple of (dem.geometry.particles.Particles, dict)
        The particles with each group's ``temperature``, ``fixed``, ``material`` and ``heat`` set, and the groups
        with ``fixed = true`` as ``{name: indices}``.

    Raises
    ------
    ValueError
        ``tables`` is not a list, or a group has no (or a repeated) name, a bad selector or a bad value; the message
        names the group and the key.
    """
    if not isinstance(tables, list):
        raise ValueError("[[groups]]: must be an array of tables")
    held, names = {}, set()
    for k, table in enumerate(tables):
        name = table.get("name")
        where = f"[groups][{k}]"
        if not isinstance(name, str) or not name:
            raise ValueError(f"{where} name: required, a string")
        where = f"[groups][{k}] ({name})"
        if name in names:
            raise ValueError(f"{where} name: used by an earlier group; names must be unique")
        names.add(name)
        chosen = select(table, particles, where)
        particles = _give(table, particles, chosen, where)
        if table.get("fixed") is True:
            held[name] = chosen
    return particles, held


def select(table: dict, particles: Particles, where: str) -> np.ndarray:
    """The indices of the particles every selector of ``table`` chooses; ``ValueError`` when it has none or they
    choose no particle.

    Parameters
    ----------
    table : dict
        One ``[[groups]]`` table; its selectors (``region``, ``ids``, ``types``, ``layer``) are read.
    particles : dem.geometry.particles.Particles
        The particles to choose from (positions in m, ids, materials).
    where : str
        The group's name in error messages (``"[groups][0] (hot)"``, say).

    Returns
    -------
    numpy.ndarray
        The indices (into ``particles``) of the chosen particles, ascending.

    Raises
    ------
    ValueError
        ``table`` has no selector, a selector is malformed, or together they choose no particle.
    """
    given = [key for key in SELECTORS if key in table]
    if not given:
        raise ValueError(f"{where}: needs a selector ({', '.join(SELECTORS)})")
    mask = np.ones(particles.n, dtype=bool)
    for key in given:
        mask &= {"region": _region, "ids": _ids, "types": _types, "layer": _layer}[key](table, particles, where)
    if not mask.any():
        raise ValueError(f"{where}: selects no particle ({', '.join(f'{k} = {table[k]!r}' for k in given)})")
    return np.flatnonzero(mask)


def _axis(table: dict, where: str, default: str | None = None) -> int:
    axis = table.get("axis", default)
    if axis not in tuple(AXES):
        raise ValueError(f"{where} axis = {axis!r}: must be \"x\", \"y\" or \"z\"")
    return AXES.index(axis)


def _number(table: dict, key: str, where: str, positive: bool = False) -> float:
    v = table.get(key)
    if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v) or (positive and v <= 0):
        raise ValueError(f"{where} {key} = {v!r}: must be a finite number{' > 0' if positive else ''} (m)")
    return float(v)


def _point(table: dict, key: str, where: str) -> np.ndarray:
    v = table.get(key)
    if (not isinstance(v, list) or len(v) != 3
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)):
        raise ValueError(f"{where} {key} = {v!r}: must be a point [x, y, z] of finite numbers (m)")
    return np.array(v, dtype=float)


def _between(x: np.ndarray, table: dict, where: str) -> np.ndarray:
    """``lo <= x <= hi`` for the bounds ``table`` gives (either may be left out: unbounded that way)."""
    lo = _number(table, "lo", where) if "lo" in table else -math.inf
    hi = _number(table, "hi", where) if "hi" in table else math.inf
    if not lo <= hi:
        raise ValueError(f"{where} lo = {lo!r}, hi = {hi!r}: must have lo <= hi")
    return (x >= lo) & (x <= hi)


def _region(table: dict, particles: Particles, where: str) -> np.ndarray:
    kind = table["region"]
    x = particles.position
    if kind == "slab":
        if "lo" not in table and "hi" not in table:
            raise ValueError(f"{where} region = \"slab\": needs lo and/or hi (m, along axis)")
        return _between(x[:, _axis(table, where)], table, where)
    if kind == "box":
        lo, hi = _point(table, "lo", where), _point(table, "hi", where)
        if np.any(lo > hi):
            raise ValueError(f"{where} region = \"box\": lo = {lo.tolist()} must lie below hi = {hi.tolist()}")
        return np.all((x >= lo) & (x <= hi), axis=1)
    if kind == "sphere":
        centre, radius = _point(table, "center", where), _number(table, "radius", where, positive=True)
        return np.sum((x - centre) ** 2, axis=1) <= radius**2
    if kind == "cylinder":
        a = _axis(table, where)
        centre, radius = _point(table, "center", where), _number(table, "radius", where, positive=True)
        across = [b for b in range(3) if b != a]
        inside = np.sum((x[:, across] - centre[across]) ** 2, axis=1) <= radius**2
        return inside & _between(x[:, a], table, where)
    raise ValueError(f"{where} region = {kind!r}: must be one of {', '.join(REGIONS)}")


def _ids(table: dict, particles: Particles, where: str) -> np.ndarray:
    value = table["ids"]
    if not isinstance(value, list) or not value:
        raise ValueError(f"{where} ids = {value!r}: must be a list of ids and [first, last] ranges")
    mask = np.zeros(particles.n, dtype=bool)
    for v in value:
        if isinstance(v, int) and not isinstance(v, bool):
            first = last = v
        elif (isinstance(v, list) and len(v) == 2 and all(isinstance(e, int) and not isinstance(e, bool) for e in v)
              and v[0] <= v[1]):
            first, last = v
        else:
            raise ValueError(f"{where} ids: entry {v!r}: must be an id or a range [first, last] with first <= last")
        mask |= (particles.id >= first) & (particles.id <= last)
    return mask


def _types(table: dict, particles: Particles, where: str) -> np.ndarray:
    value = table["types"]
    value = value if isinstance(value, list) else [value]
    names = [m.name for m in particles.materials]
    chosen = set()
    for v in value:
        if isinstance(v, str) and v in names:
            chosen.add(names.index(v))
        elif isinstance(v, int) and not isinstance(v, bool) and 1 <= v <= len(names):
            chosen.add(v - 1)
        else:
            raise ValueError(f"{where} types: {v!r}: must be a LAMMPS type 1..{len(names)} (material index + 1) or "
                             f"a material's name ({', '.join(names)})")
    return np.isin(particles.material, sorted(chosen))


def _layer(table: dict, particles: Particles, where: str) -> np.ndarray:
    side = table["layer"]
    if side not in LAYERS:
        raise ValueError(f"{where} layer = {side!r}: must be \"top\" or \"bottom\"")
    x = particles.position[:, _axis(table, where, "z")]
    t = _number(table, "thickness", where, positive=True)
    return x >= x.max() - t if side == "top" else x <= x.min() + t


def _give(table: dict, particles: Particles, chosen: np.ndarray, where: str) -> Particles:
    """``particles`` with the group's ``temperature``, ``fixed``, ``material`` and ``heat`` set on ``chosen``."""
    arrays = {key: getattr(particles, key).copy() for key in ACTIONS}
    for key in ("temperature", "heat"):
        if key in table:
            v = table[key]
            if not isinstance(v, (int, float)) or isinstance(v, bool) or not math.isfinite(v):
                raise ValueError(f"{where} {key} = {v!r}: must be a finite number "
                                 f"({'K or °C' if key == 'temperature' else 'W per particle'})")
            arrays[key][chosen] = float(v)
    if "fixed" in table:
        if not isinstance(table["fixed"], bool):
            raise ValueError(f"{where} fixed = {table['fixed']!r}: must be true or false")
        arrays["fixed"][chosen] = table["fixed"]
    if "material" in table:
        index = material_indices(f"{where} material", table["material"], particles.materials, 1)[0]
        if not 0 <= index < len(particles.materials):
            raise ValueError(f"{where} material = {index}: must index one of {len(particles.materials)} material(s)")
        arrays["material"][chosen] = index
    if not any(key in table for key in ACTIONS):
        return particles
    return Particles.from_arrays(particles.position, particles.radius, arrays["temperature"], particles.materials,
                                 arrays["material"], arrays["fixed"], arrays["heat"], prefix=where, id=particles.id)
