"""``python -m dem scenes [--json]``: list the built-in scenes with their descriptions."""


def register(sub):
    """Add the ``scenes`` command (module docstring) to the subcommands of ``python -m dem``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``python -m dem`` parser.
    """
    parser = sub.add_parser("scenes", help="list the built-in scenes", description=__doc__)
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.set_defaults(run=run)


def run(args) -> dict:
    """The built-in scenes (module docstring).

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line.

    Returns
    -------
    dict
        ``{name: description}``.
    """
    from dem.scene import builtin_scenes

    return builtin_scenes()
