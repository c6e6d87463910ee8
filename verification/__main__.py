"""``python -m verification``: the paper's claims reproduced and the DEM surrogate checked against FE.

Commands (each writes ``report.md``, ``summary.json`` and ``run.json`` plus PNG figures into ``--out DIR``):

* ``paper``      -- Rojek et al. 2022 reproduced, our numbers beside theirs (section ``paper``);
* ``dem-vs-fe``  -- DEM pipe network against FE: collinear chains, 3D clusters, transient pair
  (sections ``chains``, ``clusters``, ``transient``);
* ``all``        -- ``paper`` and ``dem-vs-fe``.

Run time against error is ``python -m benchmarks``; the stress cases are tests (``python -m pytest -m stress``).
``--quick`` runs reduced versions (``all --quick`` in under 3 minutes on 2 cores). ``--json`` prints the content of
``summary.json`` (comparison name -> relative error) as one object and nothing else on stdout. Progress goes to
stderr. Exit code: 0 when every section ran, 1 when a section failed (its one-line error on stderr, its traceback
in ``DIR/<section>/error.txt``), 2 for bad options.
"""

from __future__ import annotations

import os
import pathlib
import sys

from fem_neck.cli import OneLineParser, print_result
from verification.report import run_sections

PROG = "python -m verification"
DEFAULT_OUT = "verification-results"
COMMANDS = {
    "paper": (("paper",), "reproduce the quantitative claims of Rojek et al. 2022"),
    "dem-vs-fe": (("chains", "clusters", "transient"), "DEM pipe network against FE: chains, 3D clusters, transient"),
    "all": (("paper", "chains", "clusters", "transient"), "paper and dem-vs-fe"),
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


def add_run_options(parser, default_out: str, quick_help: str) -> None:
    """``--quick``, ``--out DIR``, ``--json`` and ``--no-progress`` (shared with ``python -m benchmarks``)."""
    parser.add_argument("--quick", action="store_true", help=quick_help)
    parser.add_argument("--out", metavar="DIR", default=default_out, help=f"output folder (default: {default_out})")
    parser.add_argument("--json", action="store_true", help="print summary.json as one JSON object on stdout")
    parser.add_argument("--no-progress", action="store_true",
                        help="no progress bars on stderr (none of the sections' either)")


def prepare_out(prog: str, out_text: str) -> pathlib.Path | None:
    """The output folder, created; ``None`` after one line on stderr when it cannot be (the caller exits 2)."""
    out = pathlib.Path(out_text)
    if not out_text.strip():
        sys.stderr.write(f"{prog}: error: --out {out_text!r}: must name a directory\n")
        return None
    if out.exists() and not out.is_dir():
        sys.stderr.write(f"{prog}: error: --out {out_text}: exists and is not a directory\n")
        return None
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # e.g. a parent is a file, or no permission
        sys.stderr.write(f"{prog}: error: --out {out_text}: cannot be created ({exc.strerror})\n")
        return None
    return out


def print_report(report, as_json: bool) -> None:
    """``--json``: the summary as one object; otherwise one line per section and the report's path."""
    if as_json:
        print_result(report.summary(), as_json=True)
        return
    for s in report.sections:
        print(f"{s.name:<10} {s.status:<14} {s.seconds:7.1f} s  {s.title if not s.error else s.error}")
    print(f"report: {report.out_dir / 'report.md'}")


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    out = prepare_out(f"{PROG} {args.command}", args.out)
    if out is None:
        return 2
    if args.no_progress:
        os.environ["TQDM_DISABLE"] = "1"  # also silences the sections' own bars (and those of worker processes)
    report = run_sections(COMMANDS[args.command][0], out, args.command, quick=args.quick,
                          progress=not args.no_progress)
    print_report(report, args.json)
    return 1 if report.failed else 0


if __name__ == "__main__":
    sys.exit(main())
