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
  ``radius`` or ``diameter``, optional ``mass`` or ``density``, ``temperature`` (LIGGGHTS: ``f_Temp``), ``vx vy vz``,
  ``omegax omegay omegaz``, ``ix iy iz``. ``ITEM: BOX BOUNDS`` gives the box and, with its ``pp``/``ff``/``ss``
  flags, the periodic axes.
* ``vtk`` -- a VTK point set (``.vtu``, ``.vtp``, legacy ``.vtk``: what LIGGGHTS, Yade, ParaView and this toolkit's
  runs write), read by VTK itself (pyvista): the points are the centres, a point field ``radius`` (Yade: ``radii``)
  or ``diameter`` the sizes, and the fields ``id``, ``temperature``, ``fixed``, ``material`` (Yade:
  ``materialId``; LIGGGHTS: ``type``, from 1), ``density`` or ``mass``, ``velocity`` (Yade: ``linVelVec``; LIGGGHTS:
  ``v``) are read where present.

The format comes from the file's name (``.csv``; ``.data``, ``.lmp`` or a name ``data.*``; ``.dump``,
``.lammpstrj`` or ``dump.*``; ``.vtu``, ``.vtp``, ``.vtk``) or an explicit ``format``. Lengths are multiplied by
``length_unit`` (0.001 for a file in mm, 1e-6 in um; densities stay kg/m^3); a LAMMPS file that records its unit
style (the title line ``units = cgs`` of ``write_data``, ``ITEM: UNITS`` of a dump) is converted from it. Particles
read from LAMMPS files are sorted by id (LAMMPS writes them in the order of its processors); other files keep their
order. A bad file raises ``ValueError`` with one line naming the file, the line and the column.

The other way: :func:`write_lammps_data` writes a packing (read here, from a scene's particles, or from a saved
moving state, :func:`packing_from_state`) as a LAMMPS data file of ``atom_style sphere`` that ``read_data`` reads;
:func:`write_csv` and :func:`write_vtu` write the two other formats.
"""

from __future__ import annotations

import csv
import io
import math
import mmap
import pathlib
import re
import warnings
from dataclasses import dataclass, field, replace

import numpy as np

FORMATS = ("csv", "lammps-data", "lammps-dump", "vtk")
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
    not read."""

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
        return len(self.radius)

    def periodic_box(self, axes=None, drop=None):
        """The file's box as a :class:`dem.periodic.PeriodicBox`, periodic along ``axes`` (default: the file's
        periodic axes); ``drop`` the temperature drop per period. ``ValueError`` when the file gives no box."""
        from dem.periodic import PeriodicBox

        if self.box_lo is None:
            raise ValueError(f"{self.source}: gives no box (a LAMMPS data file or dump does)")
        if axes is None:
            axes = self.periodic if self.periodic is not None else (False, False, False)
        return PeriodicBox(self.box_hi - self.box_lo, tuple(axes), self.box_lo, drop)


class FileError(ValueError):
    """A bad file: one line naming the file, the line and the column."""

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
    """The format of a packing file, from its name (module docstring); ``ValueError`` when the name does not say."""
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
    raise ValueError(f"{path}: the format is not known from the name; give format = one of {', '.join(FORMATS)} "
                     "(extensions: .csv; .data, .lmp, data.*; .dump, .lammpstrj, dump.*; .vtu, .vtp, .vtk)")


def read_packing(path, format: str | None = None, length_unit: float = 1.0, timestep: int | None = None,
                 periodic=None) -> Packing:
    """The packing in the file ``path`` (module docstring). ``format``: one of :data:`FORMATS` (default: from the
    name); ``length_unit``: metres per length unit of the file; ``timestep``: the snapshot of a dump (default: the
    last); ``periodic``: the periodic axes, as ``"xyz"``-letters or three bools, for files that do not record them
    (a LAMMPS data file) or to override them."""
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
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    reader = {"csv": _read_csv, "lammps-data": _read_data, "lammps-dump": _read_dump, "vtk": _read_vtk}[fmt]
    try:
        packing = reader(path, float(length_unit), timestep)
    except UnicodeDecodeError as exc:
        raise ValueError(f"{path}: cannot be read as text ({exc.reason} at byte {exc.start})") from None
    if axes is not None:
        packing = replace(packing, periodic=axes)
    return _checked(packing, path, fmt)


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


