"""Packings as VTK point sets (``.vtu``, ``.vtp``, legacy ``.vtk``), read by VTK itself (:func:`read_vtk`, the
fields: :mod:`dem.scene.packing_files`) and written as a VTU (:func:`write_vtu`)."""

from __future__ import annotations

import logging
import pathlib
import warnings

import numpy as np

from dem.scene.packing_files.packing import Packing, density_from_mass, scaled

VTK_FIELDS = {"radius": ("radius", "radii"), "diameter": ("diameter", "diameters"), "id": ("id", "ids"),
              "temperature": ("temperature", "temp", "f_temp"), "fixed": ("fixed",),
              "material": ("material", "materialid"), "type": ("type",), "density": ("density",), "mass": ("mass",),
              "velocity": ("velocity", "v", "linvelvec"), "angular_velocity": ("angular_velocity", "omega",
                                                                               "angvelvec")}


class _KeptLog(logging.Handler):
    """A logging handler that keeps the messages it is given (a VTK reader's errors, for the one-line refusal)."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record):
        self.messages.append(record.getMessage())


def read_vtk(path: pathlib.Path, length_unit: float) -> Packing:
    """The packing in the VTK point set ``path`` (the fields: :mod:`dem.scene.packing_files`).

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
    ValueError
        A file VTK cannot read, or a bad point field.
    """
    import pyvista as pv
    from vtkmodules.vtkCommonCore import vtkLogger

    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # a bad file: our one line, not VTK's log
    logged = _KeptLog()  # pyvista passes some reader errors to the logging module (an "ERROR:root:" line)
    root = logging.getLogger()
    root.addHandler(logged)
    try:
        with warnings.catch_warnings(record=True) as caught:  # pyvista reports a reader's error as a warning
            warnings.simplefilter("always")
            try:
                mesh = pv.read(str(path))
            except Exception as exc:  # VTK's readers raise many kinds; the file is what is wrong
                raise ValueError(f"{path}: cannot be read as VTK ({' '.join(str(exc).split())})") from None
    finally:
        root.removeHandler(logged)
    if mesh is None or not hasattr(mesh, "point_data") or mesh.n_points == 0:
        if caught or logged.messages:
            why = str(caught[0].message) if caught else logged.messages[0]
            raise ValueError(f"{path}: cannot be read as VTK ({' '.join(why.split())})")
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
        out["density"] = density_from_mass(mass.astype(float), radius * length_unit)
    for key in ("velocity", "angular_velocity"):
        v = get(key, 3)
        if v is not None:
            out[key] = v.astype(float)
    points = np.asarray(mesh.points, dtype=float)
    ids = np.arange(len(radius), dtype=np.int64) if ids is None else _whole(path, ids, "id")
    ignored = tuple(name for name in mesh.point_data.keys() if name not in used)
    return scaled(Packing(ids, points, radius, ignored=ignored, **out), length_unit)


def _whole(path, values: np.ndarray, name: str) -> np.ndarray:
    if values.dtype.kind == "f" and np.any(values != np.round(values)):
        k = int(np.flatnonzero(values != np.round(values))[0])
        raise ValueError(f"{path}: point field {name!r}: point {k} = {values[k]!r}: must be an integer")
    return np.round(values).astype(np.int64)



def write_vtu(path, packing: Packing) -> pathlib.Path:
    """Write ``packing`` as a VTU point set (vertex cells) with the point fields ``id``, ``radius`` and its
    optional ones: what ParaView opens and :func:`~dem.scene.packing_files.read.read_packing` reads back.

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
    import meshio

    from dem.output.writer import write_vtu as write_whole

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
