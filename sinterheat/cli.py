"""Command-line plumbing shared by the packages' CLIs (``python -m fem_neck``, ``python -m dem``, ...).

Each sub-command lives in its own module of this package and exposes ``register(subparsers)``, which adds its
parser and sets ``run``: a function of the parsed arguments returning a JSON-ready dict. :func:`main` prints that
dict (``--json``: one object on stdout, nothing else), turns a ``ValueError`` into one line on stderr with exit code
2, and never shows a traceback for bad input (an ``OSError``, e.g. ``--out`` naming a file, is treated the same).
Warnings raised while a command runs (e.g. numpy overflow in an extreme input) are collected: after an error only
the one error line is printed; after success each distinct warning is one ``warning:`` line on stderr. Ctrl-C ends
any command with one line saying where it stopped and exit code 130 (:mod:`sinterheat.interrupt`); commands report
their progress with ``sinterheat.interrupt.where().update(...)``. A command with ``--scheduler``
(:func:`add_scheduler_option`) runs inside that Dask cluster (:func:`sinterheat.pool.use_dask`); one that cannot be
reached is an ``OSError``: one line, exit code 2. A command with ``--threads`` (:func:`add_threads_option`) runs its
compiled loops and BLAS on that many threads, by default ``SINTERHEAT_THREADS`` or every core
(:mod:`sinterheat.threads`); one with ``--quiet`` (:func:`add_quiet_option`) draws no progress bars.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import json
import math
import os
import re
import sys
import warnings

from sinterheat.help_text import HelpFormatter


class OneLineParser(argparse.ArgumentParser):
    """An argparse parser whose usage errors are one line on stderr and exit code 2.

    Negative numbers in scientific notation (``--ri -1e-3``) are read as values, not as options, so that the
    command can reject them with a message about the value. Its help shows the docstrings it is given (a command's
    description is its module docstring) as plain text, paragraphs kept (:class:`sinterheat.help_text.HelpFormatter`).

    Parameters
    ----------
    args : object
        Positional arguments of ``argparse.ArgumentParser``.
    kwargs : object
        Keyword arguments of ``argparse.ArgumentParser`` (``prog``, ``description``, ...).
    """

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|nan)$", re.I)

    def error(self, message):
        """Print ``PROG: error: MESSAGE`` as one line on stderr and exit with code 2 (no usage block).

        Parameters
        ----------
        message : str
            argparse's message.
        """
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def add_output_options(parser: argparse.ArgumentParser) -> None:
    """The options every sub-command shares: ``--json`` and ``--out DIR``.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A sub-command's parser.
    """
    parser.add_argument("--json", action="store_true", help="print one JSON object on stdout, nothing else")
    parser.add_argument("--out", metavar="DIR", default=None, help="write result files into DIR")


def _worker_count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"workers = {text!r}: must be an integer >= 1") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"workers = {value!r}: must be >= 1")
    return value


def add_workers_option(parser: argparse.ArgumentParser) -> None:
    """``--workers W``: processes of a parallel sweep (default: all cores), checked to be >= 1.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A sub-command's parser.
    """
    parser.add_argument("--workers", type=_worker_count, default=None, metavar="W",
                        help="processes (default: all cores)")


def _checked_by(module: str, check: str):
    """An argparse ``type``: the option's text passed to ``module.check`` (imported only when the option is given),
    whose ``ValueError`` becomes argparse's one-line error."""
    def convert(text: str):
        try:
            return getattr(importlib.import_module(module), check)(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc)) from None
    return convert


def add_threads_option(parser: argparse.ArgumentParser) -> None:
    """``--threads N``: the threads of the compiled loops and of BLAS, 1 to the cores (:mod:`sinterheat.threads`).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A sub-command's parser.
    """
    parser.add_argument("--threads", type=_checked_by("sinterheat.threads", "check"), default=None, metavar="N",
                        help="threads of the compiled loops and BLAS, 1 to the cores (default: the environment "
                             "variable SINTERHEAT_THREADS, else every core); results are the same on any number")


def use_threads(args) -> None:
    """The threads of ``--threads``, or of :func:`sinterheat.threads.count` (a bad ``SINTERHEAT_THREADS``: a
    ``ValueError`` naming it), for the rest of the process.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed options with ``threads`` (int or None).
    """
    from sinterheat import threads

    threads.use(threads.count() if args.threads is None else args.threads)


def add_quiet_option(parser: argparse.ArgumentParser) -> None:
    """``--quiet``: no progress bars; only the result and errors.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A sub-command's parser.
    """
    parser.add_argument("--quiet", action="store_true", help="no progress bars: only the result and errors")


def add_scheduler_option(parser: argparse.ArgumentParser) -> None:
    """``--scheduler ADDRESS``: the sweep's jobs on a Dask cluster (:func:`sinterheat.pool.use_dask`); without Dask
    installed the option is refused with how to install it.

    Parameters
    ----------
    parser : argparse.ArgumentParser
        A sub-command's parser.
    """
    parser.add_argument("--scheduler", type=_checked_by("sinterheat.pool", "check_scheduler"), default=None,
                        metavar="ADDRESS",
                        help="run the independent jobs on a Dask cluster: a scheduler's address (tcp://host:8786) or "
                             "'local' (a LocalCluster of --workers processes here); needs pip install '.[dask]'")


