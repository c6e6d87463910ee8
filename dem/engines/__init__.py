"""The numerical schemes that advance a scene, as engines behind one driver (:mod:`dem.driver`).

:data:`ENGINES` registers them; a scene names its engine (``Scene.engine``: ``[solver] engine``, or the one its physics
and contact law call for):

* ``"static"`` -- the pipe network of a packing that does not move, steady or in time (:mod:`dem.engines.static`);
* ``"verlet"`` -- particles that move under velocity-Verlet steps with any contact law, the heat following their
  contacts (:mod:`dem.engines.verlet`);
* ``"staggered"`` -- Zohdi 2014's staggered, adaptive, implicit scheme of positions, temperatures and current
  (:mod:`dem.engines.staggered`).

What the driver asks of an engine (the protocol every one of them follows):

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
  ``checkpoint()`` -- everything it carries, to go on.
"""

from __future__ import annotations

import importlib

#: The engines by name, each as ``module:class`` (imported when a scene runs it).
ENGINES = {
    "static": "dem.engines.static:StaticEngine",
    "verlet": "dem.engines.verlet.engine:VerletEngine",
    "staggered": "dem.engines.staggered.engine:StaggeredEngine",
}


def engine_class(name: str):
    """The engine registered as ``name`` (:data:`ENGINES`), imported only now: a scene loads the code it runs.

    Parameters
    ----------
    name : str
        The engine's name, a key of :data:`ENGINES`.

    Returns
    -------
    type
        The engine's class.

    Raises
    ------
    ValueError
        ``name`` is not a registered engine.
    """
    if name not in ENGINES:
        raise ValueError(f"[solver] engine = {name!r}: must be one of {', '.join(ENGINES)}")
    module, cls = ENGINES[name].split(":")
    return getattr(importlib.import_module(module), cls)