def _floats(path, texts, lines, column: int, name: str) -> np.ndarray:
    """The strings ``texts`` (from the file's lines ``lines``, one per entry) as finite floats; a bad entry raises
    :class:`FileError` naming its line and ``column``."""
    try:
        values = np.array(texts, dtype=float)
    except ValueError:
        values = None
    if values is None or not np.all(np.isfinite(values)):
        for k, text in enumerate(texts):
            try:
                v = float(text)
            except ValueError:
                raise FileError(path, f"{text!r} is not a number", lines[k], column, name) from None
            if not math.isfinite(v):
                raise FileError(path, f"{text!r}: must be finite", lines[k], column, name)
    return values


def _integers(path, texts, lines, column: int, name: str) -> np.ndarray:
    values = _floats(path, texts, lines, column, name)
    bad = np.flatnonzero(values != np.round(values))
    if bad.size:
        k = int(bad[0])
        raise FileError(path, f"{texts[k]!r} is not an integer", lines[k], column, name)
    return values.astype(np.int64)


# ------------------------------------------------------------------------------------------------------ CSV
CSV_ALIASES = {"points:0": "x", "points:1": "y", "points:2": "z"}
CSV_COLUMNS = ("id", "x", "y", "z", "radius", "diameter", "temperature", "fixed", "material", "density")
TRUE, FALSE = {"true", "1", "yes", "t"}, {"false", "0", "no", "f", ""}


def _read_csv(path: pathlib.Path, length_unit: float, _timestep=None) -> Packing:
    with path.open(newline="") as fh:
        numbered = [(k + 1, line) for k, line in enumerate(fh) if line.strip() and not line.lstrip().startswith("#")]
    if not numbered:
        raise FileError(path, "empty: needs a header row (x, y, z, radius, ...) and a row per particle")
    rows = list(csv.reader(line for _, line in numbered))
    header_line, header = numbered[0][0], [h.strip() for h in rows[0]]
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
    body, lines = rows[1:], [line for line, _ in numbered[1:]]
    if not body:
        raise FileError(path, "no particle rows after the header", header_line)
    for row, line in zip(body, lines):
        if len(row) != len(header):
            raise FileError(path, f"{len(row)} values, but the header names {len(header)} columns", line)
    columns = list(zip(*body))

    def column(name):
        k = names.index(name)
        return [t.strip() for t in columns[k]], k + 1

    def numbers(name):
        texts, col = column(name)
        return _floats(path, texts, lines, col, header[col - 1])

    position = np.column_stack([numbers(a) for a in AXES])
    radius = numbers("radius") if size == "radius" else 0.5 * numbers("diameter")
    out = {}
    if "id" in names:
        texts, col = column("id")
        out["id"] = _integers(path, texts, lines, col, header[col - 1])
    if "temperature" in names:
        out["temperature"] = numbers("temperature")
    if "density" in names:
        out["density"] = numbers("density")
    if "fixed" in names:
        texts, col = column("fixed")
        words = [t.lower() for t in texts]
        bad = [k for k, w in enumerate(words) if w not in TRUE | FALSE]
        if bad:
            raise FileError(path, f"{texts[bad[0]]!r}: must be true or false (or 1, 0)", lines[bad[0]], col, "fixed")
        out["fixed"] = np.array([w in TRUE for w in words])
    if "material" in names:
        texts, col = column("material")
        if all(re.fullmatch(r"[+-]?\d+", t) for t in texts):
            out["material"] = _integers(path, texts, lines, col, "material")
            if np.any(out["material"] < 0):
                k = int(np.flatnonzero(out["material"] < 0)[0])
                raise FileError(path, f"{texts[k]!r}: a material index must be >= 0", lines[k], col, "material")
        else:
            empty = [k for k, t in enumerate(texts) if not t]
            if empty:
                raise FileError(path, "empty: a material index or name", lines[empty[0]], col, "material")
            out["material"] = np.array(texts, dtype=str)
    ignored = tuple(h for h, name in zip(header, names) if name not in CSV_COLUMNS)
    ids = out.pop("id", np.arange(len(radius), dtype=np.int64))
    return _scaled(Packing(ids, position, radius, ignored=ignored, **out), length_unit)


