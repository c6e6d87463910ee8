"""The adaptive run (:func:`effective_conductivity`): mesh, solve both bounds, refine until they meet the
tolerance, each mesh's memory estimated and refused before it is made."""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass, field

from fem_neck.curved import FoldedMesh
from fem_neck.geometry import check_positive
from fem_neck.lattice.bounds import solve_bounds
from fem_neck.lattice.budget import (available_memory, check_fits, memory_estimate, neck_circles, predicted_tetrahedra,
                                     size_that_fits)
from fem_neck.lattice.cells import PeriodicCell, check_cell, mean_neck_ratio
from fem_neck.lattice.flows import NeckFlows, neck_flows
from fem_neck.lattice.mesh import CellMesh, build_cell_mesh
from fem_neck.lattice.sizes import (FIRST_MESH, P3_FROM, REFINE_MARGIN, default_order, first_neck_size, first_rtol,
                                    mesh_rule, mesh_sizes)

# the solvers' energy tolerance over the requested rtol: the bounds' algebraic error stays ~1e-3 of the gap asked for
# (at rtol 1e-4 the bounds of BCC h/r = 0.02 move by 1.6e-10 and 4.6e-9 against CGs settled to 1e-9)
ALGEBRAIC_SHARE = 1e-3


@dataclass
class CellResult:
    r"""Effective conductivity of a periodic cell (:mod:`fem_neck.lattice`, :func:`effective_conductivity`); the values
    are the last mesh's. Conductivities are over the particles' ``kappa`` (dimensionless).

    Parameters
    ----------
    k_eff_over_kappa : float
        The best value: the ``P_p`` upper bound.
    k_lower_over_kappa, k_upper_over_kappa : float
        The two bounds.
    error_estimate : float
        ``(upper - lower) / upper`` (dimensionless).
    converged : bool
        Whether ``error_estimate`` met the tolerance asked for.
    phi : float
        Solid volume fraction (also the Wiener bound of :math:`k_{eff} / \kappa`).
    order : int
        Order ``p`` of the upper bound's elements.
    dofs : int
        Unknowns of the upper bound's solve.
    elements : int
        Tetrahedra of the mesh.
    levels : list of dict
        Every mesh solved: ``size_neck``, ``elements``, ``k_upper``, ``k_lower``, ``gap`` and ``seconds`` (wall time
        since the start, s).
    seconds : float
        Wall time of the whole computation, s.
    volume_error : float
        The mapped mesh's volume over the exact one, minus 1.
    flux_defect : float
        The lower bound's flux defect (:class:`~fem_neck.lattice.bounds.Bounds`).
    memory_estimate : float
        Estimated peak memory of the last solve, bytes (:func:`~fem_neck.lattice.budget.memory_estimate`).
    mesh : CellMesh, optional
        The last mesh.
    flows : NeckFlows, optional
        Per-neck heat flows and mean temperatures of the union cell's upper-bound solution on the last mesh, when
        asked for (:func:`fem_neck.lattice.flows.neck_flows`).
    """

    k_eff_over_kappa: float
    k_lower_over_kappa: float
    k_upper_over_kappa: float
    error_estimate: float
    converged: bool
    phi: float
    order: int
    dofs: int
    elements: int
    levels: list
    seconds: float
    volume_error: float
    flux_defect: float
    memory_estimate: float
    mesh: CellMesh | None = field(default=None, repr=False)
    flows: NeckFlows | None = field(default=None, repr=False)


def _refined_rtol(gap: float, size: float, new: float, neck: str = "newton") -> float:
    """The ``rtol`` whose refinement from a mesh of neck size ``size`` with the bounds ``gap`` apart goes to the
    neck size ``new`` (the inverse of the refinement rule of :func:`effective_conductivity`)."""
    return gap * (new / size) ** mesh_rule(neck)[1] / REFINE_MARGIN


