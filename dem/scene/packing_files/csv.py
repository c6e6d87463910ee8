"""Packings as CSV: a header row naming the columns, a row per particle (:func:`read_csv`, :func:`write_csv`; the
columns: :mod:`dem.scene.packing_files`)."""

from __future__ import annotations

import csv
import io
import pathlib
import re

import numpy as np

from dem.output.lammps_dump import rows_text
from dem.scene.packing_files.packing import AXES, FileError, Packing, scaled
from dem.scene.packing_files.text import check_rows, first_entry_line, integers, locate, number_table, write_text

CSV_ALIASES = {"points:0": "x", "points:1": "y", "points:2": "z"}
CSV_NUMBERS = ("id", "x", "y", "z", "radius", "diameter", "temperature", "density")
CSV_COLUMNS = CSV_NUMBERS + ("fixed", "material")
TRUE, FALSE = ("true", "1", "yes", "t", "1.0"), ("false", "0", "no", "f", "", "0.0")


def read_csv(path: pathlib.Path, length_unit: float) -> Packing:
    """The packing in the CSV file ``path`` (the columns: :mod:`dem.scene.packing_files`).

    Parameters
    ----------
    path : pathlib.Path
        The file.
    length_unit : float
        Metres per length unit of the file (> 0, checked by :func:`dem.scene.packing_files.read.read_packing`).

    Returns
    -------
    dem.scene.packing_files.packing.Packing
        The packing, in SI units.

    Raises
    ------
    dem.scene.packing_files.packing.FileError
        A bad file, naming the line and the column.
    """
    text = path.read_text()
    body_start, header_line, line = first_entry_line(text)
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
    table = number_table(path, body, first, header, (len(header),), what, ",", numeric)
    if len(table) == 0:
        raise FileError(path, "no particle rows after the header", header_line)
    if body.count(",") != len(table) * (len(header) - 1):  # a row of another width (or commas in comments)
        locate(path, body, first, header, (len(header),), what, ",", numeric)
    columns = {names[k]: table[:, j] for j, k in enumerate(numeric)}
    position = np.column_stack([columns[a] for a in AXES])
    radius = columns["radius"] if size == "radius" else 0.5 * columns["diameter"]
    out = {key: columns[key] for key in ("temperature", "density") if key in columns}
    ids = (integers(path, columns["id"], body, first, names.index("id") + 1, header[names.index("id")])
           if "id" in columns else np.arange(len(radius), dtype=np.int64))
    for key in ("fixed", "material"):
        if key in names:
            k = names.index(key)
            words = np.char.strip(np.loadtxt(io.StringIO(body), dtype=str, comments="#", delimiter=",", ndmin=2,
                                             usecols=[k], quotechar='"')[:, 0])
            out[key] = _csv_words(path, key, words, body, first, k + 1)
    ignored = tuple(h for h, name in zip(header, names) if name not in CSV_COLUMNS)
    return scaled(Packing(ids, position, radius, ignored=ignored, **out), length_unit)


def _csv_words(path, key: str, words: np.ndarray, body: str, first: int, column: int) -> np.ndarray:
    """``fixed`` as bools; ``material`` as indices (all integers) or names."""
    if key == "fixed":
        lower = np.char.lower(words)
        check_rows(path, ~np.isin(lower, TRUE + FALSE), body, first, column, key,
                    lambda row: f"{str(words[row])!r}: must be true or false (or 1, 0)")
        return np.isin(lower, TRUE)
    check_rows(path, words == "", body, first, column, key, lambda row: "empty: a material index or name")
    if all(re.fullmatch(r"[+-]?\d+", w) for w in words.tolist()):
        index = words.astype(np.int64)
        check_rows(path, index < 0, body, first, column, key,
                    lambda row: f"{str(words[row])!r}: a material index must be >= 0")
        return index
    return words



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
    write_text(path, [",".join(columns) + "\n", rows_text(list(columns.values()), ",")])
    return path
