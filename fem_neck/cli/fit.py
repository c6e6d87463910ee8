"""``python -m fem_neck fit``: FE sweep of the semisphere over a/r, Rojek's linear fit (eq. 40) and the full-range law.

Writes fit.json (the file the DEM's ``fit`` law reads), fit.csv (written point by point: rerunning with the same
--out resumes an interrupted sweep) and fit.png (the Fig. 16 analogue) into --out (default: results/fit). Points of
an existing fit.csv are reused only when they were solved by the same solver and method to the same --rtol; the run
says how many on stderr ("reused 38 of 40 points from fit.csv; --fresh recomputes"), and --fresh recomputes all.
--neck union sweeps and fits the half body of the union of spheres instead (no neck cylinder; default --out
results/fit-union); its fit.json records the neck, and a law read from it refuses the other neck
(fem_neck.law.ConductanceLaw.require_neck).

Its processes run BLAS on one thread (the hp solves are many small products), set before numpy loads
(``fem_neck/__main__.py``, :func:`sinterheat.threads.blas_on_one_thread`) unless OMP_NUM_THREADS,
OPENBLAS_NUM_THREADS or MKL_NUM_THREADS say otherwise.
"""

from __future__ import annotations

import sys

from fem_neck.law import NECKS
from sinterheat.cli import add_output_options, add_scheduler_option, add_workers_option


def register(subparsers) -> None:
    """Add the ``fit`` sub-command's parser (its options and ``run``) to ``subparsers``.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-commands of the ``python -m fem_neck`` parser.
    """
    p = subparsers.add_parser(
        "fit", help="sweep a/r, fit K/K_cyl = c a/r and the full-range law (Fig. 16 analogue)",
        description=__doc__.splitlines()[0] + " " + " ".join(__doc__.split("\n\n")[1].split()))
    p.add_argument("--points", type=int, default=40, metavar="N",
                   help="number of FE points (4 to 200; default 40: 5 log-spaced on [0.001, 0.02), 35 uniform on "
                        "(0, 0.97])")
    p.add_argument("--rtol", type=float, default=1e-4, help="relative tolerance of each FE point (default 1e-4)")
    p.add_argument("--fresh", action="store_true", help="recompute every point (ignore an existing fit.csv)")
    p.add_argument("--neck", choices=NECKS, default="cylinder",
                   help="the half body: cylinder (Rojek's volume-conserving neck, default) or union (the union of "
                        "spheres, no neck cylinder)")
    add_workers_option(p)
    add_scheduler_option(p)
    add_output_options(p)
    p.set_defaults(run=run)


MAX_POINTS = 200  # one point takes ~0.5 s of one core: 200 points are ~1 min on 2 cores


def run(args) -> dict:
    """Sweep ``a/r`` and fit the laws (:func:`fem_neck.fit.run_fit`); the fit as a JSON-ready dict.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options of ``python -m fem_neck fit`` (its ``--help`` lists them, with their units: lengths in m,
        temperatures in K, conductivities in W/(m K)).
    """
    from fem_neck.fit import run_fit

    if args.points > MAX_POINTS:
        raise ValueError(f"points = {args.points}: valid range 4 <= points <= {MAX_POINTS} (each point is an FE solve "
                         f"of ~0.5 s; the fit's slope is converged well before)")

    if args.out is None:
        args.out = "results/fit" if args.neck == "cylinder" else f"results/fit-{args.neck}"
    result = run_fit(args.points, args.rtol, args.out, workers=args.workers, fresh=args.fresh, neck=args.neck)
    reused = result["reused"]
    if reused["points"]:
        sys.stderr.write(f"reused {reused['points']} of {reused['of']} points from fit.csv; --fresh recomputes\n")
    if reused["not_matching"]:
        sys.stderr.write(f"fit.csv: {reused['not_matching']} points from another solver, method, neck or tolerance "
                         f"were not reused (this run: {result['method']}, {args.neck}, rtol {args.rtol:g})\n")
    return {"slope": result["slope"], "sampling": result["sampling"], "points": result["points"],
            "law": result["law"], "slope_sensitivity": result["slope_sensitivity"],
            "unconverged": result["unconverged"], "reused": reused, "seconds": result["seconds"],
            "out": str(args.out)}
