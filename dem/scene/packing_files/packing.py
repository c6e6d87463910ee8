"""The packing a file holds, in SI units (:class:`Packing`), what every reader and writer of
:mod:`dem.scene.packing_files` shares with it, and the one-line error of a bad file (:class:`FileError`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

FORMATS = ("csv", "lammps-data", "lammps-dump", "vtk", "parts")
AXES = "xyz"
SPHERE_VOLUME = 4.0 * math.pi / 3.0


@dataclass(frozen=True)
class Packing:
    """N spheres read from a file (SI units). ``id`` (N,) int; ``position`` (N, 3) m; ``radius`` (N,) m; the
    optional per-particle arrays are None where the file has no such column: ``temperature`` (N,), ``fixed`` (N,)
    bool, ``material`` (N,) an index from 0 (int) or a material's name (str), ``density`` (N,) kg/m^3, ``velocity``
    and ``angular_velocity`` (N, 3), ``image`` (N, 3) int, the periodic images (LAMMPS image flags).
    ``box_lo``, ``box_hi`` (3,) m: the box, where the file gives one; ``periodic``: its periodic axes (3 bools), None
    where the file cannot say. ``source`` the file, ``format`` its format, ``timestep`` that of a dump's snapshot,
    ``units`` the LAMMPS unit style the file records (converted from), ``ignored`` the columns or fields that were
    not read.

    Parameters
    ----------
    id : numpy.ndarray
        (N,) int, the particles' ids.
    position : numpy.ndarray
        (N, 3) centres (m).
    radius : numpy.ndarray
        (N,) radii (m).
    temperature : numpy.ndarray or None
        (N,) temperatures (the scene's unit, K or degC); None where the file has none.
    fixed : numpy.ndarray or None
        (N,) bool, True for a particle held at its temperature; None where the file has no such column.
    material : numpy.ndarray or None
        (N,) material indices from 0 (int) or material names (str); None where the file has none.
    density : numpy.ndarray or None
        (N,) densities (kg/m^3); None where the file has none.
    velocity : numpy.ndarray or None
        (N, 3) velocities (m/s); None where the file has none.
    angular_velocity : numpy.ndarray or None
        (N, 3) angular velocities (rad/s); None where the file has none.
    image : numpy.ndarray or None
        (N, 3) int, LAMMPS image flags: the periods by which a wrapped centre was moved; None where the file has
        none.
    box_lo, box_hi : numpy.ndarray or None
        (3,) lower and upper corners of the box (m); None where the file gives no box.
    periodic : tuple or None
        Three bools, the box's periodic axes; None where the file cannot say.
    source : str
        The file read (its path as given).
    format : str
        The file's format, one of ``FORMATS``.
    timestep : int or None
        The timestep of a dump's snapshot; None for other files.
    units : str or None
        The LAMMPS unit style the file records (converted from to SI), a key of ``LAMMPS_UNITS``; None where
        it records none.
    ignored : tuple
        The names of the columns or fields that were not read.
    """

    id: np.ndarray
    position: np.ndarray
    radius: np.ndarray
    temperature: np.ndarray | None = None
    fixed: np.ndarray | None = None
    material: np.ndarray | None = None
    density: np.ndarray | None = None
    velocity: np.ndarray | None = None
    angular_velocity: np.ndarray | None = None
    image: np.ndarray | None = None
    box_lo: np.ndarray | None = None
    box_hi: np.ndarray | None = None
    periodic: tuple | None = None
    source: str = ""
    format: str = ""
    timestep: int | None = None
    units: str | None = None
    ignored: tuple = field(default=())

    @property
    def n(self) -> int:
        """Number of particles."""
        return len(self.radius)

    def periodic_box(self, axes=None, drop=None):
        """The file's box as a :class:`dem.geometry.periodic.PeriodicBox`, periodic along ``axes`` (default: the file's
        periodic axes); ``drop`` the temperature drop per period. ``ValueError`` when the file gives no box.

        Parameters
        ----------
        axes : sequence of bool or None
            Three bools, the periodic axes; None: the file's (none where it cannot say).
        drop : array_like or None
            (3,) the temperature drop per period along each axis (K); None: zero.

        Returns
        -------
        dem.geometry.periodic.PeriodicBox
            The box from ``box_lo`` with lengths ``box_hi - box_lo`` (m).

        Raises
        ------
        ValueError
            The file gives no box.
        """
        from dem.geometry.periodic import PeriodicBox

        if self.box_lo is None:
            raise ValueError(f"{self.source}: gives no box (a LAMMPS data file or dump does)")
        if axes is None:
            axes = self.periodic if self.periodic is not None else (False, False, False)
        return PeriodicBox(self.box_hi - self.box_lo, tuple(axes), self.box_lo, drop)


class FileError(ValueError):
    """A bad file: one line naming the file, the line and the column.

    Parameters
    ----------
    path : str or pathlib.Path
        The file.
    message : str
        What is wrong.
    line : int or None
        The line number in the file (from 1); None where not about one line.
    column : int or None
        The column number (from 1); None where not about one column.
    name : str or None
        The column's name, given after its number; None for none.
    """

    def __init__(self, path, message: str, line: int | None = None, column: int | None = None,
                 name: str | None = None):
        where = [str(path)]
        if line is not None:
            where.append(f"line {line}")
        if column is not None:
            where.append(f"column {column}" + (f" ({name})" if name else ""))
        super().__init__(f"{', '.join(where)}: {message}")


def scaled(p: Packing, unit: float) -> Packing:
    """``p`` with its lengths (and velocities) multiplied by ``unit``; densities are kg/m^3 already.

    Parameters
    ----------
    p : Packing
        A packing as read, in the file's length unit.
    unit : float
        Metres per length unit of the file.

    Returns
    -------
    Packing
        The packing in metres (``p`` itself where ``unit`` is 1).
    """
    if unit == 1.0:
        return p
    scale = {k: getattr(p, k) * unit for k in ("position", "radius", "velocity", "box_lo", "box_hi")
             if getattr(p, k) is not None}
    return replace(p, **scale)


def density_from_mass(mass: np.ndarray, radius_m: np.ndarray) -> np.ndarray:
    """kg/m^3 of spheres of ``mass`` kg and radius ``radius_m`` m (how LAMMPS's atom_style sphere relates them).

    Parameters
    ----------
    mass : numpy.ndarray
        (N,) masses (kg).
    radius_m : numpy.ndarray
        (N,) radii (m).

    Returns
    -------
    numpy.ndarray
        (N,) densities (kg/m^3).
    """
    return mass / (SPHERE_VOLUME * radius_m**3)
