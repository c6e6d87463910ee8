r"""The upper bound: conforming ``P_p`` finite elements on an exactly curved tetrahedral mesh (Dirichlet's principle).

The temperature is held at 1 on the hot faces and 0 on the cold ones; every other boundary is insulated. The discrete
energy :math:`u^T A u` of *any* admissible ``u`` is at least the exact conductance ``K`` (Dirichlet's principle), and
the elements of :mod:`fem_neck.curved` fill the exact solid, so :math:`u^T A u \ge K` holds for the computed ``u``
whatever the solver's residual (which only makes the bound less sharp): CG stops once the energy has settled to
``ENERGY_RTOL``. The ``(p - 1)(p - 2)(p - 3) / 6`` interior nodes of every element are condensed (Schur complement,
batched); the skeleton system, kept as its element matrices (:class:`fem_neck.pcg.ElementSystem`), is solved by
conjugate gradients preconditioned by :func:`fem_neck.pcg.two_level` (the piecewise-linear hats as coarse space, block
Jacobi on the nodes of every vertex, edge and face).
"""

from __future__ import annotations

from collections.abc import Callable

from dataclasses import dataclass

import numpy as np

from fem_neck.curved import CurvedMesh
from fem_neck.simplex import Lagrange, face_normal, face_points, lagrange, tet_quadrature, triangle_quadrature

CHUNK = 2048  # elements per batch of element matrices (bounds the temporary arrays)
# CG stops when the energy has settled to this (relative): the bound is an upper one whatever the solver's error
ENERGY_RTOL = 1e-9


def quadrature_degree(p: int) -> int:
    """Quadrature degree on curved elements: ``2 p`` (the polynomial part is ``2 p - 2``; two more for the map's
    variation: at p = 4 the bounds move by 2-3e-9 relative against ``2 p + 4``, measured on the lattice cells).

    Parameters
    ----------
    p : int
        Polynomial order of the elements (>= 1).
    """
    return 2 * p


def stiffness_matrices(mesh: CurvedMesh, basis: Lagrange, degree: int | None = None,
                       elements: np.ndarray | None = None) -> np.ndarray:
    r"""Element matrices ``(E, n, n)`` of :math:`\int \nabla \phi_a \cdot \nabla \phi_b` of ``elements`` (default all):
    exact on straight elements (a combination of the reference matrices), quadrature of ``degree`` on the curved ones.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh, lengths in its own unit.
    basis : fem_neck.simplex.Lagrange
        The reference ``P_p`` basis.
    degree : int, optional
        Quadrature degree on the curved elements; default :func:`quadrature_degree`.
    elements : numpy.ndarray, optional
        Indices of the elements (rows of ``mesh.tets``); default all.
    """
    elements = np.arange(len(mesh.tets)) if elements is None else elements
    K = np.empty((len(elements), basis.n, basis.n))
    is_curved = mesh.is_curved[elements]
    straight, curved = np.flatnonzero(~is_curved), np.flatnonzero(is_curved)
    if len(straight):
        J = mesh.affine_jacobians(elements[straight])
        inv = np.linalg.inv(J)
        G = np.abs(np.linalg.det(J))[:, None, None] * np.einsum("eia,eja->eij", inv, inv)   # |det J| J^-1 J^-T
        K[straight] = (G.reshape(len(G), 9) @ basis.stiffness.reshape(9, -1)).reshape(len(G), basis.n, basis.n)
    if len(curved):
        xi, w = tet_quadrature(degree or quadrature_degree(basis.p))
        products = symmetric_products(basis.gradients(xi))                     # (6 Q, n (n + 1) / 2)
        G = mesh.metric(elements[curved], xi, w, inverse=True).reshape(len(curved), -1)
        K[curved] = np.take(G @ products, symmetric_gather(basis.n), axis=1).reshape(len(curved), basis.n, basis.n)
    return K


UPPER = ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2))


def symmetric_products(g: np.ndarray) -> np.ndarray:
    r""":math:`g_i g_j^T` of reference fields ``g (Q, 3, n)`` for the six ``(i, j)`` of ``UPPER`` (symmetrised for
    :math:`i \ne j`), each kept as its entries on and above the diagonal in the order of ``numpy.triu_indices(n)``:
    shape :math:`(6 Q, n (n + 1) / 2)`, so that :math:`\sum_q g^T G_q g` is one matrix product with the entries of
    :meth:`fem_neck.curved.CurvedMesh.metric`, packed like this (:func:`symmetric_gather` unpacks it).

    Parameters
    ----------
    g : numpy.ndarray
        Gradients of the ``n`` reference basis functions at ``Q`` points, ``(Q, 3, n)``.
    """
    a, b = np.triu_indices(g.shape[2])
    out = np.stack([0.5 * (g[:, i, a] * g[:, j, b] + g[:, j, a] * g[:, i, b]) for i, j in UPPER], axis=1)
    return out.reshape(g.shape[0] * 6, -1)


