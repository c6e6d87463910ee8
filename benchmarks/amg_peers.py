"""The AMG-preconditioned CG of ``dem.network.linsolve`` beside its previous settings and PETSc's algebraic multigrids
on the steady network of the bench packing (section "DEM steady network: AMG side by side" of ``python -m
benchmarks dem``).

Every solver gets the same matrix and right-hand side (the anchored free particles of
:func:`benchmarks.dem.packing_network`, as :func:`dem.network.heat.steady` solves them) and solves from zero to the
project's criterion, ``|b - A x| <= 1e-10 |b|`` (the unpreconditioned residual: PETSc's CG is told so, its
default being the preconditioned one). Setup (hierarchy) and solve are timed apart, the solvers alternating round
by round so that load from other processes hits all alike; the best round counts. Row ``amg_reused``: ours with
the hierarchy of an earlier matrix of the network (entries changed by up to 10 %), as a refresh reuses it. PETSc (petsc4py with ML, hypre,
GAMG) is an optional peer: its rows are left out when petsc4py is not importable.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp

from benchmarks.timing import available
from dem.network.linsolve import AMG_SEED, AMGSolver, PCGSolver

RTOL = 1e-10  # dem.network.heat.steady's linear criterion
# hypre BoomerAMG as tuned for 3D networks (PETSc's defaults for hypre take four times longer on this matrix)
HYPRE = {"pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_coarsen_type": "HMIS",
         "pc_hypre_boomeramg_interp_type": "ext+i", "pc_hypre_boomeramg_strong_threshold": "0.5",
         "pc_hypre_boomeramg_P_max": "4", "pc_hypre_boomeramg_agg_nl": "1"}
PETSC_PRECONDITIONERS = {"petsc_ml": ("ml", {}), "petsc_hypre": ("hypre", HYPRE), "petsc_gamg": ("gamg", {})}


class PreviousAMG(PCGSolver):
    """``dem.network.linsolve.AMGSolver`` as it was before its tuning: pyamg's default smoothed aggregation (Arnoldi
    estimate of ``rho(D^-1 A)`` on every level, four Gauss-Seidel sweeps on the candidate, 1 x 1 BSR coarse levels,
    BLAS threads as they come) with ``max_coarse = 500``, under the same CG."""

    name = "amg (previous settings)"

    def _preconditioner(self):
        import pyamg

        state = np.random.get_state()
        np.random.seed(AMG_SEED)
        try:
            hierarchy = pyamg.smoothed_aggregation_solver(self.A, symmetry="hermitian", max_coarse=500)
        finally:
            np.random.set_state(state)
        return hierarchy.aspreconditioner(cycle="V")


class PETScSolver:
    """CG with one of PETSc's algebraic multigrids (``pc_type``, options as ``-name value`` without the dash) on the
    CSR matrix ``A``; ``solve(b)`` to ``|b - A x| <= rtol |b|``, ``iterations`` those of the last solve."""

    def __init__(self, A, rtol: float, pc_type: str, options: dict):
        from petsc4py import PETSc

        self.PETSc = PETSc
        A = A.tocsr()
        db = PETSc.Options()
        for key, value in options.items():
            db.setValue(key, value)
        self.A = PETSc.Mat().createAIJ(size=A.shape, csr=(A.indptr.astype(PETSc.IntType),
                                                         A.indices.astype(PETSc.IntType), A.data))
        self.ksp = PETSc.KSP().create()
        self.ksp.setOperators(self.A)
        self.ksp.setType("cg")
        self.ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        self.ksp.setTolerances(rtol=rtol, atol=0.0, max_it=1000)
        self.ksp.getPC().setType(pc_type)
        self.ksp.setFromOptions()
        self.ksp.setUp()
        for key in options:
            db.delValue(key)
        self.iterations = 0

    def solve(self, b: np.ndarray) -> np.ndarray:
        rhs, x = self.A.createVecs()
        rhs.setArray(b)
        x.set(0.0)
        self.ksp.solve(rhs, x)
        if self.ksp.getConvergedReason() <= 0:
            raise ValueError(f"PETSc CG + {self.ksp.getPC().getType()} did not converge: reason "
                             f"{self.ksp.getConvergedReason()}")
        self.iterations = self.ksp.getIterationNumber()
        return x.getArray().copy()


def contenders() -> dict:
    """``name -> make(A, rtol)``: ours, ours with the previous settings, and PETSc's when petsc4py imports."""
    out = {"amg": AMGSolver, "amg_previous": PreviousAMG}
    if available("petsc4py"):
        for name, (pc_type, options) in PETSC_PRECONDITIONERS.items():
            out[name] = (lambda pc, opts: lambda A, rtol: PETScSolver(A, rtol, pc, opts))(pc_type, options)
    return out


