"""Reports: sections run one after another into one folder, rewritten after every step so that an interrupted run
keeps what finished. Used by ``python -m verification`` (the evidence) and ``python -m benchmarks`` (the timings).

A :class:`Report` is the folder ``out_dir`` with

* ``report.md`` -- a header with the status of every section and a table of every target, then each section's
  title, markdown, targets and figures;
* ``summary.json`` -- every comparison or measurement of every section, under the keys the sections chose;
* ``run.json`` -- the command, the options and each section's status, run time, error, targets and figures.

A :class:`Section` is one part of it, with its own sub-folder ``out_dir/<name>/``. Its markdown and its image links
are written relative to that sub-folder; the report rebases the links, so every image link of ``report.md``
resolves from the report's own folder, and each figure appears once (those the markdown does not show are appended
to the section). A section's *status* is ``ok``; ``fail`` when one of its targets (:meth:`Section.target`, e.g. a
time limit) is missed; ``error`` when it raised (its one-line message in the status, its traceback in
``<section>/error.txt``); ``not available`` when its module is absent; ``interrupted`` when Ctrl-C stopped it (the
finished sections stay in the files, and the run ends: :mod:`sinterheat.interrupt`). Commands exit with 1 when any
section is ``fail`` or ``error``.

:func:`add_run_options`, :func:`prepare_out` and :func:`print_report` are the options, output folder and printout
the two commands share.

Two ways to fill a section: the verification sections are modules with ``run(out_dir, quick) -> dict`` returning
``title``, ``markdown``, ``summary`` and ``figures``, and optionally ``targets`` (``(label, measured, limit)``
triples, each a :meth:`Section.target`) (:func:`run_sections`); the benchmark subjects write into the
section as they go (``section.csv``, ``section.figure``, ``section.add_text``, ``section.summary``,
``section.target``) inside ``with section.running():``.
"""

from __future__ import annotations

import contextlib
import csv
import datetime
import importlib
import importlib.util
import json
import math
import os
import pathlib
import platform
import posixpath
import re
import sys
import time
import traceback
from dataclasses import dataclass, field

import numpy as np

from sinterheat.cli import add_scheduler_option, add_threads_option, print_result, use_threads

CONTRACT_KEYS = ("title", "markdown", "summary", "figures")
OK, FAIL, ERROR, NOT_AVAILABLE, RUNNING, INTERRUPTED = "ok", "fail", "error", "not available", "running", \
    "interrupted"
PASS, NOT_MEASURED = "pass", "not measured"
IMAGE_LINK = re.compile(r"!\[([^\]]*)\]\(([^)\s]+)\)")


@dataclass
class Target:
    """A limit a measured value must not exceed (``measured <= limit``); ``measured`` None: not measured here."""

    label: str
    measured: float | None
    limit: float
    unit: str = ""

    @property
    def verdict(self) -> str:
        if self.measured is None:
            return NOT_MEASURED
        return PASS if self.measured <= self.limit else FAIL


@dataclass
class Section:
    """One section of a report: what it produced (markdown, summary, figures, targets) or why it did not."""

    name: str
    status: str
    title: str
    markdown: str = ""
    summary: dict = field(default_factory=dict)
    figures: list = field(default_factory=list)
    seconds: float = 0.0
    error: str = ""
    targets: list = field(default_factory=list)
    out_dir: pathlib.Path | None = None
    report: Report | None = field(default=None, repr=False, compare=False)

    # -- writing into the section ------------------------------------------------------------------------------------
    def folder(self) -> pathlib.Path:
        self.out_dir.mkdir(parents=True, exist_ok=True)
        return self.out_dir

    def csv(self, stem: str, rows: list[dict]) -> pathlib.Path:
        """Write ``rows`` (dicts; columns in order of appearance) to ``<stem>.csv`` in the section's folder."""
        path = self.folder() / f"{stem}.csv"
        if rows:
            columns = list(dict.fromkeys(k for row in rows for k in row))
            with path.open("w", newline="") as fh:
                writer = csv.DictWriter(fh, fieldnames=columns)
                writer.writeheader()
                writer.writerows(rows)
        return path

    def figure(self, fig, stem: str) -> pathlib.Path:
        """Save ``fig`` as ``<stem>.png`` in the section's folder and list it; returns the path."""
        path = save_figure(fig, self.folder() / f"{stem}.png", bbox_inches="tight")
        self.figures.append(path)
        return path

    def add_text(self, heading: str, text: str, figures=()) -> None:
        """Append a ``###`` subsection (and links to ``figures``, paths in the section's folder); rewrite the report."""
        links = "".join(f"\n\n![{pathlib.Path(f).stem}]({pathlib.Path(f).name})" for f in figures)
        self.markdown += f"### {heading}\n\n{text.strip()}{links}\n\n"
        self.flush()

    def target(self, label: str, measured: float | None, limit: float, unit: str = "") -> str:
        """Record a target (``measured <= limit``); a missed one makes the section ``fail``. Returns the verdict."""
        target = Target(label, None if measured is None else float(measured), float(limit), unit)
        self.targets.append(target)
        self.flush()
        return target.verdict

    def flush(self) -> None:
        if self.report is not None:
            self.report.write()

    @contextlib.contextmanager
    def running(self):
        """Time the body; an exception is recorded (``error``, traceback in ``error.txt``), not raised; at the end
        the status is ``fail`` if a target was missed, else ``ok``. The report is rewritten."""
        from sinterheat.interrupt import where

        t0 = time.perf_counter()
        self.status = RUNNING
        self.flush()
        try:
            yield self
        except KeyboardInterrupt:
            self.status, self.error = INTERRUPTED, "interrupted (Ctrl-C)"
            where().update(out=self.out_dir.parent)
            raise
        except Exception as exc:  # a failing section is reported and the run goes on
            if where().signalled:  # not a failure: an interrupt that C code turned into this error
                self.status, self.error = INTERRUPTED, "interrupted (Ctrl-C)"
                where().update(out=self.out_dir.parent)
                raise KeyboardInterrupt from exc
            self.status = ERROR
            self.error = f"{type(exc).__name__}: {exc}".splitlines()[0]
            (self.folder() / "error.txt").write_text(traceback.format_exc())
        else:
            missed = [t.label for t in self.targets if t.verdict == FAIL]
            self.status = FAIL if missed else OK
            self.error = f"target missed: {'; '.join(missed)}" if missed else ""
        finally:
            self.seconds = time.perf_counter() - t0
            self.flush()


