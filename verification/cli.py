"""``python -m verification``: the paper's claims reproduced and the DEM surrogate checked against FE.

Commands (each writes ``report.md``, ``summary.json`` and ``run.json`` plus PNG figures into ``--out DIR``):

* ``paper``      -- Rojek et al. 2022 reproduced, our numbers beside theirs (section ``paper``);
* ``dem-vs-fe``  -- DEM pipe network against FE: collinear chains, 3D clusters, transient pair, periodic lattices
  and random packings (sections ``chains``, ``clusters``, ``transient``, ``lattices``);
* ``lattices``   -- only the periodic packings (section ``lattices``: FE results are cached in its folder);
* ``densification`` -- k_eff against the solid fraction of the union of spheres up to phi ~0.97: lattices and random
  packings (FE beside DEM), a Luding-sintered compact, the Wiener and Hashin-Shtrikman bounds, Koh & Fortini
  (section ``densification``);
* ``sintered-bed`` -- a bed poured by LAMMPS and the ``hot-wall-sintering`` compact sintered past the meeting of
  their necks: k_eff through the hand-over to the union of spheres, against the Wiener and Hashin-Shtrikman bounds
  (section ``sintered_bed``; needs LAMMPS);
* ``closing-pores`` -- the closing pores' cap of the ``shared-body`` law on the union of spheres calibrated on FE cells
  that ``densification`` does not check; writes ``closing_pores.json``, the file shipped as
  ``dem/laws/closing_pores.json`` (section ``closing_pores``);
* ``neck-node-bound`` -- a rigorous lower bound on the union's k_eff: the network with a node per neck whose
  particles are exact flux elements (NGSolve), on SC, BCC and FCC cells and three random packings, against the
  periodic-cell FE's upper bound, beside the compiled Trefftz element's network (section ``neck_node_bound``; the
  exact elements need NGSolve, left out without it);
* ``all``        -- ``paper`` and ``dem-vs-fe``.

Run time against error is ``python -m benchmarks``; the stress cases are tests (``python -m pytest -m stress``).
``--quick`` runs reduced versions (``all --quick`` in under 3 minutes on 2 cores). ``--json`` prints the content of
``summary.json`` (comparison name -> relative error) as one object and nothing else on stdout. Progress goes to
stderr. Exit code: 0 when every section ran, 1 when a section failed (its one-line error on stderr, its traceback
in ``DIR/<section>/error.txt``), 2 for bad options, 130 after Ctrl-C (one line on stderr naming the section; the
report keeps the finished sections, :mod:`sinterheat.interrupt`).
"""

from __future__ import annotations

import contextlib
import os
import sys

from sinterheat.cli import OneLineParser
from verification.report import (add_run_options, enter_scheduler, prepare_out, prepare_threads, print_report,
                                 run_sections)

PROG = "python -m verification"
DEFAULT_OUT = "verification-results"
COMMANDS = {
    "paper": (("paper",), "reproduce the quantitative claims of Rojek et al. 2022"),
    "dem-vs-fe": (("chains", "clusters", "transient", "lattices"),
                  "DEM pipe network against FE: chains, 3D clusters, transient, periodic lattices and packings"),
    "lattices": (("lattices",), "DEM pipe network against FE of periodic SC, BCC, FCC lattices and random packings"),
    "all": (("paper", "chains", "clusters", "transient", "lattices"), "paper and dem-vs-fe"),
    "sintering": (("sintering",), "Luding 2005 Sec. 4 reproduced: sintering, compression and vibration tests"),
    "densification": (("densification",), "k_eff through densification: union-of-spheres lattices, random packings "
                      "and a sintered compact, FE beside DEM, with the bounds and Koh & Fortini"),
    "sintered-bed": (("sintered_bed",), "a LAMMPS bed and the hot-wall compact sintered past the meeting of their "
                     "necks: k_eff through the hand-over, against the bounds"),
    "closing-pores": (("closing_pores",), "calibrate the closing pores' cap of the union shared-body law on FE cells "
                      "the densification study does not check (writes closing_pores.json)"),
    "neck-node-bound": (("neck_node_bound",), "a lower bound on the union's k_eff: the neck-node network of exact "
                        "flux elements against the periodic-cell FE's upper bound"),
}


def build_parser() -> OneLineParser:
    parser = OneLineParser(prog=PROG, description=__doc__.splitlines()[0],
                           epilog="Run `python -m verification COMMAND --help` for a command's options.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    sub.required = True
    for name, (sections, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=f"{help_text} (sections: {', '.join(sections)})")
        add_run_options(p, DEFAULT_OUT, "reduced run (all --quick: under 3 minutes on 2 cores)")
    return parser


def main(argv=None) -> int:
    from sinterheat.interrupt import Where, run_command

    here = Where(PROG)
    return run_command(here, _main, argv, here)


def _main(argv, here) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in argv if a in COMMANDS), None)
    if command is not None:  # named early, for an interrupt that comes before parsing ends
        here.command = f"{PROG} {command}"
    args = build_parser().parse_args(argv)
    here.command = f"{PROG} {args.command}"
    out = prepare_out(f"{PROG} {args.command}", args.out)
    if out is None or not prepare_threads(f"{PROG} {args.command}", args):
        return 2
    if args.no_progress:
        os.environ["TQDM_DISABLE"] = "1"  # also silences the sections' own bars (and those of worker processes)
    with contextlib.ExitStack() as cluster:
        if not enter_scheduler(cluster, f"{PROG} {args.command}", args.scheduler):
            return 2
        report = run_sections(COMMANDS[args.command][0], out, args.command, quick=args.quick,
                              progress=not args.no_progress)
    print_report(report, args.json)
    return 1 if report.failed else 0