# ------------------------------------------------------------------------------------------------ LAMMPS data
DATA_SECTIONS = ("Atoms", "Velocities", "Masses", "Ellipsoids", "Lines", "Triangles", "Bodies", "Bonds", "Angles",
                 "Dihedrals", "Impropers", "Pair Coeffs", "PairIJ Coeffs", "Bond Coeffs", "Angle Coeffs",
                 "Dihedral Coeffs", "Improper Coeffs", "BondBond Coeffs", "BondAngle Coeffs",
                 "MiddleBondTorsion Coeffs", "EndBondTorsion Coeffs", "AngleTorsion Coeffs", "AngleAngleTorsion Coeffs",
                 "BondBond13 Coeffs", "AngleAngle Coeffs")
SPHERE_COLUMNS = ("id", "type", "diameter", "density", "x", "y", "z", "ix", "iy", "iz")
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
    with path.open() as fh:
        lines = fh.read().splitlines()
    if not lines:
        raise FileError(path, "empty: not a LAMMPS data file")
    title = UNITS_TITLE.search(lines[0])
    units = title.group(1) if title else None
    length, density_unit = _lammps_units(path, units, 1, length_unit)
    n_atoms, lo, hi = None, [None] * 3, [None] * 3
    k = 1
    while k < len(lines):  # the header: counts and box bounds, up to the first section keyword
        text = lines[k].split("#")[0].strip()
        if text in DATA_SECTIONS:
            break
        words = text.split()
        if len(words) == 2 and words[1] == "atoms":
            n_atoms = int(_integers(path, [words[0]], [k + 1], 1, "atoms")[0])
        elif len(words) == 4 and words[2][1:] == "lo" and words[3][1:] == "hi" and words[2][0] in AXES:
            a = AXES.index(words[2][0])
            lo[a], hi[a] = (float(_floats(path, [w], [k + 1], c + 1, f"{words[2][0]}{s}")[0])
                            for c, (w, s) in enumerate(zip(words[:2], ("lo", "hi"))))
        elif len(words) == 6 and words[3:] == ["xy", "xz", "yz"]:
            tilt = _floats(path, words[:3], [k + 1] * 3, 1, "xy xz yz")
            if np.any(tilt != 0):
                raise FileError(path, "a triclinic box (tilt factors xy xz yz not zero): only orthogonal boxes are "
                                "read", k + 1)
        elif words and words[0] in ("avec", "bvec", "cvec", "abc"):
            raise FileError(path, "a general triclinic box: only orthogonal boxes are read", k + 1)
        k += 1
    if n_atoms is None:
        raise FileError(path, "no 'N atoms' line in the header: not a LAMMPS data file")
    sections = _data_sections(lines, k)
    if "Atoms" not in sections:
        raise FileError(path, "no Atoms section")
    start, style, rows = sections["Atoms"]
    if style and style.split()[0] != "sphere":
        raise FileError(path, f"atom_style {style}: only atom_style sphere (id type diameter density x y z) is read",
                        start)
    if len(rows) != n_atoms:
        raise FileError(path, f"the Atoms section has {len(rows)} lines but the header says {n_atoms} atoms", start)
    columns = _table(path, rows, (7, 10), SPHERE_COLUMNS, "atom_style sphere: id type diameter density x y z "
                     "[ix iy iz]")
    nums = [row[0] for row in rows]
    ids = _integers(path, columns[0], nums, 1, "id")
    diameter = _floats(path, columns[2], nums, 3, "diameter")
    bad = np.flatnonzero(diameter <= 0)
    if bad.size:  # diameter 0 is a LAMMPS point particle, whose density column is its mass
        raise FileError(path, f"diameter = {columns[2][bad[0]]}: must be > 0 (a sphere)", nums[bad[0]], 3, "diameter")
    out = {"material": _integers(path, columns[1], nums, 2, "type") - 1,
           "density": _floats(path, columns[3], nums, 4, "density") * density_unit}
    position = np.column_stack([_floats(path, columns[4 + a], nums, 5 + a, AXES[a]) for a in range(3)])
    if len(columns) == 10:
        out["image"] = np.column_stack([_integers(path, columns[7 + a], nums, 8 + a, f"i{AXES[a]}") for a in range(3)])
    if "Velocities" in sections:
        vstart, _, vrows = sections["Velocities"]
        vcols = _table(path, vrows, (7,), VELOCITY_COLUMNS, "atom_style sphere: id vx vy vz wx wy wz")
        vnums = [row[0] for row in vrows]
        vids = _integers(path, vcols[0], vnums, 1, "id")
        where = {int(i): k for k, i in enumerate(ids)}
        missing = [int(i) for i in vids if int(i) not in where]
        if missing or len(vids) != len(ids):
            raise FileError(path, "the Velocities section must list every atom of the Atoms section once", vstart)
        order = np.array([where[int(i)] for i in vids])
        velocity, omega = np.zeros((len(ids), 3)), np.zeros((len(ids), 3))
        for a in range(3):
            velocity[order, a] = _floats(path, vcols[1 + a], vnums, 2 + a, VELOCITY_COLUMNS[1 + a])
            omega[order, a] = _floats(path, vcols[4 + a], vnums, 5 + a, VELOCITY_COLUMNS[4 + a])
        out.update(velocity=velocity, angular_velocity=omega)
    if any(v is None for v in lo):
        a = next(a for a in range(3) if lo[a] is None)
        raise FileError(path, f"no '{AXES[a]}lo {AXES[a]}hi' line in the header")
    order = np.argsort(ids, kind="stable")
    packing = Packing(ids, position, 0.5 * diameter, box_lo=np.array(lo, dtype=float),
                      box_hi=np.array(hi, dtype=float), units=units, **out)
    return _sorted(_scaled(packing, length), order)


