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

CHUNK = 2048  # elements per batch of element matrices (bounds the temporary arrays)


def mass_matrices(mesh: CurvedMesh, rt: RaviartThomas, degree: int, elements: np.ndarray) -> np.ndarray:
    """Flux mass matrices ``(E, m, m)`` of ``elements``: ``int sigma^T J^T J tau / |det J|`` on the reference element
    (exact on straight elements, quadrature of ``degree`` on curved ones)."""
    J = mesh.affine_jacobians(elements)
    G = np.einsum("eai,eaj->eij", J, J) / np.abs(np.linalg.det(J))[:, None, None]
    A = np.einsum("eij,ijab->eab", G, rt.mass)
    curved = np.flatnonzero(mesh.is_curved[elements])
    if len(curved):
        xi, w = tet_quadrature(degree)
        products = symmetric_products(rt.values(xi))                          # (6 Q, m m)
        G = mesh.metric(elements[curved], xi, w, inverse=False).reshape(len(curved), -1)
        A[curved] = (G @ products).reshape(len(curved), rt.m, rt.m)
    return A


@dataclass
class Solution:
    """``lower = P^2 / E*`` (the lower bound of the conductance for a unit temperature difference, kappa = 1), the
    heat flow ``P`` through the hot faces, ``E*``, face dofs, CG iterations, the relative residual and the largest
    normal-flux jump across a face relative to the mean flux per hot face."""

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
    into ``mesh.faces``; quadrature of ``degree`` on curved elements); see the module docstring. The element fluxes
    are eliminated chunk by chunk (``H_K = T A_K^-1 T^T``); the net flux moments of the faces are the face system's
    ``-H lambda``: its residual on the free faces (the normal-flux jumps) and the heat flow on the hot ones."""
    import scipy.sparse as sp

    from fem_neck import pcg

    rt = raviart_thomas(k)
    nf = rt.n_face
    T = rt.traces                                                           # (4 nf, m)
    l2g = (mesh.t2f[:, :, None] * nf + np.arange(nf)).reshape(len(mesh.tets), -1)
    constant = 1.0 / rt.face_basis(np.zeros((1, 2)))[0, 0]                # coefficient of the function 1
    fixed_face = np.zeros(len(mesh.faces), dtype=bool)
    fixed_face[hot] = fixed_face[cold] = True
    fixed = np.repeat(fixed_face, nf)
    lam = np.zeros(len(mesh.faces) * nf)
    lam[hot * nf] = constant
    system = pcg.Assembly(l2g, fixed, lam)
    for start in range(0, len(mesh.tets), CHUNK):
        elements = np.arange(start, min(start + CHUNK, len(mesh.tets)))
        A = mass_matrices(mesh, rt, degree or quadrature_degree(k + 1), elements)
        system.add(np.matmul(T, np.linalg.solve(A, np.broadcast_to(T.T, (len(A),) + T.T.shape))), elements)
    H = system.matrix()
    free_faces = np.flatnonzero(~fixed_face)
    coarse = sp.csr_matrix((np.ones(len(free_faces)), (np.arange(len(free_faces)) * nf, np.arange(len(free_faces)))),
                           shape=(len(system.free), len(free_faces)))
    blocks = np.arange(len(system.free)).reshape(-1, nf)
    x, iterations, residual = pcg.solve(H, system.b, pcg.two_level(H, coarse, blocks), rtol=rtol)
    lam[system.free] = x
    energy = system.energy(H, x)                                            # = sum alpha^T A alpha
    heat = float(np.sum(system.boundary_rows(lam)[hot * nf])) * constant    # into the solid at the hot faces
    jumps = np.abs(H @ x - system.b) * constant
    defect = float(jumps.max() / (abs(heat) / max(len(hot), 1))) if len(jumps) else 0.0
    return Solution(heat**2 / energy, heat, energy, len(system.free), iterations, residual, defect)
