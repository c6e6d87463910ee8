r"""Polynomial spaces on the reference tetrahedron :math:`\{\xi \ge 0, \ \xi_1 + \xi_2 + \xi_3 \le 1\}` for the
periodic-cell FE.

* quadrature: on the tetrahedron the fully symmetric rule of Witherden & Vincent (2015) where one is stored for the
  degree (``SYMMETRIC_RULES``), else, and on a face, Stroud's conical product of Gauss-Jacobi rules (exact for
  degree ``2 n - 1`` with ``n`` points per direction);
* :class:`Lagrange`: the nodal basis of ``P_p`` on the equispaced lattice :math:`\alpha / p` (:math:`|\alpha| = p`),
  nodes ordered vertices, edges, faces, interior. With the vertices of every element in ascending global order, a node
  on a shared edge or face has the same barycentric multi-index in both elements, so the global numbering needs no
  orientation logic;
* :class:`RaviartThomas`: the divergence-free fields of :math:`RT_k` (:math:`P_k^3 + x \tilde P_k`, Raviart & Thomas
  1977), with the moments of their normal traces against ``P_k`` on the four faces, for the hybridised mixed method
  (Arnold & Brezzi 1985). The Piola map :math:`\sigma = J \hat\sigma / |\det J|` keeps a reference field divergence-free
  and its face moments unchanged on any (curved) element, so only the mass matrix depends on the element.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np

VERTICES = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
EDGES = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
FACES = ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))  # face l is opposite vertex l, its vertices ascending


def barycentric(xi: np.ndarray) -> np.ndarray:
    """Barycentric coordinates ``(..., 4)`` of reference points ``(..., 3)``.

    Parameters
    ----------
    xi : numpy.ndarray
        Reference coordinates ``(..., 3)``.
    """
    return np.concatenate([1.0 - xi.sum(axis=-1, keepdims=True), xi], axis=-1)


def _gauss_jacobi(n: int, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    r"""``n`` points and weights on [0, 1] for the weight ``(1 - t)^alpha`` (``alpha > -1``): Gauss-Jacobi on [-1, 1]
    for :math:`(1 - s)^\alpha` by Golub & Welsch (1969): the points are the eigenvalues of the symmetric tridiagonal
    matrix of the monic Jacobi polynomials' three-term recurrence (:math:`\beta = 0`), the weights
    :math:`\mu_0 v_0^2` from the eigenvectors' first components, :math:`\mu_0 = 2^{\alpha + 1} / (\alpha + 1)`
    the weight's integral; then mapped to [0, 1]."""
    k = np.arange(n, dtype=float)
    two = 2.0 * k + alpha                                      # 2 k + alpha + beta
    diagonal = -alpha**2 / (two * (two + 2.0)) if alpha else np.zeros(n)
    m = k[1:]
    two = 2.0 * m + alpha
    off = m * (m + alpha) * np.sqrt(4.0 / (two**2 * (two + 1.0) * (two - 1.0)))
    s, v = np.linalg.eigh(np.diag(diagonal) + np.diag(off, 1) + np.diag(off, -1))
    return 0.5 * (s + 1.0), v[0] ** 2 / (alpha + 1.0)          # mu_0 v_0^2 over 2^(alpha + 1), the map's Jacobian


# Fully symmetric rules on the tetrahedron, all points inside, all weights positive (Witherden & Vincent 2015,
# Comput. Math. Appl. 69, 1232-1241), as orbit generators in barycentric coordinates with each point's weight on the
# reference tetrahedron (volume 1/6): (a, a, a, 1 - 3a), (a, a, 1/2 - a, 1/2 - a) and (a, a, b, 1 - 2a - b)
SYMMETRIC_RULES = {
    6: {"s31": ((0.04067395853461135312, 0.0016795351758867738247),
                (0.32233789014227551034, 0.0092261969239424536825),
                (0.21460287125915202929, 0.0066537917096945820166)),
        "s211": ((0.06366100187501752530, 0.60300566479164914137, 0.0080357142857142857143),)},
    8: {"s31": ((0.10795272496221084848, 0.0044044418180681385674),
                (0.18510948778258657028, 0.0086719579272897554525),
                (0.04231654368476728162, 0.0012542093589233666301),
                (0.31418170912403899536, 0.0069606304761558162845)),
        "s22": ((0.43559132858383020523, 0.0060468217102181371669),),
        "s211": ((0.02143393012713057484, 0.71746406342630832329, 0.0011928171484740721917),
                 (0.20413933387602912043, 0.58379737830214440593, 0.0025755810251600558023))},
}


