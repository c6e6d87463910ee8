r"""Steady axisymmetric heat conduction through sintered necks (scikit-fem), and the conductances of Rojek 2022.

Physics. In the meridian half-plane (``x`` radial, ``y`` axial) the steady conduction equation of a body of
revolution is :math:`\nabla \cdot (\kappa x \nabla T) = 0`; its weak form is the Laplacian weighted by the radial
coordinate ``x`` (``w.x[0]``), and every heat flow is :math:`2 \pi` times the meridian integral. The temperature is
fixed on the two end disks (``T = 1`` on ``top``, ``0`` on ``bottom``), every other surface is insulated, so with
:math:`\Delta T = 1`

.. math::

    K = \frac{Q}{\Delta T} &= 2 \pi \kappa \sum_{i \in \mathrm{top}} (A u)_i
        \quad \text{(the reaction at the Dirichlet dofs)} \\
      &= 2 \pi \kappa \, u^T A u \quad \text{(the energy; identical to round-off)},

which converges at twice the rate of the boundary flux :math:`-\kappa \, \partial T / \partial n` (the tests
cross-check both).
Lengths are normalised by the largest radius before meshing, and ``K`` scales back linearly with length.

Accuracy: see :mod:`fem_neck.accuracy`. Elements are Lagrange P1-P4 on the isoparametric (quadratic) version of the
graded mesh, so the curved sphere surface is followed; ``curved=False`` keeps straight sides (studies only).

Public API (all plain functions of numbers, safe to call from a process pool; gmsh is opened and closed per mesh):

* :func:`semisphere_conductance` -- the semisphere with a neck, :math:`r = 1`, :math:`\kappa = 1` (Rojek 2022, Section
  5), or the half body of the union of spheres (no neck cylinder);
* :func:`pair_conductance` -- two spheres ``r_i``, ``r_j`` with overlap ``h`` (Section 6);
* :func:`chain_conductance` -- a collinear chain;
* :func:`solve_profile` -- one solve on a given mesh and order (for convergence studies).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from fem_neck import accuracy, hpmesh, shapes, spectral
from fem_neck.geometry import check_positive, neck_geometry


@dataclass
class Solution:
    r"""One FE solve on one mesh (length-normalised body, :math:`\kappa = 1`): the conductance ``K`` = ``K_reaction``
    + ``geometry_correction``, the basis and the temperature ``u`` (``T = 0`` on ``bottom``, ``1`` on ``top``).

    Parameters
    ----------
    K : float
        Conductance of the normalised body (lengths over the length scale, :math:`\kappa = 1`): ``K_reaction`` +
        ``geometry_correction``; times ``kappa`` and the length scale it is in W/K.
    K_reaction : float
        :math:`2 \pi` times the reaction at the ``top`` dofs (normalised, as ``K``).
    geometry_correction : float
        The Hadamard correction of :func:`geometry_correction` (normalised, as ``K``).
    dofs : int
        Number of unknowns of the solve.
    order : int
        Lagrange element order, 1 to 4.
    basis : skfem.Basis
        The FE basis on the (curved) mesh.
    u : numpy.ndarray
        Temperature at the dofs of ``basis`` (dimensionless: 0 on ``bottom``, 1 on ``top``).
    matrix : scipy.sparse.csr_matrix
        The assembled axisymmetric stiffness matrix (before the temperatures were fixed).
    """

    K: float
    K_reaction: float
    geometry_correction: float
    dofs: int
    order: int
    basis: object = field(repr=False)
    u: np.ndarray = field(repr=False)
    matrix: object = field(repr=False)


@dataclass
class Result:
    r"""A conductance solved to a tolerance.

    ``solution`` and ``profile`` are what :mod:`fem_neck.render` needs; they are dropped when the result is pickled,
    so results travel cheaply between processes.

    Parameters
    ----------
    K : float
        Conductance in W/K for the given ``kappa`` and lengths.
    K_over_Kcyl : float
        :math:`K / (\kappa \pi r)` (dimensionless) with ``r`` the sphere radius (semisphere) or the smallest radius
        (pair, chain): the normalisation of Rojek 2022, eqs. 38-39.
    error_estimate : float
        Relative error estimate of ``K`` (dimensionless; :mod:`fem_neck.accuracy`).
    converged : bool
        Whether the estimate met the tolerance asked for.
    dofs : int
        Unknowns of the reported solve.
    seconds : float
        Wall time of the meshing and all solves, s.
    h_min : float
        Shortest mesh edge, in the unit of the input lengths (m for pairs and chains; units of r for the
        semisphere).
    grading : float
        Final mesh size per distance from the neck corner (dimensionless; the hp path's geometric ratio).
    order : int
        Element order of the reported solve.
    rounds : int
        Meshes (gmsh path) or orders (hp path) tried.
    necks : list of float
        Neck radius of each bond, in the unit of the input lengths.
    kappa : float
        Thermal conductivity the conductance is for, W/(m K).
    length_scale : float
        The length the body was normalised by before meshing, in the unit of the input lengths.
    solution : Solution or None
        The reported solve (None after unpickling).
    profile : object
        The meshed profile (:class:`fem_neck.shapes.ProfileMesh`, or the hp quadrilateral mesh); None after
        unpickling.
    """

    K: float
    K_over_Kcyl: float
    error_estimate: float
    converged: bool
    dofs: int
    seconds: float
    h_min: float
    grading: float
    order: int
    rounds: int
    necks: list
    kappa: float
    length_scale: float
    solution: Solution | None = field(default=None, repr=False)
    profile: object = field(default=None, repr=False)

    def __getstate__(self):
        state = dict(self.__dict__)
        state["solution"] = None
        state["profile"] = None
        return state


_ELEMENTS = {1: "ElementTriP1", 2: "ElementTriP2", 3: "ElementTriP3", 4: "ElementTriP4"}


def _axisymmetric_laplace():
    import skfem
    from skfem.helpers import dot, grad

    @skfem.BilinearForm
    def laplace(u, v, w):
        return w.x[0] * dot(grad(u), grad(v))

    return laplace


def solve_profile(profile: shapes.ProfileMesh, order: int = 2, curved: bool = True, mesh=None) -> Solution:
    r"""Solve :math:`\nabla \cdot (x \nabla T) = 0` with :math:`T = 0` on ``bottom``, 1 on ``top``; :math:`K = 2 \pi`
    times the reaction, :math:`\kappa = 1`.

    The SPD system is factorised by SuperLU in symmetric mode with a minimum-degree ordering of :math:`A + A^T` (3x
    faster than its default column ordering here).

    Parameters
    ----------
    profile : fem_neck.shapes.ProfileMesh
        The meshed meridian profile (lengths normalised), with its ``top`` and ``bottom`` boundaries and its arcs.
    order : int
        Lagrange element order, 1 to 4.
    curved : bool
        Solve on the isoparametric quadratic mesh (:func:`fem_neck.shapes.curved_mesh`) that follows the spheres;
        False keeps straight sides (studies only). P1 is always affine.
    mesh : skfem.MeshTri2, optional
        The curved mesh of ``profile``, made once and passed to reuse it across orders.

    Returns
    -------
    Solution
        The conductance of the normalised body (:math:`\kappa = 1`), its basis and temperatures.

    Raises
    ------
    ValueError
        ``order`` not 1 to 4.
    RuntimeError
        The FE basis failed on a degenerate (round-off flat) element.
    """
    import skfem
    from scipy.sparse.linalg import splu

    if order not in _ELEMENTS:
        raise ValueError(f"order = {order!r}: must be one of {', '.join(map(str, _ELEMENTS))}")
    if mesh is None or not (curved and order > 1):
        mesh = shapes.curved_mesh(profile) if curved and order > 1 else profile.mesh
    try:
        basis = skfem.Basis(mesh, getattr(skfem, _ELEMENTS[order])())
    except Exception as exc:  # skfem raises a bare Exception for degenerate (round-off flat) elements
        raise RuntimeError(f"FE basis failed on a mesh with h_min = {profile.h_min:.3g}: {exc}") from exc
    matrix = _axisymmetric_laplace().assemble(basis)
    top = basis.get_dofs("top").all()
    fixed = np.concatenate([top, basis.get_dofs("bottom").all()])
    u = np.zeros(basis.N)
    u[top] = 1.0
    reduced, rhs, u, free = skfem.condense(matrix, x=u, D=fixed)
    u[free] = splu(reduced.tocsc(), permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True}).solve(rhs)
    K = 2.0 * math.pi * float(np.sum((matrix @ u)[top]))
    correction = geometry_correction(profile, basis, u)
    return Solution(K=K + correction, K_reaction=K, geometry_correction=correction, dofs=int(basis.N), order=order,
                    basis=basis, u=u, matrix=matrix)


_REFERENCE_EDGES = np.array([[[0.0, 0.0], [1.0, 0.0]], [[1.0, 0.0], [0.0, 1.0]], [[0.0, 0.0], [0.0, 1.0]]])


def geometry_correction(profile: shapes.ProfileMesh, basis, u, points: int = 8) -> float:
    r"""First-order (Hadamard) correction of ``K`` for the gap between the meshed and the true spherical surfaces.

    Moving an insulated boundary outwards by ``delta`` changes the conductance by
    :math:`dK = \int_\Gamma \kappa |\nabla T|^2 \delta \, dS` (the shape derivative of the Dirichlet energy).
    :math:`\delta` is the distance from each boundary edge of the mesh (straight, or quadratic isoparametric) to its
    circle, evaluated at Gauss points along the edge (taken in the reference triangle, so no point inversion is needed);
    :math:`\kappa = 1`, :math:`\Delta T = 1`, :math:`dS = 2 \pi x \, ds`. It removes the :math:`O(h^4)` geometric error
    of quadratic boundaries to second order (measured: P4 from -3e-6 to 1e-8 on the reference semisphere).

    Parameters
    ----------
    profile : fem_neck.shapes.ProfileMesh
        The meshed profile: its straight mesh and its arcs (centre height and radius of each sphere's boundary).
    basis : skfem.Basis
        The basis ``u`` lives on (straight or curved mesh of ``profile``).
    u : numpy.ndarray
        Temperature at the dofs of ``basis`` (0 on ``bottom``, 1 on ``top``).
    points : int
        Gauss points per boundary edge.

    Returns
    -------
    float
        ``dK`` for the normalised body (:math:`\kappa = 1`, lengths normalised), to add to the reaction conductance.
    """
    import skfem

    mesh = basis.mesh
    s, weights = np.polynomial.legendre.leggauss(points)
    s, weights = 0.5 * (s + 1.0), 0.5 * weights
    total = 0.0
    for name, (z_centre, radius) in profile.arcs.items():
        facets = profile.mesh.boundaries[name]
        elements = mesh.f2t[0, facets]
        for k, (va, vb) in enumerate(_REFERENCE_EDGES):
            on_edge = mesh.t2f[k, elements] == facets
            if not np.any(on_edge):
                continue
            sel = elements[on_edge]
            tangent = vb - va
            ref = va[:, None] + tangent[:, None] * s[None, :]
            edge_basis = skfem.CellBasis(mesh, basis.elem, elements=sel, quadrature=(ref, weights))
            grad_u = edge_basis.interpolate(u).grad
            x = edge_basis.mapping.F(ref, tind=sel)
            jac = edge_basis.mapping.DF(ref, tind=sel)
            ds = np.hypot(jac[0, 0] * tangent[0] + jac[0, 1] * tangent[1], jac[1, 0] * tangent[0] + jac[1, 1] * tangent[1])
            gap = radius - np.hypot(x[0], x[1] - z_centre)
            total += float(np.sum((grad_u[0] ** 2 + grad_u[1] ** 2) * gap * x[0] * ds * weights))
    return 2.0 * math.pi * total


def _to_tolerance(build, kappa: float, length_scale: float, r_ref: float, rtol, order, necks) -> Result:
    """Mesh with ``build(grading)`` and solve orders ``p-1`` and ``p`` until the estimate meets ``rtol``."""
    rtol = accuracy.check_rtol(rtol)
    order = accuracy.check_order(order, rtol)
    start = time.perf_counter()

    def solve_pair(grading, p):
        profile = build(grading)
        curved = shapes.curved_mesh(profile)
        high = solve_profile(profile, p, mesh=curved)
        low = solve_profile(profile, p - 1, mesh=curved)
        return high.K, low.K, (profile, high)

    K, estimate, grading, (profile, high), rounds, converged = accuracy.solve_to_tolerance(solve_pair, rtol, order)
    K_si = K * kappa * length_scale
    return Result(
        K=K_si, K_over_Kcyl=K_si / (kappa * math.pi * r_ref), error_estimate=estimate, converged=converged,
        dofs=high.dofs, seconds=time.perf_counter() - start, h_min=profile.h_min * length_scale,
        grading=grading, order=order, rounds=rounds, necks=[float(a) for a in necks], kappa=kappa,
        length_scale=length_scale, solution=high, profile=profile,
    )


METHODS = ("hp", "gmsh")


def semisphere_conductance(a_over_r: float, rtol: float = 1e-4, order: int | None = None,
                           method: str = "hp", neck: str = "cylinder") -> Result:
    r"""Conductance of the semisphere with a cylindrical neck, :math:`r = 1`, :math:`\kappa = 1` (Rojek 2022, Sec. 5,
    Fig. 12).

    ``neck = "cylinder"`` (default): the half-neck height is ``h_n/2`` of the volume-conserving neck (eqs. 19-20);
    ``neck = "union"``: the half body of the union of spheres, no neck cylinder, ``T = 1`` on the disk of radius ``a``
    at the cap base :math:`z_i = \sqrt{1 - a^2}`. ``K_over_Kcyl`` is :math:`K / \pi` (eqs. 38-39).

    Parameters
    ----------
    a_over_r : float
        Neck radius over sphere radius (dimensionless), in ``[1e-4, 1)``; from an overlap:
        ``fem_neck.geometry.equal_neck_radius`` (the inverse is ``overlap_for_neck``).
    rtol : float
        Relative tolerance of ``K`` (dimensionless).
    order : int, optional
        The first element order tried: 2 to 11 for ``"hp"``, 2, 3 or 4 for ``"gmsh"``; default from ``rtol``.
    method : str
        ``"hp"`` -- curved spectral elements on a geometric quadrilateral mesh with the exact sphere
        (:mod:`fem_neck.hpmesh`, :mod:`fem_neck.spectral`), the order raised on one mesh until two consecutive
        orders agree to ``rtol``; ``"gmsh"`` -- the triangle path shared with pairs and chains (graded gmsh mesh,
        P2-P4, regraded until orders ``p - 1`` and ``p`` agree), an independent discretisation for cross-checks.
    neck : str
        The half body (:data:`fem_neck.law.NECKS`): ``"cylinder"``, Rojek's volume-conserving neck, or ``"union"``,
        the union of spheres (no neck cylinder).

    Returns
    -------
    Result
        ``K`` for :math:`r = 1` and :math:`\kappa = 1` (times :math:`\kappa r` it is in W/K), with its error estimate.

    Raises
    ------
    ValueError
        ``a_over_r``, ``rtol``, ``order``, ``method`` or ``neck`` out of range (the message names it).
    """
    a_over_r = float(a_over_r)
    shapes.semisphere_profile(a_over_r, neck=neck)  # validates before any meshing
    if method == "gmsh":
        return _to_tolerance(lambda g: shapes.semisphere_mesh(a_over_r, grading=g, neck=neck), 1.0, 1.0, 1.0, rtol,
                             order, [a_over_r])
    if method != "hp":
        raise ValueError(f"method = {method!r}: must be one of {', '.join(METHODS)}")
    rtol = accuracy.check_rtol(rtol)
    order = accuracy.check_hp_order(order, rtol)
    start = time.perf_counter()
    levels = accuracy.hp_corner_levels(a_over_r, rtol, neck=neck)
    mesh, shape = hpmesh.semisphere_quad_mesh(a_over_r, levels, neck=neck)
    return _hp_to_tolerance(mesh, hpmesh.end_disks(mesh, shape), rtol, order, start, 1.0, 1.0, 1.0, [a_over_r])


def _hp_to_tolerance(mesh, fixed: dict, rtol: float, p: int, start: float, kappa: float, length_scale: float,
                     r_ref: float, necks: list) -> Result:
    """Raise the order on one hp mesh (lengths in units of ``length_scale``) until ``|K_p - K_(p-1)| / K_p <=
    rtol`` (:func:`fem_neck.accuracy.hp_start_order`; the corner levels were chosen by
    :func:`fem_neck.accuracy.hp_corner_levels`)."""
    low = spectral.conductance(mesh, p - 1, fixed)
    rounds = 1
    while True:
        high = spectral.conductance(mesh, p, fixed)
        estimate = accuracy.relative_difference(high.K_over_kappa, low.K_over_kappa)
        if estimate <= rtol or p == accuracy.HP_MAX_ORDER:
            break
        low, p, rounds = high, p + 1, rounds + 1
    K = high.K_over_kappa * kappa * length_scale
    edges = mesh.points[mesh.quads] - mesh.points[np.roll(mesh.quads, -1, axis=1)]
    return Result(
        K=K, K_over_Kcyl=K / (kappa * math.pi * r_ref), error_estimate=estimate, converged=estimate <= rtol,
        dofs=high.dofs, seconds=time.perf_counter() - start,
        h_min=float(np.min(np.hypot(edges[..., 0], edges[..., 1]))) * length_scale, grading=hpmesh.SIGMA, order=p,
        rounds=rounds, necks=[float(a) for a in necks], kappa=kappa, length_scale=length_scale, solution=high,
        profile=mesh,
    )


def chain_conductance(radii, overlaps, kappa: float, rtol: float = 1e-4, order: int | None = None) -> Result:
    """Conductance (W/K) between the outer equatorial planes of a collinear chain of sintered spheres.

    Each neck is the volume-conserving model's (Rojek 2022, eqs. 21-33); the graded gmsh path, orders ``p - 1`` and
    ``p`` compared.

    Parameters
    ----------
    radii : array_like
        The N sphere radii along the chain, m, each > 0 (neighbours at most 1e6 apart).
    overlaps : array_like
        The N - 1 overlaps :math:`h = r_k + r_{k+1} - d` of neighbouring spheres, m.
    kappa : float
        Thermal conductivity, W/(m K), > 0.
    rtol : float
        Relative tolerance of ``K`` (dimensionless).
    order : int, optional
        Element order 2, 3 or 4; default from ``rtol``.

    Returns
    -------
    Result
        ``K`` in W/K; ``K_over_Kcyl`` uses the smallest radius.

    Raises
    ------
    ValueError
        A radius, overlap (named by its bond), ``kappa``, ``rtol`` or ``order`` out of range.
    """
    kappa = float(check_positive("kappa", kappa))
    radii = np.atleast_1d(check_positive("radii", radii)).astype(float)
    overlaps = np.atleast_1d(np.asarray(overlaps, dtype=float))
    scale = float(np.max(radii))
    _, _, _, necks = shapes.chain_profile(radii, overlaps)  # validates before any meshing
    return _to_tolerance(lambda g: shapes.chain_mesh(radii / scale, overlaps / scale, grading=g), kappa, scale,
                         float(np.min(radii)), rtol, order, [n[0] for n in necks])


def pair_conductance(r_i: float, r_j: float, h: float, kappa: float, rtol: float = 1e-4,
                     order: int | None = None, method: str = "auto") -> Result:
    """Conductance (W/K) of two sintered spheres between their outer equatorial planes (Rojek 2022, Sec. 6).

    At the model's limit ``h = max_overlap`` (``a = r_min``, the smaller sphere's surface vanishes) both methods
    refuse.

    Parameters
    ----------
    r_i, r_j : float
        The two sphere radii, m, > 0 and at most 1e6 apart.
    h : float
        Overlap ``r_i + r_j - d`` of the spheres whose centres are ``d`` apart, m (the neck from the
        volume-conserving model, Rojek 2022, eqs. 21-33).
    kappa : float
        Thermal conductivity, W/(m K), > 0.
    rtol : float
        Relative tolerance of ``K`` (dimensionless).
    order : int, optional
        The first element order tried (hp: 2 to 11; gmsh: 2, 3 or 4); default from ``rtol``.
    method : str
        ``"hp"`` -- the two halves of :func:`fem_neck.hpmesh.pair_quad_mesh`, order raised until two orders agree
        (necks ``1e-4 <= a / r_min < 1``); ``"gmsh"`` -- the chain of two, :func:`chain_conductance` of the radii
        ``[r_i, r_j]`` and the overlap ``[h]``; ``"auto"`` -- hp (the gmsh path only to refuse too thin a neck).

    Returns
    -------
    Result
        ``K`` in W/K; ``K_over_Kcyl`` uses the smaller radius.

    Raises
    ------
    ValueError
        A radius, ``h``, ``kappa``, ``rtol``, ``order`` or ``method`` out of range (the message names it).
    """
    geo = neck_geometry(check_positive("r_i", r_i), check_positive("r_j", r_j), h)  # names the bad argument
    kappa = float(check_positive("kappa", kappa))
    if method not in ("auto", *METHODS):
        raise ValueError(f"method = {method!r}: must be one of auto, {', '.join(METHODS)}")
    shapes.check_radius_ratio([r_i, r_j], ("r_i", "r_j"))
    r_min = min(float(r_i), float(r_j))
    if method == "gmsh" or (method == "auto" and float(geo.a) < shapes.MIN_NECK_RATIO * r_min):
        return chain_conductance([r_i, r_j], [h], kappa, rtol=rtol, order=order)  # (refuses too thin a neck)
    rtol = accuracy.check_rtol(rtol)
    order = accuracy.check_hp_order(order, rtol)
    if not shapes.MIN_NECK_RATIO * r_min <= float(geo.a) < (1.0 - 1e-9) * r_min:
        raise ValueError(f"h = {h!r}: valid range for the FE: neck radius {shapes.MIN_NECK_RATIO:g} <= a / r_min < 1 "
                         f"(here a / r_min = {float(geo.a) / r_min:.9g}; at h = max_overlap the smaller sphere's "
                         "surface is gone)")
    start = time.perf_counter()
    levels = accuracy.hp_corner_levels(float(geo.a) / r_min, rtol)
    mesh, scale, bottom, top, a = hpmesh.pair_quad_mesh(float(r_i), float(r_j), float(h), levels)
    return _hp_to_tolerance(mesh, {0.0: bottom, 1.0: top}, rtol, order, start, kappa, scale, r_min, [a])
