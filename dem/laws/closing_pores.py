r"""Closing pores: the cap of a particle's conductance where the pores around it are closing and thin.

Under ``neck = "union"`` the ``shared-body`` law caps the mean of each particle's conductivity tensor at
:math:`\kappa V_k` (:mod:`dem.laws.shared_body`): the Wiener bound, the energy of a uniform field in the solid. Near
full density the FE of the union lies well below it: the field bends around the pores, and a pore removes more
conductance than its volume. Dilute insulating pores of volume fraction :math:`\varepsilon` lower the conductivity to
:math:`k / \kappa = 1 - c \, \varepsilon` with a slope ``c`` set by their shape: 3/2 for spheres (Maxwell's dilute
limit, the Hashin-Shtrikman bound's slope), more the flatter they are (thin wedges and cracks block a field across
them with little volume). The union's lattices measure slopes of 1.6 to 2.5, and the pores there are wedges along
the faces where spheres meet; a network on particle nodes does not see them, and its cap has slope 1.

**A particle's pores.** Seen from its centre, particle ``k`` is bounded by the radical (power) planes of its
neighbours :math:`j`, :math:`n_j \cdot (x - x_k) \le l_j` with
:math:`l_j = (d_j^2 + r_k^2 - r_j^2) / (2 d_j)` (Aurenhammer 1987, the power diagram), of the ones that touch it and
of the ones that do not touch yet alike, and by the walls near it; it is followed only within the ball of radius
:math:`R_c = (1 + \gamma) r` around its centre. In the direction :math:`\hat n` the cell reaches
:math:`t(\hat n) = \min(R_c, \min_{j:\, n_j \cdot \hat n > 0} l_j / (n_j \cdot \hat n))` and the solid
:math:`\min(r, t)`, so that

.. math::

    V_{solid} = \oint \frac{\min(r, t)^3}{3} \, d\Omega, \qquad
    V_{pore} = \oint_{t > r} \frac{t^3 - r^3}{3} \, d\Omega, \qquad
    S = r^2 \oint_{t > r} d\Omega,

with ``S`` the free spherical surface that bounds the pores; the integrals are sums over ``DIRECTIONS`` directions
spread evenly over the sphere (a Fibonacci lattice). The pores' porosity is
:math:`\varepsilon = V_{pore} / (V_{pore} + V_{solid})` and their shape the scale-free
:math:`\psi = S / V_{pore}^{2/3}` (large for thin pores: the same surface over less volume).

Every quantity moves continuously with the packing: a neighbour's plane comes in from beyond :math:`R_c` and moves
to the sphere as the neighbour approaches (it is the plane of their neck once they touch), so a neck that forms
changes no plane at once, and nothing switches a cell between open and closed. A neighbour whose plane lies beyond
:math:`R_c` changes nothing, so the neighbours searched within a finite distance are all there are
(:func:`power_planes`: every pair closer than :math:`2 (1 + \gamma) r_{max}`). :data:`GAMMA` = 0.5 puts the ball
beyond the vertices of the power cells of the dense lattices, where the cap binds (simple cubic :math:`0.866 d`,
body-centred :math:`0.645 d`, face-centred :math:`0.707 d` from the centre, ``d`` the nearest neighbours' distance:
the whole cell for :math:`d \le` 1.73 r, 2.33 r and 2.12 r, so on the simple cubic lattice from :math:`h/r` = 0.27
and on the others at every overlap); a particle of a loose packing, or at a free surface, sees the large round pore
of its ball (:math:`\psi` = 2.72 for a lone sphere).

**The cap.** The slope grows with the thinness of the pores, and the particle's mean conductivity is capped at the
dilute-pore value over its own solid fraction:

.. math::

    c = 1 + \beta \max\left(0, \ln \frac{\psi}{\psi_0}\right), \qquad
    \rho = \frac{1 - c \, \varepsilon}{1 - \varepsilon}, \qquad
    \frac{1}{3} \operatorname{tr} \sum_b s_b K_b l_b^2 n_b n_b^T \le \rho \, \kappa V_k .

``rho`` is at most 1 (``c >= 1``): the cap is never looser than the Wiener bound, so the law stays below it. Pores
rounder than :math:`\psi_0` keep :math:`\rho = 1`, today's cap. Where the cap does not bind (the particle's tensor
below it: necks narrow or far apart) the law is the ``shared-body`` law bit for bit.

**The cap stays positive.** In every free direction the solid is the whole cone :math:`r^3 / 3` and the pore at
most :math:`(R_c^3 - r^3) / 3`, so with :math:`x = V_{pore} / (S r) \le x_{max} = ((1 + \gamma)^3 - 1) / 3`:
:math:`\varepsilon \le 3 x / (3 x + 1)` and, since :math:`S \le 4 \pi r^2`,
:math:`\psi \le A x^{-2/3}` with :math:`A = (4 \pi)^{1/3}`. Then :math:`c \, \varepsilon < 1` whenever
:math:`3 \beta \, x \ln^+(A x^{-2/3} / \psi_0) < 1`, whose left side is largest at
:math:`x^* = \min(x_{max}, (A / \psi_0)^{3/2} / e)`: :math:`\rho > 0` for every cell exactly when
:math:`\beta < \beta_{max}(\psi_0) = 1 / (3 x^* \ln(A x^{*-2/3} / \psi_0))` (a particle in a spherical shell of
pore comes as close to the bound as one likes), and :func:`cap_ratio` refuses a calibration beyond it
(:func:`largest_beta`).

:math:`\beta` and :math:`\psi_0` are not derived: they are calibrated on periodic-cell FE of union cells that are not
the cases ``python -m verification densification`` checks (other overlaps of the three lattices, other random
packings), by ``python -m verification closing-pores``, which writes :data:`CALIBRATION` (the cells, their FE and the
errors with the calibrated cap).
"""

