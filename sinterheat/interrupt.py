"""Ctrl-C is part of the interface: an interrupted run says where it stopped and where its partial results are.

The CLIs (``python -m fem_neck``, ``python -m dem``, ``python -m verification``) run their command through
:func:`run_command`. A Ctrl-C (SIGINT) anywhere in it -- in Python code, in a numpy, scipy or gmsh call (the
interrupt is raised when the call returns), in a tqdm bar, or while waiting for the worker processes of a parallel
sweep -- ends the run with one line on stderr and exit code 130 (128 + SIGINT, what a shell reports for Ctrl-C),
never a traceback::

    python -m fem_neck fit: interrupted at fit, fit sweep: 12 of 40 solves done; partial results in results/fit

SIGTERM (a batch scheduler's time limit, ``kill``) and SIGHUP (a closed terminal) are handled the same way: the run
keeps what it has (a ``dem run`` its last checkpoint, resumable) and ends with the line ``... interrupted by SIGTERM
at ...`` and exit code 128 + the signal (143, 129); a SIGHUP that ``nohup`` ignores stays ignored.

Long work says where it is by updating the current run's :class:`Where` (outside a CLI run :func:`where` returns a
throw-away one, so library code can always call it)::

    from sinterheat.interrupt import where
    where().update(stage="transient", step=k, t=t, out=folder)   # out: once usable files are in folder

Fields: ``stage`` (what is running), ``step`` (an int is shown as "step k"; a string as it is, e.g. "12 of 40
solves done"), ``t`` (simulated time, s) and ``out`` (the folder holding usable partial results; while it is
``None`` the line says "no results written").

How it holds. The first SIGINT raises ``KeyboardInterrupt`` and any further one is ignored, so clean-up
(``finally`` blocks, the report files, an open gmsh session, which :func:`interrupted` also finalizes) cannot be
cut short. C code may turn the interrupt into another error (numpy's import raises ``ImportError`` when it lands
there) or swallow it (in a weakref callback it is only "ignored"; in an extension module's import it can end as a
caught ``ImportError``): any error after a SIGINT counts as the interrupt, and a swallowed one is raised again at
the next :meth:`Where.update` or when the command returns (the unraisable hook keeps it off stderr). tqdm bars still
open are closed before the line is written, so it starts a line of its own. Workers of a process pool ignore SIGINT
(:func:`ignore_interrupts` as the pool's initializer, started inside :func:`shielded`, which holds a Ctrl-C back
until the pool knows every worker it started); the parent stops them (:func:`stop_pool`). :func:`exit_process` then
leaves with code 130 (Python's own exit would report a kill by SIGINT once the interrupt has passed through some
C-level imports). Before the CLI's ``main`` runs, :mod:`sinterheat.startup` holds the signals to one line (from the
package's first statement on); only during the interpreter's own start-up, a few tens of ms, are the system's
defaults in place.
"""

from __future__ import annotations

import contextlib
import contextvars
import gc
import os
import signal
import sys
import threading
from dataclasses import dataclass, field

EXIT_CODE = 130  #: 128 + SIGINT
#: The signals handled as Ctrl-C is. SIGTERM is what a batch scheduler sends at a time limit (and ``kill``), SIGHUP
#: what a closed terminal or a lost ssh session sends; each ends a run with its one line and exit code 128 + signal.
SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))
EXIT_CODES = frozenset(128 + int(signum) for signum in SIGNALS)
_current: contextvars.ContextVar[Where | None] = contextvars.ContextVar("sinterheat_where", default=None)


