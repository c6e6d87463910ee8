"""``python -m dem convert IN OUT [--format F] [--length-unit U] [--timestep N] [--periodic AXES] [--density RHO]
[--blocks B] [--json]``: a packing written in another format, e.g. for LAMMPS, or in parts for many MPI ranks.

IN is a packing file (CSV, LAMMPS data file or dump, VTK point set, a packing in parts:
:func:`dem.scene.packing_files.read.read_packing`, the format from the name or ``--format``), a saved moving state
(``state.npz``: positions, radii, temperatures,
velocities, and densities from the saved masses; a static run's state: positions, radii, temperatures, materials) or a scene (a TOML file or a built-in name: its particles,
generated ones included, with its materials' densities and its periodic box). OUT is written by its name: a LAMMPS
data file of ``atom_style sphere`` (``.data``, ``.lmp``, ``data.*``; ``read_data`` reads it, ``units si``; LAMMPS
numbers atoms from 1, so ids 0..N-1 become 1..N), ``.csv``, ``.vtu``, or a packing in parts, a folder ``NAME.parts``
of ``--blocks`` blocks (:mod:`dem.scene.packing_files.parts`: what ``[particles] file`` reads in parts under MPI,
each rank only its own). A data file does not say which axes are
periodic: the input script's ``boundary`` command does (the summary lists the periodic axes IN records). The box is
IN's (a state's or a scene's periodic box, a file's box); a centre outside it is wrapped into it along a periodic axis
(its image flag counting the periods) and refused along any other. ``--periodic`` is for packing files only (a state
or a scene says which of its axes are periodic).
"""

from __future__ import annotations

import pathlib

OUTPUTS = {"lammps-data": "LAMMPS data file (atom_style sphere)", "csv": "CSV", "vtk": "VTU",
           "parts": "packing in parts"}


def register(sub):
    """Add the ``convert`` command (module docstring) to the subcommands of ``python -m dem``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``python -m dem`` parser.
    """
    parser = sub.add_parser("convert", help="write a packing, a saved state or a scene's particles as a LAMMPS "
                            "data file, CSV, VTU or a packing in parts", description=__doc__)
    parser.add_argument("input", metavar="IN", help="packing file, state.npz, or scene (TOML file or built-in name)")
    parser.add_argument("output", metavar="OUT", help="file to write: .data / .lmp / data.* (LAMMPS), .csv, .vtu, "
                        "or a folder NAME.parts (a packing in parts)")
    parser.add_argument("--format", default=None, help="format of IN: csv, lammps-data, lammps-dump, vtk or parts "
                        "(default: from its name)")
    parser.add_argument("--length-unit", type=float, default=1.0, metavar="U",
                        help="metres per length unit of IN (0.001 for mm; default 1)")
    parser.add_argument("--timestep", type=int, default=None, metavar="N",
                        help="the snapshot of a dump (default: the last)")
    parser.add_argument("--periodic", default=None, metavar="AXES",
                        help="periodic axes of IN, e.g. xyz or xy (a LAMMPS data file does not record them)")
    parser.add_argument("--density", type=float, default=None, metavar="RHO",
                        help="kg/m^3 of every particle, for a LAMMPS data file when IN gives none")
    parser.add_argument("--blocks", type=int, default=None, metavar="B",
                        help="blocks of a packing in parts, at least the MPI ranks that will read it (default: about "
                        "65536 particles each, at least 64 where each keeps 1000)")
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.set_defaults(run=run)


def read_input(args):
    """The :class:`dem.scene.packing_files.packing.Packing` of IN and what it was (``packing``, ``state`` or ``scene``).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``input``, ``format``, ``length_unit``, ``timestep``, ``periodic``.

    Returns
    -------
    tuple of (dem.scene.packing_files.packing.Packing, str)
        The packing and its kind.

    Raises
    ------
    ValueError
        A bad input, or ``--periodic`` for a state or a scene.
    """
    from dem.scene import packing_files, state_file

    source = pathlib.Path(args.input)
    is_state = source.suffix.lower() == ".npz"
    if (is_state or source.suffix.lower() == ".toml" or (not source.exists() and not source.suffix)) and \
            args.periodic is not None:
        raise ValueError(f"--periodic = {args.periodic!r}: only for a packing file; a saved state or a scene "
                         f"keeps its own periodic box")
    if is_state:
        return packing_files.packing_from_state(state_file.load(source)), "state"
    if source.suffix.lower() == ".toml" or (not source.exists() and not source.suffix):
        from dem.scene import load_scene

        scene = load_scene(args.input)
        return packing_files.packing_from_particles(scene.particles, scene.box), "scene"
    return packing_files.read_packing(source, args.format, args.length_unit, args.timestep, args.periodic), "packing"


def run(args) -> dict:
    """Write IN as OUT (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    dict
        What was read and written: kinds, formats, particle count, id range, box and periodic axes.

    Raises
    ------
    ValueError
        A bad OUT name, ``--density``, or input.
    """
    from dem.output.lammps_dump import lammps_ids
    from dem.scene import packing_files

    target = pathlib.Path(args.output)
    try:
        out_format = packing_files.format_of(target)
    except ValueError:
        out_format = None
    if out_format not in OUTPUTS or target.suffix.lower() in (".vtk", ".vtp", ".pvtu", ".pvtp"):
        raise ValueError(f"OUT = {args.output!r}: writes a LAMMPS data file (.data, .lmp, data.*), .csv, .vtu or a "
                         f"packing in parts (NAME.parts)")
    if args.density is not None and not args.density > 0:
        raise ValueError(f"--density = {args.density!r}: must be > 0 (kg/m^3)")
    if args.blocks is not None and (out_format != "parts" or args.blocks < 1):
        raise ValueError(f"--blocks = {args.blocks!r}: for OUT = NAME.parts only, >= 1 (and at most the particles)")
    packing, kind = read_input(args)
    if out_format == "lammps-data":
        packing_files.write_lammps_data(target, packing, args.density)
    elif out_format == "csv":
        packing_files.write_csv(target, packing)
    elif out_format == "parts":
        from dem.scene.packing_files.parts import read_index, write_parts

        write_parts(target, packing, args.blocks)
        blocks = read_index(target).blocks
    else:
        packing_files.write_vtu(target, packing)
    ids = lammps_ids(packing.id) if out_format == "lammps-data" else packing.id
    result = {"input": args.input, "input_kind": kind, "input_format": packing.format or kind, "output": str(target),
              "output_format": OUTPUTS[out_format], "particles": packing.n,
              "ids": [int(ids.min()), int(ids.max())]}
    if packing.box_lo is not None:
        result["box"] = [packing.box_lo.tolist(), packing.box_hi.tolist()]
    result["periodic"] = (None if packing.periodic is None
                          else "".join(a for a, p in zip(packing_files.AXES, packing.periodic) if p) or "none")
    if packing.ignored:
        result["ignored"] = list(packing.ignored)
    if out_format == "parts":
        result["blocks"] = blocks
    return result