def _data_sections(lines, first: int) -> dict:
    """``{keyword: (line number, style comment, [(line number, words), ...])}`` of the sections from ``lines[first]``
    on."""
    sections, current = {}, None
    for k in range(first, len(lines)):
        text, _, comment = lines[k].partition("#")
        text = text.strip()
        if text in DATA_SECTIONS:
            current = []
            sections[text] = (k + 1, comment.strip(), current)
        elif text and current is not None:
            current.append((k + 1, text.split()))
    return sections


def _table(path, rows, counts, names, layout) -> list[list[str]]:
    """The columns of the rows ``[(line, words)]``, each row with one of ``counts`` words."""
    width = len(rows[0][1]) if rows else counts[0]
    for line, words in rows:
        if len(words) not in counts or len(words) != width:
            raise FileError(path, f"{len(words)} values; expected {' or '.join(map(str, counts))} ({layout})", line)
    return [list(c) for c in zip(*(words for _, words in rows))] if rows else [[] for _ in names[:width]]


def _sorted(p: Packing, order: np.ndarray) -> Packing:
    arrays = {k: getattr(p, k)[order] for k in ("id", "position", "radius", "temperature", "fixed", "material",
                                                 "density", "velocity", "angular_velocity", "image")
              if getattr(p, k) is not None}
    return replace(p, **arrays)


# ------------------------------------------------------------------------------------------------ LAMMPS dump
DUMP_POSITIONS = (("x", "y", "z"), ("xu", "yu", "zu"), ("xs", "ys", "zs"), ("xsu", "ysu", "zsu"))
DUMP_TEMPERATURE = ("temperature", "temp", "f_temp", "f_temperature")


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
        before = data.rfind(b"ITEM: UNITS", 0, begin)  # LAMMPS writes it once, before the first snapshot
        end = starts[pick + 1] if pick + 1 < len(starts) else len(data)
        first_line = data[:begin].count(b"\n") + 1
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
    if len(text) < 2:
        raise FileError(path, "ITEM: TIMESTEP without a timestep", line - 1)
    return int(_integers(path, [text[1].strip()], [line], 1, "timestep")[0])


