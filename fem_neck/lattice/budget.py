"""What a solve of a periodic cell will need, known before its mesh is made: the tetrahedra predicted from the
cell's neck circles, the memory of the solve, and the refusal of a mesh that would not fit
(:func:`fem_neck.lattice.driver.effective_conductivity`)."""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from fem_neck.lattice.cells import TOL, PeriodicCell
from fem_neck.lattice.mesh import cell_frame
from fem_neck.lattice.sizes import SIZE_FAR, mesh_rule

# the tetrahedra of a mesh predicted before meshing (:func:`predicted_tetrahedra`): the constants fitted to 42 meshes
# (the six cubic cells and two chains at neck sizes 0.005-0.3, a random packing at 0.087 and 0.03), and the margin
# that puts every measured mesh on the safe side: 64 of them (also the other random packings and the first meshes
# of the dense-packing study) were predicted 1.04-1.77 times their tetrahedra
TETRAHEDRA_PER_CIRCLE, TETRAHEDRA_PER_VOLUME, PREDICTION_MARGIN = 315.0, 27.3, 1.3
# the union's, fitted to 27 meshes of the three cubic cells (h/r 0.02-0.6, neck sizes 0.01-0.1): with
# PREDICTION_MARGIN 1.05-2.62 times their tetrahedra (random union packings of 32-80 spheres: 1.9-3.3 times); their
# memory (p = 3 at most 18 kB per tetrahedron beyond the base, also on random packings of up to 109 127 tetrahedra;
# p = 4 at most 52 kB, FCC h/r = 0.02 at 0.01, 17 995 tetrahedra) lies within BYTES_PER_ELEMENT
UNION_TETRAHEDRA_PER_CIRCLE, UNION_TETRAHEDRA_PER_VOLUME = 353.0, 57.7
# peak memory of solve_bounds (both processes): BASE_BYTES + BYTES_PER_ELEMENT[order] * tetrahedra (measured by
# peak_memory, whole runs: p = 4 at most 41 kB per tetrahedron beyond the base on the six cells of SC, BCC, FCC at
# h/r = 0.02 and 0.08; p = 3 at most 18 kB, on the largest random packing of the dense-packing study, 106 027
# tetrahedra; about 1.4 times that here)
BASE_BYTES, BYTES_PER_ELEMENT = 0.5e9, {2: 20e3, 3: 25e3, 4: 60e3}


@dataclass(frozen=True)
class NeckCircles:
    """The neck circles on the boundary of a cell's solid, for predicting its mesh before meshing
    (:func:`predicted_tetrahedra`). Lengths in units of the largest radius.

    Parameters
    ----------
    a : numpy.ndarray
        Radius of each circle.
    h_n : numpy.ndarray
        Length of its neck (``inf`` for the union's circles, which no neck length limits).
    r_min : numpy.ndarray
        The smaller radius of its pair.
    fraction : numpy.ndarray
        The fraction of the circle inside the computational cell and on the solid's boundary.
    solid_volume : float
        Volume of the solid in the computational cell.
    neck : str
        The cell's reading (``NECKS``): which constants predict its mesh.
    """

    a: np.ndarray
    h_n: np.ndarray
    r_min: np.ndarray
    fraction: np.ndarray
    solid_volume: float
    neck: str = "newton"


