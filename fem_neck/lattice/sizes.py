"""The mesh sizes of the adaptive run (:func:`fem_neck.lattice.driver.effective_conductivity`): the first mesh of a
cell, sized from measured gaps of the bounds, the rule by which a refined mesh is sized, and the default order."""

from __future__ import annotations

import numpy as np

# the meshes: element size at the neck circles over the neck radius (the range of first meshes), far size over the
# particle radius, growth of the size per unit distance from the circles
FIRST_SIZES, SIZE_FAR, GRADING = (0.005, 0.3), 0.5, 0.8
# measured on the lattice cells: the gap falls like size_neck^GAP_ORDER; a refined mesh aims at REFINE_MARGIN rtol
# (:func:`~fem_neck.lattice.driver.effective_conductivity`)
GAP_ORDER, REFINE_MARGIN = 1.25, 0.7
# the first mesh (:func:`first_neck_size`), by order p: (size0, rtol0, neck_order, margin): at neck size size0 the
# bounds of a cell whose necks have the mean a/r = NECK0 are about rtol0 apart; larger necks need a coarser mesh, the
# gap falling like (a/r)^-neck_order, used only over NECK_RANGE (not extrapolated to necks smaller than measured);
# the first mesh aims at margin rtol. p = 4: the cubic lattices at h/r = 0.02 (a/r = 0.2) are 0.9-1.1e-4 apart at
# size 0.01, at h/r = 0.08 (a/r = 0.39) 3.3-4.4e-5. p = 3: the cubic lattices at a/r = 0.2 are 1.47-1.68e-3 apart
# at size 0.05 and 4.7-5.7e-4 at 0.0191, at a/r = 0.39 0.70-0.79e-3 and 2.2-2.4e-4; two random packings (mean a/r
# 0.32 and 0.37) were 2.5e-3 and 2.2e-3 apart at 0.087, 1.08 and 1.13 times this rule's gap (inside the margin).
FIRST_MESH = {3: (0.05, 1.9e-3, 1.1, 0.75), 4: (0.01, 1e-4, 1.3, 0.75)}
NECK0, NECK_RANGE = 0.2, (0.2, 0.5)
P3_FROM = 3e-4  # the rtol from which the upper bound is P_3 by default (below, P_4)
# the union reading's first mesh, gap order, neck range and first sizes (as FIRST_MESH, GAP_ORDER, NECK0, NECK_RANGE,
# FIRST_SIZES): its circles are sharper edges (interior angle pi + 2 arccos(a/r)), so its gap falls more slowly with
# the neck size, and it falls with the pore fraction 1 - phi as well (a cell near closure is nearly uniform), like
# ((1 - phi) / UNION_PORE0)^UNION_PORE_ORDER over UNION_PORE_RANGE. Measured on its own cells (SC, BCC, FCC at h/r
# 0.02, 0.2-0.3, 0.3-0.6 and near closure; a/r the mean over all bonds, second neighbours included): per cell the
# gap falls like size^0.83-1.06 (p = 3, BCC h/r = 0.02: 1.49e-2, 6.45e-3, 1.71e-3, 8.25e-4 at 0.1, 0.04, 0.01,
# 0.0042); fitted at gap order 0.94 to the 37 solves at neck sizes 0.0015-0.04, like (a/r)^-0.747 and
# (1 - phi)^0.692. The cells scatter about the fit by 0.2-2.7 (SC 0.2-0.9, FCC 0.7-1.9, BCC 1.1-2.7; random
# packings of phi 0.6 0.3-0.35), so rtol0 is the fit, not the largest: a cell inside 1 / margin of it meets rtol on
# its first mesh, a BCC cell may need a second, and the first mesh's memory is not predicted for the worst cell.
UNION_FIRST_MESH = {3: (0.01, 1.52e-3, 0.747, 0.75), 4: (0.01, 7.03e-4, 0.747, 0.75)}
UNION_GAP_ORDER = 0.94
UNION_NECK0, UNION_NECK_RANGE = 0.141, (0.141, 0.70)
UNION_PORE0, UNION_PORE_ORDER, UNION_PORE_RANGE = 0.3, 0.692, (2e-5, 0.46)
UNION_FIRST_SIZES = (0.001, 0.3)


