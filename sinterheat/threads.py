"""How many threads the compiled loops (numba) and the linear algebra (BLAS) use: ``--threads N`` on the command
lines, the environment variable ``SINTERHEAT_THREADS`` for the Python API and as the commands' default, else every
core this process may run on.

:func:`count` is read when an engine is built (the engine binds its one-thread or its threaded loop then, never
inside the loop: :mod:`dem.engines.compiled`); :func:`use` sets the number for the rest of the process: numba's
threads, the BLAS libraries already loaded (threadpoolctl) and, through ``OMP_NUM_THREADS``, ``OPENBLAS_NUM_THREADS``
and ``MKL_NUM_THREADS``, those loaded later and child processes (which also inherit ``SINTERHEAT_THREADS``).
numba's threading layer is ``workqueue`` (numba's own, present everywhere; it needs neither TBB nor OpenMP, and its
idle threads sleep) unless ``NUMBA_THREADING_LAYER`` names another.
"""

from __future__ import annotations

import os

ENVIRONMENT = "SINTERHEAT_THREADS"
BLAS_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
THREADING_LAYER = "workqueue"

_chosen: int | None = None  # set by use()


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def check(value, name: str = "threads") -> int:
    """``value`` (an int or its text) as a thread count, 1 to :func:`cores`; else a ``ValueError`` naming ``name``."""
    limit = cores()
    try:
        number = int(str(value).strip())
    except ValueError:
        raise ValueError(f"{name} = {value!r}: must be an integer from 1 to {limit} (the cores of this machine)") \
            from None
    if not 1 <= number <= limit:
        raise ValueError(f"{name} = {number}: must be from 1 to {limit} (the cores of this machine)")
    return number


def count() -> int:
    """The threads to use: those of :func:`use`, else ``SINTERHEAT_THREADS``, else :func:`cores`."""
    if _chosen is not None:
        return _chosen
    value = os.environ.get(ENVIRONMENT)
    return cores() if value is None or not value.strip() else check(value, ENVIRONMENT)


def use(number: int) -> None:
    """Use ``number`` threads (checked by :func:`check`) from here on: numba's loops and BLAS (module docstring)."""
    global _chosen
    _chosen = check(number)
    for variable in (ENVIRONMENT, *BLAS_VARIABLES):  # the child processes (a sweep's workers) inherit them
        os.environ[variable] = str(_chosen)
    from threadpoolctl import threadpool_limits

    threadpool_limits(_chosen)


def bind_numba() -> int:
    """The thread count of :func:`count`, set as numba's for the calling thread when more than one (its threading
    layer chosen first, module docstring); returns it. Called where an engine binds its loop."""
    number = count()
    if number > 1:
        import numba

        if "NUMBA_THREADING_LAYER" not in os.environ:
            numba.config.THREADING_LAYER = THREADING_LAYER
        numba.set_num_threads(number)
    return number
