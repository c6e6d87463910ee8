"""The first thing a CLI does: hold Ctrl-C to one line from the first statement on.

Until a command's ``main`` installs the handler of :mod:`sinterheat.interrupt`, Python's default handler would turn a
Ctrl-C into a traceback -- and importing numpy, scipy and the package itself takes from a tenth of a second to
several on a busy machine. ``python -m dem`` imports the package ``dem`` (and so numpy and scipy) before its
``__main__`` runs, so the package calls :func:`hold` as its first statement when it is imported for ``-m``;
:func:`run_main` calls it again, imports the command's module and runs its ``main``. A signal before ``main`` has
taken over ends the process at once (nothing is written yet, nothing needs cleaning up) with the one line ``<prog>
<command>: interrupted at start-up; no results written`` and exit code 130, as one after it does; SIGTERM and SIGHUP
likewise (``interrupted by SIGTERM``, exit code 128 + the signal; a SIGHUP that ``nohup`` ignores stays ignored).

A CLI may name commands whose processes run BLAS on one thread throughout (``one_blas_thread`` of :func:`run_main`):
for them the BLAS libraries are told so before numpy loads them (:func:`sinterheat.threads.blas_on_one_thread`), so
that their thread pools are never started.
"""

import functools
import importlib
import os
import signal
import sys


def _leave(prog: str, signum, frame):
    """The start-up handler: the one line, and out."""
    command = _command()
    by = "" if signum == signal.SIGINT else f" by {signal.Signals(signum).name}"
    try:
        sys.stderr.write(f"{prog}{'' if command is None else ' ' + command}: interrupted{by} at start-up; "
                         f"no results written\n")
        sys.stderr.flush()
    finally:
        os._exit(128 + int(signum))


def _command():
    """The sub-command on the command line (its first word that is not an option), or None."""
    return next((a for a in sys.argv[1:] if not a.startswith("-")), None)


def hold(prog: str) -> None:
    """Install the start-up handler (module docstring) for SIGINT, SIGTERM and SIGHUP; ``prog`` names the command
    in its line, e.g. ``"python -m dem"``.

    Parameters
    ----------
    prog : str
        The command as the user typed it, which starts the one line a signal writes (``"python -m dem"``, say).
    """
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is not None and (name == "SIGINT" or signal.getsignal(signum) is not signal.SIG_IGN):
            signal.signal(signum, functools.partial(_leave, prog))


def run_main(prog: str, module: str, *, one_blas_thread: tuple = (), **kwargs):
    """``sys.exit(main(**kwargs))`` of ``module`` (a dotted name) for ``python -m <package>``, Ctrl-C (and SIGTERM,
    SIGHUP) held to one line from here on (module docstring).

    Parameters
    ----------
    prog : str
        The command as the user typed it (``"python -m dem"``, say), for the start-up line (:func:`hold`).
    module : str
        Dotted name of the module whose ``main`` runs the command (``"dem.cli"``, say).
    one_blas_thread : tuple of str
        Sub-commands whose processes run BLAS on one thread throughout: for them
        :func:`sinterheat.threads.blas_on_one_thread` is called before ``module`` (and numpy) is imported.
    **kwargs
        Keyword arguments passed on to that ``main``.
    """
    hold(prog)
    if _command() in one_blas_thread:
        from sinterheat.threads import blas_on_one_thread

        blas_on_one_thread()
    main = importlib.import_module(module).main
    from sinterheat.interrupt import exit_process

    exit_process(main(**kwargs))