def refreshed_hierarchy(A, b, change: float = 0.1, seed: int = 0) -> AMGSolver:
    """Our solver of an earlier matrix of the network, ``D A D`` with ``D^2`` uniform in ``1 -+ change/2`` (entries
    changed by up to ``change``, as conductances between refreshes), solved once: its hierarchy is what a refresh
    reuses (row ``amg_reused``, whose setup is then none)."""
    scale = sp.diags(np.sqrt(np.random.default_rng(seed).uniform(1 - change / 2, 1 + change / 2, A.shape[0])))
    earlier = AMGSolver((scale @ A @ scale).tocsr(), rtol=RTOL)
    earlier.solve(b)
    return earlier


def side_by_side_rows(A, b, rounds: int) -> list[dict]:
    """One row per contender: best setup and solve seconds over ``rounds`` alternating rounds, the best total wall
    and CPU (process) seconds, iterations, the relative residual reached and the largest difference to our solution;
    ratios of the totals over ours and over the fastest PETSc (wall and CPU: on a loaded machine the wall times
    mostly measure the waits for a core)."""
    makers = contenders()
    earlier = refreshed_hierarchy(A, b)
    makers = {"amg": makers.pop("amg"), "amg_reused": lambda A, rtol: AMGSolver(A, rtol=rtol, hierarchy_of=earlier),
              **makers}
    best = {name: {"setup_seconds": np.inf, "solve_seconds": np.inf, "seconds": np.inf, "cpu_seconds": np.inf}
            for name in makers}
    solutions, iterations = {}, {}
    for _ in range(rounds):
        for name, make in makers.items():
            t0, c0 = time.perf_counter(), time.process_time()
            solver = make(A, RTOL)
            t1 = time.perf_counter()
            x = solver.solve(b)
            t2, c2 = time.perf_counter(), time.process_time()
            row = best[name]
            row["cpu_seconds"] = min(row["cpu_seconds"], c2 - c0)
            row["setup_seconds"] = min(row["setup_seconds"], t1 - t0)
            row["solve_seconds"] = min(row["solve_seconds"], t2 - t1)
            row["seconds"] = min(row["seconds"], t2 - t0)
            solutions[name], iterations[name] = x, solver.iterations
            del solver
    norm_b, ours = float(np.linalg.norm(b)), solutions["amg"]
    rows = []
    for name in makers:
        x = solutions[name]
        rows.append({"solver": name, **best[name], "iterations": iterations[name],
                     "relative_residual": float(np.linalg.norm(b - A @ x)) / norm_b,
                     "max_difference_to_amg": float(np.max(np.abs(x - ours)))})
    for key in ("seconds", "cpu_seconds"):
        prefix = "" if key == "seconds" else "cpu_"
        fastest_petsc = min((r[key] for r in rows if r["solver"].startswith("petsc")), default=None)
        for row in rows:
            row[f"{prefix}over_amg"] = row[key] / best["amg"][key]
            row[f"{prefix}over_fastest_petsc"] = None if fastest_petsc is None else row[key] / fastest_petsc
    return rows
