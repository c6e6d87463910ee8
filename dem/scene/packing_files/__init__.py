"""Packings from the files DEM users have, and packings written for LAMMPS.

:func:`~dem.scene.packing_files.read.read_packing` reads one packing of spheres into a
:class:`~dem.scene.packing_files.packing.Packing` (numpy arrays, SI units):

* ``csv`` -- a header row naming the columns ``x, y, z, radius`` (or ``diameter``), optionally ``id``,
  ``temperature``, ``fixed`` (true/false, 1/0), ``material`` (an index into the scene's materials, from 0, or a
  material's name) and ``density``; ParaView's ``Points:0``, ``Points:1``, ``Points:2`` name x, y, z. Other columns
  are ignored (listed in ``Packing.ignored``); lines starting with ``#`` are comments.
* ``lammps-data`` -- a LAMMPS data file of ``atom_style sphere`` (``Atoms`` lines ``id type diameter density x y z``
  with optional image flags ``ix iy iz``; a ``Velocities`` section ``id vx vy vz wx wy wz`` is read too). The box
  is the ``xlo xhi``, ``ylo yhi``, ``zlo zhi`` header; a data file does not record which axes are periodic (LAMMPS's
  ``write_data`` writes the bounds only; the periodicity is the ``boundary`` command of the input script), so
  :attr:`dem.scene.packing_files.packing.Packing.periodic` is None unless ``periodic`` is given. ``type`` k becomes material index k - 1.
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
  (:mod:`dem.scene.packing_files.parts`; read here whole), in SI units.

The format comes from the file's name (``.csv``; ``.data``, ``.lmp`` or a name ``data.*``; ``.dump``, ``.lammpstrj``
or ``dump.*``; ``.vtu``, ``.vtp``, ``.vtk``; ``.parts``) or an explicit ``format``. Lengths are multiplied by
``length_unit`` (0.001 for a file in mm, 1e-6 in um; densities stay kg/m^3); a LAMMPS file that records its unit
style (the title line ``units = cgs`` of ``write_data``, ``ITEM: UNITS`` of a dump) is converted from it. Particles
read from LAMMPS files are sorted by id (LAMMPS writes them in the order of its processors); other files keep their
order. A bad file raises ``ValueError`` with one line naming the file, the line and the column. A file that reads
but looks wrong gets a ``UserWarning``: positions of at most 6 significant digits with pairs within that rounding of
touching (:func:`~dem.scene.packing_files.read.printed_precision`), a median radius beyond ``RADIUS_PLAUSIBLE``
(another length unit than the file says).

The other way: :func:`~dem.scene.packing_files.lammps.write_lammps_data` writes a packing (read here, from a scene's
particles, or from a saved state, :func:`~dem.scene.packing_files.scene.packing_from_state`) as a LAMMPS data file of
``atom_style sphere`` that ``read_data`` reads; :func:`~dem.scene.packing_files.csv.write_csv` and
:func:`~dem.scene.packing_files.vtk.write_vtu` write the two other formats (a run's LAMMPS text dumps:
:mod:`dem.output.lammps_dump`).

The package, one format a module: :mod:`~dem.scene.packing_files.packing` (the packing record, the one-line error of a
bad file), :mod:`~dem.scene.packing_files.text` (tables of numbers in text files),
:mod:`~dem.scene.packing_files.csv`, :mod:`~dem.scene.packing_files.lammps` (data files and dumps),
:mod:`~dem.scene.packing_files.vtk`, :mod:`~dem.scene.packing_files.parts` (packings in parts), the reader the name
picks (:mod:`~dem.scene.packing_files.read`) and the scene's side (:mod:`~dem.scene.packing_files.scene`); the public
names used elsewhere are importable from here.
"""

# the public names used elsewhere (the package's front door, the command line, tests, benchmarks, the guide)
from dem.scene.packing_files.csv import write_csv  # noqa: F401
from dem.scene.packing_files.lammps import wrapped, write_lammps_data  # noqa: F401
from dem.scene.packing_files.packing import AXES, Packing  # noqa: F401
from dem.scene.packing_files.read import format_of, printed_precision, read_packing  # noqa: F401
from dem.scene.packing_files.scene import (SCENE_KEYS, packing_from_particles, packing_from_state,  # noqa: F401
                                           scene_particles)
from dem.scene.packing_files.vtk import write_vtu  # noqa: F401