def _parse_frame(path, frame: str, first_line: int, step: int, units: str | None, scales) -> Packing:
    lines = frame.split("\n")
    items, k = {}, 0
    while k < len(lines):
        if lines[k].startswith("ITEM:"):
            items[lines[k][5:].strip().split(" ")[0]] = k
            if lines[k].startswith("ITEM: ATOMS"):
                break
        k += 1
    if "NUMBER" not in items or "BOX" not in items or "ATOMS" not in items:
        missing = next(m for m in ("NUMBER OF ATOMS", "BOX BOUNDS", "ATOMS") if m.split()[0] not in items)
        raise FileError(path, f"timestep {step}: no 'ITEM: {missing}' line", first_line)
    line_of = lambda j: first_line + j  # noqa: E731 -- file line of the frame's line j
    n = int(_integers(path, [lines[items["NUMBER"] + 1].strip()], [line_of(items["NUMBER"] + 1)], 1, "atoms")[0])
    box_head = lines[items["BOX"]].split()[3:]
    flags = [w for w in box_head if w not in ("xy", "xz", "yz")]
    if box_head and box_head[0] == "abc":
        raise FileError(path, "a general triclinic box: only orthogonal boxes are read", line_of(items["BOX"]))
    lo, hi, tilted = np.zeros(3), np.zeros(3), len(flags) != len(box_head)
    for a in range(3):
        j = items["BOX"] + 1 + a
        words = lines[j].split() if j < len(lines) else []
        if len(words) != (3 if tilted else 2):
            raise FileError(path, f"box bounds of {AXES[a]}: expected {'3' if tilted else '2'} numbers", line_of(j))
        lo[a], hi[a] = (_floats(path, [w], [line_of(j)], c + 1, f"{AXES[a]}{s}")[0]
                        for c, (w, s) in enumerate(zip(words[:2], ("lo", "hi"))))
        if tilted and float(words[2]) != 0.0:
            raise FileError(path, "a triclinic box (tilt factors not zero): only orthogonal boxes are read",
                            line_of(j), 3)
    periodic = tuple(f == "pp" for f in flags) if len(flags) == 3 else None
    names = lines[items["ATOMS"]].split()[2:]
    keys = [name.lower() for name in names]
    head = items["ATOMS"]
    rows = [line for line in lines[head + 1:head + 1 + n]]
    if len(rows) < n or any(not r.strip() for r in rows):
        got = sum(1 for r in rows if r.strip())
        raise FileError(path, f"timestep {step}: {got} atom lines, but ITEM: NUMBER OF ATOMS says {n}",
                        line_of(head))
    after = head + 1 + n
    if after < len(lines) and lines[after].strip() and not lines[after].startswith("ITEM:"):
        raise FileError(path, f"timestep {step}: more atom lines than ITEM: NUMBER OF ATOMS says ({n})",
                        line_of(after))
    words = [r.split() for r in rows]
    for j, w in enumerate(words):
        if len(w) != len(names):
            raise FileError(path, f"{len(w)} values, but ITEM: ATOMS names {len(names)} columns", line_of(head + 1 + j))
    columns = list(zip(*words))
    numbers = [line_of(head + 1 + j) for j in range(n)]

    def col(name, integer=False):
        k = keys.index(name)
        return (_integers if integer else _floats)(path, columns[k], numbers, k + 1, names[k])

    length, density_unit = scales
    position_names = next((c for c in DUMP_POSITIONS if all(a in keys for a in c)), None)
    if position_names is None:
        raise FileError(path, f"no position columns in ITEM: ATOMS ({' '.join(names)}); needs x y z (or xu yu zu, "
                        "xs ys zs, xsu ysu zsu)", line_of(head))
    if "radius" not in keys and "diameter" not in keys:
        raise FileError(path, f"no radius or diameter column in ITEM: ATOMS ({' '.join(names)})", line_of(head))
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


# ------------------------------------------------------------------------------------------------------ VTK
VTK_FIELDS = {"radius": ("radius", "radii"), "diameter": ("diameter", "diameters"), "id": ("id", "ids"),
              "temperature": ("temperature", "temp", "f_temp"), "fixed": ("fixed",),
              "material": ("material", "materialid"), "type": ("type",), "density": ("density",), "mass": ("mass",),
              "velocity": ("velocity", "v", "linvelvec"), "angular_velocity": ("angular_velocity", "omega",
                                                                               "angvelvec")}


def _read_vtk(path: pathlib.Path, length_unit: float, _timestep=None) -> Packing:
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # a bad file: our one line, not VTK's log
    with warnings.catch_warnings(record=True) as caught:  # pyvista reports a reader's error as a warning
        warnings.simplefilter("always")
        try:
            mesh = pv.read(str(path))
        except Exception as exc:  # VTK's readers raise many kinds; the file is what is wrong
            raise ValueError(f"{path}: cannot be read as VTK ({' '.join(str(exc).split())})") from None
    if mesh is None or not hasattr(mesh, "point_data") or mesh.n_points == 0:
        if caught:
            raise ValueError(f"{path}: cannot be read as VTK ({' '.join(str(caught[0].message).split())})")
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


