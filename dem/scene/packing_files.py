"""Packings from the files DEM users have, and packings written for LAMMPS.

:func:`read_packing` reads one packing of spheres into a :class:`Packing` (numpy arrays, SI units):

* ``csv`` -- a header row naming the columns ``x, y, z, radius`` (or ``diameter``), optionally ``id``,
  ``temperature``, ``fixed`` (true/false, 1/0), ``material`` (an index into the scene's materials, from 0, or a
  material's name) and ``density``; ParaView's ``Points:0``, ``Points:1``, ``Points:2`` name x, y, z. Other columns
  are ignored (listed in :attr:`Packing.ignored`); lines starting with ``#`` are comments.
* ``lammps-data`` -- a LAMMPS data file of ``atom_style sphere`` (``Atoms`` lines ``id type diameter density x y z``
  with optional image flags ``ix iy iz``; a ``Velocities`` section ``id vx vy vz wx wy wz`` is read too). The box
  is the ``xlo xhi``, ``ylo yhi``, ``zlo zhi`` header; a data file does not record which axes are periodic (LAMMPS's
  ``write_data`` writes the bounds only; the periodicity is the ``boundary`` command of the input script), so
  :attr:`Packing.periodic` is None unless ``periodic`` is given. ``type`` k becomes material index k - 1.
* ``lammps-dump`` -- a LAMMPS or LIGGGHTS text dump (``dump custom``): the last snapshot or the one at
  ``timestep``; columns ``id``, ``type``, positions ``x y z`` (or unwrapped ``xu yu zu``, scaled ``xs ys zs``,
  scaled unwrapped ``xsu ysu zsu``; unwrapped positions are wrapped into the box along its periodic axes),
  ``radius`` or ``diameter``, optional ``mass`` or ``density``, ``temperature`` (or ``T``; LIGGGHTS: ``f_Temp``),
  ``vx vy vz``, ``omegax omegay omegaz``, ``ix iy iz``. ``ITEM: BOX BOUNDS`` gives the box and, with its
  ``pp``/``ff``/``ss`` flags, the periodic axes.
* ``vtk`` -- a VTK point set (``.vtu``, ``.vtp``, legacy ``.vtk``: what LIGGGHTS, Yade, ParaView and this toolkit's
  runs write), read by VTK itself (pyvista): the points are the centres, a point field ``radius`` (Yade: ``radii``)
  or ``diameter`` the sizes, and the fields ``id``, ``temperature``, ``fixed``, ``material`` (Yade:
  ``materialId``; LIGGGHTS: ``type``, from 1), ``density`` or ``mass``, ``velocity`` (Yade: ``linVelVec``; LIGGGHTS:
  ``v``) are read where present.

* ``parts`` -- a packing in parts, a folder ``NAME.parts`` of blocks that MPI ranks read one part each
  (:mod:`dem.scene.packing_parts`; read here whole), in SI units.

The format comes from the file's name (``.csv``; ``.data``, ``.lmp`` or a name ``data.*``; ``.dump``, ``.lammpstrj``
or ``dump.*``; ``.vtu``, ``.vtp``, ``.vtk``; ``.parts``) or an explicit ``format``. Lengths are multiplied by
``length_unit`` (0.001 for a file in mm, 1e-6 in um; densities stay kg/m^3); a LAMMPS file that records its unit
style (the title line ``units = cgs`` of ``write_data``, ``ITEM: UNITS`` of a dump) is converted from it. Particles
read from LAMMPS files are sorted by id (LAMMPS writes them in the order of its processors); other files keep their
order. A bad file raises ``ValueError`` with one line naming the file, the line and the column. A file that reads
but looks wrong gets a ``UserWarning``: positions of at most 6 significant digits with pairs within that rounding of
touching (:func:`printed_precision`), a median radius beyond ``RADIUS_PLAUSIBLE`` (another length unit than the file
says).

The other way: :func:`write_lammps_data` writes a packing (read here, from a scene's particles, or from a saved
state, :func:`packing_from_state`) as a LAMMPS data file of ``atom_style sphere`` that ``read_data`` reads;
:func:`write_csv` and :func:`write_vtu` write the two other formats (a run's LAMMPS text dumps: :mod:`dem.output.lammps_dump`).
"""

from __future__ import annotations

import csv
import io
import logging
import math
import mmap
import pathlib
import re
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

from dem.output.atomic import write_aside
from dem.output.lammps_dump import lammps_ids, rows_text as _rows_text

FORMATS = ("csv", "lammps-data", "lammps-dump", "vtk", "parts")
AXES = "xyz"
# LAMMPS unit styles a granular packing can be in: metres and kg/m^3 per unit of length and of density
LAMMPS_UNITS = {"si": (1.0, 1.0), "cgs": (1e-2, 1e3), "micro": (1e-6, 1e3), "nano": (1e-9, 1e6)}
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


# --------------------------------------------------------------------------------------------------- reading
def format_of(path) -> str:
    """The format of a packing file, from its name (module docstring); ``ValueError`` when the name does not say.

    Parameters
    ----------
    path : str or pathlib.Path
        The file's path (only its name is read).

    Returns
    -------
    str
        One of ``FORMATS``.

    Raises
    ------
    ValueError
        The name matches no format.
    """
    p = pathlib.Path(path)
    name, suffix = p.name.lower(), p.suffix.lower()
    if suffix == ".csv":
        return "csv"
    if suffix in (".data", ".lmp") or name.startswith("data."):
        return "lammps-data"
    if suffix in (".dump", ".lammpstrj") or name.startswith("dump."):
        return "lammps-dump"
    if suffix in (".vtu", ".vtp", ".vtk", ".pvtu", ".pvtp"):
        return "vtk"
    if suffix == ".parts":
        return "parts"
    raise ValueError(f"{path}: the format is not known from the name; give format = one of {', '.join(FORMATS)} "
                     "(extensions: .csv; .data, .lmp, data.*; .dump, .lammpstrj, dump.*; .vtu, .vtp, .vtk; .parts)")


def read_packing(path, format: str | None = None, length_unit: float = 1.0, timestep: int | None = None,
                 periodic=None) -> Packing:
    """The packing in the file ``path`` (module docstring). ``format``: one of ``FORMATS`` (default: from the
    name); ``length_unit``: metres per length unit of the file; ``timestep``: the snapshot of a dump (default: the
    last); ``periodic``: the periodic axes, as ``"xyz"``-letters or three bools, for files that do not record them
    (a LAMMPS data file) or to override them.

    Parameters
    ----------
    path : str or pathlib.Path
        The packing file.
    format : str or None
        One of ``FORMATS``; None: from the file's name (:func:`format_of`).
    length_unit : float
        Metres per length unit of the file, > 0 (0.001 for mm, 1e-6 for um).
    timestep : int or None
        The snapshot of a dump to read; None: its last.
    periodic : str or sequence of bool or None
        The periodic axes, as ``"xyz"`` letters (``"xy"``, say) or three bools; None: what the file records.

    Returns
    -------
    Packing
        The packing, in SI units.

    Raises
    ------
    ValueError
        A bad argument, or a bad file (:class:`FileError`, one line naming the file, the line and the column).
    """
    path = pathlib.Path(path)
    fmt = format_of(path) if format is None else format
    if fmt not in FORMATS:
        raise ValueError(f"format = {fmt!r}: must be one of {', '.join(FORMATS)}")
    if not (isinstance(length_unit, (int, float)) and not isinstance(length_unit, bool)
            and math.isfinite(length_unit) and length_unit > 0):
        raise ValueError(f"length_unit = {length_unit!r}: must be a number > 0 (metres per length unit of the file)")
    if timestep is not None and fmt != "lammps-dump":
        raise ValueError(f"timestep = {timestep!r}: only for LAMMPS dumps (format = 'lammps-dump')")
    axes = None if periodic is None else _axes(periodic)
    if fmt == "parts":  # a folder (dem.scene.packing_parts), in SI units as written
        from dem.scene.packing_parts import read_whole

        if length_unit != 1.0:
            raise ValueError(f"length_unit = {length_unit!r}: a packing in parts is in metres (1)")
        packing = read_whole(path)
    elif not path.is_file():
        raise ValueError(f"{path}: no such file")
    else:
        reader = {"csv": _read_csv, "lammps-data": _read_data, "lammps-dump": _read_dump, "vtk": _read_vtk}[fmt]
        try:
            packing = reader(path, float(length_unit), timestep)
        except UnicodeDecodeError as exc:
            raise ValueError(f"{path}: cannot be read as text ({exc.reason} at byte {exc.start})") from None
    if axes is not None:
        packing = replace(packing, periodic=axes)
    packing = _checked(packing, path, fmt)
    _warn_unit(packing, length_unit)
    _warn_precision(packing)
    return packing


