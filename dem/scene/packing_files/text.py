"""Text files of numbers, as the CSV and LAMMPS readers of :mod:`dem.scene.packing_files` read them: tables parsed
at C speed, a bad entry named by its line and column (:class:`~dem.scene.packing_files.packing.FileError`), and a
text file written whole."""

from __future__ import annotations

import csv
import io
import math
import pathlib

import numpy as np

from dem.output.atomic import write_aside
from dem.scene.packing_files.packing import FileError


# A table of numbers is parsed at C speed (np.loadtxt); only a table that fails is read again, line by line, to name
# the line and column of the first bad entry.
def number_table(path, text: str, first_line: int, names, widths, what: str, delimiter=None,
                 usecols=None) -> np.ndarray:
    """The numbers of ``text`` -- rows of ``delimiter``-separated entries (whitespace by default; blank lines and
    ``#`` comments skipped) that start on the file's line ``first_line`` -- as an array (rows, columns): every row
    has the same number of entries, one of ``widths`` (``what`` says which in an error); ``usecols``: only these
    columns are converted (the others may hold words). ``names`` name the columns in errors.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, named in errors.
    text : str
        The table's text.
    first_line : int
        The file's line (from 1) on which ``text`` starts.
    names : sequence of str
        The columns' names, in errors.
    widths : sequence of int
        The numbers of entries a row may have.
    what : str
        What an error says was expected of a row (``"7 or 10 (atom_style sphere: ...)"``).
    delimiter : str or None
        The separator of entries; None: whitespace.
    usecols : sequence of int or None
        The columns to convert; None: all.

    Returns
    -------
    numpy.ndarray
        (rows, columns) float, the table.

    Raises
    ------
    FileError
        A row of another width, or an entry that is not a finite number, naming its line and column.
    """
    if not text.strip():
        return np.empty((0, len(usecols) if usecols is not None else widths[0]))
    try:
        arr = np.loadtxt(io.StringIO(text), dtype=float, comments="#", delimiter=delimiter, ndmin=2, usecols=usecols,
                         quotechar='"' if delimiter else None)
    except ValueError:
        arr = None
    if arr is None or (usecols is None and arr.shape[1] not in widths) or not np.all(np.isfinite(arr)):
        locate(path, text, first_line, names, widths, what, delimiter, usecols)
        raise FileError(path, "cannot be read as a table of numbers", first_line)  # locate found nothing: unlikely
    return arr


def _data_lines(text: str, first_line: int):
    """``(file line, entries text)`` of the lines of ``text`` that hold entries (not blank, not a comment)."""
    for k, line in enumerate(text.split("\n")):
        body = line.split("#")[0]
        if body.strip():
            yield first_line + k, body


def locate(path, text, first_line, names, widths, what, delimiter, usecols) -> None:
    """Raise :class:`~dem.scene.packing_files.packing.FileError` at the first row of ``text`` with a number of entries not in ``widths`` (or unlike
    the first row's), or an entry (of ``usecols``) that is not a finite number; return where there is none.

    Parameters
    ----------
    path, text, first_line, names, widths, what, delimiter, usecols
        As for :func:`number_table`.

    Raises
    ------
    FileError
        The first bad row or entry, naming its line and column.
    """
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


def row_line(text: str, first_line: int, row: int) -> int:
    """The file line of row ``row`` of the table ``text`` (which starts on line ``first_line``).

    Parameters
    ----------
    text : str
        The table's text.
    first_line : int
        The file's line (from 1) on which ``text`` starts.
    row : int
        The row (from 0; blank lines and comments are no rows).

    Returns
    -------
    int
        The file's line of that row; ``first_line`` where the table has fewer rows.
    """
    for k, (line, _) in enumerate(_data_lines(text, first_line)):
        if k == row:
            return line
    return first_line


def check_rows(path, bad: np.ndarray, text: str, first_line: int, column: int, name: str, message) -> None:
    """Raise :class:`~dem.scene.packing_files.packing.FileError` at the first row where ``bad`` holds, ``message(row)`` saying what is wrong.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, named in the error.
    bad : numpy.ndarray
        (rows,) bool, True where a row is wrong.
    text : str
        The table's text.
    first_line : int
        The file's line (from 1) on which ``text`` starts.
    column : int
        The column (from 1) the error names.
    name : str
        That column's name.
    message : callable
        ``message(row)``: what is wrong with row ``row``.

    Raises
    ------
    FileError
        ``bad`` holds somewhere.
    """
    if np.any(bad):
        row = int(np.flatnonzero(bad)[0])
        raise FileError(path, message(row), row_line(text, first_line, row), column, name)


def integers(path, values: np.ndarray, text: str, first_line: int, column: int, name: str) -> np.ndarray:
    """The column ``values`` of the table ``text`` as integers; a fraction raises :class:`~dem.scene.packing_files.packing.FileError`.

    Parameters
    ----------
    path : str or pathlib.Path
        The file, named in errors.
    values : numpy.ndarray
        (rows,) float, the column's numbers.
    text, first_line, column, name
        As for :func:`check_rows`.

    Returns
    -------
    numpy.ndarray
        (rows,) int64, the column.

    Raises
    ------
    FileError
        An entry is not a whole number.
    """
    check_rows(path, values != np.round(values), text, first_line, column, name,
               lambda row: f"{float(values[row])!r} is not an integer")
    return values.astype(np.int64)


def first_entry_line(text: str, start: int = 0) -> tuple[int, int, str]:
    """``(offset after it, its line number, the line)`` of the first line of ``text`` that is neither blank nor a
    ``#`` comment, from offset ``start`` (line numbers from 1 at offset 0); ``(-1, line, "")`` when there is none.

    Parameters
    ----------
    text : str
        The file's text.
    start : int
        The offset in ``text`` to look from.

    Returns
    -------
    tuple of (int, int, str)
        The offset just after that line, its line number (from 1) and the line.
    """
    line = text.count("\n", 0, start) + 1
    while start < len(text):
        end = text.find("\n", start)
        end = len(text) if end < 0 else end
        here = text[start:end]
        if here.strip() and not here.lstrip().startswith("#"):
            return end + 1, line, here
        start, line = end + 1, line + 1
    return -1, line, ""


def write_text(path: pathlib.Path, parts) -> None:
    """Write the strings (or iterables of strings) ``parts`` to ``path``: aside, then renamed, so that a file on disk
    is always whole.

    Parameters
    ----------
    path : pathlib.Path
        The file to write.
    parts : iterable
        Strings, or iterables of strings (the rows of a table), written one after another.
    """
    def write(fh):
        for part in parts:
            fh.writelines([part] if isinstance(part, str) else part)

    write_aside(path, write)