def neck_circles(cell: PeriodicCell, samples: int = 360) -> NeckCircles:
    """The :class:`NeckCircles` of ``cell``: each bond's two circles sampled at ``samples`` points, the fraction
    of them inside the computational cell and inside no other particle (there the circle is not on the boundary).

    Parameters
    ----------
    cell : PeriodicCell
        The cell.
    samples : int
        Points per circle.
    """
    frame = cell_frame(cell)
    local, geo, e = frame.local, frame.geo, frame.e
    c, r = local.centres, local.radii
    bi, bj = local.bonds.T
    union = cell.neck == "union"
    slack = TOL if union else 0.0  # a union's circle may lie on a mirror plane, a face of the cell
    helper = np.where(np.abs(e[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    u = np.cross(e, helper)
    u /= np.linalg.norm(u, axis=1)[:, None]
    v = np.cross(e, u)
    angle = np.linspace(0.0, 2.0 * np.pi, samples, endpoint=False)
    ring = np.cos(angle)[None, :, None] * u[:, None, :] + np.sin(angle)[None, :, None] * v[:, None, :]
    fractions = []
    ends = (geo.z_i,) if union else (geo.z_i, geo.z_i + geo.h_n)
    for z in ends:
        points = (c[bi] + z[:, None] * e)[:, None, :] + geo.a[:, None, None] * ring  # (bonds, samples, 3)
        inside = np.ones(points.shape[:2], dtype=bool)
        for n, d in frame.halfspaces:
            inside &= points @ n <= d + slack
        for k in range(len(r)):
            covered = np.linalg.norm(points - c[k], axis=2) < r[k] * (1.0 - 1e-9)
            inside &= ~(covered & ((bi != k) & (bj != k))[:, None])
        fractions.append(inside.mean(axis=1))
    h_n = np.full(len(bi), np.inf) if union else geo.h_n  # a union's circle: no neck length limits its size
    a, h_n, r_min = (np.tile(np.asarray(x, dtype=float), len(ends)) for x in (geo.a, h_n, np.minimum(r[bi], r[bj])))
    return NeckCircles(a, h_n, r_min, np.concatenate(fractions), frame.solid_volume, cell.neck)


def predicted_tetrahedra(circles: NeckCircles, size_neck: float) -> float:
    r"""Tetrahedra of the mesh of neck size ``size_neck`` (:func:`~fem_neck.lattice.sizes.mesh_sizes`), predicted before
    meshing, on the safe side. A mesh of local size :math:`h(x)` has about :math:`\int dV / h^3` tetrahedra up to a
    constant. Around a neck circle of radius ``a`` the size is :math:`s + G \rho` at the distance :math:`\rho`
    (``GRADING`` G, :math:`s = \min(s_n a, h_n)` with ``size_neck`` :math:`s_n`,
    :func:`fem_neck.cluster.neck_size_fields`) up to :math:`U = F r_{min}` (``SIZE_FAR`` F), so the circle adds
    :math:`a \left(1 / (2 s) - 1 / U + s / (2 U^2)\right)` times a constant (the solid's angle around it over
    :math:`G^2`); the rest of the solid adds its volume over :math:`F^3`. The two constants are measured
    (``TETRAHEDRA_PER_CIRCLE``, ``TETRAHEDRA_PER_VOLUME``), times ``PREDICTION_MARGIN``.

    Parameters
    ----------
    circles : NeckCircles
        The cell's neck circles (:func:`neck_circles`).
    size_neck : float
        Element size at the neck circles over the neck radius (dimensionless).
    """
    s = np.minimum(size_neck * circles.a, circles.h_n)
    far = SIZE_FAR * circles.r_min
    near = np.where(s < far, circles.a * (0.5 / s - 1.0 / far + 0.5 * s / far**2), 0.0)
    per_circle, per_volume = ((UNION_TETRAHEDRA_PER_CIRCLE, UNION_TETRAHEDRA_PER_VOLUME) if circles.neck == "union"
                              else (TETRAHEDRA_PER_CIRCLE, TETRAHEDRA_PER_VOLUME))
    return PREDICTION_MARGIN * (per_circle * float(np.sum(circles.fraction * near))
                                + per_volume * circles.solid_volume / SIZE_FAR**3)


def memory_estimate(elements: float, order: int) -> float:
    """Peak bytes of one :func:`~fem_neck.lattice.bounds.solve_bounds` on ``elements`` tetrahedra (both processes;
    measured, see ``BYTES_PER_ELEMENT``).

    Parameters
    ----------
    elements : float
        Tetrahedra of the mesh.
    order : int
        Order of the upper bound: 2, 3 or 4.
    """
    return BASE_BYTES + BYTES_PER_ELEMENT[order] * elements


def peak_memory() -> float:
    """Peak resident bytes of this process plus the largest of its finished children (the lower-bound solves): at
    least what the run held at any one time."""
    import resource

    kib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss + resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return kib * 1024.0


def available_memory() -> float:
    """Bytes the machine can still give (``MemAvailable``), or all of its memory where that is unknown."""
    try:
        for line in open("/proc/meminfo"):
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) * 1024.0
    except OSError:
        pass
    return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))


def size_that_fits(circles: NeckCircles, calibration: float, order: int, budget: float) -> float | None:
    """The finest neck size (down to a fiftieth of the reading's ``FIRST_SIZES``' finest) whose solve fits in
    ``budget`` bytes (``calibration`` times its :func:`predicted_tetrahedra`), or ``None`` if not even the coarsest
    does.

    Parameters
    ----------
    circles : NeckCircles
        The cell's neck circles (:func:`neck_circles`).
    calibration : float
        Tetrahedra meshed over predicted (at least 1).
    order : int
        Order of the upper bound: 2, 3 or 4.
    budget : float
        Bytes the solve may use.
    """
    def fits(size):
        return memory_estimate(calibration * predicted_tetrahedra(circles, size), order) <= budget

    first_sizes = mesh_rule(circles.neck)[4]
    lo, hi = first_sizes[0] / 50.0, first_sizes[1]
    if not fits(hi):
        return None
    if fits(lo):
        return lo
    for _ in range(60):  # bisection in log size: the predicted tetrahedra fall as the size grows
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if fits(mid) else (mid, hi)
    return hi


def check_fits(cell: PeriodicCell, circles: NeckCircles, size: float, calibration: float, order: int,
                budget: float, what: str, rtol_at) -> None:
    """``ValueError`` unless the solve on the mesh of neck size ``size`` (``calibration`` times its
    :func:`predicted_tetrahedra`) fits in ``budget`` bytes, naming ``what`` it is, the estimate and the rtol that
    would fit (``rtol_at(size)`` of the finest size that fits).

    Parameters
    ----------
    cell : PeriodicCell
        The cell (its name is in the message).
    circles : NeckCircles
        The cell's neck circles (:func:`neck_circles`).
    size : float
        Element size at the neck circles over their radius (dimensionless).
    calibration : float
        Tetrahedra meshed over predicted (at least 1).
    order : int
        Order of the upper bound: 2, 3 or 4.
    budget : float
        Bytes the solve may use.
    what : str
        What the mesh is, for the message.
    rtol_at : callable
        ``rtol_at(size)``: the ``rtol`` that the mesh of neck size ``size`` would reach.
    """
    elements = calibration * predicted_tetrahedra(circles, size)
    need = memory_estimate(elements, order)
    if need <= budget:
        return
    fit = size_that_fits(circles, calibration, order, budget)
    if fit is None:
        coarsest = mesh_rule(circles.neck)[4][1]
        need = memory_estimate(calibration * predicted_tetrahedra(circles, coarsest), order)
        tail = f"no rtol fits: even neck size {coarsest:g} a needs ~{need / 1e9:.1f} GB"
    else:
        tail = f"rtol = {rtol_at(fit):.1e} would fit"
    raise ValueError(f"{cell.name}: {what} (neck size {size:.3g} a, ~{elements:.0f} tetrahedra) needs "
                     f"~{need / 1e9:.1f} GB, more than the {budget / 1e9:.1f} GB available; {tail}")