def scene_particles(table: dict, materials, base_dir=None):
    """``[particles] file = "..."`` of a scene: the :class:`dem.particles.Particles` of the file (``format``,
    ``length_unit``, ``timestep`` as for :func:`read_packing`; the path relative to ``base_dir``, the scene's folder)
    and the file's box as a :class:`dem.periodic.PeriodicBox` (periodic along the axes the file says are, none where
    it cannot say), or None. ``temperature`` (a number or a list), ``fixed``, ``material`` (a name or index, or a
    list of them) and ``heat`` come from the table where given, else from the file; a density the file gives must be
    its material's."""
    from dem.particles import Particles, material_indices

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
    try:
        packing = read_packing(path, **options)
    except ValueError as exc:
        raise ValueError(f"[particles] file: {exc}") from None
    n = packing.n
    values = {}
    for key in ("temperature", "fixed", "heat"):
        value = table.get(key, getattr(packing, key, None))
        if isinstance(value, (int, float)) and not isinstance(value, bool) and key != "fixed":
            value = np.full(n, float(value))
        elif isinstance(value, bool) and key == "fixed":
            value = np.full(n, value)
        values[key] = value
    if values["temperature"] is None:
        raise ValueError(f"[particles] temperature: required (a number or a list); {name!r} has no temperature column")
    material = material_indices("[particles] material" if "material" in table else f"[particles] file {name!r}: "
                                "material", table.get("material", packing.material), materials, n)
    particles = Particles.from_arrays(packing.position, packing.radius, values["temperature"], materials, material,
                                      values["fixed"], values["heat"], prefix="[particles]", id=packing.id)
    if packing.density is not None:
        expected = np.array([m.density for m in particles.materials])[particles.material]
        off = np.flatnonzero(np.abs(packing.density - expected) > DENSITY_RTOL * expected)
        if off.size:
            k = int(off[0])
            m = particles.materials[particles.material[k]]
            raise ValueError(f"[particles] file {name!r}: particle id {packing.id[k]} has density "
                             f"{packing.density[k]:.6g} kg/m^3 but its material {m.name!r} {m.density:.6g}; give the "
                             "material that density (with [[materials]] for several: LAMMPS type k is material k - 1)")
    box = packing.periodic_box() if packing.box_lo is not None else None
    return particles, box


# --------------------------------------------------------------------------------------------------- writing
def packing_from_particles(particles, box=None) -> Packing:
    """A :class:`Packing` of a scene's :class:`dem.particles.Particles` (densities from its materials) in the
    periodic box ``box`` (:class:`dem.periodic.PeriodicBox`) or none."""
    density = np.array([m.density for m in particles.materials], dtype=float)[particles.material]
    lo = hi = periodic = None
    if box is not None:
        lo, hi, periodic = box.origin, box.origin + box.lengths, tuple(box.periodic)
    return Packing(particles.id, particles.position, particles.radius, particles.temperature, particles.fixed,
                   particles.material, density, box_lo=lo, box_hi=hi, periodic=periodic)


def packing_from_state(state: dict) -> Packing:
    """A :class:`Packing` of a saved moving state (:func:`dem.state_file.load`): positions, radii, temperatures,
    velocities and angular velocities; the density is the one that gives each particle its saved mass as a sphere
    (``m / (4/3 pi r^3)``, also what LAMMPS computes the mass from). 3D states only: a 2D state's disks lie in the
    x-z plane with a height, which LAMMPS's 2D spheres (x-y plane) do not have."""
    if int(state["dimension"]) != 3:
        raise ValueError("state: a 2D state (disks in the x-z plane): only 3D states can be written as packings")
    radius = np.asarray(state["radius"], dtype=float)
    ids = state["id"] if "id" in state else np.arange(len(radius), dtype=np.int64)
    return Packing(np.asarray(ids, dtype=np.int64), np.asarray(state["x"], dtype=float), radius,
                   np.asarray(state["T"], dtype=float), density=state["mass"] / (SPHERE_VOLUME * radius**3),
                   velocity=np.asarray(state["v"], dtype=float), angular_velocity=np.asarray(state["w"], dtype=float))


