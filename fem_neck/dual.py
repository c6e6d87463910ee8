r"""The lower bound: a divergence-free heat flux on the exactly curved mesh (Thomson's principle), from the hybridised
mixed method with Raviart-Thomas elements of degree ``k`` (Arnold & Brezzi 1985), made exactly admissible whatever
the face solver's residual.

On every element the flux is a divergence-free field of ``RT_k`` mapped by Piola (:mod:`fem_neck.simplex`); its normal
traces are tied together by a multiplier :math:`\lambda` in :math:`P_k` on every face (the temperature trace), which is
1 on the hot faces, 0 on the cold ones and unknown elsewhere. Eliminating the element fluxes leaves the symmetric
positive definite face system :math:`H \lambda = 0`, with :math:`H = \sum_K H_K`, :math:`H_K = T A_K^{-1} T^T`
(:math:`A_K` the element's flux mass, ``T`` the reference trace moments); the element flux of :math:`\lambda` is
:math:`A_K^{-1} T^T \lambda_K` and its outward trace moments :math:`H_K \lambda_K`. The face system is minimised by
conjugate gradients until its energy :math:`\lambda^T H \lambda` has settled (as the upper bound's,
``fem_neck.primal.ENERGY_RTOL``), so the element fluxes of the iterate still jump across the faces by the residual.

Equilibration (:func:`equilibrate`): every face gets one flux -- the mean of its two sides' traces, zero on the
insulated faces -- whose face means are then corrected (the correction of least norm, a sparse direct solve on the
element graph) so that the net flux out of every element vanishes; the element then takes the divergence-free field of
least energy with exactly these traces (:math:`\lambda_K + \mu_K` with :math:`H_K \mu_K` the change of its traces; the
traces of divergence-free ``RT_k`` fields are all of ``P_k`` per face with zero net flux). The result is divergence free
in every element with one normal flux on every face and none on the insulated ones, to round-off whatever the iterate:
admissible in the complementary principle on the exact solid, so :math:`K \ge P^2 / E^*` with ``P`` the heat it carries
through the hot faces and :math:`E^* = \int |q|^2` (the largest normal-flux jump left is reported, ``flux_defect``). The
correction is of the size of the solver's error, which the bound feels only to second order (it is the maximum of
:math:`P^2 / E^*`); making an iterate's flux admissible to decouple the guarantee from the algebraic error follows
Jiranek, Strakos & Vohralik 2010. Degree :math:`k = p - 1` converges at the rate of the :math:`P_p` upper bound (both
errors :math:`O(h^{2p})` in the energy).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numba import njit

from fem_neck.curved import CurvedMesh
from fem_neck.primal import ENERGY_RTOL, numbering, quadrature_degree, symmetric_gather, symmetric_products
from fem_neck.simplex import RaviartThomas, face_points, lagrange, raviart_thomas, tet_quadrature, triangle_quadrature

CHUNK = 2048  # elements per batch of element matrices (bounds the temporary arrays)


def mass_matrices(mesh: CurvedMesh, rt: RaviartThomas, degree: int, elements: np.ndarray) -> np.ndarray:
    r"""Flux mass matrices of ``elements``, :math:`\int \sigma^T J^T J \tau / |\det J|` on the reference element
    (exact on straight elements, quadrature of ``degree`` on curved ones), each kept as its upper triangle in the order
    of ``numpy.triu_indices(m)``: ``(E, m (m + 1) / 2)`` (:func:`fem_neck.primal.symmetric_gather` unpacks it).

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    rt : fem_neck.simplex.RaviartThomas
        The reference flux space.
    degree : int
        Quadrature degree on the curved elements.
    elements : numpy.ndarray
        Indices of the elements (rows of ``mesh.tets``).
    """
    a, b = np.triu_indices(rt.m)
    A = np.empty((len(elements), len(a)))
    is_curved = mesh.is_curved[elements]
    straight, curved = np.flatnonzero(~is_curved), np.flatnonzero(is_curved)
    if len(straight):
        J = mesh.affine_jacobians(elements[straight])
        G = np.einsum("eai,eaj->eij", J, J) / np.abs(np.linalg.det(J))[:, None, None]
        A[straight] = G.reshape(len(G), 9) @ rt.mass[:, :, a, b].reshape(9, -1)
    if len(curved):
        xi, w = tet_quadrature(degree)
        products = symmetric_products(rt.values(xi))                          # (6 Q, m (m + 1) / 2)
        G = mesh.metric(elements[curved], xi, w, inverse=False).reshape(len(curved), -1)
        A[curved] = G @ products
    return A


def element_matrices(mesh: CurvedMesh, rt: RaviartThomas, degree: int) -> SymmetricStack:
    r"""The hybridised element matrices :math:`H_K = T A_K^{-1} T^T` (``4 n_f`` square) of every element, with
    :math:`A_K` the flux mass (:func:`mass_matrices`) and ``T`` the reference trace moments (``rt.traces``): one
    compiled pass per batch of elements (Cholesky factor :math:`A_K = L L^T`, :math:`W = L^{-1} T^T`,
    :math:`H_K = W^T W`, exactly symmetric).

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    rt : fem_neck.simplex.RaviartThomas
        The reference flux space.
    degree : int
        Quadrature degree on the curved elements.
    """
    # the fields rotated (orthogonally, so still orthonormal in the reference mass) to put those without traces
    # first: their rows of L^-1 T^T vanish, and the kernel skips them
    _, singular, vt = np.linalg.svd(rt.traces)
    rank = int(np.sum(singular > 1e-12 * singular[0]))
    rt = RaviartThomas(rt.k, rt.exponents, rt.coefficients @ np.concatenate([vt[rank:], vt[:rank]]).T,
                       rt.face_exponents, rt.face_coefficients)
    T = np.ascontiguousarray(rt.traces)                                     # (4 nf, m), zero in its first m - rank
    position = symmetric_gather(rt.m).reshape(rt.m, rt.m)
    E = len(mesh.tets)
    H_K = SymmetricStack(E, len(T))
    for begin in range(0, E, CHUNK):
        elements = np.arange(begin, min(begin + CHUNK, E))
        if not _trace_products(mass_matrices(mesh, rt, degree, elements), position, T, rt.m - rank,
                               H_K.packed[begin:begin + CHUNK]):
            raise ValueError("an element's flux mass matrix is not positive definite: the mesh has a degenerate "
                             "element")
    return H_K


@njit(cache=True, fastmath=True)
def _trace_products(A, position, T, first, out):
    """``out[e]`` = the upper triangle (the order of ``numpy.triu_indices``) of :math:`T A_e^{-1} T^T` for every
    symmetric positive definite ``A_e``, kept as the upper triangles ``A`` (entry ``(i, j)`` at ``position[i, j]``),
    where the first ``first`` columns of ``T`` are zero; False if one is not (a pivot of its Cholesky factor not
    positive)."""
    E, m, n = A.shape[0], T.shape[1], T.shape[0]
    L = np.empty((m, m))
    W = np.empty((m, n))
    H = np.empty((n, n))
    for e in range(E):
        for i in range(m):                                       # A_e = L L^T, row by row
            for j in range(i + 1):
                s = A[e, position[i, j]]
                for k in range(j):
                    s -= L[i, k] * L[j, k]
                if i == j:
                    if not s > 0.0:
                        return False
                    L[i, i] = np.sqrt(s)
                else:
                    L[i, j] = s / L[j, j]
        for i in range(first, m):                                # W = L^-1 T^T (zero above first), forward
            for c in range(n):
                W[i, c] = T[c, i]
            for k in range(first, i):
                f = L[i, k]
                for c in range(n):
                    W[i, c] -= f * W[k, c]
            f = 1.0 / L[i, i]
            for c in range(n):
                W[i, c] *= f
        H[:, :] = 0.0                                            # W^T W (whole rows: the loops vectorise)
        for k in range(first, m):
            for a in range(n):
                f = W[k, a]
                for c in range(n):
                    H[a, c] += f * W[k, c]
        p = 0
        for a in range(n):
            for c in range(a, n):
                out[e, p] = H[a, c]
                p += 1
    return True


@dataclass
class Solution:
    r"""The equilibrated flux of :func:`solve`, for the unit temperature difference and :math:`\kappa = 1`: ``lower``
    and ``heat_flow`` are then :math:`K / \kappa` and :math:`P / \kappa`, in the mesh's length unit (m for a mesh in
    metres).

    Parameters
    ----------
    lower : float
        :math:`P^2 / E^*`: the lower bound of the conductance.
    heat_flow : float
        ``P``, the heat the flux carries through the hot faces.
    energy : float
        ``E* = int |q|^2`` of the equilibrated flux.
    dofs : int
        Unknowns of the face system (the free faces' moments).
    iterations : int
        CG iterations on the face system.
    residual : float
        Relative residual of the face system CG stopped at (dimensionless).
    flux_defect : float
        Largest normal-flux jump across a face of the equilibrated flux, relative to the mean flux per hot face
        (dimensionless; round-off).
    """

    lower: float
    heat_flow: float
    energy: float
    dofs: int
    iterations: int
    residual: float
    flux_defect: float


class SymmetricStack:
    """Symmetric matrices ``(E, n, n)`` kept as their upper triangles (half the memory); ``stack[rows] = M`` keeps
    the upper triangles of ``M``, ``stack[rows]`` gives the symmetric matrices.

    Parameters
    ----------
    count : int
        Number of matrices ``E``.
    n : int
        Size of each square matrix.
    """

    def __init__(self, count: int, n: int):
        self.n = n
        self.upper = np.triu_indices(n)
        self.packed = np.empty((count, len(self.upper[0])))
        self.gather = symmetric_gather(n)                                    # entry (i, j) -> its packed place

    def __len__(self) -> int:
        """Number of matrices."""
        return len(self.packed)

    def __setitem__(self, rows, matrices: np.ndarray) -> None:
        self.packed[rows] = matrices[:, self.upper[0], self.upper[1]]

    def __getitem__(self, rows) -> np.ndarray:
        return np.take(self.packed[rows], self.gather, axis=1).reshape(-1, self.n, self.n)

    def times(self, x: np.ndarray) -> np.ndarray:
        """``M_e x_e`` for every matrix, ``x (E, n)``.

        Parameters
        ----------
        x : numpy.ndarray
            One vector per matrix, ``(E, n)``.
        """
        out = np.empty_like(x)
        _packed_products(self.packed, self.gather.reshape(self.n, self.n), np.ascontiguousarray(x), out)
        return out


@njit(cache=True)
def _packed_products(packed, position, x, out):
    """``out[e] = M_e x[e]`` for the symmetric ``M_e`` kept as the upper triangles ``packed`` (entry ``(i, j)`` at
    ``position[i, j]``)."""
    E, n = x.shape
    for e in range(E):
        for i in range(n):
            s = 0.0
            for j in range(n):
                s += packed[e, position[i, j]] * x[e, j]
            out[e, i] = s


class SymmetricBlocks:
    """A symmetric matrix of ``n_f`` square blocks kept as its blocks on and above the diagonal, in block compressed
    rows (``data (K, n_f, n_f)``, ``indices``, ``indptr``): ``@`` multiplies by the whole matrix, each stored block off
    the diagonal acting also as its transpose below it (half the memory, and half the memory traffic of a product,
    of the full block sparse matrix).

    Parameters
    ----------
    data : numpy.ndarray
        The stored blocks ``(K, n_f, n_f)``, those on and above the diagonal.
    indices : numpy.ndarray
        Block column of every stored block, ascending within a block row.
    indptr : numpy.ndarray
        Start of every block row in ``data`` and ``indices``, and the end (block rows + 1).
    """

    def __init__(self, data: np.ndarray, indices: np.ndarray, indptr: np.ndarray):
        self.data, self.indices, self.indptr = data, indices, indptr
        n = (len(indptr) - 1) * data.shape[1]
        self.shape = (n, n)

    def __matmul__(self, x: np.ndarray) -> np.ndarray:
        nf = self.data.shape[1]
        y = np.zeros(len(x))
        _symmetric_block_product(self.data, self.indices, self.indptr, np.ascontiguousarray(x).reshape(-1, nf),
                                 y.reshape(-1, nf))
        return y

    def block_rows(self) -> np.ndarray:
        """The block row of every stored block (``indices`` holds their block columns)."""
        return np.repeat(np.arange(len(self.indptr) - 1), np.diff(self.indptr))

    def entries(self, a: int, b: int):
        """Entry ``(a, b)`` of every block as a symmetric CSR matrix of the block rows (both triangles); the first
        moments' ``(0, 0)`` is the Galerkin matrix of the face means.

        Parameters
        ----------
        a, b : int
            Row and column within a block (0 to ``n_f - 1``).
        """
        import scipy.sparse as sp

        rows = self.block_rows()
        cols, upper, lower = self.indices, self.data[:, a, b], self.data[:, b, a]
        off = rows != cols
        n = len(self.indptr) - 1
        return sp.csr_matrix((np.concatenate([upper, lower[off]]),
                              (np.concatenate([rows, cols[off]]), np.concatenate([cols, rows[off]]))), shape=(n, n))

    def tocsr(self):
        """The whole matrix as CSR (for checks: twice the memory)."""
        import scipy.sparse as sp

        rows = self.block_rows()
        off = sp.bsr_matrix((np.where((rows != self.indices)[:, None, None], self.data, 0.0), self.indices,
                             self.indptr), shape=self.shape)
        diagonal = sp.bsr_matrix((np.where((rows == self.indices)[:, None, None], self.data, 0.0), self.indices,
                                  self.indptr), shape=self.shape)
        return (diagonal + off + off.T).tocsr()


@njit(cache=True, fastmath=True)
def _symmetric_block_product(data, indices, indptr, x, y):
    """``y += H x`` for the symmetric block matrix of :class:`SymmetricBlocks` (``x``, ``y`` as ``(rows, n_f)``):
    each stored block read once, for its own product and its transpose's."""
    nf = data.shape[1]
    below = np.empty(nf)
    for i in range(len(indptr) - 1):
        for k in range(indptr[i], indptr[i + 1]):
            j = indices[k]
            below[:] = 0.0
            for a in range(nf):
                s = 0.0
                xa = x[i, a]
                for b in range(nf):
                    s += data[k, a, b] * x[j, b]
                    below[b] += data[k, a, b] * xa
                y[i, a] += s
            if j != i:
                for b in range(nf):
                    y[j, b] += below[b]


@dataclass
class FaceSystem:
    r"""The face system on the free faces' moments (:func:`face_system`); ``d`` denotes the faces held at a
    temperature, ``f`` the free ones.

    Parameters
    ----------
    matrix : SymmetricBlocks
        ``H_ff``, one ``n_f`` square block per pair of faces of an element.
    b : numpy.ndarray
        Right-hand side :math:`-H_{fd} \lambda_d`.
    constant : float
        :math:`\lambda_d^T H_{dd} \lambda_d`.
    free : numpy.ndarray
        The free dofs (indices into the face multipliers ``(n_faces n_f,)``).
    diagonal : numpy.ndarray
        The free faces' diagonal blocks ``(n_free, n_f, n_f)`` (for block Jacobi).
    """

    matrix: object
    b: np.ndarray
    constant: float
    free: np.ndarray
    diagonal: np.ndarray

    def energy(self, x: np.ndarray) -> float:
        r""":math:`\lambda^T H \lambda` of :math:`\lambda` = ``x`` on the free dofs, the held values elsewhere.

        Parameters
        ----------
        x : numpy.ndarray
            Values of the free dofs, in the order of ``free``.
        """
        return float(x @ (self.matrix @ x) - 2.0 * (x @ self.b) + self.constant)


def face_system(mesh: CurvedMesh, H_K: SymmetricStack, fixed_face: np.ndarray, lam: np.ndarray) -> FaceSystem:
    """``sum_K H_K`` on the free faces as a symmetric block matrix (:class:`SymmetricBlocks`): two faces of one
    element share only that element, so a block off the diagonal is one element's, and a diagonal block the sum over
    the face's elements; the held faces' multipliers ``lam`` go to the right-hand side.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    H_K : SymmetricStack
        The element matrices :math:`T A_K^{-1} T^T` (``4 n_f`` square).
    fixed_face : numpy.ndarray
        Boolean mask over ``mesh.faces``: True on the faces held at a temperature.
    lam : numpy.ndarray
        Face multipliers ``(n_faces n_f,)``; only those of the held faces are read (the temperature there, K).
    """
    nf, E = H_K.n // 4, len(H_K)
    free_faces = np.flatnonzero(~fixed_face)
    n_free = len(free_faces)
    index = np.full(len(mesh.faces), -1, dtype=np.int64)
    index[free_faces] = np.arange(n_free)
    local = index[mesh.t2f]                                                 # (E, 4), -1 on the held faces
    local_row, local_col = np.nonzero(~np.eye(4, dtype=bool))              # the 12 pairs of distinct faces
    rows, cols = local[:, local_row], local[:, local_col]
    off = (rows >= 0) & (cols >= 0) & (rows < cols)                         # the blocks above the diagonal
    keys = np.concatenate([np.arange(n_free) * (n_free + 1), (rows * n_free + cols)[off]])
    order = np.argsort(keys)
    place = np.empty_like(order)
    place[order] = np.arange(len(order))
    block = np.full((E, 4, 4), -1, dtype=np.int64)                          # each element block's place in data
    pairs = np.full(off.shape, -1, dtype=np.int64)
    pairs[off] = place[n_free:]
    block[:, local_row, local_col] = pairs
    diagonal = np.arange(4)
    block[:, diagonal, diagonal] = np.where(local >= 0, place[np.maximum(local, 0)], -1)
    data = np.zeros((len(keys), nf, nf))
    _add_blocks(data, H_K.packed, H_K.gather.reshape(H_K.n, H_K.n), block)
    b = np.zeros((n_free, nf))
    constant = 0.0
    near = np.flatnonzero(np.any(fixed_face[mesh.t2f], axis=1))              # elements with a held face
    for begin in range(0, len(near), CHUNK):
        chunk = near[begin:begin + CHUNK]
        faces = mesh.t2f[chunk]
        known = np.where(fixed_face[faces][:, :, None], lam.reshape(-1, nf)[faces], 0.0).reshape(len(chunk), 4 * nf)
        load = -np.matmul(H_K[chunk], known[:, :, None]).reshape(len(chunk), 4, nf)
        at = local[chunk]
        np.add.at(b, at[at >= 0], load[at >= 0])
        constant -= float(np.sum(known * load.reshape(len(chunk), 4 * nf)))
    indptr = np.concatenate([[0], np.cumsum(np.bincount(keys // n_free, minlength=n_free))])
    matrix = SymmetricBlocks(data, keys[order] % n_free, indptr)
    free = (free_faces[:, None] * nf + np.arange(nf)).ravel()
    return FaceSystem(matrix, b.ravel(), constant, free, data[place[:n_free]])


@njit(cache=True)
def _add_blocks(data, packed, position, block):
    """Adds block ``(l, m)`` of every element's symmetric matrix (``packed`` upper triangles, ``position`` of entry
    ``(i, j)`` among them) into ``data[block[e, l, m]]`` where that is not -1."""
    nf = data.shape[1]
    for e in range(block.shape[0]):
        for l in range(4):
            for m in range(4):
                k = block[e, l, m]
                if k >= 0:
                    for i in range(nf):
                        for j in range(nf):
                            data[k, i, j] += packed[e, position[l * nf + i, m * nf + j]]


def trace_multipliers(mesh: CurvedMesh, p: int, u: np.ndarray, k: int) -> np.ndarray:
    """Face multipliers ``(n_faces n_f,)`` of the ``P_p`` temperature ``u`` (skeleton values in the numbering of
    :func:`fem_neck.primal.numbering`): its trace on every face projected onto ``P_k`` in the face basis (on the
    unit triangle of the face's own coordinates, from its first element) -- close to the face system's solution,
    from which its CG starts.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    p : int
        Order of the ``P_p`` temperature.
    u : numpy.ndarray
        Skeleton values of the temperature (:class:`fem_neck.primal.Solution` ``u``), K.
    k : int
        Degree of the face space ``P_k``.
    """
    basis, rt = lagrange(p), raviart_thomas(k)
    skeleton = numbering(mesh, basis).l2g
    nf = rt.n_face
    st, w = triangle_quadrature(p + k)
    weighted = 2.0 * w[:, None] * rt.face_basis(st)                      # the face basis is orthonormal for 2 int
    first = mesh.first_sides()
    out = np.zeros((len(mesh.faces), nf))
    for face in range(4):
        elements = np.flatnonzero(first[:, face])
        values = basis.values(face_points(face, st))[:, :skeleton.shape[1]]  # interior nodes vanish on the faces
        out[mesh.t2f[elements, face]] = u[skeleton[elements]] @ (weighted.T @ values).T
    return out.ravel()


class MeanCorrection:
    r"""The face means' correction of least norm that leaves no element a net flux (:func:`equilibrate`): with ``B``
    the signed incidence of the elements and their live faces (all but the insulated ones), :math:`c = B^T y`,
    :math:`B B^T y = -` the elements' net fluxes; :math:`B B^T` depends on the mesh only and is factored once (SuperLU),
    so that the lower bound's process can factor it while it waits for the upper bound's temperature.

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    fixed_face : numpy.ndarray
        Boolean mask over ``mesh.faces``: True on the faces held at a temperature (whose flux is free).
    """

    def __init__(self, mesh: CurvedMesh, fixed_face: np.ndarray):
        import scipy.sparse as sp
        from scipy.sparse.linalg import splu

        E, faces = len(mesh.tets), mesh.t2f.ravel()
        self.sides = mesh.face_sides()
        self.sign = np.where(mesh.first_sides().ravel(), 1.0, -1.0)
        self.insulated = (self.sides == 1) & ~fixed_face
        live = ~self.insulated[faces]
        self.B = sp.csr_matrix((self.sign[live], (np.repeat(np.arange(E), 4)[live], faces[live])),
                               shape=(E, len(mesh.faces)))
        # symmetric positive definite: SuperLU's symmetric mode (no pivoting, the minimum-degree ordering of B B^T):
        # half the fill of its default column ordering, half the time (BCC h/r = 0.02: 1.5e6 against 3.0e6 entries)
        self.factor = splu((self.B @ self.B.T).tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})

    def __call__(self, net: np.ndarray) -> np.ndarray:
        """The correction ``c`` of the face means ``(n_faces,)`` for the elements' net fluxes.

        Parameters
        ----------
        net : numpy.ndarray
            Net flux out of every element ``(E,)``, in the unit of the face moments.
        """
        return self.B.T @ self.factor.solve(-net)


def equilibrate(mesh: CurvedMesh, H_K: SymmetricStack, lam: np.ndarray, fixed_face: np.ndarray,
                correction: MeanCorrection | None = None) -> np.ndarray:
    r"""Element multipliers ``(E, 4 n_f)`` whose element fluxes :math:`A_K^{-1} T^T \lambda_K` form an admissible flux:
    one normal flux on every face, none on the insulated ones (the module docstring), from the element matrices
    ``H_K`` (``4 n_f`` square), any face multipliers ``lam (n_faces n_f,)`` and the faces held at a temperature
    (``fixed_face``, whose flux is free).

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh.
    H_K : SymmetricStack
        The element matrices :math:`T A_K^{-1} T^T` (``4 n_f`` square).
    lam : numpy.ndarray
        Face multipliers ``(n_faces n_f,)`` (any: the CG iterate).
    fixed_face : numpy.ndarray
        Boolean mask over ``mesh.faces``: True on the faces held at a temperature (whose flux is free).
    correction : MeanCorrection, optional
        The factored correction of the face means on this mesh (made here if None).
    """
    correction = MeanCorrection(mesh, fixed_face) if correction is None else correction
    E, n = len(H_K), H_K.n
    nf = n // 4
    faces = mesh.t2f.ravel()
    lam_K = lam.reshape(-1, nf)[mesh.t2f].reshape(E, n)
    outward = H_K.times(lam_K).reshape(E * 4, nf)
    # each face's flux along the normal out of its first element: the mean of its sides
    sign = correction.sign
    flux = np.zeros((len(mesh.faces), nf))
    np.add.at(flux, faces, sign[:, None] * outward)
    flux /= correction.sides[:, None]
    flux[correction.insulated] = 0.0
    # the face means' correction of least norm that leaves no element a net flux
    flux[:, 0] += correction((sign * flux[faces, 0]).reshape(E, 4).sum(axis=1))
    # each element's divergence-free field of least energy with these traces: H_K mu = change of the traces (the
    # constant multiplier, H_K's null space, added to make the system regular; the change is orthogonal to it)
    change = (sign[:, None] * flux[faces] - outward).reshape(E, n)
    if not _add_regularised_solves(H_K.packed, H_K.gather.reshape(n, n), nf, change, lam_K):
        raise ValueError("an element matrix H_K is not positive definite on the fields of zero net flux")
    return lam_K


@njit(cache=True, fastmath=True)
def _add_regularised_solves(packed, position, nf, rhs, out):
    """``out[e] += (H_e + c c^T)^-1 rhs[e]`` for the symmetric ``H_e`` kept as the upper triangles ``packed`` (entry
    ``(i, j)`` at ``position[i, j]``) and ``c`` the constant multiplier (1 at every ``nf``-th entry), by a Cholesky
    factor of each; False if a pivot is not positive."""
    E, n = rhs.shape
    L = np.empty((n, n))
    y = np.empty(n)
    for e in range(E):
        for i in range(n):
            for j in range(i + 1):
                s = packed[e, position[i, j]]
                if i % nf == 0 and j % nf == 0:
                    s += 1.0
                for k in range(j):
                    s -= L[i, k] * L[j, k]
                if i == j:
                    if not s > 0.0:
                        return False
                    L[i, i] = np.sqrt(s)
                else:
                    L[i, j] = s / L[j, j]
        for i in range(n):                                       # L y = rhs
            s = rhs[e, i]
            for k in range(i):
                s -= L[i, k] * y[k]
            y[i] = s / L[i, i]
        for i in range(n - 1, -1, -1):                           # L^T x = y (x over y)
            s = y[i]
            for k in range(i + 1, n):
                s -= L[k, i] * y[k]
            y[i] = s / L[i, i]
        for i in range(n):
            out[e, i] += y[i]
    return True


def solve(mesh: CurvedMesh, k: int, hot: np.ndarray, cold: np.ndarray, etol: float = ENERGY_RTOL,
          degree: int | None = None, start: Callable[[], np.ndarray] | None = None) -> Solution:
    """The equilibrated hybridised ``RT_k`` flux with temperature 1 on the ``hot`` faces and 0 on the ``cold`` ones
    (indices into ``mesh.faces``; quadrature of ``degree`` on curved elements); see the module docstring. CG stops
    when the face system's energy has settled to ``etol`` (:func:`fem_neck.pcg.solve`), starting from zero or from
    the face multipliers ``start()`` returns once the system is assembled (:func:`trace_multipliers`).

    Parameters
    ----------
    mesh : fem_neck.curved.CurvedMesh
        The curved tetrahedral mesh of the solid (any length unit).
    k : int
        Degree of the Raviart-Thomas space (0 to 7).
    hot, cold : numpy.ndarray
        Indices into ``mesh.faces`` of the faces held at 1 and at 0.
    etol : float
        Relative energy tolerance of CG's energy stop (dimensionless).
    degree : int, optional
        Quadrature degree on curved elements; default ``quadrature_degree(k + 1)``.
    start : callable, optional
        Returns the face multipliers ``(n_faces n_f,)`` CG starts from (:func:`trace_multipliers`); zero if None.
    """
    import scipy.sparse as sp

    from fem_neck import pcg

    rt = raviart_thomas(k)
    nf = rt.n_face
    E = len(mesh.tets)
    constant = 1.0 / rt.face_basis(np.zeros((1, 2)))[0, 0]                # coefficient of the function 1
    fixed_face = np.zeros(len(mesh.faces), dtype=bool)
    fixed_face[hot] = fixed_face[cold] = True
    lam = np.zeros(len(mesh.faces) * nf)
    lam[hot * nf] = constant
    H_K = element_matrices(mesh, rt, degree or quadrature_degree(k + 1))
    system = face_system(mesh, H_K, fixed_face, lam)
    H = system.matrix
    n_free = len(system.diagonal)
    # the coarse space: the face means (the first moment of each free face); its Galerkin matrix P^T H P is the
    # (0, 0) entry of every block
    P = sp.csr_matrix((np.ones(n_free), (np.arange(n_free) * nf, np.arange(n_free))), shape=(n_free * nf, n_free))
    coarse = H.entries(0, 0)
    precondition = pcg.two_level(H, P, coarse, system.diagonal)
    correction = MeanCorrection(mesh, fixed_face)                          # (before start(), which may wait)
    x0 = None if start is None else start()[system.free]
    energy0 = system.constant if x0 is None else system.energy(x0)
    x, iterations, residual = pcg.solve(H, system.b, precondition, x0=x0, energy=(energy0, etol))
    lam[system.free] = x
    dofs = len(system.free)
    del H, precondition, system                                             # (memory for the equilibration)
    lam_K = equilibrate(mesh, H_K, lam, fixed_face, correction)
    outward = H_K.times(lam_K).reshape(E * 4, nf)
    energy = float(np.einsum("ea,ea->", lam_K, outward.reshape(E, -1)))    # = sum alpha^T A alpha
    jumps = np.zeros((len(mesh.faces), nf))                                 # outward moments summed per face
    np.add.at(jumps, mesh.t2f.ravel(), outward)
    heat = float(np.sum(jumps[hot, 0])) * constant                          # a hot face has one side
    jumps[fixed_face] = 0.0
    defect = float(np.abs(jumps).max() * constant / (abs(heat) / max(len(hot), 1)))
    return Solution(heat**2 / energy, heat, energy, dofs, iterations, residual, defect)
