"""The two bounds of a meshed cell (:mod:`fem_neck.lattice`): the conforming upper bound and the equilibrated flux's
lower bound, solved side by side in two processes."""

from __future__ import annotations

import contextlib
import time
from dataclasses import dataclass, field

import numpy as np

from fem_neck.lattice.mesh import CellMesh
from sinterheat.threads import one_blas_thread


@dataclass(frozen=True)
class Bounds:
    r"""Both bounds of one mesh (:func:`solve_bounds`), as :math:`k / \kappa` of the cell (dimensionless).

    Parameters
    ----------
    upper : float
        Upper bound (``P_p`` energy, :mod:`fem_neck.primal`).
    lower : float
        Lower bound (``RT_(p-1)`` flux, :mod:`fem_neck.dual`).
    flux_defect : float
        The flux's largest normal-flux jump relative to its mean flux per hot face (admissibility; round-off).
    dofs_upper, dofs_lower : int
        Unknowns of the two solves.
    elements : int
        Tetrahedra of the mesh.
    volume_error : float
        The mapped mesh's volume over the exact one, minus 1 (dimensionless).
    seconds : float
        Wall time of both solves, s.
    temperature : numpy.ndarray, optional
        The upper bound's skeleton temperatures (:class:`fem_neck.primal.Solution` ``u``), for
        :func:`fem_neck.lattice.flows.neck_flows`.
    """

    upper: float
    lower: float
    flux_defect: float
    dofs_upper: int
    dofs_lower: int
    elements: int
    volume_error: float
    seconds: float
    temperature: np.ndarray | None = field(default=None, repr=False, compare=False)

    @property
    def gap(self) -> float:
        """``(upper - lower) / upper``: the relative error bound (dimensionless)."""
        return (self.upper - self.lower) / self.upper


def _dual(mesh, order: int, hot, cold, etol: float, temperature):
    """The lower bound, its CG started from the trace of the upper bound's temperature (``temperature()``, called
    once the face system is assembled)."""
    from fem_neck import dual

    def start():
        return dual.trace_multipliers(mesh, order, temperature(), order - 1)

    with one_blas_thread():  # the dense work is many small products (see fem_neck.spectral.conductance)
        return dual.solve(mesh, order - 1, hot, cold, etol, start=start)


@contextlib.contextmanager
def small_pages():
    """The process (and the processes it forks meanwhile) without transparent huge pages, as before afterwards
    (Linux's ``prctl(PR_SET_THP_DISABLE)``; elsewhere nothing). The bounds' large arrays are written once, fresh: a
    huge page for them can stall the kernel finding or compacting 2 MB of free memory on a busy machine (a third of
    the system time of BCC h/r = 0.02; the benchmarks guide's lattice section)."""
    import ctypes

    get, set_ = 42, 41                                            # PR_GET_THP_DISABLE, PR_SET_THP_DISABLE
    try:
        prctl = ctypes.CDLL(None, use_errno=True).prctl
        before = prctl(get, 0, 0, 0, 0)
        changed = before >= 0 and prctl(set_, 1, 0, 0, 0) == 0
    except (AttributeError, OSError, TypeError):                  # no prctl: not Linux
        changed = False
    try:
        yield
    finally:
        if changed:
            prctl(set_, before, 0, 0, 0)


_TEMPERATURES = None  # in the lower bound's process: the queue on which the upper bound's temperature arrives
_JOB = None  # in the lower bound's process: the arguments of its solve, inherited through the fork (not pickled)
# the upper bound's temperature goes to the lower bound's process once its CG's energy has settled to START_SHARE etol,
# not at the end: the flux's CG starts as well from it (its distance from the flux's solution is the discretisation's;
# on BCC h/r = 0.02 at rtol 1e-4, 21 steps from iterates settled to 1e-5, 1e-4 and 1e-3 as from 1e-7)
START_SHARE = 100.0


