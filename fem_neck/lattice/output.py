"""A periodic cell's mesh written for ParaView (:mod:`fem_neck.lattice`)."""

from __future__ import annotations

from fem_neck.lattice.driver import CellResult


def write_vtu(result: CellResult, path) -> None:
    """The cell's mesh (straight tetrahedra, vertices on the exact surfaces) for ParaView (VTU).

    Parameters
    ----------
    result : CellResult
        A result that kept its ``mesh``.
    path : str or pathlib.Path
        The ``.vtu`` file to write.
    """
    import meshio

    mesh = result.mesh.curved
    unit = result.mesh.unit
    meshio.Mesh(mesh.points * unit, [("tetra", mesh.tets)]).write(str(path))
