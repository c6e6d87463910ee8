"""Run verification sections and assemble their results into one folder.

A *section* is a module of this package with ``run(out_dir: pathlib.Path, quick: bool = False) -> dict`` returning
``title`` (str), ``markdown`` (str), ``summary`` (dict: comparison name -> relative error, or a small dict holding
one) and ``figures`` (list of PNG paths). :func:`run_sections` runs the sections one after another, each in its own
sub-folder ``out_dir/<section>/``, and :class:`Report` rewrites after every section

* ``report.md`` -- a header with the status of every section, then each section's title, markdown and figures;
* ``summary.json`` -- every comparison of every section, under the keys the sections chose;
* ``run.json`` -- the command, the options and each section's status, run time and error,

so that an interrupted run keeps what finished. A section whose module is absent is reported as not available; a
section that raises is reported as failed with its one-line message, and the run goes on. Ctrl-C marks the running
section as interrupted in the three files and ends the run (:mod:`fem_neck.interrupt`).
"""

from __future__ import annotations

import datetime
import importlib
import importlib.util
import json
import math
import os
import pathlib
import platform
import sys
import time
import traceback
from dataclasses import dataclass, field

import numpy as np

CONTRACT_KEYS = ("title", "markdown", "summary", "figures")
OK, FAILED, NOT_AVAILABLE, INTERRUPTED = "ok", "failed", "not available", "interrupted"


@dataclass
class SectionRecord:
    """What one section produced, or why it did not."""

    name: str
    status: str
    title: str
    markdown: str = ""
    summary: dict = field(default_factory=dict)
    figures: list = field(default_factory=list)
    seconds: float = 0.0
    error: str = ""


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
    """The output folder of one verification run; every call of :meth:`add` rewrites the three files."""

    def __init__(self, out_dir: pathlib.Path, command: str, quick: bool):
        self.out_dir = pathlib.Path(out_dir)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        self.command = command
        self.quick = quick
        self.started = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
        self.sections: list[SectionRecord] = []

    # -- assembling -------------------------------------------------------------------------------------------------
    def add(self, record: SectionRecord) -> None:
        self.sections.append(record)
        self.write()

    def summary(self) -> dict:
        """All comparisons of the sections that ran, under the sections' own keys.

        Sections name their keys (e.g. ``paper.sec6.K_fe``; the bench's keys are fixed by its issue); a key that an
        earlier section already used is prefixed with ``"<section>:"`` rather than overwritten.
        """
        out = {}
        for s in self.sections:
            for key, value in s.summary.items():
                out[key if key not in out else f"{s.name}:{key}"] = jsonable(value)
        return out

    def _relative(self, path) -> str:
        path = pathlib.Path(path)
        if not path.is_absolute():
            return path.as_posix()
        try:
            return path.relative_to(self.out_dir.resolve()).as_posix()
        except ValueError:
            return os.path.relpath(path, self.out_dir.resolve())

    def markdown(self) -> str:
        lines = [
            "# Verification report",
            "",
            f"`python -m verification {self.command}{' --quick' if self.quick else ''}` -- started "
            f"{self.started.isoformat()}, Python {platform.python_version()}, {platform.machine()}, "
            f"{os.cpu_count()} cores.",
            "",
            "| section | status | seconds |",
            "|---|---|---|",
        ]
        for s in self.sections:
            status = s.status if not s.error else f"{s.status}: {s.error}"
            lines.append(f"| [{s.title}](#{_anchor(s.title)}) | {status.replace('|', '/')} | {s.seconds:.1f} |")
        lines.append("")
        for s in self.sections:
            lines += [f"## {s.title}", ""]
            if s.status != OK:
                lines += [f"*{s.status}*: {s.error}", ""]
                continue
            lines += [s.markdown.rstrip(), ""]
            for fig in s.figures:
                rel = self._relative(fig)
                if rel not in s.markdown:
                    lines += [f"![{pathlib.Path(rel).stem}]({rel})", ""]
        return "\n".join(lines)

    def write(self) -> None:
        """Rewrite ``report.md``, ``summary.json`` and ``run.json`` (each via a temporary file, then renamed)."""
        run = {
            "command": self.command,
            "quick": self.quick,
            "started": self.started.isoformat(),
            "sections": {
                s.name: {"status": s.status, "title": s.title, "seconds": round(s.seconds, 3), "error": s.error,
                         "figures": [self._relative(f) for f in s.figures]}
                for s in self.sections
            },
        }
        _write_atomic(self.out_dir / "report.md", self.markdown() + "\n")
        _write_atomic(self.out_dir / "summary.json", json.dumps(self.summary(), indent=2) + "\n")
        _write_atomic(self.out_dir / "run.json", json.dumps(run, indent=2) + "\n")

    @property
    def failed(self) -> list[SectionRecord]:
        return [s for s in self.sections if s.status == FAILED]


