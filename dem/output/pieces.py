"""The files of a run shared out among MPI ranks: each rank writes its piece of every snapshot, rank 0 the rest.

A snapshot is one ``.vtu`` piece per rank (``particles_NNNNNNNNN_R.vtu``: the particles rank R owns; likewise the
bonds) and a parallel VTK file ``particles_NNNNNNNNN.pvtu`` that names the pieces; the ``.pvd`` collections list the
``.pvtu`` files, so ParaView opens all ranks' particles as one data set. ``timeseries.csv``, ``profiles.csv``,
``summary.json`` and the plots are rank 0's (the engine reduces or gathers their numbers there; an engine whose plots
need every particle in one process makes none). A resumed run goes on with the files as the serial writer does:
rank 0 drops the rows and files written after the checkpoint, every rank takes up the snapshot times.
"""

from __future__ import annotations

import meshio
import numpy as np

from dem.output.atomic import write_aside
from dem.output.writer import DIGITS, RunWriter, listed_snapshots, write_pvd, write_vtu
from dem.parallel.comm import world

def refuse_lammps_dump(scene) -> None:
    """Refuse ``[output] lammps_dump`` on several ranks (the dump needs every particle in one process, and each rank
    writes its piece of a snapshot); MPI is touched only where the scene asks for the dump.

    Parameters
    ----------
    scene : dem.scene.parse.Scene
        The scene.

    Raises
    ------
    ValueError
        The scene asks for a LAMMPS dump and the run has more than one rank.
    """
    if scene.output.lammps_dump and world().Get_size() > 1:
        raise ValueError("[output] lammps_dump = true: not written under MPI (each rank writes its piece of a VTU "
                         "snapshot); run on one process, or convert a state with python -m dem convert")


VTK_TYPES = {np.dtype(k): v for k, v in (("float32", "Float32"), ("float64", "Float64"), ("int8", "Int8"),
                                          ("int16", "Int16"), ("int32", "Int32"), ("int64", "Int64"),
                                          ("uint8", "UInt8"), ("uint16", "UInt16"), ("uint32", "UInt32"),
                                          ("uint64", "UInt64"))}


def _arrays(tag: str, fields: dict) -> str:
    rows = []
    for name, values in fields.items():
        values = np.asarray(values)
        components = 1 if values.ndim == 1 else values.shape[1]
        rows.append(f'      <PDataArray type="{VTK_TYPES[values.dtype]}" Name="{name}" '
                    f'NumberOfComponents="{components}"/>')
    return f"    <{tag}>\n" + "".join(r + "\n" for r in rows) + f"    </{tag}>\n"


def write_pvtu(path, pieces: list[str], point_fields: dict, cell_fields: dict) -> None:
    """A parallel unstructured grid naming the VTU ``pieces`` (file names beside it), whose point and cell data
    arrays are those of ``point_fields`` and ``cell_fields`` (name: an array of the right type and components).

    Parameters
    ----------
    path : str or pathlib.Path
        The ``.pvtu`` file to write.
    pieces : list of str
        The pieces' file names, relative to ``path``'s folder.
    point_fields : dict
        ``{name: array}`` whose dtype and components the point data declare.
    cell_fields : dict
        ``{name: array}`` whose dtype and components the cell data declare.
    """
    text = ('<?xml version="1.0"?>\n<VTKFile type="PUnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
            '  <PUnstructuredGrid GhostLevel="0">\n'
            + _arrays("PPointData", point_fields) + _arrays("PCellData", cell_fields)
            + '    <PPoints>\n      <PDataArray type="Float64" NumberOfComponents="3"/>\n    </PPoints>\n'
            + "".join(f'    <Piece Source="{p}"/>\n' for p in pieces)
            + "  </PUnstructuredGrid>\n</VTKFile>\n")
    write_aside(path, lambda fh: fh.write(text))


class PieceWriter(RunWriter):
    """:class:`~dem.output.writer.RunWriter` on rank ``rank`` of ``ranks`` (module docstring).

    Parameters
    ----------
    out_dir : str or pathlib.Path
        The run folder.
    scene : dem.scene.parse.Scene
        The scene.
    engine : object
        The engine that runs it (:mod:`dem.engines`).
    rank : int
        This process's rank.
    ranks : int
        Number of ranks.
    resume_step : int or None
        The step of the checkpoint a resumed run goes on from; None: a fresh run.
    """

    def __init__(self, out_dir, scene, engine, rank: int, ranks: int, resume_step: int | None = None):
        self.rank, self.ranks = rank, ranks
        super().__init__(out_dir, scene, engine, resume_step if rank == 0 else None)
        if resume_step is not None and rank > 0:  # rank 0 rewrites the files; the others only take up the clock
            self.snapshots = [(t, s) for t, s in listed_snapshots(self.out, self.kinds[0]) if s <= resume_step]
            self._resumed_clock()

    def _row(self, row: dict) -> None:
        if self.rank == 0:
            super()._row(row)

    def snapshot(self) -> None:
        """Write this rank's pieces of the snapshot at the current step (rank 0 also the profile); list it."""
        e = self.engine
        step, t = e.steps, e.t
        if self.snapshots and self.snapshots[-1][1] == step:
            return
        if self.rank == 0:
            self._profile(t)
        if self.scene.output.vtu:
            x = e.positions()
            fields = e.particle_fields()
            self._piece("particles", step, meshio.Mesh(x, [("vertex", np.arange(len(x)).reshape(-1, 1))],
                                                       point_data=fields), fields, {})
            points, lines, link_fields = e.links()
            self._piece(e.link_kind, step, meshio.Mesh(
                points, [("line", np.asarray(lines, dtype=np.int64).reshape(-1, 2))],
                cell_data={k: [v] for k, v in link_fields.items()}), {}, link_fields)
        self.snapshots.append((t, step))
        self._write_pvd()

    def _piece(self, kind: str, step: int, mesh, point_fields: dict, cell_fields: dict) -> None:
        stem = f"{kind}_{step:0{DIGITS}d}"
        write_vtu(self.out / f"{stem}_{self.rank}.vtu", mesh)
        if self.rank == 0:
            write_pvtu(self.out / f"{stem}.pvtu", [f"{stem}_{r}.vtu" for r in range(self.ranks)], point_fields,
                       cell_fields)

    def _write_pvd(self) -> None:
        if self.rank == 0 and self.scene.output.vtu:
            for kind in self.kinds:
                write_pvd(self.out / f"{kind}.pvd",
                          [(t, f"{kind}_{s:0{DIGITS}d}.pvtu") for t, s in self.snapshots])
