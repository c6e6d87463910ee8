r"""A network's matrix over several MPI ranks as a PETSc MPIAIJ matrix, solved by conjugate gradients with an
algebraic multigrid preconditioner (petsc4py, imported only by a distributed run).

Each rank gives its own rows, in CSR with global column numbers (:func:`matrix`); :class:`PetscSolver` solves with
them to the project's criterion ``|b - A x| <= rtol |b|`` (the unpreconditioned residual, as
:class:`dem.network.linsolve.PCGSolver`). The preconditioner by default (``DEFAULTS``) is the first available of

* Trilinos ML (smoothed aggregation): the fastest on the project's 10^6-particle steady network, 2.8-3.0 s for setup
  and solve on one rank and 1.6-1.75 s on two;
* hypre BoomerAMG with HMIS coarsening, ext+i interpolation, strong threshold 0.5, at most 4 interpolation entries per
  row and one level of aggressive coarsening: 3.9-4.3 / 2.1-2.2 s (PETSc's default hypre options: 17.1 / 11.1 s);
* PETSc's own GAMG: 4.6-5.0 / 2.4-2.5 s.

CG stops at that residual or after ``max_iterations``, never on PETSc's divergence test: in a step far above the
network's stiffest time constant (``C/dt`` far below the conductances) the right-hand side ``|b| ~ C/dt |T|`` is tiny
next to the residual of the warm start, :math:`\sim K |\Delta T|`, and the default test (a residual above ``1e5 |b|``) ended
such a solve before its first iteration, where the serial CG converges.

Every option can be set by the user through PETSc's options database, which these defaults never override: the
environment variable ``PETSC_OPTIONS`` (``PETSC_OPTIONS="-pc_type gamg -ksp_monitor" mpiexec -n 4 python -m dem run
...``) or a ``.petscrc`` file in the working directory.
"""

from __future__ import annotations

import numpy as np

NO_DIVERGENCE_TEST = 1e300  # KSP's divtol: never reached (module docstring)
# the preconditioners in order of preference, each with its tuned options (module docstring)
DEFAULTS = (
    ("ml", {}),
    ("hypre", {"pc_hypre_type": "boomeramg", "pc_hypre_boomeramg_coarsen_type": "HMIS",
               "pc_hypre_boomeramg_interp_type": "ext+i", "pc_hypre_boomeramg_strong_threshold": "0.5",
               "pc_hypre_boomeramg_P_max": "4", "pc_hypre_boomeramg_agg_nl": "1"}),
    ("gamg", {}),
)


def petsc():
    """The ``PETSc`` module, initialised (from the options database: ``PETSC_OPTIONS``, ``.petscrc``)."""
    try:
        import petsc4py

        petsc4py.init()
        from petsc4py import PETSc
    except ImportError as exc:
        raise ValueError(f"a distributed run needs petsc4py, which is not importable ({exc}); install the MPI extra "
                         f"(README: the block after 'mpi-command') and set PETSC_DIR") from None
    return PETSc


def matrix(comm, rows, n_global: int):
    """The PETSc MPIAIJ matrix whose rows on this rank are ``rows`` (scipy CSR, columns numbered globally, sorted);
    the ranks' rows follow each other in rank order.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    rows : scipy.sparse.csr_matrix
        This rank's rows, columns numbered globally and sorted.
    n_global : int
        The matrix's global size.

    Returns
    -------
    object
        The assembled matrix (a ``petsc4py.PETSc.Mat``).

    Raises
    ------
    ValueError
        petsc4py is not importable.
    """
    PETSc = petsc()
    n_local = rows.shape[0]
    A = PETSc.Mat().createAIJ(size=((n_local, n_global), (n_local, n_global)),
                              csr=(rows.indptr.astype(PETSc.IntType), rows.indices.astype(PETSc.IntType),
                                   rows.data), comm=comm)
    A.assemble()
    return A


def _preconditioner(PETSc) -> tuple[str, dict]:
    """The first preconditioner of ``DEFAULTS`` this PETSc has."""
    probe = PETSc.PC().create(comm=PETSc.COMM_SELF)
    try:
        for name, options in DEFAULTS:
            try:
                probe.setType(name)
            except PETSc.Error:
                continue
            return name, options
    finally:
        probe.destroy()
    return "jacobi", {}