def _axes(periodic) -> tuple:
    if isinstance(periodic, str):
        if not set(periodic) <= set(AXES):
            raise ValueError(f"periodic = {periodic!r}: must name axes among x, y, z (e.g. \"xy\")")
        return tuple(a in periodic for a in AXES)
    values = tuple(periodic)
    if len(values) != 3 or not all(isinstance(v, (bool, np.bool_)) for v in values):
        raise ValueError(f"periodic = {periodic!r}: must be axis letters (\"xyz\") or three true/false values")
    return tuple(bool(v) for v in values)


def _scaled(p: Packing, unit: float) -> Packing:
    """``p`` with its lengths (and velocities) multiplied by ``unit``; densities are kg/m^3 already."""
    if unit == 1.0:
        return p
    scale = {k: getattr(p, k) * unit for k in ("position", "radius", "velocity", "box_lo", "box_hi")
             if getattr(p, k) is not None}
    return replace(p, **scale)


def _density_from_mass(mass: np.ndarray, radius_m: np.ndarray) -> np.ndarray:
    """kg/m^3 of spheres of ``mass`` kg and radius ``radius_m`` m (how LAMMPS's atom_style sphere relates them)."""
    return mass / (SPHERE_VOLUME * radius_m**3)


def _checked(p: Packing, path, fmt: str) -> Packing:
    """Checks that hold whatever the format: at least one particle, radii > 0, unique ids, a box that holds the
    centres along its periodic axes."""
    if p.n == 0:
        raise ValueError(f"{path}: holds no particles")
    bad = np.flatnonzero(~(p.radius > 0))
    if bad.size:
        k = int(bad[0])
        raise ValueError(f"{path}: particle id {p.id[k]}: radius = {p.radius[k]:.9g} m: must be > 0")
    unique, counts = np.unique(p.id, return_counts=True)
    if np.any(counts > 1):
        raise ValueError(f"{path}: id {unique[counts > 1][0]} is given to {counts[counts > 1][0]} particles; ids "
                         "must be unique")
    if np.any(p.id < 0):
        raise ValueError(f"{path}: id {p.id[p.id < 0][0]}: ids must be >= 0")
    if p.box_lo is not None and np.any(p.box_hi <= p.box_lo):
        a = int(np.flatnonzero(p.box_hi <= p.box_lo)[0])
        raise ValueError(f"{path}: box {AXES[a]}lo = {p.box_lo[a]:.9g} >= {AXES[a]}hi = {p.box_hi[a]:.9g}")
    return replace(p, source=str(path), format=fmt)


RADIUS_PLAUSIBLE = (1e-8, 0.05)  # m: the median radius of a powder or a granular bed (10 nm to 5 cm)
PRINTED_DIGITS = 6  # LAMMPS's default float format in dumps (%g)


def _warn_unit(p: Packing, length_unit: float) -> None:
    """Warn when the particles' median radius (m) lies outside ``RADIUS_PLAUSIBLE``: the file is likely in
    another length unit than it says (or than ``length_unit``)."""
    r = float(np.median(p.radius))
    if RADIUS_PLAUSIBLE[0] <= r <= RADIUS_PLAUSIBLE[1]:
        return
    said = (f"LAMMPS units {p.units}" if p.units is not None else
            f"length_unit = {length_unit:g}" + (" and no LAMMPS units line" if p.format.startswith("lammps") else ""))
    hint = ("in mm (length_unit = 1e-3) or um (1e-6)" if r > RADIUS_PLAUSIBLE[1] else
            "in metres read with a length_unit for mm or um")
    warnings.warn(f"{p.source}: the median radius is {r:.3g} m (read with {said}): grains are "
                  f"{RADIUS_PLAUSIBLE[0]:g} to {RADIUS_PLAUSIBLE[1]:g} m; is the file {hint}?", stacklevel=3)


def printed_precision(x: np.ndarray, digits: int = PRINTED_DIGITS) -> float | None:
    """The largest rounding error (m) of coordinates ``x`` that carry at most ``digits`` significant digits (each
    equal to itself rounded to them), or None where one carries more.

    Parameters
    ----------
    x : numpy.ndarray
        Coordinates (m), any shape; zeros carry no digits and are skipped.
    digits : int
        Number of significant digits, >= 1 (``PRINTED_DIGITS``, LAMMPS's ``%g``, by default).

    Returns
    -------
    float or None
        Half the step of the last digit of the largest coordinate (m), or None where a coordinate carries more
        digits or all are zero.
    """
    x = np.asarray(x, dtype=float).ravel()
    x = x[x != 0.0]
    if not len(x):
        return None
    step = 10.0 ** (np.floor(np.log10(np.abs(x))) - (digits - 1))
    if not np.allclose(np.round(x / step) * step, x, rtol=1e-12, atol=0.0):
        return None
    return float(0.5 * step.max())


def _warn_precision(p: Packing) -> None:
    """Warn when the positions carry at most :data:`PRINTED_DIGITS` significant digits and contacts sit within that
    rounding (their gap or overlap below it): those contacts may be gained or lost by the rounding."""
    error = printed_precision(p.position)
    if error is None or p.n < 2:
        return
    from scipy.spatial import cKDTree

    tolerance = 2.0 * math.sqrt(3.0) * error  # the distance of two rounded centres is off by at most this
    i, j = cKDTree(p.position).query_pairs(2.0 * float(p.radius.max()) + tolerance, output_type="ndarray").T
    gap = np.linalg.norm(p.position[i] - p.position[j], axis=1) - (p.radius[i] + p.radius[j])
    near = int(np.count_nonzero(np.abs(gap) <= tolerance))
    if near:
        warnings.warn(f"{p.source}: the positions carry {PRINTED_DIGITS} significant digits (rounded by up to "
                      f"{error:.3g} m) and {near} pair(s) within {tolerance:.3g} m of touching "
                      f"({int(np.count_nonzero(gap < 0))} contacts in all), so the rounding may make or break "
                      "contacts; write the file with full precision (LAMMPS: dump_modify format float %.17g)",
                      stacklevel=3)


# A table of numbers is parsed at C speed (np.loadtxt); only a table that fails is read again, line by line, to name
# the line and column of the first bad entry.
def _table(path, text: str, first_line: int, names, widths, what: str, delimiter=None, usecols=None) -> np.ndarray:
    """The numbers of ``text`` -- rows of ``delimiter``-separated entries (whitespace by default; blank lines and
    ``#`` comments skipped) that start on the file's line ``first_line`` -- as an array (rows, columns): every row
    has the same number of entries, one of ``widths`` (``what`` says which in an error); ``usecols``: only these
    columns are converted (the others may hold words). ``names`` name the columns in errors."""
    if not text.strip():
        return np.empty((0, len(usecols) if usecols is not None else widths[0]))
    try:
        arr = np.loadtxt(io.StringIO(text), dtype=float, comments="#", delimiter=delimiter, ndmin=2, usecols=usecols,
                         quotechar='"' if delimiter else None)
    except ValueError:
        arr = None
    if arr is None or (usecols is None and arr.shape[1] not in widths) or not np.all(np.isfinite(arr)):
        _locate(path, text, first_line, names, widths, what, delimiter, usecols)
        raise FileError(path, "cannot be read as a table of numbers", first_line)  # _locate found nothing: unlikely
    return arr


