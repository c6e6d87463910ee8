r"""Transient conduction in an insulated sintered pair: axisymmetric FE against the lumped-capacity pipe model.

The pair of spheres ``r_i``, ``r_j`` with the volume-conserving cylindrical neck (Rojek 2022, Sections 4.3) is a
body of revolution. In its meridian half-plane (``x`` radial >= 0, ``y`` axial, centre i at the origin, centre j at
``y = d``) the section is the union of two half-disks and the neck rectangle ``[0, a] x [z_i, z_i + h_n]``, built with
gmsh OCC booleans (as in :mod:`fem_neck.cluster`, the caps need no explicit cut). The neck is split by the line
``y = z_split`` where each particle's share of the cylinder equals its cap's volume, so that each particle owns exactly
:math:`\frac{4}{3} \pi r^3` -- the DEM's mass -- and the initial field (``T_i`` on particle i, ``T_j`` on j) is sharp.

The heat equation :math:`\rho c \, \partial T/\partial t = \nabla \cdot (\kappa \nabla T)`, insulated everywhere,
in axisymmetric weak form (every integrand weighted by the radial coordinate ``x``, design notes): mass
:math:`M = 2 \pi \rho c \int u v x`, stiffness :math:`A = 2 \pi \kappa \int \nabla u \cdot \nabla v \, x`. Time
stepping is implicit: backward Euler for the first steps (it damps the stiff modes of the discontinuous start;
Rannacher's start-up) then Crank-Nicolson, with the step doubling in blocks up to a cap (:func:`time_grid`), each
distinct step's matrix factorised once. Both conserve :math:`\mathbf{1}^T M T` exactly (:math:`A \mathbf{1} = 0`), i.e.
the energy :math:`\sum_i C_i \bar T_i`.

The lumped model (Rojek 2022, eqs. 2-4): :math:`C_i \, dT_i/dt = K (T_j - T_i)`, so the particle-temperature
difference decays as :math:`e^{-\lambda t}` with :math:`\lambda = K (1/C_i + 1/C_j)`,
:math:`C = \rho c \tfrac{4}{3} \pi r^3`. The FE difference of the particle *means* tends to
:math:`e^{-\lambda_1 t}` with :math:`\lambda_1` the smallest non-zero eigenvalue of :math:`(A, M)`
(:func:`first_decay_rate`); :math:`\lambda_1 (1/C_i + 1/C_j)^{-1}` is the conductance the lumped model would need.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from fem_neck.geometry import check_positive, neck_geometry

_EXTEND = 0.25  # the neck rectangle reaches this fraction of z into each disk (hidden inside it, see cluster.py)


@dataclass
class PairMesh:
    r"""Meridian-plane mesh of the closed pair (:func:`pair_mesh`).

    Parameters
    ----------
    mesh : skfem.MeshTri1
        Triangles of the meridian half-plane (``x`` radial, ``y`` axial), m.
    particle : numpy.ndarray
        Particle of every element, 0 (i) or 1 (j).
    z_split : float
        Axial position of the neck split from centre i, m (:func:`split_position`).
    volume_exact : float
        :math:`\frac{4}{3} \pi (r_i^3 + r_j^3)`, m^3.
    geometry : fem_neck.geometry.NeckGeometry
        The pair's neck geometry.
    """

    mesh: object
    particle: np.ndarray
    z_split: float
    volume_exact: float
    geometry: object = field(repr=False)


def split_position(geo, r_i) -> float:
    r"""Axial position (from centre i) where the neck is split: :math:`z_i + V_{cap,i} / (\pi a^2)`.

    Parameters
    ----------
    geo : fem_neck.geometry.NeckGeometry
        The pair's neck geometry (m).
    r_i : float
        Radius of particle i, m.
    """
    cap_i = np.pi * geo.h_ci**2 * (3.0 * r_i - geo.h_ci) / 3.0
    return float(geo.z_i + cap_i / (np.pi * geo.a**2))


def pair_mesh(r_i: float, r_j: float, h: float, grading: float = 0.3, size_max: float = 0.08,
              size_min: float = 0.05) -> PairMesh:
    """Graded triangular mesh of the closed pair's meridian section (both spheres whole, insulated everywhere).

    The size grows linearly with the distance ``s`` to the two neck corners, ``min(size_max r_min, size_min m +
    grading s)`` with ``m = min(a, h_n)``; single-threaded gmsh (deterministic).

    Parameters
    ----------
    r_i, r_j : float
        The two particle radii, m, finite and > 0.
    h : float
        Overlap of the two spheres, m, > 0 (the input of :func:`fem_neck.geometry.neck_geometry`).
    grading : float
        Growth of the element size per distance from the neck corners (dimensionless).
    size_max : float
        Largest element size, relative to the smaller radius (dimensionless).
    size_min : float
        Element size at the corners, relative to ``min(a, h_n)`` (dimensionless).
    """
    from skfem import MeshTri1

    from fem_neck.shapes import gmsh_session

    r_i = float(check_positive("r_i", r_i))
    r_j = float(check_positive("r_j", r_j))
    unit = max(r_i, r_j)
    geo = neck_geometry(r_i / unit, r_j / unit, h / unit)
    a, z_i, h_n, d = (float(v) for v in (geo.a, geo.z_i, geo.h_n, geo.d))
    ri, rj = r_i / unit, r_j / unit
    z_split = split_position(geo, ri)
    corners = ((a, z_i), (a, z_i + h_n))
    m = min(a, h_n)
    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        disk_i = occ.addDisk(0.0, 0.0, 0.0, ri, ri)
        disk_j = occ.addDisk(0.0, d, 0.0, rj, rj)
        lo, hi = z_i - _EXTEND * z_i, z_i + h_n + _EXTEND * float(geo.z_j)
        neck = occ.addRectangle(-a, lo, 0.0, 2 * a, hi - lo)
        union, _ = occ.fuse([(2, disk_i)], [(2, disk_j), (2, neck)])
        half = occ.addRectangle(0.0, -2 * ri, 0.0, 2 * max(ri, rj), d + 2 * (ri + rj))
        section, _ = occ.intersect(union, [(2, half)])
        cut = occ.addLine(occ.addPoint(0.0, z_split, 0.0), occ.addPoint(a, z_split, 0.0))
        pieces, _ = occ.fragment(section, [(1, cut)])
        occ.synchronize()
        size = gmsh.model.mesh.field.add("MathEval")
        dist = [f"sqrt((x-{x!r})^2+(y-{y!r})^2)" for x, y in corners]
        gmsh.model.mesh.field.setString(
            size, "F", f"min({size_max * min(ri, rj)!r}, {size_min * m!r} + {grading!r}*min({dist[0]}, {dist[1]}))")
        gmsh.model.mesh.field.setAsBackgroundMesh(size)
        for opt, val in (("Mesh.MeshSizeExtendFromBoundary", 0), ("Mesh.MeshSizeFromPoints", 0),
                         ("Mesh.MeshSizeFromCurvature", 0), ("Mesh.Algorithm", 6)):
            gmsh.option.setNumber(opt, val)
        gmsh.model.mesh.generate(2)
        node_tags, coords, _ = gmsh.model.mesh.getNodes()
        tris = []
        for dim, tag in gmsh.model.getEntities(2):
            _, nodes = gmsh.model.mesh.getElementsByType(2, tag)
            tris.append(nodes)
    xy = np.asarray(coords).reshape(-1, 3)[:, :2]
    index = np.full(int(node_tags.max()) + 1, -1, dtype=np.int64)
    index[node_tags.astype(np.int64)] = np.arange(len(node_tags))
    tri = index[np.concatenate(tris).astype(np.int64)].reshape(-1, 3)
    used, tri = np.unique(tri, return_inverse=True)
    tri = tri.reshape(-1, 3)
    p = xy[used]
    e1, e2 = p[tri[:, 1]] - p[tri[:, 0]], p[tri[:, 2]] - p[tri[:, 0]]
    flip = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0] < 0
    tri[flip] = tri[flip][:, [0, 2, 1]]
    particle = (p[tri].mean(axis=1)[:, 1] > z_split).astype(np.int64)
    mesh = MeshTri1((p * unit).T.copy(), tri.T.copy())
    return PairMesh(mesh=mesh, particle=particle, z_split=z_split * unit,
                    volume_exact=4.0 / 3.0 * np.pi * (r_i**3 + r_j**3), geometry=neck_geometry(r_i, r_j, h))


def _forms(basis, kappa, rho_c):
    from skfem import BilinearForm
    from skfem.helpers import dot, grad

    @BilinearForm
    def stiffness(u, v, w):
        return 2.0 * np.pi * kappa * dot(grad(u), grad(v)) * w.x[0]

    @BilinearForm
    def mass(u, v, w):
        return 2.0 * np.pi * rho_c * u * v * w.x[0]

    return stiffness.assemble(basis).tocsc(), mass.assemble(basis).tocsc()


@dataclass
class TransientResult:
    r"""The integration of :func:`solve_transient`.

    Parameters
    ----------
    t : numpy.ndarray
        Times, s, from 0 (len(steps) + 1).
    T_mean : numpy.ndarray
        Particle-mean temperatures (len(t), 2), K.
    C : numpy.ndarray
        FE heat capacities of the two particles (2,), J/K: :math:`\rho c` times each particle's mesh volume.
    energy : numpy.ndarray
        Total heat content :math:`\mathbf{1}^T M T` at each time, J (up to a constant; conserved).
    dofs : int
        Unknowns of the FE space.
    """

    t: np.ndarray
    T_mean: np.ndarray
    C: np.ndarray
    energy: np.ndarray
    dofs: int


def time_grid(t_end: float, dt0: float, dt_max: float, steps_per_block: int = 8) -> np.ndarray:
    """Time steps to ``t_end``: ``steps_per_block`` steps of ``dt0``, then of ``2 dt0``, ``4 dt0``, ... until the
    step reaches ``dt_max``, then steps of ``dt_max`` (the last one shortened to land on ``t_end``).

    Parameters
    ----------
    t_end : float
        End time, s, > 0.
    dt0 : float
        First time step, s, > 0.
    dt_max : float
        Largest time step, s, > 0.
    steps_per_block : int
        Steps taken at each step size before it doubles.
    """
    t_end = float(check_positive("t_end", t_end))
    dt0 = float(check_positive("dt0", dt0))
    dt_max = float(check_positive("dt_max", dt_max))
    steps, t, dt = [], 0.0, dt0
    while t < t_end * (1 - 1e-12):
        for _ in range(steps_per_block):
            step = min(dt, t_end - t)
            steps.append(step)
            t += step
            if t >= t_end * (1 - 1e-12):
                break
        dt = min(2.0 * dt, dt_max)
    return np.array(steps)


def solve_transient(pm: PairMesh, kappa: float, rho: float, c: float, T_i: float, T_j: float, steps: np.ndarray,
                    order: int = 2, startup: int = 4) -> TransientResult:
    """Integrate the insulated pair from ``T_i``/``T_j`` over the time ``steps`` (array of dt): ``startup`` backward
    Euler steps, then Crank-Nicolson; each distinct dt is factorised once (scipy splu).

    Parameters
    ----------
    pm : PairMesh
        The meshed pair.
    kappa : float
        Thermal conductivity, W/(m K), > 0.
    rho : float
        Density, kg/m^3, > 0.
    c : float
        Specific heat capacity, J/(kg K), > 0.
    T_i, T_j : float
        Initial temperatures of particles i and j, K.
    steps : numpy.ndarray
        The time steps, s, each > 0 (:func:`time_grid`).
    order : int
        Element order, 1 or 2.
    startup : int
        Backward Euler steps before Crank-Nicolson.
    """
    import scipy.sparse.linalg as spl
    from skfem import Basis, ElementTriP1, ElementTriP2, Functional

    check_positive("kappa", kappa)
    check_positive("rho", rho)
    check_positive("c", c)
    steps = check_positive("steps", np.atleast_1d(steps))
    elem = {1: ElementTriP1(), 2: ElementTriP2()}.get(order)
    if elem is None:
        raise ValueError(f"order = {order}: must be 1 or 2")
    basis = Basis(pm.mesh, elem)
    A, M = _forms(basis, kappa, rho * c)
    # initial field: each dof takes the temperature of the particle on whose side it lies (the split line: mean)
    y = basis.doflocs[1]
    u = np.where(y < pm.z_split, T_i, T_j).astype(float)
    on_split = np.abs(y - pm.z_split) < 1e-12 * max(float(pm.geometry.r_i), float(pm.geometry.r_j))
    u[on_split] = 0.5 * (T_i + T_j)
    weight = Functional(lambda w: 2.0 * np.pi * w.x[0] * (w["u"] if "u" in w else 1.0))
    vol = np.bincount(pm.particle, weights=weight.elemental(basis), minlength=2)

    def means(v):
        return np.bincount(pm.particle, weights=weight.elemental(basis, u=basis.interpolate(v)), minlength=2) / vol

    ones = np.ones(basis.N)
    t, T_mean, energy = [0.0], [means(u)], [ones @ (M @ u)]
    factors = {}
    for n, dt in enumerate(steps):
        theta = 1.0 if n < startup else 0.5
        key = (float(dt), theta)
        if key not in factors:
            factors[key] = spl.splu((M + theta * dt * A).tocsc())
        u = factors[key].solve(M @ u - (1.0 - theta) * dt * (A @ u))
        t.append(t[-1] + dt)
        T_mean.append(means(u))
        energy.append(ones @ (M @ u))
    return TransientResult(t=np.array(t), T_mean=np.array(T_mean), C=rho * c * vol, energy=np.array(energy),
                           dofs=basis.N)


def first_decay_rate(pm: PairMesh, kappa: float, rho: float, c: float, order: int = 2) -> float:
    r"""Smallest non-zero eigenvalue :math:`\lambda_1` of :math:`A x = \lambda M x` (1/s): the late-time decay rate of
    the insulated pair's temperature difference.

    Parameters
    ----------
    pm : PairMesh
        The meshed pair.
    kappa : float
        Thermal conductivity, W/(m K).
    rho : float
        Density, kg/m^3.
    c : float
        Specific heat capacity, J/(kg K).
    order : int
        Element order, 1 or 2.
    """
    import scipy.sparse.linalg as spl
    from skfem import Basis, ElementTriP1, ElementTriP2

    basis = Basis(pm.mesh, ElementTriP2() if order == 2 else ElementTriP1())
    A, M = _forms(basis, kappa, rho * c)
    # shift below zero so that the singular A (constant mode) is harmless; the two smallest are 0 and lambda_1
    lam0 = kappa / (rho * c) / float(pm.geometry.r_j) ** 2
    vals = spl.eigsh(A, k=2, M=M, sigma=-lam0, which="LM", return_eigenvectors=False)
    return float(np.max(vals))


def lumped_pair(t, T_i: float, T_j: float, C_i: float, C_j: float, K: float) -> np.ndarray:
    r"""Closed form of the lumped pair (Rojek 2022, eqs. 2-4): temperatures (len(t), 2).

    Parameters
    ----------
    t : array_like
        Times, s.
    T_i, T_j : float
        Initial temperatures of particles i and j, K.
    C_i, C_j : float
        Heat capacities of the particles, J/K (:math:`\rho c \frac{4}{3} \pi r^3`).
    K : float
        Conductance of the pipe between them, W/K.
    """
    t = np.asarray(t, dtype=float)
    T_eq = (C_i * T_i + C_j * T_j) / (C_i + C_j)
    decay = np.exp(-K * (1.0 / C_i + 1.0 / C_j) * t)
    return np.column_stack([T_eq + (T_i - T_eq) * decay, T_eq + (T_j - T_eq) * decay])
