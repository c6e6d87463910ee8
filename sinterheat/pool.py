"""Independent jobs over worker processes: a pool on this machine, or a Dask cluster.

The sweeps of the CLIs -- ``python -m fem_neck fit`` and ``unequal``, ``python -m verification sintering`` and
``lattices``, the size sweeps of ``python -m benchmarks`` -- hand their independent jobs to the pool of
:func:`pool`:

* by default, worker processes of this machine (``concurrent.futures``: started in a fraction of a second), or this
  process itself when one worker (or one job) is asked for; forked, unless numba's threads in this process are GNU
  OpenMP's (:func:`sinterheat.threads.openmp_started`), which a forked child cannot use: then spawned;
* inside :func:`use_dask` -- what the CLIs' ``--scheduler`` does -- a ``dask.distributed`` cluster: ``"local"``
  starts a ``LocalCluster`` of one-thread worker processes on this machine (several seconds), any other value is the
  address of a running scheduler (``tcp://host:8786``, e.g. one that dask-jobqueue started on SLURM). Dask is an
  optional extra (``pip install '.[dask]'``); nothing imports it outside :func:`use_dask`.

A job is a module-level function with picklable arguments, so that a worker on another machine imports it by name:
those workers need the same sinterheat installed, and a job that writes files writes them on its worker's file
system (a folder that jobs write into must be one the workers share, as a cluster's home or scratch is). A Dask
worker runs one of these jobs at a time, whatever its thread count (gmsh and the solvers hold one state per
process).

:func:`run_jobs` runs a list of jobs and yields their results as they finish (a tqdm bar, the run's
:func:`sinterheat.interrupt.where`); a pool itself serves callers that submit more as results arrive (a grid whose
runs start from other runs' states): ``submit(func, *args, priority=...)`` returns a future (``result()``),
``wait(futures)`` blocks until at least one has finished and returns those that have, ``slots`` is how many jobs
run at once (``None``: as many as are submitted; a Dask scheduler starts the waiting job of highest ``priority``
first, a local pool the one submitted first).

Ctrl-C. Local workers ignore SIGINT (:func:`sinterheat.interrupt.ignore_interrupts`, started under
:func:`sinterheat.interrupt.shielded`, as are a ``LocalCluster``'s); the parent stops the pool. A local worker also
ends when its parent does, however the parent ended (a SIGKILL, the OOM killer). On Dask the jobs not
started are cancelled and a ``LocalCluster`` started here is closed; a job already running on a remote cluster runs
to its end there (Dask does not stop a running task), so its files may still land after the command has left.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import sys
import threading
import time
import uuid
from concurrent import futures as cf

from sinterheat.interrupt import ignore_interrupts, shielded, stop_pool, where
from sinterheat.threads import openmp_started

INSTALL = "pip install '.[dask]' (in the repository; or pip install 'dask[distributed]')"  #: how to get Dask
LOCAL = "local"  #: the ``--scheduler`` value that starts a LocalCluster on this machine
CONNECT_TIMEOUT = 10.0  #: s to reach a scheduler before giving up
POLL_INTERVAL = 0.02  #: s between looks at the Dask jobs' states (:meth:`DaskPool.wait`)
_client = None  # the Dask client of the enclosing use_dask(), if any


def dask_available() -> bool:
    """Whether ``dask.distributed`` can be imported (without importing it)."""
    import importlib.util

    return importlib.util.find_spec("distributed") is not None


def check_scheduler(scheduler: str) -> str:
    """``scheduler`` if Dask is installed and the value can name one (``"local"`` or an address), else
    ``ValueError`` saying what is wrong (and how to install Dask).

    Parameters
    ----------
    scheduler : str
        ``"local"`` or a scheduler's address (``tcp://host:8786``).
    """
    if not dask_available():
        raise ValueError(f"scheduler = {scheduler!r}: Dask is not installed; {INSTALL}")
    if not scheduler or scheduler != scheduler.strip() or " " in scheduler:
        raise ValueError(f"scheduler = {scheduler!r}: must be {LOCAL!r} or a scheduler address such as "
                         "tcp://host:8786")
    return scheduler


@contextlib.contextmanager
def use_dask(scheduler, workers: int | None = None):
    """Within the block, every :func:`pool` is the Dask cluster ``scheduler`` (module docstring): ``"local"`` (a
    ``LocalCluster`` of ``workers`` processes, default all cores, closed at the end), a scheduler's address (a
    scheduler that cannot be reached within :data:`CONNECT_TIMEOUT` is an ``OSError``), or a
    ``distributed.Client`` of the caller's (used as it is); ``None`` changes nothing. When the block ends by an
    error or an interrupt, Dask's log lines while it closes (jobs cancelled, workers killed) are silenced: the
    error's one line is what the user reads.

    Parameters
    ----------
    scheduler : str or distributed.Client or None
        ``"local"``, a scheduler's address, a client, or None.
    workers : int, optional
        Worker processes of a ``"local"`` cluster; default all cores.
    """
    global _client
    if scheduler is None:
        yield None
        return
    logs = [logging.getLogger(name) for name in ("distributed", "tornado.application")]  # Dask and its event loop
    levels = [log.level for log in logs]
    try:
        with contextlib.ExitStack() as stack:
            client = scheduler if not isinstance(scheduler, str) else _connect(stack, scheduler, workers)
            previous, _client = _client, client
            try:
                yield client
            except BaseException:
                for log in logs:
                    log.setLevel(logging.CRITICAL)
                raise
            finally:
                _client = previous
    finally:
        for log, level in zip(logs, levels):
            log.setLevel(level)


def _connect(stack: contextlib.ExitStack, scheduler: str, workers: int | None):
    """A ``distributed.Client`` of ``scheduler`` (``"local"``: on a new ``LocalCluster``), closed with ``stack``."""
    check_scheduler(scheduler)
    from distributed import Client, LocalCluster

    if scheduler == LOCAL:
        # SIGINT blocked in its event-loop thread and so in every worker process it spawns; its HTTP server on a
        # free port (another cluster may hold the default 8787); its workers' own log lines silenced (a worker whose
        # heartbeat finds the scheduler closed while the cluster shuts down logs an error with a traceback on the
        # shared stderr): a job's error reaches this process as its exception
        with shielded():
            cluster = stack.enter_context(LocalCluster(
                n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                dashboard_address=":0", scheduler_kwargs={"dashboard": False}, silence_logs=logging.CRITICAL))
        return stack.enter_context(Client(cluster))
    try:
        return stack.enter_context(Client(scheduler, timeout=CONNECT_TIMEOUT))
    except OSError as exc:
        raise OSError(f"scheduler {scheduler}: cannot connect ({' '.join(str(exc).split())})") from None


def pool(workers: int | None = None, *, start: str = "fork"):
    """The pool jobs go to, as a context manager (module docstring): the Dask cluster of :func:`use_dask` if one is
    in use, else ``workers`` local processes (default: all cores), started by ``start`` (``"fork"``: warm, with what
    this process imported; ``"spawn"``: fresh interpreters), or this process itself for one worker.

    Parameters
    ----------
    workers : int, optional
        Number of local worker processes; default all cores (ignored on Dask).
    start : str
        Start method of local workers: ``"fork"`` or ``"spawn"``.
    """
    if _client is not None:
        return DaskPool(_client)
    workers = workers or os.cpu_count() or 1
    return InProcess() if workers == 1 else ProcessPool(workers, start)


class InProcess:
    """Jobs run in this process, one by one, each when it is waited for (so results still come one at a time)."""

    slots = 1

    def __init__(self):
        self._queued = {}

    def submit(self, func, *args, priority: float = 0.0) -> cf.Future:
        """Queue ``func(*args)``; it runs when its future is waited for.

        Parameters
        ----------
        func : callable
            The job: a picklable function (for process and Dask pools).
        args : object
            Its positional arguments.
        priority : float
            Ignored (the jobs run in the order they are waited for).
        """
        future = cf.Future()
        self._queued[future] = (func, args)
        return future

    def wait(self, futures) -> set:
        """Run the first queued job of ``futures`` unless one is done already; the futures that are done.

        Parameters
        ----------
        futures : iterable of concurrent.futures.Future
            Futures this pool's :meth:`submit` returned.
        """
        done = {f for f in futures if f.done()}
        if done:
            return done
        future = next(f for f in futures if f in self._queued)
        func, args = self._queued.pop(future)
        try:
            future.set_result(func(*args))
        except Exception as exc:  # raised by result(), as from a worker
            future.set_exception(exc)
        return {future}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._queued.clear()


class ProcessPool:
    """``workers`` processes of this machine that ignore SIGINT; stopped at once when the block ends by an error.

    Parameters
    ----------
    workers : int
        Number of worker processes.
    start : str
        Start method: ``"fork"`` (falls back to ``"spawn"`` where fork is unsafe or missing) or ``"spawn"``.
    """

    def __init__(self, workers: int, start: str):
        method = start if start in multiprocessing.get_all_start_methods() else "spawn"
        if method == "fork" and openmp_started():  # a forked worker's first parallel loop would end it
            method = "spawn"
        self.slots = workers
        self._executor = cf.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context(method),
                                                initializer=_worker_start)

    def submit(self, func, *args, priority: float = 0.0) -> cf.Future:
        """Start ``func(*args)`` on a worker process; its future.

        Parameters
        ----------
        func : callable
            The job: a picklable function (for process and Dask pools).
        args : object
            Its positional arguments.
        priority : float
            Ignored (the executor runs jobs in the order submitted).
        """
        with shielded():  # a worker started here cannot catch the Ctrl-C meant for this process
            return self._executor.submit(func, *args)

    def wait(self, futures) -> set:
        """The futures of ``futures`` that are done, once one is.

        Parameters
        ----------
        futures : iterable of concurrent.futures.Future
            Futures this pool's :meth:`submit` returned.
        """
        return cf.wait(list(futures), return_when=cf.FIRST_COMPLETED).done

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        if exc_type is None:
            self._executor.shutdown()
        else:
            stop_pool(self._executor)


def end_with_parent() -> None:
    """In a worker process: end it when its parent ends, however the parent ended. A parent killed outright
    (SIGKILL, the OOM killer) cannot stop its workers, which would wait for their next job for ever, holding their
    memory: a thread waits for the parent to end. Outside a child of ``multiprocessing`` it does nothing."""
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with, args=(parent,), name="sinterheat-parent", daemon=True).start()


def _worker_start() -> None:
    """Initializer of the local workers: they ignore SIGINT (:func:`sinterheat.interrupt.ignore_interrupts`) and
    end with their parent (:func:`end_with_parent`)."""
    ignore_interrupts()
    end_with_parent()


def _exit_with(parent) -> None:
    parent.join()  # returns once the parent process has ended
    os._exit(1)


_ONE_AT_A_TIME = threading.Lock()


def _alone(func, *args):
    """A job on a Dask worker: one at a time in its process, whatever the worker's thread count."""
    with _ONE_AT_A_TIME:
        return func(*args)