def _data_lines(text: str, first_line: int):
    """``(file line, entries text)`` of the lines of ``text`` that hold entries (not blank, not a comment)."""
    for k, line in enumerate(text.split("\n")):
        body = line.split("#")[0]
        if body.strip():
            yield first_line + k, body


def _locate(path, text, first_line, names, widths, what, delimiter, usecols) -> None:
    """Raise :class:`FileError` at the first row of ``text`` with a number of entries not in ``widths`` (or unlike
    the first row's), or an entry (of ``usecols``) that is not a finite number."""
    width = None
    for line, body in _data_lines(text, first_line):
        words = next(csv.reader([body])) if delimiter else body.split()
        if len(words) not in widths or (width is not None and len(words) != width):
            raise FileError(path, f"{len(words)} values; expected {what}", line)
        width = len(words)
        for c in (range(len(words)) if usecols is None else usecols):
            word = words[c].strip()
            try:
                value = float(word)
            except ValueError:
                raise FileError(path, f"{word!r} is not a number", line, c + 1, names[c]) from None
            if not math.isfinite(value):
                raise FileError(path, f"{word!r}: must be finite", line, c + 1, names[c])


def _row_line(text: str, first_line: int, row: int) -> int:
    """The file line of row ``row`` of the table ``text`` (which starts on line ``first_line``)."""
    for k, (line, _) in enumerate(_data_lines(text, first_line)):
        if k == row:
            return line
    return first_line


def _check_rows(path, bad: np.ndarray, text: str, first_line: int, column: int, name: str, message) -> None:
    """Raise :class:`FileError` at the first row where ``bad`` holds, ``message(row)`` saying what is wrong."""
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise FileError(path, message(row), _row_line(text, first_line, row), column, name)


def _integers(path, values: np.ndarray, text: str, first_line: int, column: int, name: str) -> np.ndarray:
    """The column ``values`` of the table ``text`` as integers; a fraction raises :class:`FileError`."""
    _check_rows(path, values != np.round(values), text, first_line, column, name,
                lambda row: f"{float(values[row])!r} is not an integer")
    return values.astype(np.int64)


def _header_line(text: str, start: int = 0) -> tuple[int, int, str]:
    """``(offset after it, its line number, the line)`` of the first line of ``text`` that is neither blank nor a
    ``#`` comment, from offset ``start`` (line numbers from 1 at offset 0); ``(-1, line, "")`` when there is none."""
    line = text.count("\n", 0, start) + 1
    while start < len(text):
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        here = text[start:end]
        if here.strip() and not here.lstrip().startswith("#"):
            return end + 1, line, here
        start, line = end + 1, line + 1
    return -1, line, ""


# ------------------------------------------------------------------------------------------------------ CSV
CSV_ALIASES = {"points:0": "x", "points:1": "y", "points:2": "z"}
CSV_NUMBERS = ("id", "x", "y", "z", "radius", "diameter", "temperature", "density")
CSV_COLUMNS = CSV_NUMBERS + ("fixed", "material")
TRUE, FALSE = ("true", "1", "yes", "t", "1.0"), ("false", "0", "no", "f", "", "0.0")


def _read_csv(path: pathlib.Path, length_unit: float, _timestep=None) -> Packing:
    text = path.read_text()
    body_start, header_line, line = _header_line(text)
    if body_start < 0:
        raise FileError(path, "empty: needs a header row (x, y, z, radius, ...) and a row per particle")
    header = [h.strip() for h in next(csv.reader([line]))]
    names = [CSV_ALIASES.get(h.lower(), h.lower()) for h in header]
    for k, name in enumerate(names):
        if name in CSV_COLUMNS and names.index(name) != k:
            raise FileError(path, f"column {header[k]!r} appears twice", header_line, k + 1)
    size = "radius" if "radius" in names else "diameter"
    missing = [c for c in ("x", "y", "z", size) if c not in names]
    if missing:
        raise FileError(path, f"no column {missing[0]!r} in the header ({', '.join(header)}); needs x, y, z and "
                        "radius or diameter", header_line)
    if "radius" in names and "diameter" in names:
        raise FileError(path, "both radius and diameter columns: give one", header_line)
    body, first = text[body_start:], header_line + 1
    numeric = [k for k, name in enumerate(names) if name in CSV_NUMBERS]
    what = f"{len(header)}, the columns of the header"
    table = _table(path, body, first, header, (len(header),), what, ",", numeric)
    if len(table) == 0:
        raise FileError(path, "no particle rows after the header", header_line)
    if body.count(",") != len(table) * (len(header) - 1):  # a row of another width (or commas in comments)
        _locate(path, body, first, header, (len(header),), what, ",", numeric)
    columns = {names[k]: table[:, j] for j, k in enumerate(numeric)}
    position = np.column_stack([columns[a] for a in AXES])
    radius = columns["radius"] if size == "radius" else 0.5 * columns["diameter"]
    out = {key: columns[key] for key in ("temperature", "density") if key in columns}
    ids = (_integers(path, columns["id"], body, first, names.index("id") + 1, header[names.index("id")])
           if "id" in columns else np.arange(len(radius), dtype=np.int64))
    for key in ("fixed", "material"):
        if key in names:
            k = names.index(key)
            words = np.char.strip(np.loadtxt(io.StringIO(body), dtype=str, comments="#", delimiter=",", ndmin=2,
                                             usecols=[k], quotechar='"')[:, 0])
            out[key] = _csv_words(path, key, words, body, first, k + 1)
    ignored = tuple(h for h, name in zip(header, names) if name not in CSV_COLUMNS)
    return _scaled(Packing(ids, position, radius, ignored=ignored, **out), length_unit)


def _csv_words(path, key: str, words: np.ndarray, body: str, first: int, column: int) -> np.ndarray:
    """``fixed`` as bools; ``material`` as indices (all integers) or names."""
    if key == "fixed":
        lower = np.char.lower(words)
        _check_rows(path, ~np.isin(lower, TRUE + FALSE), body, first, column, key,
                    lambda row: f"{str(words[row])!r}: must be true or false (or 1, 0)")
        return np.isin(lower, TRUE)
    _check_rows(path, words == "", body, first, column, key, lambda row: "empty: a material index or name")
    if all(re.fullmatch(r"[+-]?\d+", w) for w in words.tolist()):
        index = words.astype(np.int64)
        _check_rows(path, index < 0, body, first, column, key,
                    lambda row: f"{str(words[row])!r}: a material index must be >= 0")
        return index
    return words


# ------------------------------------------------------------------------------------------------ LAMMPS data
DATA_SECTIONS = ("Atoms", "Velocities", "Masses", "Ellipsoids", "Lines", "Triangles", "Bodies", "Bonds", "Angles",
                 "Dihedrals", "Impropers", "Pair Coeffs", "PairIJ Coeffs", "Bond Coeffs", "Angle Coeffs",
                 "Dihedral Coeffs", "Improper Coeffs", "BondBond Coeffs", "BondAngle Coeffs",
                 "MiddleBondTorsion Coeffs", "EndBondTorsion Coeffs", "AngleTorsion Coeffs", "AngleAngleTorsion Coeffs",
                 "BondBond13 Coeffs", "AngleAngle Coeffs")
