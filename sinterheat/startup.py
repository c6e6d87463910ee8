"""The first thing a CLI's ``__main__`` does: hold Ctrl-C to one line from the first statement on.

Until a command's ``main`` installs the handler of :mod:`sinterheat.interrupt`, Python's default handler would turn a
Ctrl-C into a traceback -- and importing numpy, scipy and the package itself takes from a tenth of a second to
several on a busy machine. :func:`run_main` installs a handler that only raises ``KeyboardInterrupt`` before it
imports anything else (``signal`` is built in), imports the command's module and runs its ``main``; an interrupt
before ``main`` has taken over ends with the one line ``<prog> <command>: interrupted at start-up; no results
written`` and exit code 130, as one after it does; SIGTERM and SIGHUP likewise (``interrupted by SIGTERM``, exit code
128 + the signal).
"""

import importlib
import os
import signal
import sys

_arrived = [signal.SIGINT]  # the signal that interrupted the start-up


def _raise(signum, frame):
    _arrived[0] = signum
    raise KeyboardInterrupt


def run_main(prog: str, module: str, **kwargs):
    """``sys.exit(main(**kwargs))`` of ``module`` (a dotted name) for ``python -m <package>``, Ctrl-C (and SIGTERM,
    SIGHUP: :data:`sinterheat.interrupt.SIGNALS`) held to one line from here on (module docstring)."""
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        signum = getattr(signal, name, None)
        if signum is not None and (name == "SIGINT" or signal.getsignal(signum) is not signal.SIG_IGN):
            signal.signal(signum, _raise)
    try:
        main = importlib.import_module(module).main
        from sinterheat.interrupt import exit_process
    except KeyboardInterrupt:
        command = next((a for a in sys.argv[1:] if not a.startswith("-")), None)
        by = "" if _arrived[0] == signal.SIGINT else f" by {signal.Signals(_arrived[0]).name}"
        sys.stderr.write(f"{prog}{'' if command is None else ' ' + command}: interrupted{by} at start-up; "
                         f"no results written\n")
        sys.stderr.flush()
        os._exit(128 + int(_arrived[0]))
    exit_process(main(**kwargs))
