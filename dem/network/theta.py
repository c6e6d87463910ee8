r"""The :math:`\theta` method's step of a heat network, written once, with its linear solve a plug-in.

One step of size ``dt`` from ``T`` solves :math:`(C/\Delta t + \theta A) T^+ = (C/\Delta t - (1-\theta) A) T + r` (:math:`\theta` = 0 explicit
forward Euler, 1 implicit backward Euler, 1/2 Crank-Nicolson; :mod:`dem.network.heat`, Rojek 2022, eqs. 2-4 in
time). :class:`ThetaStepper` assembles the system and its right-hand side from a :class:`dem.network.heat.Network`
(or a network with massless nodes, :class:`dem.network.necks.NeckHeat`: ``C = 0`` on its necks),
keeps one solver per step size and estimates a step's local error (the adaptive controller of
:func:`dem.network.heat.integrate`, whose loop around the step is the same on one process and on MPI ranks); the
solve itself is a plug-in with ``build``, ``solve``, ``everything_fixed`` and ``extrapolated_starts``:

* :class:`LocalSolves` -- one process: scipy's direct solver or CG preconditioned by pyamg's multigrid
  (:func:`dem.network.linsolve.make_solver`);
* :class:`dem.network.distributed.RankSolves` -- the rows of every rank, CG on PETSc (KSP) across them.

Either way an iterative solve is shifted uniformly, by an amount of the order of its tolerance, so that its residuals
sum to zero (:func:`balancing_shift`): the step's heat balance holds to round-off.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from dem.network.linsolve import make_solver

ORDER = {0.0: 1, 1.0: 1, 0.5: 2}  # order q of the theta method
CACHED_SOLVERS = 8  # the solvers a stepper keeps, one per step size (the least recently used dropped)


def balancing_shift(residual: float, weight: float) -> float:
    r"""The uniform shift of an iterative solve's temperatures that makes its residuals sum to zero (the module
    docstring's energy bookkeeping): ``residual / weight``; 0 where ``weight`` came out 0, the capacities ``C/dt``
    lost to round-off next to the conductances in the matrix's row sums, whose run the heat balance check then
    refuses (``energy_error``) instead of dividing by zero.

    Parameters
    ----------
    residual : float
        The sum of the solve's residuals ``b - M T`` (W).
    weight : float
        The sum of the entries of the step's matrix :math:`M = C/\Delta t + \theta A` (W/K).

    Returns
    -------
    float
        The shift (K).
    """
    return residual / weight if weight > 0.0 else 0.0


class LocalSolves:
    r"""The linear solves of :math:`\theta` steps on one process (module docstring): a solver per system from
    :func:`dem.network.linsolve.make_solver`, an iterative one's solution balanced (:func:`balancing_shift`).

    Parameters
    ----------
    linear : str
        The linear solver (``dem.network.linsolve.BACKENDS``, or ``"auto"``).
    rtol : float
        The relative residual of iterative solves.
    """

    #: An iterative solve starts from the temperatures extrapolated from the last steps (:meth:`ThetaStepper.guess`).
    extrapolated_starts = True

    def __init__(self, linear: str, rtol: float):
        self.linear, self.rtol = linear, rtol

    @staticmethod
    def everything_fixed(net) -> bool:
        """Whether ``net`` has no free particle (nothing evolves).

        Parameters
        ----------
        net : dem.network.heat.Network
            The network.

        Returns
        -------
        bool
            No free particle.
        """
        return net.n_free == 0

    def build(self, M: sp.csr_matrix, laplacian_diagonal: np.ndarray, previous=None):
        r"""The solver of the step's system ``M``.

        Parameters
        ----------
        M : scipy.sparse.csr_matrix
            :math:`C/\Delta t + \theta A` over the free particles (W/K).
        laplacian_diagonal : numpy.ndarray
            The Laplacian's part of its diagonal (W/K), for the ``"auto"`` choice.
        previous : object or None
            The solver of the last system of this step size, whose AMG hierarchy a changed matrix reuses; None.

        Returns
        -------
        object
            The solver (``name``; ``solve(b, x0)``).
        """
        return make_solver(M, self.linear, laplacian_diagonal, self.rtol, previous=previous)

    @staticmethod
    def solve(solver, rhs: np.ndarray, guess: np.ndarray) -> np.ndarray:
        """The step's temperatures: ``solver`` on ``rhs`` from ``guess``, balanced where the solve is iterative.

        Parameters
        ----------
        solver : object
            A solver of :meth:`build`.
        rhs : numpy.ndarray
            The right-hand side per free particle (W).
        guess : numpy.ndarray
            The start of an iterative solve (K or degC).

        Returns
        -------
        numpy.ndarray
            The free temperatures after the step.
        """
        T_new = solver.solve(rhs, guess)
        if solver.name != "direct":
            T_new += balancing_shift(float(np.sum(rhs - solver.A @ T_new)), float(solver.A.sum()))
        return T_new


class ThetaStepper:
    """Theta-method steps on ``net`` (module docstring); the system solver is built once per step size (cached,
    least recently used dropped), and where the matrix changes every step (radiation) the new step's solver is
    given the cached one (an AMG hierarchy to reuse).

    Parameters
    ----------
    net : dem.network.heat.Network
        The network (on several ranks that of this rank's held particles, ``DistributedNetwork.net``).
    theta : float
        0 (explicit), 1 (implicit) or 0.5 (Crank-Nicolson).
    solves : LocalSolves or dem.network.distributed.RankSolves
        The linear solves (module docstring).
    """

    def __init__(self, net, theta: float, solves):
        self.net, self.theta, self.solves = net, theta, solves
        self.linear_sinks = net.sources.radiation is None
        self._cache: dict = {}
        self.factorizations = 0
        self.backend = "none"
        self.A0 = net.matrix(net.sinks(net.initial)) if self.linear_sinks else None
        self.history: list = []  # (T, dt) at the start of the last two accepted steps: warm starts for CG
        self._rate: tuple = (None, None)
        self.everything_fixed = solves.everything_fixed(net)

    def _solver(self, dt: float, A: sp.csr_matrix, same_matrix: bool):
        """The solver of the step size ``dt``: the cached one when the matrix is that of the last step of this size
        (``same_matrix``: no radiation), else one for the new matrix, given the cached one (radiation's
        linearisation changes the diagonal a little from step to step)."""
        last = self._cache.pop(dt, None)
        if last is not None and same_matrix:
            self._cache[dt] = last  # most recently used last
            return last
        M = A * self.theta
        M = (M + sp.diags(self.net.C / dt)).tocsr()
        solver = self.solves.build(M, self.net.base_diag * self.theta, last)
        self.factorizations += 0 if getattr(solver, "reused", False) else 1
        self.backend = solver.name
        if len(self._cache) >= CACHED_SOLVERS:
            self._cache.pop(next(iter(self._cache)))
        self._cache[dt] = solver
        return solver

    def guess(self, T: np.ndarray, dt: float) -> np.ndarray:
        """Start of the iterative solve: quadratic extrapolation at a constant step, else linear, else ``T``; ``T``
        where the solves take no extrapolated start (``extrapolated_starts``).

        Parameters
        ----------
        T : numpy.ndarray
            The free temperatures at the step's start (K or degC).
        dt : float
            The step (s).

        Returns
        -------
        numpy.ndarray
            The start.
        """
        h = self.history if self.solves.extrapolated_starts else []
        if len(h) == 2 and h[0][1] == dt and h[1][1] == dt:
            return 3.0 * (T - h[0][0]) + h[1][0]
        if h:
            return T + (T - h[0][0]) * (dt / h[0][1])
        return T

    def accept(self, T: np.ndarray, dt: float):
        """Record an accepted step of size ``dt`` that started from ``T``.

        Parameters
        ----------
        T : numpy.ndarray
            The free temperatures at the step's start (K or degC).
        dt : float
            The step (s).
        """
        self.history = [(T, dt)] + self.history[:1]

    def rate(self, T: np.ndarray):
        """``(dT/dt, sinks)`` at ``T``; the last one is kept (an explicit step and its error estimate share it).

        Parameters
        ----------
        T : numpy.ndarray
            The free temperatures (K or degC).

        Returns
        -------
        tuple
            ``(dT/dt in K/s, {name: (g, b)})``.
        """
        if self._rate[0] is not T:
            sinks = self.net.sinks(T)
            A = self.A0 if self.linear_sinks else self.net.matrix(sinks)
            C = self.net.C  # a massless node (a neck, dem.network.necks) has no rate of its own: 0
            self._rate = (T, (np.divide(self.net.rhs(sinks) - A @ T, C, out=np.zeros(len(C)), where=C > 0.0), sinks))
        return self._rate[1]

    def step(self, T: np.ndarray, dt: float, guess: np.ndarray | None = None):
        """One step of size ``dt`` from ``T``.

        Parameters
        ----------
        T : numpy.ndarray
            The free temperatures at the step's start (K or degC).
        dt : float
            The step (s).
        guess : numpy.ndarray or None
            The start of an iterative solve; None: :meth:`guess`.

        Returns
        -------
        tuple
            ``(T_new, T_theta, sinks)``: the temperatures after the step, their theta-weighted mean with ``T`` (the
            step's flows are those at ``T_theta``) and the ambient terms ``{name: (g, b)}``.
        """
        net = self.net
        if self.everything_fixed:  # nothing evolves
            return T, T, net.sinks(T)
        if self.theta == 0.0:
            f, sinks = self.rate(T)
            return T + dt * f, T, sinks
        sinks = net.sinks(T)
        A = self.A0 if self.linear_sinks else net.matrix(sinks)
        rhs = net.C / dt * T + net.rhs(sinks)
        if self.theta < 1.0:
            rhs -= (1.0 - self.theta) * (A @ T)
        solver = self._solver(dt, A, self.linear_sinks)
        T_new = self.solves.solve(solver, rhs, self.guess(T, dt) if guess is None else guess)
        self.backend = solver.name
        return T_new, self.theta * T_new + (1.0 - self.theta) * T, sinks

    def estimated_step(self, T: np.ndarray, dt: float):
        """One step with an estimate of its local error: ``(T_new, parts, error)`` with ``parts`` the
        ``(dt, T_theta, sinks)`` of the sub-steps taken (for the energy bookkeeping) and ``error`` the max-norm
        estimate of the local error of a step of size ``dt``.

        Explicit (forward Euler): the difference to Heun's step, ``dt/2 |f(T_new) - f(T)|``; ``f(T_new)`` starts
        the next step, so the estimate costs nothing. Implicit and Crank-Nicolson: step doubling, :math:`|T_2 - T_1| /
        (2^q - 1)` with ``T_1`` one step of ``dt`` and ``T_2`` two of ``dt/2`` (the solution kept, the more
        accurate one); with ``dt`` a power of 2 times a base step both solvers stay cached as the step grows.

        Parameters
        ----------
        T : numpy.ndarray
            The free temperatures at the step's start (K or degC).
        dt : float
            The step (s).

        Returns
        -------
        tuple
            ``(T_new, parts, error)``; ``error`` in the temperatures' unit.
        """
        if self.theta == 0.0:
            T_new, T_theta, sinks = self.step(T, dt)
            f0, f1 = self.rate(T)[0], self.rate(T_new)[0]
            return T_new, [(dt, T_theta, sinks)], 0.5 * dt * float(np.max(np.abs(f1 - f0), initial=0.0))
        half = 0.5 * dt
        T_a, th_a, s_a = self.step(T, half)
        T_b, th_b, s_b = self.step(T_a, half, 2.0 * T_a - T)
        T_1 = self.step(T, dt, T_b)[0]
        q = ORDER[self.theta]
        err = float(np.max(np.abs(T_b - T_1), initial=0.0)) / (2.0**q - 1.0)
        return T_b, [(half, th_a, s_a), (half, th_b, s_b)], err