# a section's keyword line (after the title line: the pattern starts with its newline, which re finds fast)
SECTION_LINE = re.compile(r"\n[ \t]*(" + "|".join(DATA_SECTIONS) + r")[ \t]*(?:#([^\n]*))?(?=\r?\n|$)")
SPHERE_COLUMNS = ("id", "type", "diameter", "density", "x", "y", "z", "ix", "iy", "iz")
SPHERE_LAYOUT = "7 or 10 (atom_style sphere: id type diameter density x y z [ix iy iz])"
VELOCITY_COLUMNS = ("id", "vx", "vy", "vz", "wx", "wy", "wz")
UNITS_TITLE = re.compile(r"units\s*=\s*(\w+)")


def _lammps_units(path, style: str | None, line: int, length_unit: float) -> tuple[float, float]:
    """Metres per length unit and kg/m^3 per density unit of a LAMMPS file that records its unit ``style`` (on
    ``line``), else ``(length_unit, 1)``."""
    if style is None:
        return length_unit, 1.0
    if style not in LAMMPS_UNITS:
        raise FileError(path, f"written in LAMMPS units {style}; packings are read in units {', '.join(LAMMPS_UNITS)} "
                        "(granular models use si or cgs)", line)
    if length_unit != 1.0:
        raise FileError(path, f"records LAMMPS units {style} (converted from): leave length_unit at 1, not "
                        f"{length_unit:g}", line)
    return LAMMPS_UNITS[style]


def _read_data(path: pathlib.Path, length_unit: float, _timestep=None) -> Packing:
    text = path.read_text()
    if not text.strip():
        raise FileError(path, "empty: not a LAMMPS data file")
    title = UNITS_TITLE.search(text[:text.find("\n") if "\n" in text else len(text)])
    units = title.group(1) if title else None
    length, density_unit = _lammps_units(path, units, 1, length_unit)
    marks = list(SECTION_LINE.finditer(text))
    sections = {}  # keyword: (its line, style comment, body text, the body's first line)
    for m, after in zip(marks, marks[1:] + [None]):
        line = text.count("\n", 0, m.start()) + 2
        sections[m.group(1)] = (line, (m.group(2) or "").strip(), text[m.end():after.start() if after else None],
                                line)
    n_atoms, lo, hi = _data_header(path, text[:marks[0].start()] if marks else text)
    if "Atoms" not in sections:
        raise FileError(path, "no Atoms section")
    start, style, body, first = sections["Atoms"]
    if style and style.split()[0] != "sphere":
        raise FileError(path, f"atom_style {style}: only atom_style sphere (id type diameter density x y z) is read",
                        start)
    atoms = _table(path, body, first, SPHERE_COLUMNS, (7, 10), SPHERE_LAYOUT)
    if len(atoms) != n_atoms:
        raise FileError(path, f"the Atoms section has {len(atoms)} lines but the header says {n_atoms} atoms", start)
    ids = _integers(path, atoms[:, 0], body, first, 1, "id")
    _unique_ids(path, ids, body, first)
    diameter = atoms[:, 2]
    _check_rows(path, diameter <= 0, body, first, 3, "diameter",  # diameter 0: a LAMMPS point particle
                lambda row: f"diameter = {float(diameter[row])!r}: must be > 0 (a sphere)")
    out = {"material": _integers(path, atoms[:, 1], body, first, 2, "type") - 1,
           "density": atoms[:, 3] * density_unit}
    if atoms.shape[1] == 10:
        out["image"] = np.column_stack([_integers(path, atoms[:, 7 + a], body, first, 8 + a, f"i{AXES[a]}")
                                        for a in range(3)])
    if "Velocities" in sections:
        vstart, _, vbody, vfirst = sections["Velocities"]
        v = _table(path, vbody, vfirst, VELOCITY_COLUMNS, (7,), "7 (atom_style sphere: id vx vy vz wx wy wz)")
        vids = _integers(path, v[:, 0], vbody, vfirst, 1, "id")
        order, where = np.argsort(ids), np.argsort(vids)
        if len(vids) != len(ids) or np.any(ids[order] != vids[where]):
            raise FileError(path, "the Velocities section must list every atom of the Atoms section once", vstart)
        velocity, omega = np.empty((len(ids), 3)), np.empty((len(ids), 3))
        velocity[order], omega[order] = v[where, 1:4], v[where, 4:7]
        out.update(velocity=velocity, angular_velocity=omega)
    packing = Packing(ids, atoms[:, 4:7], 0.5 * diameter, box_lo=lo, box_hi=hi, units=units, **out)
    return _sorted(_scaled(packing, length), np.argsort(ids, kind="stable"))


def _unique_ids(path, ids: np.ndarray, body: str, first: int) -> None:
    """Refuse an id given to two atoms of a section, naming both lines (before any other section is matched to
    the atoms)."""
    order = np.argsort(ids, kind="stable")
    same = np.flatnonzero(ids[order][1:] == ids[order][:-1])
    if same.size:
        a, b = order[same[0]], order[same[0] + 1]
        raise FileError(path, f"id {ids[a]} is given to two atoms (lines {_row_line(body, first, a)} and "
                        f"{_row_line(body, first, b)}); ids must be unique", _row_line(body, first, b))


def _data_header(path, header: str) -> tuple[int, np.ndarray, np.ndarray]:
    """The atom count and the box bounds of a data file's header (the lines before its first section)."""
    n_atoms, lo, hi = None, [None] * 3, [None] * 3
    for k, line in enumerate(header.split("\n")[1:], start=2):
        words = line.split("#")[0].split()
        if len(words) == 2 and words[1] == "atoms":
            n_atoms = int(_integers(path, _table(path, words[0], k, ("atoms",), (1,), "1")[0], words[0], k, 1,
                                    "atoms")[0])
        elif len(words) == 4 and words[2][1:] == "lo" and words[3][1:] == "hi" and words[2][0] in AXES:
            a = AXES.index(words[2][0])
            lo[a], hi[a] = _table(path, " ".join(words[:2]), k, (words[2], words[3]), (2,), "2")[0]
        elif len(words) == 6 and words[3:] == ["xy", "xz", "yz"]:
            if np.any(_table(path, " ".join(words[:3]), k, ("xy", "xz", "yz"), (3,), "3") != 0):
                raise FileError(path, "a triclinic box (tilt factors xy xz yz not zero): only orthogonal boxes are "
                                "read", k)
        elif words and words[0] in ("avec", "bvec", "cvec", "abc"):
            raise FileError(path, "a general triclinic box: only orthogonal boxes are read", k)
    if n_atoms is None:
        raise FileError(path, "no 'N atoms' line in the header: not a LAMMPS data file")
    if any(v is None for v in lo):
        a = next(a for a in range(3) if lo[a] is None)
        raise FileError(path, f"no '{AXES[a]}lo {AXES[a]}hi' line in the header")
    return n_atoms, np.array(lo, dtype=float), np.array(hi, dtype=float)


def _sorted(p: Packing, order: np.ndarray) -> Packing:
    arrays = {k: getattr(p, k)[order] for k in ("id", "position", "radius", "temperature", "fixed", "material",
                                                 "density", "velocity", "angular_velocity", "image")
              if getattr(p, k) is not None}
    return replace(p, **arrays)


# ------------------------------------------------------------------------------------------------ LAMMPS dump
DUMP_POSITIONS = (("x", "y", "z"), ("xu", "yu", "zu"), ("xs", "ys", "zs"), ("xsu", "ysu", "zsu"))
DUMP_TEMPERATURE = ("temperature", "temp", "t", "f_temp", "f_temperature")


