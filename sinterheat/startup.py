"""The first thing a CLI's ``__main__`` does: hold Ctrl-C to one line from the first statement on.

Until a command's ``main`` installs the handler of :mod:`sinterheat.interrupt`, Python's default handler would turn a
Ctrl-C into a traceback -- and importing numpy, scipy and the package itself takes from a tenth of a second to
several on a busy machine. :func:`run_main` installs a handler that only raises ``KeyboardInterrupt`` before it
imports anything else (``signal`` is built in), imports the command's module and runs its ``main``; an interrupt
before ``main`` has taken over ends with the one line ``<prog> <command>: interrupted at start-up; no results
written`` and exit code 130, as one after it does.
"""

import importlib
import os
import signal
import sys

EXIT_CODE = 130  # 128 + SIGINT, as sinterheat.interrupt.EXIT_CODE


def _raise(signum, frame):
    raise KeyboardInterrupt


def run_main(prog: str, module: str, **kwargs):
    """``sys.exit(main(**kwargs))`` of ``module`` (a dotted name) for ``python -m <package>``, Ctrl-C held to one line
    from here on (module docstring)."""
    signal.signal(signal.SIGINT, _raise)
    try:
        main = importlib.import_module(module).main
        from sinterheat.interrupt import exit_process
    except KeyboardInterrupt:
        command = next((a for a in sys.argv[1:] if not a.startswith("-")), None)
        sys.stderr.write(f"{prog}{'' if command is None else ' ' + command}: interrupted at start-up; "
                         f"no results written\n")
        sys.stderr.flush()
        os._exit(EXIT_CODE)
    exit_process(main(**kwargs))