class DaskPool:
    """Jobs on the cluster of a ``distributed.Client``; those not started are cancelled when the block ends by an
    error (Ctrl-C included).

    Parameters
    ----------
    client : distributed.Client
        The connected client of the cluster.
    """

    slots = None

    def __init__(self, client):
        self._client = client
        self._submitted = []

    def submit(self, func, *args, priority: float = 0.0):
        """Start ``func(*args)`` on the cluster, one job at a time per worker process; its Dask future.

        Parameters
        ----------
        func : callable
            The job: a picklable function.
        args : object
            Its positional arguments.
        priority : float
            Dask's scheduling priority (higher runs first).
        """
        key = f"{getattr(func, '__name__', 'job')}-{uuid.uuid4().hex}"
        future = self._client.submit(_alone, func, *args, key=key, priority=priority, pure=False)
        self._submitted.append(future)
        return future

    def wait(self, futures) -> set:
        """The futures of ``futures`` that are done, once one is. Polled here rather than waited for in
        ``distributed.wait``: a Ctrl-C that lands inside distributed's blocking call leaves its event loop a callback
        that fails with a traceback on stderr; here it lands in ``time.sleep``.

        Parameters
        ----------
        futures : iterable of distributed.Future
            Futures this pool's :meth:`submit` returned.
        """
        while True:
            done = {future for future in futures if future.done()}  # the client's own state: no round trip
            if done:
                return done
            time.sleep(POLL_INTERVAL)

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        if exc_type is not None:
            with contextlib.suppress(Exception):
                self._client.cancel([f for f in self._submitted if not f.done()])
        self._submitted.clear()


