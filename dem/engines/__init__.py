"""The numerical schemes that advance a scene, as engines behind one driver (:mod:`dem.driver`).

:data:`ENGINES` registers them; a scene names its engine (``Scene.engine``: ``[solver] engine``, or the one its physics
and contact law call for):

* ``"static"`` -- the pipe network of a packing that does not move, steady or in time (:mod:`dem.engines.static`);
* ``"verlet"`` -- particles that move under velocity-Verlet steps with any contact law, the heat following their
  contacts (:mod:`dem.engines.verlet`);
* ``"staggered"`` -- Zohdi 2014's staggered, adaptive, implicit scheme of positions, temperatures and current
  (:mod:`dem.engines.staggered`).

A run launched under MPI (:func:`dem.parallel.comm.launched`) takes the scene's engine from :data:`RANK_ENGINES`
instead: the same scheme with the sample shared out among the ranks, each in :mod:`dem.engines.distributed` under the
name of the engine it shares out (``static``: :mod:`dem.engines.distributed.static`, ``verlet``:
:mod:`dem.engines.distributed.verlet`); the driver runs either kind alike.

What the driver asks of an engine (the protocol every one of them follows):

* ``Engine.refuse(scene, resume)`` -- what it cannot do with the scene, refused before the run's folder or MPI is
  touched (:class:`Engine`);
* ``Engine(scene, restart=None)`` -- built from a scene; ``restart`` is a checkpoint of the same scene's run (the dict
  its ``checkpoint()`` gave): it goes on from there, bit for bit;
* ``name``; ``link_kind`` (``"bonds"`` or ``"contacts"``: what the lines of its snapshots are); ``t``, ``steps``,
  ``t_start`` (the time the run started at: 0, or a saved state's);
* ``run(observe, progress, checkpoint)`` -- advance to ``[solver] t_end``, calling ``observe()`` where a row of the
  time series may be due (every step of a static packing, every output time of moving particles, and at the
  start), ``progress(t)`` as simulated time passes and ``checkpoint(make, final)`` between steps, with ``make()``
  building the checkpoint only when the driver keeps one;
* ``record()`` (one row: a dict of numbers), ``positions()``, ``particle_fields()``, ``links()`` (``(points, lines,
  fields)``), ``profile()`` (or None), ``plots(out, summary)`` -- what the writer (:mod:`dem.output.writer`) writes;
* ``summary()`` -- what the run found; ``state()`` -- the sample as it ends (:mod:`dem.scene.state_file`);
  ``checkpoint()`` -- everything it carries, to go on;
* ``pieces_only`` -- true where each process holds only its piece of the sample (:class:`Engine`).
"""

from __future__ import annotations

import importlib

#: The engines by name, each as ``module:class`` (imported when a scene runs it).
ENGINES = {
    "static": "dem.engines.static:StaticEngine",
    "verlet": "dem.engines.verlet.engine:VerletEngine",
    "staggered": "dem.engines.staggered.engine:StaggeredEngine",
}


#: The engines of a run launched under MPI, by the names of :data:`ENGINES` whose scheme they share out among the ranks.
RANK_ENGINES = {
    "static": "dem.engines.distributed.static:DistributedStaticEngine",
    "verlet": "dem.engines.distributed.verlet:RankVerletEngine",
}


class Engine:
    """What every engine shares of the protocol (module docstring): what the driver asks of its class before one is
    built, and the kind of sample it holds."""

    #: True where each process holds only its piece of the sample, as the static engine on several ranks does; the
    #: driver then writes the snapshots in pieces (:class:`dem.output.pieces.PieceWriter`) and no ``state.npz``, and
    #: the summary lists the temperatures gathered from the ranks (``gathered_temperatures()``).
    pieces_only = False

    @classmethod
    def refuse(cls, scene, resume: bool) -> None:
        """Refuse what this engine cannot do with ``scene`` before the run's folder or MPI is touched; the engines
        of one process refuse nothing here (they check the scene as they are built).

        Parameters
        ----------
        scene : dem.scene.parse.Scene
            The scene.
        resume : bool
            Whether the run would go on from a checkpoint.

        Raises
        ------
        ValueError
            One line naming what the engine cannot do and what to do instead.
        """


def engine_class(name: str, ranks: bool = False):
    """The engine registered as ``name`` (:data:`ENGINES`, or :data:`RANK_ENGINES` for a run on MPI ranks), imported
    only now: a scene loads the code it runs.

    Parameters
    ----------
    name : str
        The engine's name, a key of :data:`ENGINES`.
    ranks : bool
        The run was launched under MPI (:func:`dem.parallel.comm.launched`): the engine that shares the sample out
        among the ranks.

    Returns
    -------
    type
        The engine's class.

    Raises
    ------
    ValueError
        ``name`` is not a registered engine, or has none on MPI ranks.
    """
    if name not in ENGINES:
        raise ValueError(f"[solver] engine = {name!r}: must be one of {', '.join(ENGINES)}")
    if ranks and name not in RANK_ENGINES:
        raise ValueError(f"[solver] engine = {name!r}: under mpiexec run static packings and the verlet engine "
                         f"(particles that move), not this one; run this scene without mpiexec")
    module, cls = (RANK_ENGINES if ranks else ENGINES)[name].split(":")
    return getattr(importlib.import_module(module), cls)