def _receive_temperatures(queue, job: tuple) -> None:
    """Initializer of the lower bound's process: the queue of the upper bound's temperature and the arguments
    ``(mesh, order, hot, cold, etol)`` of its solve, which a forked process's initializer gets without pickling (a
    submitted job's arguments are pickled and piped: 40 MB of mesh and kept Jacobians on BCC h/r = 0.02); the
    process ends with its parent (:func:`sinterheat.pool.end_with_parent`: killed outright, the parent would leave it
    waiting on the queue for ever, holding the mesh)."""
    from sinterheat.pool import end_with_parent

    global _TEMPERATURES, _JOB
    _TEMPERATURES, _JOB = queue, job
    end_with_parent()


def _dual_receiving():
    mesh, order, hot, cold, etol = _JOB
    return _dual(mesh, order, hot, cold, etol, _TEMPERATURES.get)


def solve_bounds(cm: CellMesh, order: int = 4, workers: int = 2, etol: float | None = None) -> Bounds:
    r"""Upper and lower bound of the cell's :math:`k / \kappa` on the mesh ``cm`` (:mod:`fem_neck.lattice`), the two
    solves in parallel processes when ``workers >= 2`` (the lower bound assembles its system while the upper bound
    solves, then starts its CG from the upper bound's temperature, sent once the upper bound's CG has settled to
    ``START_SHARE etol``). Both integrate the curved elements at the same
    points, where the elements are mapped once. Both CGs stop when their energy has settled to ``etol`` (default
    ``fem_neck.primal.ENERGY_RTOL``).

    Parameters
    ----------
    cm : CellMesh
        The meshed cell.
    order : int
        Order ``p`` of the upper bound (the lower bound's flux has degree ``p - 1``).
    workers : int
        Processes: 2 or more runs the two bounds side by side, 1 one after the other.
    etol : float, optional
        Relative energy tolerance of both CGs (dimensionless).
    """
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context

    import pyamg  # noqa: F401  (imported before the fork: the lower bound's process inherits it, as it does dual)

    from fem_neck import dual, pcg, primal  # noqa: F401
    from sinterheat import amg  # noqa: F401
    from fem_neck.simplex import tet_quadrature

    t0 = time.perf_counter()
    etol = primal.ENERGY_RTOL if etol is None else etol
    mesh = cm.curved
    with small_pages():  # (the lower bound's process, forked inside, inherits it)
        mesh.keep_jacobians(tet_quadrature(primal.quadrature_degree(order))[0])  # = dual's quadrature_degree(order)
        try:
            if workers >= 2:
                context = get_context("fork")
                queue = context.Queue()     # put does not wait for the reader (which may have failed before reading)
                queue.cancel_join_thread()  # nor does the exit, if it never read
                pool = ProcessPoolExecutor(1, mp_context=context, initializer=_receive_temperatures,
                                           initargs=(queue, (mesh, order, cm.hot, cm.cold, etol)))
            else:
                pool = contextlib.nullcontext()
            with pool:
                future = pool.submit(_dual_receiving) if workers >= 2 else None
                with one_blas_thread():
                    early = None if future is None else (START_SHARE * etol, queue.put)
                    up = primal.solve(mesh, order, cm.hot, cm.cold, etol, early=early)
                    volume = primal.volume(mesh)  # (while the lower bound finishes in its process)
                low = (future.result() if future is not None
                       else _dual(mesh, order, cm.hot, cm.cold, etol, lambda: up.u))
        finally:  # the kept Jacobians (a few hundred MB on a fine mesh) go with the solves, also when one fails
            mesh.keep_jacobians(None)
    scale = cm.height / cm.area
    return Bounds(float(up.energy * scale), float(low.lower * scale), float(low.flux_defect), int(up.dofs),
                  int(low.dofs), len(mesh.tets), float(volume / cm.volume_exact - 1.0), time.perf_counter() - t0,
                  up.u)
