"""A run's snapshots as LAMMPS text dumps (``dump custom``), for OVITO and LAMMPS's tools (``[output] lammps_dump``).

:func:`write_dump` writes one snapshot: ``ITEM: UNITS`` (``si``), ``TIMESTEP``, ``NUMBER OF ATOMS``, ``BOX BOUNDS``
(``pp`` along the periodic axes, ``ff`` elsewhere) and ``ATOMS id type radius x y z`` followed by ``vx vy vz``,
``fx fy fz`` and ``T`` where the run has them. Numbers are written to round-trip (the shortest digits that read back to
the same double), so :func:`dem.scene.packing_files.read.read_packing` reads a snapshot back bit for bit. The same
formatting serves the LAMMPS data files of :mod:`dem.scene.packing_files.lammps` (:func:`rows_text`, :func:`lammps_ids`).
"""

from __future__ import annotations

import pathlib

import numpy as np

from dem.output.atomic import write_aside


def lammps_ids(ids: np.ndarray) -> np.ndarray:
    """The atom ids a packing gets in LAMMPS, which numbers atoms from 1: its own ids where all are >= 1, else its
    ids + 1 (this toolkit numbers particles from 0).

    Parameters
    ----------
    ids : numpy.ndarray
        (N,) int, the packing's ids (N >= 1).

    Returns
    -------
    numpy.ndarray
        (N,) int, the ids shifted (where needed) so that the smallest is 1.
    """
    ids = np.asarray(ids, dtype=np.int64)
    return ids if ids.min() >= 1 else ids + 1 - min(int(ids.min()), 0)


def rows_text(columns, sep: str, chunk: int = 100_000):
    """The rows of ``columns`` (arrays of one length) as lines of text, ``chunk`` rows per string yielded: floats as
    the shortest digits that read back to the same double (``repr``), integers as they are, bools as true/false.

    Parameters
    ----------
    columns : sequence of array_like
        The columns, each as long as the others.
    sep : str
        The separator between the words of a row.
    chunk : int
        Rows per string yielded.

    Yields
    ------
    str
        ``chunk`` rows (the last string fewer), each ending in a newline.
    """
    columns = [np.asarray(c) for c in columns]
    for start in range(0, len(columns[0]), chunk):
        words = []
        for column in (c[start:start + chunk] for c in columns):
            if column.dtype.kind == "b":
                words.append(np.where(column, "true", "false").tolist())
            else:
                words.append(list(map(repr if column.dtype.kind == "f" else str, column.tolist())))
        yield "\n".join(map(sep.join, zip(*words))) + "\n"


def write_dump(path, timestep: int, ids, types, radius, position, box_lo, box_hi, periodic, velocity=None,
               force=None, temperature=None) -> pathlib.Path:
    """Write one snapshot of a LAMMPS text dump (module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        The file to write (written aside, then moved into place).
    timestep : int
        The snapshot's step number (``ITEM: TIMESTEP``).
    ids : array_like
        (N,) int, the particles' ids (:func:`lammps_ids` makes them start at 1).
    types : array_like
        (N,) int, the LAMMPS atom types (from 1).
    radius : array_like
        (N,) radii, m.
    position : array_like
        (N, 3) centres, m.
    box_lo, box_hi : array_like
        (3,) the box's lower and upper corners, m.
    periodic : sequence of bool
        The box's periodic axes.
    velocity, force : array_like or None
        (N, 3) velocities (m/s) and forces (N); None: no such columns.
    temperature : array_like or None
        (N,) temperatures (the scene's unit); None: no ``T`` column.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    path = pathlib.Path(path)
    x = np.asarray(position, dtype=float).reshape(-1, 3)
    n = len(x)
    names = ["id", "type", "radius", "x", "y", "z"]
    columns = [lammps_ids(ids), np.asarray(types, dtype=np.int64), np.asarray(radius, dtype=float), *x.T]
    for extra, data in (("vx vy vz", velocity), ("fx fy fz", force)):
        if data is not None:
            names += extra.split()
            columns += list(np.asarray(data, dtype=float).reshape(n, 3).T)
    if temperature is not None:
        names.append("T")
        columns.append(np.asarray(temperature, dtype=float))
    flags = " ".join("pp" if p else "ff" for p in periodic)
    head = ["ITEM: UNITS", "si", "ITEM: TIMESTEP", str(int(timestep)), "ITEM: NUMBER OF ATOMS", str(n),
            f"ITEM: BOX BOUNDS {flags}", *(f"{float(box_lo[a])!r} {float(box_hi[a])!r}" for a in range(3)),
            "ITEM: ATOMS " + " ".join(names)]

    def write(fh):
        fh.write("\n".join(head) + "\n")
        for part in rows_text(columns, " "):
            fh.write(part)

    write_aside(path, write)
    return path