def _format(value) -> str:
    if isinstance(value, float):
        return f"{value:.10g}"
    if isinstance(value, (list, tuple)) and len(value) > 8:
        return f"[{len(value)} items]"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_format(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k}: {_format(v)}" for k, v in value.items()) + "}"
    return str(value)


def print_result(result: dict, as_json: bool) -> None:
    """``--json``: one JSON object; otherwise one ``key: value`` line per entry.

    A reader that closes the pipe early (``| head``) ends the output quietly, as for any Unix filter.

    Parameters
    ----------
    result : dict
        The command's JSON-ready result.
    as_json : bool
        Print one JSON object instead of lines.
    """
    try:
        _write_result(result, as_json)
        sys.stdout.flush()
    except BrokenPipeError:
        sys.stdout = open(os.devnull, "w")  # nothing more can reach the reader; keep interpreter exit quiet


def finite_or_none(value):
    """``value`` with every non-finite float (NaN, +-inf) replaced by ``None``: JSON has no NaN, and a number that
    is not defined (e.g. an order fitted from fewer than two points) is reported as null, never as NaN.

    Parameters
    ----------
    value : object
        A number, or a dict, list or tuple of them (nested).
    """
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: finite_or_none(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [finite_or_none(v) for v in value]
    return value


def _write_result(result: dict, as_json: bool) -> None:
    result = finite_or_none(result)
    for warning in result.get("warnings", ()):  # what a run says of its own standing: on stderr too
        print(f"warning: {warning}", file=sys.stderr)
    if as_json:
        json.dump(result, sys.stdout)
        sys.stdout.write("\n")
    else:
        width = max((len(k) for k in result), default=0)
        for key, value in result.items():
            print(f"{key:<{width}}  {_format(value)}")


def build_parser(prog: str, description: str, modules, package: str) -> argparse.ArgumentParser:
    """The top-level parser of ``prog`` with one sub-command per module of ``modules`` (each module's ``register`` adds
    its parser).

    Parameters
    ----------
    prog : str
        The program's name (``python -m fem_neck``).
    description : str
        The top-level help text.
    modules : sequence of str
        The sub-command modules' names, relative to ``package``.
    package : str
        The package holding them (``fem_neck.cli``).
    """
    parser = OneLineParser(prog=prog, description=description)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    sub.required = True
    for name in modules:
        importlib.import_module(f"{package}.{name}").register(sub)
    return parser


def main(argv=None, *, prog: str, description=None, modules, package: str) -> int:
    """Run the sub-command named in ``argv`` among ``modules`` of ``package`` (each exposing ``register``).

    Parameters
    ----------
    argv : list of str, optional
        The command-line arguments after the program name; default ``sys.argv[1:]``.
    prog : str
        The program's name (``python -m fem_neck``), which starts every error line.
    description : str, optional
        The top-level help text; default this module's docstring's first line.
    modules : sequence of str
        The sub-command modules' names, relative to ``package``.
    package : str
        The package holding them (``fem_neck.cli``).
    """
    from sinterheat.interrupt import Where, run_command

    here = Where(prog)
    return run_command(here, _main, argv, here, prog, description, modules, package)


def _main(argv, here, prog, description, modules, package) -> int:
    given = sys.argv[1:] if argv is None else list(argv)
    named = next((a for a in given if a in modules), None)
    if named is not None:  # the command's name, for an interrupt that comes before parsing ends
        here.command = f"{prog} {named}"
    parser = build_parser(prog, description or __doc__.splitlines()[0], modules, package)
    args = parser.parse_args(argv)
    here.command = f"{prog} {args.command}"
    here.update(stage=args.command)
    with warnings.catch_warnings(record=True) as caught:
        try:
            if hasattr(args, "threads"):
                use_threads(args)
            with _cluster(args):
                result = args.run(args)
        except (ValueError, OSError) as exc:  # bad input, or an output path that cannot be written
            if here.signalled:  # not bad input: an interrupt that C code turned into this error
                raise
            sys.stderr.write(f"{prog} {args.command}: error: {_error_text(exc, args, given)}\n")
            return 2
    if here.signalled:  # the command finished, but the user asked it to stop: no result is printed
        raise KeyboardInterrupt
    for text in dict.fromkeys(f"{w.category.__name__}: {_one_line(w.message)}" for w in caught):
        sys.stderr.write(f"{prog} {args.command}: warning: {text}\n")
    print_result(result, args.json)
    return 0


def _cluster(args):
    """The Dask cluster of ``--scheduler`` around the command, if the option is given."""
    scheduler = getattr(args, "scheduler", None)
    if scheduler is None:
        return contextlib.nullcontext()
    from sinterheat.pool import use_dask

    return use_dask(scheduler, getattr(args, "workers", None))


def _error_text(exc: Exception, args, argv) -> str:
    """The error's one line; a file-system error on a path the user gave names it (``--out DIR: Not a directory``
    for an option, the path alone for a positional argument), as the arguments' own checks do."""
    path = getattr(exc, "filename", None) if isinstance(exc, OSError) else None
    if path is not None and exc.strerror:
        path = str(path)
        for dest, value in vars(args).items():
            given = str(value) if isinstance(value, (str, os.PathLike)) else ""
            # the path itself, a file in it, or its temporary (.part)
            if given and path.startswith(given) and path[len(given):len(given) + 1] in ("", os.sep, "."):
                option = f"--{dest.replace('_', '-')}"
                return f"{option + ' ' if option in argv else ''}{value}: {exc.strerror}"
    return _one_line(exc)


def _one_line(message) -> str:
    return " ".join(str(message).split())
