r"""Closing pores: the cap of a particle's conductance where the pores around it are closing and thin.

Under ``neck = "union"`` the ``shared-body`` law caps the mean of each particle's conductivity tensor at
:math:`\kappa V_k` (:mod:`dem.laws.shared_body`): the Wiener bound, the energy of a uniform field in the solid. Near
full density the FE of the union lies well below it: the field bends around the pores, and a pore removes more
conductance than its volume. Dilute insulating pores of volume fraction :math:`\varepsilon` lower the conductivity to
:math:`k / \kappa = 1 - c \, \varepsilon` with a slope ``c`` set by their shape: 3/2 for spheres (Maxwell's dilute
limit, the Hashin-Shtrikman bound's slope), more the flatter they are (thin wedges and cracks block a field across
them with little volume). The union's lattices measure slopes of 1.6 to 2.5, and the pores there are wedges along
the faces where spheres meet; a network on particle nodes does not see them, and its cap has slope 1.

**A particle's pores.** Seen from its centre, particle ``k`` is bounded by the planes of its necks
(:math:`n_b \cdot (x - x_k) \le l_b`: the radical planes and the walls it touches). Where every direction from the
centre meets one of them, they enclose the particle's *cell* (its power cell, as far as its own necks bound it), and
what of the cell lies outside its sphere is the pore space next to it. In the direction :math:`\hat n` the cell
reaches :math:`t(\hat n) = \min_{b:\, n_b \cdot \hat n > 0} l_b / (n_b \cdot \hat n)` and the solid
:math:`\min(r, t)`, so that

.. math::

    V_{solid} = \oint \frac{\min(r, t)^3}{3} \, d\Omega, \qquad
    V_{pore} = \oint_{t > r} \frac{t^3 - r^3}{3} \, d\Omega, \qquad
    S = r^2 \oint_{t > r} d\Omega,

with ``S`` the free spherical surface that bounds the pores; the integrals are sums over ``DIRECTIONS`` directions
spread evenly over the sphere (a Fibonacci lattice). The pores' porosity is
:math:`\varepsilon = V_{pore} / (V_{pore} + V_{solid})` and their shape the scale-free
:math:`\psi = S / V_{pore}^{2/3}` (large for thin pores: the same surface over less volume). A cell left open in some
direction (no plane ahead: a particle at a free surface or in a loose packing) has no closing pores and keeps the
Wiener cap.

**The cap.** The slope grows with the thinness of the pores, and the particle's mean conductivity is capped at the
dilute-pore value over its own solid fraction:

.. math::

    c = 1 + \beta \max\left(0, \ln \frac{\psi}{\psi_0}\right), \qquad
    \rho = \frac{1 - c \, \varepsilon}{1 - \varepsilon}, \qquad
    \frac{1}{3} \operatorname{tr} \sum_b s_b K_b l_b^2 n_b n_b^T \le \rho \, \kappa V_k .

``rho`` is at most 1 (``c >= 1``): the cap is never looser than the Wiener bound, so the law stays below it. Pores
rounder than :math:`\psi_0` keep :math:`\rho = 1`, today's cap; so does an open cell, and as a cell closes its pore
volume comes in from infinity (:math:`\psi \to 0`), so the cap does not jump. Where the cap does not bind (the
particle's tensor below it: necks narrow or far apart) the law is the ``shared-body`` law bit for bit. ``rho`` stays
positive: the free surface is at most :math:`4 \pi r^2`, so a large porosity forces a small :math:`\psi`.

The cell is bounded by the particle's necks only: a neighbour that does not yet touch bounds no pore. When a new neck
forms at a particle whose cap binds, its plane cuts the cell at once (at the sphere, where the power cell had its face
farther out), and the cap moves with it: the body-centred cubic lattice, whose second neighbours touch at
:math:`h/r` = 0.268, has its octahedral cell of eight planes cut to the truncated octahedron of fourteen there, and
its ``k_eff`` rises from 0.8086 to 0.8318 :math:`\kappa` between :math:`h/r` 0.266 and 0.268 (the Wiener cap's from
0.8247 to 0.8318). Necks that begin to meet change no plane, and there the cap is continuous.

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

CALIBRATION = pathlib.Path(__file__).with_name("closing_pores.json")  # written by python -m verification closing-pores
DIRECTIONS = 2000  # directions of the quadrature over the sphere


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


def directions(count: int = DIRECTIONS) -> np.ndarray:
    """``count`` unit vectors spread evenly over the sphere (a Fibonacci lattice), each standing for the solid angle
    :math:`4 \\pi / count`.

    Parameters
    ----------
    count : int
        How many.

    Returns
    -------
    numpy.ndarray
        (count, 3) unit vectors.
    """
    k = np.arange(count) + 0.5
    z = 1.0 - 2.0 * k / count
    azimuth = math.pi * (1.0 + math.sqrt(5.0)) * k
    s = np.sqrt(1.0 - z * z)
    return np.column_stack([s * np.cos(azimuth), s * np.sin(azimuth), z])


@numba.njit(cache=True, parallel=True)
def _cell_kernel(n, radius, particle, normals, planes, dirs):
    m = len(particle)
    counts = np.zeros(n + 1, dtype=np.int64)
    for e in range(m):
        counts[particle[e] + 1] += 1
    offsets = np.cumsum(counts)
    fill = offsets[:-1].copy()
    order = np.empty(m, dtype=np.int64)
    for e in range(m):
        order[fill[particle[e]]] = e
        fill[particle[e]] += 1
    weight = 4.0 * np.pi / len(dirs)
    solid = np.empty(n)
    pore = np.empty(n)
    free = np.empty(n)
    for k in numba.prange(n):
        r = radius[k]
        lo, hi = offsets[k], offsets[k + 1]
        v_solid = v_pore = area = 0.0
        for d in range(len(dirs)):
            reach = np.inf
            for b in range(lo, hi):
                e = order[b]
                c = normals[e, 0] * dirs[d, 0] + normals[e, 1] * dirs[d, 1] + normals[e, 2] * dirs[d, 2]
                if c > 0.0:
                    reach = min(reach, planes[e] / c)
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
    """Per particle, the solid, the pore volume and the free surface of the cell its necks' planes enclose (module
    docstring); the pore volume is ``inf`` where the cell is open.

    Parameters
    ----------
    radius : numpy.ndarray
        Particle radii, m.
    particle : numpy.ndarray
        The particle of every neck end (int).
    normals : numpy.ndarray
        The unit direction from the particle's centre toward every neck (one row each).
    planes : numpy.ndarray
        The distance from the particle's centre to every neck's plane (the radical plane, or the wall), m, > 0.
    count : int
        Directions of the quadrature (:func:`directions`).

    Returns
    -------
    tuple of numpy.ndarray
        The solid volume (m^3), the pore volume (m^3; ``inf`` for an open cell) and the free spherical surface (m^2).
    """
    f = np.ascontiguousarray
    radius = f(radius, dtype=float)
    return _cell_kernel(len(radius), radius, f(particle, dtype=np.int64), f(np.reshape(normals, (-1, 3)), dtype=float),
                        f(planes, dtype=float), directions(count))


def cap_ratio(solid: np.ndarray, pore: np.ndarray, free: np.ndarray, beta: float, psi0: float) -> np.ndarray:
    r"""The cap :math:`\rho` of every particle over its Wiener bound (module docstring).

    Parameters
    ----------
    solid, pore, free : numpy.ndarray
        Per particle, its solid and pore volumes (m^3; the pore ``inf`` for an open cell) and its free surface (m^2)
        (:func:`particle_cells`).
    beta : float
        How fast the pores' slope grows with their thinness (dimensionless, >= 0).
    psi0 : float
        The shape :math:`S / V_{pore}^{2/3}` (dimensionless, > 0) up to which pores keep the Wiener cap.

    Returns
    -------
    numpy.ndarray
        :math:`\rho` per particle, in (0, 1] (dimensionless).

    Raises
    ------
    ValueError
        ``beta`` or ``psi0`` out of its range.
    """
    if not (np.isfinite(beta) and beta >= 0.0):
        raise ValueError(f"closing pores: beta = {beta!r}: must be finite and >= 0")
    if not (np.isfinite(psi0) and psi0 > 0.0):
        raise ValueError(f"closing pores: psi0 = {psi0!r}: must be finite and > 0")
    closed = np.isfinite(pore) & (pore > 0.0)
    rho = np.ones(len(solid))
    v, s, p = pore[closed], free[closed], solid[closed]
    slope = 1.0 + beta * np.maximum(0.0, np.log(s / v ** (2.0 / 3.0) / psi0))
    eps = v / (v + p)
    rho[closed] = (1.0 - slope * eps) / (1.0 - eps)
    return rho