def _anchor(title: str) -> str:
    """GitHub-style heading anchor."""
    keep = "".join(c for c in title.lower() if c.isalnum() or c in " -_")
    return keep.replace(" ", "-")


def _write_atomic(path: pathlib.Path, text: str) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def section_available(name: str) -> bool:
    """True when ``verification.<name>`` exists in this installation."""
    return importlib.util.find_spec(f"verification.{name}") is not None


def run_section(name: str, out_dir: pathlib.Path, quick: bool, options: dict | None = None) -> SectionRecord:
    """Import ``verification.<name>`` and call its ``run(out_dir / name, quick, **options)``; never raises."""
    if not section_available(name):
        return SectionRecord(name, NOT_AVAILABLE, name, error=f"verification.{name} is not available yet")
    t0 = time.perf_counter()
    try:
        module = importlib.import_module(f"verification.{name}")
        section_dir = pathlib.Path(out_dir) / name
        section_dir.mkdir(parents=True, exist_ok=True)
        result = check_section_result(name, module.run(section_dir, quick=quick, **(options or {})))
        summary = jsonable(result["summary"])
    except Exception as exc:  # a failing section is reported (traceback in <section>/error.txt), the run goes on
        from fem_neck.interrupt import where

        if where().signalled:  # not a failure: an interrupt that C code turned into this error
            raise KeyboardInterrupt from exc
        message = f"{type(exc).__name__}: {exc}".splitlines()[0]
        error_file = pathlib.Path(out_dir) / name / "error.txt"
        error_file.parent.mkdir(parents=True, exist_ok=True)
        error_file.write_text(traceback.format_exc())
        return SectionRecord(name, FAILED, name, seconds=time.perf_counter() - t0, error=message)
    return SectionRecord(name, OK, str(result["title"]), markdown=str(result["markdown"]), summary=summary,
                         figures=[str(f) for f in result["figures"]], seconds=time.perf_counter() - t0)


def run_sections(names, out_dir: pathlib.Path, command: str, quick: bool = False, options: dict | None = None,
                 progress: bool = True) -> Report:
    """Run ``names`` in order into ``out_dir``; the report files are rewritten after each section."""
    from tqdm import tqdm

    from fem_neck.interrupt import where

    report = Report(out_dir, command, quick)
    here = where()
    bar = tqdm(names, desc="verification", unit="section", file=sys.stderr, disable=not progress)
    for k, name in enumerate(bar):
        bar.set_postfix_str(name)
        here.update(stage=f"section {name}", step=f"{k} of {len(names)} sections done")
        t0 = time.perf_counter()
        try:
            record = run_section(name, report.out_dir, quick, options)
        except KeyboardInterrupt:  # the finished sections stay in the files, this one is marked
            report.add(SectionRecord(name, INTERRUPTED, name, seconds=time.perf_counter() - t0,
                                     error="interrupted (Ctrl-C)"))
            here.update(out=report.out_dir)
            raise
        if record.status != OK:
            bar.write(f"python -m verification {command}: {name}: {record.status}: {record.error}", file=sys.stderr)
        report.add(record)
        here.update(out=report.out_dir)
    return report


def save_figure(fig, path: pathlib.Path, dpi: int = 110, **savefig_options) -> pathlib.Path:
    """Write ``fig`` as a PNG at ``path`` and release it (pyplot figures are closed; a bare ``Figure`` needs
    nothing); returns ``path``."""
    import matplotlib.pyplot as plt

    fig.savefig(path, dpi=dpi, **savefig_options)
    plt.close(fig)
    return path


def md_table(header, rows, fmt: str = "{:.6g}") -> str:
    """A markdown table; floats are written with ``fmt``, ``None`` as an em dash, anything else with ``str``."""

    def cell(v):
        if v is None:
            return "—"
        if isinstance(v, (float, np.floating)):
            return fmt.format(v)
        return str(v)

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)
