"""Packings in LAMMPS's files: data files of ``atom_style sphere`` read (:func:`read_data`) and written
(:func:`write_lammps_data`), text dumps (``dump custom``, LIGGGHTS's too) read (:func:`read_dump`); the columns and
unit styles: :mod:`dem.scene.packing_files`. A run's own dumps: :mod:`dem.output.lammps_dump`."""

from __future__ import annotations

import mmap
import pathlib
import re
from dataclasses import replace

import numpy as np

from dem.output.lammps_dump import lammps_ids, rows_text
from dem.scene.packing_files.packing import AXES, FileError, Packing, density_from_mass, scaled
from dem.scene.packing_files.text import check_rows, integers, number_table, row_line, write_text

# LAMMPS unit styles a granular packing can be in: metres and kg/m^3 per unit of length and of density
LAMMPS_UNITS = {"si": (1.0, 1.0), "cgs": (1e-2, 1e3), "micro": (1e-6, 1e3), "nano": (1e-9, 1e6)}


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


def read_data(path: pathlib.Path, length_unit: float) -> Packing:
    """The packing in the LAMMPS data file ``path`` (``atom_style sphere``), sorted by id.

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
    atoms = number_table(path, body, first, SPHERE_COLUMNS, (7, 10), SPHERE_LAYOUT)
    if len(atoms) != n_atoms:
        raise FileError(path, f"the Atoms section has {len(atoms)} lines but the header says {n_atoms} atoms", start)
    ids = integers(path, atoms[:, 0], body, first, 1, "id")
    _unique_ids(path, ids, body, first)
    diameter = atoms[:, 2]
    check_rows(path, diameter <= 0, body, first, 3, "diameter",  # diameter 0: a LAMMPS point particle
                lambda row: f"diameter = {float(diameter[row])!r}: must be > 0 (a sphere)")
    out = {"material": integers(path, atoms[:, 1], body, first, 2, "type") - 1,
           "density": atoms[:, 3] * density_unit}
    if atoms.shape[1] == 10:
        out["image"] = np.column_stack([integers(path, atoms[:, 7 + a], body, first, 8 + a, f"i{AXES[a]}")
                                        for a in range(3)])
    if "Velocities" in sections:
        vstart, _, vbody, vfirst = sections["Velocities"]
        v = number_table(path, vbody, vfirst, VELOCITY_COLUMNS, (7,), "7 (atom_style sphere: id vx vy vz wx wy wz)")
        vids = integers(path, v[:, 0], vbody, vfirst, 1, "id")
        order, where = np.argsort(ids), np.argsort(vids)
        if len(vids) != len(ids) or np.any(ids[order] != vids[where]):
            raise FileError(path, "the Velocities section must list every atom of the Atoms section once", vstart)
        velocity, omega = np.empty((len(ids), 3)), np.empty((len(ids), 3))
        velocity[order], omega[order] = v[where, 1:4], v[where, 4:7]
        out.update(velocity=velocity, angular_velocity=omega)
    packing = Packing(ids, atoms[:, 4:7], 0.5 * diameter, box_lo=lo, box_hi=hi, units=units, **out)
    return _sorted(scaled(packing, length), np.argsort(ids, kind="stable"))


def _unique_ids(path, ids: np.ndarray, body: str, first: int) -> None:
    """Refuse an id given to two atoms of a section, naming both lines (before any other section is matched to
    the atoms)."""
    order = np.argsort(ids, kind="stable")
    same = np.flatnonzero(ids[order][1:] == ids[order][:-1])
    if same.size:
        a, b = order[same[0]], order[same[0] + 1]
        raise FileError(path, f"id {ids[a]} is given to two atoms (lines {row_line(body, first, a)} and "
                        f"{row_line(body, first, b)}); ids must be unique", row_line(body, first, b))


def _data_header(path, header: str) -> tuple[int, np.ndarray, np.ndarray]:
    """The atom count and the box bounds of a data file's header (the lines before its first section)."""
    n_atoms, lo, hi = None, [None] * 3, [None] * 3
    for k, line in enumerate(header.split("\n")[1:], start=2):
        words = line.split("#")[0].split()
        if len(words) == 2 and words[1] == "atoms":
            n_atoms = int(integers(path, number_table(path, words[0], k, ("atoms",), (1,), "1")[0], words[0], k, 1,
                                    "atoms")[0])
        elif len(words) == 4 and words[2][1:] == "lo" and words[3][1:] == "hi" and words[2][0] in AXES:
            a = AXES.index(words[2][0])
            lo[a], hi[a] = number_table(path, " ".join(words[:2]), k, (words[2], words[3]), (2,), "2")[0]
        elif len(words) == 6 and words[3:] == ["xy", "xz", "yz"]:
            if np.any(number_table(path, " ".join(words[:3]), k, ("xy", "xz", "yz"), (3,), "3") != 0):
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


