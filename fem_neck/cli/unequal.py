"""``python -m fem_neck unequal``: FE of unequal sintered pairs against eq. 43 (K from a only) and the law per half.

Writes unequal.json, unequal.csv and unequal.png into --out when given (nothing otherwise).
"""

from __future__ import annotations

from sinterheat.cli import add_output_options, add_scheduler_option, add_workers_option


def register(subparsers) -> None:
    """Add the ``unequal`` sub-command's parser (its options and ``run``) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    from fem_neck.unequal import NECKS, RATIOS

    p = subparsers.add_parser("unequal", help="unequal radii: FE pairs vs eq. 43 and the full-range law per half",
                              description=" ".join(__doc__.split()))
    p.add_argument("--ratios", default=",".join(f"{q:g}" for q in RATIOS), metavar="Q1,Q2,...",
                   help="radius ratios r_j/r_i in [1, 100] (default %(default)s)")
    p.add_argument("--necks", default=",".join(f"{x:g}" for x in NECKS), metavar="X1,X2,...",
                   help="neck radii a/r_i in [0.001, 0.99] (default %(default)s)")
    p.add_argument("--rtol", type=float, default=1e-4, help="relative tolerance of each FE solve (default 1e-4)")
    add_workers_option(p)
    add_scheduler_option(p)
    add_output_options(p)
    p.set_defaults(run=run)


MAX_PAIRS = 200  # FE pair solves in one study (~1 s each of one core)


def run(args) -> dict:
    """Run the unequal-radii study (:func:`fem_neck.unequal.study`); its result as a JSON-ready dict.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck unequal`` (its ``--help`` lists them, with their units: lengths in m,
        temperatures in K, conductivities in W/(m K)).
    """
    from fem_neck.unequal import study

    pairs = len(args.ratios.split(",")) * len(args.necks.split(","))
    if pairs > MAX_PAIRS:
        raise ValueError(f"ratios x necks = {pairs} pair solves exceeds the limit of {MAX_PAIRS} for one study (each "
                         f"is an FE solve of ~1 s); run fewer ratios or necks at a time")

    result = study(args.ratios.split(","), args.necks.split(","), args.rtol, args.out, workers=args.workers)
    return {k: v for k, v in result.items() if k != "cases"} | ({"out": str(args.out)} if args.out else {})