def _read_dump(path: pathlib.Path, length_unit: float, timestep: int | None) -> Packing:
    with path.open("rb") as fh:
        try:
            data = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ)
        except ValueError:  # an empty file cannot be mapped
            raise FileError(path, "empty: not a LAMMPS dump") from None
    with data:
        starts = _frame_starts(data)
        if not starts:
            raise FileError(path, "no 'ITEM: TIMESTEP' line: not a LAMMPS dump")
        steps = [_frame_step(path, data, s) for s in starts]
        if timestep is None:
            pick = len(starts) - 1
        elif timestep in steps:
            pick = steps.index(timestep)
        else:
            listed = ", ".join(map(str, steps[:10])) + (", ..." if len(steps) > 10 else "")
            raise ValueError(f"{path}: timestep = {timestep}: not in the dump (its timesteps: {listed})")
        begin = starts[pick]
        end = starts[pick + 1] if pick + 1 < len(starts) else len(data)
        first_line = data[:begin].count(b"\n") + 1
        before = data.rfind(b"ITEM: UNITS", 0, begin)  # LAMMPS writes it once, before the first snapshot
        units, unit_line = None, None
        if before >= 0:
            unit_line = data[:before].count(b"\n") + 2
            units = data[before:begin].split(b"\n")[1].decode().strip()
        scales = _lammps_units(path, units, unit_line, length_unit)
        frame = data[begin:end].decode()
    return _parse_frame(path, frame, first_line, steps[pick], units, scales)


def _frame_starts(data) -> list[int]:
    out, k = [], data.find(b"ITEM: TIMESTEP")
    while k >= 0:
        if k == 0 or data[k - 1:k] == b"\n":
            out.append(k)
        k = data.find(b"ITEM: TIMESTEP", k + 1)
    return out


def _frame_step(path, data, start: int) -> int:
    end = data.find(b"\n", data.find(b"\n", start) + 1)
    text = data[start:end if end >= 0 else len(data)].decode(errors="replace").split("\n")
    line = data[:start].count(b"\n") + 2
    if len(text) < 2 or not re.fullmatch(r"\s*\d+\s*", text[1]):
        raise FileError(path, f"ITEM: TIMESTEP: {text[1].strip() if len(text) > 1 else ''!r} is not a timestep",
                        line)
    return int(text[1])


def _parse_frame(path, frame: str, first_line: int, step: int, units: str | None, scales) -> Packing:
    atoms_at = frame.find("ITEM: ATOMS")
    if atoms_at < 0:
        raise FileError(path, f"timestep {step}: no 'ITEM: ATOMS' line", first_line)
    head = frame[:atoms_at].split("\n")
    items = {line[5:].strip().split(" ")[0]: k for k, line in enumerate(head) if line.startswith("ITEM:")}
    if "NUMBER" not in items or "BOX" not in items:
        missing = "NUMBER OF ATOMS" if "NUMBER" not in items else "BOX BOUNDS"
        raise FileError(path, f"timestep {step}: no 'ITEM: {missing}' line", first_line)
    k = items["NUMBER"] + 1
    n = int(_integers(path, _table(path, head[k], first_line + k, ("atoms",), (1,), "1")[0], head[k],
                      first_line + k, 1, "atoms")[0])
    lo, hi, periodic = _dump_box(path, head, items["BOX"], first_line)
    header_end = frame.find("\n", atoms_at)
    header_end = len(frame) if header_end < 0 else header_end
    names = frame[atoms_at:header_end].split()[2:]
    atoms_line = first_line + frame.count("\n", 0, atoms_at)
    body_end = frame.find("\nITEM:", header_end)  # the next snapshot's UNITS or TIME lines, if any
    body = frame[header_end + 1:body_end + 1 if body_end >= 0 else None]
    table = _table(path, body, atoms_line + 1, names, (len(names),), f"{len(names)}, the columns of ITEM: ATOMS")
    if len(table) != n:
        raise FileError(path, f"timestep {step}: {len(table)} atom lines, but ITEM: NUMBER OF ATOMS says {n}",
                        atoms_line)
    keys = [name.lower() for name in names]

    def col(name, integer=False):
        k = keys.index(name)
        return _integers(path, table[:, k], body, atoms_line + 1, k + 1, names[k]) if integer else table[:, k]

    length, density_unit = scales
    position_names = next((c for c in DUMP_POSITIONS if all(a in keys for a in c)), None)
    if position_names is None:
        raise FileError(path, f"no position columns in ITEM: ATOMS ({' '.join(names)}); needs x y z (or xu yu zu, "
                        "xs ys zs, xsu ysu zsu)", atoms_line)
    if "radius" not in keys and "diameter" not in keys:
        raise FileError(path, f"no radius or diameter column in ITEM: ATOMS ({' '.join(names)})", atoms_line)
    position = np.column_stack([col(a) for a in position_names])
    if position_names[0].startswith("xs"):
        position = lo + position * (hi - lo)
    out = {}
    if position_names[0].endswith("u") and periodic is not None:  # unwrapped: into the box along periodic axes
        shift = np.floor((position - lo) / (hi - lo))
        shift[:, ~np.array(periodic)] = 0
        position = position - shift * (hi - lo)
        out["image"] = shift.astype(np.int64)
    elif all(a in keys for a in ("ix", "iy", "iz")):
        out["image"] = np.column_stack([col(a, True) for a in ("ix", "iy", "iz")])
    radius = col("radius") if "radius" in keys else 0.5 * col("diameter")
    ids = col("id", True) if "id" in keys else np.arange(n, dtype=np.int64)
    if "type" in keys:
        out["material"] = col("type", True) - 1
    if "density" in keys:
        out["density"] = col("density") * density_unit
    elif "mass" in keys:
        mass_unit = density_unit * length**3 if units is not None else 1.0  # kg per mass unit of the file
        out["density"] = _density_from_mass(col("mass") * mass_unit, radius * length)
    temperature = next((t for t in DUMP_TEMPERATURE if t in keys), None)
    if temperature is not None:
        out["temperature"] = col(temperature)
    if all(v in keys for v in ("vx", "vy", "vz")):
        out["velocity"] = np.column_stack([col(v) for v in ("vx", "vy", "vz")])
    if all(w in keys for w in ("omegax", "omegay", "omegaz")):
        out["angular_velocity"] = np.column_stack([col(w) for w in ("omegax", "omegay", "omegaz")])
    read = set(position_names) | {"radius", "diameter", "id", "type", "density", "mass", temperature, "ix", "iy", "iz",
                                  "vx", "vy", "vz", "omegax", "omegay", "omegaz"}
    ignored = tuple(name for name, key in zip(names, keys) if key not in read)
    packing = Packing(ids, position, radius, box_lo=lo, box_hi=hi, periodic=periodic, timestep=step, units=units,
                      ignored=ignored, **out)
    return _sorted(_scaled(packing, length), np.argsort(ids, kind="stable"))


def _dump_box(path, head: list, k: int, first_line: int):
    """Bounds and periodic axes (``pp`` flags; None when the dump gives no flags) of ``ITEM: BOX BOUNDS`` on the
    snapshot's line ``k``."""
    box_head = head[k].split()[3:]
    if box_head and box_head[0] == "abc":
        raise FileError(path, "a general triclinic box: only orthogonal boxes are read", first_line + k)
    flags = [w for w in box_head if w not in ("xy", "xz", "yz")]
    tilted = len(flags) != len(box_head)
    width = 3 if tilted else 2
    bounds = np.empty((3, width))
    for a in range(3):
        j = k + 1 + a
        text = head[j] if j < len(head) else ""
        if not text.strip():
            raise FileError(path, f"no box bounds of {AXES[a]} (ITEM: BOX BOUNDS is followed by one line per axis)",
                            first_line + j)
        bounds[a] = _table(path, text, first_line + j, (f"{AXES[a]}lo", f"{AXES[a]}hi", "tilt"), (width,),
                           f"{width}, the bounds of {AXES[a]}{' and a tilt factor' if tilted else ''}")[0]
    if tilted and np.any(bounds[:, 2] != 0):
        raise FileError(path, "a triclinic box (tilt factors not zero): only orthogonal boxes are read",
                        first_line + k)
    periodic = tuple(f == "pp" for f in flags) if len(flags) == 3 else None
    return bounds[:, 0], bounds[:, 1], periodic


