"""NGSolve on the mirror cell of a periodic packing: the independent reference of the periodic-cell FE and its peer
in the benchmarks (optional extra ``pip install .[peers]``).

The same solid as :func:`fem_neck.lattice.mesh.build_cell_mesh` -- the spheres and volume-conserving neck cylinders that
reach the cell, cut to it -- is built in netgen's own OCC kernel, meshed by netgen, refined geometrically toward the
neck circles (``RefineHP``: anisotropic layers, factor ``hp_factor``), curved to order ``p``, and solved with H1
elements of order ``p`` (``T = 1`` on ``z = 0``, 0 on ``z = P_z/2``, static condensation, sparse Cholesky). The
conductance is the energy ``u^T A u``; ``k / kappa = E (P_z / 2) / A``. Nothing of fem_neck's meshing, geometry
maps or solvers is used: only the cell's particles and necks.
"""

from __future__ import annotations

import time

import numpy as np


def ngsolve_cell(cell, order: int, maxh: float = 0.5, hp_levels: int | None = None, hp_factor: float = 0.125) -> dict:
    """``{"k": k_eff / kappa, "ndof", "elements", "seconds"}`` of the cell along z (module docstring); ``hp_levels``
    defaults to ``order``."""
    import ngsolve as ngs
    from netgen import occ

    from fem_neck.lattice import PeriodicCell, local_cluster, mirror_symmetry

    t0 = time.perf_counter()
    ngs.ngsglobals.msg_level = 0
    _, diagonal, anti = mirror_symmetry(cell)
    unit = float(cell.radii.max())
    scaled = PeriodicCell(cell.centres / unit, cell.radii / unit, cell.period / unit, cell.name)
    box = scaled.period / 2.0
    local = local_cluster(scaled, box)
    geo = local.necks()
    e = local.directions()
    bi = local.bonds[:, 0]
    solid = None
    for k in range(local.n):
        s = occ.Sphere(occ.Pnt(*local.centres[k]), local.radii[k])
        solid = s if solid is None else solid + s
    for b in range(len(bi)):
        start = local.centres[bi[b]] + 0.75 * geo.z_i[b] * e[b]
        solid = solid + occ.Cylinder(occ.Pnt(*start), occ.Vec(*e[b]), geo.a[b],
                                     geo.h_n[b] + 0.25 * (geo.z_i[b] + geo.z_j[b]))
    if diagonal:
        apex = (0.5 * box[0], 0.5 * box[1]) if anti else (box[0], box[1])
        domain = occ.WorkPlane().MoveTo(0, 0).LineTo(box[0], 0).LineTo(*apex).Close().Face().Extrude(box[2])
    else:
        domain = occ.Box(occ.Pnt(0, 0, 0), occ.Pnt(*box))
    shape = solid * domain
    for face in shape.faces:
        z = face.center.z
        if abs(z) < 1e-7:
            face.name = "hot"
        elif abs(z - box[2]) < 1e-7:
            face.name = "cold"
    for edge in shape.edges:  # the neck circles: all their points at distance a from a bond axis, at a neck end
        if edge.mass < 1e-9:  # a degenerate edge (a sphere's pole) has no curve to evaluate
            continue
        lo, hi = edge.parameter_interval
        pts = np.array([[q.x, q.y, q.z] for q in (edge.Value(lo + t * (hi - lo)) for t in (0.1, 0.5, 0.9))])
        for b in range(len(bi)):
            rel = pts - local.centres[bi[b]]
            axial = rel @ e[b]
            radial = np.linalg.norm(rel - axial[:, None] * e[b], axis=1)
            at_end = np.all(np.abs(axial - geo.z_i[b]) < 1e-6) or np.all(np.abs(axial - geo.z_i[b] - geo.h_n[b]) < 1e-6)
            if np.all(np.abs(radial - geo.a[b]) < 1e-6) and at_end:
                edge.hpref = 1
    mesh = ngs.Mesh(occ.OCCGeometry(shape).GenerateMesh(maxh=maxh))
    levels = order if hp_levels is None else hp_levels
    if levels:
        mesh.RefineHP(levels=levels, factor=hp_factor)
    mesh.Curve(order)
    fes = ngs.H1(mesh, order=order, dirichlet="hot|cold")
    u, v = fes.TnT()
    form = ngs.BilinearForm(ngs.grad(u) * ngs.grad(v) * ngs.dx, condense=True).Assemble()
    temp = ngs.GridFunction(fes)
    temp.Set(1.0, definedon=mesh.Boundaries("hot"))
    res = temp.vec.CreateVector()
    res.data = -form.mat * temp.vec
    res.data += form.harmonic_extension_trans * res
    temp.vec.data += form.mat.Inverse(fes.FreeDofs(True), inverse="sparsecholesky") * res
    temp.vec.data += form.harmonic_extension * temp.vec
    temp.vec.data += form.inner_solve * res
    full = ngs.BilinearForm(ngs.grad(u) * ngs.grad(v) * ngs.dx).Assemble()
    energy = ngs.InnerProduct(temp.vec, full.mat * temp.vec)
    area = box[0] * box[1] * (0.25 if anti else 0.5 if diagonal else 1.0)
    return {"k": float(energy * box[2] / area), "ndof": int(fes.ndof), "elements": int(mesh.ne),
            "seconds": time.perf_counter() - t0}