class PetscSolver:
    """CG + AMG on a distributed matrix (module docstring): ``solve(b, x0)`` with ``b`` and ``x0`` this rank's
    entries; ``iterations`` sums the CG iterations of all solves, ``name`` says which preconditioner ran;
    :meth:`destroy` when done.

    Parameters
    ----------
    A : object
        The distributed symmetric positive definite matrix (:func:`matrix`).
    rtol : float
        The relative unpreconditioned residual at which CG stops.
    max_iterations : int
        The most CG iterations per solve.
    """

    def __init__(self, A, rtol: float = 1e-10, max_iterations: int = 10_000):
        PETSc = petsc()
        options = PETSc.Options()
        name, tuned = _preconditioner(PETSc)
        if not options.hasName("pc_type"):
            options["pc_type"] = name
            for key, value in tuned.items():
                if not options.hasName(key):
                    options[key] = value
        self.ksp = PETSc.KSP().create(comm=A.getComm())
        self.ksp.setOperators(A)
        self.ksp.setType("cg")
        self.ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        # no divergence test, as the serial CG has none: PETSc's default (a residual above 1e5 |b|) stopped the
        # stiff steps at their first iteration, whose warm start is far off |b| where C/dt << K (module docstring)
        self.ksp.setTolerances(rtol=rtol, atol=0.0, divtol=NO_DIVERGENCE_TEST, max_it=max_iterations)
        self.ksp.setFromOptions()
        self.ksp.setUp()
        pc = self.ksp.getPC()
        self.name = f"petsc-{self.ksp.getType()}-{pc.getType()}"
        self.A, self.iterations = A, 0
        self._x, self._b = A.createVecs()

    def destroy(self) -> None:
        """Free its PETSc objects now. Left to petsc4py's garbage collection, or alive together in numbers, ML
        preconditioners crashed this PETSc (3.18, Debian) with a segmentation fault after a few dozen solvers in one
        process; destroyed after use they do not."""
        for obj in (self.ksp, self.A, self._x, self._b):
            obj.destroy()

    def solve(self, b: np.ndarray, x0: np.ndarray | None = None) -> np.ndarray:
        """CG + AMG to ``|b - A x| <= rtol |b|``.

        Parameters
        ----------
        b : numpy.ndarray
            This rank's entries of the right-hand side (e.g. W).
        x0 : numpy.ndarray or None
            This rank's entries of a start; None: zero.

        Returns
        -------
        numpy.ndarray
            This rank's entries of ``x`` (e.g. K).

        Raises
        ------
        ValueError
            CG did not converge (the message gives PETSc's reason).
        """
        PETSc = petsc()
        self._b.setArray(b)
        self.ksp.setInitialGuessNonzero(x0 is not None)
        if x0 is not None:
            self._x.setArray(x0)
        self.ksp.solve(self._b, self._x)
        self.iterations += self.ksp.getIterationNumber()
        if self.ksp.getConvergedReason() < 0:
            reason = self.ksp.getConvergedReason()
            names = {v: k for k, v in vars(PETSc.KSP.ConvergedReason).items() if isinstance(v, int)}
            raise ValueError(f"PETSc {self.name} did not converge ({names.get(reason, reason)} after "
                             f"{self.ksp.getIterationNumber()} iterations, relative residual "
                             f"{self.ksp.getResidualNorm() / max(self._b.norm(), 1e-300):.3g}); set other options "
                             f"in PETSC_OPTIONS (e.g. -pc_type gamg)")
        return self._x.getArray().copy()


def largest_eigenvalue(comm, apply, n_local: int, rtol: float = 1e-10, max_iterations: int = 100) -> float:
    """The largest eigenvalue of a symmetric positive (semi)definite operator shared out among the ranks: the Lanczos
    estimate of conjugate gradients on it (PETSc's ``KSPComputeExtremeSingularValues``, no preconditioner) from a
    random start, after ``max_iterations`` steps or where CG reaches ``rtol`` (the largest eigenvalue of the Krylov
    space converges long before the solve does). It never exceeds the operator's.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    apply : callable
        ``apply(x)``: this rank's entries of the operator times ``x`` from this rank's entries of ``x``; called on
        every rank together (it may communicate).
    n_local : int
        This rank's entries.
    rtol : float
        The relative residual at which CG stops.
    max_iterations : int
        The most CG iterations (Lanczos steps).

    Returns
    -------
    float
        The estimate (the operator's unit; 0 for an empty operator).
    """
    PETSc = petsc()
    n_global = comm.allreduce(n_local)
    if n_global == 0:
        return 0.0

    class Operator:
        def mult(self, mat, x, y):
            y.setArray(apply(x.getArray(readonly=True).copy()))

    A = PETSc.Mat().createPython(((n_local, n_global), (n_local, n_global)), Operator(), comm=comm)
    A.setUp()
    ksp = PETSc.KSP().create(comm=comm)
    b, x = A.createVecs()
    try:
        ksp.setOperators(A)
        ksp.setType("cg")
        ksp.getPC().setType("none")
        ksp.setComputeSingularValues(True)
        ksp.setTolerances(rtol=rtol, atol=0.0, divtol=NO_DIVERGENCE_TEST, max_it=max_iterations)
        b.setArray(np.random.default_rng(comm.Get_rank()).uniform(-1.0, 1.0, n_local))
        ksp.solve(b, x)
        largest, _ = ksp.computeExtremeSingularValues()
    finally:
        for obj in (ksp, A, b, x):
            obj.destroy()
    return float(largest)
