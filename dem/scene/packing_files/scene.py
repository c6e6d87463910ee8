"""Packings and scenes: a scene's ``[particles] file`` read into its particles (:func:`scene_particles`, whole or,
under MPI, a rank's part), and a packing of a scene's particles or of a saved state (:func:`packing_from_particles`,
:func:`packing_from_state`) for the writers."""

from __future__ import annotations

import pathlib
from dataclasses import replace

import numpy as np

from dem.scene.packing_files.packing import SPHERE_VOLUME, Packing
from dem.scene.packing_files.parts import HELD, read_index, read_part
from dem.scene.packing_files.read import format_of, read_packing


SCENE_KEYS = ("file", "format", "length_unit", "timestep")  # [particles] keys of a packing file
DENSITY_RTOL = 1e-3  # a file's density against its material's: printed digits (LAMMPS dumps: 6) pass, a mix-up fails


def scene_particles(table: dict, materials, base_dir=None, part=None):
    """``[particles] file = "..."`` of a scene: the :class:`dem.geometry.particles.Particles` of the file (``format``,
    ``length_unit``, ``timestep`` as for :func:`~dem.scene.packing_files.read.read_packing`; the path relative to ``base_dir``, the scene's folder)
    and the file's box as a :class:`dem.geometry.periodic.PeriodicBox` (periodic along the axes the file says are, none where
    it cannot say), or None. ``temperature`` (a number or a list), ``fixed``, ``material`` (a name or index, or a
    list of them) and ``heat`` come from the table where given, else from the file; a density the file gives must be
    its material's. With ``part``, a packing in parts (:mod:`dem.scene.packing_files.parts`) gives only the particles that
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
        ``(ranks, rank, box_of, bonds)``: read a packing in parts as rank ``rank`` of ``ranks``, the scene's periodic
        box ``box_of(file_box)`` (a callable from the file's box, or None, to the scene's), with a halo of ``bonds``
        bond lengths (:func:`dem.scene.packing_files.parts.read_part`); None: read the whole file.

    Returns
    -------
    tuple of (dem.geometry.particles.Particles, dem.geometry.periodic.PeriodicBox or None, object)
        The particles, the file's box, and the :class:`dem.scene.packing_files.parts.Part` they are of (None where the
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


def _part_of(path, table: dict, options: dict, ranks: int, rank: int, box_of, bonds: int):
    """The packing and :class:`dem.scene.packing_files.parts.Part` that rank ``rank`` of ``ranks`` holds of the packing in
    parts ``path`` (:func:`scene_particles`)."""
    extra = sorted(set(options) - {"format"})
    if extra:
        raise ValueError(f"{extra[0]}: not for a packing in parts (in metres, one snapshot)")
    if "fixed" in table:
        raise ValueError(f"[particles] fixed: not for a packing read in parts on several ranks (the fixed particles "
                         f"are the file's, {path.name}/{HELD}); write them into it, or run on one "
                         "process")
    index = read_index(path)
    file_box = None
    if index.box_lo is not None:
        from dem.geometry.periodic import PeriodicBox

        file_box = PeriodicBox(index.box_hi - index.box_lo, index.periodic or (False,) * 3, index.box_lo)
    return read_part(path, ranks, rank, box_of(file_box), bonds)



def packing_from_particles(particles, box=None) -> Packing:
    """A :class:`~dem.scene.packing_files.packing.Packing` of a scene's :class:`dem.geometry.particles.Particles` (densities from its materials) in the
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
    r"""A :class:`~dem.scene.packing_files.packing.Packing` of a saved state (:func:`dem.scene.state_file.load`) in its
    periodic box, if it has one: positions, radii, temperatures, ids; of a moving state also velocities, angular
    velocities and the density that gives each particle its saved mass :math:`m` as a sphere of radius :math:`r`
    (:math:`\rho = m / (\frac{4}{3} \pi r^3)`, also what LAMMPS computes the mass from), of a static one its materials
    (no density: the scene's materials have them). 3D states only: a 2D state's disks lie in the x-z plane with a
    height, which LAMMPS's 2D spheres (x-y plane) do not have.

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

