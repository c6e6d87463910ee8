"""The MPI side of a run over several processes: whether this run is one, its communicator, the exchange of halo
values between ranks and the reductions the engines on several ranks need.

A run is distributed when it was launched by ``mpiexec``/``srun`` with more than one rank (:func:`launched`, read
from the launcher's environment, so that a run without MPI imports neither mpi4py nor PETSc), or when asked with
``DEM_MPI=1`` (the distributed route on one rank: to time it against the serial one, or to test it).
"""

from __future__ import annotations

import os

import numpy as np

# the launchers' rank counts: Open MPI's mpiexec, MPICH/Intel MPI's Hydra and Slurm's srun (PMI, PMIx)
SIZE_VARIABLES = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS")
RANK_VARIABLES = ("OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK")
ASK_VARIABLE = "DEM_MPI"  # "1": the distributed route even on one rank


def launched() -> bool:
    """Whether this process is one of several MPI ranks (or ``DEM_MPI=1`` asks for the distributed route)."""
    if os.environ.get(ASK_VARIABLE, "") == "1":
        return True
    for name in SIZE_VARIABLES:
        value = os.environ.get(name, "")
        if value.isdigit() and int(value) > 1:
            return True
    return False


def launcher_rank() -> int:
    """This process's rank as its launcher set it (0 when none did), read without importing MPI."""
    for name in RANK_VARIABLES:
        value = os.environ.get(name, "")
        if value.isdigit():
            return int(value)
    return 0


def world():
    """``MPI.COMM_WORLD`` (mpi4py imported now); a ValueError naming the missing extra if it is not installed."""
    try:
        from mpi4py import MPI
    except ImportError as exc:
        raise ValueError(f"launched under MPI but mpi4py is not importable ({exc}); install the MPI extra (README: "
                         f"the block after 'mpi-command') or run without mpiexec") from None
    return MPI.COMM_WORLD


def agree(comm, action):
    """Run ``action()`` on every rank; if it raises a ValueError on any rank, raise it on all of them (with the first
    failing rank's message), so that no rank waits in a collective call for one that stopped.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    action : callable
        Called without arguments on every rank. It makes no collective call, or makes the same ones on every rank
        whatever raised before them (raising after them): else a rank that raised first leaves the others waiting.

    Returns
    -------
    object
        This rank's result of ``action()``.

    Raises
    ------
    ValueError
        ``action`` raised one on some rank.
    """
    message = None
    try:
        result = action()
    except ValueError as exc:
        message, result = " ".join(str(exc).split()), None
    messages = comm.allgather(message)
    failed = [m for m in messages if m is not None]
    if failed:
        raise ValueError(failed[0])
    return result


def on_root(comm, action):
    """``action()`` on rank 0 only, its result (or its ``ValueError``) on every rank of ``comm`` (None: no MPI, the
    action runs here).

    Parameters
    ----------
    comm : object or None
        The MPI communicator (an ``mpi4py.MPI.Comm``); None: no MPI.
    action : callable
        Called without arguments on rank 0.

    Returns
    -------
    object
        Rank 0's result, on every rank.

    Raises
    ------
    ValueError
        ``action`` raised one on rank 0.
    """
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


def reduction(name: str):
    """MPI's reduction operation ``name`` (mpi4py imported now), for a communicator's ``allreduce``.

    Parameters
    ----------
    name : str
        ``"SUM"``, ``"MAX"`` or ``"MIN"``.

    Returns
    -------
    object
        The operation (an ``mpi4py.MPI.Op``).
    """
    from mpi4py import MPI

    return {"SUM": MPI.SUM, "MAX": MPI.MAX, "MIN": MPI.MIN}[name]


def total(comm, value):
    """Sum over ranks of a number or an array.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    value : float or array_like
        This rank's part (any unit).

    Returns
    -------
    float or numpy.ndarray
        The sum, on every rank.
    """
    from mpi4py import MPI

    if np.isscalar(value):
        return comm.allreduce(value, op=MPI.SUM)
    out = np.array(value, dtype=float)
    comm.Allreduce(MPI.IN_PLACE, out, op=MPI.SUM)
    return out


def maximum(comm, value: float) -> float:
    """Largest value over ranks.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    value : float
        This rank's value.

    Returns
    -------
    float
        The maximum, on every rank.
    """
    from mpi4py import MPI

    return comm.allreduce(value, op=MPI.MAX)


def minimum(comm, value: float) -> float:
    """Smallest value over ranks.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    value : float
        This rank's value.

    Returns
    -------
    float
        The minimum, on every rank.
    """
    from mpi4py import MPI

    return comm.allreduce(value, op=MPI.MIN)


class HaloExchange:
    """Values of the particles another rank owns, brought to the ranks that hold them as halo.

    ``held`` the global indices of the particles this rank holds (sorted), ``owner`` the rank owning each of them.
    Built once (which entries each rank sends where); :meth:`fill` then copies the owners' values into the halo
    entries of an array over the held particles.

    Parameters
    ----------
    comm : object
        The MPI communicator (an ``mpi4py.MPI.Comm``).
    held : numpy.ndarray
        Global indices of the particles this rank holds, sorted.
    owner : numpy.ndarray
        The rank owning each held particle.
    """

    def __init__(self, comm, held: np.ndarray, owner: np.ndarray):
        self.comm = comm
        size, rank = comm.Get_size(), comm.Get_rank()
        halo = np.flatnonzero(owner != rank)
        order = np.argsort(owner[halo], kind="stable")
        self.receive_at = halo[order]  # local positions of the halo, grouped by owner
        self.receive_counts = np.bincount(owner[halo], minlength=size).astype(np.int64)
        self.send_counts = np.zeros(size, dtype=np.int64)
        comm.Alltoall(self.receive_counts, self.send_counts)
        wanted = np.empty(int(self.send_counts.sum()), dtype=np.int64)  # global indices the others need from me
        comm.Alltoallv([np.ascontiguousarray(held[self.receive_at]), (self.receive_counts, None)],
                       [wanted, (self.send_counts, None)])
        self.send_from = np.searchsorted(held, wanted)

    def fill(self, values: np.ndarray) -> np.ndarray:
        """``values`` (over the held particles, owned entries valid) with the halo entries set from their owners.

        Parameters
        ----------
        values : numpy.ndarray
            One value per held particle (any unit), changed in place.

        Returns
        -------
        numpy.ndarray
            ``values``.
        """
        sent = np.ascontiguousarray(values[self.send_from], dtype=float)
        received = np.empty(len(self.receive_at), dtype=float)
        self.comm.Alltoallv([sent, (self.send_counts, None)], [received, (self.receive_counts, None)])
        values[self.receive_at] = received
        return values
