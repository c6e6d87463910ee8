"""``python -m fem_neck`` sub-commands: each lives in its own module of this package and exposes
``register(subparsers)``; the plumbing (``--json``, one-line errors, Ctrl-C) is :mod:`sinterheat.cli`."""

from sinterheat import cli

COMMAND_MODULES = ("neck", "solve", "converge", "fit", "unequal", "cluster", "lattice")  # each module imports its heavy dependencies (gmsh, scikit-fem) inside run()


def main(argv=None, *, description=None) -> int:
    """Run ``python -m fem_neck`` (:func:`sinterheat.cli.main`); return the exit code.

    Parameters
    ----------
    argv : list of str, optional
        The command-line arguments after the program name; default ``sys.argv[1:]``.
    description : str, optional
        The top-level help text; default this package's docstring's first line.
    """
    return cli.main(argv, prog="python -m fem_neck", description=description or __doc__.splitlines()[0],
                    modules=COMMAND_MODULES, package="fem_neck.cli")
