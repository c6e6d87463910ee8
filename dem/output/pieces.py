"""The files of a run shared out among MPI ranks: each rank writes its piece of every snapshot, rank 0 the rest.

A snapshot is one ``.vtu`` piece per rank (``particles_NNNNNNNNN_R.vtu``: the particles rank R owns; likewise the
bonds) and a parallel VTK file ``particles_NNNNNNNNN.pvtu`` that names the pieces; the ``.pvd`` collections list the
``.pvtu`` files, so ParaView opens all ranks' particles as one data set. ``timeseries.csv`` and ``summary.json`` are
rank 0's (the engine reduces their numbers over the ranks); no plots (they need every particle in one process).
"""

from __future__ import annotations

import meshio
import numpy as np

from dem.output.writer import DIGITS, RunWriter, write_pvd, write_summary, write_vtu

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
    arrays are those of ``point_fields`` and ``cell_fields`` (name: an array of the right type and components)."""
    text = ('<?xml version="1.0"?>\n<VTKFile type="PUnstructuredGrid" version="0.1" byte_order="LittleEndian">\n'
            '  <PUnstructuredGrid GhostLevel="0">\n'
            + _arrays("PPointData", point_fields) + _arrays("PCellData", cell_fields)
            + '    <PPoints>\n      <PDataArray type="Float64" NumberOfComponents="3"/>\n    </PPoints>\n'
            + "".join(f'    <Piece Source="{p}"/>\n' for p in pieces)
            + "  </PUnstructuredGrid>\n</VTKFile>\n")
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(text)
    tmp.replace(path)


class PieceWriter(RunWriter):
    """:class:`~dem.output.writer.RunWriter` on rank ``rank`` of ``ranks`` (module docstring)."""

    def __init__(self, out_dir, scene, engine, rank: int, ranks: int):
        self.rank, self.ranks = rank, ranks
        super().__init__(out_dir, scene, engine)

    def _row(self, row: dict) -> None:
        if self.rank == 0:
            super()._row(row)

    def snapshot(self) -> None:
        e = self.engine
        step, t = e.steps, e.t
        if self.snapshots and self.snapshots[-1][1] == step:
            return
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

    def finish(self, summary: dict, plots: bool = False) -> dict:
        """The last row and snapshot (all ranks), then ``summary.json`` (rank 0)."""
        if self.last is not None and self.last["step"] % self.scene.output.every:
            self._guarded("timeseries.csv", lambda: self._row(self.last))
        if self.csv is not None:
            self.csv.close()
        if self.last is not None:
            self._guarded("snapshot", self.snapshot)
        if self.rank == 0:
            write_summary(self.out / "summary.json", self._with_errors(summary))
        return summary
