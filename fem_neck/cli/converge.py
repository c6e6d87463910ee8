"""``python -m fem_neck converge``: mesh convergence of the semisphere conductance (Rojek 2022, Fig. 15 analogue).

The study is :func:`fem_neck.convergence.study` (series, extrapolation and observed orders are described there).
"""

from __future__ import annotations

from sinterheat.cli import add_output_options


def register(subparsers) -> None:
    """Add the ``converge`` sub-command's parser (its options and ``run``) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    p = subparsers.add_parser(
        "converge", help="mesh convergence of the semisphere conductance (Fig. 15 analogue)",
        description=__doc__.splitlines()[0] + " P1/P2 on graded and uniform meshes, straight or curved boundary, and "
        "hp orders 2-9. Writes converge.png and converge.json into --out (default: .).")
    size = p.add_mutually_exclusive_group(required=True)
    size.add_argument("--h-over-r", type=float, metavar="X", help="overlap over r, 0 < X < 2/3")
    size.add_argument("--a-over-r", type=float, metavar="X", help="neck radius over r, 0 < X < 1")
    add_output_options(p)
    p.set_defaults(run=run)


def run(args) -> dict:
    """Run the convergence study (:func:`fem_neck.convergence.study`); its summary as a JSON-ready dict.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck converge`` (its ``--help`` lists them, with their units:
        lengths in m, temperatures in K, conductivities in W/(m K)).
    """
    from fem_neck import convergence
    from fem_neck.cli.solve import semisphere_case

    h, a = semisphere_case(args)
    study = convergence.study(a, args.out or ".", title=f"semisphere h/r={h:.4g}, a/r={a:.4g}")
    study["h_over_r"] = h  # as given (the study's own is recomputed from a/r, equal to round-off)
    return study