def lammps_ids(ids: np.ndarray) -> np.ndarray:
    """The atom ids a packing gets in LAMMPS, which numbers atoms from 1: its own ids where all are >= 1, else its
    ids + 1 (this toolkit numbers particles from 0)."""
    ids = np.asarray(ids, dtype=np.int64)
    return ids if ids.min() >= 1 else ids + 1 - min(int(ids.min()), 0)


def write_lammps_data(path, packing: Packing, density=None, pad: float = 0.0) -> pathlib.Path:
    """Write ``packing`` as a LAMMPS data file of ``atom_style sphere`` (``units si``): the header (atoms, atom
    types, box), ``Atoms # sphere`` (``id type diameter density x y z ix iy iz``) and, where the packing has
    velocities, ``Velocities`` (``id vx vy vz wx wy wz``). Ids from :func:`lammps_ids`; type = material index + 1
    (names: their order of appearance); ``density`` kg/m^3 (one number or per particle) where the packing has none.
    The box is the packing's, or the particles' bounding box grown by ``pad`` (m) beyond the largest radius; the
    periodicity is not part of a data file: the input script's ``boundary`` command sets it. Numbers are written
    to round-trip (17 significant digits)."""
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
    if packing.box_lo is not None:
        lo, hi = packing.box_lo, packing.box_hi
    else:
        lo, hi = (x - r[:, None]).min(axis=0) - pad, (x + r[:, None]).max(axis=0) + pad
    image = packing.image if packing.image is not None else np.zeros((n, 3), dtype=np.int64)
    ids = lammps_ids(packing.id)
    head = [f"LAMMPS data file of {n} spheres written by sinterheat (dem.packing_files), units = si", "",
            f"{n} atoms", f"{int(types.max())} atom types", ""]
    g = "{:.17g}".format
    head += [f"{g(lo[a])} {g(hi[a])} {c}lo {c}hi" for a, c in enumerate(AXES)]
    rows = [f"{ids[k]} {types[k]} {g(2.0 * r[k])} {g(rho[k])} {g(x[k, 0])} {g(x[k, 1])} {g(x[k, 2])} "
            f"{image[k, 0]} {image[k, 1]} {image[k, 2]}" for k in range(n)]
    text = head + ["", "Atoms # sphere", ""] + rows
    if packing.velocity is not None:
        v = packing.velocity
        w = packing.angular_velocity if packing.angular_velocity is not None else np.zeros((n, 3))
        text += ["", "Velocities", ""] + [f"{ids[k]} {g(v[k, 0])} {g(v[k, 1])} {g(v[k, 2])} {g(w[k, 0])} "
                                          f"{g(w[k, 1])} {g(w[k, 2])}" for k in range(n)]
    _write_text(path, "\n".join(text) + "\n")
    return path


def _types(material, n: int) -> np.ndarray:
    if material is None:
        return np.ones(n, dtype=np.int64)
    material = np.asarray(material)
    if material.dtype.kind in "iu":
        return material.astype(np.int64) + 1
    names = list(dict.fromkeys(material.tolist()))
    return np.array([names.index(m) + 1 for m in material.tolist()], dtype=np.int64)


def write_csv(path, packing: Packing) -> pathlib.Path:
    """Write ``packing`` as CSV (``id, x, y, z, radius`` and its optional columns), numbers to round-trip."""
    path = pathlib.Path(path)
    columns = {"id": packing.id, "x": packing.position[:, 0], "y": packing.position[:, 1],
               "z": packing.position[:, 2], "radius": packing.radius}
    for key in ("temperature", "fixed", "material", "density"):
        if getattr(packing, key) is not None:
            columns[key] = getattr(packing, key)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(columns)
    for row in zip(*columns.values()):
        writer.writerow([_csv_value(v) for v in row])
    _write_text(path, buffer.getvalue())
    return path


def _csv_value(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.17g}"
    return str(v)


def write_vtu(path, packing: Packing) -> pathlib.Path:
    """Write ``packing`` as a VTU point set (vertex cells) with the point fields ``id``, ``radius`` and its
    optional ones: what ParaView opens and :func:`read_packing` reads back."""
    import meshio

    from dem.io import write_vtu as write_whole

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


def _write_text(path: pathlib.Path, text: str) -> None:
    tmp = path.with_name(path.name + ".part")  # written aside, then renamed: a file on disk is always whole
    tmp.write_text(text)
    tmp.replace(path)
