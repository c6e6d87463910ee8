"""The specimen of a steady run's effective conductivity ``k_eff = Q L / (A dT)``: its two ends, held at different
temperatures, and the length ``L`` and cross-section ``A`` between them.

An end is a wall with a temperature or a group of held particles (``fixed``; a named group of the scene, else the
held particles of one temperature, named ``held at T``). A static scene whose generator made no specimen gets one
wherever it has exactly two ends at different temperatures (:func:`find_specimen`):

* two walls facing each other along an axis: ``L`` the distance between their planes;
* a wall and a group: ``L`` the distance from the wall's plane to the group's mean centre along the wall's normal;
* two groups: along the axis their mean centres lie furthest apart (each group on its own side: their centres do
  not interleave along it), ``L`` the distance between those mean centres (the held particles are isothermal, so
  the temperature drops between their centres).

``A``: along each other axis the period of a periodic box, else the extent between two walls facing each other
along it (the walls of a saved state), else the particles' extent (their outermost surfaces). ``Q`` is the heat
that leaves the hot end (:func:`dem.engines.static.effective_conductivity`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from dem.geometry.periodic import AXES
from dem.geometry.walls import axis_of, box_axes, extent


@dataclass(frozen=True)
class Specimen:
    """Length L (m) and cross-section A (m^2) for ``k_eff = Q L/(A dT)``, the hot and cold temperatures, the
    ``axis`` (0, 1, 2) along which heat flows, and the ends: ``hot_end``/``cold_end`` are ``("wall", name)`` or
    ``("group", name)`` (the held group of :func:`held_groups`). ``periodic``: instead, the period's face normal to
    z, across which the temperature drops by ``hot - cold``.

    Parameters
    ----------
    length : float
        L, the distance between the two ends along ``axis`` (m).
    area : float
        A, the cross-section normal to ``axis`` (m^2), from :func:`cross_section`.
    hot : float
        Temperature of the hot end (the scene's unit, K or degC).
    cold : float
        Temperature of the cold end (same unit); ``hot - cold`` is the dT of ``k_eff``.
    hot_end : tuple
        The hot end, ``("wall", name)`` or ``("group", name)``.
    cold_end : tuple
        The cold end, in the same form.
    periodic : bool
        True where the specimen is the period itself (the temperature drops by ``hot - cold`` across it), not two
        ends.
    axis : int
        The axis along which heat flows: 0, 1 or 2 (x, y, z).
    """

    length: float
    area: float
    hot: float
    cold: float
    hot_end: tuple = ("wall", "hot")
    cold_end: tuple = ("wall", "cold")
    periodic: bool = False
    axis: int = 2

    def describe(self) -> dict:
        """What the summary says of the specimen: its axis, length (m), area (m^2) and ends."""
        if self.periodic:
            ends = {"hot": "period", "cold": "period"}
        else:
            ends = {"hot": " ".join(self.hot_end), "cold": " ".join(self.cold_end)}
        return {"axis": AXES[self.axis], "length": float(self.length), "area": float(self.area), **ends}


def held_name(temperature: float) -> str:
    """The name of the held particles of one temperature that no named group holds.

    Parameters
    ----------
    temperature : float
        The temperature the particles are held at (the scene's unit, K or degC).

    Returns
    -------
    str
        ``"held at T"``, with T to ten significant digits.
    """
    return f"held at {temperature:.10g}"


def held_groups(particles, named: dict | None = None) -> dict[str, np.ndarray]:
    """The groups of held (``fixed``) particles, ``{name: indices}``: every named group (``named``: ``{name:
    indices}``) whose particles are all held, then the other held particles by temperature (:func:`held_name`).

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles (their ``fixed`` flags and temperatures are read).
    named : dict or None
        The scene's named groups, ``{name: indices}`` (indices into ``particles``); None for none.

    Returns
    -------
    dict
        ``{name: indices}`` of every held group, named groups first.
    """
    fixed = np.asarray(particles.fixed, dtype=bool)
    out, taken = {}, np.zeros(len(fixed), dtype=bool)
    for name, idx in (named or {}).items():
        idx = np.asarray(idx, dtype=np.int64)
        if len(idx) and np.all(fixed[idx]):
            out[name] = idx
            taken[idx] = True
    rest = np.flatnonzero(fixed & ~taken)
    T = particles.temperature[rest]
    for value in np.unique(T):
        out[held_name(float(value))] = rest[T == value]
    return out


def group_flows(groups: dict, into: dict) -> dict[str, float]:
    """The heat flow (W) into each held group: the sum over its particles of ``into`` (``{index: W}``).

    Parameters
    ----------
    groups : dict
        The held groups, ``{name: indices}`` (:func:`held_groups`).
    into : dict
        The heat flow into each held particle, ``{index: W}``; every index of ``groups`` must be a key.

    Returns
    -------
    dict
        ``{name: W}``, the total heat flow into each group (W).
    """
    return {name: float(sum(into[int(k)] for k in idx)) for name, idx in groups.items()}


def find_specimen(particles, walls, box=None, named: dict | None = None, bounds=(), span=None) -> Specimen | None:
    """The specimen between the scene's two ends (module docstring), or None where it has not exactly two ends
    at different temperatures that face each other along an axis. ``walls``: the scene's walls (those with a
    temperature are ends); ``box``: its :class:`dem.geometry.periodic.PeriodicBox` or None; ``named``: its named
    groups ``{name: indices}``; ``bounds``: walls that only bound the cross-section (a saved state's); ``span``:
    the whole packing's extent where ``particles`` are a part of it.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles (positions in m, temperatures, ``fixed`` flags).
    walls : sequence of dem.geometry.walls.Wall
        The scene's walls; those with a temperature are ends.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box, whose periods give the cross-section along periodic axes; None without one.
    named : dict or None
        The scene's named groups, ``{name: indices}``; None for none.
    bounds : sequence of dem.geometry.walls.Wall
        Walls that only bound the cross-section (a saved state's), not ends.
    span : tuple or None
        ``(lo, hi)``, (3,) each: the extent of the packing's surfaces (m), where ``particles`` are only a part of
        it (:mod:`dem.scene.packing_files.parts`); None: that of ``particles``.

    Returns
    -------
    Specimen or None
        The specimen, or None where the scene has not exactly two ends at different temperatures facing each other
        along an axis a positive length apart.
    """
    ends = [("wall", w.name, float(w.temperature), w) for w in walls if w.temperature is not None]
    for name, idx in held_groups(particles, named).items():
        T = np.unique(particles.temperature[idx])
        if len(T) == 1:
            ends.append(("group", name, float(T[0]), idx))
    if len(ends) != 2 or ends[0][2] == ends[1][2]:
        return None
    hot, cold = sorted(ends, key=lambda e: -e[2])
    axis = _axis(hot, cold, particles.position)
    if axis is None:
        return None
    length = abs(_where(hot, axis, particles.position) - _where(cold, axis, particles.position))
    if not length > 0:
        return None
    return Specimen(length, cross_section(particles, axis, box, bounds, span), hot[2], cold[2], hot[:2], cold[:2],
                    axis=axis)


def _axis(hot, cold, x: np.ndarray) -> int | None:
    """The axis between two ends: a wall's normal (two walls facing each other), else the axis along which two
    groups' mean centres lie furthest apart, the groups not interleaving along it."""
    walls = [e[3] for e in (hot, cold) if e[0] == "wall"]
    if walls:
        axis = axis_of(walls[0].normal)
        if axis is None or (len(walls) == 2 and not np.allclose(walls[0].normal, -walls[1].normal, atol=1e-12)):
            return None
        return axis
    a, b = x[hot[3]], x[cold[3]]
    axis = int(np.argmax(np.abs(a.mean(axis=0) - b.mean(axis=0))))
    apart = a[:, axis].max() < b[:, axis].min() or b[:, axis].max() < a[:, axis].min()
    return axis if apart else None


def _where(end, axis: int, x: np.ndarray) -> float:
    """An end's place along ``axis``: a wall's plane, a group's mean centre."""
    return float(end[3].point[axis]) if end[0] == "wall" else float(x[end[3], axis].mean())


def cross_section(particles, axis: int, box=None, bounds=(), span=None) -> float:
    """The area (m^2) normal to ``axis``: along each other axis the box's period, else the extent between the
    ``bounds`` walls facing each other along it, else the particles' extent.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The particles, whose outermost surfaces give the extent along an axis nothing else bounds (m).
    axis : int
        The axis the cross-section is normal to: 0, 1 or 2 (x, y, z).
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box, whose period (m) is the extent along each periodic axis; None without one.
    bounds : sequence of dem.geometry.walls.Wall
        Walls bounding the cross-section; two facing each other along an axis give its extent there.
    span : tuple or None
        ``(lo, hi)``, (3,) each: the extent of the particles' outermost surfaces (m); None: from ``particles``.

    Returns
    -------
    float
        The cross-section's area (m^2).
    """
    walls = list(bounds)
    pairs = box_axes(walls)
    offsets = np.array([w.offset for w in walls])
    area = 1.0
    for a in range(3):
        if a == axis:
            continue
        if box is not None and box.periodic[a]:
            area *= float(box.lengths[a])
        elif a in pairs:
            area *= extent(offsets, *pairs[a])
        elif span is not None:
            area *= float(span[1][a] - span[0][a])
        else:
            x, r = particles.position[:, a], particles.radius
            area *= float(np.max(x + r) - np.min(x - r))
    return area
