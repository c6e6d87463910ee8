r"""Temperature and heat-flux pictures of a solved neck: VTU (meshio, for ParaView) and PNG (pyvista, off-screen).

The analogues of Rojek 2022, Figs. 13 (temperature), 14 (heat-flux magnitude) and 17 (unequal pair). The field of a
:class:`fem_neck.conduction.Result` is sampled on a refined linear mesh of its meridian half-plane and mirrored
across the axis, so the picture shows the full axial section. Units: lengths in the solve's unit (metres for pairs
and chains, ``r = 1`` for the semisphere), ``T`` in kelvin above the bottom disk for ``delta_t`` across the body,
heat flux :math:`q = \kappa |\nabla T|` in W/m^2 (per square unit of the input's length unit).
"""

from __future__ import annotations

import pathlib

import numpy as np


def sampled_fields(result, delta_t: float = 1.0, refine: int = 2):
    """Refined linear sampling of the solution: ``(points (n, 2), triangles (m, 3), T (n,), q (n,))``.

    Parameters
    ----------
    result : fem_neck.conduction.Result
        A result solved in this process (one that kept its ``solution`` and ``profile``).
    delta_t : float
        Temperature difference across the body, K: the solve's unit field is scaled by it.
    refine : int
        Times each element is subdivided for the sampling (the hp path: ``2 refine + 4`` points per edge).
    """
    import skfem

    from fem_neck import spectral

    sol = result.solution
    if sol is None:
        raise ValueError("result has no field (it was pickled, which drops the solution); solve in this process")
    if isinstance(sol, spectral.Solution):  # the hp path: sample the polynomials directly
        points, triangles, temperature, gradient = spectral.sample(result.profile, sol, points_per_edge=2 * refine + 4)
        scale = result.length_scale
        return points * scale, triangles, delta_t * temperature, result.kappa * delta_t * gradient / scale
    basis = sol.basis
    dg = basis.with_element(skfem.ElementDG(skfem.ElementTriP1()))
    grad = basis.interpolate(sol.u).grad
    gx, gy = dg.project(grad[0]), dg.project(grad[1])
    mesh_t, temperature = basis.refinterp(sol.u, nrefs=refine)
    _, dtx = dg.refinterp(gx, nrefs=refine)
    _, dty = dg.refinterp(gy, nrefs=refine)
    scale = result.length_scale
    flux = result.kappa * delta_t * np.hypot(dtx, dty) / scale
    return mesh_t.p.T * scale, mesh_t.t.T, delta_t * temperature, flux


def _mirrored(points, triangles, *fields):
    mirror = points * np.array([-1.0, 1.0])
    n = points.shape[0]
    pts = np.vstack([points, mirror])
    tri = np.vstack([triangles, triangles[:, ::-1] + n])
    return pts, tri, [np.concatenate([f, f]) for f in fields]


def write_vtu(result, path, delta_t: float = 1.0) -> pathlib.Path:
    """Write ``temperature`` and ``heat_flux`` (point data) on the refined meridian mesh (x radial, y axial).

    Parameters
    ----------
    result : fem_neck.conduction.Result
        A result solved in this process (one that kept its ``solution`` and ``profile``).
    path : str or pathlib.Path
        The ``.vtu`` file to write.
    delta_t : float
        Temperature difference across the body, K.
    """
    import meshio

    points, triangles, temperature, flux = sampled_fields(result, delta_t)
    path = pathlib.Path(path)
    meshio.write(path, meshio.Mesh(np.column_stack([points, np.zeros(len(points))]), [("triangle", triangles)],
                                   point_data={"temperature": temperature, "heat_flux": flux}))
    return path


def write_png(result, path, title: str = "", delta_t: float = 1.0) -> pathlib.Path:
    """Two panels, temperature and heat-flux magnitude (log colour scale), of the mirrored axial section.

    Parameters
    ----------
    result : fem_neck.conduction.Result
        A result solved in this process (one that kept its ``solution`` and ``profile``).
    path : str or pathlib.Path
        The PNG file to write.
    title : str
        Text put before each panel's field name.
    delta_t : float
        Temperature difference across the body, K.
    """
    import pyvista

    pyvista.OFF_SCREEN = True
    pyvista.vtk_verbosity("off")  # no X server here: VTK's harmless display warning would clutter stderr
    points, triangles, temperature, flux = sampled_fields(result, delta_t)
    points, triangles, (temperature, flux) = _mirrored(points, triangles, temperature, flux)
    cells = np.column_stack([np.full(len(triangles), 3), triangles]).ravel()
    grid = pyvista.UnstructuredGrid(cells, np.full(len(triangles), pyvista.CellType.TRIANGLE),
                                    np.column_stack([points, np.zeros(len(points))]))
    grid.point_data["temperature [K]"] = temperature
    grid.point_data["|q| [W/m^2]"] = np.maximum(flux, flux.max() * 1e-6)
    plotter = pyvista.Plotter(shape=(1, 2), off_screen=True, window_size=(1400, 700))
    for col, (name, log) in enumerate((("temperature [K]", False), ("|q| [W/m^2]", True))):
        plotter.subplot(0, col)
        plotter.add_mesh(grid.copy(), scalars=name, cmap="turbo", log_scale=log, show_edges=False,
                         scalar_bar_args={"title": name, "vertical": False, "fmt": "%.3g",
                                          "position_x": 0.2, "position_y": 0.04, "width": 0.6, "height": 0.08})
        plotter.add_text(f"{title}  {name.split(' ')[0]}", font_size=10)
        plotter.view_xy()
        plotter.camera.zoom(0.9)
    path = pathlib.Path(path)
    plotter.screenshot(str(path))
    plotter.close()
    return path