# ------------------------------------------------------------------------------------------------------ VTK
VTK_FIELDS = {"radius": ("radius", "radii"), "diameter": ("diameter", "diameters"), "id": ("id", "ids"),
              "temperature": ("temperature", "temp", "f_temp"), "fixed": ("fixed",),
              "material": ("material", "materialid"), "type": ("type",), "density": ("density",), "mass": ("mass",),
              "velocity": ("velocity", "v", "linvelvec"), "angular_velocity": ("angular_velocity", "omega",
                                                                               "angvelvec")}


class _KeptLog(logging.Handler):
    """A logging handler that keeps the messages it is given (a VTK reader's errors, for the one-line refusal)."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def _read_vtk(path: pathlib.Path, length_unit: float, _timestep=None) -> Packing:
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # a bad file: our one line, not VTK's log
    logged = _KeptLog()  # pyvista passes some reader errors to the logging module (an "ERROR:root:" line)
    root = logging.getLogger()
    root.addHandler(logged)
    try:
        with warnings.catch_warnings(record=True) as caught:  # pyvista reports a reader's error as a warning
            warnings.simplefilter("always")
            try:
                mesh = pv.read(str(path))
            except Exception as exc:  # VTK's readers raise many kinds; the file is what is wrong
                raise ValueError(f"{path}: cannot be read as VTK ({' '.join(str(exc).split())})") from None
    finally:
        root.removeHandler(logged)
    if mesh is None or not hasattr(mesh, "point_data") or mesh.n_points == 0:
        if caught or logged.messages:
            why = str(caught[0].message) if caught else logged.messages[0]
            raise ValueError(f"{path}: cannot be read as VTK ({' '.join(why.split())})")
        raise ValueError(f"{path}: holds no points (a VTK point set: the particle centres, with a radius or diameter "
                         "point field)")
    fields = {name.lower(): name for name in mesh.point_data.keys()}

    def get(key, components=1):
        name = next((fields[a] for a in VTK_FIELDS[key] if a in fields), None)
        if name is None:
            return None
        values = np.asarray(mesh.point_data[name])
        shape = (mesh.n_points,) if components == 1 else (mesh.n_points, components)
        if values.shape != shape:
            raise ValueError(f"{path}: point field {name!r} has shape {values.shape}, expected {shape}")
        if values.dtype.kind == "f" and not np.all(np.isfinite(values)):
            k = int(np.flatnonzero(~np.isfinite(values.reshape(mesh.n_points, -1)).any(axis=1))[0])
            raise ValueError(f"{path}: point field {name!r}: point {k} = {values[k]}: must be finite")
        used.add(name)
        return values

    used: set = set()
    radius = get("radius")
    if radius is None:
        diameter = get("diameter")
        if diameter is None:
            raise ValueError(f"{path}: no radius or diameter point field (fields: "
                             f"{', '.join(mesh.point_data.keys()) or 'none'})")
        radius = 0.5 * diameter
    radius = radius.astype(float)
    out = {}
    ids = get("id")
    for key in ("temperature", "density"):
        v = get(key)
        if v is not None:
            out[key] = v.astype(float)
    fixed = get("fixed")
    if fixed is not None:
        out["fixed"] = fixed.astype(bool)
    material, type_ = get("material"), get("type")
    if material is not None:
        out["material"] = _whole(path, material, "material")
    elif type_ is not None:
        out["material"] = _whole(path, type_, "type") - 1
    mass = get("mass")
    if "density" not in out and mass is not None:
        out["density"] = _density_from_mass(mass.astype(float), radius * length_unit)
    for key in ("velocity", "angular_velocity"):
        v = get(key, 3)
        if v is not None:
            out[key] = v.astype(float)
    points = np.asarray(mesh.points, dtype=float)
    ids = np.arange(len(radius), dtype=np.int64) if ids is None else _whole(path, ids, "id")
    ignored = tuple(name for name in mesh.point_data.keys() if name not in used)
    return _scaled(Packing(ids, points, radius, ignored=ignored, **out), length_unit)


def _whole(path, values: np.ndarray, name: str) -> np.ndarray:
    if values.dtype.kind == "f" and np.any(values != np.round(values)):
        k = int(np.flatnonzero(values != np.round(values))[0])
        raise ValueError(f"{path}: point field {name!r}: point {k} = {values[k]!r}: must be an integer")
    return np.round(values).astype(np.int64)


# ----------------------------------------------------------------------------------------------------- scenes
SCENE_KEYS = ("file", "format", "length_unit", "timestep")  # [particles] keys of a packing file
DENSITY_RTOL = 1e-3  # a file's density against its material's: printed digits (LAMMPS dumps: 6) pass, a mix-up fails


def scene_particles(table: dict, materials, base_dir=None, part=None):
    """``[particles] file = "..."`` of a scene: the :class:`dem.geometry.particles.Particles` of the file (``format``,
    ``length_unit``, ``timestep`` as for :func:`read_packing`; the path relative to ``base_dir``, the scene's folder)
    and the file's box as a :class:`dem.geometry.periodic.PeriodicBox` (periodic along the axes the file says are, none where
    it cannot say), or None. ``temperature`` (a number or a list), ``fixed``, ``material`` (a name or index, or a
    list of them) and ``heat`` come from the table where given, else from the file; a density the file gives must be
    its material's. With ``part``, a packing in parts (:mod:`dem.scene.packing_parts`) gives only the particles that
    rank holds (a list in the table is of the whole packing, taken at their places), and its ``Part`` the particles
    of the whole packing that its file holds at their temperature (``fixed`` in the table is refused there).

    Parameters
    ----------
    table : dict
        The scene's ``[particles]`` table, with its ``file`` key.
    materials : sequence of dem.geometry.particles.Material
        The scene's materials.
    base_dir : str or pathlib.Path or None
        The scene's folder, against which a relative ``file`` is read; None: the working directory.
    part : tuple or None
        ``(ranks, rank, box_of)``: read a packing in parts as rank ``rank`` of ``ranks``, the scene's periodic box
        ``box_of(file_box)`` (a callable from the file's box, or None, to the scene's); None: read the whole file.

    Returns
    -------
    tuple of (dem.geometry.particles.Particles, dem.geometry.periodic.PeriodicBox or None, object)
        The particles, the file's box, and the :class:`dem.scene.packing_parts.Part` they are of (None where the
        whole file was read).

    Raises
    ------
    ValueError
        A bad key of the table, a bad file, or a density of the file that is not its material's.
    """
    from dem.geometry.particles import Particles, material_indices

    name = table["file"]
    if not isinstance(name, str):
        raise ValueError(f"[particles] file = {name!r}: must be a path (string)")
    for key in ("position", "radius"):
        if key in table:
            raise ValueError(f"[particles] {key}: the particles come from file = {name!r}; give one or the other")
    options = {k: table[k] for k in ("format", "length_unit", "timestep") if k in table}
    if "timestep" in options and (not isinstance(options["timestep"], int) or isinstance(options["timestep"], bool)):
        raise ValueError(f"[particles] timestep = {options['timestep']!r}: must be an integer (a dump's timestep)")
    path = pathlib.Path(base_dir) / name if base_dir is not None else pathlib.Path(name)
    held = None
    try:
        if part is not None and options.get("format", format_of(path) if path.suffix else None) == "parts":
            packing, held = _part_of(path, table, options, *part)
        else:
            packing = read_packing(path, **options)
    except ValueError as exc:
        raise ValueError(f"[particles] file: {exc}") from None
    n = packing.n
    values = {}
    for key in ("temperature", "fixed", "heat", "material"):
        value = table.get(key, getattr(packing, key, None))
        if held is not None and key in table and isinstance(value, list):
            if len(value) != held.n:
                raise ValueError(f"[particles] {key}: {len(value)} values for the {held.n} particles of {name!r}")
            value = np.asarray(value)[held.held]
        if isinstance(value, (int, float)) and not isinstance(value, bool) and key not in ("fixed", "material"):
            value = np.full(n, float(value))
        elif isinstance(value, bool) and key == "fixed":
            value = np.full(n, value)
        values[key] = value
    if values["temperature"] is None:
        raise ValueError(f"[particles] temperature: required (a number or a list); {name!r} has no temperature column")
    if "material" not in table and packing.material is not None and packing.material.dtype.kind in "iu":
        beyond = np.flatnonzero(packing.material >= len(materials))
        if beyond.size:
            k = int(beyond[0])
            raise ValueError(f"[particles] file {name!r}: particle id {packing.id[k]} is of material "
                             f"{packing.material[k]} (LAMMPS type {packing.material[k] + 1}) but the scene has "
                             f"{len(materials)} material(s); give [[materials]] (LAMMPS type k is material k - 1) or "
                             "[particles] material")
    material = material_indices("[particles] material" if "material" in table else f"[particles] file {name!r}: "
                                "material", values["material"], materials, n)
    particles = Particles.from_arrays(packing.position, packing.radius, values["temperature"], materials, material,
                                      values["fixed"], values["heat"], prefix="[particles]", id=packing.id)
    if packing.density is not None:
        expected = np.array([m.density for m in particles.materials])[particles.material]
        off = np.flatnonzero(np.abs(packing.density - expected) > DENSITY_RTOL * expected)
        if off.size:
            k = int(off[0])
            m = particles.materials[particles.material[k]]
            if packing.units is None and abs(m.density / packing.density[k] / 1e3 - 1.0) <= DENSITY_RTOL:
                advice = (f"{packing.density[k]:.6g} is the material's density in g/cm^3, as a LAMMPS file in "
                          "units micro or cgs writes it: give the file its units line (`units = micro` or `units = cgs` in its first line, as write_data "
                          "writes it), which converts its lengths too")
            else:
                advice = ("give the material that density (with [[materials]] for several: LAMMPS type k is material "
                          "k - 1)")
            raise ValueError(f"[particles] file {name!r}: particle id {packing.id[k]} has density "
                             f"{packing.density[k]:.6g} kg/m^3 but its material {m.name!r} {m.density:.6g}; {advice}")
    box = packing.periodic_box() if packing.box_lo is not None else None
    if held is not None and held.fixed is not None:  # the whole packing's fixed particles, as the scene has them
        f = held.fixed
        T = table.get("temperature", f.temperature)
        T = np.asarray(T, dtype=float)[held.fixed_places] if isinstance(T, list) else np.broadcast_to(T, (f.n,))
        held = replace(held, fixed=Particles.from_arrays(f.position, f.radius, T, materials,
                                                         fixed=np.ones(f.n, dtype=bool), prefix="[particles]",
                                                         id=f.id))
    return particles, box, held


def _part_of(path, table: dict, options: dict, ranks: int, rank: int, box_of):
    """The packing and :class:`dem.scene.packing_parts.Part` that rank ``rank`` of ``ranks`` holds of the packing in
    parts ``path`` (:func:`scene_particles`)."""
    from dem.scene import packing_parts

    extra = sorted(set(options) - {"format"})
    if extra:
        raise ValueError(f"{extra[0]}: not for a packing in parts (in metres, one snapshot)")
    if "fixed" in table:
        raise ValueError(f"[particles] fixed: not for a packing read in parts on several ranks (the fixed particles "
                         f"are the file's, {path.name}/{packing_parts.HELD}); write them into it, or run on one "
                         "process")
    index = packing_parts.read_index(path)
    file_box = None
    if index.box_lo is not None:
        from dem.geometry.periodic import PeriodicBox

        file_box = PeriodicBox(index.box_hi - index.box_lo, index.periodic or (False,) * 3, index.box_lo)
    return packing_parts.read_part(path, ranks, rank, box_of(file_box))


# --------------------------------------------------------------------------------------------------- writing
def packing_from_particles(particles, box=None) -> Packing:
    """A :class:`Packing` of a scene's :class:`dem.geometry.particles.Particles` (densities from its materials) in the
    periodic box ``box`` (:class:`dem.geometry.periodic.PeriodicBox`) or none.

    Parameters
    ----------
    particles : dem.geometry.particles.Particles
        The scene's particles.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box; None: the packing has no box.

    Returns
    -------
    Packing
        The packing: ids, positions (m), radii (m), temperatures, fixed flags, material indices and densities
        (kg/m^3).
    """
    density = np.array([m.density for m in particles.materials], dtype=float)[particles.material]
    lo = hi = periodic = None
    if box is not None:
        lo, hi, periodic = box.origin, box.origin + box.lengths, tuple(box.periodic)
    return Packing(particles.id, particles.position, particles.radius, particles.temperature, particles.fixed,
                   particles.material, density, box_lo=lo, box_hi=hi, periodic=periodic)


def packing_from_state(state: dict) -> Packing:
    """A :class:`Packing` of a saved state (:func:`dem.scene.state_file.load`) in its periodic box, if it has one:
    positions, radii, temperatures, ids; of a moving state also velocities, angular velocities and the density that
    gives each particle its saved mass as a sphere (``m / (4/3 pi r^3)``, also what LAMMPS computes the mass from),
    of a static one its materials (no density: the scene's materials have them). 3D states only: a 2D state's disks
    lie in the x-z plane with a height, which LAMMPS's 2D spheres (x-y plane) do not have.

    Parameters
    ----------
    state : dict
        The saved state's arrays (:func:`dem.scene.state_file.load`).

    Returns
    -------
    Packing
        The packing (SI units).

    Raises
    ------
    ValueError
        The state is a moving 2D one.
    """
    from dem.scene.state_file import saved_box

    if state["moving"] and int(state["dimension"]) != 3:
        raise ValueError("state: a 2D state (disks in the x-z plane): only 3D states can be written as packings")
    radius = np.asarray(state["radius"], dtype=float)
    ids = state["id"] if "id" in state else np.arange(len(radius), dtype=np.int64)
    box = saved_box(state)
    lo = hi = periodic = None
    if box is not None:
        lo, hi, periodic = box.origin, box.origin + box.lengths, tuple(box.periodic)
    moving = {"density": state["mass"] / (SPHERE_VOLUME * radius**3), "velocity": np.asarray(state["v"], dtype=float),
              "angular_velocity": np.asarray(state["w"], dtype=float)} if state["moving"] else \
        {"material": np.asarray(state["material"], dtype=np.int64) if "material" in state else None}
    return Packing(np.asarray(ids, dtype=np.int64), np.asarray(state["x"], dtype=float), radius,
                   np.asarray(state["T"], dtype=float), box_lo=lo, box_hi=hi, periodic=periodic, **moving)


def write_lammps_data(path, packing: Packing, density=None, pad: float = 0.0) -> pathlib.Path:
    """Write ``packing`` as a LAMMPS data file of ``atom_style sphere`` (``units si``): the header (atoms, atom
    types, box), ``Atoms # sphere`` (``id type diameter density x y z ix iy iz``) and, where the packing has
    velocities, ``Velocities`` (``id vx vy vz wx wy wz``). Ids from :func:`dem.output.lammps_dump.lammps_ids`;
    type = material index + 1 (names: their order of appearance); ``density`` kg/m^3 (one number or per particle)
    where the packing has none.
    The box is the packing's, or the particles' bounding box grown by ``pad`` (m) beyond the largest radius; the
    periodicity is not part of a data file: the input script's ``boundary`` command sets it. A centre outside the
    packing's box (``lo <= x < hi``, LAMMPS's rule) is wrapped into it along a periodic axis, its image flag counting
    the periods (:func:`wrapped`), and refused along any other. Numbers are written to round-trip (the shortest
    digits that read back to the same double).

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write (written aside, then moved into place).
    packing : Packing
        The packing.
    density : float or array_like or None
        Density (kg/m^3), one number or one per particle, for a packing without densities; None: the packing's.
    pad : float
        Where the packing has no box: how far (m) the box reaches beyond the particles' outermost surfaces.

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    ValueError
        The packing has no density and none is given, a density is not finite and > 0, or a centre lies outside
        the box along a non-periodic axis.
    """
    path = pathlib.Path(path)
    n = packing.n
    if packing.density is not None:
        rho = np.asarray(packing.density, dtype=float)
    elif density is not None:
        rho = np.broadcast_to(np.asarray(density, dtype=float), (n,))
    else:
        raise ValueError(f"{path.name}: a LAMMPS data file needs each particle's density: give density (kg/m^3)")
    if not np.all(np.isfinite(rho) & (rho > 0)):
        k = int(np.flatnonzero(~(np.isfinite(rho) & (rho > 0)))[0])
        raise ValueError(f"density[{k}] = {rho[k]!r}: must be a finite number > 0 (kg/m^3)")
    types = _types(packing.material, n)
    x, r = packing.position, packing.radius
    image = packing.image if packing.image is not None else np.zeros((n, 3), dtype=np.int64)
    ids = lammps_ids(packing.id)
    if packing.box_lo is not None:
        lo, hi = packing.box_lo, packing.box_hi
        x, image = wrapped(packing, path.name)
    else:
        lo, hi = (x - r[:, None]).min(axis=0) - pad, (x + r[:, None]).max(axis=0) + pad
    lo, hi = (np.asarray(b, dtype=float).tolist() for b in (lo, hi))
    head = [f"LAMMPS data file of {n} spheres written by sinterheat (dem.scene.packing_files), units = si", "",
            f"{n} atoms", f"{int(types.max())} atom types", ""]
    head += [f"{lo[a]!r} {hi[a]!r} {c}lo {c}hi" for a, c in enumerate(AXES)]
    parts = ["\n".join(head + ["", "Atoms # sphere", ""]) + "\n",
             _rows_text([ids, types, 2.0 * r, rho, *x.T, *np.asarray(image).T], " ")]
    if packing.velocity is not None:
        w = packing.angular_velocity if packing.angular_velocity is not None else np.zeros((n, 3))
        parts += ["\nVelocities\n\n", _rows_text([ids, *packing.velocity.T, *w.T], " ")]
    _write_text(path, parts)
    return path


def wrapped(packing: Packing, what: str = "packing") -> tuple[np.ndarray, np.ndarray]:
    """The centres of ``packing`` in its box, ``lo <= x < hi`` (LAMMPS's rule), and their image flags: along a
    periodic axis a centre outside is moved by whole periods and its flag counts them (``x + image L`` is kept);
    along any other (or where the packing cannot say which axes are periodic) a centre outside is refused with
    ``ValueError`` naming the particle and ``what`` (LAMMPS would lose it: "Did not assign all atoms correctly").

    Parameters
    ----------
    packing : Packing
        The packing, with a box (``box_lo``, ``box_hi``).
    what : str
        What the error message calls the packing (a file's name, say).

    Returns
    -------
    tuple of (numpy.ndarray, numpy.ndarray)
        The wrapped centres, (N, 3) m, and their image flags, (N, 3) int.

    Raises
    ------
    ValueError
        A centre lies outside the box along an axis that is not periodic (or not known to be).
    """
    x = np.array(packing.position, dtype=float)
    image = (np.zeros((packing.n, 3), dtype=np.int64) if packing.image is None
             else np.array(packing.image, dtype=np.int64))
    lo, hi = np.asarray(packing.box_lo, dtype=float), np.asarray(packing.box_hi, dtype=float)
    periodic = packing.periodic if packing.periodic is not None else (False, False, False)
    for a in range(3):
        length = hi[a] - lo[a]
        if periodic[a]:
            k = np.floor((x[:, a] - lo[a]) / length)
            x[:, a] -= k * length
            x[:, a] = np.where(x[:, a] >= hi[a], lo[a], np.maximum(x[:, a], lo[a]))  # round-off at the faces
            image[:, a] += k.astype(np.int64)
            continue
        outside = np.flatnonzero((x[:, a] < lo[a]) | (x[:, a] >= hi[a]))
        if outside.size:
            m = int(outside[0])
            unknown = " (which axes are periodic is not known: give them, e.g. --periodic xy)" \
                if packing.periodic is None else ""
            raise ValueError(f"{what}: particle id {packing.id[m]} has {AXES[a]} = {float(x[m, a])!r} m, outside the "
                             f"box [{float(lo[a])!r}, {float(hi[a])!r}) along {AXES[a]}, which is not periodic{unknown}; "
                             f"{outside.size} particle(s) lie outside it (LAMMPS would lose them)")
    return x, image


def _types(material, n: int) -> np.ndarray:
    if material is None:
        return np.ones(n, dtype=np.int64)
    material = np.asarray(material)
    if material.dtype.kind in "iu":
        return material.astype(np.int64) + 1
    names = list(dict.fromkeys(material.tolist()))
    return np.array([names.index(m) + 1 for m in material.tolist()], dtype=np.int64)


def write_csv(path, packing: Packing) -> pathlib.Path:
    """Write ``packing`` as CSV (``id, x, y, z, radius`` and its optional columns), numbers that read back to the
    same doubles.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write.
    packing : Packing
        The packing.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    path = pathlib.Path(path)
    columns = {"id": packing.id, "x": packing.position[:, 0], "y": packing.position[:, 1],
               "z": packing.position[:, 2], "radius": packing.radius}
    for key in ("temperature", "fixed", "material", "density"):
        if getattr(packing, key) is not None:
            columns[key] = getattr(packing, key)
    names = np.asarray(columns.get("material", [])).tolist()
    if any("," in str(name) or '"' in str(name) for name in names):
        raise ValueError(f"{path.name}: material names with commas or quotes cannot be written as CSV")
    _write_text(path, [",".join(columns) + "\n", _rows_text(list(columns.values()), ",")])
    return path


def write_vtu(path, packing: Packing) -> pathlib.Path:
    """Write ``packing`` as a VTU point set (vertex cells) with the point fields ``id``, ``radius`` and its
    optional ones: what ParaView opens and :func:`read_packing` reads back.

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write.
    packing : Packing
        The packing.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    import meshio

    from dem.output.writer import write_vtu as write_whole

    fields = {"id": packing.id, "radius": packing.radius}
    for key in ("temperature", "density", "velocity", "angular_velocity"):
        if getattr(packing, key) is not None:
            fields[key] = getattr(packing, key)
    if packing.fixed is not None:
        fields["fixed"] = packing.fixed.astype(np.int8)
    if packing.material is not None and np.asarray(packing.material).dtype.kind in "iu":
        fields["material"] = np.asarray(packing.material, dtype=np.int32)
    path = pathlib.Path(path)
    write_whole(path, meshio.Mesh(packing.position, [("vertex", np.arange(packing.n).reshape(-1, 1))],
                                  point_data=fields))
    return path


def _write_text(path: pathlib.Path, parts) -> None:
    """Write the strings (or iterables of strings) ``parts`` to ``path``: aside, then renamed, so that a file on disk
    is always whole."""
    def write(fh):
        for part in parts:
            fh.writelines([part] if isinstance(part, str) else part)

    write_aside(path, write)