def symmetric_gather(n: int) -> np.ndarray:
    """``(n n,)``: where entry ``(a, b)`` of a symmetric ``n`` square matrix is among its packed entries on and above
    the diagonal (the order of ``numpy.triu_indices(n)``).

    Parameters
    ----------
    n : int
        Size of the square matrix.
    """
    upper = np.triu_indices(n)
    position = np.empty((n, n), dtype=np.int64)
    position[upper] = position.T[upper] = np.arange(len(upper[0]))
    return position.ravel()


def volume(mesh: CurvedMesh, degree: int = 10) -> float:
    """Volume of the mapped mesh (a check of the geometry against the exact solid): ``1/3 int x . n dS`` over its
    boundary faces (the divergence theorem), each face mapped with its element and integrated by the triangle rule of
    ``degree`` (exact on the straight ones).

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved mesh; the volume is in the cube of its length unit.
    degree : int
        Degree of the triangle quadrature on each boundary face.
    """
    sides = mesh.face_sides()
    st, w = triangle_quadrature(degree)
    total = 0.0
    for face in range(4):
        elements = np.flatnonzero(sides[mesh.t2f[:, face]] == 1)
        normal = face_normal(face)                                                # outward, times the face's Jacobian
        for start in range(0, len(elements), CHUNK):
            x, J = mesh.map(elements[start:start + CHUNK], face_points(face, st))
            a, b, c = J[..., 0], J[..., 1], J[..., 2]                             # the columns of J
            bc = np.cross(b, c)
            # |det J| J^-T n^ = sign(det J) (n^_0 b x c + n^_1 c x a + n^_2 a x b): outward n dS
            n = np.sign(np.einsum("eqi,eqi->eq", a, bc))[..., None] * (
                normal[0] * bc + normal[1] * np.cross(c, a) + normal[2] * np.cross(a, b))
            total += float(np.einsum("eqi,eqi,q->", x, n, w))
    return total / 3.0


@dataclass(frozen=True)
class Numbering:
    """Global dofs of the skeleton nodes (vertices, edges, faces) of every element.

    Parameters
    ----------
    l2g : numpy.ndarray
        Global dof of each element's skeleton nodes ``(M, n_skeleton)``, in the local order of
        :class:`fem_neck.simplex.Lagrange`.
    n : int
        Number of global skeleton dofs.
    """

    l2g: np.ndarray
    n: int


def numbering(mesh: CurvedMesh, basis: Lagrange) -> Numbering:
    """The :class:`Numbering` of the skeleton nodes: vertices first, then ``n_edge`` dofs per edge, then ``n_face``
    per face.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    basis : fem_neck.simplex.Lagrange
        The reference ``P_p`` basis (its dofs per edge and per face).
    """
    M = len(mesh.tets)
    nv, ne = len(mesh.points), len(mesh.edges)
    cols = [mesh.tets]
    pe, pf = basis.n_edge, basis.n_face
    for k in range(6):
        cols.append(nv + mesh.t2e[:, k:k + 1] * pe + np.arange(pe))
    for f in range(4):
        cols.append(nv + ne * pe + mesh.t2f[:, f:f + 1] * pf + np.arange(pf))
    l2g = np.concatenate(cols, axis=1)
    return Numbering(l2g.reshape(M, -1), nv + ne * pe + len(mesh.faces) * pf)


def skeleton_groups(basis: Lagrange) -> list:
    """The sizes of the groups of an element's skeleton dofs in the order of :func:`numbering` that are one mesh
    entity's (a vertex, the ``n_edge`` nodes of an edge, the ``n_face`` of a face): consecutive global dofs in every
    element, fixed or free together (:class:`fem_neck.pcg.ElementSystem`).

    Parameters
    ----------
    basis : fem_neck.simplex.Lagrange
        The reference ``P_p`` basis.
    """
    return [size for size in [1] * 4 + [basis.n_edge] * 6 + [basis.n_face] * 4 if size]


def face_dofs(mesh: CurvedMesh, basis: Lagrange, faces: np.ndarray) -> np.ndarray:
    """Global dofs of every node on the given faces.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    basis : fem_neck.simplex.Lagrange
        The reference ``P_p`` basis.
    faces : numpy.ndarray
        Indices into ``mesh.faces``.
    """
    nv, ne = len(mesh.points), len(mesh.edges)
    pe, pf = basis.n_edge, basis.n_face
    verts = mesh.faces[faces]
    ekey = mesh.edges[:, 0] * nv + mesh.edges[:, 1]
    pairs = verts[:, [[0, 1], [0, 2], [1, 2]]].reshape(-1, 2)
    edges = np.searchsorted(ekey, pairs[:, 0] * nv + pairs[:, 1])
    out = [verts.ravel(), (nv + edges[:, None] * pe + np.arange(pe)).ravel(),
           (nv + ne * pe + faces[:, None] * pf + np.arange(pf)).ravel()]
    return np.unique(np.concatenate(out))


