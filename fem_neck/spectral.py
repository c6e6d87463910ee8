r"""Curved tensor-product spectral elements: axisymmetric conduction on a quadrilateral mesh (the hp-FEM path).

An element of order ``p`` is the image of the unit square under a transfinite (Gordon-Hall) map of its four edges,
so an edge on the sphere follows the circle exactly -- no geometric error, no correction. The shape functions are
the tensor-product Lagrange polynomials on the Gauss-Lobatto-Legendre nodes (:math:`(p + 1)^2` per element, continuous
across edges); the stiffness is integrated with ``p + 2`` Gauss points per direction. On a mesh graded
geometrically toward the re-entrant corner the conductance converges exponentially in ``p`` (Babuska-Guo), which
is what makes this path fast: a few hundred to a few thousand unknowns for 1e-6 (see :mod:`fem_neck.hpmesh`).

Physics as in :mod:`fem_neck.conduction`: in the meridian half-plane (``x`` radial, ``z`` axial) the weak form is
``int x grad T . grad v`` (the radial weight of axisymmetry), ``T`` is fixed on two straight boundaries, every
other boundary is insulated, and the conductance is :math:`K = 2 \pi \kappa u^T A u` for a unit temperature difference
(the energy, equal to the reaction heat flow).

Meshes are plain arrays (:class:`QuadMesh`); coordinates may be given relative to a point of interest (the corner)
so that tiny elements near it keep full precision: only ``x`` (the weight) must be absolute.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from sinterheat.threads import one_blas_thread

MAX_ORDER = 12
LAYER_MAX = 200  #: largest layer of unknowns :func:`solve` eliminates layer by layer; beyond, sparse LU (SuperLU)


@dataclass(frozen=True)
class QuadMesh:
    r"""Quadrilaterals with straight or circular edges.

    Parameters
    ----------
    points : numpy.ndarray
        Vertex coordinates ``(V, 2)``, ``(x, z)`` with ``x`` the radial coordinate, in the length unit of the body
        (relative to ``origin``).
    quads : numpy.ndarray
        Vertex indices ``(E, 4)``, counter-clockwise.
    arc_angles : numpy.ndarray
        ``(E, 4, 2)``: for edge ``k`` (from vertex ``k`` to ``k + 1``) the angle offsets ``delta_start``,
        ``delta_end`` of its ends along its circle, rad, or NaN for a straight edge.
    arc_circle : numpy.ndarray
        ``(E, 4)``: index into ``circles`` of a curved edge's circle (-1 for straight edges).
    circles : tuple of callable
        Functions of the angle offset :math:`\delta` (array, rad) giving ``(points, d_points)``, the points (..., 2) and
        their derivatives :math:`d\,\mathrm{points} / d\delta` (..., 2), cancellation-free in the coordinates of the
        points.
    origin : tuple of float
        ``(0, z0)``: absolute coordinates are ``points + origin`` (only the axial coordinate may be shifted: the
        radial one is the weight of the axisymmetric forms).
    """

    points: np.ndarray
    quads: np.ndarray
    arc_angles: np.ndarray
    arc_circle: np.ndarray
    circles: tuple
    origin: tuple = (0.0, 0.0)


@functools.lru_cache(maxsize=None)
def reference(order: int):
    """GLL nodes on [0, 1], Gauss points/weights on [0, 1], and the 1D Lagrange values and derivatives at the Gauss
    points: ``(nodes, gauss, weights, values (q, p+1), derivatives (q, p+1))``, ``q = p + 2``.

    Parameters
    ----------
    order : int
        Polynomial order ``p`` (1 to ``MAX_ORDER``).
    """
    from numpy.polynomial import legendre

    coefficients = np.zeros(order + 1)
    coefficients[-1] = 1.0
    interior = legendre.legroots(legendre.legder(coefficients)) if order > 1 else np.array([])
    nodes = 0.5 * (np.concatenate(([-1.0], np.sort(interior), [1.0])) + 1.0)
    g, w = np.polynomial.legendre.leggauss(order + 2)
    gauss, weights = 0.5 * (g + 1.0), 0.5 * w
    values, derivatives = lagrange(nodes, gauss)
    return nodes, gauss, weights, values, derivatives


def lagrange(nodes: np.ndarray, x: np.ndarray):
    """Values and derivatives ``(len(x), len(nodes))`` of the Lagrange polynomials on ``nodes`` at ``x``.

    Parameters
    ----------
    nodes : numpy.ndarray
        Interpolation nodes (1D).
    x : numpy.ndarray
        Evaluation points (1D).
    """
    diff = x[:, None] - nodes[None, :]
    n = nodes.size
    values = np.empty((x.size, n))
    derivatives = np.empty((x.size, n))
    for j in range(n):
        others = np.delete(np.arange(n), j)
        denom = np.prod(nodes[j] - nodes[others])
        terms = diff[:, others]
        values[:, j] = np.prod(terms, axis=1) / denom
        total = np.zeros(x.size)
        for m in range(others.size):
            total += np.prod(np.delete(terms, m, axis=1), axis=1)
        derivatives[:, j] = total / denom
    return values, derivatives


def _edge_offsets(mesh: QuadMesh, k: int, s: np.ndarray):
    """Offset of edge ``k`` of every element from its chord, and its derivative in the edge parameter ``s`` (from
    vertex ``k`` to ``k + 1``): ``(E, m, 2)`` each, zero on straight edges; ``None`` when no such edge is curved."""
    angles = mesh.arc_angles[:, k]
    curved = np.flatnonzero(~np.isnan(angles[:, 0]))
    if curved.size == 0:
        return None
    start = mesh.points[mesh.quads[curved, k]]
    end = mesh.points[mesh.quads[curved, (k + 1) % 4]]
    d0, d1 = angles[curved, 0], angles[curved, 1]
    delta = d0[:, None] + s[None, :] * (d1 - d0)[:, None]
    point = np.empty(delta.shape + (2,))
    tangent = np.empty_like(point)
    which = mesh.arc_circle[curved, k]
    for c in np.unique(which):
        on = which == c
        point[on], tangent[on] = mesh.circles[c](delta[on])
    chord = end - start
    offset = np.zeros((mesh.quads.shape[0], s.size, 2))
    slope = np.zeros_like(offset)
    offset[curved] = point - start[:, None, :] - s[None, :, None] * chord[:, None, :]
    slope[curved] = tangent * (d1 - d0)[:, None, None] - chord[:, None, :]
    return offset, slope


def geometry(mesh: QuadMesh, xi: np.ndarray, eta: np.ndarray):
    """Transfinite map at reference points ``(xi, eta)`` (1D arrays, same length m): ``X (E, m, 2)``, ``dX/dxi`` and
    ``dX/deta``. Bilinear interpolation of the vertices plus, per curved edge, its offset from the chord blended
    linearly toward the opposite edge (Gordon-Hall).

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh.
    xi, eta : numpy.ndarray
        Reference coordinates in ``[0, 1]`` (1D, same length).
    """
    P = mesh.points[mesh.quads]                          # (E, 4, 2)
    xi_, eta_ = xi[None, :, None], eta[None, :, None]
    p0, p1, p2, p3 = (P[:, k, None, :] for k in range(4))
    X = (1 - xi_) * (1 - eta_) * p0 + xi_ * (1 - eta_) * p1 + xi_ * eta_ * p2 + (1 - xi_) * eta_ * p3
    X_xi = (1 - eta_) * (p1 - p0) + eta_ * (p2 - p3)
    X_eta = (1 - xi_) * (p3 - p0) + xi_ * (p2 - p1)
    # edge k and its parameter: 0 bottom (s = xi), 1 right (s = eta), 2 top (s = 1 - xi), 3 left (s = 1 - eta)
    for k, s in enumerate((xi, eta, 1 - xi, 1 - eta)):
        found = _edge_offsets(mesh, k, s)
        if found is None:
            continue
        off, dos = found
        if k == 0:
            X += (1 - eta_) * off
            X_xi += (1 - eta_) * dos
            X_eta -= off
        elif k == 1:
            X += xi_ * off
            X_xi += off
            X_eta += xi_ * dos
        elif k == 2:
            X += eta_ * off
            X_xi -= eta_ * dos
            X_eta += off
        else:
            X += (1 - xi_) * off
            X_xi -= off
            X_eta -= (1 - xi_) * dos
    return X, X_xi, X_eta


def numbering(mesh: QuadMesh, order: int):
    r"""Global dof of every local node, shape :math:`(E, (p + 1)^2)` (local node :math:`a + (p + 1) b`, ``a`` along
    :math:`\xi`), the dof count, the skeleton dof count and the vertex pair of every global edge ``(NE, 2)``. Vertices
    come first, then ``p - 1`` nodes per edge (ordered from its lower to its higher vertex index) -- together the
    skeleton -- then :math:`(p - 1)^2` interior nodes per element.

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh.
    order : int
        Polynomial order ``p``.
    """
    p = order
    quads = mesh.quads
    n_vertices = mesh.points.shape[0]
    first, second = quads, np.roll(quads, -1, axis=1)
    lo, hi = np.minimum(first, second), np.maximum(first, second)
    keys, edge_of = np.unique(lo * n_vertices + hi, return_inverse=True)
    edge_of = edge_of.reshape(quads.shape)
    edge_vertices = np.column_stack([keys // n_vertices, keys % n_vertices])
    forward = first < second
    n_elements = quads.shape[0]
    skeleton = n_vertices + keys.size * (p - 1)
    l2g = np.empty((n_elements, (p + 1) ** 2), dtype=np.int64)
    for k, node in enumerate(_element(p).corner_nodes):
        l2g[:, node] = quads[:, k]
    positions = np.arange(p - 1)
    for k, nodes in enumerate(_element(p).edge_nodes):
        pos = np.where(forward[:, k, None], positions[None, :], p - 2 - positions[None, :])
        l2g[:, nodes] = n_vertices + edge_of[:, k, None] * (p - 1) + pos
    l2g[:, _element(p).interior] = skeleton + np.arange(n_elements * (p - 1) ** 2).reshape(n_elements, -1)
    return l2g, int(skeleton + n_elements * (p - 1) ** 2), int(skeleton), edge_vertices


@dataclass(frozen=True)
class _Element:
    """Order-``p`` reference data: quadrature (points ``xi``, ``eta``, weights ``w``), reference gradients
    ``(Q, n)`` of the shape functions, and the local node sets (corners, edges in edge direction, skeleton =
    corners + edges, interior)."""

    xi: np.ndarray
    eta: np.ndarray
    w: np.ndarray
    g_xi: np.ndarray
    g_eta: np.ndarray
    corner_nodes: tuple
    edge_nodes: tuple
    skeleton: np.ndarray
    interior: np.ndarray


@functools.lru_cache(maxsize=None)
def _element(p: int) -> _Element:
    _, gauss, weights, B, D = reference(p)
    q = gauss.size
    idx = lambda a, b: a + (p + 1) * b  # noqa: E731
    edges = (
        [idx(a, 0) for a in range(1, p)],
        [idx(p, b) for b in range(1, p)],
        [idx(a, p) for a in range(p - 1, 0, -1)],
        [idx(0, b) for b in range(p - 1, 0, -1)],
    )
    corners = (idx(0, 0), idx(p, 0), idx(p, p), idx(0, p))
    interior = np.array([idx(a, b) for b in range(1, p) for a in range(1, p)], dtype=np.int64)
    skeleton = np.setdiff1d(np.arange((p + 1) ** 2), interior)
    return _Element(
        xi=np.tile(gauss, q), eta=np.repeat(gauss, q), w=np.tile(weights, q) * np.repeat(weights, q),
        # d/dxi = D[i, a] B[j, b] and d/deta = B[i, a] D[j, b] at quadrature point i + q j, node a + (p + 1) b
        g_xi=np.einsum("ia,jb->jiba", D, B).reshape(q * q, -1), g_eta=np.einsum("ia,jb->jiba", B, D).reshape(q * q, -1),
        corner_nodes=corners, edge_nodes=tuple(np.array(e, dtype=np.int64) for e in edges), skeleton=skeleton,
        interior=interior,
    )


def stiffness(mesh: QuadMesh, order: int):
    """Element matrices ``(E, n, n)`` of ``int x grad u . grad v`` (``x`` = first coordinate, the radius) and the
    smallest ``det J`` at a quadrature point.

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh.
    order : int
        Polynomial order ``p``.
    """
    el = _element(order)
    X, X_xi, X_eta = geometry(mesh, el.xi, el.eta)
    det = X_xi[..., 0] * X_eta[..., 1] - X_xi[..., 1] * X_eta[..., 0]          # (E, Q)
    scale = el.w[None, :] * X[..., 0] / det
    c_xx = scale * np.einsum("eqk,eqk->eq", X_eta, X_eta)
    c_xe = -scale * np.einsum("eqk,eqk->eq", X_xi, X_eta)
    c_ee = scale * np.einsum("eqk,eqk->eq", X_xi, X_xi)
    flux_xi = c_xx[..., None] * el.g_xi + c_xe[..., None] * el.g_eta          # (E, Q, n)
    flux_eta = c_xe[..., None] * el.g_xi + c_ee[..., None] * el.g_eta
    return np.matmul(el.g_xi.T, flux_xi) + np.matmul(el.g_eta.T, flux_eta), float(det.min())


@dataclass
class Solution:
    r"""One solve of :func:`solve`.

    Parameters
    ----------
    K_over_kappa : float
        :math:`K / \kappa` for a unit temperature difference, in the length unit of the mesh (m for a mesh in metres).
    dofs : int
        Unknowns of the discretisation (all nodes).
    skeleton_dofs : int
        Unknowns actually solved for (vertices and edge nodes; the interiors are condensed).
    order : int
        Polynomial order ``p`` of the elements.
    u_local : numpy.ndarray
        Temperature, shape :math:`(E, (p + 1)^2)`, at every local node, in the unit of the fixed values (K).
    jacobian_min : float
        Smallest Jacobian determinant of the element maps at the quadrature points (> 0 for a valid mesh), in the
        square of the length unit.
    """

    K_over_kappa: float
    dofs: int
    skeleton_dofs: int
    order: int
    u_local: np.ndarray
    jacobian_min: float


def conductance(mesh: QuadMesh, order: int, fixed_vertices: dict) -> Solution:
    """:func:`solve` with BLAS on one thread: the dense work here is many small products, for which a second BLAS
    thread only adds synchronisation -- on a busy 2-core machine it made the element matrices 3-6x slower and a
    dense 300 x 300 Cholesky 5-50x slower (measured); parallel sweeps use processes instead.

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh of the meridian half-plane.
    order : int
        Polynomial order ``p`` (1 to ``MAX_ORDER``).
    fixed_vertices : dict
        Temperature (K) to a mask over the vertices where it is held; two entries (as in :func:`solve`).
    """
    with one_blas_thread():
        return solve(mesh, order, fixed_vertices)


def solve(mesh: QuadMesh, order: int, fixed_vertices: dict) -> Solution:
    r"""Solve :math:`\nabla \cdot (x \nabla T) = 0` with ``T`` held at ``value`` on every edge whose two vertices are in
    ``fixed_vertices[value]`` (a boolean mask over the vertices; two values), insulated elsewhere; return
    :math:`K / \kappa = 2 \pi u^T A u / (\Delta T)^2`. Element interiors are condensed (Schur complement, batched) so
    only the skeleton is factorised; the energy of the condensed system equals that of the full one.

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh of the meridian half-plane.
    order : int
        Polynomial order ``p`` (1 to ``MAX_ORDER``).
    fixed_vertices : dict
        Temperature (K) to a mask over the vertices where it is held; two entries, the difference of their keys being
        the temperature difference.
    """
    if not (isinstance(order, (int, np.integer)) and 1 <= order <= MAX_ORDER):
        raise ValueError(f"order = {order!r}: valid range 1 <= order <= {MAX_ORDER}")
    p = int(order)
    el = _element(p)
    matrices, jac_min = stiffness(mesh, p)
    if not jac_min > 0.0:
        raise RuntimeError(f"degenerate element (det J = {jac_min:.3g} <= 0): the mesh is invalid for this shape")
    l2g, n, n_skel, edge_vertices = numbering(mesh, p)
    sk, inn = el.skeleton, el.interior
    S = matrices[:, sk[:, None], sk[None, :]]
    if inn.size:
        K_ib = matrices[:, inn[:, None], sk[None, :]]
        elimination = np.linalg.solve(matrices[:, inn[:, None], inn[None, :]], K_ib)   # K_ii^-1 K_ib
        S = S - np.matmul(np.transpose(K_ib, (0, 2, 1)), elimination)
    # fixed skeleton dofs: vertices in a mask, and the nodes of edges with both ends in the same mask
    u = np.zeros(n_skel)
    is_fixed = np.zeros(n_skel, dtype=bool)
    values = sorted(fixed_vertices)
    n_vertices = mesh.points.shape[0]
    for value in values:
        mask = np.asarray(fixed_vertices[value], dtype=bool)
        edges = np.flatnonzero(mask[edge_vertices[:, 0]] & mask[edge_vertices[:, 1]])
        dofs = np.concatenate([np.flatnonzero(mask), (n_vertices + edges[:, None] * (p - 1)
                                                      + np.arange(p - 1)[None, :]).ravel()])
        u[dofs] = value
        is_fixed[dofs] = True
    free = ~is_fixed
    index = np.cumsum(free) - 1
    g = l2g[:, sk]
    rows = np.broadcast_to(g[:, :, None], S.shape)
    cols = np.broadcast_to(g[:, None, :], S.shape)
    free_rows = free[rows]
    ff = free_rows & free[cols]
    fd = free_rows & ~free[cols]
    n_free = int(free.sum())
    rhs = -np.bincount(index[rows[fd]], S[fd] * u[cols[fd]], minlength=n_free)
    layer = np.full(n_skel, np.iinfo(np.int64).max)  # a skeleton dof's layer: the lowest of its elements' layers
    np.minimum.at(layer, g, element_layers(mesh)[:, None])
    u[free] = _skeleton_solve(index[rows[ff]], index[cols[ff]], S[ff], rhs, layer[free])
    u_skel = u[g]                                                               # (E, skeleton nodes)
    energy = float(np.einsum("ei,eij,ej->", u_skel, S, u_skel))
    u_local = np.empty((mesh.quads.shape[0], (p + 1) ** 2))
    u_local[:, sk] = u_skel
    if inn.size:
        u_local[:, inn] = -np.einsum("eij,ej->ei", elimination, u_skel)
    delta = values[-1] - values[0]
    return Solution(K_over_kappa=2.0 * math.pi * energy / delta**2, dofs=n, skeleton_dofs=n_skel, order=p,
                    u_local=u_local, jacobian_min=jac_min)


def element_layers(mesh: QuadMesh) -> np.ndarray:
    """Every element's layer ``(E,)``: its distance, in steps between elements sharing a vertex, from an element at
    one end of the mesh (a pseudo-peripheral one: the farthest from the farthest from element 0). Elements sharing a
    vertex are in the same or in neighbouring layers, so a dof's unknowns couple only with those of its own and the
    two neighbouring layers of dofs (:func:`solve`); on the graded meshes of :mod:`fem_neck.hpmesh` the layers are
    the rings around the corner.

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh (connected: an element that no path of shared vertices reaches gets layer -1).
    """
    quads = mesh.quads
    layers = np.zeros(quads.shape[0], dtype=np.int64)
    start = 0
    for _ in range(3):  # from element 0, then twice from the farthest element found
        layers.fill(-1)
        layers[start] = 0
        frontier = np.zeros(quads.shape[0], dtype=bool)
        frontier[start] = True
        reached = np.zeros(mesh.points.shape[0], dtype=bool)
        step = 0
        while frontier.any():
            reached[quads[frontier]] = True
            step += 1
            frontier = (layers < 0) & reached[quads].any(axis=1)
            layers[frontier] = step
        start = int(np.argmax(layers))
    return layers


def _skeleton_solve(rows: np.ndarray, cols: np.ndarray, values: np.ndarray, rhs: np.ndarray,
                    layer: np.ndarray) -> np.ndarray:
    """The solution of the condensed skeleton system ``A x = rhs``, ``A`` given by its entries ``A[rows, cols] +=
    values`` (duplicates summed) and every unknown's ``layer`` (unknowns couple only within a layer and with the
    neighbouring layers: :func:`element_layers`).

    When no layer holds more than :data:`LAYER_MAX` unknowns, ``A`` is block tridiagonal in the layers and is
    eliminated layer by layer (block Gaussian elimination, dense LAPACK on the one BLAS thread of
    :func:`conductance`; the cost grows as the unknowns times the square of a layer's; the Schur complements of a
    symmetric positive definite matrix stay so, so no pivoting across layers is needed), which needs no scipy:
    importing scipy's sparse solvers costs a process more CPU than a sweep's hundred solves. Otherwise by sparse LU
    (SuperLU).
    """
    n = rhs.size
    if layer.min() < 0 or np.bincount(layer).max() > LAYER_MAX:  # a part no layer reaches, or too large a layer
        import scipy.sparse as sp
        from scipy.sparse.linalg import splu

        A = sp.csc_matrix((values, (rows, cols)), shape=(n, n))
        return splu(A, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True}).solve(rhs)
    layer = np.unique(layer, return_inverse=True)[1]  # layers without an unknown dropped
    sizes = np.bincount(layer)
    order = np.argsort(layer, kind="stable")
    starts = np.concatenate([[0], np.cumsum(sizes)])
    position = np.empty(n, dtype=np.int64)
    position[order] = np.arange(n)
    local = position - starts[layer]                  # an unknown's place within its layer
    w, m = int(sizes.max()), sizes.size
    block = layer[rows] + (layer[cols] - layer[rows] + 1) * m  # 0..m-1 below, m..2m-1 diagonal, 2m.. above
    blocks = np.bincount((block * w + local[rows]) * w + local[cols], values, minlength=3 * m * w * w)
    blocks = blocks.reshape(3, m, w, w)               # [below (row layer k), diagonal, above][k]
    b = rhs[order]
    kept, schur, y = [], blocks[1, 0, :sizes[0], :sizes[0]], b[:sizes[0]]
    for k in range(m - 1):
        n0, n1 = sizes[k], sizes[k + 1]
        z = np.linalg.solve(schur, np.column_stack([blocks[2, k, :n0, :n1], y]))  # S_k^-1 [A_k,k+1 | y_k]
        kept.append(z)
        below = blocks[0, k + 1, :n1, :n0]
        schur = blocks[1, k + 1, :n1, :n1] - below @ z[:, :-1]
        y = b[starts[k + 1]:starts[k + 2]] - below @ z[:, -1]
    x = np.empty(n)
    part = np.linalg.solve(schur, y)
    x[starts[m - 1]:] = part
    for k in range(m - 2, -1, -1):
        part = kept[k][:, -1] - kept[k][:, :-1] @ part
        x[starts[k]:starts[k + 1]] = part
    out = np.empty(n)
    out[order] = x
    return out


def measure(mesh: QuadMesh, order: int = 4) -> tuple[float, float]:
    r""":math:`(2 \pi \int x \, dA, \min \det J)`: the volume of revolution of the mesh (a check against the exact body)
    and its smallest Jacobian determinant at the order's quadrature points (> 0 for a valid mesh).

    Parameters
    ----------
    mesh : QuadMesh
        The quadrilateral mesh of the meridian half-plane.
    order : int
        Order whose quadrature (``p + 2`` Gauss points per direction) integrates the volume.
    """
    el = _element(order)
    X, X_xi, X_eta = geometry(mesh, el.xi, el.eta)
    det = X_xi[..., 0] * X_eta[..., 1] - X_xi[..., 1] * X_eta[..., 0]
    return 2.0 * math.pi * float(np.sum(el.w[None, :] * X[..., 0] * det)), float(det.min())


def sample(mesh: QuadMesh, solution: Solution, points_per_edge: int = 6):
    """The solution on a uniform ``points_per_edge``-grid in every element, for pictures and VTU files:
    ``(points (n, 2), triangles (m, 3), T (n,), |grad T| (n,))`` in absolute coordinates (points per element, not
    shared).

    Parameters
    ----------
    mesh : QuadMesh
        The mesh ``solution`` was solved on.
    solution : Solution
        The solve to sample.
    points_per_edge : int
        Sample points along each edge of every element (>= 2).
    """
    p = solution.order
    nodes = reference(p)[0]
    s = np.linspace(0.0, 1.0, points_per_edge)
    values, derivatives = lagrange(nodes, s)
    xi, eta = np.tile(s, s.size), np.repeat(s, s.size)
    X, X_xi, X_eta = geometry(mesh, xi, eta)
    shape = np.einsum("ia,jb->jiba", values, values).reshape(s.size**2, -1)
    d_xi = np.einsum("ia,jb->jiba", derivatives, values).reshape(s.size**2, -1)
    d_eta = np.einsum("ia,jb->jiba", values, derivatives).reshape(s.size**2, -1)
    u = solution.u_local
    T = u @ shape.T
    t_xi, t_eta = u @ d_xi.T, u @ d_eta.T
    det = X_xi[..., 0] * X_eta[..., 1] - X_xi[..., 1] * X_eta[..., 0]
    # grad T = J^-T (dT/dxi, dT/deta), J = [X_xi X_eta]
    gx = (X_eta[..., 1] * t_xi - X_xi[..., 1] * t_eta) / det
    gz = (-X_eta[..., 0] * t_xi + X_xi[..., 0] * t_eta) / det
    m = s.size
    local = np.array([[i + m * j, i + 1 + m * j, i + 1 + m * (j + 1)] for j in range(m - 1) for i in range(m - 1)]
                     + [[i + m * j, i + 1 + m * (j + 1), i + m * (j + 1)] for j in range(m - 1) for i in range(m - 1)])
    offsets = (np.arange(mesh.quads.shape[0]) * m * m)[:, None, None]
    triangles = (local[None, :, :] + offsets).reshape(-1, 3)
    return X.reshape(-1, 2) + np.asarray(mesh.origin), triangles, T.ravel(), np.hypot(gx, gz).ravel()