DUMP_POSITIONS = (("x", "y", "z"), ("xu", "yu", "zu"), ("xs", "ys", "zs"), ("xsu", "ysu", "zsu"))
DUMP_TEMPERATURE = ("temperature", "temp", "t", "f_temp", "f_temperature")


def read_dump(path: pathlib.Path, length_unit: float, timestep: int | None) -> Packing:
    """The packing of one snapshot of the LAMMPS text dump ``path`` (``dump custom``), sorted by id.

    Parameters
    ----------
    path : pathlib.Path
        The file.
    length_unit : float
        Metres per length unit of the file (> 0, checked by :func:`dem.scene.packing_files.read.read_packing`).
    timestep : int or None
        The snapshot to read; None: the last.

    Returns
    -------
    dem.scene.packing_files.packing.Packing
        The packing, in SI units.

    Raises
    ------
    dem.scene.packing_files.packing.FileError
        A bad file, naming the line and the column.
    """
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
    n = int(integers(path, number_table(path, head[k], first_line + k, ("atoms",), (1,), "1")[0], head[k],
                      first_line + k, 1, "atoms")[0])
    lo, hi, periodic = _dump_box(path, head, items["BOX"], first_line)
    header_end = frame.find("\n", atoms_at)
    header_end = len(frame) if header_end < 0 else header_end
    names = frame[atoms_at:header_end].split()[2:]
    atoms_line = first_line + frame.count("\n", 0, atoms_at)
    body_end = frame.find("\nITEM:", header_end)  # the next snapshot's UNITS or TIME lines, if any
    body = frame[header_end + 1:body_end + 1 if body_end >= 0 else None]
    table = number_table(path, body, atoms_line + 1, names, (len(names),), f"{len(names)}, the columns of ITEM: ATOMS")
    if len(table) != n:
        raise FileError(path, f"timestep {step}: {len(table)} atom lines, but ITEM: NUMBER OF ATOMS says {n}",
                        atoms_line)
    keys = [name.lower() for name in names]

    def col(name, integer=False):
        k = keys.index(name)
        return integers(path, table[:, k], body, atoms_line + 1, k + 1, names[k]) if integer else table[:, k]

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
        out["density"] = density_from_mass(col("mass") * mass_unit, radius * length)
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
    return _sorted(scaled(packing, length), np.argsort(ids, kind="stable"))


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
        bounds[a] = number_table(path, text, first_line + j, (f"{AXES[a]}lo", f"{AXES[a]}hi", "tilt"), (width,),
                           f"{width}, the bounds of {AXES[a]}{' and a tilt factor' if tilted else ''}")[0]
    if tilted and np.any(bounds[:, 2] != 0):
        raise FileError(path, "a triclinic box (tilt factors not zero): only orthogonal boxes are read",
                        first_line + k)
    periodic = tuple(f == "pp" for f in flags) if len(flags) == 3 else None
    return bounds[:, 0], bounds[:, 1], periodic



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
             rows_text([ids, types, 2.0 * r, rho, *x.T, *np.asarray(image).T], " ")]
    if packing.velocity is not None:
        w = packing.angular_velocity if packing.angular_velocity is not None else np.zeros((n, 3))
        parts += ["\nVelocities\n\n", rows_text([ids, *packing.velocity.T, *w.T], " ")]
    write_text(path, parts)
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