def bar_switch(progress: bool) -> dict:
    """The ``tqdm`` keywords of a study's bar: off when ``progress`` is false or ``TQDM_DISABLE`` is set (the
    command-line tools set it for ``--no-progress``). The variable is read here, when the bar is made: tqdm reads it
    once, when it is imported, which may be before the tool sets it.

    Parameters
    ----------
    progress : bool
        Whether the caller wants a bar.
    """
    return {"disable": True} if not progress or os.environ.get("TQDM_DISABLE") else {}


def run_jobs(jobs, workers: int | None = None, *, start: str = "fork", desc: str = "", unit: str = "job",
             progress: bool = True, done: int = 0, alongside: ProcessPool | None = None):
    """Run ``func(*args)`` for every ``(func, args)`` of ``jobs`` on :func:`pool` (one job: in this process unless
    on Dask); yield the results as they finish.

    ``alongside``: a local pool the caller has started already (the process that draws a sweep's figure, say, idle
    until the sweep ends), whose processes take jobs beside this process, which runs jobs too: of the ``workers``
    processes, this one and those of ``alongside`` are counted, and only the rest are started (none, for two workers
    and one process alongside), so fewer processes are forked, each of which costs more CPU than a short job
    (``_shared``). Not on Dask, and not for one worker (then the jobs run in this process alone).

    A tqdm bar on stderr counts ``done`` jobs finished earlier plus these, and so does the run's
    :func:`sinterheat.interrupt.where` (its step: ``"<desc>: k of n <unit>s done"``). On an interrupt, an error, or
    when the caller stops iterating, the pool is stopped at once.

    Parameters
    ----------
    jobs : list of tuple
        ``(func, args)`` pairs: each job is ``func(*args)``.
    workers : int, optional
        Local worker processes; default all cores (at most one per job).
    start : str
        Start method of local workers: ``"fork"`` or ``"spawn"``.
    desc : str
        Label of the bar and of the interrupt line.
    unit : str
        What a job is called in the bar (``"solve"``, ...).
    progress : bool
        Draw the bar.
    done : int
        Jobs finished earlier (a resumed sweep), counted in the bar's total.
    alongside : ProcessPool or None
        A local pool of the caller's whose processes take jobs beside this one (it is not stopped here).
    """
    from tqdm import tqdm

    here = where()
    label = f"{desc}: " if desc else ""
    total = done + len(jobs)
    here.update(step=f"{label}{done} of {total} {unit}s done")
    if not jobs:
        return
    processes = min(workers or os.cpu_count() or 1, len(jobs))
    shared = alongside is not None and processes > 1 and _client is None
    more = processes - 1 - alongside.slots if shared else 0
    with tqdm(total=total, initial=done, desc=desc, unit=unit, file=sys.stderr, **bar_switch(progress)) as bar, \
            contextlib.ExitStack() as stack:
        if shared:
            pools = [alongside] + ([stack.enter_context(ProcessPool(more, start))] if more > 0 else [])
            results = _shared(jobs, pools)
        else:
            results = _submitted(jobs, stack.enter_context(pool(processes, start=start)))
        for result in results:
            bar.update()
            yield result
            done += 1  # counted once the caller has taken it (e.g. written it to a file)
            here.update(step=f"{label}{done} of {total} {unit}s done")