@dataclass
class Solution:
    r"""The conforming solve of :func:`solve`.

    Parameters
    ----------
    energy : float
        :math:`u^T A u`: the upper bound of the conductance over :math:`\kappa` (:math:`K / \kappa`, for the unit
        temperature difference), in the mesh's length unit (m for a mesh in metres).
    u : numpy.ndarray
        Temperature of every skeleton node (vertices, edges, faces; the interior nodes are condensed), for 1 K on
        the hot faces and 0 on the cold ones.
    dofs : int
        Unknowns of the whole discretisation (all nodes, interior ones included).
    skeleton_dofs : int
        Unknowns of the condensed system CG solved.
    iterations : int
        CG iterations.
    residual : float
        Relative residual ``|r| / |b|`` CG stopped at (dimensionless).
    """

    energy: float
    u: np.ndarray
    dofs: int
    skeleton_dofs: int
    iterations: int
    residual: float


def solve(mesh: CurvedMesh, p: int, hot: np.ndarray, cold: np.ndarray, etol: float = ENERGY_RTOL,
          degree: int | None = None, early: tuple[float, Callable[[np.ndarray], None]] | None = None) -> Solution:
    """The conforming ``P_p`` solution with ``u = 1`` on the ``hot`` faces and 0 on the ``cold`` ones (indices into
    ``mesh.faces``; quadrature of ``degree`` on curved elements, default :func:`quadrature_degree`); see the module
    docstring. CG stops when the energy has settled to ``etol`` (:func:`fem_neck.pcg.solve`).

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh of the solid (any length unit; the energy is per unit ``kappa`` in that unit).
    p : int
        Polynomial order of the elements (>= 1).
    hot, cold : numpy.ndarray
        Indices into ``mesh.faces`` of the faces held at 1 and at 0.
    etol : float
        Relative energy tolerance of CG's energy stop (dimensionless).
    degree : int, optional
        Quadrature degree on curved elements; default :func:`quadrature_degree`.
    early : tuple, optional
        ``(tol, report)``: ``report(u)`` gets the skeleton temperature (as :class:`Solution` ``u``) of the first CG
        iterate whose energy has settled to ``tol`` (looser than ``etol``), before CG goes on (``settled`` of
        :func:`fem_neck.pcg.solve`).
    """
    from fem_neck import pcg

    basis = lagrange(p)
    skel = basis.n - basis.n_interior
    num = numbering(mesh, basis)
    fixed = np.zeros(num.n, dtype=bool)
    values = np.zeros(num.n)
    hot_dofs = face_dofs(mesh, basis, hot)
    fixed[hot_dofs] = fixed[face_dofs(mesh, basis, cold)] = True
    values[hot_dofs] = 1.0
    system = pcg.ElementSystem(num.l2g, fixed, values, skeleton_groups(basis))
    hats = hat_values(basis)
    coarse = np.empty((len(mesh.tets), 4, 4))                               # each element's part of P^T A_ff P
    for start in range(0, len(mesh.tets), CHUNK):
        elements = np.arange(start, min(start + CHUNK, len(mesh.tets)))
        K = condensed(stiffness_matrices(mesh, basis, degree, elements), skel)
        system.add(K, elements)
        coarse[elements] = hat_parts(K, ~fixed[num.l2g[elements]], hats)
    P = hat_prolongation(mesh, basis, num)[system.free]
    # block Jacobi on the nodes of one vertex, edge or face
    precondition = pcg.two_level(system, P, coarse_matrix(mesh, coarse), local=system.block_jacobi())

    def temperature(x: np.ndarray) -> np.ndarray:
        u = values.copy()
        u[system.free] = x
        return u

    settled = None if early is None else (early[0], lambda x: early[1](temperature(x)))
    x, iterations, residual = pcg.solve(system, system.b, precondition, energy=(system.constant, etol),
                                        settled=settled)
    u = temperature(x)
    return Solution(system.energy(x), u, num.n + basis.n_interior * len(mesh.tets), num.n, iterations, residual)