def _symmetric_rule(orbits: dict) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(Q, 3)`` and weights of a rule of ``SYMMETRIC_RULES``: every distinct permutation of each orbit's
    barycentric generator."""
    generators = ([((a, a, a, 1.0 - 3.0 * a), w) for a, w in orbits.get("s31", ())]
                  + [((a, a, 0.5 - a, 0.5 - a), w) for a, w in orbits.get("s22", ())]
                  + [((a, a, b, 1.0 - 2.0 * a - b), w) for a, b, w in orbits.get("s211", ())])
    points, weights = [], []
    for generator, w in generators:
        for lam in sorted(set(itertools.permutations(generator))):
            points.append(lam[1:])
            weights.append(w)
    return np.array(points), np.array(weights)


@functools.lru_cache(maxsize=None)
def tet_quadrature(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(Q, 3)`` and weights ``(Q,)`` exact for polynomials of ``degree`` on the reference tetrahedron
    (weights sum to its volume 1/6): the symmetric rule of ``SYMMETRIC_RULES`` for that degree (degree 6: 24 points
    against the conical product's 64; degree 8: 46 against 125), else Stroud's conical product."""
    if degree in SYMMETRIC_RULES:
        return _symmetric_rule(SYMMETRIC_RULES[degree])
    n = max(1, (degree + 2) // 2)
    (a, wa), (b, wb), (c, wc) = _gauss_jacobi(n, 2.0), _gauss_jacobi(n, 1.0), _gauss_jacobi(n, 0.0)
    A, B, C = (g.ravel() for g in np.meshgrid(a, b, c, indexing="ij"))
    W = np.einsum("i,j,k->ijk", wa, wb, wc).ravel()
    points = np.column_stack([A, B * (1.0 - A), C * (1.0 - A) * (1.0 - B)])
    return points, W


@functools.lru_cache(maxsize=None)
def triangle_quadrature(degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``(Q, 2)`` (coordinates ``s, t`` of the unit triangle) and weights summing to 1/2."""
    n = max(1, (degree + 2) // 2)
    (a, wa), (b, wb) = _gauss_jacobi(n, 1.0), _gauss_jacobi(n, 0.0)
    A, B = (g.ravel() for g in np.meshgrid(a, b, indexing="ij"))
    return np.column_stack([A, B * (1.0 - A)]), np.outer(wa, wb).ravel()


def _exponents(degree: int, dim: int, homogeneous: bool = False) -> np.ndarray:
    """Exponents of the monomials of total degree ``<= degree`` (or ``== degree``) in ``dim`` variables."""
    out = [e for e in itertools.product(range(degree + 1), repeat=dim)
           if (sum(e) == degree if homogeneous else sum(e) <= degree)]
    return np.array(sorted(out, key=lambda e: (sum(e), e[::-1])), dtype=np.int64).reshape(-1, dim)


def monomials(x: np.ndarray, exponents: np.ndarray) -> np.ndarray:
    """Monomials ``(..., m)`` at points ``(..., d)``.

    Parameters
    ----------
    x : numpy.ndarray
        Points ``(..., d)``.
    exponents : numpy.ndarray
        Integer exponents ``(m, d)``, one row per monomial.
    """
    return np.prod(x[..., None, :] ** exponents, axis=-1)


def monomial_gradients(x: np.ndarray, exponents: np.ndarray) -> np.ndarray:
    """Gradients ``(..., d, m)`` of the monomials at points ``(..., d)``.

    Parameters
    ----------
    x : numpy.ndarray
        Points ``(..., d)``.
    exponents : numpy.ndarray
        Integer exponents ``(m, d)``, one row per monomial.
    """
    d = exponents.shape[1]
    out = []
    for k in range(d):
        e = exponents.copy()
        coef = e[:, k].astype(float)
        e[:, k] = np.maximum(e[:, k] - 1, 0)
        out.append(coef * monomials(x, e))
    return np.stack(out, axis=-2)


def _node_indices(p: int) -> list[tuple[int, ...]]:
    """Barycentric multi-indices of the P_p nodes, ordered vertices, edges (from the lower to the higher vertex),
    faces (lexicographic in the face's first two vertices), interior."""
    nodes = [tuple(p if k == i else 0 for k in range(4)) for i in range(4)]
    for i, j in EDGES:
        for m in range(1, p):
            nodes.append(tuple(p - m if k == i else m if k == j else 0 for k in range(4)))
    for f in FACES:
        for a in range(1, p):
            for b in range(1, p - a):
                alpha = [0, 0, 0, 0]
                alpha[f[0]], alpha[f[1]], alpha[f[2]] = a, b, p - a - b
                nodes.append(tuple(alpha))
    nodes += [a for a in itertools.product(range(1, p), repeat=4) if sum(a) == p]
    return nodes


@dataclass(frozen=True)
class Lagrange:
    """The nodal basis of ``P_p`` on the reference tetrahedron (module docstring).

    Parameters
    ----------
    p : int
        Polynomial order (1 to 8).
    nodes : numpy.ndarray
        Reference coordinates ``(n, 3)`` of the nodes, ordered vertices, edges, faces, interior.
    n_edge, n_face, n_interior : int
        Nodes inside each edge (``p - 1``), inside each face (``(p - 1)(p - 2)/2``) and inside the element
        (``(p - 1)(p - 2)(p - 3)/6``).
    exponents : numpy.ndarray
        Exponents ``(n, 3)`` of the monomials of total degree ``<= p``.
    coefficients : numpy.ndarray
        Coefficients ``(n, n)`` of the basis functions (columns) on the monomials (rows).
    """

    p: int
    nodes: np.ndarray
    n_edge: int
    n_face: int
    n_interior: int
    exponents: np.ndarray
    coefficients: np.ndarray

    @property
    def n(self) -> int:
        """Number of basis functions."""
        return len(self.nodes)

    def values(self, xi: np.ndarray) -> np.ndarray:
        """Basis values ``(..., n)`` at reference points ``(..., 3)``.

        Parameters
        ----------
        xi : numpy.ndarray
            Reference coordinates ``(..., 3)``.
        """
        return monomials(xi, self.exponents) @ self.coefficients

    def gradients(self, xi: np.ndarray) -> np.ndarray:
        """Reference gradients ``(..., 3, n)``.

        Parameters
        ----------
        xi : numpy.ndarray
            Reference coordinates ``(..., 3)``.
        """
        return monomial_gradients(xi, self.exponents) @ self.coefficients

    @functools.cached_property
    def stiffness(self) -> np.ndarray:
        r"""``S[i, j]`` :math:`= \int \partial_i \phi \, \partial_j \phi^T` (3, 3, n, n) on the reference tetrahedron
        (exact)."""
        x, w = tet_quadrature(2 * self.p)
        g = self.gradients(x)
        return np.einsum("q,qia,qjb->ijab", w, g, g)


@functools.lru_cache(maxsize=None)
def lagrange(p: int) -> Lagrange:
    """The :class:`Lagrange` basis of order ``p`` (1 to 8; ValueError otherwise), cached."""
    if not 1 <= p <= 8:
        raise ValueError(f"order = {p!r}: valid range 1 <= order <= 8")
    alpha = np.array(_node_indices(p), dtype=float)
    nodes = alpha[:, 1:] / p
    exponents = _exponents(p, 3)
    coefficients = np.linalg.inv(monomials(nodes, exponents))
    return Lagrange(p, nodes, p - 1, (p - 1) * (p - 2) // 2, (p - 1) * (p - 2) * (p - 3) // 6, exponents,
                    coefficients)


def face_points(face: int, st: np.ndarray) -> np.ndarray:
    """Reference points ``(..., 3)`` of face ``face`` at its coordinates ``(s, t)``: ``v_a + s (v_b - v_a) + t (v_c
    - v_a)`` with ``(a, b, c)`` its vertices in ascending order -- the same parametrisation from both elements.

    Parameters
    ----------
    face : int
        Face index 0 to 3 (face ``l`` is opposite vertex ``l``).
    st : numpy.ndarray
        Coordinates ``(..., 2)`` on the unit triangle.
    """
    a, b, c = (VERTICES[v] for v in FACES[face])
    return a + st[..., :1] * (b - a) + st[..., 1:] * (c - a)


def face_normal(face: int) -> np.ndarray:
    """Outward normal of reference face ``face`` scaled by the Jacobian of its ``(s, t)`` parametrisation.

    Parameters
    ----------
    face : int
        Face index 0 to 3 (face ``l`` is opposite vertex ``l``).
    """
    a, b, c = (VERTICES[v] for v in FACES[face])
    n = np.cross(b - a, c - a)
    inward = VERTICES[face] - a
    return -n if n @ inward > 0 else n


@dataclass(frozen=True)
class RaviartThomas:
    r"""Divergence-free fields of ``RT_k`` on the reference tetrahedron (module docstring).

    :meth:`values` gives the ``m`` fields at reference points ``xi``, shape (..., 3, m); ``traces`` (4 n_f, m) are the
    moments :math:`\int_F \mu \, \tau \cdot n_{out} \, dS` against the face basis :math:`\mu` (``n_f`` functions of
    ``(s, t)`` per face, orthonormal on the unit triangle, the first constant); ``mass[i, j]``
    :math:`= \int \tau_i \tau_j^T` (3, 3, m, m).

    Parameters
    ----------
    k : int
        Degree of the space (0 to 7).
    exponents : numpy.ndarray
        Exponents ``(n_k, 3)`` of the monomials of ``P_k``.
    coefficients : numpy.ndarray
        ``(3 n_k + n_h, m)``: the divergence-free fields as combinations of the monomial fields (``e_d`` times each
        monomial, then ``x`` times each of the ``n_h`` homogeneous ones).
    face_exponents : numpy.ndarray
        Exponents ``(n_f, 2)`` of the monomials of ``P_k`` in the face coordinates ``(s, t)``.
    face_coefficients : numpy.ndarray
        ``(n_f, n_f)``: the orthonormal face basis on those monomials.
    """

    k: int
    exponents: np.ndarray
    coefficients: np.ndarray       # (3 n_full, m): div-free combinations of the monomial fields
    face_exponents: np.ndarray
    face_coefficients: np.ndarray  # (n_f_monomials, n_f)

    @property
    def m(self) -> int:
        """Number of divergence-free fields."""
        return self.coefficients.shape[1]

    @property
    def n_face(self) -> int:
        """Number of face functions per face."""
        return self.face_coefficients.shape[1]

    def _full(self, xi: np.ndarray) -> np.ndarray:
        """The monomial fields of RT_k at ``xi``: ``(..., 3, n_full)``: ``e_d m`` for every monomial ``m`` of
        ``P_k`` and direction ``d``, then ``x m`` for the homogeneous ones."""
        mono = monomials(xi, self.exponents)                      # (..., nk)
        hom = mono[..., self._homogeneous]                         # (..., nh)
        parts = []
        for d in range(3):
            f = np.zeros(xi.shape[:-1] + (3, mono.shape[-1]))
            f[..., d, :] = mono
            parts.append(f)
        parts.append(xi[..., :, None] * hom[..., None, :])
        return np.concatenate(parts, axis=-1)

    @functools.cached_property
    def _homogeneous(self) -> np.ndarray:
        return np.flatnonzero(self.exponents.sum(axis=1) == self.k)

    def values(self, xi: np.ndarray) -> np.ndarray:
        """The ``m`` fields (..., 3, m) at reference points ``xi`` (..., 3).

        Parameters
        ----------
        xi : numpy.ndarray
            Reference coordinates ``(..., 3)``.
        """
        return self._full(xi) @ self.coefficients

    def face_basis(self, st: np.ndarray) -> np.ndarray:
        r"""The face functions :math:`\mu` (..., n_f) at face coordinates ``st`` (..., 2).

        Parameters
        ----------
        st : numpy.ndarray
            Coordinates ``(..., 2)`` on the unit triangle.
        """
        return monomials(st, self.face_exponents) @ self.face_coefficients

    @functools.cached_property
    def traces(self) -> np.ndarray:
        r"""The face moments :math:`\int_F \mu \, \tau \cdot n_{out} \, dS`, (4 n_f, m): face-basis function (rows) by
        field."""
        st, w = triangle_quadrature(2 * self.k + 2)
        mu = self.face_basis(st)                                   # (q, n_f)
        rows = []
        for f in range(4):
            flux = np.einsum("d,qdm->qm", face_normal(f), self.values(face_points(f, st)))
            rows.append(np.einsum("q,qa,qm->am", w, mu, flux))
        return np.concatenate(rows, axis=0)

    @functools.cached_property
    def mass(self) -> np.ndarray:
        r"""``mass[i, j]`` :math:`= \int \tau_i \tau_j^T` (3, 3, m, m) on the reference tetrahedron."""
        x, w = tet_quadrature(2 * self.k + 2)
        v = self.values(x)
        return np.einsum("q,qia,qjb->ijab", w, v, v)


def _divergence(xi: np.ndarray, exponents: np.ndarray, homogeneous: np.ndarray, k: int) -> np.ndarray:
    """Divergence ``(..., n_full)`` of the monomial fields of :meth:`RaviartThomas._full`."""
    grads = monomial_gradients(xi, exponents)                      # (..., 3, nk)
    mono = monomials(xi, exponents)
    parts = [grads[..., d, :] for d in range(3)]
    parts.append((3 + k) * mono[..., homogeneous])                 # div(x m) = (3 + deg m) m
    return np.concatenate(parts, axis=-1)


@functools.lru_cache(maxsize=None)
def raviart_thomas(k: int) -> RaviartThomas:
    """The :class:`RaviartThomas` space of degree ``k`` (0 to 7; ValueError otherwise), its fields orthonormal in
    the reference mass, cached."""
    if not 0 <= k <= 7:
        raise ValueError(f"k = {k!r}: valid range 0 <= k <= 7")
    exponents = _exponents(k, 3)
    homogeneous = np.flatnonzero(exponents.sum(axis=1) == k)
    x, w = tet_quadrature(2 * k + 2)
    div = _divergence(x, exponents, homogeneous, k)               # (q, n_full)
    B = np.einsum("q,qa,qm->am", w, monomials(x, exponents), div)  # (dim P_k, n_full)
    _, s, vt = np.linalg.svd(B)
    rank = int(np.sum(s > 1e-10 * s[0]))
    Z = vt[rank:].T                                                # null space: divergence-free combinations
    face_exponents = _exponents(k, 2)
    st, wt = triangle_quadrature(2 * k + 2)
    F = monomials(st, face_exponents)
    gram = np.einsum("q,qa,qb->ab", wt, F, F) * 2.0               # orthonormal on the unit triangle of area 1/2
    face_coefficients = np.linalg.inv(np.linalg.cholesky(gram)).T
    rt = RaviartThomas(k, exponents, Z, face_exponents, face_coefficients)
    # orthonormalise the divergence-free fields in the reference mass (conditioning of the element problems)
    mass = np.einsum("iiab->ab", rt.mass)
    L = np.linalg.cholesky(mass)
    return RaviartThomas(k, exponents, Z @ np.linalg.inv(L).T, face_exponents, face_coefficients)