def jsonable(value):
    """``value`` with numpy scalars/arrays turned into Python objects and non-finite floats into ``None``."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, (str, int, float, bool)) or value is None:
        return value
    if isinstance(value, pathlib.PurePath):
        return str(value)
    raise TypeError(f"summary value {value!r} of type {type(value).__name__} is not JSON-ready")


def check_section_result(name: str, result) -> dict:
    """Raise ``ValueError`` unless ``result`` follows the section contract; return it."""
    if not isinstance(result, dict):
        raise ValueError(f"section {name}: run() returned {type(result).__name__}, expected dict")
    missing = [k for k in CONTRACT_KEYS if k not in result]
    if missing:
        raise ValueError(f"section {name}: run() result lacks {', '.join(missing)}")
    if not isinstance(result["summary"], dict):
        raise ValueError(f"section {name}: summary must be a dict")
    return result


class Report:
    """The output folder of one run; every change of a section rewrites the three files."""

    def __init__(self, out_dir: pathlib.Path, command: str, quick: bool, program: str = "python -m verification",
                 title: str = "Verification report", preamble: str = ""):
        self.out_dir = pathlib.Path(out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self.command = command
        self.quick = quick
        self.program = program
        self.title = title
        self.preamble = preamble
        self.started = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
        self.sections: list[Section] = []

    # -- assembling -------------------------------------------------------------------------------------------------
    def section(self, name: str, title: str) -> Section:
        """A new section writing into ``out_dir/<name>/`` and into this report."""
        section = Section(name, RUNNING, title, out_dir=self.out_dir / name, report=self)
        self.sections.append(section)
        return section

    def add(self, section: Section) -> None:
        """Append a section that has finished elsewhere; rewrite the files."""
        if section.out_dir is None:
            section.out_dir = self.out_dir / section.name
        section.report = self
        self.sections.append(section)
        self.write()

    def summary(self) -> dict:
        """All comparisons of the sections that ran, under the sections' own keys.

        Sections name their keys (e.g. ``paper.sec6.K_fe``; the benchmarks' keys are documented in the README); a
        key that an earlier section already used is prefixed with ``"<section>:"`` rather than overwritten.
        """
        out = {}
        for s in self.sections:
            for key, value in s.summary.items():
                out[key if key not in out else f"{s.name}:{key}"] = jsonable(value)
        return out

    def _relative(self, path) -> str:
        """``path`` (absolute, or relative to the working directory) relative to the report's folder."""
        return pathlib.Path(os.path.relpath(pathlib.Path(path).resolve(), self.out_dir.resolve())).as_posix()

    def _section_markdown(self, s: Section) -> tuple[str, set]:
        """The section's markdown with its image links rebased from its folder onto the report's; the link set."""
        base = self._relative(s.out_dir) if s.out_dir is not None else "."
        linked = set()

        def rebase(match):
            alt, target = match.groups()
            if not (target.startswith(("/", "http://", "https://", "data:"))):
                target = posixpath.normpath(posixpath.join(base, target))
            linked.add(target)
            return f"![{alt}]({target})"

        return IMAGE_LINK.sub(rebase, s.markdown), linked

    def markdown(self) -> str:
        lines = [
            f"# {self.title}",
            "",
            f"`{self.program} {self.command}{' --quick' if self.quick else ''}` -- started "
            f"{self.started.isoformat()}, Python {platform.python_version()}, {platform.machine()}, "
            f"{os.cpu_count()} cores." + (f" {self.preamble}" if self.preamble else ""),
            "",
            "| section | status | seconds |",
            "|---|---|---|",
        ]
        for s in self.sections:
            status = s.status if not s.error else f"{s.status}: {s.error}"
            lines.append(f"| [{s.title}](#{_anchor(s.title)}) | {status.replace('|', '/')} | {s.seconds:.1f} |")
        targets = [(s, t) for s in self.sections for t in s.targets]
        if targets:
            lines += ["", "Targets:", "", targets_table([t for _, t in targets], [s.name for s, _ in targets])]
        lines.append("")
        for s in self.sections:
            lines += [f"## {s.title}", ""]
            if s.status in (ERROR, NOT_AVAILABLE):
                lines += [f"*{s.status}*: {s.error}", ""]
                continue
            text, linked = self._section_markdown(s)
            if text.strip():
                lines += [text.rstrip(), ""]
            if s.targets:
                lines += [targets_table(s.targets), ""]
            for fig in dict.fromkeys(self._relative(f) for f in s.figures):
                if fig not in linked:
                    lines += [f"![{pathlib.Path(fig).stem}]({fig})", ""]
        return "\n".join(lines)

    def write(self) -> None:
        """Rewrite ``report.md``, ``summary.json`` and ``run.json`` (each via a temporary file, then renamed)."""
        run = {
            "command": self.command,
            "quick": self.quick,
            "started": self.started.isoformat(),
            "sections": {
                s.name: {"status": s.status, "title": s.title, "seconds": round(s.seconds, 3), "error": s.error,
                         "targets": [{"label": t.label, "measured": jsonable(t.measured), "limit": t.limit,
                                      "unit": t.unit, "verdict": t.verdict} for t in s.targets],
                         "figures": list(dict.fromkeys(self._relative(f) for f in s.figures))}
                for s in self.sections
            },
        }
        _write_atomic(self.out_dir / "report.md", self.markdown() + "\n")
        _write_atomic(self.out_dir / "summary.json", json.dumps(self.summary(), indent=2) + "\n")
        _write_atomic(self.out_dir / "run.json", json.dumps(run, indent=2) + "\n")

    @property
    def failed(self) -> list[Section]:
        """Sections that raised or missed a target."""
        return [s for s in self.sections if s.status in (FAIL, ERROR)]


def image_links(markdown: str) -> list[str]:
    """The targets of the image links ``![alt](target)`` of a markdown text, in order."""
    return [target for _, target in IMAGE_LINK.findall(markdown)]


def targets_table(targets: list[Target], sections: list[str] | None = None) -> str:
    """A markdown table of targets: what, measured, limit, verdict (and the section, if given)."""
    header = (["section"] if sections else []) + ["target", "measured", "limit", "verdict"]
    rows = []
    for k, t in enumerate(targets):
        measured = "—" if t.measured is None else f"{t.measured:.3g} {t.unit}".strip()
        rows.append(([sections[k]] if sections else []) + [t.label, measured, f"<= {t.limit:g} {t.unit}".strip(),
                                                           t.verdict.upper() if t.verdict == FAIL else t.verdict])
    return md_table(header, rows)


def _anchor(title: str) -> str:
    """GitHub-style heading anchor."""
    keep = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return keep.replace(" ", "-")


def _write_atomic(path: pathlib.Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


# the sections whose module is not ``verification.<name>``
SECTION_MODULES = {"sintering": "verification.luding.section"}


def section_module(name: str) -> str:
    """The module of the section ``name``: ``SECTION_MODULES``' or ``verification.<name>``."""
    return SECTION_MODULES.get(name, f"verification.{name}")


def section_available(name: str) -> bool:
    """True when the module of the section ``name`` (:func:`section_module`) exists in this installation."""
    return importlib.util.find_spec(section_module(name)) is not None


def run_section(name: str, out_dir: pathlib.Path, quick: bool, options: dict | None = None,
                report: Report | None = None) -> Section:
    """Import the module of the section ``name`` (:func:`section_module`) and call its ``run(out_dir / name, quick,
    **options)``; never raises. With ``report`` the section is part of it (and rewrites it as it goes)."""
    if report is not None:
        section = report.section(name, name)
    else:
        section = Section(name, RUNNING, name, out_dir=pathlib.Path(out_dir) / name)
    if not section_available(name):
        section.status, section.error = NOT_AVAILABLE, f"{section_module(name)} is not available yet"
        section.flush()
        return section
    with section.running():
        module = importlib.import_module(section_module(name))
        result = check_section_result(name, module.run(section.folder(), quick=quick, **(options or {})))
        section.summary.update(jsonable(result["summary"]))
        section.title, section.markdown = str(result["title"]), str(result["markdown"])
        section.figures += [pathlib.Path(f) for f in result["figures"]]
        for label, measured, limit in result.get("targets", ()):
            section.target(label, measured, limit)
    return section


def run_sections(names, out_dir: pathlib.Path, command: str, quick: bool = False, options: dict | None = None,
                 progress: bool = True) -> Report:
    """Run the verification sections ``names`` in order into ``out_dir``; the report is rewritten as they go."""
    from tqdm import tqdm

    from sinterheat.interrupt import where

    report = Report(out_dir, command, quick)
    here = where()
    bar = tqdm(names, desc="verification", unit="section", file=sys.stderr, disable=not progress)
    for k, name in enumerate(bar):
        bar.set_postfix_str(name)
        here.update(stage=f"section {name}", step=f"{k} of {len(names)} sections done")
        section = run_section(name, report.out_dir, quick, options, report=report)
        here.update(out=report.out_dir)
        if section.status != OK:
            bar.write(f"python -m verification {command}: {name}: {section.status}: {section.error}", file=sys.stderr)
    return report


def save_figure(fig, path: pathlib.Path, dpi: int = 110, **savefig_options) -> pathlib.Path:
    """Write ``fig`` as a PNG at ``path`` and release it (pyplot figures are closed; a bare ``Figure`` needs
    nothing); returns ``path``."""
    fig.savefig(path, dpi=dpi, **savefig_options)
    if "matplotlib.pyplot" in sys.modules:
        sys.modules["matplotlib.pyplot"].close(fig)
    return path


def md_table(header, rows, fmt: str = "{:.6g}") -> str:
    """A markdown table; floats are written with ``fmt``, ``None`` as an em dash, anything else with ``str``."""

    def cell(v):
        if v is None:
            return "—"
        if isinstance(v, (float, np.floating)):
            return fmt.format(v)
        return str(v).replace("|", "/")

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)


def records_table(rows: list[dict], columns: list[str] | None = None, fmt: str = "{:.4g}") -> str:
    """A markdown table of dict ``rows`` (columns: given, or every key in order of appearance)."""
    if not rows:
        return "(no rows)"
    columns = columns or list(dict.fromkeys(k for row in rows for k in row))
    return md_table(columns, [[row.get(c) for c in columns] for row in rows], fmt)


# --- the commands that write reports (python -m verification, python -m benchmarks) ---------------------------------
def add_run_options(parser, default_out: str, quick_help: str) -> None:
    """The options of a report command: ``--quick``, ``--out DIR``, ``--json``, ``--no-progress`` (or ``--quiet``),
    ``--threads`` (:func:`sinterheat.cli.add_threads_option`) and ``--scheduler`` (the sweeps' jobs on a Dask cluster,
    :mod:`sinterheat.pool`)."""
    parser.add_argument("--quick", action="store_true", help=quick_help)
    parser.add_argument("--out", metavar="DIR", default=default_out, help=f"output folder (default: {default_out})")
    parser.add_argument("--json", action="store_true", help="print summary.json as one JSON object on stdout")
    parser.add_argument("--no-progress", "--quiet", action="store_true",
                        help="no progress bars on stderr (none of the sections' either)")
    add_threads_option(parser)
    add_scheduler_option(parser)


def prepare_threads(prog: str, args) -> bool:
    """The threads of ``--threads`` (or ``SINTERHEAT_THREADS``) for the run (:func:`sinterheat.cli.use_threads`);
    ``False`` after one line on stderr when the environment variable is bad (the caller exits 2)."""
    try:
        use_threads(args)
    except ValueError as exc:
        sys.stderr.write(f"{prog}: error: {exc}\n")
        return False
    return True


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


def enter_scheduler(stack: contextlib.ExitStack, prog: str, scheduler: str | None) -> bool:
    """Enter the Dask cluster of ``--scheduler`` (if given) on ``stack``; ``False`` after one line on stderr when it
    cannot be reached (the caller exits 2)."""
    from sinterheat.pool import use_dask

    try:
        stack.enter_context(use_dask(scheduler))
    except OSError as exc:
        sys.stderr.write(f"{prog}: error: {' '.join(str(exc).split())}\n")  # names the scheduler
        return False
    return True


def print_report(report, as_json: bool) -> None:
    """``--json``: the summary as one object; otherwise one line per section and the report's path."""
    if as_json:
        print_result(report.summary(), as_json=True)
        return
    for s in report.sections:
        print(f"{s.name:<10} {s.status:<14} {s.seconds:7.1f} s  {s.title if not s.error else s.error}")
    print(f"report: {report.out_dir / 'report.md'}")
