"""The reader a packing file's name (or ``format``) picks (:func:`format_of`, :func:`read_packing`), and the checks
and warnings every packing read gets, whatever its format."""

from __future__ import annotations

import math
import pathlib
import warnings
from dataclasses import replace

import numpy as np

from dem.scene.packing_files.csv import read_csv
from dem.scene.packing_files.lammps import read_data, read_dump
from dem.scene.packing_files.packing import AXES, FORMATS, Packing
from dem.scene.packing_files.parts import read_whole
from dem.scene.packing_files.vtk import read_vtk


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
        A bad argument, or a bad file (:class:`~dem.scene.packing_files.packing.FileError`, one line naming the file, the line and the column).
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
    if fmt == "parts":  # a folder (dem.scene.packing_files.parts), in SI units as written
        if length_unit != 1.0:
            raise ValueError(f"length_unit = {length_unit!r}: a packing in parts is in metres (1)")
        packing = read_whole(path)
    elif not path.is_file():
        raise ValueError(f"{path}: no such file")
    else:
        try:
            if fmt == "lammps-dump":
                packing = read_dump(path, float(length_unit), timestep)
            else:
                packing = {"csv": read_csv, "lammps-data": read_data, "vtk": read_vtk}[fmt](path, float(length_unit))
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
