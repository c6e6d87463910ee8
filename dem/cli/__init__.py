"""``python -m dem``: run a pipe-network thermal DEM scene, list the built-in scenes, drive one contact, or convert a
packing (for LAMMPS).

Usage::

    python -m dem run SCENE [--out DIR] [--json]     SCENE: a TOML file or a built-in name
    python -m dem scenes [--json]
    python -m dem laws [--json]                      the conductance and contact laws a scene can select
    python -m dem contact SCENE --history FILE.csv [--no-damping] [--out DIR] [--json]
    python -m dem convert IN OUT [--format F] [--length-unit U] [--json]   IN: a packing file, state.npz or scene;
                                                                          OUT: a LAMMPS data file, CSV or VTU

Each sub-command is a module of this package exposing ``register(subparsers)``; the plumbing is that of
:mod:`sinterheat.cli` (one JSON object with ``--json``; bad input: one line on stderr, exit code 2).
"""

from sinterheat import cli

COMMANDS = ("run", "scenes", "contact", "laws", "convert")


def main(argv=None) -> int:
    """``python -m dem``: parse the command line, run the command, print its result.

    Parameters
    ----------
    argv : list of str or None
        The arguments after the program name; None: ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit code: 0, 2 for bad input (a one-line error), 128 + the signal when interrupted.
    """
    return cli.main(argv, prog="python -m dem", description=" ".join(__doc__.split("\n\n")[0].split()),
                    modules=COMMANDS, package="dem.cli")