def condensed(K: np.ndarray, skel: int) -> np.ndarray:
    r"""Element matrices ``K (E, n, n)`` with their last ``n - skel`` (interior) nodes condensed out: the Schur
    complement :math:`K_{bb} - K_{bi} K_{ii}^{-1} K_{ib}`, ``(E, skel, skel)``; for one interior node (``P_4``) the
    rank-one update :math:`K_{bb} - k_{bi} k_{bi}^T / k_{ii}`.

    Parameters
    ----------
    K : numpy.ndarray
        Symmetric element matrices ``(E, n, n)``, the skeleton nodes first (W/K for a conductance).
    skel : int
        Number of skeleton nodes ``(<= n)``.
    """
    n = K.shape[1]
    if n == skel:
        return K
    Kbb, Kbi = K[:, :skel, :skel], K[:, :skel, skel:]
    if n - skel == 1:
        k = Kbi[:, :, 0]
        return Kbb - k[:, :, None] * (k / K[:, skel, skel, None])[:, None, :]
    return Kbb - np.matmul(Kbi, np.linalg.solve(K[:, skel:, skel:], np.transpose(Kbi, (0, 2, 1))))


def hat_values(basis: Lagrange) -> np.ndarray:
    """``(n_skeleton, 4)``: the four vertex hats' values (barycentric coordinates) at the skeleton nodes of the
    reference element, the coefficients of the hats in the skeleton basis on every element.

    Parameters
    ----------
    basis : fem_neck.simplex.Lagrange
        The reference ``P_p`` basis.
    """
    skel = basis.n - basis.n_interior
    return np.concatenate([1.0 - basis.nodes[:skel].sum(axis=1, keepdims=True), basis.nodes[:skel]], axis=1)


def hat_parts(K: np.ndarray, free: np.ndarray, hats: np.ndarray) -> np.ndarray:
    r"""Every element's part :math:`H^T K_e^{ff} H` ``(E, 4, 4)`` of the hats' coarse matrix (:func:`coarse_matrix`):
    ``K (E, n, n)`` with the rows and columns of its fixed dofs (``free`` False) zeroed, ``hats`` ``H (n, 4)``
    (:func:`hat_values`); two matrix products over all elements, the few with a fixed dof redone.

    Parameters
    ----------
    K : numpy.ndarray
        Element matrices ``(E, n, n)`` on the skeleton dofs.
    free : numpy.ndarray
        Boolean ``(E, n)``: True where the element's dof is free.
    hats : numpy.ndarray
        The hats' coefficients ``(n, 4)`` in the skeleton basis.
    """
    E, n = free.shape
    KH = (K.reshape(E * n, n) @ hats).reshape(E, n, 4)
    out = (np.ascontiguousarray(KH.transpose(0, 2, 1)).reshape(E * 4, n) @ hats).reshape(E, 4, 4)
    near = np.flatnonzero(~free.all(axis=1))
    out[near] = hats.T @ (K[near] * free[near][:, :, None] * free[near][:, None, :]) @ hats
    return out


def coarse_matrix(mesh: CurvedMesh, blocks: np.ndarray):
    r"""The Galerkin matrix :math:`P^T A_{ff} P` of the hats (:func:`hat_prolongation` on the free dofs) as the sum
    of its element parts ``blocks (E, 4, 4)`` on the elements' vertices, :math:`H^T K_e^{ff} H` (:func:`hat_parts`)
    with ``H`` of :func:`hat_values` and :math:`K_e^{ff}` the element matrix with the fixed dofs' rows and columns
    zeroed (the same matrix as the sparse product, without it); CSR ``(n_vertices, n_vertices)``.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    blocks : numpy.ndarray
        Every element's part ``(E, 4, 4)``, in the unit of the system matrix.
    """
    import scipy.sparse as sp

    rows = np.broadcast_to(mesh.tets[:, :, None], blocks.shape).ravel()
    cols = np.broadcast_to(mesh.tets[:, None, :], blocks.shape).ravel()
    n = len(mesh.points)
    return sp.csr_matrix((blocks.ravel(), (rows, cols)), shape=(n, n))                # (sums the duplicates)


def hat_prolongation(mesh: CurvedMesh, basis: Lagrange, num: Numbering):
    """The piecewise-linear hats in the skeleton basis, ``(n_skeleton, n_vertices)``: a hat's coefficient at a node
    is its barycentric coordinate there.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    basis : fem_neck.simplex.Lagrange
        The reference ``P_p`` basis.
    num : Numbering
        The skeleton numbering of :func:`numbering`.
    """
    import scipy.sparse as sp

    lam = hat_values(basis)
    skel = len(lam)
    dofs, first = np.unique(num.l2g, return_index=True)                    # each node from the first element using it
    element, node = np.divmod(first, skel)
    vals = lam[node]                                                       # (the same from every element)
    keep = vals > 0.0
    rows = np.broadcast_to(dofs[:, None], vals.shape)
    return sp.csr_matrix((vals[keep], (rows[keep], mesh.tets[element][keep])), shape=(num.n, len(mesh.points)))
