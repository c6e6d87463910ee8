r"""Per-neck heat flows and mean temperatures of a union cell's FE solution (:mod:`fem_neck.lattice`).

Under the union of spheres the solid is the union of the cut spheres (:mod:`fem_neck.geometry.union`): particle ``k``
owns the points of the solid whose power distance :math:`|x - c_k|^2 - r_k^2` is least, and two particles meet on a
flat face in their radical plane, the disc inside their neck circle less what third spheres' cells take of it (a lens
inside a third sphere has no face). :func:`neck_flows` reads, from the conforming ``P_p`` solution of
:func:`~fem_neck.lattice.driver.effective_conductivity` (the upper bound), every period bond's heat flow through its
face and the face's mean temperature, and every particle's mean temperature.

**Flows.** Every skeleton node of the mesh belongs to the particle whose power cell holds it. With ``A`` the
(condensed) stiffness matrix, whose rows sum to zero, the heat entering the nodes of particle ``p`` is
:math:`\sum_{n \in p} (A u)_n = \sum_{n \in p} \sum_{m \notin p} A_{nm} (u_m - u_n)`, a sum over pairs of nodes of two
particles: the flow from ``q`` into ``p`` is :math:`-\sum_{n \in p, m \in q} A_{nm} (u_m - u_n)`, antisymmetric, and
with the heat the isothermal faces give (the reactions :math:`(A u)_n` of their nodes) the flows into every particle
sum to its equations' residual: zero to the solver's tolerance. This is the weighted residual of the particle's
indicator in the FE space (the flux that conserves heat on the discrete level); summed over the necks it gives the
FE's own heat flow. Only the elements whose nodes lie in two particles' cells (along the faces) and those on the
isothermal faces are integrated again, and nothing is done unless asked for.

**The period from the mirror cell.** The FE solves the cell :math:`[0, P/2]^3` (or its wedge) of a packing
mirror-symmetric about the planes through the origin, with the temperature :math:`T = -z + \theta` (per unit
gradient), :math:`\theta` periodic, even under the mirrors normal to x and y (and the diagonal ones) and odd under the
one normal to z. The cell's images under those
mirrors tile the period; in an image the particles are the images of the cell's, and a flow is reversed where the
image flips z. A face on an isothermal plane (between a particle and its own image across it) carries the heat of the
plane's nodes; a particle centred on that plane is cut by it in its own body, so its reaction there is no neck's.

**Temperatures.** A particle's mean temperature is the integral of ``T`` over its cut sphere (the quadrature points of
the mapped elements in its power cell), a face's the mean of ``T`` over the disc (a polar rule on the disc, the points
in a third sphere's cell dropped, each located in the mesh and ``T`` evaluated there). Both are for a mean gradient
``G`` along ``-z`` (heat flowing toward ``+z``) with each particle at its centre in ``[0, P)``; a face is seen from
the bond's first particle ``i``, at its centre.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fem_neck.lattice.cells import PeriodicCell
from fem_neck.lattice.mesh import CellMesh, _inside, cell_frame

DISC_RINGS, DISC_ANGLES = 12, 48  # the polar rule on a face's disc: Gauss points in a^2 and equal angles
CUT_DEGREE = 12  # the finer rule (343 points) of the elements a face cuts, which it splits at its points
NEAREST = 24  # tetrahedra whose centroids are nearest a point tried for the one that holds it
CHUNK = 2048  # elements per batch


@dataclass
class NeckFlows:
    r"""Per-neck heat flows and mean temperatures of a union cell (:func:`neck_flows`), for a mean temperature gradient
    ``G`` (K/m) along ``-z`` and conductivity :math:`\kappa` (W/(m K)): flows over :math:`\kappa G` (m^2),
    temperatures over ``G`` (m), with the temperature :math:`T / G = -z + \theta` (:math:`\theta` periodic) and each
    particle at its centre in ``[0, P)``.

    Parameters
    ----------
    i, j, shift : numpy.ndarray
        The period's bonds, as :meth:`~fem_neck.lattice.cells.PeriodicCell.bonds`: particle ``i`` and the image
        ``c_j + shift P``.
    flow : numpy.ndarray
        Heat flow from ``i`` to ``j`` through the bond's face over :math:`\kappa G`, m^2 (zero where there is no face).
    face : numpy.ndarray
        Whether the bond has a face (its lens is not inside a third sphere).
    face_temperature : numpy.ndarray
        Mean temperature over the face over ``G``, m, seen from ``i`` at its centre (NaN where there is no face).
    temperature : numpy.ndarray
        Mean temperature over each particle's cut sphere over ``G``, m.
    volume : numpy.ndarray
        Each particle's cut sphere's volume as integrated (the mesh's), m^3.
    residual : numpy.ndarray
        Each particle's net inflow over :math:`\kappa G`, m^2: zero to the solver's tolerance.
    total : float
        The heat flow across a period face over :math:`\kappa G`, m^2: :math:`k_{eff} / \kappa` times its area.
    """

    i: np.ndarray
    j: np.ndarray
    shift: np.ndarray
    flow: np.ndarray
    face: np.ndarray
    face_temperature: np.ndarray
    temperature: np.ndarray
    volume: np.ndarray
    residual: np.ndarray
    total: float

    def as_dict(self) -> dict:
        """The flows as a JSON-ready dict (a face's missing temperature as None)."""
        return {"bonds": [{"i": int(a), "j": int(b), "shift": [int(s) for s in sh], "flow": float(q),
                           "face_temperature": float(t) if f else None}
                          for a, b, sh, q, f, t in zip(self.i, self.j, self.shift, self.flow, self.face,
                                                       self.face_temperature)],
                "particle_temperature": [float(t) for t in self.temperature],
                "particle_volume": [float(v) for v in self.volume],
                "total_flow": float(self.total)}


def _symmetries(box: np.ndarray, diagonal: bool, anti: bool) -> list:
    """The maps ``x = M y + o`` that take the computational cell onto the pieces of the period (mirrors through the
    origin, then ``x <-> y``, then ``(x, y) -> (P/2 - y, P/2 - x)``), with the sign of ``z`` each keeps."""
    out = []
    swaps = [np.eye(3)] + ([np.array([[0.0, 1, 0], [1, 0, 0], [0, 0, 1]])] if diagonal else [])
    antis = [(np.eye(3), np.zeros(3))]
    if anti:
        antis.append((np.array([[0.0, -1, 0], [-1, 0, 0], [0, 0, 1]]), np.array([box[0], box[1], 0.0])))
    for fx in (1.0, -1.0):
        for fy in (1.0, -1.0):
            for fz in (1.0, -1.0):
                F = np.diag([fx, fy, fz])
                for S in swaps:
                    for A, a in antis:
                        out.append((F @ S @ A, F @ S @ a, fz))
    return out


def _fold(x: np.ndarray, period: np.ndarray, box: np.ndarray, diagonal: bool, anti: bool):
    """Points ``x`` of the period mapped into the computational cell: ``(y, sign of z)`` with ``x`` an image of ``y``
    (:func:`_symmetries`) up to a period."""
    y = x - np.round(x / period) * period
    sign = np.where(y[:, 2] < 0.0, -1.0, 1.0)
    y = np.abs(y)
    if diagonal:
        swap = y[:, 1] > y[:, 0]
        y[swap] = y[swap][:, [1, 0, 2]]
        if anti:
            over = y[:, 0] + y[:, 1] > box[0]
            y[over] = np.column_stack([box[0] - y[over, 1], box[1] - y[over, 0], y[over, 2]])
    return y, sign


def _owner(x: np.ndarray, centres: np.ndarray, period: np.ndarray):
    """The particle each point ``x`` is a centre image of, and the image's shift: ``x = c_k + n P``."""
    d = x[:, None, :] - centres[None]
    n = np.round(d / period)
    k = np.argmin(np.linalg.norm(d - n * period, axis=2), axis=1)
    return k, n[np.arange(len(x)), k].astype(np.int64)


def neck_flows(cell: PeriodicCell, cm: CellMesh, u: np.ndarray, order: int) -> NeckFlows:
    r"""The per-neck flows and temperatures (module docstring) of a union cell from its conforming solution.

    Parameters
    ----------
    cell : PeriodicCell
        The cell (``neck = "union"``), lengths in m.
    cm : CellMesh
        Its mesh (:func:`~fem_neck.lattice.mesh.build_cell_mesh`).
    u : numpy.ndarray
        The skeleton temperatures of the ``P_order`` solution on ``cm`` (:class:`fem_neck.primal.Solution` ``u``:
        1 on :math:`z = 0`, 0 on :math:`z = P_z / 2`).
    order : int
        The elements' order ``p``.
    """
    from fem_neck import primal
    from fem_neck.simplex import lagrange, tet_quadrature

    if cell.neck != "union":
        raise ValueError(f"neck = {cell.neck!r}: per-neck flows are read on the union of spheres (neck = 'union')")
    frame = cell_frame(cell)
    mesh, unit, box, height = cm.curved, frame.unit, frame.box, cm.height
    period = frame.scaled.period
    centres = frame.scaled.centres
    tol = 1e-6
    keep = _inside(frame.halfspaces, frame.local.centres, tol)
    sc, sr = frame.local.centres[keep], frame.local.radii[keep]  # the particles centred in the cell
    ns = len(sc)

    def region(x):
        return np.argmin(np.sum((x[:, None, :] - sc[None]) ** 2, axis=2) - sr[None] ** 2, axis=1)

    basis = lagrange(order)
    skel = basis.n - basis.n_interior
    num = primal.numbering(mesh, basis)
    dofs, first = np.unique(num.l2g, return_index=True)
    element, node = np.divmod(first, skel)
    J = mesh.affine_jacobians(element)
    where = np.empty((num.n, 3))
    where[dofs] = mesh.points[mesh.tets[element, 0]] + np.einsum("eij,ej->ei", J, basis.nodes[node])
    owner = np.concatenate([region(where[s:s + 65536]) for s in range(0, num.n, 65536)])
    fixed = np.zeros(num.n, dtype=bool)
    hot = primal.face_dofs(mesh, basis, cm.hot)
    fixed[hot] = True
    fixed[primal.face_dofs(mesh, basis, cm.cold)] = True
    on_hot = np.zeros(num.n, dtype=bool)
    on_hot[hot] = True
    reg = owner[num.l2g]
    work = np.flatnonzero(np.any(reg != reg[:, :1], axis=1) | np.any(fixed[num.l2g], axis=1))
    inflow = np.zeros((ns, ns))     # inflow[p, q]: heat from q into p (mesh units, unit temperature difference)
    reaction = np.zeros((ns, 2))    # heat into p from the hot and the cold plane
    for s in range(0, len(work), CHUNK):
        e = work[s:s + CHUNK]
        K = primal.condensed(primal.stiffness_matrices(mesh, basis, None, e), skel)
        ue, re, ge = u[num.l2g[e]], reg[e], num.l2g[e]
        flow = -K * (ue[:, None, :] - ue[:, :, None])
        cross = re[:, :, None] != re[:, None, :]
        np.add.at(inflow, (np.broadcast_to(re[:, :, None], flow.shape)[cross],
                           np.broadcast_to(re[:, None, :], flow.shape)[cross]), flow[cross])
        react = np.einsum("enm,em->en", K, ue)
        at = fixed[ge]
        np.add.at(reaction, (re[at], np.where(on_hot[ge[at]], 0, 1)), react[at])

    # the cell's particles in every piece of the period: owner and shift
    maps = _symmetries(box, frame.diagonal, frame.anti)
    bonds_i, bonds_j, bonds_s = frame.scaled.bonds()
    index = {(a, b, tuple(sh)): n for n, (a, b, sh) in enumerate(zip(bonds_i, bonds_j, bonds_s))}
    flow_b = np.zeros(len(bonds_i))

    def add(kp, np_, kq, nq, q):
        """Heat ``q`` from (kp, np_) to (kq, nq) onto its bond."""
        key = (kp, kq, tuple(nq - np_))
        if key in index:
            flow_b[index[key]] += q
        else:
            flow_b[index[(kq, kp, tuple(np_ - nq))]] -= q

    scale = unit * unit * height  # mesh flows (unit temperature difference over height) -> over kappa G, m^2
    mirror = [sc * [1, 1, -1], sc * [1, 1, -1] + [0, 0, 2 * height]]
    on_plane = [np.abs(sc[:, 2]) < tol, np.abs(sc[:, 2] - height) < tol]
    for M, o, fz in maps:
        k, n = _owner(sc @ M.T + o, centres, period)
        for p in range(ns):
            for q in range(p):
                if inflow[q, p] != 0.0:
                    add(k[p], n[p], k[q], n[q], fz * inflow[q, p] * scale)
        if fz < 0:
            continue  # a face on an isothermal plane is its own image under the mirror normal to z
        for side in range(2):
            km, nm = _owner(mirror[side] @ M.T + o, centres, period)
            for p in np.flatnonzero(~on_plane[side] & (reaction[:, side] != 0.0)):
                add(km[p], nm[p], k[p], n[p], reaction[p, side] * scale)
    total = float(np.sum(reaction[:, 0]) * scale * len(maps) / 2)
    residual = np.zeros(cell.n)
    np.add.at(residual, bonds_j, flow_b)
    np.add.at(residual, bonds_i, -flow_b)

    # particle volumes and temperature integrals (theta = T + z, and z), in the cell's particles, then the period's
    vol, int_theta, int_z = np.zeros(ns), np.zeros(ns), np.zeros(ns)

    def integrate(e, degree):
        """Add the elements ``e`` to the particles' integrals at the points of the rule of ``degree``; the
        elements whose points lie in two particles' cells are returned instead."""
        xi, w = tet_quadrature(degree)
        ue = _element_values(mesh, basis, num, u, e)
        x, Jq = mesh.map(e, xi)
        dv = np.abs(np.linalg.det(Jq)) * w
        T = (ue @ basis.values(xi).T - 1.0) * height  # over G, in units of the mesh: -z on the isothermal planes
        r = region(x.reshape(-1, 3)).reshape(dv.shape)
        cut = np.any(r != r[:, :1], axis=1) if degree < CUT_DEGREE else np.zeros(len(e), dtype=bool)
        np.add.at(vol, r[~cut], dv[~cut])
        np.add.at(int_theta, r[~cut], ((T + x[..., 2]) * dv)[~cut])
        np.add.at(int_z, r[~cut], (x[..., 2] * dv)[~cut])
        return e[cut]

    cut = np.concatenate([integrate(np.arange(s, min(s + CHUNK, len(mesh.tets))), order + 2)
                          for s in range(0, len(mesh.tets), CHUNK)])
    for s in range(0, len(cut), CHUNK // 8):
        integrate(cut[s:s + CHUNK // 8], CUT_DEGREE)
    volume, int_T = np.zeros(cell.n), np.zeros(cell.n)
    for M, o, fz in maps:
        k, n = _owner(sc @ M.T + o, centres, period)
        np.add.at(volume, k, vol)
        # z of the image in k's own frame: fz z - n_z P_z; T = -z + fz theta
        np.add.at(int_T, k, -(fz * int_z - n[:, 2] * period[2] * vol) + fz * int_theta)

    face_T, face = _face_temperatures(frame, mesh, basis, num, u, height, bonds_i, bonds_j, bonds_s)
    return NeckFlows(bonds_i, bonds_j, bonds_s, flow_b, face, face_T * unit, int_T / volume * unit,
                     volume * unit**3, residual, total)


def _element_values(mesh, basis, num, u, elements):
    """All nodal values ``(E, n)`` of the ``elements``: the skeleton's from ``u``, the interior nodes' (condensed out
    of the solve) from the element's equations."""
    from fem_neck import primal

    skel = basis.n - basis.n_interior
    ub = u[num.l2g[elements]]
    if not basis.n_interior:
        return ub
    K = primal.stiffness_matrices(mesh, basis, None, elements)
    ui = -np.linalg.solve(K[:, skel:, skel:], np.einsum("eib,eb->ei", K[:, skel:, :skel], ub)[..., None])[..., 0]
    return np.concatenate([ub, ui], axis=1)


def _face_temperatures(frame, mesh, basis, num, u, height, bonds_i, bonds_j, bonds_s):
    """Mean temperature (over G, in the mesh's unit) over every bond's face seen from ``i``, NaN where there is
    none, and whether there is one (module docstring)."""
    from scipy.spatial import cKDTree

    from fem_neck.geometry.union import lens

    cell = frame.scaled
    c, r, P = cell.centres, cell.radii, cell.period
    vec = c[bonds_j] + bonds_s * P - c[bonds_i]
    d = np.linalg.norm(vec, axis=1)
    e = vec / d[:, None]
    neck = lens(r[bonds_i], r[bonds_j], d)
    t, wt = np.polynomial.legendre.leggauss(DISC_RINGS)
    t, wt = 0.5 * (t + 1.0), 0.5 * wt
    angle = 2.0 * np.pi * np.arange(DISC_ANGLES) / DISC_ANGLES
    reach = 2.0 * r.max()
    images, owner, _ = cell.images(-reach * np.ones(3), P + reach)
    tets = mesh.tets
    tree = cKDTree(mesh.points[tets].mean(axis=1))
    points, weights, rows = [], [], []
    for b in range(len(d)):
        helper = np.array([1.0, 0, 0]) if abs(e[b, 0]) < 0.9 else np.array([0, 1.0, 0])
        t1 = np.cross(e[b], helper)
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(e[b], t1)
        middle = c[bonds_i[b]] + neck.l_i[b] * e[b]
        rho = neck.a[b] * np.sqrt(t)
        x = (middle + rho[:, None, None] * (np.cos(angle)[None, :, None] * t1
             + np.sin(angle)[None, :, None] * t2)).reshape(-1, 3)
        own = np.sum((x - c[bonds_i[b]]) ** 2, axis=1) - r[bonds_i[b]] ** 2
        # a point of the disc is inside both spheres, so only a sphere holding it can take it from the face
        near = np.linalg.norm(images - middle, axis=1) < neck.a[b] + r.max()
        other = np.sum((x[:, None, :] - images[near][None]) ** 2, axis=2) - r[owner[near]][None] ** 2
        on = np.all(other >= own[:, None] - 1e-9, axis=1)
        points.append(x[on])
        weights.append(np.repeat(wt, DISC_ANGLES)[on])
        rows.append(np.full(on.sum(), b))
    x, weight, rows = np.concatenate(points), np.concatenate(weights), np.concatenate(rows)
    y, sign = _fold(x, P, frame.box, frame.diagonal, frame.anti)
    theta = (_evaluate(mesh, basis, num, u, tree, tets, y) - 1.0) * height + y[:, 2]
    total = np.bincount(rows, weight * (-x[:, 2] + sign * theta), minlength=len(d))
    area = np.bincount(rows, weight, minlength=len(d))
    face = area > 0.0
    return np.where(face, total / np.where(face, area, 1.0), np.nan), face


def _evaluate(mesh, basis, num, u, tree, tets, y):
    """The solution at points ``y`` of the computational cell (each in the straight tetrahedron among the
    ``NEAREST`` whose centroids are nearest that holds it best)."""
    _, cand = tree.query(y, k=min(NEAREST, len(tets)))
    v = mesh.points[tets[cand]]                                          # (N, k, 4, 3)
    J = np.transpose(v[:, :, 1:] - v[:, :, :1], (0, 1, 3, 2))
    xi = np.linalg.solve(J, (y[:, None, :] - v[:, :, 0])[..., None])[..., 0]
    lam = np.concatenate([1.0 - xi.sum(axis=2, keepdims=True), xi], axis=2)
    best = np.argmax(lam.min(axis=2), axis=1)
    rows = np.arange(len(y))
    elements, xi = cand[rows, best], xi[rows, best]
    values = _element_values(mesh, basis, num, u, elements)
    return np.einsum("en,en->e", values, basis.values(xi))