def _submitted(jobs, jobs_pool):
    """The results of ``jobs`` (``(func, args)`` pairs), all submitted to ``jobs_pool`` at once, as they finish."""
    running = [jobs_pool.submit(func, *args) for func, args in jobs]
    while running:
        finished = jobs_pool.wait(running)
        running = [f for f in running if f not in finished]
        for future in finished:
            yield future.result()


def _shared(jobs, pools):
    """The results of ``jobs`` (``(func, args)`` pairs) as they finish, run by the local ``pools`` and by this
    process: each pool is handed the jobs in order, one more than it has slots (so that none of its processes waits
    for the next), and whenever none of theirs has finished this process runs the last job not yet handed out."""
    waiting = list(jobs)
    running = {}  # future: its pool
    while waiting or running:
        for jobs_pool in pools:
            while waiting and sum(p is jobs_pool for p in running.values()) <= jobs_pool.slots:
                func, args = waiting.pop(0)
                running[jobs_pool.submit(func, *args)] = jobs_pool
        finished = {f for f in running if f.done()}
        if not finished and waiting:
            func, args = waiting.pop()
            yield func(*args)
            continue
        if not finished:
            finished = cf.wait(list(running), return_when=cf.FIRST_COMPLETED).done
        for future in finished:
            del running[future]
            yield future.result()
