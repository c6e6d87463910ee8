r"""Effective conductivity of periodic packings of sintered spheres: 3D FE of the mirror cell with two-sided bounds.

Geometry. A :class:`~fem_neck.lattice.cells.PeriodicCell` holds the particles of one period (centres, radii, the period
box); every overlapping pair of particle images is bonded (Rojek 2022, eq. 21) and gets the volume-conserving
cylindrical neck of :func:`fem_neck.geometry.neck_geometry` (eqs. 22-33). The solid is the union of all spheres and all
neck cylinders, exactly as in :mod:`fem_neck.cluster`; it conserves each particle's volume, so the solid volume fraction
is :math:`\phi = \sum \frac{4}{3} \pi r^3 / |P|` exactly (:math:`|P|` the period's volume). The pair neck model has an
answer only while the necks of one particle stay apart: :func:`~fem_neck.lattice.cells.check_cell` refuses a cell where
two neck circles on one sphere touch (for the cubic lattices from :math:`a/r = \sin(\theta/2)`, :math:`\theta` the
smallest angle between bonds: SC 90 deg, BCC 70.5 deg, FCC 60 deg; see :func:`~fem_neck.lattice.cells.max_h_over_r`).

The union reading (``neck = "union"``). The solid is the union of the spheres: Arzt's (1982) truncated spheres, each cut
by its radical planes (:mod:`fem_neck.geometry.union`), no cylinders. A neck is the circle where two spheres meet
(:class:`~fem_neck.lattice.mesh.UnionNecks`), second neighbours that overlap are necks too, and the necks of one
particle may meet; the model holds up to the overlap at which the spheres fill space
(:func:`~fem_neck.lattice.cells.union_max_h_over_r`), and :math:`\phi` is the exact volume of the cut spheres over the
period. Its circles are re-entrant edges of interior angle :math:`\pi + 2 \arccos(a/r)` (equal spheres), sharper than a
pair neck's, so its first mesh, gap order and mesh prediction are measured on its own cells (``UNION_*``). Below
``UNION_MIN_H_OVER_R`` the gap between two spheres at their circle is too thin a wedge to mesh.

The computational cell. A macroscopic gradient along z through a packing that is mirror-symmetric about the planes
:math:`x = 0`, :math:`y = 0`, :math:`z = 0` (hence also about :math:`x = P_x/2` etc.) leaves the planes :math:`z = 0`
and :math:`z = P_z/2` isothermal (the temperature fluctuation is odd under the z mirror) and the planes normal to x and
y insulated (it is even under those). The FE therefore solves the box :math:`[0, P/2]^3` -- an eighth of the period --
with :math:`T = 1` on :math:`z = 0`, :math:`T = 0` on :math:`z = P_z/2` and no flux elsewhere; when the packing is also
symmetric under :math:`x \leftrightarrow y` (the cubic lattices) only the wedge :math:`0 \le y \le x` of that box is
solved (a sixteenth), and when also under :math:`(x, y) \to (P/2 - y, P/2 - x)` (face-centred cubic) only its half with
:math:`x + y \le P/2`. Then :math:`k_{eff} = Q (P_z / 2) / A` with ``Q`` the heat flow and ``A`` the cell's
cross-section, for :math:`\kappa = 1`.

Two bounds (the error estimate). With ``K`` the exact heat flow of the cell for a unit temperature difference, both
are computed on one mesh whose tetrahedra fill the exact solid (:mod:`fem_neck.curved`: every boundary edge and
face mapped onto its sphere, cylinder, plane or their intersection curve), so there is no geometric error:

* **upper**: conforming ``P_p`` elements (:mod:`fem_neck.primal`). By Dirichlet's principle the energy of any
  admissible temperature is at least ``K``.
* **lower**: the hybridised Raviart-Thomas flux of degree ``p - 1`` (:mod:`fem_neck.dual`): divergence-free in every
  element, normal-continuous across faces and zero on the insulated ones, hence admissible in the complementary
  (Thomson) principle: :math:`K \ge P^2 / E^*` with ``P`` the heat it carries through the hot face and
  :math:`E^* = \int |q|^2`.

Both converge at one rate, so ``error_estimate = (upper - lower) / upper`` bounds the error of the reported value
(the upper) and is 2-3 times it (the two errors are about equal, measured on the lattice cells). The bounds hold up
to the quadrature of the curved elements (degree ``2 p``: 2-3e-9 relative at p = 4, measured against ``2 p + 4``)
and round-off, whatever the solvers' residuals: both CGs stop when their energy has settled to ``ALGEBRAIC_SHARE
rtol`` (1e-7 at the default ``rtol``); the energy of any iterate is an upper bound, and the flux of any iterate is
made exactly admissible (:func:`fem_neck.dual.equilibrate`). The mesh is graded toward every neck circle, where the
temperature is singular (``size_neck a`` at the circles, growing by ``GRADING`` per unit distance); it is refined
until the estimate meets ``rtol``, and the memory of each solve is estimated before its mesh is made
(:func:`~fem_neck.lattice.driver.effective_conductivity`).

The package, one concern a module: :mod:`~fem_neck.lattice.cells` (periodic cells, the cubic lattices and their
bonds), :mod:`~fem_neck.lattice.mesh` (the computational cell's curved mesh), :mod:`~fem_neck.lattice.bounds` (the two
bounds on one mesh), :mod:`~fem_neck.lattice.sizes` (the first and refined mesh sizes),
:mod:`~fem_neck.lattice.budget` (the tetrahedra and memory of a solve, predicted before meshing),
:mod:`~fem_neck.lattice.driver` (the adaptive run), :mod:`~fem_neck.lattice.flows` (a union cell's per-neck
flows and temperatures), :mod:`~fem_neck.lattice.network` (the pipe network's lattice sum)
and :mod:`~fem_neck.lattice.output` (the mesh for ParaView); the public names used elsewhere are importable from here.
"""

# the public names used elsewhere (verification, benchmarks, tests, the guide), importable from the package
from fem_neck.lattice.bounds import Bounds, solve_bounds  # noqa: F401
from fem_neck.lattice.budget import memory_estimate, neck_circles, peak_memory, predicted_tetrahedra  # noqa: F401
from fem_neck.lattice.cells import (BASIS, COORDINATION, EDGE_OVER_SPACING, KINDS, MIN_NECK_RATIO, NECKS,  # noqa: F401
                                    UNION_MIN_H_OVER_R, PeriodicCell, check_cell, check_h_over_r, lattice_cell,
                                    max_h_over_r, max_neck_ratio, mean_neck_ratio, mirror_symmetry, union_max_h_over_r,
                                    union_neck_ratio)
from fem_neck.lattice.driver import CellResult, effective_conductivity  # noqa: F401
from fem_neck.lattice.flows import NeckFlows, neck_flows  # noqa: F401
from fem_neck.lattice.mesh import CellMesh, UnionNecks, build_cell_mesh, local_cluster  # noqa: F401
from fem_neck.lattice.network import network_conductivity  # noqa: F401
from fem_neck.lattice.output import write_vtu  # noqa: F401
from fem_neck.lattice.sizes import (FIRST_MESH, GAP_ORDER, UNION_GAP_ORDER, UNION_PORE_ORDER,  # noqa: F401
                                    default_order, first_neck_size, first_rtol, mesh_sizes)