from __future__ import annotations

import functools
import json
import math
import pathlib

import numba
import numpy as np

from dem.geometry.exposure import fibonacci_directions
from fem_neck.geometry.cut_kernels import ends_by_particle

CALIBRATION = pathlib.Path(__file__).with_name("closing_pores.json")  #: written by python -m verification closing-pores
DIRECTIONS = 2000  #: directions of the quadrature over the sphere
GAMMA = 0.5  #: the cell is followed within (1 + GAMMA) r of the centre (module docstring)


@functools.lru_cache(maxsize=1)
def calibration(path: str | None = None) -> dict:
    """The calibrated ``beta`` and ``psi0`` (module docstring) of a closing_pores.json (default: :data:`CALIBRATION`).

    Parameters
    ----------
    path : str or None
        A file written by ``python -m verification closing-pores``; None: the one shipped.

    Returns
    -------
    dict
        Its content: ``beta`` and ``psi0`` (dimensionless), and the calibration's record.
    """
    return json.loads(pathlib.Path(path or CALIBRATION).read_text())


def power_planes(position: np.ndarray, radius: np.ndarray, box=None, walls=()):
    """The planes that bound each particle's cell within :math:`(1 + \\gamma) r` of its centre (module docstring):
    the radical planes of every neighbour (touching or not, images across a periodic box's faces included) and the
    walls that lie that close.

    Parameters
    ----------
    position : numpy.ndarray
        Particle centres (n, 3), m.
    radius : numpy.ndarray
        Particle radii (n,), m, > 0.
    box : dem.geometry.periodic.PeriodicBox or None
        The periodic box of the packing; None without one.
    walls : sequence of dem.geometry.walls.Wall
        Plane walls (their normals point into the packing).

    Returns
    -------
    tuple of numpy.ndarray
        ``particle`` (int, the particle each plane bounds), ``normals`` (unit vectors from its centre toward the
        plane) and ``planes`` (the distance from its centre to the plane, m; negative where the centre lies beyond
        it, inside a larger sphere), one row per plane.
    """
    from dem.geometry.bonds import candidate_pairs, periodic_pairs

    position, radius = np.asarray(position, dtype=float).reshape(-1, 3), np.asarray(radius, dtype=float)
    reach = (1.0 + GAMMA) * radius
    # l_k < R_k <=> d < R_k + sqrt(GAMMA (2 + GAMMA) r_k^2 + r_j^2), at most 2 (1 + GAMMA) r_max: every pair closer
    # than that (the search of the bonds with every radius (1 + GAMMA) r_max), then each end's plane kept or not
    search = np.full(len(radius), (1.0 + GAMMA) * float(radius.max(initial=0.0)))
    if box is not None and box.any_periodic:
        i, j, shift = periodic_pairs(position, search, box)
        vectors = box.bond_vectors(position, i, j, shift)
    else:
        i, j = candidate_pairs(position, search)
        vectors = position[j] - position[i]
    d = np.linalg.norm(vectors, axis=1)
    i, j, vectors, d = i[d > 0.0], j[d > 0.0], vectors[d > 0.0], d[d > 0.0]  # coincident centres share no plane
    l_i = (d * d + radius[i] ** 2 - radius[j] ** 2) / (2.0 * d)
    l_j = d - l_i
    unit = vectors / d[:, None]
    near_i, near_j = l_i < reach[i], l_j < reach[j]
    particle, normals, planes = [i[near_i], j[near_j]], [unit[near_i], -unit[near_j]], [l_i[near_i], l_j[near_j]]
    for wall in walls:
        distance = wall.distance(position)
        near = np.flatnonzero(distance < reach)
        particle.append(near)
        normals.append(np.tile(-np.asarray(wall.normal, dtype=float), (len(near), 1)))
        planes.append(distance[near])
    return (np.concatenate(particle).astype(np.int64), np.concatenate(normals).reshape(-1, 3),
            np.concatenate(planes).astype(float))


