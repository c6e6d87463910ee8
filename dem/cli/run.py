"""``python -m dem run SCENE [--out DIR [--resume | --overwrite]] [--threads N] [--quiet] [--json]``: run a scene
(TOML path or built-in name), print its summary.

With ``--out`` the run writes its folder as it goes (``dem.output.folder``): a folder that holds a run already is
refused unless ``--resume`` (go on from its last checkpoint, written every few seconds: a run with a fixed step ends
bit for bit as if it had not stopped) or ``--overwrite`` (delete that run's files first). Ctrl-C stops the run with
one line saying where, leaving the folder usable and resumable. ``--threads N``: the compiled loops (and BLAS) on N
threads, the same results on any number (default ``SINTERHEAT_THREADS``, else every core); ``--quiet``: no progress
bar. The console shows the heat flow into held particles as a total per group (``--json`` and ``summary.json``:
also per particle, for up to 1000 of them).

Under ``mpiexec -n N`` (N > 1) a static scene runs on N ranks (:mod:`dem.engines.distributed`; PETSc options through
``PETSC_OPTIONS``), each reading only its part of a packing in parts (``[particles] file = "NAME.parts"``,
:mod:`dem.scene.packing_files.parts`); rank 0 prints the summary and the one-line errors, the other ranks print
nothing.
"""

import os
import sys

from sinterheat.cli import add_output_options, add_quiet_option, add_threads_option


def register(sub):
    """Add the ``run`` command (module docstring) to the subcommands of ``python -m dem``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subparsers of the ``python -m dem`` parser.
    """
    parser = sub.add_parser("run", help="run a scene (TOML file or built-in name)", description=__doc__)
    parser.add_argument("scene", help="path to a scene TOML file, or a built-in name (see `python -m dem scenes`)")
    add_output_options(parser)
    parser.add_argument("--resume", action="store_true", help="go on with the interrupted run in --out")
    parser.add_argument("--overwrite", action="store_true", help="delete the run already in --out first")
    add_threads_option(parser)
    add_quiet_option(parser)
    parser.set_defaults(run=run)


def run(args) -> dict:
    """Run the scene ``args.scene`` (module docstring) and return its summary.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed command line: ``scene``, ``out``, ``resume``, ``overwrite``, ``quiet`` and ``json``.

    Returns
    -------
    dict
        The run's summary: in full with ``--json``, else as the console shows it (:func:`console`).

    Raises
    ------
    ValueError
        A bad scene or run folder, or the run ran out of memory (one line, which the CLI prints).
    """
    from dem.scene import load_scene
    from dem.driver import run as run_scene
    from dem.memory import available_bytes
    from dem.parallel.comm import launched, launcher_rank, world

    if launched() and launcher_rank() > 0:  # one summary, one error line: rank 0's
        sys.stdout = sys.stderr = open(os.devnull, "w")

    quiet = os.environ.get("TQDM_DISABLE")
    if args.quiet:  # no bar; the run keeps its position for the line an interrupt prints
        os.environ["TQDM_DISABLE"] = "1"
    try:
        comm = world() if launched() else None  # a packing in parts: each rank reads its own part
        scene = load_scene(args.scene, part=None if comm is None else (comm.Get_size(), comm.Get_rank()))
        summary = run_scene(scene, args.out, progress=True, resume=args.resume, overwrite=args.overwrite).summary
    except MemoryError:  # beyond the estimate checked up front (dem.memory): say so in one line all the same
        raise ValueError(f"scene = {args.scene!r}: ran out of memory (the machine had "
                         f"{(available_bytes() or 0.0) / 2**30:.3g} GiB available); use fewer particles") from None
    finally:  # called in a process that goes on (a test, a notebook), the environment is left as it was
        if quiet is None:
            os.environ.pop("TQDM_DISABLE", None)
        else:
            os.environ["TQDM_DISABLE"] = quiet
    return summary if args.json else console(summary)


def console(summary: dict) -> dict:
    """The summary as the console shows it: the heat flow into the held particles as a total per group, not one
    number per particle (``--json`` and ``summary.json`` have them all).

    Parameters
    ----------
    summary : dict
        The run's summary (:meth:`dem.engines.static.StaticEngine.summary` and the driver's additions).

    Returns
    -------
    dict
        ``summary`` without ``boundary_heat_flow["particles"]`` (unchanged where there is none).
    """
    flows = summary.get("boundary_heat_flow")
    if not isinstance(flows, dict) or "particles" not in flows:
        return summary
    return {**summary, "boundary_heat_flow": {k: v for k, v in flows.items() if k != "particles"}}
