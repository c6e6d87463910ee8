"""Peer codes for the bench, on the same problems as ours: NGSolve (FE conductance) and OpenPNM (pipe network).

Both are optional (``pip install .[peers]``); :func:`available` says which are importable and the bench skips the
rest, saying so. Nothing here is used by the toolkit itself.

* :func:`ngsolve_semisphere` -- the semisphere with a cylindrical neck of Rojek 2022, Fig. 12 (equal spheres,
  sphere radius 1, overlap h/r): T = 1 on the equatorial disk, T = 0 on the neck's end disk at the mid-plane
  z = r - h/2, insulated elsewhere; axisymmetric (weight rho in the bilinear form), H1 elements of order p on a
  netgen/OCC mesh curved to order p, optionally hp-refined toward the re-entrant corner (a, sqrt(r^2 - a^2)).
  ``K/K_cyl = 2 pi E / (pi r)`` with ``E = u^T A u`` the energy (kappa = 1, Delta T = 1).
* :func:`openpnm_steady` -- Fourier conduction on a given network: throat conductances, fixed-temperature pores.
"""

from __future__ import annotations

import importlib.util
import math
import time

import numpy as np

from fem_neck.geometry import equal_neck_radius


def available() -> dict:
    """``{"ngsolve": bool, "openpnm": bool}``: which peers are importable."""
    return {name: importlib.util.find_spec(name) is not None for name in ("ngsolve", "openpnm")}


def ngsolve_semisphere(h_over_r: float, order: int, maxh: float = 0.3, hp_levels: int = 2,
                       hp_factor: float = 0.125) -> tuple[float, int]:
    """``(K/K_cyl, ndof)`` of the semisphere with neck, solved by NGSolve (see the module docstring)."""
    import ngsolve as ngs
    from netgen import occ

    ngs.ngsglobals.msg_level = 0
    r = 1.0
    a = float(equal_neck_radius(r, h_over_r))
    z_i = math.sqrt((r - a) * (r + a))
    z_top = r - 0.5 * h_over_r
    quarter = occ.Circle((0, 0), r).Face() * occ.Rectangle(r, z_i).Face()
    neck = occ.MoveTo(0, z_i).Rectangle(a, z_top - z_i).Face()
    shape = quarter + neck
    shape.edges.Min(occ.Y).name = "equator"
    shape.edges.Max(occ.Y).name = "neck"
    shape.vertices.Nearest((a, z_i, 0)).hpref = 1
    mesh = ngs.Mesh(occ.OCCGeometry(shape, dim=2).GenerateMesh(maxh=maxh))
    if hp_levels:
        mesh.RefineHP(levels=hp_levels, factor=hp_factor)
    mesh.Curve(order)
    fes = ngs.H1(mesh, order=order, dirichlet="equator|neck")
    u, v = fes.TnT()
    form = ngs.BilinearForm(ngs.x * ngs.grad(u) * ngs.grad(v) * ngs.dx).Assemble()
    temp = ngs.GridFunction(fes)
    temp.Set(1.0, definedon=mesh.Boundaries("equator"))
    rhs = -form.mat * temp.vec
    temp.vec.data += form.mat.Inverse(fes.FreeDofs(), inverse="sparsecholesky") * rhs
    energy = ngs.InnerProduct(temp.vec, form.mat * temp.vec)
    return 2.0 * math.pi * energy / (math.pi * r), fes.ndof


def openpnm_steady(coords, i, j, conductance, fixed, t_fixed) -> tuple[np.ndarray, dict]:
    """Steady Fourier conduction in OpenPNM on the network (coords, bonds i-j, throat conductances [W/K]).

    ``fixed`` is a boolean mask of pores held at ``t_fixed`` (array over all pores; only fixed entries are read).
    Returns the pore temperatures and ``{"setup_seconds", "solve_seconds", "solver"}`` (building the
    network/phase/algorithm, and ``run()`` with OpenPNM's default solver, whose name is ``solver``).
    """
    import logging

    import openpnm as op

    logging.getLogger("openpnm").setLevel(logging.ERROR)
    t0 = time.perf_counter()
    ws = op.Workspace()
    ws.clear()
    net = op.network.Network(coords=np.asarray(coords, float), conns=np.column_stack([i, j]).astype(np.int64))
    phase = op.phase.Phase(network=net)
    phase["throat.thermal_conductance"] = np.asarray(conductance, float)
    alg = op.algorithms.FourierConduction(network=net, phase=phase)
    pores = np.flatnonzero(fixed)
    alg.set_value_BC(pores=pores, values=np.asarray(t_fixed, float)[pores])
    t1 = time.perf_counter()
    alg.run()
    t2 = time.perf_counter()
    temperature = np.array(alg["pore.temperature"])
    ws.clear()
    return temperature, {"setup_seconds": t1 - t0, "solve_seconds": t2 - t1, "solver": ws.settings.default_solver}