@numba.njit(cache=True, parallel=True)
def _cell_kernel(n, radius, ball, particle, normals, planes, dirs):
    offsets, order = ends_by_particle(n, particle)
    weight = 4.0 * np.pi / len(dirs)
    solid = np.empty(n)
    pore = np.empty(n)
    free = np.empty(n)
    for k in numba.prange(n):
        r = radius[k]
        lo, hi = offsets[k], offsets[k + 1]
        v_solid = v_pore = area = 0.0
        for d in range(len(dirs)):
            reach = ball * r
            for b in range(lo, hi):
                e = order[b]
                c = normals[e, 0] * dirs[d, 0] + normals[e, 1] * dirs[d, 1] + normals[e, 2] * dirs[d, 2]
                if c > 0.0:
                    reach = min(reach, planes[e] / c)
            reach = max(reach, 0.0)  # a plane behind the centre (inside a larger sphere): no solid that way
            if reach > r:
                v_solid += r * r * r
                v_pore += reach ** 3 - r * r * r
                area += 1.0
            else:
                v_solid += reach ** 3
        solid[k] = v_solid * weight / 3.0
        pore[k] = v_pore * weight / 3.0
        free[k] = area * weight * r * r
    return solid, pore, free


def particle_cells(radius: np.ndarray, particle: np.ndarray, normals: np.ndarray, planes: np.ndarray,
                   count: int = DIRECTIONS):
    """Per particle, the solid, the pore volume and the free surface of its cell within :math:`(1 + \\gamma) r` of its
    centre, bounded by ``planes`` (module docstring; the planes of :func:`power_planes`).

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    particle : numpy.ndarray
        The particle each plane bounds (int).
    normals : numpy.ndarray
        The unit direction from the particle's centre toward every plane (one row each).
    planes : numpy.ndarray
        The distance from the particle's centre to every plane (a radical plane, or a wall), m.
    count : int
        Directions of the quadrature (:func:`dem.geometry.exposure.fibonacci_directions`).

    Returns
    -------
    tuple of numpy.ndarray
        The solid volume (m^3), the pore volume (m^3) and the free spherical surface (m^2).
    """
    f = np.ascontiguousarray
    radius = f(radius, dtype=float)
    return _cell_kernel(len(radius), radius, 1.0 + GAMMA, f(particle, dtype=np.int64),
                        f(np.reshape(normals, (-1, 3)), dtype=float), f(planes, dtype=float),
                        fibonacci_directions(count))


def largest_beta(psi0: float, gamma: float = GAMMA) -> float:
    r""":math:`\beta_{max}(\psi_0)`: every cell's cap stays positive exactly for :math:`\beta` below it (module
    docstring).

    Parameters
    ----------
    psi0 : float
        The shape :math:`S / V_{pore}^{2/3}` (dimensionless, > 0) up to which pores keep the Wiener cap.
    gamma : float
        The cell's ball, :math:`R_c = (1 + \gamma) r` (dimensionless, > 0).

    Returns
    -------
    float
        :math:`\beta_{max}` (dimensionless, > 0).
    """
    a = (4.0 * math.pi) ** (1.0 / 3.0) / psi0
    x = min(((1.0 + gamma) ** 3 - 1.0) / 3.0, a ** 1.5 / math.e)
    return 1.0 / (3.0 * x * math.log(a * x ** (-2.0 / 3.0)))  # the logarithm is >= 2/3 at x <= a^1.5 / e


def cap_ratio(solid: np.ndarray, pore: np.ndarray, free: np.ndarray, beta: float, psi0: float) -> np.ndarray:
    r"""The cap :math:`\rho` of every particle over its Wiener bound (module docstring).

    Parameters
    ----------
    solid, pore, free : numpy.ndarray
        Per particle, its solid and pore volumes (m^3) and its free surface (m^2) (:func:`particle_cells`).
    beta : float
        How fast the pores' slope grows with their thinness (dimensionless, in
        :math:`[0, \beta_{max}(\psi_0))`, :func:`largest_beta`).
    psi0 : float
        The shape :math:`S / V_{pore}^{2/3}` (dimensionless, > 0) up to which pores keep the Wiener cap.

    Returns
    -------
    numpy.ndarray
        :math:`\rho` per particle, in (0, 1] (dimensionless).

    Raises
    ------
    ValueError
        ``psi0`` or ``beta`` out of its range.
    """
    if not (np.isfinite(psi0) and psi0 > 0.0):
        raise ValueError(f"closing pores: psi0 = {psi0!r}: must be finite and > 0")
    top = largest_beta(psi0)
    if not (np.isfinite(beta) and 0.0 <= beta < top):
        raise ValueError(f"closing pores: beta = {beta!r}: must be in [0, {top:.6g}) with psi0 = {psi0!r} (beyond it "
                         f"a cell's cap can reach 0)")
    porous = pore > 0.0
    rho = np.ones(len(solid))
    v, s, p = pore[porous], free[porous], solid[porous]
    slope = 1.0 + beta * np.maximum(0.0, np.log(s / v ** (2.0 / 3.0) / psi0))
    eps = v / (v + p)
    rho[porous] = (1.0 - slope * eps) / (1.0 - eps)
    return rho