def mesh_sizes(size_neck: float) -> dict:
    """The mesh of neck size ``size_neck`` (element size at the neck circles over the neck radius): far size and
    grading fixed (``SIZE_FAR``, ``GRADING``).

    Parameters
    ----------
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless).
    """
    return {"size_neck": size_neck, "size_far": SIZE_FAR, "grading": GRADING}


def mesh_rule(neck: str) -> tuple:
    """``(FIRST_MESH, GAP_ORDER, NECK0, NECK_RANGE, FIRST_SIZES)`` of the reading ``neck`` (the union's:
    ``UNION_*``).

    Parameters
    ----------
    neck : str
        How the cell's bonds are read (``NECKS`` of :mod:`fem_neck.lattice.cells`).
    """
    if neck == "union":
        return UNION_FIRST_MESH, UNION_GAP_ORDER, UNION_NECK0, UNION_NECK_RANGE, UNION_FIRST_SIZES
    return FIRST_MESH, GAP_ORDER, NECK0, NECK_RANGE, FIRST_SIZES


def _neck_factor(neck_ratio: float, order: int, neck: str = "newton", pore: float = UNION_PORE0) -> float:
    """How much coarser than at ``NECK0`` a mesh may be for the same gap when the mean neck is ``neck_ratio`` (and,
    read as the union, the pore fraction ``pore`` rather than ``UNION_PORE0``)."""
    first_mesh, gap_order, neck0, neck_range, _ = mesh_rule(neck)
    neck_order = first_mesh[order][2]
    factor = (float(np.clip(neck_ratio, *neck_range)) / neck0) ** (neck_order / gap_order)
    if neck == "union":
        factor *= (float(np.clip(pore, *UNION_PORE_RANGE)) / UNION_PORE0) ** (-UNION_PORE_ORDER / gap_order)
    return factor


def first_neck_size(rtol: float, neck_ratio: float, order: int, neck: str = "newton",
                    pore: float = UNION_PORE0) -> float:
    r"""Neck size of the first mesh of a cell: the size whose gap is predicted at ``margin rtol`` (``FIRST_MESH``:
    ``rtol0`` at ``size0`` for :math:`a / r` = ``NECK0``, the gap falling like the size to the power ``GAP_ORDER`` and
    like :math:`a / r` to the power ``-neck_order``; the union's ``UNION_*``, its gap also falling with the pore
    fraction), within ``FIRST_SIZES``.

    Parameters
    ----------
    rtol : float
        Relative gap of the bounds asked for.
    neck_ratio : float
        The cell's mean ``a / r`` (:func:`~fem_neck.lattice.cells.mean_neck_ratio`).
    order : int
        Order of the upper bound (3 or 4).
    neck : str
        The cell's reading (``NECKS``).
    pore : float
        The cell's pore fraction :math:`1 - \phi` (read as the union only).
    """
    first_mesh, gap_order, _, _, first_sizes = mesh_rule(neck)
    size0, rtol0, _, margin = first_mesh[order]
    size = size0 * (margin * rtol / rtol0) ** (1.0 / gap_order) * _neck_factor(neck_ratio, order, neck, pore)
    return float(np.clip(size, *first_sizes))


def first_rtol(size: float, neck_ratio: float, order: int, neck: str = "newton", pore: float = UNION_PORE0) -> float:
    """The ``rtol`` whose first mesh (:func:`first_neck_size`) has the neck size ``size``.

    Parameters
    ----------
    size : float
        Element size at the neck circles over their radius.
    neck_ratio, order, neck, pore
        As for :func:`first_neck_size`.
    """
    first_mesh, gap_order, _, _, _ = mesh_rule(neck)
    size0, rtol0, _, margin = first_mesh[order]
    return rtol0 * (size / (size0 * _neck_factor(neck_ratio, order, neck, pore))) ** gap_order / margin


def default_order(rtol: float) -> int:
    """The order of the upper bound for ``rtol`` unless one is given: 3 from ``P3_FROM`` up, else 4.

    Parameters
    ----------
    rtol : float
        The relative error asked for (dimensionless).
    """
    return 3 if rtol >= P3_FROM else 4