@dataclass
class Where:
    """Where a run is (module docstring).

    Parameters
    ----------
    command : str
        The command, e.g. ``"python -m fem_neck fit"``.
    stage : str
        What is running.
    step : int or str or None
        An int is shown as "step k"; a string as it is (e.g. "12 of 40 solves done").
    t : float or None
        Simulated time, s.
    out : str or None
        The folder holding usable partial results; None: no results written yet.
    signalled : bool
        Whether a handled signal has arrived (set by the handler).
    signum : int
        The signal that arrived (SIGINT, SIGTERM or SIGHUP).
    """

    command: str = ""
    stage: str = ""
    step: int | str | None = None
    t: float | None = None
    out: str | None = None
    signalled: bool = field(default=False, repr=False)  # a SIGINT has arrived (set by the handler)
    signum: int = field(default=signal.SIGINT, repr=False)  # the signal that arrived (SIGINT, SIGTERM or SIGHUP)

    _FIELDS = ("stage", "step", "t", "out")

    def update(self, **fields) -> Where:
        """Set any of ``stage``, ``step``, ``t``, ``out`` (an unknown name is a programming error: ``TypeError``).

        After a Ctrl-C it raises ``KeyboardInterrupt`` (once the fields are set): an interrupt that C code swallowed
        surfaces at the next update.

        Parameters
        ----------
        fields : object
            New values by name: ``stage`` (str), ``step`` (int or str), ``t`` (simulated time, s), ``out`` (folder).
        """
        for name, value in fields.items():
            if name not in self._FIELDS:
                raise TypeError(f"Where.update: unknown field {name!r} (fields: {', '.join(self._FIELDS)})")
            setattr(self, name, str(value) if name == "out" and value is not None else value)
        if self.signalled:
            raise KeyboardInterrupt
        return self

    def message(self) -> str:
        """The one line: ``<command>: interrupted at <where>; partial results in <out>`` (or no results written)."""
        at = [self.stage] if self.stage else []
        if self.step is not None:
            at.append(f"step {self.step}" if isinstance(self.step, int) else str(self.step))
        if self.t is not None:
            at.append(f"t = {self.t:.6g} s")
        results = f"partial results in {self.out}" if self.out else "no results written"
        by = "" if self.signum == signal.SIGINT else f" by {signal.Signals(self.signum).name}"
        return f"{self.command}: interrupted{by} at {', '.join(at) or 'start-up'}; {results}"

    @property
    def exit_code(self) -> int:
        """The exit code of the interrupted run, 128 + the signal (130 for Ctrl-C, 143 for SIGTERM, 129 for SIGHUP,
        what a shell reports for each)."""
        return 128 + int(self.signum)


def where() -> Where:
    """The :class:`Where` of the run in progress (a throw-away one outside :func:`interruptible`)."""
    return _current.get() or Where()


def handled() -> list[int]:
    """The :data:`SIGNALS` a run handles here: all but SIGTERM or SIGHUP where they are ignored already (``nohup``
    ignores SIGHUP so that the run outlives its terminal: it does)."""
    return [signum for signum in SIGNALS if signum == signal.SIGINT or signal.getsignal(signum) is not signal.SIG_IGN]


def _raise_once(signum, frame):
    state = _current.get()
    if state is not None:
        if state.signalled:
            return  # a second Ctrl-C (or SIGTERM) must not cut the clean-up short
        state.signalled = True
        state.signum = signum
    raise KeyboardInterrupt


def _unraisable(previous):
    def hook(unraisable):
        if issubclass(unraisable.exc_type, KeyboardInterrupt) and _current.get() is not None:
            return  # swallowed (raised in a destructor or a weakref callback): the flag the handler set raises it
            # again at the next Where.update or when the command returns (raised in here, it would only be printed)
        previous(unraisable)

    return hook


@contextlib.contextmanager
def interruptible(state: Where):
    """Run a command's body with ``state`` as the current :class:`Where` and the SIGINT handler of this module
    (:func:`run_command` is the usual way). The previous handler is restored unless the run was interrupted (then
    the process is on its way out, and a further Ctrl-C during its exit stays ignored).

    Parameters
    ----------
    state : Where
        The run's position, updated by the command and read by the handler.
    """
    token = _current.set(state)
    main_thread = threading.current_thread() is threading.main_thread()
    previous = {signum: signal.signal(signum, _raise_once) for signum in handled()} if main_thread else {}
    hook, sys.unraisablehook = sys.unraisablehook, _unraisable(sys.unraisablehook)
    try:
        yield state
    finally:
        sys.unraisablehook = hook
        _current.reset(token)
        if not state.signalled:
            for signum, handler in previous.items():
                if handler is not None:
                    signal.signal(signum, handler)


def run_command(state: Where, func, *args) -> int:
    """``func(*args)`` (a command's body, returning its exit code) under :func:`interruptible`; after Ctrl-C the
    one line of :func:`interrupted` and its exit code instead::

        here = Where("python -m fem_neck fit")
        return run_command(here, body, argv, here)   # body updates here.command, here.update(...)

    Parameters
    ----------
    state : Where
        The run's position (its ``command`` names the line).
    func : callable
        The command's body, returning its exit code.
    args : object
        Its positional arguments.
    """
    try:
        with interruptible(state):
            code = func(*args)
    except BaseException as exc:
        if isinstance(exc, KeyboardInterrupt) or state.signalled:  # also an interrupt C code turned into an error
            return interrupted(state)
        raise
    return interrupted(state) if state.signalled else code  # an interrupt that C code swallowed


