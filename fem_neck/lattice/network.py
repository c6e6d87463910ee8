"""The pipe network's lattice sum on a periodic cell's bonds, beside the FE of :mod:`fem_neck.lattice`."""

from __future__ import annotations

import numpy as np

from fem_neck.geometry import neck_geometry
from fem_neck.lattice.cells import PeriodicCell


def network_conductivity(cell: PeriodicCell, pair_conductance) -> float:
    r""":math:`k_{zz} / \kappa` of the pipe network on the cell's bonds when every particle's temperature follows the
    uniform gradient (exact for lattices, whose bond stars are centrosymmetric): :math:`\sum_b K_b \, dz_b^2 / |P|`
    over the period's volume :math:`|P|`. ``pair_conductance(r_i, r_j, a)`` gives the bond conductances for
    :math:`\kappa = 1`.

    Parameters
    ----------
    cell : PeriodicCell
        The cell (pair reading).
    pair_conductance : callable
        ``(r_i, r_j, a) -> K`` in W/K for ``kappa`` = 1 W/(m K), vectorised (e.g. a partial of
        :func:`fem_neck.law.pair_conductance`).
    """
    i, j, s = cell.bonds()
    e = cell.centres[j] + s * cell.period - cell.centres[i]
    d = np.linalg.norm(e, axis=1)
    h = cell.radii[i] + cell.radii[j] - d
    a = neck_geometry(cell.radii[i], cell.radii[j], h).a
    K = np.asarray(pair_conductance(cell.radii[i], cell.radii[j], a), dtype=float)
    return float(np.sum(K * e[:, 2] ** 2) / np.prod(cell.period))
