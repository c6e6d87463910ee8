"""The lower bound: a divergence-free heat flux on the exactly curved mesh (Thomson's principle), from the hybridised
mixed method with Raviart-Thomas elements of degree ``k`` (Arnold & Brezzi 1985).

On every element the flux is a divergence-free field of ``RT_k`` mapped by Piola (:mod:`fem_neck.simplex`); its
normal traces are tied together by a multiplier ``lambda`` in ``P_k`` on every face (the temperature trace), which is
1 on the hot faces, 0 on the cold ones and unknown elsewhere. Eliminating the element fluxes leaves the symmetric
positive definite face system ``H lambda = 0``, with ``H = sum_K T A_K^-1 T^T`` (``A_K`` the element's flux mass,
``T`` the reference trace moments). Its solution's flux ``q`` has, exactly, zero divergence in every element, the
same normal flux on both sides of every interior face (moments in ``P_k`` of a ``P_k`` trace) and none on the
insulated faces: admissible in the complementary principle on the exact solid, so ``K >= P^2 / E*`` with ``P`` the
heat it carries through the hot face and ``E* = int |q|^2``. The normal-flux continuity holds to the face system's
residual; the largest jump is reported (``flux_defect``). Degree ``k = p - 1`` converges at the rate of the
``P_p`` upper bound (both errors ``O(h^2p)`` in the energy).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from fem_neck.curved import CurvedMesh
from fem_neck.primal import quadrature_degree, symmetric_products
from fem_neck.simplex import RaviartThomas, raviart_thomas, tet_quadrature

CHUNK = 512


def mass_matrices(mesh: CurvedMesh, rt: RaviartThomas, degree: int) -> np.ndarray:
    """Element flux mass matrices ``(M, m, m)``: ``int sigma^T J^T J tau / |det J|`` on the reference element (exact
    on straight elements, quadrature of ``degree`` on curved ones)."""
    J = mesh.affine_jacobians()
    det = np.linalg.det(J)
    G = np.einsum("eai,eaj->eij", J, J) / np.abs(det)[:, None, None]
    A = np.einsum("eij,ijab->eab", G, rt.mass)
    curved = mesh.curved
    if len(curved):
        xi, w = tet_quadrature(degree)
        products = symmetric_products(rt.values(xi))                          # (6 Q, m m)
        for start in range(0, len(curved), CHUNK):
            el = curved[start:start + CHUNK]
            G = mesh.metric(el, xi, w, inverse=False).reshape(len(el), -1)
            A[el] = (G @ products).reshape(len(el), rt.m, rt.m)
    return A


@dataclass
class Solution:
    """``lower = P^2 / E*`` (the lower bound of the conductance for a unit temperature difference, kappa = 1), the
    heat flow ``P`` through the hot faces, ``E*``, face dofs, CG iterations, the relative residual and the largest
    normal-flux jump across a face relative to the mean flux density through the hot face."""

    lower: float
    heat_flow: float
    energy: float
    dofs: int
    iterations: int
    residual: float
    flux_defect: float


def solve(mesh: CurvedMesh, k: int, hot: np.ndarray, cold: np.ndarray, rtol: float = 1e-10,
          degree: int | None = None) -> Solution:
    """The hybridised ``RT_k`` flux with temperature 1 on the ``hot`` faces and 0 on the ``cold`` ones (indices
    into ``mesh.faces``); see the module docstring."""
    import scipy.sparse as sp

    from fem_neck import pcg

    rt = raviart_thomas(k)
    nf = rt.n_face
    A = mass_matrices(mesh, rt, degree or quadrature_degree(k + 1))
    T = rt.traces                                                           # (4 nf, m)
    Ainv_Tt = np.linalg.solve(A, np.broadcast_to(T.T, A.shape[:1] + T.T.shape))  # A^-1 T^T (M, m, 4 nf)
    H = np.matmul(T, Ainv_Tt)                                               # (M, 4 nf, 4 nf)
    l2g = (mesh.t2f[:, :, None] * nf + np.arange(nf)).reshape(len(mesh.tets), -1)
    n = len(mesh.faces) * nf
    constant = 1.0 / rt.face_basis(np.zeros((1, 2)))[0, 0]                # coefficient of the function 1
    fixed_face = np.zeros(len(mesh.faces), dtype=bool)
    fixed_face[hot] = fixed_face[cold] = True
    fixed = np.repeat(fixed_face, nf)
    lam = np.zeros(n)
    lam[hot * nf] = constant
    Hff, b, free = pcg.assemble(H, l2g, fixed, lam)
    free_faces = np.flatnonzero(~fixed_face)
    coarse = sp.csr_matrix((np.ones(len(free_faces)), (np.arange(len(free_faces)) * nf, np.arange(len(free_faces)))),
                           shape=(len(free), len(free_faces)))
    blocks = np.arange(len(free)).reshape(-1, nf)
    x, iterations, residual = pcg.solve(Hff, b, pcg.two_level(Hff, coarse, blocks), rtol=rtol)
    lam[free] = x
    # element fluxes (coefficients of the divergence-free basis) and their face moments
    alpha = -np.einsum("emf,ef->em", Ainv_Tt, lam[l2g])
    moments = np.einsum("fm,em->ef", T, alpha).reshape(len(mesh.tets), 4, nf)
    energy = pcg.element_energy(H, l2g, lam)                               # = sum alpha^T A alpha
    net = np.zeros((len(mesh.faces), nf))
    np.add.at(net, mesh.t2f, moments)
    heat = -float(net[hot, 0].sum()) * constant                              # into the solid at the hot faces
    per_face = abs(heat) / max(len(hot), 1)
    defect = float(np.max(np.abs(net[free_faces])) * constant / per_face) if len(free_faces) else 0.0
    return Solution(heat**2 / energy, heat, energy, len(free), iterations, residual, defect)
