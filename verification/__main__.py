"""``python -m verification``: the paper's claims, the DEM surrogate against FE, and the speed/stability studies.

Commands (each writes ``report.md``, ``summary.json`` and ``run.json`` plus PNG figures into ``--out DIR``):

* ``paper``      -- Rojek et al. 2022 reproduced, our numbers beside theirs (section ``paper``);
* ``dem-vs-fe``  -- DEM pipe network against FE: collinear chains, 3D clusters, transient pair
  (sections ``chains``, ``clusters``, ``transient``);
* ``all``        -- ``paper`` and ``dem-vs-fe``;
* ``bench``, ``stability`` -- run time against error, and stress tests (sections of the same names; they may add
  options of their own, see ``python -m verification bench --help``).

``--quick`` runs reduced versions (``all --quick`` in under 3 minutes on 2 cores). ``--json`` prints the content of
``summary.json`` (comparison name -> relative error) as one object and nothing else on stdout. Progress goes to
stderr. Exit code: 0 when every section ran, 1 when a section failed (its one-line error on stderr, its traceback
in ``DIR/<section>/error.txt``), 2 for bad options or a command whose module is not available.
"""

from __future__ import annotations

import argparse
import importlib
import os
import pathlib
import sys

from fem_neck.cli import OneLineParser, print_result
from verification.report import run_sections, section_available

PROG = "python -m verification"
DEFAULT_OUT = "verification-results"
COMMANDS = {
    "paper": (("paper",), "reproduce the quantitative claims of Rojek et al. 2022"),
    "dem-vs-fe": (("chains", "clusters", "transient"), "DEM pipe network against FE: chains, 3D clusters, transient"),
    "all": (("paper", "chains", "clusters", "transient"), "paper and dem-vs-fe"),
    "bench": (("bench",), "run time against error for FE, neck radius and DEM, with peers"),
    "stability": (("stability",), "numerical stability stress tests"),
    "sintering": (("sintering",), "Luding 2005 Sec. 4 reproduced: sintering, compression and vibration tests"),
}
PLUGINS = ("bench", "stability")  # their modules may define add_arguments(parser) for options of their own


def build_parser(command: str | None = None) -> tuple[argparse.ArgumentParser, list[str]]:
    """The parser, and the option names a plug-in section added for ``command`` (passed on to its ``run``)."""
    parser = OneLineParser(prog=PROG, description=__doc__.splitlines()[0],
                           epilog="Run `python -m verification COMMAND --help` for a command's options.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    sub.required = True
    extra: list[str] = []
    for name, (sections, help_text) in COMMANDS.items():
        p = sub.add_parser(name, help=help_text, description=f"{help_text} (sections: {', '.join(sections)})")
        p.add_argument("--quick", action="store_true", help="reduced run (all --quick: under 3 minutes on 2 cores)")
        p.add_argument("--out", metavar="DIR", default=DEFAULT_OUT, help=f"output folder (default: {DEFAULT_OUT})")
        p.add_argument("--json", action="store_true", help="print summary.json as one JSON object on stdout")
        p.add_argument("--no-progress", action="store_true", help="no progress bars on stderr (none of the sections' either)")
        if name == command and name in PLUGINS and section_available(name):
            module = importlib.import_module(f"verification.{name}")
            if hasattr(module, "add_arguments"):
                before = {a.dest for a in p._actions}
                module.add_arguments(p)
                extra = [a.dest for a in p._actions if a.dest not in before]
    return parser, extra


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    command = next((a for a in argv if a in COMMANDS), None)
    parser, extra = build_parser(command)
    args = parser.parse_args(argv)
    sections = COMMANDS[args.command][0]
    if args.command in PLUGINS and not section_available(args.command):
        sys.stderr.write(f"{PROG} {args.command}: not available: verification.{args.command} is not installed yet\n")
        return 2
    out = pathlib.Path(args.out)
    if not args.out.strip():
        sys.stderr.write(f"{PROG} {args.command}: error: --out {args.out!r}: must name a directory\n")
        return 2
    if out.exists() and not out.is_dir():
        sys.stderr.write(f"{PROG} {args.command}: error: --out {args.out}: exists and is not a directory\n")
        return 2
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:  # e.g. a parent is a file, or no permission
        sys.stderr.write(f"{PROG} {args.command}: error: --out {args.out}: cannot be created ({exc.strerror})\n")
        return 2
    options = {k: getattr(args, k) for k in extra}
    if args.no_progress:
        os.environ["TQDM_DISABLE"] = "1"  # also silences the sections' own bars (and those of worker processes)
    report = run_sections(sections, out, args.command, quick=args.quick, options=options,
                          progress=not args.no_progress)
    if args.json:
        print_result(report.summary(), as_json=True)
    else:
        for s in report.sections:
            print(f"{s.name:<10} {s.status:<14} {s.seconds:7.1f} s  {s.title if s.status == 'ok' else s.error}")
        print(f"report: {out / 'report.md'}")
    return 1 if report.failed else 0


if __name__ == "__main__":
    sys.exit(main())
