"""``python -m fem_neck neck``: the neck of two sintered spheres (Rojek 2022, Section 4)."""

from sinterheat.cli import add_output_options
from fem_neck.geometry import METHODS, neck_geometry, neck_radius


def register(subparsers) -> None:
    """Add the ``neck`` sub-command's parser (its options and ``run``) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    p = subparsers.add_parser(
        "neck",
        help="neck radius and geometry of two sintered spheres",
        description="Neck of two spheres of radii RI and RJ overlapping by H (metres): volume-conserving "
        "cylindrical neck by Newton's method (Rojek 2022, eqs. 21-33), its first iterate (eq. 34) or Coble's "
        "neck (eqs. 10-12).",
    )
    p.add_argument("--ri", type=float, required=True, metavar="R_I", help="radius of particle i [m]")
    p.add_argument("--rj", type=float, required=True, metavar="R_J", help="radius of particle j [m]")
    p.add_argument("--h", type=float, required=True, metavar="H", help="overlap r_i + r_j - d [m]")
    p.add_argument("--method", choices=METHODS, default="newton", help="neck model (default: newton)")
    add_output_options(p)
    p.set_defaults(run=run)


def run(args) -> dict:
    """The neck geometry of the pair (:func:`fem_neck.geometry.neck_geometry`) as a JSON-ready dict.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck neck`` (its ``--help`` lists them, with their units: lengths in m,
        temperatures in K, conductivities in W/(m K)).
    """
    geo = neck_geometry(args.ri, args.rj, args.h, method=args.method)
    a_coble = neck_radius(args.ri, args.rj, args.h, method="coble")
    result = {
        "method": args.method,
        "r_i": args.ri,
        "r_j": args.rj,
        "h": args.h,
        "a": float(geo.a),
        "h_ci": float(geo.h_ci),
        "h_cj": float(geo.h_cj),
        "h_n": float(geo.h_n),
        "d": float(geo.d),
        "iterations": int(geo.iterations),
        "volume_residual": float(geo.volume_residual),
        "a_coble": a_coble,
        "coble_error": (a_coble - float(geo.a)) / float(geo.a),
    }
    if args.out:
        import json
        import pathlib

        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "neck.json").write_text(json.dumps(result, indent=2) + "\n")
    return result
