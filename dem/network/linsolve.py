r"""Sparse symmetric positive definite solves behind one small interface.

``make_solver(A, backend)`` returns an object with ``solve(b, x0=None) -> x`` for a fixed matrix, so a
factorisation or a multigrid hierarchy is built once and reused for every right-hand side (every time step).
Backends (``BACKENDS``; a PETSc/MPI backend is one more entry with the same two methods):

* ``"direct"`` -- sparse LU (SuperLU, symmetric mode with a minimum-degree ordering of :math:`A + A^T`); exact to
  round-off. Fill-in grows fast on 3D networks, so ``"auto"`` uses it for small systems only.
* ``"cg"`` -- conjugate gradients with a Jacobi (diagonal) preconditioner. Converges in a handful of iterations
  when the capacity term :math:`C/\Delta t` dominates the diagonal (implicit steps of large packings).
* ``"amg"`` -- conjugate gradients preconditioned by a smoothed-aggregation algebraic multigrid V-cycle (pyamg),
  for large steady networks, with settings tuned for network matrices (:class:`AMGSolver`); a matrix that changed
  a little since an earlier one of the same size (``make_solver(previous=...)``: a refresh, radiation's Newton and
  time steps) is preconditioned by the earlier hierarchy, with no setup. ``python -m benchmarks dem`` times it
  beside its previous settings and PETSc's CG with ML, hypre BoomerAMG and GAMG on the steady network of the
  10^6-particle bench packing (section "DEM steady network: AMG side by side"; PETSc's rows where petsc4py
  imports).

``"auto"`` (:func:`choose_backend`) looks at the diagonal dominance first: the Jacobi-scaled matrix has condition number
at most :math:`1 + 2/\rho` with :math:`\rho = \min_i m_i / L_{ii}` (:math:`m_i` the part of the diagonal beyond the
Laplacian: :math:`C_i/\Delta t` in a time step). When that bound is at most ``JACOBI_MAX_CONDITION``, Jacobi-CG reaches
a relative residual of 1e-10 within about :math:`\frac{\sqrt{4000}}{2} \ln(2 \sqrt{4000} / 10^{-10}) \approx 880`
iterations (1000 are allowed), and it is chosen above ``JACOBI_MIN`` unknowns (chains with conductances spread over 1e4
... 1e12 at the bound took at most 504 iterations). The target is on the unscaled residual, which floating point may not
reach on badly scaled systems: should CG fail, the matrix falls back to direct or AMG (:class:`AutoCGSolver`). Otherwise
(steady networks, very large time steps) direct up to ``DIRECT_MAX`` unknowns, AMG above.

The thresholds come from timing the three backends on random sintered packings between fixed plates, steady and with the
capacity term :math:`C/\Delta t` for steps of 1 to 1000 times the cheap explicit bound :math:`2 \min_i C_i / L_{ii}`:
``python -m benchmarks dem`` prints that table with the choice of ``"auto"`` beside each row (section "DEM linear
solvers"). What it shows: SuperLU's fill-in on 3D networks makes the factorisation grow about as :math:`N^2`, while a
Jacobi-CG solve costs about as much as a direct back-substitution from ~10 000 unknowns on whenever :math:`C/\Delta t`
dominates; in a time integration CG is also warm-started from the extrapolated previous steps, and with ``dt = "auto"``
every step size gets its own solver, which tips the balance further. Without diagonal dominance (steady networks, very
large dt) a single solve decides: direct costs milliseconds up to a few thousand unknowns; above, AMG is chosen for its
robustness to conductance contrasts, although plain Jacobi-CG often converges faster on benign packings -- it has no
convergence guarantee there.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spl

from sinterheat.threads import one_blas_thread

DIRECT_MAX = 5_000  # without diagonal dominance: direct up to this many unknowns, AMG above
JACOBI_MIN = 1_000  # with diagonal dominance: Jacobi-CG above this many unknowns, direct below
JACOBI_MAX_CONDITION = 4000.0  # diagonally dominant: Jacobi condition-number bound 1 + 2/rho at most this
AMG_SEED = 0  # the random start vector of pyamg's spectral-radius estimates (AMGSolver)
AMG_REUSE_GROWTH = 2.0  # a reused AMG hierarchy is dropped once a solve takes this x the most its own matrix took
AMG_SMOOTHER = ("gauss_seidel", {"sweep": "symmetric"})  # one symmetric sweep before and after each coarse correction
AMG_OPTIONS = {  # pyamg.smoothed_aggregation_solver's settings (AMGSolver): the finest level's smoother row-weighted
    "symmetry": "hermitian", "strength": None, "max_coarse": 500, "improve_candidates": None,
    "presmoother": AMG_SMOOTHER, "postsmoother": AMG_SMOOTHER,
    "smooth": [("jacobi", {"omega": 1.8, "weighting": "local"})] + [("jacobi", {"omega": 4.0 / 3.0})] * 9}


class SolverError(ValueError):
    """The linear solve failed (no convergence); a ValueError so that the CLI reports it in one line."""


class DirectSolver:
    """Sparse LU, factorised once.

    Parameters
    ----------
    A : scipy.sparse.spmatrix
        The symmetric positive definite matrix (e.g. W/K).
    rtol : float
        Not read (an exact solve); taken so that every backend is made alike.
    """

    name = "direct"

    def __init__(self, A: sp.spmatrix, rtol: float = 0.0):
        self.lu = spl.splu(sp.csc_matrix(A), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
        self.iterations = 0

    def solve(self, b: np.ndarray, x0=None) -> np.ndarray:
        """The solution by the factorisation.

        Parameters
        ----------
        b : numpy.ndarray
            The right-hand side (e.g. W).
        x0 : numpy.ndarray or None
            A start (warm start of an iterative solver; not read by a direct one); None: zero.

        Returns
        -------
        numpy.ndarray
            ``x`` with ``A x = b`` (e.g. K).
        """
        return self.lu.solve(b)


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """Inner product without BLAS: BLAS threads that spin between calls slow the CG loop on a busy machine."""
    return float(np.einsum("i,i->", a, b))


class PCGSolver:
    r"""Preconditioned conjugate gradients to :math:`|r| \le \mathrm{rtol} \, |b|`, warm-started from ``x0``.

    Parameters
    ----------
    A : scipy.sparse.spmatrix
        The symmetric positive definite matrix (e.g. W/K).
    rtol : float
        The relative residual at which the iteration stops.
    max_iterations : int or None
        The most iterations per solve; None: :math:`\max(1000, 10 \sqrt{N})` (:math:`N` unknowns).
    """

    name = "cg"

    def __init__(self, A: sp.spmatrix, rtol: float = 1e-12, max_iterations: int | None = None):
        self.A = sp.csr_matrix(A)
        self.rtol = rtol
        self.max_iterations = max_iterations or max(1000, 10 * int(np.sqrt(self.A.shape[0])))
        self.iterations = 0
        self.precondition = self._preconditioner()
        self.product = self._product()

    def _product(self):
        """The iteration's product ``p -> A p``: scipy's."""
        return lambda p: self.A @ p

    def _preconditioner(self):
        inv_diag = 1.0 / self.A.diagonal()
        return lambda r: inv_diag * r

    def solve(self, b: np.ndarray, x0=None) -> np.ndarray:
        """CG to ``|r| <= rtol |b|``.

        Parameters
        ----------
        b : numpy.ndarray
            The right-hand side (e.g. W).
        x0 : numpy.ndarray or None
            A start (warm start of an iterative solver; not read by a direct one); None: zero.

        Returns
        -------
        numpy.ndarray
            ``x`` with ``A x = b`` (e.g. K).

        Raises
        ------
        SolverError
            The iteration did not reach ``rtol`` within its iterations, or broke down (``A`` not positive definite
            to round-off).
        """
        A, M = self.A, self.precondition
        x = np.zeros_like(b) if x0 is None else np.array(x0, dtype=float)
        r = b - A @ x if np.any(x) else np.array(b, dtype=float)  # from zero (a steady start): no pass over A
        target2 = self.rtol**2 * _dot(b, b)
        rr = _dot(r, r)
        if rr <= target2:
            return x
        z = M(r)
        p = z.copy()
        rz = _dot(r, z)
        for k in range(1, self.max_iterations + 1):
            q = self.product(p)
            pq = _dot(p, q)
            if not pq > 0.0:  # breakdown: p in the null space of A as rounded (not positive definite to round-off)
                raise SolverError(f"{self.name} broke down at iteration {k} (p.Ap = {pq:.3g}: the matrix is singular "
                                  f"to round-off, e.g. capacities C/dt lost next to the conductances); try a smaller "
                                  f"dt or solver.linear = \"direct\"")
            alpha = rz / pq
            x += alpha * p
            q *= alpha
            r -= q
            rr = _dot(r, r)
            if rr <= target2:
                self.iterations += k
                return x
            z = M(r)
            rz_new = _dot(r, z)
            p *= rz_new / rz
            p += z
            rz = rz_new
        raise SolverError(f"{self.name} did not reach rtol = {self.rtol:g} in {self.max_iterations} iterations "
                          f"(relative residual {np.sqrt(rr / _dot(b, b)):.3g}); try solver.linear = "
                          f"\"direct\" or \"amg\"")


class AMGSolver(PCGSolver):
    r"""CG preconditioned by one smoothed-aggregation V-cycle (pyamg), hierarchy built once (``AMG_OPTIONS``).

    Three things make it cheap on the network matrices (weighted graph Laplacians plus a positive diagonal):

    * the prolongation smoother of the finest level weights each row by its Gershgorin row sum :math:`\sum_j |A_{ij}|`
      (pyamg's ``weighting="local"``) instead of estimating :math:`\rho(D^{-1} A)` by restarted Arnoldi, which costs as
      much as the rest of the setup on :math:`10^6` unknowns. A Laplacian row sums to :math:`2 A_{ii}`, so
      :math:`\omega = 1.8` is a damping of :math:`0.9 / A_{ii}`, next to pyamg's default
      :math:`\frac{4}{3} / \rho(D^{-1} A) = 0.84` (:math:`\rho = 1.59` on the bench packing). Coarse levels (pyamg holds
      them as BSR, whose ``abs`` is a Python loop) keep the default weighting; their Arnoldi is cheap;
    * the constant vector is the near-null space of a graph Laplacian as it is: no relaxation sweeps improve it;
    * every connection is strong (``strength=None``): pyamg's default symmetric measure with :math:`\theta = 0` keeps
      every entry too, so the aggregates are the same, without computing and scaling a copy of every level
      (the setup takes 0.7 of the CPU time on the bench packing's 10^6 unknowns, the same iterates to the bit);
    * the coarse levels are converted from BSR with 1 x 1 blocks to CSR once built: pyamg's block Gauss-Seidel on
      1 x 1 blocks takes four times the time of the scalar kernel on the same entries;
    * the V-cycle (``AMG_SMOOTHER`` before and after each coarse correction) is :class:`dem.network.amg_cycle.VCycle`:
      without the two residual norms per cycle of pyamg's ``aspreconditioner``, and on a large system compiled, on
      numba's threads, with hybrid Gauss-Seidel sweeps over fixed row blocks;
    * on a large system the coarsest level has up to ``dem.network.amg_setup.COARSEST_MAX`` unknowns and is solved
      exactly by its Cholesky factors (13 CG iterations become 10 on the bench packing's 10^6 unknowns);

    and setup and solves run with one BLAS thread: the Arnoldi and the coarse solve call BLAS on vectors, whose
    spinning threads multiplied the setup time by four on a loaded two-core machine.

    ``hierarchy_of``: the solver of an earlier matrix of the same size (the same network refreshed, the next Newton
    or time step), whose hierarchy then preconditions this one, with no setup. A fixed V-cycle with symmetric
    smoothing is a symmetric positive definite operator, a valid CG preconditioner for any SPD matrix, and CG
    stops on this matrix's own residual: the criterion is the same as with a fresh hierarchy, only the iterations
    may grow (:meth:`solve` bounds them).

    Parameters
    ----------
    A : scipy.sparse.spmatrix
        The symmetric positive definite matrix (e.g. W/K).
    rtol : float
        The relative residual at which CG stops.
    max_iterations : int or None
        The most iterations per solve; None: :math:`\max(1000, 10 \sqrt{N})` (:math:`N` unknowns).
    hierarchy_of : AMGSolver or None
        The solver of an earlier matrix of the same size whose hierarchy preconditions this one; None: build one.
    """

    name = "amg"

    def __init__(self, A: sp.spmatrix, rtol: float = 1e-12, max_iterations: int | None = None,
                 hierarchy_of: "AMGSolver | None" = None):
        # an earlier matrix's solver whose hierarchy preconditions (reuse): the one that built it, so that a chain of
        # reuses holds one earlier matrix, not all of them
        self.hierarchy_of = hierarchy_of if hierarchy_of is None else (hierarchy_of.hierarchy_of or hierarchy_of)
        super().__init__(A, rtol, max_iterations)
        self.fresh_max_iterations = self.max_iterations
        self.fresh_iterations = None  # the most iterations a solve on this matrix's own hierarchy took (bounds reuses)

    @property
    def reused(self) -> bool:
        """Whether the hierarchy preconditioning this matrix is an earlier matrix's."""
        return self.hierarchy_of is not None

    def _product(self):
        """The iteration's product ``p -> A p``: from ``COMPILED_FROM`` unknowns on, where the cycle runs compiled,
        ``dem.network.amg_kernels.matvec`` over ``BLOCKS`` row blocks on numba's threads (each row summed in scipy's
        order: the same products to the bit), into one array that every iteration reuses; else scipy's."""
        from dem.network.amg_cycle import BLOCKS, COMPILED_FROM

        A = self.A
        if A.shape[0] < COMPILED_FROM:
            return super()._product()
        from dem.network import amg_kernels

        bounds = amg_kernels.row_blocks(A.indptr, BLOCKS)
        q = np.empty(A.shape[0])

        def product(p):
            amg_kernels.matvec(A.indptr, A.indices, A.data, p, q, bounds)
            return q

        return product

    def _preconditioner(self):
        if self.hierarchy_of is not None:
            self.hierarchy = self.hierarchy_of.hierarchy
            return self.hierarchy_of.precondition
        from dem.network.amg_cycle import COMPILED_FROM, VCycle
        from sinterheat import amg

        with one_blas_thread():
            if self.A.shape[0] >= COMPILED_FROM:  # the finest level compiled, on threads
                from dem.network import amg_setup

                self.hierarchy = amg_setup.hierarchy(self.A, AMG_SEED, AMG_OPTIONS)
            else:
                self.hierarchy = amg.hierarchy(self.A, AMG_SEED, **AMG_OPTIONS)   # seeded, on CSR
        return VCycle(self.hierarchy)

    def solve(self, b: np.ndarray, x0=None) -> np.ndarray:
        """CG to the criterion. A reused hierarchy (``hierarchy_of``) that needs more than ``AMG_REUSE_GROWTH``
        times the most iterations a solve on its own matrix took (plus one) is dropped there and a fresh one built
        for this matrix, which then solves from ``x0`` again.

        Parameters
        ----------
        b : numpy.ndarray
            The right-hand side (e.g. W).
        x0 : numpy.ndarray or None
            A start (warm start of an iterative solver; not read by a direct one); None: zero.

        Returns
        -------
        numpy.ndarray
            ``x`` with ``A x = b`` (e.g. K).

        Raises
        ------
        SolverError
            The iteration did not reach ``rtol`` within its iterations.
        """
        with one_blas_thread():
            if not self.reused:
                return self._own_solve(b, x0)
            fresh = self.hierarchy_of.fresh_iterations
            self.max_iterations = (self.fresh_max_iterations if fresh is None
                                   else int(AMG_REUSE_GROWTH * fresh) + 1)
            try:
                return super().solve(b, x0)
            except SolverError:
                self.hierarchy_of = None
                self.precondition = self._preconditioner()
                self.max_iterations = self.fresh_max_iterations
                return self._own_solve(b, x0)

    def _own_solve(self, b, x0):
        """A solve on the hierarchy of this matrix; the most iterations one took bound those of a reuse."""
        before = self.iterations
        x = super().solve(b, x0)
        if self.iterations > before:  # a zero right-hand side or a converged start says nothing
            self.fresh_iterations = max(self.fresh_iterations or 0, self.iterations - before)
        return x


BACKENDS = {"direct": DirectSolver, "cg": PCGSolver, "amg": AMGSolver}


class AutoCGSolver(PCGSolver):
    """Jacobi-CG as picked by ``"auto"``; should it not converge (the unscaled residual target out of reach in
    floating point), the matrix goes to ``fallback`` for good.

    Parameters
    ----------
    A : scipy.sparse.spmatrix
        The symmetric positive definite matrix (e.g. W/K).
    rtol : float
        The relative residual at which CG stops.
    fallback : str
        The backend taken should CG fail: ``"direct"`` or ``"amg"``.
    """

    def __init__(self, A: sp.spmatrix, rtol: float = 1e-12, fallback: str = "amg"):
        super().__init__(A, rtol)
        self.fallback_name, self.fallback = fallback, None

    def solve(self, b: np.ndarray, x0=None) -> np.ndarray:
        """Jacobi-CG, or the fallback once CG has failed.

        Parameters
        ----------
        b : numpy.ndarray
            The right-hand side (e.g. W).
        x0 : numpy.ndarray or None
            A start (warm start of an iterative solver; not read by a direct one); None: zero.

        Returns
        -------
        numpy.ndarray
            ``x`` with ``A x = b`` (e.g. K).

        Raises
        ------
        SolverError
            The fallback failed as well (an iterative one).
        """
        if self.fallback is None:
            try:
                return super().solve(b, x0)
            except SolverError:
                self.fallback = BACKENDS[self.fallback_name](self.A, rtol=self.rtol)
                self.name = self.fallback.name
        return self.fallback.solve(b, x0)


def choose_backend(A: sp.spmatrix, laplacian_diagonal: np.ndarray) -> str:
    """The ``"auto"`` rule of the module docstring.

    Parameters
    ----------
    A : scipy.sparse.spmatrix
        The symmetric positive definite matrix (e.g. W/K).
    laplacian_diagonal : numpy.ndarray
        The part of ``A``'s diagonal that the Laplacian makes (the rest is the capacity term ``C/dt`` and the like).

    Returns
    -------
    str
        ``"cg"``, ``"direct"`` or ``"amg"``.
    """
    n = A.shape[0]
    extra = A.diagonal() - laplacian_diagonal
    # rho > 0 needs extra > 0 wherever the Laplacian's diagonal is: a steady network (extra = 0) stops here, before
    # the quotients (a few fresh arrays of a node each)
    if n > JACOBI_MIN and np.all((extra > 0) | ~(laplacian_diagonal > 0)):
        with np.errstate(divide="ignore"):
            rho = np.min(np.where(laplacian_diagonal > 0, extra / laplacian_diagonal, np.inf), initial=np.inf)
        if rho > 0 and 1.0 + 2.0 / rho <= JACOBI_MAX_CONDITION:
            return "cg"
    return "direct" if n <= DIRECT_MAX else "amg"


def make_solver(A: sp.spmatrix, backend: str = "auto", laplacian_diagonal: np.ndarray | None = None,
                rtol: float = 1e-12, previous=None):
    """A solver for the SPD matrix ``A`` (module docstring). ``previous``: the solver of an earlier matrix of the same
    size that changed little since (a refreshed network, the next Newton or time step); when both are AMG, its
    hierarchy preconditions ``A`` (no setup; :class:`AMGSolver`, ``hierarchy_of``).

    Parameters
    ----------
    A : scipy.sparse.spmatrix
        The symmetric positive definite matrix (e.g. W/K).
    backend : str
        ``"auto"`` or one of ``BACKENDS``.
    laplacian_diagonal : numpy.ndarray or None
        The Laplacian's part of the diagonal, for ``"auto"``; None: the whole diagonal.
    rtol : float
        The relative residual of the iterative backends.
    previous : object or None
        The solver of an earlier matrix of the same size; None: none.

    Returns
    -------
    object
        A solver with ``solve(b, x0=None)``.

    Raises
    ------
    ValueError
        ``backend`` is unknown.
    """
    if backend == "auto":
        backend = choose_backend(A, A.diagonal() if laplacian_diagonal is None else laplacian_diagonal)
        if backend == "cg":
            return AutoCGSolver(A, rtol, "direct" if A.shape[0] <= DIRECT_MAX else "amg")
    if backend not in BACKENDS:
        raise ValueError(f"solver.linear = {backend!r}: must be one of auto, {', '.join(BACKENDS)}")
    if backend == "amg" and isinstance(previous, AMGSolver) and previous.A.shape == A.shape:
        return AMGSolver(A, rtol=rtol, hierarchy_of=previous)
    return BACKENDS[backend](A, rtol=rtol)
