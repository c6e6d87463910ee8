"""How many threads the compiled loops (numba) and the linear algebra (BLAS) use: ``--threads N`` on the command
lines, the environment variable ``SINTERHEAT_THREADS`` for the Python API and as the commands' default, else every
core this process may run on.

:func:`count` is read when an engine is built (the engine binds its one-thread or its threaded loop then, never
inside the loop: :mod:`dem.engines.compiled`); :func:`use` sets the number for the rest of the process: numba's
threads, the BLAS libraries already loaded (threadpoolctl) and, through ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``
and ``MKL_NUM_THREADS``, those loaded later and child processes (which also inherit ``SINTERHEAT_THREADS``).
:func:`one_blas_thread` pins BLAS to one thread for a block of work.

numba's threading layer: GNU OpenMP (``omp``) where numba finds it, else its own ``workqueue``, unless
``NUMBA_THREADING_LAYER`` names one. OpenMP starts a parallel loop in about a microsecond, the workqueue in about a
tenth of a millisecond, and a step of the velocity-Verlet loop starts one (:mod:`dem.engines.verlet.loop`). GNU
OpenMP cannot be used again in a child forked from a process that used it (numba terminates that child), so once it
runs, the local pools spawn their workers instead of forking them (:func:`openmp_started`,
:class:`sinterheat.pool.ProcessPool`).
"""

from __future__ import annotations

import functools
import os
import sys

ENVIRONMENT = "SINTERHEAT_THREADS"
BLAS_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
# numba's threading layers, the first one found (module docstring); numba wants all three named, and TBB after the
# workqueue, which every numba has, is never reached
THREADING_LAYERS = ["omp", "workqueue", "tbb"]

_chosen: int | None = None  # set by use()


def cores() -> int:
    """The cores this process may run on, at most ``NUMBA_NUM_THREADS`` where the user set it (numba's pool then has
    no more threads, and asking it for more raises)."""
    try:
        number = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        number = os.cpu_count() or 1
    cap = os.environ.get("NUMBA_NUM_THREADS", "").strip()
    return min(number, int(cap)) if cap.isdigit() and int(cap) >= 1 else number


def check(value, name: str = "threads") -> int:
    """``value`` (an int or its text) as a thread count, 1 to :func:`cores`; else a ``ValueError`` naming ``name``.

    Parameters
    ----------
    value : int or str
        The thread count, or its text.
    name : str
        The parameter's name in the error message.
    """
    limit = cores()
    try:
        number = int(str(value).strip())
    except ValueError:
        raise ValueError(f"{name} = {value!r}: must be an integer from 1 to {limit} (the cores this process may use)") \
            from None
    if not 1 <= number <= limit:
        raise ValueError(f"{name} = {number}: must be from 1 to {limit} (the cores this process may use)")
    return number


def count() -> int:
    """The threads to use: those of :func:`use`, else ``SINTERHEAT_THREADS``, else :func:`cores`."""
    if _chosen is not None:
        return _chosen
    value = os.environ.get(ENVIRONMENT)
    return cores() if value is None or not value.strip() else check(value, ENVIRONMENT)


def share_among_ranks(ranks: int) -> None:
    """On ``ranks`` MPI ranks of one machine, each rank's share of its cores (:func:`use` of ``cores() // ranks``, at
    least 1) unless ``SINTERHEAT_THREADS`` or ``--threads`` chose the number: every rank's threads at once would
    oversubscribe the cores.

    Parameters
    ----------
    ranks : int
        The ranks of the run (``MPI_COMM_WORLD``'s size).
    """
    if not os.environ.get(ENVIRONMENT):
        use(max(1, cores() // ranks))


def use(number: int) -> None:
    """Use ``number`` threads (checked by :func:`check`) from here on: numba's loops and BLAS (module docstring).

    Parameters
    ----------
    number : int or str
        Thread count, 1 to :func:`cores`.
    """
    global _chosen
    _chosen = check(number)
    for variable in (ENVIRONMENT, *BLAS_VARIABLES):  # the child processes (a sweep's workers) inherit them
        os.environ[variable] = str(_chosen)
    from threadpoolctl import threadpool_limits

    threadpool_limits(_chosen)


def blas_on_one_thread() -> None:
    """BLAS on one thread in this process and its children, for a command whose BLAS work is all many small products
    (:func:`one_blas_thread`): ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS`` and ``MKL_NUM_THREADS`` set to 1 unless
    the user has set them. Called before numpy is first imported, it keeps the BLAS libraries from starting their
    thread pools at all: OpenBLAS's idle threads spin for about a tenth of a second after they start, in this process
    and again in every forked worker that sets the thread count (as :func:`one_blas_thread` does), which for a
    command of short solves is CPU time of the same order as the solves themselves. Called later, it reaches only the
    child processes started by ``spawn`` or a fresh interpreter."""
    for variable in BLAS_VARIABLES:
        os.environ.setdefault(variable, "1")


@functools.lru_cache(maxsize=None)
def _blas_pools():
    """The BLAS thread-pool controller (threadpoolctl), made once: limiting a pool then costs ~20 us."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def one_blas_thread():
    """A context in which BLAS runs on one thread, whatever :func:`use` chose: for work of many small products or
    vector operations between compiled kernels (the hp element matrices, the AMG setup), where a second BLAS thread
    only adds synchronisation and, on a busy machine, spins while waiting for a core."""
    return _blas_pools().limit(limits=1, user_api="blas")


def bind_numba() -> int:
    """The thread count of :func:`count`, set as numba's for the calling thread when more than one (its threading
    layer chosen first, module docstring); returns it. Called where an engine binds its loop."""
    number = count()
    if number > 1:
        import numba

        if "NUMBA_THREADING_LAYER" not in os.environ:
            numba.config.THREADING_LAYER = "default"
            numba.config.THREADING_LAYER_PRIORITY = list(THREADING_LAYERS)
        numba.set_num_threads(number)
    return number


def openmp_started() -> bool:
    """Whether numba's threads in this process are GNU OpenMP's (started by :func:`bind_numba` or a parallel loop):
    a child forked from it would be terminated at its own first parallel loop."""
    numba = sys.modules.get("numba")
    if numba is None:
        return False
    try:
        return numba.threading_layer() == "omp"
    except ValueError:  # no parallel loop has run yet: no layer chosen
        return False
