r"""Particle state as arrays (structure of arrays): the lumped capacities of the pipe network.

Rojek, Kasztelan & Tharmaraj 2022, Section 2: every particle is a lumped capacity :math:`C_i = m_i c` (eq. 1) at its
centre with one temperature :math:`T_i`. The mass is :math:`m_i = \rho \frac{4}{3} \pi r_i^3`: the volume-conserving
neck (Section 4.2) moves material from the caps into the neck, so the sphere volume stays exact.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


# Magnitudes the network stays representable for (C_i T_i, K_ij dT and their sums finite in double precision); each
# range is far wider than any sintered powder, and a value outside is refused with the range in the message.
RADIUS_RANGE = (1e-12, 1e6)            # m
POSITION_MAX = 1e12                    # m, |x|, |y|, |z|
TEMPERATURE_MAX = 1e12                 # |T| in the scene's unit (K or C)
PROPERTY_RANGE = (1e-10, 1e10)         # conductivity W/(m K), density kg/m^3, specific heat J/(kg K)


def check_range(name: str, arr: np.ndarray, low: float | None, high: float, what: str = "") -> np.ndarray:
    """Raise ``ValueError`` naming the first entry outside ``[low, high]`` (``|value| <= high`` when ``low`` is
    None) and the valid range.

    Parameters
    ----------
    name : str
        The array's name in the error message (``"particles.radius"``, say).
    arr : numpy.ndarray
        The values, any shape (any unit).
    low : float or None
        The smallest valid value; None: ``|value| <= high`` instead.
    high : float
        The largest valid value (or magnitude, where ``low`` is None).
    what : str
        Text after the range in the message (its unit, e.g. ``" m"``).

    Returns
    -------
    numpy.ndarray
        ``arr``, unchanged.

    Raises
    ------
    ValueError
        An entry lies outside the range.
    """
    bad = (np.abs(arr) > high) if low is None else ((arr < low) | (arr > high))
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        where = "".join(f"[{i}]" for i in np.unravel_index(k, np.shape(arr)))
        valid = f"|value| <= {high:g}" if low is None else f"{low:g} <= value <= {high:g}"
        raise ValueError(f"{name}{where} = {np.ravel(arr)[k]:.9g}: outside the valid range {valid}{what}")
    return arr


def check_vector(name: str, value) -> np.ndarray:
    """``value`` as a finite 3-vector of at most POSITION_MAX per component, else ``ValueError`` naming it.

    Parameters
    ----------
    name : str
        The vector's name in the error message (``"particles.radius"``, say).
    value : array_like
        The vector [x, y, z] (m).

    Returns
    -------
    numpy.ndarray
        (3,) floats.

    Raises
    ------
    ValueError
        ``value`` is not a finite 3-vector, or a component exceeds ``POSITION_MAX``.
    """
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        v = np.full(1, np.nan)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} = {value!r}: must be a finite 3-vector")
    return check_range(name, v, None, POSITION_MAX, " m")


def check_unit_vector(name: str, value) -> np.ndarray:
    """``value`` as a unit 3-vector (a finite, non-zero 3-vector, normalised), else ``ValueError`` naming it.

    Parameters
    ----------
    name : str
        The vector's name in the error message (``"particles.radius"``, say).
    value : array_like
        The direction [x, y, z] (any length).

    Returns
    -------
    numpy.ndarray
        (3,) the unit vector.

    Raises
    ------
    ValueError
        ``value`` is not a finite, non-zero 3-vector.
    """
    v = check_vector(name, value)
    if np.linalg.norm(v) == 0.0:
        raise ValueError(f"{name} = {value!r}: must be a finite non-zero 3-vector")
    return v / np.linalg.norm(v)


def check_temperature(name: str, value) -> float:
    """``value`` as a finite temperature within ``TEMPERATURE_MAX``, else ``ValueError`` naming it.

    Parameters
    ----------
    name : str
        The temperature's name in the error message (``"particles.radius"``, say).
    value : float
        The temperature (the scene's unit, K or degC).

    Returns
    -------
    float
        ``value`` as a float.

    Raises
    ------
    ValueError
        ``value`` is not a finite number, or its magnitude exceeds ``TEMPERATURE_MAX``.
    """
    if not isinstance(value, (int, float)) or isinstance(value, bool) or not np.isfinite(value):
        raise ValueError(f"{name} = {value!r}: must be a finite number")
    return float(check_range(name, np.float64(value), None, TEMPERATURE_MAX))


def finite_array(name: str, value, shape_tail=(), dtype=float) -> np.ndarray:
    """``value`` as an array of rank ``1 + len(shape_tail)`` with the given trailing shape and finite entries.

    Parameters
    ----------
    name : str
        The array's name in the error message (``"particles.radius"``, say).
    value : array_like
        The values (any unit).
    shape_tail : tuple of int
        The shape after the first axis (``(3,)`` for a list of 3-vectors; ``()`` for a list of numbers).
    dtype : type
        The array's dtype.

    Returns
    -------
    numpy.ndarray
        The array.

    Raises
    ------
    ValueError
        ``value`` is not numeric, has another shape, or has an entry that is not finite.
    """
    try:
        arr = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{name}: must be a list of numbers{' of length ' + str(shape_tail[0]) if shape_tail else ''}"
                         f" ({exc})") from None
    if arr.ndim != 1 + len(shape_tail) or tuple(arr.shape[1:]) != tuple(shape_tail):
        want = "a list of numbers" if not shape_tail else f"a list of {shape_tail[0]}-vectors"
        raise ValueError(f"{name}: must be {want}, got shape {arr.shape}")
    if arr.dtype.kind == "f" and not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ValueError(f"{name}[{bad[0]}] = {arr[tuple(bad)]}: must be finite")
    return arr


def check_positive_entries(name: str, arr: np.ndarray, allow_zero: bool = False) -> np.ndarray:
    """Raise ``ValueError`` naming the first entry that is not ``> 0`` (or ``>= 0``).

    Parameters
    ----------
    name : str
        The array's name in the error message (``"particles.radius"``, say).
    arr : numpy.ndarray
        The values (any unit).
    allow_zero : bool
        Whether 0 is valid.

    Returns
    -------
    numpy.ndarray
        ``arr``, unchanged.

    Raises
    ------
    ValueError
        An entry is not ``> 0`` (``>= 0`` with ``allow_zero``).
    """
    bad = arr < 0.0 if allow_zero else arr <= 0.0
    if np.any(bad):
        k = int(np.flatnonzero(bad)[0])
        raise ValueError(f"{name}[{k}] = {arr.flat[k]:.9g}: must be {'>= 0' if allow_zero else '> 0'}")
    return arr


@dataclass(frozen=True)
class Material:
    r"""Thermal properties of one material (SI units): conductivity :math:`\kappa` in W/(m K), density in kg/m^3, ``c``
    in J/(kg K); the electrical conductivity :math:`\sigma` in S/m for electrical physics.

    Parameters
    ----------
    conductivity : float or None
        Thermal conductivity :math:`\kappa` (W/(m K)); None for a scene without thermal physics.
    density : float
        Density :math:`\rho` (kg/m^3).
    specific_heat : float or None
        Specific heat c (J/(kg K)); None for a scene without thermal physics.
    name : str
        The material's name (in messages and ``[[groups]] material``).
    electrical_conductivity : float or None
        Electrical conductivity :math:`\sigma` (S/m), for electrical physics; None: none.

    Raises
    ------
    ValueError
        A property given is not a finite number > 0 within ``PROPERTY_RANGE``, or the density is missing.
    """

    conductivity: float | None
    density: float
    specific_heat: float | None
    name: str = "material"
    electrical_conductivity: float | None = None

    def __post_init__(self):
        for key in ("conductivity", "density", "specific_heat", "electrical_conductivity"):
            value = getattr(self, key)
            if value is None and key != "density":  # a scene without thermal physics needs only the density
                continue
            if not isinstance(value, (int, float)) or isinstance(value, bool) or not np.isfinite(value) or value <= 0:
                raise ValueError(f"material {self.name!r}: {key} = {value!r}: must be a finite number > 0")
            check_range(f"material {self.name!r}: {key}", np.float64(value), *PROPERTY_RANGE)


COPPER = Material(394.0, 8960.0, 385.0, "copper")


@dataclass(frozen=True)
class Particles:
    """N spheres: ``position`` (N, 3) m, ``radius`` (N,) m, ``temperature`` (N,), ``material`` (N,) index into
    ``materials``, ``fixed`` (N,) bool (held at the initial temperature), ``heat`` (N,) internal heat W (eq. 3),
    ``id`` (N,) the particles' ids (integers >= 0, unique; 0..N-1 unless given, e.g. by a packing file), written
    to the outputs.

    Build with :meth:`from_arrays`, which validates every array and names the first bad entry.

    Parameters
    ----------
    position : numpy.ndarray
        (N, 3) centres (m).
    radius : numpy.ndarray
        (N,) radii (m).
    temperature : numpy.ndarray
        (N,) temperatures (the scene's unit, K or degC).
    material : numpy.ndarray
        (N,) int, each particle's index into ``materials``.
    fixed : numpy.ndarray
        (N,) bool, True for a particle held at its initial temperature.
    heat : numpy.ndarray
        (N,) internal heat source of each particle (W, eq. 3).
    materials : tuple of Material
        The materials.
    id : numpy.ndarray or None
        (N,) int, the particles' ids; None: 0..N-1.
    """

    position: np.ndarray
    radius: np.ndarray
    temperature: np.ndarray
    material: np.ndarray
    fixed: np.ndarray
    heat: np.ndarray
    materials: tuple = field(default=(COPPER,))
    id: np.ndarray = None

    def __post_init__(self):
        if self.id is None:
            object.__setattr__(self, "id", np.arange(len(self.radius), dtype=np.int64))

    @classmethod
    def from_arrays(cls, position, radius, temperature, materials=(COPPER,), material=None, fixed=None,
                    heat=None, prefix: str = "particles", id=None) -> "Particles":
        """Validated particle state; ``material`` defaults to 0, ``fixed`` to False, ``heat`` to 0 W, ``id`` to
        0..N-1.

        Parameters
        ----------
        position : array_like
            (N, 3) centres (m), N >= 1, each component within ``POSITION_MAX``.
        radius : array_like
            (N,) radii (m), within ``RADIUS_RANGE``.
        temperature : array_like
            (N,) temperatures (the scene's unit, K or degC), within ``TEMPERATURE_MAX``.
        materials : Material or sequence of Material
            The materials (at least one).
        material : array_like or None
            (N,) int, each particle's index into ``materials``; None: all 0.
        fixed : array_like or None
            (N,) bool, True for a particle held at its temperature; None: none held.
        heat : array_like or None
            (N,) internal heat source of each particle (W); None: none.
        prefix : str
            The table the arrays come from, in error messages (``"[particles]"``, say).
        id : array_like or None
            (N,) int, unique ids >= 0; None: 0..N-1.

        Returns
        -------
        Particles
            The validated particles.

        Raises
        ------
        ValueError
            An array has a bad shape, length or entry (the first is named), or a heat capacity is not finite and
            positive.
        """
        sep = " " if prefix.startswith("[") else "."
        if isinstance(materials, Material):
            materials = (materials,)
        materials = tuple(materials)
        if not materials:
            raise ValueError("materials: at least one material is required")
        pos = finite_array(f"{prefix}{sep}position", position, (3,))
        n = len(pos)
        if n == 0:
            raise ValueError(f"{prefix}{sep}position: at least one particle is required")
        check_range(f"{prefix}{sep}position", pos, None, POSITION_MAX, " m")
        rad = check_positive_entries(f"{prefix}{sep}radius", finite_array(f"{prefix}{sep}radius", radius))
        check_range(f"{prefix}{sep}radius", rad, *RADIUS_RANGE, " m")
        temp = check_range(f"{prefix}{sep}temperature", finite_array(f"{prefix}{sep}temperature", temperature),
                           None, TEMPERATURE_MAX)
        mat = np.zeros(n, dtype=np.int64) if material is None else finite_array(f"{prefix}{sep}material", material,
                                                                                dtype=np.int64)
        fix = np.zeros(n, dtype=bool) if fixed is None else _bool_array(f"{prefix}{sep}fixed", fixed)
        q = np.zeros(n) if heat is None else finite_array(f"{prefix}{sep}heat", heat)
        ids = np.arange(n, dtype=np.int64) if id is None else finite_array(f"{prefix}{sep}id", id, dtype=np.int64)
        for key, arr in (("radius", rad), ("temperature", temp), ("material", mat), ("fixed", fix), ("heat", q),
                         ("id", ids)):
            if len(arr) != n:
                raise ValueError(f"{prefix}{sep}{key} has {len(arr)} entries but {prefix}{sep}position has {n}")
        if np.any((mat < 0) | (mat >= len(materials))):
            k = int(np.flatnonzero((mat < 0) | (mat >= len(materials)))[0])
            raise ValueError(f"{prefix}{sep}material[{k}] = {mat[k]}: must index one of {len(materials)} material(s)")
        _check_ids(f"{prefix}{sep}id", ids)
        out = cls(pos, rad, temp, mat, fix, q, materials, ids)
        if any(m.specific_heat is None for m in materials):
            return out  # no thermal physics: no capacities to check
        cap = out.capacity
        bad = ~np.isfinite(cap) | (cap <= 0)
        if np.any(bad):
            k = int(np.flatnonzero(bad)[0])
            raise ValueError(f"{prefix}{sep}radius[{k}] = {rad[k]:.6g}: gives a heat capacity of {cap[k]:.6g} J/K, "
                             f"which is not a finite positive number")
        return out

    @property
    def n(self) -> int:
        """Number of particles."""
        return len(self.radius)

    def _property(self, key: str, physics: str = "thermal") -> np.ndarray:
        values = [getattr(m, key) for m in self.materials]
        if any(v is None for v in values):
            name = next(m.name for m in self.materials if getattr(m, key) is None)
            raise ValueError(f"material {name!r}: {key} is required for {physics} physics")
        return np.array(values, dtype=float)[self.material]

    @property
    def conductivity(self) -> np.ndarray:
        """Thermal conductivity of each particle's material (n,), W/(m K)."""
        return self._property("conductivity")

    @property
    def electrical_conductivity(self) -> np.ndarray:
        r"""Electrical conductivity :math:`\sigma` of each particle, S/m."""
        return self._property("electrical_conductivity", "electrical")

    @property
    def volume(self) -> np.ndarray:
        """Volume of each sphere (n,), m^3."""
        with np.errstate(over="ignore", under="ignore"):
            return 4.0 / 3.0 * np.pi * self.radius**3

    @property
    def mass(self) -> np.ndarray:
        r""":math:`m_i = \rho \frac{4}{3} \pi r_i^3`, kg."""
        return self._property("density") * self.volume

    @property
    def capacity(self) -> np.ndarray:
        """``C_i = m_i c`` (Rojek 2022, eq. 1), J/K."""
        return self.mass * self._property("specific_heat")

    def permuted(self, order: np.ndarray) -> "Particles":
        """The same particles in the order ``order`` (used to test independence from ordering).

        Parameters
        ----------
        order : numpy.ndarray
            (N,) int, a permutation of 0..N-1.

        Returns
        -------
        Particles
            The particles, ``k``-th the ``order[k]``-th of these.
        """
        return Particles(self.position[order], self.radius[order], self.temperature[order], self.material[order],
                         self.fixed[order], self.heat[order], self.materials, self.id[order])


def material_indices(name: str, value, materials, n: int) -> list | None:
    """The indices into ``materials`` of ``value``: a material's name or index, or a list (or array) of them for
    ``n`` particles; None stays None (material 0). Indices are range-checked by :meth:`Particles.from_arrays`.

    Parameters
    ----------
    name : str
        The key's name in error messages (``"[particles] material"``, say).
    value : str or int or list or numpy.ndarray or None
        A material's name or index, or one per particle.
    materials : sequence of Material
        The materials the names refer to.
    n : int
        The number of particles a single name or index is given to.

    Returns
    -------
    list of int or None
        The indices, or None where ``value`` is None.

    Raises
    ------
    ValueError
        An unknown name, or an entry that is neither a name nor an integer.
    """
    if value is None:
        return None
    names = [m.name for m in materials]
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (str, int)) and not isinstance(value, bool):
        value = [value] * n
    if not isinstance(value, list):
        raise ValueError(f"{name}: must be a material name/index or a list of them")
    out = []
    for k, v in enumerate(value):
        if isinstance(v, str):
            if v not in names:
                raise ValueError(f"{name}[{k}] = {v!r}: unknown (materials: {', '.join(names)})")
            out.append(names.index(v))
        elif isinstance(v, int) and not isinstance(v, bool):
            out.append(v)
        else:
            raise ValueError(f"{name}[{k}] = {v!r}: must be a material name or index")
    return out


def _check_ids(name: str, ids: np.ndarray) -> None:
    """Raise ``ValueError`` naming the first id that is negative or given twice."""
    if np.any(ids < 0):
        k = int(np.flatnonzero(ids < 0)[0])
        raise ValueError(f"{name}[{k}] = {ids[k]}: must be >= 0")
    order = np.argsort(ids, kind="stable")
    twice = np.flatnonzero(np.diff(ids[order]) == 0)
    if twice.size:
        k = int(order[twice[0] + 1])
        raise ValueError(f"{name}[{k}] = {ids[k]}: given to particle {int(order[twice[0]])} already; ids must be "
                         "unique")


def _bool_array(name: str, value) -> np.ndarray:
    arr = np.asarray(value)
    if arr.ndim != 1 or (arr.size and arr.dtype != bool):
        raise ValueError(f"{name}: must be a list of true/false")
    return arr.astype(bool)