def effective_conductivity(cell: PeriodicCell, rtol: float = 1e-4, order: int | None = None,
                           max_memory: float | None = None, max_meshes: int = 4, workers: int = 2,
                           progress=None, flows: bool = False) -> CellResult:
    r""":math:`k_{eff} / \kappa` along z of the periodic ``cell`` with two-sided bounds (:mod:`fem_neck.lattice`).

    The first mesh has the neck size :func:`~fem_neck.lattice.sizes.first_neck_size` (from ``rtol`` and the cell's mean
    neck); while the bounds are more than ``rtol`` apart it predicts the neck size that meets ``rtol`` (the gap falls
    like :math:`s_n^{\mathrm{GAP\_ORDER}}` in ``size_neck`` :math:`s_n`) and solves there, at most ``max_meshes``
    meshes. Before each mesh is made, its tetrahedra are predicted
    (:func:`~fem_neck.lattice.budget.predicted_tetrahedra`, on the safe side; from the second mesh on scaled up if a
    mesh had more) and the memory of its solve estimated (:func:`~fem_neck.lattice.budget.memory_estimate`): one that
    would not fit in ``max_memory`` bytes (default: what the machine has available) is refused with a ``ValueError``
    naming the estimate and the ``rtol`` that would fit. A mesh too coarse for the curvature of its surfaces (a curved
    element folds, :class:`fem_neck.curved.FoldedMesh`) is followed by one twice as fine.

    Parameters
    ----------
    cell : PeriodicCell
        The packing, mirror-symmetric about x = 0, y = 0 and z = 0; its bonds read as ``cell.neck``.
    rtol : float
        Relative gap ``(upper - lower) / upper`` of the bounds to reach.
    order : int, optional
        Order of the upper bound, 3 or 4 (default :func:`~fem_neck.lattice.sizes.default_order`).
    max_memory : float, optional
        Bytes the solves may use (default: what the machine has available).
    max_meshes : int
        Most meshes solved.
    workers : int
        2: the two bounds in parallel processes; 1: one after the other.
    progress : callable, optional
        ``progress(text)`` reports each mesh.
    flows : bool
        Also read the per-neck flows and temperatures of the last mesh's solution (a union cell only;
        :func:`fem_neck.lattice.flows.neck_flows`): ``CellResult.flows``.
    """
    check_positive("rtol", rtol)
    if flows and cell.neck != "union":
        raise ValueError(f"flows: per-neck flows are read on the union of spheres (neck = 'union'), not {cell.neck!r}")
    check_cell(cell)
    explicit = order is not None
    order = order or default_order(rtol)
    if order not in FIRST_MESH:  # (solve_bounds takes p = 2 too; its first mesh is not measured)
        raise ValueError(f"order = {order!r}: must be one of {', '.join(map(str, FIRST_MESH))} (the orders whose "
                         f"first mesh is sized from measurements)")
    budget = available_memory() if max_memory is None else float(max_memory)
    t0 = time.perf_counter()
    neck = mean_neck_ratio(cell)
    circles = neck_circles(cell)
    pore = 1.0 - cell.phi
    size = first_neck_size(rtol, neck, order, cell.neck, pore)
    gap_order = mesh_rule(cell.neck)[1]
    calibration = 1.0  # tetrahedra meshed over predicted, where a mesh had more than predicted

    def first_fit(fit: float) -> float:
        """The rtol whose first mesh is the finest that fits, at the order that rtol gets (unless one was given)."""
        reach = first_rtol(fit, neck, order, cell.neck, pore)
        if not explicit and default_order(reach) != order:  # p = 4 does not fit, p = 3 from P3_FROM does
            reach = max(first_rtol(size_that_fits(circles, calibration, 3, budget), neck, 3, cell.neck, pore),
                        P3_FROM)
        return reach

    what, rtol_at = "the first mesh", first_fit
    history = []
    for level in range(max_meshes):
        check_fits(cell, circles, size, calibration, order, budget, what, rtol_at)
        if progress is not None:
            progress(f"neck size {size:.3g} a")
        cm = build_cell_mesh(cell, **mesh_sizes(size))
        calibration = max(calibration, len(cm.curved.tets) / predicted_tetrahedra(circles, size))
        check_fits(cell, circles, size, calibration, order, budget, what, rtol_at)
        try:
            b = solve_bounds(cm, order, workers, ALGEBRAIC_SHARE * rtol)
        except FoldedMesh:  # too coarse for the curvature of its surfaces (seen on random union packings)
            if level == max_meshes - 1:
                raise
            what = f"the mesh of neck size {size:.3g} a folds a curved element; the mesh twice as fine"
            size /= 2.0
            continue
        history.append({"size_neck": size, "elements": b.elements, "k_upper": b.upper, "k_lower": b.lower,
                        "gap": b.gap, "seconds": time.perf_counter() - t0})
        if b.gap <= rtol:
            break
        # the neck size that meets REFINE_MARGIN rtol, at least 1.5x finer, at most 8x
        new = size * min(max((REFINE_MARGIN * rtol / b.gap) ** (1.0 / gap_order), 1.0 / 8.0), 1.0 / 1.5)
        what = (f"rtol = {rtol:g} needs a finer mesh than the {b.elements} tetrahedra whose bounds are {b.gap:.2e} "
                f"apart; that mesh")
        rtol_at = functools.partial(_refined_rtol, b.gap, size, neck=cell.neck)
        size = new
    return CellResult(k_eff_over_kappa=b.upper, k_lower_over_kappa=b.lower, k_upper_over_kappa=b.upper,
                      error_estimate=b.gap, converged=bool(b.gap <= rtol), phi=cell.phi, order=order, dofs=b.dofs_upper,
                      elements=b.elements, levels=history, seconds=time.perf_counter() - t0,
                      volume_error=b.volume_error, flux_defect=b.flux_defect,
                      memory_estimate=memory_estimate(b.elements, order), mesh=cm,
                      flows=neck_flows(cell, cm, b.temperature, order) if flows else None)