def interrupted(state: Where) -> int:
    """After a ``KeyboardInterrupt``: finalize gmsh if a session is open, close open tqdm bars, write the one line
    on stderr; returns the exit code, 128 + the signal (:data:`EXIT_CODE` for Ctrl-C).

    Parameters
    ----------
    state : Where
        The interrupted run's position.
    """
    if threading.current_thread() is threading.main_thread():
        for signum in SIGNALS:
            signal.signal(signum, signal.SIG_IGN)
    gmsh = sys.modules.get("gmsh")
    if gmsh is not None:
        with contextlib.suppress(Exception):
            if gmsh.isInitialized():
                gmsh.finalize()
    tqdm = sys.modules.get("tqdm")
    if tqdm is not None:
        for bar in list(getattr(tqdm.tqdm, "_instances", ())):
            with contextlib.suppress(Exception):
                bar.close()
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(state.message() + "\n")
        sys.stderr.flush()
    return state.exit_code


def ignore_interrupts() -> None:
    """Initializer of pool workers: ignore SIGINT and SIGHUP (a terminal's Ctrl-C or hang-up reaches the whole
    process group; the parent handles it and stops the pool), die of SIGTERM as a process does by default (it is how
    :func:`stop_pool` ends them; a forked worker would otherwise inherit the parent's handler), and undo the block
    :func:`shielded` handed down."""
    for signum in SIGNALS:
        signal.signal(signum, signal.SIG_DFL if signum == getattr(signal, "SIGTERM", None) else signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, set(SIGNALS))


@contextlib.contextmanager
def shielded():
    """Hold back SIGINT while worker processes are being started; a Ctrl-C meanwhile is raised on leaving the block.

    A worker forked here but interrupted before its pool has recorded it would never be stopped: it would outlive
    the run, holding the run's stdout and stderr. Two holds: SIGINT is blocked in this thread, so that a fork
    inherits it blocked and a worker cannot be interrupted before :func:`ignore_interrupts` runs; and the Python
    handler is swapped for one that only records the signal, because the kernel gives a SIGINT sent to the process
    to any thread that does not block it (tqdm's monitor, BLAS threads), and its C handler then has this thread run
    the Python handler all the same."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    held = []
    previous = {signum: signal.getsignal(signum) for signum in SIGNALS}
    for signum, handler in previous.items():
        if handler is not None:  # None: a handler not installed from Python, left as it is
            signal.signal(signum, lambda signum, frame: held.append(signum))
    old = signal.pthread_sigmask(signal.SIG_BLOCK, set(SIGNALS)) if hasattr(signal, "pthread_sigmask") else None
    try:
        yield
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)  # a signal held on this thread is recorded now
        for signum, handler in previous.items():
            if handler is not None:
                signal.signal(signum, handler)
        if held:
            signal.raise_signal(held[0])


def stop_pool(pool) -> None:
    """Stop a ``concurrent.futures.ProcessPoolExecutor`` at once: cancel what has not started and terminate the
    workers (their running jobs are abandoned).

    Parameters
    ----------
    pool : concurrent.futures.ProcessPoolExecutor
        The executor to stop.
    """
    processes = list((getattr(pool, "_processes", None) or {}).values())  # no public handle before Python 3.14
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        with contextlib.suppress(Exception):
            process.terminate()
    for process in processes:
        with contextlib.suppress(Exception):
            process.join(timeout=5.0)


def exit_process(code: int):
    """``sys.exit(code)`` for a CLI's ``__main__``; after an interrupt (:data:`EXIT_CODE`) stdout and stderr are
    flushed and the process leaves at once with that code (``os._exit``): the run has unwound, and Python's own
    exit would report a kill by SIGINT instead once the interrupt has passed through some C-level imports. Any
    other code: the garbage collector's objects are frozen first (``gc.freeze``), so that the interpreter's shutdown
    does not walk them again (cyclic garbage the command left is then freed with the process, without its
    finalizers; the commands close their files themselves).

    Parameters
    ----------
    code : int
        The exit code.
    """
    if threading.current_thread() is threading.main_thread():  # the command is over: a late signal ends the process
        for signum in handled():  # as the system's default does (no start-up line, no KeyboardInterrupt traceback)
            signal.signal(signum, signal.SIG_DFL)
    if code in EXIT_CODES:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(code)
    # the command is over and has closed its files: what it made lives until the process ends, so the collector
    # need not walk it again while the interpreter shuts down (its passes over numpy's and scipy's objects took
    # ~0.05 s of CPU, a twentieth of `python -m fem_neck fit`); atexit handlers run as before
    gc.freeze()
    sys.exit(code)
