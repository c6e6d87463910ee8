"""Whether this process runs under ``mpiexec``, and its communicator: what the driver asks before it builds an engine.
mpi4py is imported only when the run was launched by ``mpiexec`` (a plain run loads nothing of MPI)."""

from __future__ import annotations

import os

LAUNCH_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK")  # set by Open MPI's and MPICH's mpiexec


def launched() -> bool:
    """Whether this process was started by ``mpiexec``."""
    return any(name in os.environ for name in LAUNCH_VARIABLES)


def world():
    """MPI's world communicator."""
    try:
        from mpi4py import MPI
    except ImportError as exc:
        raise ValueError(f"mpiexec: this run was launched by mpiexec but mpi4py cannot be imported ({exc}); install "
                         f"mpi4py or run without mpiexec") from exc
    return MPI.COMM_WORLD


def on_root(comm, action):
    """``action()`` on rank 0 only, its result (or its ``ValueError``) on every rank of ``comm`` (None: no MPI, the
    action runs here)."""
    if comm is None:
        return action()
    error = result = None
    if comm.Get_rank() == 0:
        try:
            result = action()
        except ValueError as exc:
            error = str(exc)
    error, result = comm.bcast((error, result), root=0)
    if error is not None:
        raise ValueError(error)
    return result
