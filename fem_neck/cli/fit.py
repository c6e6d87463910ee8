"""``python -m fem_neck fit``: FE sweep of the semisphere over a/r, Rojek's linear fit (eq. 40) and the full-range law.

Writes fit.json (the file the DEM's ``fit`` law reads), fit.csv (written point by point: rerunning with the same
--out resumes an interrupted sweep) and fit.png (the Fig. 16 analogue) into --out (default: results/fit).
"""

from __future__ import annotations

from fem_neck.cli import add_output_options, add_workers_option


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "fit", help="sweep a/r, fit K/K_cyl = c a/r and the full-range law (Fig. 16 analogue)",
        description=__doc__.splitlines()[0] + " " + " ".join(__doc__.split("\n\n")[1].split()))
    p.add_argument("--points", type=int, default=40, metavar="N",
                   help="number of FE points (4 to 200; default 40: 5 log-spaced on [0.001, 0.02), 35 uniform on "
                        "(0, 0.97])")
    p.add_argument("--rtol", type=float, default=1e-4, help="relative tolerance of each FE point (default 1e-4)")
    add_workers_option(p)
    add_output_options(p)
    p.set_defaults(run=run, out="results/fit")


MAX_POINTS = 200  # one point takes ~0.5 s of one core: 200 points are ~1 min on 2 cores


def run(args) -> dict:
    from fem_neck.fit import run_fit

    if args.points > MAX_POINTS:
        raise ValueError(f"points = {args.points}: valid range 4 <= points <= {MAX_POINTS} (each point is an FE solve "
                         f"of ~0.5 s; the fit's slope is converged well before)")

    result = run_fit(args.points, args.rtol, args.out, workers=args.workers)
    return {"slope": result["slope"], "sampling": result["sampling"], "points": result["points"],
            "law": result["law"], "slope_sensitivity": result["slope_sensitivity"],
            "unconverged": result["unconverged"], "seconds": result["seconds"], "out": str(args.out)}
